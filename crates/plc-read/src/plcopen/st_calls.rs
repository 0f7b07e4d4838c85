//! ST calls of function block instances and their fields, lowered to rungs (a part of
//! [`super`], the ST lowering, kept apart so that the statements and the calls can change
//! independently).
//!
//! - A user function block instance (IEC 61131-3, 3rd ed., 6.6.3.4, 7.3.3.2.3) is its own POU
//!   after the resolver expands it (`Inst` with variables `Inst.X`, as FBD and LD call it):
//!   `Inst(X := e, Q => y)` is `Inst.X := e` for each input given (in the order written), a
//!   `call` of the instance's POU, then `y := Inst.Q` for each output. An input left out keeps
//!   its value from before (an instance's inputs are retained between calls, 6.6.1.2). Its
//!   inputs are written (`Inst.X := e;`) and its inputs and outputs read (`y := Inst.Q;`) as
//!   the variables they are; an output is written only by the instance (refused).
//! - A standard function block instance (TON … RS) keeps its output fields and PT/PV in the
//!   model, not its BOOL inputs: an input that a call of the body leaves out, or that the body
//!   reads or writes as `T1.IN`, gets a variable of the POU that holds it between calls,
//!   `st__T1__IN` (a compiler name: IEC identifiers have no double `_`), written by every call
//!   that gives the input and by `T1.IN := e`, read by the calls that leave it out. PT and PV
//!   left out (and not otherwise named) are the instance's own PT and PV fields, which keep
//!   the last value given (and its declared initial value).
//!
//! Invariant: which inputs need their variable is decided for a whole ST text before its first
//! statement is lowered ([`Lower::prepare`]), so that every call stores what a later one reads.
//! Informal (positional) arguments are named before they come here ([`super::functions`]).
//! Deliberately not here: EN/ENO of function block calls, instances of the library's function blocks other than the standard
//! ones (refused by name).

use super::super::st_scope::{Decl, FbPins};
use super::{field_type, place_path, refuse, Lower, L};
use crate::st::ast::*;
use plc_model::Type;
use plc_syntax::{ElementKind, Move};

/// The inputs of a standard function block type and their types (IEC 61131-3 2nd ed.,
/// 2.5.2.3.1–4), in the order of its call's operands.
pub(super) fn std_pins(ty: &str) -> Option<&'static [(&'static str, Type)]> {
    Some(match ty {
        "TON" | "TOF" | "TP" => &[("IN", Type::Bool), ("PT", Type::Time)],
        "CTU" => &[("CU", Type::Bool), ("R", Type::Bool), ("PV", Type::Int)],
        "CTD" => &[("CD", Type::Bool), ("LD", Type::Bool), ("PV", Type::Int)],
        "CTUD" => &[
            ("CU", Type::Bool),
            ("CD", Type::Bool),
            ("R", Type::Bool),
            ("LD", Type::Bool),
            ("PV", Type::Int),
        ],
        "R_TRIG" | "F_TRIG" => &[("CLK", Type::Bool)],
        "SR" => &[("S1", Type::Bool), ("R", Type::Bool)],
        "RS" => &[("S", Type::Bool), ("R1", Type::Bool)],
        _ => return None,
    })
}

/// The name of the variable that holds input `pin` of standard instance `inst`.
pub(super) fn held(inst: &str, pin: &str) -> String {
    format!("st__{inst}__{pin}")
}

impl Lower<'_> {
    /// Finds, in statements `body`, the inputs of standard instances that need a variable
    /// (left out of a call, or named as `T1.IN`), and declares it.
    pub(in super::super) fn prepare(&mut self, body: &[Statement]) {
        let mut want: Vec<(String, String, Type)> = Vec::new();
        let mut add = |inst: &str, ty: &str, pin: &str| {
            let Some(&(p, t)) = std_pins(ty).and_then(|ps| ps.iter().find(|(p, _)| *p == pin))
            else {
                return;
            };
            if !want.iter().any(|(i, q, _)| i == inst && q == p) {
                want.push((inst.to_owned(), p.to_owned(), t));
            }
        };
        for s in body {
            let a = crate::st::accesses(s);
            for path in a.reads.iter().chain(&a.writes) {
                if let Ok(Some((Decl::Instance { name, ty, .. }, false))) = self.scope.find(path) {
                    add(name, ty, &path[name.len() + 1..].to_ascii_uppercase());
                }
            }
            walk(s, &mut |callee, args| {
                if let Ok(Some((Decl::Instance { name, ty, .. }, true))) =
                    self.scope.find(&place_path(callee))
                {
                    for &(p, t) in std_pins(ty).unwrap_or(&[]) {
                        let given = args.iter().any(|a| {
                            matches!(a, Arg::Input { name: Some(n), .. } if n.eq_ignore_ascii_case(p))
                        });
                        // PT and PV left out are the instance's own fields.
                        if !given && t == Type::Bool {
                            add(name, ty, p);
                        }
                    }
                }
            });
        }
        for (inst, pin, ty) in want {
            let n = held(&inst, &pin);
            if !self.held.contains(&n) {
                self.declare(&n, ty);
                self.held.push(n);
            }
        }
    }

    /// The variable holding input `pin` of standard instance `inst`, if it has one.
    pub(super) fn held_var(&self, inst: &str, pin: &str) -> Option<String> {
        let n = held(inst, pin);
        self.held.contains(&n).then_some(n)
    }

    /// What field `field` (upper case) of instance `name` of type `ty` is as a variable: an
    /// input or output of a user function block, an output field of a standard one, or the
    /// variable holding a standard one's input.
    pub(super) fn instance_field(
        &self,
        at: usize,
        name: &str,
        ty: &str,
        field: &str,
        write: bool,
    ) -> L<(String, Type)> {
        let path = format!("{name}.{field}");
        if let Some(fb) = self.scope.fb(ty) {
            let find = |v: &[(String, String)]| {
                v.iter()
                    .find(|(n, _)| n.eq_ignore_ascii_case(field))
                    .cloned()
            };
            let (pin, pty, input) = match (find(&fb.inputs), find(&fb.outputs)) {
                (Some((n, t)), _) => (n, t, true),
                (None, Some((n, t))) => (n, t, false),
                (None, None) => {
                    return refuse(
                        at,
                        format!("`{path}`: function block {ty} has no input or output `{field}`"),
                    )
                }
            };
            if write && !input {
                return refuse(
                    at,
                    format!("a write of `{path}`, an output of the instance (only the instance writes it)"),
                );
            }
            return match Type::parse(&pty) {
                Some(t) if !matches!(t, Type::Fb(_)) => Ok((format!("{name}.{pin}"), t)),
                _ => refuse(
                    at,
                    format!("`{path}` of type {pty}, which the model does not execute"),
                ),
            };
        }
        if let Some(v) = self.held_var(name, field) {
            let t = std_pins(ty)
                .and_then(|ps| ps.iter().find(|(p, _)| *p == field))
                .map_or(Type::Bool, |&(_, t)| t);
            return Ok((v, t));
        }
        match field_type(ty, field) {
            Some(t) if !write => Ok((path, t)),
            _ if write => refuse(
                at,
                format!("a write of `{path}`, which is not an input of the instance"),
            ),
            _ => refuse(
                at,
                format!(
                    "`{path}`: only the inputs and outputs of a function block instance are read"
                ),
            ),
        }
    }

    /// `inst(…)` of user function block type `fb`: the inputs given moved in, `call`, the
    /// outputs asked for moved out.
    pub(super) fn user_fb_call(
        &mut self,
        at: usize,
        inst: &str,
        fb: &FbPins,
        args: &[Arg],
    ) -> L<()> {
        let field = |n: &str| Place {
            base: inst.to_owned(),
            base_at: at,
            selectors: vec![Selector::Field(n.to_owned())],
        };
        let mut outputs = Vec::new();
        for a in args {
            match a {
                Arg::Input {
                    name: Some(n),
                    value,
                } => {
                    if !fb.inputs.iter().any(|(p, _)| p.eq_ignore_ascii_case(n)) {
                        return refuse(
                            at,
                            format!(
                                "input `{n}` in the call of `{inst}` ({} has inputs {})",
                                fb.name,
                                names(&fb.inputs)
                            ),
                        );
                    }
                    self.assign(&field(n), value)?;
                }
                Arg::Input { name: None, .. } => {
                    return refuse(at, format!("an informal argument in the call of `{inst}`"))
                }
                Arg::Output { name, target } => {
                    if !fb.outputs.iter().any(|(p, _)| p.eq_ignore_ascii_case(name)) {
                        return refuse(
                            at,
                            format!(
                                "output `{name}` in the call of `{inst}` ({} has outputs {})",
                                fb.name,
                                names(&fb.outputs)
                            ),
                        );
                    }
                    outputs.push((name, target));
                }
            }
        }
        let call = ElementKind::Call(self.name(inst));
        self.emit(vec![call]);
        for (name, target) in outputs {
            let (from, fty) = self.read(&field(name))?;
            let (to, tty) = self.written(target)?;
            if fty != tty {
                return refuse(
                    target.base_at,
                    format!("`{name} => {to}`: {to} is {tty}, the output {fty}"),
                );
            }
            self.copy(&from, &to, fty);
        }
        Ok(())
    }

    /// `Inst.A();`, a call of action A of a user instance ([`super::super::fb_actions`]): A's
    /// number moved into the instance's selector, then a `call` of the instance. False when
    /// `callee` is not an action of an instance.
    pub(super) fn action_call(&mut self, callee: &Place, args: &[Arg]) -> L<bool> {
        let [Selector::Field(action)] = &callee.selectors[..] else {
            return Ok(false);
        };
        let Some(Decl::Instance { name, ty, .. }) = self.scope.get(&callee.base) else {
            return Ok(false);
        };
        let Some(k) = self.scope.fb(ty).and_then(|fb| {
            fb.actions
                .iter()
                .position(|a| a.eq_ignore_ascii_case(action))
        }) else {
            return Ok(false);
        };
        let inst = name.clone();
        if !args.is_empty() {
            return refuse(
                callee.base_at,
                format!("arguments in the call of action `{inst}.{action}` (an action has none)"),
            );
        }
        let select = ElementKind::Move(Box::new(Move {
            from: self.operand(&super::Val::Lit(plc_syntax::Scalar::Number(
                (k as u64 + 1).into(),
            ))),
            to: self.name(&format!("{inst}.{}", super::super::fb_actions::SELECTOR)),
        }));
        self.emit(vec![select]);
        let call = ElementKind::Call(self.name(&inst));
        self.emit(vec![call]);
        Ok(true)
    }

    /// `to := from` of two variables of type `ty`.
    pub(super) fn copy(&mut self, from: &str, to: &str, ty: Type) {
        if ty == Type::Bool {
            let c = self.contact(from, false);
            self.emit(vec![
                c,
                ElementKind::Coil {
                    var: self.name(to),
                    negated: false,
                },
            ]);
        } else {
            let m = ElementKind::Move(Box::new(Move {
                from: self.operand(&super::Val::Var(from.to_owned(), ty)),
                to: self.name(to),
            }));
            self.emit(vec![m]);
        }
    }

    /// `a := b` of two structures: each field of `a` from the field of `b` of the same path
    /// (IEC 61131-3 7.3.3.2.1: an assignment of a structured variable copies every element).
    pub(super) fn structure_assign(&mut self, at: usize, target: &Place, value: &Expr) -> L<bool> {
        let Expr::Var(source) = value else {
            return Ok(false);
        };
        let (tp, sp) = (place_path(target), place_path(source));
        // Two structures, or two arrays (`a := b`: a move per element, IEC 61131-3 6.4.4.5
        // assigns an array of the same type whole).
        let (Ok(Some((to, true))), Ok(Some((from, true)))) =
            (self.scope.find(&tp), self.scope.find(&sp))
        else {
            return Ok(false);
        };
        let arrays = matches!((to, from), (Decl::Array { .. }, Decl::Array { .. }));
        let structures = matches!((to, from), (Decl::Structure { .. }, Decl::Structure { .. }));
        let (Some(to), Some(from), true) = (to.leaves(), from.leaves(), arrays || structures)
        else {
            return Ok(false);
        };
        let what = if arrays {
            "arrays whose elements"
        } else {
            "structures whose fields"
        };
        let rel = |leaves: &[(String, String)], root: usize| -> Vec<(String, String, String)> {
            leaves
                .iter()
                .map(|(n, t)| (n[root..].to_ascii_lowercase(), n.clone(), t.clone()))
                .collect()
        };
        let (mut to, mut from) = (rel(&to, tp.len()), rel(&from, sp.len()));
        to.sort();
        from.sort();
        let same =
            to.len() == from.len() && to.iter().zip(&from).all(|(a, b)| a.0 == b.0 && a.2 == b.2);
        if !same {
            return refuse(at, format!("`{tp} := {sp}` of {what} differ"));
        }
        for ((_, t, ty), (_, f, _)) in to.iter().zip(&from) {
            match Type::parse(ty) {
                Some(ty) if !matches!(ty, Type::Fb(_)) => self.copy(f, t, ty),
                _ => {
                    return refuse(
                        at,
                        format!("`{tp} := {sp}`: field `{t}` of type {ty}, which the model does not execute"),
                    )
                }
            }
        }
        Ok(true)
    }
}

fn names(pins: &[(String, String)]) -> String {
    let v: Vec<&str> = pins.iter().map(|(n, _)| n.as_str()).collect();
    if v.is_empty() {
        "none".into()
    } else {
        v.join(", ")
    }
}

/// Every call statement in `s`, nested ones included.
fn walk(s: &Statement, f: &mut dyn FnMut(&Place, &[Arg])) {
    let all = |v: &[Statement], f: &mut dyn FnMut(&Place, &[Arg])| {
        for s in v {
            walk(s, f);
        }
    };
    match &s.kind {
        Stmt::Call { callee, args } => f(callee, args),
        Stmt::If { arms, otherwise } => {
            for (_, b) in arms {
                all(b, f);
            }
            all(otherwise, f);
        }
        Stmt::Case {
            arms, otherwise, ..
        } => {
            for (_, b) in arms {
                all(b, f);
            }
            all(otherwise, f);
        }
        Stmt::While { body, .. } | Stmt::Repeat { body, .. } | Stmt::For { body, .. } => {
            all(body, f)
        }
        _ => {}
    }
}
