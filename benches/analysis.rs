//! Speed of the analysis (parse excluded) on generated programs, and the per-variable data
//! dependence method against the pairwise definition.
//!
//! Targets (issue 2): a 1,000,000-rung program analysed in under 1 s on the 2-core machine; growth
//! from 100k to 1M within 12×; at 20k rungs the dependence computation at least 100× faster than
//! the pairwise method. `cargo bench --bench analysis`.

use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion};
use plc_deps::analysis::dependences::data_dependences_pairwise;
use plc_deps::analysis::{accesses, analyse, data_dependences, data_levels};
use plc_deps::model::Program;
use plc_deps::synth::{generate_string, GenConfig};

#[global_allocator]
static GLOBAL: mimalloc::MiMalloc = mimalloc::MiMalloc;

fn program(rungs: usize) -> Program {
    let config = GenConfig {
        rungs,
        width: 1000,
        seed: 42,
        timers: true,
        loops: true,
        jumps: true,
        calls: false,
        ..Default::default()
    };
    plc_deps::read::program_from_json(&generate_string(&config)).expect("generated programs load")
}

fn analysis(c: &mut Criterion) {
    let mut group = c.benchmark_group("analyse");
    group.sample_size(10);
    for rungs in [100_000usize, 1_000_000] {
        let p = program(rungs);
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

criterion_group!(benches, analysis, dependences_vs_pairwise);
criterion_main!(benches);
