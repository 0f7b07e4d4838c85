//! Library function blocks the model lacks, hand-written: an RTC instance (IEC 61131-3
//! 2.5.2.3.5) in an FBD body is a black box that reads IN and PDT and writes Q and CDT; `run`
//! leaves its outputs at their initial values; one note names the instance.

use crate::plcopen_common as px;

use px::{block, in_var, line_col, project_in, report_and_warnings, run_scans, var_in};
use serde_json::json;

#[test]
fn an_rtc_instance_is_a_black_box_reading_its_inputs_and_writing_its_outputs() {
    let body = [
        in_var(1, "go"),
        in_var(2, "t0"),
        block(
            3,
            "RTC",
            Some("clock"),
            &[("IN", &[(1, None)]), ("PDT", &[(2, None)])],
            &["Q", "CDT"],
        ),
        var_in("outVariable", 4, "valid", (3, Some("Q"))),
        var_in("outVariable", 5, "now", (3, Some("CDT"))),
    ]
    .concat();
    let xml = project_in(
        "FBD",
        &[
            ("inputVars", "go", "BOOL"),
            ("inputVars", "t0", "DINT"),
            ("outputVars", "valid", "BOOL"),
            ("outputVars", "now", "DINT"),
            ("localVars", "clock", "RTC"),
        ],
        &body,
    );
    let (r, err) = report_and_warnings(&xml);
    let at = line_col(&xml, "<variable name=\"clock\"");
    assert!(err.contains(&format!("warning: <stdin>:{at}: instance P.clock of the library block RTC (IEC 61131-3 2.5.2.3.5): a black box that reads its inputs IN, PDT and writes its outputs Q, CDT; `run` does not compute it (its outputs keep their initial values)")), "{err}");
    let text = r.to_string();
    for v in ["go", "t0", "valid", "now", "clock"] {
        assert!(text.contains(&format!("\"{v}\"")), "{v} in {text}");
    }
    let v = run_scans(&xml, 2);
    assert_eq!(
        v["outputs"],
        json!({"valid": false, "now": 0, "clock.Q": false, "clock.CDT": 0})
    );
}
