//! What the standard functions compute (`Element::Function`): one definition, which the
//! interpreter runs and the C runtime (`crates/plc-codegen/src/c/runtime.rs`, `_plc_fn_*`) mirrors
//! operation for operation; docs/scan.md *Standard functions* states the rules.
//!
//! - REAL functions are IEEE 754 `f32` operations: SQRT (exact), and LN, LOG, EXP, SIN … ATAN,
//!   EXPT through the platform's C math library (`logf`, `log10f`, `expf`, `sinf`, …, `powf`),
//!   which both the interpreter (Rust's `f32` methods call it) and the generated C call, so the
//!   two agree bit for bit on one host. Out of the domain the IEEE result stands: SQRT(-1) and
//!   LN(-1) are NaN, LN(0) is -inf; no fault. EXPT of an integer exponent converts it to REAL.
//! - ABS of an integer wraps (the model's overflow rule): ABS(INT#-32768) = -32768.
//! - SHL, SHR, ROL, ROR work on the bit pattern of the input's width ([`bit_width`]): SHL and
//!   SHR shift in zeros (SHR is logical) and give 0 for a count < 0 or ≥ the width; ROL and
//!   ROR rotate by the count modulo the width (a negative count rotates the other way).
//! - MUX(K, IN0 … INn) is INk; for K outside 0..=n it is the type's zero (0, FALSE, T#0ms).
//! - AND, OR, XOR (of two or more inputs) and NOT of a bit string or integer work bit by bit
//!   on its bit pattern of the type's width (IEC 61131-3 2.5.1.5.3; `NOT(INT#0)` is -1).
//! - [`convert`]: one function from a value to a type (module docs of `convert`).
//!
//! Not here: the typing of a call (`plc_model::Function::types`).

use plc_model::{bit_width, Function, Type, Value, Wide};

/// `func(args)` as a value of type `out` (the types are the call's, as resolved).
pub fn apply(func: Function, args: &[Value], out: Type) -> Value {
    use Function::*;
    match func {
        Abs => match args[0] {
            Value::Real(x) => Value::Real(x.abs()),
            Value::Lreal(w) => Value::Lreal(Wide::new(f64::from_bits(w.bits()).abs().to_bits())),
            v if v.ty().is_signed() => from_integer(integer(v).abs(), out),
            other => other,
        },
        Sqrt | Ln | Log | Exp | Sin | Cos | Tan | Asin | Acos | Atan => match out {
            Type::Lreal => lreal(real_fn64(func, real64(args[0]))),
            _ => Value::Real(real_fn(func, real32(args[0]))),
        },
        Expt => match out {
            Type::Lreal => lreal(real64(args[0]).powf(real64(args[1]))),
            _ => Value::Real(real32(args[0]).powf(real32(args[1]))),
        },
        Shl | Shr | Rol | Ror => {
            let n = integer(args[1]) as i64;
            let width = bit_width(out).unwrap_or(32);
            Value::from_bits(out, shift(func, args[0].to_bits(), n, width))
        }
        Mux => {
            let k = integer(args[0]);
            match usize::try_from(k).ok().and_then(|k| args.get(k + 1)) {
                Some(v) => *v,
                None => out.zero(),
            }
        }
        And => Value::from_bits(out, args.iter().fold(u64::MAX, |m, v| m & v.to_bits())),
        Or => Value::from_bits(out, args.iter().fold(0, |m, v| m | v.to_bits())),
        Xor => Value::from_bits(out, args.iter().fold(0, |m, v| m ^ v.to_bits())),
        Not => Value::from_bits(out, !args[0].to_bits()),
        Convert { .. } => convert(args[0], out),
        Trunc => from_integer(real_to_i64(real64(args[0]).trunc()) as i128, out),
        // The string functions run on STRING slots (`strings::apply`), never here.
        Concat | Len | Left | Right | Mid | Insert | Delete | Replace | Find => out.zero(),
    }
}

/// The real function `f` (one of SQRT … ATAN) of `x`, in the float type of `x`: `f32` for
/// REAL, `f64` for LREAL (`real_fn`, `real_fn64`: one body, the C library's float or double
/// functions).
macro_rules! real_function {
    ($name:ident, $t:ty) => {
        fn $name(f: Function, x: $t) -> $t {
            match f {
                Function::Sqrt => x.sqrt(),
                Function::Ln => x.ln(),
                Function::Log => x.log10(),
                Function::Exp => x.exp(),
                Function::Sin => x.sin(),
                Function::Cos => x.cos(),
                Function::Tan => x.tan(),
                Function::Asin => x.asin(),
                Function::Acos => x.acos(),
                _ => x.atan(),
            }
        }
    };
}
real_function!(real_fn, f32);
real_function!(real_fn64, f64);

/// `bits` (the low `width` bits) shifted or rotated by `n`.
pub fn shift(f: Function, bits: u64, n: i64, width: u32) -> u64 {
    let mask = if width == 64 {
        u64::MAX
    } else {
        (1u64 << width) - 1
    };
    let v = bits & mask;
    let w = width as i64;
    let r = match f {
        Function::Shl | Function::Shr if !(0..w).contains(&n) => 0,
        Function::Shl => v << n,
        Function::Shr => v >> n,
        _ => {
            let k = n.rem_euclid(w) as u32;
            let k = if f == Function::Ror {
                (width - k) % width
            } else {
                k
            };
            if k == 0 {
                v
            } else {
                (v << k) | (v >> (width - k))
            }
        }
    };
    r & mask
}

fn lreal(x: f64) -> Value {
    Value::Lreal(Wide::new(x.to_bits()))
}

/// The REAL (`f32`) value of an argument: a REAL as it is, an LREAL rounded to nearest, an
/// integer (exact, then rounded to nearest, as C's conversion from its own type rounds).
fn real32(v: Value) -> f32 {
    match v {
        Value::Real(x) => x,
        Value::Lreal(w) => f64::from_bits(w.bits()) as f32,
        other => integer(other) as f32,
    }
}

/// The LREAL (`f64`) value of an argument.
fn real64(v: Value) -> f64 {
    match v {
        Value::Real(x) => x as f64,
        Value::Lreal(w) => f64::from_bits(w.bits()),
        other => integer(other) as f64,
    }
}

/// The integer value of an integer, bit string, BOOL or TIME argument, exactly; of a REAL or
/// LREAL, rounded ([`real_to_i64`] of the rounded value).
fn integer(v: Value) -> i128 {
    match v {
        Value::Bool(b) => b as i128,
        Value::Real(x) => real_to_i64(x.round() as f64) as i128,
        Value::Lreal(w) => real_to_i64(f64::from_bits(w.bits()).round()) as i128,
        other => other.as_i128().unwrap_or(0),
    }
}

/// An integral real as an `i64`: NaN is 0, beyond the range the nearest end (as the C
/// runtime's `_plc_lreal_to_i64`).
fn real_to_i64(x: f64) -> i64 {
    x as i64
}

/// An integer as a value of type `ty`, wrapping to its width (the model's overflow rule).
fn from_integer(i: i128, ty: Type) -> Value {
    match ty {
        Type::Bool => Value::Bool(i != 0),
        Type::Real => Value::Real(i as f32),
        Type::Lreal => lreal(i as f64),
        Type::Fb(_) => Value::Bool(false),
        _ => Value::from_bits(ty, i as u64),
    }
}

/// `v` converted to type `to` (IEC 61131-3 2.5.1.5.1, `*_TO_*`):
/// - to BOOL: non-zero is TRUE (a REAL NaN is non-zero);
/// - BOOL to a number: 0 or 1;
/// - between the integers, bit strings and TIME (milliseconds): the integer, wrapped to the
///   target's width (the model's overflow rule: DINT_TO_INT(40000) = -25536);
/// - an integer to REAL or LREAL: the nearest value (ties to even); LREAL to REAL the nearest;
/// - REAL or LREAL to an integer type: rounded to the nearest integer, halfway cases away from
///   zero (`round`: 0.5 → 1, 1.5 → 2, 2.5 → 3, -2.5 → -3, as matiec/Beremiz's `__real_to_sint`
///   and CODESYS's `REAL_TO_INT(1.5) = 2` do), NaN → 0, beyond ±2^63 the nearest end, then
///   wrapped to the target's width like any other integer.
pub fn convert(v: Value, to: Type) -> Value {
    match (v, to) {
        (Value::Real(x), Type::Bool) => Value::Bool(x != 0.0),
        (Value::Lreal(w), Type::Bool) => Value::Bool(f64::from_bits(w.bits()) != 0.0),
        (_, Type::Real) => Value::Real(real32(v)),
        (_, Type::Lreal) => lreal(real64(v)),
        (other, _) => from_integer(integer(other), to),
    }
}

/// `convert(v, to)` where a TIME is counted in units of `unit` milliseconds rather than in
/// milliseconds ([`plc_model::Dialect::time_unit_ms`]: matiec's seconds): TIME to an integer
/// is the whole units, toward zero (`tv_sec`); TIME to a real the units with their fraction;
/// an integer to TIME that many units, a real to TIME its units cut toward zero to the
/// millisecond (matiec's `__real_to_time` keeps the fraction in nanoseconds); anything else as
/// [`convert`].
pub fn convert_time_in(v: Value, from: Type, to: Type, unit: i64) -> Value {
    let unit = unit as i128;
    match (from, to) {
        (Type::Time, Type::Time) | (Type::Time, Type::Bool) => convert(v, to),
        (Type::Time, Type::Real | Type::Lreal) => {
            let units = integer(v) as f64 / unit as f64;
            convert(lreal(units), to)
        }
        (Type::Time, _) => from_integer(integer(v) / unit, to),
        (Type::Real | Type::Lreal, Type::Time) => {
            let ms = (real64(v) * unit as f64).trunc();
            from_integer(real_to_i64(ms) as i128, to)
        }
        (_, Type::Time) => from_integer(integer(v) * unit, to),
        _ => convert(v, to),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use Function::*;

    fn one(f: Function, v: Value, out: Type) -> Value {
        apply(f, &[v], out)
    }

    #[test]
    fn numeric_functions_on_edge_cases() {
        assert_eq!(
            one(Abs, Value::Int(i16::MIN), Type::Int),
            Value::Int(i16::MIN)
        );
        assert_eq!(one(Abs, Value::Dint(-7), Type::Dint), Value::Dint(7));
        assert_eq!(one(Abs, Value::Real(-0.0), Type::Real), Value::Real(0.0));
        assert_eq!(
            one(Sqrt, Value::Real(2.0), Type::Real),
            Value::Real(2f32.sqrt())
        );
        let Value::Real(x) = one(Sqrt, Value::Real(-1.0), Type::Real) else {
            panic!()
        };
        assert!(x.is_nan());
        assert_eq!(
            one(Ln, Value::Real(0.0), Type::Real),
            Value::Real(f32::NEG_INFINITY)
        );
        assert_eq!(one(Log, Value::Real(1000.0), Type::Real), Value::Real(3.0));
        assert_eq!(one(Exp, Value::Real(0.0), Type::Real), Value::Real(1.0));
        assert_eq!(one(Sin, Value::Real(0.0), Type::Real), Value::Real(0.0));
        assert_eq!(one(Cos, Value::Real(0.0), Type::Real), Value::Real(1.0));
        assert_eq!(
            one(Atan, Value::Real(f32::INFINITY), Type::Real),
            Value::Real(std::f32::consts::FRAC_PI_2)
        );
        let Value::Real(x) = one(Asin, Value::Real(2.0), Type::Real) else {
            panic!()
        };
        assert!(x.is_nan());
        let e = |a, b| apply(Expt, &[a, b], Type::Real);
        assert_eq!(e(Value::Real(2.0), Value::Int(10)), Value::Real(1024.0));
        assert_eq!(e(Value::Real(2.0), Value::Real(-1.0)), Value::Real(0.5));
        assert_eq!(e(Value::Real(0.0), Value::Int(0)), Value::Real(1.0));
    }

    #[test]
    fn shifts_are_on_the_bit_pattern_of_the_width() {
        let s = |f, a, n, ty| apply(f, &[a, Value::Dint(n)], ty);
        assert_eq!(s(Shl, Value::Int(1), 15, Type::Int), Value::Int(i16::MIN));
        assert_eq!(s(Shl, Value::Int(1), 16, Type::Int), Value::Int(0));
        assert_eq!(s(Shl, Value::Int(1), -1, Type::Int), Value::Int(0));
        assert_eq!(s(Shr, Value::Int(-1), 4, Type::Int), Value::Int(0x0fff));
        assert_eq!(
            s(Shr, Value::Dint(i32::MIN), 31, Type::Dint),
            Value::Dint(1)
        );
        assert_eq!(s(Rol, Value::Int(i16::MIN), 1, Type::Int), Value::Int(1));
        assert_eq!(s(Ror, Value::Int(1), 1, Type::Int), Value::Int(i16::MIN));
        assert_eq!(
            s(Rol, Value::Dint(0x1234_5678), 36, Type::Dint),
            Value::Dint(0x2345_6781)
        );
        assert_eq!(s(Ror, Value::Dint(1), -1, Type::Dint), Value::Dint(2));
        assert_eq!(s(Rol, Value::Int(5), 0, Type::Int), Value::Int(5));
    }

    #[test]
    fn mux_picks_its_kth_input_or_zero() {
        let ins = [
            Value::Int(0),
            Value::Time(10),
            Value::Time(20),
            Value::Time(30),
        ];
        let m = |k| apply(Mux, &[Value::Int(k), ins[1], ins[2], ins[3]], Type::Time);
        assert_eq!(m(0), Value::Time(10));
        assert_eq!(m(2), Value::Time(30));
        assert_eq!(m(3), Value::Time(0));
        assert_eq!(m(-1), Value::Time(0));
    }

    #[test]
    fn conversions_round_truncate_and_wrap() {
        let c = convert;
        assert_eq!(c(Value::Real(0.5), Type::Int), Value::Int(1));
        assert_eq!(c(Value::Real(1.5), Type::Int), Value::Int(2));
        assert_eq!(c(Value::Real(2.5), Type::Int), Value::Int(3));
        assert_eq!(c(Value::Real(-2.5), Type::Dint), Value::Dint(-3));
        assert_eq!(c(Value::Real(-1.4), Type::Dint), Value::Dint(-1));
        assert_eq!(c(Value::Real(f32::NAN), Type::Dint), Value::Dint(0));
        assert_eq!(c(Value::Real(40000.0), Type::Int), Value::Int(-25536));
        assert_eq!(c(Value::Real(1e30), Type::Dint), Value::Dint(-1));
        assert_eq!(c(Value::Real(1.5), Type::Time), Value::Time(2));
        assert_eq!(c(Value::Dint(40000), Type::Int), Value::Int(-25536));
        assert_eq!(c(Value::Int(-1), Type::Dint), Value::Dint(-1));
        assert_eq!(
            c(Value::Dint(16_777_217), Type::Real),
            Value::Real(16_777_216.0)
        );
        assert_eq!(c(Value::Time(1500), Type::Dint), Value::Dint(1500));
        assert_eq!(c(Value::Bool(true), Type::Real), Value::Real(1.0));
        assert_eq!(c(Value::Int(-3), Type::Bool), Value::Bool(true));
        assert_eq!(c(Value::Real(f32::NAN), Type::Bool), Value::Bool(true));
        assert_eq!(c(Value::Real(0.0), Type::Bool), Value::Bool(false));
        let t = |x| apply(Trunc, &[Value::Real(x)], Type::Int);
        assert_eq!(t(2.9), Value::Int(2));
        assert_eq!(t(-2.9), Value::Int(-2));
        assert_eq!(t(70000.7), Value::Int(4464));
    }
}
