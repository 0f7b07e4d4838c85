//! The hot variable (`hot_fraction`): which main rungs set the global `FAULT` and which read it.
//!
//! `k_w = clamp(round(F * n), 1, n)` writer slots and `k_r = max(1, k_w / 10)` reader slots are
//! spread evenly over the `n` main rungs: slot `i` of `k` is rung `(i * n + off) / k`, with the
//! offset `off < k` drawn from the seed (its own splitmix64 stream, so the main stream and thus
//! every other choice of the program are the same with or without the hot variable). Only
//! normal and FOR body rungs can carry a duty, one write and one read each; a slot that falls
//! on a header, NEXT, jump, call or end rung is owed to the next such rung that has no slot of
//! its own, so the counts are exact unless slots are still owed after the last normal or body
//! rung (at most one per header, NEXT, jump, call or end rung). This module only decides the
//! slots; the elements are added by `super::rung`.

use super::emit::Rng;

/// Rungs `(i * n + off) / count` for `i < count`, in increasing order.
struct Spread {
    count: usize,
    n: usize,
    off: usize,
    next: usize,
}

impl Spread {
    fn new(count: usize, n: usize, rng: &mut Rng) -> Self {
        let off = rng.below(count);
        Spread {
            count,
            n,
            off,
            next: 0,
        }
    }

    /// Whether rung `r` (visited in increasing order, every rung once) holds the next slot.
    fn hits(&mut self, r: usize) -> bool {
        if self.next >= self.count {
            return false;
        }
        let at = (self.next as u128 * self.n as u128 + self.off as u128) / self.count as u128;
        if at as usize == r {
            self.next += 1;
            true
        } else {
            false
        }
    }
}

/// The slots of the hot variable's writers and readers, and how many are owed to the next rungs
/// that can take them.
pub(super) struct HotPlan {
    writers: Spread,
    readers: Spread,
    writes_owed: usize,
    reads_owed: usize,
}

/// What the current rung does with the hot variable.
#[derive(Clone, Copy, Default)]
pub(super) struct HotDuty {
    /// Read `FAULT` as a negated contact after the other conditions.
    pub(super) read: bool,
    /// Set `FAULT` on an extra path of the output branch.
    pub(super) write: bool,
}

impl HotPlan {
    /// The plan for `n ≥ 1` main rungs and a fraction `0 < fraction ≤ 1`.
    pub(super) fn new(n: usize, fraction: f64, seed: u64) -> Self {
        let writers = ((fraction * n as f64).round() as usize).clamp(1, n);
        let readers = (writers / 10).max(1);
        let mut rng = Rng::new(seed ^ 0x5EED_0000_FA01_7000);
        HotPlan {
            writers: Spread::new(writers, n, &mut rng),
            readers: Spread::new(readers, n, &mut rng),
            writes_owed: 0,
            reads_owed: 0,
        }
    }

    /// Visits main rung `r` (in order); `can_carry` when it is a normal or FOR body rung.
    pub(super) fn duty(&mut self, r: usize, can_carry: bool) -> HotDuty {
        self.writes_owed += usize::from(self.writers.hits(r));
        self.reads_owed += usize::from(self.readers.hits(r));
        if !can_carry {
            return HotDuty::default();
        }
        let duty = HotDuty {
            read: self.reads_owed > 0,
            write: self.writes_owed > 0,
        };
        self.writes_owed -= usize::from(duty.write);
        self.reads_owed -= usize::from(duty.read);
        duty
    }
}
