//! Speed of loading (reading the JSON text into the surface syntax, then resolving it into the
//! model) on generated programs of 100k and 1M rungs, with throughput in bytes of program text.
//!
//! Target: at least 100 MB/s of program JSON, parse and resolve together. `cargo bench --bench
//! load`; the `load` group loads as the command line does (the main rungs resolved as they are
//! read), the `parse` group times the reader alone, into the whole syntax tree. The programs
//! are generated in-process (`plc_deps::synth`) with every knob on, so the timers, loops, jumps
//! and calls are read too.

use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion, Throughput};
use plc_deps::synth::{generate_string, GenConfig};

#[global_allocator]
static GLOBAL: mimalloc::MiMalloc = mimalloc::MiMalloc;

fn text(rungs: usize) -> String {
    generate_string(&GenConfig::all_features(rungs, 5000, 42))
}

fn load(c: &mut Criterion) {
    let mut group = c.benchmark_group("load");
    group.sample_size(10);
    for rungs in [100_000usize, 1_000_000] {
        let t = text(rungs);
        group.throughput(Throughput::Bytes(t.len() as u64));
        group.bench_with_input(BenchmarkId::from_parameter(rungs), &t, |b, t| {
            b.iter(|| plc_deps::load::program_from_json(t).expect("generated programs load"))
        });
    }
    group.finish();
    let mut group = c.benchmark_group("parse");
    group.sample_size(10);
    for rungs in [100_000usize, 1_000_000] {
        let t = text(rungs);
        group.throughput(Throughput::Bytes(t.len() as u64));
        group.bench_with_input(BenchmarkId::from_parameter(rungs), &t, |b, t| {
            b.iter(|| {
                plc_deps::read::json::parse(t)
                    .map(|s| s.vars.len())
                    .expect("parses")
            })
        });
    }
    group.finish();
}

criterion_group!(benches, load);
criterion_main!(benches);
