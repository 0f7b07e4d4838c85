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
    let number = |s: &str| -> Option<u32> {
        let digits: String = s.chars().take_while(char::is_ascii_digit).collect();
        digits.parse().ok()
    };
    let mut parts = err[at + file.len()..].split(':').skip(1);
    let line = parts.next().and_then(number);
    let column = parts.next().and_then(number);
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
            &[
                "run",
                "analyses/example-a/program.json",
                "--scans",
                "1",
                "--inputs",
                &file,
            ],
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
        assert!(
            err.contains("GT needs its input `IN2` connected"),
            "{cmd}: {err}"
        );
        assert!(line > 1, "{cmd}: {err}");
    }
}

/// `NETWORK 1+I VW0, VW2`: not a network number. It was read as the rung id `1+I VW0`, which
/// `convert` then wrote into JSON that does not load.
#[test]
fn a_network_whose_number_is_not_a_number_is_refused_by_every_command() {
    let file = "tests/fuzz-regressions/stl/convert-rung-id.stl";
    for cmd in ["report", "convert", "il"] {
        let out = run_within(&[cmd, file], LIMIT);
        assert_eq!(located(&out, file), (3, 9), "{cmd}");
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(
            err.contains("NETWORK needs its number, not `1+I VW0`"),
            "{cmd}: {err}"
        );
    }
}
