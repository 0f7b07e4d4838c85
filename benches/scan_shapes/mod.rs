//! The scan benchmarks' shapes and their one measurement, shared by `benches/scan.rs` (all
//! shapes) and the per-shape benches (`scan_local`, `scan_random`, `scan_chain`,
//! `scan_uniform`):
//! - `local`: `gen --rungs 20000 --width 1000` (20 levels of ~1000 rungs of 4–6 contacts and
//!   an output, each reading nearby lanes of the level before),
//! - `random`: `gen --rungs 20000 --width 1000 --reads random` (the same, each rung reading
//!   3–6 variables drawn at random from the whole level before),
//! - `chain`: 50 rungs, each reading the previous rung's coil (no parallelism: the parallel
//!   executor must fall back to the sequential scan),
//! - `uniform`: 20,000 rungs of 6 contacts and a coil on 64 inputs (the interpreter's best
//!   case).
//!
//! The generated shapes come from the library's generator (`plc_deps::synth`); the chain and
//! the uniform rungs are built here, as JSON programs. Throughput is in main-program rungs, so
//! criterion prints rung executions per second. Each shape is measured as the sequential scan
//! (`seq`) and the parallel executor on 2 workers with the measured plan (`par-auto-2`, or
//! `par-fallback` when it plans the sequential walk); the parallel benchmark enters the
//! workers once per batch of scans (`iter_custom`), as `plc-deps run` does once per run.

// Each bench uses the shapes it measures; the others are unused there.
#![allow(dead_code)]

use criterion::{BenchmarkId, Criterion, Throughput};
use plc_deps::analysis::analyse;
use plc_deps::exec::parallel::{ParallelMachine, PlanConfig, PlanKind, ScanDriver};
use plc_deps::exec::{ExecConfig, Fault, Layout, Machine};
use plc_deps::model::Program;
use serde_json::json;
use std::time::{Duration, Instant};

/// A program of `plc-deps gen`: `rungs` rungs in lanes of `width`, reading `reads`.
pub(crate) fn generated(rungs: usize, width: usize, reads: plc_deps::synth::Reads) -> Program {
    let text = plc_deps::synth::generate_string(&plc_deps::synth::GenConfig {
        rungs,
        width,
        seed: 1,
        reads,
        ..Default::default()
    });
    plc_deps::load::program_from_json(&text).expect("generated program loads")
}

/// Rung i reads the coil of rung i − 1 and an input.
pub(crate) fn chain(n: usize) -> Program {
    let mut vars = vec![json!({"name": "go", "type": "BOOL", "class": "input", "init": true})];
    let mut rungs = Vec::new();
    for i in 0..n {
        vars.push(json!({"name": format!("c{i}"), "type": "BOOL"}));
        let prev = if i == 0 {
            "go".to_string()
        } else {
            format!("c{}", i - 1)
        };
        rungs.push(json!({"id": format!("R{i}"), "ld": [{"contact": prev}, {"contact": "go"}, {"coil": format!("c{i}")}]}));
    }
    plc_deps::load::program_from_value(&json!({"program": "chain", "vars": vars, "rungs": rungs}))
        .expect("chain loads")
}

/// `n` rungs of 6 contacts (inputs, sometimes an earlier coil; a third negated) and a coil.
pub(crate) fn uniform(n: usize) -> Program {
    let mut x = 0x9E37_79B9_7F4A_7C15u64;
    let mut rand = move || {
        x ^= x << 13;
        x ^= x >> 7;
        x ^= x << 17;
        x
    };
    let mut vars: Vec<_> = (0..64)
        .map(|i| json!({"name": format!("i{i}"), "type": "BOOL", "class": "input"}))
        .collect();
    vars.extend((0..n).map(|k| json!({"name": format!("c{k}"), "type": "BOOL"})));
    let rungs: Vec<_> = (0..n)
        .map(|k| {
            let mut ld: Vec<_> = (0..6)
                .map(|_| {
                    let r = rand();
                    let name = if k > 0 && r % 4 == 0 {
                        format!("c{}", (r >> 8) as usize % k)
                    } else {
                        format!("i{}", (r >> 8) % 64)
                    };
                    json!({"contact": name, "negated": (r >> 40) % 3 == 0})
                })
                .collect();
            ld.push(json!({"coil": format!("c{k}")}));
            json!({"id": format!("R{k}"), "ld": ld})
        })
        .collect();
    plc_deps::load::program_from_value(&json!({"program": "uniform", "vars": vars, "rungs": rungs}))
        .expect("uniform loads")
}

struct Nothing;

impl ScanDriver for Nothing {
    fn before_scan(&mut self, _: &Machine, _: u64, _: &mut [u8]) {}
    fn after_scan(&mut self, _: &Machine, _: u64, _: &[u8], _: &[Fault], _: Duration) {}
    fn wants_state(&self) -> bool {
        false
    }
    fn wants_time(&self) -> bool {
        false
    }
}

pub(crate) fn bench_program(c: &mut Criterion, name: &str, p: &Program) {
    let rungs = p.main().rungs.len() as u64;
    let a = analyse(p);
    let exec = ExecConfig::default();
    let seq = Machine::new(p, Layout::dense(p), &exec).expect("lowers");
    let par = ParallelMachine::new(
        p,
        &a,
        &exec,
        &PlanConfig {
            kind: PlanKind::Auto,
            ..PlanConfig::new(2)
        },
    )
    .expect("lowers");
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .build()
        .expect("pool");
    let mut g = c.benchmark_group(name);
    g.throughput(Throughput::Elements(rungs));
    g.bench_function(BenchmarkId::new("seq", rungs), |b| {
        let mut st = seq.initial_state();
        let mut faults = Vec::new();
        let mut scan = 0;
        b.iter(|| {
            seq.run_scan(&mut st, scan, &mut faults);
            scan += 1;
        })
    });
    let label = if par.sequential_reason().is_some() {
        "par-fallback"
    } else {
        "par-auto-2"
    };
    g.bench_function(BenchmarkId::new(label, rungs), |b| {
        let mut st = par.initial_state();
        let mut scan = 0;
        b.iter_custom(|iters| {
            let t = Instant::now();
            let _ = par.run(Some(&pool), &mut st, scan..scan + iters, &mut Nothing);
            scan += iters;
            t.elapsed()
        })
    });
    g.finish();
}

/// A short measurement: 10 samples over 3 s after 1 s of warm-up, so that one shape's bench
/// (seq and par) takes well under a minute.
pub(crate) fn quick() -> Criterion {
    Criterion::default()
        .sample_size(10)
        .warm_up_time(Duration::from_secs(1))
        .measurement_time(Duration::from_secs(3))
}
