//! The readers against hostile input (the findings of a fuzz campaign): text nested deeper than
//! any stack, long chains of blocks, a diagnostic past a trailing CR, a multi-byte STL mnemonic,
//! a connection listed twice, EN wired to ENO in a cycle, Micro/WIN's numeric labels, and
//! `convert` on every format. Each command must end with its result or one located error (exit
//! 2): never a panic, a stack overflow or a hang. Every run here has a watchdog: a command
//! that has not ended after [`WATCHDOG`] is killed and the test fails (a hang, not a timing).

use crate::common::cli::{error_line, one_line, root, tmp};
use crate::plcopen_common as px;
use std::io::Write;
use std::process::{Command, Output, Stdio};
use std::time::{Duration, Instant};

/// How long a command may run before it is taken for a hang (generous: debug builds, a busy
/// machine).
const WATCHDOG: Duration = Duration::from_secs(300);

/// Runs `plc-deps ARGS` (standard input `stdin`) and waits for it at most [`WATCHDOG`]; its
/// output is read as it comes (a full pipe would stall it).
fn run_watched(args: &[&str], stdin: &[u8]) -> Output {
    use std::io::Read;
    let mut child = Command::new(env!("CARGO_BIN_EXE_plc-deps"))
        .current_dir(root())
        .args(args)
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("run plc-deps");
    let mut input = child.stdin.take().unwrap();
    let stdin = stdin.to_vec();
    // Written from a thread: a command that fails early closes its input unread.
    let writer = std::thread::spawn(move || {
        let _ = input.write_all(&stdin);
    });
    let drain = |mut r: Box<dyn Read + Send>| {
        std::thread::spawn(move || {
            let mut v = Vec::new();
            r.read_to_end(&mut v).expect("read output");
            v
        })
    };
    let stdout = drain(Box::new(child.stdout.take().unwrap()));
    let stderr = drain(Box::new(child.stderr.take().unwrap()));
    let started = Instant::now();
    let status = loop {
        if let Some(status) = child.try_wait().expect("wait") {
            break status;
        }
        if started.elapsed() > WATCHDOG {
            child.kill().expect("kill");
            child.wait().expect("reap");
            panic!("plc-deps {args:?} still ran after {WATCHDOG:?}: a hang");
        }
        std::thread::sleep(Duration::from_millis(20));
    };
    writer.join().unwrap();
    Output {
        status,
        stdout: stdout.join().unwrap(),
        stderr: stderr.join().unwrap(),
    }
}

/// Writes `text` to a scratch file `name` and returns its path.
fn file(name: &str, text: &str) -> String {
    let p = tmp(name);
    std::fs::write(&p, text).unwrap();
    p.to_str().unwrap().to_owned()
}

/// The argument lists of every command that reads a program, on `path` (output to scratch
/// files where the command writes files).
fn every_command(path: &str, tag: &str) -> Vec<Vec<String>> {
    let out = |n: &str| tmp(&format!("{tag}-{n}")).to_str().unwrap().to_owned();
    let s = |v: &[&str]| v.iter().map(|x| x.to_string()).collect::<Vec<_>>();
    vec![
        s(&["report", path]),
        s(&["order", path]),
        s(&["run", path, "--mode", "both", "--scans", "2"]),
        s(&["c", path, "-o", &out("c")]),
        s(&["il", path]),
        s(&["convert", path, "-o", &out("convert.json")]),
    ]
}

/// Runs every command on `path`; each must fail with exactly `expected` (one line, exit 2).
fn every_command_fails(path: &str, tag: &str, expected: &str) {
    for args in every_command(path, tag) {
        let argv: Vec<&str> = args.iter().map(String::as_str).collect();
        let out = run_watched(&argv, b"");
        let what = format!("{args:?}");
        let line = error_line(&out, &what);
        assert_eq!(line, expected.replace("FILE", path), "{what}");
    }
}

/// Runs every command on `path` but those named in `skip`; each must succeed.
fn every_command_but_succeeds(path: &str, tag: &str, skip: &[&str]) {
    for args in every_command(path, tag) {
        if skip.contains(&args[0].as_str()) {
            continue;
        }
        let argv: Vec<&str> = args.iter().map(String::as_str).collect();
        let out = run_watched(&argv, b"");
        assert_eq!(
            out.status.code(),
            Some(0),
            "{args:?}: {}",
            String::from_utf8_lossy(&out.stderr)
        );
    }
}

/// Runs every command on `path`; each must succeed (`run` may refuse what it does not execute,
/// with exit 2 and that reason, which is not the case here).
fn every_command_succeeds(path: &str, tag: &str) {
    for args in every_command(path, tag) {
        let argv: Vec<&str> = args.iter().map(String::as_str).collect();
        let out = run_watched(&argv, b"");
        assert_eq!(
            out.status.code(),
            Some(0),
            "{args:?}: {}",
            String::from_utf8_lossy(&out.stderr)
        );
    }
}

fn st_project(body: &str) -> String {
    let vars = [
        ("localVars", "x", "INT"),
        ("localVars", "a", "INT"),
        ("localVars", "c", "BOOL"),
    ];
    px::project_in("ST", &vars, body)
}

/// An FBD body whose one in variable holds `expression`, moved into `x` by a block.
fn fbd_expression_project(expression: &str) -> String {
    let vars = [("localVars", "x", "INT"), ("localVars", "a", "INT")];
    let body = format!(
        "<inVariable localId=\"1\"><connectionPointOut/><expression>{expression}</expression></inVariable>{}{}",
        px::block(2, "MOVE", None, &[("IN", &[(1, None)])], &["OUT"]),
        px::var_in("outVariable", 3, "x", (2, Some("OUT"))),
    );
    px::project_in("FBD", &vars, &body)
}

/// An FBD body whose one in variable holds BOOL `expression`, ANDed with `a` into `x` (boolean
/// blocks only, which `il` translates too).
fn fbd_bool_project(expression: &str) -> String {
    let vars = [("localVars", "x", "BOOL"), ("localVars", "a", "BOOL")];
    let body = format!(
        "<inVariable localId=\"1\"><connectionPointOut/><expression>{expression}</expression></inVariable>{}{}{}",
        px::in_var(4, "a"),
        px::block(2, "AND", None, &[("IN1", &[(1, None)]), ("IN2", &[(4, None)])], &["OUT"]),
        px::var_in("outVariable", 3, "x", (2, Some("OUT"))),
    );
    px::project_in("FBD", &vars, &body)
}

const LIMIT: usize = plc_deps::read::st::parser::MAX_NESTING;

#[test]
fn ten_thousand_parentheses_in_an_st_body_are_a_nesting_error_in_every_command() {
    let text = st_project(&format!(
        "x := {}a{};",
        "(".repeat(10_000),
        ")".repeat(10_000)
    ));
    let path = file("hostile-parens.xml", &text);
    let col = text
        .lines()
        .find(|l| l.contains("x := ("))
        .unwrap()
        .find('(')
        .unwrap()
        + LIMIT;
    let line = text.lines().position(|l| l.contains("x := (")).unwrap() + 1;
    every_command_fails(&path, "parens", &format!("error: FILE:{line}:{col}: at pou P, ST: ST syntax error: nested more than 128 levels deep (parentheses, operators, calls and compound statements each count one; docs/plcopen.md)"));
}

#[test]
fn five_thousand_nested_ifs_in_an_st_body_are_a_nesting_error_in_every_command() {
    let body = format!(
        "{}x := 1;{}",
        "IF c THEN ".repeat(5_000),
        " END_IF;".repeat(5_000)
    );
    let text = st_project(&body);
    let path = file("hostile-ifs.xml", &text);
    let l = text.lines().position(|l| l.contains("IF c THEN")).unwrap();
    let col = text.lines().nth(l).unwrap().find("IF").unwrap() + 10 * (LIMIT - 1) + 4;
    every_command_fails(&path, "ifs", &format!("error: FILE:{}:{col}: at pou P, ST: ST syntax error: nested more than 128 levels deep (parentheses, operators, calls and compound statements each count one; docs/plcopen.md)", l + 1));
}

#[test]
fn twenty_thousand_unary_minus_in_an_fbd_expression_are_a_nesting_error_in_every_command() {
    let text = fbd_expression_project(&format!("{}a", "- ".repeat(20_000)));
    let path = file("hostile-minus.xml", &text);
    let line = text
        .lines()
        .position(|l| l.contains("<inVariable"))
        .unwrap()
        + 1;
    let col = text
        .lines()
        .nth(line - 1)
        .unwrap()
        .find("<inVariable")
        .unwrap()
        + 1;
    every_command_fails(&path, "minus", &format!("error: FILE:{line}:{col}: at pou P, FBD, inVariable localId 1: expression `{}…`: nested more than 128 levels deep (parentheses, operators, calls and compound statements each count one; docs/plcopen.md)", "- ".repeat(30)));
}

#[test]
fn ten_thousand_parentheses_in_an_fbd_expression_are_a_nesting_error() {
    let text = fbd_expression_project(&format!("{}a{}", "(".repeat(10_000), ")".repeat(10_000)));
    let path = file("hostile-fbd-parens.xml", &text);
    let out = run_watched(&["report", &path], b"");
    let line = error_line(&out, "report");
    assert!(
        line.ends_with(&format!("pou P, FBD, inVariable localId 1: expression `{}…`: nested more than 128 levels deep (parentheses, operators, calls and compound statements each count one; docs/plcopen.md)", "(".repeat(60))),
        "{line}"
    );
}

#[test]
fn st_and_fbd_nested_up_to_the_limit_go_through_every_command() {
    // An ST body at the limit: statements nested as deep as they may, the innermost assigning
    // an expression as tall as it may be there.
    let ifs = LIMIT / 2;
    let parens = LIMIT - ifs - 4;
    let body = format!(
        "{}x := {}a + a{};{}",
        "IF c THEN ".repeat(ifs),
        "(".repeat(parens),
        ")".repeat(parens),
        " END_IF;".repeat(ifs)
    );
    let path = file("hostile-st-limit.xml", &st_project(&body));
    for args in every_command(&path, "st-limit") {
        let argv: Vec<&str> = args.iter().map(String::as_str).collect();
        let out = run_watched(&argv, b"");
        let stderr = String::from_utf8_lossy(&out.stderr);
        // `run` does not execute ST bodies: it says so, at the body, as `c`, `il` and `convert`
        // do (docs/scan.md); the others succeed.
        if matches!(args[0].as_str(), "run" | "c" | "il" | "convert") {
            assert!(
                out.status.code() == Some(0) || out.status.code() == Some(2),
                "{args:?}: {stderr}"
            );
            assert!(
                !stderr.contains("panicked") && !stderr.contains("nested more than"),
                "{args:?}: {stderr}"
            );
        } else {
            assert_eq!(out.status.code(), Some(0), "{args:?}: {stderr}");
        }
    }
    // An FBD in variable at the limit: a chain of operators as long as it may be, and NOT as
    // deep: each is a chain of blocks the whole pipeline orders, lowers and runs.
    let chain = format!("a{}", " AND a".repeat(LIMIT - 2));
    every_command_succeeds(
        &file("hostile-fbd-chain.xml", &fbd_bool_project(&chain)),
        "fbd-chain",
    );
    let not = format!("{}a", "NOT ".repeat(LIMIT - 1));
    every_command_succeeds(
        &file("hostile-fbd-not.xml", &fbd_bool_project(&not)),
        "fbd-not",
    );
    // Past the limit by one, each is the nesting error.
    for text in [
        format!("a{}", " AND a".repeat(LIMIT - 1)),
        format!("{}a", "NOT ".repeat(LIMIT)),
    ] {
        let out = run_watched(
            &[
                "report",
                &file("hostile-fbd-over.xml", &fbd_bool_project(&text)),
            ],
            b"",
        );
        assert!(error_line(&out, &text).contains("nested more than 128 levels deep"));
    }
}

#[test]
fn an_error_after_the_trailing_cr_of_a_long_line_is_shown_in_a_cr_only_file() {
    // An old Mac file: CR line endings only, so the whole file is one long line, and the error
    // (the JSON ends inside an object) is after its last CR.
    let text = format!(
        "{{\r  \"pous\": [\r{}",
        "    {\"name\": \"P\"},\r".repeat(12)
    );
    let path = file("hostile-cr-only.json", &text);
    let out = run_watched(&["report", &path], b"");
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{stderr}");
    assert!(!stderr.contains("panicked"), "{stderr}");
    assert_eq!(
        one_line(&stderr),
        format!("error: {path}:1:{}: EOF while parsing a value", text.len())
    );
}

#[test]
fn a_one_character_multi_byte_stl_mnemonic_is_an_unknown_instruction() {
    for m in ["é", "€", "命", "+é", "é+", "Aé"] {
        let text = format!("ORGANIZATION_BLOCK MAIN:OB1\nBEGIN\nNETWORK 1\nLD I0.0\n{m} Q0.0\nEND_ORGANIZATION_BLOCK\n");
        let path = file("hostile-mnemonic.stl", &text);
        let out = run_watched(&["report", &path], b"");
        assert_eq!(
            error_line(&out, m),
            format!("error: {path}:5:1: unknown instruction `{m}` (not an S7-200 instruction plc-deps reads; docs/il.md lists them)")
        );
    }
}

fn bools(names: &[&'static str]) -> Vec<(&'static str, &'static str, &'static str)> {
    names.iter().map(|n| ("localVars", *n, "BOOL")).collect()
}

/// The inputs (`in`) of rung `id` of a report.
fn reads_of(report: &serde_json::Value, id: &str) -> Vec<String> {
    let rung = report["rungs"]
        .as_array()
        .unwrap()
        .iter()
        .find(|r| r["id"] == id)
        .unwrap_or_else(|| panic!("no rung {id}: {report}"));
    let mut v: Vec<String> = rung["in"]
        .as_array()
        .unwrap()
        .iter()
        .map(|x| x.as_str().unwrap().to_owned())
        .collect();
    v.sort();
    v
}

#[test]
fn a_connection_listed_twice_in_one_pin_is_read_once_with_a_warning() {
    // The rail twice into contact 2, contact 2 twice into coil 3: Beremiz ORs a power with
    // itself, which is that power.
    let body = [
        px::rail(1),
        px::contact(2, "a", &[1, 1], ""),
        px::coil(3, "x", &[2, 2], ""),
    ]
    .concat();
    let text = px::project(&bools(&["a", "x"]), &body);
    let path = file("hostile-twice.xml", &text);
    for args in every_command(&path, "twice") {
        let argv: Vec<&str> = args.iter().map(String::as_str).collect();
        let out = run_watched(&argv, b"");
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(0), "{args:?}: {stderr}");
        let warnings: Vec<&str> = stderr
            .lines()
            .filter(|l| l.starts_with("warning"))
            .collect();
        assert_eq!(warnings.len(), 2, "{args:?}: {stderr}");
    }
    let out = run_watched(&["report", &path, "--format", "json"], b"");
    let warnings = one_line(&String::from_utf8_lossy(&out.stderr));
    let at = |needle: &str, nth: usize| {
        let (l, line) = text
            .lines()
            .enumerate()
            .find(|(_, l)| l.contains(needle))
            .unwrap();
        let col = line.match_indices(needle).nth(nth).unwrap().0 + 1;
        format!("{path}:{}:{col}", l + 1)
    };
    assert_eq!(
        warnings,
        format!(
            "warning: {}: pou P, LD: the input of contact localId 2 is connected to localId 1 more than once; it is read once (as Beremiz ORs a power with itself)\n\
             warning: {}: pou P, LD: the input of coil localId 3 is connected to localId 2 more than once; it is read once (as Beremiz ORs a power with itself)",
            at("<connection refLocalId=\"1\"", 1),
            at("<connection refLocalId=\"2\"", 1),
        )
    );
    let report: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(reads_of(&report, "P.R1"), ["a"]);
}

/// An FBD body of ADD blocks `(localId, EN fed by (localId, pin))`, each adding `a` and `a`.
fn en_project(blocks: &[(u32, (u32, &str))]) -> String {
    let vars = [("localVars", "a", "INT"), ("localVars", "x", "INT")];
    let mut body = px::in_var(100, "a");
    for &(id, (from, pin)) in blocks {
        body += &px::block(
            id,
            "ADD",
            None,
            &[
                ("EN", &[(from, Some(pin))]),
                ("IN1", &[(100, None)]),
                ("IN2", &[(100, None)]),
            ],
            &["ENO", "OUT"],
        );
    }
    body += &px::var_in("outVariable", 200, "x", (blocks[0].0, Some("OUT")));
    px::project_in("FBD", &vars, &body)
}

#[test]
fn en_wired_to_enos_in_a_cycle_is_an_error_naming_the_blocks() {
    let own = en_project(&[(1, (1, "ENO"))]);
    let path = file("hostile-own-eno.xml", &own);
    let at = |text: &str, needle: &str| {
        let (l, line) = text
            .lines()
            .enumerate()
            .find(|(_, l)| l.contains(needle))
            .unwrap();
        format!("{}:{}", l + 1, line.find(needle).unwrap() + 1)
    };
    let own_at = at(&own, "<connection refLocalId=\"1\" formalParameter=\"ENO\"");
    every_command_fails(&path, "own-eno", &format!("error: FILE:{own_at}: at pou P, FBD, block localId 1: blocks 1 → 1 form a cycle of arcs; feed the value back through a variable instead (one block writes it, the other reads it)"));
    let two = en_project(&[(1, (2, "ENO")), (2, (1, "ENO"))]);
    let path = file("hostile-two-eno.xml", &two);
    let two_at = at(&two, "<connection refLocalId=\"2\" formalParameter=\"ENO\"");
    every_command_fails(&path, "two-eno", &format!("error: FILE:{two_at}: at pou P, FBD, block localId 1: blocks 1 → 2 → 1 form a cycle of arcs; feed the value back through a variable instead (one block writes it, the other reads it)"));
}

const MICROWIN: &str = "ORGANIZATION_BLOCK MAIN:OB1
BEGIN
NETWORK 1
LD     I0.0
JMP    4
NETWORK 2
LD     I0.1
=      Q0.0
NETWORK 3
LBL    4
LD     I0.2
=      Q0.1
END_ORGANIZATION_BLOCK
";

/// The report of `path` as JSON (the command must succeed).
fn report_json(path: &str) -> serde_json::Value {
    let out = run_watched(&["report", path, "--format", "json"], b"");
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(0), "{path}: {stderr}");
    serde_json::from_slice(&out.stdout).unwrap()
}

/// The jump edges of a report's control-flow graph and its control dependences, as text.
fn jumps_and_control(report: &serde_json::Value) -> (Vec<String>, Vec<String>) {
    let edges = report["cfg"]["edges"].as_array().unwrap();
    let jumps = edges
        .iter()
        .filter(|e| e["kind"] == "jump")
        .map(|e| {
            format!(
                "{} -> {}",
                e["from"].as_str().unwrap(),
                e["to"].as_str().unwrap()
            )
        })
        .collect();
    let control = report["dependences"]
        .as_array()
        .unwrap()
        .iter()
        .filter(|d| d["kind"] == "control")
        .map(|d| {
            format!(
                "{} -> {} ({})",
                d["from"].as_str().unwrap(),
                d["to"].as_str().unwrap(),
                d["cause"].as_str().unwrap()
            )
        })
        .collect();
    (jumps, control)
}

#[test]
fn numeric_stl_labels_as_micro_win_writes_them_jump_and_round_trip_through_il() {
    let path = file("hostile-microwin.stl", MICROWIN);
    let report = report_json(&path);
    let (jumps, control) = jumps_and_control(&report);
    assert_eq!(jumps, ["N1 -> N3"]);
    assert_eq!(control, ["N1 -> N2 (branch)"]);
    every_command_succeeds(&path, "microwin");
    // `il` writes the labels back as they were, and its listing reports the same.
    let out = run_watched(&["il", &path], b"");
    let il = String::from_utf8(out.stdout).unwrap();
    assert!(
        il.lines().any(|l| l.split_whitespace().eq(["JMP", "4"])),
        "{il}"
    );
    assert!(
        il.lines().any(|l| l.split_whitespace().eq(["LBL", "4"])),
        "{il}"
    );
    let again = file("hostile-microwin-il.stl", &il);
    assert_eq!(jumps_and_control(&report_json(&again)), (jumps, control));
    // Micro/WIN numbers labels 0 to 255: a larger number is an error at it.
    for (from, to) in [("JMP    4", "JMP    256"), ("LBL    4", "LBL    256")] {
        let text = MICROWIN.replace(from, to);
        let bad = file("hostile-microwin-256.stl", &text);
        let line = text.lines().position(|l| l == to).unwrap() + 1;
        assert_eq!(
            error_line(&run_watched(&["report", &bad], b""), to),
            format!("error: {bad}:{line}:8: label 256 is out of range (S7-200 labels are numbered 0 to 255)")
        );
    }
}

#[test]
fn convert_reads_stl_and_plcopen_and_its_output_reports_the_same() {
    // A project without ST bodies: `convert` writes an ST body that lowers as its rungs, which
    // `report` of the XML analyses per statement instead (docs/plcopen.md, ST bodies).
    let plcopen = root().join("tests/plcopen/assemblyarea__plc.xml");
    let cases = [
        file("hostile-convert.stl", MICROWIN),
        file(
            "hostile-convert-blocks.stl",
            &std::fs::read_to_string(root().join("tests/stl/blocks.stl")).unwrap(),
        ),
        plcopen.to_str().unwrap().to_owned(),
    ];
    for (k, path) in cases.iter().enumerate() {
        let json = tmp(&format!("hostile-converted-{k}.json"));
        let out = run_watched(
            &[
                "convert",
                path,
                "--allow-skipped",
                "-o",
                json.to_str().unwrap(),
            ],
            b"",
        );
        assert_eq!(
            out.status.code(),
            Some(0),
            "{path}: {}",
            String::from_utf8_lossy(&out.stderr)
        );
        let (a, b) = (report_json(path), report_json(json.to_str().unwrap()));
        for key in ["rungs", "dependences", "cfg", "levels"] {
            assert_eq!(a[key], b[key], "{path}: {key}");
        }
    }
}

/// Blocks in the long chains: each feeds the next, in one network or rung.
const CHAIN: usize = 20_000;

#[test]
fn a_chain_of_twenty_thousand_fbd_blocks_goes_through_every_command_and_il_refuses_it() {
    // `il` builds its N-ary trees by recursion along a chain: it refuses chains past 256 blocks
    // with one error naming the block (checked by an explicit stack), and translates 256.
    // PLCopen: AND blocks, each ANDing `a` with the one before.
    let mut body = px::in_var(1, "a");
    for k in 0..CHAIN as u32 {
        let from = if k == 0 {
            (1, None)
        } else {
            (k + 1, Some("OUT"))
        };
        body += &px::block(
            k + 2,
            "AND",
            None,
            &[("IN1", &[from]), ("IN2", &[(1, None)])],
            &["OUT"],
        );
    }
    body += &px::var_in(
        "outVariable",
        CHAIN as u32 + 2,
        "x",
        (CHAIN as u32 + 1, Some("OUT")),
    );
    let vars = [("localVars", "x", "BOOL"), ("localVars", "a", "BOOL")];
    let chain_xml = file("hostile-chain.xml", &px::project_in("FBD", &vars, &body));
    every_command_but_succeeds(&chain_xml, "chain-xml", &["il"]);
    il_refuses_the_chain(&chain_xml);
    // The JSON format: the same chain as AND blocks, and a rung of as many contacts in series.
    let blocks: Vec<String> = (1..=CHAIN)
        .map(|k| {
            let first = if k == 1 {
                "\"a\"".to_owned()
            } else {
                format!("{{\"from\": {}}}", k - 1)
            };
            let out = if k == CHAIN { ", \"out\": \"x\"" } else { "" };
            format!("{{\"id\": {k}, \"op\": \"AND\", \"in\": [{first}, \"b\"]{out}}}")
        })
        .collect();
    let contacts = vec!["{\"contact\": \"a\"}"; CHAIN].join(", ");
    let vars = "\"vars\": [{\"name\": \"a\", \"type\": \"BOOL\", \"class\": \"input\"}, {\"name\": \"b\", \"type\": \"BOOL\", \"class\": \"input\"}, {\"name\": \"x\", \"type\": \"BOOL\", \"class\": \"output\"}]";
    let fbd = format!(
        "{{\"program\": \"p\", {vars}, \"fbd\": {{\"networks\": [{{\"id\": \"N1\", \"blocks\": [{}]}}]}}}}",
        blocks.join(", ")
    );
    let chain_json = file("hostile-chain.json", &fbd);
    every_command_but_succeeds(&chain_json, "chain-json", &["il"]);
    il_refuses_the_chain(&chain_json);
    // 256 blocks chained: translated, and the STL loads back.
    let short = format!(
        "{{\"program\": \"p\", {vars}, \"fbd\": {{\"networks\": [{{\"id\": \"N1\", \"blocks\": [{}]}}]}}}}",
        blocks[..255]
            .iter()
            .cloned()
            .chain([r#"{"id": 256, "op": "AND", "in": [{"from": 255}, "b"], "out": "x"}"#.to_string()])
            .collect::<Vec<_>>()
            .join(", ")
    );
    let out = run_watched(&["il", &file("chain-256.json", &short)], b"");
    assert_eq!(
        out.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let stl = file("chain-256.stl", &String::from_utf8_lossy(&out.stdout));
    let back = run_watched(&["report", &stl], b"");
    assert_eq!(
        back.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&back.stderr)
    );
    let ld = format!(
        "{{\"program\": \"p\", {vars}, \"rungs\": [{{\"id\": \"R1\", \"ld\": [{contacts}, {{\"coil\": \"x\"}}]}}]}}"
    );
    every_command_succeeds(&file("hostile-series.json", &ld), "series-json");
}

/// `il` on a chain of [`CHAIN`] blocks: exit 2, one error at the 257th block of the chain.
fn il_refuses_the_chain(path: &str) {
    let out = run_watched(&["il", path], b"");
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{err}");
    assert!(
        err.contains("its inputs come through a chain of more than 256 blocks"),
        "{err}"
    );
    assert_eq!(err.matches("error").count(), 1, "{err}");
}

#[test]
fn an_ld_rung_of_twenty_thousand_contacts_in_series_goes_through_every_command() {
    let mut body = px::rail(1);
    for k in 0..CHAIN as u32 {
        body += &px::contact(k + 2, "a", &[k + 1], "");
    }
    body += &px::coil(CHAIN as u32 + 2, "x", &[CHAIN as u32 + 1], "");
    let text = px::project(&bools(&["a", "x"]), &body);
    every_command_succeeds(&file("hostile-series.xml", &text), "series");
}

/// An LD body of `stages` stages from the rail: each stage is two contacts `a` and `b` fed by
/// the stage before, joined into one contact `a` (`nested`: only the `a` side is fed by the
/// stage before, the `b` side by the rail, so the `or`s nest one in the other).
fn ld_stages(stages: u32, nested: bool) -> String {
    let mut body = px::rail(1);
    let mut prev = 1;
    for k in 0..stages {
        let (a, b, j) = (2 + 3 * k, 3 + 3 * k, 4 + 3 * k);
        body += &px::contact(a, "a", &[prev], "");
        body += &px::contact(b, "b", &[if nested { 1 } else { prev }], "");
        body += &px::contact(j, "a", &[a, b], "");
        prev = j;
    }
    body += &px::coil(2 + 3 * stages, "x", &[prev], "");
    px::project(&bools(&["a", "b", "x"]), &body)
}

#[test]
fn ld_wiring_past_the_power_depth_is_an_error_not_a_stack_overflow() {
    // 100 OR sections in series are read as one rung; 300 pass more joins than the reader
    // follows, and 5,000 nested ORs too: one error each, at once (the rung reader's, after
    // the data-flow reading gives up as early).
    let path = file("hostile-or-100.xml", &ld_stages(100, false));
    let report = report_json(&path);
    assert_eq!(reads_of(&report, "P.R1"), ["a", "b"]);
    for (name, text) in [
        ("hostile-or-300.xml", ld_stages(300, false)),
        ("hostile-or-nested.xml", ld_stages(5_000, true)),
    ] {
        let path = file(name, &text);
        let line = error_line(&run_watched(&["report", &path], b""), name);
        assert!(
            line.contains("joins or blocks on its way from the left rail (the most plc-deps follows; docs/plcopen.md)"),
            "{line}"
        );
    }
    // ORs nested past 40 (as deep as the JSON format holds them) are read as a data-flow
    // network instead, with the reason.
    let path = file("hostile-or-nested-50.xml", &ld_stages(50, true));
    let out = run_watched(&["report", &path], b"");
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(0), "{stderr}");
    assert!(stderr.contains("are nested more than 40 deep (the most the JSON program format holds; docs/plcopen.md)"), "{stderr}");
}
