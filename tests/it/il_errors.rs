//! Errors of `plc-deps il` and of the STL reader, each with its exact message and exit code 2:
//! a network that needs a 10th level of the logic stack, an unknown instruction, unbalanced
//! stacks (OLD with one value, LPP without LPS, an LPS never popped), and programs with no
//! S7-200 form (TP, `b := a MOD b`, a rung deeper than 9 levels). Also what the reader does with the
//! blocks around the networks: a subroutine, an interrupt routine (a warning), SM0.1.

use crate::common;

use common::cli::{error_line, run, tmp};
use plc_deps::exec::{ExecConfig, Layout, Machine};
use plc_deps::model::{PouKind, Value, VarId};
use serde_json::json;

#[test]
fn stl_stack_errors_name_the_line_column_and_network() {
    let cases = [
        ("overflow", "13:1: network 1: logic stack overflow: LD needs a 10th level (the S7-200 logic stack has 9)"),
        ("unknown", "5:1: unknown instruction `XYZ` (not an S7-200 instruction plc-deps reads; docs/il.md lists them)"),
        ("unbalanced-old", "6:1: network 1: unbalanced logic stack: OLD needs 2 value(s), the network has 1 here"),
        ("unbalanced-lpp", "6:1: network 1: unbalanced logic stack: LPP with no LPS open"),
        ("unbalanced-lps", "9:1: network 1: unbalanced logic stack: 1 LPS not popped by LPP at the end of the network"),
    ];
    for (name, want) in cases {
        let file = format!("tests/stl/{name}.stl");
        for cmd in ["report", "run", "order", "il"] {
            let out = run(&[cmd, &file]);
            assert_eq!(
                error_line(&out, name),
                format!("error: {file}:{want}"),
                "{cmd}"
            );
        }
    }
}

fn il_error(program: serde_json::Value, what: &str) -> String {
    let path = tmp(&format!("il-{what}.json"));
    std::fs::write(&path, program.to_string()).unwrap();
    let out = run(&["il", path.to_str().unwrap()]);
    let line = error_line(&out, what);
    line.replacen(&format!("error: {}: ", path.display()), "", 1)
}

fn vars() -> serde_json::Value {
    json!([{"name": "a", "type": "BOOL", "class": "input"}, {"name": "q", "type": "BOOL", "class": "output"},
           {"name": "n", "type": "INT"}, {"name": "t", "type": "TP"}])
}

#[test]
fn programs_without_an_s7_200_form_are_one_error_naming_the_rung() {
    let tp = json!({"program": "p", "vars": vars(), "rungs": [{"id": "R1", "ld": [{"contact": "a"}, {"tp": "t", "pt": "T#1s"}]}]});
    assert_eq!(
        il_error(tp, "tp"),
        "rung R1: TP has no S7-200 instruction (the S7-200 has TON, TONR and TOF)"
    );
    let m = json!({"program": "p", "vars": vars(), "rungs": [{"id": "R2", "ld": [{"op": "MOD", "in": [7, "n"], "out": "n"}]}]});
    assert_eq!(il_error(m, "mod"), "rung R2: `n := 7 MOD n` has no S7-200 form (the zero test of the divisor would read the result: write the result to another variable)");
    // Each `or` after a contact loads one more level: 10 of them need 10 levels.
    let mut cond = json!([{"contact": "a"}]);
    for _ in 0..10 {
        cond = json!([{"contact": "a"}, {"or": [cond, [{"contact": "q"}]]}]);
    }
    let mut ld = cond.as_array().unwrap().clone();
    ld.push(json!({"coil": "q"}));
    let deep = json!({"program": "p", "vars": vars(), "rungs": [{"id": "R4", "ld": ld}]});
    assert_eq!(
        il_error(deep, "deep"),
        "rung R4: needs 11 levels of the logic stack; the S7-200 has 9 (split the rung)"
    );
}

#[test]
fn blocks_subroutines_interrupts_and_the_first_scan_bit() {
    let out = run(&[
        "run",
        "tests/stl/blocks.stl",
        "--scans",
        "1",
        "--mode",
        "seq",
    ]);
    assert_eq!(
        String::from_utf8_lossy(&out.stderr),
        "warning[W0104]: interrupt routine INT_0 never runs here: plc-deps run raises no interrupt events (`plc-deps report` lists what it shares with the main program)\n\n"    );
    let text = std::fs::read_to_string(common::cli::root().join("tests/stl/blocks.stl")).unwrap();
    let (p, _) = plc_deps::load::stl(&text).unwrap();
    let pous: Vec<(&str, PouKind)> = p.pous().iter().map(|u| (u.name.as_str(), u.kind)).collect();
    assert_eq!(
        pous,
        [
            ("MAIN", PouKind::Main),
            ("SBR_0", PouKind::Subroutine),
            ("INT_0", PouKind::Interrupt)
        ]
    );
    let m = Machine::new(
        &p,
        Layout::dense(&p),
        &ExecConfig {
            cycle_ms: 10,
            loop_cap: 10,
            scan_budget: plc_deps::exec::DEFAULT_SCAN_BUDGET,
        },
    )
    .unwrap();
    let id = |n: &str| VarId::from_raw(p.vars().iter().position(|v| v.name == n).unwrap() as u32);
    let mut st = m.initial_state();
    let mut seen = Vec::new();
    for (k, i0) in [false, true, true].into_iter().enumerate() {
        m.set_inputs(&mut st, &[(id("I0_0"), Value::Bool(i0))]);
        m.run_scan(&mut st, k as u64, &mut Vec::new());
        seen.push(format!(
            "SM0_1={} count={} Q0_0={}",
            m.value(&st, id("SM0_1")).to_json(),
            m.value(&st, id("count")).to_json(),
            m.value(&st, id("Q0_0")).to_json()
        ));
    }
    assert_eq!(
        seen,
        [
            "SM0_1=true count=5 Q0_0=false",
            "SM0_1=false count=5 Q0_0=true",
            "SM0_1=false count=5 Q0_0=true",
        ]
    );
}

#[test]
fn set_and_reset_of_n_bits_count_on_from_the_address() {
    let text = std::fs::read_to_string(common::cli::root().join("tests/stl/set-bits.stl")).unwrap();
    let (p, _) = plc_deps::load::stl(&text).unwrap();
    let m = Machine::new(
        &p,
        Layout::dense(&p),
        &ExecConfig {
            cycle_ms: 10,
            loop_cap: 10,
            scan_budget: plc_deps::exec::DEFAULT_SCAN_BUDGET,
        },
    )
    .unwrap();
    let id = |n: &str| VarId::from_raw(p.vars().iter().position(|v| v.name == n).unwrap() as u32);
    let mut st = m.initial_state();
    let bits = ["M0_6", "M0_7", "M1_0"];
    let mut seen = Vec::new();
    for (k, (i0, i1)) in [(true, false), (false, true)].into_iter().enumerate() {
        m.set_inputs(
            &mut st,
            &[(id("I0_0"), Value::Bool(i0)), (id("I0_1"), Value::Bool(i1))],
        );
        m.run_scan(&mut st, k as u64, &mut Vec::new());
        seen.push(
            bits.map(|b| m.value(&st, id(b)).to_json().to_string())
                .join(" "),
        );
    }
    assert_eq!(seen, ["true true true", "true false false"]);
    let out = run(&["report", "tests/stl/set-symbolic.stl"]);
    assert_eq!(
        error_line(&out, "symbolic"),
        "error: tests/stl/set-symbolic.stl:8:8: S of 2 bits needs an absolute bit address (I, Q, M, V) to count from"
    );
}

/// An FBD network's AND of INTs is a bitwise AND, not a contact: `il` refuses it, naming the
/// block and the variable, rather than writing `LD status` (which would read a bit).
#[test]
fn a_bitwise_fbd_network_is_refused_naming_the_block() {
    let doc = json!({"program": "p", "vars": [
        {"name": "status", "type": "INT", "class": "input"}, {"name": "mask", "type": "INT", "class": "input"},
        {"name": "bits", "type": "INT", "class": "output"}
    ], "fbd": {"networks": [{"id": "N1", "blocks": [
        {"id": 1, "op": "AND", "in": ["status", "mask"], "out": "bits"}
    ]}]}});
    assert_eq!(
        il_error(doc, "bitwise-fbd"),
        "network N1 block 1: `status` is not a BOOL: `plc-deps il` translates FBD networks of boolean AND, OR and NOT (not yet: the bitwise ANDW, ORW, XORW, INVW of a network; a ladder rung's AND box of INTs is translated)"
    );
}
