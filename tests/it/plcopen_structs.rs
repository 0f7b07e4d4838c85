//! PLCopen structures, hand-written (tests/plcopen_structs/*.xml): a variable of a structure
//! type is one model variable per elementary field (`m.On`, `plant.Motor.Speed`), so LD and FBD
//! bodies read and write exactly the field they name, `run` executes them with the fields'
//! initial values, and dependences are per field; ST reads a whole structure as all its fields;
//! an array field stays one whole variable; an unknown field is one located error.

use crate::common;
use crate::plcopen_common as px;

use common::cli::{error_line, run_stdin};
use px::{
    block, in_var, io, line_col, project_in, report, run_inputs, run_scans, rung, trace, var_in,
};
use serde_json::json;

fn fixture(name: &str) -> String {
    std::fs::read_to_string(common::cli::root().join(format!("tests/plcopen_structs/{name}.xml")))
        .unwrap()
}

/// `m.On := (start OR m.On) AND NOT stop; lamp := m.On` — worked out by hand: start in scan 1
/// latches the field, it holds in scan 2 without start, stop in scan 3 drops it; the untouched
/// field `m.Speed` keeps its declared initial value 5.
#[test]
fn a_structure_field_latched_by_a_coil_and_read_by_a_contact_runs() {
    let xml = fixture("struct_ld");
    let got = trace(
        "struct-ld",
        &xml,
        "start,stop\n1,0\n0,0\n0,1\n0,0\n",
        &["m.On", "lamp", "m.Speed"],
    );
    assert_eq!(
        got,
        vec![
            vec!["1", "1", "0", "0"],
            vec!["1", "1", "0", "0"],
            vec!["5", "5", "5", "5"],
        ]
    );
    let r = report(&xml);
    assert_eq!(
        io(&r),
        vec![
            rung("P.R1", &["start", "stop", "m.On"], &["m.On"]),
            rung("P.R2", &["m.On"], &["lamp"]),
        ]
    );
}

/// Target := ADD(Motor.Speed, 3) = 5 + 3; Twice := Motor.Speed * 2 = 10 (an expression);
/// Scaled := MUL(Motor.Target, Motor.Gain) = 8 * 4, Gain 4 from the variable's structured
/// initial value over the declaration's 1.
#[test]
fn an_int_field_through_add_in_fbd_runs() {
    let v = run_scans(&fixture("struct_fbd"), 1);
    assert_eq!(v["outputs"], json!({"Twice": 10, "Scaled": 32}));
    assert_eq!(v["state"]["Motor.Target"], json!(8));
    assert_eq!(v["state"]["Motor.Gain"], json!(4));
    assert_eq!(v["state"]["Motor.Speed"], json!(5));
}

/// Writing `plant.Motor.On` and reading `plant.Valve` are independent; reading
/// `plant.Motor.On` after the write is the one flow dependence. The nested structure's fields
/// start from the variable's structured initial value (Speed 7, Level -3) and the member's
/// declared one (Valve TRUE).
#[test]
fn nested_fields_have_exact_dependences_and_initial_values() {
    let xml = fixture("struct_nested");
    let r = report(&xml);
    assert_eq!(
        io(&r),
        vec![
            rung("P.R1", &["go"], &["plant.Motor.On"]),
            rung("P.R2", &["plant.Valve"], &["open"]),
            rung("P.R3", &["plant.Motor.On"], &["running"]),
        ]
    );
    assert_eq!(
        r["dependences"],
        json!([{"kind": "flow", "from": "P.R1", "to": "P.R3", "var": "plant.Motor.On"}])
    );
    let v = run_inputs("struct-nested", &xml, "go\n1\n", &[]);
    assert_eq!(v["outputs"], json!({"open": true, "running": true}));
    assert_eq!(
        [
            &v["state"]["plant.Motor.Speed"],
            &v["state"]["plant.Level"],
            &v["state"]["plant.Valve"]
        ],
        [&json!(7), &json!(-3), &json!(true)]
    );
}

/// A structure in a function block type's interface is a field of each instance (`d.st.On`):
/// the type's body writes its fields, the program reads them through the instance.
#[test]
fn a_structure_in_a_function_block_interface_is_a_field_of_each_instance() {
    let xml = fixture("struct_fb");
    let r = report(&xml);
    let rungs = io(&r);
    assert!(
        rungs.contains(&rung("d:Drive.2", &["d.go"], &["d.st.On"])),
        "{rungs:?}"
    );
    assert!(
        rungs.contains(&rung("d:Drive.4", &["d.cmd.Speed"], &["d.st.Speed"])),
        "{rungs:?}"
    );
    assert!(
        rungs.contains(&rung("P.4", &["d.st.On"], &["lamp"])),
        "{rungs:?}"
    );
    // start → d.go → d.st.On → lamp: Beremiz (PLCGenerator.ComputeProgram) writes the out
    // variables lamp and speed before it calls d (blocks after out variables), so lamp sees
    // d.st.On of the previous scan: TRUE after the second scan. d.st.Speed copies the input
    // structure's field, which nothing wires: its declared 5. The instance's outputs are
    // outputs too.
    let v = run_inputs("struct-fb", &xml, "start\n1\n1\n", &[]);
    assert_eq!(
        v["outputs"],
        json!({"lamp": true, "speed": 5, "d.st.On": true, "d.st.Speed": 5})
    );
}

/// A field the structure does not have is one error at the element that names it, with the
/// field and a hint; in ST, at the statement, with the structure's fields.
#[test]
fn an_unknown_field_is_one_located_error() {
    let xml = fixture("struct_unknown_field");
    let out = run_stdin(&["report", "-"], xml.as_bytes());
    assert_eq!(out.status.code(), Some(2));
    let err = String::from_utf8_lossy(&out.stderr);
    let at = line_col(&xml, "<contact localId=\"7\"");
    assert!(
        err.starts_with("error[E0204]: undefined variable `m.Onn`\n"),
        "{err}"
    );
    assert!(err.contains(&format!("--> <stdin>:{at}\n")), "{err}");
    assert!(err.contains("did you mean `m.On`?"), "{err}");
    assert_eq!(err.matches("error").count(), 1, "{err}");

    let st = fixture("struct_st").replace("n := a.Speed + 1;", "n := a.Sped + 1;");
    let e = error_line(
        &run_stdin(&["report", "-"], st.as_bytes()),
        "unknown ST field",
    );
    let at = line_col(&st, "n := a.Sped");
    assert_eq!(e, format!("error: <stdin>:{at}: at pou P, ST: `a.Sped`: structure `a` has no field `Sped` (its fields: Speed, On, Hist[1], Hist[2], Hist[3], Hist[4])"));
}

/// An array field is one whole variable without a value: the report reads the other fields
/// one by one, and `run` refuses the LD body, naming the field.
#[test]
fn an_array_field_is_one_variable_per_element_and_runs() {
    let xml = fixture("struct_array_field");
    let r = report(&xml);
    assert_eq!(
        io(&r),
        vec![
            rung("P.R1", &["start", "stop", "m.On"], &["m.On"]),
            rung("P.R2", &["m.On"], &["lamp"]),
        ]
    );
    // The array field of INT is scalarised (docs/plcopen.md, "Arrays"): the body runs.
    let v = run_scans(&xml, 1);
    assert_eq!(v["outputs"]["lamp"], json!(false), "{v}");
}

/// ST: a field is its variable (written whole, it is not read but for the stand-in's
/// may-write); `b := a` reads every field of `a` and writes every field of `b`; an array field
/// is one variable per element, and an element of a variable subscript may be any of them.
#[test]
fn st_reads_fields_and_whole_structures() {
    let r = report(&fixture("struct_st"));
    assert_eq!(
        io(&r),
        vec![
            rung("P.st1", &["a.On"], &["a.On"]),
            rung("P.st2", &["a.Speed", "n"], &["n"]),
            rung(
                "P.st3",
                &[
                    "a.Speed",
                    "a.On",
                    "a.Hist[1]",
                    "a.Hist[2]",
                    "a.Hist[3]",
                    "a.Hist[4]",
                    "b.Speed",
                    "b.On",
                    "b.Hist[1]",
                    "b.Hist[2]",
                    "b.Hist[3]",
                    "b.Hist[4]"
                ],
                &[
                    "b.Speed",
                    "b.On",
                    "b.Hist[1]",
                    "b.Hist[2]",
                    "b.Hist[3]",
                    "b.Hist[4]"
                ]
            ),
            // `a.Hist[i]`: the element `i` chooses may be any (docs/plcopen.md, "Arrays").
            rung(
                "P.st4",
                &["i", "a.Hist[1]", "a.Hist[2]", "a.Hist[3]", "a.Hist[4]", "n"],
                &["a.Hist[1]", "a.Hist[2]", "a.Hist[3]", "a.Hist[4]"]
            ),
            rung("P.st5", &["a.Speed"], &["a.Speed"]),
        ]
    );
}

/// A global structure named external by programs of two tasks: the fields are globals, and the
/// task-sharing list names the one field both tasks touch (`cell.Full`), not `cell.Count`,
/// which only one task reads and writes. A structure declared in place in a program's locals
/// is flattened as well (`Fill:pos.Busy`, a subroutine's local).
#[test]
fn global_structure_fields_are_shared_between_tasks_field_by_field() {
    let r = report(&fixture("struct_global"));
    assert_eq!(
        r["task_sharing"],
        json!([{"var": "cell.Full",
                "readers": [{"task": "Slow", "instance": "e", "program": "Empty"}],
                "writers": [{"task": "Fast", "instance": "f", "program": "Fill"},
                            {"task": "Slow", "instance": "e", "program": "Empty"}]}])
    );
    let rungs = io(&r);
    assert!(
        rungs.contains(&rung(
            "Fill.R1",
            &["Fill:sensor"],
            &["cell.Full", "Fill:pos.Busy"]
        )),
        "{rungs:?}"
    );
    assert!(
        rungs.contains(&rung(
            "Empty.st1",
            &["cell.Full", "cell.Count"],
            &["cell.Full", "cell.Count"]
        )),
        "{rungs:?}"
    );
}

/// A structure that contains itself is the cycle error of data types, at the type.
#[test]
fn a_structure_containing_itself_is_one_located_error() {
    let xml = fixture("struct_ld").replace(
        r#"<variable name="On"><type><BOOL/></type></variable>"#,
        r#"<variable name="On"><type><BOOL/></type></variable><variable name="Self"><type><derived name="MotorT"/></type></variable>"#,
    );
    let e = error_line(&run_stdin(&["report", "-"], xml.as_bytes()), "cycle");
    let at = line_col(&xml, "<dataType name=\"MotorT\"");
    assert_eq!(e, format!("error: <stdin>:{at}: at types/dataTypes, dataType MotorT: data type `MotorT` is defined through itself (a cycle of derived types)"));
}

/// An FBD counter whose loop closes through an in-out variable on a field (`c.n`, as Beremiz
/// closes its counter examples): `c.n := ADD(c.n, c.step)`, 3 scans from 10 by 2 (the
/// structure's declared initial values) give 16.
#[test]
fn a_counter_closes_its_loop_through_an_in_out_field() {
    let body = [
        in_var(1, "c.step"),
        block(
            2,
            "ADD",
            None,
            &[("IN1", &[(3, None)]), ("IN2", &[(1, None)])],
            &["OUT"],
        ),
        var_in("inOutVariable", 3, "c.n", (2, Some("OUT"))),
    ]
    .concat();
    let xml = project_in("FBD", &[("localVars", "c", "CounterT")], &body).replace(
        "<dataTypes/>",
        r#"<dataTypes><dataType name="CounterT"><baseType><struct><variable name="n"><type><INT/></type><initialValue><simpleValue value="10"/></initialValue></variable><variable name="step"><type><INT/></type><initialValue><simpleValue value="2"/></initialValue></variable></struct></baseType></dataType></dataTypes>"#,
    );
    let v = run_scans(&xml, 3);
    assert_eq!(v["state"]["c.n"], json!(16));
    assert_eq!(v["state"]["c.step"], json!(2));
}

/// The JSON format's dotted variable names (what `convert` writes for fields): a dotted name
/// whose first part is a variable or an instance of the scope (it would hide `T1.Q`), or a plain
/// name that is the first part of dotted names, is declared twice; an instance's name is never
/// dotted. So in a PLCopen POU, `m : MotorT` next to `m : INT` is still a duplicate.
#[test]
fn dotted_names_that_would_hide_another_are_declared_twice() {
    let json = |vars: &str| {
        format!(
            r#"{{"program": "x", "vars": [{vars}, {{"name": "a", "type": "BOOL"}}], "rungs": [{{"id": "R1", "ld": [{{"contact": "a"}}, {{"coil": "a"}}]}}]}}"#
        )
    };
    let first_error = |text: &str| {
        let out = run_stdin(&["report", "-"], text.as_bytes());
        assert_eq!(out.status.code(), Some(2));
        String::from_utf8_lossy(&out.stderr)
            .lines()
            .next()
            .unwrap()
            .to_owned()
    };
    assert_eq!(
        first_error(&json(
            r#"{"name": "T1", "type": "TON"}, {"name": "T1.Q", "type": "BOOL"}"#
        )),
        "error[E0203]: variable `T1.Q` is declared twice"
    );
    assert_eq!(
        first_error(&json(
            r#"{"name": "m.a", "type": "BOOL"}, {"name": "m", "type": "INT"}"#
        )),
        "error[E0203]: variable `m` is declared twice"
    );
    assert_eq!(
        first_error(&json(r#"{"name": "g.x", "type": "TON"}"#)),
        "error[E0105]: `g.x` is not a valid name (letters, digits and _, not starting with a digit)"
    );
    let twice = fixture("struct_ld").replace(
        r#"<variable name="stop"><type><BOOL/></type></variable>"#,
        r#"<variable name="stop"><type><BOOL/></type></variable><variable name="m"><type><INT/></type></variable>"#,
    );
    // The input `m` comes first (inputs before locals), then the local structure's field.
    assert_eq!(
        first_error(&twice),
        "error[E0203]: variable `m.Speed` is declared twice"
    );
}

/// The generated C of the structure fixtures (each field a member of the C state, its name
/// mangled) computes the interpreter's state after every scan: the project converted to the
/// JSON format, then compiled and compared scan by scan, with inputs that set and drop the
/// latch.
#[test]
fn the_c_of_structure_fields_agrees_with_the_interpreter() {
    let mut batch = common::c::Batch::default();
    for (name, csv) in [
        ("struct_ld", "start,stop\n1,0\n0,0\n0,1\n0,0\n1,1\n"),
        ("struct_fbd", ""),
        ("struct_nested", ""),
        ("struct_fb", ""),
    ] {
        let out = run_stdin(&["convert", "-"], fixture(name).as_bytes());
        assert_eq!(
            out.status.code(),
            Some(0),
            "{name}: {}",
            String::from_utf8_lossy(&out.stderr)
        );
        let json = String::from_utf8(out.stdout).unwrap();
        batch.add(
            json,
            csv.into(),
            6,
            plc_deps::codegen::c::CConfig::default(),
            name.into(),
        );
    }
    batch.check(1, "plcopen-structs");
}
