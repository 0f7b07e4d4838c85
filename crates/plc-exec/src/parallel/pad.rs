//! Padding: a value on its own cache-line block, so that per-worker data (barrier epochs,
//! decision lines, fault buffers) never shares a cache line — nor, through the adjacent-line
//! prefetcher, a pair of lines — with another worker's. `crossbeam_utils::CachePadded` (128
//! bytes on x86-64 and aarch64, as the hand-written `Padded` it replaces; rayon already builds
//! crossbeam-utils). No logic; the bottom of the parallel module.

pub(super) use crossbeam_utils::CachePadded as Padded;
