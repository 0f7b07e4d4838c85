//! Memory shared by the workers without locks: the state's bytes ([`SharedSlots`]), the padded
//! per-worker fault buffers and the decision cells. The state is read and written with plain
//! loads and stores of each value's bytes. That is sound because of the plan's discipline,
//! checked for every plan in every build against the lowered code's byte accesses (`check`):
//! in one phase no byte written by one worker is read or written by another, so two workers
//! never access one byte at the same time unless both only read it; and every phase starts
//! after a Release/Acquire hand-over (the completion counter, the barrier or a ready flag) from
//! the end of the phases whose writes it reads. A plan that fails its check is never run.
//! (Relaxed atomics of each value's width compile to the same instructions one by one, but they
//! keep the compiler from merging and reordering the interpreter's accesses: the parallel
//! path's per-rung cost was 1.25× the sequential walk's with them, 1.05× without, one worker
//! running every unit of gen 20k, four interleaved rounds.) The raw accesses themselves
//! ([`SharedSlots`], `ItemStore`) are `crate::raw`'s; this module says no `unsafe`. Depends on
//! the barrier, padding and typed indices below it; it does not run anything.

use super::barrier::SpinBarrier;
use super::flags::ReadyFlags;
use super::units::{Units, WindowBell};
use crate::parallel::ids::{Decision, DecisionSlot};
use crate::parallel::pad::Padded;
use crate::parallel::planning::RemoteLines;
use crate::{Fault, LINE_BYTES};
use std::sync::atomic::{AtomicU32, Ordering};
use std::sync::{Mutex, MutexGuard, PoisonError};

pub(super) use crate::raw::ItemStore;
pub use crate::raw::SharedSlots;

impl SharedSlots {
    /// Starts bringing a slice's remote lines into this core's cache: the ones it will write
    /// exclusive, the ones it will read shared (`planning::remote`; a hint, nothing else).
    #[inline]
    pub(super) fn prefetch(&self, lines: &RemoteLines) {
        let line = |l: u32| self.byte_ptr(l as usize * LINE_BYTES as usize);
        for &l in &lines.writes {
            plc_hint::prefetch_write(line(l));
        }
        for &l in &lines.reads {
            plc_hint::prefetch_read(line(l));
        }
    }
}

/// One worker's faults of the current scan, each with the first task of the item that raised it
/// (the key of the sequential order). A mutex that is never contended (its worker fills it
/// during a scan, worker 0 empties it between scans, after the hand-over that ends the scan):
/// faults are rare, and worker 0 takes each lock once a scan.
pub(super) type FaultBuffer = Padded<Mutex<Vec<(u32, Fault)>>>;

/// The buffer's faults (a panic while a worker held it leaves its faults as they were).
pub(super) fn faults_of(buffer: &FaultBuffer) -> MutexGuard<'_, Vec<(u32, Fault)>> {
    buffer.lock().unwrap_or_else(PoisonError::into_inner)
}

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
    /// Per plan: the exchange lines of its `par-exchange` candidate.
    pub(super) xbufs: &'a [Option<super::xlines::XBuffer>],
    /// Per plan: worker 0's state in its `par-exchange` candidate's own layout, if it has one
    /// (the other workers copy it into their private states when a window starts).
    pub(super) xhomes: &'a [Option<SharedSlots>],
}
