//! Blocks of FBD and LD bodies whose op the model lacks under the name the file gives: the type
//! conversions between types the reader maps onto the model's, and black boxes for the rest
//! (IEC 61131-3 2.5.1.5 functions the model lacks, user functions of the project, function
//! blocks of an editor's library that the file does not define).
//!
//! A conversion `A_TO_B` (IEC 61131-3 2.5.1.5.1) between types the reader maps onto the
//! model's (docs/plcopen.md *Elementary types*) becomes, in place and keeping the block's id,
//! the model's conversion of the mapped types ([`standard_function`]: `SINT_TO_REAL` is
//! `INT_TO_REAL`, computed by `run`). The standard functions the model has under their own
//! names (SQRT, MUX, INT_TO_REAL, …) never come here. Any other block the model lacks becomes a call of a stand-in function block type (reading its inputs,
//! writing its outputs with their own values, [`super::textual::stand_in`]) on an instance
//! `<op>__<localId>` added to the POU: the analysis sees exactly the block's inputs read and
//! its outputs written, and `run` leaves the outputs at their initial values (a note names every
//! such block). Its pins' types come from the function's declaration (a user function), from
//! the conversion's name, or else from what is wired to each pin (the variable, constant or
//! block output feeding an input; the variables an output writes, or the type of its first
//! input for SHL, SHR, ROL, ROR, MUX and MOVE-like ops); an input whose type cannot be told is
//! an error naming it; so is an output that feeds something whose type cannot be told; an
//! output that feeds nothing is read as BOOL, and the black box's note names it.
//!
//! Invariants: a stand-in type is named after the op, with `__2`, `__3` … for a second
//! signature of the same op (`__1`, `__2` … for a built-in op such as `SUB` of a DT and a TIME); every black box of a body is in [`Notes::black_boxes`].
//!
//! Deliberately not here: computing what the black boxes compute (`run` does not).

use super::block_types::{BlackBox, Ctx, Sig};
use super::wiring::{ElemId, Graph};
use super::xml::{error, R};
use plc_diag::Origin;
use plc_fbd::OpKind;
use plc_model::Function;
use plc_syntax::fbd::{Block, Connection, Input, Inputs};
use plc_syntax::Scalar;
use std::borrow::Cow;

/// The model type an IEC elementary type name is read as (`None`: not elementary).
fn model(t: &str) -> Option<String> {
    super::elementary::model_type_of(t).map(str::to_owned)
}

/// The standard function blocks' outputs (IEC 61131-3 2.5.2.3).
fn standard_outputs(fb: &str) -> Option<&'static [(&'static str, &'static str)]> {
    Some(match fb {
        "TON" | "TOF" | "TP" => &[("Q", "BOOL"), ("ET", "TIME")],
        "CTU" | "CTD" => &[("Q", "BOOL"), ("CV", "INT")],
        "CTUD" => &[("QU", "BOOL"), ("QD", "BOOL"), ("CV", "INT")],
        "SR" | "RS" => &[("Q1", "BOOL")],
        "R_TRIG" | "F_TRIG" => &[("Q", "BOOL")],
        _ => return None,
    })
}

/// The BOOL inputs of the model's blocks (IEC 61131-3 2.5.1.5, 2.5.2.3).
fn standard_bool_input(op: &str, pin: &str) -> bool {
    match op {
        "AND" | "OR" | "XOR" | "NOT" => true,
        "SEL" => pin == "G",
        "TON" | "TOF" | "TP" => pin == "IN",
        "CTU" | "CTD" | "CTUD" => matches!(pin, "CU" | "CD" | "R" | "LD"),
        "SR" | "RS" => matches!(pin, "S1" | "R" | "S" | "R1"),
        "R_TRIG" | "F_TRIG" => pin == "CLK",
        _ => pin == "EN",
    }
}

/// True for the standard function blocks the model has.
pub(super) fn is_standard_fb(ty: &str) -> bool {
    standard_outputs(ty).is_some()
}

impl Ctx {
    /// The members of instance `inst`'s initial value that are inputs of its type `ty`, under
    /// the inputs' own names (`pt` → `PT`), with their values; the others are not inputs.
    pub(super) fn init_inputs(
        &self,
        inst: &str,
        ty: &str,
    ) -> Vec<(String, Scalar<'static>, Origin)> {
        let Some(members) = self.inits.get(&inst.to_ascii_lowercase()) else {
            return Vec::new();
        };
        members
            .iter()
            .filter_map(|(m, v, at)| Some((self.input_pin(ty, m)?, v.clone(), *at)))
            .collect()
    }

    /// The input of function block type `ty` named `member` in any case, under its own name.
    pub(super) fn input_pin(&self, ty: &str, member: &str) -> Option<String> {
        if is_standard_fb(ty) {
            let upper = member.to_ascii_uppercase();
            return self.input_type(ty, &upper).map(|_| upper);
        }
        self.fb_inputs
            .get(ty)?
            .iter()
            .find(|(n, _)| n.eq_ignore_ascii_case(member))
            .map(|(n, _)| n.clone())
    }

    /// The function block type instance `inst` is declared with, if it is one.
    pub(super) fn fb_type_of(&self, inst: &str) -> Option<String> {
        let t = self.vars.get(&inst.to_ascii_lowercase())?;
        (is_standard_fb(t) || self.fbs.contains_key(t)).then(|| t.clone())
    }

    /// The type of input `pin` of a block `op`, where it is known.
    pub(super) fn input_type(&self, op: &str, pin: &str) -> Option<String> {
        if standard_bool_input(op, pin) {
            return Some("BOOL".to_owned());
        }
        match (op, pin) {
            ("TON" | "TOF" | "TP", "PT") => return Some("TIME".to_owned()),
            ("CTU" | "CTD" | "CTUD", "PV") => return Some("INT".to_owned()),
            _ => {}
        }
        let sig = self
            .fb_inputs
            .get(op)
            .or_else(|| self.functions.get(op).map(|s| &s.inputs))?;
        sig.iter().find(|(n, _)| n == pin).map(|(_, t)| t.clone())
    }

    /// The type of the variable or field `name` (`T1.Q`).
    fn var_type(&self, name: &str) -> Option<String> {
        let mut parts = name.split('.');
        let mut ty = self.vars.get(&parts.next()?.to_ascii_lowercase())?.clone();
        for f in parts {
            let outs: Vec<(String, String)> = match standard_outputs(&ty) {
                Some(o) => o
                    .iter()
                    .map(|(a, b)| (a.to_string(), b.to_string()))
                    .collect(),
                None => self.fbs.get(&ty)?.clone(),
            };
            ty = outs.into_iter().find(|(n, _)| n.eq_ignore_ascii_case(f))?.1;
        }
        Some(ty)
    }

    fn constant_type(v: &Scalar) -> Option<String> {
        Some(
            match v {
                Scalar::Bool(_) => "BOOL",
                Scalar::Number(n) if n.is_f64() => "REAL",
                Scalar::Number(n) => match n.as_i64() {
                    Some(i) if i16::try_from(i).is_ok() => "INT",
                    _ => "DINT",
                },
                Scalar::Str(s) if plc_syntax::is_time_literal(s) => "TIME",
                Scalar::Str(_) => "DINT",
                _ => return None,
            }
            .to_owned(),
        )
    }
}

/// Types what feeds the pins of one body.
pub(super) struct Typer<'c, 'g, 'a, 'i> {
    pub ctx: &'c Ctx,
    pub g: &'g Graph<'a, 'i>,
}

impl Typer<'_, '_, '_, '_> {
    /// The type of what input `i` reads (an arc from a block the reader added is BOOL).
    pub(super) fn input(&self, i: &Input, depth: u32) -> Option<String> {
        match &i.from {
            Connection::Variable(v) => self.ctx.var_type(v),
            Connection::Constant(c) => Ctx::constant_type(c),
            Connection::Arc { block, pin } => {
                let pin = pin
                    .as_ref()
                    .and_then(|p| p.as_ref().ok())
                    .map(|p| p.as_ref());
                match self.g.elems.iter().position(|e| e.local_id == *block) {
                    Some(e) => self.output(ElemId(e as u32), pin, depth),
                    None => Some("BOOL".to_owned()),
                }
            }
            Connection::Invalid(_) => None,
        }
    }

    /// The type output `pin` of element `e` is used as (`first`: it is the first output, which
    /// a connection without `formalParameter` means): the variable it writes, or the type of
    /// the other inputs of a block it feeds.
    fn consumer_type(&self, e: ElemId, pin: &str, first: bool) -> Option<String> {
        self.g.consumers[e.0 as usize]
            .iter()
            .filter(|(_, _, p)| p.map_or(first, |p| p == pin))
            .find_map(|&(c, k, _)| {
                let cel = self.g.get(c);
                if cel.tag != "block" {
                    let i = super::pins::block_input(cel.node, "", Origin::NONE).ok()?;
                    return self.input(&i, 0);
                }
                let op = cel.node.attribute("typeName").unwrap_or("");
                let pin = cel.inputs.get(k).and_then(|p| p.name).unwrap_or("");
                if let Some(t) = self.ctx.input_type(op, pin) {
                    return Some(t);
                }
                // Ops whose data inputs share one type: the others' type.
                let same = matches!(
                    op,
                    "ADD"
                        | "SUB"
                        | "MUL"
                        | "DIV"
                        | "MOD"
                        | "MOVE"
                        | "SEL"
                        | "MAX"
                        | "MIN"
                        | "LIMIT"
                        | "MUX"
                ) || plc_model::CmpOp::parse(op).is_some();
                if !same {
                    return None;
                }
                cel.inputs
                    .iter()
                    .enumerate()
                    .filter(|(j, p)| *j != k && !matches!(p.name, Some("EN" | "G" | "K")))
                    .find_map(|(_, p)| {
                        let s = p.sources.first()?;
                        self.output(s.elem, s.pin, 1)
                    })
            })
    }

    /// The type of output `pin` of element `e`.
    pub(super) fn output(&self, e: ElemId, pin: Option<&str>, depth: u32) -> Option<String> {
        let el = self.g.get(e);
        if depth > 32 {
            return None;
        }
        match el.tag {
            "inVariable" | "inOutVariable" => {
                let i = super::pins::block_input(el.node, "", Origin::NONE).ok()?;
                return self.input(&i, depth + 1);
            }
            "block" => {}
            _ => return Some("BOOL".to_owned()),
        }
        let ty = el.node.attribute("typeName")?;
        let pin = pin.filter(|p| !p.is_empty());
        if pin == Some("ENO") {
            return Some("BOOL".to_owned());
        }
        let first_in = || {
            el.inputs
                .iter()
                .filter(|p| !matches!(p.name, Some("EN" | "G" | "K" | "N")))
                .find_map(|p| {
                    let s = p.sources.first()?;
                    self.output(s.elem, s.pin, depth + 1)
                })
        };
        if let Some((_, to)) = conversion(ty) {
            return to;
        }
        if let Some(sig) = self.ctx.functions.get(ty) {
            return pick(&sig.outputs, pin);
        }
        if let Some(o) = standard_outputs(ty) {
            let o: Vec<(String, String)> = o
                .iter()
                .map(|(a, b)| (a.to_string(), b.to_string()))
                .collect();
            return pick(&o, pin);
        }
        if let Some(o) = self.ctx.fbs.get(ty) {
            return pick(o, pin);
        }
        match OpKind::parse(ty) {
            Some(OpKind::Compare(_)) => Some("BOOL".to_owned()),
            // BOOL, or a bit string's AND (bit by bit): the inputs' type.
            Some(OpKind::And | OpKind::Or | OpKind::Xor | OpKind::Not) => {
                first_in().or(Some("BOOL".to_owned()))
            }
            Some(_) => first_in(),
            None if matches!(ty, "SHL" | "SHR" | "ROL" | "ROR" | "MUX") => first_in(),
            None if ty.ends_with("_TO_STRING") || ty == "CONCAT" => Some("STRING".to_owned()),
            None => None,
        }
    }
}

/// The (name, type) pin `pin` of `pins` (`None` or empty: the first).
fn pick(pins: &[(String, String)], pin: Option<&str>) -> Option<String> {
    match pin.filter(|p| !p.is_empty()) {
        Some(p) => pins.iter().find(|(n, _)| n == p).map(|(_, t)| t.clone()),
        None => pins.first().map(|(_, t)| t.clone()),
    }
}

/// `A_TO_B` (and `TRUNC`, REAL to DINT): the model types of A and B, when they are elementary.
fn conversion(ty: &str) -> Option<(Option<String>, Option<String>)> {
    if ty == "TRUNC" {
        return Some((Some("REAL".into()), Some("DINT".into())));
    }
    let (a, b) = ty.split_once("_TO_")?;
    let (a, b) = (model(a), model(b));
    (a.is_some() && b.is_some()).then_some((a, b))
}

/// The standard function the model has for block type `ty`: by its name, or a conversion
/// `A_TO_B` between types the reader maps onto the model's (`SINT_TO_INT` is `INT_TO_INT`).
pub(super) fn standard_function(ty: &str) -> Option<Function> {
    if let Some(f) = Function::parse(ty) {
        return Some(f);
    }
    // Only numbers, bit strings, BOOL and TIME: a STRING or a date read as a number is not one.
    const NUMERIC: &[&str] = &[
        "BOOL", "SINT", "INT", "DINT", "LINT", "USINT", "UINT", "UDINT", "ULINT", "REAL", "LREAL",
        "BYTE", "WORD", "DWORD", "LWORD", "TIME",
    ];
    let (a, b) = ty.split_once("_TO_")?;
    if !NUMERIC.contains(&a) || !NUMERIC.contains(&b) {
        return None;
    }
    match conversion(ty)? {
        (Some(a), Some(b)) => Function::parse(&format!("{a}_TO_{b}")),
        _ => None,
    }
}

/// True for ADD or SUB of inputs of different types, or MUL or DIV of a TIME: the date and
/// time arithmetic of IEC 61131-3 Table 30 (`SUB(DT, TIME)`, `DIV(TIME, INT)` …), which the
/// model's arithmetic (one numeric type) lacks, so it is a black box.
pub(super) fn mixed_arithmetic(t: &Typer, ty: &str, b: &Block) -> bool {
    if !matches!(ty, "ADD" | "SUB" | "MUL" | "DIV") {
        return false;
    }
    let Some(Ok(Inputs::Named(ins))) = &b.inputs else {
        return false;
    };
    if matches!(ty, "MUL" | "DIV") {
        // MUL_TIME, DIV_TIME: a TIME by a number.
        return ins
            .iter()
            .any(|(_, i)| t.input(i, 0).as_deref() == Some("TIME"));
    }
    // A number literal takes the type of its use; a TIME literal is TIME.
    let types: Vec<String> = ins
        .iter()
        .filter(|(_, i)| !matches!(i.from, Connection::Constant(Scalar::Number(_))))
        .filter_map(|(_, i)| t.input(i, 0))
        .collect();
    types.windows(2).any(|w| w[0] != w[1])
}

/// The model's op for the typed TIME arithmetic `ty` of IEC 61131-3 Table 30 that is one TIME
/// operation: ADD_TIME and SUB_TIME (TIME, TIME → TIME).
fn time_arithmetic(ty: &str) -> Option<&'static str> {
    match ty {
        "ADD_TIME" => Some("ADD"),
        "SUB_TIME" => Some("SUB"),
        _ => None,
    }
}

/// True when the model or the project has op `ty` (nothing to do here).
pub(super) fn is_known(ctx: &Ctx, ty: &str) -> bool {
    OpKind::parse(ty).is_some() || ctx.fbs.contains_key(ty)
}

/// Rewrites block `b` (element `e`, op `ty`) that the model lacks: a conversion in place, or a
/// call of a black box on a new instance. Returns a variable to declare in the POU, with its
/// type: the new instance, or the result variable of a conversion from BOOL.
pub(super) fn rewrite(
    t: &Typer,
    e: ElemId,
    b: &mut Block<'static>,
    boxes: &mut Vec<BlackBox>,
    place: &str,
) -> R<Option<(String, String)>> {
    let el = t.g.get(e);
    let ty = el.node.attribute("typeName").unwrap_or("");
    let inputs = match b.inputs.take() {
        Some(Ok(Inputs::Named(v))) => v,
        _ => Vec::new(),
    };
    let at = b.origin;
    if let Some(op) = time_arithmetic(ty) {
        // ADD_TIME, SUB_TIME (IEC 61131-3 Table 30: TIME + TIME, TIME - TIME → TIME; matiec's
        // standard library): the model's ADD and SUB of TIME.
        b.op = Ok(Cow::Borrowed(op));
        b.inputs = Some(Ok(Inputs::Named(inputs)));
        return Ok(None);
    }
    if let Some(f) = standard_function(ty) {
        // A conversion between types the reader maps onto the model's: the model's own.
        b.op = Ok(Cow::Owned(f.name()));
        b.inputs = Some(Ok(Inputs::Named(inputs)));
        return Ok(None);
    }
    if let Some(f) = t.ctx.executed_functions.get(&ty.to_ascii_lowercase()) {
        // A function of the project whose calls are executed: a call of its body on an
        // instance of this block's own (super::user_functions).
        let inst = format!("{}__{}", f, el.local_id);
        let name = super::user_functions::type_name(f);
        b.op = Ok(Cow::Owned(name.clone()));
        b.instance = Some(Ok(Cow::Owned(inst.clone())));
        b.inputs = Some(Ok(Inputs::Named(inputs)));
        return Ok(Some((inst, name)));
    }
    // A black box: its name becomes a function block type's, so it must be an identifier.
    super::xml::identifier(ty, "block type", el.node, place)?;
    let declared = t.ctx.functions.get(ty).cloned();
    let conv = conversion(ty);
    let mut sig = Sig {
        inputs: Vec::new(),
        outputs: Vec::new(),
    };
    let mut guessed = Vec::new();
    for (pin, input) in &inputs {
        let from_decl = declared.as_ref().and_then(|d| {
            d.inputs
                .iter()
                .find(|(n, _)| n == pin.as_ref())
                .map(|(_, t)| t.clone())
        });
        let from_conv = conv.as_ref().and_then(|c| c.0.clone());
        let pty = from_decl.or(from_conv).or_else(|| t.input(input, 0));
        let Some(pty) = pty else {
            return Err(error(
                input.origin,
                place,
                format!("the type of input {pin} of {ty} (localId {}) cannot be told from what feeds it; plc-deps reads {ty} as a black box, whose pins need a type", el.local_id),
            ));
        };
        sig.inputs.push((pin.to_string(), pty));
    }
    for (k, (pin, pnode)) in el.outputs.iter().enumerate() {
        if *pin == "ENO" {
            continue;
        }
        let pname = if pin.is_empty() { "OUT" } else { pin };
        // A built-in op (date and time arithmetic) is typed by its use, anything else by its
        // declaration or inputs first.
        let pty = if OpKind::parse(ty).is_some() {
            t.consumer_type(e, pin, k == 0)
                .or_else(|| t.output(e, Some(pin), 0))
        } else {
            t.output(e, Some(pin), 0)
                .or_else(|| t.consumer_type(e, pin, k == 0))
        };
        // Nothing tells the type because the output feeds nothing (Beremiz's `csv_reload` ACK
        // left unwired): BOOL, which the black box's note says; nothing reads it, and what it
        // would hold is not computed anyway. An output that feeds something untyped stays an
        // error.
        let feeds_nothing = !t.g.consumers[e.0 as usize]
            .iter()
            .any(|(_, _, p)| p.map_or(k == 0, |p| p == *pin));
        let pty = match pty {
            Some(p) => p,
            None if feeds_nothing => {
                guessed.push(format!("{pname} (localId {})", el.local_id));
                "BOOL".to_owned()
            }
            None => {
                return Err(error(
                    super::xml::origin(*pnode),
                    place,
                    format!("the type of output {pname} of {ty} (localId {}) cannot be told from what it feeds; plc-deps reads {ty} as a black box, whose pins need a type", el.local_id),
                ))
            }
        };
        sig.outputs.push((pname.to_owned(), pty));
    }
    let name = stand_in_name(boxes, ty, &sig, at);
    if let Some(bb) = boxes.iter_mut().find(|x| x.name == name) {
        for g in guessed {
            if !bb.guessed.contains(&g) {
                bb.guessed.push(g);
            }
        }
    }
    let inst = match el.node.attribute("instanceName") {
        Some(i) => i.to_owned(),
        None => format!("{}__{}", ty, el.local_id),
    };
    if let Some(bb) = boxes.iter_mut().find(|x| x.name == name) {
        bb.sites.push(format!("{place} ({inst})"));
    }
    b.op = Ok(Cow::Owned(name.clone()));
    b.instance = Some(Ok(Cow::Owned(inst.clone())));
    b.inputs = Some(Ok(Inputs::Named(inputs)));
    Ok(el
        .node
        .attribute("instanceName")
        .is_none()
        .then_some((inst, name)))
}

/// The stand-in type for `op` with `sig` (made on first use).
fn stand_in_name(boxes: &mut Vec<BlackBox>, op: &str, sig: &Sig, at: Origin) -> String {
    if let Some(b) = boxes.iter().find(|b| b.op == op && &b.sig == sig) {
        return b.name.clone();
    }
    let k = boxes.iter().filter(|b| b.op == op).count();
    // A built-in op's name would call the op, so its black boxes are numbered from 1.
    let name = if k == 0 && OpKind::parse(op).is_none() {
        op.to_owned()
    } else {
        format!("{op}__{}", k + 1)
    };
    boxes.push(BlackBox {
        name: name.clone(),
        op: op.to_owned(),
        sig: sig.clone(),
        origin: at,
        sites: Vec::new(),
        guessed: Vec::new(),
    });
    name
}
