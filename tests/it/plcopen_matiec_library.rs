//! matiec's library blocks beyond the standard ones the model has (the typed counters of
//! `lib/counter.txt`; INTEGRAL, DERIVATIVE, PID, RAMP, HYSTERESIS of `lib/*_st.txt`; SEMA of
//! `lib/sema.txt`), which the PLCopen reader adds as ST POUs when a project uses them and does
//! not define them (crates/plc-read/src/plcopen/matiec_lib.rs). The programs of
//! tests/matiec_library/ call them in ST, as FBD blocks and as LD boxes; the values below are
//! worked out by hand from matiec's definitions (the files and lines named at each test, matiec
//! at 6bb2c339), sequential and parallel equal after every scan (`--mode both`), and the C of
//! `plc-deps c` equal to the interpreter after every scan. TIME_TO_REAL is in seconds (matiec's
//! `__time_to_real`), as these Beremiz projects' dialect says (docs/dialects.md).

use crate::common::cli::run;
use crate::st_exec::{c_equals_run, run_json};
use serde_json::{json, Value};

/// The state of `names` after `scans` scans.
fn state(file: &str, scans: u32, csv: Option<&str>, names: &[&str]) -> Vec<Value> {
    let v = run_json(file, scans, csv);
    names.iter().map(|n| v["state"][*n].clone()).collect()
}

/// REAL values compared to 1e-5 (REAL is single precision: 0.1 added three times is
/// 0.3000000x).
fn assert_reals(got: &[Value], want: &[f64], what: &str) {
    assert_eq!(got.len(), want.len());
    for (g, w) in got.iter().zip(want) {
        let g = g
            .as_f64()
            .unwrap_or_else(|| panic!("{what}: {g} is not a number"));
        assert!((g - w).abs() < 1e-5, "{what}: got {got:?}, want {want:?}");
    }
}

#[test]
fn typed_counters_count_past_int_and_stop_at_their_limits_in_st() {
    let f = "tests/matiec_library/counters_st.xml";
    // lib/counter.txt: CTU_DINT (lines 52-72) counts a rising edge of CU while CV < PV, R
    // clears CV and wins; Q := CV >= PV. CTD_UDINT (225-245): LD loads PV and wins, a rising
    // edge of CD takes one off while CV > 0; Q := CV <= 0. CTUD_LINT (the CTUD_ of 276-):
    // R, else LD, else an edge of CU alone counts up while CV < PV, of CD alone down while
    // CV > 0; QU := CV >= PV, QD := CV <= 0.
    // x toggles, TRUE in odd scans: CU/CD rise in scans 1, 3, 5, …
    // c1: PV 100000, R in scan 3: CV 1, 1, 0 (R wins over the edge), 0, 1, 1, 2, …
    // c2: PV 2, LD in scan 1: CV 2, 2, 1, 1, 0 (Q), 0, 0 (an UDINT at 0 is not counted down).
    // c3 (R left out of the call: FALSE, its initial value, IEC 61131-3 6.6.1.2): PV
    // 5 000 000 000 (beyond DINT), LD in scan 1: 5e9 (QU); CD rises in scans 3 and 5:
    // 4 999 999 999, 4 999 999 998; CU from scan 6 rises in 7 and 9: back to 5e9, then kept.
    let names = ["cv1", "q1", "cv2", "q2", "cv3", "qu3", "qd3"];
    let expect: [(u32, [Value; 7]); 7] = [
        (
            1,
            [
                json!(1),
                json!(false),
                json!(2),
                json!(false),
                json!(5_000_000_000i64),
                json!(true),
                json!(false),
            ],
        ),
        (
            3,
            [
                json!(0),
                json!(false),
                json!(1),
                json!(false),
                json!(4_999_999_999i64),
                json!(false),
                json!(false),
            ],
        ),
        (
            5,
            [
                json!(1),
                json!(false),
                json!(0),
                json!(true),
                json!(4_999_999_998i64),
                json!(false),
                json!(false),
            ],
        ),
        (
            6,
            [
                json!(1),
                json!(false),
                json!(0),
                json!(true),
                json!(4_999_999_998i64),
                json!(false),
                json!(false),
            ],
        ),
        (
            7,
            [
                json!(2),
                json!(false),
                json!(0),
                json!(true),
                json!(4_999_999_999i64),
                json!(false),
                json!(false),
            ],
        ),
        (
            9,
            [
                json!(3),
                json!(false),
                json!(0),
                json!(true),
                json!(5_000_000_000i64),
                json!(true),
                json!(false),
            ],
        ),
        (
            11,
            [
                json!(4),
                json!(false),
                json!(0),
                json!(true),
                json!(5_000_000_000i64),
                json!(true),
                json!(false),
            ],
        ),
    ];
    for (scans, want) in expect {
        assert_eq!(state(f, scans, None, &names), want, "after scan {scans}");
    }
    // Edges in scans 5, 7, …, 65539: 32768 counts, past INT's 32767 (a CTU's INT CV stops at
    // its PV, at most 32767).
    assert_eq!(
        state(f, 65540, None, &["cv1", "q1"]),
        [json!(32768), json!(false)]
    );
    c_equals_run(f, 9, None);
}

#[test]
fn integral_derivative_pid_ramp_hysteresis_and_sema_follow_matiecs_definitions_in_st() {
    let f = "tests/matiec_library/blocks_st.xml";
    // n = 1, 2, …; xr = 2n.
    // INTEGRAL (lib/integral_st.txt, body lines 27-31): Q := NOT R1; R1: XOUT := X0; else RUN:
    // XOUT += XIN * CYCLE (s). XIN 1.0, CYCLE 100 ms, RUN except in scan 4, R1 in scan 5
    // (X0 2.0): 0.1, 0.2, 0.3, 0.3, 2.0 (Q FALSE), 2.1, 2.2.
    // DERIVATIVE (lib/derivative_st.txt, 22-29): RUN from scan 2, CYCLE 0.5 s. Scan 1: 0 and
    // X1 = X2 = X3 = 2. Then XOUT = (3 (XIN - X3) + X1 - X2) / 5: scan 2 (3·2 + 0)/5 = 1.2,
    // scan 3 (3·4 + 4 - 2)/5 = 2.8, scan 4 (3·6 + 6 - 4)/5 = 4.0, then 4.0 (slope 2 / 0.5 s).
    // PID (lib/pid_st.txt, 28-33): SP 5, X0 1, KP 2, TR 0.5, TD 0.25, CYCLE 0.5 s, AUTO from
    // scan 3; ERROR = xr - 5. Manual: XOUT = KP X0 = 2.0 (scans 1, 2; the integrator preset to
    // TR (X0 - ERROR): 1.0 in scan 2, and the derivative's history -1). Scan 3: ERROR 1,
    // I = 1.0 + 0.5 = 1.5, D = (3 (1 + 1) + 0)/5 = 1.2: 2 (1 + 3 + 0.3) = 8.6. Scan 4: ERROR 3,
    // I 3.0, D (3·4 + 1 + 1)/5 = 2.8: 2 (3 + 6 + 0.7) = 19.4. Scan 5: ERROR 5, I 5.5, D 4.0:
    // 2 (5 + 11 + 1) = 34.
    // RAMP (lib/ramp_st.txt, 29-37): X0 1, X1 5, TR 2 s, CYCLE 0.5 s, RUN from scan 2. Scan 1
    // tracks X0: 1.0; scans 2-5 ramp from T = 0, 0.5, 1, 1.5 s: 1, 2, 3, 4 (BUSY); scan 6 T =
    // 2 s >= TR: 5.0, BUSY FALSE.
    // HYSTERESIS (lib/hysteresis_st.txt, 13-15): XIN2 7, EPS 1: rises above 8, falls below 6.
    // h = 7.5, 8.0 (not above), 8.5 (TRUE), 6.0 (not below: kept), 5.0 (FALSE), 7.0.
    // SEMA (lib/sema.txt, 26-27): CLAIM in scans 2 and 5, RELEASE in 4 and 5: BUSY F, T, T, F,
    // T (CLAIM wins), T.
    let reals = ["ix", "dx", "px", "rx"];
    let bools = ["iq", "busy", "hq", "sq"];
    let expect: [(u32, [f64; 4], [bool; 4]); 7] = [
        (1, [0.1, 0.0, 2.0, 1.0], [true, false, false, false]),
        (2, [0.2, 1.2, 2.0, 1.0], [true, true, false, true]),
        (3, [0.3, 2.8, 8.6, 2.0], [true, true, true, true]),
        (4, [0.3, 4.0, 19.4, 3.0], [true, true, true, false]),
        (5, [2.0, 4.0, 34.0, 4.0], [false, true, false, true]),
        (6, [2.1, 4.0, 52.0, 5.0], [true, false, false, true]),
        (7, [2.2, 4.0, 74.0, 5.0], [true, false, false, true]),
    ];
    for (scans, r, b) in expect {
        assert_reals(
            &state(f, scans, None, &reals),
            &r,
            &format!("after scan {scans}"),
        );
        let b: Vec<Value> = b.iter().map(|x| json!(x)).collect();
        assert_eq!(state(f, scans, None, &bools), b, "after scan {scans}");
    }
    c_equals_run(f, 7, None);
}

/// An informal call binds its arguments in declaration order, the inputs first and then the
/// outputs (matiec's `generate_c_st.cc`, `fb_invocation_c`: each parameter in turn takes the
/// next informal value, and an output's is assigned after the call): `pid2(n >= 3, xr, …,
/// T#500ms, px2)` is `pid1`'s formal call with `XOUT => px2`, so `px2` is `px` after every scan.
#[test]
fn an_informal_call_binds_the_inputs_then_the_outputs() {
    let f = "tests/matiec_library/blocks_st.xml";
    for scans in 1..=5 {
        let s = state(f, scans, None, &["px", "px2"]);
        assert_eq!(s[0], s[1], "after scan {scans}");
        assert_ne!(
            s[0],
            json!(0.0),
            "after scan {scans}: the PID's output is not 0"
        );
    }
}

#[test]
fn library_blocks_run_as_fbd_blocks() {
    let (f, csv) = (
        "tests/matiec_library/blocks_fbd.xml",
        "tests/matiec_library/blocks_fbd.csv",
    );
    // cu = 1, 0, 1, 0, 1; x = 7.5, 8.5, 6.5, 5.5, 6.0 (blocks_fbd.csv).
    // CTU_DINT (PV 100000, R unconnected: FALSE): CV 1, 1, 2, 2, 3.
    // HYSTERESIS (XIN2 7, EPS 1): FALSE, TRUE (8.5 > 8), TRUE, FALSE (5.5 < 6), FALSE.
    // INTEGRAL (RUN = cu, XIN = x, CYCLE 100 ms, R1 unconnected): 0.75, 0.75, 1.4, 1.4, 2.0.
    let expect = [
        (1, 1, false, 0.75),
        (2, 1, true, 0.75),
        (3, 2, true, 1.4),
        (4, 2, false, 1.4),
        (5, 3, false, 2.0),
    ];
    for (scans, cv, hq, ix) in expect {
        let v = state(f, scans, Some(csv), &["cv1", "hq", "ix"]);
        assert_eq!(v[..2], [json!(cv), json!(hq)], "after scan {scans}");
        assert_reals(&v[2..], &[ix], &format!("after scan {scans}"));
    }
    c_equals_run(f, 5, Some(csv));
}

#[test]
fn library_blocks_run_as_ld_boxes() {
    let (f, csv) = (
        "tests/matiec_library/blocks_ld.xml",
        "tests/matiec_library/blocks_ld.csv",
    );
    // blocks_ld.csv: cd = 0, 1, 0, 1, 0, 1, 0, 1; ld in scan 1; claim in 2 and 5, release in
    // 4 and 5. CTD_UDINT (PV 2): CV 2, 1, 1, 0 (Q), 0, 0, 0, 0. SEMA: F, T, T, F, T, T, T, T.
    let expect = [
        (1, 2, false, false),
        (2, 1, false, true),
        (3, 1, false, true),
        (4, 0, true, false),
        (5, 0, true, true),
        (8, 0, true, true),
    ];
    for (scans, cv, q, busy) in expect {
        assert_eq!(
            state(f, scans, Some(csv), &["cv2", "q2", "busy"]),
            [json!(cv), json!(q), json!(busy)],
            "after scan {scans}"
        );
    }
    c_equals_run(f, 8, Some(csv));
}

#[test]
fn a_projects_own_pid_wins_over_the_librarys() {
    let f = "tests/matiec_library/own_pid.xml";
    // The project's PID is XOUT := KP * (SP - PV) = 3 (4 - 1) = 9 (matiec's would be
    // KP * (PV - SP + …), negative here); the library's INTEGRAL integrates it, 9 per 1 s
    // cycle: 9, 18.
    assert_reals(&state(f, 1, None, &["y", "z"]), &[9.0, 9.0], "scan 1");
    assert_reals(&state(f, 2, None, &["y", "z"]), &[9.0, 18.0], "scan 2");
    let out = run(&["report", f]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{err}");
    assert!(
        err.contains("matiec's library blocks): INTEGRAL (lib/integral_st.txt)\n"),
        "{err}"
    );
    assert!(!err.contains("PID (lib/pid_st.txt)"), "{err}");
    c_equals_run(f, 2, None);
}

#[test]
fn the_report_analyses_library_blocks_like_user_function_blocks() {
    let out = run(&["report", "tests/matiec_library/blocks_st.xml"]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{err}");
    // One note names the blocks added (PID brings INTEGRAL and DERIVATIVE, already used), at
    // the first use; nothing is said about the library's own bodies.
    assert!(err.contains("INTEGRAL (lib/integral_st.txt), DERIVATIVE (lib/derivative_st.txt), PID (lib/pid_st.txt), RAMP (lib/ramp_st.txt), HYSTERESIS (lib/hysteresis_st.txt), SEMA (lib/sema.txt)\n  --> tests/matiec_library/blocks_st.xml:8:55\n"), "{err}");
    assert!(!err.contains("pou PID"), "{err}");
    let text = String::from_utf8_lossy(&out.stdout);
    // The rungs of the library bodies, per instance, are in the schedule: PID's own calls of
    // its INTEGRAL and DERIVATIVE instances included.
    for r in [
        "i1:INTEGRAL.st1",
        "pid1:PID.st2",
        "pid1.ITERM:INTEGRAL.st1",
        "pid1.DTERM:DERIVATIVE.st1",
        "r1:RAMP.st1",
        "h1:HYSTERESIS.st1",
        "s1:SEMA.st1",
    ] {
        assert!(text.contains(r), "{r} in {text}");
    }
}

#[test]
fn codesys_projects_do_not_get_matiecs_library() {
    // CODESYS's and TwinCAT's libraries have their own blocks of these names (CODESYS's Util
    // PID has other pins): in their dialect (docs/dialects.md) an undefined INTEGRAL stays an
    // undefined type, which `run` refuses by name.
    let xml = std::fs::read_to_string(
        crate::common::cli::root().join("tests/matiec_library/own_pid.xml"),
    )
    .unwrap()
    .replace("productName=\"Beremiz\"", "productName=\"CODESYS\"");
    let (_, err) = crate::plcopen_common::report_and_warnings(&xml);
    assert!(!err.contains("matiec's library"), "{err}");
    let out = crate::common::cli::run_stdin(&["run", "-"], xml.as_bytes());
    let e = crate::st_exec::refusal(&out, "run");
    assert!(
        e.contains("variable `i1` is of type `INTEGRAL`, which the file does not define"),
        "{e}"
    );
}
