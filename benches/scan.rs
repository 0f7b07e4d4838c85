//! Scan speed on every shape of `scan_shapes` (local, random reads, chain, uniform), the
//! sequential interpreter and the parallel executor. Run with `cargo bench --bench scan`; one
//! shape alone with `cargo bench --bench scan_local` (or `scan_random`, `scan_chain`,
//! `scan_uniform`).

mod scan_shapes;

use criterion::{criterion_group, criterion_main, Criterion};
use plc_deps::synth::Reads;
use scan_shapes::{bench_program, chain, generated, quick, uniform};

fn scan(c: &mut Criterion) {
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
    config = quick();
    targets = scan
}
criterion_main!(benches);
