//! How PLCopen LD and FBD bodies execute, checked against what Beremiz's generator
//! (`PLCGenerator.py`) and matiec make of them: EN/ENO of functions and function blocks (IEC
//! 61131-3 2.5.1.2), and the statement order of a body (`PLCGenerator.ComputeProgram`).
//!
//! Each case is a small file of `tests/plcopen_semantics/` run scan by scan from an inputs CSV;
//! the expected values are worked out in the comments from the rule they test. Every run is
//! `run --mode both` (the sequential and the parallel executor, identical after every scan),
//! and the generated C (`plc-deps c`) gives the interpreter's state after every scan.

use crate::common;
use crate::plcopen_common as px;

use plc_deps::codegen::c::{generate, CConfig};
use plc_deps::exec::{ExecConfig, Layout, Machine};
use std::path::PathBuf;

fn file(name: &str) -> (PathBuf, String) {
    let path = common::cli::root()
        .join("tests/plcopen_semantics")
        .join(name);
    let text = std::fs::read_to_string(&path).unwrap();
    (path, text)
}

/// Runs `name` one scan per row of `csv` with `--mode both` (which must find seq == par) and
/// returns each of `columns` after each scan; then checks the generated C against the
/// interpreter on the same inputs.
fn scans(name: &str, csv: &str, columns: &[&str]) -> Vec<Vec<String>> {
    let (_, xml) = file(name);
    let tag = format!("sem-{}", name.trim_end_matches(".xml"));
    let tr = common::cli::tmp(&format!("{tag}-trace.csv"));
    let extra = ["--mode", "both", "--trace", tr.to_str().unwrap()];
    let v = px::run_inputs(&tag, &xml, csv, &extra);
    assert_eq!(
        v["identical"],
        serde_json::json!(true),
        "{name}: seq != par"
    );
    let rows = csv.lines().count() as u64 - 1;
    c_matches_interpreter(&xml, csv, rows, &tag);
    px::trace_columns(&tr, columns)
}

/// Builds the generated C of `xml`, runs it on `csv` and compares its state line after every
/// scan (and its faults) with the sequential interpreter's.
pub(crate) fn c_matches_interpreter(xml: &str, csv: &str, scans: u64, tag: &str) {
    let (p, fbd, _) = plc_deps::load::plcopen_for_run(xml).expect("the file loads for run");
    let cfg = CConfig::default();
    let dir = common::c::fresh_dir(tag);
    let mut sources = Vec::new();
    for f in generate(&p, &fbd, &cfg) {
        if f.name.ends_with(".c") {
            sources.push(f.name.clone());
        }
        std::fs::write(dir.join(&f.name), f.text).unwrap();
    }
    common::c::compile(&dir, "prog", &sources);
    let (c_lines, c_faults) = common::c::run_c(&dir, csv, scans);
    let exec = ExecConfig {
        cycle_ms: cfg.cycle_ms,
        loop_cap: cfg.loop_cap,
        scan_budget: cfg.scan_budget,
    };
    let m = Machine::new(&p, Layout::dense(&p), &exec).unwrap();
    let table = plc_deps::cmd::run::parse_inputs_csv(&p, csv, "inputs.csv").unwrap();
    let mut st = m.initial_state();
    let mut lines = Vec::new();
    let mut faults = 0;
    for k in 0..scans {
        let mut f = Vec::new();
        m.set_inputs(&mut st, table.at(k));
        m.run_scan(&mut st, k, &mut f);
        lines.push(common::c::state_line(&p, &m, &st));
        faults += f.len();
    }
    assert_eq!(c_lines, lines, "{tag}: C and interpreter differ");
    assert_eq!(c_faults.len(), faults, "{tag}: faults differ");
}

fn col(v: &[&str]) -> Vec<String> {
    v.iter().map(|s| s.to_string()).collect()
}

#[test]
fn a_function_with_en_false_is_skipped_and_the_block_it_feeds_still_runs() {
    // ADD (localId 4, EN := En) feeds MUL (no EN) and the out variables Y (OUT) and E (ENO).
    // matiec: ADD's EN FALSE returns INT's initial value 0 (lib/C/iec_std_functions.h,
    // TEST_EN: `return __INIT_INT`) into the temporary Beremiz assigns, so MUL, which runs
    // every scan, gives Z = 0 * 2 = 0; Y and E are written only `IF _TMP_ADD4_ENO THEN`
    // (PLCGenerator.GetUsedEno), so they keep 6 and TRUE.
    let csv = "En,A\n1,5\n0,7\n1,3\n";
    let t = scans("en_function_fbd.xml", csv, &["Y", "Z", "E"]);
    assert_eq!(t[0], col(&["6", "6", "4"]), "Y");
    assert_eq!(t[1], col(&["12", "0", "8"]), "Z");
    assert_eq!(t[2], col(&["1", "1", "1"]), "E");
}

/// Run, Start, B: the TON runs 4 scans of 10 ms with IN (Q from the 4th, ET = PT = 30 ms), then
/// EN is FALSE for 3 scans with IN FALSE and B 1, 0, 1, then EN is TRUE again with IN FALSE.
const TON_CSV: &str = "Run,Start,B\n1,1,1\n1,1,1\n1,1,1\n1,1,1\n0,0,1\n0,0,0\n0,0,1\n1,0,1\n";

/// What the TON cases give: matiec does not run an FB body whose EN is FALSE (generate_c.cc,
/// "Control execution": `if (!EN) { ENO := FALSE; return; }`), so T1.Q stays TRUE while EN is
/// FALSE though IN is FALSE, and the AND of T1.Q and B (no EN) runs every scan: Y follows B.
/// With EN TRUE again and IN FALSE the TON resets: Q FALSE.
fn check_ton(t: &[Vec<String>]) {
    assert_eq!(t[0], col(&["0", "0", "0", "1", "1", "1", "1", "0"]), "T1.Q");
    assert_eq!(t[1], col(&["0", "0", "0", "1", "1", "0", "1", "0"]), "Y");
    assert_eq!(t[2], col(&["0", "0", "0", "1", "1", "1", "1", "0"]), "Q");
}

#[test]
fn a_function_block_with_en_false_keeps_its_outputs_and_its_readers_run_fbd() {
    let t = scans("en_fb_fbd.xml", TON_CSV, &["T1.Q", "Y", "Q"]);
    check_ton(&t);
}

#[test]
fn an_ld_timer_with_en_from_the_rail_runs_as_matiec_runs_it() {
    // As bottle-refiller's TON0 (localId 15): EN from the left rail through contact Run.
    // Beremiz writes each coil from the expression of its wire: E := T1.ENO, which matiec sets
    // to EN (FALSE when the body is skipped).
    let t = scans("en_fb_ld.xml", TON_CSV, &["T1.Q", "Y", "Q", "E"]);
    check_ton(&t);
    assert_eq!(t[3], col(&["1", "1", "1", "1", "0", "0", "0", "1"]), "E");
}

#[test]
fn a_set_and_a_reset_of_one_coil_in_two_rungs_run_in_file_order() {
    // The lock controller's shape: rung 1 sets Lock from Enable AND Open and, through the same
    // Enable contact, drives Lamp from Lock; rung 2, between them in the file, resets Lock from
    // Close. Beremiz (PLCGenerator.ComputeProgram) runs one statement per coil in file order:
    //   Lock := Lock OR (Enable AND Open); Lock := Lock AND NOT Close; Lamp := Enable AND Lock.
    // Scan 1 (Enable, Open, Close): Lock set then reset, Lamp FALSE (running rung 1 whole before
    // rung 2 gave Lamp TRUE). Scan 2 (no Close): Lock, Lamp TRUE. Scan 3 (Close): Lock reset,
    // Lamp FALSE. Scan 4 (Open without Enable): nothing set.
    let csv = "Enable,Open,Close\n1,1,1\n1,1,0\n1,0,1\n0,1,0\n";
    let t = scans("set_reset_order_ld.xml", csv, &["Lock", "Lamp"]);
    assert_eq!(t[0], col(&["0", "1", "0", "0"]), "Lock");
    assert_eq!(t[1], col(&["0", "1", "0", "0"]), "Lamp");
    let (_, xml) = file("set_reset_order_ld.xml");
    let r = px::report(&xml);
    let ids: Vec<String> = px::io(&r).into_iter().map(|x| x.0).collect();
    assert_eq!(ids, ["P.R1", "P.R2", "P.R3"], "one rung per run of outputs");
}

#[test]
fn fbd_out_variables_run_in_file_order_each_pulling_its_block() {
    // No executionOrderId: Beremiz writes A := ADD(A, 1) (out variable localId 3, first in the
    // file) before B := MUL(A, 2) (localId 6), though MUL's localId 5 is below ADD's 8.
    // From A = 0: A 1, 2, 3 and B = 2 * A of the same scan.
    let t = scans("statement_order_fbd.xml", "Go\n0\n0\n0\n", &["A", "B"]);
    assert_eq!(t[0], col(&["1", "2", "3"]), "A");
    assert_eq!(t[1], col(&["2", "4", "6"]), "B");
}

#[test]
fn an_fbd_out_variable_is_written_at_its_own_statement() {
    // Beremiz writes Y := GT(ADD(X, 1), 0) first (localId 8): ADD's result goes into the
    // temporary _TMP_ADD5_OUT; then Z := X (localId 9) reads last scan's X; only then
    // X := _TMP_ADD5_OUT (localId 10). So Z lags X by one scan: X 1, 2, 3, Z 0, 1, 2
    // (matiec's trace of this file through Beremiz's generator, corpus/against-matiec, is
    // the same). Were X written when ADD runs, Z would equal X.
    let t = scans("write_place_fbd.xml", "Go\n0\n0\n0\n", &["X", "Z", "Y"]);
    assert_eq!(t[0], col(&["1", "2", "3"]), "X");
    assert_eq!(t[1], col(&["0", "1", "2"]), "Z");
    assert_eq!(t[2], col(&["1", "1", "1"]), "Y");
}

#[test]
fn a_user_function_called_from_fbd_runs_its_body_with_its_locals_started_on_every_call() {
    // TWICE_SUM's FBD body writes its result MUL(T, 2) first (the first out variable in the
    // file), with T started from its initial value 7 on every call (matiec's C declares a
    // function's variables on each call), then T := A + B, which no later call sees: Y and Z
    // are 14 on every scan, X counts (matiec's trace of this file through Beremiz's generator
    // is the same). Read as a black box, Y and Z would stay 0.
    let t = scans("user_function_fbd.xml", "Go\n0\n0\n0\n", &["X", "Y", "Z"]);
    assert_eq!(t[0], col(&["1", "2", "3"]), "X");
    assert_eq!(t[1], col(&["14", "14", "14"]), "Y");
    assert_eq!(t[2], col(&["14", "14", "14"]), "Z");
}

#[test]
fn fbd_blocks_with_execution_order_ids_run_first_in_id_order() {
    // The same body with executionOrderId 1 on MUL and 2 on ADD: Beremiz computes MUL first,
    // so B := 2 * A reads the A of the previous scan.
    let t = scans("exec_order_fbd.xml", "Go\n0\n0\n0\n", &["A", "B"]);
    assert_eq!(t[0], col(&["1", "2", "3"]), "A");
    assert_eq!(t[1], col(&["0", "2", "4"]), "B");
}

#[test]
fn an_unconnected_timer_pt_takes_its_initial_value_with_a_warning() {
    // IEC 61131-3 2.5.2.1: an input nothing sets keeps its initial value, TIME's T#0ms (Beremiz
    // leaves PT out of the call `T1(IN := Start)`, matiec keeps the instance's initial PT).
    // matiec's TON (lib/timer.txt) only starts the time in the call that sees IN rise (Q FALSE)
    // and compares from the next call, so an IN that is TRUE one scan at a time never shows Q
    // (docs/dialects.md).
    let t = scans(
        "unconnected_pt_fbd.xml",
        "Start\n1\n0\n1\n",
        &["Q", "T1.PT"],
    );
    assert_eq!(t[0], col(&["0", "0", "0"]), "Q");
    assert_eq!(t[1], col(&["0", "0", "0"]), "T1.PT");
    let (_, xml) = file("unconnected_pt_fbd.xml");
    let (_, warnings) = px::report_and_warnings(&xml);
    assert!(
        warnings.contains(
            "input PT of TON (localId 4) is not connected: it takes its type's initial value T#0ms"
        ),
        "{warnings}"
    );
}
