//! The ready flags of a dependence-driven plan at run time: one counter per worker, on its own
//! padded block, that says "I have finished my first k items of the scan of barrier epoch e"
//! as `e << 32 | k`. The owner publishes with a Release store after an item that another
//! worker waits for; a waiter reads with Acquire until the value reaches what it needs: these
//! two are the synchronisation points that order the producer's state writes (plain stores,
//! `shared`) before the consumer's reads. Values only grow during a run (the epoch is the
//! barrier's, the same on every worker after the scan's first barrier), so a flag needs no
//! reset between scans or plans.
//!
//! A waiter spins briefly, then yields, then sleeps in short bounded parks (it polls the flag
//! and the barrier's poison in between), so that a worker without a core of its own never costs
//! the others a time slice per wait. Unlike the barrier it is not woken by the producer:
//! a publish stays one plain store, and the bounded park only matters when a producer is
//! descheduled for longer than the yield period. Depends on the barrier (for its poison), the
//! backoff (the wait loop) and the padding; knows nothing of plans.

use super::backoff::{wait_until, Pace};
use super::barrier::SpinBarrier;
use crate::parallel::pad::Padded;
use std::sync::atomic::{AtomicU64, Ordering};
use std::time::Duration;

/// A waiter spins 2^10 hints, then yields for 200 µs, then parks in bounded sleeps.
const PACE: Pace = Pace {
    spins: 1 << 10,
    yield_for: Duration::from_micros(200),
};
/// One bounded park.
const PARK: Duration = Duration::from_micros(20);

/// One ready counter per worker.
pub(super) struct ReadyFlags(Box<[Padded<AtomicU64>]>);

/// The value of "worker finished `done` items of the scan of epoch `epoch`".
#[inline]
fn value(epoch: u64, done: u32) -> u64 {
    (epoch << 32) | done as u64
}

impl ReadyFlags {
    pub(super) fn new(workers: usize) -> ReadyFlags {
        ReadyFlags(
            (0..workers)
                .map(|_| Padded::new(AtomicU64::new(0)))
                .collect(),
        )
    }

    /// Worker `w` has finished its first `done` items of the scan of `epoch`.
    #[inline]
    pub(super) fn publish(&self, w: usize, epoch: u64, done: u32) {
        self.0[w].store(value(epoch, done), Ordering::Release);
    }

    /// Waits until worker `w` has finished its first `done` items of the scan of `epoch`;
    /// false if a worker panicked (the barrier is poisoned).
    #[inline]
    pub(super) fn wait(&self, w: usize, epoch: u64, done: u32, barrier: &SpinBarrier) -> bool {
        let need = value(epoch, done);
        let flag = &*self.0[w];
        if flag.load(Ordering::Acquire) >= need {
            return true;
        }
        self.wait_slow(flag, need, barrier)
    }

    #[cold]
    fn wait_slow(&self, flag: &AtomicU64, need: u64, barrier: &SpinBarrier) -> bool {
        let reached = || (flag.load(Ordering::Acquire) >= need).then_some(());
        let park = || {
            if barrier.is_poisoned() {
                return false;
            }
            std::thread::park_timeout(PARK);
            true
        };
        wait_until(barrier.pace(PACE), reached, park).is_some()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::sync::atomic::AtomicU32;

    /// A consumer that waits for each item sees the producer's (Relaxed) write of it, and
    /// flags of an earlier epoch do not satisfy a wait of a later one.
    #[test]
    fn a_wait_sees_the_writes_before_the_publish() {
        let flags = ReadyFlags::new(2);
        let barrier = SpinBarrier::new(2);
        let data = AtomicU32::new(0);
        flags.publish(0, 1, 5);
        std::thread::scope(|s| {
            s.spawn(|| {
                for k in 1..=2000u32 {
                    data.store(k, Ordering::Relaxed);
                    flags.publish(0, 2, k);
                }
            });
            for k in 1..=2000u32 {
                assert!(flags.wait(0, 2, k, &barrier));
                assert!(data.load(Ordering::Relaxed) >= k);
            }
        });
        assert_eq!(flags.0[0].load(Ordering::SeqCst), (2 << 32) | 2000);
    }

    #[test]
    fn poison_releases_a_waiter() {
        let flags = ReadyFlags::new(2);
        let barrier = SpinBarrier::new(2);
        std::thread::scope(|s| {
            s.spawn(|| {
                std::thread::sleep(Duration::from_millis(20));
                barrier.poison();
            });
            assert!(!flags.wait(1, 1, 1, &barrier));
        });
    }
}
