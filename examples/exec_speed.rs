//! Interpreter speed: 20,000 rungs of 6 contacts and a coil, scanned repeatedly.
//!
//! `cargo run --release --example exec_speed [rungs] [scans]`
use plc_deps::exec::{ExecConfig, Layout, Machine};
use plc_deps::model::{Value, VarId};
use serde_json::json;
use std::time::Instant;

fn main() {
    let mut args = std::env::args().skip(1);
    let rungs: usize = args
        .next()
        .map_or(20_000, |a| a.parse().expect("rung count"));
    let scans: u64 = args.next().map_or(500, |a| a.parse().expect("scan count"));
    let inputs = 64usize;
    // xorshift, fixed seed: the same program every run.
    let mut x = 0x9E37_79B9_7F4A_7C15u64;
    let mut rand = move || {
        x ^= x << 13;
        x ^= x >> 7;
        x ^= x << 17;
        x
    };
    let mut vars = Vec::new();
    for i in 0..inputs {
        vars.push(json!({"name": format!("i{i}"), "type": "BOOL", "class": "input"}));
    }
    for k in 0..rungs {
        vars.push(json!({"name": format!("c{k}"), "type": "BOOL"}));
    }
    let mut rung_list = Vec::with_capacity(rungs);
    for k in 0..rungs {
        let mut ld = Vec::with_capacity(7);
        for _ in 0..6 {
            let r = rand();
            // Mostly inputs, sometimes an earlier coil; a third negated.
            let name = if k > 0 && r % 4 == 0 {
                format!("c{}", (r >> 8) as usize % k)
            } else {
                format!("i{}", (r >> 8) as usize % inputs)
            };
            if (r >> 40) % 3 == 0 {
                ld.push(json!({"contact": name, "negated": true}));
            } else {
                ld.push(json!({"contact": name}));
            }
        }
        ld.push(json!({"coil": format!("c{k}")}));
        rung_list.push(json!({"id": format!("R{k}"), "ld": ld}));
    }
    let doc = json!({"program": "speed", "vars": vars, "rungs": rung_list});
    let program = plc_deps::load::program_from_value(&doc).expect("program loads");
    let machine =
        Machine::new(&program, Layout::dense(&program), &ExecConfig::default()).expect("lowers");
    let mut state = machine.initial_state();
    let mut faults = Vec::new();
    // Input patterns, precomputed so that the timed loop only scans.
    let patterns: Vec<Vec<(VarId, Value)>> = (0..16)
        .map(|_| {
            (0..inputs)
                .map(|i| (VarId::from_raw(i as u32), Value::Bool(rand() % 2 == 0)))
                .collect()
        })
        .collect();
    for k in 0..20 {
        machine.scan(&mut state, k, &patterns[k as usize % 16], &mut faults);
    }
    let mut best = f64::MAX;
    let mut total = 0.0;
    let rounds = 5;
    for round in 0..rounds {
        let t = Instant::now();
        for k in 0..scans {
            machine.set_inputs(&mut state, &patterns[k as usize % 16]);
            machine.run_scan(&mut state, 20 + round * scans + k, &mut faults);
        }
        let ns = t.elapsed().as_nanos() as f64 / (scans as f64 * rungs as f64);
        best = best.min(ns);
        total += ns;
    }
    let on = (inputs..inputs + rungs)
        .filter(|&v| machine.value(&state, VarId::from_raw(v as u32)).as_bool() == Some(true))
        .count();
    assert!(faults.is_empty());
    println!(
        "{rungs} rungs × 7 elements, {} instructions, {scans} scans × {rounds} rounds: {:.2} ns/rung best, {:.2} mean; {:.0} M rungs/s; {on} coils on",
        machine.instruction_count(),
        best,
        total / rounds as f64,
        1e3 / best
    );
}
