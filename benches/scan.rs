//! Scan speed: the sequential interpreter and the parallel executor, per scan, on
//! - `gen --rungs 20000 --width 1000` (20 levels of ~1000 rungs of 4–6 contacts and an output,
//!   each reading nearby lanes of the level before: the "local" shape),
//! - `gen --rungs 20000 --levels 20 --reads random` (the same, each rung reading 3–6 variables
//!   drawn at random from the whole level before),
//! - a 50-rung chain (each rung reads the previous rung's coil: no parallelism; the parallel
//!   executor must fall back to the sequential scan),
//! - 20,000 uniform rungs of 6 contacts and a coil on 64 inputs (the interpreter's best case).
//!
//! Throughput is in main-program rungs, so criterion prints rung executions per second.
//! The parallel benchmarks enter the workers once per batch of scans (`iter_custom`), as
//! `plc-deps run` does once per run. Run with `cargo bench --bench scan`.

use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion, Throughput};
use plc_deps::analysis::analyse;
use plc_deps::exec::parallel::{ParallelMachine, PlanConfig, PlanKind, ScanDriver};
use plc_deps::exec::{ExecConfig, Fault, Layout, Machine};
use plc_deps::model::Program;
use serde_json::json;
use std::time::{Duration, Instant};

fn generated(rungs: usize, width: usize, reads: plc_deps::synth::Reads) -> Program {
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
fn chain(n: usize) -> Program {
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
fn uniform(n: usize) -> Program {
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
    fn wants_time(&self) -> bool {
        false
    }
}

fn bench_program(c: &mut Criterion, name: &str, p: &Program) {
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

fn scan(c: &mut Criterion) {
    use plc_deps::synth::Reads;
    bench_program(c, "gen-20000x1000", &generated(20_000, 1000, Reads::Local));
    bench_program(
        c,
        "random-reads-20000x20-levels",
        &generated(20_000, 1000, Reads::Random),
    );
    bench_program(c, "chain-50", &chain(50));
    bench_program(c, "uniform-6-contacts-20000", &uniform(20_000));
}

criterion_group! {
    name = benches;
    config = Criterion::default().sample_size(30).measurement_time(Duration::from_secs(4));
    targets = scan
}
criterion_main!(benches);
