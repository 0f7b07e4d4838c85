//! Speed of writing the report (analysis excluded): the JSON and the default text report of
//! generated programs at 100k and 1M rungs, written to a sink so that only building the document
//! and rendering it are measured. Targets: the whole `report` of a 1M-rung program (read,
//! analyse, write) under 10 s end to end, growth 100k → 1M within 11×; this bench is the writing
//! part. `cargo bench --bench report`.

use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion};
use plc_deps::analysis::analyse;
use plc_deps::cmd::report::{write_report, ReportFormat};
use plc_deps::model::Program;
use plc_deps::report::TextOptions;
use plc_deps::synth::{generate_string, GenConfig};
use std::io::{self, Write};

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
    plc_deps::load::program_from_json(&generate_string(&config)).expect("generated programs load")
}

/// Counts the bytes written (so the output cannot be optimised away) and keeps none.
struct Sink(u64);

impl Write for Sink {
    fn write(&mut self, b: &[u8]) -> io::Result<usize> {
        self.0 += b.len() as u64;
        Ok(b.len())
    }
    fn flush(&mut self) -> io::Result<()> {
        Ok(())
    }
}

fn writing(c: &mut Criterion) {
    for rungs in [100_000usize, 1_000_000] {
        let p = program(rungs);
        let a = analyse(&p);
        let mut group = c.benchmark_group(format!("write report {rungs} rungs"));
        group.sample_size(10);
        for (name, format) in [("json", ReportFormat::Json), ("text", ReportFormat::Text)] {
            group.bench_with_input(BenchmarkId::from_parameter(name), &format, |b, &format| {
                b.iter(|| {
                    let mut sink = Sink(0);
                    write_report(
                        &p,
                        &a,
                        None,
                        format,
                        &TextOptions::default(),
                        None,
                        &mut sink,
                    )
                    .unwrap();
                    sink.0
                })
            });
        }
        group.finish();
    }
}

criterion_group!(benches, writing);
criterion_main!(benches);
