//! The loader's error behaviour beyond one error per file (tests/errors/ holds those): several
//! errors in program order, line and column of the node, a byte-order mark, an empty file.

use plc_deps::load::program_from_json;
use plc_deps::read::LoadError;

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
        Some("error: p.json:3:56: rung R2 at rungs[1].ld[1].coil: undefined variable `Y`")
    );
    let d = &e.diagnostics()[0];
    assert_eq!(d.code(), "E0204");
    // The most precise node: the operand `"X"`, the coil's `"Y"`, the unknown key `"negate"`.
    let positions: Vec<_> = e
        .diagnostics()
        .iter()
        .map(|d| d.location.position)
        .collect();
    assert_eq!(positions, [Some((2, 41)), Some((3, 56)), Some((4, 46))]);
}

/// Every kind of node an error can name gives its own line and column: a variable's fields, a
/// rung's id and label, an element, an operand inside a branch, a FOR's fields, a subroutine,
/// an FBD block's pin and field.
#[test]
fn every_error_points_at_its_most_precise_node() {
    let cases: &[(&str, &str)] = &[
        (
            r#"{"program": "p", "vars": [
  {"name": "A", "type": "WSTRING"}], "rungs": [{"id": "R1", "ld": [{"ret": true}]}]}"#,
            "p.json:2:25: at vars[0].type: unknown type `WSTRING`",
        ),
        (
            r#"{"program": "p", "vars": [{"name": "A", "type": "BOOL", "init": 7}],
 "rungs": [{"id": "R1", "ld": [{"ret": true}]}]}"#,
            "p.json:1:65: at vars[0].init: the initial value needs BOOL, but `7` is a number",
        ),
        (
            r#"{"program": "p", "rungs": [{"id": "R1", "ld": [{"ret": true}]},
  {"id": "R1", "ld": [{"ret": true}]}]}"#,
            "p.json:2:10: rung R1 at rungs[1].id: rung id `R1` is used twice",
        ),
        (
            r#"{"program": "p", "rungs": [{"id": "R1", "label": "9x", "ld": [{"ret": true}]}]}"#,
            "p.json:1:50: rung R1 at rungs[0].label: `9x` is not a valid name",
        ),
        (
            r#"{"program": "p", "vars": [{"name": "A", "type": "BOOL"}], "rungs": [
  {"id": "R1", "ld": [{"or": [[{"contact": "A"}], [{"coil": "A"}]]}]}]}"#,
            "p.json:2:52: rung R1 at rungs[0].ld[0].or[1][0]: this element is not allowed inside `or`",
        ),
        (
            r#"{"program": "p", "vars": [{"name": "B", "type": "BOOL"}], "rungs": [
  {"id": "R1", "ld": [{"for": {"var": "B", "from": 1, "to": 2}}]},
  {"id": "R2", "ld": [{"next": true}]}]}"#,
            "p.json:2:39: rung R1 at rungs[0].ld[0].for.var: a FOR index needs an integer (SINT … LINT, USINT … ULINT)",
        ),
        (
            r#"{"program": "p", "rungs": [{"id": "R1", "ld": [{"ret": true}]}],
 "subroutines": {"1S": {"rungs": [{"id": "S", "ld": [{"ret": true}]}]}}}"#,
            "p.json:2:24: at subroutines.1S: `1S` is not a valid name",
        ),
        (
            r#"{"program": "p", "rungs": [{"id": "R1", "ld": [{"contact": 5, "x": 1}]}]}"#,
            "p.json:1:63: rung R1 at rungs[0].ld[0].x: unknown field `x` in a contact",
        ),
        // Found by the FBD lowering, on the model: the pin, not the network or the body.
        (
            r#"{"program": "p", "vars": [{"name": "X", "type": "INT"}],
 "fbd": {"networks": [{"id": "N1", "blocks": [
   {"id": 1, "op": "GT", "in": ["X", 5]},
   {"id": 2, "op": "ADD", "in": ["X", {"from": 1}], "out": "X"}]}]}}"#,
            "p.json:4:39: network N1 block 2 at fbd.networks[0].blocks[1].in[1]: an arithmetic block needs INT",
        ),
        (
            r#"{"program": "p", "vars": [{"name": "X", "type": "INT"}],
 "fbd": {"networks": [{"id": "N1", "blocks": [
   {"id": 1, "op": "JMP", "label": "L9", "cond": true}]}]}}"#,
            "p.json:3:27: network N1 block 1 at fbd.networks[0].blocks[0].label: undefined label `L9`",
        ),
    ];
    for (text, want) in cases {
        let got = err(text).in_file("p.json").to_string();
        assert!(got.starts_with(want), "{got}\n  wanted {want}");
    }
}

#[test]
fn a_byte_order_mark_is_skipped() {
    let text =
        "\u{feff}{\"program\": \"p\", \"rungs\": [{\"id\": \"R1\", \"ld\": [{\"ret\": true}]}]}";
    assert_eq!(program_from_json(text).expect("loads").rungs().len(), 1);
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
    let (p, fbd) = plc_deps::load::program_and_fbd_from_json(text).expect("loads");
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

/// A configuration is checked against the program once it resolves: each name, and each
/// instance's program (a POU that can run); a malformed one is refused where `serde_json`
/// stops in it. Each error is located at the value it names.
#[test]
fn a_configuration_that_does_not_fit_is_refused_where_it_goes_wrong() {
    let program = |conf: &str| {
        format!(
            "{{\"program\": \"p\", \"rungs\": [{{\"id\": \"R1\", \"ld\": [{{\"call\": \"S\"}}]}}],\n \"subroutines\": {{\"S\": {{\"rungs\": [{{\"id\": \"S1\", \"ld\": [{{\"ret\": true}}]}}]}}}},\n \"interrupts\": {{\"I\": {{\"rungs\": [{{\"id\": \"I1\", \"ld\": [{{\"ret\": true}}]}}]}}}},\n \"configuration\": {conf}}}"
        )
    };
    let ok = r#"{"name": "K", "resources": [{"name": "R", "tasks": [
   {"name": "T", "priority": 1, "instances": [{"name": "s", "program": "S"}]},
   {"name": "U", "interval": null, "instances": [{"name": "m", "program": "p"}]}]}]}"#;
    let p = program_from_json(&program(ok)).expect("loads");
    // Tasks in run order: by priority.
    let c = p.configuration().expect("kept");
    let tasks: Vec<(&str, u32)> = c.resources[0]
        .tasks
        .iter()
        .map(|t| (t.name.as_str(), t.priority))
        .collect();
    assert_eq!(tasks, [("U", 0), ("T", 1)]);
    let cases: &[(&str, &str, &str)] = &[
        (
            r#"{"name": "K", "resources": [{"name": "R", "instances": [
   {"name": "i", "program": "I"}]}]}"#,
            "p.json:5:18: at configuration.resources[0].instances[0].program: program instance `i` runs `I`, which is not a program or subroutine of this file (they are p, S)",
            "E0309",
        ),
        (
            r#"{"name": "K", "resources": [{"name": "R", "tasks": [
   {"name": "T 1"}]}]}"#,
            "p.json:5:5: at configuration.resources[0].tasks[0].name: `T 1` is not a valid name (letters, digits and _, not starting with a digit)",
            "E0105",
        ),
        (
            r#"{"name": "K", "resources": [{"name": "R", "tasks": [
   {"name": "T", "cycle": "T#1s"}]}]}"#,
            "p.json:5:24: at configuration: unknown field `cycle`, expected one of `name`, `priority`, `interval`, `single`, `instances`",
            "E0309",
        ),
        (
            r#"{"name": "K", "resources": [{"name": "R", "tasks": [
   {"name": "T", "priority": -1}]}]}"#,
            "p.json:5:31: at configuration: invalid value: integer `-1`, expected u32",
            "E0309",
        ),
    ];
    for (conf, expected, code) in cases {
        let e = err(&program(conf));
        assert_eq!(e.in_file("p.json").to_string(), *expected, "{conf}");
        assert_eq!(e.diagnostics()[0].code(), *code);
    }
}
