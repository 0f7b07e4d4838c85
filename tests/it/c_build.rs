//! Generated C that builds everywhere: rungs whose power ends unread (branches without an
//! output, a contact after a box) leave no unused variable for `-Wall -Werror` to refuse, and
//! program names that C library headers define as macros (`P_tmpdir`, `WNOHANG`, `errno`,
//! `stdin`, …) build with the Makefile's flags, with `make CFLAGS=-O1` (which replaces them but
//! keeps the standard) and with the GNU dialect; every build runs as the interpreter does.

use crate::common;

use common::c::{run_interpreter, Batch};
use common::cli::{run, tmp};
use plc_deps::codegen::c::CConfig;
use std::path::Path;
use std::process::Command;

/// Rungs whose last power nobody reads: a trailing contact after each kind of box, branches
/// that end in contacts, a box's Q read only by a branch without an output, an OR after a box.
const UNREAD_POWER: &str = r#"{
  "program": "unread",
  "vars": [
    {"name": "A", "type": "BOOL", "class": "input"},
    {"name": "B", "type": "BOOL", "class": "input"},
    {"name": "N", "type": "INT", "class": "input"},
    {"name": "Y", "type": "BOOL", "class": "output"},
    {"name": "Z", "type": "INT", "class": "output"},
    {"name": "T1", "type": "TON"}, {"name": "T2", "type": "TP"},
    {"name": "C1", "type": "CTU"}, {"name": "C2", "type": "CTUD"},
    {"name": "S1", "type": "SR"}, {"name": "RT", "type": "R_TRIG"}
  ],
  "rungs": [
    {"id": "R1", "ld": [{"contact": "A"}, {"ton": "T1", "pt": "T#20ms"}, {"contact": "B"}]},
    {"id": "R2", "ld": [{"contact": "A"}, {"branch": [[{"contact": "B"}], [{"contact": "A"}, {"coil": "Y"}]]}]},
    {"id": "R3", "ld": [{"contact": "A"}, {"branch": [[{"contact": "B"}], [{"contact": "B", "negated": true}]]}]},
    {"id": "R4", "ld": [{"contact": "B"}, {"ctu": "C1", "pv": 3, "reset": "N_RESET"}, {"branch": [[{"contact": "A"}], [{"contact": "B"}]]}]},
    {"id": "R5", "ld": [{"contact": "A"}, {"branch": [[{"sr": "S1", "reset": "B"}], [{"r_trig": "RT"}, {"contact": "B"}]]}]},
    {"id": "R6", "ld": [{"contact": "A"}, {"op": "ADD", "in": ["N", 1], "out": "Z"}, {"contact": "B"}]},
    {"id": "R7", "ld": [{"contact": "B"}, {"tp": "T2", "pt": "T#30ms"}, {"or": [[{"contact": "A"}], [{"contact": "B"}]]}]},
    {"id": "R8", "ld": [{"contact": "A"}, {"ctud": "C2", "pv": 2, "cd": "B", "reset": "N_RESET", "load": "N_RESET"}, {"contact": "B"}, {"contact": "A"}]},
    {"id": "R9", "ld": [{"contact": "T1.Q"}, {"branch": [[{"contact": "C1.Q"}], [{"contact": "S1.Q1"}]]}]}
  ]
}"#;

fn unread_power() -> String {
    UNREAD_POWER.replace("N_RESET", "Y")
}

const UNREAD_CSV: &str = "A,B,N\n1,0,1\n1,1,2\n0,1,3\n1,1,4\n1,0,5\n0,0,6\n1,1,7\n1,1,8\n0,1,9\n";

#[test]
fn rungs_whose_power_ends_unread_compile_with_werror_and_run_as_the_interpreter() {
    // Rows (the default) and statements: one `cc -std=c11 -Wall -Wextra -Werror -O2` run.
    let mut batch = Batch::default();
    for rows in [true, false] {
        let cfg = CConfig {
            rows,
            ..CConfig::default()
        };
        batch.add(
            unread_power(),
            UNREAD_CSV.into(),
            12,
            cfg,
            format!("unread rows={rows}"),
        );
    }
    batch.check(1, "c-unread");
}

/// Variables named as macros or functions of the headers the generated C includes (with GNU
/// or POSIX feature macros), keywords and the generated functions' parameters.
const LIBC_NAMES: &[&str] = &[
    "P_tmpdir",
    "L_ctermid",
    "WNOHANG",
    "EOF",
    "stdin",
    "errno",
    "main",
    "printf",
    "NULL",
    "BUFSIZ",
    "INT_MAX",
    "M_PI",
    "CLOCKS_PER_SEC",
    "TIME_UTC",
    "va_arg",
    "int",
    "self",
    "ctx",
];

fn libc_program() -> String {
    let mut vars = vec![
        serde_json::json!({"name": "P_tmpdir", "type": "BOOL", "class": "input"}),
        serde_json::json!({"name": "L_ctermid", "type": "INT", "class": "input"}),
        serde_json::json!({"name": "WNOHANG", "type": "BOOL", "class": "input"}),
    ];
    for name in &LIBC_NAMES[3..] {
        let ty = if ["stdin", "main", "NULL", "va_arg", "self"].contains(name) {
            "BOOL"
        } else {
            "INT"
        };
        vars.push(serde_json::json!({"name": name, "type": ty, "class": "output"}));
    }
    serde_json::json!({
        "program": "libc",
        "vars": vars,
        "rungs": [
            {"id": "R1", "ld": [{"contact": "P_tmpdir"}, {"contact": "WNOHANG"}, {"coil": "stdin"}]},
            {"id": "R2", "ld": [{"op": "ADD", "in": ["L_ctermid", 1], "out": "EOF"}]},
            {"id": "R3", "ld": [{"op": "ADD", "in": ["EOF", "errno"], "out": "printf"}, {"coil": "main"}]},
            {"id": "R4", "ld": [{"contact": "main"}, {"op": "ADD", "in": ["errno", 1], "out": "errno"}]},
            {"id": "R5", "ld": [{"contact": "stdin"}, {"branch": [[{"coil": "NULL"}], [{"coil": "va_arg"}], [{"coil": "self"}]]}]},
            {"id": "R6", "ld": [{"op": "MUL", "in": ["printf", 2], "out": "BUFSIZ"}, {"op": "SUB", "in": ["BUFSIZ", 1], "out": "INT_MAX"}]},
            {"id": "R7", "ld": [{"op": "ADD", "in": ["INT_MAX", "M_PI"], "out": "CLOCKS_PER_SEC"}, {"op": "ADD", "in": ["EOF", 0], "out": "TIME_UTC"}]},
            {"id": "R8", "ld": [{"contact": "WNOHANG"}, {"op": "ADD", "in": ["int", 3], "out": "int"}, {"op": "SUB", "in": ["int", 1], "out": "ctx"}]}
        ]
    })
    .to_string()
}

const LIBC_CSV: &str = "P_tmpdir,L_ctermid,WNOHANG\n1,5,1\n0,7,1\n1,-3,0\n1,100,1\n";

fn make(dir: &Path, args: &[&str]) {
    let clean = Command::new("make")
        .args(["-s", "clean"])
        .current_dir(dir)
        .output()
        .unwrap();
    assert!(clean.status.success());
    let out = Command::new("make")
        .arg("-s")
        .args(args)
        .current_dir(dir)
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "make {args:?}: {}",
        String::from_utf8_lossy(&out.stderr)
    );
}

#[test]
fn names_that_libc_headers_define_build_with_any_cflags_and_run_as_the_interpreter() {
    let dir = tmp("c-libc-names");
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    let text = libc_program();
    let program = dir.join("program.json");
    std::fs::write(&program, &text).unwrap();
    let c = dir.join("c");
    let out = run(&["c", program.to_str().unwrap(), "-o", c.to_str().unwrap()]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let (want, _) = run_interpreter(&text, LIBC_CSV, 4, &CConfig::default());
    let first: serde_json::Value = serde_json::from_str(&want[0]).unwrap();
    assert_eq!(first["stdin"], true, "the inputs reach the program");
    for args in [
        &[][..],
        &["CFLAGS=-O1"],
        &["CSTD=-std=gnu11", "CFLAGS=-O1 -Wall -Werror"],
    ] {
        make(&c, args);
        let states = common::c::run_with_input(&c.join("plc_program"), &[], LIBC_CSV.as_bytes());
        let lines: Vec<String> = String::from_utf8(states.stdout)
            .unwrap()
            .lines()
            .map(String::from)
            .collect();
        assert_eq!(lines, want, "make {args:?}");
    }
}
