//! The spinning barrier the workers meet at between the phases of a scan.
//!
//! Invariant: every worker calls [`SpinBarrier::wait`] the same number of times per run, with
//! its own epoch counter; it depends only on the padding below it and knows nothing of plans.

use super::pad::Padded;
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};

/// A spinning barrier for a fixed set of workers: each worker publishes the number of barriers
/// it has reached in its own cache line and waits until every other worker has reached as many
/// (no shared counter to fight over: one line transfer per worker pair). Spins with
/// `spin_loop`, then yields, so that it behaves when there are more workers than cores.
pub struct SpinBarrier {
    epochs: Box<[Padded<AtomicU64>]>,
    poisoned: AtomicBool,
}

impl SpinBarrier {
    /// A barrier for `n` workers.
    pub fn new(n: usize) -> SpinBarrier {
        SpinBarrier {
            epochs: (0..n).map(|_| Padded(AtomicU64::new(0))).collect(),
            poisoned: AtomicBool::new(false),
        }
    }

    /// Worker `w` arrives (its count in `epoch`) and waits for all; false if a worker panicked.
    #[inline]
    pub fn wait(&self, w: usize, epoch: &mut u64) -> bool {
        *epoch += 1;
        let e = *epoch;
        self.epochs[w].0.store(e, Ordering::Release);
        for (i, other) in self.epochs.iter().enumerate() {
            if i == w {
                continue;
            }
            let mut spins = 0u32;
            while other.0.load(Ordering::Acquire) < e {
                if spins < 2000 {
                    spins += 1;
                    std::hint::spin_loop();
                } else {
                    if self.poisoned.load(Ordering::Relaxed) {
                        return false;
                    }
                    std::thread::yield_now();
                }
            }
        }
        true
    }

    /// Releases every waiter for good (a worker panicked).
    pub fn poison(&self) {
        self.poisoned.store(true, Ordering::Relaxed);
    }
}
