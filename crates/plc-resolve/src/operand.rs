//! Operand resolution for the resolver: an operand of the surface syntax (a [`Scalar`]) read
//! into an [`Untyped`] operand, and a variable's field resolved against its type.
//!
//! The operand vocabulary itself — literals, typing a constant to the type its context needs —
//! is the model's ([`plc_model::untyped`], shared with the FBD lowering); this module only reads
//! the syntax's scalars into it (a JSON integer is taken exactly, a string operand is
//! [`plc_model::untyped::parse_text`]'s).

use plc_diag::Invalid;
pub(crate) use plc_model::untyped::{default_type, typed, Lookup, Untyped};
use plc_model::{Field, Type, VarRef};
use plc_syntax::Scalar;

/// Parses an operand; `lookup` resolves a variable name to its reference and type.
pub(crate) fn parse(s: &Scalar, lookup: &Lookup<'_>) -> Result<Untyped, Invalid> {
    match s {
        Scalar::Bool(b) => Ok(Untyped::Bool(*b)),
        Scalar::Number(n) => Ok(Untyped::number(n.as_i64(), n.as_u64(), n.as_f64())),
        Scalar::Str(s) => plc_model::untyped::parse_text(s, lookup),
        other => Err(Invalid::Shape {
            expected: "an operand (variable name, number, boolean or TIME literal)",
            found: other.kind(),
        }),
    }
}

/// Resolves `NAME` or `NAME.FIELD` against a variable's type.
pub(crate) fn field_ref(
    var: plc_model::VarId,
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
