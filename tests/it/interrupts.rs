//! Interrupt routines end to end: read from JSON (`"interrupts"`) and from STL
//! (`INTERRUPT_BLOCK`), refused as the target of a `call`, written back by `il` and `convert`,
//! and reported with what each shares with the main program.

use crate::common;

use common::cli::{run as plc_deps, tmp};

const EXAMPLE: &str = "analyses/encoder-interrupt/program.json";

/// The `interrupts` section of a JSON report.
fn interrupts(args: &[&str]) -> serde_json::Value {
    let out = plc_deps(args);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let doc: serde_json::Value = serde_json::from_slice(&out.stdout).expect("JSON report");
    doc["interrupts"].clone()
}

#[test]
fn the_stl_an_interrupt_routine_is_written_as_reads_back_with_the_same_sharing() {
    let stl = tmp("cutter.stl");
    let stl = stl.to_str().unwrap();
    let out = plc_deps(&["il", EXAMPLE, "-o", stl]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let text = std::fs::read_to_string(stl).unwrap();
    assert!(text.contains("INTERRUPT_BLOCK ENCODER:INT0\n"), "{text}");
    assert!(text.contains("END_INTERRUPT_BLOCK\n"), "{text}");
    let from_json = interrupts(&["report", EXAMPLE, "--format", "json"]);
    let from_stl = interrupts(&["report", stl, "--format", "json"]);
    assert_eq!(from_json, from_stl);
    assert_eq!(from_json[0]["pou"], "ENCODER");
    let vars: Vec<&str> = from_json[0]["shared"]
        .as_array()
        .unwrap()
        .iter()
        .map(|s| s["var"].as_str().unwrap())
        .collect();
    assert_eq!(vars, ["pulses", "cut_request", "running"]);
}

#[test]
fn convert_keeps_interrupt_routines_apart_from_subroutines() {
    let out = plc_deps(&["convert", EXAMPLE]);
    assert!(out.status.success());
    let doc: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert!(doc["interrupts"]["ENCODER"]["rungs"].is_array(), "{doc}");
    assert!(doc.get("subroutines").is_none(), "{doc}");
}

#[test]
fn calling_an_interrupt_routine_is_refused_at_the_call() {
    let path = tmp("calls-an-interrupt.json");
    std::fs::write(
        &path,
        r#"{"program": "P", "vars": [{"name": "X", "type": "BOOL"}],
  "rungs": [{"id": "R1", "ld": [{"call": "INT0"}]}],
  "interrupts": {"INT0": {"rungs": [{"id": "I1", "ld": [{"coil": "X"}]}]}}}"#,
    )
    .unwrap();
    let out = plc_deps(&["report", path.to_str().unwrap()]);
    assert_eq!(out.status.code(), Some(2));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains("calls-an-interrupt.json:2:42")
            && err.contains("rung R1")
            && err.contains("a call of an interrupt routine"),
        "{err}"
    );
    assert!(out.stdout.is_empty());
}

#[test]
fn run_says_the_interrupt_routine_never_runs() {
    let out = plc_deps(&["run", EXAMPLE, "--scans", "3"]);
    assert!(out.status.success());
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains("warning[W0104]: interrupt routine ENCODER never runs here"),
        "{err}"
    );
}
