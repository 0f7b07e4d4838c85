//! Name resolution and operand typing: variables (locals first, then program variables),
//! members of function block instances, writable targets, typed operands and instances.

use super::elements::Scope;
use super::operand::{self, Untyped};
use super::path::At;
use super::util::expect_type;
use super::{Builder, Result};
use plc_diag::{Diagnostic, Invalid, LoadError, Origin};
use plc_model::*;
use plc_syntax::{Name, Operand as SynOperand};

/// An error of an element's operand: at the operand's path and origin, in the scope's rung.
fn fail(s: &Scope, at: &At, origin: Origin, kind: Invalid) -> LoadError {
    LoadError::invalid(Some(s.rung_id), &at.with(""), kind).at(origin)
}

impl<'a> Builder<'a> {
    /// `d` with a "did you mean" hint when it is an undefined variable and a declared variable
    /// or instance (of any POU) has a name close to it ([`plc_diag::suggest`]).
    pub(super) fn hinted(&self, d: Diagnostic) -> Diagnostic {
        if d.hint.is_some() {
            return d;
        }
        if let Invalid::Type {
            expected,
            operand,
            found,
            ..
        } = &d.kind
        {
            let hint = instance_output_hint(operand, found, expected);
            return d.with_hint(hint);
        }
        let Invalid::UndefinedVar { name } = &d.kind else {
            return d;
        };
        // Display names are `SBR_0:name` for subroutine locals: the declared name is the last part.
        fn declared(n: &str) -> &str {
            n.rsplit(':').next().unwrap_or(n)
        }
        let vars = self.vars.iter().map(|v| declared(&v.name));
        let instances = self.instances.iter().map(|i| declared(&i.display));
        let hint = plc_diag::suggest::did_you_mean(name, vars.chain(instances));
        d.with_hint(hint)
    }

    /// A name a block or element writes, in the scope of `pou`: not a field, not a member or an
    /// instance. An input may be written (matiec accepts a coil on `%IX0.0`): the write lasts
    /// until the next scan copies the input image in (the analysis warns, W0208).
    pub(super) fn writable_name(
        &self,
        text: &str,
        pou: PouId,
        what: &'static str,
    ) -> std::result::Result<VarId, Invalid> {
        let (r, t) = self.lookup(text, pou)?;
        let fail = |why| {
            Err(Invalid::NotWritable {
                what,
                var: text.to_owned(),
                why,
            })
        };
        if r.field.is_some() {
            return fail("instance fields are written only by their function block");
        }
        // An input of a user instance is set by the instance's caller (IEC 61131-3 6.6.1.2).
        let member_input = self.is_member_input(text, pou);
        if text.contains('.') && !self.is_own_variable(text, pou) && !member_input {
            return fail("it belongs to a function block instance (only the instance writes it)");
        }
        if matches!(t, Type::Fb(_)) {
            return fail("it is a function block instance");
        }
        // An instance's own input (`G1.X`, written in its body) is set by its calls, not by the
        // input image.
        let v = &self.vars[r.var.index()];
        if v.class == VarClass::Input && !v.hidden && !v.name.contains('.') {
            self.written_inputs.borrow_mut().push(r.var);
        }
        Ok(r.var)
    }

    /// A member (input or output) of user function block instance `i`, read as `G1.NAME`.
    pub(super) fn member(
        &self,
        i: usize,
        base: &str,
        field: Option<&str>,
    ) -> std::result::Result<(VarRef, Type), Invalid> {
        let inst = &self.instances[i];
        let Some(f) = field else {
            return Err(Invalid::InstanceValue {
                name: base.to_owned(),
            });
        };
        match inst
            .inputs
            .iter()
            .chain(&inst.outputs)
            .find(|(n, _)| n == f)
        {
            Some(&(_, v)) => Ok((
                VarRef {
                    var: v,
                    field: None,
                },
                self.vars[v.index()].ty,
            )),
            None => Err(Invalid::UnknownMember {
                instance: base.to_owned(),
                fb: inst.fb.clone(),
                member: f.to_owned(),
                members: inst
                    .inputs
                    .iter()
                    .chain(&inst.outputs)
                    .map(|(n, _)| n.as_str())
                    .collect::<Vec<_>>()
                    .join(", "),
            }),
        }
    }

    /// The variable or field `text` names in the scope of `pou`. A dotted name is first the
    /// variable of that exact name (a structure's field, `Motor.Speed`), then a field of a
    /// variable or member of an instance (`T1.Q`, `G1.OUT`); locals before the program's.
    pub(super) fn lookup(
        &self,
        text: &str,
        pou: PouId,
    ) -> std::result::Result<(VarRef, Type), Invalid> {
        let (base, field) = match text.split_once('.') {
            Some((b, f)) => (b, Some(f)),
            None => (text, None),
        };
        let exact = |id: VarId| {
            Ok((
                VarRef {
                    var: id,
                    field: None,
                },
                self.vars[id.index()].ty,
            ))
        };
        if field.is_some() {
            if let Some(&id) = self.locals[pou.index()].get(text) {
                return exact(id);
            }
        }
        let id = match self.locals[pou.index()].get(base) {
            Some(&id) => id,
            None => {
                if let Some(&i) = self.local_instances[pou.index()].get(base) {
                    return self.member(i, base, field);
                }
                if field.is_some() {
                    if let Some(&id) = self.globals.get(text) {
                        return exact(id);
                    }
                }
                match self.globals.get(base) {
                    Some(&id) => id,
                    None => match self.global_instances.get(base) {
                        Some(&i) => return self.member(i, base, field),
                        None => return Err(self.undefined(text, base, pou)),
                    },
                }
            }
        };
        operand::field_ref(id, text, self.vars[id.index()].ty, field)
    }

    /// The error of name `text` (first part `base`) that names nothing: the whole name when
    /// `base` is a structure (its field is unknown), else `base`.
    fn undefined(&self, text: &str, base: &str, pou: PouId) -> Invalid {
        let root = |scope| self.structure_roots.contains(&(scope, base.to_owned()));
        let name = if text.len() > base.len() && (root(Some(pou)) || root(None)) {
            text
        } else {
            base
        };
        Invalid::UndefinedVar {
            name: name.to_owned(),
        }
    }

    /// True when `text` is an input of a user function block instance `pou` sees (`G1.IN`),
    /// which IEC 61131-3 (6.6.1.2) lets the instance's caller set before a call.
    fn is_member_input(&self, text: &str, pou: PouId) -> bool {
        let Some((base, field)) = text.split_once('.') else {
            return false;
        };
        let i = self.local_instances[pou.index()]
            .get(base)
            .or_else(|| self.global_instances.get(base));
        i.is_some_and(|&i| self.instances[i].inputs.iter().any(|(n, _)| n == field))
    }

    /// True when `text` is the name of a variable of `pou`'s scope or the program's as it is
    /// (a structure's field), not a field of a variable or a member of an instance.
    fn is_own_variable(&self, text: &str, pou: PouId) -> bool {
        self.locals[pou.index()].contains_key(text) || self.globals.contains_key(text)
    }

    pub(super) fn var_ref(&self, name: &Name, at: &At, s: &Scope) -> Result<(VarRef, Type)> {
        self.lookup(name.as_str(), s.pou)
            .map_err(|k| fail(s, at, name.origin, k))
    }

    pub(super) fn untyped(&self, v: &SynOperand, at: &At, s: &Scope) -> Result<Untyped> {
        operand::parse(&v.value, &|n| self.lookup(n, s.pou)).map_err(|k| fail(s, at, v.origin, k))
    }

    pub(super) fn operand_of(
        &self,
        v: &SynOperand,
        at: &At,
        s: &Scope,
        ty: Type,
        what: &'static str,
    ) -> Result<Operand> {
        let u = self.untyped(v, at, s)?;
        operand::typed(&u, ty, what, &v.value.display()).map_err(|k| fail(s, at, v.origin, k))
    }

    /// Two operands of one numeric type (the type of whichever fixes one).
    pub(super) fn numeric_pair(
        &self,
        a: &SynOperand,
        b: &SynOperand,
        at: &At,
        s: &Scope,
        what: &'static str,
    ) -> Result<(Operand, Operand)> {
        let (pa, pb) = (at.key("a"), at.key("b"));
        let ua = self.untyped(a, &pa, s)?;
        let ub = self.untyped(b, &pb, s)?;
        let ty = ua
            .ty()
            .or(ub.ty())
            .unwrap_or_else(|| operand::default_type(&ua).max_numeric(operand::default_type(&ub)));
        if !ty.is_comparable() {
            let (p, j) = if ua.ty().is_some() {
                (&pa, a)
            } else {
                (&pb, b)
            };
            return Err(fail(
                s,
                p,
                j.origin,
                Invalid::Type {
                    what,
                    expected: plc_model::COMPARABLE.into(),
                    operand: j.value.display(),
                    found: ty.to_string(),
                },
            ));
        }
        let oa = operand::typed(&ua, ty, what, &a.value.display())
            .map_err(|k| fail(s, &pa, a.origin, k))?;
        let ob = operand::typed(&ub, ty, what, &b.value.display())
            .map_err(|k| fail(s, &pb, b.origin, k))?;
        Ok((oa, ob))
    }

    /// A variable that an element writes: not an input, not a field, of type `ty` if given.
    pub(super) fn writable(
        &self,
        name: &Name,
        at: &At,
        s: &Scope,
        what: &'static str,
        ty: Option<Type>,
    ) -> Result<VarId> {
        let id = self
            .writable_name(name.as_str(), s.pou, what)
            .map_err(|k| fail(s, at, name.origin, k))?;
        let var = &self.vars[id.index()];
        if let Some(ty) = ty {
            expect_type(var.ty, ty, what, &var.name).map_err(|k| fail(s, at, name.origin, k))?;
        }
        Ok(id)
    }

    pub(super) fn instance(&self, name: &Name, at: &At, s: &Scope, fb: FbKind) -> Result<VarId> {
        let (r, t) = self.var_ref(name, at, s)?;
        if r.field.is_some() || t != Type::Fb(fb) {
            return Err(fail(
                s,
                at,
                name.origin,
                Invalid::Type {
                    what: "this box",
                    expected: format!("a {} instance", Type::Fb(fb)),
                    operand: name.value.to_string(),
                    found: t.to_string(),
                },
            ));
        }
        Ok(r.var)
    }
}

trait MaxNumeric {
    fn max_numeric(self, other: Type) -> Type;
}
impl MaxNumeric for Type {
    fn max_numeric(self, other: Type) -> Type {
        if self == Type::Real || other == Type::Real {
            Type::Real
        } else {
            self
        }
    }
}

/// Where an operand of the wrong type is a standard function block instance (`{"move": "C1"}`
/// on a CTU): the output of that instance that has the type the element needs (`C1.CV`), in
/// the words of a hint. IEC 61131-3 6.6.3.2: an instance's outputs are read as
/// `instance.output`; the instance itself is not a value.
fn instance_output_hint(operand: &str, found: &str, expected: &str) -> Option<String> {
    let boolean = expected == "BOOL";
    let time = expected == "TIME";
    let output = match found {
        "CTU" | "CTD" | "CTUD" if !boolean && !time => "CV",
        "CTU" | "CTD" if boolean => "Q",
        "CTUD" if boolean => "QU",
        "TON" | "TOF" | "TP" if time => "ET",
        "TON" | "TOF" | "TP" | "R_TRIG" | "F_TRIG" if boolean => "Q",
        "SR" | "RS" if boolean => "Q1",
        _ => return None,
    };
    Some(format!(
        "`{operand}` is a {found} instance; its output {output} is `{operand}.{output}`"
    ))
}
