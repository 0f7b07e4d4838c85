//! `plc-deps il` and the STL reader together: a random ladder program (tests/common), written
//! as S7-200 STL and read back, gives the same state after every scan as the original under
//! the interpreter, for random inputs; and its STL loads, so no network needs more than the 9
//! levels of the S7-200 logic stack (the reader refuses a 10th).

use crate::common;

use plc_deps::exec::{ExecConfig, Layout, Machine};
use plc_deps::model::{Program, Type, Value, VarClass, VarId};
use proptest::prelude::*;
use serde_json::Value as Json;

/// The random programs use TP, which the S7-200 has not, and `b := a MOD b`, which has no
/// S7-200 form (the divisor's zero test would read the result): turned into TON and
/// `b := a MOD 2` before generating. MOD and `out := a - out` / `out := a / out` stay: the
/// STL computes them through a scratch word.
fn s7_only(v: &mut Json) {
    match v {
        Json::Object(m) => {
            if let Some(t) = m.remove("tp") {
                m.insert("ton".into(), t);
            }
            // TP, and the standard FBs S7-200 has no instruction for (their boxes are left
            // out below; what reads their outputs then reads a TON's, or fails to load).
            let none = ["TP", "SR", "RS", "R_TRIG", "F_TRIG", "CTUD"];
            if none.iter().any(|t| m.get("type") == Some(&Json::from(*t))) {
                m.insert("type".into(), "TON".into());
            }
            let out = m.get("out").cloned();
            if let (Some(Json::String(op)), Some(Json::Array(ins))) =
                (m.get("op").cloned(), m.get_mut("in"))
            {
                if op == "MOD" && out.is_some() && ins.get(1) == out.as_ref() {
                    ins[1] = Json::from(2);
                }
            }
            m.values_mut().for_each(s7_only);
        }
        Json::Array(a) => {
            // The standard FBs with no S7-200 instruction (SR, RS, R_TRIG, F_TRIG, CTUD) are
            // left out of the series they are in; so are the elementary types S7-200 has no
            // instructions for (`common::typed`, the LINT input `kl`): their variables and
            // every element that names one.
            const NONE: [&str; 5] = ["sr", "rs", "r_trig", "f_trig", "ctud"];
            a.retain(|e| !NONE.iter().any(|k| e.get(k).is_some()));
            let typed: Vec<String> = common::typed()
                .iter()
                .map(|(n, _, _)| n.to_string())
                .chain(["kl".to_string()])
                .map(|n| format!("\"{n}\""))
                .collect();
            a.retain(|e| {
                let text = e.to_string();
                !typed.iter().any(|n| text.contains(n.as_str()))
            });
            // The standard functions with an S7-200 instruction stay; the others are left out.
            const S7: [&str; 14] = [
                "ADD",
                "SUB",
                "MUL",
                "DIV",
                "MOD",
                "SQRT",
                "LN",
                "EXP",
                "SIN",
                "COS",
                "TAN",
                "INT_TO_DINT",
                "DINT_TO_REAL",
                "REAL_TO_DINT",
            ];
            a.retain(|e| {
                e.get("op")
                    .and_then(Json::as_str)
                    .is_none_or(|op| S7.contains(&op) || e.get("id").is_some())
            });
            a.iter_mut().for_each(s7_only)
        }
        _ => {}
    }
}

/// The state of every declared variable of `names` after each scan, as JSON text, and the
/// scan's faults (rung id and kind).
fn states(p: &Program, names: &[String], inputs: &[Vec<(String, Value)>]) -> Vec<Vec<String>> {
    let exec = ExecConfig {
        cycle_ms: 10,
        loop_cap: 12,
        scan_budget: plc_deps::exec::DEFAULT_SCAN_BUDGET,
    };
    let m = Machine::new(p, Layout::dense(p), &exec).unwrap();
    let id = |n: &str| {
        VarId::from_raw(
            p.vars()
                .iter()
                .position(|v| v.name == n)
                .unwrap_or_else(|| panic!("no {n}")) as u32,
        )
    };
    let mut st = m.initial_state();
    let mut out = Vec::new();
    for (k, scan) in inputs.iter().enumerate() {
        let set: Vec<(VarId, Value)> = scan.iter().map(|(n, v)| (id(n), *v)).collect();
        m.set_inputs(&mut st, &set);
        let mut faults = Vec::new();
        m.run_scan(&mut st, k as u64, &mut faults);
        let mut line: Vec<String> = names
            .iter()
            .map(|n| format!("{n}={}", m.value(&st, id(n)).to_json()))
            .collect();
        // The faults too (a MOD by zero is a DIV by zero in the STL: the same rung, once).
        line.extend(
            faults
                .iter()
                .map(|f| format!("fault {} {:?}", p.rung(f.rung).id, f.kind)),
        );
        out.push(line);
    }
    out
}

/// What one case did.
#[derive(Debug, PartialEq)]
enum Outcome {
    /// The loader refused the random program (a jump into a FOR body).
    Refused,
    /// `il` refused it: a timer's Q feeding more elements inside an output branch.
    NoForm,
    /// Written, read back and compared scan by scan (panics on the first difference).
    Same,
}

fn round_trip(seed: u64, input_seed: u64) -> Outcome {
    let mut doc: Json = serde_json::from_str(&common::random_program(seed, 16)).unwrap();
    s7_only(&mut doc);
    let Ok((p, fbd)) = plc_deps::load::program_and_fbd_from_json(&doc.to_string()) else {
        return Outcome::Refused;
    };
    let stl = match plc_deps::codegen::il::generate(&p, &fbd) {
        Ok(s) => s,
        Err(e) => {
            assert!(
                e.message.contains("inside an output branch"),
                "seed {seed}: {e}"
            );
            return Outcome::NoForm;
        }
    };
    let (back, _) = plc_deps::load::stl(&stl)
        .unwrap_or_else(|e| panic!("seed {seed}: {}\n{stl}", e.in_file("il.stl")));
    let names: Vec<String> = p
        .vars()
        .iter()
        .filter(|v| !v.hidden)
        .map(|v| v.name.clone())
        .collect();
    let mut rng = common::Rng::new(input_seed);
    let inputs: Vec<Vec<(String, Value)>> = (0..12)
        .map(|_| {
            p.vars()
                .iter()
                .filter(|v| v.class == VarClass::Input)
                .map(|v| {
                    let value = match v.ty {
                        Type::Bool => Value::Bool(rng.chance(50)),
                        _ => Value::Int(rng.below(7) as i16 - 2),
                    };
                    (v.name.clone(), value)
                })
                .collect()
        })
        .collect();
    let want = states(&p, &names, &inputs);
    let got = states(&back, &names, &inputs);
    for (k, (w, g)) in want.iter().zip(&got).enumerate() {
        assert_eq!(w, g, "seed {seed}, scan {k}\n{stl}");
    }
    Outcome::Same
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 128, ..ProptestConfig::default() })]
    #[test]
    fn random_ladder_programs_survive_il_and_back(seed in any::<u64>(), input_seed in any::<u64>()) {
        round_trip(seed, input_seed);
    }
}

/// Most random programs are compared, not skipped.
#[test]
fn most_random_programs_have_an_s7_200_form() {
    let outcomes: Vec<Outcome> = (0..300).map(|s| round_trip(s, s ^ 0x5a5a)).collect();
    let same = outcomes.iter().filter(|o| **o == Outcome::Same).count();
    let loaded = outcomes.iter().filter(|o| **o != Outcome::Refused).count();
    eprintln!("{same} of {loaded} loaded programs round-tripped");
    assert!(
        same * 10 >= loaded * 9,
        "only {same} of {loaded} loaded programs round-tripped"
    );
}
