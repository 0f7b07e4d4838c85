//! PLCopen TC6 XML FBD bodies, hand-written: a counter whose loop closes through an in-out
//! variable (as every Beremiz counter example does), run and reported; a wiring cycle closed with a one-scan delay, as Beremiz closes it.

use crate::common;
use crate::plcopen_common as px;

use common::cli::{one_line, run_stdin};
use px::{block, in_var, project_in, run_scans, var_in};
use serde_json::{json, Value};

/// Cnt := SEL(G := Reset, IN0 := ADD(Cnt, 1), IN1 := 0); Big := GT(Cnt, 5).
fn counter() -> String {
    let body = [
        in_var(1, "Reset"),
        in_var(2, "1"),
        in_var(3, "0"),
        in_var(10, "Cnt"),
        block(
            4,
            "ADD",
            None,
            &[("IN1", &[(10, None)]), ("IN2", &[(2, None)])],
            &["OUT"],
        ),
        block(
            5,
            "SEL",
            None,
            &[
                ("G", &[(1, None)]),
                ("IN0", &[(4, Some("OUT"))]),
                ("IN1", &[(3, None)]),
            ],
            &["OUT"],
        ),
        var_in("inOutVariable", 6, "Cnt", (5, Some("OUT"))),
        in_var(7, "5"),
        block(
            8,
            "GT",
            None,
            &[("IN1", &[(6, None)]), ("IN2", &[(7, None)])],
            &["OUT"],
        ),
        var_in("outVariable", 9, "Big", (8, Some("OUT"))),
    ]
    .concat();
    project_in(
        "FBD",
        &[
            ("inputVars", "Reset", "BOOL"),
            ("outputVars", "Cnt", "INT"),
            ("outputVars", "Big", "BOOL"),
        ],
        &body,
    )
}

#[test]
fn a_counter_closes_its_loop_through_the_in_out_variable() {
    let xml = counter();
    assert_eq!(
        run_scans(&xml, 7)["outputs"],
        json!({"Cnt": 7, "Big": true})
    );
    assert_eq!(
        run_scans(&xml, 5)["outputs"],
        json!({"Cnt": 5, "Big": false})
    );
    let out = run_stdin(&["report", "-", "--format", "json"], xml.as_bytes());
    let r: Value = serde_json::from_slice(&out.stdout).unwrap();
    let ids: Vec<&str> = r["rungs"]
        .as_array()
        .unwrap()
        .iter()
        .map(|x| x["id"].as_str().unwrap())
        .collect();
    // One rung per block, in data-flow order: ADD, SEL, GT.
    assert_eq!(ids, ["P.4", "P.5", "P.8"]);
}

#[test]
fn a_wiring_cycle_is_closed_as_beremiz_closes_it() {
    let body = [
        in_var(1, "X"),
        block(
            2,
            "ADD",
            None,
            &[("IN1", &[(1, None)]), ("IN2", &[(3, Some("OUT"))])],
            &["OUT"],
        ),
        block(
            3,
            "ADD",
            None,
            &[("IN1", &[(1, None)]), ("IN2", &[(2, Some("OUT"))])],
            &["OUT"],
        ),
        var_in("outVariable", 4, "Y", (3, Some("OUT"))),
    ]
    .concat();
    let xml = project_in(
        "FBD",
        &[("inputVars", "X", "INT"), ("outputVars", "Y", "INT")],
        &body,
    );
    // The walk from block 2 reaches 3, whose arc back into 2 (in progress) is cut: 3 reads
    // 2's OUT of the last scan. So Y = X + last(2.OUT) and 2.OUT = X + Y: with X = 1,
    // Y = 1 (2.OUT = 2), 3 (4), 5 (6).
    let (_, warnings) = px::report_and_warnings(&xml);
    assert!(
        warnings.contains("blocks 3 and 2 are in a loop of arcs"),
        "{warnings}"
    );
    let t = px::trace("fbd-cycle", &xml, "X\n1\n1\n1\n", &["Y"]);
    assert_eq!(t[0], ["1", "3", "5"]);
}

#[test]
fn execution_order_ids_that_disagree_with_the_data_flow_get_a_warning_with_both_orders() {
    // SEL (5) numbered before ADD (4), which feeds it.
    let xml = counter()
        .replace(
            "localId=\"4\" typeName=\"ADD\"",
            "localId=\"4\" typeName=\"ADD\" executionOrderId=\"3\"",
        )
        .replace(
            "localId=\"5\" typeName=\"SEL\"",
            "localId=\"5\" typeName=\"SEL\" executionOrderId=\"1\"",
        )
        .replace(
            "localId=\"8\" typeName=\"GT\"",
            "localId=\"8\" typeName=\"GT\" executionOrderId=\"2\"",
        );
    let out = run_stdin(&["report", "-", "--format", "json"], xml.as_bytes());
    assert_eq!(out.status.code(), Some(0));
    let stderr = one_line(&String::from_utf8_lossy(&out.stderr));
    let warnings: Vec<&str> = stderr
        .lines()
        .filter(|l| l.starts_with("warning: "))
        .collect();
    assert_eq!(warnings.len(), 1, "{stderr}");
    assert!(warnings[0].ends_with("pou P, FBD: the file's executionOrderIds run localIds 5, 8, 4; plc-deps runs them 4, 5, 8 (data flow first, ties by localId; `plc-deps order` shows the whole order)"), "{stderr}");
    assert!(warnings[0].starts_with("warning: <stdin>:"), "{stderr}");
}

#[test]
fn comments_become_the_network_comment() {
    let xml =
        std::fs::read_to_string(common::cli::root().join("tests/plcopen/comment_fbd.xml")).unwrap();
    let (_, fbd, notes) = plc_deps::load::plcopen(&xml).unwrap();
    assert!(notes.is_empty());
    assert_eq!(fbd.pous[0].networks[0].comment.as_deref(), Some("Adds one"));
}

/// An untyped literal takes its type from where it is used (IEC 61131-3 2.3.1: an integer
/// literal is ANY_INT until its use decides): `MUL(0, 0)` feeding an INT variable is an INT
/// multiplication, the same feeding a DINT one is DINT, and `ADD(x, 3)` on a REAL is REAL.
#[test]
fn untyped_literals_take_the_type_their_use_needs() {
    for (ty, a, b, want) in [
        ("INT", "0", "0", "0"),
        ("INT", "300", "100", "30000"),
        ("DINT", "300", "1000", "300000"),
        ("REAL", "1.5", "4", "6.0"),
    ] {
        let body = [
            in_var(1, a),
            in_var(2, b),
            block(
                3,
                "MUL",
                None,
                &[("IN1", &[(1, None)]), ("IN2", &[(2, None)])],
                &["OUT"],
            ),
            var_in("outVariable", 4, "x", (3, Some("OUT"))),
        ]
        .concat();
        let xml = project_in("FBD", &[("outputVars", "x", ty)], &body);
        let r = run_scans(&xml, 1);
        assert_eq!(
            r["outputs"]["x"].to_string(),
            want,
            "MUL({a}, {b}) → {ty}: {r}"
        );
    }
    // A literal too big for the type its use decides is refused, naming it.
    let body = [
        in_var(1, "40000"),
        in_var(2, "1"),
        block(
            3,
            "MUL",
            None,
            &[("IN1", &[(1, None)]), ("IN2", &[(2, None)])],
            &["OUT"],
        ),
        var_in("outVariable", 4, "x", (3, Some("OUT"))),
    ]
    .concat();
    let xml = project_in("FBD", &[("outputVars", "x", "INT")], &body);
    let out = common::cli::run_stdin(&["report", "-"], xml.as_bytes());
    assert_eq!(out.status.code(), Some(2));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("40000") && err.contains("INT"), "{err}");
}

/// An in variable's expression is computed by the blocks it stands for, and the block it feeds
/// reads exactly its variables: arithmetic with precedence and parentheses, unary minus,
/// comparisons and boolean operators; a struct field is its variable reference.
#[test]
fn in_variable_expressions_are_computed_and_read_exactly() {
    let fbd = |expr: &str, out_ty: &str| {
        let body = [in_var(1, expr), var_in("outVariable", 2, "x", (1, None))].concat();
        project_in(
            "FBD",
            &[
                ("inputVars", "a", "INT"),
                ("inputVars", "b", "INT"),
                ("inputVars", "c", "BOOL"),
                ("inputVars", "unused", "INT"),
                ("outputVars", "x", out_ty),
            ],
            &body,
        )
    };
    let csv = "a,b,c,unused\n7,5,1,9\n-3,4,0,9\n";
    for (expr, ty, want) in [
        ("a + b * 2", "INT", ["17", "5"]),
        ("(a + b) * 2", "INT", ["24", "2"]),
        ("-a MOD 4 + b", "INT", ["2", "7"]),
        ("a &gt; b AND c", "BOOL", ["1", "0"]),
        ("NOT (a = 7) OR a &lt;= -3", "BOOL", ["0", "1"]),
        // Constant sub-expressions are folded (IEC 61131-3 constant expressions), so they keep
        // the type of their use: INT here, never DINT.
        ("a + 2 * 3", "INT", ["13", "3"]),
        ("a * (10 - 4) / -(1 + 2)", "INT", ["-14", "6"]),
        ("a &lt; 2 * 3", "BOOL", ["0", "1"]),
    ] {
        let xml = fbd(expr, ty);
        let got = px::trace(&format!("expr-{}", want[0]), &xml, csv, &["x"]);
        assert_eq!(got, [want.map(str::to_owned).to_vec()], "{expr}");
        let r = px::report(&xml);
        let (ins, outs) =
            px::io(&r)
                .into_iter()
                .fold((Vec::new(), Vec::new()), |(mut i, mut o), (_, ri, ro)| {
                    i.extend(
                        ri.as_array()
                            .unwrap()
                            .iter()
                            .map(|v| v.as_str().unwrap().to_owned()),
                    );
                    o.extend(
                        ro.as_array()
                            .unwrap()
                            .iter()
                            .map(|v| v.as_str().unwrap().to_owned()),
                    );
                    (i, o)
                });
        let mut ins: Vec<String> = ins.into_iter().filter(|v| !v.starts_with('_')).collect();
        ins.sort();
        ins.dedup();
        // The variables are the expression's only lower-case letters besides `&lt;`/`&gt;`.
        let want_ins: Vec<&str> = ["a", "b", "c"]
            .into_iter()
            .filter(|v| expr.contains(v))
            .collect();
        assert_eq!(ins, want_ins, "{expr}: the reads");
        assert!(outs.iter().any(|o| o == "x"), "{expr}: {outs:?}");
    }
    // A call, `**` and a malformed expression are one error each, naming the expression.
    for (expr, why) in [
        (
            "MAX(a, b)",
            "a call of `MAX` in an in variable is not read yet",
        ),
        ("a ** 2", "`**` has no block in plc-deps"),
        ("a + ", "expression `a +`"),
    ] {
        let out = run_stdin(&["report", "-"], fbd(expr, "INT").as_bytes());
        assert_eq!(out.status.code(), Some(2), "{expr}");
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(
            err.contains(why) && err.contains("inVariable localId 1"),
            "{expr}: {err}"
        );
    }
}

/// An array element in an in variable reads the whole array and its subscript's variables (the
/// model holds an array as one value), and `run` refuses the body, saying why; a struct field is
/// read as its variable reference.
#[test]
fn an_array_element_of_a_variable_subscript_reads_every_element_and_the_subscript() {
    let body = [
        in_var(1, "arr[i + 1] * 2"),
        var_in("outVariable", 2, "x", (1, None)),
    ]
    .concat();
    let xml = project_in(
        "FBD",
        &[
            ("inputVars", "i", "INT"),
            ("inputVars", "other", "INT"),
            ("localVars", "arr", "ARRAY_OF_INT"),
            ("outputVars", "x", "INT"),
        ],
        &body,
    )
    .replace(
        "<derived name=\"ARRAY_OF_INT\"/>",
        "<array><dimension lower=\"0\" upper=\"9\"/><baseType><INT/></baseType></array>",
    );
    let r = px::report(&xml);
    let mut ins: Vec<String> = px::io(&r)
        .into_iter()
        .flat_map(|(_, i, _)| i.as_array().unwrap().clone())
        .map(|v| v.as_str().unwrap().to_owned())
        .filter(|v| !v.starts_with('_'))
        .collect();
    ins.sort();
    ins.dedup();
    // The array is one variable per element (docs/plcopen.md, "Arrays"): `arr[i + 1]` may be
    // any of them.
    let mut want: Vec<String> = (0..10).map(|k| format!("arr[{k}]")).collect();
    want.push("i".into());
    assert_eq!(ins, want);
    let out = run_stdin(&["run", "-", "--scans", "1"], xml.as_bytes());
    assert_eq!(out.status.code(), Some(2));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains("`run` cannot execute the FBD body of `P`"),
        "{err}"
    );
}

/// A function block instance's output in an in variable's expression (`NOT t.Q`) is that field:
/// the block reads the instance (the report names variables, not fields) and `run` computes it.
#[test]
fn an_instance_field_in_an_expression_reads_that_field() {
    let body = [
        in_var(1, "NOT t.Q AND go"),
        var_in("outVariable", 2, "y", (1, None)),
    ]
    .concat();
    let xml = project_in(
        "FBD",
        &[
            ("inputVars", "go", "BOOL"),
            ("localVars", "t", "TON"),
            ("outputVars", "y", "BOOL"),
        ],
        &body,
    );
    let r = px::report(&xml);
    let mut reads: Vec<String> = px::io(&r)
        .into_iter()
        .flat_map(|(_, i, _)| i.as_array().unwrap().clone())
        .map(|v| v.as_str().unwrap().to_owned())
        .filter(|v| !v.starts_with('_'))
        .collect();
    reads.sort();
    reads.dedup();
    // The report names the instance a field belongs to.
    assert_eq!(reads, ["go", "t"]);
    let got = px::trace("instance-field", &xml, "go\n1\n0\n", &["y"]);
    assert_eq!(got, [vec!["1".to_owned(), "0".to_owned()]]);
}
