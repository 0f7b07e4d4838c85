//! Arrays in PLCopen projects, scalarised by the reader (crates/plc-read/src/plcopen/
//! data_types.rs, st_lower.rs; docs/plcopen.md, Arrays): an `ARRAY[lo..hi] OF T` variable is one
//! variable per element (`a[3]`, `m[1,2]`), its initial value read as IEC 61131-3 6.4.4.5 (3rd
//! ed.) reads `[1, 2, 3]` and `[3(0), 2(1)]` (the elements after the last value given take the
//! type's default, the last subscript varies fastest); ST reads and writes an element of
//! constant subscripts as that variable and one of variable subscripts through a selection
//! (every element read; an out-of-bounds subscript reads 0, writes nothing and records a fault
//! at its statement's rung). The values below are worked out by hand from those rules and
//! IEC 61131-3 7.3.3's statements; seq == par after every scan, and the generated C prints the
//! interpreter's state after every scan.

use crate::common::c::{assert_ok, run_with_input};
use crate::common::cli::{run, tmp};
use crate::plcopen_common as px;
use crate::st_exec::{c_equals_run, pairs, run_json, values};
use serde_json::json;

#[test]
fn declarations_are_one_variable_per_element_with_their_initial_values() {
    let v = run_json("tests/st_arrays/decls.xml", 1, None);
    let names = [
        "a[1]", "a[2]", "a[3]", "a[4]", "a[5]", "r[-2]", "r[-1]", "r[0]", "r[1]", "m[1,0]",
        "m[1,1]", "m[1,2]", "m[2,0]", "m[2,1]", "m[2,2]", "row[0]", "row[1]", "row[2]", "row[3]",
        "b[0]", "b[1]", "b[2]",
    ];
    let expected = [
        // a : ARRAY[1..5] OF INT := [1, 2, 3]: the last two elements INT's default 0.
        ("a[1]", json!(1)),
        ("a[2]", json!(2)),
        ("a[3]", json!(3)),
        ("a[4]", json!(0)),
        ("a[5]", json!(0)),
        // r : ARRAY[-2..1] OF DINT := [3(0), 1]: a negative lower bound, a repetition.
        ("r[-2]", json!(0)),
        ("r[-1]", json!(0)),
        ("r[0]", json!(0)),
        ("r[1]", json!(1)),
        // m : ARRAY[1..2, 0..2] OF INT := [3(1), 3(2)]: the last subscript varies fastest.
        ("m[1,0]", json!(1)),
        ("m[1,1]", json!(1)),
        ("m[1,2]", json!(1)),
        ("m[2,0]", json!(2)),
        ("m[2,1]", json!(2)),
        ("m[2,2]", json!(2)),
        // row : Row, TYPE Row : ARRAY[0..3] OF INT := [2(7), 9]: the type's initial value.
        ("row[0]", json!(7)),
        ("row[1]", json!(7)),
        ("row[2]", json!(9)),
        ("row[3]", json!(0)),
        // b : ARRAY[0..2] OF BOOL := [TRUE]: the rest FALSE.
        ("b[0]", json!(true)),
        ("b[1]", json!(false)),
        ("b[2]", json!(false)),
    ];
    assert_eq!(values(&v, &names), pairs(&expected));
}

/// tests/st_arrays/st.xml, scan 1 then scan 2 (a = [1, 2, 3, 0, 0], b = [TRUE, FALSE, FALSE],
/// idx = 1 at the start).
#[test]
fn constant_and_variable_subscripts_read_and_write_their_elements() {
    let f = "tests/st_arrays/st.xml";
    let names = [
        "s", "a[4]", "a[5]", "r[-2]", "r[-1]", "r[0]", "r[1]", "rs", "m[1,0]", "m[1,2]", "m[2,1]",
        "m[2,2]", "x", "y", "b[1]", "bb", "bc", "c[1]", "c[4]", "c[5]",
    ];
    let scan1 = [
        // FOR i := 1 TO 5 DO s := s + a[i]: 1 + 2 + 3 + 0 + 0 before a[4] and a[5] are written.
        ("s", json!(6)),
        ("a[4]", json!(10)), // a[4] := 10
        ("a[5]", json!(11)), // a[2 + 3] := a[1] + a[4]: a constant expression subscript
        // FOR k := -2 TO 1 DO r[k] := k * 10.
        ("r[-2]", json!(-20)),
        ("r[-1]", json!(-10)),
        ("r[0]", json!(0)),
        ("r[1]", json!(10)),
        ("rs", json!(-10)), // r[-2] + r[idx] = -20 + 10
        // m[i, j] := i * 10 + j over both dimensions.
        ("m[1,0]", json!(10)),
        ("m[1,2]", json!(12)),
        ("m[2,1]", json!(21)),
        ("m[2,2]", json!(22)),
        ("x", json!(21)),      // m[2, 1]
        ("y", json!(12)),      // m[idx, idx + 1] = m[1, 2]
        ("b[1]", json!(true)), // b[idx] := NOT b[idx]
        ("bb", json!(true)),   // b[idx - 1] AND b[1] = b[0] AND b[1]
        ("bc", json!(false)),  // b[2]
        // c := a: a move per element.
        ("c[1]", json!(1)),
        ("c[4]", json!(10)),
        ("c[5]", json!(11)),
    ];
    assert_eq!(values(&run_json(f, 1, None), &names), pairs(&scan1));
    let v = run_json(f, 2, None);
    assert_eq!(v["faults"], json!([]));
    let scan2 = [
        ("s", json!(27)),       // 1 + 2 + 3 + 10 + 11
        ("b[1]", json!(false)), // NOT TRUE
        ("bb", json!(false)),   // TRUE AND FALSE
    ];
    assert_eq!(values(&v, &["s", "b[1]", "bb"]), pairs(&scan2),);
    c_equals_run(f, 2, None);
}

/// k = 2, 4, 0 in scans 0, 1, 2 (a : ARRAY[1..3] OF INT := [5, 6, 7]): `z := a[k]` reads 6,
/// then (k = 4, 0 out of bounds) 0 with a fault at rung P.st1.2 (the bounds check of statement
/// 1); `a[k - 1] := 40 + k` writes a[1] := 42, a[3] := 44, then (k - 1 = -1) nothing, with a
/// fault at P.st2.3.
#[test]
fn an_out_of_bounds_subscript_is_a_fault_of_its_scan_and_statement() {
    let f = "tests/st_arrays/range.xml";
    let csv = "tests/st_arrays/range.csv";
    let v = run_json(f, 1, Some(csv));
    assert_eq!(
        values(&v, &["z", "a[1]"]),
        pairs(&[("z", json!(6)), ("a[1]", json!(42))])
    );
    assert_eq!(v["faults"], json!([]));
    let v = run_json(f, 3, Some(csv));
    assert_eq!(
        values(&v, &["z", "a[1]", "a[2]", "a[3]", "n"]),
        pairs(&[
            ("z", json!(0)),
            ("a[1]", json!(42)),
            ("a[2]", json!(6)),
            ("a[3]", json!(44)),
            ("n", json!(3)),
        ])
    );
    assert_eq!(
        v["faults"],
        json!([
            {"scan": 1, "rung": "P.st1.2", "kind": "index-range"},
            {"scan": 2, "rung": "P.st1.2", "kind": "index-range"},
            // Statement 2's bounds rung comes after the rungs of `k - 1` and `40 + k`, each
            // computed in DINT and cut to INT as matiec's C does (docs/dialects.md).
            {"scan": 2, "rung": "P.st2.7", "kind": "index-range"},
        ])
    );
    c_equals_run(f, 3, Some(csv));
    // The generated C prints the same faults, one JSON line each on standard error.
    let dir = tmp("st-arrays-range-c-faults");
    let _ = std::fs::remove_dir_all(&dir);
    assert_ok(&run(&["c", f, "-o", dir.to_str().unwrap()]), "plc-deps c");
    let make = std::process::Command::new("make")
        .arg("-s")
        .current_dir(&dir)
        .output()
        .unwrap();
    assert_ok(&make, "make");
    let input = std::fs::read(crate::common::cli::root().join(csv)).unwrap();
    let out = run_with_input(&dir.join("plc_program"), &["3".to_owned()], &input);
    let faults: Vec<serde_json::Value> = String::from_utf8(out.stderr)
        .unwrap()
        .lines()
        .map(|l| serde_json::from_str(l).unwrap())
        .collect();
    assert_eq!(json!(faults), v["faults"]);
}

/// The analysis: a constant subscript (`a[2]`, `a[1 + 1]`) is its element's variable, so
/// `y := a[1]` does not depend on `a[2] := x`; a variable subscript reads (`w := a[i]`) or
/// writes (`a[i] := 0`, which keeps the other elements: it reads them too) every element.
#[test]
fn report_dependences_are_per_element_for_constant_subscripts_only() {
    let xml = std::fs::read_to_string(crate::common::cli::root().join("tests/st_arrays/deps.xml"))
        .unwrap();
    let r = px::report(&xml);
    let all = ["a[1]", "a[2]", "a[3]"];
    assert_eq!(
        px::io(&r),
        vec![
            // A stand-in reads what it writes (its may-write, as for a structure's field).
            px::rung("P.st1", &["x", "a[2]"], &["a[2]"]),
            px::rung("P.st2", &["y", "a[1]"], &["y"]),
            px::rung("P.st3", &["z", "a[2]"], &["z"]),
            px::rung("P.st4", &["i", "w", "a[1]", "a[2]", "a[3]"], &["w"]),
            px::rung("P.st5", &["i", "a[1]", "a[2]", "a[3]"], &all),
        ]
    );
    let flows: Vec<_> = r["dependences"]
        .as_array()
        .unwrap()
        .iter()
        .filter(|d| d["kind"] == "flow")
        .cloned()
        .collect();
    assert_eq!(
        flows,
        vec![
            json!({"kind": "flow", "from": "P.st1", "to": "P.st3", "var": "a[2]"}),
            json!({"kind": "flow", "from": "P.st1", "to": "P.st4", "var": "a[2]"}),
            json!({"kind": "flow", "from": "P.st1", "to": "P.st5", "var": "a[2]"}),
        ]
    );
}

/// FBD: `a[3] := ADD(a[1], a[ 1 + 1 ])` = 5 + 6 and `Twice := a[3] * 2` = 22 (a = [5, 6, 0]);
/// the analysis sees the elements as the variables they are: one flow dependence, on `a[3]`.
#[test]
fn fbd_in_and_out_variables_of_constant_subscripts_are_the_elements() {
    let f = "tests/st_arrays/fbd.xml";
    let v = run_json(f, 1, None);
    assert_eq!(
        values(&v, &["a[1]", "a[2]", "a[3]", "Twice"]),
        pairs(&[
            ("a[1]", json!(5)),
            ("a[2]", json!(6)),
            ("a[3]", json!(11)),
            ("Twice", json!(22)),
        ])
    );
    let xml = std::fs::read_to_string(crate::common::cli::root().join(f)).unwrap();
    let r = px::report(&xml);
    assert_eq!(px::io(&r)[0], px::rung("P.3", &["a[1]", "a[2]"], &["a[3]"]));
    c_equals_run(f, 1, None);
}
