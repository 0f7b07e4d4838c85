//! The arithmetic `plc-deps il` writes through a scratch word: MOD (`a - (a / b) * b`, with
//! `out := 0` when a variable divisor is 0) and `out := a - out` / `out := a / out`. The STL of
//! one MOD rung is pinned instruction by instruction; the whole program, read back by the STL
//! reader, gives the interpreter's state and faults after every scan for divisors of both
//! signs, zero, and the one overflowing quotient (-32768 / -1). Also a counter in a word
//! instruction, which the S7-200 reads as its count.

use plc_deps::exec::{ExecConfig, Layout, Machine};
use plc_deps::model::{Program, Value, VarId};
use serde_json::json;

fn program() -> serde_json::Value {
    let int = |name: &str, class: &str| json!({"name": name, "type": "INT", "class": class});
    json!({"program": "arith", "vars": [
        {"name": "go", "type": "BOOL", "class": "input"},
        int("a", "input"), int("b", "input"),
        int("r1", "memory"), int("r2", "memory"), int("r3", "memory"), int("r4", "memory"),
        int("r5", "memory"),
        {"name": "d", "type": "DINT", "init": 1000001}, {"name": "e", "type": "DINT"}
    ], "rungs": [
        {"id": "R1", "ld": [{"contact": "go"}, {"op": "MOD", "in": ["a", -3], "out": "r1"}]},
        {"id": "R2", "ld": [{"op": "MOD", "in": ["a", "b"], "out": "r2"}]},
        {"id": "R3", "ld": [{"op": "ADD", "in": ["r3", 11], "out": "r3"},
                            {"op": "MOD", "in": ["r3", "b"], "out": "r3"}]},
        {"id": "R4", "ld": [{"op": "SUB", "in": ["a", "r4"], "out": "r4"}]},
        {"id": "R5", "ld": [{"op": "ADD", "in": ["r5", 7], "out": "r5"},
                            {"op": "DIV", "in": [1000, "r5"], "out": "r5"}]},
        {"id": "R6", "ld": [{"op": "MOD", "in": ["d", 7], "out": "e"},
                            {"op": "ADD", "in": ["d", 3], "out": "d"}]}
    ]})
}

fn load(doc: &serde_json::Value) -> (Program, plc_deps::fbd::Fbd) {
    plc_deps::load::program_and_fbd_from_json(&doc.to_string()).expect("the program loads")
}

#[test]
fn a_mod_by_a_variable_is_a_division_a_product_a_difference_and_a_zero_test() {
    let (p, fbd) = load(&program());
    let stl = plc_deps::codegen::il::generate(&p, &fbd).unwrap();
    let net = |title: &str| {
        let start = stl.find(&format!("// {title}\n")).unwrap();
        let body = &stl[start..];
        let end = body[1..].find("NETWORK").map_or(body.len(), |e| e + 1);
        let end = body[..end].find("END_").unwrap_or(end);
        body[..end].lines().skip(1).collect::<Vec<_>>().join("\n")
    };
    assert_eq!(
        net("R2"),
        "LD     SM0.0\nMOVW   a, IL_TMP_INT\n/I     b, IL_TMP_INT\n*I     b, IL_TMP_INT\n\
         MOVW   a, r2\n-I     IL_TMP_INT, r2\nLPS\nAW=    b, 0\nMOVW   0, r2\nLPP"
    );
    // A constant divisor needs no zero test; `out := a - out` goes through the scratch word.
    assert_eq!(
        net("R1"),
        "LD     go\nMOVW   a, IL_TMP_INT\n/I     -3, IL_TMP_INT\n*I     -3, IL_TMP_INT\n\
         MOVW   a, r1\n-I     IL_TMP_INT, r1"
    );
    assert_eq!(
        net("R4"),
        "LD     SM0.0\nMOVW   a, IL_TMP_INT\n-I     r4, IL_TMP_INT\nMOVW   IL_TMP_INT, r4"
    );
    assert!(stl.contains("    IL_TMP_INT : INT; // scratch word of the arithmetic\n"));
    assert!(stl.contains("    IL_TMP_DINT : DINT; // scratch word of the arithmetic\n"));
}

/// The state of the program's variables and the faults (rung id, kind) after each scan.
fn run(p: &Program, scans: &[(bool, i16, i16)]) -> Vec<String> {
    run_named(p, &["r1", "r2", "r3", "r4", "r5", "d", "e"], scans)
}

/// [`run`] showing the variables `names`.
fn run_named(p: &Program, names: &[&str], scans: &[(bool, i16, i16)]) -> Vec<String> {
    let m = Machine::new(p, Layout::dense(p), &ExecConfig::default()).unwrap();
    let id = |n: &str| VarId::from_raw(p.vars().iter().position(|v| v.name == n).unwrap() as u32);
    let mut st = m.initial_state();
    let mut out = Vec::new();
    for (k, &(go, a, b)) in scans.iter().enumerate() {
        let set = [
            (id("go"), Value::Bool(go)),
            (id("a"), Value::Int(a)),
            (id("b"), Value::Int(b)),
        ];
        m.set_inputs(&mut st, &set);
        let mut faults = Vec::new();
        m.run_scan(&mut st, k as u64, &mut faults);
        let mut line: Vec<String> = names
            .iter()
            .map(|n| format!("{n}={}", m.value(&st, id(n)).to_json()))
            .collect();
        line.extend(
            faults
                .iter()
                .map(|f| format!("{} {:?}", p.rung(f.rung).id, f.kind)),
        );
        out.push(line.join(" "));
    }
    out
}

#[test]
fn the_stl_read_back_gives_the_interpreters_results_and_faults() {
    let (p, fbd) = load(&program());
    let stl = plc_deps::codegen::il::generate(&p, &fbd).unwrap();
    let (back, _) = plc_deps::load::stl(&stl).unwrap_or_else(|e| panic!("{e:?}\n{stl}"));
    let mut scans = Vec::new();
    for a in [-7i16, 7, 0, -32768, 32767, 5] {
        for b in [3i16, 0, -1, -4, 1] {
            scans.push((a % 2 == 0, a, b));
        }
    }
    let want = run(&p, &scans);
    assert_eq!(run(&back, &scans), want, "\n{stl}");
    // The cases are the ones meant: -32768 MOD -1, a zero divisor (a fault, r2 = 0), a
    // negative dividend (the remainder takes its sign).
    assert!(want.iter().any(|l| l.contains("R2 DivByZero")));
    let at = |a: i16, b: i16| {
        let k = scans.iter().position(|s| s.1 == a && s.2 == b).unwrap();
        want[k].clone()
    };
    assert!(at(-32768, -1).contains("r2=0 "), "{}", at(-32768, -1));
    assert!(at(-7, 3).contains("r2=-1 "), "{}", at(-7, 3));
    assert!(at(7, -4).contains("r2=3 "), "{}", at(7, -4));
    assert!(at(7, 0).contains("r2=0 "), "{}", at(7, 0));
}

/// A counter in a word instruction is its count: `il` writes a CTU's CV that way (`LDW>= c1,
/// 2`, `MOVW c1, n`), and the reader reads it back, for a declared counter as for `C5`.
#[test]
fn a_counter_as_a_word_is_its_count() {
    let doc = json!({"program": "cv", "vars": [
        {"name": "up", "type": "BOOL", "class": "input"}, {"name": "r", "type": "BOOL", "class": "input"},
        {"name": "c1", "type": "CTU"}, {"name": "n", "type": "INT"}, {"name": "q", "type": "BOOL"}
    ], "rungs": [
        {"id": "R1", "ld": [{"contact": "up"}, {"ctu": "c1", "pv": 5, "reset": "r"}]},
        {"id": "R2", "ld": [{"compare": "GE", "a": "c1.CV", "b": 2}, {"coil": "q"}]},
        {"id": "R3", "ld": [{"move": "c1.CV", "to": "n"}]}
    ]});
    let (p, fbd) = load(&doc);
    let stl = plc_deps::codegen::il::generate(&p, &fbd).unwrap();
    assert!(stl.contains("\nLDW>=  c1, 2\n"), "{stl}");
    assert!(stl.contains("\nMOVW   c1, n\n"), "{stl}");
    let (back, _) = plc_deps::load::stl(&stl).unwrap_or_else(|e| panic!("{e:?}\n{stl}"));
    let absolute = "ORGANIZATION_BLOCK m:OB1\nNETWORK 1\nLD I0.0\nLD I0.1\nCTU C5, 5\n\
        NETWORK 2\nLDW>= C5, 2\n= Q0.0\nNETWORK 3\nLD SM0.0\nMOVW C5, VW0\nEND_ORGANIZATION_BLOCK\n";
    let (abs, _) = plc_deps::load::stl(absolute).unwrap_or_else(|e| panic!("{e:?}"));
    let trace = |p: &Program, names: [&str; 5]| {
        let m = Machine::new(p, Layout::dense(p), &ExecConfig::default()).unwrap();
        let id =
            |n: &str| VarId::from_raw(p.vars().iter().position(|v| v.name == n).unwrap() as u32);
        let mut st = m.initial_state();
        (0..12u64)
            .map(|k| {
                let (up, r) = (k % 2 == 0, k == 9);
                m.set_inputs(
                    &mut st,
                    &[
                        (id(names[0]), Value::Bool(up)),
                        (id(names[1]), Value::Bool(r)),
                    ],
                );
                m.run_scan(&mut st, k, &mut Vec::new());
                format!(
                    "{} {}",
                    m.value(&st, id(names[2])).to_json(),
                    m.value(&st, id(names[3])).to_json()
                ) + &format!(" {}", m.value(&st, id(names[4])).to_json())
            })
            .collect::<Vec<_>>()
    };
    let want = trace(&p, ["up", "r", "q", "n", "c1"]);
    assert_eq!(trace(&back, ["up", "r", "q", "n", "c1"]), want);
    assert_eq!(trace(&abs, ["I0_0", "I0_1", "Q0_0", "VW0", "C5"]), want);
    assert!(want[4].starts_with("true 3 "), "{:?}", want);
}

/// AND, OR, XOR and NOT of INTs and DINTs are the S7-200's ANDW/ORW/XORW/INVW and the D forms
/// in their two-operand form (`ANDW IN1, OUT` is `OUT := IN1 AND OUT`): an input that is the
/// output needs no move. Read back by the STL reader, the program computes the interpreter's
/// values for inputs of every sign, and the values are the ones worked out by hand.
#[test]
fn bitwise_functions_are_the_word_instructions_and_read_back() {
    let doc = json!({"program": "bits", "vars": [
        {"name": "go", "type": "BOOL", "class": "input"},
        {"name": "a", "type": "INT", "class": "input"}, {"name": "b", "type": "INT", "class": "input"},
        {"name": "r1", "type": "INT"}, {"name": "r2", "type": "INT"}, {"name": "r3", "type": "INT"},
        {"name": "r4", "type": "INT"}, {"name": "r5", "type": "INT"},
        {"name": "d", "type": "DINT", "init": 305419896}, {"name": "e", "type": "DINT"}
    ], "rungs": [
        {"id": "R1", "ld": [{"contact": "go"}, {"op": "AND", "in": ["a", 255], "out": "r1"}]},
        {"id": "R2", "ld": [{"op": "OR", "in": ["a", "b", 4096], "out": "r2"}]},
        {"id": "R3", "ld": [{"op": "XOR", "in": ["b", "r3"], "out": "r3"}]},
        {"id": "R4", "ld": [{"op": "NOT", "in": ["a"], "out": "r4"}]},
        {"id": "R5", "ld": [{"op": "NOT", "in": ["r5"], "out": "r5"}]},
        {"id": "R6", "ld": [{"op": "XOR", "in": ["d", -1], "out": "e"},
                            {"op": "AND", "in": [65535, "e"], "out": "e"}]}
    ]});
    let (p, fbd) = load(&doc);
    let stl = plc_deps::codegen::il::generate(&p, &fbd).unwrap();
    for line in [
        "MOVW   a, r1\nANDW   255, r1",
        "MOVW   a, r2\nORW    b, r2\nORW    4096, r2",
        "XORW   b, r3",
        "MOVW   a, r4\nINVW   r4",
        "INVW   r5",
        "MOVD   d, e\nXORD   -1, e\nANDD   65535, e",
    ] {
        assert!(stl.contains(line), "{line} in\n{stl}");
    }
    assert!(!stl.contains("MOVW   r5, r5"), "{stl}");
    let (back, _) = plc_deps::load::stl(&stl).unwrap_or_else(|e| panic!("{e:?}\n{stl}"));
    let scans: Vec<(bool, i16, i16)> = [(true, 0x1234, 0x00F0), (false, -1, 3), (true, -32768, -2)]
        .into_iter()
        .collect();
    let names = ["r1", "r2", "r3", "r4", "r5", "e"];
    let want = run_named(&p, &names, &scans);
    assert_eq!(run_named(&back, &names, &scans), want, "\n{stl}");
    // By hand, scan 1: 0x1234 AND 0xFF = 0x34; 0x1234 OR 0xF0 OR 0x1000 = 0x12F4; 0 XOR 0xF0;
    // NOT 0x1234 = -0x1235; NOT 0 = -1; 0x12345678 XOR -1 = 0xEDCBA987, AND 0xFFFF = 0xA987.
    assert_eq!(want[0], "r1=52 r2=4852 r3=240 r4=-4661 r5=-1 e=43399");
    // Scan 2 (go off: r1 kept): -1 OR 3 = -1; 0xF0 XOR 3 = 0xF3; NOT -1 = 0; NOT -1 = 0.
    assert_eq!(want[1], "r1=52 r2=-1 r3=243 r4=0 r5=0 e=43399");
}

/// INT_TO_REAL is two S7-200 instructions through a DINT scratch word (`I_DI`, then `DI_R`),
/// exact for every INT; read back it gives the interpreter's REAL. A conversion S7-200 cannot
/// do exactly is refused by its name, which says both types (REAL_TO_INT: `ROUND` gives a
/// DINT, and `DI_I` leaves its output unchanged where an INT cannot hold it).
#[test]
fn int_to_real_goes_through_a_dint_and_a_refused_conversion_names_its_types() {
    let doc = json!({"program": "conv", "vars": [
        {"name": "go", "type": "BOOL", "class": "input"},
        {"name": "a", "type": "INT", "class": "input"}, {"name": "b", "type": "INT", "class": "input"},
        {"name": "x", "type": "REAL"}, {"name": "y", "type": "REAL"}
    ], "rungs": [
        {"id": "R1", "ld": [{"contact": "go"}, {"op": "INT_TO_REAL", "in": ["a"], "out": "x"}]},
        {"id": "R2", "ld": [{"op": "INT_TO_REAL", "in": ["b"], "out": "y"},
                            {"op": "MUL", "in": ["y", 0.5], "out": "y"}]}
    ]});
    let (p, fbd) = load(&doc);
    let stl = plc_deps::codegen::il::generate(&p, &fbd).unwrap();
    assert!(
        stl.contains("LD     go\nI_DI   a, IL_TMP_DINT\nDI_R   IL_TMP_DINT, x\n"),
        "{stl}"
    );
    let (back, _) = plc_deps::load::stl(&stl).unwrap_or_else(|e| panic!("{e:?}\n{stl}"));
    let scans = [(true, -32768, 32767), (false, 5, -3), (true, 12345, 1)];
    let want = run_named(&p, &["x", "y"], &scans);
    assert_eq!(run_named(&back, &["x", "y"], &scans), want, "\n{stl}");
    assert_eq!(want[0], "x=-32768.0 y=16383.5");
    assert_eq!(want[1], "x=-32768.0 y=-1.5");

    let doc = json!({"program": "conv", "vars": [
        {"name": "r", "type": "REAL", "class": "input"}, {"name": "n", "type": "INT"}
    ], "rungs": [{"id": "R1", "ld": [{"op": "REAL_TO_INT", "in": ["r"], "out": "n"}]}]});
    let (p, fbd) = load(&doc);
    let err = plc_deps::codegen::il::generate(&p, &fbd).unwrap_err();
    assert_eq!(
        err.to_string(),
        "rung R1: REAL_TO_INT is not expressible in S7-200 IL"
    );
}
