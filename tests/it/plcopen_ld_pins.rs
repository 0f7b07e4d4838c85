//! Block pins in hand-written PLCopen TC6 LD rungs beyond one wire per pin and the power output:
//! extensible comparisons and ADD/MUL (`IN3` …), outputs other than the power output read after
//! the box, and several wires into one data pin (their OR), each with the rungs the report shows
//! and a run worked out by hand from the IEC 61131-3 meaning of the diagram.

use crate::common;
use crate::plcopen_common as px;

use common::cli::{error_line, run_stdin};
use px::{
    block, coil, contact, in_var, io, project, rail, report, run_inputs, rung, trace, var_in,
};
use serde_json::json;

/// A coil fed by output `pin` of block `from`.
fn coil_on(id: u32, var: &str, from: u32, pin: &str) -> String {
    coil(id, var, &[], "").replace(
        "<connectionPointIn></connectionPointIn>",
        &format!("<connectionPointIn><connection refLocalId=\"{from}\" formalParameter=\"{pin}\"/></connectionPointIn>"),
    )
}

/// The outputs after one scan with the inputs of the CSV row.
fn outputs(tag: &str, xml: &str, header: &str, row: &str) -> serde_json::Value {
    run_inputs(tag, xml, &format!("{header}\n{row}\n"), &[])["outputs"].clone()
}

/// a, b, c → EQ(a, b, c) → Same; GT(a, b, c) → Down; ADD(a, b, c) → S; MUL(a, b, c) → P.
fn extensible() -> String {
    // Each block with in variables of its own (localIds 10 * id + 1 …), so each is a rung.
    let three = |id: u32, ty: &str, outs: &[&str]| {
        let v = 10 * id;
        [
            in_var(v + 1, "a"),
            in_var(v + 2, "b"),
            in_var(v + 3, "c"),
            block(
                id,
                ty,
                None,
                &[
                    ("IN1", &[(v + 1, None)]),
                    ("IN2", &[(v + 2, None)]),
                    ("IN3", &[(v + 3, None)]),
                ],
                outs,
            ),
        ]
        .concat()
    };
    let ld = [
        rail(1),
        three(5, "EQ", &["OUT"]),
        coil_on(6, "Same", 5, "OUT"),
        three(7, "GT", &["OUT"]),
        coil_on(8, "Down", 7, "OUT"),
        three(9, "ADD", &["OUT"]),
        var_in("outVariable", 10, "S", (9, Some("OUT"))),
        three(11, "MUL", &["OUT"]),
        var_in("outVariable", 12, "P", (11, Some("OUT"))),
    ]
    .concat();
    project(
        &[
            ("inputVars", "a", "INT"),
            ("inputVars", "b", "INT"),
            ("inputVars", "c", "INT"),
            ("outputVars", "Same", "BOOL"),
            ("outputVars", "Down", "BOOL"),
            ("outputVars", "S", "INT"),
            ("outputVars", "P", "INT"),
        ],
        &ld,
    )
}

#[test]
fn extensible_compares_chain_and_extensible_adds_sum() {
    let xml = extensible();
    let r = report(&xml);
    assert_eq!(
        io(&r),
        vec![
            rung("P.R1", &["a", "b", "c"], &["Same"]),
            rung("P.R2", &["a", "b", "c"], &["Down"]),
            // The steps read OUT after writing it, so the report counts S and P as read too.
            rung("P.R3", &["a", "b", "c", "S"], &["S"]),
            rung("P.R4", &["a", "b", "c", "P"], &["P"]),
        ]
    );
    let h = "a,b,c";
    // EQ(a, b, c) = a = b AND b = c; GT(a, b, c) = a > b AND b > c.
    assert_eq!(
        outputs("ext1", &xml, h, "2,2,2"),
        json!({"Same": true, "Down": false, "S": 6, "P": 8})
    );
    assert_eq!(
        outputs("ext2", &xml, h, "2,2,3"),
        json!({"Same": false, "Down": false, "S": 7, "P": 12})
    );
    assert_eq!(
        outputs("ext3", &xml, h, "5,3,1"),
        json!({"Same": false, "Down": true, "S": 9, "P": 15})
    );
    // a > b but not b > c: the chain, not a > c alone.
    assert_eq!(
        outputs("ext4", &xml, h, "5,3,4"),
        json!({"Same": false, "Down": false, "S": 12, "P": 60})
    );
}

#[test]
fn an_extensible_add_that_reads_its_own_out_is_read_as_data_flow() {
    let ld = [
        rail(1),
        in_var(2, "a"),
        in_var(3, "b"),
        in_var(4, "S"),
        block(
            5,
            "ADD",
            None,
            &[
                ("IN1", &[(2, None)]),
                ("IN2", &[(3, None)]),
                ("IN3", &[(4, None)]),
            ],
            &["OUT"],
        ),
        var_in("outVariable", 6, "S", (5, Some("OUT"))),
    ]
    .concat();
    let xml = project(
        &[
            ("inputVars", "a", "INT"),
            ("inputVars", "b", "INT"),
            ("outputVars", "S", "INT"),
        ],
        &ld,
    );
    // Read as data flow (the rung reader computes ADD in OUT step by step, so it cannot):
    // S := a + b + S, an accumulator: 3, 6, 9 with a = 1, b = 2.
    let got = trace("add-acc", &xml, "a,b\n1,2\n1,2\n1,2\n", &["S"]);
    assert_eq!(got[0], ["3", "6", "9"]);
}

#[test]
fn a_sub_with_three_inputs_is_refused() {
    let ld = [
        rail(1),
        in_var(2, "a"),
        block(
            5,
            "SUB",
            None,
            &[
                ("IN1", &[(2, None)]),
                ("IN2", &[(2, None)]),
                ("IN3", &[(2, None)]),
            ],
            &["OUT"],
        ),
        var_in("outVariable", 6, "S", (5, Some("OUT"))),
    ]
    .concat();
    let xml = project(
        &[("inputVars", "a", "INT"), ("outputVars", "S", "INT")],
        &ld,
    );
    let out = run_stdin(&["report", "-"], xml.as_bytes());
    let line = error_line(&out, "SUB of three");
    assert!(
        line.contains("SUB has no input `IN3` (inputs: IN1, IN2)"),
        "{line}"
    );
}

/// Cu, Cd → CTUD0 (R unconnected: FALSE; LD := 0, a BOOL literal; PV := 2); QD → Down, written
/// in the file before the block, QU → Up; CV ≥ 1 (GE fed by CV) → Some.
fn updown() -> String {
    let ld = [
        rail(1),
        coil_on(2, "Down", 5, "QD"),
        contact(3, "Cu", &[1], ""),
        contact(4, "Cd", &[1], ""),
        block(
            5,
            "CTUD",
            Some("CTUD0"),
            &[
                ("CU", &[(3, None)]),
                ("CD", &[(4, None)]),
                ("R", &[]),
                ("LD", &[(6, None)]),
                ("PV", &[(7, None)]),
            ],
            &["QU", "QD", "CV"],
        ),
        in_var(6, "0"),
        in_var(7, "2"),
        coil_on(8, "Up", 5, "QU"),
        in_var(9, "1"),
        block(
            10,
            "GE",
            None,
            &[("IN1", &[(5, Some("CV"))]), ("IN2", &[(9, None)])],
            &["OUT"],
        ),
        coil_on(11, "Some", 10, "OUT"),
    ]
    .concat();
    project(
        &[
            ("inputVars", "Cu", "BOOL"),
            ("inputVars", "Cd", "BOOL"),
            ("outputVars", "Up", "BOOL"),
            ("outputVars", "Down", "BOOL"),
            ("outputVars", "Some", "BOOL"),
            ("localVars", "CTUD0", "CTUD"),
        ],
        &ld,
    )
}

#[test]
fn outputs_of_a_box_other_than_its_power_are_read_after_it() {
    let xml = updown();
    assert_eq!(
        io(&report(&xml)),
        vec![rung(
            "P.R1",
            &["Cu", "Cd", "CTUD0"],
            &["Up", "Down", "Some", "CTUD0"]
        )]
    );
    // CV: 0, 1, 1, 2, 1 (QD is CV ≤ 0, QU is CV ≥ PV = 2). In the first scan Down is TRUE only
    // because QD is read after the call (before it, the instance's QD is still FALSE).
    let got = trace(
        "updown",
        &xml,
        "Cu,Cd\n0,0\n1,0\n0,0\n1,0\n0,1\n",
        &["Down", "Up", "Some"],
    );
    assert_eq!(got[0], ["1", "0", "0", "0", "0"], "Down = QD");
    assert_eq!(got[1], ["0", "0", "0", "1", "0"], "Up = QU");
    assert_eq!(got[2], ["0", "1", "1", "1", "1"], "Some = CV >= 1");
}

#[test]
fn an_edge_on_a_timer_input_is_an_r_trig_in_front() {
    let ld = [
        rail(1),
        contact(2, "Go", &[1], ""),
        in_var(3, "T#20ms"),
        block(
            4,
            "TON",
            Some("T0"),
            &[("IN", &[(2, None)]), ("PT", &[(3, None)])],
            &["Q"],
        )
        .replace(
            "formalParameter=\"IN\"",
            "formalParameter=\"IN\" edge=\"rising\"",
        ),
        coil_on(5, "Done", 4, "Q"),
    ]
    .concat();
    let xml = project(
        &[
            ("inputVars", "Go", "BOOL"),
            ("outputVars", "Done", "BOOL"),
            ("localVars", "T0", "TON"),
        ],
        &ld,
    );
    // Read as data flow: IN is R_TRIG(Go), a one-scan pulse, so with Go held TRUE the timer
    // (20 ms, cycle 10 ms) starts and stops again: Done never rises (without the edge it
    // would from scan 2).
    let got = trace("edge-in", &xml, "Go\n1\n1\n1\n1\n1\n", &["Done"]);
    assert_eq!(got[0], ["0", "0", "0", "0", "0"]);
    let plain = xml.replace(" edge=\"rising\"", "");
    let got = trace("edge-in-plain", &plain, "Go\n1\n1\n1\n1\n1\n", &["Done"]);
    assert_eq!(got[0], ["0", "0", "1", "1", "1"]);
}

/// S → SR0.S1; R := a OR b (two wires into R) → SR0; Q1 → Q.
fn sr_two_resets() -> String {
    let ld = [
        rail(1),
        contact(2, "S", &[1], ""),
        contact(3, "a", &[1], ""),
        contact(4, "b", &[1], ""),
        block(
            5,
            "SR",
            Some("SR0"),
            &[("S1", &[(2, None)]), ("R", &[(3, None), (4, None)])],
            &["Q1"],
        ),
        coil_on(6, "Q", 5, "Q1"),
    ]
    .concat();
    project(
        &[
            ("inputVars", "S", "BOOL"),
            ("inputVars", "a", "BOOL"),
            ("inputVars", "b", "BOOL"),
            ("outputVars", "Q", "BOOL"),
            ("localVars", "SR0", "SR"),
        ],
        &ld,
    )
}

#[test]
fn two_wires_into_a_data_pin_are_their_or() {
    let xml = sr_two_resets();
    // The OR is written into SR0__R before the box, in the same rung.
    assert_eq!(
        io(&report(&xml)),
        vec![rung(
            "P.R1",
            &["S", "a", "b", "SR0", "SR0__R"],
            &["Q", "SR0", "SR0__R"]
        )]
    );
    // Q1 := S1 OR (NOT R AND Q1), R = a OR b: set, hold, reset by a, set, hold, reset by b.
    let got = trace(
        "sr-or",
        &xml,
        "S,a,b\n1,0,0\n0,0,0\n0,1,0\n1,0,0\n0,0,0\n0,0,1\n0,0,0\n",
        &["Q"],
    );
    assert_eq!(got[0], ["1", "1", "0", "1", "1", "0", "0"]);
}

#[test]
fn a_box_whose_fed_pin_cannot_run_first_in_its_rung_is_read_as_data_flow() {
    // Contact S feeds coil X (first in the file) and SR0.S1; R := a OR b. Merged, the shared
    // contact S would run SR0 before the OR that feeds R is written, so the body is read as
    // data flow instead: Q := SR0(S1 := S, R := a OR b).Q1, X := S.
    let ld = [
        rail(1),
        contact(2, "S", &[1], ""),
        coil(7, "X", &[2], ""),
        contact(3, "a", &[1], ""),
        contact(4, "b", &[1], ""),
        block(
            5,
            "SR",
            Some("SR0"),
            &[("S1", &[(2, None)]), ("R", &[(3, None), (4, None)])],
            &["Q1"],
        ),
        coil_on(6, "Q", 5, "Q1"),
    ]
    .concat();
    let xml = project(
        &[
            ("inputVars", "S", "BOOL"),
            ("inputVars", "a", "BOOL"),
            ("inputVars", "b", "BOOL"),
            ("outputVars", "Q", "BOOL"),
            ("outputVars", "X", "BOOL"),
            ("localVars", "SR0", "SR"),
        ],
        &ld,
    );
    let got = trace(
        "feed-after",
        &xml,
        "S,a,b\n1,0,0\n0,0,0\n0,1,0\n1,0,1\n0,0,0\n",
        &["Q", "X"],
    );
    assert_eq!(
        got[0],
        ["1", "1", "0", "1", "1"],
        "Q: set, held, reset, set wins, held"
    );
    assert_eq!(got[1], ["1", "0", "0", "1", "0"], "X = S");
}
