//! FBD bodies (TC6 `FBD`) → the syntax's FBD body ([`crate::syntax::fbd`]), so that order,
//! fragments and lowering are the JSON format's (docs/fbd.md).
//!
//! Mapping: a `block` is a block with id = its localId, op = its `typeName`, its instance, its
//! inputs by pin name and its outputs by pin name; `EN` is the conditional arc (`cond`). An
//! input fed by a block is a data arc (`formalParameter` names the output pin; none: the first
//! output), by an `inVariable` a variable or a constant, by an `inOutVariable` its variable (so
//! a feedback loop closes through the variable, as Beremiz closes it). An `outVariable` or
//! `inOutVariable` fed by a block output is a variable that output writes; fed directly by a
//! variable it is a MOVE block with the out variable's localId. `jump` and `return` are JMP and
//! RET blocks whose condition is their input. A `label` starts a new network (networks
//! `<pou>.N1`, `<pou>.N2` … in file order; one network without labels is `<pou>`).
//! `connector`/`continuation` pairs are spliced by [`super::wiring`]; the text of the
//! `comment`s of a network, in file order, is its comment.
//!
//! Order: the FBD text-generation paper's depth-first topological sort over the arcs, ties by
//! localId (docs/fbd.md). Beremiz instead pulls blocks on demand from the out variables in file
//! order, and runs the blocks with `executionOrderId > 0` first in id order; where a body
//! carries such ids, a note lists them (`plc-deps order` shows the order plc-deps uses).
//!
//! Deliberately not here (errors naming the element): negated or edge-qualified pins, several
//! wires into one FBD pin, ENO wired on, expressions as in/out variables.

use super::interface::literal;
use super::wiring::{graph, ElemId, Graph, Source};
use super::xml::{attr, error, identifier, origin, variable_ref, ExecOrder, Notes, Tc6, R};
use crate::syntax::fbd::{Block, Connection, Input, Inputs, Network, OutVar, Outputs, Targets};
use crate::syntax::FbdBody;
use roxmltree::Node;
use std::borrow::Cow;

const FBD_TAGS: &[&str] = &[
    "block",
    "inVariable",
    "outVariable",
    "inOutVariable",
    "connector",
    "continuation",
    "jump",
    "label",
    "return",
    "comment",
];

/// Reads FBD body `node` of POU `pou`.
pub fn body(tc6: Tc6, node: Node, pou: &str, notes: &mut Notes) -> R<FbdBody<'static>> {
    let place = format!("pou {pou}, FBD");
    let g = graph(tc6, node, &place)?;
    g.only(FBD_TAGS, "FBD", &place)?;
    let mut ordered = Vec::new();
    for el in &g.elems {
        if let Some(x) = el
            .node
            .attribute("executionOrderId")
            .and_then(|x| x.trim().parse::<u32>().ok())
        {
            if x > 0 {
                ordered.push((x, el.local_id));
            }
        }
    }
    ordered.sort_unstable();
    let f = Fbd { g: &g, place };
    let mut networks: Vec<Network<'static>> = Vec::new();
    let mut current: Vec<Block<'static>> = Vec::new();
    let mut label: Option<(String, Node)> = None;
    let mut labels = 0;
    let mut comments: Vec<String> = Vec::new();
    for (i, el) in g.elems.iter().enumerate() {
        let e = ElemId(i as u32);
        match el.tag {
            "label" => {
                let here = g.place(&f.place, e);
                let l = identifier(attr(el.node, "label", &here)?, "label", el.node, &here)?;
                if !current.is_empty() || label.is_some() {
                    let k = networks.len();
                    networks.push(network(
                        pou,
                        k,
                        label.take(),
                        std::mem::take(&mut current),
                        std::mem::take(&mut comments),
                    ));
                }
                labels += 1;
                label = Some((l, el.node));
            }
            "comment" => {
                let t: String = el
                    .node
                    .descendants()
                    .filter(|d| d.is_text())
                    .filter_map(|d| d.text())
                    .collect();
                if !t.trim().is_empty() {
                    comments.push(t.trim().to_owned());
                }
            }
            "block" => current.push(f.block(e)?),
            "jump" | "return" => current.push(f.control(e)?),
            "outVariable" | "inOutVariable" => {
                if let Some(b) = f.variable_move(e)? {
                    current.push(b);
                }
            }
            _ => {}
        }
    }
    let k = networks.len();
    networks.push(network(pou, k, label, current, comments));
    if labels == 0 {
        if let Some(n) = networks.first_mut() {
            n.id = Ok(Cow::Owned(pou.to_owned()));
        }
    }
    if !ordered.is_empty() {
        notes.exec_orders.push(ExecOrder {
            networks: networks
                .iter()
                .filter_map(|n| n.id.as_ref().ok().map(|i| i.to_string()))
                .collect(),
            origin: origin(node),
            ids: ordered,
        });
    }
    Ok(FbdBody {
        origin: origin(node),
        comment: None,
        networks,
        problem: None,
    })
}

fn network(
    pou: &str,
    k: usize,
    label: Option<(String, Node)>,
    blocks: Vec<Block<'static>>,
    comments: Vec<String>,
) -> Network<'static> {
    let at = label
        .as_ref()
        .map_or(crate::diag::Origin::NONE, |(_, n)| origin(*n));
    Network {
        origin: at,
        id: Ok(Cow::Owned(format!("{pou}.N{}", k + 1))),
        label: label.map(|(l, _)| Ok(Cow::Owned(l))),
        comment: (!comments.is_empty()).then(|| Ok(Cow::Owned(comments.join("\n")))),
        blocks: Ok(blocks),
        problem: None,
    }
}

struct Fbd<'g, 'a, 'i> {
    g: &'g Graph<'a, 'i>,
    place: String,
}

impl Fbd<'_, '_, '_> {
    fn at(&self, e: ElemId) -> String {
        self.g.place(&self.place, e)
    }

    fn new_block(&self, e: ElemId, op: &str) -> Block<'static> {
        let el = self.g.get(e);
        Block {
            origin: origin(el.node),
            id: Ok(el.local_id),
            op: Ok(Cow::Owned(op.to_owned())),
            inputs: None,
            outputs: None,
            instance: None,
            label: None,
            cond: None,
            after: None,
            comment: None,
            problem: None,
        }
    }

    fn block(&self, e: ElemId) -> R<Block<'static>> {
        let el = self.g.get(e);
        let here = self.at(e);
        let ty = attr(el.node, "typeName", &here)?;
        let mut b = self.new_block(e, ty);
        if let Some(inst) = el.node.attribute("instanceName") {
            b.instance = Some(Ok(Cow::Owned(identifier(
                inst, "instance", el.node, &here,
            )?)));
        }
        let mut inputs = Vec::new();
        for pin in &el.inputs {
            let name = pin.name.unwrap_or("");
            for a in ["negated", "edge", "storage"] {
                if matches!(pin.node.attribute(a), Some(v) if v != "false" && v != "none") {
                    return Err(error(
                        origin(pin.node),
                        &here,
                        format!("input {name} of {ty} (localId {}) is {a}: qualified pins are not supported yet", el.local_id),
                    ));
                }
            }
            let input = match pin.sources.as_slice() {
                [] => continue,
                [s] => self.input(e, s)?,
                _ => {
                    return Err(error(
                        origin(pin.node),
                        &here,
                        format!("input {name} of {ty} (localId {}) has {} connections; an FBD pin takes one", el.local_id, pin.sources.len()),
                    ))
                }
            };
            if name == "EN" {
                b.cond = Some(input);
            } else {
                inputs.push((Cow::Owned(name.to_owned()), input));
            }
        }
        b.inputs = Some(Ok(Inputs::Named(inputs)));
        let mut outputs = Vec::new();
        for (pin, pnode) in &el.outputs {
            if matches!(pnode.attribute("negated"), Some("true" | "1")) {
                return Err(error(
                    origin(*pnode),
                    &here,
                    format!("output {pin} of {ty} (localId {}) is negated: qualified pins are not supported yet", el.local_id),
                ));
            }
            let targets = self.targets(e, pin, el.outputs.first().map(|o| o.0) == Some(*pin))?;
            if *pin == "ENO" && !targets.is_empty() {
                return Err(error(
                    origin(*pnode),
                    &here,
                    format!(
                        "ENO of {ty} (localId {}) is wired: ENO is not supported in FBD yet",
                        el.local_id
                    ),
                ));
            }
            if !targets.is_empty() {
                outputs.push((
                    Cow::Owned(pin.to_string()),
                    Ok(Targets::Many(targets.into_iter().map(Ok).collect())),
                ));
            }
        }
        if !outputs.is_empty() {
            b.outputs = Some(Ok(Outputs::Named(outputs)));
        }
        Ok(b)
    }

    /// The out and in-out variables output `pin` of block `e` writes (`first`: the block's first
    /// output, which a connection without `formalParameter` means).
    fn targets(&self, e: ElemId, pin: &str, first: bool) -> R<Vec<OutVar<'static>>> {
        let mut out = Vec::new();
        for &(c, _, p) in &self.g.consumers[e.0 as usize] {
            let cel = self.g.get(c);
            let this = match p {
                Some(p) => p == pin,
                None => first,
            };
            if this && matches!(cel.tag, "outVariable" | "inOutVariable") {
                out.push(OutVar {
                    origin: origin(cel.node),
                    name: Cow::Owned(self.var_name(c)?),
                });
            }
        }
        Ok(out)
    }

    fn var_name(&self, e: ElemId) -> R<String> {
        let el = self.g.get(e);
        let text = el
            .node
            .children()
            .find(|c| c.is_element() && c.tag_name().name() == "expression")
            .and_then(|c| c.text())
            .ok_or_else(|| {
                error(
                    origin(el.node),
                    &self.at(e),
                    format!("the {} has no expression", el.tag),
                )
            })?;
        variable_ref(text, el.node, &self.at(e))
    }

    /// What source `s` gives to an input of block `consumer`.
    fn input(&self, consumer: ElemId, s: &Source) -> R<Input<'static>> {
        let src = self.g.get(s.elem);
        let from = match src.tag {
            "block" => Connection::Arc {
                block: src.local_id,
                pin: s.pin.map(|p| Ok(Cow::Owned(p.to_owned()))),
            },
            "inVariable" | "inOutVariable" => {
                let text = src
                    .node
                    .children()
                    .find(|c| c.is_element() && c.tag_name().name() == "expression")
                    .and_then(|c| c.text())
                    .unwrap_or("");
                match literal(text) {
                    Some(v) => Connection::Constant(v),
                    None => Connection::Variable(Cow::Owned(variable_ref(
                        text,
                        src.node,
                        &self.at(s.elem),
                    )?)),
                }
            }
            other => {
                return Err(error(
                    s.origin,
                    &self.at(consumer),
                    format!(
                        "a {other} (localId {}) cannot feed an input in FBD",
                        src.local_id
                    ),
                ))
            }
        };
        Ok(Input {
            origin: s.origin,
            from,
        })
    }

    /// JMP and RET blocks.
    fn control(&self, e: ElemId) -> R<Block<'static>> {
        let el = self.g.get(e);
        let here = self.at(e);
        let mut b = self.new_block(e, if el.tag == "jump" { "JMP" } else { "RET" });
        if el.tag == "jump" {
            let l = identifier(attr(el.node, "label", &here)?, "label", el.node, &here)?;
            b.label = Some(Ok(Cow::Owned(l)));
        }
        match el.inputs.first().map(|p| p.sources.as_slice()) {
            Some([s]) => b.cond = Some(self.input(e, s)?),
            Some([]) | None => {}
            Some(more) => {
                return Err(error(
                    origin(el.node),
                    &here,
                    format!(
                        "the {} has {} connections; it takes one",
                        el.tag,
                        more.len()
                    ),
                ))
            }
        }
        Ok(b)
    }

    /// An out or in-out variable fed directly by a variable: a MOVE block (a variable fed by a
    /// block is one of that block's outputs, `None` here).
    fn variable_move(&self, e: ElemId) -> R<Option<Block<'static>>> {
        let el = self.g.get(e);
        let here = self.at(e);
        let sources = el
            .inputs
            .first()
            .map(|p| p.sources.as_slice())
            .unwrap_or(&[]);
        match sources {
            [] if el.tag == "inOutVariable" => Ok(None),
            [] => Err(error(
                origin(el.node),
                &here,
                format!("outVariable localId {} is not connected", el.local_id),
            )),
            [s] if self.g.get(s.elem).tag == "block" => Ok(None),
            [s] => {
                let mut b = self.new_block(e, "MOVE");
                b.inputs = Some(Ok(Inputs::List(vec![self.input(e, s)?])));
                b.outputs = Some(Ok(Outputs::First(OutVar {
                    origin: origin(el.node),
                    name: Cow::Owned(self.var_name(e)?),
                })));
                Ok(Some(b))
            }
            more => Err(error(
                origin(el.node),
                &here,
                format!(
                    "{} localId {} has {} connections; it takes one",
                    el.tag,
                    el.local_id,
                    more.len()
                ),
            )),
        }
    }
}
