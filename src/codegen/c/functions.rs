//! The standard functions (`Element::Function`) as C expressions over the runtime's
//! `_plc_fn_*` helpers, each the C form of one rule of `crate::exec::functions` (the
//! interpreter's definition): REAL functions call the C math library the interpreter calls too,
//! through `_plc_opaque_f32` so that GCC cannot fold a constant argument with its own (more
//! exact) arithmetic; integers wrap with `_plc_w16`/`_plc_w32`; REAL to an integer rounds with
//! `roundf` (halfway away from zero) or truncates with `truncf`, then `_plc_real_to_i64`.
//!
//! Not here: where the statement goes (`ladder`), the helpers' text (`runtime`, after `_plc_f32`).

use crate::model::{bit_width, Function, Type};

/// `func(args)` as a C expression of the output type `out`; each argument is its C text and
/// its type.
pub(crate) fn expr(func: Function, args: &[(String, Type)], out: Type) -> String {
    use Function::*;
    let a = |i: usize| args[i].0.as_str();
    match func {
        Abs => match out {
            Type::Int => format!("_plc_fn_abs_i16({})", a(0)),
            Type::Real => format!("fabsf({})", a(0)),
            _ => format!("_plc_fn_abs_i32({})", a(0)),
        },
        Sqrt | Ln | Log | Exp | Sin | Cos | Tan | Asin | Acos | Atan => {
            let f = func.name().to_ascii_lowercase();
            format!("_plc_fn_{f}({})", a(0))
        }
        Expt => format!("_plc_fn_expt({}, (float){})", a(0), a(1)),
        Shl | Shr | Rol | Ror => {
            let width = bit_width(out).unwrap_or(32);
            let kind = match func {
                Shl => 0,
                Shr => 1,
                Rol => 2,
                _ => 3,
            };
            let mask = if width == 16 { "uint16_t" } else { "uint32_t" };
            wrap(
                &format!(
                    "(int64_t)_plc_fn_shift({kind}, (uint64_t)({mask}){}, (int64_t){}, {width})",
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
        Convert { .. } => convert(a(0), args[0].1, out),
        Trunc => wrap(&format!("_plc_real_to_i64(truncf({}))", a(0)), out),
    }
}

/// `x` (of type `from`) converted to `to`, as `crate::exec::functions::convert` does.
fn convert(x: &str, from: Type, to: Type) -> String {
    match (from, to) {
        (_, Type::Bool) => format!("({x} != 0)"),
        (Type::Real, Type::Real) => x.to_owned(),
        (_, Type::Real) => format!("(float){x}"),
        (Type::Real, _) => wrap(&format!("_plc_real_to_i64(roundf({x}))"), to),
        _ => wrap(&format!("(int64_t){x}"), to),
    }
}

/// An `int64_t` expression wrapped to an integer type's width (TIME and DINT: 32 bits).
fn wrap(e: &str, to: Type) -> String {
    match to {
        Type::Int => format!("_plc_w16({e})"),
        Type::Bool => format!("({e} != 0)"),
        Type::Real => format!("(float){e}"),
        _ => format!("_plc_w32({e})"),
    }
}

/// The zero of a type as C (MUX out of range).
fn zero(ty: Type) -> &'static str {
    match ty {
        Type::Real => "0.0f",
        _ => "0",
    }
}
