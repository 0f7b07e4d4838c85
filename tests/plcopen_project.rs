//! PLCopen projects as wholes: tasks and program instances, ST bodies through their interface,
//! recognition by content, and what each of the editors' real files (tests/plcopen/, copied
//! from /work/shared/plcopen with their MANIFEST.md) gives today.

mod common;
#[path = "plcopen_common/mod.rs"]
mod px;

use common::cli::{one_line, run, run_stdin};
use px::{coil, contact, rail, NS};
use serde_json::Value;

fn pou(name: &str, var: (&str, &str), ld: &str) -> String {
    format!(
        "<pou name=\"{name}\" pouType=\"program\"><interface><localVars><variable name=\"{}\"><type><BOOL/></type></variable><variable name=\"{}\"><type><BOOL/></type></variable></localVars></interface><body><LD>{ld}</LD></body></pou>",
        var.0, var.1
    )
}

fn json_report(args: &[&str], stdin: &str) -> (Value, String) {
    let out = run_stdin(args, stdin.as_bytes());
    let err = one_line(&String::from_utf8_lossy(&out.stderr));
    assert_eq!(out.status.code(), Some(0), "{err}");
    (serde_json::from_slice(&out.stdout).unwrap(), err)
}

fn rung_ids(r: &Value) -> Vec<String> {
    r["rungs"]
        .as_array()
        .unwrap()
        .iter()
        .map(|x| x["id"].as_str().unwrap().to_owned())
        .collect()
}

#[test]
fn tasks_run_their_program_instances_in_priority_order() {
    let a = pou(
        "A",
        ("a", "x"),
        &[rail(1), contact(2, "a", &[1], ""), coil(3, "x", &[2], "")].concat(),
    );
    let b = pou(
        "B",
        ("b", "y"),
        &[rail(1), contact(2, "b", &[1], ""), coil(3, "y", &[2], "")].concat(),
    );
    let xml = format!(
        "<project xmlns=\"{NS}\"><types><pous>{a}{b}</pous></types><instances><configurations><configuration name=\"C\"><resource name=\"R\">\
         <task name=\"Slow\" priority=\"5\" interval=\"T#100ms\"><pouInstance name=\"ia\" typeName=\"A\"/></task>\
         <task name=\"Fast\" priority=\"1\" interval=\"T#10ms\"><pouInstance name=\"ib\" typeName=\"B\"/></task>\
         </resource></configuration></configurations></instances></project>"
    );
    let (r, err) = json_report(&["report", "-", "--format", "json"], &xml);
    assert_eq!(rung_ids(&r), ["Fast.B", "Slow.A", "A.R1", "B.R1"]);
    let col = xml.find("<resource").unwrap() + 1;
    assert_eq!(
        err.lines().filter(|l| l.starts_with("warning: ")).collect::<Vec<_>>(),
        [format!("warning: <stdin>:1:{col}: tasks Fast (T#10ms, priority 1), Slow (T#100ms, priority 5) run one after another in every scan (in priority order), not each at its own interval")]
    );
}

#[test]
fn an_st_body_is_analysed_through_its_interface_with_a_warning() {
    let (r, err) = json_report(
        &[
            "report",
            "tests/plcopen/e-cockpit-python-scripting__plc.xml",
            "--format",
            "json",
        ],
        "",
    );
    let rung = &r["rungs"][0];
    assert_eq!(rung["id"], "PLC_PRG.body");
    assert_eq!(rung["in"], serde_json::json!(["i"]));
    assert_eq!(rung["out"], serde_json::json!(["i"]));
    assert!(err.contains("warning: tests/plcopen/e-cockpit-python-scripting__plc.xml:36:11: pou PLC_PRG: its ST body is not read yet; it is analysed through its interface (inputs read; outputs, locals and externals written) and not executed by `run`"), "{err}");
    assert!(err.contains("warning: tests/plcopen/e-cockpit-python-scripting__plc.xml:16:5: vendor data (addData) ignored: http://www.3s-software.com/plcopenxml/projectinformation"), "{err}");
}

#[test]
fn a_program_is_recognised_by_its_content_not_its_extension() {
    let xml =
        std::fs::read_to_string(common::cli::root().join("tests/plcopen/llf-actuators__plc.xml"))
            .unwrap();
    let path = common::cli::tmp("actuators.json");
    std::fs::write(&path, xml).unwrap();
    for cmd in ["report", "order"] {
        let out = run(&[cmd, path.to_str().unwrap()]);
        assert_eq!(
            out.status.code(),
            Some(0),
            "{cmd}: {}",
            String::from_utf8_lossy(&out.stderr)
        );
    }
    let out = run(&[
        "run",
        path.to_str().unwrap(),
        "--scans",
        "3",
        "--format",
        "json",
    ]);
    assert_eq!(
        out.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
}

/// What each fixture gives: the rung count it loads with, or its one error (docs/plcopen.md).
#[test]
fn the_editors_files_load_or_say_exactly_why_not() {
    let expect: &[(&str, &str)] = &[
        ("assemblyarea__plc.xml", "86:17: at pou Assignment, localVars, variable CTUD0: variable `CTUD0` is an instance of the standard function block CTUD, which is not supported yet (supported: TON, TOF, TP, CTU, CTD)"),
        ("beremiz__exemples_first_steps_plc.xml", "22:11: at pou AverageVal, returnType: POU `AverageVal` is a function (it has a return type): functions are not supported yet"),
        ("beremiz__exemples_svghmi_traffic_light_plc.xml", "104:17: at pou traffic_light_sequence, localVars, variable R_TRIG0: variable `R_TRIG0` is an instance of the standard function block R_TRIG, which is not supported yet (supported: TON, TOF, TP, CTU, CTD)"),
        ("beremiz__old_tests_linux_test_master_DS401GUI_plc.xml", "98:17: at pou MAIN_TEST, localVars, variable DigitalOut: type BYTE of variable `DigitalOut` is not supported yet (supported: BOOL, INT, DINT, REAL, TIME, and function block types)"),
        ("beremiz__tests_projects_iec61131_lang_test_plc.xml", "25:17: at pou CONVERSION_TEST, outputVars, variable RESULT: type string of variable `RESULT` is not supported yet (supported: BOOL, INT, DINT, REAL, TIME, and function block types)"),
        ("beremiz__tests_projects_svghmi_plc.xml", "98:17: at pou MainStuff, localVars, variable R_TRIG0: variable `R_TRIG0` is an instance of the standard function block R_TRIG, which is not supported yet (supported: TON, TOF, TP, CTU, CTD)"),
        ("beremiz__tests_projects_wxHMI_plc.xml", "82:17: at pou main, localVars, variable PowerCtrl: variable `PowerCtrl` is an instance of the standard function block RS, which is not supported yet (supported: TON, TOF, TP, CTU, CTD)"),
        ("bottle-refiller__plc.xml", "108:17: at pou BottleRefill, localVars, variable first_bot_state_bit: type BYTE of variable `first_bot_state_bit` is not supported yet (supported: BOOL, INT, DINT, REAL, TIME, and function block types)"),
        ("e-cockpit-python-scripting__plc.xml", "loads: 1 rungs"),
        ("llf-actuators__plc.xml", "loads: 8 rungs"),
        ("mixer-with-lld__plc.xml", "83:17: at pou Mixer, localVars, variable PT_MIXER_MOTOR: type UINT of variable `PT_MIXER_MOTOR` is not supported yet (supported: BOOL, INT, DINT, REAL, TIME, and function block types)"),
        ("sail-plant-automation__plc.xml", "634:13: at pou program0, LD, block localId 14: block XOR (localId 14) is not supported in an LD body yet (supported: TON, TOF, TP, CTU, CTD, ADD, SUB, MUL, DIV, MOD, MOVE, EQ, NE, LT, LE, GT, GE)"),
    ];
    for (file, want) in expect {
        let path = format!("tests/plcopen/{file}");
        let out = run(&["report", &path, "--format", "json"]);
        let got = if out.status.code() == Some(0) {
            let r: Value = serde_json::from_slice(&out.stdout).unwrap();
            format!("loads: {} rungs", r["rungs"].as_array().unwrap().len())
        } else {
            assert_eq!(out.status.code(), Some(2), "{file}");
            let e = common::cli::error_line(&out, file);
            e.strip_prefix(&format!("error: {path}:"))
                .unwrap_or(&e)
                .to_owned()
        };
        assert_eq!(&got, want, "{file}");
    }
}
