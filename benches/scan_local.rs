//! Scan speed on one shape, the local shape: `gen --rungs 20000 --width 1000`: the sequential interpreter and the parallel executor (see
//! `scan_shapes`). Run with `cargo bench --bench scan_local` (well under a minute).

mod scan_shapes;

use criterion::{criterion_group, criterion_main, Criterion};
use plc_deps::synth::Reads;
use scan_shapes::{bench_program, generated, quick};

fn scan(c: &mut Criterion) {
    bench_program(c, "gen-20000x1000", &generated(20_000, 1000, Reads::Local));
}

criterion_group! {
    name = benches;
    config = quick();
    targets = scan
}
criterion_main!(benches);
