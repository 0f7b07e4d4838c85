//! Operand resolution and typing for the resolver.
//!
//! An OPERAND is a variable name or field (`"N"`, `"T1.Q"`), a JSON number or boolean, or a
//! TIME literal string. Numbers have no type of their own: they take the type the context needs
//! (the other compare operand, the box's output), and must fit it.

use crate::diag::Invalid;
use crate::model::{parse_time_literal, Field, Operand, Type, Value, VarRef};
use crate::syntax::Scalar;

/// An operand before its constant (if any) is given a type.
#[derive(Clone, Debug)]
pub(crate) enum Untyped {
    Var(VarRef, Type),
    Bool(bool),
    Number(f64, bool /* integral */),
    Time(i64),
}

impl Untyped {
    /// The type, when the operand itself fixes one.
    pub fn ty(&self) -> Option<Type> {
        match self {
            Untyped::Var(_, t) => Some(*t),
            Untyped::Bool(_) => Some(Type::Bool),
            Untyped::Time(_) => Some(Type::Time),
            Untyped::Number(..) => None,
        }
    }
}

/// Parses an operand; `lookup` resolves a variable name to its reference and type.
pub(crate) fn parse(
    s: &Scalar,
    lookup: &dyn Fn(&str) -> Result<(VarRef, Type), Invalid>,
) -> Result<Untyped, Invalid> {
    match s {
        Scalar::Bool(b) => Ok(Untyped::Bool(*b)),
        Scalar::Number(n) => {
            if let Some(i) = n.as_i64() {
                Ok(Untyped::Number(i as f64, true))
            } else {
                Ok(Untyped::Number(n.as_f64().unwrap_or(f64::NAN), false))
            }
        }
        Scalar::Str(s) => {
            if crate::syntax::is_time_literal(s) {
                match parse_time_literal(s) {
                    Some(ms) => Ok(Untyped::Time(ms)),
                    None => Err(Invalid::BadTime {
                        text: s.to_string(),
                    }),
                }
            } else {
                let (r, t) = lookup(s)?;
                Ok(Untyped::Var(r, t))
            }
        }
        other => Err(Invalid::Shape {
            expected: "an operand (variable name, number, boolean or TIME literal)",
            found: other.kind(),
        }),
    }
}

/// Gives `u` the type `ty`, checking that it has it (or, for numbers, fits it).
pub(crate) fn typed(
    u: &Untyped,
    ty: Type,
    what: &'static str,
    text: &str,
) -> Result<Operand, Invalid> {
    let mismatch = |found: String| Invalid::Type {
        what,
        expected: ty.to_string(),
        operand: text.to_owned(),
        found,
    };
    match (u, ty) {
        (Untyped::Var(r, t), _) if *t == ty => Ok(Operand::Var(*r)),
        (Untyped::Var(_, t), _) => Err(mismatch(t.to_string())),
        (Untyped::Bool(b), Type::Bool) => Ok(Operand::Const(Value::Bool(*b))),
        (Untyped::Time(ms), Type::Time) => match i32::try_from(*ms) {
            Ok(v) => Ok(Operand::Const(Value::Time(v))),
            Err(_) => Err(Invalid::Range {
                value: text.to_owned(),
                ty: "TIME".into(),
            }),
        },
        (Untyped::Number(x, integral), Type::Int | Type::Dint) => {
            let range = if ty == Type::Int {
                i16::MIN as f64..=i16::MAX as f64
            } else {
                i32::MIN as f64..=i32::MAX as f64
            };
            if !*integral {
                Err(mismatch("a REAL constant".into()))
            } else if !range.contains(x) {
                Err(Invalid::Range {
                    value: text.to_owned(),
                    ty: ty.to_string(),
                })
            } else if ty == Type::Int {
                Ok(Operand::Const(Value::Int(*x as i16)))
            } else {
                Ok(Operand::Const(Value::Dint(*x as i32)))
            }
        }
        (Untyped::Number(x, _), Type::Real) => Ok(Operand::Const(Value::Real(*x as f32))),
        (Untyped::Number(..), Type::Time) => Err(Invalid::Type {
            what,
            expected: "TIME (a literal like \"T#1s\")".into(),
            operand: text.to_owned(),
            found: "a plain number".into(),
        }),
        (Untyped::Bool(_), _) => Err(mismatch("BOOL".into())),
        (Untyped::Time(_), _) => Err(mismatch("TIME".into())),
        (Untyped::Number(..), _) => Err(mismatch("a number".into())),
    }
}

/// The default type of a constant when nothing else fixes it.
pub(crate) fn default_type(u: &Untyped) -> Type {
    match u {
        Untyped::Number(_, true) => Type::Dint,
        Untyped::Number(_, false) => Type::Real,
        other => other.ty().unwrap_or(Type::Dint),
    }
}

/// Resolves `NAME` or `NAME.FIELD` against a variable's type.
pub(crate) fn field_ref(
    var: crate::model::VarId,
    name: &str,
    ty: Type,
    field: Option<&str>,
) -> Result<(VarRef, Type), Invalid> {
    match (ty, field) {
        (_, None) => Ok((VarRef { var, field: None }, ty)),
        (Type::Fb(fb), Some(f)) => match Field::lookup(fb, f) {
            Some((field, fty)) => Ok((
                VarRef {
                    var,
                    field: Some(field),
                },
                fty,
            )),
            None => Err(Invalid::UnknownFieldOf {
                var: name.to_owned(),
                ty: ty.to_string(),
                field: f.to_owned(),
                fields: Field::names(fb),
            }),
        },
        (_, Some(f)) => Err(Invalid::UnknownFieldOf {
            var: name.to_owned(),
            ty: ty.to_string(),
            field: f.to_owned(),
            fields: "none: only instances of function blocks have fields",
        }),
    }
}
