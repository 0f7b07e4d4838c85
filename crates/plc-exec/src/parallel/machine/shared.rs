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
//! running every unit of gen 20k, four interleaved rounds.) Every `unsafe` states its argument. Depends on the barrier,
//! padding and typed indices below it; it does not run anything.

use super::barrier::SpinBarrier;
use super::flags::ReadyFlags;
use super::units::{Units, WindowBell};
use crate::parallel::ids::{Decision, DecisionSlot};
use crate::parallel::pad::Padded;
use crate::parallel::planning::RemoteLines;
use crate::{Addr, Fault, Machine, Store, Word, LINE_BYTES};
use std::sync::atomic::{AtomicU32, Ordering};
use std::sync::{Mutex, MutexGuard, PoisonError};

/// The state's bytes, shared by all workers without locks.
#[derive(Copy, Clone, Debug)]
pub struct SharedSlots {
    /// The first byte: on a 64-byte line (a `State`'s memory).
    pub(super) ptr: *mut u8,
    pub(super) len: usize,
}

// SAFETY: a `SharedSlots` is only created by `ParallelMachine::run` from the `&mut State` it
// holds for the whole run, and only for plans that passed their check: in a phase, no byte
// one worker writes is read or written by another, and phases are ordered by Release/Acquire
// hand-overs, so sharing it between threads never lets two accesses to one byte race (the
// module's argument; `ItemStore` below).
unsafe impl Send for SharedSlots {}
// SAFETY: as above.
unsafe impl Sync for SharedSlots {}

impl SharedSlots {
    /// The slots of `mem`, for `machine`'s accesses.
    ///
    /// # Panics
    /// If `mem` is smaller than the machine's state ([`Machine::state_size`]).
    pub(super) fn new(mem: &mut [u8], machine: &Machine) -> SharedSlots {
        assert!(
            mem.len() >= machine.state_size() as usize,
            "state too small for this machine"
        );
        SharedSlots {
            ptr: mem.as_mut_ptr(),
            len: mem.len(),
        }
    }

    /// The pointer to the `T` at `at`, unchecked. Every address a [`Machine`]'s instructions,
    /// loops and counters use ends inside its state size (asserted once by `Machine::new` from
    /// the same immutable instructions), and `new` asserted that the memory has at least that
    /// many bytes: the same argument as the sequential walk's trusted store. A bounds check per
    /// access cost the parallel scan about a fifth of its time per rung (gen 20k, half the
    /// rungs per worker: 55 µs a scan checked, 48 unchecked).
    #[inline(always)]
    fn at<T: Word>(&self, at: Addr) -> *mut u8 {
        debug_assert!(at.index() + T::SIZE <= self.len, "access out of the state");
        self.ptr.wrapping_add(at.index())
    }

    /// Starts bringing a slice's remote lines into this core's cache: the ones it will write
    /// exclusive, the ones it will read shared (`planning::remote`; a hint, nothing else).
    #[inline]
    pub(super) fn prefetch(&self, lines: &RemoteLines) {
        let line = |l: u32| self.ptr.wrapping_add(l as usize * LINE_BYTES as usize);
        for &l in &lines.writes {
            plc_hint::prefetch_write(line(l));
        }
        for &l in &lines.reads {
            plc_hint::prefetch_read(line(l));
        }
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

    /// The memory as a shared slice, for workers that only read it while no thread writes it.
    ///
    /// # Safety
    /// No thread writes the memory while the slice lives, and it does not outlive the run.
    pub(super) unsafe fn bytes<'a>(self) -> &'a [u8] {
        // SAFETY: as in `bytes_mut`; the caller guarantees that nobody writes meanwhile.
        unsafe { std::slice::from_raw_parts(self.ptr, self.len) }
    }
}

/// The shared state as the interpreter's [`Store`] while a worker runs one item of a checked
/// plan with one machine's code: the only way the workers' interpreter reaches the shared
/// bytes. It exists for one call of [`Machine::resume`]: every address it is given is then an
/// address of that machine's code, which `Machine::new` checked to end inside the machine's
/// state size, and [`new`](Self::new) asserts that the memory holds that many bytes.
pub(super) struct ItemStore(SharedSlots);

impl ItemStore {
    /// The shared slots as `m`'s store, for one item.
    ///
    /// # Safety
    /// The store is passed only to `m`'s interpreter ([`Machine::resume`]) and dropped when it
    /// returns, so it is loaded from and stored to only at addresses of `m`'s code; and the
    /// accesses of that item are allowed to this worker in this phase by the plan's check (no
    /// byte it writes is touched by another worker, no byte it reads is written by another),
    /// ordered after the phases before by a Release/Acquire hand-over.
    ///
    /// # Panics
    /// If the memory is smaller than `m`'s state.
    #[inline(always)]
    pub(super) unsafe fn new(slots: SharedSlots, m: &Machine) -> ItemStore {
        assert!(
            slots.len >= m.state_size() as usize,
            "state too small for this machine"
        );
        ItemStore(slots)
    }
}

impl Store for ItemStore {
    #[inline(always)]
    fn load<T: Word>(&self, at: Addr) -> T {
        let p = self.0.at::<T>(at);
        // SAFETY: `p..p + T::SIZE` is inside the state's memory: `at` is an address of the code
        // of the machine the store was made for (the contract of `ItemStore::new`), which ends
        // inside its state size, and `new` asserted that the memory has at least that many
        // bytes (initialised, borrowed for the whole run). No other worker writes these bytes
        // meanwhile (the plan check, by the same contract), so this read races with nothing.
        unsafe { T::read(std::slice::from_raw_parts(p, T::SIZE)) }
    }
    #[inline(always)]
    fn store<T: Word>(&mut self, at: Addr, v: T) {
        let p = self.0.at::<T>(at);
        // SAFETY: in bounds as in `load`; no other worker reads or writes these bytes meanwhile
        // (the plan check, by the contract of `new`), so no access races with this write.
        unsafe { v.write(std::slice::from_raw_parts_mut(p, T::SIZE)) }
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
