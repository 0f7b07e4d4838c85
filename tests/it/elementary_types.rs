//! The elementary types at their declared widths, end to end: a program declaring SINT … LINT,
//! USINT … ULINT, LREAL, BYTE … LWORD loads (typed and based literals, range checks with their
//! codes), runs with the IEC overflow rule (wrap in the width: two's complement for the signed
//! types, modulo 2^n for the unsigned ones and the bit strings; DIV by zero 0 and a fault), prints
//! 64-bit values exactly in the state JSON, reads them from `--inputs`, and its generated C prints
//! the same state after every scan. The values below are worked out by hand.

use crate::common;

use common::cli::{error_line, run};
use plc_deps::codegen::c::CConfig;
use std::path::PathBuf;

/// Every new type, each starting at (or near) an extreme, stepped once per scan while `GO`.
const PROGRAM: &str = r#"{"program": "types", "vars": [
  {"name": "GO", "type": "BOOL", "class": "input"},
  {"name": "S8", "type": "SINT", "init": 127},
  {"name": "U8", "type": "USINT", "init": 250},
  {"name": "U16", "type": "UINT", "init": "16#FFFF"},
  {"name": "U32", "type": "UDINT", "init": 4294967295},
  {"name": "L64", "type": "LINT", "init": 9223372036854775807},
  {"name": "U64", "type": "ULINT", "init": 18446744073709551615},
  {"name": "W", "type": "WORD", "init": "2#1010"},
  {"name": "B", "type": "BYTE", "class": "input"},
  {"name": "DW", "type": "DWORD", "init": "DWORD#16#DEADBEEF"},
  {"name": "LW", "type": "LWORD", "init": 18446744073709551615},
  {"name": "LR", "type": "LREAL", "init": 0.1},
  {"name": "N8", "type": "SINT", "init": -128},
  {"name": "Z", "type": "USINT", "init": 9},
  {"name": "Q1", "type": "BOOL", "class": "output"},
  {"name": "Q2", "type": "BOOL", "class": "output"},
  {"name": "Q3", "type": "BOOL", "class": "output"},
  {"name": "Q4", "type": "BOOL", "class": "output"}
 ],
 "rungs": [
  {"id": "R1", "ld": [{"contact": "GO"}, {"op": "ADD", "in": ["S8", 1], "out": "S8"}]},
  {"id": "R2", "ld": [{"contact": "GO"}, {"op": "ADD", "in": ["U8", 10], "out": "U8"}]},
  {"id": "R3", "ld": [{"contact": "GO"}, {"op": "ADD", "in": ["U16", "UINT#1"], "out": "U16"}]},
  {"id": "R4", "ld": [{"contact": "GO"}, {"op": "MUL", "in": ["U32", 2], "out": "U32"}]},
  {"id": "R5", "ld": [{"contact": "GO"}, {"op": "ADD", "in": ["L64", 1], "out": "L64"}]},
  {"id": "R6", "ld": [{"contact": "GO"}, {"op": "ADD", "in": ["U64", 1], "out": "U64"}]},
  {"id": "R7", "ld": [{"compare": "GT", "a": "LW", "b": "16#FFFFFFFF"}, {"coil": "Q1"}]},
  {"id": "R8", "ld": [{"contact": "GO"}, {"op": "ADD", "in": ["LR", 0.2], "out": "LR"}]},
  {"id": "R9", "ld": [{"compare": "EQ", "a": "DW", "b": 3735928559}, {"coil": "Q2"}]},
  {"id": "R10", "ld": [{"compare": "LT", "a": "W", "b": "WORD#16#B"}, {"coil": "Q3"}]},
  {"id": "R11", "ld": [{"compare": "GE", "a": "B", "b": 200}, {"coil": "Q4"}]},
  {"id": "R12", "ld": [{"contact": "GO"}, {"op": "DIV", "in": ["N8", -1], "out": "N8"}]},
  {"id": "R13", "ld": [{"contact": "Q4"}, {"op": "DIV", "in": ["Z", 0], "out": "Z"},
                       {"op": "SUB", "in": ["Z", 1], "out": "Z"}]}
 ]}"#;

const INPUTS: &str = "GO,B\n1,16#FF\n1,7\n0,200\n";

fn write(name: &str, text: &str) -> PathBuf {
    let path = common::cli::tmp(name);
    std::fs::write(&path, text).unwrap();
    path
}

/// The state after the first scan of [`INPUTS`], checked equal under the parallel executor.
fn state_after_one_scan() -> serde_json::Value {
    let prog = write("types.json", PROGRAM);
    let csv = write(
        "types.csv",
        &INPUTS.lines().take(2).collect::<Vec<_>>().join("\n"),
    );
    let out = run(&[
        "run",
        prog.to_str().unwrap(),
        "--inputs",
        csv.to_str().unwrap(),
        "--mode",
        "both",
        "--format",
        "json",
    ]);
    let report: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap_or_else(|e| {
        panic!("{e}: {}", String::from_utf8_lossy(&out.stderr));
    });
    assert_eq!(report["identical"], true, "sequential and parallel agree");
    report["state"].clone()
}

#[test]
fn every_type_wraps_in_its_width() {
    let s = state_after_one_scan();
    // 127 + 1 wraps to -128; 250 + 10 = 260 mod 256; 65535 + 1 mod 2^16; (2^32 - 1) · 2 mod 2^32.
    assert_eq!(s["S8"], -128);
    assert_eq!(s["U8"], 4);
    assert_eq!(s["U16"], 0);
    assert_eq!(s["U32"], 4294967294u64);
    // LINT max + 1 is LINT min; ULINT max + 1 is 0: printed exactly, not through a double.
    assert_eq!(s["L64"], i64::MIN);
    assert_eq!(s["U64"], 0);
    assert_eq!(s["LW"], u64::MAX);
    // -128 / -1 overflows SINT: it wraps to -128 (as DINT's MIN / -1 does).
    assert_eq!(s["N8"], -128);
    // 9 / 0 is 0 (and a fault), 0 - 1 wraps to 255.
    assert_eq!(s["Z"], 255);
    // 0.1 + 0.2 in double precision.
    assert_eq!(s["LR"].as_f64(), Some(0.1f64 + 0.2));
    assert_eq!(s["B"], 255, "16#FF read from the CSV");
    assert_eq!(
        s["Q1"], true,
        "LWORD max > 16#FFFFFFFF (unsigned 64-bit compare)"
    );
    assert_eq!(s["Q2"], true, "DWORD#16#DEADBEEF = 3735928559");
    assert_eq!(s["Q3"], true, "2#1010 < WORD#16#B");
    assert_eq!(s["Q4"], true, "BYTE 255 >= 200");
    assert_eq!(s["S8"].to_string(), "-128");
    assert_eq!(s["LW"].to_string(), "18446744073709551615");
}

#[test]
fn later_scans_keep_wrapping_and_fault_on_division_by_zero() {
    let prog = write("types-fault.json", PROGRAM);
    let csv = write("types-fault.csv", INPUTS);
    let out = run(&[
        "run",
        prog.to_str().unwrap(),
        "--inputs",
        csv.to_str().unwrap(),
        "--mode",
        "seq",
        "--format",
        "json",
    ]);
    // R13 divides by zero in scans 0 and 2 (B = 255, then 200): the run reports the faults.
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(
        stderr.contains("2 faults (first: div-by-zero on rung R13 in scan 0"),
        "{stderr}"
    );
    let report: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let s = &report["state"];
    // Scans 0 and 1 step with GO; scan 2 has GO off.
    assert_eq!(s["U8"], 14);
    assert_eq!(s["S8"], -127);
    assert_eq!(s["U16"], 1);
    assert_eq!(s["Z"], 255);
    assert_eq!(s["Q4"], true);
    assert_eq!(s["U64"], 1);
    assert_eq!(s["L64"], i64::MIN + 1);
    assert_eq!(s["U32"], 4294967292u64);
    assert_eq!(s["N8"], -128);
    assert_eq!(s["LR"].as_f64(), Some(0.1f64 + 0.2 + 0.2));
    assert_eq!(s["B"], 200);
}

#[test]
fn out_of_range_constants_and_bad_literals_are_located_errors() {
    let case = |vars: &str, rung: &str, name: &str| {
        let text = format!(
            r#"{{"program": "p", "vars": [{vars}], "rungs": [{{"id": "R1", "ld": [{rung}]}}]}}"#
        );
        let path = write(name, &text);
        error_line(&run(&["report", path.to_str().unwrap()]), name)
    };
    let usint = r#"{"name": "U", "type": "USINT"}, {"name": "Y", "type": "BOOL"}"#;
    let line = case(
        usint,
        r#"{"compare": "GT", "a": "U", "b": 256}, {"coil": "Y"}"#,
        "u.json",
    );
    assert!(line.contains("constant 256 does not fit USINT"), "{line}");
    let line = case(
        usint,
        r#"{"compare": "GT", "a": "U", "b": -1}, {"coil": "Y"}"#,
        "n.json",
    );
    assert!(line.contains("constant -1 does not fit USINT"), "{line}");
    let line = case(
        usint,
        r#"{"compare": "GT", "a": "U", "b": "16#FG"}, {"coil": "Y"}"#,
        "g.json",
    );
    assert!(line.contains("`16#FG` is not a valid literal"), "{line}");
    assert!(line.contains("rungs[0].ld[0].b"), "{line}");
    let line = case(
        usint,
        r#"{"compare": "GT", "a": "U", "b": "UINT#5"}, {"coil": "Y"}"#,
        "t.json",
    );
    assert!(
        line.contains("needs USINT, but `UINT#5` is a UINT literal"),
        "{line}"
    );
    let word = r#"{"name": "W", "type": "WORD"}"#;
    let line = case(
        word,
        r#"{"op": "ADD", "in": ["W", 1], "out": "W"}"#,
        "w.json",
    );
    assert!(
        line.contains("this arithmetic box needs a number or TIME, but `W` is WORD"),
        "{line}"
    );
    let lreal = r#"{"name": "X", "type": "LREAL"}"#;
    let line = case(
        lreal,
        r#"{"op": "MOD", "in": ["X", 2], "out": "X"}"#,
        "m.json",
    );
    assert!(
        line.contains("needs an integer, but `X` is LREAL"),
        "{line}"
    );
    let ulint = r#"{"name": "U", "type": "ULINT", "init": 18446744073709551616}"#;
    let line = case(ulint, "", "big.json");
    assert!(line.contains("does not fit ULINT"), "{line}");
}

#[test]
fn a_based_literal_of_a_signed_type_is_its_bits() {
    let text = r#"{"program": "p", "vars": [{"name": "S", "type": "SINT", "init": "SINT#16#FF"},
        {"name": "I", "type": "LINT", "init": "LINT#-5"}], "rungs": [{"id": "R1", "ld": []}]}"#;
    let path = write("bits.json", text);
    let out = run(&[
        "run",
        path.to_str().unwrap(),
        "--scans",
        "1",
        "--mode",
        "seq",
        "--format",
        "json",
    ]);
    let report: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(report["state"]["S"], -1);
    assert_eq!(report["state"]["I"], -5);
}

#[test]
fn csv_inputs_out_of_their_type_are_refused() {
    let prog = write("types-in.json", PROGRAM);
    let csv = write("types-in.csv", "GO,B\n1,256\n");
    let out = run(&[
        "run",
        prog.to_str().unwrap(),
        "--inputs",
        csv.to_str().unwrap(),
    ]);
    let line = error_line(&out, "B = 256");
    assert!(line.contains("`256` is not a BYTE (0..255)"), "{line}");
}

#[test]
fn json_inputs_take_64_bit_integers_exactly_and_based_strings() {
    let prog = write("types-json.json", &PROGRAM.replace(
        r#"{"name": "Z", "type": "USINT", "init": 9},"#,
        r#"{"name": "Z", "type": "USINT", "init": 9}, {"name": "UL", "type": "ULINT", "class": "input"},"#,
    ));
    let inputs = write(
        "types-in.json",
        r#"[{"GO": false, "B": "16#FE", "UL": 18446744073709551615}]"#,
    );
    let args = [
        "run",
        prog.to_str().unwrap(),
        "--inputs",
        inputs.to_str().unwrap(),
    ];
    let out = run(&[&args[..], &["--mode", "seq", "--format", "json"]].concat());
    let report: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(report["state"]["UL"], u64::MAX);
    assert_eq!(report["state"]["B"], 254);
    let bad = write("types-bad.json", r#"[{"B": 300}]"#);
    let line = error_line(
        &run(&[
            "run",
            prog.to_str().unwrap(),
            "--inputs",
            bad.to_str().unwrap(),
        ]),
        "B = 300",
    );
    assert!(
        line.ends_with("scan 0, input `B`: `300` is not a BYTE (0..255)"),
        "{line}"
    );
}

#[test]
fn generated_c_prints_the_interpreters_state_after_every_scan() {
    let cfg = CConfig {
        cycle_ms: 10,
        loop_cap: 100,
        chunk_rungs: 4,
        rows: false,
        scan_budget: plc_deps::exec::DEFAULT_SCAN_BUDGET,
        ..CConfig::default()
    };
    common::c::check(PROGRAM, INPUTS, 3, &cfg, "elementary-types");
}

#[test]
fn random_programs_use_every_elementary_type() {
    // The C and parallel differential tests draw from this generator: every typed variable is
    // written by some program that loads (so every type's arithmetic reaches them).
    let mut written = std::collections::BTreeSet::new();
    for seed in 0..200 {
        let text = common::random_program(seed, 24);
        if plc_deps::load::program_from_json(&text).is_err() {
            continue;
        }
        for (name, _, _) in common::typed() {
            if text.contains(&format!("\"out\":\"{name}\""))
                || text.contains(&format!("\"to\":\"{name}\""))
            {
                written.insert(name);
            }
        }
    }
    let all: Vec<_> = common::typed().into_iter().map(|(n, _, _)| n).collect();
    assert_eq!(
        written.into_iter().collect::<Vec<_>>().len(),
        all.len(),
        "{all:?}"
    );
}
