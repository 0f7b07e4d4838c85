//! The standard functions (`Element::Function`) as C expressions over the runtime's
//! `_plc_fn_*` helpers, each the C form of one rule of `plc_exec::functions` (the
//! interpreter's definition): REAL functions call the C math library the interpreter calls too,
//! through `_plc_opaque_f32` so that GCC cannot fold a constant argument with its own (more
//! exact) arithmetic; integers wrap through `uint64_t` to their width; REAL or LREAL to an integer rounds with
//! `roundf`/`round` (halfway away from zero) or truncates with `trunc`, then `_plc_lreal_to_i64`.
//!
//! Not here: where the statement goes (`ladder`), the helpers' text (`runtime`, after `_plc_f32`).

use super::spelling::{c_type, num_suffix};
use plc_model::{bit_width, Function, Type};

/// `func(args)` as a C expression of the output type `out`; each argument is its C text and
/// its type.
///
/// `time_unit`: milliseconds per unit of a number converted from or to TIME
/// ([`plc_model::Dialect::time_unit_ms`]), as `plc_exec::functions::convert_time_in`.
pub(crate) fn expr(func: Function, args: &[(String, Type)], out: Type, time_unit: i64) -> String {
    use Function::*;
    let a = |i: usize| args[i].0.as_str();
    let wide = out == Type::Lreal;
    if func.is_textual() {
        return string_expr(func, args, out);
    }
    match func {
        Abs => match out {
            Type::Real => format!("fabsf({})", a(0)),
            Type::Lreal => format!("fabs({})", a(0)),
            t if t.is_signed() => format!("_plc_fn_abs_{}({})", num_suffix(t), a(0)),
            _ => a(0).to_owned(),
        },
        Sqrt | Ln | Log | Exp | Sin | Cos | Tan | Asin | Acos | Atan => {
            let f = func.name().to_ascii_lowercase();
            let suffix = if wide { "_f64" } else { "" };
            format!("_plc_fn_{f}{suffix}({})", as_real(a(0), args[0].1, out))
        }
        Expt if wide => format!(
            "_plc_fn_expt_f64({}, {})",
            as_real(a(0), args[0].1, out),
            as_real(a(1), args[1].1, out)
        ),
        Expt => format!(
            "_plc_fn_expt({}, {})",
            as_real(a(0), args[0].1, out),
            as_real(a(1), args[1].1, out)
        ),
        Shl | Shr | Rol | Ror => {
            let width = bit_width(out).unwrap_or(32);
            let kind = match func {
                Shl => 0,
                Shr => 1,
                Rol => 2,
                _ => 3,
            };
            wrap(
                &format!(
                    "(int64_t)_plc_fn_shift({kind}, (uint64_t)({}){}, (int64_t){}, {width})",
                    unsigned(width),
                    a(0),
                    a(1)
                ),
                out,
            )
        }
        Mux => {
            let k = a(0);
            let mut e = zero(out).to_owned();
            for i in (1..args.len()).rev() {
                e = format!("((int64_t){k} == {} ? {} : {e})", i - 1, a(i));
            }
            e
        }
        And | Or | Xor => {
            let op = match func {
                And => " & ",
                Or => " | ",
                _ => " ^ ",
            };
            let bits: Vec<String> = (0..args.len()).map(|i| bits_of(a(i), out)).collect();
            wrap(&format!("(int64_t)({})", bits.join(op)), out)
        }
        Not => wrap(&format!("(int64_t)~{}", bits_of(a(0), out)), out),
        Convert { from, to } if time_unit != 1 && (from == Type::Time) != (to == Type::Time) => {
            convert_time_in(a(0), from, to, time_unit)
        }
        Convert { .. } => convert(a(0), args[0].1, out),
        Trunc => wrap(&format!("{}(trunc((double){}))", TO_I64, a(0)), out),
        Concat | Len | Left | Right | Mid | Insert | Delete | Replace | Find => {
            string_expr(func, args, out)
        }
    }
}

/// The runtime's real-to-`int64_t` conversion (NaN 0, beyond the range the nearest end).
const TO_I64: &str = "_plc_lreal_to_i64";

/// `x` (of type `from`) as the real type `out` (REAL or LREAL), as C converts.
fn as_real(x: &str, from: Type, out: Type) -> String {
    if from == out {
        x.to_owned()
    } else {
        format!("({}){x}", c_type(out))
    }
}

/// `x` (of type `from`) converted to `to`, as `plc_exec::functions::convert` does.
fn convert(x: &str, from: Type, to: Type) -> String {
    match (from, to) {
        (_, Type::Bool) => format!("({x} != 0)"),
        (_, Type::Real | Type::Lreal) => as_real(x, from, to),
        (Type::Real, _) => wrap(&format!("{TO_I64}((double)roundf({x}))"), to),
        (Type::Lreal, _) => wrap(&format!("{TO_I64}(round({x}))"), to),
        _ => wrap(&format!("(int64_t){x}"), to),
    }
}

/// `x` (of type `from`) converted to `to` with TIME counted in units of `unit` ms, as
/// `plc_exec::functions::convert_time_in`: TIME to an integer whole units toward zero (C's
/// division), to a real the units with their fraction; an integer to TIME that many units, a
/// real its units cut toward zero to the millisecond.
fn convert_time_in(x: &str, from: Type, to: Type, unit: i64) -> String {
    match (from, to) {
        (Type::Time, Type::Bool) => convert(x, from, to),
        (Type::Time, Type::Real | Type::Lreal) => {
            format!("({})((double){x} / {unit}.0)", c_type(to))
        }
        (Type::Time, _) => wrap(&format!("((int64_t){x} / {unit})"), to),
        (Type::Real | Type::Lreal, Type::Time) => {
            wrap(&format!("{TO_I64}(trunc((double){x} * {unit}.0))"), to)
        }
        (_, Type::Time) => wrap(&format!("((int64_t){x} * {unit})"), to),
        _ => convert(x, from, to),
    }
}

/// A string function or a conversion to or from STRING (`_plc_str_*` of the runtime, each the
/// C form of one rule of `plc_exec::strings`); integer arguments as `int64_t`, integer results
/// wrapped to the output's type.
fn string_expr(func: Function, args: &[(String, Type)], out: Type) -> String {
    use Function::*;
    let a = |i: usize| args[i].0.as_str();
    let n = |i: usize| format!("(int64_t)({})", a(i));
    match func {
        Concat => args[1..].iter().fold(a(0).to_owned(), |acc, (x, _)| {
            format!("_plc_str_concat({acc}, {x})")
        }),
        Len => wrap(&format!("{}.len", a(0)), out),
        Left => format!("_plc_str_left({}, {})", a(0), n(1)),
        Right => format!("_plc_str_right({}, {})", a(0), n(1)),
        Mid => format!("_plc_str_mid({}, {}, {})", a(0), n(1), n(2)),
        Insert => format!("_plc_str_insert({}, {}, {})", a(0), a(1), n(2)),
        Delete => format!("_plc_str_delete({}, {}, {})", a(0), n(1), n(2)),
        Replace => format!("_plc_str_replace({}, {}, {}, {})", a(0), a(1), n(2), n(3)),
        Find => wrap(&format!("_plc_str_find({}, {})", a(0), a(1)), out),
        Convert { from, .. } if out == Type::String => match from {
            Type::Bool => format!("_plc_str_of_bool({})", a(0)),
            t if t.is_bits() => format!("_plc_str_of_bits((uint64_t)({}))", a(0)),
            t if t.is_unsigned() => format!("_plc_str_of_uint((uint64_t)({}))", a(0)),
            _ => format!("_plc_str_of_int((int64_t)({}))", a(0)),
        },
        _ if out == Type::Bool => format!("_plc_str_to_bool({})", a(0)),
        _ => wrap(&format!("_plc_str_to_int({})", a(0)), out),
    }
}

/// An `int64_t` expression wrapped to an integer type's width (two's complement).
fn wrap(e: &str, to: Type) -> String {
    match to {
        Type::Bool => format!("({e} != 0)"),
        Type::Real | Type::Lreal => format!("({}){e}", c_type(to)),
        t => format!("({})({})(uint64_t)({e})", c_type(t), unsigned(t.bits())),
    }
}

/// `x`'s bit pattern of `ty`'s width as a `uint64_t` (the upper bits zero).
fn bits_of(x: &str, ty: Type) -> String {
    format!("(uint64_t)({})({x})", unsigned(ty.bits()))
}

/// The unsigned C type of `width` bits.
fn unsigned(width: u32) -> &'static str {
    match width {
        8 => "uint8_t",
        16 => "uint16_t",
        32 => "uint32_t",
        _ => "uint64_t",
    }
}

/// The zero of a type as C (MUX out of range).
fn zero(ty: Type) -> &'static str {
    match ty {
        Type::Real => "0.0f",
        Type::Lreal => "0.0",
        _ => "0",
    }
}
