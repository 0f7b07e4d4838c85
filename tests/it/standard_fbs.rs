//! The standard function blocks SR, RS, R_TRIG, F_TRIG and CTUD (IEC 61131-3 2nd ed.,
//! 2.5.2.3.1–2.5.2.3.3), scan by scan: each table of inputs → outputs is written from the
//! standard's definition of the block's body, and both the interpreter and the generated C
//! (compiled with `cc -std=c11 -Wall -Wextra -Werror`) must give it. Also the analysis: a box
//! reads and writes its whole instance and reads its operands.

use crate::common;

use common::c::{build, run_c};
use plc_deps::analysis::accesses::accesses;
use plc_deps::codegen::c::CConfig;
use plc_deps::exec::{ExecConfig, Layout, Machine};
use plc_deps::model::{Program, RungId, Value, VarId};
use serde_json::{json, Value as Json};

fn program(vars: Json, rungs: Json) -> String {
    json!({"program": "fbs", "vars": vars, "rungs": rungs}).to_string()
}

/// One instance of each standard function block: B1 SR, B2 RS, E1 R_TRIG, E2 F_TRIG, C CTUD.
fn instances() -> Vec<Json> {
    [
        ("B1", "SR"),
        ("B2", "RS"),
        ("E1", "R_TRIG"),
        ("E2", "F_TRIG"),
        ("C", "CTUD"),
    ]
    .iter()
    .map(|(n, t)| json!({"name": n, "type": t}))
    .collect()
}

fn var(p: &Program, name: &str) -> VarId {
    VarId::from_raw(p.vars().iter().position(|v| v.name == name).unwrap() as u32)
}

/// The interpreter's value of each of `outs` (an instance as its JSON fields) after each scan
/// of `rows` (values of `ins`, BOOL or INT).
fn interpret(text: &str, ins: &[&str], rows: &[Vec<i64>], outs: &[&str]) -> Vec<Vec<Json>> {
    let p = plc_deps::load::program_from_json(text).expect("program loads");
    let m = Machine::new(&p, Layout::dense(&p), &ExecConfig::default()).unwrap();
    let mut st = m.initial_state();
    let mut got = Vec::new();
    for (k, row) in rows.iter().enumerate() {
        let vals: Vec<(VarId, Value)> = ins
            .iter()
            .zip(row)
            .map(|(n, &x)| {
                let id = var(&p, n);
                let v = match p.var(id).ty {
                    plc_deps::model::Type::Bool => Value::Bool(x != 0),
                    _ => Value::Int(x as i16),
                };
                (id, v)
            })
            .collect();
        let mut faults = Vec::new();
        m.set_inputs(&mut st, &vals);
        m.run_scan(&mut st, k as u64, &mut faults);
        assert!(faults.is_empty());
        got.push(
            outs.iter()
                .map(|n| m.value(&st, var(&p, n)).to_json())
                .collect(),
        );
    }
    got
}

/// The same from the generated C: its state line after each scan, the `outs` of it.
fn compiled(
    text: &str,
    tag: &str,
    ins: &[&str],
    rows: &[Vec<i64>],
    outs: &[&str],
) -> Vec<Vec<Json>> {
    let dir = build(text, &CConfig::default(), tag);
    let mut csv = ins.join(",") + "\n";
    for row in rows {
        let cells: Vec<String> = row.iter().map(|x| x.to_string()).collect();
        csv.push_str(&cells.join(","));
        csv.push('\n');
    }
    let (lines, faults) = run_c(&dir, &csv, rows.len() as u64);
    assert!(faults.is_empty(), "{faults:?}");
    let _ = std::fs::remove_dir_all(&dir);
    lines
        .iter()
        .map(|l| {
            let state: Json = serde_json::from_str(l).unwrap();
            outs.iter().map(|n| state[*n].clone()).collect()
        })
        .collect()
}

/// Runs the table through the interpreter and the C; `expect` gives the `outs` of each row.
fn check(
    text: &str,
    tag: &str,
    ins: &[&str],
    rows: &[Vec<i64>],
    outs: &[&str],
    expect: &[Vec<Json>],
) {
    let i = interpret(text, ins, rows, outs);
    for (k, (g, e)) in i.iter().zip(expect).enumerate() {
        assert_eq!(
            g, e,
            "{tag}: interpreter after scan {k} (inputs {:?})",
            rows[k]
        );
    }
    let c = compiled(text, tag, ins, rows, outs);
    assert_eq!(c.len(), rows.len(), "{tag}: C scans");
    for (k, (g, e)) in c.iter().zip(expect).enumerate() {
        assert_eq!(g, e, "{tag}: C after scan {k} (inputs {:?})", rows[k]);
    }
}

fn bool_vars(ins: &[&str], outs: &[&str]) -> Vec<Json> {
    let mut v: Vec<Json> = ins
        .iter()
        .map(|n| json!({"name": n, "type": "BOOL", "class": "input"}))
        .collect();
    v.extend(
        outs.iter()
            .map(|n| json!({"name": n, "type": "BOOL", "class": "output"})),
    );
    v
}

#[test]
fn sr_is_set_dominant_and_rs_reset_dominant() {
    let mut vars = bool_vars(&["s", "r"], &["q_sr", "q_rs"]);
    vars.push(json!({"name": "B1", "type": "SR"}));
    vars.push(json!({"name": "B2", "type": "RS"}));
    let text = program(
        Json::Array(vars),
        json!([
            {"id": "R1", "ld": [{"contact": "s"}, {"sr": "B1", "reset": "r"}, {"coil": "q_sr"}]},
            {"id": "R2", "ld": [{"contact": "s"}, {"rs": "B2", "reset": "r"}, {"coil": "q_rs"}]}
        ]),
    );
    // (S, R) → SR: Q1 := S1 OR (NOT R AND Q1); RS: Q1 := NOT R1 AND (S OR Q1).
    let table: [((i64, i64), (bool, bool)); 9] = [
        ((0, 0), (false, false)),
        ((1, 0), (true, true)),
        ((0, 0), (true, true)),
        ((1, 1), (true, false)),
        ((0, 0), (true, false)),
        ((0, 1), (false, false)),
        ((1, 0), (true, true)),
        ((1, 1), (true, false)),
        ((0, 1), (false, false)),
    ];
    let rows: Vec<Vec<i64>> = table.iter().map(|((s, r), _)| vec![*s, *r]).collect();
    let expect: Vec<Vec<Json>> = table
        .iter()
        .map(|(_, (sr, rs))| vec![json!(sr), json!(rs), json!({"Q1": sr}), json!({"Q1": rs})])
        .collect();
    check(
        &text,
        "bistable",
        &["s", "r"],
        &rows,
        &["q_sr", "q_rs", "B1", "B2"],
        &expect,
    );
}

#[test]
fn r_trig_and_f_trig_follow_the_standard_bodies() {
    let mut vars = bool_vars(&["clk"], &["q_r", "q_f"]);
    vars.push(json!({"name": "E1", "type": "R_TRIG"}));
    vars.push(json!({"name": "E2", "type": "F_TRIG"}));
    let text = program(
        Json::Array(vars),
        json!([
            {"id": "R1", "ld": [{"contact": "clk"}, {"r_trig": "E1"}, {"coil": "q_r"}]},
            {"id": "R2", "ld": [{"contact": "clk"}, {"f_trig": "E2"}, {"coil": "q_f"}]}
        ]),
    );
    // R_TRIG: Q := CLK AND NOT M; M := CLK. F_TRIG: Q := NOT CLK AND NOT M; M := NOT CLK, with M
    // FALSE at the start: the first evaluation with CLK FALSE gives Q TRUE.
    let table: [(i64, bool, bool); 9] = [
        (0, false, true),
        (0, false, false),
        (1, true, false),
        (1, false, false),
        (0, false, true),
        (0, false, false),
        (1, true, false),
        (0, false, true),
        (1, true, false),
    ];
    let rows: Vec<Vec<i64>> = table.iter().map(|(c, _, _)| vec![*c]).collect();
    let expect: Vec<Vec<Json>> = table
        .iter()
        .map(|(_, r, f)| vec![json!(r), json!(f), json!({"Q": r}), json!({"Q": f})])
        .collect();
    check(
        &text,
        "trigger",
        &["clk"],
        &rows,
        &["q_r", "q_f", "E1", "E2"],
        &expect,
    );
}

#[test]
fn ctud_counts_both_ways_with_reset_then_load_first() {
    let mut vars = bool_vars(&["cu", "cd", "r", "ld"], &["qu"]);
    vars.push(json!({"name": "pv", "type": "INT", "class": "input"}));
    vars.push(json!({"name": "C", "type": "CTUD"}));
    let text = program(
        Json::Array(vars),
        json!([{"id": "R1", "ld": [{"contact": "cu"},
            {"ctud": "C", "cd": "cd", "reset": "r", "load": "ld", "pv": "pv"}, {"coil": "qu"}]}]),
    );
    // (CU, CD, R, LD, PV) → CV. Edges of CU and CD are taken on every call; R wins over LD,
    // LD over counting; both edges at once count nothing. QU := CV >= PV, QD := CV <= 0.
    let table: [([i64; 5], i64); 16] = [
        ([0, 0, 0, 0, 2], 0),
        ([1, 0, 0, 0, 2], 1),
        ([1, 0, 0, 0, 2], 1),
        ([0, 0, 0, 0, 2], 1),
        ([1, 0, 0, 0, 2], 2),
        ([0, 1, 0, 0, 2], 1),
        ([1, 1, 0, 0, 2], 2),
        ([0, 0, 0, 0, 2], 2),
        ([1, 1, 0, 0, 2], 2),
        ([0, 0, 0, 1, 3], 3),
        ([0, 1, 1, 1, 3], 0),
        ([0, 0, 0, 0, 3], 0),
        ([0, 1, 0, 0, 3], -1),
        ([1, 0, 0, 1, 5], 5),
        ([0, 0, 0, 0, 5], 5),
        ([0, 1, 0, 0, 4], 4),
    ];
    let rows: Vec<Vec<i64>> = table.iter().map(|(r, _)| r.to_vec()).collect();
    let expect: Vec<Vec<Json>> = table
        .iter()
        .map(|(r, cv)| {
            let (qu, qd) = (*cv >= r[4], *cv <= 0);
            vec![json!(qu), json!({"QU": qu, "QD": qd, "CV": cv, "PV": r[4]})]
        })
        .collect();
    check(
        &text,
        "ctud",
        &["cu", "cd", "r", "ld", "pv"],
        &rows,
        &["qu", "C"],
        &expect,
    );
}

#[test]
fn ctud_stops_at_the_int_limits() {
    let mut vars = bool_vars(&["cu", "cd", "ld"], &[]);
    vars.push(json!({"name": "pv", "type": "INT", "class": "input"}));
    vars.push(json!({"name": "C", "type": "CTUD"}));
    let text = program(
        Json::Array(vars),
        json!([{"id": "R1", "ld": [{"contact": "cu"},
            {"ctud": "C", "cd": "cd", "reset": false, "load": "ld", "pv": "pv"}]}]),
    );
    let table: [([i64; 4], i64); 6] = [
        ([0, 0, 1, 32766], 32766),
        ([1, 0, 0, 32766], 32767),
        ([0, 0, 0, 32766], 32767),
        ([1, 0, 0, 32766], 32767),
        ([0, 0, 1, -32768], -32768),
        ([0, 1, 0, -32768], -32768),
    ];
    let rows: Vec<Vec<i64>> = table.iter().map(|(r, _)| r.to_vec()).collect();
    let expect: Vec<Vec<Json>> = table
        .iter()
        .map(|(r, cv)| vec![json!({"QU": *cv >= r[3], "QD": *cv <= 0, "CV": cv, "PV": r[3]})])
        .collect();
    check(
        &text,
        "ctud-limits",
        &["cu", "cd", "ld", "pv"],
        &rows,
        &["C"],
        &expect,
    );
}

#[test]
fn each_box_reads_and_writes_its_instance_and_reads_its_operands() {
    let mut vars = bool_vars(&["a", "b", "c", "d"], &["q"]);
    vars.push(json!({"name": "n", "type": "INT"}));
    vars.extend(instances());
    let text = program(
        Json::Array(vars),
        json!([
            {"id": "R1", "ld": [{"contact": "a"}, {"sr": "B1", "reset": "b"}, {"coil": "q"}]},
            {"id": "R2", "ld": [{"contact": "B1.Q1"}, {"rs": "B2", "reset": "C.QD"}]},
            {"id": "R3", "ld": [{"contact": "c"}, {"r_trig": "E1"}]},
            {"id": "R4", "ld": [{"f_trig": "E2"}, {"coil": "q"}]},
            {"id": "R5", "ld": [{"contact": "E1.Q"},
                {"ctud": "C", "cd": "E2.Q", "reset": "d", "load": false, "pv": "n"}]}
        ]),
    );
    let p = plc_deps::load::program_from_json(&text).unwrap();
    let acc = accesses(&p);
    let names = |vs: &[VarId]| -> Vec<String> {
        let mut v: Vec<String> = vs.iter().map(|&x| p.var(x).name.clone()).collect();
        v.sort();
        v
    };
    let expect: [(&[&str], &[&str]); 5] = [
        (&["B1", "a", "b"], &["B1", "q"]),
        (&["B1", "B2", "C"], &["B2"]),
        (&["E1", "c"], &["E1"]),
        (&["E2"], &["E2", "q"]),
        (&["C", "E1", "E2", "d", "n"], &["C"]),
    ];
    for (k, (ins, outs)) in expect.iter().enumerate() {
        let r = RungId::from_raw(k as u32);
        assert_eq!(names(acc.ins(r)), *ins, "IN of R{}", k + 1);
        assert_eq!(names(acc.outs(r)), *outs, "OUT of R{}", k + 1);
    }
}

#[test]
fn fbd_blocks_run_the_same_bodies_with_every_output_wired() {
    let mut vars = bool_vars(
        &["s", "r", "cu", "cd"],
        &["q1", "q2", "qr", "qf", "qu", "qd"],
    );
    vars.push(json!({"name": "cv", "type": "INT", "class": "output"}));
    vars.extend(instances());
    let text = json!({"program": "fbd_fbs", "vars": vars, "fbd": {"networks": [{"id": "N1", "blocks": [
        {"id": 1, "op": "SR", "instance": "B1", "in": {"S1": "s", "R": "r"}, "out": {"Q1": "q1"}},
        {"id": 2, "op": "RS", "instance": "B2", "in": {"S": "s", "R1": "r"}, "out": {"Q1": "q2"}},
        {"id": 3, "op": "R_TRIG", "instance": "E1", "in": {"CLK": "s"}, "out": {"Q": "qr"}},
        {"id": 4, "op": "F_TRIG", "instance": "E2", "in": {"CLK": "s"}, "out": {"Q": "qf"}},
        {"id": 5, "op": "CTUD", "instance": "C",
         "in": {"CU": {"from": 3, "pin": "Q"}, "CD": "cd", "R": "r", "LD": false, "PV": 2},
         "out": {"QU": "qu", "QD": "qd", "CV": "cv"}}
    ]}]}})
    .to_string();
    // (S, R, CD) → SR, RS, R_TRIG(S), F_TRIG(S), and CTUD counting the rising edges of S up and
    // of CD down, with R; PV 2.
    #[allow(clippy::type_complexity)]
    let table: [([i64; 3], (bool, bool, bool, bool), i64); 8] = [
        ([0, 0, 0], (false, false, false, true), 0),
        ([1, 0, 0], (true, true, true, false), 1),
        ([0, 0, 0], (true, true, false, true), 1),
        ([1, 0, 0], (true, true, true, false), 2),
        ([1, 1, 0], (true, false, false, false), 0),
        ([0, 0, 1], (true, false, false, true), -1),
        ([0, 1, 0], (false, false, false, false), 0),
        // Both edges at once: no count.
        ([1, 0, 1], (true, true, true, false), 0),
    ];
    let rows: Vec<Vec<i64>> = table
        .iter()
        .map(|(r, _, _)| vec![r[0], r[1], 0, r[2]])
        .collect();
    let expect: Vec<Vec<Json>> = table
        .iter()
        .map(|(_, (a, b, c, d), cv)| {
            [*a, *b, *c, *d, *cv >= 2, *cv <= 0]
                .iter()
                .map(|x| json!(x))
                .chain([json!(cv)])
                .collect()
        })
        .collect();
    let outs = ["q1", "q2", "qr", "qf", "qu", "qd", "cv"];
    check(&text, "fbd", &["s", "r", "cu", "cd"], &rows, &outs, &expect);
}
