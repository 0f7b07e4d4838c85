//! The backing memory of a state: bytes on 64-byte-aligned lines, so that a byte address / 64 is
//! the cache line it lives on (what the parallel plan check counts) and no value straddles two
//! lines (the layout aligns each value to its width).
//!
//! A [`Mem`] is a whole number of lines viewed as one byte slice of the requested length (the
//! bytes past it, up to the end of the last line, are zero and never seen; the view is
//! `raw::LineBytes`). It does no typed access (`store`) and knows no layout (`layout`).

pub use super::line::LINE_BYTES;
use super::raw::LineBytes;
use std::fmt;
use std::ops::{Deref, DerefMut};

/// A state's memory: `len` bytes starting on a 64-byte boundary, zero-initialised.
#[derive(Clone)]
pub struct Mem(LineBytes);

impl Mem {
    /// `len` zero bytes.
    pub fn zeroed(len: usize) -> Mem {
        Mem(LineBytes::zeroed(len))
    }
}

impl Deref for Mem {
    type Target = [u8];
    #[inline(always)]
    fn deref(&self) -> &[u8] {
        self.0.bytes()
    }
}

impl DerefMut for Mem {
    #[inline(always)]
    fn deref_mut(&mut self) -> &mut [u8] {
        self.0.bytes_mut()
    }
}

impl PartialEq for Mem {
    fn eq(&self, other: &Mem) -> bool {
        **self == **other
    }
}

impl Eq for Mem {}

impl fmt::Debug for Mem {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_list().entries(self.iter()).finish()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn memory_starts_on_a_line_and_has_its_length() {
        for len in [0, 1, 63, 64, 65, 1000] {
            let mut m = Mem::zeroed(len);
            assert_eq!(m.len(), len);
            assert_eq!(m.as_ptr() as usize % 64, 0);
            assert!(m.iter().all(|&b| b == 0));
            if len > 0 {
                m[len - 1] = 7;
                assert_eq!(m[len - 1], 7);
            }
        }
    }
}
