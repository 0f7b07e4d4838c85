//! ST calls of the project's own functions and STRING literals, lowered to rungs (a part of
//! [`super`], the ST lowering, kept apart so that the statements and the calls can change
//! independently).
//!
//! - A STRING literal `'…'` (IEC 61131-3, 3rd ed., 6.3.3: `$'`, `$$`, `$L`, `$N`, `$P`, `$R`,
//!   `$T`, `$hh`) is an operand of type STRING, as the model has it (`plc_model::strings`);
//!   a double-byte literal `"…"` (WSTRING) is refused by name (the model has no WSTRING).
//!
//! Invariant: a literal accepted here is one `plc_model::parse_string_literal` decodes, so the
//! resolver never meets a malformed one. Deliberately not here: WSTRING, `STRING[n]` lengths.

use super::super::user_functions::{default_of, FnSig};
use super::{refuse, Lower, Val, L};
use crate::st::ast::*;
use plc_model::Type;
use plc_syntax::Scalar;
use plc_syntax::{ElementKind, Move};
use std::borrow::Cow;

/// The operand of ST string literal `s` (quotes included), refused when it is a WSTRING or
/// has a malformed `$` escape.
pub(super) fn string_literal(at: usize, s: &str) -> L<Scalar<'static>> {
    if s.starts_with('"') {
        return refuse(
            at,
            format!("the WSTRING literal `{s}` (the model has no WSTRING)"),
        );
    }
    if plc_model::parse_string_literal(s).is_none() {
        return refuse(
            at,
            format!("the string literal `{s}` (a malformed `$` escape)"),
        );
    }
    Ok(Scalar::Str(Cow::Owned(s.to_owned())))
}

/// The input pins of standard function `f` called with `n` inputs, in their order (IEC 61131-3
/// 2nd ed., 2.5.1.5: SEL `G, IN0, IN1`, LIMIT `MN, IN, MX`, MAX and MIN `IN1 … INn`; the
/// model's pins for the others), `None` for a name that is not a standard function.
fn std_function_pins(f: &str, n: usize) -> Option<Vec<String>> {
    Some(match f {
        "SEL" => vec!["G".into(), "IN0".into(), "IN1".into()],
        "LIMIT" => vec!["MN".into(), "IN".into(), "MX".into()],
        "MAX" | "MIN" => (1..=n.max(2)).map(|i| format!("IN{i}")).collect(),
        "MOVE" => vec!["IN".into()],
        _ => plc_model::Function::parse(f)?.input_names(n),
    })
}

/// The arguments of a call of standard function `f` in the order of its pins: informal ones as
/// written, formal ones (`MID(IN := s, P := 2, L := 3)`) put in their pins' places (IEC 61131-3
/// 3rd ed., 6.6.1.4.2). Mixed, unknown or repeated names and a missing pin are refused.
pub(super) fn formal_order<'a>(at: usize, f: &str, args: &'a [Arg]) -> L<Cow<'a, [Arg]>> {
    let named = |a: &Arg| matches!(a, Arg::Input { name: Some(_), .. });
    if !args.iter().any(named) {
        return Ok(Cow::Borrowed(args));
    }
    let Some(pins) = std_function_pins(f, args.len()) else {
        return Ok(Cow::Borrowed(args));
    };
    if !args.iter().all(named) {
        return refuse(
            at,
            format!("the call of {f} with formal and informal inputs mixed"),
        );
    }
    let mut out = Vec::with_capacity(pins.len());
    for p in &pins {
        let mut given = args
            .iter()
            .filter(|a| matches!(a, Arg::Input { name: Some(n), .. } if n.eq_ignore_ascii_case(p)));
        match (given.next(), given.next()) {
            (Some(a), None) => out.push(a.clone()),
            (Some(_), Some(_)) => {
                return refuse(at, format!("input {p} given twice in the call of {f}"))
            }
            (None, _) => return refuse(at, format!("the call of {f} without its input {p}")),
        }
    }
    if out.len() != args.len() {
        let unknown = args.iter().find_map(|a| match a {
            Arg::Input { name: Some(n), .. } if !pins.iter().any(|p| p.eq_ignore_ascii_case(n)) => {
                Some(n.clone())
            }
            _ => None,
        });
        return refuse(
            at,
            format!(
                "input `{}` in the call of {f} (its inputs are {})",
                unknown.unwrap_or_default(),
                pins.join(", ")
            ),
        );
    }
    Ok(Cow::Owned(out))
}

/// The arguments of a call of function block instance `inst` whose inputs are `pins` and
/// outputs `outs` (in declaration order), informal ones named: `T1(start, T#1s)` is
/// `T1(IN := start, PT := T#1s)` (IEC 61131-3 3rd ed., 6.6.1.4.2; matiec binds them in
/// declaration order, EN left out), and informal arguments past the inputs are the outputs'
/// targets: `pid1(TRUE, pv, sp, 0.0, kp, tr, td, t, y)` gives `XOUT => y`, as matiec's C for an
/// informal call assigns each output after the call (`generate_c_st.cc`, `fb_invocation_c`).
/// Informal and formal inputs mixed, more informal ones than inputs and outputs, or an output's
/// argument that is not a variable, are refused.
pub(super) fn name_informal<'a>(
    at: usize,
    inst: &str,
    pins: &[String],
    outs: &[String],
    args: &'a [Arg],
) -> L<Cow<'a, [Arg]>> {
    let informal = |a: &Arg| matches!(a, Arg::Input { name: None, .. });
    if !args.iter().any(informal) {
        return Ok(Cow::Borrowed(args));
    }
    if args.iter().any(|a| !informal(a)) {
        return refuse(
            at,
            format!("the call of `{inst}` with formal and informal arguments mixed"),
        );
    }
    if args.len() > pins.len() + outs.len() {
        return refuse(
            at,
            format!(
                "{} informal arguments in the call of `{inst}`, which has {} inputs ({}){}",
                args.len(),
                pins.len(),
                pins.join(", "),
                match outs.len() {
                    0 => String::new(),
                    n => format!(" and {n} outputs ({})", outs.join(", ")),
                }
            ),
        );
    }
    let mut named = Vec::with_capacity(args.len());
    for (k, a) in args.iter().enumerate() {
        let Arg::Input { value, .. } = a else {
            named.push(a.clone());
            continue;
        };
        named.push(match (pins.get(k), value) {
            (Some(p), _) => Arg::Input {
                name: Some(p.clone()),
                value: value.clone(),
            },
            (None, Expr::Var(target)) => Arg::Output {
                name: outs[k - pins.len()].clone(),
                target: target.clone(),
            },
            (None, _) => {
                return refuse(
                    at,
                    format!(
                        "informal argument {} of the call of `{inst}` is for its output `{}`, and is not a variable",
                        k + 1,
                        outs[k - pins.len()]
                    ),
                )
            }
        });
    }
    Ok(Cow::Owned(named))
}

/// A value moved into a variable: a literal or a variable.
impl Lower<'_> {
    /// `to := v` for a variable `to` of type `ty` (a BOOL as a set, reset or coil).
    fn put(&mut self, to: &str, ty: Type, v: &Val) {
        match (ty, v) {
            (Type::Bool, Val::Lit(Scalar::Bool(b))) => {
                let el = if *b {
                    ElementKind::Set(self.name(to))
                } else {
                    ElementKind::Reset(self.name(to))
                };
                self.emit(vec![el]);
            }
            (Type::Bool, Val::Var(n, _)) => {
                let n = n.clone();
                self.copy(&n, to, Type::Bool)
            }
            _ => {
                let m = ElementKind::Move(Box::new(Move {
                    from: self.operand(v),
                    to: self.name(to),
                }));
                self.emit(vec![m]);
            }
        }
    }

    /// The instance of function `sig`'s type that this body calls it through (one per body:
    /// a function keeps nothing between calls, [`FnSig::starts`]).
    fn function_instance(&mut self, sig: &FnSig) -> String {
        let inst = instance_name(&sig.name);
        if !self.fn_instances.contains(&inst) {
            self.fn_instances.push(inst.clone());
            self.declare_instance(&inst, &sig.ty);
        }
        inst
    }

    /// A call of the project's function `callee` (`None` when it is not one): its inputs
    /// evaluated (in declaration order, as matiec passes them), every variable of the function
    /// started (the inputs given from their arguments, the others from their initial values),
    /// the `call` of the function's instance (skipped when EN is FALSE), the result moved out
    /// (the return type's default when skipped: matiec returns the variable it initialised),
    /// the outputs `=>` moved out when EN is TRUE (matiec copies back the values it passed in
    /// otherwise), ENO `=>` the value of EN (IEC 61131-3 3rd ed., 6.6.1.5, 7.3.3.2.3).
    pub(super) fn user_function_call(
        &mut self,
        callee: &Place,
        args: &[Arg],
        want: Option<Type>,
        out: Option<&str>,
    ) -> L<Option<Option<Val>>> {
        if !callee.selectors.is_empty() {
            return Ok(None);
        }
        let at = callee.base_at;
        let key = callee.base.to_ascii_lowercase();
        if self.scope.funcs.contains_key(&key) && self.pou.eq_ignore_ascii_case(&callee.base) {
            return refuse(
                at,
                format!(
                    "the call of function `{}` in its own body: IEC 61131-3 (2.5) forbids recursion",
                    callee.base
                ),
            );
        }
        let Some(sig) = self.scope.func(&callee.base).cloned() else {
            return Ok(None);
        };
        let fname = sig.name.clone();
        if let Some(why) = &sig.refused {
            return refuse(
                at,
                format!("the call of function `{fname}`, which is not executed: {why}"),
            );
        }
        let ty = |t: &str| Type::parse(t).filter(|t| !matches!(t, Type::Fb(_)));
        let Some(ret) = ty(&sig.ret) else {
            return refuse(
                at,
                format!("the call of function `{fname}` of type {}", sig.ret),
            );
        };
        // Which argument goes where.
        let mut en: Option<&Expr> = None;
        let mut eno: Option<&Place> = None;
        let mut given: Vec<(usize, &Expr)> = Vec::new();
        let mut outs: Vec<(usize, &Place)> = Vec::new();
        let mut next = 0;
        for a in args {
            match a {
                Arg::Input { name: None, value } => {
                    if next >= sig.inputs.len() {
                        return refuse(
                            at,
                            format!(
                                "more arguments than inputs in the call of function `{fname}` ({} has {})",
                                fname,
                                sig.inputs.len()
                            ),
                        );
                    }
                    given.push((next, value));
                    next += 1;
                }
                Arg::Input {
                    name: Some(n),
                    value,
                } if n.eq_ignore_ascii_case("EN") => en = Some(value),
                Arg::Input {
                    name: Some(n),
                    value,
                } => match sig
                    .inputs
                    .iter()
                    .position(|(p, _)| p.eq_ignore_ascii_case(n))
                {
                    Some(i) if !given.iter().any(|(g, _)| *g == i) => given.push((i, value)),
                    Some(_) => {
                        return refuse(
                            at,
                            format!("input `{n}` given twice in the call of `{fname}`"),
                        )
                    }
                    None => {
                        return refuse(
                            at,
                            format!(
                                "input `{n}` in the call of function `{fname}` (its inputs: {})",
                                pin_names(&sig.inputs)
                            ),
                        )
                    }
                },
                Arg::Output { name, target } if name.eq_ignore_ascii_case("ENO") => {
                    eno = Some(target)
                }
                Arg::Output { name, target } => {
                    match sig.outputs.iter().position(|(p, _)| p.eq_ignore_ascii_case(name)) {
                        Some(i) => outs.push((i, target)),
                        None => {
                            return refuse(
                                at,
                                format!(
                                    "output `{name}` in the call of function `{fname}` (its outputs: {})",
                                    pin_names(&sig.outputs)
                                ),
                            )
                        }
                    }
                }
            }
        }
        given.sort_by_key(|(i, _)| *i);
        // EN first, then the inputs, in declaration order.
        let en = match en {
            Some(e) => Some(self.bool_contact(e)?),
            None => None,
        };
        let mut vals: Vec<(usize, Val)> = Vec::new();
        for (i, e) in given {
            let (pin, pty) = &sig.inputs[i];
            let Some(t) = ty(pty) else {
                return refuse(
                    at,
                    format!("input `{pin}` of function `{fname}` of type {pty}"),
                );
            };
            let v = if t == Type::Bool {
                self.bool_operand(e)?
            } else {
                self.value(e, Some(t))?
            };
            if let (Some(vt), false) = (v.ty(), t == Type::Bool) {
                if vt != t
                    && !(vt.is_int() && t.is_int())
                    && !(vt.is_numeric() && matches!(t, Type::Real | Type::Lreal))
                {
                    return refuse(
                        at,
                        format!("input `{pin}` of function `{fname}` is {t}, its argument {vt}"),
                    );
                }
            }
            vals.push((i, v));
        }
        let inst = self.function_instance(&sig);
        // The inputs: those given their arguments, the others their initial values (matiec
        // passes a left-out input's default); the function's body starts the rest.
        for (i, (pin, pty)) in sig.inputs.iter().enumerate() {
            let Some(t) = ty(pty) else {
                return refuse(
                    at,
                    format!("input `{pin}` of function `{fname}` of type {pty}"),
                );
            };
            let v = match vals.iter().find(|(j, _)| *j == i) {
                Some((_, v)) => v.clone(),
                None => Val::Lit(
                    sig.starts
                        .iter()
                        .find(|(n, _, _)| n == pin)
                        .and_then(|(_, _, init)| init.clone())
                        .unwrap_or_else(|| default_of(t)),
                ),
            };
            self.put(&format!("{inst}.{pin}"), t, &v);
        }
        let d = match out {
            Some(o) if want == Some(ret) => o.to_owned(),
            _ => self.temp(ret),
        };
        // EN FALSE: no call, the result the return type's default, the outputs untouched.
        let skip = en.as_ref().map(|e| {
            let l = self.label();
            let c = self.contact(e, true);
            let j = self.jmp(&l);
            self.emit(vec![c, j]);
            l
        });
        let call = ElementKind::Call(self.name(&inst));
        self.emit(vec![call]);
        self.put(&d, ret, &Val::Var(format!("{inst}.{}", sig.name), ret));
        for (i, target) in outs {
            let (pin, pty) = &sig.outputs[i];
            let Some(t) = ty(pty) else {
                return refuse(
                    at,
                    format!("output `{pin}` of function `{fname}` of type {pty}"),
                );
            };
            let (to, tty) = self.written(target)?;
            if tty != t {
                return refuse(
                    target.base_at,
                    format!("`{pin} => {to}`: {to} is {tty}, the output {t}"),
                );
            }
            self.copy(&format!("{inst}.{pin}"), &to, t);
        }
        if let Some(l) = skip {
            let end = self.label();
            let j = self.jmp(&end);
            self.emit(vec![j]);
            self.place(l);
            self.put(&d, ret, &Val::Lit(default_of(ret)));
            self.place(end);
        }
        if let Some(target) = eno {
            let (to, tty) = self.written(target)?;
            if tty != Type::Bool {
                return refuse(
                    target.base_at,
                    format!("`ENO => {to}`: {to} is {tty}, ENO BOOL"),
                );
            }
            match &en {
                Some(e) => {
                    let e = e.clone();
                    self.copy(&e, &to, Type::Bool)
                }
                None => self.emit(vec![ElementKind::Set(self.name(&to))]),
            }
        }
        Ok(Some(match out {
            Some(o) if o == d => None,
            _ => Some(Val::Var(d, ret)),
        }))
    }
}

/// The instance a body calls function `f` through.
pub(super) fn instance_name(f: &str) -> String {
    format!("st__{f}")
}

fn pin_names(pins: &[(String, String)]) -> String {
    if pins.is_empty() {
        return "none".into();
    }
    pins.iter()
        .map(|(n, _)| n.as_str())
        .collect::<Vec<_>>()
        .join(", ")
}
