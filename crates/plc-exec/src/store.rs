//! The memory the interpreter works on: bytes, each value stored in its type's width at an
//! address aligned to that width, read and written through typed loads and stores ([`Word`])
//! behind a small trait ([`Store`]), so that the same (monomorphised) interpreter runs on a plain
//! byte slice and on the parallel executor's shared memory.
//!
//! Invariants: an [`Addr`] is a byte address into a state; the machine only ever loads or stores
//! a `T` at an address that is a multiple of `T::SIZE` (the layout aligns every value to its
//! width), so a state whose memory starts on a 64-byte boundary ([`Mem`](super::Mem)) has every
//! value inside one cache line, and byte address / 64 is its line. A BOOL byte always holds 0 or
//! 1: the interpreter only ever writes those, and relies on it when it reads. This module knows
//! nothing of types or variables (see `layout`).

/// A byte address in a state's memory.
#[derive(Copy, Clone, Debug, PartialEq, Eq, PartialOrd, Ord, Hash, Default)]
pub struct Addr(pub u32);

impl Addr {
    /// The byte index.
    #[inline(always)]
    pub fn index(self) -> usize {
        self.0 as usize
    }

    /// The address `bytes` further on.
    #[inline(always)]
    pub fn offset(self, bytes: u32) -> Addr {
        Addr(self.0 + bytes)
    }
}

mod sealed {
    pub trait Sealed {}
}

/// A value the machine stores: a fixed number of bytes (its width, and its alignment), read and
/// written in native byte order. Implemented for `u8` (BOOL and internal flags), `i16` (INT),
/// `i32` (DINT, TIME), `f32` (REAL), `i64` and `u64` (internal times and loop counters).
pub trait Word: Copy + sealed::Sealed {
    /// Width in bytes (a power of two; also the alignment the layout gives the value).
    const SIZE: usize;
    /// Reads the value from exactly `SIZE` bytes.
    fn read(bytes: &[u8]) -> Self;
    /// Writes the value to exactly `SIZE` bytes.
    fn write(self, bytes: &mut [u8]);
}

/// `Word` for a type `$t`, in its native-endian bytes.
macro_rules! word {
    ($($t:ty),*) => {$(
        impl sealed::Sealed for $t {}
        impl Word for $t {
            const SIZE: usize = std::mem::size_of::<$t>();
            #[inline(always)]
            fn read(bytes: &[u8]) -> Self {
                <$t>::from_ne_bytes(bytes.try_into().expect("SIZE bytes"))
            }
            #[inline(always)]
            fn write(self, bytes: &mut [u8]) {
                bytes.copy_from_slice(&self.to_ne_bytes())
            }
        }
    )*};
}

word!(u8, i8, i16, u16, i32, u32, i64, u64, f32, f64);

/// Memory read and written by the interpreter.
///
/// Addresses come from the machine's [`Layout`](super::Layout) and lowering; a store must
/// accept every address below [`Machine::state_size`](super::Machine::state_size).
pub trait Store {
    /// The `T` at `at`.
    fn load<T: Word>(&self, at: Addr) -> T;
    /// Writes `v` at `at`.
    fn store<T: Word>(&mut self, at: Addr, v: T);
}

/// The sequential store: the bytes of a [`State`](super::State), indexed directly (bounds
/// checked; any alignment works, the layout's keeps each value in one cache line).
impl Store for [u8] {
    #[inline(always)]
    fn load<T: Word>(&self, at: Addr) -> T {
        T::read(&self[at.index()..at.index() + T::SIZE])
    }
    #[inline(always)]
    fn store<T: Word>(&mut self, at: Addr, v: T) {
        v.write(&mut self[at.index()..at.index() + T::SIZE])
    }
}

/// The bits of the `width`-byte value at `at` (1, 2, 4 or 8), zero-extended: a layout-free view
/// of a stored value, for digests and comparisons.
///
/// # Panics
/// If `width` is not 1, 2, 4 or 8, or the value is not inside `mem`.
#[inline(always)]
pub fn load_bits(mem: &[u8], at: Addr, width: u32) -> u64 {
    match width {
        1 => mem.load::<u8>(at) as u64,
        2 => mem.load::<i16>(at) as u16 as u64,
        4 => mem.load::<i32>(at) as u32 as u64,
        8 => mem.load::<u64>(at),
        _ => panic!("no value is {width} bytes wide"),
    }
}
