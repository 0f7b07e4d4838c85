//! LD bodies that are not series-parallel rungs, read as the boolean data-flow network that
//! Beremiz's generator makes of every LD body (`PLCGenerator.ComputeProgram`/`GeneratePaths`,
//! docs/design/plcopen-semantics.md §1.1): the body becomes an FBD body
//! ([`plc_syntax::fbd`]) whose blocks compute the power flow.
//!
//! [`super::ld`] reads an LD body as rungs of contacts, coils and boxes; a wiring it cannot
//! express that way (a box inside a parallel branch, a block fed by a block, EN on a timer,
//! functions such as SEL or `BOOL_TO_INT` in a rung, an `inOutVariable`) is read here instead,
//! with a note naming what stopped the rung reader. Mapping:
//!
//! - the left rail is TRUE; a contact is `power AND v` (negated: `NOT v`; an edge: an
//!   `R_TRIG`/`F_TRIG` of the variable, on an instance `<KIND>__<localId>` added to the POU);
//!   several wires into one pin are their OR (a wired OR);
//! - a coil, an out variable and the input side of an in-out variable write the power into their
//!   variable (negated coil: `NOT power`; set: `v OR power`; reset: `v AND NOT power`; an edge
//!   coil: the `R_TRIG`/`F_TRIG` of the power); a coil passes its input power on;
//! - a block is an FBD block on its own pins (EN is its condition, an ENO wired on is its EN's
//!   power, or TRUE without EN); a negated input pin reads `NOT` of its wire; a rising edge on CU
//!   or CD of a counter is the plain pin (the counter detects the edge itself);
//! - a jump or return is JMP/RET with the power as its condition.
//!
//! Each connected component of the wiring (a rung) is one network `<pou>.N<k>`, in the order of
//! its first coil, out variable, jump or return in the file (rungs of blocks only last), as
//! [`super::ld`] orders rungs; within a network plc-deps's FBD order applies (docs/fbd.md). The
//! blocks this module adds have ids above every localId of the body.
//!
//! Deliberately not here: labels (an error here: a jump target would need the rung structure),
//! and the ops themselves (the FBD resolver checks them, located at the block).

use super::black_box;
use super::block_types::{BlackBox, Ctx};
use super::ld::components;
use super::pins::{
    add_target, bool_literal, is_const, konst, output_negated, pin_modifiers, pin_of,
    unconnected_default, Added,
};
use super::wiring::{graph, ElemId, Graph, Source};
use super::write_places::{self, Statement};
use super::xml::{attr, error, identifier, origin, variable_ref, Note, Notes, Tc6, R};
use plc_diag::Origin;
use plc_syntax::fbd::{Block, Connection, Input, Inputs, Network, OutVar, Outputs};
use plc_syntax::{FbdBody, Scalar};
use roxmltree::Node;
use std::borrow::Cow;
use std::collections::{HashMap, HashSet};

/// The elements read here: the rung reader's, and in-out variables.
const FLOW_TAGS: &[&str] = &[
    "leftPowerRail",
    "rightPowerRail",
    "contact",
    "coil",
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

/// Reads LD body `node` of POU `pou` as a data-flow network.
pub(super) fn body(
    tc6: Tc6,
    node: Node,
    pou: &str,
    ctx: &Ctx,
    notes: &mut Notes,
) -> R<FbdBody<'static>> {
    let place = format!("pou {pou}, LD");
    let g = graph(tc6, node, &place, notes)?;
    g.only(FLOW_TAGS, "LD", &place)?;
    if let Some(i) = g.elems.iter().position(|el| el.tag == "label") {
        let e = ElemId(i as u32);
        return Err(error(
            origin(g.get(e).node),
            &g.place(&place, e),
            "a label in an LD body read as a data-flow network: jumps need the rung structure"
                .to_owned(),
        ));
    }
    let component = components(&g);
    let mut f = Flow {
        g: &g,
        place,
        a: Added::new(&g).with_elements(&ctx.vars),
        done: HashMap::new(),
        ctx,
        boxes: std::mem::take(&mut notes.black_boxes),
        tracing: HashSet::new(),
        notes: Vec::new(),
        depth: 0,
    };
    // Beremiz's statement order (PLCGenerator.ComputeProgram): coils, out and in-out variables
    // in file order, then the blocks; each block is computed when a statement first reads it.
    // Rungs whose statements interleave in the file are one network, so that this order holds
    // across them; networks in the order of their first statement, rungs of blocks only last.
    let statement = |t: &str| {
        matches!(
            t,
            "coil" | "outVariable" | "inOutVariable" | "jump" | "return"
        )
    };
    let mut span: HashMap<usize, (usize, usize)> = HashMap::new();
    let mut firsts: Vec<usize> = Vec::new();
    for (i, el) in g.elems.iter().enumerate() {
        if statement(el.tag) {
            let s = span.entry(component[i]).or_insert_with(|| {
                firsts.push(component[i]);
                (i, i)
            });
            s.1 = i;
        }
    }
    // The network of each component: components whose spans overlap share one.
    let mut net_of: HashMap<usize, usize> = HashMap::new();
    let mut nets = 0;
    let mut reach = 0;
    for &c in &firsts {
        let (first, last) = span[&c];
        if nets == 0 || first > reach {
            nets += 1;
            reach = last;
        } else {
            reach = reach.max(last);
        }
        net_of.insert(c, nets - 1);
    }
    for (i, el) in g.elems.iter().enumerate() {
        if el.tag == "block" && !net_of.contains_key(&component[i]) {
            nets += 1;
            net_of.insert(component[i], nets - 1);
        }
    }
    let mut networks = Vec::new();
    for n in 0..nets {
        let mut statements: Vec<Statement> = Vec::new();
        for (i, el) in g.elems.iter().enumerate() {
            if net_of.get(&component[i]) != Some(&n) {
                continue;
            }
            let e = ElemId(i as u32);
            match el.tag {
                "coil" | "outVariable" | "inOutVariable" if f.write_out(e)?.is_some() => {
                    statements.push(Statement::Write {
                        at: origin(el.node),
                        local_id: el.local_id,
                    });
                }
                "jump" | "return" => statements.push(Statement::Run(f.control(e)?)),
                _ => {}
            }
        }
        for (i, el) in g.elems.iter().enumerate() {
            if el.tag == "block" && net_of.get(&component[i]) == Some(&n) {
                statements.push(Statement::Run(f.block(ElemId(i as u32))?));
            }
        }
        let mut blocks = std::mem::take(&mut f.a.blocks);
        let t = black_box::Typer { ctx, g: &g };
        let ty = |id: u32, pin: Option<&str>| {
            let e = g.elems.iter().position(|el| el.local_id == id)?;
            t.output(ElemId(e as u32), pin, 0)
        };
        let cut = super::fbd_loops::cut(&mut blocks, &mut f.a, &ty, &f.place);
        notes.list.extend(cut);
        if blocks.is_empty() {
            continue;
        }
        let k = networks.len() + 1;
        super::user_functions::call_pins(&mut blocks);
        let roots = write_places::place_writes(&mut blocks, &statements, &mut f.a, ctx);
        networks.push(Network {
            origin: blocks[0].origin,
            id: Ok(Cow::Owned(format!("{pou}.N{k}"))),
            label: None,
            comment: None,
            blocks: Ok(blocks),
            order: Some(Ok(roots.into_iter().map(Ok).collect())),
            problem: None,
        });
    }
    notes.black_boxes = std::mem::take(&mut f.boxes);
    notes.list.append(&mut f.notes);
    notes
        .ld_vars
        .extend(f.a.vars.drain(..).map(|v| (pou.to_owned(), v)));
    Ok(FbdBody {
        origin: origin(node),
        comment: None,
        networks,
        problem: None,
    })
}

struct Flow<'g, 'a, 'i> {
    g: &'g Graph<'a, 'i>,
    place: String,
    /// The blocks of the network being built, and the instances added to the POU.
    a: Added,
    /// Block elements already emitted: their index in the current network.
    done: HashMap<ElemId, usize>,
    /// What blocks may call, and the types of the names the body sees.
    ctx: &'g Ctx,
    /// The project's black boxes so far ([`super::black_box`]).
    boxes: Vec<BlackBox>,
    /// Contacts, coils and ENOs whose power is being followed (`through`).
    tracing: HashSet<ElemId>,
    /// Warnings for the body (unconnected inputs that take their initial value).
    notes: Vec<Note>,
    /// Calls of [`Flow::value`] open: at most [`super::ld_power::MAX_POWER_DEPTH`], so that a
    /// long wiring is an error, not a stack overflow.
    depth: usize,
}

fn var_input(v: &str, at: Origin) -> Input<'static> {
    Input {
        origin: at,
        from: Connection::Variable(Cow::Owned(v.to_owned())),
    }
}

impl Flow<'_, '_, '_> {
    fn at(&self, e: ElemId) -> String {
        self.g.place(&self.place, e)
    }

    /// The power or value into input pin `k` of element `e` (several wires: their OR; none:
    /// `None`).
    fn pin(&mut self, e: ElemId, k: usize) -> R<Option<Input<'static>>> {
        let sources: Vec<Source> = match self.g.get(e).inputs.get(k) {
            Some(p) => p.sources.clone(),
            None => return Ok(None),
        };
        let mut values: Vec<Input<'static>> = Vec::new();
        for s in &sources {
            let v = self.value(s)?;
            if !values.iter().any(|w| same(w, &v)) {
                values.push(v);
            }
        }
        Ok(match values.len() {
            0 => None,
            1 => values.pop(),
            _ if values.iter().any(|v| is_const(v, true)) => Some(konst(true, sources[0].origin)),
            _ => {
                let at = sources[0].origin;
                let pins: Vec<String> = (1..=values.len()).map(|i| format!("IN{i}")).collect();
                let inputs = pins.iter().map(|p| p.as_str()).zip(values).collect();
                Some(self.a.add("OR", inputs, at))
            }
        })
    }

    /// The power into the single input of element `e` (unconnected: FALSE).
    fn power(&mut self, e: ElemId) -> R<Input<'static>> {
        let at = origin(self.g.get(e).node);
        Ok(self.pin(e, 0)?.unwrap_or_else(|| konst(false, at)))
    }

    /// What output `s.pin` of element `s.elem` gives (at most
    /// [`super::ld_power::MAX_POWER_DEPTH`] elements deep).
    fn value(&mut self, s: &Source) -> R<Input<'static>> {
        let most = super::ld_power::MAX_POWER_DEPTH;
        if self.depth >= most {
            return Err(error(
                s.origin,
                &self.at(s.elem),
                format!("the value into this pin passes more than {most} elements on its way from the left rail (the most plc-deps follows; docs/plcopen.md)"),
            ));
        }
        self.depth += 1;
        let v = self.value_of(s);
        self.depth -= 1;
        v
    }

    fn value_of(&mut self, s: &Source) -> R<Input<'static>> {
        let e = s.elem;
        let el = self.g.get(e);
        let at = s.origin;
        Ok(match el.tag {
            "leftPowerRail" => konst(true, at),
            "inVariable" | "inOutVariable" => {
                let here = self.at(e);
                super::expression::block_input(&mut self.a, el.node, &here, at)?
            }
            "contact" => {
                let lid = el.local_id;
                let p = self.through(e, at, |f| f.power(e))?;
                let v = variable_ref(&self.expression(e)?, el.node, &self.at(e))?;
                let term = match (el.node.attribute("negated"), el.node.attribute("edge")) {
                    (Some("true" | "1"), _) => {
                        let v = var_input(&v, at);
                        self.a.not(v, at)
                    }
                    (_, Some("rising")) => self.a.trigger("rising", var_input(&v, at), lid, at),
                    (_, Some("falling")) => self.a.trigger("falling", var_input(&v, at), lid, at),
                    _ => var_input(&v, at),
                };
                self.a.and(p, term, at)
            }
            "coil" => self.through(e, at, |f| f.power(e))?,
            "block" => {
                if s.pin == Some("ENO") {
                    let en = el.inputs.iter().position(|p| p.name == Some("EN"));
                    return match en {
                        Some(k) => self.through(e, at, |f| {
                            Ok(f.pin(e, k)?.unwrap_or_else(|| konst(false, at)))
                        }),
                        None => Ok(konst(true, at)),
                    };
                }
                let id = self.block(e)?;
                let arc = Input {
                    origin: at,
                    from: Connection::Arc {
                        block: id,
                        pin: s.pin.map(|p| Ok(Cow::Owned(pin_of(p).to_owned()))),
                    },
                };
                if output_negated(&el.outputs, s.pin) {
                    self.a.not(arc, at)
                } else {
                    arc
                }
            }
            other => {
                return Err(error(
                    at,
                    &self.at(e),
                    format!(
                        "a {other} (localId {}) cannot feed power or a value",
                        el.local_id
                    ),
                ))
            }
        })
    }

    /// Runs `follow`, which follows the power into element `e` (a contact, a coil, or a block's
    /// EN for its ENO). A wiring that leads back to `e` before it reaches a rail, a variable or a
    /// block's output has no value to start from: an error naming the element, not an endless
    /// recursion. (A block's outputs are arcs, emitted once: a loop through a block is a
    /// feedback arc, which the FBD order reads as the previous scan's value.)
    fn through<T>(
        &mut self,
        e: ElemId,
        at: Origin,
        follow: impl FnOnce(&mut Self) -> R<T>,
    ) -> R<T> {
        if !self.tracing.insert(e) {
            let el = self.g.get(e);
            return Err(error(
                at,
                &self.at(e),
                format!(
                    "the power into this {} (localId {}) comes back from its own output through contacts and coils only: a loop with no value to start from",
                    el.tag, el.local_id
                ),
            ));
        }
        let out = follow(self);
        self.tracing.remove(&e);
        out
    }

    /// The text of element `e`'s `variable` (contacts, coils) or `expression` (variables).
    fn expression(&self, e: ElemId) -> R<String> {
        self.g.expression(&self.place, e)
    }

    /// Emits block element `e` (once) and returns its id.
    fn block(&mut self, e: ElemId) -> R<u32> {
        let el = self.g.get(e);
        if self.done.contains_key(&e) {
            return Ok(el.local_id);
        }
        let here = self.at(e);
        let ty = attr(el.node, "typeName", &here)?;
        let idx = self.a.blocks.len();
        self.done.insert(e, idx);
        let mut b = Block {
            origin: origin(el.node),
            id: Ok(el.local_id),
            op: Ok(Cow::Owned(ty.to_owned())),
            inputs: None,
            outputs: None,
            instance: None,
            label: None,
            cond: None,
            en: false,
            after: None,
            comment: None,
            problem: None,
        };
        if let Some(inst) = el.node.attribute("instanceName") {
            b.instance = Some(Ok(Cow::Owned(identifier(
                inst, "instance", el.node, &here,
            )?)));
        }
        // A placeholder keeps the block's place (before the blocks its inputs add, which the
        // FBD order puts first anyway by their arcs).
        self.a.blocks.push(b);
        let mut inputs = Vec::new();
        let mut cond = None;
        for k in 0..el.inputs.len() {
            let pin = &el.inputs[k];
            let pname = pin.name.unwrap_or("");
            let pnode = pin.node;
            let mut v = match self.pin(e, k)? {
                Some(v) => v,
                None => match unconnected_default(ty, pname, origin(pnode)) {
                    Some((c, text)) => {
                        self.notes.push(Note {
                            origin: origin(pnode),
                            message: format!("{here}: input {pname} of {ty} (localId {}) is not connected: it takes its type's initial value {text} (IEC 61131-3 2.5.2.1)", el.local_id),
                        });
                        c
                    }
                    None => continue,
                },
            };
            let at = origin(pnode);
            let (negated, edge) = pin_modifiers(pnode, ty, pname, el.local_id, &here)?;
            let counter_edge = matches!(ty, "CTU" | "CTD" | "CTUD") && matches!(pname, "CU" | "CD");
            match edge {
                Some(edge) if !(counter_edge && edge == "rising") => {
                    v = self.a.trigger(edge, v, el.local_id, at)
                }
                _ => {}
            }
            if negated {
                v = self.a.not(v, at);
            }
            let v = bool_literal(self.ctx, ty, pname, v);
            if pname == "EN" {
                cond = Some(v);
            } else {
                inputs.push((Cow::Owned(pname.to_owned()), v));
            }
        }
        let net = &mut self.a.blocks;
        net[idx].inputs = Some(Ok(Inputs::Named(inputs)));
        net[idx].en = cond.is_some();
        net[idx].cond = cond;
        let mut b = std::mem::replace(&mut self.a.blocks[idx], placeholder());
        let t = black_box::Typer {
            ctx: self.ctx,
            g: self.g,
        };
        self.a
            .compare(&mut b, el.inputs.len(), &|i: &Input| t.input(i, 0));
        self.a.blocks[idx] = b;
        let t = black_box::Typer {
            ctx: self.ctx,
            g: self.g,
        };
        if !black_box::is_known(self.ctx, ty)
            || black_box::mixed_arithmetic(&t, ty, &self.a.blocks[idx])
        {
            let b = &mut self.a.blocks[idx];
            if let Some((inst, bt)) = black_box::rewrite(&t, e, b, &mut self.boxes, &here)? {
                let at = b.origin;
                self.a.declare(&inst, &bt, at);
            }
        }
        Ok(el.local_id)
    }

    /// Writes `v` into variable `var` (at `at`): as a target of the block whose output `v` is,
    /// else by a MOVE.
    fn write(&mut self, var: String, v: Input<'static>, at: Origin) -> u32 {
        let target = OutVar {
            origin: at,
            name: Cow::Owned(var),
        };
        if let Connection::Arc { block, pin } = &v.from {
            let pin = pin_name(pin)
                .map(str::to_owned)
                .or_else(|| self.first_output(*block));
            let block = *block;
            if let Some(b) = self
                .a
                .blocks
                .iter_mut()
                .find(|b| b.id.as_ref().ok() == Some(&block))
            {
                add_target(b, pin.unwrap_or_else(|| "OUT".to_owned()), target);
                return block;
            }
        }
        let id = self.a.next_id;
        let _ = self.a.add_on("MOVE", None, Inputs::List(vec![v]), at);
        if let Some(b) = self.a.blocks.last_mut() {
            b.outputs = Some(Ok(Outputs::First(target)));
        }
        id
    }

    /// The first output pin of the block with id `id`, when it is an element of the body.
    fn first_output(&self, id: u32) -> Option<String> {
        let el = self
            .g
            .elems
            .iter()
            .find(|el| el.local_id == id && el.tag == "block")?;
        el.outputs
            .iter()
            .map(|(p, _)| *p)
            .find(|p| *p != "ENO")
            .map(str::to_owned)
    }

    /// A coil, an out variable or the input side of an in-out variable: the id of the block
    /// that writes its variable.
    fn write_out(&mut self, e: ElemId) -> R<Option<u32>> {
        let el = self.g.get(e);
        if el.inputs.first().is_none_or(|p| p.sources.is_empty()) {
            return Ok(None); // Beremiz skips an unconnected coil or variable.
        }
        let at = origin(el.node);
        let here = self.at(e);
        let var = variable_ref(&self.expression(e)?, el.node, &here)?;
        let p = self.power(e)?;
        if el.tag != "coil" {
            return Ok(Some(self.write(var, p, at)));
        }
        let flag = |a: &str| el.node.attribute(a);
        let v = match (flag("negated"), flag("storage"), flag("edge")) {
            (Some("true" | "1"), _, _) => self.a.not(p, at),
            (_, Some("set"), _) => {
                self.a
                    .add("OR", vec![("IN1", var_input(&var, at)), ("IN2", p)], at)
            }
            (_, Some("reset"), _) => {
                let np = self.a.not(p, at);
                self.a
                    .add("AND", vec![("IN1", var_input(&var, at)), ("IN2", np)], at)
            }
            (_, _, Some(edge @ ("rising" | "falling"))) => self.a.trigger(edge, p, el.local_id, at),
            _ => p,
        };
        Ok(Some(self.write(var, v, at)))
    }

    /// A jump or a return: JMP/RET with the power as its condition; its block id.
    fn control(&mut self, e: ElemId) -> R<u32> {
        let el = self.g.get(e);
        let at = origin(el.node);
        let here = self.at(e);
        let p = self.power(e)?;
        let op = if el.tag == "jump" { "JMP" } else { "RET" };
        let label = match el.tag {
            "jump" => Some(identifier(
                attr(el.node, "label", &here)?,
                "label",
                el.node,
                &here,
            )?),
            _ => None,
        };
        let id = self.a.next_id;
        self.a.next_id += 1;
        self.a.blocks.push(Block {
            origin: at,
            id: Ok(id),
            op: Ok(Cow::Borrowed(op)),
            inputs: None,
            outputs: None,
            instance: None,
            label: label.map(|l| Ok(Cow::Owned(l))),
            cond: (!is_const(&p, true)).then_some(p),
            en: false,
            after: None,
            comment: None,
            problem: None,
        });
        Ok(id)
    }
}

/// Two inputs that read the same thing (a duplicate wire of a wired OR).
fn same(a: &Input, b: &Input) -> bool {
    match (&a.from, &b.from) {
        (Connection::Variable(x), Connection::Variable(y)) => x == y,
        (Connection::Constant(Scalar::Bool(x)), Connection::Constant(Scalar::Bool(y))) => x == y,
        (Connection::Arc { block: x, pin: p }, Connection::Arc { block: y, pin: q }) => {
            x == y && pin_name(p) == pin_name(q)
        }
        _ => false,
    }
}

/// The name of an arc's output pin, if given.
fn pin_name<'x>(p: &'x Option<plc_syntax::fbd::Read<plc_syntax::Text<'_>>>) -> Option<&'x str> {
    p.as_ref().and_then(|r| r.as_ref().ok()).map(|s| s.as_ref())
}

/// A block to hold a place for a moment.
fn placeholder() -> Block<'static> {
    Block {
        origin: Origin::NONE,
        id: Ok(0),
        op: Ok(Cow::Borrowed("")),
        inputs: None,
        outputs: None,
        instance: None,
        label: None,
        cond: None,
        en: false,
        after: None,
        comment: None,
        problem: None,
    }
}
