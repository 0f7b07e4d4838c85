//! What real Beremiz/OpenPLC exports write and matiec accepts, read and run as matiec and the
//! Beremiz/OpenPLC runtime run it (issue 39): a coil on a `%IX`-located input (W0208), blocks
//! with unconnected inputs in LD bodies read as data flow, EN on function blocks in LD, function
//! block instances in a program's VAR_INPUT, and VAR_IN_OUT of POUs no call wires.
//!
//! Each case is a small hand-written file of `tests/plcopen_load/` run scan by scan from an
//! inputs CSV; the expected values are worked out in the comments from IEC 61131-3 and matiec's
//! rules. Every run is `run --mode both` (seq == par after every scan), and the generated C
//! (`plc-deps c`) gives the interpreter's state after every scan.

use crate::common;
use crate::plcopen_common as px;

use plc_deps::codegen::c::{generate, CConfig};
use plc_deps::exec::{ExecConfig, Layout, Machine};

fn file(name: &str) -> String {
    let path = common::cli::root().join("tests/plcopen_load").join(name);
    std::fs::read_to_string(&path).unwrap()
}

/// Runs `name` one scan per row of `csv` with `--mode both` (which must find seq == par) and
/// returns each of `columns` after each scan; then checks the generated C against the
/// interpreter on the same inputs.
fn scans(name: &str, csv: &str, columns: &[&str]) -> Vec<Vec<String>> {
    let xml = file(name);
    let tag = format!("load-{}", name.trim_end_matches(".xml"));
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

/// The generated C of `xml` on `csv`, state line by state line, against the sequential
/// interpreter fed as `run` feeds it (the parsed table, with the input image of the inputs the
/// program writes).
fn c_matches_interpreter(xml: &str, csv: &str, scans: u64, tag: &str) {
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
fn a_coil_on_a_located_input_lasts_until_the_next_scans_input_copy() {
    // Rungs run in the order of their coils in the file: Before := Btn, Btn := Go, Seen := Btn.
    // matiec accepts the coil on %IX0.0; the Beremiz/OpenPLC runtime copies the input image
    // into the located variables before every cycle (OpenPLC's updateBuffersIn, Beremiz's
    // __retrieve_*), so Before reads the image (the last value the inputs gave Btn, FALSE
    // before any) and Seen the program's write. Scan 0: image 0, Btn := 1. Scan 1 (no Btn
    // cell): image still 0, Btn := Go = 0. Scan 2: image 1, Btn := 0. Scan 3: image 1, Btn := 1.
    // Scans 4, 5: image 1 though the program wrote 0 at the end of scan 4 (Go stays 0).
    let csv = "Btn,Go\n0,1\n,0\n1,0\n,1\n,0\n,\n";
    let t = scans("input_write_ld.xml", csv, &["Before", "Btn", "Seen"]);
    assert_eq!(t[0], col(&["0", "0", "1", "1", "1", "1"]), "Before");
    assert_eq!(t[1], col(&["1", "0", "0", "1", "0", "0"]), "Btn");
    assert_eq!(t[2], col(&["1", "0", "0", "1", "0", "0"]), "Seen");
    let (_, warnings) = px::report_and_warnings(&file("input_write_ld.xml"));
    // W0208, once: one input is written, by rung P.R2 (the coil's).
    assert!(
        warnings.contains("rung P.R2 writes the input `Btn`: the value lasts until the next scan copies the input image into it"),
        "{warnings}"
    );
    assert_eq!(
        warnings.matches("writes the input").count(),
        1,
        "{warnings}"
    );
}

#[test]
fn unconnected_counter_inputs_take_their_initial_values_in_an_ld_body_read_as_data_flow() {
    // C1 has EN (from contact En), so the body is read as data flow (Beremiz's form of LD);
    // its R is not connected: FALSE (IEC 61131-3 2.5.2.1, the type's initial value), PV is 2.
    // matiec's CTU (lib/counter.txt): on a rising CU (its R_TRIG), CV := CV + 1 while CV < PV;
    // Q := CV >= PV. With EN FALSE the
    // body does not run (generate_c.cc: `if (!EN) { ENO := FALSE; return; }`), so its CU edge
    // memory keeps TRUE from scan 2 and the TRUE CU of scan 5 is no edge. C0 has PV not
    // connected (0): it never counts (CV < PV is 0 < 0) and Q0 = CV >= 0 is TRUE from the first
    // call. C1 stops at its PV, 2.
    let csv = "En,Up\n1,1\n1,0\n1,1\n0,0\n0,1\n1,1\n1,0\n1,1\n";
    let t = scans(
        "unconnected_ctu_ld.xml",
        csv,
        &["C1.CV", "Q", "Q0", "C0.CV"],
    );
    assert_eq!(
        t[0],
        col(&["1", "1", "2", "2", "2", "2", "2", "2"]),
        "C1.CV"
    );
    assert_eq!(t[1], col(&["0", "0", "1", "1", "1", "1", "1", "1"]), "Q");
    assert_eq!(t[2], col(&["1", "1", "1", "1", "1", "1", "1", "1"]), "Q0");
    assert_eq!(
        t[3],
        col(&["0", "0", "0", "0", "0", "0", "0", "0"]),
        "C0.CV"
    );
    let (_, warnings) = px::report_and_warnings(&file("unconnected_ctu_ld.xml"));
    for pin in ["input R of CTU (localId 5)", "input PV of CTU (localId 8)"] {
        assert!(warnings.contains(pin), "{pin}: {warnings}");
    }
}
