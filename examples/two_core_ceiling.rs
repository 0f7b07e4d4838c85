//! What two cores of this machine can give the scan at all: the ceiling of any parallel scan.
//!
//! `cargo run --release --example two_core_ceiling -- FILE [scans] [rounds]`
//!
//! A parallel scan of one program on two workers can be at most as fast as two *independent*
//! sequential scans running side by side, each on its own copy of the program and its own state:
//! they share nothing, wait for nothing and move no cache line between the cores, so whatever
//! keeps them from running twice as fast as one scan alone (two vCPUs that are one physical core's
//! hardware threads, a shared cache or memory bandwidth, a hypervisor's steal) caps the parallel
//! scan too. This example measures that ratio on a program file, and the same for a loop that
//! touches no memory (pure ALU work) as the machine's own ceiling:
//!
//! * `alone`: one thread runs `scans` sequential scans (the interpreter of `plc-deps run --mode
//!   seq`), timed;
//! * `side by side`: two threads each run `scans` scans of their own machine at the same time;
//! * `ceiling = 2 × alone / side by side`: 2.0 when the two cores are independent.
//!
//! and, closer to what a parallel scan does, `halves`: each of two threads runs half of every
//! level (the first and the second half of the level's tasks, in rung ranges, through
//! `Machine::run_from` as the parallel workers do), each on its own state, with nothing shared
//! and nothing waited for; `ceiling = alone / the slower half side by side`. This is the
//! speed-up a parallel scan of the program could reach on this host if moving state between the
//! cores and handing over between levels cost nothing. (On straight-line programs such as
//! `plc-deps gen`'s; results of a half are meaningless, only its time counts.)
//!
//! Rounds alternate the two, and the median and range over the rounds are printed, because the
//! host is shared and noisy. Nothing here is used by the tool: it explains the speed-up figures
//! of the README.

use plc_deps::exec::{Addr, ExecConfig, Layout, Machine, Store, Word};
use plc_deps::model::RungId;
use std::time::{Duration, Instant};

/// A state's bytes without a bounds check per access, as the parallel workers access theirs.
struct Unchecked<'a>(&'a mut [u8]);

impl Store for Unchecked<'_> {
    #[inline(always)]
    fn load<T: Word>(&self, at: Addr) -> T {
        debug_assert!(at.0 as usize + T::SIZE <= self.0.len());
        // SAFETY: every address a machine's instructions use ends inside its state size
        // (checked by `Machine::new`), and the slice is a state of that machine (`halves`).
        unsafe { T::read(self.0.get_unchecked(at.0 as usize..at.0 as usize + T::SIZE)) }
    }
    #[inline(always)]
    fn store<T: Word>(&mut self, at: Addr, v: T) {
        debug_assert!(at.0 as usize + T::SIZE <= self.0.len());
        // SAFETY: as in `load`.
        v.write(unsafe {
            self.0
                .get_unchecked_mut(at.0 as usize..at.0 as usize + T::SIZE)
        })
    }
}

fn main() {
    let mut args = std::env::args().skip(1);
    let file = args
        .next()
        .expect("usage: two_core_ceiling FILE [scans] [rounds]");
    let scans: u64 = args.next().map_or(1000, |a| a.parse().expect("scan count"));
    let rounds: usize = args.next().map_or(7, |a| a.parse().expect("round count"));
    let text = std::fs::read_to_string(&file).expect("reads the program");
    let program = plc_deps::load::program_from_json(&text).expect("the program loads");
    let rungs = program.rungs.len();
    let scan_many = || {
        let machine = Machine::new(&program, Layout::dense(&program), &ExecConfig::default())
            .expect("lowers");
        let mut state = machine.initial_state();
        let mut faults = Vec::new();
        // Warm the caches and the branch predictors, then time.
        for k in 0..20 {
            machine.run_scan(&mut state, k, &mut faults);
        }
        let t = Instant::now();
        for k in 0..scans {
            machine.run_scan(&mut state, 20 + k, &mut faults);
        }
        t.elapsed()
    };
    let alu = || {
        let t = Instant::now();
        let mut x = 0x9E37_79B9_7F4A_7C15u64;
        for _ in 0..200_000_000u64 {
            x ^= x << 13;
            x ^= x >> 7;
            x ^= x << 17;
        }
        std::hint::black_box(x);
        t.elapsed()
    };
    // Per level, the rung ranges of its first and of its second half of tasks.
    let analysis = plc_deps::analysis::analyse(&program);
    let machine =
        Machine::new(&program, Layout::dense(&program), &ExecConfig::default()).expect("lowers");
    let mut halves: [Vec<(u32, u32)>; 2] = [Vec::new(), Vec::new()];
    for level in &analysis.schedule.levels {
        let mid = level.len().div_ceil(2);
        for (h, part) in [&level[..mid], &level[mid..]].into_iter().enumerate() {
            for t in part {
                for r in &analysis.schedule.tasks[t.0 as usize].rungs {
                    match halves[h].last_mut() {
                        Some(last) if last.1 == r.0 => last.1 = r.0 + 1,
                        _ => halves[h].push((r.0, r.0 + 1)),
                    }
                }
            }
        }
    }
    let half = |h: usize| {
        let mut state = machine.initial_state();
        let mut faults = Vec::new();
        let mut scan = |k: u64| {
            let mut ctx = machine.context(k, &mut faults);
            let mut mem = Unchecked(state.bytes_mut());
            for &(lo, hi) in &halves[h] {
                machine.run_from(&mut mem, &mut ctx, RungId(lo), |r: RungId| {
                    lo <= r.0 && r.0 < hi
                });
            }
        };
        for k in 0..20 {
            scan(k);
        }
        let t = Instant::now();
        for k in 0..scans {
            scan(20 + k);
        }
        t.elapsed()
    };
    println!("{file}: {rungs} rungs, {scans} scans a run, {rounds} rounds");
    let split: Vec<[f64; 3]> = (0..rounds)
        .map(|_| {
            let alone = scan_many();
            let (a, b) = std::thread::scope(|s| {
                let a = s.spawn(|| half(0));
                let b = s.spawn(|| half(1));
                (a.join().expect("runs"), b.join().expect("runs"))
            });
            let ns = |d: Duration| d.as_nanos() as f64 / (scans * rungs as u64) as f64;
            [
                ns(alone),
                ns(a.max(b)),
                alone.as_secs_f64() / a.max(b).as_secs_f64(),
            ]
        })
        .collect();
    report("halves (each level split, private states)", &split);
    report(
        "interpreter",
        &ceilings(rounds, &scan_many, scans * rungs as u64),
    );
    report("ALU loop (no memory)", &ceilings(rounds, &alu, 200_000_000));
}

/// Per round: (ns per unit alone, ns per unit side by side, ceiling).
fn ceilings(rounds: usize, work: &(dyn Fn() -> Duration + Sync), units: u64) -> Vec<[f64; 3]> {
    (0..rounds)
        .map(|_| {
            let alone = work();
            let (a, b) = std::thread::scope(|s| {
                let a = s.spawn(work);
                let b = s.spawn(work);
                (a.join().expect("runs"), b.join().expect("runs"))
            });
            let side = a.max(b);
            let ns = |d: Duration| d.as_nanos() as f64 / units as f64;
            [
                ns(alone),
                ns(side),
                2.0 * alone.as_secs_f64() / side.as_secs_f64(),
            ]
        })
        .collect()
}

fn report(what: &str, rows: &[[f64; 3]]) {
    let median_range = |i: usize| {
        let mut v: Vec<f64> = rows.iter().map(|r| r[i]).collect();
        v.sort_by(f64::total_cmp);
        (v[v.len() / 2], v[0], v[v.len() - 1])
    };
    let (a, a0, a1) = median_range(0);
    let (s, s0, s1) = median_range(1);
    let (c, c0, c1) = median_range(2);
    println!(
        "{what}: alone {a:.2} ns/unit ({a0:.2}–{a1:.2}), side by side {s:.2} ({s0:.2}–{s1:.2}), \
         ceiling {c:.2}× ({c0:.2}–{c1:.2})"
    );
}
