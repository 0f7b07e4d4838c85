//! Structural checks that need the whole resolved program: FOR/NEXT pairing and nesting, no jump
//! into a FOR body from outside it, no recursive subroutine calls.
//!
//! S7-200 rules (the instruction set of Zhao & Yan's S7-200 examples): FOR/NEXT pairs nest like brackets inside one POU;
//! a jump may leave a loop body but not enter one (the loop head would be bypassed); subroutines
//! may nest but not recurse (the call graph is acyclic, which also keeps every CALL's access
//! summary finite).

use crate::diag::{Invalid, LoadError, Origin};
use crate::model::*;
use crate::syntax;

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
pub(crate) fn check(p: &mut Program, places: Places) -> Result<(), LoadError> {
    let mut errors = Vec::new();
    pair_loops(p, places, &mut errors);
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
        .take(crate::diag::MAX_ERRORS)
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
    let base = match (places.get(r.index()), &rung.block_path) {
        (Some(Some(at)), _) => super::util::rung_path(at.pou_path, at.index),
        (_, Some(block)) => block.clone(),
        (_, None) => String::new(),
    };
    let suffix = match element {
        None => ".ld".to_owned(),
        Some(i) => format!(".ld[{i}]"),
    };
    let e = LoadError::invalid(Some(&rung.id), &format!("{base}{suffix}"), kind);
    (r, element, e)
}

fn last_top(rung: &Rung) -> Option<&Element> {
    rung.series.last()
}

fn pair_loops(p: &mut Program, places: Places, errors: &mut Vec<Located>) {
    for pou in 0..p.pous.len() {
        let mut stack: Vec<RungId> = Vec::new();
        for r in p.pou_rungs(PouId(pou as u32)) {
            match last_top(p.rung(r)) {
                Some(Element::For { .. }) => stack.push(r),
                Some(Element::Next { .. }) => {
                    let Some(head) = stack.pop() else {
                        errors.push(err(p, places, r, Some(0), Invalid::NextWithoutFor));
                        continue;
                    };
                    if let Some(Element::Next { head: h }) = p.rungs[r.index()].series.last_mut() {
                        *h = head;
                    }
                    if let Some(Element::For { next, .. }) = p.rungs[head.index()].series.last_mut()
                    {
                        *next = r;
                    }
                }
                _ => {}
            }
        }
        // Unclosed heads, in program order.
        for head in stack {
            let n = p.rung(head).series.len();
            errors.push(err(
                p,
                places,
                head,
                Some(n.saturating_sub(1)),
                Invalid::ForWithoutNext,
            ));
        }
    }
}

/// Jumps may leave loop bodies but not enter them.
fn check_jumps(p: &Program, places: Places, errors: &mut Vec<Located>) {
    // body[r] = innermost FOR head whose body (head+1 ..= next) holds r.
    let mut body: Vec<Option<RungId>> = vec![None; p.rungs.len()];
    for r in p.rung_ids() {
        if let Some(Element::For { next, .. }) = last_top(p.rung(r)) {
            for b in r.0 + 1..=next.0 {
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
        r.0 >= head.0 && r.0 <= next.0
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
                    h = if head.0 == 0 {
                        None
                    } else {
                        body[head.index()]
                    };
                }
            }
        });
        if let Some((label, head)) = bad {
            errors.push(err(
                p,
                places,
                r,
                None,
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
    let mut calls: Vec<Vec<(PouId, RungId)>> = vec![Vec::new(); p.pous.len()];
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
    let mut colour = vec![Colour::White; p.pous.len()];
    for root in 0..p.pous.len() {
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
                            .map(|&(q, _)| p.pous[q].name.as_str())
                            .collect();
                        chain.push(&p.pou(callee).name);
                        return Err(err(
                            p,
                            places,
                            rung,
                            None,
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
