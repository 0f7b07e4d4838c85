//! Names and text that a program file should not be able to slip into the outputs: control
//! characters (C0, DEL, C1) in names and ids are refused with their place (E0110, or E0105 for
//! identifiers), whatever the format (JSON, PLCopen TC6 XML, STL); file text quoted in a message
//! is escaped on the terminal; a comment, which may hold anything, is escaped where it is
//! written (HTML) and nothing of it reaches the DOT, C or STL raw. Also `gen`'s argument limits.

use crate::common::cli::{error_line, graphviz, run, run_stdin, tmp};
use crate::plcopen_common as px;

/// The control characters every check is tried with: NUL, BEL, ESC, DEL and the C1 CSI.
const CONTROLS: &[(char, &str, &str)] = &[
    ('\u{0}', "\\u0000", "U+0000"),
    ('\u{7}', "\\u0007", "U+0007"),
    ('\u{1b}', "\\u001b", "U+001B"),
    ('\u{7f}', "\\u007f", "U+007F"),
    ('\u{9b}', "\\u009b", "U+009B"),
];

/// The text holds no control character but line feed and tab (nothing a terminal would obey).
fn assert_printable(bytes: &[u8], what: &str) {
    let text = String::from_utf8_lossy(bytes);
    let bad: Vec<char> = text
        .chars()
        .filter(|c| c.is_control() && !matches!(c, '\n' | '\t'))
        .collect();
    assert!(bad.is_empty(), "{what}: raw {bad:?} in {text}");
}

/// A JSON program whose program name is `name`, rung id `id` and rung comment `comment`
/// (JSON string contents, escapes allowed).
fn json_program(name: &str, id: &str, comment: &str) -> String {
    format!(
        "{{\"program\": \"{name}\",\n \"vars\": [{{\"name\": \"A\", \"type\": \"BOOL\"}}, {{\"name\": \"B\", \"type\": \"BOOL\"}}],\n \"rungs\": [\n  {{\"id\": \"R0\", \"ld\": [{{\"contact\": \"A\"}}, {{\"coil\": \"B\"}}]}},\n  {{\"id\": \"{id}\", \"comment\": \"{comment}\", \"ld\": [{{\"contact\": \"B\"}}, {{\"coil\": \"A\"}}]}}\n ]}}\n"
    )
}

#[test]
fn json_rung_ids_and_program_names_with_control_characters_are_refused_with_their_place() {
    for (c, json, code) in CONTROLS {
        let text = json_program("P", &format!("R{json}1"), "");
        let out = run_stdin(&["report", "-"], text.as_bytes());
        assert_printable(&out.stderr, code);
        let escaped = format!("{:?}", format!("R{c}1"));
        assert_eq!(
            error_line(&out, code),
            format!("error: <stdin>:5:10: at rungs[1].id: rung id {escaped} holds the control character {code} (names and ids are printable text)"),
        );
        let text = json_program(&format!("P{json}"), "R1", "");
        let out = run_stdin(&["il", "-"], text.as_bytes());
        assert_printable(&out.stderr, code);
        let escaped = format!("{:?}", format!("P{c}"));
        assert_eq!(
            error_line(&out, code),
            format!("error: <stdin>:1:13: at program: program name {escaped} holds the control character {code} (names and ids are printable text)"),
        );
    }
    // A newline in the program's name was written straight into the STL of `il`.
    let out = run_stdin(&["il", "-"], json_program("P\\nX", "R1", "").as_bytes());
    assert!(error_line(&out, "newline")
        .contains("program name \"P\\nX\" holds the control character U+000A"));
}

#[test]
fn json_variable_names_with_control_characters_are_refused_and_quoted_escaped() {
    for (_, json, code) in CONTROLS {
        let text = json_program("P", "R1", "")
            .replace("\"name\": \"A\"", &format!("\"name\": \"A{json}\""));
        let out = run_stdin(&["report", "-"], text.as_bytes());
        assert_printable(&out.stderr, code);
        let line = error_line(&out, code);
        assert!(
            line.starts_with("error: <stdin>:2:20: at vars[0].name: `A\\u{"),
            "{line}"
        );
        assert!(
            line.ends_with(
                "` is not a valid name (letters, digits and _, not starting with a digit)"
            ),
            "{line}"
        );
    }
}

#[test]
fn stl_names_with_control_characters_are_refused_with_their_place() {
    let stl = "ORGANIZATION_BLOCK MAIN:OB1\nBEGIN\nNETWORK 1 // first\nLD     I0.0\n=      Q0.0\nEND_ORGANIZATION_BLOCK\n";
    for (c, _, code) in CONTROLS {
        if *c == '\u{0}' {
            continue; // NUL: below.
        }
        let cases = [
            (
                "MAIN:OB1",
                format!("MA{c}IN:OB1"),
                format!(
                    "error: <stdin>:1:20: at program: program name {:?}",
                    format!("MA{c}IN")
                ),
            ),
            (
                "// first",
                format!("// fi{c}rst"),
                format!(
                    "error: <stdin>:3:9: at rungs[0].id: rung id {:?}",
                    format!("fi{c}rst")
                ),
            ),
        ];
        for (from, to, expected) in cases {
            let text = stl.replacen(from, &to, 1);
            let out = run_stdin(&["report", "-"], text.as_bytes());
            assert_printable(&out.stderr, code);
            assert_eq!(
                error_line(&out, code),
                format!("{expected} holds the control character {code} (names and ids are printable text)")
            );
        }
        let text = stl.replacen("I0.0", &format!("I0{c}.0"), 1);
        let out = run_stdin(&["report", "-"], text.as_bytes());
        assert_printable(&out.stderr, code);
        assert!(error_line(&out, code).starts_with("error: <stdin>:4:"));
    }
    // NUL: the file is binary, not text (the program reader's check).
    let text = stl.replacen("first", "fi\u{0}rst", 1);
    let out = run_stdin(&["report", "-"], text.as_bytes());
    assert_printable(&out.stderr, "NUL");
    assert_eq!(
        error_line(&out, "NUL"),
        "error: cannot read the program <stdin>: binary data, not text (a NUL byte at offset 49)"
    );
}

#[test]
fn plcopen_names_with_control_characters_are_refused_with_their_place() {
    let ld = format!(
        "{}{}{}",
        px::rail(1),
        px::contact(2, "A", &[1], ""),
        px::coil(3, "B", &[2], "")
    );
    let base = px::project(
        &[("localVars", "A", "BOOL"), ("localVars", "B", "BOOL")],
        &ld,
    );
    // XML allows DEL and the C1 controls in attributes; C0 ones are not XML at all.
    for (c, code) in [
        ('\u{7f}', "U+007F"),
        ('\u{9b}', "U+009B"),
        ('\u{85}', "U+0085"),
    ] {
        for (from, to) in [
            ("<pou name=\"P\"", format!("<pou name=\"P{c}\"")),
            ("<variable name=\"A\"", format!("<variable name=\"A{c}\"")),
        ] {
            let text = base.replacen(from, &to, 1);
            let out = run_stdin(&["report", "-"], text.as_bytes());
            assert_printable(&out.stderr, code);
            let line = error_line(&out, code);
            let escaped = format!("{c:?}").trim_matches('\'').to_string();
            assert!(line.contains(&escaped), "{code}: {line}");
            assert!(line.starts_with("error: <stdin>:"), "{code}: {line}");
        }
    }
    let text = base.replacen("<pou name=\"P\"", "<pou name=\"P&#27;\"", 1);
    let out = run_stdin(&["report", "-"], text.as_bytes());
    assert_printable(&out.stderr, "ESC reference");
    assert!(error_line(&out, "ESC reference").starts_with("error: <stdin>:"));
}

#[test]
fn file_text_quoted_in_a_message_reaches_the_terminal_escaped() {
    // An unknown STL keyword and an unknown JSON element, each holding ESC.
    let out = run_stdin(&["report", "-"], b"ORGANIZATION_BLOCK M:OB1\nBEGIN\nNETWORK 1\nL\x1b[31mD I0.0\n=      Q0.0\nEND_ORGANIZATION_BLOCK\n");
    assert_eq!(out.status.code(), Some(2));
    assert_printable(&out.stderr, "stl keyword");
    assert!(
        String::from_utf8_lossy(&out.stderr).contains("\\u{1b}"),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let text = json_program("P", "R1", "")
        .replace("{\"contact\": \"B\"}", "{\"con\\u001b[2Jtact\": \"B\"}");
    let out = run_stdin(&["report", "-"], text.as_bytes());
    assert_eq!(out.status.code(), Some(2));
    assert_printable(&out.stderr, "json key");
    assert!(String::from_utf8_lossy(&out.stderr).contains("con\\u{1b}[2Jtact"));
    // In colour (forced through a pseudo-terminal is not possible here): the JSON form escapes too.
    let out = run_stdin(&["report", "--format", "json", "-"], text.as_bytes());
    assert_printable(&out.stderr, "json diagnostics");
}

#[test]
fn a_comment_with_escape_is_escaped_in_every_output() {
    let text = json_program("P", "R1", "stop \\u001b[2J here\\u0007");
    let path = tmp("hostile-comment.json");
    std::fs::write(&path, &text).unwrap();
    let file = path.to_str().unwrap();
    let html = run(&["report", "--format", "html", file]);
    assert!(html.status.success());
    assert_printable(&html.stdout, "html");
    let page = String::from_utf8_lossy(&html.stdout);
    assert!(
        page.contains("stop \\u{1b}[2J here\\u{7}"),
        "the comment is shown, escaped"
    );
    for args in [
        vec!["report", file],
        vec!["report", "--format", "json", file],
        vec!["il", file],
        vec!["convert", file],
        vec!["run", "--scans", "2", file],
    ] {
        let out = run(&args);
        assert!(
            out.status.success(),
            "{args:?}: {}",
            String::from_utf8_lossy(&out.stderr)
        );
        assert_printable(&out.stdout, &format!("{args:?}"));
        assert_printable(&out.stderr, &format!("{args:?}"));
    }
    let dot = run(&["report", "--format", "dot", file]);
    assert!(dot.status.success());
    assert_printable(&dot.stdout, "dot");
    graphviz(&dot.stdout, "dot with a hostile comment");
    let dir = tmp("hostile-comment-c");
    let _ = std::fs::remove_dir_all(&dir);
    let out = run(&["c", file, "-o", dir.to_str().unwrap()]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    for entry in std::fs::read_dir(&dir).unwrap() {
        let p = entry.unwrap().path();
        assert_printable(&std::fs::read(&p).unwrap(), &p.display().to_string());
    }
}

#[test]
fn gen_refuses_sizes_it_could_not_read_back_naming_the_flag() {
    let max = "4000000";
    for (args, expected) in [
        (
            vec!["--rungs", "4000001"],
            "error: --rungs must be at most 4000000 (a larger program would pass the 2 GiB the readers read), not 4000001",
        ),
        (
            vec!["--rungs", "18446744073709551615"],
            "error: --rungs must be at most 4000000 (a larger program would pass the 2 GiB the readers read), not 18446744073709551615",
        ),
        (
            vec!["--rungs", "10", "--loops", "--for-body", "18446744073709551615"],
            "error: --for-body must be at most 4000000 (the most rungs a program has), not 18446744073709551615",
        ),
        (
            vec!["--rungs", "10", "--loops", "--for-body", "18446744073709551614"],
            "error: --for-body must be at most 4000000 (the most rungs a program has), not 18446744073709551614",
        ),
    ] {
        let mut all = vec!["gen"];
        all.extend_from_slice(&args);
        let out = run(&all);
        assert_eq!(error_line(&out, &format!("{args:?}")), expected);
    }
    // The accepted extremes load back.
    for args in [
        vec!["--rungs", "10", "--loops", "--for-body", max],
        vec!["--rungs", "12", "--loops", "--for-body", "10"],
        vec!["--rungs", "10", "--width", "18446744073709551615"],
        vec!["--rungs", "10", "--levels", "18446744073709551615"],
        vec![
            "--rungs",
            "10",
            "--seed",
            "18446744073709551615",
            "--timers",
            "--jumps",
            "--calls",
            "--loops",
            "--hot-fraction",
            "1",
        ],
        vec![
            "--rungs",
            "1",
            "--loops",
            "--for-body",
            max,
            "--jumps",
            "--calls",
            "--timers",
        ],
    ] {
        let mut all = vec!["gen"];
        all.extend_from_slice(&args);
        let out = run(&all);
        assert!(
            out.status.success(),
            "{args:?}: {}",
            String::from_utf8_lossy(&out.stderr)
        );
        let back = run_stdin(&["report", "--format", "json", "-"], &out.stdout);
        assert!(
            back.status.success(),
            "{args:?} loads back: {}",
            String::from_utf8_lossy(&back.stderr)
        );
    }
}

/// A PLCopen project whose program `P` has an ST body (three statements, the last calling a
/// function the project does not define, which `run` cannot execute), and where it starts.
fn st_project() -> (String, String) {
    let xml = px::project_in(
        "ST",
        &[
            ("inputVars", "start", "BOOL"),
            ("outputVars", "run", "BOOL"),
            ("localVars", "count", "INT"),
        ],
        "<xhtml:p xmlns:xhtml=\"http://www.w3.org/1999/xhtml\"><![CDATA[count := count + 1;\nrun := start;\ncount := MYFUNC(count);]]></xhtml:p>",
    );
    let at = px::line_col(&xml, "<ST>");
    (xml, at)
}

#[test]
fn run_c_and_il_refuse_an_st_body_they_do_not_execute_unless_allowed() {
    let (xml, at) = st_project();
    let call = px::line_col(&xml, "MYFUNC");
    let refused = |what: &str| {
        format!("error: <stdin>:{at}: pou P: its ST body is not executed: the call of function `MYFUNC` (only the standard functions are executed) at {call} is not executed yet (it is read only as stand-in rungs that keep every value); {what}")
    };
    // The reader's warning W0501 comes first: the error is the last line.
    let error_line = |out: &std::process::Output, what: &str| {
        assert_eq!(out.status.code(), Some(2), "{what}");
        assert!(out.stdout.is_empty(), "{what}");
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert!(
            stderr.starts_with("warning[W0501]: pou P: its ST body"),
            "{what}: {stderr}"
        );
        stderr.trim_end().lines().last().unwrap().to_string()
    };
    let out = run_stdin(&["run", "-", "--scans", "2"], xml.as_bytes());
    assert_eq!(
        error_line(&out, "run"),
        refused("give --allow-skipped to run the rest of the project without it")
    );
    let dir = tmp("hostile-st-c");
    let _ = std::fs::remove_dir_all(&dir);
    let c = ["c", "-", "-o", dir.to_str().unwrap()];
    let out = run_stdin(&c, xml.as_bytes());
    assert_eq!(
        error_line(&out, "c"),
        refused("give --allow-skipped to write the C without it")
    );
    assert!(!dir.exists(), "nothing written");
    let out = run_stdin(&["il", "-"], xml.as_bytes());
    assert_eq!(error_line(&out, "il"), refused("its STL cannot be written"));
    // The JSON format has no mark for a stand-in: `convert` refuses too, unless allowed.
    let out = run_stdin(&["convert", "-"], xml.as_bytes());
    assert_eq!(
        error_line(&out, "convert"),
        refused("give --allow-skipped to write the JSON without it")
    );
    let out = run_stdin(&["convert", "-", "--allow-skipped"], xml.as_bytes());
    assert_eq!(out.status.code(), Some(0), "convert --allow-skipped");
    assert!(!out.stdout.is_empty());

    // Allowed: the outputs list the POU.
    let (line, column) = at.split_once(':').unwrap();
    let listed = format!("P (ST body at {at})");
    let out = run_stdin(
        &["run", "-", "--scans", "2", "--allow-skipped"],
        xml.as_bytes(),
    );
    assert_eq!(out.status.code(), Some(0));
    let text = String::from_utf8(out.stdout).unwrap();
    assert!(
        text.contains(&format!(
            "\nnot executed (--allow-skipped; stand-in rungs keep every value): {listed}\n"
        )),
        "{text}"
    );
    let args = [
        "run",
        "-",
        "--scans",
        "2",
        "--allow-skipped",
        "--format",
        "json",
    ];
    let (r, _) = px::json_output(&args, &xml);
    let expected = serde_json::json!([{"pou": "P", "language": "ST", "line": line.parse::<u32>().unwrap(), "column": column.parse::<u32>().unwrap()}]);
    assert_eq!(r["skipped_pous"], expected);
    let args = [
        "run",
        "-",
        "--scans",
        "2",
        "--allow-skipped",
        "--format",
        "html",
    ];
    let out = run_stdin(&args, xml.as_bytes());
    assert!(String::from_utf8_lossy(&out.stdout).contains(&format!("<li>{listed}</li>")));
    let c = ["c", "-", "-o", dir.to_str().unwrap(), "--allow-skipped"];
    let out = run_stdin(&c, xml.as_bytes());
    assert_eq!(
        out.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let marked: Vec<String> = std::fs::read_dir(&dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| {
            std::fs::read_to_string(p)
                .unwrap()
                .contains("/* NOT EXECUTED: the ST body of POU P is not translated")
        })
        .map(|p| p.file_name().unwrap().to_string_lossy().into_owned())
        .collect();
    assert_eq!(marked.len(), 2, "the POU's header and source: {marked:?}");
}

#[test]
fn report_says_which_bodies_it_analysed_only_through_stand_ins() {
    let (xml, at) = st_project();
    let out = run_stdin(&["report", "-"], xml.as_bytes());
    assert_eq!(out.status.code(), Some(0));
    let text = String::from_utf8(out.stdout).unwrap();
    assert!(text.contains(&format!("\nBodies not read as logic\n  P (ST body at {at})\n  each analysed through stand-in rungs that read and write whole variables")), "{text}");
    let (r, _) = px::report_and_warnings(&xml);
    assert_eq!(r["skipped_pous"][0]["pou"], "P");
    assert_eq!(r["skipped_pous"][0]["language"], "ST");
    // A program without such bodies has no key (the report JSON is unchanged).
    let (plain, _) = px::json_output(
        &["report", "-", "--format", "json"],
        &json_program("P", "R1", ""),
    );
    assert!(plain.get("skipped_pous").is_none());
}
