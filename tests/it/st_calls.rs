//! PLCopen ST bodies executed, beyond the elementary statements of st_exec.rs: enumeration
//! values, function block instances' fields and calls (user and standard), whole structures
//! (crates/plc-read/src/plcopen/st_lower.rs and st_calls.rs). Each program of tests/st/ runs
//! to the values worked out by hand below from IEC 61131-3 (3rd ed.) and matiec's compilation
//! of the same ST, sequential and parallel equal after every scan (`--mode both`), and the C of
//! `plc-deps c` equal to the interpreter after every scan.

use crate::st_exec::{c_equals_run, pairs, run_json, values};
use serde_json::json;

#[test]
fn enumeration_values_are_their_integers_in_expressions_and_case_labels() {
    let f = "tests/st/enums.xml";
    // STATE = (IDLE, RUN := 5, HALT): IDLE 0, RUN 5, HALT 6 (a value without its own is one
    // more than the previous one's, IEC 61131-3 6.4.4.2, as matiec numbers them); COLOR#BLUE
    // is 2. s starts at IDLE (the first value). Scan 1: IDLE → s := RUN (5), n = 1; s = HALT is
    // false, k = 0. Scan 2: RUN → s := STATE#HALT (6), n = 11; s = HALT and c = BLUE <> RED:
    // k = 1. Scan 3: HALT → IDLE (0), n = 111. Scan 4: IDLE → RUN, n = 112.
    let expect = [(1, 5, 1, 0), (2, 6, 11, 1), (3, 0, 111, 1), (4, 5, 112, 1)];
    for (scans, s, n, k) in expect {
        let v = run_json(f, scans, None);
        assert_eq!(
            values(&v, &["s", "c", "n", "k"]),
            pairs(&[
                ("s", json!(s)),
                ("c", json!(2)),
                ("n", json!(n)),
                ("k", json!(k))
            ]),
            "after scan {scans}"
        );
    }
    c_equals_run(f, 4, None);
}

#[test]
fn user_function_block_instances_are_called_with_their_inputs_kept_between_calls() {
    let f = "tests/st/user_fbs.xml";
    // Acc: IF En THEN Sum := Sum + X; Big := Sum > 10. A is called with X := n, En := TRUE
    // every scan (n = 1, 2, …): Sum = 1, 3, 6, 10, 15 (Big from 15, scan 5). B gets X := 5 by
    // a write of its input, En := TRUE only in scan 1, and is called with no arguments: En keeps
    // TRUE (an instance's inputs are retained between calls, IEC 61131-3 6.6.1.2, as matiec's
    // instance structure keeps them), so Sum = 5, 10, 15, … (Big from 15, scan 3).
    let expect = [
        (1, 1, 5, false),
        (2, 3, 10, false),
        (3, 6, 15, true),
        (5, 15, 25, true),
    ];
    for (scans, s1, s2, big) in expect {
        let v = run_json(f, scans, None);
        assert_eq!(
            values(&v, &["s1", "s2", "big", "B.En", "A.Big"]),
            pairs(&[
                ("s1", json!(s1)),
                ("s2", json!(s2)),
                ("big", json!(big)),
                ("B.En", json!(true)),
                ("A.Big", json!(scans >= 5)),
            ]),
            "after scan {scans}"
        );
    }
    c_equals_run(f, 5, None);
}

#[test]
fn standard_function_block_calls_that_leave_inputs_out_use_their_last_values() {
    let f = "tests/st/std_inputs.xml";
    // Scan k runs at t = 10 (k - 1) ms. T1 gets IN := TRUE, PT := T#20ms in scan 1 only, then
    // `T1();` keeps both (IEC 61131-3 6.6.1.2): ET 0, 10, 20 and Q from scan 3 (t = 20). In
    // scan 6, after the call, `T1.IN := FALSE`: scan 7's call resets it (Q FALSE, ET 0), and
    // `in1 := T1.IN` reads TRUE until then. C1: PV := 3, CU := NOT CU toggles, so CU rises in
    // scans 1, 3, 5, 7: CV 1, 1, 2, 2, 3, 3, 3 (matiec's CTU counts while CV < PV), Q (CV >= PV)
    // from scan 5; R never given: FALSE.
    let expect = [
        (1, false, 0, true, 1),
        (2, false, 10, true, 1),
        (3, true, 20, true, 2),
        (5, true, 20, true, 3),
        (6, true, 20, true, 3),
        (7, false, 0, false, 3),
    ];
    for (scans, q, et, in1, cv) in expect {
        let v = run_json(f, scans, None);
        assert_eq!(
            values(&v, &["q", "et", "in1", "cv"]),
            pairs(&[
                ("q", json!(q)),
                ("et", json!(et)),
                ("in1", json!(in1)),
                ("cv", json!(cv)),
            ]),
            "after scan {scans}"
        );
        assert_eq!(
            v["state"]["C1"]["Q"],
            json!(scans >= 5),
            "after scan {scans}"
        );
    }
    c_equals_run(f, 7, None);
}

#[test]
fn a_whole_structure_assigned_copies_every_field() {
    let f = "tests/st/structs.xml";
    // c := b (b as the previous scan left it); a.x += 2, a.on toggles, a.t += 5 ms; b := a
    // copies x, on and t (IEC 61131-3 7.3.3.2.1). After scan k: a = b = (2k, k odd, 5k ms),
    // c = (2(k - 1), k even and k > 1, 5(k - 1) ms).
    for k in [1i64, 2, 3] {
        let v = run_json(f, k as u32, None);
        assert_eq!(
            values(&v, &["b.x", "b.on", "b.t", "c.x", "c.on", "c.t"]),
            pairs(&[
                ("b.x", json!(2 * k)),
                ("b.on", json!(k % 2 == 1)),
                ("b.t", json!(5 * k)),
                ("c.x", json!(2 * (k - 1))),
                ("c.on", json!(k % 2 == 0)),
                ("c.t", json!(5 * (k - 1))),
            ]),
            "after scan {k}"
        );
    }
    c_equals_run(f, 3, None);
}
