//! Memory shared by the workers without locks: the state's bytes ([`SharedSlots`]), the padded
//! per-worker fault buffers and the decision cells. The state is read and written through
//! Relaxed atomics of each value's width (on x86-64 and aarch64 the same plain loads and stores
//! as unshared memory), so even a plan that broke its discipline would give wrong values, never
//! a data race; the discipline (no byte written by one worker in a phase is read or written by
//! another; checked against the lowered code by `check`) and the barrier between phases are
//! what make the values right. Every `unsafe` states its argument. Depends on the barrier,
//! padding and typed indices below it; it does not run anything.

use super::barrier::SpinBarrier;
use super::flags::ReadyFlags;
use super::units::{Units, WindowBell};
use crate::exec::parallel::ids::{Decision, DecisionSlot};
use crate::exec::parallel::pad::Padded;
use crate::exec::{Addr, Fault, Store, Word};
use std::cell::UnsafeCell;
use std::sync::atomic::{AtomicU32, Ordering};

/// The state's bytes, shared by all workers without locks.
#[derive(Copy, Clone, Debug)]
pub struct SharedSlots {
    /// The first byte: on a 64-byte line (a `State`'s memory).
    pub(super) ptr: *mut u8,
    pub(super) len: usize,
}

// SAFETY: a `SharedSlots` is only created by `ParallelMachine::run` from the `&mut State` it
// holds for the whole run; every access through it is atomic (`Store` below), so sharing it
// between threads cannot race; the plan's discipline and the barriers make the values right.
unsafe impl Send for SharedSlots {}
// SAFETY: as above.
unsafe impl Sync for SharedSlots {}

#[cold]
#[inline(never)]
fn bad_access(at: Addr, width: usize, len: usize) -> ! {
    panic!(
        "access of {width} bytes at byte {} out of range or misaligned ({len} bytes)",
        at.0
    )
}

impl SharedSlots {
    /// The pointer to the `T` at `at`, checked: in bounds and aligned to `T::SIZE`.
    #[inline(always)]
    fn at<T: Word>(&self, at: Addr) -> *mut u8 {
        if at.index() + T::SIZE > self.len || !at.index().is_multiple_of(T::SIZE) {
            bad_access(at, T::SIZE, self.len);
        }
        // SAFETY: in bounds of the allocation (checked just above).
        unsafe { self.ptr.add(at.index()) }
    }

    /// The memory as a slice, for worker 0 while every other worker waits at a barrier.
    ///
    /// # Safety
    /// No other thread accesses the memory while the slice lives, and it does not outlive the
    /// run (the `&mut State` the memory is borrowed from).
    pub(super) unsafe fn bytes_mut<'a>(self) -> &'a mut [u8] {
        // SAFETY: `ptr..ptr + len` is the state's memory, borrowed mutably for the whole run;
        // the caller guarantees exclusive access while the slice lives.
        unsafe { std::slice::from_raw_parts_mut(self.ptr, self.len) }
    }
}

impl Store for SharedSlots {
    #[inline(always)]
    fn load<T: Word>(&self, at: Addr) -> T {
        let p = self.at::<T>(at);
        // SAFETY: in bounds and aligned to `T::SIZE` (checked by `at`, with the memory starting
        // on a 64-byte line); the machine accesses each value always in its one width, so no
        // mixed-size access to these bytes runs at the same time.
        unsafe { T::load_relaxed(p) }
    }
    #[inline(always)]
    fn store<T: Word>(&mut self, at: Addr, v: T) {
        let p = self.at::<T>(at);
        // SAFETY: as in `load`.
        unsafe { v.store_relaxed(p) }
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
    /// The workers' ready flags (dependence-driven plans).
    pub(super) ready: &'a ReadyFlags,
    /// The claimed units of levelled plans (`units`).
    pub(super) units: &'a Units,
    /// Worker 0's announcements of windows.
    pub(super) bell: &'a WindowBell,
}

// SAFETY: the fault buffers are each used by one worker during a scan and by worker 0 between
// scans, with the barrier ordering the hand-over (see `ParallelMachine::worker`).
unsafe impl Sync for Shared<'_> {}
