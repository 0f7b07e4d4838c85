//! PLCopen ST bodies executed (crates/plc-read/src/plcopen/st_lower.rs): the programs of
//! tests/st/ — one per statement kind, the operators and their precedence, the standard function
//! block calls — run to the values worked out by hand below from IEC 61131-3 (3rd ed., 7.3:
//! Table 71's precedence, the statements' rules) and the executor's number rules (docs/scan.md:
//! INT wraps, DIV truncates toward zero, MOD has the dividend's sign, an integer division by
//! zero gives 0 and a `div-by-zero` fault), sequential and parallel equal after every scan
//! (`--mode both`); the C that `plc-deps c` writes for each builds with its Makefile and prints
//! the interpreter's state after every scan. What the lowering cannot execute is refused by
//! `run` and `c`, naming the construct and its line and column; the exports of tests/plcopen
//! that have ST bodies run as far as their other bodies allow.

use crate::common;
use crate::plcopen_common as px;

use common::c::{assert_ok, run_with_input};
use common::cli::{run, run_stdin, tmp};
use serde_json::{json, Value};
use std::process::Command;
use std::process::Output;

/// `plc-deps run FILE --scans N --mode both --format json [--inputs CSV]`: the report, with
/// seq == par checked.
pub(crate) fn run_json(file: &str, scans: u32, inputs: Option<&str>) -> Value {
    let n = scans.to_string();
    let mut args = vec![
        "run", file, "--scans", &n, "--mode", "both", "--format", "json",
    ];
    if let Some(i) = inputs {
        args.extend(["--inputs", i]);
    }
    let out = run(&args);
    let v: Value = serde_json::from_slice(&out.stdout)
        .unwrap_or_else(|e| panic!("{file}: {e}: {}", String::from_utf8_lossy(&out.stderr)));
    assert_eq!(v["identical"], json!(true), "{file}: seq != par");
    v
}

/// The user's variables of a run's state (the compiler temporaries `st__…` left out), as
/// (name, value) pairs for the names asked.
pub(crate) fn values(v: &Value, names: &[&str]) -> Vec<(String, Value)> {
    names
        .iter()
        .map(|n| (n.to_string(), v["state"][*n].clone()))
        .collect()
}

pub(crate) fn pairs(expected: &[(&str, Value)]) -> Vec<(String, Value)> {
    expected
        .iter()
        .map(|(n, v)| (n.to_string(), v.clone()))
        .collect()
}

/// `plc-deps c FILE`, built with its Makefile and run for `scans` scans on `csv`: the state line
/// after every scan equals the state of `plc-deps run --scans k` for every k.
pub(crate) fn c_equals_run(file: &str, scans: u32, csv: Option<&str>) {
    let dir = tmp(&format!("st-c-{}", file.replace(['/', '.'], "_")));
    let _ = std::fs::remove_dir_all(&dir);
    let out = run(&["c", file, "-o", dir.to_str().unwrap()]);
    assert_ok(&out, "plc-deps c");
    let make = Command::new("make")
        .arg("-s")
        .current_dir(&dir)
        .output()
        .unwrap();
    assert_ok(&make, "make");
    let input = match csv {
        Some(c) => std::fs::read(common::cli::root().join(c)).unwrap(),
        None => Vec::new(),
    };
    let out = run_with_input(&dir.join("plc_program"), &[scans.to_string()], &input);
    let lines: Vec<Value> = String::from_utf8(out.stdout)
        .unwrap()
        .lines()
        .map(|l| serde_json::from_str(l).unwrap())
        .collect();
    assert_eq!(lines.len(), scans as usize, "{file}");
    for k in 1..=scans {
        let r = run_json(file, k, csv);
        assert_eq!(
            lines[k as usize - 1],
            r["state"],
            "{file}: C and run differ after scan {k}"
        );
    }
}

/// The `error:` line of a command that failed with exit code 2 (the reader's warnings before it
/// left out).
pub(crate) fn refusal(out: &Output, what: &str) -> String {
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{what}: {stderr}");
    let errors: Vec<&str> = stderr.lines().filter(|l| l.starts_with("error")).collect();
    assert_eq!(errors.len(), 1, "{what}: {stderr}");
    errors[0].to_owned()
}

#[test]
fn operators_follow_the_standards_precedence_and_the_executors_number_rules() {
    let f = "tests/st/expressions.xml";
    let v = run_json(f, 1, None);
    // a = 7, b = 3, big = 32767 (INT), zero = 0.
    let expected = [
        ("r1", json!(13)),      // a + b * 2: * before +
        ("r2", json!(20)),      // (a + b) * 2
        ("r3", json!(3)),       // a - b - 1: left to right
        ("r4", json!(2)),       // 7 / 3 truncates toward zero
        ("r5", json!(-1)),      // -a MOD b: unary minus first; -7 MOD 3 has the dividend's sign
        ("r6", json!(11)),      // 2 + 3 * 4 - 10 / 3 = 2 + 12 - 3
        ("ov", json!(-32768)),  // 32767 + 1 wraps in INT
        ("dz", json!(0)),       // 7 / 0 gives 0 (and a div-by-zero fault)
        ("x1", json!(false)),   // (a > b AND b > 5) OR NOT (a = 7): AND before OR
        ("x2", json!(true)),    // a > b AND (b > 5 OR a = 7)
        ("x3", json!(true)),    // TRUE XOR (a < b): comparison before XOR
        ("x4", json!(false)),   // (NOT x3) OR (x2 AND FALSE)
        ("x5", json!(true)),    // (x1 = x4) AND (a <> b): = before AND
        ("f1", json!(8.0)),     // 2.0 ** 3.0
        ("f2", json!(3.5)),     // INT_TO_REAL(7) / 2.0
        ("m1", json!(10)),      // MAX(7, 3, 10)
        ("m2", json!(3)),       // MIN(7, 3)
        ("m3", json!(20)),      // LIMIT(0, 35, 20)
        ("m4", json!(3)),       // SEL(TRUE, 7, 3) is IN1
        ("m5", json!(4)),       // ABS(3 - 7)
        ("m6", json!(1)),       // MAX(m6, n) writing an operand: MAX(0, 1)
        ("d1", json!(7000000)), // INT_TO_DINT(7) * 1000000 in DINT
        ("m7", json!(3)),       // MOD(7, 3) + DIV(7, 3): the standard functions (Table 29)
        ("m8", json!(11)),      // ADD(7, 3, 1): ADD is extensible
    ];
    let names: Vec<&str> = expected.iter().map(|e| e.0).collect();
    assert_eq!(values(&v, &names), pairs(&expected));
    assert_eq!(v["fault_count"], json!(1));
    // The third rung of statement 12: `a / zero` of INTs is computed in DINT (matiec's C `int`),
    // after the two rungs that widen its operands.
    assert_eq!(v["faults"][0]["rung"], json!("P.st12.3"));
    assert_eq!(v["faults"][0]["kind"], json!("div-by-zero"));
    c_equals_run(f, 2, None);
}

#[test]
fn if_elsif_else_case_and_return_take_the_branch_each_scan_selects() {
    let f = "tests/st/control.xml";
    // n counts the scans. IF: n = 1 → 10, n = 2 → 20, n <= 4 → 30 + n, else -1; the nested IF
    // adds 1 the first time (setting flag) and 100 after. CASE: 1, 2 → 100; 3..4 → 200 + n;
    // 5 → nothing (c keeps 204); else 999. RETURN when n > 2 skips `after := after + 1`.
    let rows = [
        (1, 10, 100, 0, 1),
        (2, 20, 100, 0, 2),
        (3, 33, 203, 1, 2),
        (4, 34, 204, 101, 2),
        (5, -1, 204, 101, 2),
        (6, -1, 999, 101, 2),
    ];
    for (n, s, c, h, after) in rows {
        let v = run_json(f, n, None);
        assert_eq!(
            values(&v, &["n", "s", "c", "h", "after"]),
            pairs(&[
                ("n", json!(n)),
                ("s", json!(s)),
                ("c", json!(c)),
                ("h", json!(h)),
                ("after", json!(after))
            ]),
            "after {n} scans"
        );
    }
    c_equals_run(f, 6, None);
}

#[test]
fn for_while_repeat_exit_and_continue_loop_as_the_standard_says() {
    let f = "tests/st/loops.xml";
    let v = run_json(f, 1, None);
    let expected = [
        ("sum", json!(15)), // 1 + 2 + 3 + 4 + 5
        ("i", json!(3)),    // the last FOR: i := 3, and 3 TO 1 runs no iteration
        ("z", json!(0)),
        ("cnt", json!(4)), // j = 10, 7, 4, 1: the final value `lim` read once (1), not the 100 the body writes
        ("j", json!(-2)),  // the first value past the final one
        ("ev", json!(12)), // CONTINUE skips odd k; EXIT at k = 8: 2 + 4 + 6
        ("k", json!(8)),   // left by EXIT, not incremented
        ("w", json!(243)), // 1, 3, 9, 27, 81, 243: the test before each iteration
        ("rp", json!(41)), // REPEAT runs once before its test: 1, then 11, 21, 31, 41
        ("q", json!(5)),   // BY st read once (2): m = 0, 2, 4, 6, 8
        ("m", json!(10)),
    ];
    let names: Vec<&str> = expected.iter().map(|e| e.0).collect();
    assert_eq!(values(&v, &names), pairs(&expected));
    c_equals_run(f, 2, None);
}

#[test]
fn standard_function_block_calls_run_their_boxes_with_their_inputs_and_outputs() {
    let (f, csv) = ("tests/st/fbs.xml", "tests/st/fbs.csv");
    // start = 1, 1, 1, 1, 1, 0, 1, 1 at t = 0, 10, … 70 ms. TON PT 30 ms: Q from t = 30 (ET 30),
    // reset at scan 5, restarted at t = 60 (ET 10 at t = 70). R_TRIG counts the rises at scans
    // 0 and 6. CTU PV 2 counts the same rises (R stays FALSE: `done` is FALSE when start is),
    // Q at CV 2 from scan 6. SR: set by C1.Q at scan 6, reset by T1.Q only before that.
    let v = run_json(f, 5, Some(csv));
    assert_eq!(
        values(&v, &["done", "et", "edges", "cv", "q"]),
        pairs(&[
            ("done", json!(true)),
            ("et", json!(30)),
            ("edges", json!(1)),
            ("cv", json!(1)),
            ("q", json!(false))
        ])
    );
    let v = run_json(f, 8, Some(csv));
    assert_eq!(
        values(&v, &["done", "et", "edges", "cv", "q"]),
        pairs(&[
            ("done", json!(false)),
            ("et", json!(10)),
            ("edges", json!(2)),
            ("cv", json!(2)),
            ("q", json!(true))
        ])
    );
    c_equals_run(f, 8, Some(csv));
}

/// An ST program P with an INT x, an INT y, a TON T1 and an array-free body `body`.
fn st_program(body: &str) -> String {
    px::project_in(
        "ST",
        &[
            ("localVars", "x", "INT"),
            ("localVars", "y", "INT"),
            ("localVars", "T1", "TON"),
        ],
        &format!(
            "<xhtml:p xmlns:xhtml=\"http://www.w3.org/1999/xhtml\"><![CDATA[{body}]]></xhtml:p>"
        ),
    )
}

#[test]
fn what_is_not_executed_is_refused_by_run_and_c_with_its_place() {
    let cases = [
        (
            "x := 1;\ny := MYFUNC(x);",
            "MYFUNC(",
            "the call of function `MYFUNC` (only the standard functions are executed)",
        ),
        (
            // Informal arguments bind to IN, PT in order (tests/it/st_functions.rs); a third
            // has no input to go to.
            "x := 1;\nT1(TRUE, T#1s, 3);",
            "T1(TRUE",
            "3 informal arguments in the call of `T1`, which has 2 inputs (IN, PT)",
        ),
        (
            "x := 1;\n{ printf(\"hi\"); }\ny := 2;",
            "{ printf",
            "a pragma `{…}` (matiec copies its text, C code, into what it generates)",
        ),
        (
            "T1.Q := TRUE;",
            "T1.Q",
            "a write of `T1.Q`, which is not an input of the instance",
        ),
        (
            "IF x > 0 THEN\n  EXIT;\nEND_IF;",
            "EXIT",
            "EXIT outside a loop",
        ),
    ];
    for (body, at, what) in cases {
        let xml = st_program(body);
        let body_at = px::line_col(&xml, "<ST>");
        let place = px::line_col(&xml, at);
        for (args, help) in [
            (vec!["run", "-"], "run the rest of the project"),
            (
                vec!["c", "-", "-o", "/nonexistent/st-refused"],
                "write the C",
            ),
        ] {
            let e = refusal(&run_stdin(&args, xml.as_bytes()), body);
            assert_eq!(
                e,
                format!("error: <stdin>:{body_at}: pou P: its ST body is not executed: {what} at {place} is not executed yet (it is read only as stand-in rungs that keep every value); give --allow-skipped to {help} without it"),
                "{body}"
            );
        }
    }
}

#[test]
fn the_plcopen_exports_with_st_bodies_run_as_far_as_their_other_bodies_allow() {
    // e-cockpit: PLC_PRG is `i := i + 1;`.
    let v = run_json("tests/plcopen/e-cockpit-python-scripting__plc.xml", 5, None);
    assert_eq!(v["state"]["i"], json!(5));
    // first_steps: CounterST (IF Reset THEN Cnt := ResetCounterValue; ELSE Cnt := Cnt + 1;
    // END_IF; Out := Cnt;) counts the scans with Reset FALSE. Its SFC and IL function blocks
    // run too (tests/it/sfc_exec.rs, il_exec.rs), so nothing is skipped.
    let f = "tests/plcopen/beremiz__exemples_first_steps_plc.xml";
    let v = run_json(f, 4, None);
    assert_eq!(v["state"]["CounterST0.Cnt"], json!(4));
    assert_eq!(v["state"]["CounterST0.OUT"], json!(4));
    let skipped = v["skipped_pous"].as_array().map_or(0, |a| a.len());
    assert_eq!(skipped, 0, "{}", v["skipped_pous"]);
    // bottle-refiller: its ST function blocks write their outputs in C pragmas.
    let f = "tests/plcopen/bottle-refiller__plc.xml";
    let e = refusal(&run(&["run", f]), "bottle-refiller");
    assert!(
        e.contains("pou bot_size_rand_generator0: its ST body is not executed: a pragma `{…}` (matiec copies its text, C code, into what it generates) at 3335:3"),
        "{e}"
    );
}
