//! PLCopen TC6 data types (`types/dataTypes`) and Beremiz SVGHMI's HMI_* types, hand-written:
//! aliases and subranges read as their base type (the type's initial value the variable's
//! default; the range not enforced), enumerations as INT with their values numbered from 0,
//! arrays and structures as whole variables without a value (only where `run` does not execute
//! the body), one note naming them; a cycle or an unknown base is one located error.

use crate::common;
use crate::plcopen_common as px;

use common::cli::{error_line, run_stdin};
use px::{coil, contact, io, line_col, project_in, rail, report_and_warnings, run_scans, rung};
use serde_json::json;

const TYPES: &str = r#"<dataTypes>
  <dataType name="LEVEL"><baseType><subrangeSigned><range lower="0" upper="1000"/><baseType><INT/></baseType></subrangeSigned></baseType><initialValue><simpleValue value="10"/></initialValue></dataType>
  <dataType name="LEVEL2"><baseType><derived name="LEVEL"/></baseType></dataType>
  <dataType name="VALVE"><baseType><enum><values><value name="OPEN"/><value name="CLOSED"/></values></enum></baseType><initialValue><simpleValue value="CLOSED"/></initialValue></dataType>
  <dataType name="TABLE"><baseType><array><dimension lower="1" upper="8"/><baseType><INT/></baseType></array></baseType></dataType>
</dataTypes>"#;

fn with_types(lang: &str, vars: &[(&str, &str, &str)], body: &str) -> String {
    project_in(lang, vars, body).replace("<dataTypes/>", TYPES)
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
fn aliases_subranges_enumerations_and_hmi_types_load_and_run_with_their_defaults() {
    let xml = with_types(
        "LD",
        &[
            ("inputVars", "go", "HMI_BOOL"),
            ("outputVars", "lamp", "HMI_BOOL"),
            ("outputVars", "lvl", "LEVEL2"),
            ("outputVars", "v", "VALVE"),
            ("outputVars", "n", "HMI_INT"),
        ],
        &ld(),
    );
    let (_, err) = report_and_warnings(&xml);
    assert_eq!(
        err.trim_end(),
        format!("warning: <stdin>:{}: data types are read as the model's types (IEC 61131-3 6.4.4): HMI_BOOL → BOOL (an alias of BOOL, from the Beremiz SVGHMI library): P.go, P.lamp; LEVEL2 → INT (an alias of INT, subrange 0..1000 not enforced): P.lvl; VALVE → INT (an enumeration, read as INT with OPEN = 0, CLOSED = 1): P.v; HMI_INT → INT (an alias of INT, from the Beremiz SVGHMI library): P.n; `run` does not check subranges, an array of an elementary type is one variable per element (`a[i]`) and any other array one whole variable (a read or write of any element reads or writes it) with no value, and a structure is one variable per elementary field (`s.f`)", line_col(&xml, "<variable name=\"go\""))
    );
    let v = run_scans(&xml, 1);
    assert_eq!(
        v["outputs"],
        json!({"lamp": false, "lvl": 10, "v": 1, "n": 0})
    );
}

#[test]
fn st_reads_enumeration_values_as_constants_and_an_element_of_a_variable_subscript_as_any_element()
{
    let body = "<xhtml:p xmlns:xhtml=\"http://www.w3.org/1999/xhtml\"><![CDATA[v := OPEN;\ntab[i] := tab[2] + 1;\nIF v = CLOSED THEN i := 1; END_IF;]]></xhtml:p>";
    let xml = with_types(
        "ST",
        &[
            ("localVars", "v", "VALVE"),
            ("localVars", "i", "INT"),
            ("localVars", "tab", "TABLE"),
        ],
        body,
    );
    let (r, _) = report_and_warnings(&xml);
    assert_eq!(
        io(&r),
        vec![
            rung("P.st1", &["v"], &["v"]),
            // `tab[i] := tab[2] + 1`: the element `i` chooses may be any (docs/plcopen.md,
            // "Arrays").
            rung(
                "P.st2",
                &[
                    "i", "tab[1]", "tab[2]", "tab[3]", "tab[4]", "tab[5]", "tab[6]", "tab[7]",
                    "tab[8]"
                ],
                &["tab[1]", "tab[2]", "tab[3]", "tab[4]", "tab[5]", "tab[6]", "tab[7]", "tab[8]"]
            ),
            rung("P.st3", &["v", "i"], &["i"]),
        ]
    );
}

#[test]
fn an_array_of_int_is_one_variable_per_element_and_its_pou_runs() {
    let xml = with_types(
        "LD",
        &[
            ("inputVars", "go", "BOOL"),
            ("outputVars", "lamp", "BOOL"),
            ("localVars", "tab", "TABLE"),
        ],
        &ld(),
    );
    assert!(run_stdin(&["report", "-"], xml.as_bytes()).status.success());
    // TABLE is ARRAY[1..8] OF INT: eight INT variables `tab[1]` … `tab[8]` (docs/plcopen.md,
    // "Arrays"), so the LD body runs.
    let v = run_scans(&xml, 1);
    assert_eq!(v["outputs"]["lamp"], json!(false), "{v}");
}

#[test]
fn a_cycle_of_data_types_is_one_located_error() {
    let xml = project_in("LD", &[("inputVars", "go", "BOOL")], &ld()).replace(
        "<dataTypes/>",
        r#"<dataTypes><dataType name="A"><baseType><derived name="B"/></baseType></dataType><dataType name="B"><baseType><derived name="A"/></baseType></dataType></dataTypes>"#,
    );
    let e = error_line(&run_stdin(&["report", "-"], xml.as_bytes()), "cycle");
    assert!(
        e.contains("is defined through itself (a cycle of derived types)"),
        "{e}"
    );
    // A type derived from a type nobody defines (a library type the export does not carry) is
    // a black box, no longer an error (issue 39): the variable of it is one whole variable.
    let unknown = project_in(
        "LD",
        &[
            ("inputVars", "go", "BOOL"),
            ("outputVars", "lamp", "BOOL"),
            ("localVars", "x", "A"),
        ],
        &ld(),
    )
    .replace(
        "<dataTypes/>",
        r#"<dataTypes><dataType name="A"><baseType><derived name="NOPE"/></baseType></dataType></dataTypes>"#,
    );
    let (_, w) = report_and_warnings(&unknown);
    assert!(
        w.contains("NOPE → DINT (a type that neither the file nor plc-deps defines (a library type: a black box)"),
        "{w}"
    );
}
