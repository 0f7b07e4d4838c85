//! SFC bodies made executable: the chart ([`super::sfc`]) LOWERED to ladder rungs of the
//! syntax's vocabulary, scan by scan as matiec's generated C runs it
//! (`stage4/generate_c/generate_c_sfc.cc`, `generate_c_sfc_c::visit(sequential_function_chart_c)`;
//! IEC 61131-3 3rd ed. 6.7.3–6.7.5), so that `run` (seq and par) and `c` execute it.
//!
//! Each scan, in this order (matiec's comments in quotes):
//! 1. "Calculate elapsed_time": `elapsed := now - last; last := now`. `now` is the elapsed time
//!    of a TON `sfc__clock` that runs from the first scan (virtual time: scan k at k × cycle,
//!    docs/scan.md), so the first scan's elapsed time is 0 (matiec: `__lasttick_time` is set at
//!    initialisation); it saturates after T#24d20h31m23s647ms, the largest TIME.
//! 2. "Steps initialization": for each step, `prev := X`; `IF X THEN T := T + elapsed`.
//! 3. "Actions initialization": each action's `state`, `set`, `reset` := FALSE; its set and
//!    reset remaining times (SD, DS, SL) count down by `elapsed`, and reaching 0 sets `set`
//!    (`reset`).
//! 4. "Transitions fire test", in matiec's transition list order (text order; a transition
//!    with a PRIORITY — Beremiz writes one for every `priority` attribute, 0 included — goes
//!    after every one whose priority is not greater, one without after all): a transition whose
//!    FROM steps are all active takes its condition's value (else FALSE); one with a PRIORITY
//!    that fires resets its FROM steps at once, so a later transition from the same step does not
//!    fire (selective divergence as matiec does it).
//! 5. "Transitions reset steps" (text order): a fired transition without PRIORITY resets its
//!    FROM steps. 6. "Transitions set steps": a fired transition sets its TO steps, `T := 0`.
//! 7. "Steps association" (steps in text order, each step's associations in order), with
//!    `active := X`, `activated := X AND NOT prev`, `desactivated := NOT X AND prev`; the target
//!    is the variable itself when the action's name is a variable, else the action's `state`:
//!    N: `IF active THEN target := 1`, `IF desactivated THEN target := 0`; S, R: `IF active THEN
//!    set (reset) := 1`; L: `IF active AND T < d THEN target := 1 ELSIF desactivated OR active THEN
//!    target := 0`; D: `IF active AND T >= d THEN 1 ELSIF desactivated THEN 0`; P, P1: `target :=
//!    activated`; P0: `target := desactivated`; SL: `IF activated THEN set := 1, reset remaining
//!    := d`; SD, DS: `IF activated THEN set remaining := d`; DS also `IF desactivated THEN set
//!    remaining := 0`. (So P on an initial step never fires on the first scan: its `prev` is
//!    already TRUE, as in matiec.) The indicator is ignored, as matiec does.
//! 8. "Actions state evaluation": `IF set THEN set remaining := 0, stored := 1`; `IF reset THEN
//!    reset remaining := 0, stored := 0`; `state := state OR stored`.
//! 9. "Actions execution": each variable used as an action: `IF reset THEN v := 0 ELSIF set THEN
//!    v := 1`; then each action in text order: `IF state THEN <body>`.
//!
//! Names: step `S`'s flag and elapsed time are the POU variables `S.X` (BOOL, TRUE initially
//! for an initial step) and `S.T` (TIME), which the conditions and action bodies read (and
//! which `run` shows); everything else is a compiler variable `sfc__…` (no IEC identifier has
//! a double `_`). Rungs: `P.sfc.clock.N`, `P.step.S.N` (step S's prologue and associations),
//! `P.tr.T.N` (transition `T<localId>`, or its name when it is a named transition), `P.act.A.N`
//! (action A's state and body), located at the element they come from.
//!
//! Invariant: a body is lowered whole or not at all ([`lower`] returns the reason and place of
//! what it cannot execute: an unknown qualifier, an action that is neither an action nor a BOOL
//! variable, what the ST lowering refuses in a condition or an action body).
//! Deliberately not here: macro steps, IL, FBD action bodies, function block instances in
//! transition conditions (refused by [`super::sfc`]).

use super::sfc::{Chart, Code};
use super::st_lower::Lower;
use super::st_scope::{Decl, Scope};
use super::xml::{origin, Tc6};
use crate::st;
use plc_diag::Origin;
use plc_model::{ArithOp, CmpOp, TimerKind, Type};
use plc_syntax::{
    Arith, Compare, Element, ElementKind, Located, Move, Name, Operand, Rung, Scalar, Timer, Var,
    VarClass,
};
use std::borrow::Cow;

/// What the lowering makes of a chart: its rungs and the variables it declares.
pub(super) struct Lowered {
    pub rungs: Vec<Rung<'static>>,
    pub vars: Vec<Var<'static>>,
}

type Refused = (Origin, String);

/// The largest TIME, the clock's preset.
const MAX_TIME: &str = "T#24d20h31m23s647ms";

fn nm(s: &str, at: Origin) -> Name<'static> {
    Located {
        value: Cow::Owned(s.to_owned()),
        origin: at,
    }
}

fn op(s: &str, at: Origin) -> Operand<'static> {
    Located {
        value: Scalar::Str(Cow::Owned(s.to_owned())),
        origin: at,
    }
}

fn contact(v: &str, negated: bool, at: Origin) -> ElementKind<'static> {
    ElementKind::Contact {
        var: nm(v, at),
        negated,
        edge: None,
    }
}

fn set(v: &str, at: Origin) -> ElementKind<'static> {
    ElementKind::Set(nm(v, at))
}

fn reset(v: &str, at: Origin) -> ElementKind<'static> {
    ElementKind::Reset(nm(v, at))
}

fn coil(v: &str, at: Origin) -> ElementKind<'static> {
    ElementKind::Coil {
        var: nm(v, at),
        negated: false,
    }
}

fn mov(from: Operand<'static>, to: &str, at: Origin) -> ElementKind<'static> {
    ElementKind::Move(Box::new(Move {
        from,
        to: nm(to, at),
    }))
}

fn cmp(op_: CmpOp, a: Operand<'static>, b: Operand<'static>) -> ElementKind<'static> {
    ElementKind::Compare(Box::new(Compare { op: op_, a, b }))
}

fn zero(at: Origin) -> Operand<'static> {
    op("T#0ms", at)
}

fn declare(vars: &mut Vec<Var<'static>>, name: &str, ty: &str, init: Option<bool>, at: Origin) {
    vars.push(Var {
        origin: at,
        name: nm(name, at),
        ty: nm(ty, at),
        class: Located {
            value: VarClass::Memory,
            origin: at,
        },
        init: init.map(|b| {
            Box::new(Located {
                value: Scalar::Bool(b),
                origin: at,
            })
        }),
        problem: None,
    });
}

/// One entry of matiec's action list: an action or a variable named as one.
struct Entry {
    name: String,
    /// The variable's declared name when the action's name is a variable.
    var: Option<String>,
    timed: bool,
    origin: Origin,
}

impl Entry {
    fn f(&self, field: &str) -> String {
        format!("sfc__{}__{field}", self.name)
    }
    /// What N, L, D, P… write: the variable, or the action's state.
    fn target(&self) -> String {
        self.var.clone().unwrap_or_else(|| self.f("state"))
    }
}

/// Lowers chart `c` of POU `pou`, whose names are `scope`.
pub(super) fn lower(
    tc6: Tc6,
    c: &Chart,
    pou: &str,
    scope: &Scope,
    inits: &super::block_types::Inits,
    notes: &mut super::xml::Notes,
    at: Origin,
) -> Result<Lowered, Refused> {
    if let Some(r) = &c.refused {
        return Err(r.clone());
    }
    // The names the conditions and actions see: the POU's, and each step's X and T.
    let mut sc = scope.clone();
    let mut vars = Vec::new();
    for s in &c.steps {
        for (f, ty) in [("X", "BOOL"), ("T", "TIME")] {
            let n = format!("{}.{f}", s.name);
            if sc.get(&n).is_some() {
                return Err((
                    s.origin,
                    format!("step `{}`: `{n}` is also a variable of the POU", s.name),
                ));
            }
            sc.declare(&n, ty);
            declare(&mut vars, &n, ty, (f == "X").then_some(s.initial), s.origin);
        }
        declare(&mut vars, &prev(&s.name), "BOOL", None, s.origin);
    }
    for t in &c.temps {
        sc.declare(t, "BOOL");
        declare(&mut vars, t, "BOOL", None, at);
    }
    // matiec's action list: the actions (text order), then the variables named as actions.
    let mut entries: Vec<Entry> = c
        .actions
        .iter()
        .map(|a| Entry {
            name: a.name.clone(),
            var: None,
            timed: false,
            origin: a.origin,
        })
        .collect();
    for s in &c.steps {
        for a in &s.assocs {
            let var = match sc.get(&a.action) {
                Some(Decl::Elementary { name, ty }) if ty == "BOOL" => Some(name.clone()),
                Some(_) => {
                    return Err((
                        a.origin,
                        format!(
                        "action `{}` is a variable that is not BOOL (matiec writes 0 or 1 to it)",
                        a.action
                    ),
                    ))
                }
                None => None,
            };
            let known = entries
                .iter()
                .position(|e| e.name.eq_ignore_ascii_case(&a.action));
            let k = match (known, var) {
                (Some(k), _) => k,
                (None, Some(v)) => {
                    entries.push(Entry {
                        name: a.action.clone(),
                        var: Some(v),
                        timed: false,
                        origin: a.origin,
                    });
                    entries.len() - 1
                }
                (None, None) => {
                    return Err((
                        a.origin,
                        format!(
                            "action `{}`, which is neither an action of the POU nor a variable",
                            a.action
                        ),
                    ))
                }
            };
            if matches!(a.qualifier.as_str(), "SL" | "SD" | "DS") {
                entries[k].timed = true;
            }
        }
    }
    // An action whose name is also a variable is the variable (matiec's `is_variable` first).
    for e in entries.iter_mut() {
        if e.var.is_none() {
            if let Some(Decl::Elementary { name, ty }) = sc.get(&e.name) {
                if ty == "BOOL" {
                    e.var = Some(name.clone());
                }
            }
        }
    }
    for e in &entries {
        let mut fields = vec!["set", "reset"];
        if e.var.is_none() {
            fields.extend(["state", "stored"]);
        }
        for f in fields {
            declare(&mut vars, &e.f(f), "BOOL", None, e.origin);
        }
        if e.timed {
            declare(&mut vars, &e.f("srt"), "TIME", None, e.origin);
            declare(&mut vars, &e.f("rrt"), "TIME", None, e.origin);
        }
    }
    for (i, _) in c.transitions.iter().enumerate() {
        declare(&mut vars, &fired(i), "BOOL", None, at);
    }
    declare(&mut vars, "sfc__clock", "TON", None, at);
    declare(&mut vars, "sfc__last", "TIME", None, at);
    declare(&mut vars, "sfc__el", "TIME", None, at);

    let mut l = Lower::new(&sc, pou);
    let fail = |l: &Lower, e: super::st_lower::Refusal| (l.origin(e.at), e.what);

    // 1. elapsed time
    l.unit_at(format!("{pou}.sfc.clock"), at);
    l.rung(vec![ElementKind::Timer(Box::new(Timer {
        kind: TimerKind::Ton,
        instance: nm("sfc__clock", at),
        pt: op(MAX_TIME, at),
    }))]);
    l.rung(vec![ElementKind::Arith(Box::new(Arith {
        op: ArithOp::Sub,
        a: op("sfc__clock.ET", at),
        b: op("sfc__last", at),
        out: nm("sfc__el", at),
    }))]);
    l.rung(vec![mov(op("sfc__clock.ET", at), "sfc__last", at)]);
    // 2. steps
    for s in &c.steps {
        let o = s.origin;
        l.unit_at(format!("{pou}.step.{}", s.name), o);
        let x = format!("{}.X", s.name);
        let t = format!("{}.T", s.name);
        l.rung(vec![contact(&x, false, o), coil(&prev(&s.name), o)]);
        l.rung(vec![
            contact(&x, false, o),
            ElementKind::Arith(Box::new(Arith {
                op: ArithOp::Add,
                a: op(&t, o),
                b: op("sfc__el", o),
                out: nm(&t, o),
            })),
        ]);
    }
    // 3. actions
    for e in &entries {
        let o = e.origin;
        l.unit_at(format!("{pou}.act.{}", e.name), o);
        if e.var.is_none() {
            l.rung(vec![reset(&e.f("state"), o)]);
        }
        l.rung(vec![reset(&e.f("set"), o)]);
        l.rung(vec![reset(&e.f("reset"), o)]);
        if e.timed {
            for (rt, flag) in [("srt", "set"), ("rrt", "reset")] {
                let (rt, flag) = (e.f(rt), e.f(flag));
                let tmp = l.bool_temp_var();
                l.rung(vec![cmp(CmpOp::Gt, op(&rt, o), zero(o)), coil(&tmp, o)]);
                l.rung(vec![
                    contact(&tmp, false, o),
                    ElementKind::Arith(Box::new(Arith {
                        op: ArithOp::Sub,
                        a: op(&rt, o),
                        b: op("sfc__el", o),
                        out: nm(&rt, o),
                    })),
                ]);
                l.rung(vec![
                    contact(&tmp, false, o),
                    cmp(CmpOp::Le, op(&rt, o), zero(o)),
                    set(&flag, o),
                ]);
                l.rung(vec![
                    contact(&tmp, false, o),
                    cmp(CmpOp::Le, op(&rt, o), zero(o)),
                    mov(zero(o), &rt, o),
                ]);
            }
        }
    }
    // 4. transition tests, in matiec's list order
    let mut order: Vec<(usize, i64)> = Vec::new();
    for (i, t) in c.transitions.iter().enumerate() {
        match t.priority {
            Some(p) => {
                let at = order
                    .iter()
                    .position(|&(_, q)| q > p)
                    .unwrap_or(order.len());
                order.insert(at, (i, p));
            }
            None => order.push((i, 0)),
        }
    }
    for &(i, _) in &order {
        let t = &c.transitions[i];
        let o = t.origin;
        l.unit_at(format!("{pou}.tr.{}", t.unit), o);
        l.rung(vec![reset(&fired(i), o)]);
        let skip = l.new_label();
        let not_all: Vec<ElementKind> = if t.from.len() == 1 {
            vec![contact(&format!("{}.X", t.from[0]), true, o)]
        } else {
            vec![ElementKind::Or(
                t.from
                    .iter()
                    .map(|s| {
                        vec![Element {
                            origin: o,
                            kind: contact(&format!("{s}.X"), true, o),
                        }]
                    })
                    .collect(),
            )]
        };
        let mut ld = not_all;
        ld.push(ElementKind::Jmp(nm(&skip, o)));
        l.rung(ld);
        let Code::Expr { text, node } = &t.cond else {
            return Err((o, "a transition condition that is not an expression".into()));
        };
        let src = node.document().input_text();
        let map = if node.is_text() {
            super::st_body::file_offsets(src, node.range().start, node.text().unwrap_or(""))
        } else {
            None
        };
        l.text(map, origin(*node));
        let text = text.trim_end();
        let text = text.strip_suffix(';').unwrap_or(text);
        let e = st::parser::expression(text).map_err(|e| {
            (
                l.origin(e.at),
                format!("ST syntax error in a transition condition: {}", e.message),
            )
        })?;
        let mut ld = l.condition(&e).map_err(|e| fail(&l, e))?;
        ld.push(coil(&fired(i), o));
        l.rung(ld);
        if t.priority.is_some() {
            for s in &t.from {
                l.rung(vec![
                    contact(&fired(i), false, o),
                    reset(&format!("{s}.X"), o),
                ]);
            }
        }
        l.put_label(skip);
    }
    // 5. and 6. reset and set steps, in text order
    for (i, t) in c.transitions.iter().enumerate() {
        if t.priority.is_some() {
            continue;
        }
        l.unit_at(format!("{pou}.tr.{}.reset", t.unit), t.origin);
        for s in &t.from {
            let o = t.origin;
            l.rung(vec![
                contact(&fired(i), false, o),
                reset(&format!("{s}.X"), o),
            ]);
        }
    }
    for (i, t) in c.transitions.iter().enumerate() {
        let o = t.origin;
        l.unit_at(format!("{pou}.tr.{}.set", t.unit), o);
        for s in &t.to {
            l.rung(vec![
                contact(&fired(i), false, o),
                set(&format!("{s}.X"), o),
            ]);
            l.rung(vec![
                contact(&fired(i), false, o),
                mov(zero(o), &format!("{s}.T"), o),
            ]);
        }
    }
    // 7. associations
    for s in &c.steps {
        if s.assocs.is_empty() {
            continue;
        }
        l.unit_at(format!("{pou}.step.{}.assoc", s.name), s.origin);
        let x = format!("{}.X", s.name);
        let p = prev(&s.name);
        let t = format!("{}.T", s.name);
        for a in &s.assocs {
            let o = a.origin;
            let Some(e) = entries
                .iter()
                .find(|e| e.name.eq_ignore_ascii_case(&a.action))
            else {
                continue;
            };
            let target = e.target();
            let active = || contact(&x, false, o);
            let activated = || vec![contact(&x, false, o), contact(&p, true, o)];
            let desactivated = || vec![contact(&x, true, o), contact(&p, false, o)];
            let duration = |l: &mut Lower| -> Result<Operand<'static>, Refused> {
                let Some(d) = &a.duration else {
                    return Err((o, format!("qualifier {} without a duration", a.qualifier)));
                };
                let e = st::parser::expression(d).map_err(|e| {
                    (
                        o,
                        format!("the duration `{d}`: ST syntax error: {}", e.message),
                    )
                })?;
                l.operand_of(&e, Type::Time).map_err(|e| (o, e.what))
            };
            let q = a.qualifier.to_ascii_uppercase();
            match q.as_str() {
                "N" => {
                    l.rung(vec![active(), set(&target, o)]);
                    let mut d = desactivated();
                    d.push(reset(&target, o));
                    l.rung(d);
                }
                "S" => l.rung(vec![active(), set(&e.f("set"), o)]),
                "R" => l.rung(vec![active(), set(&e.f("reset"), o)]),
                "L" | "D" => {
                    let d = duration(&mut l)?;
                    let tmp = l.bool_temp_var();
                    let c = if q == "L" { CmpOp::Lt } else { CmpOp::Ge };
                    l.rung(vec![active(), cmp(c, op(&t, o), d), coil(&tmp, o)]);
                    l.rung(vec![contact(&tmp, false, o), set(&target, o)]);
                    if q == "L" {
                        l.rung(vec![
                            contact(&tmp, true, o),
                            ElementKind::Or(vec![
                                desactivated()
                                    .into_iter()
                                    .map(|kind| Element { origin: o, kind })
                                    .collect(),
                                vec![Element {
                                    origin: o,
                                    kind: active(),
                                }],
                            ]),
                            reset(&target, o),
                        ]);
                    } else {
                        let mut ld = vec![contact(&tmp, true, o)];
                        ld.extend(desactivated());
                        ld.push(reset(&target, o));
                        l.rung(ld);
                    }
                }
                "P" | "P1" | "P0" => {
                    let mut ld = if q == "P0" {
                        desactivated()
                    } else {
                        activated()
                    };
                    ld.push(coil(&target, o));
                    l.rung(ld);
                }
                "SL" => {
                    let d = duration(&mut l)?;
                    let mut ld = activated();
                    ld.push(set(&e.f("set"), o));
                    l.rung(ld);
                    let mut ld = activated();
                    ld.push(mov(d, &e.f("rrt"), o));
                    l.rung(ld);
                }
                "SD" | "DS" => {
                    let d = duration(&mut l)?;
                    let mut ld = activated();
                    ld.push(mov(d, &e.f("srt"), o));
                    l.rung(ld);
                    if q == "DS" {
                        let mut ld = desactivated();
                        ld.push(mov(zero(o), &e.f("srt"), o));
                        l.rung(ld);
                    }
                }
                other => return Err((o, format!("the action qualifier `{other}`"))),
            }
        }
    }
    // 8. action states
    for e in &entries {
        let o = e.origin;
        l.unit_at(format!("{pou}.act.{}.state", e.name), o);
        let (s, r) = (e.f("set"), e.f("reset"));
        if e.timed {
            l.rung(vec![contact(&s, false, o), mov(zero(o), &e.f("srt"), o)]);
            l.rung(vec![contact(&r, false, o), mov(zero(o), &e.f("rrt"), o)]);
        }
        if e.var.is_none() {
            let stored = e.f("stored");
            l.rung(vec![contact(&s, false, o), set(&stored, o)]);
            l.rung(vec![contact(&r, false, o), reset(&stored, o)]);
            l.rung(vec![contact(&stored, false, o), set(&e.f("state"), o)]);
        }
    }
    // 9. execution: the variables, then the actions' bodies
    for e in entries.iter().filter(|e| e.var.is_some()) {
        let o = e.origin;
        let v = e.target();
        l.unit_at(format!("{pou}.act.{}.run", e.name), o);
        l.rung(vec![contact(&e.f("reset"), false, o), reset(&v, o)]);
        l.rung(vec![
            contact(&e.f("reset"), true, o),
            contact(&e.f("set"), false, o),
            set(&v, o),
        ]);
    }
    for a in &c.actions {
        let Some(e) = entries.iter().find(|e| e.name == a.name) else {
            continue;
        };
        if e.var.is_some() {
            continue;
        }
        let o = a.origin;
        l.unit_at(format!("{pou}.act.{}.run", a.name), o);
        let skip = l.new_label();
        l.rung(vec![
            contact(&e.f("state"), true, o),
            ElementKind::Jmp(nm(&skip, o)),
        ]);
        match &a.body {
            Code::Statements { node } => {
                let text = node.text().unwrap_or("");
                let src = node.document().input_text();
                let map = super::st_body::file_offsets(src, node.range().start, text);
                l.text(map, origin(*node));
                if let Some(p) = super::st_lower::first_pragma(text) {
                    return Err((
                        l.origin(p),
                        "a pragma `{…}` (matiec copies its text, C code, into what it generates)"
                            .into(),
                    ));
                }
                let body = st::statements(text)
                    .map_err(|e| (l.origin(e.at), format!("ST syntax error: {}", e.message)))?;
                l.lower_statements(&body).map_err(|e| fail(&l, e))?;
            }
            Code::Ld { node } => {
                let rungs = super::ld::rungs(tc6, *node, pou, inits, notes).map_err(|e| {
                    (
                        origin(*node),
                        format!("the LD body of action `{}`: {e}", a.name),
                    )
                })?;
                if rungs.iter().any(|r| {
                    r.label.is_some()
                        || r.ld
                            .iter()
                            .any(|el| matches!(el.kind, ElementKind::Ret | ElementKind::End))
                }) {
                    return Err((
                        origin(*node),
                        format!("the LD body of action `{}` has labels or returns", a.name),
                    ));
                }
                for r in rungs {
                    l.rung(r.ld.into_iter().map(|e| e.kind).collect());
                }
            }
            Code::Text { text, node } => {
                l.text(None, origin(*node));
                let body = st::statements(text).map_err(|e| {
                    (
                        origin(*node),
                        format!(
                            "ST syntax error in COMPUTE_FUNCTION_BLOCKS `{text}`: {}",
                            e.message
                        ),
                    )
                })?;
                l.lower_statements(&body).map_err(|e| {
                    (
                        origin(*node),
                        format!("{} (in the blocks of the transition conditions)", e.what),
                    )
                })?;
            }
            Code::Expr { .. } => {}
        }
        l.put_label(skip);
    }
    l.finish();
    vars.extend(std::mem::take(&mut l.vars));
    Ok(Lowered {
        rungs: std::mem::take(&mut l.rungs),
        vars,
    })
}

fn prev(step: &str) -> String {
    format!("sfc__{step}__prev")
}

fn fired(i: usize) -> String {
    format!("sfc__t{}", i + 1)
}
