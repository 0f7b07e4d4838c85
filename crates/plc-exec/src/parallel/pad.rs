//! Padding: a value on its own 128-byte block, so that per-worker data (barrier epochs, decision
//! lines, fault buffers) never shares a cache line — nor, through the adjacent-line prefetcher,
//! a pair of lines — with another worker's. No logic; the bottom of the parallel module.

/// Pads its content to its own 128-byte block (two cache lines: also keeps the adjacent-line
/// prefetcher from coupling neighbours).
#[repr(align(128))]
#[derive(Debug, Default)]
pub(super) struct Padded<T>(pub(super) T);
