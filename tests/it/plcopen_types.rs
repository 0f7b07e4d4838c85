//! The elementary types of IEC 61131-3 in hand-written PLCopen TC6 XML: those the model has
//! (BYTE, UINT, LREAL, ULINT …) read as themselves; those it lacks read as one it has (LTIME as
//! TIME, DATE as DINT …) with one note naming every mapped variable and what `run` computes
//! differently; typed and based literals as initial values;
//! strings accepted only where `run` does not execute the body.

use crate::common;
use crate::plcopen_common as px;

use common::cli::{error_line, run_stdin};
use px::{coil, contact, line_col, project_in, rail, report_and_warnings, run_scans};
use serde_json::json;

/// `ty` typed variables: `(class, name, TC6 type element, initial value)`.
fn with_types(lang: &str, vars: &[(&str, &str, &str, &str)], body: &str) -> String {
    let mut xml = project_in(
        lang,
        &vars.iter().map(|v| (v.0, v.1, "BOOL")).collect::<Vec<_>>(),
        body,
    );
    for (_, name, ty, init) in vars {
        let init = if init.is_empty() {
            String::new()
        } else {
            format!("<initialValue><simpleValue value=\"{init}\"/></initialValue>")
        };
        xml = xml.replace(
            &format!("<variable name=\"{name}\"><type><BOOL/></type></variable>"),
            &format!("<variable name=\"{name}\"><type>{ty}</type>{init}</variable>"),
        );
    }
    xml
}

fn ld() -> String {
    [
        rail(1),
        contact(2, "go", &[1], ""),
        coil(3, "lamp", &[2], ""),
    ]
    .concat()
}

#[test]
fn elementary_types_are_read_as_themselves_and_the_others_named_in_one_note() {
    let xml = with_types(
        "LD",
        &[
            ("inputVars", "go", "<BOOL/>", ""),
            ("outputVars", "lamp", "<BOOL/>", ""),
            ("outputVars", "b", "<BYTE/>", "16#10"),
            ("outputVars", "u", "<UINT/>", "UINT#7"),
            ("outputVars", "r", "<LREAL/>", "2.5"),
            ("outputVars", "big", "<ULINT/>", "18446744073709551615"),
            ("outputVars", "t", "<LTIME/>", "T#1s"),
        ],
        &ld(),
    );
    let (_, err) = report_and_warnings(&xml);
    // Only LTIME is mapped: BYTE, UINT, LREAL and ULINT are the model's own.
    assert_eq!(
        err.trim_end(),
        format!("warning: <stdin>:{}: elementary types the model lacks are read as one it has: P.t LTIME → TIME; `run` computes them as that type (dates and times of day as DINT, LTIME as 32-bit ms TIME), so it differs from a PLC where a value leaves that type's range, and a string has no value (it stands in as a DINT 0)", line_col(&xml, "<variable name=\"t\""))
    );
    let v = run_scans(&xml, 1);
    assert_eq!(
        v["outputs"],
        json!({"lamp": false, "b": 16, "u": 7, "r": 2.5, "big": 18446744073709551615u64, "t": 1000})
    );
}

#[test]
fn a_wstring_is_analysed_everywhere_and_run_refuses_it_where_it_would_execute_the_body() {
    // A STRING has values (tests/it/strings.rs); a WSTRING has none.
    let vars = [
        ("inputVars", "go", "<BOOL/>", ""),
        ("outputVars", "lamp", "<BOOL/>", ""),
        ("localVars", "msg", "<wstring/>", "&quot;hello&quot;"),
    ];
    let xml = with_types("LD", &vars, &ld());
    // The report reads it (a whole variable, with a warning naming why `run` would refuse).
    let (r, err) = report_and_warnings(&xml);
    assert_eq!(r["rungs"][0]["out"], json!(["lamp"]));
    let at = line_col(&xml, "<variable name=\"msg\"");
    assert!(
        err.contains(&format!("<stdin>:{at}: pou P: variable `msg` is a WSTRING")),
        "{err}"
    );
    let e = error_line(
        &run_stdin(&["run", "-", "--scans", "1"], xml.as_bytes()),
        "string in LD",
    );
    assert_eq!(e, format!("error: <stdin>:{at}: at run: pou P: variable `msg` is a WSTRING, for which plc-deps has no values: the analysis reads it as a whole variable, but `run` cannot execute the LD body of `P`"));
    let st = with_types(
        "ST",
        &vars,
        "<xhtml xmlns=\"http://www.w3.org/1999/xhtml\">IF go THEN msg := &quot;on&quot;; END_IF;</xhtml>",
    );
    let (r, err) = report_and_warnings(&st);
    assert_eq!(r["rungs"][0]["in"], json!(["go", "msg"]));
    assert_eq!(r["rungs"][0]["out"], json!(["msg"]));
    assert!(err.contains("P.msg WSTRING → DINT"), "{err}");
}
