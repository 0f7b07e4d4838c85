//! Blocks and pins shared by the FBD reader ([`super::fbd`]) and the LD bodies read as data flow
//! ([`super::ld_flow`]): the blocks a reader adds to a body ([`Added`]: NOT of a negated pin,
//! edge detectors, the gates of the power flow, extensible and BOOL comparisons), what an
//! in variable gives to a pin, pin qualifiers, BOOL literals typed by their pin, output targets.
//!
//! Invariants: added blocks have ids above every localId of the body; added instances and
//! variables have names with a double `_`, which no IEC 61131-3 identifier of the file has.
//!
//! Deliberately not here: reading elements (the body readers), ops the model lacks
//! ([`super::black_box`]).

use super::block_types::Ctx;
use super::interface::{literal, name};
use super::wiring::Graph;
use super::xml::{error, origin, variable_ref, R};
use plc_diag::Origin;
use plc_syntax::fbd::{Block, Connection, Input, Inputs, OutVar, Outputs, Targets};
use plc_syntax::{Located, Scalar, Var, VarClass};
use roxmltree::Node;
use std::borrow::Cow;

/// A block's output pin as the syntax names it: the unnamed result of a user function
/// (`formalParameter=""`, old Beremiz files) is `OUT`.
pub(super) fn pin_of(p: &str) -> &str {
    if p.is_empty() {
        "OUT"
    } else {
        p
    }
}

/// Blocks and variables a reader adds to a body: NOT of a negated pin, edge detectors, the
/// gates of an LD body read as data flow ([`super::ld_flow`]). Their ids count up from above
/// every localId of the body.
pub(super) struct Added {
    pub next_id: u32,
    pub blocks: Vec<Block<'static>>,
    /// Edge-detector instances (`R_TRIG__<localId>`), to add to the POU.
    pub vars: Vec<Var<'static>>,
    /// The lower-case names of the scalarised arrays' element variables the POU sees (`a[3]`,
    /// [`super::data_types`]): an element of constant subscripts that is one is read as it.
    pub elements: std::collections::HashSet<String>,
}

pub(super) fn konst(b: bool, at: Origin) -> Input<'static> {
    Input {
        origin: at,
        from: Connection::Constant(Scalar::Bool(b)),
    }
}

/// The value an unconnected data input `pin` of standard function block `ty` takes: its type's
/// initial value (IEC 61131-3 2.5.2.1: an input nothing sets keeps its initial value; 2.4.2: the
/// type's default), T#0ms for a timer's PT and 0 for a counter's PV, with the text the warning
/// shows; a BOOL input (a timer's IN, a counter's CU, CD, R or LD, a bistable's or a trigger's
/// input) FALSE, as matiec leaves an input no call sets at its initial value. Other blocks and
/// pins: `None`.
pub(super) fn unconnected_default(
    ty: &str,
    pin: &str,
    at: Origin,
) -> Option<(Input<'static>, &'static str)> {
    let counter = |t: &str| {
        ["CTU", "CTD", "CTUD"]
            .iter()
            .any(|c| t == *c || t.strip_prefix(c).is_some_and(|r| r.starts_with('_')))
    };
    let (c, text) = match (ty, pin) {
        ("TON" | "TOF" | "TP", "PT") => (Scalar::Str(Cow::Borrowed("T#0ms")), "T#0ms"),
        (t, "PV") if counter(t) => (Scalar::Number(0.into()), "0"),
        ("TON" | "TOF" | "TP", "IN")
        | ("SR", "S1" | "R")
        | ("RS", "S" | "R1")
        | ("R_TRIG" | "F_TRIG", "CLK") => (Scalar::Bool(false), "FALSE"),
        (t, "CU" | "CD" | "R" | "LD") if counter(t) => (Scalar::Bool(false), "FALSE"),
        _ => return None,
    };
    Some((
        Input {
            origin: at,
            from: Connection::Constant(c),
        },
        text,
    ))
}

pub(super) fn is_const(i: &Input, b: bool) -> bool {
    matches!(i.from, Connection::Constant(Scalar::Bool(x)) if x == b)
}

impl Added {
    pub(super) fn new(g: &Graph) -> Added {
        Added {
            next_id: g.elems.iter().map(|el| el.local_id).max().unwrap_or(0) + 1,
            blocks: Vec::new(),
            vars: Vec::new(),
            elements: std::collections::HashSet::new(),
        }
    }

    /// The same, knowing the element variables among `vars` (lower-case name → type).
    pub(super) fn with_elements(
        mut self,
        vars: &std::collections::HashMap<String, String>,
    ) -> Added {
        self.elements = vars.keys().filter(|n| n.contains('[')).cloned().collect();
        self
    }

    /// Adds block `op` with `inputs` (by pin name) at `at`: an arc from its first output.
    pub(super) fn add(
        &mut self,
        op: &str,
        inputs: Vec<(&str, Input<'static>)>,
        at: Origin,
    ) -> Input<'static> {
        let named = inputs
            .into_iter()
            .map(|(p, i)| (Cow::Owned(p.to_owned()), i))
            .collect();
        self.add_on(op, None, Inputs::Named(named), at)
    }

    /// Adds block `op` (on `instance`) with `inputs` at `at`: an arc from its first output.
    pub(super) fn add_on(
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
            en: false,
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

    pub(super) fn and(
        &mut self,
        a: Input<'static>,
        b: Input<'static>,
        at: Origin,
    ) -> Input<'static> {
        if is_const(&a, true) {
            return b;
        }
        if is_const(&b, true) {
            return a;
        }
        self.add("AND", vec![("IN1", a), ("IN2", b)], at)
    }

    pub(super) fn not(&mut self, a: Input<'static>, at: Origin) -> Input<'static> {
        match a.from {
            Connection::Constant(Scalar::Bool(x)) => konst(!x, at),
            _ => self.add("NOT", vec![("IN", a)], at),
        }
    }

    /// A comparison block `b`: extensible, `op(IN1, …, INn)` with n ≥ 3 (IEC 61131-3 Table
    /// 31: `IN1 op IN2 AND IN2 op IN3 …`), it becomes the AND of a new comparison per
    /// neighbouring pair, keeping its id and outputs; EQ and NE of BOOLs (which IEC allows, the
    /// model's comparison does not) become `NOT (a XOR b)` and `a XOR b`. An unconnected input
    /// is 0, a function input's default (IEC 61131-3 2.5.1.1). `declared` is the number of
    /// input pins the element lists in the file: a pin numbered past it (`IN2147483647`) is no
    /// unconnected pin of the element, and the block is left as it is, for the resolver to
    /// refuse its gap, instead of filling every number up to it.
    pub(super) fn compare(
        &mut self,
        b: &mut Block<'static>,
        declared: usize,
        ty: &dyn Fn(&Input) -> Option<String>,
    ) {
        let is_bool = |i: &Input| ty(i).as_deref() == Some("BOOL");
        let op = match &b.op {
            Ok(op) if plc_model::CmpOp::parse(op).is_some() => op.to_string(),
            _ => return,
        };
        let Some(Ok(Inputs::Named(ins))) = &b.inputs else {
            return;
        };
        let index = |p: &str| p.strip_prefix("IN").and_then(|k| k.parse::<usize>().ok());
        let n = ins.iter().filter_map(|(p, _)| index(p)).max().unwrap_or(0);
        if n > declared {
            return;
        }
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
    pub(super) fn typed(&mut self, ty: Option<&str>, at: Origin) {
        let Some(ty) = ty else { return };
        let Some(b) = self.blocks.last_mut() else {
            return;
        };
        let (Ok(op), Ok(id)) = (&b.op, &b.id) else {
            return;
        };
        let v = format!("{op}__{id}");
        add_target(
            b,
            "OUT".to_owned(),
            OutVar {
                origin: at,
                name: Cow::Owned(v.clone()),
            },
        );
        self.declare(&v, ty, at);
    }

    /// Declares instance `inst` of function block type `ty` in the POU.
    pub(super) fn declare(&mut self, inst: &str, ty: &str, at: Origin) {
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
    pub(super) fn trigger(
        &mut self,
        edge: &str,
        clk: Input<'static>,
        local_id: u32,
        at: Origin,
    ) -> Input<'static> {
        let kind = if edge == "falling" {
            "F_TRIG"
        } else {
            "R_TRIG"
        };
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

/// The text of `node`'s `expression` (empty without one).
pub(super) fn expression_text<'a>(node: Node<'a, '_>) -> &'a str {
    node.children()
        .find(|c| c.is_element() && c.tag_name().name() == "expression")
        .and_then(|c| c.text())
        .unwrap_or("")
}

/// What an `inVariable` or `inOutVariable` element `node` gives to a pin (at `at`): its
/// literal, else its variable (an expression: [`super::expression::block_input`]).
pub(super) fn block_input(node: Node, place: &str, at: Origin) -> R<Input<'static>> {
    let text = expression_text(node);
    let from = match literal(text) {
        Some(v) => Connection::Constant(v),
        // A string has no value in the model: a stand-in 0 (`run` refuses such a body).
        // A STRING literal, its `$` escapes read when it is typed (`"…"` is a WSTRING: no value).
        None if text.trim().starts_with('\'') && is_string_literal(text) => {
            Connection::Constant(Scalar::Str(Cow::Owned(text.trim().to_owned())))
        }
        // A WSTRING literal: no value; the empty STRING stands in (`run` refuses the body).
        None if is_string_literal(text) => Connection::Constant(Scalar::Str(Cow::Borrowed("''"))),
        None => Connection::Variable(Cow::Owned(variable_ref(text, node, place)?)),
    };
    Ok(Input { origin: at, from })
}

/// A `0` or `1` feeding a BOOL input pin is FALSE or TRUE (IEC 61131-3 6.3.2: literals are
/// typed by their use).
pub(super) fn bool_literal(
    ctx: &Ctx,
    ty: &str,
    pin: &str,
    mut i: Input<'static>,
) -> Input<'static> {
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

/// The MOVE block `id` (at `at`) that writes what `from` gives into `to`.
pub(super) fn move_block(
    id: u32,
    from: Input<'static>,
    to: OutVar<'static>,
    at: Origin,
) -> Block<'static> {
    Block {
        origin: at,
        id: Ok(id),
        op: Ok(Cow::Borrowed("MOVE")),
        inputs: Some(Ok(Inputs::List(vec![from]))),
        outputs: Some(Ok(Outputs::First(to))),
        instance: None,
        label: None,
        cond: None,
        en: false,
        after: None,
        comment: None,
        problem: None,
    }
}

/// Adds `target` to output `pin` of block `b`.
pub(super) fn add_target(b: &mut Block<'static>, pin: String, target: OutVar<'static>) {
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
pub(super) fn is_string_literal(text: &str) -> bool {
    let t = text.trim();
    t.len() >= 2
        && ((t.starts_with('\'') && t.ends_with('\'')) || (t.starts_with('"') && t.ends_with('"')))
}

/// The qualifiers of input pin `pin` (its `variable` node `pnode`) of block `ty`: negated, and
/// the edge (`rising`/`falling`). A `storage` qualifier is an error.
pub(super) fn pin_modifiers<'n>(
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
pub(super) fn output_negated(outputs: &[(&str, Node)], pin: Option<&str>) -> bool {
    let found = match pin {
        Some(p) => outputs.iter().find(|(n, _)| *n == p),
        None => outputs.iter().find(|(n, _)| *n != "ENO"),
    };
    found.is_some_and(|(_, n)| matches!(n.attribute("negated"), Some("true" | "1")))
}
