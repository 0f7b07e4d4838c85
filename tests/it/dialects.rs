//! `--dialect`: where the toolchains a file was written for differ, `run` and `c` follow the
//! file's (docs/dialects.md). `tests/dialects/beremiz.xml` and `codesys.xml` are one ST program
//! whose fileHeader names Beremiz or CODESYS. Expected values, each from its toolchain:
//! - CTU with PV 3 and CTD with PV 2 on a CU/CD that rises every other scan: matiec's
//!   `lib/counter.txt` counts only while `CV < PV` (CTD: `CV > 0`), and so does CODESYS's and
//!   Beckhoff's standard library ("as long as CV is less than PV"): after 10 scans (5 rising
//!   edges) CV is 3 and 0; IEC 61131-3's text (dialect `iec`) counts on: 5 and -5.
//! - TON with `PT := T#0s` and IN TRUE from the first scan: matiec's `lib/timer.txt` sets
//!   `Q := FALSE` in the call that sees IN rise and compares from the next call, so Q is FALSE
//!   after scan 1 and TRUE after scan 2; CODESYS and `iec` compare at once (TRUE after scan 1).
//! - TIME_TO_INT(T#2500ms), INT_TO_TIME(3), TIME_TO_REAL(T#1500ms): matiec counts seconds
//!   (`__time_to_int` is `tv_sec`; `__int_to_time(3)` is 3 s; `__time_to_real` seconds): 2,
//!   T#3s, 1.5; CODESYS milliseconds: 2500, T#3ms, 1500.0.
//! - `i * 258` with INT `i = 200`: matiec writes C's `i * 258`, computed in `int` (C11
//!   6.3.1.1), so `(i * 258) > 30000` compares 51600 (TRUE) and `(i * 258) / 2` is 25800,
//!   cut to INT only when stored; IEC 61131-3 types the product INT, which wraps to -13936:
//!   FALSE and -6968 (the CODESYS export keeps IEC's rule). Both cut the product passed to
//!   INT_TO_DINT's INT input: -13936.
//! - TON `T2` called twice a scan, with `PT := T#0s` then `T#1h`: matiec's TON, once elapsed
//!   (STATE 2 in `lib/timer.txt`), keeps Q until IN falls, so `q2` is TRUE from scan 2 (scan 1
//!   only starts the time); CODESYS and `iec` recompute `ET >= PT` in each call: FALSE.

use crate::common::c::{assert_ok, run_with_input};
use crate::common::cli::{run, tmp};
use serde_json::{json, Value};
use std::process::Command;

const BEREMIZ: &str = "tests/dialects/beremiz.xml";
const CODESYS: &str = "tests/dialects/codesys.xml";

/// The state after `scans` scans, run in both modes (which must agree).
fn state(file: &str, scans: u32, dialect: Option<&str>) -> Value {
    let n = scans.to_string();
    let mut args = vec![
        "run", file, "--scans", &n, "--mode", "both", "--format", "json",
    ];
    if let Some(d) = dialect {
        args.extend(["--dialect", d]);
    }
    let out = run(&args);
    let v: Value = serde_json::from_slice(&out.stdout)
        .unwrap_or_else(|e| panic!("{file}: {e}: {}", String::from_utf8_lossy(&out.stderr)));
    assert_eq!(v["identical"], json!(true), "{file}: seq != par");
    v["state"].clone()
}

/// The generated C's state after each of `scans` scans equals `run`'s.
fn c_equals_run(file: &str, scans: u32, dialect: Option<&str>) {
    let dir = tmp(&format!(
        "dialect-c-{}-{}",
        file.replace(['/', '.'], "_"),
        dialect.unwrap_or("file")
    ));
    let _ = std::fs::remove_dir_all(&dir);
    let mut args = vec!["c", file, "-o", dir.to_str().unwrap()];
    if let Some(d) = dialect {
        args.extend(["--dialect", d]);
    }
    assert_ok(&run(&args), "plc-deps c");
    let make = Command::new("make")
        .arg("-s")
        .current_dir(&dir)
        .output()
        .unwrap();
    assert_ok(&make, "make");
    let out = run_with_input(&dir.join("plc_program"), &[scans.to_string()], b"");
    let lines: Vec<Value> = String::from_utf8(out.stdout)
        .unwrap()
        .lines()
        .map(|l| serde_json::from_str(l).unwrap())
        .collect();
    assert_eq!(lines.len(), scans as usize, "{file}");
    for k in 1..=scans {
        assert_eq!(
            lines[k as usize - 1],
            state(file, k, dialect),
            "{file} ({dialect:?}): C and run differ after scan {k}"
        );
    }
}

#[test]
fn a_beremiz_project_runs_as_matiec_runs_it() {
    let s1 = state(BEREMIZ, 1, None);
    assert_eq!(
        s1["q0"],
        json!(false),
        "TON with PT 0: Q only from the next call"
    );
    assert_eq!(
        (&s1["secs"], &s1["t3"], &s1["r"]),
        (&json!(2), &json!(3000), &json!(1.5))
    );
    assert_eq!(
        (&s1["big"], &s1["half"], &s1["conv"]),
        (&json!(true), &json!(25800), &json!(-13936)),
        "INT arithmetic in C's int, cut where stored or passed"
    );
    assert_eq!(s1["q2"], json!(false));
    let s2 = state(BEREMIZ, 2, None);
    assert_eq!((&s2["q0"], &s2["q2"]), (&json!(true), &json!(true)));
    let s10 = state(BEREMIZ, 10, None);
    assert_eq!((&s10["C1"]["CV"], &s10["D1"]["CV"]), (&json!(3), &json!(0)));
    c_equals_run(BEREMIZ, 4, None);
}

#[test]
fn a_codesys_export_runs_as_codesys_runs_it() {
    let s1 = state(CODESYS, 1, None);
    assert_eq!(s1["q0"], json!(true), "TON with PT 0: Q in the same call");
    assert_eq!(
        (&s1["secs"], &s1["t3"], &s1["r"]),
        (&json!(2500), &json!(3), &json!(1500.0))
    );
    assert_eq!(
        (&s1["big"], &s1["half"], &s1["conv"]),
        (&json!(false), &json!(-6968), &json!(-13936)),
        "INT arithmetic in INT (IEC's typing)"
    );
    assert_eq!(state(CODESYS, 2, None)["q2"], json!(false));
    let s10 = state(CODESYS, 10, None);
    assert_eq!((&s10["C1"]["CV"], &s10["D1"]["CV"]), (&json!(3), &json!(0)));
    c_equals_run(CODESYS, 4, None);
}

#[test]
fn dialect_on_the_command_line_overrides_the_files() {
    let s1 = state(BEREMIZ, 1, Some("iec"));
    assert_eq!((&s1["q0"], &s1["secs"]), (&json!(true), &json!(2500)));
    assert_eq!(
        s1["half"],
        json!(25800),
        "the width of ST arithmetic is fixed when the body is read, by the file's editor"
    );
    let s10 = state(BEREMIZ, 10, Some("iec"));
    assert_eq!(
        (&s10["C1"]["CV"], &s10["D1"]["CV"]),
        (&json!(5), &json!(-5)),
        "IEC 61131-3's text counts to the type's limits"
    );
    assert_eq!(state(CODESYS, 1, Some("matiec"))["secs"], json!(2));
    c_equals_run(BEREMIZ, 4, Some("iec"));
    let out = run(&["run", BEREMIZ, "--dialect", "s7"]);
    assert_eq!(out.status.code(), Some(2));
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(
        stderr.contains("`s7` is not a dialect (iec, matiec, codesys)"),
        "{stderr}"
    );
}
