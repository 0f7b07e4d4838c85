//! One table of inputs CSV files, good and bad, each read by `plc-deps run --inputs` and by the
//! harness of the C that `plc-deps c` writes (built once with its Makefile): the same files are
//! accepted with the same states after every scan, and the others refused with the same one
//! error line (the same message at the same line and column). docs/scan.md, *Inputs*, defines
//! the files; and a JSON `--inputs` error names its true line and column.

use crate::common;

use common::c::run_interpreter;
use common::cli::{run, tmp};
use plc_deps::codegen::c::CConfig;
use std::path::Path;
use std::process::{Command, Stdio};

/// Every input type, an output and a memory variable, all of them used.
const PROGRAM: &str = r#"{
  "program": "cells",
  "vars": [
    {"name": "A", "type": "BOOL", "class": "input"},
    {"name": "SI", "type": "SINT", "class": "input"},
    {"name": "N", "type": "INT", "class": "input"},
    {"name": "D", "type": "DINT", "class": "input"},
    {"name": "L", "type": "LINT", "class": "input"},
    {"name": "US", "type": "USINT", "class": "input"},
    {"name": "UI", "type": "UINT", "class": "input"},
    {"name": "UD", "type": "UDINT", "class": "input"},
    {"name": "UL", "type": "ULINT", "class": "input"},
    {"name": "B", "type": "BYTE", "class": "input"},
    {"name": "W", "type": "WORD", "class": "input"},
    {"name": "DW", "type": "DWORD", "class": "input"},
    {"name": "LW", "type": "LWORD", "class": "input"},
    {"name": "R", "type": "REAL", "class": "input"},
    {"name": "LR", "type": "LREAL", "class": "input"},
    {"name": "T", "type": "TIME", "class": "input"},
    {"name": "Y", "type": "BOOL", "class": "output"},
    {"name": "M", "type": "BOOL"}
  ],
  "rungs": [
    {"id": "R1", "ld": [{"contact": "A"}, {"coil": "Y"}]},
    {"id": "R2", "ld": [{"contact": "Y"}, {"coil": "M"}]}
  ]
}"#;

/// What a file gives: accepted, with these scans and these values (JSON text) after the last
/// scan; or refused with this error line of the C harness (`plc-deps run` says the same of its
/// file).
enum Want {
    Accepted(u64, &'static [(&'static str, &'static str)]),
    Refused(&'static str),
}
use Want::{Accepted, Refused};

const INPUTS: &str = "A, SI, N, D, L, US, UI, UD, UL, B, W, DW, LW, R, LR, T";

fn cases() -> Vec<(&'static str, &'static [u8], Want)> {
    vec![
        // Files, lines and records.
        ("empty file", b"", Accepted(1, &[("A", "false")])),
        ("header only", b"A,N\n", Accepted(1, &[("N", "0")])),
        ("byte-order mark", b"\xef\xbb\xbfA,N\n1,5\n", Accepted(1, &[("A", "true"), ("N", "5")])),
        ("bom then bad", b"\xef\xbb\xbfA,Q\n", Refused("1:3: unknown input variable `Q` (inputs: INPUTS)")),
        ("crlf", b"A,N\r\n1,5\r\n0,6\r\n", Accepted(2, &[("A", "false"), ("N", "6")])),
        ("crlf error line", b"A\r\n1\r\nx\r\n", Refused("3:1: scan 1, column `A`: `x` is not a BOOL (true, false, 1 or 0)")),
        ("lone cr", b"A\r1\r0", Accepted(2, &[("A", "false")])),
        ("lone cr error line", b"A\r1\rx", Refused("3:1: scan 1, column `A`: `x` is not a BOOL (true, false, 1 or 0)")),
        ("empty and blank lines", b"\n\nA,N\n\n  \t\n1,2\n\n", Accepted(1, &[("A", "true"), ("N", "2")])),
        ("blank lines keep line numbers", b"A\n1\n\n \n0\nx\n", Refused("6:1: scan 2, column `A`: `x` is not a BOOL (true, false, 1 or 0)")),
        ("no final line end", b"A,N\n1,9", Accepted(1, &[("N", "9")])),
        // Quoting (RFC 4180).
        ("quoted cells", b"\"A\",\"N\"\n\"1\",\" 5 \"\n", Accepted(1, &[("A", "true"), ("N", "5")])),
        ("spaces after a closing quote", b"A,N\n1,\"5\"  \n", Accepted(1, &[("N", "5")])),
        ("quoted comma", b"N,R\n\"7\",\"1,5\"\n", Refused("2:5: scan 0, column `R`: `1,5` is not a valid REAL")),
        ("doubled quote", b"A,R\n1,\"2\"\"\"\n", Refused("2:3: scan 0, column `R`: `2\"` is not a valid REAL")),
        ("quoted line end", b"A,N\n1,\"x\ny\"\n1,zz\n", Refused("2:3: scan 0, column `N`: `x\ny` is not an INT (-32768..32767)")),
        ("line after a quoted line end", b"A,N\n\"1\",\"\n\"\n", Refused("2:5: scan 0, column `N`: `\n` is not an INT (-32768..32767)")),
        ("open quote", b"A,N\n1,\"5\n0,1\n", Refused("2:3: a quoted cell is not closed")),
        ("text after a closing quote", b"A,N\n1,\"5\"x\n", Refused("2:6: text after the closing quote of a cell")),
        ("quote inside a cell", b"A,N\n1,5\"\n", Refused("2:4: a quote inside a cell that does not start with one (quote the whole cell and double the quote)")),
        ("space before a quote", b"A,N\n1, \"5\"\n", Refused("2:4: a quote inside a cell that does not start with one (quote the whole cell and double the quote)")),
        // The header.
        ("duplicate column", b"A,N,A\n", Refused("1:5: input `A` has two columns")),
        ("unknown column", b"A,Nope\n", Refused("1:3: unknown input variable `Nope` (inputs: INPUTS)")),
        ("case matters", b"a\n", Refused("1:1: unknown input variable `a` (inputs: INPUTS)")),
        ("an output's column", b"A,Y\n", Refused("1:3: `Y` is not an input variable (it is an output)")),
        ("a memory's column", b"M\n", Refused("1:1: `M` is not an input variable (it is a memory variable)")),
        ("empty column name", b"A,,N\n", Refused("1:3: empty column name in the header")),
        ("whitespace around names and cells", b"  A ,\tN \n  1\t,  7  \n", Accepted(1, &[("A", "true"), ("N", "7")])),
        // Rows.
        ("extra cell", b"A,N\n1,2,3\n", Refused("2:5: 3 values in a row, the header has 2 columns")),
        ("extra empty cell", b"A\n1,\n", Refused("2:3: 2 values in a row, the header has 1 column")),
        ("missing cells keep values", b"A,N\n1,4\n\n0\n,7\n", Accepted(3, &[("A", "false"), ("N", "7")])),
        ("empty row is a scan", b"A,N\n1,4\n,\n", Accepted(2, &[("A", "true"), ("N", "4")])),
        ("column of a cell with leading spaces", b"A,N\n1,  x\n", Refused("2:3: scan 0, column `N`: `x` is not an INT (-32768..32767)")),
        // BOOL.
        ("bool forms", b"A\nTRUE\nFalse\n1\n 0 \n\"true\"\n", Accepted(5, &[("A", "true")])),
        ("bool yes", b"A\nyes\n", Refused("2:1: scan 0, column `A`: `yes` is not a BOOL (true, false, 1 or 0)")),
        ("bool 2", b"A\n2\n", Refused("2:1: scan 0, column `A`: `2` is not a BOOL (true, false, 1 or 0)")),
        // Integers and bit strings.
        ("based literals", b"W,B,D,DW\n16#FFFF,2#1010_1010,8#17,16#dead_BEEF\n", Accepted(1, &[("W", "65535"), ("B", "170"), ("D", "15"), ("DW", "3735928559")])),
        ("plus sign and underscores", b"N,D\n+1_000,-2_147_483_648\n", Accepted(1, &[("N", "1000"), ("D", "-2147483648")])),
        ("64-bit extremes", b"UL,L,LW\n18446744073709551615,-9223372036854775808,16#FFFF_FFFF_FFFF_FFFF\n", Accepted(1, &[("UL", "18446744073709551615"), ("L", "-9223372036854775808"), ("LW", "18446744073709551615")])),
        ("ULINT overflow", b"UL\n18446744073709551616\n", Refused("2:1: scan 0, column `UL`: `18446744073709551616` is not a ULINT (0..18446744073709551615)")),
        ("INT overflow", b"N\n32768\n", Refused("2:1: scan 0, column `N`: `32768` is not an INT (-32768..32767)")),
        ("SINT underflow", b"SI\n-129\n", Refused("2:1: scan 0, column `SI`: `-129` is not a SINT (-128..127)")),
        ("USINT negative", b"US\n-1\n", Refused("2:1: scan 0, column `US`: `-1` is not a USINT (0..255)")),
        ("UINT and UDINT", b"UI,UD\n65535,4294967295\n", Accepted(1, &[("UI", "65535"), ("UD", "4294967295")])),
        ("LWORD negative", b"LW\n-1\n", Refused("2:1: scan 0, column `LW`: `-1` is not an LWORD (0..18446744073709551615)")),
        ("negative hex", b"N\n-16#F\n", Refused("2:1: scan 0, column `N`: `-16#F` is not an INT (-32768..32767)")),
        ("hex digit beyond base", b"B\n8#8\n", Refused("2:1: scan 0, column `B`: `8#8` is not a BYTE (0..255)")),
        ("double underscore", b"N\n1__0\n", Refused("2:1: scan 0, column `N`: `1__0` is not an INT (-32768..32767)")),
        ("C hex", b"N\n0x10\n", Refused("2:1: scan 0, column `N`: `0x10` is not an INT (-32768..32767)")),
        ("huge integer", b"L\n99999999999999999999999999999999999999999\n", Refused("2:1: scan 0, column `L`: `99999999999999999999999999999999999999999` is not an LINT (-9223372036854775808..9223372036854775807)")),
        // REAL and LREAL.
        ("real forms", b"R,LR\n1.5e3,-.25\n", Accepted(1, &[("R", "1500.0"), ("LR", "-0.25")])),
        ("real point and exponent forms", b"R,LR\n1.,2E-3\n+7,1.e2\n", Accepted(2, &[("R", "7.0"), ("LR", "100.0")])),
        ("real rounding", b"R,LR\n0.1,0.1\n", Accepted(1, &[("R", "0.1"), ("LR", "0.1")])),
        ("real overflow and underflow", b"R,LR\n3.5e38,1e-400\n", Accepted(1, &[("R", "null"), ("LR", "0.0")])),
        ("real infinity", b"R,LR\n-Infinity,nan\n", Accepted(1, &[("R", "null"), ("LR", "null")])),
        ("hex REAL", b"R\n0x1p3\n", Refused("2:1: scan 0, column `R`: `0x1p3` is not a valid REAL")),
        ("hex LREAL", b"LR\n0x1.8p1\n", Refused("2:1: scan 0, column `LR`: `0x1.8p1` is not a valid LREAL")),
        ("exponent without digits", b"R\n1e\n", Refused("2:1: scan 0, column `R`: `1e` is not a valid REAL")),
        ("real with underscore", b"R\n1_0.5\n", Refused("2:1: scan 0, column `R`: `1_0.5` is not a valid REAL")),
        ("real with a suffix", b"R\n1.5f\n", Refused("2:1: scan 0, column `R`: `1.5f` is not a valid REAL")),
        ("real point alone", b"R\n.\n", Refused("2:1: scan 0, column `R`: `.` is not a valid REAL")),
        // TIME.
        ("time forms", b"T\nT#1.5s\n250\nTIME#1m30s\nt#1h\n+7\n", Accepted(5, &[("T", "7")])),
        ("time literal", b"T\nT#1d2h3m4s5ms\n", Accepted(1, &[("T", "93784005")])),
        ("time extremes", b"T\nT#-24d20h31m23s648ms\n2147483647\n", Accepted(2, &[("T", "2147483647")])),
        ("time in microseconds", b"T\nT#1us\n", Refused("2:1: scan 0, column `T`: `T#1us` is not a TIME")),
        ("time unit without T#", b"T\n1s\n", Refused("2:1: scan 0, column `T`: `1s` is not a TIME (milliseconds or a literal like T#1s)")),
        ("time based integer", b"T\n16#10\n", Refused("2:1: scan 0, column `T`: `16#10` is not a TIME")),
        ("time fraction of a ms", b"T\nT#0.5ms\n", Refused("2:1: scan 0, column `T`: `T#0.5ms` is not a whole number of milliseconds (TIME counts milliseconds)")),
        ("time too precise", b"T\nT#0.0000000000001s\n", Refused("2:1: scan 0, column `T`: `T#0.0000000000001s` is not a whole number of milliseconds (TIME counts milliseconds)")),
        ("time out of range", b"T\nT#24d20h31m23s648ms\n", Refused("2:1: scan 0, column `T`: `T#24d20h31m23s648ms` is out of the range of TIME (32-bit ms)")),
        ("time ms out of range", b"T\n-2147483649\n", Refused("2:1: scan 0, column `T`: `-2147483649` is out of the range of TIME (32-bit ms)")),
        ("time huge", b"T\nT#99999999999999999999999999999999999999999d\n", Refused("2:1: scan 0, column `T`: `T#99999999999999999999999999999999999999999d` is out of the range of TIME (32-bit ms)")),
        ("time just past the end, not whole", b"T\nT#2147483647.5ms\n", Refused("2:1: scan 0, column `T`: `T#2147483647.5ms` is out of the range of TIME (32-bit ms)")),
        ("time two points", b"T\nT#1.2.3s\n", Refused("2:1: scan 0, column `T`: `T#1.2.3s` is not a TIME")),
        ("time prefix case", b"T\nTime#1s\n", Refused("2:1: scan 0, column `T`: `Time#1s` is not a TIME")),
        // Text.
        ("not UTF-8", b"A\n\xff\n", Refused("cannot read <stdin>: not UTF-8 text (byte 0xff at offset 2 is not valid UTF-8)")),
        ("overlong UTF-8", b"A\n\xc0\x80\n", Refused("cannot read <stdin>: not UTF-8 text (byte 0xc0 at offset 2 is not valid UTF-8)")),
        ("NUL byte", b"A\n1\n\0\n", Refused("cannot read <stdin>: binary data, not text (a NUL byte at offset 4)")),
    ]
}

/// The C harness's exit code, state lines and standard error for `csv` on its standard input.
fn run_harness(exe: &Path, csv: &[u8]) -> (Option<i32>, Vec<String>, String) {
    use std::io::Write;
    let mut child = Command::new(exe)
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let mut stdin = child.stdin.take().unwrap();
    let input = csv.to_vec();
    let writer = std::thread::spawn(move || {
        let _ = stdin.write_all(&input);
    });
    let out = child.wait_with_output().unwrap();
    writer.join().unwrap();
    let lines = String::from_utf8_lossy(&out.stdout)
        .lines()
        .map(String::from)
        .collect();
    (
        out.status.code(),
        lines,
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}

#[test]
fn run_and_the_c_harness_accept_and_refuse_the_same_csv_files_alike() {
    let dir = tmp("csv-cells");
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    let program = dir.join("program.json");
    std::fs::write(&program, PROGRAM).unwrap();
    let c = dir.join("c");
    let out = run(&["c", program.to_str().unwrap(), "-o", c.to_str().unwrap()]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let make = Command::new("make")
        .arg("-s")
        .current_dir(&c)
        .output()
        .unwrap();
    assert!(
        make.status.success(),
        "make: {}",
        String::from_utf8_lossy(&make.stderr)
    );
    let exe = c.join("plc_program");
    let mut failures = Vec::new();
    for (k, (name, csv, want)) in cases().into_iter().enumerate() {
        let file = dir.join(format!("case{k}.csv"));
        std::fs::write(&file, csv).unwrap();
        let path = file.to_str().unwrap();
        let runs = run(&[
            "run",
            program.to_str().unwrap(),
            "--inputs",
            path,
            "--format",
            "json",
            "--mode",
            "seq",
        ]);
        let (code, lines, stderr) = run_harness(&exe, csv);
        match want {
            Accepted(scans, values) => {
                assert!(
                    runs.status.success(),
                    "{name}: run: {}",
                    String::from_utf8_lossy(&runs.stderr)
                );
                assert_eq!(code, Some(0), "{name}: C: {stderr}");
                let report: serde_json::Value = serde_json::from_slice(&runs.stdout).unwrap();
                assert_eq!(report["scans"], scans, "{name}: run's scans");
                assert_eq!(lines.len() as u64, scans, "{name}: C's scans");
                // Every scan's state: the C's lines are the interpreter's, fed by `run`'s parser.
                let text = std::str::from_utf8(csv).unwrap();
                let (states, _) = run_interpreter(PROGRAM, text, scans, &CConfig::default());
                assert_eq!(lines, states, "{name}: the states after every scan");
                let last: serde_json::Value = serde_json::from_str(lines.last().unwrap()).unwrap();
                assert_eq!(last, report["state"], "{name}: run's state");
                for (var, value) in values {
                    assert_eq!(last[var].to_string(), *value, "{name}: {var}");
                }
            }
            Refused(message) => {
                let message = message.replace("INPUTS", INPUTS);
                let want = if message.starts_with("cannot read") {
                    format!("error: {message}")
                } else {
                    format!("error: <stdin>:{message}")
                };
                assert_eq!(code, Some(2), "{name}: C's exit code ({stderr})");
                assert!(lines.is_empty(), "{name}: C printed no state");
                if stderr.trim_end() != want {
                    failures.push(format!(
                        "{name}: C\n  got  {:?}\n  want {want:?}",
                        stderr.trim_end()
                    ));
                }
                // `--format json`: the error is a JSON diagnostic; its message.
                let diagnostic: serde_json::Value = serde_json::from_slice(&runs.stderr)
                    .unwrap_or_else(|_| {
                        panic!("{name}: {}", String::from_utf8_lossy(&runs.stderr))
                    });
                let rust = format!("error: {}", diagnostic["message"].as_str().unwrap())
                    .replace(&format!("--inputs {path}"), "<stdin>")
                    .replace(path, "<stdin>");
                assert_eq!(
                    runs.status.code(),
                    Some(2),
                    "{name}: run's exit code ({rust})"
                );
                assert!(runs.stdout.is_empty(), "{name}: run wrote no report");
                if rust.trim_end() != want {
                    failures.push(format!(
                        "{name}: run\n  got  {:?}\n  want {want:?}",
                        rust.trim_end()
                    ));
                }
            }
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

#[test]
fn a_json_inputs_error_names_its_true_line_and_column() {
    let dir = tmp("json-place");
    std::fs::create_dir_all(&dir).unwrap();
    let program = dir.join("program.json");
    std::fs::write(&program, PROGRAM).unwrap();
    for (k, (json, want)) in [
        // serde_json says 1:0 and 3:2 (the character before the `{` it only peeked at).
        (
            "{\"A\": true}",
            "1:1: invalid type: map, expected an array with one object of input values per scan",
        ),
        (
            "\n\n  {\"A\": true}",
            "3:3: invalid type: map, expected an array with one object of input values per scan",
        ),
        ("", "1:1: EOF while parsing a value"),
        ("[{\"A\": true},\n {\"N\": tru}]", "2:11: expected ident"),
        (
            "[{\"A\": true},\n {\"nope\": 1}]",
            "2:8: scan 1: unknown input variable `nope` (inputs: INPUTS)",
        ),
        (
            "[{\"N\": 70000}]",
            "1:13: scan 0, input `N`: `70000` is not an INT (-32768..32767)",
        ),
    ]
    .into_iter()
    .enumerate()
    {
        let file = dir.join(format!("inputs{k}.json"));
        std::fs::write(&file, json).unwrap();
        let path = file.to_str().unwrap();
        let out = run(&["run", program.to_str().unwrap(), "--inputs", path]);
        assert_eq!(out.status.code(), Some(2), "{json}");
        let want = format!("error: {path}:{}", want.replace("INPUTS", INPUTS));
        assert_eq!(
            String::from_utf8_lossy(&out.stderr).trim_end(),
            want,
            "{json}"
        );
    }
}
