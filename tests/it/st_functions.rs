//! PLCopen ST bodies that call the project's own functions, give function block calls informal
//! arguments, and use STRINGs, executed (crates/plc-read/src/plcopen/st_functions.rs and
//! user_functions.rs). Each program of tests/st_functions/ runs to the values worked out by
//! hand below from IEC 61131-3 (3rd ed.) and from the C matiec generates for the same ST
//! (stage4/generate_c/generate_c.cc: a function's variables declared with their initial values
//! on every call, the result with its type's default; `if (!EN) return <result>;` before the
//! body; generate_c_inlinefcall.cc: an output `=>` copied back from a temporary holding the
//! target's own value, so untouched when EN is FALSE; generate_c_st.cc: a left-out input gets
//! its declared default), sequential and parallel equal after every scan, and the C of
//! `plc-deps c` equal to the interpreter after every scan. Recursion is refused by name.

use crate::common::cli::run;
use crate::st_exec::{c_equals_run, pairs, refusal, run_json, values};
use serde_json::{json, Value};

#[test]
fn user_functions_run_with_informal_formal_and_output_arguments_en_eno_and_nesting() {
    let f = "tests/st_functions/functions.xml";
    // n counts the scans. ADD3 := a + b + c; BUMP: VAR n := 10, n := n + x, BUMP := n;
    // DIVMOD := a / b, r := a MOD b; TWICE := ADD3(x, x, 0); ISPOS := x > 0;
    // KEEP (x := 5 declared) := x * 10 + y.
    let names = [
        "r1", "r2", "r3", "q", "rem", "r4", "r5", "ok", "rem2", "dummy", "p", "rem3", "r6",
    ];
    let expect = |n: i64| -> Vec<(&str, Value)> {
        let en = n > 1;
        vec![
            ("r1", json!(3 + n)),   // ADD3(1, 2, n), informal
            ("r2", json!(101 + n)), // ADD3(c := 100, a := n, b := 1), formal in any order
            // BUMP(n) + BUMP(1): its local n starts at 10 on every call (IEC 61131-3 6.6.2,
            // matiec declares it with its initial value in the C function), never accumulates.
            ("r3", json!(10 + n + 11)),
            ("q", json!(3)),   // DIVMOD(17, 5, r => rem): 17 / 5
            ("rem", json!(2)), // 17 MOD 5
            // ADD3(ADD3(1, 1, 1), TWICE(n), 2) + 2: nested calls and a function calling one.
            ("r4", json!(3 + 2 * n + 2 + 2)),
            // ADD3(EN := n > 1, …, ENO => ok) after r5 := 55: EN FALSE gives the result's
            // default, 0 (matiec returns the initialised result variable), ENO FALSE.
            ("r5", json!(if en { 6 } else { 0 })),
            ("ok", json!(en)),
            // DIVMOD(EN := n > 1, a := 9, b := 2, r => rem2) after rem2 := 77: EN FALSE leaves
            // the output's target as it was, the result 0.
            ("rem2", json!(if en { 1 } else { 77 })),
            ("dummy", json!(if en { 4 } else { 0 })),
            // IF ISPOS(n - 1) THEN p := p + 1: a BOOL function as a condition, TRUE from scan 2.
            ("p", json!(n - 1)),
            ("rem3", json!(1)), // DIVMOD(a := 7, b := 2, r => rem3); as a statement
            // KEEP(y := n) + KEEP(x := 1, y := 2): the left-out x is its declared 5 on every
            // call (matiec passes the input's default), not the 1 of the call before.
            ("r6", json!(50 + n + 12)),
        ]
    };
    for n in [1i64, 2, 3] {
        let v = run_json(f, n as u32, None);
        assert_eq!(values(&v, &names), pairs(&expect(n)), "after scan {n}");
        assert_eq!(v["fault_count"], json!(0));
    }
    c_equals_run(f, 3, None);
}

#[test]
fn informal_function_block_arguments_bind_in_declaration_order_and_a_function_writes_its_global() {
    let f = "tests/st_functions/calls.xml";
    // A(n, TRUE) is A(X := n, En := TRUE) (Acc's inputs in declaration order): Sum = 1, 3, 6.
    // T1(go, T#20ms) is TON's IN, PT; C1(go, FALSE, 2) CTU's CU, R, PV (IEC 61131-3 2.5.2.3).
    // go = n >= 2: T1 runs from scan 2 (t = 10 ms), ET 10 at scan 3; C1 counts the rise of
    // scan 2. TICK(0): g := g + 1 (the global, 100 at start), TICK := g * 10.
    let expect = [(1, 1, 0, 0, 101), (2, 3, 0, 1, 102), (3, 6, 10, 1, 103)];
    for (scans, sum, et, cv, g) in expect {
        let v = run_json(f, scans, None);
        assert_eq!(
            values(&v, &["A.Sum", "cv", "g", "t"]),
            pairs(&[
                ("A.Sum", json!(sum)),
                ("cv", json!(cv)),
                ("g", json!(g)),
                ("t", json!(g * 10)),
            ]),
            "after scan {scans}"
        );
        assert_eq!(v["state"]["T1"]["ET"], json!(et), "after scan {scans}");
        assert_eq!(v["state"]["T1"]["PT"], json!(20));
        assert_eq!(v["state"]["C1"]["PV"], json!(2));
    }
    c_equals_run(f, 3, None);
}

#[test]
fn the_analysis_sees_a_function_call_read_and_write_the_global_the_function_touches() {
    let out = run(&["report", "tests/st_functions/calls.xml", "--format", "json"]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let j: Value = serde_json::from_slice(&out.stdout).unwrap();
    let rung = |id: &str| {
        j["rungs"]
            .as_array()
            .unwrap()
            .iter()
            .find(|r| r["id"] == id)
            .cloned()
            .unwrap_or_else(|| panic!("no rung {id}"))
    };
    // `t := TICK(0);`: TICK's body reads and writes the global g; the statement writes t.
    let st6 = rung("P.st6");
    for (key, var) in [("in", "g"), ("out", "g"), ("out", "t")] {
        assert!(
            st6[key].as_array().unwrap().contains(&json!(var)),
            "P.st6 {key} lacks {var}: {st6}"
        );
    }
    // `n := n + 1;` touches no global.
    assert!(!rung("P.st1")["in"]
        .as_array()
        .unwrap()
        .contains(&json!("g")));
}

#[test]
fn strings_in_st_run_with_matiecs_texts() {
    let f = "tests/st_functions/strings.xml";
    let v = run_json(f, 1, None);
    // Texts as matiec's C library gives them (lib/C/iec_std_functions.h; tests/it/strings.rs).
    let expected = [
        ("b", json!("-42")),      // INT_TO_STRING(-42): "%d"
        ("c", json!("N=\t-42!")), // CONCAT('N=$T', b, '!'): $T is a tab (6.3.3)
        ("d", json!("OK")),       // '$4F$4b': $hh escapes
        ("l", json!(107)),        // LEN(c) = 7, + 100 as a = 'ab$'c' (a quote by $')
        ("same", json!(true)),    // d = 'OK'
        ("differ", json!(false)), // d <> 'OK'
        ("less", json!(false)),   // "ab'c" < "N=…": 'a' (97) > 'N' (78)
        ("e", json!("=\t-")),     // MID(c, 3, 2): L = 3 bytes from P = 2
        ("f", json!(5)),          // FIND(c, '4'): 1-based
        ("k", json!(-1)),         // STRING_TO_DINT('-1_234'): matiec restarts at '_'
        ("tb", json!(true)),      // STRING_TO_BOOL('True')
        // REPLACE(IN1 := a, IN2 := 'XY', L := 1, P := 2) by pin names: matiec's __replace
        // copies min(L, len(IN2)) = 1 byte of IN2: "aX'c"; then INSERT(r, LEFT(c, 2), 1)
        // puts "N=" after the first byte.
        ("r", json!("aN=X'c")),
    ];
    let names: Vec<&str> = expected.iter().map(|e| e.0).collect();
    assert_eq!(values(&v, &names), pairs(&expected));
    c_equals_run(f, 2, None);
}

#[test]
fn a_function_calling_itself_directly_or_through_another_is_refused_by_name() {
    let e = refusal(
        &run(&["run", "tests/st_functions/recursion.xml"]),
        "recursion",
    );
    assert!(
        e.contains("F → G → F") && e.contains("forbids recursion"),
        "{e}"
    );
    assert!(e.contains("recursion.xml:21:13"), "{e}");
    let e = refusal(&run(&["run", "tests/st_functions/self.xml"]), "self");
    assert!(
        e.contains("function `F` in its own body") && e.contains("forbids recursion"),
        "{e}"
    );
    let out = run(&["c", "tests/st_functions/self.xml", "-o", "/nonexistent/x"]);
    assert_eq!(out.status.code(), Some(2));
}
