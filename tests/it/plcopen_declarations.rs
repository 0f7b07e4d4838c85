//! What real Beremiz, OpenPLC and CODESYS exports declare, read as their toolchains read it
//! (tests/plcopen_decl/*.xml, hand-written): every literal form with its exact value, function
//! block instances with initial values, enumerations with named values, subranges and
//! enumerations declared in place, qualifiers, and types nobody defines as black boxes.
//!
//! The values are worked out from IEC 61131-3 (6.3.3 Table 8 durations, 6.3.4 Table 9 dates,
//! 6.3.2 typed and based literals, 6.4.4.2 enumerations, 6.5.1.4 instance initial values) and
//! matiec (`iec_flex.ll` for the duration grammar, `__date_to_timespec` for a date's seconds).

use crate::common;
use crate::plcopen_common as px;

use common::cli::{error_line, run, run_stdin};
use px::{json_output, line_col, project_in, trace};
use serde_json::json;

fn file(name: &str) -> String {
    format!("tests/plcopen_decl/{name}")
}

/// The outputs after one scan of `run --mode both` (sequential and parallel, checked equal).
fn outputs(name: &str) -> serde_json::Value {
    let f = file(name);
    let (v, _) = json_output(
        &[
            "run", &f, "--scans", "1", "--mode", "both", "--format", "json",
        ],
        "",
    );
    v["outputs"].clone()
}

#[test]
fn every_literal_form_has_its_exact_value() {
    let v = outputs("literals.xml");
    assert_eq!(
        v,
        json!({
            "lamp": false,
            // Durations (Table 8; `_` between units as matiec's lexer allows), in ms.
            "t1": 5_400_000,        // T#1h_30m = 90 min
            "t2": 1,                // T#0D_0H_0M_0S_1MS
            "t3": 1500,             // T#1.5s
            "t4": -250,             // T#-250ms
            "t5": 120_000,          // TIME#2m
            "t6": 1500,             // LTIME#1s_500ms, LTIME read as TIME
            "t7": 2,                // t#2000us
            "t8": 86_400_000,       // Time#1d
            // Dates: seconds since 1970-01-01 (matiec's tv_sec); 2024-01-31 is day 19753.
            "d1": 1_706_659_200,    // D#2024-01-31
            "d2": 86_400,           // DATE#1970-01-02
            // Times of day: ms since midnight.
            "tod1": 45_015_500,     // TOD#12:30:15.5
            "tod2": 1000,           // TIME_OF_DAY#00:00:01
            "dt1": 1_706_702_400,   // DT#2024-01-31-12:00:00 = day 19753 + 43200 s
            "dt2": 60,              // DATE_AND_TIME#1970-01-01-00:01:00
            // Typed and based literals (6.3.2).
            "i1": 5,                // INT#5
            "b1": 255,              // 16#FF
            "b2": 165,              // 2#1010_0101
            "i2": 15,               // 8#17
            "x1": true,             // BOOL#1
            "r1": 1.5,              // REAL#1.5
            "r2": 1000.0,           // 1.0E3
            "w1": 65535,            // WORD#16#ffff
            "l1": -0.015,           // LREAL#-1.5E-2
            "i3": -1000             // DINT#-1_000
        })
    );
}

#[test]
fn enumerations_with_named_values_subranges_and_library_enumerations() {
    // MODE: IDLE := 1, RUNNING := 5, STOPPED (one more: 6), FAULT := 16#10. A variable without
    // an initial value starts at the first value (IDLE = 1); `MODE#STOPPED` is the typed form.
    // LOGLEVEL is Beremiz's (NativeLib.xml: CRITICAL, WARNING, INFO, DEBUG := INFO), which the
    // file names without defining: DEBUG is 3, the default INFO 2. In place: (RED, GREEN := 5,
    // BLUE) makes BLUE 6; INT (-5..5) := -3.
    assert_eq!(
        outputs("enums.xml"),
        json!({"lamp": false, "m": 5, "m2": 1, "m3": 6, "m4": 16, "LEVEL": 3, "LEVEL2": 2, "c": 6, "s": -3})
    );
}

#[test]
fn retain_persistent_constant_and_temp_lists_are_accepted() {
    let f = file("qualifiers.xml");
    let (v, _) = json_output(
        &[
            "run", &f, "--scans", "1", "--mode", "both", "--format", "json",
        ],
        "",
    );
    assert_eq!(v["state"]["K"], json!(7));
    assert_eq!(v["state"]["tmp"], json!(0));
    assert_eq!(v["state"]["keep"], json!(2_147_483_647));
}

#[test]
fn an_instance_initial_value_feeds_the_unconnected_inputs_of_its_fbd_calls() {
    // T0 := (PT := T#30ms), its block has no PT pin; T1 := (pt := T#0s_20ms), its PT pin is
    // listed but not connected (the member matched in any case); T2's PT is wired to the
    // literal T#0S_40MS and its declared T#1h does not apply. IN is TRUE from scan 0 (t = 0,
    // 10 ms a scan): a TON's Q rises when ET reaches PT (IEC 61131-3 Table 46).
    let inputs = "go\n1\n1\n1\n1\n1\n";
    let f = std::fs::read_to_string(file("fb_init_fbd.xml")).unwrap();
    let t = trace(
        "decl-fb-init-fbd",
        &f,
        inputs,
        &["lamp", "lamp2", "lamp3", "T0.PT", "T1.PT", "T2.PT"],
    );
    assert_eq!(t[0], ["0", "0", "0", "1", "1"], "PT 30 ms");
    assert_eq!(t[1], ["0", "0", "1", "1", "1"], "PT 20 ms");
    assert_eq!(t[2], ["0", "0", "0", "0", "1"], "PT 40 ms");
    assert_eq!(t[3], ["30"; 5]);
    assert_eq!(t[4], ["20"; 5]);
    assert_eq!(t[5], ["40"; 5]);
}

#[test]
fn an_instance_initial_value_feeds_an_ld_box_without_its_pin() {
    let inputs = "go\n1\n1\n1\n1\n";
    let f = std::fs::read_to_string(file("fb_init_ld.xml")).unwrap();
    let t = trace("decl-fb-init-ld", &f, inputs, &["lamp", "T0.PT"]);
    assert_eq!(t[0], ["0", "0", "1", "1"], "PT 20 ms");
    assert_eq!(t[1], ["20"; 4]);
}

#[test]
fn an_instance_initial_value_of_an_output_is_refused_by_run_by_name() {
    let f = file("fb_init_output.xml");
    let text = std::fs::read_to_string(&f).unwrap();
    let out = run(&["run", &f, "--scans", "1"]);
    let err = error_line(&out, "run");
    assert_eq!(
        err,
        format!("error: {f}:{}: at run: pou P: the initial value of `T0.Q`: `Q` is not an input of TON (the model gives an instance's inputs their declared values, nothing else); so `run` cannot execute the LD body of `P`", line_col(&text, "<simpleValue value=\"TRUE\""))
    );
    // The analysis reads it all the same.
    assert_eq!(run(&["report", &f]).status.code(), Some(0));
}

#[test]
fn a_type_nobody_defines_is_a_black_box_that_run_refuses_by_name() {
    let f = file("unknown_type.xml");
    let text = std::fs::read_to_string(&f).unwrap();
    let (r, warnings) = json_output(&["report", &f, "--format", "json"], "");
    assert!(
        warnings.contains("types that the file names and nobody defines (an editor's library types?) are read as black boxes: JSONVAR: P.doc;"),
        "{warnings}"
    );
    assert_eq!(r["program"], json!("P"));
    let err = error_line(&run(&["run", &f, "--scans", "1"]), "run");
    assert_eq!(
        err,
        format!("error: {f}:{}: at run: pou P: variable `doc` is of type `JSONVAR`, which the file does not define (a black box without a value), so `run` cannot execute `P`", line_col(&text, "<variable name=\"doc\""))
    );
}

/// The one error of `report` on a program whose output `v` of `ty` starts at `init`.
fn literal_error(ty: &str, init: &str) -> (String, String) {
    let xml = project_in(
        "LD",
        &[("outputVars", "v", ty)],
        "<leftPowerRail localId=\"1\"><connectionPointOut formalParameter=\"\"/></leftPowerRail>",
    );
    let tag = if ty == "BOOL" || ty == "INT" || ty == "DINT" || ty == "REAL" || ty == "TIME" {
        format!("<{ty}/>")
    } else {
        format!("<derived name=\"{ty}\"/>")
    };
    let xml = xml.replace(
        &format!("<type>{tag}</type>"),
        &format!(
            "<type><{ty}/></type><initialValue><simpleValue value=\"{init}\"/></initialValue>"
        ),
    );
    let err = error_line(&run_stdin(&["report", "-"], xml.as_bytes()), init);
    (err, xml)
}

#[test]
fn malformed_literals_are_one_located_error() {
    // Two `_` in a row, a unit after a trailing `_`, a day that does not exist, an hour 24, a
    // fraction of a second in a DT (not whole seconds), a duration finer than a millisecond.
    for (ty, init) in [
        ("TIME", "T#1h__30m"),
        ("TIME", "T#1h_"),
        ("DATE", "D#2023-02-29"),
        ("TOD", "TOD#24:00:00"),
        ("DT", "DT#2024-01-01-00:00:00.5"),
        ("TIME", "T#1500us"),
    ] {
        let (err, xml) = literal_error(ty, init);
        let at = line_col(&xml, "<simpleValue");
        assert!(
            err.starts_with(&format!("error: <stdin>:{at}: ")),
            "{init}: {err}"
        );
        assert!(err.contains(&format!("`{init}`")), "{init}: {err}");
    }
}

#[test]
fn a_ctu_cv_feeding_an_ld_out_variable_is_assigned_not_a_contact() {
    // CU rising on scans 0, 2, 4, 6 (go 1, 0, 1, 0 …): CV counts 1, 1, 2, 2, 3, 3 and stays at
    // 3, and Q rises when CV reaches PV = 3 (matiec's CTU counts while CV < PV, lib/counter.txt:
    // the file is a Beremiz export, docs/dialects.md); `count` is CV after the box.
    let inputs = "go\n1\n0\n1\n0\n1\n0\n1\n";
    let f = std::fs::read_to_string(file("ld_ctu_cv.xml")).unwrap();
    let t = trace("decl-ctu-cv", &f, inputs, &["count", "lamp"]);
    assert_eq!(t[0], ["1", "1", "2", "2", "3", "3", "3"]);
    assert_eq!(t[1], ["0", "0", "0", "0", "1", "1", "1"]);
}

#[test]
fn a_structure_passed_whole_into_a_function_block_input_feeds_its_fields() {
    // q := (x := 3, y := 4) into F's input p : PT2, whose body adds p.x and p.y.
    assert_eq!(
        outputs("struct_whole_input.xml"),
        json!({"total": 7, "f0.s": 7})
    );
}

#[test]
fn pin_names_in_any_case_and_codesys_positional_operator_pins() {
    // ADD(In1 := a, In2 := b) with a = INT#5, b = 16#10: 21. MUX(K := k, In0 := a, in1 := b):
    // a when k = 0, b when k = 1 (IEC 61131-3 Table 31). TON(in := go, Pt := T#20ms): Q at
    // 20 ms.
    let inputs = "go,k\n1,0\n1,1\n1,1\n";
    let f = std::fs::read_to_string(file("codesys_pins.xml")).unwrap();
    let t = trace("decl-pins", &f, inputs, &["sum", "sel", "lamp"]);
    assert_eq!(t[0], ["21", "21", "21"]);
    assert_eq!(t[1], ["5", "16", "16"]);
    assert_eq!(t[2], ["0", "0", "1"]);
}

#[test]
fn codesys_local_ids_up_to_2_to_the_64_and_not_s_in1() {
    // localIds 2^64 - 1, 2^32 - 1 and 2^63 (TC6 `xsd:unsignedLong`); NOT's pin written In1.
    let f = file("codesys_local_ids.xml");
    let text = std::fs::read_to_string(&f).unwrap();
    let inputs = "go\n1\n0\n";
    let t = trace("decl-ids", &text, inputs, &["lamp"]);
    assert_eq!(t[0], ["0", "1"]);
    let (_, warnings) = json_output(&["report", &f, "--format", "json"], "");
    assert!(
        warnings.contains("localIds beyond 4294967295 are renumbered (the model numbers blocks in 32 bits), and messages name them so: 18446744073709551615 → 4294967294, 9223372036854775808 → 4294967293"),
        "{warnings}"
    );
}
