//! The standard functions end to end: `convert` against a plain reference (property test),
//! located type and shape errors in the JSON format (exit 2, one line naming the operand),
//! the S7-200 IL instructions and the IL error for a function S7-200 cannot express, and a
//! `convert` round trip of a function box.

mod common;

use plc_deps::exec::functions::convert;
use plc_deps::model::{Type, Value};
use proptest::prelude::*;

/// An integer wrapped to `bits` bits, signed.
fn wrap(v: i128, bits: u32) -> i128 {
    let m = 1i128 << bits;
    let r = v.rem_euclid(m);
    if r >= m / 2 {
        r - m
    } else {
        r
    }
}

/// The conversion rules of docs/scan.md, written out plainly in f64 and i128.
fn reference(v: Value, to: Type) -> Value {
    let int: Option<i128> = match v {
        Value::Bool(b) => Some(b as i128),
        Value::Int(i) => Some(i as i128),
        Value::Dint(i) | Value::Time(i) => Some(i as i128),
        Value::Real(x) if to == Type::Real || to == Type::Bool => None,
        Value::Real(x) => {
            let x = x as f64;
            Some(if x.is_nan() {
                0
            } else {
                let r = if x >= 0.0 {
                    (x + 0.5).floor()
                } else {
                    (x - 0.5).ceil()
                };
                if r >= 9.223372036854775808e18 {
                    i64::MAX as i128
                } else if r < -9.223372036854775808e18 {
                    i64::MIN as i128
                } else {
                    r as i128
                }
            })
        }
    };
    match (to, int, v) {
        (Type::Bool, Some(i), _) => Value::Bool(i != 0),
        (Type::Bool, None, Value::Real(x)) => Value::Bool(x != 0.0),
        (Type::Real, None, Value::Real(x)) => Value::Real(x),
        (Type::Real, Some(i), _) => Value::Real(i as f64 as f32),
        (Type::Int, Some(i), _) => Value::Int(wrap(i, 16) as i16),
        (Type::Dint, Some(i), _) => Value::Dint(wrap(i, 32) as i32),
        (Type::Time, Some(i), _) => Value::Time(wrap(i, 32) as i32),
        _ => unreachable!(),
    }
}

fn value() -> impl Strategy<Value = Value> {
    prop_oneof![
        any::<bool>().prop_map(Value::Bool),
        any::<i16>().prop_map(Value::Int),
        any::<i32>().prop_map(Value::Dint),
        any::<i32>().prop_map(Value::Time),
        any::<f32>().prop_map(Value::Real),
        (-70000i32..70000, 0u8..4).prop_map(|(i, q)| Value::Real(i as f32 + q as f32 * 0.25)),
    ]
}

fn same(a: Value, b: Value) -> bool {
    match (a, b) {
        (Value::Real(x), Value::Real(y)) => {
            x.to_bits() == y.to_bits() || (x.is_nan() && y.is_nan())
        }
        _ => a == b,
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(4000))]
    #[test]
    fn convert_agrees_with_the_plain_reference(v in value(), k in 0usize..5) {
        let to = [Type::Bool, Type::Int, Type::Dint, Type::Real, Type::Time][k];
        let (got, want) = (convert(v, to), reference(v, to));
        prop_assert!(same(got, want), "{v:?} → {to}: {got:?}, reference {want:?}");
    }
}

fn program(rung: &str, vars: &str) -> String {
    format!(r#"{{"program": "p", "vars": [{vars}], "rungs": [{{"id": "R1", "ld": [{rung}]}}]}}"#)
}

fn load_error(text: &str) -> String {
    let out = common::cli::run_stdin(&["report", "-"], text.as_bytes());
    assert_eq!(
        out.status.code(),
        Some(2),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    common::cli::one_line(&String::from_utf8_lossy(&out.stderr))
}

#[test]
fn a_function_box_of_the_wrong_types_is_a_located_error() {
    let vars = r#"{"name": "i", "type": "INT"}, {"name": "r", "type": "REAL"}"#;
    let e = load_error(&program(r#"{"op": "SQRT", "in": ["i"], "out": "r"}"#, vars));
    assert!(e.contains("needs REAL (SQRT), but `i` is INT"), "{e}");
    assert!(e.contains("rungs[0].ld[0].in[0]"), "{e}");
    let e = load_error(&program(
        r#"{"op": "TRUNC", "in": ["r"], "out": "r"}"#,
        vars,
    ));
    assert!(
        e.contains("needs INT or DINT (TRUNC), but `r` is REAL"),
        "{e}"
    );
    assert!(e.contains("rungs[0].ld[0].out"), "{e}");
    let e = load_error(&program(
        r#"{"op": "INT_TO_REAL", "in": ["r"], "out": "r"}"#,
        vars,
    ));
    assert!(
        e.contains("needs INT (INT_TO_REAL), but `r` is REAL"),
        "{e}"
    );
    let e = load_error(&program(r#"{"op": "SHL", "in": ["i"], "out": "i"}"#, vars));
    assert!(e.contains("expected two operands, found 1 operands"), "{e}");
    let e = load_error(&program(
        r#"{"op": "MUX", "in": [0, "i"], "out": "i"}"#,
        vars,
    ));
    assert!(e.contains("expected K and two or more inputs"), "{e}");
    let e = load_error(&program(
        r#"{"op": "SQRTX", "in": ["r"], "out": "r"}"#,
        vars,
    ));
    assert!(e.contains("a standard function"), "{e}");
}

#[test]
fn il_has_the_s7_200_instruction_or_a_clear_error() {
    let vars = r#"{"name": "i", "type": "INT"}, {"name": "d", "type": "DINT"}, {"name": "r", "type": "REAL"}, {"name": "x", "type": "BOOL", "class": "input"}"#;
    let rung = r#"{"contact": "x"}, {"op": "SQRT", "in": ["r"], "out": "r"}, {"op": "SHL", "in": ["i", 3], "out": "i"}, {"op": "ROR", "in": ["d", 1], "out": "d"}, {"op": "INT_TO_DINT", "in": ["i"], "out": "d"}, {"op": "REAL_TO_DINT", "in": ["r"], "out": "d"}"#;
    let out = common::cli::run_stdin(&["il", "-"], program(rung, vars).as_bytes());
    assert_eq!(
        out.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let il = String::from_utf8_lossy(&out.stdout);
    let il = il.split_whitespace().collect::<Vec<_>>().join(" ");
    for line in [
        "SQRT r, r",
        "SLW i, 3",
        "RRD d, 1",
        "I_DI i, d",
        "ROUND r, d",
    ] {
        assert!(il.contains(line), "{line} in {il}");
    }
    let out = common::cli::run_stdin(
        &["il", "-"],
        program(r#"{"op": "MUX", "in": [0, 1, 2], "out": "i"}"#, vars).as_bytes(),
    );
    assert_eq!(out.status.code(), Some(2));
    let e = String::from_utf8_lossy(&out.stderr);
    assert!(
        e.contains("MUX of INT is not expressible in S7-200 IL") && e.contains("R1"),
        "{e}"
    );
}

#[test]
fn a_function_box_converts_and_reads_back() {
    let vars = r#"{"name": "k", "type": "INT"}, {"name": "t", "type": "TIME"}"#;
    let text = program(
        r#"{"op": "MUX", "in": ["k", "T#1s", "T#2s", "T#3s"], "out": "t"}"#,
        vars,
    );
    let out = common::cli::run_stdin(&["convert", "-"], text.as_bytes());
    assert_eq!(out.status.code(), Some(0));
    let json = String::from_utf8_lossy(&out.stdout);
    assert!(
        json.contains(r#"{"op":"MUX","in":["k","T#1s","T#2s","T#3s"],"out":"t"}"#),
        "{json}"
    );
    let again = common::cli::run_stdin(&["convert", "-"], json.as_bytes());
    assert_eq!(String::from_utf8_lossy(&again.stdout), json);
}
