//! The scan budget (docs/scan.md, *Scan budget*): programs whose scan would never end — 30
//! subroutines each calling the next twice (2^30 calls in one scan), 100 nested FOR loops each
//! under the loop cap — end promptly with a `scan-budget` fault, with the same state and faults
//! in the sequential walk, the parallel executor, `--mode both` and the generated C; a budget
//! lower than a normal program needs faults it exactly where the charges say. And `run --mode
//! both` keeps no memory per scan.

use crate::common::c::check;
use crate::common::cli::{run, tmp};
use plc_deps::codegen::c::CConfig;
use serde_json::{json, Value};
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

/// Main rung R1 calls S0; S0 … S28 each call the next twice (two rungs), S29 adds 1 to `n`;
/// R2 adds 1000 to `n`. A whole scan would make 2^30 calls.
fn calls_program() -> String {
    let mut subs = serde_json::Map::new();
    for k in 0..30 {
        let rungs = if k < 29 {
            json!([{"id": format!("S{k}.a"), "ld": [{"call": format!("S{}", k + 1)}]},
                   {"id": format!("S{k}.b"), "ld": [{"call": format!("S{}", k + 1)}]}])
        } else {
            json!([{"id": "S29.a", "ld": [{"op": "ADD", "in": ["n", 1], "out": "n"}]}])
        };
        subs.insert(format!("S{k}"), json!({ "rungs": rungs }));
    }
    json!({"program": "calls", "vars": [{"name": "n", "type": "DINT", "class": "output"}],
        "rungs": [{"id": "R1", "ld": [{"call": "S0"}]},
                  {"id": "R2", "ld": [{"op": "ADD", "in": ["n", 1000], "out": "n"}]}],
        "subroutines": subs})
    .to_string()
}

/// 100 nested FOR loops of two trips each (F0 … F99, the body B adds 1 to `n`, NEXT rungs N99
/// … N0), then R adds 1000 to `n`. Every loop is far under the loop cap, the nest 2^100 trips.
fn fors_program() -> String {
    let depth = 100;
    let mut vars = vec![json!({"name": "n", "type": "DINT", "class": "output"})];
    vars.extend((0..depth).map(|d| json!({"name": format!("i{d}"), "type": "INT"})));
    let mut rungs: Vec<Value> = (0..depth)
        .map(|d| json!({"id": format!("F{d}"), "ld": [{"for": {"var": format!("i{d}"), "from": 1, "to": 2}}]}))
        .collect();
    rungs.push(json!({"id": "B", "ld": [{"op": "ADD", "in": ["n", 1], "out": "n"}]}));
    rungs.extend(
        (0..depth)
            .rev()
            .map(|d| json!({"id": format!("N{d}"), "ld": [{"next": true}]})),
    );
    rungs.push(json!({"id": "R", "ld": [{"op": "ADD", "in": ["n", 1000], "out": "n"}]}));
    json!({"program": "fors", "vars": vars, "rungs": rungs}).to_string()
}

/// A normal program whose charges are easy to count by hand. The loop task (L1 … L4) charges 2
/// per call of SUB (its two rungs) and 3 per NEXT loop-back (L2, L3, L4): 5 per trip, 50 for
/// the ten trips. L5 is a task of its own: its call charges 2 to a fresh count.
fn counted_program() -> String {
    json!({"program": "counted",
        "vars": [{"name": "n", "type": "INT", "class": "output"}, {"name": "m", "type": "INT", "class": "output"},
                 {"name": "k", "type": "INT", "class": "output"}, {"name": "i", "type": "INT", "class": "output"}],
        "rungs": [{"id": "L1", "ld": [{"for": {"var": "i", "from": 1, "to": 10}}]},
                  {"id": "L2", "ld": [{"op": "ADD", "in": ["n", 1], "out": "n"}]},
                  {"id": "L3", "ld": [{"call": "SUB"}]},
                  {"id": "L4", "ld": [{"next": true}]},
                  {"id": "L5", "ld": [{"call": "SUB"}, {"op": "ADD", "in": ["k", 1], "out": "k"}]}],
        "subroutines": {"SUB": {"rungs": [
            {"id": "S1", "ld": [{"op": "ADD", "in": ["m", 1], "out": "m"}]},
            {"id": "S2", "ld": [{"op": "ADD", "in": ["m", 1], "out": "m"}]}]}}})
    .to_string()
}

/// Writes `text` to a scratch file named `name`.
fn program_file(name: &str, text: &str) -> String {
    let path = tmp(name);
    std::fs::write(&path, text).unwrap();
    path.to_str().unwrap().to_string()
}

/// `plc-deps run FILE --format json ARGS` under a watchdog of `limit`: the exit code and the
/// report. A run still going at the limit is killed and fails the test.
fn run_json(file: &str, args: &[&str], limit: Duration) -> (i32, Value) {
    let mut child = Command::new(env!("CARGO_BIN_EXE_plc-deps"))
        .args(["run", file, "--format", "json"])
        .args(args)
        .stdout(Stdio::piped())
        .stderr(Stdio::null())
        .spawn()
        .unwrap();
    let started = Instant::now();
    loop {
        if let Some(status) = child.try_wait().unwrap() {
            let out = child.wait_with_output().unwrap();
            let report: Value = serde_json::from_slice(&out.stdout).unwrap();
            return (status.code().unwrap(), report);
        }
        if started.elapsed() > limit {
            let _ = child.kill();
            let _ = child.wait();
            panic!("`run {file} {args:?}` still running after {limit:?}");
        }
        std::thread::sleep(Duration::from_millis(20));
    }
}

/// The faults of a report as (scan, rung, kind).
fn faults(r: &Value) -> Vec<(u64, String, String)> {
    r["faults"]
        .as_array()
        .unwrap()
        .iter()
        .map(|f| {
            (
                f["scan"].as_u64().unwrap(),
                f["rung"].as_str().unwrap().to_string(),
                f["kind"].as_str().unwrap().to_string(),
            )
        })
        .collect()
}

/// Runs `file` in `--mode seq`, `par` and `both` with `args`: each faults (exit 1) with a
/// scan-budget fault in every scan, and all three give the same state and faults (`both` says
/// identical). Returns the sequential report.
fn same_in_every_mode(file: &str, args: &[&str], scans: u64, limit: Duration) -> Value {
    let scans = scans.to_string();
    let mut reports = Vec::new();
    for mode in ["seq", "par", "both"] {
        let mut all = vec!["--mode", mode, "--scans", &scans];
        all.extend_from_slice(args);
        let (code, r) = run_json(file, &all, limit);
        assert_eq!(code, 1, "{mode}: the run faulted");
        if mode == "both" {
            assert_eq!(r["identical"], json!(true), "{mode}: seq == par");
        }
        let fs = faults(&r);
        for k in 0..scans.parse::<u64>().unwrap() {
            assert!(
                fs.iter().any(|f| f.0 == k && f.2 == "scan-budget"),
                "{mode}: a scan-budget fault in scan {k}: {fs:?}"
            );
        }
        reports.push((mode, r));
    }
    let (_, seq) = &reports[0];
    for (mode, r) in &reports[1..] {
        assert_eq!(r["state"], seq["state"], "{mode}: state as seq");
        assert_eq!(r["faults"], seq["faults"], "{mode}: faults as seq");
    }
    reports.swap_remove(0).1
}

#[test]
fn two_to_the_thirty_calls_end_with_a_budget_fault_in_every_mode() {
    let file = program_file("budget_calls.json", &calls_program());
    let r = same_in_every_mode(
        &file,
        &["--scan-budget", "100000"],
        2,
        Duration::from_secs(120),
    );
    // The refused call is in the subroutines; the rest of the scan (R2) still runs.
    let fs = faults(&r);
    assert_eq!(fs.len(), 2, "{fs:?}");
    assert!(fs
        .iter()
        .all(|f| f.2 == "scan-budget" && f.1.starts_with('S')));
    let n = r["state"]["n"].as_i64().unwrap();
    assert_eq!(n % 1000 % 2, 0, "each scan adds its S29 runs and 1000: {n}");
    assert!(n > 2000, "R2 ran in both scans: {n}");
}

#[test]
fn a_hundred_nested_loops_end_with_a_budget_fault_in_every_mode() {
    let file = program_file("budget_fors.json", &fors_program());
    let r = same_in_every_mode(
        &file,
        &["--scan-budget", "100000"],
        2,
        Duration::from_secs(120),
    );
    let fs = faults(&r);
    assert_eq!(fs.len(), 2, "only the budget faults, no loop-cap: {fs:?}");
    assert!(fs
        .iter()
        .all(|f| f.2 == "scan-budget" && f.1.starts_with('N')));
    assert!(r["state"]["n"].as_i64().unwrap() > 2000);
}

#[test]
fn the_default_budget_ends_a_scan_of_two_to_the_thirty_calls() {
    let file = program_file("budget_calls_default.json", &calls_program());
    let (code, r) = run_json(
        &file,
        &["--mode", "seq", "--scans", "1"],
        Duration::from_secs(120),
    );
    assert_eq!(code, 1);
    let fs = faults(&r);
    assert_eq!(fs.len(), 1, "{fs:?}");
    assert_eq!(fs[0].2, "scan-budget");
}

#[test]
fn the_generated_c_faults_where_the_interpreter_does() {
    let budget = |b: u64| CConfig {
        scan_budget: b,
        ..CConfig::default()
    };
    for (tag, text) in [
        ("budget-calls", calls_program()),
        ("budget-fors", fors_program()),
    ] {
        check(&text, "", 2, &budget(100_000), tag);
    }
    check(&counted_program(), "", 3, &budget(21), "budget-counted-21");
    check(&counted_program(), "", 2, &budget(49), "budget-counted-49");
    check(
        &counted_program(),
        "",
        2,
        &CConfig::default(),
        "budget-counted",
    );
}

#[test]
fn the_generated_c_with_the_default_budget_ends_a_scan_of_two_to_the_thirty_calls() {
    // The interpreter side of `check` runs in this (unoptimised) test binary: the calls
    // program takes seconds a scan at the default budget, so one scan.
    check(
        &calls_program(),
        "",
        1,
        &CConfig::default(),
        "budget-calls-default",
    );
}

#[test]
fn a_budget_below_the_need_faults_at_the_counted_charge() {
    let file = program_file("budget_counted.json", &counted_program());
    let limit = Duration::from_secs(60);
    // 50 charges a scan fit a budget of 50: no fault, ten trips.
    let (code, r) = run_json(&file, &["--scans", "1", "--scan-budget", "50"], limit);
    assert_eq!(code, 0);
    assert_eq!(r["state"], json!({"n": 10, "m": 22, "k": 1, "i": 11}));
    // 49: the tenth NEXT (charges 47 → 50) is refused: the loop ends with i = 10, the fault is
    // on L4; L5's call is charged to its own task and runs.
    let (code, r) = run_json(&file, &["--scans", "1", "--scan-budget", "49"], limit);
    assert_eq!(code, 1);
    assert_eq!(r["state"], json!({"n": 10, "m": 22, "k": 1, "i": 10}));
    assert_eq!(
        faults(&r),
        vec![(0, "L4".to_string(), "scan-budget".to_string())]
    );
    // 21: four trips charge 20; the fifth call (20 → 22) is refused with the fault on L3, and
    // the fifth NEXT is refused silently (the task's budget is spent): n = 5, m = 8, i = 5;
    // then L5's call (a fresh count) adds 2 to m. Every scan alike, in every mode.
    let r = same_in_every_mode(&file, &["--scan-budget", "21"], 2, limit);
    assert_eq!(r["state"], json!({"n": 10, "m": 20, "k": 2, "i": 5}));
    assert_eq!(
        faults(&r),
        vec![
            (0, "L3".to_string(), "scan-budget".to_string()),
            (1, "L3".to_string(), "scan-budget".to_string())
        ]
    );
}

#[test]
fn the_default_budget_is_documented_and_shown() {
    assert_eq!(plc_deps::exec::DEFAULT_SCAN_BUDGET, 10_000_000);
    let help = run(&["run", "--help"]);
    let text = String::from_utf8_lossy(&help.stdout);
    assert!(text.contains("--scan-budget <N>"), "{text}");
    assert!(text.contains("[default: 10000000]"), "{text}");
    let doc = std::fs::read_to_string(crate::common::cli::root().join("docs/scan.md")).unwrap();
    assert!(doc.contains("`--scan-budget`, default 10 000 000"));
}

/// The peak resident memory of `plc-deps ARGS` in KiB (its own, from `wait4`).
#[cfg(target_os = "linux")]
#[allow(clippy::zombie_processes)] // reaped by `wait4`, which also gives its peak memory
fn peak_kib(args: &[&str]) -> i64 {
    let child = Command::new(env!("CARGO_BIN_EXE_plc-deps"))
        .args(args)
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .spawn()
        .unwrap();
    let pid = child.id() as libc::pid_t;
    let mut status = 0;
    // SAFETY: all-zero bytes are a valid `rusage` (plain integers and timevals).
    let mut usage: libc::rusage = unsafe { std::mem::zeroed() };
    // SAFETY: `pid` is our child, not yet waited for (the `Child` is never waited on), and both
    // pointers are to live locals of the types `wait4` writes.
    let got = unsafe { libc::wait4(pid, &mut status, 0, &mut usage) };
    assert_eq!(got, pid, "wait4");
    assert!(
        libc::WIFEXITED(status) && libc::WEXITSTATUS(status) == 0,
        "{args:?}: status {status}"
    );
    usage.ru_maxrss
}

#[cfg(target_os = "linux")]
#[test]
fn both_modes_keep_no_memory_per_scan() {
    let file = program_file(
        "budget_memory.json",
        r#"{"program": "m", "vars": [{"name": "a", "type": "BOOL", "class": "input"},
            {"name": "q", "type": "BOOL", "class": "output"}],
            "rungs": [{"id": "R1", "ld": [{"contact": "a"}, {"coil": "q"}]}]}"#,
    );
    let peak = |scans: &str| {
        peak_kib(&[
            "run", &file, "--mode", "both", "--plan", "seq", "--scans", scans, "--format", "json",
        ])
    };
    let (small, large) = (peak("2000"), peak("400000"));
    // 400,000 scans kept 24 bytes each before: 9.6 MB more than 2,000 scans.
    assert!(
        large - small < 2048,
        "peak {large} KiB for 400000 scans, {small} KiB for 2000"
    );
}

#[cfg(target_os = "linux")]
#[test]
fn four_billion_scans_reserve_nothing_up_front() {
    // Under a 3 GiB address space limit (the allocator reserves its arena, the workers their
    // stacks), a run of 2^32 scans starts and keeps running, and its resident memory does not
    // grow between its first and its fourth second (the old digests grew by 16–28 bytes a
    // scan, some hundred thousand scans a second here). Killed then, not aborted.
    let file = program_file(
        "budget_4g.json",
        r#"{"program": "m", "vars": [{"name": "a", "type": "BOOL", "class": "input"},
            {"name": "q", "type": "BOOL", "class": "output"}],
            "rungs": [{"id": "R1", "ld": [{"contact": "a"}, {"coil": "q"}]}]}"#,
    );
    let script = format!(
        "ulimit -v 3145728; exec \"{}\" run \"{file}\" --mode both --plan seq --scans 4294967296 --format json",
        env!("CARGO_BIN_EXE_plc-deps")
    );
    let mut child = Command::new("sh")
        .args(["-c", &script])
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let hwm = |pid: u32| -> Option<i64> {
        let status = std::fs::read_to_string(format!("/proc/{pid}/status")).ok()?;
        let line = status.lines().find(|l| l.starts_with("VmHWM:"))?;
        line.split_whitespace().nth(1)?.parse().ok()
    };
    std::thread::sleep(Duration::from_secs(1));
    let early = hwm(child.id());
    std::thread::sleep(Duration::from_secs(3));
    let late = hwm(child.id());
    let still = child.try_wait().unwrap();
    let _ = child.kill();
    let out = child.wait_with_output().unwrap();
    assert!(
        still.is_none(),
        "ended early ({still:?}): {}",
        String::from_utf8_lossy(&out.stderr)
    );
    let (early, late) = (early.expect("VmHWM at 1 s"), late.expect("VmHWM at 4 s"));
    assert!(
        late - early < 1024,
        "resident peak grew from {early} KiB to {late} KiB"
    );
}
