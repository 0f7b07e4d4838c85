//! STRING values (IEC 61131-3 2.3.1, 6.3.3): literals with `$` escapes, MOVE, comparisons and
//! the string functions, run by the interpreter (sequential and parallel) and by the generated
//! C, with the exact texts matiec's C library gives (`lib/C/iec_std_lib.h`,
//! `lib/C/iec_std_functions.h`; each expectation names the function it follows); and the
//! Beremiz exports whose bodies use strings run.

use crate::common;

use common::cli::{root, run};
use plc_deps::codegen::c::CConfig;
use serde_json::Value as Json;

const CSV: &str = "N,GO\n-42,0\n7,1\n";

fn program() -> String {
    std::fs::read_to_string(root().join("tests/strings/basic.json")).unwrap()
}

#[test]
fn string_functions_run_with_matiecs_texts_seq_equal_par() {
    let csv = common::cli::tmp("strings-basic.csv");
    std::fs::write(&csv, CSV).unwrap();
    let path = root().join("tests/strings/basic.json");
    let out = run(&[
        "run",
        path.to_str().unwrap(),
        "--inputs",
        csv.to_str().unwrap(),
        "--scans",
        "2",
        "--mode",
        "both",
        "--format",
        "json",
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let j: Json = serde_json::from_slice(&out.stdout).unwrap();
    let s = &j["state"];
    // __sint_to_string: snprintf "%lld".
    assert_eq!(s["B"], "7");
    // CONCAT of 'N=$T', B and '!': `$T` is a tab (6.3.3 Table 7).
    assert_eq!(s["C"], "N=\t7!");
    // A MOVE of '$4F$4b' (`$hh` escapes) under power.
    assert_eq!(s["D"], "OK");
    // __len.
    assert_eq!(s["L"], 5);
    // MID(C, L := 3, P := 2): three bytes from the second.
    assert_eq!(s["E"], "=\t7");
    // __pfind: the 1-based position of '7'.
    assert_eq!(s["F"], 4);
    // __pstring_to_sint reads digits from the right and restarts at any byte above '.': the
    // '_' of '-1_234' resets it, so matiec gives -1 (not -1234).
    assert_eq!(s["K"], -1);
    // __bit_to_string: "16#%llx" of WORD 255, written in scan 1, read by R6 in scan 2.
    assert_eq!(s["A"], "16#ff");
    // __str_cmp: '1' < 'N'.
    assert_eq!(s["LESS"], true);
    assert_eq!(s["SAME"], true);
    // __string_to_bool: 'True' upper-cased is TRUE.
    assert_eq!(s["TB"], true);
    assert_eq!(j["identical"], true, "seq == par");
}

#[test]
fn generated_c_computes_the_strings_as_the_interpreter() {
    for rows in [true, false] {
        let cfg = CConfig {
            rows,
            ..CConfig::default()
        };
        common::c::check(&program(), CSV, 2, &cfg, &format!("strings rows={rows}"));
    }
}

/// Every function on edge cases, C against the interpreter: truncation at 126 bytes, negative
/// lengths, positions past the end, bytes above 127 and control bytes in the JSON output.
#[test]
fn string_edge_cases_agree_in_c_and_interpreter() {
    let long = "x".repeat(100);
    let text = format!(
        r#"{{
  "program": "edges",
  "vars": [
    {{"name": "N", "type": "INT", "class": "input"}},
    {{"name": "L", "type": "STRING", "init": "'{long}'"}},
    {{"name": "C", "type": "STRING"}}, {{"name": "D", "type": "STRING"}},
    {{"name": "E", "type": "STRING"}}, {{"name": "F", "type": "STRING"}},
    {{"name": "G", "type": "STRING"}}, {{"name": "H", "type": "STRING"}},
    {{"name": "I", "type": "STRING"}}, {{"name": "J", "type": "STRING"}},
    {{"name": "P", "type": "INT"}}, {{"name": "Q", "type": "USINT"}},
    {{"name": "U", "type": "ULINT", "init": 18446744073709551615}},
    {{"name": "GE", "type": "BOOL"}}
  ],
  "rungs": [
    {{"id": "R1", "ld": [{{"op": "CONCAT", "in": ["L", "L"], "out": "C"}}]}},
    {{"id": "R2", "ld": [{{"op": "LEFT", "in": ["'hello'", "N"], "out": "D"}}]}},
    {{"id": "R3", "ld": [{{"op": "RIGHT", "in": ["'hello'", "N"], "out": "E"}}]}},
    {{"id": "R4", "ld": [{{"op": "INSERT", "in": ["C", "'$00$FF$22$5C'", "N"], "out": "F"}}]}},
    {{"id": "R5", "ld": [{{"op": "DELETE", "in": ["'hello'", 2, "N"], "out": "G"}}]}},
    {{"id": "R6", "ld": [{{"op": "REPLACE", "in": ["'hello'", "'XYZ'", 2, "N"], "out": "H"}}]}},
    {{"id": "R7", "ld": [{{"op": "ULINT_TO_STRING", "in": ["U"], "out": "I"}}]}},
    {{"id": "R8", "ld": [{{"op": "INT_TO_STRING", "in": ["N"], "out": "J"}}]}},
    {{"id": "R9", "ld": [{{"op": "FIND", "in": ["'aab'", "'ab'"], "out": "P"}}]}},
    {{"id": "R10", "ld": [{{"op": "LEN", "in": ["C"], "out": "Q"}}]}},
    {{"id": "R11", "ld": [{{"compare": "GE", "a": "C", "b": "L"}}, {{"coil": "GE"}}]}}
  ]
}}"#
    );
    let csv = "N\n-1\n0\n1\n3\n5\n7\n200\n";
    common::c::check(&text, csv, 7, &CConfig::default(), "string edges");
    // The interpreter's values at N = 3 (scan 4), from matiec's functions.
    let (lines, _) = common::c::run_interpreter(&text, csv, 7, &CConfig::default());
    let s: Json = serde_json::from_str(&lines[3]).unwrap();
    // CONCAT stops at STR_MAX_LEN (126).
    assert_eq!(s["C"].as_str().unwrap().len(), 126);
    assert_eq!(s["Q"], 126);
    assert_eq!(s["D"], "hel");
    assert_eq!(s["E"], "llo");
    assert_eq!(s["G"], "heo", "__delete: 2 bytes from position 3");
    // __replace copies at most L bytes of IN2 (`to_copy = IN2.len < L ? IN2.len : L`): 'XY'.
    assert_eq!(s["H"], "heXYo", "__replace: 2 bytes from position 3");
    assert_eq!(s["I"], "18446744073709551615", "__uint_to_string");
    assert_eq!(s["P"], 0, "__pfind misses 'ab' in 'aab'");
    assert_eq!(s["GE"], true);
    let s: Json = serde_json::from_str(&lines[0]).unwrap();
    assert_eq!(s["D"], "", "LEFT of a negative length: __INIT_STRING");
}

/// The three Beremiz test projects whose FBD bodies use strings: each runs (the ST body of
/// iec61131_lang_test's CONVERSION_TEST is skipped, as every ST body is).
#[test]
fn beremiz_exports_with_strings_run() {
    for (file, extra) in [
        ("beremiz__tests_projects_svghmi_plc.xml", None),
        ("beremiz__tests_projects_wxHMI_plc.xml", None),
        (
            "beremiz__tests_projects_iec61131_lang_test_plc.xml",
            Some("--allow-skipped"),
        ),
    ] {
        let path = root().join("tests/plcopen").join(file);
        let mut args = vec![
            "run",
            path.to_str().unwrap(),
            "--scans",
            "3",
            "--format",
            "json",
        ];
        args.extend(extra);
        let out = run(&args);
        assert!(
            out.status.success(),
            "{file}: {}",
            String::from_utf8_lossy(&out.stderr)
        );
        let j: Json = serde_json::from_slice(&out.stdout).unwrap();
        assert_eq!(j["identical"], true, "{file}: seq == par");
        if file.contains("svghmi") {
            // PumpControl: strout := CONCAT(INT_TO_STRING(Pressure), strin), Pressure 0 and
            // strin's initial value `blup` (saved unquoted by Beremiz's editor).
            assert_eq!(j["state"]["Pump0.strout"], "0blup");
            // MainStuff: CURRENT_PAGE_0 := SEL(R_TRIG0.Q, CURRENT_PAGE_0, '!RelativePageTest@/PUMP2'):
            // no rising edge of PAGESWITCH, so it keeps its (empty) value.
            assert_eq!(j["state"]["CURRENT_PAGE_0"], "");
        }
    }
}

/// The generated C of the two Beremiz exports that run whole (FBD bodies with STRING locals,
/// SEL of STRINGs, CONCAT, INT_TO_STRING, a python_poll black box fed a STRING) builds with
/// its Makefile and ends in the state `run` ends in.
#[test]
fn beremiz_exports_with_strings_in_c_end_as_run() {
    for file in [
        "beremiz__tests_projects_svghmi_plc.xml",
        "beremiz__tests_projects_wxHMI_plc.xml",
    ] {
        let path = root().join("tests/plcopen").join(file);
        let path = path.to_str().unwrap();
        let dir = common::c::fresh_dir("strings-beremiz");
        let out = run(&["c", path, "-o", dir.to_str().unwrap(), "--force"]);
        common::c::assert_ok(&out, &format!("plc-deps c {file}"));
        let make = std::process::Command::new("make")
            .current_dir(&dir)
            .output()
            .expect("make runs");
        common::c::assert_ok(&make, &format!("make {file}"));
        let c = common::c::run_with_input(&dir.join("plc_program"), &["3".into()], b"");
        common::c::assert_ok(&c, &format!("plc_program {file}"));
        let last = String::from_utf8_lossy(&c.stdout)
            .lines()
            .last()
            .unwrap()
            .to_owned();
        let c_state: Json = serde_json::from_str(&last).unwrap();
        let i = run(&["run", path, "--scans", "3", "--format", "json"]);
        let i: Json = serde_json::from_slice(&i.stdout).unwrap();
        assert_eq!(
            c_state, i["state"],
            "{file}: C == interpreter after 3 scans"
        );
    }
}
