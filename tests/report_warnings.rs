//! Programs the analysis must not get wrong quietly: an endless jump loop (no path to STOP),
//! a rung nothing reaches, a subroutine nothing calls.

use plc_deps::app::{render_report, ReportFormat};
use plc_deps::read::program_from_json;
use plc_deps::report::View;
use serde_json::{json, Value};

fn report(text: &str) -> (Value, String) {
    let p = program_from_json(text).unwrap();
    let j = serde_json::from_str(&render_report(&p, ReportFormat::Json, View::All)).unwrap();
    (j, render_report(&p, ReportFormat::Text, View::All))
}

#[test]
fn endless_loop_is_a_warning_with_a_sound_tree() {
    // R2 and R3 jump to each other forever once R1 lets control in; R4 is after the loop.
    let (j, text) = report(
        r#"{"program": "p",
            "vars": [{"name": "a", "type": "BOOL", "class": "input"}, {"name": "y", "type": "BOOL"}],
            "rungs": [
              {"id": "R1", "ld": [{"contact": "a"}, {"jmp": "L4"}]},
              {"id": "R2", "label": "L2", "ld": [{"coil": "y"}]},
              {"id": "R3", "ld": [{"jmp": "L2"}]},
              {"id": "R4", "label": "L4", "ld": [{"contact": "y"}, {"coil": "y"}]}
            ]}"#,
    );
    let warnings = j["warnings"].as_array().unwrap();
    assert!(
        warnings.iter().any(|w| w
            .as_str()
            .unwrap()
            .starts_with("rungs R2, R3 can never reach the end of the scan")),
        "{warnings:?}"
    );
    assert!(text.contains("warning: rungs R2, R3 can never reach the end of the scan"));
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
    let warnings: Vec<&str> = j["warnings"]
        .as_array()
        .unwrap()
        .iter()
        .map(|w| w.as_str().unwrap())
        .collect();
    assert_eq!(
        warnings,
        vec![
            "rung R2 can never run (no path from the start of the scan reaches it)",
            "subroutine S is never called"
        ]
    );
    assert!(text.contains("warning: subroutine S is never called"));
}
