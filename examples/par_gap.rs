//! Where the parallel scan's time goes, against the sequential walk, with and without the work a
//! caller does between scans.
//!
//! `cargo run --release --example par_gap -- FILE [scans] [rounds] [threads]`
//!
//! `plc-deps run` digests the whole state after every scan (to check seq == par), on the calling
//! thread, between two timed scans. That is untimed work for the caller, but it moves every line
//! the other workers wrote into the caller's cache, and it keeps the other workers waiting at the
//! next scan's first barrier for as long as it lasts. This example times, per plan kind (`seq`,
//! `par`, `deps`), the scans of a run whose driver does nothing between scans (`idle`) and of
//! one that reads every byte of the state after each scan as the digest does (`read`), in
//! alternating rounds, and prints the medians and ranges. The host's speed
//! drifts from round to round, so the last column is each plan's time against seq's in the
//! *same* round (the median of those per-round ratios, and their range). Nothing here is used by
//! the tool.

use plc_deps::analysis::analyse;
use plc_deps::exec::parallel::{ParallelMachine, PlanConfig, PlanKind, ScanDriver};
use plc_deps::exec::{ExecConfig, Fault, Machine};
use std::time::Duration;

/// A driver that times every scan and, when `read`, reads the whole state after it.
struct Probe {
    read: bool,
    total: Duration,
    sink: u64,
}

impl ScanDriver for Probe {
    fn before_scan(&mut self, _: &Machine, _: u64, _: &mut [u8]) {}
    fn after_scan(&mut self, _: &Machine, _: u64, slots: &[u8], _: &[Fault], t: Duration) {
        self.total += t;
        if self.read {
            let mut x = 0u64;
            for c in slots.chunks(8) {
                let mut w = [0u8; 8];
                w[..c.len()].copy_from_slice(c);
                x = (x ^ u64::from_le_bytes(w)).wrapping_mul(0x9E37_79B9_7F4A_7C15);
            }
            self.sink ^= x;
        }
    }
}

fn main() {
    let mut args = std::env::args().skip(1);
    let file = args
        .next()
        .expect("usage: par_gap FILE [scans] [rounds] [threads]");
    let scans: u64 = args.next().map_or(1000, |a| a.parse().expect("scan count"));
    let rounds: usize = args.next().map_or(3, |a| a.parse().expect("round count"));
    let threads: usize = args.next().map_or(2, |a| a.parse().expect("thread count"));
    let text = std::fs::read_to_string(&file).expect("reads the program");
    let program = plc_deps::load::program_from_json(&text).expect("the program loads");
    let analysis = analyse(&program);
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads.saturating_sub(1).max(1))
        .build()
        .expect("a pool");
    let kinds = [PlanKind::Seq, PlanKind::Par, PlanKind::Deps];
    let machines: Vec<ParallelMachine> = kinds
        .iter()
        .map(|&kind| {
            let config = PlanConfig {
                kind,
                ..PlanConfig::new(threads)
            };
            ParallelMachine::new(&program, &analysis, &ExecConfig::default(), &config)
                .expect("lowers")
        })
        .collect();
    let mut sink = 0u64;
    // results[kind][read] = µs per scan, one per round
    let mut results = vec![[Vec::new(), Vec::new()]; kinds.len()];
    for _ in 0..rounds {
        for (k, pm) in machines.iter().enumerate() {
            for read in [false, true] {
                let mut state = pm.initial_state();
                let mut d = Probe {
                    read,
                    total: Duration::ZERO,
                    sink: 0,
                };
                pm.run(Some(&pool), &mut state, 0..16, &mut d);
                d.total = Duration::ZERO;
                pm.run(Some(&pool), &mut state, 16..16 + scans, &mut d);
                sink ^= d.sink;
                results[k][read as usize].push(d.total.as_secs_f64() * 1e6 / scans as f64);
            }
        }
    }
    std::hint::black_box(sink);
    println!("{file}: {scans} scans a run, {rounds} rounds, {threads} threads; µs per scan");
    let med = |v: &[f64]| {
        let mut v = v.to_vec();
        v.sort_by(f64::total_cmp);
        (v[v.len() / 2], v[0], v[v.len() - 1])
    };
    for (k, &kind) in kinds.iter().enumerate() {
        for read in [false, true] {
            let r = read as usize;
            let (m, lo, hi) = med(&results[k][r]);
            let paired: Vec<f64> = results[0][r]
                .iter()
                .zip(&results[k][r])
                .map(|(s, p)| s / p)
                .collect();
            let (pm, plo, phi) = med(&paired);
            let name = kind.name();
            println!(
                "  {name:8} {:5} {m:9.1} ({lo:.1}–{hi:.1})  {pm:.2}x seq ({plo:.2}–{phi:.2})",
                if read { "read" } else { "idle" },
            );
        }
    }
}
