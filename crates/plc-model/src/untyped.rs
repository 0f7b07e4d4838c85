//! Operands before their constants are typed: the vocabulary the resolver (ladder, ST, STL,
//! variable initial values) and the FBD lowering (`plc_fbd::lower`) share.
//!
//! An OPERAND is a variable name or field (`"N"`, `"T1.Q"`), a number or boolean, a TIME
//! literal string, or an IEC literal string (IEC 61131-3 2.2.1): based (`"16#FF"`, `"2#1010"`,
//! `"8#17"`) or typed (`"UINT#5"`, `"WORD#16#FF"`, `"LREAL#1.5"`, `"BOOL#1"`). Numbers and
//! based literals have no type of their own: they take the type the context needs (the other
//! compare operand, the box's output), and must fit it. An integer is taken exactly (a ULINT
//! constant of 2^64 - 1 is not rounded through a double); a typed literal has its type, and so
//! has a STRING literal (`"'abc'"`, `$` escapes read: [`parse_string_literal`]).
//!
//! Not here: reading an operand out of the surface syntax (`plc_resolve`'s `operand`, which
//! calls [`parse_text`] for strings) and resolving names (the caller's `lookup`).

use crate::{
    intern, is_time_literal, parse_int_literal, parse_string_literal, parse_time_literal,
    split_typed_literal, Operand, Type, Value, VarRef, Wide,
};
use plc_diag::Invalid;

/// An operand before its constant (if any) is given a type.
#[derive(Clone, Debug)]
pub enum Untyped {
    Var(VarRef, Type),
    Bool(bool),
    /// An integer: a JSON integer or a based literal, exact.
    Int(i128),
    /// A JSON number with a fraction or exponent.
    Real(f64),
    Time(i64),
    /// A typed literal (`UINT#5`).
    Typed(Value),
}

impl Untyped {
    /// The type, when the operand itself fixes one.
    pub fn ty(&self) -> Option<Type> {
        match self {
            Untyped::Var(_, t) => Some(*t),
            Untyped::Bool(_) => Some(Type::Bool),
            Untyped::Time(_) => Some(Type::Time),
            Untyped::Typed(v) => Some(v.ty()),
            Untyped::Int(_) | Untyped::Real(_) => None,
        }
    }

    /// A number as JSON reads it (its value as `i64`, as `u64`, as `f64`): exact when it is an
    /// integer, else its double (NaN if it has none).
    pub fn number(as_i64: Option<i64>, as_u64: Option<u64>, as_f64: Option<f64>) -> Untyped {
        match (as_i64, as_u64) {
            (Some(i), _) => Untyped::Int(i as i128),
            (_, Some(u)) => Untyped::Int(u as i128),
            _ => Untyped::Real(as_f64.unwrap_or(f64::NAN)),
        }
    }
}

/// Resolves a variable name to its reference and type (the scope an operand is parsed in).
pub type Lookup<'a> = dyn Fn(&str) -> Result<(VarRef, Type), Invalid> + 'a;

/// Parses an operand written as a string: a STRING literal, a TIME literal, a based or typed
/// literal, or else a name that `lookup` resolves.
pub fn parse_text(s: &str, lookup: &Lookup<'_>) -> Result<Untyped, Invalid> {
    if s.starts_with('\'') {
        // A STRING literal (IEC 61131-3 6.3.3), its `$` escapes read.
        match parse_string_literal(s.trim_end()) {
            Some(b) => Ok(Untyped::Typed(Value::Str(intern(&b)))),
            None => Err(Invalid::BadLiteral {
                text: s.to_string(),
            }),
        }
    } else if is_time_literal(s) {
        match parse_time_literal(s) {
            Some(ms) => Ok(Untyped::Time(ms)),
            None => Err(Invalid::BadTime {
                text: s.to_string(),
            }),
        }
    } else if s.contains('#') {
        literal(s).ok_or_else(|| Invalid::BadLiteral {
            text: s.to_string(),
        })
    } else {
        let (r, t) = lookup(s)?;
        Ok(Untyped::Var(r, t))
    }
}

/// A based or typed literal (names never hold `#`); `None` if `s` is not one, or a typed one's
/// value does not fit its type.
fn literal(s: &str) -> Option<Untyped> {
    let Some((ty, rest)) = split_typed_literal(s) else {
        return parse_int_literal(s).map(Untyped::Int);
    };
    let int = || parse_int_literal(rest);
    let v = match ty {
        Type::Bool => match rest.to_ascii_uppercase().as_str() {
            "1" | "TRUE" => Value::Bool(true),
            "0" | "FALSE" => Value::Bool(false),
            _ => return None,
        },
        Type::Real => Value::Real(real_text(rest)? as f32),
        Type::Lreal => Value::Lreal(Wide::new(real_text(rest)?.to_bits())),
        // A based literal of a signed type is its bits (`SINT#16#FF` is -1: IEC 61131-3
        // 2.2.1 leaves it open; this is what CODESYS does); a decimal one must fit.
        t if t.is_signed() && rest.contains('#') => {
            let v = int()?;
            (v >= 0 && v < 1i128 << t.bits()).then(|| Value::from_bits(t, v as u64))?
        }
        t => Value::int_of(t, int()?)?,
    };
    Some(Untyped::Typed(v))
}

/// A real literal's digits (`1.5`, `-2.0E3`, `1_000.5`, or an integer), as `f64`.
fn real_text(s: &str) -> Option<f64> {
    let ok = |c: char| c.is_ascii_digit() || matches!(c, '.' | '-' | '+' | 'e' | 'E' | '_');
    if !s.chars().all(ok) || !s.bytes().any(|b| b.is_ascii_digit()) {
        return None;
    }
    s.replace('_', "").parse().ok()
}

/// Gives `u` the type `ty`, checking that it has it (or, for numbers, fits it).
pub fn typed(u: &Untyped, ty: Type, what: &'static str, text: &str) -> Result<Operand, Invalid> {
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
        (Untyped::Typed(v), _) if v.ty() == ty => Ok(Operand::Const(*v)),
        (Untyped::Typed(v), _) => Err(mismatch(format!("a {} literal", v.ty()))),
        (Untyped::Int(x), t) if t.is_int() || t.is_bits() => match Value::int_of(t, *x) {
            Some(v) => Ok(Operand::Const(v)),
            None => Err(Invalid::Range {
                value: text.to_owned(),
                ty: ty.to_string(),
            }),
        },
        // A JSON integer beyond 64 bits reads as a double: out of range, not a REAL.
        (Untyped::Real(x), t) if (t.is_int() || t.is_bits()) && x.fract() == 0.0 => {
            Err(Invalid::Range {
                value: text.to_owned(),
                ty: ty.to_string(),
            })
        }
        (Untyped::Real(_), t) if t.is_int() || t.is_bits() => {
            Err(mismatch("a REAL constant".into()))
        }
        (Untyped::Int(x), Type::Real) => Ok(Operand::Const(Value::Real(*x as f32))),
        (Untyped::Real(x), Type::Real) => Ok(Operand::Const(Value::Real(*x as f32))),
        (Untyped::Int(x), Type::Lreal) => Ok(Operand::Const(Value::Lreal(Wide::new(
            (*x as f64).to_bits(),
        )))),
        (Untyped::Real(x), Type::Lreal) => Ok(Operand::Const(Value::Lreal(Wide::new(x.to_bits())))),
        (Untyped::Int(_) | Untyped::Real(_), Type::Time) => Err(Invalid::Type {
            what,
            expected: "TIME (a literal like \"T#1s\")".into(),
            operand: text.to_owned(),
            found: "a plain number".into(),
        }),
        (Untyped::Bool(_), _) => Err(mismatch("BOOL".into())),
        (Untyped::Time(_), _) => Err(mismatch("TIME".into())),
        (Untyped::Int(_) | Untyped::Real(_), _) => Err(mismatch("a number".into())),
    }
}

/// The default type of a constant when nothing else fixes it.
pub fn default_type(u: &Untyped) -> Type {
    match u {
        Untyped::Int(_) => Type::Dint,
        Untyped::Real(_) => Type::Real,
        other => other.ty().unwrap_or(Type::Dint),
    }
}
