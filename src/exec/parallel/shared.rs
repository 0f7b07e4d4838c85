//! Memory shared by the workers without locks: the slot array ([`SharedSlots`]), the padded
//! per-worker fault buffers and decisions. Every `unsafe` here rests on the plan's discipline,
//! stated in its `// SAFETY:` comment.

use super::barrier::SpinBarrier;
use crate::exec::{Fault, Store};
use std::cell::UnsafeCell;
use std::sync::atomic::AtomicU32;

/// Pads its content to its own 128-byte block (two cache lines: also keeps the adjacent-line
/// prefetcher from coupling neighbours).
#[repr(align(128))]
pub(super) struct Padded<T>(pub(super) T);

/// The slot array shared by all workers, without locks.
#[derive(Copy, Clone)]
pub struct SharedSlots {
    pub(super) ptr: *mut u64,
    pub(super) len: usize,
}

// SAFETY: a `SharedSlots` is only created by `ParallelMachine::run` from the `&mut State` it
// holds for the whole run, and used by the workers under the plan's discipline: in a parallel
// phase, no slot written by one worker is read or written by another (checked by
// `ParallelMachine::verify`, from the schedule's guarantee), so there are no data races; between
// phases the barrier's release/acquire orders all accesses.
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

pub(super) struct Shared<'a> {
    pub(super) slots: SharedSlots,
    pub(super) decisions: &'a [AtomicU32],
    pub(super) faults: &'a [FaultBuffer],
    pub(super) barrier: SpinBarrier,
}

// SAFETY: the fault buffers are each used by one worker during a scan and by worker 0 between
// scans, with the barrier ordering the hand-over (see `ParallelMachine::worker`).
unsafe impl Sync for Shared<'_> {}
