//! How the model's types, values and conditions are spelled in C: the fixed-width C type of each
//! IEC type (and the runtime's struct of each standard function block), constants exact in
//! their type (limits, 64-bit literals, reals by their bits when a literal cannot say them),
//! the suffix of the runtime's per-type helpers, and a negated condition.
//!
//! Plain functions of a type or value; not here: where the text goes (`ladder`, `types`,
//! `harness`).

use plc_model::*;

/// The C operator of a comparison.
pub(crate) fn cmp_symbol(op: CmpOp) -> &'static str {
    match op {
        CmpOp::Eq => "==",
        CmpOp::Ne => "!=",
        CmpOp::Lt => "<",
        CmpOp::Le => "<=",
        CmpOp::Gt => ">",
        CmpOp::Ge => ">=",
    }
}

/// `!c`, without a double negation of a simple name.
pub(crate) fn negate(c: &str) -> String {
    let atom = |s: &str| {
        s.bytes()
            .all(|b| b.is_ascii_alphanumeric() || b == b'_' || b == b'.' || b == b'-' || b == b'>')
    };
    match c.strip_prefix('!') {
        Some(rest) if atom(rest) => rest.to_string(),
        _ if atom(c) => format!("!{c}"),
        _ => format!("!({c})"),
    }
}

/// The C type of an IEC type.
pub(crate) fn c_type(ty: Type) -> &'static str {
    match ty {
        Type::Bool => "bool",
        Type::Sint => "int8_t",
        Type::Int => "int16_t",
        Type::Dint | Type::Time => "int32_t",
        Type::Lint => "int64_t",
        Type::Usint | Type::Byte => "uint8_t",
        Type::Uint | Type::Word => "uint16_t",
        Type::Udint | Type::Dword => "uint32_t",
        Type::Ulint | Type::Lword => "uint64_t",
        Type::Real => "float",
        Type::Lreal => "double",
        Type::String => "_plc_string",
        Type::Fb(FbKind::Ton | FbKind::Tof | FbKind::Tp) => "_plc_timer",
        Type::Fb(FbKind::Ctu | FbKind::Ctd) => "_plc_counter",
        Type::Fb(FbKind::Sr | FbKind::Rs) => "_plc_bistable",
        Type::Fb(FbKind::RTrig | FbKind::FTrig) => "_plc_trigger",
        Type::Fb(FbKind::Ctud) => "_plc_updown",
    }
}

/// A C constant of a value: an integer literal of the type's C type (`u` for UDINT and DWORD,
/// `INT64_C`/`UINT64_C` for the 64-bit types; a minimum as `(-MAX - 1)`, since `-N` negates a
/// literal that may not fit), a real with its suffix or, when negative or not finite, by its
/// bits.
/// A constant as a static initializer: a STRING as `{len, "bytes"}` (a function call is no
/// constant expression), anything else as [`c_const`].
pub(crate) fn c_init(v: Value) -> String {
    match v {
        Value::Str(id) => {
            let b = plc_model::str_bytes(id);
            format!("{{{}, {}}}", b.len(), super::names::c_bytes(b))
        }
        v => c_const(v),
    }
}

pub(crate) fn c_const(v: Value) -> String {
    let ty = v.ty();
    match v {
        Value::Bool(b) => (if b { "1" } else { "0" }).to_string(),
        Value::Str(id) => {
            let b = plc_model::str_bytes(id);
            format!("_plc_str_lit({}, {})", b.len(), super::names::c_bytes(b))
        }
        Value::Real(f) if f.is_finite() && f.is_sign_positive() => format!("{f:?}f"),
        Value::Real(f) => format!("_plc_f32(0x{:08x}u)", f.to_bits()),
        Value::Lreal(_) => match v.as_f64() {
            Some(f) if f.is_finite() && f.is_sign_positive() => format!("{f:?}"),
            _ => format!("_plc_f64(0x{:016x}ull)", v.to_bits()),
        },
        v => {
            let i = v.as_i128().unwrap_or(0);
            let (lo, _) = int_range(ty);
            let lit = |n: i128| match ty {
                Type::Lint => format!("INT64_C({n})"),
                Type::Ulint | Type::Lword => format!("UINT64_C({n})"),
                Type::Udint | Type::Dword => format!("{n}u"),
                _ => n.to_string(),
            };
            if i == lo && i < 0 {
                format!("(-{} - 1)", lit(-(lo + 1)))
            } else {
                lit(i)
            }
        }
    }
}

/// The suffix of the runtime's functions for a number type (`i16` for INT, `u8` for USINT and
/// BYTE, `f64` for LREAL; TIME is `i32`).
pub(crate) fn num_suffix(ty: Type) -> &'static str {
    match ty {
        Type::Sint => "i8",
        Type::Int => "i16",
        Type::Lint => "i64",
        Type::Usint | Type::Byte => "u8",
        Type::Uint | Type::Word => "u16",
        Type::Udint | Type::Dword => "u32",
        Type::Ulint | Type::Lword => "u64",
        Type::Real => "f32",
        Type::Lreal => "f64",
        _ => "i32",
    }
}
