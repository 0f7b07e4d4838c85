//! The FBD worked examples in `analyses/` (Example C of the FBD text-generation paper, KASKAD 1–5 of the KASKAD-SAU manual): their
//! order and fragment trees, and their behaviour on the scan interpreter, with the numbers
//! computed by hand from the seeds (comments give the computation).

use plc_deps::exec::{ExecConfig, Layout, Machine, State, VarValue};
use plc_deps::fbd::{Fbd, FbdPou};
use plc_deps::model::{Program, Value, VarId};
use std::path::Path;

struct Sim {
    p: Program,
    fbd: Fbd,
    m: Machine,
    st: State,
    scan: u64,
}

impl Sim {
    fn load(example: &str) -> Sim {
        let path = Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("analyses")
            .join(example)
            .join("program.json");
        let text = std::fs::read_to_string(&path).expect("example exists");
        let (p, fbd) = plc_deps::load::program_and_fbd_from_json(&text)
            .unwrap_or_else(|e| panic!("{example}: {e}"));
        let m = Machine::new(&p, Layout::dense(&p), &ExecConfig::default()).expect("lowers");
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
        assert!(faults.is_empty(), "scan {}: {faults:?}", self.scan);
        self.scan += 1;
    }

    fn int(&self, name: &str) -> i64 {
        match self.m.value(&self.st, self.id(name)) {
            VarValue::Scalar(Value::Int(i)) => i as i64,
            VarValue::Scalar(Value::Dint(i) | Value::Time(i)) => i as i64,
            other => panic!("{name} is not an integer: {other:?}"),
        }
    }

    fn real(&self, name: &str) -> f32 {
        match self.m.value(&self.st, self.id(name)) {
            VarValue::Scalar(Value::Real(f)) => f,
            other => panic!("{name} is not a REAL: {other:?}"),
        }
    }

    fn pou(&self, name: &str) -> &FbdPou {
        self.fbd
            .pous
            .iter()
            .find(|p| p.name == name)
            .unwrap_or_else(|| panic!("no FBD body {name}"))
    }
}

/// Block ids of a list of block indices.
fn ids(p: &FbdPou, net: usize, bs: &[plc_deps::fbd::BlockId]) -> Vec<u32> {
    bs.iter().map(|b| p.networks[net].block(*b).id).collect()
}

// ---------------------------------------------------------------- Example C (the FBD text-generation paper)

#[test]
fn example_c_order_and_fragment_tree_are_the_seeds() {
    let s = Sim::load("example-c");
    let pou = s.pou("block1");
    let plan = &pou.plans[0];
    // The emitted C: 3, 4; if (3) {flag; 8}; if (4) {flag; 10; 27; if (27) {24}}; if (flag) {15; 17}.
    assert_eq!(ids(pou, 0, &plan.order), vec![3, 4, 8, 10, 27, 24, 15, 17]);
    let tree: Vec<(String, Option<String>, String, Vec<u32>)> = plan
        .fragment_order()
        .into_iter()
        .map(|f| {
            let fr = &plan.fragments[f.index()];
            (
                fr.name.clone(),
                fr.parent.map(|q| plan.fragments[q.index()].name.clone()),
                fr.condition.clone(),
                ids(pou, 0, &fr.blocks),
            )
        })
        .collect();
    let expect = |n: &str, p: Option<&str>, c: &str, b: &[u32]| {
        (
            n.to_string(),
            p.map(str::to_string),
            c.to_string(),
            b.to_vec(),
        )
    };
    assert_eq!(
        tree,
        vec![
            expect("root", None, "always", &[3, 4]),
            expect("F(3)", Some("root"), "3.OUT", &[8]),
            expect("F(4)", Some("root"), "4.OUT", &[10, 27]),
            expect("F(27)", Some("F(4)"), "27.OUT", &[24]),
            expect("FC", Some("root"), "F(3) OR F(4)", &[15, 17]),
        ]
    );
    // The lowered rungs follow the fragment tree as nested `if` blocks.
    let rungs: Vec<&str> =
        s.p.pou_rungs(plc_deps::model::PouId::from_raw(0))
            .map(|r| s.p.rung(r).id.as_str())
            .collect();
    assert_eq!(
        rungs,
        vec![
            "N1.3",
            "N1.4",
            "N1.F(3)",
            "N1.8",
            "N1.F(3).end",
            "N1.F(4)",
            "N1.10",
            "N1.27",
            "N1.F(27)",
            "N1.24",
            "N1.F(27).end",
            "N1.F(4).end",
            "N1.FC",
            "N1.15",
            "N1.17",
            "N1.FC.end"
        ]
    );
}

#[test]
fn example_c_runs_like_the_seeds_c_for_var1_0_1_2() {
    let mut s = Sim::load("example-c");
    let int = |v: i16| Value::Int(v);
    let writes = |s: &Sim| s.int("WriteValue_17.Writes");
    // Var1 = 0: neither 3 nor 4 holds, so nothing runs; the run flag stays FALSE, WriteValue is
    // not called. Var3 keeps its initial 1.
    s.step(&[("Var1", int(0)), ("Var2", int(7))]);
    assert_eq!(
        (s.int("LVar"), s.int("Var3"), s.int("Written"), writes(&s)),
        (0, 1, 0, 0)
    );
    // Var1 = 1: F(3): LVar := 7 + 10 = 17, flag; FC: 15 = 17 - 1 = 16, WriteValue(16).
    s.step(&[("Var1", int(1)), ("Var2", int(7))]);
    assert_eq!(
        (s.int("LVar"), s.int("Var3"), s.int("Written"), writes(&s)),
        (17, 1, 16, 1)
    );
    // Var1 = 2: F(4): _10 = 7 * 3 = 21, LVar := 21; 27: 21 > 0, so F(27): Var3 := 1 * 21;
    // FC: 15 = 20, WriteValue(20).
    s.step(&[("Var1", int(2)), ("Var2", int(7))]);
    assert_eq!(
        (s.int("LVar"), s.int("Var3"), s.int("Written"), writes(&s)),
        (21, 21, 20, 2)
    );
    // Var1 = 0 again: the flag was reset at the network's start, FC does not run.
    s.step(&[("Var1", int(0)), ("Var2", int(7))]);
    assert_eq!(
        (s.int("LVar"), s.int("Var3"), s.int("Written"), writes(&s)),
        (21, 21, 20, 2)
    );
    // Var1 = 2, Var2 = 0: _10 = 0, LVar := 0; 27 false, so Var3 stays; FC: 0 - 1 = -1.
    s.step(&[("Var1", int(2)), ("Var2", int(0))]);
    assert_eq!(
        (s.int("LVar"), s.int("Var3"), s.int("Written"), writes(&s)),
        (0, 21, -1, 3)
    );
    // Var1 = 2, Var2 = 2: _10 = 6, Var3 := 21 * 6 = 126 (persistent data), WriteValue(5).
    s.step(&[("Var1", int(2)), ("Var2", int(2))]);
    assert_eq!(
        (s.int("LVar"), s.int("Var3"), s.int("Written"), writes(&s)),
        (6, 126, 5, 4)
    );
    // Var1 = 1, Var2 = 2: F(3) only: LVar := 12, WriteValue(11); Var3 untouched.
    s.step(&[("Var1", int(1)), ("Var2", int(2))]);
    assert_eq!(
        (s.int("LVar"), s.int("Var3"), s.int("Written"), writes(&s)),
        (12, 126, 11, 5)
    );
}

// ---------------------------------------------------------------- KASKAD 1–5 (the KASKAD-SAU manual)

#[test]
fn kaskad_1_average_of_three() {
    let mut s = Sim::load("kaskad-1");
    assert_eq!(
        ids(s.pou("Middle_3"), 0, &s.pou("Middle_3").plans[0].order),
        vec![1, 2, 3]
    );
    for (a, b, c) in [
        (1.5f32, 2.25f32, -0.75f32),
        (1.0, 2.0, 4.0),
        (10.0, 20.0, 30.5),
    ] {
        s.step(&[
            ("glVar1", Value::Real(a)),
            ("glVar2", Value::Real(b)),
            ("glVar3", Value::Real(c)),
        ]);
        // FAdd, FAdd, FDiv by 3 in f32, as the editor's code does.
        assert_eq!(
            s.real("Result"),
            ((a + b) + c) / 3.0,
            "({a} + {b} + {c}) / 3"
        );
    }
    assert_eq!(s.real("Result"), 20.166666);
}

fn kaskad_loop(example: &str) {
    let mut s = Sim::load(example);
    for k in 1..=5 {
        s.step(&[]);
        // Every scan: ten times Count := Count + 1, then idx := 0.
        assert_eq!(s.int("Count"), 10 * k, "{example}: Count after scan {k}");
        assert_eq!(s.int("idx"), 0, "{example}: idx after scan {k}");
    }
}

#[test]
fn kaskad_2_loop_with_post_check_adds_10_per_scan() {
    kaskad_loop("kaskad-2");
}

#[test]
fn kaskad_3_loop_with_pre_check_adds_10_per_scan() {
    kaskad_loop("kaskad-3");
}

/// The scans (0-based) after which `name` changed, over `scans` scans.
fn toggles(s: &mut Sim, name: &str, scans: u64) -> Vec<u64> {
    let mut last = s.int(name);
    let mut at = Vec::new();
    for _ in 0..scans {
        s.step(&[]);
        let now = s.int(name);
        if now != last {
            at.push(s.scan - 1);
            last = now;
        }
    }
    at
}

#[test]
fn kaskad_4_time_variable_pulse_generator() {
    // 10 ms cycle: scan k runs at 10k ms. Scan 0: TimeVar = 0, so TSTART (its hidden TON starts at
    // 0 ms); TimeVar < 1 s: RET. Scan k: the POU's first rung sets TimeVar := 10k ms. Scan 100:
    // TimeVar = 1000 ms is not < 1 s: TSTOP, TimeVar := 0, Result := 1 - 0 = 1. Scan 101
    // (1010 ms): TimeVar = 0, TSTART again, so the next toggle is at scan 101 + 100 = 201; then
    // every 101 scans: each half period is 1 s plus one scan.
    let mut s = Sim::load("kaskad-4");
    s.step(&[]);
    assert_eq!((s.int("TimeVar"), s.int("Result")), (0, 0));
    for _ in 1..=50 {
        s.step(&[]);
    }
    assert_eq!(
        s.int("TimeVar"),
        500,
        "TimeVar accumulates the elapsed time: 500 ms at scan 50"
    );
    let mut s = Sim::load("kaskad-4");
    let at = toggles(&mut s, "Result", 1000);
    assert_eq!(at, vec![100, 201, 302, 403, 504, 605, 706, 807, 908]);
    assert_eq!(s.int("Result"), 1, "nine toggles from 0");
}

#[test]
fn kaskad_5_two_generator_instances_keep_their_own_data() {
    // GENERATOR is example 4 with PERIOD for 1 s: Gen1 (PERIOD 1 s) toggles at 100, 201, 302, …;
    // Gen2 (PERIOD 2 s) at 200, 401, 602, 803 (each half period = PERIOD + one scan).
    let mut s = Sim::load("kaskad-5");
    let mut last = (0, 0);
    let (mut t1, mut t2) = (Vec::new(), Vec::new());
    for _ in 0..1000 {
        s.step(&[]);
        let now = (s.int("Result1"), s.int("Result2"));
        if now.0 != last.0 {
            t1.push(s.scan - 1);
        }
        if now.1 != last.1 {
            t2.push(s.scan - 1);
        }
        last = now;
    }
    assert_eq!(t1, vec![100, 201, 302, 403, 504, 605, 706, 807, 908]);
    assert_eq!(t2, vec![200, 401, 602, 803]);
    // Their data are separate: at scan 1000 (10 000 ms) Gen1 restarted at 9090 ms, Gen2 at 8040.
    assert_eq!(s.int("Gen1.GEN_TIMER"), 9990 - 9090);
    assert_eq!(s.int("Gen2.GEN_TIMER"), 9990 - 8040);
    assert_eq!((s.int("Gen1.RESULT"), s.int("Gen2.RESULT")), (1, 0));
}

#[test]
fn example_c_control_dependences_are_the_fragment_tree() {
    // Inside the network, each block rung is control dependent exactly on the guard of its
    // fragment (none for the root), and each guard on the guard of its parent fragment.
    let s = Sim::load("example-c");
    let a = plc_deps::analysis::analyse(&s.p);
    let name = |n: u32| {
        s.p.rungs()
            .get(n as usize)
            .map_or("START/STOP".to_string(), |r| r.id.clone())
    };
    let mut deps: Vec<(String, String)> = a
        .control
        .iter()
        .filter(|d| d.controller != d.dependent)
        .map(|d| (name(d.dependent), name(d.controller)))
        .filter(|(dep, _)| !dep.ends_with(".end") && dep.starts_with("N1."))
        .collect();
    deps.sort();
    let expect: Vec<(String, String)> = [
        ("N1.10", "N1.F(4)"),
        ("N1.24", "N1.F(27)"),
        ("N1.27", "N1.F(4)"),
        ("N1.8", "N1.F(3)"),
        ("N1.15", "N1.FC"),
        ("N1.17", "N1.FC"),
        ("N1.F(27)", "N1.F(4)"),
    ]
    .iter()
    .map(|(a, b)| (a.to_string(), b.to_string()))
    .collect::<std::collections::BTreeSet<_>>()
    .into_iter()
    .collect();
    assert_eq!(deps, expect);
}
