//! The command line as a user meets it: bad programs give one located error and exit code 2
//! without touching the output file; good ones give reports, the schema, DOT that Graphviz
//! renders cleanly, and generated programs that load.
//!
//! `tests/errors/NAME.json` holds a bad program and `NAME.err` the exact error text
//! (`UPDATE_EXPECT=1` re-blesses).

mod common;

use common::cli::*;

use std::path::PathBuf;

#[test]
fn every_bad_program_gives_one_located_error_and_exit_code_2() {
    let mut cases: Vec<PathBuf> = std::fs::read_dir(root().join("tests/errors"))
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "json"))
        .collect();
    cases.sort();
    assert!(cases.len() >= 15);
    let mut failures = Vec::new();
    for case in cases {
        let rel = case
            .strip_prefix(root())
            .unwrap()
            .to_str()
            .unwrap()
            .to_owned();
        let out_file = tmp(&format!(
            "{}.txt",
            case.file_stem().unwrap().to_str().unwrap()
        ));
        let out = run(&["report", &rel, "-o", out_file.to_str().unwrap()]);
        let stderr = String::from_utf8(out.stderr).unwrap();
        assert_eq!(out.status.code(), Some(2), "{rel}: {stderr}");
        assert!(out.stdout.is_empty(), "{rel}: nothing on stdout");
        assert!(!out_file.exists(), "{rel}: no output file on error");
        assert_eq!(stderr.lines().count(), 1, "{rel}: one line: {stderr}");
        assert!(!stderr.contains("panicked"), "{rel}: {stderr}");
        let expected_path = case.with_extension("err");
        if std::env::var_os("UPDATE_EXPECT").is_some() {
            std::fs::write(&expected_path, &stderr).unwrap();
        } else if std::fs::read_to_string(&expected_path).unwrap_or_default() != stderr {
            failures.push(format!("{rel}: got {stderr}"));
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

#[test]
fn missing_file_is_an_io_error() {
    let out = run(&["report", "no/such/file.json"]);
    assert_eq!(out.status.code(), Some(1));
    let stderr = String::from_utf8(out.stderr).unwrap();
    assert!(stderr.starts_with("error: no/such/file.json: "), "{stderr}");
}

#[test]
fn report_writes_the_output_file_whole() {
    let out_file = tmp("example-b.json");
    let out = run(&[
        "report",
        "analyses/example-b/program.json",
        "--format",
        "json",
        "-o",
        out_file.to_str().unwrap(),
    ]);
    assert!(out.status.success());
    assert!(out.stdout.is_empty());
    let written = std::fs::read_to_string(&out_file).unwrap();
    assert_eq!(
        written,
        std::fs::read_to_string(root().join("analyses/example-b/report.json")).unwrap()
    );
}

#[test]
fn views_select_what_the_text_shows() {
    let paper = String::from_utf8(
        run(&[
            "report",
            "analyses/example-b/program.json",
            "--view",
            "paper",
        ])
        .stdout,
    )
    .unwrap();
    assert!(paper.contains("paper control view") && !paper.contains("combined (correct)"));
    let combined = String::from_utf8(
        run(&[
            "report",
            "analyses/example-b/program.json",
            "--view",
            "combined",
        ])
        .stdout,
    )
    .unwrap();
    assert!(!combined.contains("paper control view") && combined.contains("combined (correct)"));
}

#[test]
fn schema_is_json_and_describes_every_element_kind() {
    let out = run(&["schema"]);
    assert!(out.status.success());
    let schema: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let kinds: Vec<String> = schema["$defs"]["element"]["oneOf"]
        .as_array()
        .unwrap()
        .iter()
        .map(|v| v["required"][0].as_str().unwrap().to_owned())
        .collect();
    for k in [
        "contact", "compare", "or", "coil", "set", "reset", "branch", "ton", "tof", "tp", "ctu",
        "ctd", "move", "op", "jmp", "ret", "end", "call", "for", "next",
    ] {
        assert!(kinds.iter().any(|x| x == k), "schema lacks {k}");
    }
}

#[test]
fn dot_renders_with_graphviz_without_warnings() {
    for example in [
        "example-a",
        "example-b",
        "conveyor",
        "mixing-station",
        "packaging-line",
    ] {
        for view in ["combined", "paper"] {
            let program = format!("analyses/{example}/program.json");
            let out = run(&["report", &program, "--format", "dot", "--view", view]);
            assert!(out.status.success());
            graphviz(&out.stdout, &format!("{example} ({view})"));
        }
    }
}

/// The DOT report ranks by the levels the schedule has, puts subroutine rungs beside the
/// ranks, and draws every dependence between two rungs as one edge.
#[test]
fn dot_ranks_are_the_schedule_levels_and_edges_are_merged() {
    let out = run(&[
        "report",
        "analyses/example-b/program.json",
        "--format",
        "dot",
    ]);
    assert!(out.status.success());
    let dot = String::from_utf8(out.stdout).unwrap();
    // Example B's combined schedule has 3 levels; R11 and R12 run inside R10's task.
    assert!(dot.contains("{ rank=same; \"level 3\"; \"R3\"; \"R5\"; \"R6\"; \"R7\"; \"R8\"; }"));
    assert!(!dot.contains("level 4"), "{dot}");
    assert!(dot.contains("subgraph \"cluster_sub0\" { label=\"subroutine SBR_A (runs inside its caller's task)\"; style=dotted; \"R11\"; }"));
    // R2 → R5: flow and output on idx, one edge in both colours.
    let r2_r5: Vec<&str> = dot
        .lines()
        .filter(|l| l.starts_with("  \"R2\" -> \"R5\""))
        .collect();
    assert_eq!(
        r2_r5,
        ["  \"R2\" -> \"R5\" [label=\"flow idx\\noutput idx\", color=\"black:red\"];"]
    );
    let paper = run(&[
        "report",
        "analyses/example-b/program.json",
        "--format",
        "dot",
        "--view",
        "paper",
    ]);
    let paper = String::from_utf8(paper.stdout).unwrap();
    assert!(paper.contains("\"data level 3\""), "{paper}");
    assert_ne!(dot, paper);
    // One graph cannot show every levelling.
    let all = run(&[
        "report",
        "analyses/example-b/program.json",
        "--format",
        "dot",
        "--view",
        "all",
    ]);
    assert_eq!(all.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&all.stderr).contains("draws one levelling"));
}

#[test]
fn generated_programs_load_and_report() {
    let file = tmp("gen.json");
    let out = run(&[
        "gen",
        "--rungs",
        "300",
        "--width",
        "20",
        "--seed",
        "7",
        "--timers",
        "--loops",
        "--jumps",
        "--calls",
        "-o",
        file.to_str().unwrap(),
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let out = run(&["report", file.to_str().unwrap(), "--format", "json"]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let r: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(
        r["rungs"]
            .as_array()
            .unwrap()
            .iter()
            .filter(|x| !x["pou"].as_str().unwrap().starts_with("SBR"))
            .count(),
        300
    );
}
