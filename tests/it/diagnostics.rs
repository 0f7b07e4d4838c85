//! Diagnostics as the command line prints them: every code documented in docs/diagnostics.md,
//! the rustc-style rendering (caret under the token, a "did you mean" hint, long lines cut
//! around the token, an XML tag name), the JSON lines of `--format json` with their documented
//! keys, and the exit codes (0 done, 1 a run that faulted or whose modes differed, 2 bad input
//! or usage).

use crate::common;

use common::cli::{root, run, run_stdin, tmp};
use serde_json::Value;

/// Every `"E0123"` / `"W0123"` string literal of the source files under `dir`.
fn codes_in(dir: &std::path::Path, out: &mut Vec<String>) {
    for entry in std::fs::read_dir(dir).unwrap() {
        let path = entry.unwrap().path();
        if path.is_dir() {
            codes_in(&path, out);
        } else if path.extension().is_some_and(|e| e == "rs") {
            let text = std::fs::read_to_string(&path).unwrap();
            let b = text.as_bytes();
            for i in 0..b.len().saturating_sub(6) {
                let code = &b[i + 1..i + 6];
                if b[i] == b'"'
                    && matches!(code[0], b'E' | b'W')
                    && code[1..].iter().all(u8::is_ascii_digit)
                    && b[i + 6] == b'"'
                {
                    out.push(String::from_utf8(code.to_vec()).unwrap());
                }
            }
        }
    }
}

#[test]
fn every_code_the_source_defines_is_documented_with_an_example() {
    let mut codes = Vec::new();
    codes_in(&root().join("src"), &mut codes);
    codes_in(&root().join("crates"), &mut codes);
    codes.sort();
    codes.dedup();
    assert!(codes.len() >= 47, "found {codes:?}");
    assert!(codes.contains(&"E0204".to_string()) && codes.contains(&"W0104".to_string()));
    let doc = std::fs::read_to_string(root().join("docs/diagnostics.md")).unwrap();
    let missing: Vec<&String> = codes
        .iter()
        .filter(|c| {
            let section = doc.split(&format!("\n### {c} — ")).nth(1);
            // The section's example is its first line starting with the code's severity.
            let kind = if c.starts_with('E') {
                "error["
            } else {
                "warning["
            };
            !section.is_some_and(|s| {
                s.split("\n### ")
                    .next()
                    .unwrap()
                    .contains(&format!("{kind}{c}]: "))
            })
        })
        .collect();
    assert!(
        missing.is_empty(),
        "codes without a section and example in docs/diagnostics.md: {missing:?}"
    );
}

const MISSPELT: &str = r#"{"program": "p", "vars": [{"name": "Start", "type": "BOOL", "class": "input"}, {"name": "Count", "type": "INT"}, {"name": "Q", "type": "BOOL", "class": "output"}],
 "rungs": [{"id": "R1", "ld": [{"contact": "Strat"}, {"coil": "Q"}]},
           {"id": "R2", "ld": [{"op": "ADD", "in": ["Coutn", 1], "out": "Count"}]}]}"#;

#[test]
fn an_undefined_name_gets_a_caret_under_it_and_the_nearest_declared_name() {
    let out = run_stdin(&["report", "-"], MISSPELT.as_bytes());
    assert_eq!(out.status.code(), Some(2));
    assert_eq!(
        String::from_utf8(out.stderr).unwrap(),
        r#"error[E0204]: undefined variable `Strat`
  --> <stdin>:2:44
  |
2 |  "rungs": [{"id": "R1", "ld": [{"contact": "Strat"}, {"coil": "Q"}]},
  |                                            ^^^^^^^ rung R1 at rungs[0].ld[0].contact
  |
  = help: did you mean `Start`?

error[E0204]: undefined variable `Coutn`
  --> <stdin>:3:53
  |
3 |            {"id": "R2", "ld": [{"op": "ADD", "in": ["Coutn", 1], "out": "Count"}]}]}
  |                                                     ^^^^^^^ rung R2 at rungs[1].ld[0].in[0]
  |
  = help: did you mean `Count`?

"#
    );
}

#[test]
fn a_minified_file_shows_only_the_neighbourhood_of_the_token() {
    let vars: Vec<String> = (0..400)
        .map(|i| format!("{{\"name\": \"v{i}\", \"type\": \"BOOL\"}}"))
        .collect();
    let text = format!(
        "{{\"program\": \"p\", \"vars\": [{}], \"rungs\": [{{\"id\": \"R1\", \"ld\": [{{\"contact\": \"nope\"}}, {{\"coil\": \"v1\"}}]}}]}}",
        vars.join(", ")
    );
    assert!(text.len() > 10_000 && !text.contains('\n'));
    let out = run_stdin(&["report", "-"], text.as_bytes());
    let stderr = String::from_utf8(out.stderr).unwrap();
    let column = text.find("\"nope\"").unwrap() + 1;
    let lines: Vec<&str> = stderr.lines().collect();
    assert_eq!(lines[0], "error[E0204]: undefined variable `nope`");
    assert_eq!(lines[1], format!("  --> <stdin>:1:{column}"));
    assert_eq!(
        lines[3],
        "1 | ...ungs\": [{\"id\": \"R1\", \"ld\": [{\"contact\": \"nope\"}, {\"coil\": \"v1\"}]}]}"
    );
    assert_eq!(
        lines[4],
        "  |                                            ^^^^^^ rung R1 at rungs[0].ld[0].contact"
    );
    assert!(stderr.len() < 400, "{stderr}");
}

#[test]
fn an_xml_error_underlines_the_tag_name() {
    let out = run_stdin(&["report", "-"], b"<svg width=\"3\"/>");
    assert_eq!(out.status.code(), Some(2));
    assert_eq!(
        String::from_utf8(out.stderr).unwrap(),
        "error[E0501]: not a PLCopen TC6 project: the root element is `svg`, not `project`\n  --> <stdin>:1:1\n  |\n1 | <svg width=\"3\"/>\n  |  ^^^ at top level\n\n"
    );
}

#[test]
fn with_format_json_each_error_is_one_object_with_the_documented_keys() {
    let file = "tests/errors/undefined-variable.json";
    let text = std::fs::read_to_string(root().join(file)).unwrap();
    let start = text.find("\"B\"").unwrap();
    for cmd in [
        &["report", file, "--format", "json"][..],
        &["order", file, "--format", "json"],
        &["run", file, "--format", "json"],
    ] {
        let out = run(cmd);
        assert_eq!(out.status.code(), Some(2), "{cmd:?}");
        assert!(out.stdout.is_empty());
        let stderr = String::from_utf8(out.stderr).unwrap();
        assert_eq!(stderr.lines().count(), 1, "{stderr}");
        let d: Value = serde_json::from_str(&stderr).unwrap();
        assert_eq!(
            d,
            serde_json::json!({
                "code": "E0204", "severity": "error", "message": "undefined variable `B`",
                "file": file, "line": 1, "column": start + 1,
                "span": {"start": start, "end": start + 3}, "hint": null,
                "location": "rung R2 at rungs[1].ld[0].or[1][0].contact"
            })
        );
    }
    let several = run_stdin(&["report", "-", "--format", "json"], MISSPELT.as_bytes());
    let lines: Vec<Value> = String::from_utf8(several.stderr)
        .unwrap()
        .lines()
        .map(|l| serde_json::from_str(l).unwrap())
        .collect();
    assert_eq!(lines.len(), 2);
    assert_eq!(lines[1]["hint"], "did you mean `Count`?");
    let missing = run(&["report", "no/such.json", "--format", "json"]);
    assert_eq!(
        serde_json::from_slice::<Value>(&missing.stderr).unwrap(),
        serde_json::json!({"code": null, "severity": "error",
            "message": "cannot read the program no/such.json: No such file or directory",
            "file": null, "line": null, "column": null, "span": null, "hint": null, "location": null})
    );
}

#[test]
fn exit_codes_are_0_done_1_run_fault_and_2_bad_input_or_usage() {
    let ok = run(&["run", "analyses/example-a/program.json", "--scans", "3"]);
    assert_eq!(ok.status.code(), Some(0));
    assert!(ok.stderr.is_empty());
    let faulty = tmp("div0.json");
    std::fs::write(
        &faulty,
        r#"{"program": "p", "vars": [{"name": "d", "type": "INT", "class": "input"}, {"name": "x", "type": "INT", "class": "output"}],
            "rungs": [{"id": "R1", "ld": [{"op": "DIV", "in": [1, "d"], "out": "x"}]}]}"#,
    )
    .unwrap();
    let out = run(&["run", faulty.to_str().unwrap(), "--scans", "2"]);
    assert_eq!(out.status.code(), Some(1));
    assert!(String::from_utf8(out.stdout)
        .unwrap()
        .contains("faults: 2 (1 distinct fault)"));
    assert_eq!(
        String::from_utf8(out.stderr).unwrap(),
        "error: the run faulted: 2 faults (first: div-by-zero on rung R1 in scan 0; faults in the report)\n"
    );
    for usage in [
        &["run"][..],
        &["frobnicate"],
        &["report", "x.json", "--format", "bogus"],
        &["run", "x.json", "--scans", "many"],
        &["gen"],
    ] {
        assert_eq!(run(usage).status.code(), Some(2), "{usage:?}");
    }
    let bad = run(&["report", "tests/errors/syntax.json"]);
    assert_eq!(bad.status.code(), Some(2));
}

#[test]
fn a_run_whose_modes_differ_is_a_failure_naming_the_first_difference() {
    use plc_deps::cmd::run::{failure, run_report, RunConfig, RunMode};
    let mut c = RunConfig::new(root().join("analyses/example-a/program.json"));
    c.scans = Some(2);
    c.mode = RunMode::Both;
    c.threads = 2;
    let mut r = run_report(&c).unwrap();
    assert_eq!((r.identical, r.fault_count), (Some(true), 0));
    assert_eq!(failure(&r), None);
    r.identical = Some(false);
    r.first_difference =
        Some(serde_json::json!({"scan": 1, "variable": "Y", "seq": true, "par": false}));
    let e = plc_deps::cmd::CliError::Run(failure(&r).unwrap());
    assert_eq!(
        e.to_string(),
        "the sequential and parallel runs differ (first in scan 1, variable Y; first_difference in the report)"
    );
    assert_eq!(e.exit_code(), 1);
}

/// Rungs the analysis warns about: R2 skipped by a jump, R4 empty, R5 without effect, and a
/// subroutine nothing calls.
const IDLE: &str = r#"{"program": "p",
 "vars": [{"name": "a", "type": "BOOL", "class": "input"}, {"name": "y", "type": "BOOL"}],
 "rungs": [
   {"id": "R1", "ld": [{"jmp": "L3"}]},
   {"id": "R2", "ld": [{"contact": "a"}, {"coil": "y"}]},
   {"id": "R3", "label": "L3", "ld": [{"contact": "y"}, {"coil": "y"}]},
   {"id": "R4", "ld": []},
   {"id": "R5", "ld": [{"contact": "a"}]}
 ],
 "subroutines": {"S": {"rungs": [{"id": "S1", "ld": [{"contact": "a"}, {"coil": "y"}]}]}}}"#;

#[test]
fn the_analysis_warnings_are_coded_diagnostics_at_their_rungs() {
    let out = run_stdin(&["report", "-", "--format", "json"], IDLE.as_bytes());
    assert_eq!(out.status.code(), Some(0));
    let shown: Vec<Value> = String::from_utf8(out.stderr)
        .unwrap()
        .lines()
        .map(|l| serde_json::from_str(l).unwrap())
        .collect();
    let brief: Vec<(&str, &str, &str)> = shown
        .iter()
        .map(|d| {
            assert_eq!(d["severity"], "warning");
            (
                d["code"].as_str().unwrap(),
                d["file"].as_str().unwrap(),
                d["message"].as_str().unwrap(),
            )
        })
        .collect();
    assert_eq!(
        brief,
        [
            (
                "W0201",
                "<stdin>",
                "rung R2 can never run (no path from the start of the scan reaches it)"
            ),
            ("W0203", "<stdin>", "subroutine S is never called"),
            ("W0205", "<stdin>", "rung R4 is empty (no elements)"),
            (
                "W0206",
                "<stdin>",
                "rung R5 has no effect: nothing is written and control is not transferred"
            ),
        ]
    );
    // Each is placed at its first rung (the subroutine at its first rung S1).
    let places: Vec<(u64, u64)> = shown
        .iter()
        .map(|d| (d["line"].as_u64().unwrap(), d["column"].as_u64().unwrap()))
        .collect();
    assert_eq!(places, [(5, 4), (10, 34), (7, 4), (8, 4)]);
    // The report has the same warnings with their codes.
    let report: Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(
        report["warning_codes"],
        serde_json::json!(["W0201", "W0203", "W0205", "W0206"])
    );
    assert_eq!(report["warnings"][3], brief[3].2);
    // As text, in the rustc style, with the rung's line under a caret.
    let out = run_stdin(&["report", "-"], IDLE.as_bytes());
    let stderr = String::from_utf8(out.stderr).unwrap();
    assert!(
        stderr.starts_with("warning[W0201]: rung R2 can never run (no path from the start of the scan reaches it)\n  --> <stdin>:5:4\n  |\n5 |    {\"id\": \"R2\", "),
        "{stderr}"
    );
    let text = String::from_utf8(out.stdout).unwrap();
    assert!(
        text.contains("\n  warning[W0206]: rung R5 has no effect"),
        "{text}"
    );
}

#[test]
fn listing_only_the_direct_pairs_is_a_coded_warning() {
    // R1 writes X; R2 and R3 read it: with --max-pairs 1 only the direct pairs are listed.
    let program = r#"{"program": "p", "vars": [{"name": "a", "type": "BOOL", "class": "input"}, {"name": "x", "type": "BOOL"}, {"name": "y", "type": "BOOL"}],
      "rungs": [{"id": "R1", "ld": [{"contact": "a"}, {"coil": "x"}]},
                {"id": "R2", "ld": [{"contact": "x"}, {"coil": "x"}]},
                {"id": "R3", "ld": [{"contact": "x"}, {"coil": "y"}]}]}"#;
    let out = run_stdin(
        &["report", "-", "--format", "json", "--max-pairs", "1"],
        program.as_bytes(),
    );
    assert_eq!(out.status.code(), Some(0));
    let d: Value = serde_json::from_slice(&out.stderr).unwrap();
    assert_eq!(d["code"], "W0207", "{d}");
    let report: Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(report["dependences_listed"], "direct");
    let message = d["message"].as_str().unwrap();
    let listed = report["dependences"]
        .as_array()
        .unwrap()
        .iter()
        .filter(|x| x["kind"] != "control")
        .count();
    assert!(
        message.ends_with(&format!(
            "data dependence pairs are more than --max-pairs allows; listing the {listed} direct ones (they imply the rest; --dependences all lists every pair)"
        )),
        "{message}"
    );
}

/// The hint of a fragment-rule error is a fix: applied to the program, it loads.
#[test]
fn a_fragment_rule_error_hints_the_fix_and_the_fix_loads() {
    let broken =
        std::fs::read_to_string(root().join("tests/errors/fbd-fragment-rule.json")).unwrap();
    let out = run_stdin(&["order", "-"], broken.as_bytes());
    assert_eq!(out.status.code(), Some(2));
    let stderr = String::from_utf8(out.stderr).unwrap();
    assert!(
        stderr.contains("= help: write that output of block 9 to a variable and use the variable in block 12 instead of the arc: it keeps its last value in the scans where block 9 does not run"),
        "{stderr}"
    );
    // The fix: block 9 writes V, block 12 reads V.
    let fixed = broken
        .replace(
            r#"{"name": "Y", "type": "INT", "class": "output"}"#,
            r#"{"name": "Y", "type": "INT", "class": "output"}, {"name": "V", "type": "INT"}"#,
        )
        .replace(
            r#""cond": {"from": 4}}"#,
            r#""cond": {"from": 4}, "out": "V"}"#,
        )
        .replace(r#"{"from": 9}]"#, r#""V"]"#);
    assert_ne!(fixed, broken);
    let out = run_stdin(&["order", "-"], fixed.as_bytes());
    assert_eq!(
        out.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    // A one-source control arc from another fragment: the hint is to remove it.
    let ordered = broken.replace(
        r#"[{"from": 8}, {"from": 9}]"#,
        r#"[{"from": 8}, 1], "after": [9]"#,
    );
    let out = run_stdin(&["order", "-"], ordered.as_bytes());
    assert_eq!(out.status.code(), Some(2));
    let stderr = String::from_utf8(out.stderr).unwrap();
    assert!(
        stderr.starts_with("error[E0410]: block 12 (fragment F(3)) runs after block 9"),
        "{stderr}"
    );
    assert!(
        stderr.contains("= help: remove the control arc from block 9 to block 12: block 9 does not run in every scan that runs block 12, so it cannot order it"),
        "{stderr}"
    );
    let out = run_stdin(
        &["order", "-"],
        ordered.replace(r#", "after": [9]"#, "").as_bytes(),
    );
    assert_eq!(
        out.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
}
