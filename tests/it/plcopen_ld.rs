//! PLCopen TC6 XML LD bodies, hand-written: the rungs the reader rebuilds from the wiring, as
//! the report shows them (IN/OUT, dependences, levels), and a run of one of them.

use serde_json::{json, Value};

use crate::plcopen_common as px;

use px::{
    coil, conn, contact, in_var, io, project, rail, report, report_and_warnings, run_inputs,
    run_scans, rung, trace,
};

fn deps(r: &Value) -> Vec<(String, String, String, String)> {
    r["dependences"]
        .as_array()
        .unwrap()
        .iter()
        .map(|d| {
            let s = |k: &str| d[k].as_str().unwrap_or("").to_owned();
            (
                s("kind"),
                s("from"),
                s("to"),
                d["var"].as_str().unwrap_or("").to_owned(),
            )
        })
        .collect()
}

fn dep(kind: &str, from: &str, to: &str, var: &str) -> (String, String, String, String) {
    (kind.into(), from.into(), to.into(), var.into())
}

/// A seal-in latch: (Start OR Motor) AND NOT Stop → Motor; then Motor → Lamp.
pub(crate) fn latch() -> String {
    let ld = [
        rail(1),
        contact(2, "Start", &[1], ""),
        contact(3, "Motor", &[1], ""),
        contact(4, "Stop", &[2, 3], "negated=\"true\""),
        coil(5, "Motor", &[4], ""),
        contact(6, "Motor", &[1], ""),
        coil(7, "Lamp", &[6], ""),
    ]
    .concat();
    project(
        &[
            ("inputVars", "Start", "BOOL"),
            ("inputVars", "Stop", "BOOL"),
            ("outputVars", "Motor", "BOOL"),
            ("outputVars", "Lamp", "BOOL"),
        ],
        &ld,
    )
}

#[test]
fn a_latch_is_one_rung_with_a_parallel_branch_and_feeds_the_next() {
    let r = report(&latch());
    assert_eq!(
        io(&r),
        vec![
            rung("P.R1", &["Start", "Stop", "Motor"], &["Motor"]),
            rung("P.R2", &["Motor"], &["Lamp"]),
        ]
    );
    assert_eq!(deps(&r), vec![dep("flow", "P.R1", "P.R2", "Motor")]);
    assert_eq!(r["levels"]["data"], json!([["P.R1"], ["P.R2"]]));
    assert_eq!(r["levels"]["combined"], json!([["P.R1"], ["P.R2"]]));
}

#[test]
fn a_latch_runs_as_a_latch() {
    let inputs = "Start,Stop\n1,0\n0,0\n0,0\n0,1\n0,0\n";
    let motor = trace("latch", &latch(), inputs, &["Motor"]);
    // Set by Start in scan 0, held while Start is released, dropped by Stop in scan 3.
    assert_eq!(motor[0], ["1", "1", "1", "0", "0"]);
}

#[test]
fn shared_prefixes_become_branches_and_parallel_wires_an_or() {
    // R1: A → X and A → B → Y (one prefix, two outputs); R2: (C OR D) → Z; R3: X → W.
    let ld = [
        rail(1),
        contact(2, "A", &[1], ""),
        coil(3, "X", &[2], ""),
        contact(4, "B", &[2], ""),
        coil(5, "Y", &[4], ""),
        contact(6, "C", &[1], ""),
        contact(7, "D", &[1], ""),
        coil(8, "Z", &[6, 7], ""),
        contact(9, "X", &[1], ""),
        coil(10, "W", &[9], ""),
    ]
    .concat();
    let vars: Vec<(&str, &str, &str)> = ["A", "B", "C", "D"]
        .iter()
        .map(|n| ("inputVars", *n, "BOOL"))
        .chain(
            ["X", "Y", "Z", "W"]
                .iter()
                .map(|n| ("localVars", *n, "BOOL")),
        )
        .collect();
    let r = report(&project(&vars, &ld));
    assert_eq!(
        io(&r),
        vec![
            rung("P.R1", &["A", "B"], &["X", "Y"]),
            rung("P.R2", &["C", "D"], &["Z"]),
            rung("P.R3", &["X"], &["W"]),
        ]
    );
    assert_eq!(deps(&r), vec![dep("flow", "P.R1", "P.R3", "X")]);
    assert_eq!(r["levels"]["data"], json!([["P.R1", "P.R2"], ["P.R3"]]));
}

#[test]
fn negated_and_edge_contacts_and_set_reset_coils() {
    // R1: rising S → set M; R2: falling S → reset M; R3: NOT M → N.
    let ld = [
        rail(1),
        contact(2, "S", &[1], "edge=\"rising\""),
        coil(3, "M", &[2], "storage=\"set\""),
        contact(4, "S", &[1], "edge=\"falling\""),
        coil(5, "M", &[4], "storage=\"reset\""),
        contact(6, "M", &[1], "negated=\"true\""),
        coil(7, "N", &[6], ""),
    ]
    .concat();
    let xml = project(
        &[
            ("inputVars", "S", "BOOL"),
            ("outputVars", "M", "BOOL"),
            ("outputVars", "N", "BOOL"),
        ],
        &ld,
    );
    let r = report(&xml);
    assert_eq!(
        io(&r),
        vec![
            rung("P.R1", &["S", "P.R1:edge1"], &["M", "P.R1:edge1"]),
            rung("P.R2", &["S", "P.R2:edge1"], &["M", "P.R2:edge1"]),
            rung("P.R3", &["M"], &["N"]),
        ]
    );
    assert_eq!(
        deps(&r),
        vec![
            dep("output", "P.R1", "P.R2", "M"),
            dep("flow", "P.R1", "P.R3", "M"),
            dep("flow", "P.R2", "P.R3", "M"),
        ]
    );
    assert_eq!(r["levels"]["data"], json!([["P.R1"], ["P.R2"], ["P.R3"]]));
    // S rises in scan 1 (M set), falls in scan 3 (M reset).
    assert_eq!(
        run_scans(&xml, 2)["outputs"],
        json!({"M": false, "N": true})
    );
}

#[test]
fn a_ton_in_a_rung_times_its_input() {
    // Enable → TON0(IN, PT := T#20ms).Q → Done.
    let ld = [
        rail(1),
        contact(2, "Enable", &[1], ""),
        in_var(3, "T#20ms"),
        format!(
            "<block localId=\"4\" typeName=\"TON\" instanceName=\"TON0\"><inputVariables>\
             <variable formalParameter=\"IN\">{}</variable>\
             <variable formalParameter=\"PT\">{}</variable></inputVariables>\
             <inOutVariables/><outputVariables>\
             <variable formalParameter=\"Q\"><connectionPointOut/></variable>\
             <variable formalParameter=\"ET\"><connectionPointOut/></variable></outputVariables></block>",
            conn(&[2]),
            conn(&[3])
        ),
        (
            "<coil localId=\"5\"><connectionPointIn><connection refLocalId=\"4\" formalParameter=\"Q\"/></connectionPointIn><variable>Done</variable></coil>"
        ).to_string(),
        contact(6, "Done", &[1], ""),
        coil(7, "Lamp", &[6], ""),
    ]
    .concat();
    let xml = project(
        &[
            ("inputVars", "Enable", "BOOL"),
            ("outputVars", "Done", "BOOL"),
            ("outputVars", "Lamp", "BOOL"),
            ("localVars", "TON0", "TON"),
        ],
        &ld,
    );
    let r = report(&xml);
    assert_eq!(
        io(&r),
        vec![
            rung("P.R1", &["Enable", "TON0"], &["Done", "TON0"]),
            rung("P.R2", &["Done"], &["Lamp"]),
        ]
    );
    assert_eq!(deps(&r), vec![dep("flow", "P.R1", "P.R2", "Done")]);
    for (scans, done) in [(2, false), (3, true)] {
        let n = scans.to_string();
        let v = run_inputs(
            "ton",
            &xml,
            "Enable\n1\n",
            &["--scans", &n, "--cycle", "10ms"],
        );
        assert_eq!(
            v["outputs"],
            json!({"Done": done, "Lamp": done}),
            "{scans} scans"
        );
    }
}

#[test]
fn a_jump_skips_the_rungs_up_to_its_label() {
    // R1: Skip → JMP L1; R2: A → X; R3 (label L1): B → Y.
    let ld = [
        rail(1),
        contact(2, "Skip", &[1], ""),
        format!("<jump localId=\"3\" label=\"L1\">{}</jump>", conn(&[2])),
        contact(4, "A", &[1], ""),
        coil(5, "X", &[4], ""),
        "<label localId=\"6\" label=\"L1\"/>".to_string(),
        contact(7, "B", &[1], ""),
        coil(8, "Y", &[7], ""),
    ]
    .concat();
    let vars: Vec<(&str, &str, &str)> = vec![
        ("inputVars", "Skip", "BOOL"),
        ("inputVars", "A", "BOOL"),
        ("inputVars", "B", "BOOL"),
        ("outputVars", "X", "BOOL"),
        ("outputVars", "Y", "BOOL"),
    ];
    let r = report(&project(&vars, &ld));
    assert_eq!(deps(&r), vec![dep("control", "P.R1", "P.R2", "")]);
    assert_eq!(r["levels"]["control"], json!([["P.R1", "P.R3"], ["P.R2"]]));
    assert_eq!(r["levels"]["combined"], json!([["P.R1", "P.R3"], ["P.R2"]]));
}

#[test]
fn counters_compares_and_arithmetic_boxes_in_rungs() {
    use px::{block, var_in};
    // R1: Pulse → CTU0(CU, R := Reset contact, PV := 3).Q → Full.
    // R2: GT(IN1 := N, IN2 := 4).OUT → High.   R3: Go → ADD(EN, N, 1) → N.
    let ld = [
        rail(1),
        contact(2, "Pulse", &[1], "edge=\"rising\""),
        contact(3, "Reset", &[1], ""),
        in_var(4, "3"),
        block(
            5,
            "CTU",
            Some("CTU0"),
            &[("CU", &[(2, None)]), ("R", &[(3, None)]), ("PV", &[(4, None)])],
            &["Q", "CV"],
        ),
        coil(6, "Full", &[], "").replace(
            "<connectionPointIn></connectionPointIn>",
            "<connectionPointIn><connection refLocalId=\"5\" formalParameter=\"Q\"/></connectionPointIn>",
        ),
        in_var(7, "N"),
        in_var(8, "4"),
        block(8 + 1, "GT", None, &[("IN1", &[(7, None)]), ("IN2", &[(8, None)])], &["OUT"]),
        coil(10, "High", &[], "").replace(
            "<connectionPointIn></connectionPointIn>",
            "<connectionPointIn><connection refLocalId=\"9\" formalParameter=\"OUT\"/></connectionPointIn>",
        ),
        contact(11, "Go", &[1], ""),
        in_var(12, "N"),
        in_var(13, "1"),
        block(
            14,
            "ADD",
            None,
            &[("EN", &[(11, None)]), ("IN1", &[(12, None)]), ("IN2", &[(13, None)])],
            &["ENO", "OUT"],
        ),
        var_in("outVariable", 15, "N", (14, Some("OUT"))),
    ]
    .concat();
    let xml = project(
        &[
            ("inputVars", "Pulse", "BOOL"),
            ("inputVars", "Reset", "BOOL"),
            ("inputVars", "Go", "BOOL"),
            ("outputVars", "Full", "BOOL"),
            ("outputVars", "High", "BOOL"),
            ("outputVars", "N", "INT"),
            ("localVars", "CTU0", "CTU"),
        ],
        &ld,
    );
    let r = report(&xml);
    assert_eq!(
        io(&r),
        vec![
            rung(
                "P.R1",
                &["Pulse", "Reset", "CTU0", "P.R1:edge1"],
                &["Full", "CTU0", "P.R1:edge1"]
            ),
            rung("P.R2", &["N"], &["High"]),
            rung("P.R3", &["Go", "N"], &["N"]),
        ]
    );
    assert_eq!(deps(&r), vec![dep("anti", "P.R2", "P.R3", "N")]);
    // Three rising edges of Pulse; Go on in six scans.
    let inputs = "Pulse,Reset,Go\n1,0,1\n0,0,1\n1,0,1\n0,0,1\n1,0,1\n0,0,1\n0,0,0\n";
    let v = run_inputs("boxes", &xml, inputs, &[]);
    // N counts 0..6 (High from the scan that starts with N = 5), CTU0 reaches PV = 3.
    assert_eq!(v["outputs"], json!({"Full": true, "High": true, "N": 6}));
}

#[test]
fn outputs_of_rungs_that_interleave_in_the_file_run_in_file_order() {
    // Coils in file order: X (rung 1), Y (rung 2), Z (rung 1 again, from the same contact A).
    // Beremiz (PLCGenerator.ComputeProgram) runs one statement per coil in file order, so the
    // first component is split into two rungs around Y's, contact A read again for Z.
    let ld = [
        rail(1),
        contact(2, "A", &[1], ""),
        coil(3, "X", &[2], ""),
        contact(4, "B", &[1], ""),
        coil(5, "Y", &[4], "executionOrderId=\"7\""),
        coil(6, "Z", &[2], ""),
    ]
    .concat();
    let xml = project(
        &[
            ("localVars", "A", "BOOL"),
            ("localVars", "B", "BOOL"),
            ("localVars", "X", "BOOL"),
            ("localVars", "Y", "BOOL"),
            ("localVars", "Z", "BOOL"),
        ],
        &ld,
    );
    let (r, stderr) = report_and_warnings(&xml);
    assert_eq!(
        io(&r),
        vec![
            rung("P.R1", &["A"], &["X"]),
            rung("P.R2", &["B"], &["Y"]),
            rung("P.R3", &["A"], &["Z"]),
        ]
    );
    let warnings: Vec<&str> = stderr
        .lines()
        .filter_map(|l| l.strip_prefix("warning: <stdin>:"))
        .map(|l| l.split_once(": ").unwrap().1)
        .collect();
    assert_eq!(
        warnings,
        ["pou P, LD: executionOrderId 7 of coil localId 5 is ignored (Beremiz does not read it in LD)"]
    );
}
