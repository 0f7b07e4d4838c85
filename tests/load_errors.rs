//! The loader's error behaviour beyond one error per file (tests/errors/ holds those): several
//! errors in program order, line and column of the node, a byte-order mark, an empty file.

use plc_deps::read::{program_from_json, LoadError};

fn err(text: &str) -> LoadError {
    program_from_json(text).expect_err("the program is invalid")
}

#[test]
fn several_errors_come_in_program_order_each_located() {
    let text = r#"{"program": "p", "vars": [{"name": "A", "type": "BOOL"}], "rungs": [
        {"id": "R1", "ld": [{"contact": "X"}, {"coil": "A"}]},
        {"id": "R2", "ld": [{"contact": "A"}, {"coil": "Y"}]},
        {"id": "R3", "ld": [{"contact": "A", "negate": true}]}
    ]}"#;
    let e = err(text);
    assert_eq!(e.diagnostics().len(), 3);
    assert_eq!(
        e.to_string(),
        "rung R1 at rungs[0].ld[0].contact: undefined variable `X`\n\
         rung R2 at rungs[1].ld[1].coil: undefined variable `Y`\n\
         rung R3 at rungs[2].ld[0].negate: unknown field `negate` in a contact (allowed: contact, negated, edge)"
    );
    assert_eq!(
        e.in_file("p.json").to_string().lines().nth(1),
        Some("error: p.json: rung R2 at rungs[1].ld[1].coil: undefined variable `Y`")
    );
    let d = &e.diagnostics()[0];
    assert_eq!(d.code(), "E0204");
    assert_eq!(
        d.location.position,
        Some((2, 9)),
        "line and column of rung R1"
    );
}

#[test]
fn a_byte_order_mark_is_skipped() {
    let text =
        "\u{feff}{\"program\": \"p\", \"rungs\": [{\"id\": \"R1\", \"ld\": [{\"ret\": true}]}]}";
    assert_eq!(program_from_json(text).expect("loads").rungs.len(), 1);
}

#[test]
fn an_empty_file_is_a_syntax_error_at_column_1() {
    for text in ["", "\n", "  \n  "] {
        match err(text) {
            LoadError::Syntax {
                column, message, ..
            } => {
                assert_eq!(column, 1);
                assert!(message.contains("empty"), "{message}");
            }
            other => panic!("expected a syntax error, got {other}"),
        }
    }
    // An error at the start of a line is column 1, not 0.
    match err("{\"program\": \"p\",\n") {
        LoadError::Syntax { line, column, .. } => assert_eq!((line, column), (2, 1)),
        other => panic!("expected a syntax error, got {other}"),
    }
}

#[test]
fn at_most_twenty_errors_are_reported() {
    let rungs: Vec<String> = (0..50)
        .map(|i| format!(r#"{{"id": "R{i}", "ld": [{{"contact": "X{i}"}}]}}"#))
        .collect();
    let text = format!(r#"{{"program": "p", "rungs": [{}]}}"#, rungs.join(","));
    assert_eq!(err(&text).diagnostics().len(), plc_deps::diag::MAX_ERRORS);
}

#[test]
fn instances_map_to_their_function_block_type_and_pou() {
    let text = r#"{"program": "p",
      "vars": [{"name": "G1", "type": "GEN"}, {"name": "G2", "type": "GEN"}, {"name": "R", "type": "INT"}],
      "rungs": [{"id": "R1", "ld": [{"move": "G2.OUT", "to": "R"}]}],
      "function_blocks": {"GEN": {"inputs": [{"name": "IN", "type": "INT"}],
        "outputs": [{"name": "OUT", "type": "INT"}],
        "rungs": [{"id": "B1", "ld": [{"move": "IN", "to": "OUT"}]}]}}}"#;
    let (p, fbd) = plc_deps::read::program_and_fbd_from_json(text).expect("loads");
    let names: Vec<(&str, &str)> = fbd
        .instances
        .iter()
        .map(|i| (i.name.as_str(), i.fb.as_str()))
        .collect();
    assert_eq!(names, [("G1", "GEN"), ("G2", "GEN")]);
    for i in &fbd.instances {
        assert_eq!(p.pou(i.pou).name, i.name);
        assert_eq!(p.var(i.outputs[0].1).name, format!("{}.OUT", i.name));
    }
}

#[test]
fn every_unpaired_for_and_next_is_reported() {
    let text = r#"{"program": "p", "vars": [{"name": "i", "type": "INT"}], "rungs": [
        {"id": "R1", "ld": [{"next": true}]},
        {"id": "R2", "ld": [{"for": {"var": "i", "from": 1, "to": 2}}]},
        {"id": "R3", "ld": [{"for": {"var": "i", "from": 1, "to": 2}}]}
    ]}"#;
    assert_eq!(
        err(text).to_string(),
        "rung R1 at rungs[0].ld[0]: NEXT without a FOR\n\
         rung R2 at rungs[1].ld[0]: FOR without a NEXT\n\
         rung R3 at rungs[2].ld[0]: FOR without a NEXT"
    );
}
