//! Every raw memory access of the executor, and nothing else: the state's memory on 64-byte
//! lines ([`LineBytes`]), the checked lowered code and its unchecked reads ([`CheckedCode`]),
//! the sequential walk's unchecked store ([`Trusted`]), the state shared by the parallel
//! workers ([`SharedSlots`], [`ItemStore`]) and the exchange lines' SIMD packing
//! ([`pack_bools`]). It is the only module of the crate that says `unsafe` but for the callers
//! of its `unsafe fn`s (the interpreter `run`, and the parallel machine's `items`, `claimed`,
//! `exchange` and `workers`), each of which argues the callee's `# Safety` section in its own
//! file.
//!
//! Invariants, each established in this file by the only constructor of its type:
//! - a [`CheckedCode`] has passed its check (`CheckedCode::new`): the last instruction is an
//!   `EndPou`; every instruction index the code holds (rung starts, POU entries, FOR tests and
//!   exits, jump and call targets) is an instruction; every fused rung's operands and table
//!   exist; and every byte any instruction or loop counter accesses ends inside the state size
//!   (the byte accesses `access` computes, the ones the parallel plan check uses too). The code
//!   is immutable afterwards (no `&mut` access to it is given out).
//! - a [`LineBytes`] is `len` initialised bytes starting on a 64-byte line.
//! - a [`SharedSlots`] points at a state's memory, borrowed mutably for the whole run.
//!
//! What it does not do: decide which worker may touch which bytes when (the plan check and the
//! machine's phases do; the `unsafe fn`s here state what they need of that), or interpret
//! instructions (`run`). Rust's reference on unsafe code ("Behavior considered undefined") is
//! the standard the arguments follow.

use super::fuse::{FusedId, FusedRung, Table};
use super::line::LINE_BYTES;
use super::lower::{Code, Op};
use super::store::{Addr, Store, Word};
use super::Machine;
use std::ops::Deref;

// ---------------------------------------------------------------------------------------------
// The state's memory.

/// One cache line of state memory.
#[repr(C, align(64))]
#[derive(Copy, Clone)]
struct Line([u8; LINE_BYTES as usize]);

const _: () = assert!(std::mem::size_of::<Line>() == LINE_BYTES as usize);
const _: () = assert!(std::mem::align_of::<Line>() == LINE_BYTES as usize);

/// `len` bytes starting on a 64-byte boundary: a whole number of [`Line`]s viewed as one byte
/// slice (the bytes past `len`, up to the end of the last line, are zero and never seen).
#[derive(Clone)]
pub(crate) struct LineBytes {
    lines: Vec<Line>,
    /// At most `64 × lines.len()` (`zeroed`, the only constructor; never changed).
    len: usize,
}

impl LineBytes {
    /// `len` zero bytes.
    pub(crate) fn zeroed(len: usize) -> LineBytes {
        LineBytes {
            lines: vec![Line([0; LINE_BYTES as usize]); len.div_ceil(LINE_BYTES as usize)],
            len,
        }
    }

    /// The bytes.
    #[inline(always)]
    pub(crate) fn bytes(&self) -> &[u8] {
        // SAFETY: `Line` is `repr(C)` around `[u8; 64]` (size asserted above): the lines are
        // `64 × lines.len()` initialised bytes with no padding, and `len <= 64 × lines.len()`
        // (`zeroed`, the only constructor).
        unsafe { std::slice::from_raw_parts(self.lines.as_ptr().cast::<u8>(), self.len) }
    }

    /// The bytes, to write.
    #[inline(always)]
    pub(crate) fn bytes_mut(&mut self) -> &mut [u8] {
        // SAFETY: as in `bytes`; the `&mut self` borrow makes the slice the only access.
        unsafe { std::slice::from_raw_parts_mut(self.lines.as_mut_ptr().cast::<u8>(), self.len) }
    }
}

// ---------------------------------------------------------------------------------------------
// The checked code.

/// Lowered code that passed the check its unchecked reads rely on (the module's invariants).
/// Read-only: it derefs to the [`Code`], and nothing gives `&mut` access to it.
#[derive(Debug)]
pub(crate) struct CheckedCode(Code);

impl CheckedCode {
    /// Checks `code` (the module's first invariant) and keeps it.
    ///
    /// # Panics
    /// If lowering broke one of the invariants (a bug, never bad input).
    pub(crate) fn new(code: Code) -> CheckedCode {
        let n = code.ops.len();
        assert!(
            matches!(code.ops.last(), Some(Op::EndPou)),
            "lowering: the code ends with an EndPou"
        );
        let pcs = code.rung_op.iter().chain(&code.pou_entry);
        let loops = code.fors.iter().flat_map(|l| [l.test, l.exit]);
        let jumps = code.ops.iter().filter_map(|op| match *op {
            Op::Jmp { to } | Op::JmpBack { to, .. } | Op::Call { to, .. } => Some(to),
            _ => None,
        });
        for pc in pcs.copied().chain(loops).chain(jumps) {
            assert!(pc.index() < n, "lowering: instruction {} of {n}", pc.raw());
        }
        for op in &code.ops {
            if let Op::Fused { f, table, .. } | Op::FusedHead { f, table, .. } = *op {
                assert!(
                    f.index() < code.fused.len() && (table as usize) < code.tables.len(),
                    "lowering: a fused rung's operands"
                );
            }
            if let Op::For { f } | Op::ForTest { f } | Op::Next { f } = *op {
                assert!(f.index() < code.fors.len(), "lowering: a FOR loop");
            }
        }
        // Every byte any instruction touches is inside the state (loop counters and constants
        // included); `Trusted` and `ItemStore` rely on it.
        assert!(
            code.access_end() <= code.size as u64,
            "lowering placed an access past the state"
        );
        CheckedCode(code)
    }

    /// The instructions, for the interpreter's unchecked fetch.
    #[inline(always)]
    pub(crate) fn ops(&self) -> CheckedOps<'_> {
        CheckedOps(&self.0.ops)
    }

    /// The operands and truth table of a fused rung.
    ///
    /// # Safety
    /// `(f, table)` are the operands of a `Fused` or `FusedHead` instruction of this code (all
    /// of which `new` checked).
    #[inline(always)]
    pub(crate) unsafe fn fused_operands(&self, f: FusedId, table: u16) -> (&FusedRung, &Table) {
        debug_assert!(f.index() < self.0.fused.len() && (table as usize) < self.0.tables.len());
        // SAFETY: `new` asserted both indices in range for every fused instruction, the
        // caller's operands are such an instruction's, and the code never changes.
        unsafe {
            (
                self.0.fused.get_unchecked(f.index()),
                self.0.tables.get_unchecked(table as usize),
            )
        }
    }
}

impl Deref for CheckedCode {
    type Target = Code;
    #[inline(always)]
    fn deref(&self) -> &Code {
        &self.0
    }
}

/// The instructions of a [`CheckedCode`].
#[derive(Copy, Clone)]
pub(crate) struct CheckedOps<'a>(&'a [Op]);

impl CheckedOps<'_> {
    /// The instruction at `pc`, unchecked.
    ///
    /// # Safety
    /// `pc` is an instruction index the code holds (a rung's start, a POU's entry, a FOR
    /// loop's test or exit, the target of a `Jmp`, `JmpBack` or `Call` instruction), or one
    /// past an instruction that is not an `EndPou`. Then `pc` is an instruction: `new` checked
    /// the indices, and the last instruction is an `EndPou`.
    #[inline(always)]
    pub(crate) unsafe fn at(self, pc: usize) -> Op {
        debug_assert!(pc < self.0.len());
        // SAFETY: in range by this function's contract and `CheckedCode::new`'s check.
        *unsafe { self.0.get_unchecked(pc) }
    }
}

// ---------------------------------------------------------------------------------------------
// The sequential walk's store.

/// A state's memory with the bounds already checked for every address a machine's code uses:
/// the sequential interpreter's store, without a bounds check per access.
pub(crate) struct Trusted<'a>(&'a mut [u8]);

impl<'a> Trusted<'a> {
    /// The store of `mem` for `code`'s accesses.
    ///
    /// # Safety
    /// The store is loaded from and stored to only at the addresses (and widths) of `code`'s
    /// instructions and loop counters: it is passed only to the interpreter running `code`.
    /// They end inside `code.size` (`CheckedCode::new`), and this asserts that `mem` has that
    /// many bytes.
    ///
    /// # Panics
    /// If `mem` has fewer than `code.size` bytes.
    #[inline(always)]
    pub(crate) unsafe fn new(mem: &'a mut [u8], code: &CheckedCode) -> Trusted<'a> {
        assert!(
            mem.len() >= code.size as usize,
            "state too small for this machine"
        );
        Trusted(mem)
    }
}

impl Store for Trusted<'_> {
    #[inline(always)]
    fn load<T: Word>(&self, at: Addr) -> T {
        debug_assert!(at.index() + T::SIZE <= self.0.len());
        // SAFETY: in bounds by the contract of `Trusted::new`.
        T::read(unsafe { self.0.get_unchecked(at.index()..at.index() + T::SIZE) })
    }
    #[inline(always)]
    fn store<T: Word>(&mut self, at: Addr, v: T) {
        debug_assert!(at.index() + T::SIZE <= self.0.len());
        // SAFETY: in bounds by the contract of `Trusted::new`.
        v.write(unsafe { self.0.get_unchecked_mut(at.index()..at.index() + T::SIZE) })
    }
}

// ---------------------------------------------------------------------------------------------
// The parallel workers' shared state.

/// The state's bytes, shared by all workers without locks.
#[derive(Copy, Clone, Debug)]
pub struct SharedSlots {
    /// The first byte: on a 64-byte line (a `State`'s memory).
    ptr: *mut u8,
    len: usize,
}

// SAFETY: a `SharedSlots` is only created by the parallel machine's run from the `&mut State`
// it holds for the whole run, and only for plans that passed their check: in a phase, no byte
// one worker writes is read or written by another, and phases are ordered by Release/Acquire
// hand-overs, so sharing it between threads never lets two accesses to one byte race (every
// access goes through `bytes`, `bytes_mut` or `ItemStore`, whose contracts say so).
unsafe impl Send for SharedSlots {}
// SAFETY: as above.
unsafe impl Sync for SharedSlots {}

impl SharedSlots {
    /// The slots of `mem`, for `machine`'s accesses.
    ///
    /// # Panics
    /// If `mem` is smaller than the machine's state ([`Machine::state_size`]).
    pub(crate) fn new(mem: &mut [u8], machine: &Machine) -> SharedSlots {
        assert!(
            mem.len() >= machine.state_size() as usize,
            "state too small for this machine"
        );
        SharedSlots {
            ptr: mem.as_mut_ptr(),
            len: mem.len(),
        }
    }

    /// The address of byte `index` (a hint's target: never dereferenced here).
    #[inline(always)]
    pub(crate) fn byte_ptr(&self, index: usize) -> *mut u8 {
        self.ptr.wrapping_add(index)
    }

    /// The memory as a slice, for one worker while no other thread accesses it.
    ///
    /// # Safety
    /// No other thread accesses the memory while the slice lives, and it does not outlive the
    /// run (the `&mut State` the memory is borrowed from).
    #[inline]
    pub(crate) unsafe fn bytes_mut<'a>(self) -> &'a mut [u8] {
        // SAFETY: `ptr..ptr + len` is the state's memory, borrowed mutably for the whole run;
        // the caller guarantees exclusive access while the slice lives.
        unsafe { std::slice::from_raw_parts_mut(self.ptr, self.len) }
    }

    /// The memory as a shared slice, for workers that only read it while no thread writes it.
    ///
    /// # Safety
    /// No thread writes the memory while the slice lives, and it does not outlive the run.
    #[inline]
    pub(crate) unsafe fn bytes<'a>(self) -> &'a [u8] {
        // SAFETY: as in `bytes_mut`; the caller guarantees that nobody writes meanwhile.
        unsafe { std::slice::from_raw_parts(self.ptr, self.len) }
    }
}

/// The shared state as the interpreter's [`Store`] while a worker runs one item of a checked
/// plan with one machine's code: the only way the workers' interpreter reaches the shared
/// bytes. Unchecked: a bounds check per access cost the parallel scan about a fifth of its time
/// per rung (gen 20k, half the rungs per worker: 55 µs a scan checked, 48 unchecked).
pub(crate) struct ItemStore(SharedSlots);

impl ItemStore {
    /// The shared slots as `m`'s store, for one item.
    ///
    /// # Safety
    /// The store is passed only to `m`'s interpreter ([`Machine::resume`]) and dropped when it
    /// returns, so it is loaded from and stored to only at addresses of `m`'s code (which end
    /// inside `m`'s state size: `CheckedCode::new`; this asserts the memory has that many
    /// bytes); and the accesses of that item are allowed to this worker in this phase by the
    /// plan's check (no byte it writes is touched by another worker, no byte it reads is
    /// written by another), ordered after the phases before by a Release/Acquire hand-over.
    ///
    /// # Panics
    /// If the memory is smaller than `m`'s state.
    #[inline(always)]
    pub(crate) unsafe fn new(slots: SharedSlots, m: &Machine) -> ItemStore {
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
        debug_assert!(
            at.index() + T::SIZE <= self.0.len,
            "access out of the state"
        );
        let p = self.0.ptr.wrapping_add(at.index());
        // SAFETY: `p..p + T::SIZE` is inside the state's memory: `at` is an address of the code
        // of the machine the store was made for (the contract of `ItemStore::new`), which ends
        // inside its state size, and `new` asserted that the memory has at least that many
        // bytes (initialised, borrowed for the whole run). No other worker writes these bytes
        // meanwhile (the plan check, by the same contract), so this read races with nothing.
        unsafe { T::read(std::slice::from_raw_parts(p, T::SIZE)) }
    }
    #[inline(always)]
    fn store<T: Word>(&mut self, at: Addr, v: T) {
        debug_assert!(
            at.index() + T::SIZE <= self.0.len,
            "access out of the state"
        );
        let p = self.0.ptr.wrapping_add(at.index());
        // SAFETY: in bounds as in `load`; no other worker reads or writes these bytes meanwhile
        // (the plan check, by the contract of `new`), so no access races with this write.
        unsafe { v.write(std::slice::from_raw_parts_mut(p, T::SIZE)) }
    }
}

// ---------------------------------------------------------------------------------------------
// The exchange lines' packing.

/// Bit 0 of each of 16 bytes as a 16-bit mask (byte i → bit i), by SSE2.
#[cfg(target_arch = "x86_64")]
#[inline(always)]
pub(crate) fn pack_bools(q: &[u8; 16]) -> u16 {
    use std::arch::x86_64::{_mm_loadu_si128, _mm_movemask_epi8, _mm_slli_epi64};
    // Shifting each 64-bit lane left by 7 puts bit 0 of every byte into that byte's top bit,
    // which the byte mask collects, byte i → bit i.
    // SAFETY: SSE2 is in the x86_64 baseline (every x86_64 CPU has it and the target enables
    // it), so the three intrinsics exist wherever this code runs; the load reads the 16 bytes
    // of `q`, a `&[u8; 16]`, and allows any alignment.
    let bits =
        unsafe { _mm_movemask_epi8(_mm_slli_epi64::<7>(_mm_loadu_si128(q.as_ptr().cast()))) };
    bits as u16
}
