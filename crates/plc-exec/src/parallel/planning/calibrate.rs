//! The per-line cost of the data-movement model, measured on this machine: a micro-benchmark of
//! a few milliseconds that `plc-deps run` runs once, at plan time, before planning for more
//! than one worker.
//!
//! Two threads share a buffer of [`LINES`] 64-byte lines. Each round, the *writer* writes one
//! word of every line and hands over (a release store); the *reader* then reads one word of
//! every line in a scrambled order — independent loads, as the interpreter's reads of several
//! variables are — timing the pass (the lines come from the writer's cache), then reads them
//! again (now from its own cache). The per-line cost is the median over rounds of the
//! difference, per line. With one step taken as 1 ns (the machine the other cost constants
//! were measured on: `config`), that is the line cost in steps.
//!
//! Safe code only (atomics, `std::thread::scope`). A round waits at most [`ROUND_WAIT`] for
//! the other thread, and counts only if the hand-over came while the reader spun ([`SPIN`]):
//! otherwise both threads may have shared a core and no line moved. With fewer than half the
//! rounds counted (a busy machine), the measurement gives up and the plan keeps the default. It does not pin threads: the operating system
//! places them, as it places the workers.

use crate::parallel::config::{LineCostSource, PlanConfig};
use std::sync::atomic::{AtomicU64, Ordering};
use std::time::{Duration, Instant};

/// Lines per round (32 KiB: fits the reader's L1/L2, so the second pass is a cache hit).
const LINES: usize = 512;
/// Rounds measured (the first one is not counted).
const ROUNDS: usize = 24;
/// How long a thread waits for the other in one round before giving up.
const ROUND_WAIT: Duration = Duration::from_millis(20);
/// How long a thread spins before it yields; a round whose hand-over took longer is not
/// counted (the two threads were not both on a core, so the lines may not have moved).
const SPIN: Duration = Duration::from_micros(50);

#[repr(align(64))]
struct Line([AtomicU64; 8]);

/// What the micro-benchmark measured: ns per line, in tenths.
#[derive(Copy, Clone, Debug, PartialEq, Eq)]
pub struct LineTiming {
    /// Reading a line the other thread wrote.
    pub remote_tenths_ns: u64,
    /// Reading a line already in the reader's cache.
    pub local_tenths_ns: u64,
}

impl LineTiming {
    /// The line cost in steps (1 step ≈ 1 ns), at least 1.
    pub fn steps(self) -> u64 {
        (self.remote_tenths_ns.saturating_sub(self.local_tenths_ns) / 10).max(1)
    }
}

/// Runs the micro-benchmark; `None` if the two threads could not meet (a busy machine).
pub fn measure_line_cost() -> Option<LineTiming> {
    let buf: Vec<Line> = (0..LINES)
        .map(|_| Line(std::array::from_fn(|_| AtomicU64::new(0))))
        .collect();
    // A scrambled order of the lines (an odd multiplier modulo a power of two is a bijection).
    let order: Vec<usize> = (0..LINES).map(|i| (i * 173 + 61) % LINES).collect();
    // Round r: the writer sets `turn` to 2r + 1 when the lines are written; the reader sets it
    // to 2r + 2 when it has read them.
    let turn = AtomicU64::new(0);
    // Waits until `turn` reaches `want`: Some(whether the other thread answered while this one
    // spun, so both were on a core), or None after ROUND_WAIT.
    let wait_for = |want: u64| -> Option<bool> {
        let start = Instant::now();
        let mut spins = 0u32;
        while turn.load(Ordering::Acquire) < want {
            spins = spins.wrapping_add(1);
            if spins.is_multiple_of(64) {
                let waited = start.elapsed();
                if waited > ROUND_WAIT {
                    return None;
                }
                if waited > SPIN {
                    std::thread::yield_now();
                }
            }
            std::hint::spin_loop();
        }
        Some(start.elapsed() <= SPIN)
    };
    let (buf, order, turn_ref) = (&buf, &order, &turn);
    std::thread::scope(|s| {
        s.spawn(move || {
            for r in 0..ROUNDS as u64 {
                if r > 0 && wait_for(2 * r).is_none() {
                    return;
                }
                for line in buf.iter() {
                    line.0[0].store(r, Ordering::Relaxed);
                }
                turn_ref.store(2 * r + 1, Ordering::Release);
            }
        });
        let mut remote = Vec::with_capacity(ROUNDS);
        let mut local = Vec::with_capacity(ROUNDS);
        for r in 0..ROUNDS as u64 {
            let Some(together) = wait_for(2 * r + 1) else {
                // Let the writer go on, so the scope can end.
                turn_ref.store(u64::MAX, Ordering::Release);
                return None;
            };
            let pass = || {
                let t = Instant::now();
                let sum: u64 = order
                    .iter()
                    .map(|&i| buf[i].0[0].load(Ordering::Relaxed))
                    .fold(0, u64::wrapping_add);
                std::hint::black_box(sum);
                t.elapsed().as_nanos() as u64
            };
            let (far, near) = (pass(), pass());
            if r > 0 && together {
                remote.push(far);
                local.push(near);
            }
            turn_ref.store(2 * r + 2, Ordering::Release);
        }
        if remote.len() < ROUNDS / 2 {
            return None;
        }
        remote.sort_unstable();
        local.sort_unstable();
        let per_line = |v: &[u64]| v[v.len() / 2] * 10 / LINES as u64;
        Some(LineTiming {
            remote_tenths_ns: per_line(&remote),
            local_tenths_ns: per_line(&local),
        })
    })
}

/// Round trips per batch of the hand-over measurement, and batches.
const TRIPS: u64 = 2000;
const BATCHES: usize = 7;

/// The time of one phase hand-over between two threads on this machine, in ns: two threads
/// increment one counter in turn (each waits, spinning, for the other's increment), as the
/// workers' completion counter is passed between phases; the median over batches of the time
/// per increment. A phase boundary of the plan costs about two of them (each worker's count
/// reaching the other) plus the spin that notices the last: the barrier cost is taken as three.
/// `None` when the threads could not both run (a batch took over 20 ms: a busy machine).
pub fn measure_handover() -> Option<u64> {
    let counter = AtomicU64::new(0);
    let gave_up = std::sync::atomic::AtomicBool::new(false);
    let (c, g) = (&counter, &gave_up);
    // Thread `me` (0 or 1) increments when the count is its parity, up to `until`.
    let play = move |me: u64, until: u64| -> bool {
        let start = Instant::now();
        let mut spins = 0u32;
        loop {
            let v = c.load(Ordering::Acquire);
            if v >= until {
                return true;
            }
            if v % 2 == me {
                c.store(v + 1, Ordering::Release);
                continue;
            }
            spins = spins.wrapping_add(1);
            if spins.is_multiple_of(256)
                && (g.load(Ordering::Relaxed) || start.elapsed() > ROUND_WAIT)
            {
                g.store(true, Ordering::Relaxed);
                return false;
            }
            std::hint::spin_loop();
        }
    };
    let mut per: Vec<u64> = Vec::with_capacity(BATCHES);
    std::thread::scope(|s| {
        s.spawn(move || {
            for b in 0..BATCHES as u64 {
                if !play(1, (b + 1) * 2 * TRIPS) {
                    return;
                }
            }
        });
        for b in 0..BATCHES as u64 {
            let t = Instant::now();
            if !play(0, (b + 1) * 2 * TRIPS) {
                return;
            }
            per.push(t.elapsed().as_nanos() as u64 / (2 * TRIPS));
        }
    });
    if gave_up.load(Ordering::Relaxed) || per.len() < BATCHES {
        return None;
    }
    per.sort_unstable();
    Some(per[BATCHES / 2].max(1))
}

impl PlanConfig {
    /// This configuration with the line cost ([`measure_line_cost`]) and the barrier cost
    /// ([`measure_handover`]) measured on this machine; unchanged for one worker; the defaults,
    /// saying so, when a measurement gave up.
    pub fn calibrated(self) -> PlanConfig {
        if self.threads < 2 {
            return self;
        }
        let handover = measure_handover();
        let s = PlanConfig {
            barrier_cost: handover.map_or(self.barrier_cost, |h| 3 * h),
            handover_ns: handover,
            ..self
        };
        match measure_line_cost() {
            Some(t) => PlanConfig {
                line_cost: t.steps(),
                line_cost_source: LineCostSource::Measured {
                    remote_tenths_ns: t.remote_tenths_ns,
                    local_tenths_ns: t.local_tenths_ns,
                },
                ..s
            },
            None => PlanConfig {
                line_cost_source: LineCostSource::GaveUp,
                ..s
            },
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_line_from_the_other_thread_costs_at_least_a_local_one_and_steps_are_positive() {
        // A busy machine may give up; when it measures, the numbers are sane.
        if let Some(t) = measure_line_cost() {
            assert!(t.remote_tenths_ns >= t.local_tenths_ns / 2, "{t:?}");
            assert!(t.steps() >= 1);
            assert!(t.remote_tenths_ns < 100_000, "{t:?} (10 µs a line)");
        }
        let t = LineTiming {
            remote_tenths_ns: 305,
            local_tenths_ns: 12,
        };
        assert_eq!(t.steps(), 29);
        let same = LineTiming {
            remote_tenths_ns: 10,
            local_tenths_ns: 12,
        };
        assert_eq!(same.steps(), 1);
    }
}
