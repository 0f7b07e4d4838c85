//! The memory the interpreter works on: a flat array of 64-bit slots, behind a small trait so the
//! same (monomorphised) interpreter runs on a plain slice and on a shared store.

/// Slot memory read and written by the interpreter.
///
/// Slot indices come from the machine's [`Layout`](super::Layout); a store must accept every
/// index below [`Machine::slot_count`](super::Machine::slot_count). A BOOL slot always holds 0
/// or 1: the interpreter only ever writes those, and relies on it when it reads.
pub trait Store {
    /// The value of `slot`.
    fn get(&self, slot: u32) -> u64;
    /// Writes `v` to `slot`.
    fn set(&mut self, slot: u32, v: u64);
}

/// The sequential store: the slots of a [`State`](super::State), indexed directly.
impl Store for [u64] {
    #[inline(always)]
    fn get(&self, slot: u32) -> u64 {
        self[slot as usize]
    }
    #[inline(always)]
    fn set(&mut self, slot: u32, v: u64) {
        self[slot as usize] = v;
    }
}
