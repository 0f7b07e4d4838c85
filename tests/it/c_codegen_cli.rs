//! `plc-deps c` as a user runs it: the Makefile builds, the program's last JSON line equals the
//! `state` of `plc-deps run --format json`; hostile program names stay inside DIR and compile;
//! `-o DIR` is all files or none, an existing folder with files is refused unless `--force`;
//! `make PARTFLAGS=…` reaches the part files of a large ladder POU and nothing else.

use crate::common;

use common::c::{assert_ok, run_with_input};
use common::cli::{error_line, files_in, root, run, tmp};
use std::process::Command;

fn make(dir: &std::path::Path) {
    let out = Command::new("make")
        .arg("-s")
        .current_dir(dir)
        .output()
        .unwrap();
    assert_ok(&out, "make");
}

fn run_program(dir: &std::path::Path, csv: &[u8]) -> String {
    let out = run_with_input(&dir.join("plc_program"), &[], csv);
    String::from_utf8(out.stdout).unwrap()
}

#[test]
fn the_makefile_builds_a_program_whose_state_is_the_runs_state() {
    let dir = tmp("c-conveyor");
    let _ = std::fs::remove_dir_all(&dir);
    let d = dir.to_str().unwrap();
    let prog = "analyses/conveyor/program.json";
    let out = run(&["c", prog, "-o", d, "--cycle", "1s"]);
    assert_ok(&out, "plc-deps c");
    make(&dir);
    let csv = std::fs::read(root().join("analyses/conveyor/inputs.csv")).unwrap();
    let lines = run_program(&dir, &csv);
    let last: serde_json::Value = serde_json::from_str(lines.lines().last().unwrap()).unwrap();
    let runs = run(&[
        "run",
        prog,
        "--inputs",
        "analyses/conveyor/inputs.csv",
        "--cycle",
        "1s",
        "--mode",
        "seq",
        "--format",
        "json",
    ]);
    let report: serde_json::Value = serde_json::from_slice(&runs.stdout).unwrap();
    assert_eq!(last, report["state"]);
    assert_eq!(
        lines.lines().count() as u64,
        report["scans"].as_u64().unwrap()
    );
}

#[test]
fn hostile_names_stay_inside_the_folder_and_compile() {
    // Variable names must be identifiers (the reader refuses others); these are the ones that
    // could still break C: keywords, macros, names of the generated code, encodings of each other.
    // The program name and rung ids are free text.
    let program = serde_json::json!({
        "program": "../../evil\"*/ #define x",
        "vars": [
            {"name": "int", "type": "BOOL", "class": "input"},
            {"name": "_plc_state", "type": "BOOL", "class": "input"},
            {"name": "a_046b", "type": "INT", "class": "output"},
            {"name": "_ua__046b", "type": "INT"},
            {"name": "self", "type": "BOOL"},
            {"name": "NULL", "type": "BOOL", "class": "output"},
            {"name": "_L1", "type": "BOOL"},
            {"name": "_p1", "type": "BOOL"},
            {"name": "INT16_MAX", "type": "INT"},
            {"name": "ctx", "type": "BOOL"}
        ],
        "rungs": [
            {"id": "*/#R1", "ld": [{"contact": "int"}, {"coil": "self"}]},
            {"id": "R\\2", "ld": [{"contact": "self"}, {"op": "ADD", "in": ["INT16_MAX", 1], "out": "a_046b"}]},
            {"id": "R3", "ld": [{"contact": "_plc_state"}, {"op": "ADD", "in": ["a_046b", 2], "out": "_ua__046b"}, {"coil": "NULL"}]},
            {"id": "R4", "ld": [{"contact": "NULL", "negated": true}, {"coil": "_L1"}, {"call": "main"}]},
            {"id": "R5", "ld": [{"contact": "ctx"}, {"coil": "_p1"}, {"call": "MAIN"}]}
        ],
        "subroutines": {"main": {"rungs": [{"id": "S1", "ld": [{"op": "ADD", "in": ["INT16_MAX", 3], "out": "INT16_MAX"}]}]},
                        "MAIN": {"rungs": [{"id": "S2", "ld": [{"contact": "int"}, {"ret": true}]}]}}
    });
    let file = tmp("hostile.json");
    std::fs::write(&file, program.to_string()).unwrap();
    let dir = tmp("c-hostile");
    let _ = std::fs::remove_dir_all(&dir);
    let out = run(&["c", file.to_str().unwrap(), "-o", dir.to_str().unwrap()]);
    assert_ok(&out, "plc-deps c");
    // Every file is directly inside DIR, with a plain name.
    for name in files_in(&dir, |_| true) {
        assert!(
            name.bytes()
                .all(|b| b.is_ascii_alphanumeric() || b"_.-".contains(&b)),
            "{name}"
        );
    }
    assert!(!tmp("evil").exists() && !dir.parent().unwrap().join("main.c").exists());
    make(&dir);
    let csv = b"int,_plc_state\ntrue,true\n0,1\n";
    let lines = run_program(&dir, csv);
    let inputs = tmp("hostile.csv");
    std::fs::write(&inputs, csv).unwrap();
    let runs = run(&[
        "run",
        file.to_str().unwrap(),
        "--inputs",
        inputs.to_str().unwrap(),
        "--mode",
        "seq",
        "--format",
        "json",
    ]);
    let report: serde_json::Value = serde_json::from_slice(&runs.stdout).unwrap();
    let last: serde_json::Value = serde_json::from_str(lines.lines().last().unwrap()).unwrap();
    assert_eq!(last, report["state"]);
    assert_eq!(last["a_046b"], 1);
    assert_eq!(last["self"], false);
    // Two POUs whose names differ only in case get two files.
    // (Besides the rows' kernels `plc_rows.c` and table files `plc_table*.c`.)
    let c_files = files_in(&dir, |n| {
        n.ends_with(".c") && n != "plc_rows.c" && !n.starts_with("plc_table")
    })
    .len();
    assert_eq!(c_files, 5, "main.c, plc_program.c and three POUs");
}

#[test]
fn the_folder_is_written_whole_and_an_existing_one_needs_force() {
    // In a folder of its own: the leftover check below looks at every file beside it, and the
    // other tests of this process write their folders (and temporary ones) concurrently.
    let dir = tmp("c-atomic-alone").join("c-atomic");
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    std::fs::write(dir.join("notes.txt"), "mine").unwrap();
    let d = dir.to_str().unwrap();
    let prog = "analyses/example-a/program.json";
    let line = error_line(&run(&["c", prog, "-o", d]), "existing folder");
    assert!(
        line.contains("exists and is not empty (give --force"),
        "{line}"
    );
    assert!(dir.join("notes.txt").exists());
    // A bad program writes nothing.
    let bad = tmp("bad.json");
    std::fs::write(
        &bad,
        r#"{"program": "p", "vars": [], "rungs": [{"id": "R1", "ld": [{"contact": "nope"}]}]}"#,
    )
    .unwrap();
    let fresh = tmp("c-none");
    let _ = std::fs::remove_dir_all(&fresh);
    error_line(
        &run(&["c", bad.to_str().unwrap(), "-o", fresh.to_str().unwrap()]),
        "bad",
    );
    assert!(!fresh.exists());
    // --force replaces the folder whole.
    let out = run(&["c", prog, "-o", d, "--force"]);
    assert!(out.status.success());
    assert!(!dir.join("notes.txt").exists());
    assert!(dir.join("main.c").exists() && dir.join("Makefile").exists());
    let parent = dir.parent().unwrap();
    let leftovers = files_in(parent, |n| n.contains(".tmp-") || n.contains(".old-"));
    assert!(leftovers.is_empty(), "{leftovers:?}");
}

/// `make PARTFLAGS=…` adds the flags to the part files of a large ladder POU and to nothing
/// else, and the program builds with `PARTFLAGS=-O1` under `-Werror`.
#[test]
fn partflags_reach_the_part_files_only() {
    let dir = tmp("c-partflags");
    let _ = std::fs::remove_dir_all(&dir);
    let json = tmp("c-partflags.json");
    let gen = run(&["gen", "--rungs", "300"]);
    assert_ok(&gen, "plc-deps gen");
    std::fs::write(&json, &gen.stdout).unwrap();
    // Every rung as statements (with rows, 300 rungs are a few runs: one function, no part).
    let out = run(&[
        "c",
        json.to_str().unwrap(),
        "-o",
        dir.to_str().unwrap(),
        "--statements",
    ]);
    assert_ok(&out, "plc-deps c");
    let dry = Command::new("make")
        .args(["-n", "PARTFLAGS=-O1"])
        .current_dir(&dir)
        .output()
        .unwrap();
    assert_ok(&dry, "make -n");
    let text = String::from_utf8(dry.stdout).unwrap();
    let compiles: Vec<&str> = text.lines().filter(|l| l.contains(" -c ")).collect();
    // 300 rungs: 5 functions of 64 rungs (the last 44), one part file.
    let parts: Vec<&str> = compiles
        .iter()
        .copied()
        .filter(|l| l.contains("_part"))
        .collect();
    assert_eq!(parts.len(), 1, "{text}");
    assert!(
        parts[0].ends_with("-O2 -O1 -c -o pou__g_e_n_part0.o pou__g_e_n_part0.c"),
        "{text}"
    );
    assert!(compiles.len() > parts.len(), "{text}");
    for l in compiles.iter().filter(|l| !l.contains("_part")) {
        assert!(!l.contains("-O1"), "{l}");
    }
    let build = Command::new("make")
        .args(["-s", "PARTFLAGS=-O1"])
        .current_dir(&dir)
        .output()
        .unwrap();
    assert_ok(&build, "make PARTFLAGS=-O1");
    assert!(dir.join("plc_program").is_file());
}
