//! The synchronisation of a levelled plan's scans as *units* that any worker may run: a unit is
//! worker 0's start of a scan (the inputs written), one worker's slice of a parallel phase, or a
//! sequential phase. Every unit of a run has an id, growing through the run; a unit is
//! *claimed* by the one worker whose `fetch_max` of its id into the unit's claim cell finds a
//! smaller value, and counted in one completion counter when it is done. A phase may start when
//! the counter has reached the phase's first unit: so a worker that finds its neighbour's slice
//! unclaimed when it has finished its own runs it (takes it over), and a worker without a core of
//! its own (another process on it, more workers than cores) delays the scan by at most the unit
//! it is running, never by a scheduler time slice per barrier. This is the help-first work
//! taking of Blumofe & Leiserson (1999) cut down to static slices; the slices stay each worker's
//! first choice, so the layout's per-(phase, worker) lines keep one writer at a time.
//!
//! Also here: the window bell, worker 0's announcement of the next window of scans (a seqlock of
//! its few numbers, so a worker that wakes late never reads half of one window and half of
//! another), which the other workers wait on (spin, yield, park; worker 0 unparks them).
//!
//! Invariants: ids only grow (the window's base is the count of units issued before it), so a
//! claim for a unit of a finished scan always fails and a late worker never runs a stale unit;
//! completion is a Release increment and waits are Acquire loads of the counter, which orders a
//! unit's state writes before any later phase's reads. Depends on the barrier (its poison), the
//! backoff (the wait loop) and the padding; knows nothing of plans.

use super::backoff::{wait_until, Pace};
use super::barrier::SpinBarrier;
use crate::parallel::pad::Padded;
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::sync::OnceLock;
use std::thread::Thread;
use std::time::Duration;

/// A waiter (on the completion counter or the bell) spins 2^11 hints, then yields for 200 µs,
/// then parks.
const PACE: Pace = Pace {
    spins: 1 << 11,
    yield_for: Duration::from_micros(200),
};
/// One bounded park of a waiter on the completion counter.
const PARK: Duration = Duration::from_micros(50);

/// Claim cells and the completion counter of one run.
pub(super) struct Units {
    completed: Padded<AtomicU64>,
    claims: Box<[Padded<AtomicU64>]>,
}

impl Units {
    /// Cells for scans of at most `per_scan` units.
    pub(super) fn new(per_scan: usize) -> Units {
        Units {
            completed: Padded::new(AtomicU64::new(0)),
            claims: (0..per_scan)
                .map(|_| Padded::new(AtomicU64::new(0)))
                .collect(),
        }
    }

    /// Units completed in the run so far (Acquire).
    #[inline]
    pub(super) fn completed(&self) -> u64 {
        self.completed.load(Ordering::Acquire)
    }

    /// Claims the unit at position `pos` of its scan, whose id is `id` (at least 1): true for
    /// exactly one caller per id.
    #[inline]
    pub(super) fn claim(&self, pos: usize, id: u64) -> bool {
        let cell = &*self.claims[pos];
        cell.load(Ordering::Relaxed) < id && cell.fetch_max(id, Ordering::AcqRel) < id
    }

    /// A unit is done (Release: its writes are seen by whoever sees the count).
    #[inline]
    pub(super) fn done(&self) {
        self.completed.fetch_add(1, Ordering::Release);
    }

    /// Waits until `target` units are done, or `give_up` says so (checked while sleeping), or
    /// the barrier is poisoned. True when the count was reached.
    #[inline]
    pub(super) fn wait(
        &self,
        target: u64,
        poison: &SpinBarrier,
        give_up: impl Fn() -> bool,
    ) -> bool {
        self.completed() >= target || self.wait_slow(target, poison, give_up)
    }

    #[cold]
    fn wait_slow(&self, target: u64, poison: &SpinBarrier, give_up: impl Fn() -> bool) -> bool {
        let reached = || (self.completed() >= target).then_some(());
        let park = || {
            if poison.is_poisoned() || give_up() {
                return false;
            }
            std::thread::park_timeout(PARK);
            true
        };
        wait_until(poison.pace(PACE), reached, park).is_some()
    }
}

/// A window of scans as worker 0 announces it.
#[derive(Copy, Clone, Debug, PartialEq, Eq)]
pub(super) struct WindowNote {
    /// The plan index.
    pub(super) plan: usize,
    /// The first scan.
    pub(super) first: u64,
    /// Scans (0: the run is over).
    pub(super) scans: u64,
    /// Units issued before the window (the ids of its units start above it).
    pub(super) base: u64,
    /// A `par-exchange` window; `Some(true)` when the workers' private states must first be
    /// copied from the shared state (another candidate ran since their last window).
    pub(super) exchange: Option<bool>,
}

/// A worker waiting on the bell: whether it is parked, and its thread.
type Seat = Padded<(AtomicBool, OnceLock<Thread>)>;

/// Worker 0's announcement of windows, and the other workers' seats to wait on it.
pub(super) struct WindowBell {
    /// Odd while worker 0 writes the note; +2 per window.
    seq: Padded<AtomicU64>,
    plan: AtomicU64,
    first: AtomicU64,
    scans: AtomicU64,
    base: AtomicU64,
    /// `exchange`: 0 none, 1 without copies, 2 with.
    exchange: AtomicU64,
    seats: Box<[Seat]>,
}

impl WindowBell {
    pub(super) fn new(workers: usize) -> WindowBell {
        WindowBell {
            seq: Padded::new(AtomicU64::new(0)),
            plan: AtomicU64::new(0),
            first: AtomicU64::new(0),
            scans: AtomicU64::new(0),
            base: AtomicU64::new(0),
            exchange: AtomicU64::new(0),
            seats: (0..workers)
                .map(|_| Padded::new((AtomicBool::new(false), OnceLock::new())))
                .collect(),
        }
    }

    /// Worker `w` waits on the calling thread (once, before its first wait).
    pub(super) fn register(&self, w: usize) {
        let _ = self.seats[w].1.set(std::thread::current());
    }

    /// The number of windows announced so far.
    #[inline]
    pub(super) fn announced(&self) -> u64 {
        self.seq.load(Ordering::Acquire) / 2
    }

    /// Worker 0 announces the next window and wakes the parked workers.
    pub(super) fn ring(&self, note: WindowNote) {
        let s = self.seq.load(Ordering::Relaxed);
        self.seq.store(s + 1, Ordering::Relaxed);
        std::sync::atomic::fence(Ordering::Release);
        self.plan.store(note.plan as u64, Ordering::Relaxed);
        self.first.store(note.first, Ordering::Relaxed);
        self.scans.store(note.scans, Ordering::Relaxed);
        self.base.store(note.base, Ordering::Relaxed);
        let x = note.exchange.map_or(0, |copy| 1 + copy as u64);
        self.exchange.store(x, Ordering::Relaxed);
        // SeqCst, then SeqCst loads of the parked flags; a parking waiter stores its flag then
        // loads `seq` (SeqCst): one of the two sees the other, no wake-up is lost.
        self.seq.store(s + 2, Ordering::SeqCst);
        for seat in self.seats.iter() {
            if seat.0.load(Ordering::SeqCst) {
                if let Some(t) = seat.1.get() {
                    t.unpark();
                }
            }
        }
    }

    /// The note of window number `k` (1-based) or a later one, read whole; `None` if none yet.
    fn read(&self, k: u64) -> Option<(u64, WindowNote)> {
        loop {
            let s = self.seq.load(Ordering::Acquire);
            if s / 2 < k {
                return None;
            }
            if s % 2 == 1 {
                std::hint::spin_loop();
                continue;
            }
            let note = WindowNote {
                plan: self.plan.load(Ordering::Relaxed) as usize,
                first: self.first.load(Ordering::Relaxed),
                scans: self.scans.load(Ordering::Relaxed),
                base: self.base.load(Ordering::Relaxed),
                exchange: match self.exchange.load(Ordering::Relaxed) {
                    0 => None,
                    x => Some(x == 2),
                },
            };
            std::sync::atomic::fence(Ordering::Acquire);
            if self.seq.load(Ordering::Relaxed) == s {
                return Some((s / 2, note));
            }
        }
    }

    /// Worker `w` waits for window `k` (1-based) or a later one: its number and note; `None` if
    /// the barrier was poisoned.
    pub(super) fn wait(&self, w: usize, k: u64, poison: &SpinBarrier) -> Option<(u64, WindowNote)> {
        let park = || {
            if poison.is_poisoned() {
                return false;
            }
            let me = &*self.seats[w];
            me.0.store(true, Ordering::SeqCst);
            if self.seq.load(Ordering::SeqCst) / 2 < k && !poison.is_poisoned() {
                // Woken by `ring` (or the poison's unpark of the barrier's seats, which
                // are these threads); bounded anyway, as the poison check above needs.
                std::thread::park_timeout(Duration::from_millis(5));
            }
            me.0.store(false, Ordering::SeqCst);
            true
        };
        wait_until(poison.pace(PACE), || self.read(k), park)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Two workers take units of 500 scans of 3 phases of 2 slices each; every unit runs once,
    /// and a phase's units see the whole previous phase done.
    #[test]
    fn every_unit_runs_exactly_once_and_phases_follow_each_other() {
        let units = Units::new(6);
        let poison = SpinBarrier::new(2);
        let ran: Vec<AtomicU64> = (0..500 * 6).map(|_| AtomicU64::new(0)).collect();
        std::thread::scope(|s| {
            for w in 0..2usize {
                let (units, poison, ran) = (&units, &poison, &ran);
                s.spawn(move || {
                    for scan in 0..500u64 {
                        for phase in 0..3u64 {
                            let first = scan * 6 + phase * 2;
                            assert!(units.wait(first, poison, || false));
                            for k in [w as u64, 1 - w as u64] {
                                let pos = (phase * 2 + k) as usize;
                                if units.claim(pos, first + k + 1) {
                                    assert!(units.completed() >= first);
                                    ran[(first + k) as usize].fetch_add(1, Ordering::Relaxed);
                                    units.done();
                                }
                            }
                        }
                    }
                });
            }
        });
        assert!(ran.iter().all(|r| r.load(Ordering::Relaxed) == 1));
        assert_eq!(units.completed(), 500 * 6);
    }

    #[test]
    fn a_late_reader_gets_the_latest_window_whole_and_a_waiter_is_woken() {
        let bell = WindowBell::new(2);
        let poison = SpinBarrier::new(2);
        for k in 0..3 {
            bell.ring(WindowNote {
                plan: k,
                first: 10 * k as u64,
                scans: 5,
                base: 100 * k as u64,
                exchange: None,
            });
        }
        let (n, note) = bell.wait(1, 1, &poison).expect("announced");
        assert_eq!((n, note.plan, note.first, note.base), (3, 2, 20, 200));
        std::thread::scope(|s| {
            s.spawn(|| {
                std::thread::sleep(Duration::from_millis(20));
                bell.ring(WindowNote {
                    plan: 7,
                    first: 0,
                    scans: 0,
                    base: 0,
                    exchange: None,
                });
            });
            bell.register(1);
            let (n, note) = bell.wait(1, 4, &poison).expect("announced");
            assert_eq!((n, note.plan, note.scans), (4, 7, 0));
        });
    }
}
