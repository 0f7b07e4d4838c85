//! PLCopen constructs read as data flow: LD bodies that are not series-parallel rungs (read as
//! Beremiz's boolean network), EN on a block in LD, conversions, negated pins, a wired ENO,
//! black boxes, strings that `run` refuses — each run with inputs whose outputs were worked
//! out by hand from the diagram, or checked in the report, and the new errors located.

use crate::common;
use crate::plcopen_common;

use common::cli::{error_line, run_stdin};
use plcopen_common::{
    block, coil, contact, in_var, line_col, project, project_in, rail, report_and_warnings, trace,
    var_in,
};
use serde_json::json;

fn vars<'a>(list: &[(&'a str, &'a str, &'a str)]) -> Vec<(&'a str, &'a str, &'a str)> {
    list.to_vec()
}

#[test]
fn a_coil_inside_a_parallel_branch_passes_its_power_on() {
    // A → coil X → (wired OR with B) → coil Y: not series-parallel rungs; as Beremiz generates
    // it, X := A and Y := A OR B (a coil passes the power it receives).
    let ld = [
        rail(1),
        contact(2, "A", &[1], ""),
        coil(3, "X", &[2], ""),
        contact(4, "B", &[1], ""),
        coil(5, "Y", &[3, 4], ""),
    ]
    .concat();
    let v = vars(&[
        ("inputVars", "A", "BOOL"),
        ("inputVars", "B", "BOOL"),
        ("outputVars", "X", "BOOL"),
        ("outputVars", "Y", "BOOL"),
    ]);
    let xml = project(&v, &ld);
    let (_, warnings) = report_and_warnings(&xml);
    assert!(
        warnings.contains("its LD body is read as a data-flow network"),
        "{warnings}"
    );
    assert!(
        warnings.contains("the parallel branch through localId 3 holds an output or a block"),
        "{warnings}"
    );
    let t = trace("flow-sp", &xml, "A,B\n0,0\n1,0\n0,1\n1,1\n", &["X", "Y"]);
    assert_eq!(t[0], ["0", "1", "0", "1"]);
    assert_eq!(t[1], ["0", "1", "1", "1"]);
}

#[test]
fn en_on_a_timer_in_ld_freezes_it() {
    // E → TON.EN, Go → TON.IN, PT = T#20ms, TON.Q → coil Q. Cycle 10 ms: the timer starts in
    // scan 0 and Q rises in scan 2 (20 ms later); with EN FALSE from scan 3 the timer is not
    // called, so Q keeps TRUE although IN falls (without EN it would drop at once).
    let ld = [
        rail(1),
        contact(2, "E", &[1], ""),
        contact(3, "Go", &[1], ""),
        in_var(4, "T#20ms"),
        block(
            5,
            "TON",
            Some("T1"),
            &[
                ("EN", &[(2, None)]),
                ("IN", &[(3, None)]),
                ("PT", &[(4, None)]),
            ],
            &["ENO", "Q", "ET"],
        ),
        coil(6, "Q", &[5], "")
            .replace("refLocalId=\"5\"", "refLocalId=\"5\" formalParameter=\"Q\""),
    ]
    .concat();
    let v = vars(&[
        ("inputVars", "E", "BOOL"),
        ("inputVars", "Go", "BOOL"),
        ("outputVars", "Q", "BOOL"),
        ("localVars", "T1", "TON"),
    ]);
    let xml = project(&v, &ld);
    let t = trace(
        "flow-en",
        &xml,
        "E,Go\n1,1\n1,1\n1,1\n0,1\n0,0\n1,0\n",
        &["Q"],
    );
    assert_eq!(t[0], ["0", "0", "1", "1", "1", "0"]);
}

#[test]
fn a_conversion_feeding_an_extensible_compare_in_ld() {
    // EQ(IN1 := N, IN2 := BOOL_TO_INT(A), IN3 := M) → coil X: X = (N = A?1:0) AND (A?1:0 = M).
    let ld = [
        rail(1),
        contact(2, "A", &[1], ""),
        block(3, "BOOL_TO_INT", None, &[("IN", &[(2, None)])], &["OUT"]),
        in_var(4, "N"),
        in_var(5, "M"),
        block(
            6,
            "EQ",
            None,
            &[
                ("IN1", &[(4, None)]),
                ("IN2", &[(3, Some("OUT"))]),
                ("IN3", &[(5, None)]),
            ],
            &["OUT"],
        ),
        coil(7, "X", &[6], ""),
    ]
    .concat();
    let v = vars(&[
        ("inputVars", "A", "BOOL"),
        ("inputVars", "N", "INT"),
        ("inputVars", "M", "INT"),
        ("outputVars", "X", "BOOL"),
    ]);
    let xml = project(&v, &ld);
    let t = trace(
        "flow-eq",
        &xml,
        "A,N,M\n1,1,1\n0,1,1\n0,0,0\n1,1,0\n",
        &["X"],
    );
    assert_eq!(t[0], ["1", "0", "1", "0"]);
}

#[test]
fn negated_pins_and_a_wired_eno_in_fbd() {
    // Y := AND(IN1 := NOT A, IN2 := B); Z := ENO of that AND, whose EN is C (so Z = C).
    let fbd = [
        in_var(1, "A"),
        in_var(2, "B"),
        in_var(3, "C"),
        block(
            4,
            "AND",
            None,
            &[
                ("EN", &[(3, None)]),
                ("IN1", &[(1, None)]),
                ("IN2", &[(2, None)]),
            ],
            &["ENO", "OUT"],
        )
        .replace(
            "<variable formalParameter=\"IN1\">",
            "<variable formalParameter=\"IN1\" negated=\"true\">",
        ),
        var_in("outVariable", 5, "Y", (4, Some("OUT"))),
        var_in("outVariable", 6, "Z", (4, Some("ENO"))),
    ]
    .concat();
    let v = vars(&[
        ("inputVars", "A", "BOOL"),
        ("inputVars", "B", "BOOL"),
        ("inputVars", "C", "BOOL"),
        ("outputVars", "Y", "BOOL"),
        ("outputVars", "Z", "BOOL"),
    ]);
    let xml = project_in("FBD", &v, &fbd);
    let t = trace(
        "flow-neg",
        &xml,
        "A,B,C\n0,1,1\n1,1,1\n0,0,1\n0,1,0\n",
        &["Y", "Z"],
    );
    // Scan 4: EN is FALSE, so the AND does not run and Y keeps its value from scan 3. Beremiz
    // writes an out variable fed by a block with EN only `IF _TMP_AND4_ENO THEN`
    // (PLCGenerator.GetUsedEno), Z := ENO included, so Z keeps TRUE.
    assert_eq!(t[0], ["1", "0", "0", "0"]);
    assert_eq!(t[1], ["1", "1", "1", "1"]);
}

#[test]
fn a_function_the_model_lacks_is_a_black_box_with_its_pins() {
    // y := SHIFT_LEFT(IN := a, N := 2): the report sees a read and y written through a stand-in.
    let fbd = [
        in_var(1, "a"),
        in_var(2, "2"),
        block(
            3,
            "SHIFT_LEFT",
            None,
            &[("IN", &[(1, None)]), ("N", &[(2, None)])],
            &["OUT"],
        ),
        var_in("outVariable", 4, "y", (3, Some("OUT"))),
    ]
    .concat();
    let v = vars(&[("inputVars", "a", "INT"), ("outputVars", "y", "INT")]);
    let xml = project_in("FBD", &v, &fbd);
    let (r, warnings) = report_and_warnings(&xml);
    assert!(warnings.contains("SHIFT_LEFT is read as a black box (a function block type SHIFT_LEFT reading its inputs IN INT, N INT and writing its outputs OUT INT)"), "{warnings}");
    let ins: Vec<&serde_json::Value> = r["rungs"]
        .as_array()
        .unwrap()
        .iter()
        .map(|r| &r["in"])
        .collect();
    let outs: Vec<&serde_json::Value> = r["rungs"]
        .as_array()
        .unwrap()
        .iter()
        .map(|r| &r["out"])
        .collect();
    assert!(
        ins.iter()
            .any(|i| i.as_array().unwrap().contains(&json!("a"))),
        "{ins:?}"
    );
    assert!(
        outs.iter()
            .any(|o| o.as_array().unwrap().contains(&json!("y"))),
        "{outs:?}"
    );
}

#[test]
fn a_string_literal_is_analysed_and_run_refuses_it() {
    let fbd = [
        in_var(1, "\"hello\""),
        in_var(2, "go"),
        block(
            3,
            "python_eval",
            Some("py"),
            &[("TRIG", &[(2, None)]), ("CODE", &[(1, None)])],
            &["ACK", "RESULT"],
        ),
        var_in("outVariable", 4, "done", (3, Some("ACK"))),
    ]
    .concat();
    let v = vars(&[
        ("inputVars", "go", "BOOL"),
        ("outputVars", "done", "BOOL"),
        ("localVars", "py", "python_eval"),
    ]);
    let xml = project_in("FBD", &v, &fbd);
    let (_, warnings) = report_and_warnings(&xml);
    assert!(warnings.contains("python_eval"), "{warnings}");
    let e = error_line(
        &run_stdin(&["run", "-", "--scans", "1"], xml.as_bytes()),
        "wstring literal",
    );
    let at = line_col(&xml, "<inVariable localId=\"1\"");
    assert_eq!(e, format!("error: <stdin>:{at}: at run: pou P: the inVariable localId 1 is a string literal, for which plc-deps has no values: the analysis reads it as a constant, but `run` cannot execute the FBD body of `P`"));
}

#[test]
fn a_black_box_pin_whose_type_cannot_be_told_is_a_located_error() {
    // An unknown function fed by an unknown function: neither pin has a type to go by.
    let fbd = [
        in_var(1, "a"),
        block(2, "MYSTERY", None, &[("IN", &[(1, None)])], &["OUT"]),
        block(3, "ENIGMA", None, &[("IN", &[(2, Some("OUT"))])], &["OUT"]),
        var_in("outVariable", 4, "y", (3, Some("OUT"))),
    ]
    .concat();
    let v = vars(&[("inputVars", "a", "INT"), ("outputVars", "y", "INT")]);
    let xml = project_in("FBD", &v, &fbd);
    let e = error_line(&run_stdin(&["report", "-"], xml.as_bytes()), "untyped pin");
    let at = line_col(&xml, "<variable formalParameter=\"OUT\"><connectionPointOut/></variable></outputVariables></block><block localId=\"3\"");
    assert_eq!(e, format!("error: <stdin>:{at}: at pou P, FBD, block localId 2: the type of output OUT of MYSTERY (localId 2) cannot be told from what it feeds; plc-deps reads MYSTERY as a black box, whose pins need a type"));
}

#[test]
fn a_label_in_an_ld_body_read_as_data_flow_gives_the_rung_readers_error() {
    // Not series-parallel and with a label: the data-flow reading refuses the label, so the
    // error is the rung reader's, naming the localIds.
    let ld = [
        rail(1),
        "<label localId=\"9\" label=\"L1\"/>".to_owned(),
        contact(2, "A", &[1], ""),
        coil(3, "X", &[2], ""),
        contact(4, "B", &[1], ""),
        coil(5, "Y", &[3, 4], ""),
    ]
    .concat();
    let v = vars(&[
        ("inputVars", "A", "BOOL"),
        ("inputVars", "B", "BOOL"),
        ("outputVars", "X", "BOOL"),
        ("outputVars", "Y", "BOOL"),
    ]);
    let xml = project(&v, &ld);
    let e = error_line(&run_stdin(&["report", "-"], xml.as_bytes()), "label");
    assert!(e.ends_with("at pou P, LD, coil localId 5: the wiring into localId 5 from localIds 3, 4 is not series-parallel: the parallel branch through localId 3 holds an output or a block, which a parallel (OR) branch cannot"), "{e}");
}

#[test]
fn a_loop_of_arcs_between_blocks_is_closed_with_a_one_scan_delay() {
    // NOT (1) ← MOVE (2) ← NOT (1): Beremiz marks block 1 computed before its inputs, so the
    // walk coming back to it reads its output as it is (last scan's). y := NOT(last y) toggles.
    let fbd = [
        block(1, "NOT", None, &[("IN", &[(2, Some("OUT"))])], &["OUT"]),
        block(2, "MOVE", None, &[("IN", &[(1, Some("OUT"))])], &["OUT"]),
        var_in("outVariable", 3, "y", (1, Some("OUT"))),
    ]
    .concat();
    let v = vars(&[("inputVars", "go", "BOOL"), ("outputVars", "y", "BOOL")]);
    let xml = project_in("FBD", &v, &fbd);
    let (_, warnings) = report_and_warnings(&xml);
    assert!(warnings.contains("blocks 2 and 1 are in a loop of arcs; as Beremiz closes it, block 2 reads output OUT of block 1 as the variable `NOT__1_OUT`"), "{warnings}");
    let t = trace("flow-loop", &xml, "go\n0\n0\n0\n0\n", &["y"]);
    assert_eq!(t[0], ["1", "0", "1", "0"]);
}

#[test]
fn a_block_type_that_is_not_an_identifier_is_an_error_naming_it() {
    let fbd = [
        in_var(1, "a"),
        block(2, "../x", None, &[("IN", &[(1, None)])], &["OUT"]),
        var_in("outVariable", 3, "y", (2, Some("OUT"))),
    ]
    .concat();
    let v = vars(&[("inputVars", "a", "INT"), ("outputVars", "y", "INT")]);
    let xml = project_in("FBD", &v, &fbd);
    let e = error_line(
        &run_stdin(&["report", "-"], xml.as_bytes()),
        "bad type name",
    );
    assert!(e.contains("at pou P, FBD, block localId 2: block type name `../x` is not an IEC 61131-3 identifier"), "{e}");
}
