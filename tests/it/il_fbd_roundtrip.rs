//! `plc-deps il` on random boolean FBD networks (AND, OR, NOT on variables and arcs, results
//! shared by several blocks and written to variables, including variables the network also
//! reads): the STL read back gives the same state after every scan as the FBD program, for
//! random inputs; networks the N-ary tree walk cannot hold are refused by name, never mistranslated.

use crate::common;

use common::Rng;
use plc_deps::exec::{ExecConfig, Layout, Machine};
use plc_deps::model::{Program, Value, VarClass, VarId};
use proptest::prelude::*;
use serde_json::json;

const READS: &[&str] = &["i0", "i1", "i2", "i3", "m0", "m1"];
const WRITES: &[&str] = &["q0", "q1", "q2", "m0", "m1"];

fn network(rng: &mut Rng, id: usize) -> serde_json::Value {
    let n = 2 + rng.below(7) as usize;
    let mut blocks = Vec::new();
    let mut written = Vec::new();
    for j in 1..=n {
        let op = *rng.pick(&["AND", "OR", "NOT"]);
        let pins = if op == "NOT" {
            1
        } else {
            2 + rng.below(2) as usize
        };
        let ins: Vec<serde_json::Value> = (0..pins)
            .map(|_| {
                if j > 1 && rng.chance(45) {
                    json!({"from": 1 + rng.below(j as u64 - 1)})
                } else {
                    json!(*rng.pick(READS))
                }
            })
            .collect();
        let mut b = json!({"id": j, "op": op, "in": ins});
        let w = *rng.pick(WRITES);
        if (rng.chance(40) || j == n) && !written.contains(&w) {
            written.push(w);
            b["out"] = json!(w);
        }
        blocks.push(b);
    }
    json!({"id": format!("N{id}"), "blocks": blocks})
}

fn program(seed: u64) -> String {
    let mut rng = Rng::new(seed);
    let mut vars = Vec::new();
    for i in ["i0", "i1", "i2", "i3"] {
        vars.push(json!({"name": i, "type": "BOOL", "class": "input"}));
    }
    for q in ["q0", "q1", "q2"] {
        vars.push(json!({"name": q, "type": "BOOL", "class": "output"}));
    }
    vars.push(json!({"name": "m0", "type": "BOOL"}));
    vars.push(json!({"name": "m1", "type": "BOOL", "init": true}));
    let nets: Vec<_> = (0..1 + rng.below(2) as usize)
        .map(|k| network(&mut rng, k))
        .collect();
    json!({"program": "fbd", "vars": vars, "fbd": {"networks": nets}}).to_string()
}

fn states(p: &Program, names: &[&str], inputs: &[Vec<bool>]) -> Vec<String> {
    let m = Machine::new(
        p,
        Layout::dense(p),
        &ExecConfig {
            cycle_ms: 10,
            loop_cap: 10,
            scan_budget: plc_deps::exec::DEFAULT_SCAN_BUDGET,
        },
    )
    .unwrap();
    let id = |n: &str| VarId::from_raw(p.vars().iter().position(|v| v.name == n).unwrap() as u32);
    let ins: Vec<VarId> = p
        .vars()
        .iter()
        .enumerate()
        .filter(|(_, v)| v.class == VarClass::Input)
        .map(|(i, _)| VarId::from_raw(i as u32))
        .collect();
    let mut st = m.initial_state();
    inputs
        .iter()
        .enumerate()
        .map(|(k, row)| {
            let set: Vec<_> = ins
                .iter()
                .zip(row)
                .map(|(v, b)| (*v, Value::Bool(*b)))
                .collect();
            m.set_inputs(&mut st, &set);
            m.run_scan(&mut st, k as u64, &mut Vec::new());
            names
                .iter()
                .map(|n| format!("{n}={} ", m.value(&st, id(n)).to_json()))
                .collect()
        })
        .collect()
}

/// True when compared (panics on a difference); false when the loader or `il` refused it.
fn round_trip(seed: u64) -> bool {
    let text = program(seed);
    let Ok((p, fbd)) = plc_deps::load::program_and_fbd_from_json(&text) else {
        return false;
    };
    let stl = match plc_deps::codegen::il::generate(&p, &fbd) {
        Ok(s) => s,
        Err(e) => {
            assert!(e.place.starts_with("network N"), "{e}");
            return false;
        }
    };
    let (back, _) =
        plc_deps::load::stl(&stl).unwrap_or_else(|e| panic!("{}\n{stl}", e.in_file("il.stl")));
    let mut rng = Rng::new(seed ^ 77);
    let inputs: Vec<Vec<bool>> = (0..10)
        .map(|_| (0..4).map(|_| rng.chance(50)).collect())
        .collect();
    let names = ["q0", "q1", "q2", "m0", "m1"];
    assert_eq!(
        states(&p, &names, &inputs),
        states(&back, &names, &inputs),
        "seed {seed}\n{text}\n{stl}"
    );
    true
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 128, ..ProptestConfig::default() })]
    #[test]
    fn random_boolean_fbd_networks_survive_il_and_back(seed in any::<u64>()) {
        round_trip(seed);
    }
}

/// Of 400 seeds, 208 programs load; 86 of them are translated and compared, 114 are refused
/// for a block fed by two forks (that needs a scratch bit), the rest for their read/write order.
#[test]
fn many_random_boolean_networks_are_translated() {
    let done = (0..400).filter(|&s| round_trip(s)).count();
    eprintln!("{done} of 400 random FBD programs translated and compared");
    assert!(done >= 80, "only {done} of 400");
}
