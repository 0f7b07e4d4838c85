//! Memory shared by the workers without locks: the slot array ([`SharedSlots`]), the padded
//! per-worker fault buffers and the decision cells. Every `unsafe` here rests on the plan's
//! discipline (no slot written by one worker in a phase is read or written by another; checked
//! against the lowered code by `check`), stated in its `// SAFETY:` comment. Depends on the
//! barrier, padding and typed indices below it; it does not run anything.

use super::barrier::SpinBarrier;
use super::ids::{Decision, DecisionSlot};
use super::pad::Padded;
use crate::exec::{Fault, Store};
use std::cell::UnsafeCell;
use std::sync::atomic::{AtomicU32, Ordering};

/// The slot array shared by all workers, without locks.
#[derive(Copy, Clone, Debug)]
pub struct SharedSlots {
    pub(super) ptr: *mut u64,
    pub(super) len: usize,
}

// SAFETY: a `SharedSlots` is only created by `ParallelMachine::run` from the `&mut State` it
// holds for the whole run, and used by the workers under the plan's discipline: in a parallel
// phase, no slot written by one worker is read or written by another (checked at plan time
// against the lowered instructions' accesses), so there are no data races; between phases the
// barrier's release/acquire orders all accesses.
unsafe impl Send for SharedSlots {}
// SAFETY: as above.
unsafe impl Sync for SharedSlots {}

#[cold]
#[inline(never)]
fn out_of_range(slot: u32, len: usize) -> ! {
    panic!("slot {slot} out of range ({len} slots)")
}

impl Store for SharedSlots {
    #[inline(always)]
    fn get(&self, slot: u32) -> u64 {
        if slot as usize >= self.len {
            out_of_range(slot, self.len);
        }
        // SAFETY: in bounds (checked); no other worker writes this slot in this phase (the plan's
        // discipline, see the `Sync` impl).
        unsafe { self.ptr.add(slot as usize).read() }
    }
    #[inline(always)]
    fn set(&mut self, slot: u32, v: u64) {
        if slot as usize >= self.len {
            out_of_range(slot, self.len);
        }
        // SAFETY: in bounds (checked); no other worker reads or writes this slot in this phase.
        unsafe { self.ptr.add(slot as usize).write(v) }
    }
}

/// One worker's faults of the current scan, each with the first task of the item that raised it
/// (the key of the sequential order).
pub(super) type FaultBuffer = Padded<UnsafeCell<Vec<(u32, Fault)>>>;

/// The decisions of one run, one cell per decision slot (lines of them per (phase, worker)).
pub(super) struct Decisions(Box<[AtomicU32]>);

impl Decisions {
    pub(super) fn new(n: usize) -> Decisions {
        Decisions(
            (0..n)
                .map(|_| AtomicU32::new(Decision::NotRun.pack()))
                .collect(),
        )
    }

    /// Relaxed: written in an earlier phase, ordered by the barrier in between.
    #[inline]
    pub(super) fn get(&self, s: DecisionSlot) -> Decision {
        Decision::unpack(self.0[s.index()].load(Ordering::Relaxed))
    }

    /// Relaxed: read only in later phases, after a barrier.
    #[inline]
    pub(super) fn set(&self, s: DecisionSlot, d: Decision) {
        self.0[s.index()].store(d.pack(), Ordering::Relaxed)
    }
}

pub(super) struct Shared<'a> {
    pub(super) slots: SharedSlots,
    pub(super) decisions: &'a Decisions,
    pub(super) faults: &'a [FaultBuffer],
    pub(super) barrier: SpinBarrier,
}

// SAFETY: the fault buffers are each used by one worker during a scan and by worker 0 between
// scans, with the barrier ordering the hand-over (see `ParallelMachine::worker`).
unsafe impl Sync for Shared<'_> {}
