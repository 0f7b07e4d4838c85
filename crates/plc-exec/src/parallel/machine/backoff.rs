//! The one wait loop of the parallel scan: spin briefly, then yield, then park, so that a wait
//! is fast when every worker owns a core and costs no scheduler time slice when one does not
//! (another process on the core, or more workers than cores). The barrier, the ready flags,
//! the units' completion counter and the window bell all wait through [`wait_until`]; each
//! keeps its own pace ([`Pace`]: how long it spins and yields) and its own way of parking
//! (woken by the producer or a bounded sleep), which it passes in.
//!
//! Invariants: the condition is checked before every step, so a wait that is already satisfied
//! costs one check; parking is the caller's (it re-checks its condition after announcing that
//! it parks, so no wake-up is lost) and may give up the wait (poison). Knows nothing of plans
//! or workers; depends on nothing in the parallel module.
//!
//! Not `crossbeam_utils::Backoff`: its pace is fixed step counts (spin up to 2^6, yield up to
//! 2^10 steps, then `is_completed`), while each waiter here passes its own: no spinning at all
//! when there are more workers than cores (the barrier's pace; 8 workers on 2 cores spent three
//! quarters of their time spinning, docs/scan.md), and yielding for a *time* before parking.

use std::time::{Duration, Instant};

/// How long a waiter spins, then yields, before it parks.
#[derive(Copy, Clone, Debug, PartialEq, Eq)]
pub(super) struct Pace {
    /// Spin-loop hints before the waiter starts yielding.
    pub(super) spins: u32,
    /// How long the waiter yields before it parks.
    pub(super) yield_for: Duration,
}

/// Waits until `ready` returns a value, and returns it: spins `pace.spins` times, yields for
/// `pace.yield_for`, then calls `park` between checks. `park` sleeps its own way and returns
/// false to give the wait up (a worker panicked, or the caller has other work): then `None`.
#[inline]
pub(super) fn wait_until<T>(
    pace: Pace,
    mut ready: impl FnMut() -> Option<T>,
    mut park: impl FnMut() -> bool,
) -> Option<T> {
    let mut spins = 0u32;
    let mut yielding: Option<Instant> = None;
    loop {
        if let Some(got) = ready() {
            return Some(got);
        }
        if spins < pace.spins {
            std::hint::spin_loop();
            spins += 1;
        } else if yielding.get_or_insert_with(Instant::now).elapsed() < pace.yield_for {
            std::thread::yield_now();
        } else if !park() {
            return None;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::sync::atomic::{AtomicBool, AtomicU32, Ordering};

    const PACE: Pace = Pace {
        spins: 16,
        yield_for: Duration::from_micros(100),
    };

    #[test]
    fn a_ready_condition_returns_at_once_without_parking() {
        let got = wait_until(PACE, || Some(7), || panic!("parked"));
        assert_eq!(got, Some(7));
    }

    /// A condition set by another thread after a while: the waiter spins, yields, parks, and
    /// returns the value once it is set.
    #[test]
    fn a_late_condition_is_seen_after_parking() {
        let flag = AtomicU32::new(0);
        let parked = AtomicBool::new(false);
        std::thread::scope(|s| {
            s.spawn(|| {
                std::thread::sleep(Duration::from_millis(20));
                flag.store(5, Ordering::Release);
            });
            let got = wait_until(
                PACE,
                || Some(flag.load(Ordering::Acquire)).filter(|&v| v != 0),
                || {
                    parked.store(true, Ordering::Relaxed);
                    std::thread::park_timeout(Duration::from_micros(50));
                    true
                },
            );
            assert_eq!(got, Some(5));
        });
        assert!(parked.load(Ordering::Relaxed));
    }

    #[test]
    fn a_park_that_gives_up_ends_the_wait() {
        let mut parks = 0;
        let got: Option<()> = wait_until(
            PACE,
            || None,
            || {
                parks += 1;
                parks < 3
            },
        );
        assert_eq!((got, parks), (None, 3));
    }
}
