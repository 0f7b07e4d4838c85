//! The cache line the state's memory is laid out on: what `mem` aligns to, what the lowering
//! gives each loop counter, and what the parallel plan check counts. A module of its own, below
//! `mem`, `raw` and `lower`, so that none of them imports another for it.

/// Bytes per cache line (x86-64, most aarch64).
pub const LINE_BYTES: u32 = 64;
