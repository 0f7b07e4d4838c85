//! Scan speed on one shape, 20,000 uniform rungs of 6 contacts and a coil: the sequential interpreter and the parallel executor (see
//! `scan_shapes`). Run with `cargo bench --bench scan_uniform` (well under a minute).

mod scan_shapes;

use criterion::{criterion_group, criterion_main, Criterion};
use scan_shapes::{bench_program, quick, uniform};

fn scan(c: &mut Criterion) {
    bench_program(c, "uniform-6-contacts-20000", &uniform(20_000));
}

criterion_group! {
    name = benches;
    config = quick();
    targets = scan
}
criterion_main!(benches);
