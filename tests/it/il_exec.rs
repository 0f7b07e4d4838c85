//! PLCopen IL bodies executed (crates/plc-read/src/plcopen/il_parse.rs, il_body.rs): the
//! programs of tests/il_iec/ — the load and store operators, every expression operator with its
//! `N` modifier and deferred operand `OP( … )`, functions with the current result as first
//! input, jumps and labels (a label whose current result comes from two paths), RETC, CAL and
//! CALC with formal arguments, an input operator (`CLK`) — run to the values worked out by hand
//! below from IEC 61131-3 (3rd ed., 7.2: the current result, Tables 67 and 68) as matiec's
//! generate_c_il.cc executes them (CR := CR OP operand, left to right with no precedence; a
//! function's first input is the CR; ST, JMP, CAL and RET leave the CR as it is) and the
//! executor's number rules (docs/scan.md), sequential and parallel equal after every scan
//! (`--mode both`); the C that `plc-deps c` writes for each builds and prints the interpreter's
//! state after every scan. What is not executed is refused by `run` and `c`, naming the
//! instruction and its line and column.

use crate::common;
use crate::plcopen_common as px;

use crate::st_exec::{c_equals_run, pairs, refusal, run_json, values};
use common::cli::{run, run_stdin};
use serde_json::{json, Value};

#[test]
fn il_operators_apply_to_the_current_result_left_to_right() {
    let f = "tests/il_iec/basic.xml";
    // a = 7, b = 3; n counts the scans. r1 = (7 + 3) * 2 (no precedence in IL); r2 = 7 - (3 * 2)
    // (the deferred operand); r3 = 7 / 3, r4 = 7 MOD 3; r5 = MAX(a, n); r6 = LIMIT(MN := 2,
    // IN := n, MX := 4) (the CR 2 is the first input); r7 = NOT 7 on an INT, bitwise: -8;
    // f = INT_TO_REAL(7) / 2.0. big = n > 2; x2 = NOT big AND (n = 2); x3 = big XOR NOT x2;
    // x4 = NOT (big OR NOT x2); latched set by x2 (n = 2), reset by big AND (n >= 4);
    // x5 = ((a > b) AND (b < 5)) OR (n = 1).
    let rows = [
        // n, r6, big, x2, x3, x4, latched
        (1, 2, false, false, true, false, false),
        (2, 2, false, true, false, true, true),
        (3, 3, true, false, false, false, true),
        (4, 4, true, false, false, false, false),
        (5, 4, true, false, false, false, false),
    ];
    for (n, r6, big, x2, x3, x4, latched) in rows {
        let v = run_json(f, n, None);
        let expected = [
            ("n", json!(n)),
            ("r1", json!(20)),
            ("r2", json!(1)),
            ("r3", json!(2)),
            ("r4", json!(1)),
            ("r5", json!(7)),
            ("r6", json!(r6)),
            ("r7", json!(-8)),
            ("f", json!(3.5)),
            ("big", json!(big)),
            ("x2", json!(x2)),
            ("x3", json!(x3)),
            ("x4", json!(x4)),
            ("x5", json!(true)),
            ("latched", json!(latched)),
        ];
        let names: Vec<&str> = expected.iter().map(|e| e.0).collect();
        assert_eq!(values(&v, &names), pairs(&expected), "after {n} scans");
    }
    c_equals_run(f, 5, None);
}

#[test]
fn il_jumps_labels_and_retc_follow_the_current_result() {
    let f = "tests/il_iec/jumps.xml";
    // cnt counts 1, 2, 3 and is reset to 0 by the scan that finds it >= 3 (the value stored
    // at QuitFb comes from `ADD 1` on one path, `LD 0` on the other); sum = 1 + … + cnt by a
    // backward jump; `after` counts the scans that do not end at RETC (cnt = 2).
    let rows = [
        (1, 1, 1, 1),
        (2, 2, 3, 1),
        (3, 3, 6, 2),
        (4, 0, 0, 3),
        (5, 1, 1, 4),
    ];
    for (n, cnt, sum, after) in rows {
        let v = run_json(f, n, None);
        assert_eq!(
            values(&v, &["cnt", "out", "sum", "after"]),
            pairs(&[
                ("cnt", json!(cnt)),
                ("out", json!(cnt)),
                ("sum", json!(sum)),
                ("after", json!(after))
            ]),
            "after {n} scans"
        );
    }
    c_equals_run(f, 5, None);
}

#[test]
fn il_cal_calc_and_input_operators_call_the_standard_function_blocks() {
    let (f, csv) = ("tests/il_iec/fbs.xml", "tests/il_iec/fbs.csv");
    // start = 1, 1, 1, 1, 1, 0, 1, 1 at t = 0, 10, … 70 ms (the values tests/it/st_exec.rs
    // uses for the same blocks in ST). TON PT 30 ms: Q from t = 30 (ET 30), reset at scan 6,
    // restarted at t = 60 (ET 10 at t = 70). `CLK trig` calls the R_TRIG with CLK := start:
    // rises at scans 1 and 7, counted past JMPCN. CALC calls the CTU only when start is TRUE:
    // CU := trig.Q counts the same rises, Q at CV 2 from scan 7.
    let rows = [
        (1, false, 0, 1, 1, false),
        (5, true, 30, 1, 1, false),
        (6, false, 0, 1, 1, false),
        (7, false, 0, 2, 2, true),
        (8, false, 10, 2, 2, true),
    ];
    for (n, done, et, edges, cv, q) in rows {
        let v = run_json(f, n, Some(csv));
        assert_eq!(
            values(&v, &["done", "et", "edges", "cv", "q"]),
            pairs(&[
                ("done", json!(done)),
                ("et", json!(et)),
                ("edges", json!(edges)),
                ("cv", json!(cv)),
                ("q", json!(q))
            ]),
            "after {n} scans"
        );
    }
    c_equals_run(f, 8, Some(csv));
}

#[test]
fn beremiz_first_steps_counter_il_counts_like_its_st_twin() {
    // CounterIL (LD Reset, JMPC ResetCnt, LD Cnt, ADD 1, JMP QuitFb, ResetCnt: LD
    // ResetCounterValue, QuitFb: ST Cnt, ST Out) counts the scans with Reset FALSE, as
    // CounterST does (the project's SFC block runs too).
    let f = "tests/plcopen/beremiz__exemples_first_steps_plc.xml";
    let out = run(&[
        "run",
        f,
        "--scans",
        "4",
        "--allow-skipped",
        "--format",
        "json",
    ]);
    let v: Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(v["state"]["CounterIL0.Cnt"], json!(4));
    assert_eq!(v["state"]["CounterIL0.OUT"], json!(4));
    assert_eq!(v["state"]["CounterST0.OUT"], json!(4));
    let skipped: Vec<&str> = v["skipped_pous"]
        .as_array()
        .map(|a| a.iter().map(|s| s["pou"].as_str().unwrap()).collect())
        .unwrap_or_default();
    assert!(!skipped.contains(&"CounterIL0"), "{skipped:?}");
}

#[test]
fn il_calls_the_projects_functions_informally_formally_and_with_en_eno() {
    let f = "tests/il_iec/functions.xml";
    // n counts the scans, k1 = 1. ADD3 := a + b + c; DIVMOD := a / b, rr := a MOD b;
    // KEEP (x := 5 declared) := x * 10 + y; ISPOS := x > 0; SQ (an IL body) := x * x.
    // Informal (matiec's il_function_call: the CR the first input, the operands the next
    // inputs, then the outputs): y1 = ADD3(1, 2, n); y2 = ADD3(n, n, k1) * 2 (the result is
    // the CR); q = DIVMOD(17, 5, rr => rm). Formal (the CR 99 is no input): y3 = ADD3(c := n,
    // a := 1, b := 1). EN := n > 1: y4 = ADD3(1, 1, 1) = 3 and ENO TRUE, else the result's
    // default 0 and ENO FALSE; dummy = DIVMOD(a := n, b := 1, rr => rm2) = n with rm2 0, else
    // 0 with rm2 the 77 stored before. y6 = KEEP(y := n) = 50 + n (x its declared 5).
    // pos counts the scans where ISPOS(n - 1) (JMPCN past the count): n - 1. y7 = SQ(n) + 1.
    let names = [
        "y1", "y2", "q", "rm", "y3", "y4", "done", "rm2", "dummy", "y6", "pos", "y7",
    ];
    for n in [1i64, 2, 3] {
        let en = n > 1;
        let expected = [
            ("y1", json!(3 + n)),
            ("y2", json!((2 * n + 1) * 2)),
            ("q", json!(3)),
            ("rm", json!(2)),
            ("y3", json!(2 + n)),
            ("y4", json!(if en { 3 } else { 0 })),
            ("done", json!(en)),
            ("rm2", json!(if en { 0 } else { 77 })),
            ("dummy", json!(if en { n } else { 0 })),
            ("y6", json!(50 + n)),
            ("pos", json!(n - 1)),
            ("y7", json!(n * n + 1)),
        ];
        let v = run_json(f, n as u32, None);
        assert_eq!(values(&v, &names), pairs(&expected), "after scan {n}");
        assert_eq!(v["fault_count"], json!(0));
    }
    c_equals_run(f, 3, None);
}

/// An IL program P with an INT x, an INT y, a BOOL b, a TON T1 and the body `body`.
fn il_program(body: &str) -> String {
    px::project_in(
        "IL",
        &[
            ("localVars", "x", "INT"),
            ("localVars", "y", "INT"),
            ("localVars", "b", "BOOL"),
            ("localVars", "T1", "TON"),
        ],
        &format!(
            "<xhtml:p xmlns:xhtml=\"http://www.w3.org/1999/xhtml\"><![CDATA[{body}]]></xhtml:p>"
        ),
    )
}

#[test]
fn il_formal_call_leaving_a_bool_input_out_keeps_its_last_value() {
    // The second CAL leaves IN out: it keeps the TRUE the first call gave (the instance's
    // input, as matiec's C leaves the field as it is), so the TON keeps timing: ET 20 ms after
    // 3 scans of 10 ms. plc-deps refused such a call in IL before (tests/matiec/il-fbs.xml's
    // CALC C1 without R).
    let xml = il_program(
        "LD TRUE\nST b\nCAL T1(\n  IN := b,\n  PT := T#50ms\n)\nCAL T1(\n  PT := T#50ms\n)",
    );
    let out = run_stdin(
        &[
            "run", "-", "--scans", "3", "--cycle", "10ms", "--format", "json",
        ],
        xml.as_bytes(),
    );
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let v: Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(v["state"]["T1"]["ET"], json!(20), "{v}");
}

#[test]
fn what_il_cannot_execute_is_refused_by_run_and_c_with_its_place() {
    let cases = [
        (
            "LD x\nST y\nJMP Nowhere",
            "JMP Nowhere",
            "`JMP NOWHERE`: the body has no label `NOWHERE`",
        ),
        (
            "ST y\nLD x",
            "ST y",
            "`ST` without a current result (no instruction before it sets it)",
        ),
        (
            "LD x\nMYFUNC 3\nST y",
            "MYFUNC",
            "the call of function `MYFUNC` (only the standard functions are executed)",
        ),
        (
            "LD x\nLIMIT(MN := 0, IN := x, MX := 5)\nST y",
            "LIMIT(",
            "the formal call of function `LIMIT` in IL (only the project's functions are called formally in IL)",
        ),
        (
            "LD x y\nST y",
            "y\nST",
            "IL syntax error (`y` where the end of the line was expected)",
        ),
        (
            "LD T1.PT\nST y",
            "T1.PT",
            "`T1.PT`: only the inputs and outputs of a function block instance are read",
        ),
        (
            "LD b\nST x",
            "ST x",
            "`ST` of a BOOL current result into INT `x`",
        ),
        (
            "LD 1\nL: ST y",
            "L: ST",
            "the current result at label `L`: its type cannot be told (an untyped literal?)",
        ),
    ];
    for (body, at, what) in cases {
        let xml = il_program(body);
        let body_at = px::line_col(&xml, "<IL>");
        let place = px::line_col(&xml, at);
        for (args, help) in [
            (vec!["run", "-"], "run the rest of the project"),
            (
                vec!["c", "-", "-o", "/nonexistent/il-refused"],
                "write the C",
            ),
        ] {
            let e = refusal(&run_stdin(&args, xml.as_bytes()), body);
            assert_eq!(
                e,
                format!("error: <stdin>:{body_at}: pou P: its IL body is not executed: {what} at {place} is not executed yet (it is read only as stand-in rungs that keep every value); give --allow-skipped to {help} without it"),
                "{body}"
            );
        }
    }
}

#[test]
fn il_calls_of_the_projects_functions_that_cannot_bind_are_refused_with_their_place() {
    // F has inputs a and b and an output o: the CR takes a, one operand b, a second one o.
    let project = |body: &str| {
        format!(
            r#"<?xml version="1.0" encoding="utf-8"?>
<project xmlns="http://www.plcopen.org/xml/tc6_0201">
  <fileHeader companyName="t" productName="t" productVersion="1" creationDateTime="2026-12-08T00:00:00"/>
  <contentHeader name="t"><coordinateInfo><fbd><scaling x="1" y="1"/></fbd><ld><scaling x="1" y="1"/></ld><sfc><scaling x="1" y="1"/></sfc></coordinateInfo></contentHeader>
  <types><dataTypes/><pous>
    <pou name="F" pouType="function">
      <interface><returnType><INT/></returnType><inputVars><variable name="a"><type><INT/></type></variable><variable name="b"><type><INT/></type></variable></inputVars><outputVars><variable name="o"><type><INT/></type></variable></outputVars></interface>
      <body><ST><xhtml:p xmlns:xhtml="http://www.w3.org/1999/xhtml"><![CDATA[F := a - b; o := a + b;]]></xhtml:p></ST></body>
    </pou>
    <pou name="P" pouType="program">
      <interface><localVars><variable name="x"><type><INT/></type></variable><variable name="y"><type><INT/></type></variable></localVars></interface>
      <body><IL><xhtml:p xmlns:xhtml="http://www.w3.org/1999/xhtml"><![CDATA[{body}]]></xhtml:p></IL></body>
    </pou>
  </pous></types>
  <instances><configurations/></instances>
</project>
"#
        )
    };
    let cases = [
        (
            "LD x\nF 1, y, 3\nST y",
            "F 1",
            "3 operands of `F`: function `F` takes 2 at most (its inputs after the current result, then its outputs)",
        ),
        (
            "LD x\nF 1, 2\nST y",
            "F 1",
            "operand 2 of `F` goes to output `o` of function `F`, and is not a variable",
        ),
        (
            "F(\n  a := 1,\n  2\n)\nST y",
            "F(",
            "an informal argument in the formal call of function `F` (IEC 61131-3 7.2.3: `F( … )` in IL takes formal arguments)",
        ),
        (
            "F(\n  a := 1,\n  c := 2\n)\nST y",
            "F(",
            "input `c` in the call of function `F` (its inputs: a, b)",
        ),
    ];
    for (body, at, what) in cases {
        let xml = project(body);
        let body_at = px::line_col(&xml, "<IL>");
        let place = px::line_col(&xml, at);
        let e = refusal(&run_stdin(&["run", "-"], xml.as_bytes()), body);
        assert_eq!(
            e,
            format!("error: <stdin>:{body_at}: pou P: its IL body is not executed: {what} at {place} is not executed yet (it is read only as stand-in rungs that keep every value); give --allow-skipped to run the rest of the project without it"),
            "{body}"
        );
    }
    // Bound as they should, the same calls run: y = F(x := 0, 1, o => y)... = 0 - 1 = -1, the
    // output o = 1 written first, then overwritten by the result.
    let xml = project("LD x\nF 1, y\nST y");
    let out = run_stdin(&["run", "-", "--format", "json"], xml.as_bytes());
    let v: Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(v["state"]["y"], json!(-1), "{v}");
}
