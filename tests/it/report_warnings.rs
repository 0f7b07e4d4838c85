//! Programs the analysis must not get wrong quietly: an endless jump loop (no path to STOP),
//! a rung nothing reaches, a subroutine nothing calls.

use plc_deps::cmd::report::{render_report, ReportFormat};
use plc_deps::load::program_and_fbd_from_json;
use plc_deps::report::View;
use serde_json::{json, Value};

/// R2 and R3 jump to each other forever once R1 lets control in; R4 is after the loop.
const ENDLESS: &str = r#"{"program": "p",
            "vars": [{"name": "a", "type": "BOOL", "class": "input"}, {"name": "y", "type": "BOOL"}],
            "rungs": [
              {"id": "R1", "ld": [{"contact": "a"}, {"jmp": "L4"}]},
              {"id": "R2", "label": "L2", "ld": [{"coil": "y"}]},
              {"id": "R3", "ld": [{"jmp": "L2"}]},
              {"id": "R4", "label": "L4", "ld": [{"contact": "y"}, {"coil": "y"}]}
            ]}"#;

/// The warnings of a report, as texts.
fn warning_texts(j: &Value) -> Vec<&str> {
    j["warnings"]
        .as_array()
        .unwrap()
        .iter()
        .map(|w| w.as_str().unwrap())
        .collect()
}

fn report(text: &str) -> (Value, String) {
    let (p, fbd) = program_and_fbd_from_json(text).unwrap();
    let j = serde_json::from_str(&render_report(&p, &fbd, ReportFormat::Json, View::All)).unwrap();
    (j, render_report(&p, &fbd, ReportFormat::Text, View::All))
}

#[test]
fn endless_loop_is_a_warning_with_a_sound_tree() {
    // R2 and R3 jump to each other forever once R1 lets control in; R4 is after the loop.
    let (j, text) = report(ENDLESS);
    let warnings = j["warnings"].as_array().unwrap();
    assert!(
        warnings.iter().any(|w| w
            .as_str()
            .unwrap()
            .starts_with("rungs R2, R3 can never reach the end of the scan")),
        "{warnings:?}"
    );
    assert!(text.contains("warning[W0202]: rungs R2, R3 can never reach the end of the scan"));
    assert_eq!(j["warning_codes"], json!(["W0202"]));
    // The tree treats R3 (the loop's last rung) as the loop's exit: R2 → R3 → STOP.
    assert_eq!(j["ipdom"]["R2"], "R3");
    assert_eq!(j["ipdom"]["R3"], "STOP");
    assert_eq!(j["ipdom"]["R1"], "STOP");
    // The loop is one task, guarded by R1's decision; R4 runs only when R1 jumps.
    assert_eq!(
        j["levels"]["combined"],
        json!([["R1"], [["R2", "R3"]], ["R4"]])
    );
}

#[test]
fn unreachable_rungs_and_uncalled_subroutines_are_reported() {
    let (j, text) = report(
        r#"{"program": "p",
            "vars": [{"name": "a", "type": "BOOL", "class": "input"}, {"name": "y", "type": "BOOL"}],
            "rungs": [
              {"id": "R1", "ld": [{"jmp": "L3"}]},
              {"id": "R2", "ld": [{"contact": "a"}, {"coil": "y"}]},
              {"id": "R3", "label": "L3", "ld": [{"contact": "y"}, {"coil": "y"}]}
            ],
            "subroutines": {"S": {"rungs": [{"id": "S1", "ld": [{"contact": "a"}, {"coil": "y"}]}]}}}"#,
    );
    assert_eq!(j["schedule"]["unreachable"], json!(["R2"]));
    assert_eq!(j["levels"]["combined"], json!([["R1", "R3"]]));
    let warnings = warning_texts(&j);
    assert_eq!(
        warnings,
        vec![
            "rung R2 can never run (no path from the start of the scan reaches it)",
            "subroutine S is never called"
        ]
    );
    assert!(text.contains("warning[W0203]: subroutine S is never called"));
    assert_eq!(j["warning_codes"], json!(["W0201", "W0203"]));
}

#[test]
fn empty_rungs_and_rungs_without_effect_are_warnings() {
    let (j, text) = report(
        r#"{"program": "p",
            "vars": [{"name": "a", "type": "BOOL", "class": "input"}, {"name": "y", "type": "BOOL"}],
            "rungs": [
              {"id": "R1", "ld": []},
              {"id": "R2", "ld": [{"contact": "a"}]},
              {"id": "R3", "ld": [{"contact": "a"}, {"coil": "y"}]}
            ]}"#,
    );
    let warnings = warning_texts(&j);
    assert_eq!(
        warnings,
        vec![
            "rung R1 is empty (no elements)",
            "rung R2 has no effect: nothing is written and control is not transferred"
        ]
    );
    assert!(text.contains("warning[W0205]: rung R1 is empty (no elements)"));
    assert_eq!(j["warning_codes"], json!(["W0205", "W0206"]));
}

/// The CLI prints warnings on standard error too, and the endless-loop warning says what
/// `run` does: it leaves the loop after the loop cap with a loop-cap fault.
#[test]
fn warnings_go_to_stderr_and_the_endless_loop_warning_agrees_with_run() {
    let file = std::env::temp_dir().join(format!("plc-deps-endless-{}.json", std::process::id()));
    std::fs::write(&file, ENDLESS).unwrap();
    let bin = env!("CARGO_BIN_EXE_plc-deps");
    let out = std::process::Command::new(bin)
        .args(["report", file.to_str().unwrap(), "--format", "json"])
        .output()
        .unwrap();
    assert!(out.status.success());
    // With --format json the warning is a JSON diagnostic with its code and file.
    let stderr = String::from_utf8(out.stderr).unwrap();
    let d: Value = serde_json::from_str(stderr.trim_end()).expect("one JSON diagnostic");
    assert_eq!(d["code"], "W0202");
    assert_eq!(d["severity"], "warning");
    assert_eq!(d["file"], file.to_str().unwrap());
    let message = d["message"].as_str().unwrap();
    assert!(
        message.starts_with("rungs R2, R3 can never reach the end of the scan")
            && message.contains(
                "leaves the loop after --loop-cap loop-backs of each loop-back rung per scan"
            ),
        "{stderr}"
    );
    // As text, in the style of the other diagnostics.
    let out = std::process::Command::new(bin)
        .args(["report", file.to_str().unwrap()])
        .output()
        .unwrap();
    let stderr = String::from_utf8(out.stderr).unwrap();
    // Placed at the first rung of the loop, with its line under a caret.
    assert_eq!(
        stderr,
        format!(
            "warning[W0202]: {message}\n  --> {}:5:15\n  |\n5 |               {}\n  |               {}\n\n",
            file.display(),
            r#"{"id": "R2", "label": "L2", "ld": [{"coil": "y"}]},"#,
            "^".repeat(50)
        )
    );
    assert_eq!(
        (d["line"].as_u64(), d["column"].as_u64()),
        (Some(5), Some(15))
    );
    let run = std::process::Command::new(bin)
        .args([
            "run",
            file.to_str().unwrap(),
            "--scans",
            "2",
            "--loop-cap",
            "5",
            "--mode",
            "seq",
            "--format",
            "json",
        ])
        .output()
        .unwrap();
    let j: Value = serde_json::from_slice(&run.stdout).unwrap();
    let faults = j["faults"].as_array().unwrap();
    assert!(
        faults
            .iter()
            .any(|f| f["rung"] == "R3" && f["kind"] == "loop-cap"),
        "{faults:?}"
    );
    let _ = std::fs::remove_file(&file);
}
