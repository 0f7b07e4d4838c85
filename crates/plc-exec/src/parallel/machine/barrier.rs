//! The barrier the workers meet at between the phases of a scan: spin briefly, then yield, then
//! park, so that it is fast when every worker owns a core and costs no scheduler time slice per
//! barrier when one does not (another process on the core, or more workers than cores): the
//! wait loop is `backoff`'s, parked here until an arriving worker unparks the waiter.
//!
//! Invariants: every worker calls [`SpinBarrier::wait`] the same number of times per run, with
//! its own epoch counter, and [`SpinBarrier::register`]s its thread before its first wait. It
//! depends only on the padding and the backoff below it and knows nothing of plans. Parking uses
//! `std::thread::park`/`unpark` (a futex on Linux): no crate is needed for one flag per worker.

use super::backoff::{wait_until, Pace};
use crate::parallel::pad::Padded;
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::sync::OnceLock;
use std::thread::Thread;

/// A waiter spins 2^11 hints (a few µs: what a balanced phase needs), then yields for 200 µs:
/// long enough to cover worker 0's work between two scans (the driver's digest of a large
/// state) without a wake-up latency, short enough that a descheduled worker costs the others a
/// sleep, not a time slice of spinning.
const PACE: Pace = Pace {
    spins: 1 << 11,
    yield_for: std::time::Duration::from_micros(200),
};

/// One worker's seat: the barriers it has reached, whether it is parked, and its thread.
#[derive(Debug, Default)]
struct Seat {
    epoch: AtomicU64,
    parked: AtomicBool,
    thread: OnceLock<Thread>,
}

/// A barrier for a fixed set of workers: each worker publishes the number of barriers it has
/// reached in its own cache line and waits until every other worker has reached as many (no
/// shared counter to fight over: one line transfer per worker pair). A waiter spins, then
/// yields, then parks; an arriving worker unparks the workers parked on it.
#[derive(Debug)]
pub struct SpinBarrier {
    seats: Box<[Padded<Seat>]>,
    poisoned: AtomicBool,
    /// More workers than the machine has cores: a waiter's partner may be off-core until this
    /// waiter gives its core up, so waits skip their spinning ([`SpinBarrier::pace`]).
    oversubscribed: bool,
}

impl SpinBarrier {
    /// A barrier for `n` workers.
    pub fn new(n: usize) -> SpinBarrier {
        SpinBarrier {
            seats: (0..n).map(|_| Padded::new(Seat::default())).collect(),
            poisoned: AtomicBool::new(false),
            oversubscribed: std::thread::available_parallelism().is_ok_and(|cores| n > cores.get()),
        }
    }

    /// `pace` for a waiter among this barrier's workers: without its spinning when there are
    /// more workers than cores (a spinning waiter would hold the core the worker it waits for
    /// needs: measured, 8 workers on 2 cores spent three quarters of their time spinning).
    pub(super) fn pace(&self, pace: Pace) -> Pace {
        if self.oversubscribed {
            Pace { spins: 0, ..pace }
        } else {
            pace
        }
    }

    /// Worker `w` runs on the calling thread (call once, before its first [`wait`](Self::wait)).
    pub fn register(&self, w: usize) {
        let _ = self.seats[w].thread.set(std::thread::current());
    }

    /// Worker `w` arrives (its count in `epoch`) and waits for all; false if a worker panicked.
    #[inline]
    pub fn wait(&self, w: usize, epoch: &mut u64) -> bool {
        *epoch += 1;
        let e = *epoch;
        // SeqCst store, then SeqCst loads of the parked flags; a parking waiter stores its flag
        // then loads the epochs (SeqCst): one of the two sees the other, no wake-up is lost.
        self.seats[w].epoch.store(e, Ordering::SeqCst);
        for (i, seat) in self.seats.iter().enumerate() {
            if i != w && seat.parked.load(Ordering::SeqCst) {
                if let Some(t) = seat.thread.get() {
                    t.unpark();
                }
            }
        }
        for (i, other) in self.seats.iter().enumerate() {
            if i != w && !self.wait_for(w, other, e) {
                return false;
            }
        }
        true
    }

    /// Waits until `other` has reached barrier `e`; false if the barrier was poisoned.
    #[inline]
    fn wait_for(&self, w: usize, other: &Seat, e: u64) -> bool {
        let reached = || (other.epoch.load(Ordering::Acquire) >= e).then_some(());
        let park = || {
            if self.poisoned.load(Ordering::SeqCst) {
                return false;
            }
            let me = &*self.seats[w];
            me.parked.store(true, Ordering::SeqCst);
            if other.epoch.load(Ordering::SeqCst) < e && !self.poisoned.load(Ordering::SeqCst) {
                // A registered worker is woken by `unpark`; an unregistered one (a caller
                // that skipped `register`) still wakes up: park_timeout bounds its sleep.
                if me.thread.get().is_some() {
                    std::thread::park();
                } else {
                    std::thread::park_timeout(std::time::Duration::from_micros(50));
                }
            }
            me.parked.store(false, Ordering::SeqCst);
            true
        };
        wait_until(self.pace(PACE), reached, park).is_some()
    }

    /// Whether a worker panicked (every waiter is released for good).
    pub fn is_poisoned(&self) -> bool {
        self.poisoned.load(Ordering::SeqCst)
    }

    /// Releases every waiter for good (a worker panicked).
    pub fn poison(&self) {
        self.poisoned.store(true, Ordering::SeqCst);
        for seat in self.seats.iter() {
            if let Some(t) = seat.thread.get() {
                t.unpark();
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::sync::atomic::AtomicUsize;

    /// With more workers than cores a waiter does not spin (it yields at once); with no more
    /// workers than cores it keeps the pace it was given.
    #[test]
    fn waits_skip_spinning_only_with_more_workers_than_cores() {
        let cores = std::thread::available_parallelism().map_or(1, |c| c.get());
        assert_eq!(SpinBarrier::new(cores + 1).pace(PACE).spins, 0);
        assert_eq!(
            SpinBarrier::new(cores + 1).pace(PACE).yield_for,
            PACE.yield_for
        );
        assert_eq!(SpinBarrier::new(cores).pace(PACE), PACE);
        assert_eq!(SpinBarrier::new(1).pace(PACE), PACE);
    }

    /// More workers than cores, many barriers: every worker sees every other's writes of the
    /// previous phase (the counter is exact), and nothing hangs.
    #[test]
    fn oversubscribed_workers_meet_at_every_barrier() {
        let n = 8;
        let b = SpinBarrier::new(n);
        let counter = AtomicUsize::new(0);
        std::thread::scope(|s| {
            for w in 0..n {
                let (b, counter) = (&b, &counter);
                s.spawn(move || {
                    b.register(w);
                    let mut epoch = 0;
                    for round in 0..200 {
                        counter.fetch_add(1, Ordering::Relaxed);
                        assert!(b.wait(w, &mut epoch));
                        assert_eq!(counter.load(Ordering::Relaxed), (round + 1) * n);
                        assert!(b.wait(w, &mut epoch));
                    }
                });
            }
        });
        assert_eq!(counter.load(Ordering::Relaxed), 200 * n);
    }

    /// A worker that arrives late (asleep for a while) wakes the parked ones.
    #[test]
    fn a_late_worker_unparks_the_waiters() {
        let b = SpinBarrier::new(2);
        std::thread::scope(|s| {
            s.spawn(|| {
                b.register(1);
                let mut e = 0;
                std::thread::sleep(std::time::Duration::from_millis(30));
                assert!(b.wait(1, &mut e));
            });
            b.register(0);
            let mut e = 0;
            assert!(b.wait(0, &mut e));
            assert!(b.seats[1].epoch.load(Ordering::SeqCst) >= 1);
        });
    }

    #[test]
    fn poison_releases_a_parked_waiter() {
        let b = SpinBarrier::new(2);
        std::thread::scope(|s| {
            s.spawn(|| {
                std::thread::sleep(std::time::Duration::from_millis(20));
                b.poison();
            });
            b.register(0);
            let mut e = 0;
            assert!(!b.wait(0, &mut e));
        });
    }
}
