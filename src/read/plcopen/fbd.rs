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

use super::black_box::{self, BlackBox, Ctx};
use super::interface::{literal, name};
use super::wiring::{graph, ElemId, Graph, Source};
use super::xml::{attr, error, identifier, origin, variable_ref, ExecOrder, Note, Notes, Tc6, R};
use crate::syntax::fbd::{Block, Connection, Input, Inputs, Network, OutVar, Outputs, Targets};
use crate::diag::Origin;
use crate::syntax::{FbdBody, Located, Scalar, Var, VarClass};
use std::cell::RefCell;
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
pub fn body(
    tc6: Tc6,
    node: Node,
    pou: &str,
    ctx: &Ctx,
    notes: &mut Notes,
) -> R<FbdBody<'static>> {
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
    let f = Fbd {
        g: &g,
        place,
        a: RefCell::new(Added::new(&g)),
        ctx,
        boxes: RefCell::new(std::mem::take(&mut notes.black_boxes)),
        notes: RefCell::new(Vec::new()),
    };
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
                    f.close_loops(&mut current);
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
        current.append(&mut f.a.borrow_mut().blocks);
    }
    let k = networks.len();
    f.close_loops(&mut current);
    networks.push(network(pou, k, label, current, comments));
    if labels == 0 {
        if let Some(n) = networks.first_mut() {
            n.id = Ok(Cow::Owned(pou.to_owned()));
        }
    }
    notes.black_boxes = f.boxes.take();
    notes.list.extend(f.notes.take());
    let vars = std::mem::take(&mut f.a.borrow_mut().vars);
    notes.ld_vars.extend(vars.into_iter().map(|v| (pou.to_owned(), v)));
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
    /// Blocks the reader adds (NOT of a negated pin, edge detectors), for the current network.
    a: RefCell<Added>,
    /// What blocks may call, and the types of the names the body sees.
    ctx: &'g Ctx,
    /// The project's black boxes so far ([`black_box`]).
    boxes: RefCell<Vec<BlackBox>>,
    notes: RefCell<Vec<Note>>,
}

/// A block's output pin as the syntax names it: the unnamed result of a user function
/// (`formalParameter=""`, old Beremiz files) is `OUT`.
pub fn pin_of(p: &str) -> &str {
    if p.is_empty() {
        "OUT"
    } else {
        p
    }
}

/// Blocks and variables a reader adds to a body: NOT of a negated pin, edge detectors, the
/// gates of an LD body read as data flow ([`super::ld_flow`]). Their ids count up from above
/// every localId of the body.
pub struct Added {
    pub next_id: u32,
    pub blocks: Vec<Block<'static>>,
    /// Edge-detector instances (`R_TRIG__<localId>`), to add to the POU.
    pub vars: Vec<Var<'static>>,
}

pub fn konst(b: bool, at: Origin) -> Input<'static> {
    Input {
        origin: at,
        from: Connection::Constant(Scalar::Bool(b)),
    }
}

pub fn is_const(i: &Input, b: bool) -> bool {
    matches!(i.from, Connection::Constant(Scalar::Bool(x)) if x == b)
}

impl Added {
    pub fn new(g: &Graph) -> Added {
        Added {
            next_id: g.elems.iter().map(|el| el.local_id).max().unwrap_or(0) + 1,
            blocks: Vec::new(),
            vars: Vec::new(),
        }
    }

    /// Adds block `op` with `inputs` (by pin name) at `at`: an arc from its first output.
    pub fn add(&mut self, op: &str, inputs: Vec<(&str, Input<'static>)>, at: Origin) -> Input<'static> {
        let named = inputs
            .into_iter()
            .map(|(p, i)| (Cow::Owned(p.to_owned()), i))
            .collect();
        self.add_on(op, None, Inputs::Named(named), at)
    }

    /// Adds block `op` (on `instance`) with `inputs` at `at`: an arc from its first output.
    pub fn add_on(
        &mut self,
        op: &str,
        instance: Option<String>,
        inputs: Inputs<'static>,
        at: Origin,
    ) -> Input<'static> {
        let id = self.next_id;
        self.next_id += 1;
        self.blocks.push(Block {
            origin: at,
            id: Ok(id),
            op: Ok(Cow::Owned(op.to_owned())),
            inputs: Some(Ok(inputs)),
            outputs: None,
            instance: instance.map(|i| Ok(Cow::Owned(i))),
            label: None,
            cond: None,
            after: None,
            comment: None,
            problem: None,
        });
        let first = if op.ends_with("_TRIG") { "Q" } else { "OUT" };
        Input {
            origin: at,
            from: Connection::Arc {
                block: id,
                pin: Some(Ok(Cow::Borrowed(first))),
            },
        }
    }

    pub fn and(&mut self, a: Input<'static>, b: Input<'static>, at: Origin) -> Input<'static> {
        if is_const(&a, true) {
            return b;
        }
        if is_const(&b, true) {
            return a;
        }
        self.add("AND", vec![("IN1", a), ("IN2", b)], at)
    }

    pub fn not(&mut self, a: Input<'static>, at: Origin) -> Input<'static> {
        match a.from {
            Connection::Constant(Scalar::Bool(x)) => konst(!x, at),
            _ => self.add("NOT", vec![("IN", a)], at),
        }
    }

    /// A comparison block `b`: extensible, `op(IN1, …, INn)` with n ≥ 3 (IEC 61131-3 Table
    /// 31: `IN1 op IN2 AND IN2 op IN3 …`), it becomes the AND of a new comparison per
    /// neighbouring pair, keeping its id and outputs; EQ and NE of BOOLs (which IEC allows, the
    /// model's comparison does not) become `NOT (a XOR b)` and `a XOR b`. An unconnected input
    /// is 0, a function input's default (IEC 61131-3 2.5.1.1).
    pub fn compare(&mut self, b: &mut Block<'static>, ty: &dyn Fn(&Input) -> Option<String>) {
        let is_bool = |i: &Input| ty(i).as_deref() == Some("BOOL");
        let op = match &b.op {
            Ok(op) if crate::model::CmpOp::parse(op).is_some() => op.to_string(),
            _ => return,
        };
        let Some(Ok(Inputs::Named(ins))) = &b.inputs else { return };
        let index = |p: &str| p.strip_prefix("IN").and_then(|k| k.parse::<usize>().ok());
        let n = ins.iter().filter_map(|(p, _)| index(p)).max().unwrap_or(0);
        let ins: Vec<Input<'static>> = (1..=n)
            .map(|k| {
                ins.iter()
                    .find(|(p, _)| index(p) == Some(k))
                    .map(|(_, i)| i.clone())
                    .unwrap_or(Input {
                        origin: b.origin,
                        from: Connection::Constant(Scalar::Number(0.into())),
                    })
            })
            .collect();
        let bools = ins.iter().filter(|i| is_bool(i)).count();
        let boolean = matches!(op.as_str(), "EQ" | "NE") && bools == ins.len();
        // BOOLs compared with numbers (which IEC 61131-3 does not type) are compared as
        // BOOL_TO_INT of them, 0 or 1.
        let number = ins.iter().find_map(|i| ty(i).filter(|t| t != "BOOL"));
        let ins: Vec<Input<'static>> = if bools > 0 && !boolean {
            ins.into_iter()
                .map(|i| {
                    if !is_bool(&i) {
                        return i;
                    }
                    let at = i.origin;
                    let n = |v: i64| Input {
                        origin: at,
                        from: Connection::Constant(Scalar::Number(v.into())),
                    };
                    let sel = self.add("SEL", vec![("G", i), ("IN0", n(0)), ("IN1", n(1))], at);
                    self.typed(number.as_deref(), at);
                    sel
                })
                .collect()
        } else {
            ins
        };
        if bools > 0 && !boolean && n == 2 {
            b.inputs = Some(Ok(Inputs::Named(vec![
                (Cow::Borrowed("IN1"), ins[0].clone()),
                (Cow::Borrowed("IN2"), ins[1].clone()),
            ])));
            return;
        }
        if n < 2 || (n == 2 && !boolean) {
            return;
        }
        let mut pairs = Vec::new();
        for w in ins.windows(2) {
            let at = w[1].origin;
            let pair = vec![("IN1", w[0].clone()), ("IN2", w[1].clone())];
            pairs.push(match (boolean, op.as_str()) {
                (false, _) => self.add(&op, pair, at),
                (true, "NE") => self.add("XOR", pair, at),
                (true, _) => {
                    let x = self.add("XOR", pair, at);
                    self.add("NOT", vec![("IN", x)], at)
                }
            });
        }
        let named: Vec<(Cow<'static, str>, Input<'static>)> = if pairs.len() == 1 {
            b.op = Ok(Cow::Borrowed("MOVE"));
            vec![(Cow::Borrowed("IN"), pairs.remove(0))]
        } else {
            b.op = Ok(Cow::Borrowed("AND"));
            pairs
                .into_iter()
                .enumerate()
                .map(|(k, i)| (Cow::Owned(format!("IN{}", k + 1)), i))
                .collect()
        };
        b.inputs = Some(Ok(Inputs::Named(named)));
    }

    /// Gives the last block added (a SEL of constants) a variable of type `ty` to write, so
    /// that its output has that type (a block of constants only would be DINT); the variable
    /// is `<op>__<id>`, declared in the POU.
    pub fn typed(&mut self, ty: Option<&str>, at: Origin) {
        let Some(ty) = ty else { return };
        let Some(b) = self.blocks.last_mut() else { return };
        let (Ok(op), Ok(id)) = (&b.op, &b.id) else { return };
        let v = format!("{op}__{id}");
        add_target(b, "OUT".to_owned(), OutVar { origin: at, name: Cow::Owned(v.clone()) });
        self.declare(&v, ty, at);
    }

    /// Declares instance `inst` of function block type `ty` in the POU.
    pub fn declare(&mut self, inst: &str, ty: &str, at: Origin) {
        self.vars.push(Var {
            origin: at,
            name: name(inst, at),
            ty: name(ty, at),
            class: Located {
                value: VarClass::Memory,
                origin: at,
            },
            init: None,
            problem: None,
        });
    }

    /// An R_TRIG (`rising`) or F_TRIG of `clk` on a new instance named after `local_id`.
    pub fn trigger(&mut self, edge: &str, clk: Input<'static>, local_id: u32, at: Origin) -> Input<'static> {
        let kind = if edge == "falling" { "F_TRIG" } else { "R_TRIG" };
        let inst = format!("{kind}__{local_id}");
        let mut k = 1;
        let mut unique = inst.clone();
        while self.vars.iter().any(|v| v.name.value == unique) {
            k += 1;
            unique = format!("{inst}_{k}");
        }
        self.declare(&unique, kind, at);
        let inputs = Inputs::Named(vec![(Cow::Borrowed("CLK"), clk)]);
        self.add_on(kind, Some(unique), inputs, at)
    }
}

/// What an `inVariable` or `inOutVariable` element `node` gives to a pin (at `at`): its
/// literal, else its variable.
pub fn block_input(node: Node, place: &str, at: Origin) -> R<Input<'static>> {
    let text = node
        .children()
        .find(|c| c.is_element() && c.tag_name().name() == "expression")
        .and_then(|c| c.text())
        .unwrap_or("");
    let from = match literal(text) {
        Some(v) => Connection::Constant(v),
        // A string has no value in the model: a stand-in 0 (`run` refuses such a body).
        None if is_string_literal(text) => Connection::Constant(Scalar::Number(0.into())),
        None => Connection::Variable(Cow::Owned(variable_ref(text, node, place)?)),
    };
    Ok(Input { origin: at, from })
}

/// A `0` or `1` feeding a BOOL input pin is FALSE or TRUE (IEC 61131-3 6.3.2: literals are
/// typed by their use).
pub fn bool_literal(ctx: &Ctx, ty: &str, pin: &str, mut i: Input<'static>) -> Input<'static> {
    if let Connection::Constant(Scalar::Number(n)) = &i.from {
        let b = match n.as_u64() {
            Some(0) => false,
            Some(1) => true,
            _ => return i,
        };
        if ctx.input_type(ty, pin).as_deref() == Some("BOOL") {
            i.from = Connection::Constant(Scalar::Bool(b));
        }
    }
    i
}

/// Adds `target` to output `pin` of block `b`.
pub fn add_target(b: &mut Block<'static>, pin: String, target: OutVar<'static>) {
    let mut outs = match b.outputs.take() {
        Some(Ok(Outputs::Named(v))) => v,
        _ => Vec::new(),
    };
    match outs.iter_mut().find(|(p, _)| p.as_ref() == pin) {
        Some((_, Ok(Targets::Many(v)))) => v.push(Ok(target)),
        _ => outs.push((Cow::Owned(pin), Ok(Targets::Many(vec![Ok(target)])))),
    }
    b.outputs = Some(Ok(Outputs::Named(outs)));
}

/// True when `text` is an IEC 61131-3 string literal (`'…'` or `"…"`, 6.3.3).
pub fn is_string_literal(text: &str) -> bool {
    let t = text.trim();
    t.len() >= 2
        && ((t.starts_with('\'') && t.ends_with('\'')) || (t.starts_with('"') && t.ends_with('"')))
}

/// The qualifiers of input pin `pin` (its `variable` node `pnode`) of block `ty`: negated, and
/// the edge (`rising`/`falling`). A `storage` qualifier is an error.
pub fn pin_modifiers<'n>(
    pnode: Node<'n, '_>,
    ty: &str,
    pin: &str,
    local_id: u32,
    place: &str,
) -> R<(bool, Option<&'n str>)> {
    if matches!(pnode.attribute("storage"), Some(v) if v != "none") {
        return Err(error(
            origin(pnode),
            place,
            format!("input {pin} of {ty} (localId {local_id}) has a storage qualifier, which only a coil can have"),
        ));
    }
    let negated = matches!(pnode.attribute("negated"), Some("true" | "1"));
    let edge = pnode.attribute("edge").filter(|e| *e != "none");
    if negated && edge.is_some() {
        return Err(error(
            origin(pnode),
            place,
            format!("input {pin} of {ty} (localId {local_id}) is both negated and edge-qualified"),
        ));
    }
    Ok((negated, edge))
}

/// True when output `pin` of block element `node` is negated (`None`: its first output).
pub fn output_negated(outputs: &[(&str, Node)], pin: Option<&str>) -> bool {
    let found = match pin {
        Some(p) => outputs.iter().find(|(n, _)| *n == p),
        None => outputs.iter().find(|(n, _)| *n != "ENO"),
    };
    found.is_some_and(|(_, n)| matches!(n.attribute("negated"), Some("true" | "1")))
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
        let mut ty = attr(el.node, "typeName", &here)?;
        let declared_type;
        let mut b = self.new_block(e, ty);
        if let Some(inst) = el.node.attribute("instanceName") {
            b.instance = Some(Ok(Cow::Owned(identifier(
                inst, "instance", el.node, &here,
            )?)));
            // Beremiz calls the instance by name, so the instance's type decides what runs.
            if let Some(declared) = self.ctx.fb_type_of(inst).filter(|d| d != ty) {
                self.notes.borrow_mut().push(Note {
                    origin: origin(el.node),
                    message: format!("{here}: the block is a {ty} but its instance `{inst}` is declared {declared}; it is read as a call of {declared} (Beremiz calls the instance by name)"),
                });
                declared_type = declared;
                ty = &declared_type;
                b.op = Ok(Cow::Owned(ty.to_owned()));
            }
        }
        let mut inputs = Vec::new();
        for pin in &el.inputs {
            let name = pin.name.unwrap_or("");
            let (negated, edge) = pin_modifiers(pin.node, ty, name, el.local_id, &here)?;
            let mut input = match pin.sources.as_slice() {
                // An unconnected BOOL input of a standard function block keeps its initial
                // value FALSE (nothing in the body sets it, IEC 61131-3 2.5.2.1).
                [] if black_box::is_standard_fb(ty)
                    && self.ctx.input_type(ty, name).as_deref() == Some("BOOL") =>
                {
                    konst(false, origin(pin.node))
                }
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
            let at = origin(pin.node);
            let counter_edge = matches!(ty, "CTU" | "CTD" | "CTUD") && matches!(name, "CU" | "CD");
            let mut a = self.a.borrow_mut();
            match edge {
                Some(edge) if !(counter_edge && edge == "rising") => {
                    input = a.trigger(edge, input, el.local_id, at)
                }
                _ => {}
            }
            if negated {
                input = a.not(input, at);
            }
            drop(a);
            if let Connection::Variable(v) = &input.from {
                if let Some(k) = super::library::library_constant(ty, name, v) {
                    input.from = Connection::Constant(Scalar::Number(k.into()));
                }
            }
            input = bool_literal(self.ctx, ty, name, input);
            if name == "EN" {
                b.cond = Some(input);
            } else {
                inputs.push((Cow::Owned(name.to_owned()), input));
            }
        }
        b.inputs = Some(Ok(Inputs::Named(inputs)));
        let t = black_box::Typer { ctx: self.ctx, g: self.g };
        self.a.borrow_mut().compare(&mut b, &|i: &Input| t.input(i, 0));
        if !black_box::is_known(self.ctx, ty) || black_box::mixed_arithmetic(&t, ty, &b) {
            let mut boxes = self.boxes.borrow_mut();
            if let Some((inst, bt)) = black_box::rewrite(&t, e, &mut b, &mut boxes, &here)? {
                self.a.borrow_mut().declare(&inst, &bt, b.origin);
            }
        }
        for (pin, pnode) in &el.outputs {
            let targets = self.targets(e, pin, el.outputs.first().map(|o| o.0) == Some(*pin))?;
            let negated = matches!(pnode.attribute("negated"), Some("true" | "1"));
            let targets = if negated && !targets.is_empty() {
                // The variables a negated output writes get NOT of it.
                let at = origin(*pnode);
                let arc = Input {
                    origin: at,
                    from: Connection::Arc {
                        block: el.local_id,
                        pin: Some(Ok(Cow::Owned(pin_of(pin).to_owned()))),
                    },
                };
                let mut a = self.a.borrow_mut();
                a.not(arc, at);
                if let Some(n) = a.blocks.last_mut() {
                    n.outputs = Some(Ok(Outputs::Named(vec![(
                        Cow::Borrowed("OUT"),
                        Ok(Targets::Many(targets.into_iter().map(Ok).collect())),
                    )])));
                }
                Vec::new()
            } else {
                targets
            };
            if *pin == "ENO" && !targets.is_empty() {
                // ENO is EN (IEC 61131-3 2.5.1.2: TRUE when the block ran without error).
                let en = self.eno(e, origin(*pnode))?;
                let mut a = self.a.borrow_mut();
                a.add_on("MOVE", None, Inputs::List(vec![en]), origin(*pnode));
                if let Some(m) = a.blocks.last_mut() {
                    for t in targets {
                        add_target(m, "OUT".to_owned(), t);
                    }
                }
                continue;
            }
            for t in targets {
                add_target(&mut b, pin_of(pin).to_owned(), t);
            }
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

    /// Cuts the loops of arcs among `blocks` as Beremiz closes them ([`super::fbd_loops`]).
    fn close_loops(&self, blocks: &mut [Block<'static>]) {
        let t = black_box::Typer { ctx: self.ctx, g: self.g };
        let ty = |id: u32, pin: Option<&str>| {
            let e = self.g.elems.iter().position(|el| el.local_id == id)?;
            t.output(ElemId(e as u32), pin, 0)
        };
        let notes = super::fbd_loops::cut(blocks, &mut self.a.borrow_mut(), &ty, &self.place);
        self.notes.borrow_mut().extend(notes);
    }

    /// The ENO of block `e`: what feeds its EN, TRUE without one.
    fn eno(&self, e: ElemId, at: Origin) -> R<Input<'static>> {
        let el = self.g.get(e);
        match el.inputs.iter().find(|p| p.name == Some("EN")).map(|p| p.sources.as_slice()) {
            Some([s]) => self.input(e, s),
            _ => Ok(konst(true, at)),
        }
    }

    /// What source `s` gives to an input of block `consumer`.
    fn input(&self, consumer: ElemId, s: &Source) -> R<Input<'static>> {
        let src = self.g.get(s.elem);
        match src.tag {
            "block" if s.pin == Some("ENO") => self.eno(s.elem, s.origin),
            "block" => {
                let arc = Input {
                    origin: s.origin,
                    from: Connection::Arc {
                        block: src.local_id,
                        pin: s.pin.map(|p| Ok(Cow::Owned(pin_of(p).to_owned()))),
                    },
                };
                if output_negated(&src.outputs, s.pin) {
                    return Ok(self.a.borrow_mut().not(arc, s.origin));
                }
                Ok(arc)
            }
            "inVariable" | "inOutVariable" => block_input(src.node, &self.at(s.elem), s.origin),
            other => Err(error(
                    s.origin,
                    &self.at(consumer),
                    format!(
                        "a {other} (localId {}) cannot feed an input in FBD",
                        src.local_id
                    ),
            )),
        }
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
