//! Scan speed on one shape, a 50-rung chain (no parallelism): the sequential interpreter and the parallel executor (see
//! `scan_shapes`). Run with `cargo bench --bench scan_chain` (well under a minute).

mod scan_shapes;

use criterion::{criterion_group, criterion_main, Criterion};
use scan_shapes::{bench_program, chain, quick};

fn scan(c: &mut Criterion) {
    bench_program(c, "chain-50", &chain(50));
}

criterion_group! {
    name = benches;
    config = quick();
    targets = scan
}
criterion_main!(benches);
