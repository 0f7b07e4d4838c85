//! Structural checks: FOR/NEXT pairing and nesting ([`Loops`], on the rungs as written, before
//! their elements are resolved, so that each FOR and NEXT is made with its partner's real id),
//! and, on the whole resolved program, no jump into a FOR body from outside it, no recursive
//! subroutine calls.
//!
//! S7-200 rules (the instruction set of Zhao & Yan's S7-200 examples): FOR/NEXT pairs nest like brackets inside one POU;
//! a jump may leave a loop body but not enter one (the loop head would be bypassed); subroutines
//! may nest but not recurse (the call graph is acyclic, which also keeps every CALL's access
//! summary finite).

use super::util::FastMap;
use plc_diag::{Invalid, LoadError, Origin};
use plc_model::*;
use plc_syntax as syntax;

/// Which end of a FOR/NEXT loop a rung is (by its last top-level element).
#[derive(Copy, Clone, PartialEq, Eq)]
pub(super) enum LoopEnd {
    For,
    Next,
}

/// The loop end a rung written as `ld` is, if any.
pub(super) fn loop_end(ld: &[syntax::Element]) -> Option<LoopEnd> {
    match ld.last().map(|e| &e.kind) {
        Some(syntax::ElementKind::For(_)) => Some(LoopEnd::For),
        Some(syntax::ElementKind::Next) => Some(LoopEnd::Next),
        _ => None,
    }
}

/// FOR/NEXT pairs (S7-200: they nest like brackets inside one POU), and the loop ends without
/// a partner as the errors they are: each rung and the element the error points at.
#[derive(Default)]
pub(super) struct Loops {
    partner: FastMap<RungId, RungId>,
    errors: Vec<(RungId, usize, Invalid)>,
}

impl Loops {
    /// Pairs the loop ends of one POU, given in program order as (rung, end, number of
    /// top-level elements); errors in program order, NEXTs without FOR first.
    pub(super) fn pair_pou(&mut self, ends: impl Iterator<Item = (RungId, LoopEnd, usize)>) {
        let mut open: Vec<(RungId, usize)> = Vec::new();
        for (r, end, n) in ends {
            match end {
                LoopEnd::For => open.push((r, n)),
                LoopEnd::Next => match open.pop() {
                    None => self.errors.push((r, 0, Invalid::NextWithoutFor)),
                    Some((head, _)) => {
                        self.partner.insert(head, r);
                        self.partner.insert(r, head);
                    }
                },
            }
        }
        for (head, n) in open {
            let last = n.saturating_sub(1);
            self.errors.push((head, last, Invalid::ForWithoutNext));
        }
    }

    /// The NEXT of a FOR rung, the FOR of a NEXT rung.
    pub(super) fn partner(&self, r: RungId) -> Option<RungId> {
        self.partner.get(&r).copied()
    }
}

/// A ladder rung's syntax and where it is: rung `index` of the POU whose rung array is at
/// `pou_path`.
pub(super) struct Place<'s> {
    pub(super) rung: &'s syntax::Rung<'s>,
    pub(super) pou_path: &'s str,
    pub(super) index: usize,
}

/// The place of each rung (by [`RungId`]; none for rungs lowered from FBD, whose block path the
/// model keeps).
type Places<'s> = &'s [Option<Place<'s>>];

/// Where an error about rung `r` points: its series (`None`) or its element `i`.
fn place(places: Places, r: RungId, element: Option<usize>) -> Origin {
    let Some(Some(Place { rung, .. })) = places.get(r.index()) else {
        return Origin::NONE;
    };
    let inner = match element {
        None => rung.ld_origin,
        Some(i) => rung.ld.get(i).map_or(Origin::NONE, |e| e.origin),
    };
    inner.or(rung.origin)
}

/// Every structural problem, in program order (loops and jumps per rung, then the first
/// recursive call chain); jumps are checked only when the loops pair.
pub(crate) fn check(p: &Program, places: Places, loops: Loops) -> Result<(), LoadError> {
    let mut errors: Vec<Located> = (loops.errors.into_iter())
        .map(|(r, element, kind)| err(p, places, r, Some(element), kind))
        .collect();
    if errors.is_empty() {
        check_jumps(p, places, &mut errors);
    }
    if let Err(e) = check_recursion(p, places) {
        errors.push(e);
    }
    // Each error names its rung and, by its path, the series or an element of it.
    let errors = errors
        .into_iter()
        .map(|(r, element, e)| e.at(place(places, r, element)));
    let diagnostics = errors
        .into_iter()
        .filter_map(|e| e.into_diagnostics().ok())
        .flatten()
        .take(plc_diag::MAX_ERRORS)
        .collect();
    match LoadError::from_diagnostics(diagnostics) {
        None => Ok(()),
        Some(e) => Err(e),
    }
}

/// An error of rung `r` at its series (`element` none) or at one of its top-level elements.
type Located = (RungId, Option<usize>, LoadError);

fn err(p: &Program, places: Places, r: RungId, element: Option<usize>, kind: Invalid) -> Located {
    let rung = p.rung(r);
    let base = match (places.get(r.index()), rung.block_path()) {
        (Some(Some(at)), _) => super::util::rung_path(at.pou_path, at.index),
        (_, Some(block)) => block.to_owned(),
        (_, None) => String::new(),
    };
    let suffix = match element {
        None => ".ld".to_owned(),
        Some(i) => format!(".ld[{i}]"),
    };
    let e = LoadError::invalid(Some(&rung.id), &format!("{base}{suffix}"), kind);
    (r, element, e)
}

/// The index of the first top-level element of `rung` that `is` holds for (none when the
/// element sought is inside a branch: the error then names the series).
fn top_level(rung: &Rung, is: impl Fn(&Element) -> bool) -> Option<usize> {
    rung.series.iter().position(is)
}

fn last_top(rung: &Rung) -> Option<&Element> {
    rung.series.last()
}

/// Jumps may leave loop bodies but not enter them.
fn check_jumps(p: &Program, places: Places, errors: &mut Vec<Located>) {
    // body[r] = innermost FOR head whose body (head+1 ..= next) holds r.
    let mut body: Vec<Option<RungId>> = vec![None; p.rungs().len()];
    for r in p.rung_ids() {
        if let Some(Element::For { next, .. }) = last_top(p.rung(r)) {
            for b in r.raw() + 1..=next.raw() {
                body[b as usize] = Some(r);
            }
        }
    }
    // `body` now holds the innermost head (later, inner heads overwrote outer ones).
    let encloses = |head: RungId, r: RungId| -> bool {
        let next = match last_top(p.rung(head)) {
            Some(Element::For { next, .. }) => *next,
            _ => return false,
        };
        r.raw() >= head.raw() && r.raw() <= next.raw()
    };
    for r in p.rung_ids() {
        let mut bad = None;
        walk_elements(&p.rung(r).series, &mut |e| {
            if let Element::Jmp { label, target } = e {
                let mut h = body[target.index()];
                while let Some(head) = h {
                    if !encloses(head, r) && bad.is_none() {
                        bad = Some((label.clone(), head));
                    }
                    h = if head.raw() == 0 {
                        None
                    } else {
                        body[head.index()]
                    };
                }
            }
        });
        if let Some((label, head)) = bad {
            let jump = top_level(
                p.rung(r),
                |e| matches!(e, Element::Jmp { label: l, .. } if *l == label),
            );
            errors.push(err(
                p,
                places,
                r,
                jump,
                Invalid::JumpIntoLoop {
                    label,
                    head: p.rung(head).id.clone(),
                },
            ));
        }
    }
}

fn check_recursion(p: &Program, places: Places) -> Result<(), Located> {
    // Callees per POU, with the rung that makes the call.
    let mut calls: Vec<Vec<(PouId, RungId)>> = vec![Vec::new(); p.pous().len()];
    for r in p.rung_ids() {
        let pou = p.rung(r).pou;
        walk_elements(&p.rung(r).series, &mut |e| {
            if let Element::Call { pou: callee } = e {
                calls[pou.index()].push((*callee, r));
            }
        });
    }
    // Iterative DFS with colours over the (small) call graph.
    #[derive(Clone, Copy, PartialEq)]
    enum Colour {
        White,
        Grey,
        Black,
    }
    let mut colour = vec![Colour::White; p.pous().len()];
    for root in 0..p.pous().len() {
        if colour[root] != Colour::White {
            continue;
        }
        let mut stack: Vec<(usize, usize)> = vec![(root, 0)];
        colour[root] = Colour::Grey;
        while let Some(&mut (pou, ref mut i)) = stack.last_mut() {
            if let Some(&(callee, rung)) = calls[pou].get(*i) {
                *i += 1;
                match colour[callee.index()] {
                    Colour::White => {
                        colour[callee.index()] = Colour::Grey;
                        stack.push((callee.index(), 0));
                    }
                    Colour::Grey => {
                        let start = stack
                            .iter()
                            .position(|&(q, _)| q == callee.index())
                            .unwrap_or(0);
                        let mut chain: Vec<&str> = stack[start..]
                            .iter()
                            .map(|&(q, _)| p.pous()[q].name.as_str())
                            .collect();
                        chain.push(&p.pou(callee).name);
                        let call = top_level(
                            p.rung(rung),
                            |e| matches!(e, Element::Call { pou } if *pou == callee),
                        );
                        return Err(err(
                            p,
                            places,
                            rung,
                            call,
                            Invalid::Recursion {
                                name: p.pou(callee).name.clone(),
                                chain: chain.join(" → "),
                            },
                        ));
                    }
                    Colour::Black => {}
                }
            } else {
                colour[pou] = Colour::Black;
                stack.pop();
            }
        }
    }
    Ok(())
}
