//! `plc-deps run` as a user meets it: the JSON report's keys, inputs from CSV and JSON (values
//! held between rows and after the last one), the trace file, `--mode both` on programs with
//! jumps, loops and calls, faults, and bad input: one located error, exit code 2, no output file.

use crate::common;

use common::cli::*;

use serde_json::Value;
use std::path::Path;
use std::process::Output;

fn write(name: &str, text: &str) -> String {
    let path = tmp(name);
    std::fs::write(&path, text).unwrap();
    path.to_str().unwrap().to_owned()
}

fn json_of(out: &Output) -> Value {
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    serde_json::from_slice(&out.stdout).expect("JSON on stdout")
}

/// The JSON report of a run that faulted: written whole on stdout, exit code 1 and the error
/// `the run faulted: N faults (first: KIND on rung R in scan S; …)` as one JSON line on stderr.
fn faulted_json(out: &Output, first: &str) -> Value {
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{stderr}");
    let e: Value = serde_json::from_str(stderr.trim_end()).expect("one JSON error");
    assert_eq!(e["severity"], "error");
    assert!(
        e["message"]
            .as_str()
            .unwrap()
            .starts_with("the run faulted: ")
            && e["message"].as_str().unwrap().contains(first),
        "{stderr}"
    );
    serde_json::from_slice(&out.stdout).expect("JSON on stdout")
}

/// A failing run: exit code 2, one `error:` line on stderr containing `needle`, nothing on stdout.
fn fails(args: &[&str], needle: &str) -> String {
    let out = run(args);
    let stderr = one_line(&String::from_utf8(out.stderr).unwrap());
    assert_eq!(out.status.code(), Some(2), "{args:?}: {stderr}");
    assert!(out.stdout.is_empty(), "{args:?}: nothing on stdout");
    assert_eq!(stderr.lines().count(), 1, "{args:?}: one line: {stderr}");
    assert!(stderr.starts_with("error: "), "{stderr}");
    assert!(!stderr.contains("panicked"), "{stderr}");
    assert!(
        stderr.contains(needle),
        "{args:?}: expected {needle:?} in {stderr}"
    );
    stderr
}

/// Inputs `a` (BOOL), `n` (INT), `t` (TIME); outputs copy them; a TON on `a`.
const ECHO: &str = r#"{
  "program": "echo",
  "vars": [
    {"name": "a", "type": "BOOL", "class": "input"},
    {"name": "n", "type": "INT", "class": "input"},
    {"name": "t", "type": "TIME", "class": "input"},
    {"name": "q", "type": "BOOL", "class": "output"},
    {"name": "m", "type": "INT", "class": "output"},
    {"name": "u", "type": "TIME", "class": "output"},
    {"name": "rise", "type": "DINT", "class": "output"},
    {"name": "T1", "type": "TON"}
  ],
  "rungs": [
    {"id": "R1", "ld": [{"contact": "a"}, {"coil": "q"}]},
    {"id": "R2", "ld": [{"move": "n", "to": "m"}]},
    {"id": "R3", "ld": [{"move": "t", "to": "u"}]},
    {"id": "R4", "ld": [{"contact": "a", "edge": "rising"}, {"op": "ADD", "in": ["rise", 1], "out": "rise"}]},
    {"id": "R5", "ld": [{"contact": "a"}, {"ton": "T1", "pt": "T#30ms"}]}
  ]
}"#;

#[test]
fn json_report_has_the_normative_keys() {
    let out = run(&[
        "run",
        "analyses/conveyor/program.json",
        "--scans",
        "30",
        "--format",
        "json",
        "--threads",
        "2",
    ]);
    let j = json_of(&out);
    for key in [
        "scans",
        "outputs",
        "state",
        "faults",
        "modes",
        "identical",
        "first_difference",
    ] {
        assert!(j.get(key).is_some(), "key {key} in {j}");
    }
    assert_eq!(j["scans"], 30);
    assert_eq!(j["identical"], true);
    assert!(j["first_difference"].is_null());
    assert!(j["faults"].as_array().unwrap().is_empty());
    for mode in ["seq", "par"] {
        let m = &j["modes"][mode];
        assert!(m["scans_per_s"].as_f64().unwrap() > 0.0, "{m}");
        assert!(m["ns_per_scan"].as_f64().unwrap() > 0.0, "{m}");
    }
    // State: every declared variable, BOOLs as booleans, instances as objects of their fields,
    // no hidden edge memories; outputs are the output variables.
    let state = j["state"].as_object().unwrap();
    let program: Value = serde_json::from_str(
        &std::fs::read_to_string(root().join("analyses/conveyor/program.json")).unwrap(),
    )
    .unwrap();
    let declared: Vec<&str> = program["vars"]
        .as_array()
        .unwrap()
        .iter()
        .map(|v| v["name"].as_str().unwrap())
        .collect();
    assert_eq!(
        state.keys().map(String::as_str).collect::<Vec<_>>(),
        declared,
        "state holds the declared variables, in order"
    );
    assert!(!state.keys().any(|k| k.contains(':')), "no edge memories");
    for (name, v) in state {
        let ty = program["vars"]
            .as_array()
            .unwrap()
            .iter()
            .find(|x| x["name"] == name.as_str())
            .unwrap()["type"]
            .as_str()
            .unwrap();
        match ty {
            "BOOL" => assert!(v.is_boolean(), "{name}: {v}"),
            "TON" | "TOF" | "TP" => assert!(
                v["Q"].is_boolean() && v["ET"].is_number() && v["PT"].is_number(),
                "{name}: {v}"
            ),
            "CTU" | "CTD" => assert!(
                v["Q"].is_boolean() && v["CV"].is_number() && v["PV"].is_number(),
                "{name}: {v}"
            ),
            _ => assert!(v.is_number(), "{name}: {v}"),
        }
    }
    let outputs = j["outputs"].as_object().unwrap();
    assert!(!outputs.is_empty());
    for (name, v) in outputs {
        assert_eq!(&state[name], v);
    }
}

#[test]
fn csv_inputs_hold_their_last_value_and_the_trace_shows_every_scan() {
    let program = write("echo.json", ECHO);
    let inputs = write(
        "echo.csv",
        "a,n,t\ntrue,5,T#1s\n,7,\nfalse,,250\n\n  1 , -3 ,\n",
    );
    let trace = tmp("echo-trace.csv");
    let out = run(&[
        "run",
        &program,
        "--inputs",
        &inputs,
        "--scans",
        "6",
        "--mode",
        "seq",
        "--format",
        "json",
        "--trace",
        trace.to_str().unwrap(),
    ]);
    let j = json_of(&out);
    // The last row (scan 3) set a and n; scans 4 and 5 hold them; t held since scan 2.
    assert_eq!(
        j["outputs"],
        serde_json::json!({"q": true, "m": -3, "u": 250, "rise": 2})
    );
    assert!(j["identical"].is_null());
    assert!(j["modes"].get("par").is_none());
    let text = std::fs::read_to_string(&trace).unwrap();
    let lines: Vec<&str> = text.lines().collect();
    assert_eq!(lines[0], "scan,time_ms,a,n,t,q,m,u,rise,T1.Q,T1.ET,T1.PT");
    assert_eq!(lines.len(), 7);
    assert_eq!(lines[1], "0,0,1,5,1000,1,5,1000,1,0,0,30");
    assert_eq!(lines[2], "1,10,1,7,1000,1,7,1000,1,0,10,30");
    assert_eq!(lines[3], "2,20,0,7,250,0,7,250,1,0,0,30");
    assert_eq!(lines[4], "3,30,1,-3,250,1,-3,250,2,0,0,30");
    assert_eq!(lines[6], "5,50,1,-3,250,1,-3,250,2,0,20,30");
    // A chosen subset, fields included.
    let out = run(&[
        "run",
        &program,
        "--inputs",
        &inputs,
        "--trace",
        trace.to_str().unwrap(),
        "--trace-vars",
        "rise,T1.Q,T1,rise",
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let text = std::fs::read_to_string(&trace).unwrap();
    assert_eq!(
        text.lines().next().unwrap(),
        "scan,time_ms,rise,T1.Q,T1.ET,T1.PT",
        "each column once, where it was first asked for"
    );
    assert_eq!(text.lines().count(), 5, "scans default to the input rows");
}

#[test]
fn json_inputs_give_the_same_run_as_csv() {
    let program = write("echo2.json", ECHO);
    let csv = write("echo2.csv", "a,n,t\ntrue,5,T#1s\n,7,\nfalse,,250\n1,-3,\n");
    let json = write(
        "echo2-inputs.json",
        r#"[{"a": true, "n": 5, "t": "T#1s"}, {"n": 7}, {"a": false, "t": 250}, {"a": true, "n": -3, "t": null}]"#,
    );
    let a = json_of(&run(&[
        "run", &program, "--inputs", &csv, "--scans", "9", "--format", "json",
    ]));
    let b = json_of(&run(&[
        "run", &program, "--inputs", &json, "--scans", "9", "--format", "json",
    ]));
    assert_eq!(a["state"], b["state"]);
    assert_eq!(a["identical"], true);
    assert_eq!(b["identical"], true);
}

#[test]
fn both_modes_are_identical_on_programs_with_jumps_loops_and_calls() {
    let gen = tmp("gen-all.json");
    let out = run(&[
        "gen",
        "--rungs",
        "3000",
        "--width",
        "300",
        "--timers",
        "--loops",
        "--jumps",
        "--calls",
        "--seed",
        "5",
        "-o",
        gen.to_str().unwrap(),
    ]);
    assert!(out.status.success());
    for threads in ["1", "2", "3"] {
        let j = json_of(&run(&[
            "run",
            gen.to_str().unwrap(),
            "--scans",
            "150",
            "--threads",
            threads,
            "--format",
            "json",
            "--explain",
        ]));
        assert_eq!(
            j["identical"], true,
            "{threads} threads: {}",
            j["first_difference"]
        );
        let cores = std::thread::available_parallelism().map_or(1, |n| n.get()) as u64;
        let asked: u64 = threads.parse().unwrap();
        assert_eq!(j["threads"], asked);
        assert_eq!(j["workers"], asked.min(cores));
        assert_eq!(
            j["plan"]["threads"],
            asked.min(cores),
            "planned for the cores that exist"
        );
    }
    for dir in [
        "example-a",
        "example-b",
        "conveyor",
        "mixing-station",
        "packaging-line",
    ] {
        let program = format!("analyses/{dir}/program.json");
        let j = json_of(&run(&[
            "run", &program, "--scans", "200", "--format", "json",
        ]));
        assert_eq!(j["identical"], true, "{dir}");
    }
}

/// With `--mode both` the two passes take turns of `--alternate` scans: every scan is still
/// checked seq == par (the digests of a turn of the sequential pass reach the parallel one),
/// the parallel pass chooses as one run (its scans add up to the run's), the trace is the
/// sequential pass's whole, and the report says how they alternated.
#[test]
fn both_modes_take_turns_and_every_scan_is_still_compared() {
    let wide = generated(
        "alternate_wide.json",
        &["--rungs", "600", "--levels", "6", "--reads", "random"],
    );
    let wide = wide.to_str().unwrap().to_owned();
    let alone = json_of(&run(&[
        "run", &wide, "--scans", "40", "--mode", "seq", "--format", "json",
    ]));
    for plan in ["auto", "par", "deps", "exchange"] {
        let j = json_of(&run(&[
            "run",
            &wide,
            "--scans",
            "40",
            "--threads",
            "2",
            "--plan",
            plan,
            "--alternate",
            "7",
            "--format",
            "json",
        ]));
        assert_eq!(
            j["identical"], true,
            "--plan {plan}: {}",
            j["first_difference"]
        );
        assert_eq!(j["speedup_block_scans"], 7, "--plan {plan}");
        assert_eq!(j["speedup_scans"], 40);
        assert_eq!(j["state"], alone["state"], "--plan {plan}");
        let scans: u64 = (j["plan_run"]["scans"].as_object().unwrap().values())
            .map(|v| v.as_u64().unwrap())
            .sum();
        assert_eq!(
            scans, 40,
            "--plan {plan}: the parallel pass ran every scan once"
        );
    }
    let alone = json_of(&run(&[
        "run", &wide, "--mode", "par", "--scans", "40", "--format", "json",
    ]));
    assert!(alone["speedup_block_scans"].is_null());
    let trace = tmp("alternate_trace.csv");
    let out = run(&[
        "run",
        &wide,
        "--scans",
        "40",
        "--alternate",
        "3",
        "--trace",
        trace.to_str().unwrap(),
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let text = String::from_utf8(out.stdout).unwrap();
    assert!(text.contains("identical: yes"), "{text}");
    let par = text
        .lines()
        .find(|l| l.trim_start().starts_with("par "))
        .unwrap();
    assert!(
        par.contains("; seq and par alternated every 3 scans)")
            || par.contains("sequential fallback"),
        "{par}"
    );
    let rows: Vec<String> = std::fs::read_to_string(&trace)
        .unwrap()
        .lines()
        .skip(1)
        .map(|l| l.split(',').next().unwrap().to_owned())
        .collect();
    let expected: Vec<String> = (0..40).map(|k| k.to_string()).collect();
    assert_eq!(rows, expected, "one trace row per scan, in order");
    for dir in ["example-b", "conveyor", "mixing-station", "packaging-line"] {
        let program = format!("analyses/{dir}/program.json");
        let j = json_of(&run(&[
            "run",
            &program,
            "--scans",
            "60",
            "--alternate",
            "4",
            "--format",
            "json",
        ]));
        assert_eq!(j["identical"], true, "{dir}: {}", j["first_difference"]);
    }
    fails(
        &["run", &wide, "--alternate", "0"],
        "--alternate must be at least 1",
    );
}

#[test]
fn a_sequential_walk_says_so_instead_of_a_ratio_and_every_ratio_its_scans() {
    let one = write(
        "one_rung.json",
        r#"{"program": "one", "vars": [{"name": "a", "type": "BOOL", "class": "input"},
            {"name": "q", "type": "BOOL", "class": "output"}],
            "rungs": [{"id": "R1", "ld": [{"contact": "a"}, {"coil": "q"}]}]}"#,
    );
    let out = run(&["run", &one, "--scans", "100", "--threads", "2"]);
    assert!(out.status.success());
    let text = String::from_utf8(out.stdout).unwrap();
    let par = text
        .lines()
        .find(|l| l.trim_start().starts_with("par "))
        .unwrap();
    assert!(par.contains(" sequential fallback ("), "{par}");
    assert!(
        par.contains("the same sequential walk as seq, so no ratio"),
        "{par}"
    );
    assert!(!par.contains("x seq"), "{par}");
    // 96 scans in 8 windows of 12: the whole pass's time per scan is the mean of the windows',
    // so it lies between the fastest and the slowest (0.1 ns of rounding aside).
    let j = json_of(&run(&[
        "run",
        &one,
        "--scans",
        "96",
        "--threads",
        "2",
        "--format",
        "json",
    ]));
    for mode in ["seq", "par"] {
        let m = &j["modes"][mode];
        assert_eq!(m["timing_windows"], 8, "{m}");
        let (lo, ns, hi) = (
            m["ns_per_scan_min"].as_f64().unwrap(),
            m["ns_per_scan"].as_f64().unwrap(),
            m["ns_per_scan_max"].as_f64().unwrap(),
        );
        assert!(lo > 0.0 && lo <= ns + 0.1 && ns <= hi + 0.1, "{m}");
    }
    let wide = generated(
        "wide_plans.json",
        &["--rungs", "2000", "--levels", "4", "--reads", "random"],
    );
    let cores = std::thread::available_parallelism().map_or(1, |n| n.get());
    for (plan, candidates, fallback) in [
        (
            "seq",
            vec!["seq"],
            Some("the sequential walk was asked for (--plan seq)"),
        ),
        ("par", vec!["par"], None),
    ] {
        let j = json_of(&run(&[
            "run",
            wide.to_str().unwrap(),
            "--scans",
            "40",
            "--threads",
            "2",
            "--plan",
            plan,
            "--format",
            "json",
        ]));
        assert_eq!(j["identical"], true, "--plan {plan}");
        assert_eq!(j["plan_kind"], plan);
        assert_eq!(j["speedup_scans"], 40);
        if cores >= 2 {
            assert_eq!(
                j["plan_run"]["candidates"],
                serde_json::json!(candidates),
                "--plan {plan}"
            );
            assert_eq!(j["plan_run"]["scans"][candidates[0]], 40);
            assert_eq!(
                j["sequential_fallback"],
                serde_json::json!(fallback),
                "--plan {plan}"
            );
        }
    }
    if cores >= 2 {
        let out = run(&[
            "run",
            wide.to_str().unwrap(),
            "--scans",
            "40",
            "--threads",
            "2",
            "--plan",
            "par",
        ]);
        let text = String::from_utf8(out.stdout).unwrap();
        let par = text
            .lines()
            .find(|l| l.trim_start().starts_with("par "))
            .unwrap();
        assert!(par.contains("x seq over 40 scans"), "{par}");
        let out = run(&[
            "run",
            wide.to_str().unwrap(),
            "--scans",
            "40",
            "--threads",
            "2",
            "--explain",
        ]);
        let text = String::from_utf8(out.stdout).unwrap();
        assert!(text.contains("plan kind: auto ("), "{text}");
        assert!(text.contains("candidates: seq, par"), "{text}");
        assert!(
            text.contains("plan choice (--plan auto) over 40 scans:"),
            "{text}"
        );
    }
}

#[test]
fn more_threads_than_cores_is_a_warning_and_plans_for_the_cores() {
    let cores = std::thread::available_parallelism().map_or(1, |n| n.get());
    let threads = (cores + 6).to_string();
    let out = run(&[
        "run",
        "analyses/example-a/program.json",
        "--scans",
        "30",
        "--threads",
        &threads,
        "--format",
        "json",
        "--explain",
    ]);
    assert!(out.status.success());
    let err = one_line(&String::from_utf8(out.stderr).unwrap());
    let plural = if cores == 1 { "core" } else { "cores" };
    assert!(
        err.contains(&format!(
            "warning: --threads {threads} is more than the {cores} {plural} of this machine"
        )),
        "{err}"
    );
    let j: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(j["workers"], cores as u64);
    assert_eq!(j["plan"]["threads"], cores as u64);
    assert_eq!(j["identical"], true);
}

/// `--plan` with only the sequential walk, and `--alternate` with one mode, are warned about
/// once each and the run goes on; with both modes (or `--explain`) they are used, no warning.
#[test]
fn an_option_the_run_does_not_use_is_a_warning() {
    let prog = "analyses/example-a/program.json";
    let warned = |args: &[&str]| -> String {
        let mut all = vec!["run", prog, "--scans", "5"];
        all.extend_from_slice(args);
        let out = run(&all);
        assert!(out.status.success(), "{args:?}");
        String::from_utf8(out.stderr).unwrap()
    };
    assert_eq!(
        warned(&["--mode", "seq", "--plan", "exchange"]),
        "warning[W0105]: --plan exchange has no effect with --mode seq: only the sequential walk \
         runs (give --mode par or both)\n\n"
    );
    assert_eq!(
        warned(&["--mode", "par", "--alternate", "2"]),
        "warning[W0105]: --alternate 2 has no effect unless both modes run (--mode both): it sets \
         the scans of each one's turn\n\n"
    );
    let both = warned(&["--mode", "seq", "--plan", "deps", "--alternate", "3"]);
    assert_eq!(both.matches("W0105").count(), 2, "{both}");
    for used in [
        &["--mode", "both", "--plan", "exchange", "--alternate", "2"][..],
        &["--mode", "seq", "--plan", "par", "--explain"],
        &["--mode", "seq"],
    ] {
        // Used, so not W0105 (a forced plan may still say that the model expects it slower).
        let said = warned(used);
        assert!(!said.contains("W0105"), "{used:?}: {said}");
    }
}

/// `--plan par` and `--plan exchange` force the levelled plan on a program where the cost model
/// would run the sequential walk (packaging-line's levels of 3, 4 and 1 tasks save less than a
/// barrier), say so in a warning, and still end every scan identical to the sequential walk.
#[test]
fn a_forced_plan_runs_the_levelled_plan_and_says_the_model_expects_it_slower() {
    let prog = "analyses/packaging-line/program.json";
    let auto = run(&["run", prog, "--scans", "30", "--plan", "model", "--explain"]);
    let auto_text = String::from_utf8_lossy(&auto.stdout);
    assert!(
        auto_text.contains("every scan runs the sequential walk"),
        "{auto_text}"
    );
    for (kind, candidate) in [("par", "par"), ("exchange", "par-exchange")] {
        let out = run(&["run", prog, "--scans", "30", "--plan", kind, "--explain"]);
        assert!(out.status.success());
        let text = String::from_utf8_lossy(&out.stdout);
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(
            text.contains(&format!("plan kind: {kind} (1 candidate: {candidate})")),
            "{text}"
        );
        assert!(text.contains("forced (--plan "), "{text}");
        assert!(!text.contains("sequential fallback"), "{text}");
        assert!(
            text.contains("identical: yes, seq == par after every scan"),
            "{text}"
        );
        assert!(
            err.contains(&format!(
                "warning[W0102]: --plan {kind} forces the levelled plan although the cost model expects it to be slower ("
            )),
            "{err}"
        );
    }
}

#[test]
fn text_report_and_explain() {
    let wide = generated("wide.json", &["--rungs", "4000", "--width", "400"]);
    let out = run(&[
        "run",
        wide.to_str().unwrap(),
        "--scans",
        "50",
        "--threads",
        "2",
        "--explain",
    ]);
    assert!(out.status.success());
    let text = String::from_utf8(out.stdout).unwrap();
    for needle in [
        "parallel plan: 2 workers",
        "level   1:",
        "parallel (contiguous",
        "padding:",
        "outputs after scan 49:",
        "faults: none",
        "seq ",
        "par ",
        "identical: yes",
    ] {
        assert!(text.contains(needle), "{needle:?} in\n{text}");
    }
    assert!(out.stderr.is_empty(), "quiet when stderr is not a terminal");
}

#[test]
fn a_range_fault_element_records_index_range_when_powered_and_passes_the_power_on() {
    // go = TRUE, FALSE, TRUE: the fault in scans 0 and 2; x counts the powered scans (the
    // power goes on through the element).
    let program = write(
        "range_fault.json",
        r#"{"program": "rf",
        "vars": [{"name": "go", "type": "BOOL", "class": "input"}, {"name": "x", "type": "INT", "class": "output"}],
        "rungs": [{"id": "R", "ld": [{"contact": "go"}, {"range_fault": true}, {"op": "ADD", "in": ["x", 1], "out": "x"}]}]}"#,
    );
    let inputs = write("range_fault.csv", "go\n1\n0\n1\n");
    let j = faulted_json(
        &run(&["run", &program, "--inputs", &inputs, "--format", "json"]),
        "2 faults (first: index-range on rung R in scan 0;",
    );
    assert_eq!(
        j["faults"],
        serde_json::json!([
            {"scan": 0, "rung": "R", "kind": "index-range"},
            {"scan": 2, "rung": "R", "kind": "index-range"}
        ])
    );
    assert_eq!(j["state"]["x"], serde_json::json!(2));
    // `convert` writes it back as it was read.
    let out = run(&["convert", &program]);
    assert!(
        String::from_utf8_lossy(&out.stdout).contains(r#"{"range_fault":true}"#)
            || String::from_utf8_lossy(&out.stdout).contains(r#""range_fault": true"#),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
}

#[test]
fn faults_are_reported_with_scan_rung_and_kind() {
    let program = write(
        "faulty.json",
        r#"{"program": "faulty",
        "vars": [{"name": "d", "type": "INT", "class": "input"}, {"name": "x", "type": "INT", "class": "output"}, {"name": "i", "type": "INT"}],
        "rungs": [
          {"id": "DIV", "ld": [{"op": "DIV", "in": [10, "d"], "out": "x"}]},
          {"id": "L", "label": "back", "ld": [{"op": "ADD", "in": ["i", 1], "out": "i"}]},
          {"id": "J", "ld": [{"compare": "GT", "a": "i", "b": 0}, {"jmp": "back"}]}
        ]}"#,
    );
    let inputs = write("faulty.csv", "d\n0\n5\n0\n");
    let j = faulted_json(
        &run(&[
            "run",
            &program,
            "--inputs",
            &inputs,
            "--loop-cap",
            "50",
            "--format",
            "json",
        ]),
        "5 faults (first: div-by-zero on rung DIV in scan 0;",
    );
    let faults = j["faults"].as_array().unwrap();
    assert_eq!(
        faults[0],
        serde_json::json!({"scan": 0, "rung": "DIV", "kind": "div-by-zero"})
    );
    assert_eq!(
        faults[1],
        serde_json::json!({"scan": 0, "rung": "J", "kind": "loop-cap"})
    );
    assert_eq!(
        faults[2],
        serde_json::json!({"scan": 1, "rung": "J", "kind": "loop-cap"})
    );
    assert_eq!(faults.len(), 5);
    assert_eq!(j["fault_count"], 5);
    assert_eq!(j["identical"], true);
    assert_eq!(
        j["fault_summary"],
        serde_json::json!([
            {"rung": "DIV", "kind": "div-by-zero", "count": 2, "first_scan": 0, "last_scan": 2},
            {"rung": "J", "kind": "loop-cap", "count": 3, "first_scan": 0, "last_scan": 2}
        ])
    );
    let out = run(&["run", &program, "--inputs", &inputs, "--loop-cap", "50"]);
    assert_eq!(
        (out.status.code(), String::from_utf8_lossy(&out.stderr).as_ref()),
        (Some(1), "error: the run faulted: 5 faults (first: div-by-zero on rung DIV in scan 0; faults in the report)\n")
    );
    let text = String::from_utf8(out.stdout).unwrap();
    assert!(
        text.contains(
            "faults: 5 (2 distinct faults)\n  rung DIV: div-by-zero, 2 times, scans 0 to 2\n  rung J: loop-cap, 3 times, scans 0 to 2\n"
        ),
        "{text}"
    );
}

/// A DIV by zero in every scan and an endless backward jump (`L: … jmp L`, unconditional).
const ALWAYS_FAULTY: &str = r#"{"program": "always",
    "vars": [{"name": "d", "type": "INT", "class": "input"}, {"name": "x", "type": "INT", "class": "output"}, {"name": "i", "type": "DINT", "class": "output"}],
    "rungs": [
      {"id": "DIV", "ld": [{"op": "DIV", "in": [10, "d"], "out": "x"}]},
      {"id": "L", "label": "again", "ld": [{"op": "ADD", "in": ["i", 1], "out": "i"}, {"jmp": "again"}]}
    ]}"#;

#[test]
fn a_fault_of_every_scan_is_one_summary_line_and_an_endless_loop_ends_at_the_cap() {
    let program = write("always.json", ALWAYS_FAULTY);
    let out = run(&["run", &program, "--loop-cap", "10"]);
    assert_eq!(out.status.code(), Some(1), "a faulted run exits with 1");
    let text = String::from_utf8(out.stdout).unwrap();
    let faults: Vec<&str> = text
        .lines()
        .skip_while(|l| !l.starts_with("faults:"))
        .take_while(|l| !l.starts_with("speed:"))
        .collect();
    assert_eq!(
        faults,
        [
            "faults: 2000 (2 distinct faults)",
            "  rung DIV: div-by-zero, 1000 times, scans 0 to 999",
            "  rung L: loop-cap, 1000 times, scans 0 to 999",
        ],
        "{text}"
    );
    // The endless loop runs `--loop-cap` loop-backs (11 passes) per scan, then the scan ends.
    let j = faulted_json(
        &run(&[
            "run",
            &program,
            "--loop-cap",
            "10",
            "--scans",
            "3",
            "--format",
            "json",
        ]),
        "6 faults",
    );
    assert_eq!(j["outputs"]["i"], 33);
    assert_eq!(j["fault_count"], 6);
    assert_eq!(j["faults"].as_array().unwrap().len(), 6);
    assert_eq!(j["fault_summary"][1]["count"], 3);
    assert_eq!(j["identical"], true);
    let one = run(&["run", &program, "--loop-cap", "10", "--scans", "1"]);
    let text = String::from_utf8(one.stdout).unwrap();
    assert!(
        text.starts_with("program always: 1 scan, cycle 10 ms, "),
        "{text}"
    );
    assert!(
        text.contains("  rung L: loop-cap, once, in scan 0\n"),
        "{text}"
    );
    let one = run(&[
        "run",
        &program,
        "--scans",
        "1",
        "--threads",
        "1",
        "--mode",
        "seq",
    ]);
    let text = String::from_utf8(one.stdout).unwrap();
    assert!(
        text.starts_with("program always: 1 scan, cycle 10 ms, 1 thread\n"),
        "{text}"
    );
}

#[test]
fn trace_vars_without_trace_and_stdin_twice_are_usage_errors() {
    let program = write("echo-tv.json", ECHO);
    fails(
        &["run", &program, "--trace-vars", "a"],
        "--trace-vars chooses the columns of the trace file: give --trace FILE too",
    );
    let out = run_stdin(&["run", "-", "--inputs", "-"], ECHO.as_bytes());
    assert_eq!(
        error_line(&out, "stdin twice"),
        "error: the program and --inputs cannot both be read from standard input (-)"
    );
}

#[test]
fn an_inputs_file_without_rows_is_a_warning_and_the_run_goes_on() {
    let program = write("echo-empty.json", ECHO);
    for (name, text) in [
        ("empty.csv", ""),
        ("header-only.csv", "a,n\n"),
        ("empty.json", "[]"),
    ] {
        let inputs = write(name, text);
        let out = run(&["run", &program, "--inputs", &inputs, "--format", "json"]);
        assert_eq!(
            String::from_utf8(out.stderr.clone()).unwrap(),
            format!(
                "{{\"code\":\"W0103\",\"severity\":\"warning\",\"message\":\"--inputs {inputs} has no rows: every input keeps its initial value; \
                 running 1 scan (give --scans N for more)\",\"file\":null,\"line\":null,\"column\":null,\"span\":null,\"hint\":null,\"location\":null}}\n"
            )
        );
        assert_eq!(json_of(&out)["scans"], 1);
        let out = run(&["run", &program, "--inputs", &inputs, "--scans", "4"]);
        assert!(out.status.success());
        assert_eq!(
            String::from_utf8(out.stderr).unwrap(),
            format!(
                "warning[W0103]: --inputs {inputs} has no rows: every input keeps its initial value\n\n"
            )
        );
    }
}

#[test]
fn time_below_a_millisecond_is_refused_not_rounded() {
    let program = write("echo-time.json", ECHO);
    fails(
        &["run", &program, "--cycle", "0.5ms"],
        "--cycle 0.5ms: not a whole number of milliseconds (TIME counts milliseconds)",
    );
    fails(
        &["run", &program, "--cycle", "T#1.0005s"],
        "not a whole number of milliseconds",
    );
    assert!(
        run(&["run", &program, "--cycle", "1.5ms", "--scans", "1"])
            .status
            .code()
            == Some(2)
    );
    assert!(run(&["run", &program, "--cycle", "0.002s", "--scans", "1"])
        .status
        .success());
    let inputs = write("subms.csv", "t\nT#0.4ms\n");
    fails(
        &["run", &program, "--inputs", &inputs],
        &format!(
            "{inputs}:2:1: scan 0, column `t`: `T#0.4ms` is not a whole number of milliseconds"
        ),
    );
    let literal = write("subms.json", &ECHO.replace("T#30ms", "T#0.4ms"));
    let out = run(&["run", &literal]);
    assert!(error_line(&out, "literal").contains("`T#0.4ms`"));
}

#[test]
fn output_and_trace_paths_are_checked_before_the_first_scan() {
    let program = write("echo-paths.json", ECHO);
    let start = std::time::Instant::now();
    fails(
        &[
            "run",
            &program,
            "--scans",
            "1000000000",
            "-o",
            "no/such/dir/r.json",
        ],
        "cannot write -o no/such/dir/r.json: the folder no/such/dir does not exist",
    );
    fails(
        &[
            "run",
            &program,
            "--scans",
            "1000000000",
            "--trace",
            "no/such/t.csv",
        ],
        "cannot write --trace no/such/t.csv: the folder no/such does not exist",
    );
    let dir = tmp("paths-dir");
    std::fs::create_dir_all(&dir).unwrap();
    let d = dir.to_str().unwrap();
    fails(
        &["run", &program, "--scans", "1000000000", "--trace", d],
        &format!("cannot write --trace {d}: it is a folder, not a file"),
    );
    let same = tmp("same.csv");
    let same = same.to_str().unwrap();
    fails(
        &["run", &program, "--trace", same, "-o", same],
        "-o and --trace name the same file",
    );
    assert!(start.elapsed().as_secs() < 20, "no scan ran");
    assert!(temp_files_in(&dir).is_empty());
    // Only this test's names: other tests write temporary files into the same scratch folder
    // at the same time.
    let same_name = std::path::Path::new(same)
        .file_name()
        .unwrap()
        .to_string_lossy()
        .into_owned();
    assert!(files_in(dir.parent().unwrap(), |n| n.contains(".tmp-")
        && n.contains(&same_name))
    .is_empty());
}

/// Sends `signal` to a running `plc-deps run` with `--trace` and `-o` once it has started, and
/// checks that it exits with 130 leaving neither the files nor their temporary files.
fn stopped_by(signal: &str) {
    let program = write(&format!("echo-{signal}.json"), ECHO);
    let dir = tmp(&format!("signal-{signal}"));
    std::fs::create_dir_all(&dir).unwrap();
    let (trace, report) = (dir.join("t.csv"), dir.join("r.json"));
    let mut child = std::process::Command::new(env!("CARGO_BIN_EXE_plc-deps"))
        .args([
            "run",
            &program,
            "--scans",
            "100000000",
            "--trace",
            trace.to_str().unwrap(),
            "-o",
            report.to_str().unwrap(),
        ])
        .stderr(std::process::Stdio::piped())
        .spawn()
        .unwrap();
    // Wait until the trace's temporary file exists: the scans are running.
    let t0 = std::time::Instant::now();
    while temp_files_in(&dir).is_empty() {
        assert!(t0.elapsed().as_secs() < 30, "the run did not start");
        std::thread::sleep(std::time::Duration::from_millis(20));
    }
    let kill = std::process::Command::new("kill")
        .args([&format!("-{signal}"), &child.id().to_string()])
        .status()
        .unwrap();
    assert!(kill.success());
    let status = child.wait().unwrap();
    assert_eq!(status.code(), Some(130), "{signal}");
    assert!(
        temp_files_in(&dir).is_empty(),
        "{signal}: {:?}",
        temp_files_in(&dir)
    );
    assert!(!trace.exists() && !report.exists(), "{signal}");
}

#[test]
fn a_run_stopped_by_sigint_or_sigterm_leaves_no_file() {
    stopped_by("INT");
    stopped_by("TERM");
}

#[test]
fn bad_input_is_one_located_error_with_exit_code_2_and_no_output_file() {
    let program = write("echo3.json", ECHO);
    let trace = tmp("never.csv");
    let out_file = tmp("never.json");
    let t = trace.to_str().unwrap();
    let o = out_file.to_str().unwrap();
    let csv = |name: &str, text: &str| write(name, text);
    let unknown = csv("unknown.csv", "a,temp\n1,2\n");
    fails(
        &["run", &program, "--inputs", &unknown, "--trace", t, "-o", o],
        &format!("{unknown}:1:3: unknown input variable `temp`"),
    );
    let not_input = csv("notinput.csv", "a,q\n1,1\n");
    fails(
        &["run", &program, "--inputs", &not_input],
        &format!("{not_input}:1:3: `q` is not an input variable"),
    );
    let bad_value = csv("badvalue.csv", "a,n\n1,2\n0,70000\n");
    fails(
        &["run", &program, "--inputs", &bad_value, "--trace", t],
        &format!("{bad_value}:3:3: scan 1, column `n`: `70000` is not an INT"),
    );
    let bad_bool = csv("badbool.csv", "a\nyes\n");
    fails(
        &["run", &program, "--inputs", &bad_bool],
        &format!("{bad_bool}:2:1: scan 0, column `a`: `yes` is not a BOOL"),
    );
    let too_many = csv("toomany.csv", "a\n1,2\n");
    fails(
        &["run", &program, "--inputs", &too_many],
        &format!("{too_many}:2:3: 2 values in a row"),
    );
    let bad_json = csv("bad.json", "[{\"a\": true},\n {\"a\": tru}]");
    fails(
        &["run", &program, "--inputs", &bad_json, "-o", o],
        &format!("{bad_json}:2:"),
    );
    let json_key = csv("key.json", "[{\"a\": true},\n {\"nope\": 1}]");
    fails(
        &["run", &program, "--inputs", &json_key],
        &format!("{json_key}:2:"),
    );
    fails(
        &["run", &program, "--inputs", &json_key],
        "scan 1: unknown input variable `nope`",
    );
    let json_type = csv("type.json", "[{\"n\": true}]");
    fails(
        &["run", &program, "--inputs", &json_type],
        "scan 0, input `n`: true is not an INT",
    );
    let not_array = csv("obj.json", "{\"a\": true}");
    fails(
        &["run", &program, "--inputs", &not_array],
        "an array with one object of input values per scan",
    );
    fails(
        &["run", &program, "--threads", "0", "--trace", t],
        "--threads must be at least 1",
    );
    fails(
        &["run", &program, "--cycle", "10"],
        "--cycle 10: not a TIME",
    );
    fails(&["run", &program, "--cycle", "fast"], "not a TIME");
    fails(&["run", &program, "--cycle", "T#0ms"], "positive");
    fails(
        &["run", &program, "--scans", "0"],
        "--scans must be at least 1",
    );
    fails(
        &["run", &program, "--trace", t, "--trace-vars", "a,zz"],
        "unknown variable `zz`",
    );
    fails(
        &["run", &program, "--trace", t, "--trace-vars", "T1.CV"],
        "T1 has no field CV",
    );
    let broken = csv("broken.json", "{\"program\": \"x\", \"vars\": [");
    fails(&["run", &broken, "-o", o], &format!("{broken}:1:"));
    assert!(!trace.exists(), "no trace file after an error");
    assert!(!out_file.exists(), "no output file after an error");
    // Missing files are I/O errors naming the file's role (exit code 2), as for `report`.
    fails(
        &["run", &program, "--inputs", "no/such/inputs.csv"],
        "cannot read --inputs no/such/inputs.csv: No such file or directory",
    );
    fails(
        &["run", "no/such/program.json"],
        "cannot read the program no/such/program.json: No such file or directory",
    );
}

#[test]
fn output_file_is_written_whole() {
    let program = write("echo4.json", ECHO);
    let out_file = tmp("report.json");
    let out = run(&[
        "run",
        &program,
        "--scans",
        "5",
        "--format",
        "json",
        "-o",
        out_file.to_str().unwrap(),
    ]);
    assert!(out.status.success());
    assert!(out.stdout.is_empty());
    let j: Value = serde_json::from_str(&std::fs::read_to_string(&out_file).unwrap()).unwrap();
    assert_eq!(j["scans"], 5);
}

#[allow(dead_code)]
fn exists(p: &Path) -> bool {
    p.exists()
}
