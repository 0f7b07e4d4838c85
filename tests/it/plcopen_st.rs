//! PLCopen TC6 XML ST bodies, hand-written: each top-level statement is one stand-in rung
//! `<pou>.stK` with exactly the variables it reads and writes (a compound statement with all of
//! its parts; a written variable is also read, by the `move x → x` that stands for the write; a
//! called standard instance is read and written, by its box), located at the statement's line and column in the XML file through CDATA and
//! entity references; `run` executes the lowered body (tests/it/st_exec.rs has the rest); an ST syntax error or an undeclared
//! name is one located error.

use crate::common;
use crate::plcopen_common as px;

use common::cli::{error_line, run_stdin};
use px::{io, line_col, project_in, report_and_warnings, run_scans, rung};
use serde_json::json;

const VARS: &[(&str, &str, &str)] = &[
    ("inputVars", "start", "BOOL"),
    ("inputVars", "stop", "BOOL"),
    ("outputVars", "run", "BOOL"),
    ("outputVars", "done", "BOOL"),
    ("localVars", "count", "INT"),
    ("localVars", "T1", "TON"),
];

/// An ST body of `lines` (joined by newlines) in a CDATA section, as Beremiz writes it.
fn st(lines: &[&str]) -> String {
    project_in(
        "ST",
        VARS,
        &format!(
            "<xhtml:p xmlns:xhtml=\"http://www.w3.org/1999/xhtml\"><![CDATA[{}]]></xhtml:p>",
            lines.join("\n")
        ),
    )
}

const BODY: &[&str] = &[
    "count := count + 1;",
    "IF start AND NOT stop THEN",
    "  run := TRUE;",
    "ELSIF count > 10 THEN count := 0; END_IF;",
    "T1(IN := run, PT := T#1s);",
    ";",
    "done := T1.Q;",
];

#[test]
fn each_statement_is_a_rung_with_exactly_its_reads_and_writes() {
    let (r, err) = report_and_warnings(&st(BODY));
    assert_eq!(
        io(&r),
        vec![
            rung("P.st1", &["count"], &["count"]),
            rung(
                "P.st2",
                &["start", "stop", "run", "count"],
                &["run", "count"]
            ),
            // The call of T1 is its timer box: it reads and writes the instance, so done :=
            // T1.Q (st5) depends on it (IEC 61131-3: the call updates Q and ET).
            rung("P.st3", &["run", "T1"], &["T1"]),
            rung("P.st5", &["done", "T1"], &["done"]),
        ]
    );
    let deps: Vec<(String, String, String, String)> = r["dependences"]
        .as_array()
        .unwrap()
        .iter()
        .map(|d| {
            let s = |k: &str| d[k].as_str().unwrap().to_owned();
            (s("kind"), s("from"), s("to"), s("var"))
        })
        .collect();
    assert_eq!(
        deps,
        [
            ("flow", "P.st1", "P.st2", "count"),
            ("anti", "P.st1", "P.st2", "count"),
            ("output", "P.st1", "P.st2", "count"),
            ("flow", "P.st2", "P.st3", "run"),
            ("flow", "P.st3", "P.st5", "T1"),
            // The paper's control pair of a timer instance, as for a ladder timer box.
            ("control", "P.st3", "P.st5", "T1"),
        ]
        .map(|(k, f, t, v)| (k.to_owned(), f.to_owned(), t.to_owned(), v.to_owned()))
    );
    let xml = st(BODY);
    let body = line_col(&xml, "<ST>");
    assert_eq!(
        err.lines().collect::<Vec<_>>(),
        [format!("warning: <stdin>:{body}: pou P: its ST body is analysed per statement (5 top-level statements, rungs P.st1 …, each reading and writing whole variables) and executed by `run` and `c` as the rungs it is lowered to (docs/plcopen.md, ST bodies)")]
    );
}

#[test]
fn a_run_executes_the_body() {
    // start and stop stay FALSE: `count := count + 1` runs every scan (3 after 3 scans, never
    // past 10), `run` is never set, so T1 never starts and `done` stays FALSE. (Before ST was
    // executed, the stand-ins left count at 0.)
    let xml = st(BODY);
    let v = run_scans(&xml, 3);
    assert_eq!(v["outputs"], json!({"run": false, "done": false}));
    assert_eq!(v["state"]["count"], json!(3));
}

#[test]
fn errors_are_located_at_the_statement_in_the_xml_file() {
    // An undeclared name, on the third line of the CDATA section.
    let xml = st(&["count := 1;", "run := start;", "  zz := 2;"]);
    let e = error_line(&run_stdin(&["report", "-"], xml.as_bytes()), "undeclared");
    assert_eq!(
        e,
        format!(
            "error: <stdin>:{}: at pou P, ST: `zz` is not a variable of POU `P` (nor a global it declares external), nor a function it calls",
            line_col(&xml, "zz :=")
        )
    );
    // A syntax error after an entity reference outside CDATA: the column counts `&lt;` as 4.
    let xml = project_in(
        "ST",
        VARS,
        "<xhtml xmlns=\"http://www.w3.org/1999/xhtml\">run := count &lt; 3;\ndone := ;</xhtml>",
    );
    let e = error_line(&run_stdin(&["report", "-"], xml.as_bytes()), "syntax");
    assert!(
        e.starts_with(&format!(
            "error: <stdin>:{}: at pou P, ST: ST syntax error: ",
            line_col(&xml, ";</xhtml>")
        )),
        "{e}"
    );
}

#[test]
fn an_il_body_is_still_analysed_through_its_interface() {
    let xml = project_in(
        "IL",
        VARS,
        "<xhtml xmlns=\"http://www.w3.org/1999/xhtml\">LD start\nST run</xhtml>",
    );
    let (r, err) = report_and_warnings(&xml);
    assert_eq!(
        io(&r),
        vec![rung(
            "P.body",
            &["start", "stop", "run", "done", "count"],
            &["run", "done", "count"]
        )]
    );
    assert!(err.contains(&format!("warning: <stdin>:{}: pou P: its IL body is analysed through its interface (inputs read; outputs, locals and externals written) and executed by `run` and `c` as the rungs its instructions are lowered to (docs/plcopen.md, IL bodies); the function block instances T1 are not written", line_col(&xml, "<IL>"))), "{err}");
}
