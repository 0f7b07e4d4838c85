//! The command line as a user meets it: bad programs give one located error and exit code 2
//! without touching the output file; good ones give reports, the schema, DOT that Graphviz
//! renders cleanly, and generated programs that load.
//!
//! `tests/errors/NAME.json` holds a bad program and `NAME.err` the exact error as the command
//! line renders it (rustc style, without colour: stderr is a pipe) (`UPDATE_EXPECT=1` re-blesses);
//! so do the STL reader's error cases, `tests/stl/NAME.stl` with `NAME.err` beside it.

use crate::common;

use common::cli::*;

use std::path::PathBuf;

#[test]
fn every_bad_program_gives_one_located_error_and_exit_code_2() {
    let files = |dir: &str, ext: &str| -> Vec<PathBuf> {
        std::fs::read_dir(root().join(dir))
            .unwrap()
            .map(|e| e.unwrap().path())
            .filter(|p| p.extension().is_some_and(|e| e == ext))
            .collect()
    };
    let mut cases = files("tests/errors", "json");
    assert!(cases.len() >= 15);
    // The STL reader's error cases: the files of tests/stl with an expected rendering beside them.
    let stl: Vec<PathBuf> = files("tests/stl", "err")
        .into_iter()
        .map(|e| e.with_extension("stl"))
        .collect();
    assert!(stl.len() >= 6 && stl.iter().all(|p| p.is_file()), "{stl:?}");
    cases.extend(stl);
    cases.sort();
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
        assert_eq!(
            one_line(&stderr).lines().count(),
            1,
            "{rel}: one error: {stderr}"
        );
        assert!(stderr.starts_with("error[E0"), "{rel}: {stderr}");
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
fn missing_file_is_an_io_error_with_exit_code_2() {
    let out = run(&["report", "no/such/file.json"]);
    assert_eq!(
        error_line(&out, "missing"),
        "error: cannot read the program no/such/file.json: No such file or directory"
    );
}

#[test]
fn bad_files_are_refused_before_parsing_with_the_file_and_the_byte_offset() {
    let dir = tmp("bad-files");
    std::fs::create_dir_all(&dir).unwrap();
    let file = |name: &str, bytes: &[u8]| {
        let p = dir.join(name);
        std::fs::write(&p, bytes).unwrap();
        p.to_str().unwrap().to_owned()
    };
    let latin1 = file("latin1.json", b"{\"program\": \"caf\xe9\"}");
    assert_eq!(
        error_line(&run(&["report", &latin1]), "latin-1"),
        format!(
            "error: cannot read the program {latin1}: not UTF-8 text (byte 0xe9 at offset 16 is not valid UTF-8)"
        )
    );
    let binary = file("binary.json", b"PK\x03\x04\x00\x00\xff");
    assert_eq!(
        error_line(&run(&["report", &binary]), "binary"),
        format!("error: cannot read the program {binary}: binary data, not text (a NUL byte at offset 4)")
    );
    let folder = dir.to_str().unwrap();
    assert_eq!(
        error_line(&run(&["report", folder]), "folder"),
        format!("error: cannot read the program {folder}: it is a folder, not a file")
    );
    // Over the 2 GiB limit: refused on its size (a sparse file, never read).
    let huge = dir.join("huge.json");
    std::fs::File::create(&huge)
        .unwrap()
        .set_len(3 << 30)
        .unwrap();
    let h = huge.to_str().unwrap();
    assert_eq!(
        error_line(&run(&["report", h]), "huge"),
        format!("error: cannot read the program {h}: the file is larger than the limit of 2 GiB (3221225472 bytes)")
    );
    std::fs::remove_file(&huge).unwrap();
    for cmd in ["report", "order", "run"] {
        let out = run(&[cmd, &binary]);
        assert!(error_line(&out, cmd).contains("a NUL byte at offset 4"));
    }
}

/// Files from 16 MiB on are mapped rather than read: the same checks and the same results. A
/// program padded with spaces to 17 MiB, with a byte-order mark, reports as the small one does;
/// a NUL or a byte that is not UTF-8 near its end is refused with its offset.
#[test]
fn a_large_file_is_mapped_with_the_same_checks_and_results() {
    let dir = tmp("mapped-files");
    std::fs::create_dir_all(&dir).unwrap();
    let small = "analyses/example-b/program.json";
    let program = std::fs::read(root().join(small)).unwrap();
    let size = 17 << 20;
    let padded = |bom: bool, tail: &[u8]| {
        let mut bytes = Vec::with_capacity(size + 3);
        if bom {
            bytes.extend_from_slice("\u{feff}".as_bytes());
        }
        bytes.extend_from_slice(&program);
        bytes.resize(size - tail.len(), b' ');
        bytes.extend_from_slice(tail);
        bytes
    };
    let file = |name: &str, bytes: Vec<u8>| {
        let p = dir.join(name);
        std::fs::write(&p, bytes).unwrap();
        p.to_str().unwrap().to_owned()
    };
    let expected = run(&["report", small, "--format", "json"]);
    assert!(expected.status.success());
    let big = file("big.json", padded(true, b""));
    let out = run(&["report", &big, "--format", "json"]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert_eq!(out.stdout, expected.stdout);
    let nul = file("nul.json", padded(false, b"\0 "));
    assert_eq!(
        error_line(&run(&["report", &nul]), "NUL"),
        format!(
            "error: cannot read the program {nul}: binary data, not text (a NUL byte at offset {})",
            size - 2
        )
    );
    let latin1 = file("latin1.json", padded(false, b"\xe9"));
    assert_eq!(
        error_line(&run(&["order", &latin1]), "latin-1"),
        format!(
            "error: cannot read the program {latin1}: not UTF-8 text (byte 0xe9 at offset {} is not valid UTF-8)",
            size - 1
        )
    );
    // A load error in the mapped text is placed by line and column as in a read one.
    let mut broken = padded(false, b"");
    broken.extend_from_slice(b"x");
    let broken = file("broken.json", broken);
    let out = run(&["report", &broken]);
    assert_eq!(out.status.code(), Some(2));
    assert!(
        String::from_utf8_lossy(&out.stderr).contains(&format!("{broken}:")),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn a_byte_order_mark_is_accepted_and_dash_reads_standard_input() {
    let program = std::fs::read(root().join("analyses/example-b/program.json")).unwrap();
    let expected = run(&["report", "analyses/example-b/program.json"]);
    assert!(expected.status.success());
    let mut with_bom = b"\xef\xbb\xbf".to_vec();
    with_bom.extend_from_slice(&program);
    let bom = tmp("bom.json");
    std::fs::write(&bom, &with_bom).unwrap();
    let from_bom = run(&["report", bom.to_str().unwrap()]);
    assert!(
        from_bom.status.success(),
        "{}",
        String::from_utf8_lossy(&from_bom.stderr)
    );
    assert_eq!(from_bom.stdout, expected.stdout);
    let from_stdin = run_stdin(&["report", "-"], &with_bom);
    assert!(from_stdin.status.success());
    assert_eq!(from_stdin.stdout, expected.stdout);
    let order = run(&["order", "analyses/example-b/program.json"]);
    assert_eq!(run_stdin(&["order", "-"], &program).stdout, order.stdout);
    let out = run_stdin(&["run", "-", "--scans", "3", "--format", "json"], &program);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    // Errors about standard input name it `<stdin>`.
    let out = run_stdin(&["report", "-"], b"{\"program\": ");
    assert!(error_line(&out, "stdin").starts_with("error: <stdin>:1:"));
    let out = run_stdin(&["report", "-"], b"\xff");
    assert_eq!(
        error_line(&out, "stdin"),
        "error: cannot read the program <stdin>: not UTF-8 text (byte 0xff at offset 0 is not valid UTF-8)"
    );
}

#[test]
fn an_output_folder_that_does_not_exist_is_an_error_naming_it() {
    let out = run(&[
        "report",
        "analyses/example-b/program.json",
        "-o",
        "no/such/dir/r.txt",
    ]);
    assert_eq!(
        error_line(&out, "-o"),
        "error: cannot write -o no/such/dir/r.txt: the folder no/such/dir does not exist"
    );
    let folder = tmp("out-folder");
    std::fs::create_dir_all(&folder).unwrap();
    let f = folder.to_str().unwrap();
    let out = run(&["schema", "-o", f]);
    assert!(error_line(&out, "folder").starts_with(&format!("error: cannot write -o {f}: ")));
    assert!(temp_files_in(&folder).is_empty());
    assert!(temp_files_in(folder.parent().unwrap()).is_empty());
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
    // Example B's combined schedule has 4 levels (R4 after the loop, which the iteration cap can
    // leave at R8); R11 and R12 run inside R10's task, at no level.
    assert!(dot.contains("{ rank=same; \"level 3\"; \"R3\"; \"R5\"; \"R6\"; \"R7\"; \"R8\"; }"));
    assert!(dot.contains("{ rank=same; \"level 4\"; \"R4\"; }"));
    assert!(!dot.contains("level 5"), "{dot}");
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

/// A program too big for Graphviz is refused before anything is written.
#[test]
fn dot_of_a_big_program_is_refused_with_a_message() {
    let file = tmp("big-dot.json");
    let path = file.to_str().unwrap();
    let out = run(&["gen", "--rungs", "2500", "-o", path]);
    assert!(out.status.success());
    let dot = tmp("big.dot");
    let out = run(&[
        "report",
        path,
        "--format",
        "dot",
        "-o",
        dot.to_str().unwrap(),
    ]);
    assert_eq!(out.status.code(), Some(2));
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(
        stderr.contains("2,500 rungs are too many to draw (2,000 at most)"),
        "{stderr}"
    );
    assert!(!dot.exists(), "no DOT file is written");
}

/// A big program is drawn a part at a time: a rung range or a POU, with the far ends of the
/// edges that leave the part drawn grey, levels numbered as in the whole schedule.
#[test]
fn dot_draws_a_selection_of_a_big_program() {
    let file = tmp("big-dot-selection.json");
    let path = file.to_str().unwrap();
    let out = run(&["gen", "--rungs", "2500", "--width", "40", "-o", path]);
    assert!(out.status.success());
    let out = run(&["report", path, "--format", "dot", "--rungs", "R100..R140"]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    graphviz(&out.stdout, "R100..R140 of 2,500 rungs");
    let dot = String::from_utf8(out.stdout).unwrap();
    assert!(dot.contains("label=\"41 of 2,500 rungs drawn;"), "{dot}");
    let drawn: Vec<&str> = dot
        .lines()
        .filter(|l| l.contains(" [label=\"R"))
        .map(|l| l.trim().split(' ').next().unwrap().trim_matches('"'))
        .collect();
    let expected: Vec<String> = (100..=140).map(|i| format!("R{i}")).collect();
    assert_eq!(drawn, expected);
    // Every edge has a drawn end; every other end is a grey node.
    for l in dot.lines().filter(|l| l.contains(" -> \"R")) {
        let ends: Vec<&str> = l.trim().split(" [").next().unwrap().split(" -> ").collect();
        let inside = |x: &str| expected.iter().any(|e| format!("\"{e}\"") == x);
        assert!(ends.iter().any(|x| inside(x)), "{l}");
        for x in ends.iter().filter(|x| !inside(x)) {
            assert!(
                dot.contains(&format!("  {x} [style=\"rounded,dashed\", color=grey")),
                "{x} of {l}"
            );
        }
    }
    // Example B's subroutine: its one rung, and its caller in grey.
    let out = run(&[
        "report",
        "analyses/example-b/program.json",
        "--format",
        "dot",
        "--pou",
        "SBR_A",
    ]);
    assert!(out.status.success());
    let dot = String::from_utf8(out.stdout).unwrap();
    assert!(
        dot.contains("  \"R11\" [label=\"R11\\n(SBR_A)\"];"),
        "{dot}"
    );
    assert!(dot.contains("  \"R10\" [style=\"rounded,dashed\", color=grey, fontcolor=grey];"));
    assert!(
        !dot.contains("rank=same"),
        "R11 runs inside R10's task, at no level: {dot}"
    );
}

/// A selection that names nothing, runs backwards, is too big, or is given to a report that
/// is not DOT is a usage error, exit code 2, no output file.
#[test]
fn dot_selection_errors_are_clear() {
    let file = tmp("big-dot-selection-errors.json");
    let path = file.to_str().unwrap();
    assert!(run(&["gen", "--rungs", "2500", "-o", path])
        .status
        .success());
    let b = "analyses/example-b/program.json";
    let big = format!("error: {path}: the selection has 2,400 rungs, too many to draw (2,000 at most); choose a shorter --rungs range");
    let cases: [(&[&str], &str); 6] = [
        (&["report", b, "--format", "dot", "--pou", "X"], "error: analyses/example-b/program.json: --pou: no POU `X` in the program (POUs: example_b, SBR_A, SBR_B)"),
        (&["report", b, "--format", "dot", "--rungs", "R5..R2"], "error: analyses/example-b/program.json: --rungs R5..R2: `R2` comes before `R5` in the program"),
        (&["report", b, "--format", "dot", "--rungs", "R5..R99"], "error: analyses/example-b/program.json: --rungs: no rung `R99` in the program"),
        (&["report", b, "--rungs", "R5"], "error: --rungs chooses what the DOT report draws; add --format dot (the text and JSON reports cover the whole program)"),
        (&["report", b, "--pou", "SBR_X"], "error: --pou SBR_X: the program has no configuration, so --pou selects one of its subroutines, and no subroutine has that name; it has SBR_A, SBR_B"),
        (&["report", path, "--format", "dot", "--rungs", "R1..R2400"], &big),
    ];
    for (args, expected) in cases {
        let mut args = args.to_vec();
        let out_file = tmp("selection-error.dot");
        let o = out_file.to_str().unwrap().to_owned();
        args.extend(["-o", &o]);
        let out = run(&args);
        assert_eq!(error_line(&out, expected), expected);
        assert!(!out_file.exists());
    }
}

/// On a program without a configuration, `--pou` of the text, JSON and HTML reports (and of
/// `run`) selects a subroutine: the report of that routine alone, with what it calls, from the
/// JSON program and from its STL alike (any case).
#[test]
fn pou_on_a_program_without_configuration_reports_that_subroutine() {
    for file in [
        "analyses/example-b/program.json",
        "analyses/example-b/program.stl",
    ] {
        let out = run(&["report", file, "--pou", "sbr_a", "--format", "json"]);
        assert_eq!(out.status.code(), Some(0), "{file}");
        let r: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
        assert_eq!(r["program"], "SBR_A", "{file}");
        let rungs: Vec<String> = r["rungs"]
            .as_array()
            .unwrap()
            .iter()
            .map(|r| {
                format!(
                    "{} {}",
                    r["id"].as_str().unwrap(),
                    r["pou"].as_str().unwrap()
                )
            })
            .collect();
        assert_eq!(rungs, ["R11 SBR_A"], "{file}");
    }
    // A routine that calls another keeps it: the conveyor's main program calls ALARM, so
    // selecting ALARM gives its two rungs, and nothing of the main program.
    let out = run(&["report", "analyses/conveyor/program.json", "--pou", "ALARM"]);
    let text = String::from_utf8(out.stdout).unwrap();
    assert!(text.starts_with("ALARM: 2 rungs\n"), "{text}");
    let out = run(&[
        "run",
        "analyses/conveyor/program.json",
        "--pou",
        "ALARM",
        "--scans",
        "1",
    ]);
    assert_eq!(out.status.code(), Some(0));
    assert!(String::from_utf8(out.stdout)
        .unwrap()
        .starts_with("program ALARM: 1 scan"));
}
