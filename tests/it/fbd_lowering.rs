//! FBD semantics through the lowering: every op on the interpreter (values computed by hand),
//! the fragment rules (merging, compound arcs, one-source control arcs, placement before a RET),
//! function block instances (own data, unconnected inputs, members, ladder bodies, nesting),
//! FBD and ladder mixed in one program, and the reader's FBD errors.

use plc_deps::exec::{ExecConfig, Layout, Machine, State, VarValue};
use plc_deps::fbd::{Fbd, FbdPou};
use plc_deps::model::{Program, Value, VarId};
use serde_json::{json, Value as Json};

struct Sim {
    p: Program,
    fbd: Fbd,
    m: Machine,
    st: State,
    scan: u64,
}

impl Sim {
    fn new(doc: Json) -> Sim {
        let (p, fbd) = plc_deps::load::program_and_fbd_from_json(&doc.to_string())
            .unwrap_or_else(|e| panic!("{e}"));
        let m = Machine::new(&p, Layout::dense(&p), &ExecConfig::default()).unwrap();
        let st = m.initial_state();
        Sim {
            p,
            fbd,
            m,
            st,
            scan: 0,
        }
    }
    fn id(&self, name: &str) -> VarId {
        VarId::from_raw(
            self.p
                .vars()
                .iter()
                .position(|v| v.name == name)
                .unwrap_or_else(|| panic!("no variable {name}")) as u32,
        )
    }
    fn step(&mut self, inputs: &[(&str, Value)]) {
        let vals: Vec<(VarId, Value)> = inputs.iter().map(|&(n, v)| (self.id(n), v)).collect();
        let mut faults = Vec::new();
        self.m.scan(&mut self.st, self.scan, &vals, &mut faults);
        self.scan += 1;
    }
    fn get(&self, name: &str) -> Value {
        match self.m.value(&self.st, self.id(name)) {
            VarValue::Scalar(v) => v,
            other => panic!("{name}: {other:?}"),
        }
    }
    fn int(&self, name: &str) -> i64 {
        match self.get(name) {
            Value::Int(i) => i as i64,
            Value::Dint(i) | Value::Time(i) => i as i64,
            other => panic!("{name}: {other:?}"),
        }
    }
    fn bool(&self, name: &str) -> bool {
        match self.get(name) {
            Value::Bool(b) => b,
            other => panic!("{name}: {other:?}"),
        }
    }
    fn main_fbd(&self) -> &FbdPou {
        &self.fbd.pous[0]
    }
    /// Execution order of network `n` of the main program, as block ids.
    fn order(&self, n: usize) -> Vec<u32> {
        let pou = self.main_fbd();
        pou.plans[n]
            .order
            .iter()
            .map(|b| pou.networks[n].block(*b).id)
            .collect()
    }
    /// (fragment, parent, blocks) of network `n`, in tree order.
    fn fragments(&self, n: usize) -> Vec<(String, String, Vec<u32>)> {
        let pou = self.main_fbd();
        let plan = &pou.plans[n];
        plan.fragment_order()
            .into_iter()
            .map(|f| {
                let fr = &plan.fragments[f.index()];
                let parent = fr
                    .parent
                    .map_or("-".to_string(), |q| plan.fragments[q.index()].name.clone());
                (
                    fr.name.clone(),
                    parent,
                    fr.blocks
                        .iter()
                        .map(|b| pou.networks[n].block(*b).id)
                        .collect(),
                )
            })
            .collect()
    }
}

fn program(vars: Json, blocks: Json) -> Json {
    json!({"program": "t", "vars": vars, "fbd": {"networks": [{"id": "N1", "blocks": blocks}]}})
}

fn err(doc: Json) -> String {
    match plc_deps::load::program_and_fbd_from_json(&doc.to_string()) {
        Ok(_) => panic!("expected an error"),
        Err(e) => e.to_string(),
    }
}

fn int_vars(names: &[&str]) -> Vec<Json> {
    names
        .iter()
        .map(|n| json!({"name": n, "type": "INT"}))
        .collect()
}

// ---------------------------------------------------------------- ops

#[test]
fn arithmetic_compare_and_selection_ops() {
    let mut vars = int_vars(&[
        "a", "b", "c", "sum", "prod", "mx", "mn", "lim", "sel", "mv", "m",
    ]);
    vars.push(json!({"name": "g", "type": "BOOL"}));
    vars.push(json!({"name": "gt", "type": "BOOL"}));
    let mut s = Sim::new(program(
        json!(vars),
        json!([
            {"id": 1, "op": "ADD", "in": ["a", "b", "c"], "out": "sum"},
            {"id": 2, "op": "MUL", "in": ["a", "b", 2], "out": "prod"},
            {"id": 3, "op": "MAX", "in": ["a", "b", "c"], "out": "mx"},
            {"id": 4, "op": "MIN", "in": ["a", "b", "c"], "out": "mn"},
            {"id": 5, "op": "LIMIT", "in": {"MN": 0, "IN": "a", "MX": 10}, "out": "lim"},
            {"id": 6, "op": "SEL", "in": {"G": "g", "IN0": "a", "IN1": "b"}, "out": "sel"},
            {"id": 7, "op": "GT", "in": [{"from": 3}, {"from": 4}], "out": "gt"},
            {"id": 8, "op": "MOVE", "in": [{"from": 1}], "out": ["mv"]},
            {"id": 9, "op": "MOD", "in": ["a", 4], "out": "m"}
        ]),
    ));
    let set = |a: i16, b: i16, c: i16, g: bool| {
        [
            ("a", Value::Int(a)),
            ("b", Value::Int(b)),
            ("c", Value::Int(c)),
            ("g", Value::Bool(g)),
        ]
    };
    s.step(&set(13, -2, 5, false));
    assert_eq!(
        [
            s.int("sum"),
            s.int("prod"),
            s.int("mx"),
            s.int("mn"),
            s.int("lim"),
            s.int("sel"),
            s.int("mv"),
            s.int("m")
        ],
        [16, -52, 13, -2, 10, 13, 16, 1]
    );
    assert!(s.bool("gt"));
    s.step(&set(-7, 4, 4, true));
    assert_eq!(
        [
            s.int("sum"),
            s.int("mx"),
            s.int("mn"),
            s.int("lim"),
            s.int("sel"),
            s.int("m")
        ],
        [1, 4, -7, 0, 4, -3]
    );
}

#[test]
fn outputs_that_are_also_inputs_are_computed_through_a_temp() {
    // MAX(b, a) into a: with a written first the comparison would see the new a.
    let mut s = Sim::new(program(
        json!(int_vars(&["a", "b", "x"])),
        json!([
            {"id": 1, "op": "MAX", "in": ["b", "a"], "out": "a"},
            {"id": 2, "op": "ADD", "in": ["x", "x", "x"], "out": "x"}
        ]),
    ));
    s.step(&[
        ("a", Value::Int(9)),
        ("b", Value::Int(3)),
        ("x", Value::Int(2)),
    ]);
    assert_eq!((s.int("a"), s.int("x")), (9, 6));
    assert!(s.p.vars().iter().any(|v| v.hidden && v.name == "_1_OUT"));
}

/// EQ, GT, GE, LT, LE of n inputs compare each neighbouring pair (IEC 61131-3 2.5.1.5.4:
/// `GT(a, b, c)` is `a > b AND b > c`); NE takes exactly two.
#[test]
fn extensible_comparisons_compare_neighbours() {
    let mut vars = int_vars(&["a", "b", "c"]);
    for n in ["gt", "ge", "eq", "lt", "le"] {
        vars.push(json!({"name": n, "type": "BOOL"}));
    }
    let mut s = Sim::new(program(
        json!(vars),
        json!([
            {"id": 1, "op": "GT", "in": ["a", "b", "c"], "out": "gt"},
            {"id": 2, "op": "GE", "in": ["a", "b", "c", 0], "out": "ge"},
            {"id": 3, "op": "EQ", "in": ["a", "b", "c"], "out": "eq"},
            {"id": 4, "op": "LT", "in": ["a", "b", "c"], "out": "lt"},
            {"id": 5, "op": "LE", "in": [{"from": 6}, "b", "c"], "out": "le"},
            {"id": 6, "op": "ADD", "in": ["a", 0]}
        ]),
    ));
    for (a, b, c) in [
        (3, 2, 1),
        (3, 2, 2),
        (2, 2, 2),
        (1, 2, 3),
        (1, 2, 2),
        (2, 1, -1),
    ] {
        s.step(&[
            ("a", Value::Int(a)),
            ("b", Value::Int(b)),
            ("c", Value::Int(c)),
        ]);
        assert_eq!(
            ["gt", "ge", "eq", "lt", "le"].map(|n| s.bool(n)),
            [
                a > b && b > c,
                a >= b && b >= c && c >= 0,
                a == b && b == c,
                a < b && b < c,
                a <= b && b <= c
            ],
            "a={a} b={b} c={c}"
        );
    }
    let e = err(program(
        json!([{"name": "a", "type": "INT"}, {"name": "q", "type": "BOOL"}]),
        json!([{"id": 1, "op": "NE", "in": ["a", 1, 2], "out": "q"}]),
    ));
    assert!(e.contains("NE takes 2 inputs (IN1, IN2), found 3"), "{e}");
}

#[test]
fn logic_ops_with_variables_constants_and_arcs() {
    let vars: Vec<Json> = ["x", "y", "z", "and", "or", "xor2", "xor3", "not", "andc"]
        .iter()
        .map(|n| json!({"name": n, "type": "BOOL"}))
        .collect();
    let mut s = Sim::new(program(
        json!(vars),
        json!([
            {"id": 1, "op": "AND", "in": ["x", "y"], "out": "and"},
            {"id": 2, "op": "OR", "in": ["x", "y", "z"], "out": "or"},
            {"id": 3, "op": "XOR", "in": ["x", "y"], "out": "xor2"},
            {"id": 4, "op": "XOR", "in": ["x", "y", "z"], "out": "xor3"},
            {"id": 5, "op": "NOT", "in": [{"from": 1}], "out": "not"},
            {"id": 6, "op": "AND", "in": ["x", true, {"from": 2}], "out": "andc"}
        ]),
    ));
    for (x, y, z) in [
        (false, false, false),
        (true, false, true),
        (true, true, true),
        (false, true, false),
    ] {
        s.step(&[
            ("x", Value::Bool(x)),
            ("y", Value::Bool(y)),
            ("z", Value::Bool(z)),
        ]);
        assert_eq!(
            [
                s.bool("and"),
                s.bool("or"),
                s.bool("xor2"),
                s.bool("xor3"),
                s.bool("not"),
                s.bool("andc")
            ],
            [
                x && y,
                x || y || z,
                x ^ y,
                x ^ y ^ z,
                !(x && y),
                x // x AND TRUE AND (x OR y OR z)
            ],
            "x={x} y={y} z={z}"
        );
    }
}

#[test]
fn timers_and_counters_read_through_their_instance() {
    let mut s = Sim::new(program(
        json!([
            {"name": "go", "type": "BOOL", "class": "input"},
            {"name": "T1", "type": "TON"}, {"name": "C1", "type": "CTU"},
            {"name": "q", "type": "BOOL"}, {"name": "et", "type": "TIME"}, {"name": "cv", "type": "INT"}, {"name": "done", "type": "BOOL"}
        ]),
        json!([
            {"id": 1, "op": "TON", "instance": "T1", "in": ["go", "T#30ms"], "out": ["q", "et"]},
            {"id": 2, "op": "CTU", "instance": "C1", "in": {"CU": {"from": 1, "pin": "Q"}, "R": false, "PV": 2}, "out": {"CV": "cv", "Q": "done"}}
        ]),
    ));
    // 10 ms cycle: go from scan 0; Q at scan 3 (ET = 30 ms). Off at 4, on again from 5: Q at 8.
    let mut qs = Vec::new();
    for k in 0..10 {
        s.step(&[("go", Value::Bool(k != 4))]);
        qs.push(s.bool("q"));
    }
    assert_eq!(
        qs,
        [false, false, false, true, false, false, false, false, true, true]
    );
    assert_eq!((s.int("et"), s.int("cv"), s.bool("done")), (30, 2, true));
}

#[test]
fn jumps_and_ret_between_networks() {
    // N1 (L0): n := n + 1; if n < 3 goto L0 (a loop inside the scan); N2: if stop, RET; N3: m := m + 1.
    let doc = json!({"program": "t", "vars": [
            {"name": "n", "type": "INT"}, {"name": "m", "type": "INT"}, {"name": "stop", "type": "BOOL", "class": "input"}],
        "fbd": {"networks": [
            {"id": "N1", "label": "L0", "blocks": [
                {"id": 1, "op": "ADD", "in": ["n", 1], "out": "n"},
                {"id": 2, "op": "LT", "in": ["n", 3]},
                {"id": 3, "op": "JMP", "label": "L0", "cond": {"from": 2}}]},
            {"id": "N2", "blocks": [{"id": 4, "op": "RET", "cond": "stop"}]},
            {"id": "N3", "blocks": [{"id": 5, "op": "ADD", "in": ["m", 1], "out": "m"}]}]}});
    let mut s = Sim::new(doc);
    s.step(&[("stop", Value::Bool(false))]);
    assert_eq!((s.int("n"), s.int("m")), (3, 1));
    s.step(&[("stop", Value::Bool(true))]);
    assert_eq!((s.int("n"), s.int("m")), (4, 1));
    assert_eq!(
        s.p.rung(plc_deps::model::RungId::from_raw(0))
            .label
            .as_deref(),
        Some("L0")
    );
}

// ---------------------------------------------------------------- fragments

#[test]
fn blocks_on_the_same_condition_share_a_fragment_and_control_arcs_order() {
    let s = Sim::new(program(
        json!(int_vars(&["a", "x", "y", "z", "w"])),
        json!([
            {"id": 1, "op": "GT", "in": ["a", 0]},
            {"id": 2, "op": "ADD", "in": ["a", 1], "out": "x", "cond": {"from": 1}},
            {"id": 3, "op": "ADD", "in": ["a", 2], "out": "y", "cond": {"from": 1}},
            {"id": 4, "op": "ADD", "in": ["a", 3], "out": "z", "after": [3]},
            {"id": 5, "op": "ADD", "in": ["a", 4], "out": "w"}
        ]),
    ));
    // 4 runs after 3 (one-source control arc): it joins F(1); 5 depends on nothing.
    assert_eq!(
        s.fragments(0),
        vec![
            ("root".into(), "-".into(), vec![1, 5]),
            ("F(1)".into(), "root".into(), vec![2, 3, 4])
        ]
    );
    assert_eq!(s.order(0), vec![1, 2, 3, 4, 5]);
}

#[test]
fn a_compound_arc_from_nested_fragments_reduces_to_the_outer_one() {
    // 24 is inside F(27) inside F(4): "10 or 24 ran" is "F(4) ran", so 30 joins F(4), after 24.
    let s = Sim::new(program(
        json!(int_vars(&["v", "a", "b", "c"])),
        json!([
            {"id": 4, "op": "EQ", "in": ["v", 2]},
            {"id": 10, "op": "MUL", "in": ["v", 3], "cond": {"from": 4}},
            {"id": 27, "op": "GT", "in": [{"from": 10}, 0]},
            {"id": 24, "op": "MOVE", "in": [{"from": 10}], "out": "a", "cond": {"from": 27}},
            {"id": 30, "op": "ADD", "in": ["a", 1], "out": "b", "after": [10, 24]},
            {"id": 31, "op": "ADD", "in": ["v", 1], "out": "c"}
        ]),
    ));
    assert_eq!(
        s.fragments(0),
        vec![
            ("root".into(), "-".into(), vec![4, 31]),
            ("F(4)".into(), "root".into(), vec![10, 27, 30]),
            ("F(27)".into(), "F(4)".into(), vec![24]),
        ]
    );
    // The nested fragment is placed before 30, which runs after 24 — and before 31 (its place).
    assert_eq!(s.order(0), vec![4, 10, 27, 24, 30, 31]);
}

#[test]
fn a_conditional_block_keeps_its_place_before_a_later_ret() {
    // KASKAD 4's shape: the conditional TSTART (2) comes before the RET (4) it precedes in id order.
    let s = Sim::new(program(
        json!([{"name": "t", "type": "TIME"}, {"name": "r", "type": "INT"}]),
        json!([
            {"id": 1, "op": "EQ", "in": ["t", "T#0s"]},
            {"id": 2, "op": "TSTART", "in": ["t"], "cond": {"from": 1}},
            {"id": 3, "op": "LT", "in": ["t", "T#1s"]},
            {"id": 4, "op": "RET", "cond": {"from": 3}},
            {"id": 5, "op": "ADD", "in": ["r", 1], "out": "r"}
        ]),
    ));
    assert_eq!(s.order(0), vec![1, 2, 3, 4, 5]);
    let ids: Vec<&str> = s.p.rungs().iter().map(|r| r.id.as_str()).collect();
    assert_eq!(
        ids,
        vec![
            "acc:t",
            "N1.1",
            "N1.F(1)",
            "N1.2",
            "N1.F(1).end",
            "N1.3",
            "N1.4",
            "N1.5"
        ]
    );
}

#[test]
fn a_variable_condition_opens_a_fragment_read_when_it_starts() {
    let mut s = Sim::new(program(
        json!([{"name": "en", "type": "BOOL", "class": "input"}, {"name": "n", "type": "INT"}]),
        json!([{"id": 1, "op": "ADD", "in": ["n", 1], "out": "n", "cond": "en"}]),
    ));
    assert_eq!(s.fragments(0)[1], ("F(en)".into(), "root".into(), vec![1]));
    for en in [true, false, true] {
        s.step(&[("en", Value::Bool(en))]);
    }
    assert_eq!(s.int("n"), 2);
}

#[test]
fn compound_fragment_runs_when_one_source_ran() {
    let mut s = Sim::new(program(
        json!([{"name": "a", "type": "BOOL", "class": "input"}, {"name": "b", "type": "BOOL", "class": "input"}, {"name": "n", "type": "INT"}, {"name": "x", "type": "INT"}]),
        json!([
            {"id": 1, "op": "MOVE", "in": [1], "out": "x", "cond": "a"},
            {"id": 2, "op": "MOVE", "in": [2], "out": "x", "cond": "b"},
            {"id": 3, "op": "ADD", "in": ["n", 1], "out": "n", "after": [1, 2]}
        ]),
    ));
    assert_eq!(s.fragments(0)[3], ("FC".into(), "root".into(), vec![3]));
    let mut ns = Vec::new();
    for (a, b) in [
        (false, false),
        (true, false),
        (false, true),
        (true, true),
        (false, false),
    ] {
        s.step(&[("a", Value::Bool(a)), ("b", Value::Bool(b))]);
        ns.push(s.int("n"));
    }
    assert_eq!(ns, [0, 1, 2, 3, 3]);
}

// ---------------------------------------------------------------- function blocks

fn counter_fb() -> Json {
    // COUNTER: on a rising EN (ladder edge contact in a ladder body), N := N + STEP; OUT := N.
    json!({
        "inputs": [{"name": "EN", "type": "BOOL"}, {"name": "STEP", "type": "INT", "init": 1}],
        "outputs": [{"name": "OUT", "type": "INT"}],
        "vars": [{"name": "N", "type": "INT"}],
        "rungs": [
            {"id": "R1", "ld": [{"contact": "EN", "edge": "rising"}, {"op": "ADD", "in": ["N", "STEP"], "out": "N"}]},
            {"id": "R2", "ld": [{"move": "N", "to": "OUT"}]}
        ]
    })
}

#[test]
fn instances_keep_their_own_data_unconnected_inputs_keep_their_value() {
    let doc = json!({"program": "t",
        "vars": [{"name": "p", "type": "BOOL", "class": "input"}, {"name": "C1", "type": "COUNTER"}, {"name": "C2", "type": "COUNTER"},
                 {"name": "o1", "type": "INT"}, {"name": "o2", "type": "INT"}, {"name": "sum", "type": "INT"}],
        "function_blocks": {"COUNTER": counter_fb()},
        "fbd": {"networks": [{"id": "N1", "blocks": [
            {"id": 1, "op": "COUNTER", "instance": "C1", "in": ["p"], "out": "o1"},
            {"id": 2, "op": "COUNTER", "instance": "C2", "in": {"EN": "p", "STEP": 10}, "out": {"OUT": "o2"}},
            {"id": 3, "op": "ADD", "in": [{"from": 1}, "C2.OUT"], "out": "sum"}]}]}});
    let mut s = Sim::new(doc);
    for p in [true, false, true, true, false, true] {
        s.step(&[("p", Value::Bool(p))]);
    }
    // Three rising edges: C1 adds its default STEP 1, C2 its connected 10.
    assert_eq!((s.int("o1"), s.int("o2"), s.int("sum")), (3, 30, 33));
    // Each instance has its own POU, rungs and edge memory.
    let names: Vec<&str> = s.p.pous().iter().map(|p| p.name.as_str()).collect();
    assert_eq!(names, vec!["t", "C1", "C2"]);
    assert!(
        s.p.rungs().iter().any(|r| r.id == "C1:R1") && s.p.rungs().iter().any(|r| r.id == "C2:R1")
    );
    assert!(
        s.p.vars().iter().any(|v| v.name == "C1:R1:edge1")
            && s.p.vars().iter().any(|v| v.name == "C2:R1:edge1")
    );
    assert!(s.p.vars().iter().any(|v| v.name == "C2.STEP"));
}

#[test]
fn nested_instances_and_ladder_main_calling_an_fbd_subroutine() {
    let doc = json!({"program": "t",
        "vars": [{"name": "p", "type": "BOOL", "class": "input"}, {"name": "W", "type": "WRAP"}, {"name": "r", "type": "INT"}, {"name": "calls", "type": "INT"}],
        "function_blocks": {
            "COUNTER": counter_fb(),
            "WRAP": {
                "inputs": [{"name": "GO", "type": "BOOL"}], "outputs": [{"name": "RES", "type": "INT"}],
                "vars": [{"name": "INNER", "type": "COUNTER"}],
                "fbd": {"networks": [{"id": "W1", "blocks": [
                    {"id": 1, "op": "COUNTER", "instance": "INNER", "in": {"EN": "GO", "STEP": 5}},
                    {"id": 2, "op": "MUL", "in": [{"from": 1}, 2], "out": "RES"}]}]}}},
        "rungs": [{"id": "R1", "ld": [{"call": "SBR"}]}],
        "subroutines": {"SBR": {"vars": [{"name": "k", "type": "INT"}], "fbd": {"networks": [{"id": "S1", "blocks": [
            {"id": 1, "op": "WRAP", "instance": "W", "in": ["p"], "out": "r"},
            {"id": 2, "op": "ADD", "in": ["k", 1], "out": ["k"]},
            {"id": 3, "op": "MOVE", "in": [{"from": 2}], "out": "calls"}]}]}}}});
    let mut s = Sim::new(doc);
    for p in [true, false, true] {
        s.step(&[("p", Value::Bool(p))]);
    }
    assert_eq!((s.int("r"), s.int("calls"), s.int("SBR:k")), (20, 3, 3));
    let names: Vec<&str> = s.p.pous().iter().map(|p| p.name.as_str()).collect();
    assert_eq!(names, vec!["t", "SBR", "W", "W.INNER"]);
    assert!(
        s.p.vars().iter().any(|v| v.name == "W.INNER.N")
            && s.p.vars().iter().any(|v| v.name == "SBR:_2_OUT")
    );
    // The FBD bodies: the subroutine, then the two types; WRAP has one copy (instance W).
    let bodies: Vec<(&str, usize)> = s
        .fbd
        .pous
        .iter()
        .map(|p| (p.name.as_str(), p.copies.len()))
        .collect();
    assert_eq!(bodies, vec![("SBR", 1), ("WRAP", 1)]);
}

#[test]
fn tstart_and_tstop_accumulate_elapsed_time() {
    let mut s = Sim::new(program(
        json!([{"name": "run", "type": "BOOL", "class": "input"}, {"name": "t", "type": "TIME", "init": "T#5ms"}]),
        json!([
            {"id": 1, "op": "TSTART", "in": ["t"], "cond": "run"},
            {"id": 2, "op": "NOT", "in": ["run"]},
            {"id": 3, "op": "TSTOP", "in": ["t"], "cond": {"from": 2}}
        ]),
    ));
    // Started at scan 1 (10 ms) from 5 ms; scans 2, 3 add 10 ms each; stopped at scan 4 (t = 35
    // ms); restarted at scan 6 (60 ms): scan 8 (80 ms) adds 20 ms more.
    let mut ts = Vec::new();
    for run in [false, true, true, true, false, false, true, true, true] {
        s.step(&[("run", Value::Bool(run))]);
        ts.push(s.int("t"));
    }
    assert_eq!(ts, [5, 5, 15, 25, 35, 35, 35, 45, 55]);
}

// ---------------------------------------------------------------- errors

#[test]
fn reader_errors_name_network_block_and_path() {
    let e = err(program(
        json!(int_vars(&["_1_OUT", "a"])),
        json!([{"id": 1, "op": "ADD", "in": ["a", 1]}]),
    ));
    assert_eq!(e, "network N1 block 1 at fbd.networks[0].blocks[0]: `_1_OUT` is declared, but the FBD body needs it for a hidden variable (names `_<block>_<pin>` and `_run_<network>_<fragment>` are reserved in FBD POUs)");
    let e = err(program(
        json!(int_vars(&["a"])),
        json!([
            {"id": 1, "op": "GT", "in": ["a", 1]}, {"id": 2, "op": "GT", "in": ["a", 2]},
            {"id": 4, "op": "ADD", "in": ["a", 1], "cond": {"from": 1}}, {"id": 5, "op": "ADD", "in": ["a", 2], "cond": {"from": 2}},
            {"id": 3, "op": "ADD", "in": ["a", 1], "cond": {"from": 1}, "after": [4, 5]}
        ]),
    ));
    assert!(
        e.contains("`cond` is not allowed together with a compound `after`"),
        "{e}"
    );
    let e = err(program(
        json!([{"name": "T1", "type": "TOF"}]),
        json!([{"id": 1, "op": "TON", "instance": "T1", "in": [true, "T#1s"]}]),
    ));
    assert_eq!(e, "network N1 block 1 at fbd.networks[0].blocks[0].instance: this block needs a TON instance, but `T1` is TOF");
    let e = err(program(
        json!(int_vars(&["a"])),
        json!([{"id": 1, "op": "ADD", "in": ["a", 1]}, {"id": 1, "op": "SUB", "in": ["a", 1]}]),
    ));
    assert_eq!(e, "network N1 block 1 at fbd.networks[0].blocks[1].id: block id 1 is used twice in this POU (first at fbd.networks[0].blocks[0])");
    let e = err(program(
        json!(int_vars(&["a"])),
        json!([{"id": 1, "op": "ADD", "in": ["a"]}]),
    ));
    assert_eq!(
        e,
        "network N1 block 1 at fbd.networks[0].blocks[0].in: ADD takes two or more inputs, found 1"
    );
    let e = err(program(
        json!(int_vars(&["a"])),
        json!([{"id": 1, "op": "TON", "instance": "a", "in": [true]}]),
    ));
    assert_eq!(
        e,
        "network N1 block 1 at fbd.networks[0].blocks[0].in: TON takes 2 inputs (IN, PT), found 1"
    );
    let e = err(program(
        json!(int_vars(&["a"])),
        json!([{"id": 1, "op": "MOVE", "in": [{"from": 1, "pin": "Q"}], "out": "a"}]),
    ));
    assert_eq!(e, "network N1 block 1 at fbd.networks[0].blocks[0].in[0].pin: block 1 (MOVE) has no output `Q` (outputs: OUT)");
    let e = err(
        json!({"program": "t", "vars": [{"name": "t", "type": "TIME"}],
        "fbd": {"networks": [{"id": "N1", "blocks": [{"id": 1, "op": "TSTART", "in": ["t"]}]}]},
        "rungs": [{"id": "R1", "ld": []}]}),
    );
    assert_eq!(
        e,
        "at fbd: `fbd` is not allowed together with `rungs` (a body is one of them)"
    );
}

#[test]
fn a_time_variable_is_accumulated_in_one_pou_only() {
    let body =
        json!({"networks": [{"id": "G", "blocks": [{"id": 1, "op": "TSTART", "in": ["shared"]}]}]});
    let e = err(json!({"program": "t",
        "vars": [{"name": "shared", "type": "TIME"}, {"name": "A", "type": "FB"}, {"name": "B", "type": "FB"}],
        "function_blocks": {"FB": {"fbd": body}},
        "fbd": {"networks": [{"id": "N1", "blocks": [{"id": 1, "op": "FB", "instance": "A"}, {"id": 2, "op": "FB", "instance": "B"}]}]}}));
    assert_eq!(e, "network G block 1 at function_blocks.FB.fbd.networks[0].blocks[0].in[0]: TIME variable `shared` is accumulated (TSTART/TSTOP) in A and in B; accumulate it in one POU only");
}
