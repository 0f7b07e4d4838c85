//! The standard functions end to end: `convert` against a plain reference (property test), the
//! bitwise AND/OR/XOR/NOT of FBD blocks of WORDs,
//! located type and shape errors in the JSON format (exit 2, one line naming the operand),
//! the S7-200 IL instructions and the IL error for a function S7-200 cannot express, and a
//! `convert` round trip of a function box.

use crate::common;

use plc_deps::exec::functions::convert;
use plc_deps::model::{Type, Value};
use proptest::prelude::*;

/// The elementary types a conversion goes between.
const TYPES: [Type; 16] = [
    Type::Bool,
    Type::Sint,
    Type::Int,
    Type::Dint,
    Type::Lint,
    Type::Usint,
    Type::Uint,
    Type::Udint,
    Type::Ulint,
    Type::Real,
    Type::Lreal,
    Type::Byte,
    Type::Word,
    Type::Dword,
    Type::Lword,
    Type::Time,
];

/// An integer wrapped to the width of `to` (signed for the signed types and TIME).
fn wrap(v: i128, to: Type) -> i128 {
    let bits = to.bits();
    let m = 1i128 << bits;
    let r = v.rem_euclid(m);
    if (to.is_signed() || to == Type::Time) && r >= m / 2 {
        r - m
    } else {
        r
    }
}

/// A real rounded half away from zero, NaN 0, beyond the `i64` range its nearest end.
fn round_real(x: f64) -> i128 {
    if x.is_nan() {
        return 0;
    }
    // The integer part and the fraction (`x - t` is exact); `x ± 0.5` would not be beyond
    // 2^52, where it rounds to even.
    let t = x.trunc();
    let r = if (x - t).abs() >= 0.5 {
        t + x.signum()
    } else {
        t
    };
    // 2^63, exactly representable: the first real beyond `i64::MAX`.
    let two_63 = 2f64.powi(63);
    if r >= two_63 {
        i64::MAX as i128
    } else if r < -two_63 {
        i64::MIN as i128
    } else {
        r as i128
    }
}

/// The conversion rules of docs/scan.md, written out plainly in f64 and i128.
fn reference(v: Value, to: Type) -> Value {
    let real: Option<f64> = v.as_f64();
    let int: Option<i128> = match v {
        Value::Bool(b) => Some(b as i128),
        _ if real.is_some() => None,
        other => other.as_i128(),
    };
    match (to, int, real) {
        (Type::Bool, Some(i), _) => Value::Bool(i != 0),
        (Type::Bool, _, Some(x)) => Value::Bool(x != 0.0),
        (Type::Real, Some(i), _) => Value::Real(i as f32),
        (Type::Real, _, Some(x)) => Value::Real(x as f32),
        (Type::Lreal, Some(i), _) => Value::from_bits(Type::Lreal, (i as f64).to_bits()),
        (Type::Lreal, _, Some(x)) => Value::from_bits(Type::Lreal, x.to_bits()),
        (_, Some(i), _) => Value::int_of(to, wrap(i, to)).unwrap(),
        (_, _, Some(x)) => Value::int_of(to, wrap(round_real(x), to)).unwrap(),
        _ => unreachable!(),
    }
}

fn value() -> impl Strategy<Value = Value> {
    let ints = (0usize..TYPES.len(), any::<u64>()).prop_filter_map("an integer type", |(k, b)| {
        let t = TYPES[k];
        (t.is_int() || t.is_bits() || t == Type::Time).then(|| Value::from_bits(t, b))
    });
    prop_oneof![
        any::<bool>().prop_map(Value::Bool),
        ints,
        any::<f32>().prop_map(Value::Real),
        (-70000i32..70000, 0u8..4).prop_map(|(i, q)| Value::Real(i as f32 + q as f32 * 0.25)),
        any::<f64>().prop_map(|x| Value::from_bits(Type::Lreal, x.to_bits())),
        (-1i64 << 40..1i64 << 40, 0u8..4).prop_map(|(i, q)| Value::from_bits(
            Type::Lreal,
            (i as f64 + q as f64 * 0.25).to_bits()
        )),
    ]
}

fn same(a: Value, b: Value) -> bool {
    match (a.as_f64(), b.as_f64()) {
        (Some(x), Some(y)) => a.to_bits() == b.to_bits() || (x.is_nan() && y.is_nan()),
        _ => a == b,
    }
}

/// A large LREAL (an integer of 2^52 … 2^53, where `x - 0.5` would round to even) converts to its
/// own value wrapped: the case that showed the first reference wrong.
#[test]
fn a_large_lreal_converts_exactly() {
    let x = Value::from_bits(Type::Lreal, (3275193044u64 << 32) | 670172199);
    assert_eq!(convert(x, Type::Sint), reference(x, Type::Sint));
    let big = -((1u64 << 52) as f64) - 3.0;
    let v = Value::from_bits(Type::Lreal, big.to_bits());
    assert_eq!(
        convert(v, Type::Lint),
        Value::from_bits(Type::Lint, big as i64 as u64)
    );
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(4000))]
    #[test]
    fn convert_agrees_with_the_plain_reference(v in value(), k in 0usize..TYPES.len()) {
        let to = TYPES[k];
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
    assert!(
        e.contains("needs REAL or LREAL (SQRT), but `i` is INT"),
        "{e}"
    );
    assert!(e.contains("rungs[0].ld[0].in[0]"), "{e}");
    let e = load_error(&program(
        r#"{"op": "TRUNC", "in": ["r"], "out": "r"}"#,
        vars,
    ));
    assert!(
        e.contains("needs an integer type (ANY_INT) (TRUNC), but `r` is REAL"),
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

/// FBD AND, OR, XOR and NOT blocks of WORDs are the bitwise functions (a chain of them through
/// arcs, an extensible XOR, a constant), while the same blocks of BOOLs stay contacts; values
/// worked out by hand, after each of two scans.
#[test]
fn fbd_logic_blocks_of_words_are_bitwise() {
    use plc_deps::exec::{ExecConfig, Layout, Machine};
    use plc_deps::model::VarId;
    let doc = serde_json::json!({"program": "p", "vars": [
        {"name": "status", "type": "WORD", "class": "input"},
        {"name": "mask", "type": "WORD", "class": "input"},
        {"name": "go", "type": "BOOL", "class": "input"},
        {"name": "stop", "type": "BOOL", "class": "input"},
        {"name": "bits", "type": "WORD"}, {"name": "flipped", "type": "WORD"},
        {"name": "run", "type": "BOOL"}
    ], "fbd": {"networks": [{"id": "N1", "blocks": [
        {"id": 1, "op": "AND", "in": ["status", "mask"]},
        {"id": 2, "op": "OR", "in": [{"from": 1}, 32768], "out": "bits"},
        {"id": 3, "op": "NOT", "in": [{"from": 2}]},
        {"id": 4, "op": "XOR", "in": [{"from": 3}, "status", 255], "out": "flipped"},
        {"id": 5, "op": "AND", "in": ["go", {"from": 6}]},
        {"id": 6, "op": "NOT", "in": ["stop"]},
        {"id": 7, "op": "OR", "in": [{"from": 5}, "run"], "out": "run"}
    ]}]}});
    let p = plc_deps::load::program_from_json(&doc.to_string()).unwrap();
    let words = p
        .rungs()
        .iter()
        .flat_map(|r| r.series.iter())
        .filter(|e| matches!(e, plc_deps::model::Element::Function { .. }))
        .count();
    assert_eq!(words, 4, "the four WORD blocks are functions");
    let m = Machine::new(&p, Layout::dense(&p), &ExecConfig::default()).unwrap();
    let id = |n: &str| VarId::from_raw(p.vars().iter().position(|v| v.name == n).unwrap() as u32);
    let mut st = m.initial_state();
    let mut got = Vec::new();
    for (k, (status, mask, go, stop)) in [
        (0x1234u16, 0xFFu16, true, false),
        (0xFFFF, 0x0F0F, false, true),
    ]
    .into_iter()
    .enumerate()
    {
        let set = [
            (id("status"), Value::Word(status)),
            (id("mask"), Value::Word(mask)),
            (id("go"), Value::Bool(go)),
            (id("stop"), Value::Bool(stop)),
        ];
        m.set_inputs(&mut st, &set);
        m.run_scan(&mut st, k as u64, &mut Vec::new());
        got.push(["bits", "flipped", "run"].map(|n| m.value(&st, id(n)).to_json().to_string()));
    }
    // 0x1234 & 0xFF | 0x8000 = 0x8034; NOT = 0x7FCB; ^ 0x1234 ^ 0xFF = 0x6D00; run latched.
    assert_eq!(got[0], ["32820", "27904", "true"]);
    // 0xFFFF & 0x0F0F | 0x8000 = 0x8F0F; NOT = 0x70F0; ^ 0xFFFF ^ 0xFF = 0x8FF0; run holds.
    assert_eq!(got[1], ["36623", "36848", "true"]);
}
