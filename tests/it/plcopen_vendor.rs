//! What editors write beyond the TC6 standard elements, read as the toolchain the file was
//! made for reads it (issue 39): POUs that CODESYS and TwinCAT keep in vendor data (`addData`),
//! CODESYS `vendorElement`s in FBD bodies, types and blocks a file names and nobody defines
//! (black boxes), Beremiz C pragmas in ST, and misreadings that ended in false errors.
//!
//! Each case is a small hand-written file of `tests/plcopen_vendor/` (not a corpus file).
//! Where the file runs, it runs without `--allow-skipped`, with `--mode both` (seq == par after
//! every scan), and its generated C gives the interpreter's state after every scan; where it
//! cannot run, `run` and `c` refuse it naming the POU and the construct.

use crate::common;
use crate::plcopen_semantics::c_matches_interpreter;

use std::path::PathBuf;
use std::process::Output;

fn path(name: &str) -> PathBuf {
    common::cli::root().join("tests/plcopen_vendor").join(name)
}

/// `plc-deps report FILE`: must succeed; its standard error (the warnings) on one line.
fn warnings(name: &str) -> String {
    let p = path(name);
    let out = common::cli::run(&["report", p.to_str().unwrap()]);
    let err = common::cli::one_line(&String::from_utf8_lossy(&out.stderr));
    assert_eq!(out.status.code(), Some(0), "{name}: {err}");
    err
}

/// Runs `name` one scan per row of `csv` (no `--allow-skipped`), `--mode both`, which must find
/// seq == par; checks the C against the interpreter; returns each of `columns` after each scan.
fn scans(name: &str, csv: &str, columns: &[&str]) -> Vec<Vec<String>> {
    let p = path(name);
    let tag = format!("vendor-{}", name.trim_end_matches(".xml"));
    let inputs = common::cli::tmp(&format!("{tag}.csv"));
    std::fs::write(&inputs, csv).unwrap();
    let tr = common::cli::tmp(&format!("{tag}-trace.csv"));
    let out = common::cli::run(&[
        "run",
        p.to_str().unwrap(),
        "--inputs",
        inputs.to_str().unwrap(),
        "--format",
        "json",
        "--mode",
        "both",
        "--trace",
        tr.to_str().unwrap(),
    ]);
    let err = common::cli::one_line(&String::from_utf8_lossy(&out.stderr));
    assert_eq!(out.status.code(), Some(0), "{name}: {err}");
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(
        v["identical"],
        serde_json::json!(true),
        "{name}: seq != par"
    );
    let xml = std::fs::read_to_string(&p).unwrap();
    let rows = csv.lines().count() as u64 - 1;
    c_matches_interpreter(&xml, csv, rows, &tag);
    crate::plcopen_common::trace_columns(&tr, columns)
}

/// `plc-deps CMD FILE` must fail with exit 2; its standard error on one line.
fn refused(cmd: &str, name: &str) -> String {
    let p = path(name);
    let dir = common::cli::tmp(&format!("vendor-{cmd}-{name}.out"));
    let mut args = vec![cmd, p.to_str().unwrap()];
    if cmd == "c" {
        args.extend(["--output", dir.to_str().unwrap()]);
    }
    let out: Output = common::cli::run(&args);
    let err = common::cli::one_line(&String::from_utf8_lossy(&out.stderr));
    assert_eq!(out.status.code(), Some(2), "{cmd} {name}: {err}");
    err
}

fn col(v: &[&str]) -> Vec<String> {
    v.iter().map(|s| s.to_string()).collect()
}

#[test]
fn twincat_pous_and_resource_in_application_data_are_read_and_run() {
    // types/pous and instances are empty; MAIN and the GVL are in addData. Y := A * 2 and
    // Over := Y > Limit (Limit = 10 from the GVL): A = 3 gives 6, FALSE; A = 7 gives 14, TRUE.
    let w = warnings("twincat_adddata_pous.xml");
    assert!(w.contains("POUs read from vendor data"), "{w}");
    assert!(w.contains("resource is read from vendor data"), "{w}");
    assert!(!w.contains("vendor data (addData) ignored"), "{w}");
    let t = scans("twincat_adddata_pous.xml", "A\n3\n7\n", &["Y", "Over"]);
    assert_eq!(t[0], col(&["6", "14"]), "Y");
    assert_eq!(t[1], col(&["0", "1"]), "Over");
}

#[test]
fn codesys_programs_in_resource_data_are_read_and_run() {
    // PLC_PRG (in the resource's addData, run by MainTask through `typeName=""`) calls the
    // function block Twice of types/pous: Y = A + A.
    let w = warnings("codesys_resource_pous.xml");
    assert!(w.contains("PLC_PRG"), "{w}");
    let t = scans("codesys_resource_pous.xml", "A\n3\n-4\n", &["Y"]);
    assert_eq!(t[0], col(&["6", "-8"]), "Y");
}

#[test]
fn a_codesys_vendor_element_is_skipped_with_a_note_and_positional_pins_are_read() {
    // The vendorElement (FBD implementation attributes) is wired to nothing: skipped, named by
    // its localId. SUB's In1, In2 and Out1 are IN1, IN2 and OUT; MUX's In1, In2, In3 are K,
    // IN0, IN1 (IEC 61131-3 2.5.1.5.6: MUX(K, IN0, IN1) selects IN<K>). Y = A - B;
    // Z = (K = 0 ? A - B : B).
    let w = warnings("vendor_element_fbd.xml");
    assert!(
        w.contains(
            "vendorElement localId 10000000000 (`FBD Implementation Attributes`) is skipped"
        ),
        "{w}"
    );
    let t = scans(
        "vendor_element_fbd.xml",
        "A,B,K\n5,3,0\n5,3,1\n-2,7,0\n",
        &["Y", "Z"],
    );
    assert_eq!(t[0], col(&["2", "2", "-9"]), "Y");
    assert_eq!(t[1], col(&["2", "3", "-9"]), "Z");
}

#[test]
fn a_wired_vendor_element_is_refused_naming_its_local_id() {
    let e = refused("report", "vendor_element_wired.xml");
    assert!(
        e.contains("vendor_element_wired.xml:22:9")
            && e.contains("vendorElement localId 10000000000")
            && e.contains("is wired into the body"),
        "{e}"
    );
}

#[test]
fn a_black_box_output_that_feeds_nothing_is_read_as_bool_with_a_warning() {
    // csv_reload is defined nowhere in the file: a black box. ACK feeds nothing (BOOL, said by
    // the warning); RESULT feeds the INT R, so it is INT. `run` does not compute the black box:
    // R keeps RESULT's initial value 0.
    let w = warnings("black_box_output.xml");
    assert!(
        w.contains("csv_reload is read as a black box")
            && w.contains("writing its outputs ACK BOOL, RESULT INT")
            && w.contains("feed nothing, whose type nothing in the file tells, are read as BOOL: ACK (localId 2)"),
        "{w}"
    );
    let t = scans("black_box_output.xml", "Go\n1\n0\n", &["R"]);
    assert_eq!(t[0], col(&["0", "0"]), "R");
}

#[test]
fn a_member_of_an_undefined_library_type_is_a_black_box_and_the_rest_runs() {
    // MSG_T.topic is of CODESYS's JSONVAR, which the export does not carry: one whole variable
    // without a value. P1 reads only m.qos (INT, initial 0) and P2 adds 1 to A: both run.
    let w = warnings("library_type_member.xml");
    assert!(
        w.contains("JSONVAR → DINT (a type that neither the file nor plc-deps defines (a library type: a black box)")
            && w.contains("P1.m.topic"),
        "{w}"
    );
    let t = scans(
        "library_type_member.xml",
        "P2:A\n4\n-1\n",
        &["P1:Q", "P2:Y"],
    );
    assert_eq!(t[0], col(&["0", "0"]), "P1:Q");
    assert_eq!(t[1], col(&["5", "0"]), "P2:Y");
}

#[test]
fn a_c_pragma_is_a_statement_that_reads_and_writes_everything_and_run_refuses_it() {
    // `{{ … }}` (C code with braces of its own, closed by the first `}}` as matiec's lexer
    // closes it) and `{ … }` are statements; a `(* (* *)` comment closes at its first `*)`
    // (matiec without -n). The IF holding the pragma reads and writes every variable of P
    // but the input IN (the scan writes it), and so does the lone pragma.
    let p = path("c_pragma_st.xml");
    let out = common::cli::run(&["report", p.to_str().unwrap(), "--format", "json"]);
    assert_eq!(out.status.code(), Some(0));
    let r: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let io = crate::plcopen_common::io(&r);
    assert_eq!(
        io,
        vec![
            crate::plcopen_common::rung("P.st1", &["IN", "Done"], &["Done"]),
            crate::plcopen_common::rung("P.st2", &["IN", "OUT", "Done"], &["OUT", "Done"]),
            crate::plcopen_common::rung("P.st3", &["IN", "OUT", "Done"], &["OUT", "Done"]),
            crate::plcopen_common::rung("P.st4", &["Done"], &["Done"]),
        ]
    );
    let w = common::cli::one_line(&String::from_utf8_lossy(&out.stderr));
    assert!(
        w.contains("statement 2 (at 17:1) holds a pragma")
            && w.contains("statement 3 (at 23:1) holds a pragma"),
        "{w}"
    );
    for cmd in ["run", "c"] {
        let e = refused(cmd, "c_pragma_st.xml");
        assert!(
            e.contains("pou P: its ST body is not executed: a pragma `{…}`")
                && e.contains("at 18:1"),
            "{cmd}: {e}"
        );
    }
}

#[test]
fn a_variable_of_an_undefined_enumeration_with_an_initial_value_is_no_instance() {
    // `MODE : OPMODE := AUTO`: OPMODE is not in the file. A simple initial
    // value makes it no function block instance (IEC 61131-3 6.5.1.4: an instance's is
    // structured): a black box variable, its value not read; P declares it, so `run` refuses P
    // by name (the black box has no value).
    let w = warnings("library_enum_init.xml");
    assert!(
        w.contains(
            "OPMODE → DINT (a type the file does not define, given the simple initial value `AUTO`"
        ) && w.contains("read as black boxes: OPMODE: P.MODE"),
        "{w}"
    );
    let e = refused("run", "library_enum_init.xml");
    assert!(
        e.contains("variable `MODE` is of type `OPMODE`, which the file does not define"),
        "{e}"
    );
}

#[test]
fn codesys_qualified_type_names_and_enumeration_values_are_read() {
    // `Standard.TON` is the standard TON (CODESYS's namespace of its standard library);
    // `E_MODE.Auto` is E_MODE#Auto (= 1). T1 (PT 20 ms, CODESYS dialect) sets Q once 20 ms have
    // passed since IN rose: at the third scan (0, 10, 20 ms).
    let t = scans("codesys_qualified.xml", "Go\n1\n1\n1\n1\n", &["Y", "M"]);
    assert_eq!(t[0], col(&["0", "0", "1", "1"]), "Y");
    assert_eq!(t[1], col(&["1", "1", "1", "1"]), "M");
}

#[test]
fn a_codesys_pointer_is_a_black_box_that_run_refuses_by_name() {
    // POINTER TO INT: an address plc-deps does not follow; the analysis sees `p` as one whole
    // variable, `run` refuses the POU naming it.
    let w = warnings("codesys_pointer.xml");
    assert!(w.contains("POINTER_TO_INT: PLC_PRG.p"), "{w}");
    let e = refused("run", "codesys_pointer.xml");
    assert!(
        e.contains("variable `p` is of type `POINTER_TO_INT`, which the file does not define"),
        "{e}"
    );
}

#[test]
fn of_two_configurations_the_first_is_read_with_a_warning_naming_the_other() {
    // Lab runs PLC_LAB (Y := A + 1); Virtual's PLC_VIRT is a POU no task runs (W0203).
    let p = path("two_configurations.xml");
    let out = common::cli::run(&["report", p.to_str().unwrap()]);
    let raw = String::from_utf8_lossy(&out.stderr);
    assert!(
        raw.contains("warning[W0502]: the project has 2 configurations"),
        "{raw}"
    );
    let w = warnings("two_configurations.xml");
    assert!(
        w.contains("the project has 2 configurations")
            && w.contains("reads one: `Lab`, the first in the file; not read: `Virtual`")
            && w.contains("--configuration NAME")
            && w.contains("subroutine PLC_VIRT is never called"),
        "{w}"
    );
    let t = scans(
        "two_configurations.xml",
        "PLC_LAB:A\n3\n-4\n",
        &["PLC_LAB:Y"],
    );
    assert_eq!(t[0], col(&["4", "-3"]), "PLC_LAB:Y");
}

#[test]
fn configuration_chooses_the_configuration_that_report_and_run_read() {
    let p = path("two_configurations.xml");
    let p = p.to_str().unwrap();
    // Any case, as IEC names are.
    let out = common::cli::run(&["report", p, "--configuration", "virtual"]);
    let err = common::cli::one_line(&String::from_utf8_lossy(&out.stderr));
    assert_eq!(out.status.code(), Some(0), "{err}");
    assert!(
        !err.contains("W0502") && err.contains("subroutine PLC_LAB is never called"),
        "{err}"
    );
    let report = String::from_utf8(out.stdout).unwrap();
    assert!(
        report.contains("Tasks of configuration Virtual")
            && report.contains("the only program instance: MainTask.PLC_VIRT"),
        "{report}"
    );
    // Z := B * Factor, Factor = 3 from Virtual's own global list.
    let inputs = common::cli::tmp("vendor-two-configurations.csv");
    std::fs::write(&inputs, "PLC_VIRT:B\n2\n-5\n").unwrap();
    let tr = common::cli::tmp("vendor-two-configurations-trace.csv");
    let out = common::cli::run(&[
        "run",
        p,
        "--configuration",
        "Virtual",
        "--inputs",
        inputs.to_str().unwrap(),
        "--mode",
        "both",
        "--trace",
        tr.to_str().unwrap(),
    ]);
    let err = common::cli::one_line(&String::from_utf8_lossy(&out.stderr));
    assert_eq!(out.status.code(), Some(0), "{err}");
    let t = crate::plcopen_common::trace_columns(&tr, &["PLC_VIRT:Z"]);
    assert_eq!(t[0], col(&["6", "-15"]), "PLC_VIRT:Z");
}

#[test]
fn an_unknown_configuration_is_refused_listing_the_configurations() {
    let p = path("two_configurations.xml");
    let dir = common::cli::tmp("vendor-two-configurations-c.out");
    for args in [
        vec!["report", p.to_str().unwrap(), "--configuration", "Virtul"],
        vec!["run", p.to_str().unwrap(), "--configuration", "Virtul"],
        vec![
            "c",
            p.to_str().unwrap(),
            "--configuration",
            "Virtul",
            "--output",
            dir.to_str().unwrap(),
        ],
    ] {
        let out = common::cli::run(&args);
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{args:?}: {err}");
        assert!(
            err.contains("error[E0501]: --configuration Virtul: the project has no configuration of that name; its configurations are `Lab`, `Virtual`")
                && err.contains("did you mean `Virtual`?"),
            "{args:?}: {err}"
        );
    }
    // A JSON program is not a PLCopen project.
    let json = common::cli::root().join("analyses/example-a/program.json");
    let out = common::cli::run(&["report", json.to_str().unwrap(), "--configuration", "Lab"]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{err}");
    assert!(err.contains("is not a PLCopen project"), "{err}");
}

#[test]
fn an_action_called_from_st_runs_its_body_on_the_instance_and_not_the_main_body() {
    // Cyl's main body: Count := Count + 1; Pos := Count * 10. Extend: Pos := 100, Ext := TRUE.
    // Retract: Pos := -100, Ext := FALSE, Count := 0. P calls C.Extend() (Cmd = 1),
    // C.retract() (Cmd = 2, any case) or C(), and D() every scan. Cmd 0 0 1 0 2 0:
    // C: Count 1 2 2 3 0 1 (an action does not run the main body), Pos 10 20 100 30 -100 10,
    // Ext F F T T F F; D, another instance, counts on: Pos 10 … 60.
    let w = warnings("fb_actions_st.xml");
    assert!(
        w.contains("its actions Extend, Retract are part of the body")
            && !w.contains("not executed"),
        "{w}"
    );
    let t = scans(
        "fb_actions_st.xml",
        "Cmd\n0\n0\n1\n0\n2\n0\n",
        &["Y", "E", "Z", "C.Count"],
    );
    assert_eq!(t[0], col(&["10", "20", "100", "30", "-100", "10"]), "Y");
    assert_eq!(t[1], col(&["0", "0", "1", "1", "0", "0"]), "E");
    assert_eq!(t[2], col(&["10", "20", "30", "40", "50", "60"]), "Z");
    assert_eq!(t[3], col(&["1", "2", "2", "3", "0", "1"]), "C.Count");
}

#[test]
fn the_analysis_sees_what_an_action_reads_and_writes_through_the_instance_call() {
    // P.st1 calls C.Extend() or C.retract() or C(): it reads and writes what the actions do
    // (C.Ext, C.Count through Retract) as well as the main body.
    let p = path("fb_actions_st.xml");
    let out = common::cli::run(&["report", p.to_str().unwrap(), "--format", "json"]);
    assert_eq!(out.status.code(), Some(0));
    let r: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let io = crate::plcopen_common::io(&r);
    let st1 = io
        .iter()
        .find(|x| x.0 == "P.st1")
        .unwrap_or_else(|| panic!("{io:?}"));
    for v in ["C.Ext", "C.Pos", "C.Count"] {
        let outs = st1.2.as_array().unwrap();
        assert!(outs.iter().any(|w| w == v), "{v} not written: {st1:?}");
    }
    // The action's own rungs: Extend writes Pos and Ext of the instance.
    let ext: Vec<_> = io
        .iter()
        .filter(|x| x.0 == "C:Cyl.st3" || x.0 == "C:Cyl.st4")
        .collect();
    assert_eq!(ext.len(), 2, "{io:?}");
    assert!(
        ext[0].2 == serde_json::json!(["C.Pos"]) && ext[1].2 == serde_json::json!(["C.Ext"]),
        "{ext:?}"
    );
}
