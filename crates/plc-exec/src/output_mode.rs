//! The output modes of a rung's output (coil, negated coil, set, reset) as the interpreter
//! encodes them: bit 0 = the value written when powered, bit 1 = no write when unpowered
//! (set/reset), bit 2 = the value written when unpowered otherwise. One instruction for every
//! output keeps the dispatch after a rung's conditions uniform (set/reset among coils made it
//! mispredict: −15 % per rung on generated programs).
//!
//! Its own module, below both `lower` (the general `Op::Coil`) and `fuse` (the fused rungs'
//! tables), so that neither imports the other back: `lower` uses `fuse`, `fuse` uses only this.

/// A coil: powered → TRUE, unpowered → FALSE.
pub(crate) const OUT_COIL: u8 = 0b001;
/// A negated coil: powered → FALSE, unpowered → TRUE.
pub(crate) const OUT_NCOIL: u8 = 0b100;
/// A set coil: powered → TRUE, unpowered → unchanged.
pub(crate) const OUT_SET: u8 = 0b011;
/// A reset coil: powered → FALSE, unpowered → unchanged.
pub(crate) const OUT_RESET: u8 = 0b010;
