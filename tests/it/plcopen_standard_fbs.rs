//! The standard function blocks SR, RS, R_TRIG, F_TRIG and CTUD (IEC 61131-3 2nd ed.,
//! 2.5.2.3) in hand-written PLCopen TC6 XML, with their standard pin names: as LD boxes (power in
//! S1 / S / CLK / CU, power out Q1 / Q / QU) and as FBD blocks, run scan by scan and reported.

use crate::common;
use crate::plcopen_common as px;

use px::{
    block, coil, contact, in_var, io, project, project_in, rail, report, rung, trace, var_in,
};

/// A coil on output `pin` of block `from`.
fn coil_on(id: u32, var: &str, from: u32, pin: &str) -> String {
    format!("<coil localId=\"{id}\"><connectionPointIn><connection refLocalId=\"{from}\" formalParameter=\"{pin}\"/></connectionPointIn><connectionPointOut/><variable>{var}</variable></coil>")
}

/// R1: s → SR B (R := r) → q1; R2: clk → R_TRIG E → pulse; R3: up → CTUD C (CD := down,
/// R := clr, LD := FALSE, PV := 2) → full.
fn ld_boxes() -> String {
    let ld = [
        rail(1),
        contact(2, "s", &[1], ""),
        in_var(3, "r"),
        block(
            4,
            "SR",
            Some("B"),
            &[("S1", &[(2, None)]), ("R", &[(3, None)])],
            &["Q1"],
        ),
        coil_on(5, "q1", 4, "Q1"),
        contact(6, "clk", &[1], ""),
        block(7, "R_TRIG", Some("E"), &[("CLK", &[(6, None)])], &["Q"]),
        coil(8, "pulse", &[7], ""),
        contact(9, "up", &[1], ""),
        in_var(10, "down"),
        contact(11, "clr", &[1], ""),
        in_var(12, "FALSE"),
        in_var(13, "2"),
        block(
            14,
            "CTUD",
            Some("C"),
            &[
                ("CU", &[(9, None)]),
                ("CD", &[(10, None)]),
                ("R", &[(11, None)]),
                ("LD", &[(12, None)]),
                ("PV", &[(13, None)]),
            ],
            &["QU", "QD", "CV"],
        ),
        coil_on(15, "full", 14, "QU"),
    ]
    .concat();
    project(
        &[
            ("inputVars", "s", "BOOL"),
            ("inputVars", "r", "BOOL"),
            ("inputVars", "clk", "BOOL"),
            ("inputVars", "up", "BOOL"),
            ("inputVars", "down", "BOOL"),
            ("inputVars", "clr", "BOOL"),
            ("outputVars", "q1", "BOOL"),
            ("outputVars", "pulse", "BOOL"),
            ("outputVars", "full", "BOOL"),
            ("localVars", "B", "SR"),
            ("localVars", "E", "R_TRIG"),
            ("localVars", "C", "CTUD"),
        ],
        &ld,
    )
}

#[test]
fn sr_r_trig_and_ctud_boxes_in_rungs_read_and_write_their_instances() {
    assert_eq!(
        io(&report(&ld_boxes())),
        vec![
            rung("P.R1", &["s", "r", "B"], &["q1", "B"]),
            rung("P.R2", &["clk", "E"], &["pulse", "E"]),
            rung("P.R3", &["up", "down", "clr", "C"], &["full", "C"]),
        ]
    );
}

#[test]
fn sr_r_trig_and_ctud_boxes_in_rungs_run_as_the_standard_defines_them() {
    let inputs = "s,r,clk,up,down,clr\n1,0,1,1,0,0\n0,0,1,0,0,0\n0,1,0,1,0,0\n1,1,1,0,1,0\n0,0,0,1,0,0\n0,0,0,0,0,1\n";
    let got = trace("std-ld", &ld_boxes(), inputs, &["q1", "pulse", "full"]);
    // SR: set in scan 0, held, reset in scan 2; set and reset together: set wins.
    assert_eq!(got[0], ["1", "1", "0", "1", "1", "1"]);
    // R_TRIG: one scan for each rising edge of clk (scans 0 and 3).
    assert_eq!(got[1], ["1", "0", "0", "1", "0", "0"]);
    // CTUD: CV 1, 1, 2, 1, 2, then R clears it; QU is CV >= 2.
    assert_eq!(got[2], ["0", "0", "1", "0", "1", "0"]);
}

/// FBD: q1 := RS(S := s, R1 := r).Q1; fall := F_TRIG(CLK := clk).Q.
fn fbd_blocks() -> String {
    let body = [
        in_var(1, "s"),
        in_var(2, "r"),
        block(
            3,
            "RS",
            Some("B"),
            &[("S", &[(1, None)]), ("R1", &[(2, None)])],
            &["Q1"],
        ),
        var_in("outVariable", 4, "q1", (3, Some("Q1"))),
        in_var(5, "clk"),
        block(6, "F_TRIG", Some("F"), &[("CLK", &[(5, None)])], &["Q"]),
        var_in("outVariable", 7, "fall", (6, Some("Q"))),
    ]
    .concat();
    project_in(
        "FBD",
        &[
            ("inputVars", "s", "BOOL"),
            ("inputVars", "r", "BOOL"),
            ("inputVars", "clk", "BOOL"),
            ("outputVars", "q1", "BOOL"),
            ("outputVars", "fall", "BOOL"),
            ("localVars", "B", "RS"),
            ("localVars", "F", "F_TRIG"),
        ],
        &body,
    )
}

#[test]
fn rs_and_f_trig_blocks_in_fbd_run_as_the_standard_defines_them() {
    let inputs = "s,r,clk\n1,0,1\n0,0,1\n1,1,0\n0,0,0\n";
    let got = trace("std-fbd", &fbd_blocks(), inputs, &["q1", "fall"]);
    // RS: set, held, set and reset together: reset wins.
    assert_eq!(got[0], ["1", "1", "0", "0"]);
    // F_TRIG: the falling edge of clk in scan 2.
    assert_eq!(got[1], ["0", "0", "1", "0"]);
}

#[test]
fn an_output_of_a_standard_box_other_than_its_power_output_is_read_after_it_in_ld() {
    let xml = ld_boxes().replace(
        "formalParameter=\"QU\"/></connectionPointIn><connectionPointOut/><variable>full",
        "formalParameter=\"QD\"/></connectionPointIn><connectionPointOut/><variable>full",
    );
    // The coil on QD reads the instance's field after the box (tests/it/plcopen_ld_pins.rs runs it).
    let out = common::cli::run_stdin(&["convert", "-"], xml.as_bytes());
    assert_eq!(out.status.code(), Some(0));
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(text.contains("\"C.QD\""), "{text}");
}
