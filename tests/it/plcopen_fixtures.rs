//! Runs of the real LD exports of `tests/plcopen/` with inputs, checked against what each
//! program is for, worked out by hand from its diagram (the expected rows are in the comments).

use crate::common;
use crate::plcopen_common;

use common::cli::{root, tmp};
use plcopen_common::{run_inputs, trace_columns};

/// Runs fixture `file` one scan per row of `inputs` with `--cycle cycle`; each of `columns`
/// after each scan, from the trace.
fn run(file: &str, cycle: &str, inputs: &str, columns: &[&str]) -> Vec<String> {
    let xml = std::fs::read_to_string(root().join("tests/plcopen").join(file)).unwrap();
    let tag = file.trim_end_matches(".xml");
    let tr = tmp(&format!("{tag}-trace.csv"));
    run_inputs(
        tag,
        &xml,
        inputs,
        &["--cycle", cycle, "--trace", tr.to_str().unwrap()],
    );
    trace_columns(&tr, columns)
        .into_iter()
        .map(|values| values.concat())
        .collect()
}

#[test]
fn assemblyarea_sorts_a_plastic_part_for_the_timer_and_counts_it() {
    // A non-metal part at the sorting area (scan 0) latches the sort solenoid (seal-in through
    // sortSol) until TON0 (3.5 s, 7 scans of 500 ms) fires sortTimeOut in scan 7; that edge
    // counts CTUD0 up, so QEmpty (CV <= 0) falls; in scan 8 the timeout releases the latch and
    // the timer resets. A metal part (scan 9) is not sorted (11 scans).
    let mut rows = String::from("sortArea,sortAreaMetal\n1,0\n");
    for _ in 1..9 {
        rows.push_str("0,0\n");
    }
    rows.push_str("1,1\n0,0\n");
    let got = run(
        "assemblyarea__plc.xml",
        "500ms",
        &rows,
        &["sortSol", "sortTimeOut", "QEmpty", "ChainConv"],
    );
    assert_eq!(got[0], "11111111000", "sortSol");
    assert_eq!(got[1], "00000001000", "sortTimeOut");
    assert_eq!(got[2], "11111110000", "QEmpty");
    assert_eq!(got[3], "11111111111", "the conveyors run always (alwaysON)");
}

#[test]
fn mixer_fills_mixes_for_the_pulse_and_drains() {
    // START with the tank low starts the pumps (SR0), held after START is released, stopped by
    // H_LEVEL. START with the tank full starts TP0 (8 s = 8 scans of 1 s) and the mixer motor
    // (SR1, reset by the falling edge of TP0.Q in scan 11). START again with the motor off
    // opens the valve (RS0), held until L_LEVEL falls.
    let rows = "START,STOP,L_LEVEL,H_LEVEL\n\
        1,0,1,0\n0,0,1,0\n0,0,1,1\n1,0,1,1\n\
        0,0,1,1\n0,0,1,1\n0,0,1,1\n0,0,1,1\n0,0,1,1\n0,0,1,1\n0,0,1,1\n0,0,1,1\n\
        1,0,1,1\n0,0,1,0\n0,0,0,0\n";
    let got = run(
        "mixer-with-lld__plc.xml",
        "1s",
        rows,
        &["PUMP_1", "MIXER_MOTOR", "VALVE"],
    );
    assert_eq!(got[0], "110000000000000", "PUMP_1");
    assert_eq!(got[1], "000111111110000", "MIXER_MOTOR");
    assert_eq!(got[2], "000000000000110", "VALVE");
}

#[test]
fn llf_actuators_drives_relay_0_from_opto_0_and_holds_the_others() {
    // RELAY_00 := OPTO_00; every other rung is a relay's contact on its own coil (it holds).
    let got = run(
        "llf-actuators__plc.xml",
        "10ms",
        "OPTO_00\n0\n1\n1\n0\n",
        &["RELAY_00", "RELAY_05"],
    );
    assert_eq!(got[0], "0110");
    assert_eq!(got[1], "0000");
}
