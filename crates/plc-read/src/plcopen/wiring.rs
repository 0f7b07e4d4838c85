//! The wiring graph of a graphical body (LD or FBD, TC6 2.01 `commonObjects`, `ldObjects`,
//! `fbdObjects`): every element with its `localId`, and each of its input pins with the
//! producers its `connectionPointIn/connection@refLocalId` (and `@formalParameter`, the
//! producer's output pin) names.
//!
//! Invariants: localIds are unique in the body and every `refLocalId` names an element of it
//! (else one error naming both); a `continuation` is replaced, in every pin that reads it, by
//! what feeds its `connector` of the same name (exactly one connector per continuation, and
//! every connector read by a continuation). Several connections into one pin stay several
//! sources: their OR in LD, an error in FBD (the caller decides); the same producer pin listed
//! twice in one pin (directly or through a continuation) is read once, with a note (Beremiz
//! ORs that power with itself, which is that power). Elements keep file order.
//!
//! Deliberately not here: what the elements mean (`super::ld`, `super::fbd`).

use super::xml::{attr, error, origin, Note, Notes, Tc6, R};
use plc_diag::Origin;
use roxmltree::Node;
use std::collections::{HashMap, HashSet};

/// Index of an element of a body, in file order.
#[derive(Copy, Clone, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub(super) struct ElemId(pub u32);

/// One element of the body.
pub(super) struct Elem<'a, 'i> {
    pub node: Node<'a, 'i>,
    pub local_id: u32,
    /// Its tag (`contact`, `block`, `inVariable` …).
    pub tag: &'a str,
    /// Its input pins, in file order (one unnamed pin for contacts, coils, out variables …).
    pub inputs: Vec<Pin<'a, 'i>>,
    /// A block's output pins (`formalParameter`s with their variable nodes), in file order.
    pub outputs: Vec<(&'a str, Node<'a, 'i>)>,
}

/// An input pin and what feeds it.
pub(super) struct Pin<'a, 'i> {
    /// `formalParameter` of a block's pin; `None` for the single input of other elements.
    pub name: Option<&'a str>,
    /// The pin's `variable` node (blocks) or the element itself.
    pub node: Node<'a, 'i>,
    pub sources: Vec<Source<'a>>,
}

/// A producer feeding a pin.
#[derive(Clone, Debug)]
pub(super) struct Source<'a> {
    pub elem: ElemId,
    /// The producer's output pin (`formalParameter`), if named.
    pub pin: Option<&'a str>,
    /// Where the connection is written.
    pub origin: Origin,
}

/// A body's elements.
pub(super) struct Graph<'a, 'i> {
    pub elems: Vec<Elem<'a, 'i>>,
    /// For each element, who reads it: (consumer, consumer's input pin index, producer's pin).
    pub consumers: Vec<Vec<(ElemId, usize, Option<&'a str>)>>,
}

impl<'a, 'i> Graph<'a, 'i> {
    pub(super) fn get(&self, e: ElemId) -> &Elem<'a, 'i> {
        &self.elems[e.0 as usize]
    }

    /// `pou P, LD, contact localId 5`.
    pub(super) fn place(&self, body: &str, e: ElemId) -> String {
        let el = self.get(e);
        format!("{body}, {} localId {}", el.tag, el.local_id)
    }

    /// The text of element `e`'s `variable` (contacts, coils) or `expression` (variables); `body`
    /// names the body in errors.
    pub(super) fn expression(&self, body: &str, e: ElemId) -> R<String> {
        let el = self.get(e);
        let tag = if matches!(el.tag, "contact" | "coil") {
            "variable"
        } else {
            "expression"
        };
        el.node
            .children()
            .find(|c| c.is_element() && c.tag_name().name() == tag)
            .and_then(|c| c.text())
            .map(str::to_owned)
            .ok_or_else(|| {
                error(
                    origin(el.node),
                    &self.place(body, e),
                    format!("the {} has no `{tag}`", el.tag),
                )
            })
    }

    /// An error at the first element whose tag is not one of `tags`, the elements a
    /// `language` body (`LD`, `FBD`) may hold; `body` names the body in errors.
    pub(super) fn only(&self, tags: &[&str], language: &str, body: &str) -> R<()> {
        match self.elems.iter().position(|el| !tags.contains(&el.tag)) {
            None => Ok(()),
            Some(i) => {
                let el = &self.elems[i];
                Err(error(
                    origin(el.node),
                    &self.place(body, ElemId(i as u32)),
                    format!(
                        "`{}` is not an element of an {language} body that plc-deps reads",
                        el.tag
                    ),
                ))
            }
        }
    }
}

/// Elements that are not wired: read by their callers directly (labels, comments).
const UNWIRED: &[&str] = &["label", "comment", "leftPowerRail"];

/// Reads the elements of `body` (an `LD` or `FBD` node); `place` names the body in errors and
/// notes.
pub(super) fn graph<'a, 'i>(
    tc6: Tc6,
    body: Node<'a, 'i>,
    place: &str,
    notes: &mut Notes,
) -> R<Graph<'a, 'i>> {
    let doc = body.document();
    let nodes = body_elements(tc6, body, place, notes)?;
    let ids = LocalIds::of(&nodes, body, place, notes);
    let mut elems: Vec<Elem> = Vec::new();
    let mut by_id: HashMap<u32, ElemId> = HashMap::new();
    for n in nodes {
        let tag = n.tag_name().name();
        let here = format!("{place}, {tag}");
        let raw = attr(n, "localId", &here)?;
        let local_id: u32 = ids.id(raw).ok_or_else(|| {
            error(
                origin(n),
                &here,
                format!("localId `{raw}` is not a whole number"),
            )
        })?;
        let id = ElemId(elems.len() as u32);
        if let Some(first) = by_id.insert(local_id, id) {
            let p = doc.text_pos_at(elems[first.0 as usize].node.range().start);
            return Err(error(
                origin(n),
                &here,
                format!(
                    "localId {local_id} is used twice in this body (first at line {}, column {})",
                    p.row, p.col
                ),
            ));
        }
        let mut el = Elem {
            node: n,
            local_id,
            tag,
            inputs: Vec::new(),
            outputs: Vec::new(),
        };
        if tag == "block" {
            block_pins(tc6, &mut el, &here, &ids)?;
        } else if !UNWIRED.contains(&tag) {
            for cp in tc6.children(n, "connectionPointIn") {
                el.inputs.push(Pin {
                    name: None,
                    node: n,
                    sources: connections(tc6, cp, &here, &ids)?,
                });
            }
        }
        elems.push(el);
    }
    let mut g = Graph {
        elems,
        consumers: Vec::new(),
    };
    resolve_refs(&mut g, &by_id, place)?;
    splice_continuations(tc6, &mut g, place)?;
    drop_repeated_sources(&mut g, place, notes);
    let mut consumers = vec![Vec::new(); g.elems.len()];
    for (i, el) in g.elems.iter().enumerate() {
        for (k, pin) in el.inputs.iter().enumerate() {
            for s in &pin.sources {
                consumers[s.elem.0 as usize].push((ElemId(i as u32), k, s.pin));
            }
        }
    }
    g.consumers = consumers;
    Ok(g)
}

/// The localIds of a body as the reader numbers them: TC6 allows any `xsd:unsignedLong` and
/// CODESYS writes ids up to 2^64 - 1, the model's blocks are numbered in 32 bits. An id that
/// fits is itself; the others are renumbered down from 2^32 - 1 (skipping the ids in use), in
/// file order, and one note gives the mapping.
struct LocalIds {
    big: HashMap<u64, u32>,
}

impl LocalIds {
    fn of(nodes: &[Node], body: Node, place: &str, notes: &mut Notes) -> LocalIds {
        let raw: Vec<u64> = nodes
            .iter()
            .filter_map(|n| n.attribute("localId"))
            .filter_map(|r| r.trim().parse::<u64>().ok())
            .collect();
        let mut big = HashMap::new();
        if raw.iter().all(|&x| x <= u32::MAX as u64) {
            return LocalIds { big };
        }
        let used: std::collections::HashSet<u64> = raw.iter().copied().collect();
        let mut next = u32::MAX;
        let mut shown = Vec::new();
        for &x in raw.iter().filter(|&&x| x > u32::MAX as u64) {
            if big.contains_key(&x) {
                continue;
            }
            while used.contains(&(next as u64)) {
                next -= 1;
            }
            big.insert(x, next);
            shown.push(format!("{x} → {next}"));
            next -= 1;
        }
        let at = nodes
            .iter()
            .copied()
            .find(|n| {
                n.attribute("localId")
                    .and_then(|r| r.trim().parse::<u64>().ok())
                    .is_some_and(|x| x > u32::MAX as u64)
            })
            .map_or_else(|| origin(body), origin);
        notes.push(super::xml::Note {
            origin: at,
            message: format!("{place}: localIds beyond 4294967295 are renumbered (the model numbers blocks in 32 bits), and messages name them so: {}", shown.join(", ")),
        });
        LocalIds { big }
    }

    /// The reader's number of localId `raw`; `None` when it is not a whole number (or a big
    /// one no element has).
    fn id(&self, raw: &str) -> Option<u32> {
        let x: u64 = raw.trim().parse().ok()?;
        u32::try_from(x).ok().or_else(|| self.big.get(&x).copied())
    }
}

/// The elements of a graphical body that take part in it, in file order: its TC6 children but
/// `addData` and `documentation`; a `vendorElement` (TC6's element for what an editor adds,
/// CODESYS writes one holding its FBD implementation attributes) stands for the standard
/// elements it holds, if any, with a note; else, when nothing connects to it and it has no
/// connection points (it cannot take part in the data flow), it is skipped with a note naming
/// its localId. One that is wired is an error: what it computes cannot be told.
fn body_elements<'a, 'i>(
    tc6: Tc6,
    body: Node<'a, 'i>,
    place: &str,
    notes: &mut Notes,
) -> R<Vec<Node<'a, 'i>>> {
    const STANDARD: &[&str] = &[
        "block",
        "inVariable",
        "outVariable",
        "inOutVariable",
        "label",
        "jump",
        "return",
        "comment",
        "error",
        "connector",
        "continuation",
        "actionBlock",
        "leftPowerRail",
        "rightPowerRail",
        "contact",
        "coil",
    ];
    let mut out = Vec::new();
    for n in tc6.elements(body) {
        let tag = n.tag_name().name();
        if tag == "addData" || tag == "documentation" {
            continue;
        }
        if tag != "vendorElement" {
            out.push(n);
            continue;
        }
        let id = n.attribute("localId").unwrap_or("?");
        let what = n
            .descendants()
            .find(|d| d.tag_name().name() == "alternativeText")
            .and_then(|a| a.descendants().find_map(|t| t.text()))
            .map(|t| format!(" (`{}`)", t.trim()))
            .unwrap_or_default();
        let inner: Vec<Node> = tc6
            .elements(n)
            .filter(|c| STANDARD.contains(&c.tag_name().name()))
            .collect();
        if !inner.is_empty() {
            notes.push(Note {
                origin: origin(n),
                message: format!("{place}: vendorElement localId {id}{what} is read as the standard elements it holds ({})", inner.iter().map(|c| c.tag_name().name()).collect::<Vec<_>>().join(", ")),
            });
            out.extend(inner);
            continue;
        }
        let wired = n.descendants().any(|d| {
            matches!(
                d.tag_name().name(),
                "connectionPointIn" | "connectionPointOut" | "connectionPointOutAction"
            )
        }) || body.descendants().any(|d| {
            tc6.is(d, "connection") && d.attribute("refLocalId").map(str::trim) == Some(id.trim())
        });
        if wired {
            return Err(error(
                origin(n),
                &format!("{place}, vendorElement localId {id}"),
                format!("vendorElement localId {id}{what} is wired into the body, and what an editor's own element computes cannot be told: redraw it with standard blocks"),
            ));
        }
        notes.push(Note {
            origin: origin(n),
            message: format!("{place}: vendorElement localId {id}{what} is skipped: it holds no standard element and nothing is wired to it, so it takes no part in what the body computes"),
        });
    }
    Ok(out)
}

fn block_pins<'a, 'i>(tc6: Tc6, el: &mut Elem<'a, 'i>, place: &str, ids: &LocalIds) -> R<()> {
    let n = el.node;
    for list in ["inputVariables", "inOutVariables"] {
        for l in tc6.children(n, list) {
            for v in tc6.children(l, "variable") {
                let name = attr(v, "formalParameter", place)?;
                if list == "inOutVariables" {
                    // matiec passes a VAR_IN_OUT by reference: what the block writes into it
                    // goes back to the wired variable, which the model has no arc for.
                    return Err(error(
                        origin(v),
                        place,
                        format!("block localId {} passes `{name}` to a VAR_IN_OUT, which is not supported yet (a POU's own in-out variables are: they are read as inputs when no call wires them)", el.local_id),
                    ));
                }
                let sources = match tc6.child(v, "connectionPointIn") {
                    Some(cp) => connections(tc6, cp, place, ids)?,
                    None => Vec::new(),
                };
                el.inputs.push(Pin {
                    name: Some(name),
                    node: v,
                    sources,
                });
            }
        }
    }
    for l in tc6.children(n, "outputVariables") {
        for v in tc6.children(l, "variable") {
            el.outputs.push((attr(v, "formalParameter", place)?, v));
        }
    }
    Ok(())
}

/// The connections of one `connectionPointIn` (its `refLocalId`s still raw: `elem` is the
/// localId until [`resolve_refs`]).
fn connections<'a>(tc6: Tc6, cp: Node<'a, '_>, place: &str, ids: &LocalIds) -> R<Vec<Source<'a>>> {
    if let Some(e) = tc6.child(cp, "expression") {
        return Err(error(
            origin(e),
            place,
            "an expression in place of connections (connectionPointIn/expression) is not supported",
        ));
    }
    let mut out = Vec::new();
    for c in tc6.children(cp, "connection") {
        let raw = attr(c, "refLocalId", place)?;
        let id: u32 = match ids.id(raw) {
            Some(id) => id,
            None if raw.trim().parse::<u64>().is_ok() => {
                return Err(error(
                    origin(c),
                    place,
                    format!(
                        "the connection refers to localId {}, which is not an element of this body",
                        raw.trim()
                    ),
                ))
            }
            None => {
                return Err(error(
                    origin(c),
                    place,
                    format!("refLocalId `{raw}` is not a whole number"),
                ))
            }
        };
        out.push(Source {
            elem: ElemId(id),
            pin: c.attribute("formalParameter").filter(|p| !p.is_empty()),
            origin: origin(c),
        });
    }
    Ok(out)
}

/// Keeps the first of several connections of one pin to the same producer pin, with a note at
/// each one dropped: reading a power or value twice into one pin is reading it once (Beremiz's
/// `FactorizePaths` makes `A OR A` of it), and the LD join wants distinct branches.
fn drop_repeated_sources(g: &mut Graph, place: &str, notes: &mut Notes) {
    let local_ids: Vec<u32> = g.elems.iter().map(|el| el.local_id).collect();
    for el in &mut g.elems {
        for pin in &mut el.inputs {
            if pin.sources.len() < 2 {
                continue;
            }
            let mut seen = HashSet::new();
            pin.sources.retain(|s| {
                if seen.insert((s.elem, s.pin)) {
                    return true;
                }
                let what = match pin.name {
                    Some(p) => format!("input {p} of {} localId {}", el.tag, el.local_id),
                    None => format!("the input of {} localId {}", el.tag, el.local_id),
                };
                let from = match s.pin {
                    Some(p) => format!("output {p} of localId {}", local_ids[s.elem.0 as usize]),
                    None => format!("localId {}", local_ids[s.elem.0 as usize]),
                };
                notes.push(Note {
                    origin: s.origin,
                    message: format!("{place}: {what} is connected to {from} more than once; it is read once (as Beremiz ORs a power with itself)"),
                });
                false
            });
        }
    }
}

fn resolve_refs(g: &mut Graph, by_id: &HashMap<u32, ElemId>, place: &str) -> R<()> {
    for el in &mut g.elems {
        for pin in &mut el.inputs {
            for s in &mut pin.sources {
                match by_id.get(&s.elem.0) {
                    Some(&e) => s.elem = e,
                    None => {
                        return Err(error(
                            s.origin,
                            &format!("{place}, {} localId {}", el.tag, el.local_id),
                            format!(
                                "the connection refers to localId {}, which is not an element of this body",
                                s.elem.0
                            ),
                        ))
                    }
                }
            }
        }
    }
    Ok(())
}

/// Replaces every source that is a `continuation` by the sources of its `connector`.
fn splice_continuations(tc6: Tc6, g: &mut Graph, place: &str) -> R<()> {
    let mut connectors: HashMap<&str, ElemId> = HashMap::new();
    for (i, el) in g.elems.iter().enumerate() {
        if el.tag == "connector" {
            let name = attr(el.node, "name", place)?;
            if connectors.insert(name, ElemId(i as u32)).is_some() {
                return Err(error(
                    origin(el.node),
                    &g.place(place, ElemId(i as u32)),
                    format!("more than one connector is named `{name}`"),
                ));
            }
        }
    }
    let mut feeds: HashMap<ElemId, Vec<Source>> = HashMap::new();
    let mut used: Vec<bool> = vec![false; g.elems.len()];
    for (i, el) in g.elems.iter().enumerate() {
        if el.tag != "continuation" {
            continue;
        }
        let name = attr(el.node, "name", place)?;
        let Some(&c) = connectors.get(name) else {
            return Err(error(
                origin(el.node),
                &g.place(place, ElemId(i as u32)),
                format!("continuation `{name}` has no connector of that name"),
            ));
        };
        used[c.0 as usize] = true;
        let sources: Vec<Source> = g
            .get(c)
            .inputs
            .iter()
            .flat_map(|p| p.sources.clone())
            .collect();
        if sources.iter().any(|s| g.get(s.elem).tag == "continuation") {
            return Err(error(
                origin(el.node),
                &g.place(place, ElemId(i as u32)),
                format!("connector `{name}` is fed by another continuation (chains of connectors are not supported)"),
            ));
        }
        feeds.insert(ElemId(i as u32), sources);
    }
    for (&name, &c) in &connectors {
        if !used[c.0 as usize] {
            return Err(error(
                origin(g.get(c).node),
                &g.place(place, c),
                format!("connector `{name}` is dangling: no continuation reads it"),
            ));
        }
    }
    let _ = tc6;
    for el in &mut g.elems {
        for pin in &mut el.inputs {
            if pin.sources.iter().any(|s| feeds.contains_key(&s.elem)) {
                let mut out = Vec::with_capacity(pin.sources.len());
                for s in pin.sources.drain(..) {
                    match feeds.get(&s.elem) {
                        Some(f) => out.extend(f.iter().cloned()),
                        None => out.push(s),
                    }
                }
                pin.sources = out;
            }
        }
    }
    Ok(())
}
