//! Blocks inside LD rungs → the syntax's box elements (IEC 61131-3 8.2.2: function and function
//! block boxes in ladder; TC6 `block` with `inputVariables`/`outputVariables`).
//!
//! A block takes its power from `EN` when it has one, else from its first BOOL input (`IN` of
//! TON/TOF/TP, `CU` of CTU and CTUD, `CD` of CTD, `S1` of SR, `S` of RS, `CLK` of R_TRIG and
//! F_TRIG: IEC 61131-3 2.5.2.3; functions without `EN` run always, from the rail) and gives power
//! out on `ENO`, or its first output (`Q` of timers, counters and triggers, `Q1` of SR/RS, `QU`
//! of CTUD), or `OUT` (compares). Its data inputs are
//! fed by `inVariable`s (a variable or a constant); the result of ADD … MOD and MOVE goes to the
//! `outVariable` wired to `OUT` (exactly one). A BOOL data input (`R`/`LD` of a counter, `R`/`R1`
//! of SR/RS, `CD`/`R`/`LD` of CTUD) may also be a single contact on the rail (its variable is
//! the operand). The extensible comparisons (IEC 61131-3 Table 31: `IN1 op IN2 AND IN2 op IN3
//! …`) become one compare per neighbouring pair in series; the extensible ADD and MUL (Table 29)
//! one arithmetic box per step, each writing OUT (so an `INk`, k ≥ 3, may not read OUT).
//!
//! Deliberately not here (each an error naming the block and its localId): other block types
//! (standard ones the model lacks, user function blocks and functions in LD), EN/ENO on timers
//! and counters, a data pin fed by a function's output or a contact network, negated or
//! edge-qualified pins other than a rising edge on a counter's `CU`/`CD` (the counter's own edge).
//!
//! The other outputs of a function block (`QD`, `CV` of CTUD, `ET` of a timer) are its instance's
//! fields, read after the box: a contact on `C1.QD` from the rail when they feed power, the
//! operand `C1.CV` when they feed a data pin (`super::ld` runs the box's output first). An
//! unconnected BOOL input or PV of a function block is its initial value (FALSE, 0). A BOOL data
//! input fed by several wires (their OR) or by a contact network is written, before the box in
//! the same rung, into the BOOL `instance__pin` that the box reads ([`Power::feeds`]).

use super::ld_power::{Blocks, Item, Key, Path, Power};
use super::wiring::ElemId;
use super::xml::{error, origin, variable_ref, R};
use plc_model::{ArithOp, BistableKind, CmpOp, Function, TimerKind, TriggerKind};
use plc_syntax::{
    Arith, Bistable, Compare, Counter, Ctud, Element, ElementKind, FunctionCall, Located, Move,
    Name, Operand, Scalar, Timer,
};

/// The block types an LD rung can hold, with their pins.
enum Spec {
    Timer(TimerKind),
    Counter {
        down: bool,
    },
    Bistable(BistableKind),
    Trigger(TriggerKind),
    Ctud,
    Arith(ArithOp),
    Move,
    Compare(CmpOp),
    /// A standard function (EN, its inputs, ENO, OUT).
    Function(Function),
}

impl Spec {
    fn of(ty: &str) -> Option<Spec> {
        Some(match ty {
            "TON" => Spec::Timer(TimerKind::Ton),
            "TOF" => Spec::Timer(TimerKind::Tof),
            "TP" => Spec::Timer(TimerKind::Tp),
            "CTU" => Spec::Counter { down: false },
            "CTD" => Spec::Counter { down: true },
            "SR" => Spec::Bistable(BistableKind::SetDominant),
            "RS" => Spec::Bistable(BistableKind::ResetDominant),
            "R_TRIG" => Spec::Trigger(TriggerKind::Rising),
            "F_TRIG" => Spec::Trigger(TriggerKind::Falling),
            "CTUD" => Spec::Ctud,
            "MOVE" => Spec::Move,
            _ => match (ArithOp::parse(ty), CmpOp::parse(ty)) {
                (Some(op), _) => Spec::Arith(op),
                (_, Some(op)) => Spec::Compare(op),
                _ => Spec::Function(super::black_box::standard_function(ty)?),
            },
        })
    }

    /// (power input, data inputs, power output, the output written to an out variable).
    fn pins(
        &self,
    ) -> (
        &'static str,
        &'static [&'static str],
        &'static str,
        Option<&'static str>,
    ) {
        match self {
            Spec::Timer(_) => ("IN", &["PT"], "Q", None),
            Spec::Counter { down: false } => ("CU", &["R", "PV"], "Q", None),
            Spec::Counter { down: true } => ("CD", &["LD", "PV"], "Q", None),
            Spec::Bistable(BistableKind::SetDominant) => ("S1", &["R"], "Q1", None),
            Spec::Bistable(BistableKind::ResetDominant) => ("S", &["R1"], "Q1", None),
            Spec::Trigger(_) => ("CLK", &[], "Q", None),
            Spec::Ctud => ("CU", &["CD", "R", "LD", "PV"], "QU", None),
            Spec::Arith(_) => ("EN", &["IN1", "IN2"], "ENO", Some("OUT")),
            Spec::Move => ("EN", &["IN"], "ENO", Some("OUT")),
            Spec::Compare(_) => ("EN", &["IN1", "IN2"], "OUT", None),
            Spec::Function(f) => {
                let data: &'static [&'static str] = match f {
                    Function::Expt => &["IN1", "IN2"],
                    Function::Shl | Function::Shr | Function::Rol | Function::Ror => &["IN", "N"],
                    Function::Mux => &["K", "IN0", "IN1"],
                    _ => &["IN"],
                };
                ("EN", data, "ENO", Some("OUT"))
            }
        }
    }
}

impl Spec {
    /// True for the function blocks (with an instance whose outputs are fields).
    fn is_instance(&self) -> bool {
        matches!(
            self,
            Spec::Timer(_)
                | Spec::Counter { .. }
                | Spec::Bistable(_)
                | Spec::Trigger(_)
                | Spec::Ctud
        )
    }

    /// True when `pin` is an input `IN3`, `IN4` … of an extensible block (IEC 61131-3 Tables 29
    /// and 31: ADD, MUL and the comparisons take any number of inputs).
    fn extends(&self, pin: &str) -> bool {
        let extensible = matches!(
            self,
            Spec::Compare(_) | Spec::Arith(ArithOp::Add | ArithOp::Mul)
        );
        let first = self.first_extension();
        (extensible || first == 2)
            && pin
                .strip_prefix("IN")
                .and_then(|k| k.parse::<u32>().ok())
                .is_some_and(|k| k >= first && pin == format!("IN{k}"))
    }

    /// The number k of the first extension input `INk` (MUX: IN2; ADD, MUL, compares: IN3).
    fn first_extension(&self) -> u32 {
        match self {
            Spec::Function(Function::Mux) => 2,
            _ => 3,
        }
    }
}

const SUPPORTED: &str = "TON, TOF, TP, CTU, CTD, SR, RS, R_TRIG, F_TRIG, CTUD, ADD, SUB, MUL, DIV, MOD, MOVE, EQ, NE, LT, LE, GT, GE, AND, OR, XOR, NOT, and the standard functions ABS … ATAN, EXPT, SHL … ROR, MUX, *_TO_*, TRUNC";

/// True when out variable `e` is the result of an ADD … MOD or MOVE block (part of its box).
/// The boolean functions AND, OR, XOR and NOT are not boxes but conditions of the rung
/// ([`super::ld_logic`]): an out variable after one is the rung's output, a coil.
pub(super) fn absorbed(p: &Power, e: ElemId) -> bool {
    let el = p.g.get(e);
    let [pin] = el.inputs.as_slice() else {
        return false;
    };
    let [s] = pin.sources.as_slice() else {
        return false;
    };
    let src = p.g.get(s.elem);
    src.tag == "block"
        && !src
            .node
            .attribute("typeName")
            .is_some_and(super::ld_logic::is_logic)
        && matches!(
            src.node.attribute("typeName").and_then(Spec::of),
            Some(Spec::Arith(_) | Spec::Move | Spec::Function(_))
        )
        && s.pin.is_none_or(|p| p == "OUT")
}

/// True when `pin` of block `e` is an output of a function block instance other than its power
/// output (`QD` or `CV` of a CTUD, `ET` of a timer): it is read after the box, as the instance's
/// field.
pub(super) fn reads_side(p: &Power, e: ElemId, pin: Option<&str>) -> bool {
    let el = p.g.get(e);
    let Some(pin) = pin else {
        return false;
    };
    if el.tag != "block" {
        return false;
    }
    let Some(spec) = el.node.attribute("typeName").and_then(Spec::of) else {
        return false;
    };
    spec.is_instance() && pin != spec.pins().2 && el.outputs.iter().any(|(o, _)| *o == pin)
}

/// The contact that reads output `pin` of function block `e` (its field `instance.pin`); the
/// rung puts it after the box (`super::ld` orders the outputs that read it after the box's).
pub(super) fn side_output(p: &Power, e: ElemId, pin: &str) -> R<Item> {
    let node = p.g.get(e).node;
    let name = field(p, e, pin)?;
    Ok(Item {
        key: Key::Pin(e, pin.to_owned()),
        element: Element {
            origin: origin(node),
            kind: ElementKind::Contact {
                var: Located {
                    value: name.into(),
                    origin: origin(node),
                },
                negated: false,
                edge: None,
            },
        },
    })
}

/// `instance.pin`: the field that holds output `pin` of function block `e`.
fn field(p: &Power, e: ElemId, pin: &str) -> R<String> {
    let node = p.g.get(e).node;
    let here = p.at(e);
    let raw = super::xml::attr(node, "instanceName", &here)?;
    let instance = super::xml::identifier(raw, "instance", node, &here)?;
    Ok(format!("{instance}.{pin}"))
}

/// The rules of blocks the power walk calls ([`Power::new`]).
pub(super) const BLOCKS: Blocks = Blocks {
    power_out,
    reads_side,
    side_output,
};

/// The series out of block `e`'s power output (`pin`: the output asked for).
pub(super) fn power_out(p: &mut Power, e: ElemId, pin: Option<&str>) -> R<Path> {
    let el = p.g.get(e);
    let node = el.node;
    let here = p.at(e);
    let ty = super::xml::attr(node, "typeName", &here)?;
    if super::ld_logic::is_logic(ty) {
        return super::ld_logic::power_out(p, e, ty);
    }
    let Some(spec) = Spec::of(ty) else {
        return Err(error(
            origin(node),
            &here,
            format!("block {ty} (localId {}) is not supported in an LD body yet (supported: {SUPPORTED})", el.local_id),
        ));
    };
    let (power_in, data, power_out, result) = spec.pins();
    let pin_names: Vec<&str> = el.inputs.iter().filter_map(|p| p.name).collect();
    for name in &pin_names {
        if *name != power_in && !data.contains(name) && !spec.extends(name) {
            return Err(error(
                origin(node),
                &here,
                format!("{ty} (localId {}) has the input `{name}`, which plc-deps does not support here (inputs: {power_in}, {})", el.local_id, data.join(", ")),
            ));
        }
    }
    qualified_pins(p, e, &spec, ty)?;
    // Every wired output is the power output, the result, or an output of an instance.
    for &(c, _, out_pin) in &p.g.consumers[e.0 as usize] {
        if reads_side(p, e, out_pin) {
            continue;
        }
        let first = if result.is_some() { "OUT" } else { power_out };
        let name = out_pin.unwrap_or(first);
        if name != power_out && Some(name) != result {
            return Err(error(
                origin(p.g.get(c).node),
                &p.at(c),
                format!("output `{name}` of {ty} (localId {}) is wired to localId {}: only {power_out} can be wired in LD yet", el.local_id, p.g.get(c).local_id),
            ));
        }
    }
    if let Some(asked) = pin {
        if asked != power_out {
            return Err(error(
                origin(node),
                &here,
                format!("output `{asked}` of {ty} (localId {}) feeds power to an element; only {power_out} can", el.local_id),
            ));
        }
    }
    let kinds = box_kinds(p, e, &spec, ty)?;
    let k = el.inputs.iter().position(|x| x.name == Some(power_in));
    let mut path = match k {
        Some(k) if !el.inputs[k].sources.is_empty() => p.input(e, k)?,
        _ if power_in == "EN" => Vec::new(),
        _ => {
            return Err(error(
                origin(node),
                &here,
                format!(
                    "input {power_in} of {ty} (localId {}) is not connected",
                    el.local_id
                ),
            ))
        }
    };
    path.extend(kinds.into_iter().map(|kind| Item {
        key: Key::Elem(e),
        element: Element {
            origin: origin(node),
            kind,
        },
    }));
    Ok(path)
}

/// The elements of block `e`: one, or for an extensible block with `IN3` … one per step.
fn box_kinds(p: &mut Power, e: ElemId, spec: &Spec, ty: &str) -> R<Vec<ElementKind<'static>>> {
    let extra = extended_pins(p, e, spec);
    match *spec {
        Spec::Compare(op) if !extra.is_empty() => {
            // IN1 op IN2 AND IN2 op IN3 …: a series of compares (IEC 61131-3 Table 31).
            let mut pins = vec!["IN1".to_string(), "IN2".to_string()];
            pins.extend(extra);
            let mut ops = Vec::with_capacity(pins.len());
            for x in &pins {
                ops.push(operand(p, e, x, ty)?);
            }
            Ok(ops
                .windows(2)
                .map(|w| {
                    ElementKind::Compare(Box::new(Compare {
                        op,
                        a: w[0].clone(),
                        b: w[1].clone(),
                    }))
                })
                .collect())
        }
        Spec::Arith(op) if !extra.is_empty() => {
            // OUT := IN1 op IN2 op IN3 …, left to right: OUT := IN1 op IN2, then OUT := OUT op IN3 …
            let out = result(p, e, ty)?;
            let mut kinds = vec![ElementKind::Arith(Box::new(Arith {
                op,
                a: operand(p, e, "IN1", ty)?,
                b: operand(p, e, "IN2", ty)?,
                out: out.clone(),
            }))];
            for x in &extra {
                let b = operand(p, e, x, ty)?;
                if matches!(&b.value, Scalar::Str(v) if v == &out.value) {
                    let el = p.g.get(e);
                    return Err(error(
                        b.origin,
                        &p.at(e),
                        format!("input {x} of {ty} (localId {}) reads `{}`, which its OUT writes: plc-deps computes an extensible {ty} step by step in OUT, so it cannot read OUT after IN2", el.local_id, out.value),
                    ));
                }
                kinds.push(ElementKind::Arith(Box::new(Arith {
                    op,
                    a: Located {
                        value: Scalar::Str(out.value.clone()),
                        origin: out.origin,
                    },
                    b,
                    out: out.clone(),
                })));
            }
            Ok(kinds)
        }
        _ => Ok(vec![box_kind(p, e, spec, ty)?]),
    }
}

/// The inputs `IN3`, `IN4` … of extensible block `e`, in order; an empty list for others.
fn extended_pins(p: &Power, e: ElemId, spec: &Spec) -> Vec<String> {
    let names: Vec<&str> = p.g.get(e).inputs.iter().filter_map(|x| x.name).collect();
    (spec.first_extension()..)
        .map(|k| format!("IN{k}"))
        .take_while(|n| spec.extends(n) && names.contains(&n.as_str()))
        .collect()
}

fn box_kind(p: &mut Power, e: ElemId, spec: &Spec, ty: &str) -> R<ElementKind<'static>> {
    let node = p.g.get(e).node;
    let here = p.at(e);
    let instance = || -> R<Name<'static>> {
        let raw = super::xml::attr(node, "instanceName", &here)?;
        let n = super::xml::identifier(raw, "instance", node, &here)?;
        Ok(Located {
            value: n.into(),
            origin: origin(node),
        })
    };
    Ok(match *spec {
        Spec::Timer(kind) => ElementKind::Timer(Box::new(Timer {
            kind,
            instance: instance()?,
            pt: operand(p, e, "PT", ty)?,
        })),
        Spec::Counter { down } => ElementKind::Counter(Box::new(Counter {
            down,
            instance: instance()?,
            pv: operand(p, e, "PV", ty)?,
            aux: operand(p, e, if down { "LD" } else { "R" }, ty)?,
        })),
        Spec::Bistable(kind) => ElementKind::Bistable(Box::new(Bistable {
            kind,
            instance: instance()?,
            reset: operand(
                p,
                e,
                if kind == BistableKind::SetDominant {
                    "R"
                } else {
                    "R1"
                },
                ty,
            )?,
        })),
        Spec::Trigger(kind) => ElementKind::Trigger {
            kind,
            instance: instance()?,
        },
        Spec::Ctud => ElementKind::Ctud(Box::new(Ctud {
            instance: instance()?,
            cd: operand(p, e, "CD", ty)?,
            reset: operand(p, e, "R", ty)?,
            load: operand(p, e, "LD", ty)?,
            pv: operand(p, e, "PV", ty)?,
        })),
        Spec::Arith(op) => ElementKind::Arith(Box::new(Arith {
            op,
            a: operand(p, e, "IN1", ty)?,
            b: operand(p, e, "IN2", ty)?,
            out: result(p, e, ty)?,
        })),
        Spec::Move => ElementKind::Move(Box::new(Move {
            from: operand(p, e, "IN", ty)?,
            to: result(p, e, ty)?,
        })),
        Spec::Compare(op) => ElementKind::Compare(Box::new(Compare {
            op,
            a: operand(p, e, "IN1", ty)?,
            b: operand(p, e, "IN2", ty)?,
        })),
        Spec::Function(func) => {
            let mut args = Vec::new();
            for pin in spec.pins().1 {
                args.push(operand(p, e, pin, ty)?);
            }
            for pin in extended_pins(p, e, spec) {
                args.push(operand(p, e, &pin, ty)?);
            }
            ElementKind::Function(Box::new(FunctionCall {
                func,
                args,
                out: result(p, e, ty)?,
            }))
        }
    })
}

/// The operand feeding data pin `pin` of block `e`: an inVariable (a variable or a constant), or
/// a single contact on the rail (its variable), or the rail itself (TRUE).
fn operand(p: &mut Power, e: ElemId, pin: &str, ty: &str) -> R<Operand<'static>> {
    let el = p.g.get(e);
    let here = p.at(e);
    // An unconnected (or unlisted) input of an instance whose declaration gives it a value
    // reads that value (IEC 61131-3 6.5.1.4, `T0 : TON := (PT := T#1s)`).
    let listed = el.inputs.iter().find(|x| x.name == Some(pin));
    if listed.is_none_or(|x| x.sources.is_empty()) {
        let inst = el
            .node
            .attribute("instanceName")
            .map(str::to_ascii_lowercase);
        let init = inst
            .and_then(|i| p.inits.get(&i))
            .and_then(|m| m.iter().find(|(name, _, _)| name.eq_ignore_ascii_case(pin)));
        if let Some((_, value, at)) = init {
            return Ok(Located {
                value: value.clone(),
                origin: *at,
            });
        }
    }
    let Some(input) = el.inputs.iter().find(|x| x.name == Some(pin)) else {
        return Err(error(
            origin(el.node),
            &here,
            format!("{ty} (localId {}) has no input {pin}", el.local_id),
        ));
    };
    // An unconnected input of a function block keeps the instance's value, which nothing else
    // in an LD body can set: its initial value (IEC 61131-3 2.5.2.1), FALSE or 0.
    if input.sources.is_empty() && spec_of(p, e).is_some_and(|s| s.is_instance()) {
        if let Some(value) = unconnected_default(pin) {
            return Ok(Located {
                value,
                origin: origin(input.node),
            });
        }
    }
    let simple = match input.sources.as_slice() {
        [s] => {
            let src = p.g.get(s.elem);
            src.tag != "contact"
                || (src.node.attribute("negated").is_none_or(|n| n == "false")
                    && src.node.attribute("edge").is_none_or(|n| n == "none")
                    && p.input(s.elem, 0)?.is_empty())
        }
        _ => false,
    };
    if !simple && !input.sources.is_empty() && unconnected_default(pin) == Some(Scalar::Bool(false))
    {
        return fed_by_network(p, e, pin, ty);
    }
    let [s] = input.sources.as_slice() else {
        return Err(error(
            origin(input.node),
            &here,
            format!(
                "input {pin} of {ty} (localId {}) needs exactly one connection, found {}",
                el.local_id,
                input.sources.len()
            ),
        ));
    };
    let src = p.g.get(s.elem);
    let value = match src.tag {
        "inVariable" => {
            let text = p.expression(s.elem)?;
            match super::interface::literal(&text) {
                // IEC 61131-3 6.3.2: `0` and `1` are BOOL literals too.
                Some(Scalar::Number(n)) if unconnected_default(pin) == Some(Scalar::Bool(false)) && (n.as_u64() == Some(0) || n.as_u64() == Some(1)) => {
                    Scalar::Bool(n.as_u64() == Some(1))
                }
                Some(v) => v,
                None => Scalar::Str(variable_ref(&text, src.node, &p.at(s.elem))?.into()),
            }
        }
        "leftPowerRail" => Scalar::Bool(true),
        "block" if reads_side(p, s.elem, s.pin) => {
            Scalar::Str(field(p, s.elem, s.pin.unwrap_or(""))?.into())
        }
        "contact"
            if src.node.attribute("negated").is_none_or(|n| n == "false")
                && src.node.attribute("edge").is_none_or(|n| n == "none")
                && p.input(s.elem, 0)?.is_empty() =>
        {
            Scalar::Str(p.variable(s.elem)?.value)
        }
        other => {
            return Err(error(
                s.origin,
                &here,
                format!("input {pin} of {ty} (localId {}) is fed by a {other} (localId {}): only a variable, a constant or a single contact on the rail can feed it in LD yet", el.local_id, src.local_id),
            ))
        }
    };
    Ok(Located {
        value,
        origin: s.origin,
    })
}

/// Negated and edge-qualified input pins: a rising edge on the count input of a counter (`CU`,
/// `CD` of CTU, CTD, CTUD) is what the counter detects anyway (an `R_TRIG` in front of it
/// rises in the same scans as its input), so it is read as the plain pin; any other is an error.
fn qualified_pins(p: &Power, e: ElemId, spec: &Spec, ty: &str) -> R<()> {
    let el = p.g.get(e);
    for pin in &el.inputs {
        let name = pin.name.unwrap_or("");
        let negated = pin.node.attribute("negated").is_some_and(|x| x == "true");
        let edge = pin.node.attribute("edge").filter(|x| *x != "none");
        let counts =
            matches!(spec, Spec::Counter { .. } | Spec::Ctud) && matches!(name, "CU" | "CD");
        if negated || (edge.is_some() && !(counts && edge == Some("rising"))) {
            return Err(error(
                origin(pin.node),
                &p.at(e),
                format!("input {name} of {ty} (localId {}) is {}: plc-deps reads negated and edge-qualified pins in LD only as a rising edge on CU or CD of a counter", el.local_id, if negated { "negated".to_string() } else { format!("edge-qualified ({})", edge.unwrap_or("")) }),
            ));
        }
    }
    Ok(())
}

/// A BOOL data pin fed by several wires (their OR) or by a contact network: the network is
/// written, earlier in the same rung, into the BOOL `instance__pin`, which the box reads.
fn fed_by_network(p: &mut Power, e: ElemId, pin: &str, ty: &str) -> R<Operand<'static>> {
    let el = p.g.get(e);
    let here = p.at(e);
    let k = el
        .inputs
        .iter()
        .position(|x| x.name == Some(pin))
        .unwrap_or(0);
    let at = origin(el.inputs[k].node);
    let mut path = p.input(e, k)?;
    if let Some(bad) = path.iter().find(|x| !x.element.kind.is_condition()) {
        return Err(error(
            bad.element.origin,
            &here,
            format!("input {pin} of {ty} (localId {}) is fed through an output or a box; plc-deps reads a data pin fed by contacts, compares and their ORs only", el.local_id),
        ));
    }
    let raw = super::xml::attr(el.node, "instanceName", &here)?;
    let instance = super::xml::identifier(raw, "instance", el.node, &here)?;
    let name = format!("{instance}__{pin}");
    let located = |v: &str| Located {
        value: std::borrow::Cow::Owned(v.to_owned()),
        origin: at,
    };
    p.vars.push(plc_syntax::Var {
        origin: at,
        name: located(&name),
        ty: located("BOOL"),
        class: Located {
            value: plc_syntax::VarClass::Memory,
            origin: at,
        },
        init: None,
        problem: None,
    });
    path.push(Item {
        key: Key::Feed(e, pin.to_owned()),
        element: Element {
            origin: at,
            kind: ElementKind::Coil {
                var: located(&name),
                negated: false,
            },
        },
    });
    p.feeds.push((e, path));
    Ok(Located {
        value: Scalar::Str(name.into()),
        origin: at,
    })
}

fn spec_of(p: &Power, e: ElemId) -> Option<Spec> {
    p.g.get(e).node.attribute("typeName").and_then(Spec::of)
}

/// The initial value of a function block's data input `pin` (BOOL FALSE, PV 0); `None` for PT,
/// which has no useful default and stays an error when unconnected.
fn unconnected_default(pin: &str) -> Option<Scalar<'static>> {
    match pin {
        "R" | "R1" | "LD" | "CD" => Some(Scalar::Bool(false)),
        "PV" => Some(Scalar::Number(0.into())),
        _ => None,
    }
}

/// The out variable written by the result (`OUT`) of block `e`: exactly one.
fn result(p: &Power, e: ElemId, ty: &str) -> R<Name<'static>> {
    let el = p.g.get(e);
    let outs: Vec<ElemId> = p.g.consumers[e.0 as usize]
        .iter()
        .filter(|(_, _, pin)| pin.is_none_or(|x| x == "OUT"))
        .map(|&(c, _, _)| c)
        .collect();
    match outs.as_slice() {
        [c] if p.g.get(*c).tag == "outVariable" => p.variable(*c),
        _ => Err(error(
            origin(el.node),
            &p.at(e),
            format!("output OUT of {ty} (localId {}) must be wired to exactly one outVariable, found {} connections", el.local_id, outs.len()),
        )),
    }
}
