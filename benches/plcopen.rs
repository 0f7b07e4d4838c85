//! Speed of loading PLCopen TC6 XML: a generated 50 MB LD file (rungs `(a OR NOT b) AND c →
//! coil d`, with the positions Beremiz writes), read into the surface syntax (`parse`: the XML
//! tree and the wiring of every body rebuilt into rungs) and read and resolved into the model
//! (`load`), with throughput in bytes of XML.
//!
//! Target: the whole load under 2 s. `cargo bench --bench plcopen`. The file is made by the
//! same generator as the test that checks it loads whole (`tests/plcopen_speed.rs`).

use criterion::{criterion_group, criterion_main, Criterion, Throughput};

#[global_allocator]
static GLOBAL: mimalloc::MiMalloc = mimalloc::MiMalloc;

#[allow(dead_code)]
#[path = "../tests/it/plcopen_common/generated.rs"]
mod px;

fn plcopen(c: &mut Criterion) {
    let (xml, rungs) = px::generated_ld(50_000_000);
    let mut group = c.benchmark_group("plcopen-50MB");
    group.sample_size(10);
    group.throughput(Throughput::Bytes(xml.len() as u64));
    group.bench_function("parse", |b| {
        b.iter(|| plc_deps::read::plcopen::parse(&xml).expect("the generated file parses"))
    });
    group.bench_function("load", |b| {
        b.iter(|| {
            let (p, _, _) = plc_deps::load::plcopen(&xml).expect("the generated file loads");
            assert_eq!(p.rungs().len(), rungs);
            p
        })
    });
    group.finish();
}

criterion_group!(benches, plcopen);
criterion_main!(benches);
