//! Speed of the analysis (parse excluded) on generated programs, and the per-variable data
//! dependence method against the pairwise definition.
//!
//! * `analyse/100000`, `analyse/1000000`: `gen --rungs N --width 1000 --timers --loops --jumps`
//!   (one fixed generator seed). Targets: 1,000,000 rungs analysed in under 1 s on the 2-core
//!   machine; growth from 100k to 1M within 12×.
//! * `data dependences 20k rungs`: the per-variable method at least 100× faster than the
//!   pairwise definition.
//! * `hot variable 100k rungs`: the 100k program with `--hot-fraction 0.05`, 5,000 writers and
//!   500 readers of one BOOL (about 12.5 million output pairs under the every-pair definition),
//!   so the cost of one hot variable can be measured against `analyse/100000`.
//!
//! `cargo bench --bench analysis` (a few minutes); `cargo bench --bench analysis -- --test` runs
//! each benchmark once. Parse time is excluded everywhere.

use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion};
use plc_deps::analysis::dependences::data_dependences_pairwise;
use plc_deps::analysis::{accesses, analyse, data_dependences, data_levels};
use plc_deps::model::Program;
use plc_deps::synth::{generate_string, GenConfig};
use std::time::Duration;

#[global_allocator]
static GLOBAL: mimalloc::MiMalloc = mimalloc::MiMalloc;

/// The benchmark shape: 1000 lanes, timers, loops and jumps, no calls.
fn shape(rungs: usize) -> GenConfig {
    GenConfig {
        rungs,
        width: 1000,
        seed: 42,
        timers: true,
        loops: true,
        jumps: true,
        calls: false,
        ..Default::default()
    }
}

fn load(config: &GenConfig) -> Program {
    plc_deps::load::program_from_json(&generate_string(config)).expect("generated programs load")
}

fn program(rungs: usize) -> Program {
    load(&shape(rungs))
}

fn analysis(c: &mut Criterion) {
    let mut group = c.benchmark_group("analyse");
    group.sample_size(10);
    for rungs in [100_000usize, 1_000_000] {
        let p = program(rungs);
        if rungs >= 1_000_000 {
            // 10 samples of about a second each: keep the whole run short.
            group.warm_up_time(Duration::from_secs(1));
            group.measurement_time(Duration::from_secs(8));
        }
        group.bench_with_input(BenchmarkId::from_parameter(rungs), &p, |b, p| {
            b.iter(|| analyse(p))
        });
    }
    group.finish();
}

fn dependences_vs_pairwise(c: &mut Criterion) {
    let p = program(20_000);
    let acc = accesses(&p);
    let mut group = c.benchmark_group("data dependences 20k rungs");
    group.sample_size(10);
    group.bench_function("per variable (pairs + levels)", |b| {
        b.iter(|| {
            (
                data_dependences(&acc.reads, &acc.writes),
                data_levels(&acc.reads, &acc.writes),
            )
        })
    });
    group.bench_function("pairwise definition", |b| {
        b.iter(|| data_dependences_pairwise(&acc.reads, &acc.writes))
    });
    group.finish();
}

fn hot_variable(c: &mut Criterion) {
    let p = load(&GenConfig {
        hot_fraction: Some(0.05),
        ..shape(100_000)
    });
    let acc = accesses(&p);
    let mut group = c.benchmark_group("hot variable 100k rungs");
    group.sample_size(10);
    group.bench_function("analyse", |b| b.iter(|| analyse(&p)));
    group.bench_function("data dependences (per variable)", |b| {
        b.iter(|| data_dependences(&acc.reads, &acc.writes))
    });
    group.finish();
}

criterion_group!(benches, analysis, dependences_vs_pairwise, hot_variable);
criterion_main!(benches);
