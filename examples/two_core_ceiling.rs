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
//! and `exchange`, a parallel scan that *is* correct (each run checks its final states against the
//! sequential walk's): the same halves on private states, and after each level each thread packs
//! what its half wrote (BOOLs as bits, the rest as bytes) into an exchange buffer whose lines
//! each carry a sequence number, and the other thread, before its next level, waits for those
//! lines and unpacks them into its own state. A level's 500 BOOLs cross the cores as one line
//! instead of the eight a shared byte-per-BOOL state moves, and no line of the state itself is
//! ever shared. `ceiling` for it is the measured speed-up over the sequential walk (warm-up scans
//! included on both sides). (The executor's `par-exchange` candidate is this, built on the
//! planner's slices and the lowered code's writes; here it is the two halves of each level.)
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
    let rungs = program.rungs().len();
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
                for r in &analysis.schedule.tasks[t.raw() as usize].rungs {
                    match halves[h].last_mut() {
                        Some(last) if last.1 == r.raw() => last.1 = r.raw() + 1,
                        _ => halves[h].push((r.raw(), r.raw() + 1)),
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
                machine.run_from(&mut mem, &mut ctx, RungId::from_raw(lo), |r: RungId| {
                    lo <= r.raw() && r.raw() < hi
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
    // `exchange`: per (level, half) the variables it writes; variables grouped by their writers
    // (the set of (level, half) keys), BOOL groups apart, each group on its own lines.
    let nv = program.vars().len();
    let mut keys: Vec<Vec<u32>> = vec![Vec::new(); nv];
    let mut lvl_halves: Vec<[Vec<(u32, u32)>; 2]> = Vec::new();
    for (li, level) in analysis.schedule.levels.iter().enumerate() {
        let mid = level.len().div_ceil(2);
        let mut hs: [Vec<(u32, u32)>; 2] = [Vec::new(), Vec::new()];
        for (h, part) in [&level[..mid], &level[mid..]].into_iter().enumerate() {
            for t in part {
                for r in &analysis.schedule.tasks[t.raw() as usize].rungs {
                    for v in analysis.accesses.outs(*r) {
                        let k = (li * 2 + h) as u32;
                        if keys[v.index()].last() != Some(&k) {
                            keys[v.index()].push(k);
                        }
                    }
                    match hs[h].last_mut() {
                        Some(last) if last.1 == r.raw() => last.1 = r.raw() + 1,
                        _ => hs[h].push((r.raw(), r.raw() + 1)),
                    }
                }
            }
        }
        lvl_halves.push(hs);
    }
    let mut gmap: std::collections::BTreeMap<(bool, Vec<u32>), Vec<plc_deps::model::VarId>> =
        Default::default();
    for (v, key) in keys.iter().enumerate().filter(|(_, k)| !k.is_empty()) {
        let isb = program.vars()[v].ty == plc_deps::model::Type::Bool;
        gmap.entry((!isb, key.clone()))
            .or_default()
            .push(plc_deps::model::VarId::from_raw(v as u32));
    }
    let glist: Vec<_> = gmap.into_iter().collect();
    let groups: Vec<Vec<plc_deps::model::VarId>> = glist.iter().map(|g| g.1.clone()).collect();
    let glayout = Layout::from_groups(&program, &groups, 64).expect("groups");
    let xm = Machine::new(&program, glayout.clone(), &ExecConfig::default()).expect("lowers");
    // per (level, half): segments (lo, hi, is_bool, word offset in xbuf)
    let nk = lvl_halves.len() * 2;
    let mut segs: Vec<Vec<(usize, usize, bool, usize)>> = vec![Vec::new(); nk];
    let mut total = 0usize;
    for ((notb, ks), g) in &glist {
        let lo = g.iter().map(|v| glayout.bytes_of(*v).start).min().unwrap() as usize;
        let hi = g.iter().map(|v| glayout.bytes_of(*v).end).max().unwrap() as usize;
        for &k in ks {
            segs[k as usize].push((lo, hi, !*notb, 0));
        }
    }
    for sg in segs.iter_mut() {
        sg.sort();
        for s in sg.iter_mut() {
            s.3 = total;
            total += if s.2 {
                (s.1 - s.0).div_ceil(64)
            } else {
                (s.1 - s.0).div_ceil(8)
            };
        }
        total = total.next_multiple_of(7);
    }
    #[repr(align(64))]
    struct Line([std::sync::atomic::AtomicU64; 8]);
    let xbuf: Vec<Line> = (0..total / 7 + 1)
        .map(|_| Line(Default::default()))
        .collect();
    let word = |i: usize| &xbuf[i / 7].0[i % 7];
    let key_lines = |g: usize| {
        let lo = segs[g].first().map_or(0, |s| s.3) / 7;
        let hi = if g + 1 < segs.len() {
            segs[g + 1].first().map_or(lo, |s| s.3) / 7
        } else {
            total / 7
        };
        lo..hi
    };
    let wait_key = |g: usize, e: u64| {
        for l in key_lines(g) {
            while xbuf[l].0[7].load(Acquire) < e {
                std::hint::spin_loop();
            }
        }
    };
    use std::sync::atomic::Ordering::{Acquire, Relaxed, Release};
    let xhalf = |h: usize| {
        let mut state = xm.initial_state();
        let mut faults = Vec::new();
        let nl = lvl_halves.len() as u64;
        let mut scan = |k: u64| {
            let mut ctx = xm.context(k, &mut faults);
            for (li, hs) in lvl_halves.iter().enumerate() {
                let step = k * nl + li as u64;
                // wait for the other's previous level, then unpack it
                if li > 0 || k > 0 {
                    let g = (if li > 0 { li - 1 } else { lvl_halves.len() - 1 }) * 2 + (1 - h);
                    wait_key(g, step);
                    {
                        let st = state.bytes_mut();
                        for &(lo, hi, isb, off) in &segs[g] {
                            if isb {
                                unpack(&mut st[lo..hi], |i| word(off + i).load(Relaxed));
                            } else {
                                let hi8 = lo + (hi - lo).next_multiple_of(8);
                                for (i, chunk) in st[lo..hi8].chunks_mut(8).enumerate() {
                                    chunk.copy_from_slice(
                                        &word(off + i).load(Relaxed).to_le_bytes(),
                                    );
                                }
                            }
                        }
                    }
                }
                let mut mem = Unchecked(state.bytes_mut());
                for &(lo, hi) in &hs[h] {
                    xm.run_from(&mut mem, &mut ctx, RungId::from_raw(lo), |r: RungId| {
                        lo <= r.raw() && r.raw() < hi
                    });
                }
                // pack own writes
                let g = li * 2 + h;
                let st = state.bytes_mut();
                for &(lo, hi, isb, off) in &segs[g] {
                    if isb {
                        pack(&st[lo..hi], |i, w| word(off + i).store(w, Relaxed));
                    } else {
                        let hi8 = lo + (hi - lo).next_multiple_of(8);
                        for (i, chunk) in st[lo..hi8].chunks(8).enumerate() {
                            word(off + i)
                                .store(u64::from_le_bytes(chunk.try_into().unwrap()), Relaxed);
                        }
                    }
                }
                for l in key_lines(g) {
                    xbuf[l].0[7].store(step + 1, Release);
                }
            }
        };
        for k in 0..20 + scans {
            scan(k);
        }
        // final unpack of the other's last level
        let end = (20 + scans) * nl;
        let g = (lvl_halves.len() - 1) * 2 + (1 - h);
        wait_key(g, end);
        let st = state.bytes_mut();
        for &(lo, hi, isb, off) in &segs[g] {
            if isb {
                unpack(&mut st[lo..hi], |i| word(off + i).load(Relaxed));
            } else {
                let hi8 = lo + (hi - lo).next_multiple_of(8);
                for (i, chunk) in st[lo..hi8].chunks_mut(8).enumerate() {
                    chunk.copy_from_slice(&word(off + i).load(Relaxed).to_le_bytes());
                }
            }
        }
        state
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
    let xrows: Vec<[f64; 3]> = (0..rounds)
        .map(|r| {
            for p in &xbuf {
                p.0[7].store(0, Relaxed);
            }
            let alone = scan_many();
            let t = Instant::now();
            let (a, b) = std::thread::scope(|s| {
                let a = s.spawn(|| xhalf(0));
                let b = s.spawn(|| xhalf(1));
                (a.join().expect("runs"), b.join().expect("runs"))
            });
            let par = t.elapsed();
            if r == 0 {
                // check: both states equal seq state after 20+scans scans
                let mut st = xm.initial_state();
                let mut f = Vec::new();
                for k in 0..20 + scans {
                    xm.run_scan(&mut st, k, &mut f);
                }
                let (mut sa, mut sb) = (a, b);
                println!(
                    "exchange states equal seq: {} {}",
                    sa.bytes_mut() == st.bytes_mut(),
                    sb.bytes_mut() == st.bytes_mut()
                );
            }
            let ns = |d: Duration| d.as_nanos() as f64 / ((scans + 20) * rungs as u64) as f64;
            [
                ns(alone) * scans as f64 / (scans + 20) as f64,
                ns(par),
                alone.as_secs_f64() * (scans + 20) as f64 / scans as f64 / par.as_secs_f64(),
            ]
        })
        .collect();
    report("exchange (private states, packed bits per level)", &xrows);

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

const SPREAD: [u64; 256] = {
    let mut t = [0u64; 256];
    let mut i = 0;
    while i < 256 {
        let mut v = 0u64;
        let mut b = 0;
        while b < 8 {
            if i & (1 << b) != 0 {
                v |= 1 << (8 * b);
            }
            b += 1;
        }
        t[i] = v;
        i += 1;
    }
    t
};

#[inline(always)]
fn pack_word(c: &[u8; 64]) -> u64 {
    let mut w = 0u64;
    for j in 0..8 {
        let v = u64::from_le_bytes(c[8 * j..8 * j + 8].try_into().unwrap());
        w |= (v.wrapping_mul(0x0102_0408_1020_4080) >> 56) << (8 * j);
    }
    w
}

#[inline(always)]
fn pack(bytes: &[u8], mut put: impl FnMut(usize, u64)) {
    let (chunks, tail) = bytes.as_chunks::<64>();
    for (i, c) in chunks.iter().enumerate() {
        put(i, pack_word(c));
    }
    if !tail.is_empty() {
        let mut c = [0u8; 64];
        c[..tail.len()].copy_from_slice(tail);
        put(chunks.len(), pack_word(&c));
    }
}

#[inline(always)]
fn unpack_word(w: u64, c: &mut [u8; 64]) {
    for j in 0..8 {
        c[8 * j..8 * j + 8].copy_from_slice(&SPREAD[((w >> (8 * j)) & 255) as usize].to_le_bytes());
    }
}

#[inline(always)]
fn unpack(bytes: &mut [u8], get: impl Fn(usize) -> u64) {
    let (chunks, tail) = bytes.as_chunks_mut::<64>();
    let n = chunks.len();
    for (i, c) in chunks.iter_mut().enumerate() {
        unpack_word(get(i), c);
    }
    if !tail.is_empty() {
        let mut c = [0u8; 64];
        unpack_word(get(n), &mut c);
        let k = tail.len();
        tail.copy_from_slice(&c[..k]);
    }
}
