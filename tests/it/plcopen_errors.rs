//! Bad PLCopen input: each one error with the file, line and column, exit code 2, nothing on
//! standard output, no panic.

use crate::common;
use crate::plcopen_common as px;

use common::cli::{error_line, run_stdin};
use px::{coil, contact, project, rail, NS};

fn error_of(xml: &str) -> String {
    error_line(&run_stdin(&["report", "-"], xml.as_bytes()), xml)
}

fn bools(names: &[&'static str]) -> Vec<(&'static str, &'static str, &'static str)> {
    names.iter().map(|n| ("localVars", *n, "BOOL")).collect()
}

#[test]
fn malformed_xml_names_line_and_column() {
    let xml = format!("<project xmlns=\"{NS}\">\n  <types>\n</project>\n");
    assert_eq!(
        error_of(&xml),
        "error: <stdin>:3:1: malformed XML: expected 'types' tag, not 'project'"
    );
}

#[test]
fn a_wrong_namespace_or_root_is_refused() {
    assert_eq!(
        error_of("<project xmlns=\"http://example.com/x\"/>"),
        "error: <stdin>:1:1: at top level: unknown namespace `http://example.com/x` of the PLCopen project (expected one of http://www.plcopen.org/xml/tc6_0201, http://www.plcopen.org/xml/tc6_0200, http://www.plcopen.org/xml/tc6.xsd)"
    );
    assert_eq!(
        error_of("<svg/>"),
        "error: <stdin>:1:1: at top level: not a PLCopen TC6 project: the root element is `svg`, not `project`"
    );
}

#[test]
fn entity_expansion_and_deep_nesting_are_refused() {
    let bomb = format!("<?xml version=\"1.0\"?>\n<!DOCTYPE lolz [<!ENTITY lol \"lol\"><!ENTITY lol2 \"&lol;&lol;&lol;\">]>\n<project xmlns=\"{NS}\">&lol2;</project>");
    assert_eq!(
        error_of(&bomb),
        "error: <stdin>:2:1: a DTD (<!DOCTYPE …>) is not allowed in a PLCopen file (its entities could expand without bound)"
    );
    let deep = format!(
        "<project xmlns=\"{NS}\">{}{}</project>",
        "<a>".repeat(300),
        "</a>".repeat(300)
    );
    assert_eq!(
        error_of(&deep),
        "error: <stdin>:1:816: elements nest deeper than 256 levels"
    );
}

#[test]
fn wiring_errors_name_the_local_ids() {
    let missing = project(
        &bools(&["A", "X"]),
        &[rail(1), contact(2, "A", &[9], ""), coil(3, "X", &[2], "")].concat(),
    );
    let e = error_of(&missing);
    assert!(e.ends_with("at pou P, LD, contact localId 2: the connection refers to localId 9, which is not an element of this body"), "{e}");
    let twice = project(
        &bools(&["A", "X"]),
        &[rail(1), contact(2, "A", &[1], ""), coil(2, "X", &[2], "")].concat(),
    );
    let e = error_of(&twice);
    assert!(
        e.contains("at pou P, LD, coil: localId 2 is used twice in this body (first at line "),
        "{e}"
    );
    let dangling = project(
        &bools(&["A", "X"]),
        &[rail(1), contact(2, "A", &[1], ""), "<connector localId=\"3\" name=\"c\"><connectionPointIn><connection refLocalId=\"2\"/></connectionPointIn></connector>".into(), coil(4, "X", &[2], "")].concat(),
    );
    let e = error_of(&dangling);
    assert!(e.ends_with("at pou P, LD, connector localId 3: connector `c` is dangling: no continuation reads it"), "{e}");
}

#[test]
fn names_from_the_file_must_be_identifiers() {
    let e = error_of(&project(
        &bools(&["A", "X"]),
        &[
            rail(1),
            contact(2, "../x", &[1], ""),
            coil(3, "X", &[2], ""),
        ]
        .concat(),
    ));
    assert!(e.ends_with("at pou P, LD, contact localId 2: `../x` is not a variable or a field of one (`X`, `T1.Q`): array elements, direct addresses and expressions are not supported here yet"), "{e}");
    let e = error_of(&project(&bools(&["a\"; b"]), &rail(1)).replace("a\"; b", "a&quot;; b"));
    assert!(e.ends_with("at pou P, localVars: variable name `a\"; b` is not an IEC 61131-3 identifier (letters, digits and single `_`, not starting with a digit)"), "{e}");
}

#[test]
fn types_the_model_lacks_are_named_with_their_variable() {
    let xml = project(&[("localVars", "n", "BOOL")], &rail(1)).replace(
        "<BOOL/>",
        "<bitfield><baseType><INT/></baseType></bitfield>",
    );
    let e = error_of(&xml);
    assert!(e.ends_with("at pou P, localVars, variable n: type bitfield of variable `n` is not supported yet (supported: BOOL, SINT, INT, DINT, LINT, USINT, UINT, UDINT, ULINT, REAL, LREAL, BYTE, WORD, DWORD, LWORD, TIME, STRING, the other elementary types of IEC 61131-3, data types, arrays, structures and function block types)"), "{e}");
}

#[test]
fn an_element_an_ld_body_cannot_hold_is_named() {
    let xml = project(
        &bools(&["A", "X"]),
        &[
            rail(1),
            contact(2, "A", &[1], ""),
            coil(3, "X", &[2], ""),
            "<step localId=\"4\" name=\"S0\"/>".to_owned(),
        ]
        .concat(),
    );
    let e = error_of(&xml);
    assert!(
        e.ends_with("at pou P, LD, step localId 4: `step` is not an element of an LD body that plc-deps reads"),
        "{e}"
    );
}
