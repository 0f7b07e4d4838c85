//! The standard functions (IEC 61131-3 2.5.1.5) in hand-written PLCopen TC6 XML: FBD blocks and
//! LD boxes with EN/ENO are the model's function element (no black box), analysed and run;
//! one test per family (numeric, bit shifts and MUX, type conversions) checks the values.

use crate::plcopen_common as px;

use px::{
    block, contact, in_var, io, project, project_in, rail, report_and_warnings, rung, trace,
    var_in, Source,
};

/// One function call of [`fbd`]: `(op, [(pin, input expression)], out)`.
type Call<'a> = (&'a str, &'a [(&'a str, &'a str)], &'a str);

/// FBD: `out := op(ins…)` for each call.
fn fbd(vars: &[(&str, &str, &str)], calls: &[Call]) -> String {
    let mut body = String::new();
    let mut id = 1;
    for (op, ins, out) in calls {
        let mut wires = Vec::new();
        for (_, expr) in ins.iter() {
            body.push_str(&in_var(id, expr));
            wires.push(id);
            id += 1;
        }
        let pins: Vec<(&str, Vec<Source>)> = ins
            .iter()
            .zip(&wires)
            .map(|((pin, _), w)| (*pin, vec![(*w, None)]))
            .collect();
        let pins: Vec<(&str, &[Source])> = pins.iter().map(|(p, w)| (*p, w.as_slice())).collect();
        body.push_str(&block(id, op, None, &pins, &["OUT"]));
        body.push_str(&var_in("outVariable", id + 1, out, (id, Some("OUT"))));
        id += 2;
    }
    project_in("FBD", vars, &body)
}

fn no_black_box(xml: &str) {
    let (_, warnings) = report_and_warnings(xml);
    assert!(!warnings.contains("black box"), "{warnings}");
}

#[test]
fn numeric_functions_run_in_fbd() {
    let xml = fbd(
        &[
            ("inputVars", "x", "REAL"),
            ("inputVars", "i", "INT"),
            ("outputVars", "r", "REAL"),
            ("outputVars", "e", "REAL"),
            ("outputVars", "a", "INT"),
            ("outputVars", "l", "REAL"),
        ],
        &[
            ("SQRT", &[("IN", "x")], "r"),
            ("EXPT", &[("IN1", "x"), ("IN2", "3")], "e"),
            ("ABS", &[("IN", "i")], "a"),
            ("LOG", &[("IN", "x")], "l"),
        ],
    );
    no_black_box(&xml);
    let got = trace(
        "fn-num",
        &xml,
        "x,i\n4.0,-5\n100.0,-32768\n-1.0,7\n",
        &["r", "e", "a", "l"],
    );
    assert_eq!(got[0], ["2", "10", "NaN"]);
    assert_eq!(got[1], ["64", "1000000", "-1"]);
    // ABS(-32768) wraps (INT overflow rule).
    assert_eq!(got[2], ["5", "-32768", "7"]);
    assert_eq!(got[3][1], "2");
}

#[test]
fn shifts_and_mux_run_in_fbd() {
    let xml = fbd(
        &[
            ("inputVars", "w", "INT"),
            ("inputVars", "k", "INT"),
            ("outputVars", "s", "INT"),
            ("outputVars", "o", "INT"),
            ("outputVars", "m", "DINT"),
        ],
        &[
            ("SHL", &[("IN", "w"), ("N", "4")], "s"),
            ("ROR", &[("IN", "w"), ("N", "1")], "o"),
            (
                "MUX",
                &[("K", "k"), ("IN0", "10"), ("IN1", "20"), ("IN2", "30")],
                "m",
            ),
        ],
    );
    no_black_box(&xml);
    let got = trace("fn-bit", &xml, "w,k\n1,0\n4097,2\n3,3\n", &["s", "o", "m"]);
    // SHL by 4 on 16 bits: 4097 (0x1001) → 0x0010.
    assert_eq!(got[0], ["16", "16", "48"]);
    // ROR by 1: 1 → 0x8000, 4097 → 0x8800, 3 → 0x8001.
    assert_eq!(got[1], ["-32768", "-30720", "-32767"]);
    // MUX: K out of range gives 0.
    assert_eq!(got[2], ["10", "30", "0"]);
}

#[test]
fn conversions_run_in_fbd() {
    let xml = fbd(
        &[
            ("inputVars", "x", "REAL"),
            ("inputVars", "i", "DINT"),
            ("inputVars", "b", "BOOL"),
            ("outputVars", "n", "INT"),
            ("outputVars", "t", "INT"),
            ("outputVars", "z", "BOOL"),
            ("outputVars", "c", "INT"),
            ("outputVars", "w", "INT"),
        ],
        &[
            ("REAL_TO_INT", &[("IN", "x")], "n"),
            ("TRUNC", &[("IN", "x")], "t"),
            ("DINT_TO_BOOL", &[("IN", "i")], "z"),
            ("BOOL_TO_INT", &[("IN", "b")], "c"),
            ("DINT_TO_INT", &[("IN", "i")], "w"),
        ],
    );
    no_black_box(&xml);
    let got = trace(
        "fn-conv",
        &xml,
        "x,i,b\n2.5,0,1\n-2.5,40000,0\n2.4,-1,1\n",
        &["n", "t", "z", "c", "w"],
    );
    // Rounded halfway away from zero; TRUNC toward zero.
    assert_eq!(got[0], ["3", "-3", "2"]);
    assert_eq!(got[1], ["2", "-2", "2"]);
    assert_eq!(got[2], ["0", "1", "1"]);
    assert_eq!(got[3], ["1", "0", "1"]);
    // Narrowing wraps: 40000 → -25536.
    assert_eq!(got[4], ["0", "-25536", "-1"]);
}

/// LD: `en → SQRT(EN, IN := x) → done`, OUT to `r`.
fn ld_sqrt() -> String {
    let ld = [
        rail(1),
        contact(2, "en", &[1], ""),
        in_var(3, "x"),
        block(4, "SQRT", None, &[("EN", &[(2, None)]), ("IN", &[(3, None)])], &["ENO", "OUT"]),
        var_in("outVariable", 5, "r", (4, Some("OUT"))),
        "<coil localId=\"6\"><connectionPointIn><connection refLocalId=\"4\" formalParameter=\"ENO\"/></connectionPointIn><connectionPointOut/><variable>done</variable></coil>".to_string(),
    ]
    .concat();
    project(
        &[
            ("inputVars", "en", "BOOL"),
            ("inputVars", "x", "REAL"),
            ("outputVars", "r", "REAL"),
            ("outputVars", "done", "BOOL"),
        ],
        &ld,
    )
}

#[test]
fn a_function_box_in_an_ld_rung_runs_when_powered() {
    let xml = ld_sqrt();
    no_black_box(&xml);
    let (r, _) = report_and_warnings(&xml);
    assert_eq!(io(&r), vec![rung("P.R1", &["en", "x"], &["r", "done"])]);
    let got = trace(
        "fn-ld",
        &xml,
        "en,x\n0,9.0\n1,9.0\n0,16.0\n",
        &["r", "done"],
    );
    // Unpowered: OUT is not written (ENO false); powered: r := SQRT(x).
    assert_eq!(got[0], ["0", "3", "3"]);
    assert_eq!(got[1], ["0", "1", "0"]);
}

/// AND, OR, XOR and NOT of bit strings (IEC 61131-3 2.5.1.5.3) are bitwise: blocks of WORDs
/// with a based literal, worked out by hand.
#[test]
fn bitwise_functions_of_words_run_in_fbd() {
    let xml = fbd(
        &[
            ("inputVars", "status", "WORD"),
            ("inputVars", "mask", "WORD"),
            ("outputVars", "a", "WORD"),
            ("outputVars", "o", "WORD"),
            ("outputVars", "x", "WORD"),
            ("outputVars", "n", "BYTE"),
            ("inputVars", "b", "BYTE"),
        ],
        &[
            ("AND", &[("IN1", "status"), ("IN2", "mask")], "a"),
            (
                "OR",
                &[("IN1", "status"), ("IN2", "16#8000"), ("IN3", "mask")],
                "o",
            ),
            ("XOR", &[("IN1", "status"), ("IN2", "16#00FF")], "x"),
            ("NOT", &[("IN", "b")], "n"),
        ],
    );
    no_black_box(&xml);
    let got = trace(
        "fn-bits",
        &xml,
        "status,mask,b\n4660,255,170\n65535,3855,0\n",
        &["a", "o", "x", "n"],
    );
    // 0x1234 AND 0xFF = 0x34; 0xFFFF AND 0x0F0F = 0x0F0F.
    assert_eq!(got[0], ["52", "3855"]);
    // 0x1234 OR 0x8000 OR 0xFF = 0x92FF; all ones.
    assert_eq!(got[1], ["37631", "65535"]);
    // 0x1234 XOR 0xFF = 0x12CB; 0xFFFF XOR 0xFF = 0xFF00.
    assert_eq!(got[2], ["4811", "65280"]);
    // NOT 0xAA = 0x55; NOT 0 = 0xFF.
    assert_eq!(got[3], ["85", "255"]);
}

/// LD: `en → AND(EN, IN1 := w, IN2 := m) → done`, OUT to `r`: an AND box of WORDs in a rung is
/// the bitwise function, run when powered.
#[test]
fn a_bitwise_and_box_in_an_ld_rung_runs_when_powered() {
    let ld = [
        rail(1),
        contact(2, "en", &[1], ""),
        in_var(3, "w"),
        in_var(7, "m"),
        block(
            4,
            "AND",
            None,
            &[("EN", &[(2, None)]), ("IN1", &[(3, None)]), ("IN2", &[(7, None)])],
            &["ENO", "OUT"],
        ),
        var_in("outVariable", 5, "r", (4, Some("OUT"))),
        "<coil localId=\"6\"><connectionPointIn><connection refLocalId=\"4\" formalParameter=\"ENO\"/></connectionPointIn><connectionPointOut/><variable>done</variable></coil>".to_string(),
    ]
    .concat();
    let xml = project(
        &[
            ("inputVars", "en", "BOOL"),
            ("inputVars", "w", "WORD"),
            ("inputVars", "m", "WORD"),
            ("outputVars", "r", "WORD"),
            ("outputVars", "done", "BOOL"),
        ],
        &ld,
    );
    no_black_box(&xml);
    let got = trace(
        "fn-ld-and",
        &xml,
        "en,w,m\n0,4660,255\n1,4660,255\n1,65535,3855\n",
        &["r", "done"],
    );
    // Unpowered: r keeps 0; then 0x1234 AND 0xFF = 0x34, 0xFFFF AND 0x0F0F = 0x0F0F.
    assert_eq!(got[0], ["0", "52", "3855"]);
    assert_eq!(got[1], ["0", "1", "1"]);
}
