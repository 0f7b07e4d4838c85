//! Every input the fuzz harness (`fuzz_readers`, docs/fuzzing.md) found to crash, hang or
//! mislead, kept in `tests/fuzz-regressions/` and run through the command that failed on it: each
//! now ends within seconds with exit code 2 and one error located inside the file (line and a
//! 1-based column), or succeeds with output that loads again.

use crate::common::cli::root;
use std::process::{Command, Output, Stdio};
use std::time::{Duration, Instant};

/// Runs `plc-deps ARGS` in the checkout, killing it (and failing) after `limit`.
fn run_within(args: &[&str], limit: Duration) -> Output {
    let mut child = Command::new(env!("CARGO_BIN_EXE_plc-deps"))
        .current_dir(root())
        .args(args)
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("run plc-deps");
    let start = Instant::now();
    while child.try_wait().expect("wait").is_none() {
        if start.elapsed() > limit {
            let _ = child.kill();
            let _ = child.wait();
            panic!("plc-deps {args:?} still ran after {limit:?}");
        }
        std::thread::sleep(Duration::from_millis(20));
    }
    child.wait_with_output().expect("output")
}

/// The `FILE:LINE:COLUMN` of the error on standard error, with `file` in it: (line, column).
fn located(out: &Output, file: &str) -> (u32, u32) {
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{err}");
    let at = err
        .find(file)
        .unwrap_or_else(|| panic!("the error names {file}: {err}"));
    let mut parts = err[at + file.len()..].split(':').skip(1);
    let line = parts.next().and_then(|l| l.trim().parse().ok());
    let column = parts.next().and_then(|c| c.trim().parse().ok());
    match (line, column) {
        (Some(l), Some(c)) if l >= 1 && c >= 1 => (l, c),
        _ => panic!("no 1-based line and column after {file}: {err}"),
    }
}

const LIMIT: Duration = Duration::from_secs(20);

#[test]
fn an_inputs_json_error_at_the_start_of_a_line_has_a_1_based_column() {
    for (name, want) in [
        ("column-0-top-level-object.json", (1, 1)),
        ("column-0-eof.json", (2, 1)),
    ] {
        let file = format!("tests/fuzz-regressions/inputs-json/{name}");
        let out = run_within(
            &["run", "analyses/example-a/program.json", "--scans", "1", "--inputs", &file],
            LIMIT,
        );
        assert_eq!(located(&out, &file), want, "{name}");
    }
}

#[test]
fn a_comparison_pin_numbered_past_the_declared_pins_is_refused_at_once() {
    let file = "tests/fuzz-regressions/plcopen/plcopen-pins-2147483647.xml";
    for cmd in ["report", "run"] {
        let out = run_within(&[cmd, file], LIMIT);
        let (line, _) = located(&out, file);
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(err.contains("IN2147483647"), "{cmd}: names the pin: {err}");
        assert!(line > 1, "{cmd}: {err}");
    }
}

#[test]
fn an_stl_file_whose_network_comment_is_not_a_rung_id_converts_to_json_that_loads() {
    let file = "tests/fuzz-regressions/stl/convert-rung-id.stl";
    let out = run_within(&["convert", file], LIMIT);
    if out.status.success() {
        let json = crate::common::cli::tmp("convert-rung-id.json");
        std::fs::write(&json, &out.stdout).unwrap();
        let back = run_within(&["report", json.to_str().unwrap()], LIMIT);
        assert!(
            back.status.success(),
            "the converted JSON loads: {}",
            String::from_utf8_lossy(&back.stderr)
        );
    } else {
        located(&out, file);
    }
}
