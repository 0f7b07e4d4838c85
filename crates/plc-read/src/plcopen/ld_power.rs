//! Power flow of an LD body: for each element, the series of elements that brings power to it
//! from the left rail, with parallel joins recovered as `or` groups (IEC 61131-3 8.2; TC6
//! `ldObjects`).
//!
//! A pin's power is the OR of its connections (Beremiz's `ComputeExpression`: several
//! `connection`s in one `connectionPointIn` are a wired OR). The series of the sources are
//! compared element by element from the rail: their common prefix is kept once, and what
//! follows it becomes the branches of one `or` — the series-parallel decomposition of the
//! wiring. A branch must hold conditions only (contacts, compares, nested `or`s): a coil or a
//! block inside a parallel branch, or a wiring that is not series-parallel and would need it,
//! is one error naming the localIds. Two branches that are the same series make the `or`
//! moot and are an error too, rather than a dropped read.
//!
//! Invariants: every element's series is computed once ([`Power::out`] memoises it, but for
//! the contacts and coils inside a plain series, which only their one consumer reads, walked
//! in a loop by [`Power::series`]); a loop in the wiring is an error naming its localIds;
//! nothing is dropped; the recursion goes one call deep per join or block, not per element.
//!
//! Deliberately not here: which elements end a rung and in what order rungs run (`super::ld`),
//! what blocks become (`super::ld_block`, reached through the [`Blocks`] the caller gives, since
//! a block's rules walk the power into its inputs through [`Power::out`] in turn).

use super::wiring::{ElemId, Graph, Source};
use super::xml::{error, origin, variable_ref, R};
use plc_diag::Origin;
use plc_syntax::{Edge, Element, ElementKind, Series};
use std::collections::HashMap;

/// What identifies an element of a path: two paths share a prefix when their keys agree.
#[derive(Clone, Debug, PartialEq, Eq, Hash)]
pub(super) enum Key {
    Elem(ElemId),
    /// An `or` of these sources (sorted).
    Or(Vec<ElemId>),
    /// The contact that reads output pin `.1` of function block `.0` after its box.
    Pin(ElemId, String),
    /// The coil that writes the network feeding data pin `.1` of block `.0` before its box.
    Feed(ElemId, String),
}

/// One element of a path from the left rail.
#[derive(Clone, Debug)]
pub(super) struct Item {
    pub key: Key,
    pub element: Element<'static>,
}

/// A series from the left rail to an element's output.
pub(super) type Path = Vec<Item>;

/// The most joins and blocks the power into one element may pass on its way from the rail:
/// [`Power::out`] recurses once per join or block, and this keeps it well within a thread's
/// stack (a debug build takes several KiB a level).
pub(super) const MAX_POWER_DEPTH: usize = 256;

/// The most `or`s a join may be nested in: as deep as the JSON program format holds them
/// (its 128 levels of JSON), so every later stage walks such a rung and `convert`'s output
/// loads back.
pub(super) const MAX_OR_NESTING: usize = 40;

/// How many `or`s deep `kind` nests (0 for an element that is no `or`). Bounded by
/// [`MAX_OR_NESTING`] for every `or` the reader built, so its recursion is bounded too.
fn or_nesting(kind: &ElementKind) -> usize {
    match kind {
        ElementKind::Or(branches) => {
            1 + branches
                .iter()
                .flatten()
                .map(|e| or_nesting(&e.kind))
                .max()
                .unwrap_or(0)
        }
        _ => 0,
    }
}

/// What blocks do to the power: the rules of `super::ld_block`, which `super::ld` gives to
/// [`Power::new`]. They call back into [`Power::out`] for the power into a block's inputs.
#[derive(Clone, Copy)]
pub(super) struct Blocks {
    /// The series out of block `e`'s power output `pin`.
    pub power_out: fn(&mut Power, ElemId, Option<&str>) -> R<Path>,
    /// Whether output `pin` of `e` is a function block's output read after its box.
    pub reads_side: fn(&Power, ElemId, Option<&str>) -> bool,
    /// The contact that reads output `pin` of function block `e` after its box.
    pub side_output: fn(&Power, ElemId, &str) -> R<Item>,
}

/// The power computation of one body.
pub(super) struct Power<'g, 'a, 'i> {
    pub g: &'g Graph<'a, 'i>,
    /// `pou Main, LD` (for errors).
    pub place: String,
    memo: HashMap<ElemId, Path>,
    visiting: Vec<bool>,
    /// Calls of [`Power::out`] open (at most [`MAX_POWER_DEPTH`]).
    depth: usize,
    /// Series that must run before a box in its rung: each writes the contact network feeding a
    /// data pin of the block into a variable of [`Power::vars`] (`super::ld` places them).
    pub feeds: Vec<(ElemId, Path)>,
    /// The variables those series write.
    pub vars: Vec<plc_syntax::Var<'static>>,
    /// The initial values of the POU's function block instances (an unconnected input reads
    /// its instance's, `super::interface::FbInit`).
    pub inits: super::block_types::Inits,
    blocks: Blocks,
}

impl<'g, 'a, 'i> Power<'g, 'a, 'i> {
    pub(super) fn new(g: &'g Graph<'a, 'i>, place: String, blocks: Blocks) -> Self {
        Power {
            g,
            place,
            memo: HashMap::new(),
            visiting: vec![false; g.elems.len()],
            depth: 0,
            feeds: Vec::new(),
            vars: Vec::new(),
            inits: Default::default(),
            blocks,
        }
    }

    pub(super) fn at(&self, e: ElemId) -> String {
        self.g.place(&self.place, e)
    }

    /// The series that brings power out of `e` (through its output pin `pin`).
    pub(super) fn out(&mut self, e: ElemId, pin: Option<&str>) -> R<Path> {
        if let Some(side) = pin.filter(|&x| (self.blocks.reads_side)(self, e, Some(x))) {
            return (self.blocks.side_output)(self, e, side).map(|item| vec![item]);
        }
        if let Some(p) = self.memo.get(&e) {
            return Ok(p.clone());
        }
        if self.visiting[e.0 as usize] {
            return Err(error(
                origin(self.g.get(e).node),
                &self.at(e),
                format!(
                    "the power wiring through localId {} forms a loop",
                    self.g.get(e).local_id
                ),
            ));
        }
        if self.depth >= MAX_POWER_DEPTH {
            return Err(error(
                origin(self.g.get(e).node),
                &self.at(e),
                format!(
                    "the power into localId {} passes more than {MAX_POWER_DEPTH} joins or blocks on its way from the left rail (the most plc-deps follows; docs/plcopen.md)",
                    self.g.get(e).local_id
                ),
            ));
        }
        self.visiting[e.0 as usize] = true;
        self.depth += 1;
        let path = self.compute(e, pin);
        self.depth -= 1;
        self.visiting[e.0 as usize] = false;
        let path = path?;
        self.memo.insert(e, path.clone());
        Ok(path)
    }

    fn compute(&mut self, e: ElemId, pin: Option<&str>) -> R<Path> {
        let el = self.g.get(e);
        let node = el.node;
        let here = self.at(e);
        let item = |kind| Item {
            key: Key::Elem(e),
            element: Element {
                origin: origin(node),
                kind,
            },
        };
        match el.tag {
            "leftPowerRail" => Ok(Vec::new()),
            "contact" | "coil" | "outVariable" => self.series(e),
            "inVariable" => {
                let text = self.expression(e)?;
                if text.trim().eq_ignore_ascii_case("TRUE") {
                    return Ok(Vec::new());
                }
                let var = plc_syntax::Located {
                    value: variable_ref(&text, node, &here)?.into(),
                    origin: origin(node),
                };
                Ok(vec![item(ElementKind::Contact {
                    var,
                    negated: false,
                    edge: None,
                })])
            }
            "block" => (self.blocks.power_out)(self, e, pin),
            other => Err(error(
                origin(node),
                &here,
                format!("a {other} cannot bring power to an element in LD"),
            )),
        }
    }

    /// The path out of contact or coil `e`: the contacts and coils in series behind it (each
    /// fed by one connection from the next, and feeding nothing else) are followed in a loop,
    /// not a call per element, so a rung of 20,000 contacts in series does not go 20,000 calls
    /// deep; only the path into the first of them is computed by [`Power::input`]. Their
    /// errors come in the order the recursion would give them (`e`'s first); the ones in
    /// between are marked as being computed meanwhile, so a loop back to one is the loop error.
    fn series(&mut self, e: ElemId) -> R<Path> {
        let mut items = vec![self.own_item(e)?];
        let mut chain = Vec::new();
        let mut cur = e;
        let base = loop {
            let sources = self
                .g
                .get(cur)
                .inputs
                .first()
                .map_or(&[][..], |p| p.sources.as_slice());
            match sources {
                [s] if s.pin.is_none()
                    && matches!(self.g.get(s.elem).tag, "contact" | "coil")
                    && !self.memo.contains_key(&s.elem)
                    && !self.visiting[s.elem.0 as usize]
                    && self.g.consumers[s.elem.0 as usize].len() == 1 =>
                {
                    match self.own_item(s.elem) {
                        Ok(item) => items.push(item),
                        Err(err) => break Err(err),
                    }
                    self.visiting[s.elem.0 as usize] = true;
                    chain.push(s.elem);
                    cur = s.elem;
                }
                _ => break self.input(cur, 0),
            }
        };
        for c in chain {
            self.visiting[c.0 as usize] = false;
        }
        let mut p = base?;
        p.extend(items.into_iter().rev());
        Ok(p)
    }

    /// Contact or coil `e` as the element of a path (without what feeds it).
    fn own_item(&self, e: ElemId) -> R<Item> {
        let node = self.g.get(e).node;
        let here = self.at(e);
        let kind = if self.g.get(e).tag == "contact" {
            let var = self.variable(e)?;
            let negated = super::xml::flag(node, "negated", &here)?;
            let edge = match node.attribute("edge") {
                None | Some("none") => None,
                Some("rising") => Some(Edge::Rising),
                Some("falling") => Some(Edge::Falling),
                Some(o) => return Err(error(origin(node), &here, format!("unknown edge `{o}`"))),
            };
            if negated && edge.is_some() {
                return Err(error(
                    origin(node),
                    &here,
                    "a contact both negated and edge-qualified is not supported (Beremiz would ignore the edge)",
                ));
            }
            ElementKind::Contact { var, negated, edge }
        } else {
            self.coil(e)?
        };
        Ok(Item {
            key: Key::Elem(e),
            element: Element {
                origin: origin(node),
                kind,
            },
        })
    }

    /// The coil (or an out variable fed by power) as an element.
    pub(super) fn coil(&self, e: ElemId) -> R<ElementKind<'static>> {
        let node = self.g.get(e).node;
        let here = self.at(e);
        let var = self.variable(e)?;
        let negated = super::xml::flag(node, "negated", &here)?;
        let storage = node.attribute("storage").unwrap_or("none");
        if !matches!(node.attribute("edge"), None | Some("none")) {
            return Err(error(
                origin(node),
                &here,
                "edge-qualified coils are not supported yet",
            ));
        }
        match (storage, negated) {
            ("none", _) => Ok(ElementKind::Coil { var, negated }),
            ("set", false) => Ok(ElementKind::Set(var)),
            ("reset", false) => Ok(ElementKind::Reset(var)),
            ("set" | "reset", true) => Err(error(
                origin(node),
                &here,
                "a set or reset coil that is also negated is not supported (Beremiz would ignore the storage)",
            )),
            (o, _) => Err(error(origin(node), &here, format!("unknown storage `{o}`"))),
        }
    }

    /// The variable a contact, coil or variable element names.
    pub(super) fn variable(&self, e: ElemId) -> R<plc_syntax::Name<'static>> {
        let el = self.g.get(e);
        let text = self.expression(e)?;
        Ok(plc_syntax::Located {
            value: variable_ref(&text, el.node, &self.at(e))?.into(),
            origin: origin(el.node),
        })
    }

    /// The text of element `e`'s `variable` (contacts, coils) or `expression` (variables).
    pub(super) fn expression(&self, e: ElemId) -> R<String> {
        self.g.expression(&self.place, e)
    }

    /// The power into input pin `k` of `e`: the OR of its connections.
    pub(super) fn input(&mut self, e: ElemId, k: usize) -> R<Path> {
        let el = self.g.get(e);
        let sources: Vec<Source> = el
            .inputs
            .get(k)
            .map(|p| p.sources.clone())
            .unwrap_or_default();
        match sources.len() {
            0 => Err(error(
                origin(el.inputs.get(k).map_or(el.node, |p| p.node)),
                &self.at(e),
                format!(
                    "{} localId {} is not connected on its left (an element without power does nothing; remove it or wire it)",
                    el.tag, el.local_id
                ),
            )),
            1 => self.out(sources[0].elem, sources[0].pin),
            _ => self.join(e, &sources),
        }
    }

    /// Several sources into one pin: their common prefix, then an `or` of the rest.
    fn join(&mut self, e: ElemId, sources: &[Source]) -> R<Path> {
        let mut paths = Vec::with_capacity(sources.len());
        for s in sources {
            paths.push(self.out(s.elem, s.pin)?);
        }
        // Bounded by the shortest path: two equal paths agree on every index.
        let shortest = paths.iter().map(Vec::len).min().unwrap_or(0);
        let common = (0..shortest)
            .take_while(|&i| {
                paths
                    .iter()
                    .all(|p| p.get(i).map(|x| &x.key) == paths[0].get(i).map(|x| &x.key))
            })
            .count();
        let mut branches: Vec<Series<'static>> = Vec::with_capacity(paths.len());
        for (p, s) in paths.iter().zip(sources) {
            let rest = &p[common..];
            if rest.is_empty() {
                return Err(self.not_sp(e, sources, "one of its connections is the same power as the others up to this point, so the parallel branch would be TRUE and its contacts never matter"));
            }
            if let Some(bad) = rest.iter().find(|x| !x.element.kind.is_condition()) {
                let what = match &bad.key {
                    Key::Elem(b) => format!("localId {}", self.g.get(*b).local_id),
                    Key::Or(_) | Key::Pin(..) | Key::Feed(..) => "an element".into(),
                };
                let _ = s;
                return Err(self.not_sp(e, sources, &format!("the parallel branch through {what} holds an output or a block, which a parallel (OR) branch cannot")));
            }
            branches.push(rest.iter().map(|x| x.element.clone()).collect());
        }
        let inner = branches
            .iter()
            .flatten()
            .map(|x| or_nesting(&x.kind))
            .max()
            .unwrap_or(0);
        if inner >= MAX_OR_NESTING {
            return Err(error(
                origin(self.g.get(e).node),
                &self.at(e),
                format!(
                    "the parallel (OR) branches into localId {} are nested more than {MAX_OR_NESTING} deep (the most the JSON program format holds; docs/plcopen.md)",
                    self.g.get(e).local_id
                ),
            ));
        }
        let mut keys: Vec<ElemId> = sources.iter().map(|s| s.elem).collect();
        keys.sort_unstable();
        let mut out: Path = paths.swap_remove(0);
        out.truncate(common);
        out.push(Item {
            key: Key::Or(keys),
            element: Element {
                origin: sources.first().map_or(Origin::NONE, |s| s.origin),
                kind: ElementKind::Or(branches),
            },
        });
        Ok(out)
    }

    fn not_sp(&self, e: ElemId, sources: &[Source], why: &str) -> plc_diag::LoadError {
        let ids: Vec<String> = sources
            .iter()
            .map(|s| self.g.get(s.elem).local_id.to_string())
            .collect();
        error(
            origin(self.g.get(e).node),
            &self.at(e),
            format!(
                "the wiring into localId {} from localIds {} is not series-parallel: {why}",
                self.g.get(e).local_id,
                ids.join(", ")
            ),
        )
    }
}
