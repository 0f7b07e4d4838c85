//! Where each variable lives in the slot array.
//!
//! A scalar (BOOL, INT, DINT, REAL, TIME) takes one slot. A timer instance (TON, TOF, TP) takes
//! [`TIMER_SLOTS`] slots: Q, ET, PT, then its start time and its state flags. A counter instance
//! (CTU, CTD) takes [`COUNTER_SLOTS`]: Q, CV, PV, then the CU/CD of its previous evaluation. The
//! readable fields are at [`field_offset`] from the instance's first slot.
//!
//! The interpreter never assumes slots are dense or in declaration order: a parallel executor can
//! permute and pad them (for instance, so that variables written by different workers sit on
//! different cache lines) with [`Layout::from_groups`] or [`Layout::from_starts`].

use crate::model::{FbKind, Field, Program, Type, VarId};
use std::ops::Range;

/// Slots of a timer instance (Q, ET, PT, start, flags).
pub const TIMER_SLOTS: u32 = 5;
/// Slots of a counter instance (Q, CV, PV, previous CU/CD).
pub const COUNTER_SLOTS: u32 = 4;

pub(crate) const Q: u32 = 0;
pub(crate) const ET: u32 = 1; // and CV
pub(crate) const PT: u32 = 2; // and PV
pub(crate) const START: u32 = 3; // timers: start time (ms, i64 bits)
pub(crate) const FLAGS: u32 = 4; // timers: state bits
pub(crate) const PREV: u32 = 3; // counters: CU/CD of the previous evaluation

/// Number of slots a variable of type `ty` takes.
pub fn slot_width(ty: Type) -> u32 {
    match ty {
        Type::Fb(FbKind::Ton | FbKind::Tof | FbKind::Tp) => TIMER_SLOTS,
        Type::Fb(FbKind::Ctu | FbKind::Ctd) => COUNTER_SLOTS,
        _ => 1,
    }
}

/// Offset of an instance field from the instance's first slot: Q 0, ET/CV 1, PT/PV 2.
pub fn field_offset(field: Field) -> u32 {
    match field {
        Field::Q => Q,
        Field::Et | Field::Cv => ET,
        Field::Pt | Field::Pv => PT,
    }
}

/// Why a layout was refused.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
pub enum LayoutError {
    /// The layout does not give one start per variable of the program.
    #[error("the layout has {found} variable starts, the program has {expected} variables")]
    WrongLength {
        /// Variables in the program.
        expected: usize,
        /// Starts given.
        found: usize,
    },
    /// A variable's slots go past the total.
    #[error("variable {var} (slots {start}..{end}) does not fit in {total} slots")]
    OutOfRange {
        /// Variable index.
        var: u32,
        /// First slot.
        start: u32,
        /// One past its last slot.
        end: u32,
        /// Total slots of the layout.
        total: u32,
    },
    /// Two variables share a slot.
    #[error("variables {a} and {b} overlap")]
    Overlap {
        /// One variable index.
        a: u32,
        /// The other.
        b: u32,
    },
    /// A variable index is not a variable of the program, or is listed twice.
    #[error("variable {var} is unknown or listed twice")]
    BadVar {
        /// Variable index.
        var: u32,
    },
    /// An alignment of zero slots.
    #[error("alignment must be at least one slot")]
    ZeroAlign,
}

/// The slot of each variable: `slots_of(v) = start(v) .. start(v) + width(v)`.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Layout {
    starts: Vec<u32>,
    widths: Vec<u32>,
    total: u32,
}

impl Layout {
    /// Variables one after the other, in declaration order, no padding.
    pub fn dense(p: &Program) -> Layout {
        let widths: Vec<u32> = p.vars.iter().map(|v| slot_width(v.ty)).collect();
        let mut starts = Vec::with_capacity(widths.len());
        let mut next = 0u32;
        for &w in &widths {
            starts.push(next);
            next += w;
        }
        Layout {
            starts,
            widths,
            total: next,
        }
    }

    /// A layout from explicit first slots (`starts[v]` for variable `v`) and a total slot count.
    /// Gaps (padding) are allowed; overlaps and slots past `total` are not.
    pub fn from_starts(p: &Program, starts: Vec<u32>, total: u32) -> Result<Layout, LayoutError> {
        let widths: Vec<u32> = p.vars.iter().map(|v| slot_width(v.ty)).collect();
        if starts.len() != widths.len() {
            return Err(LayoutError::WrongLength {
                expected: widths.len(),
                found: starts.len(),
            });
        }
        let mut order: Vec<u32> = (0..starts.len() as u32).collect();
        order.sort_unstable_by_key(|&v| starts[v as usize]);
        let mut prev: Option<(u32, u32)> = None; // (var, end)
        for &v in &order {
            let start = starts[v as usize];
            let end = start as u64 + widths[v as usize] as u64;
            if end > total as u64 {
                return Err(LayoutError::OutOfRange {
                    var: v,
                    start,
                    end: end.min(u32::MAX as u64) as u32,
                    total,
                });
            }
            if let Some((a, prev_end)) = prev {
                if start < prev_end {
                    return Err(LayoutError::Overlap { a, b: v });
                }
            }
            prev = Some((v, end as u32));
        }
        Ok(Layout {
            starts,
            widths,
            total,
        })
    }

    /// Groups of variables, each group dense and starting at a multiple of `align` slots; the
    /// variables in no group follow, in declaration order, in a last aligned group. The total is
    /// rounded up to `align`. With `align = 8` (64-byte lines of 8-byte slots), variables of
    /// different groups never share a cache line.
    pub fn from_groups(
        p: &Program,
        groups: &[Vec<VarId>],
        align: u32,
    ) -> Result<Layout, LayoutError> {
        if align == 0 {
            return Err(LayoutError::ZeroAlign);
        }
        let n = p.vars.len();
        let widths: Vec<u32> = p.vars.iter().map(|v| slot_width(v.ty)).collect();
        let mut starts = vec![u32::MAX; n];
        let mut next = 0u32;
        let round = |x: u32| x.div_ceil(align) * align;
        for g in groups {
            next = round(next);
            for &v in g {
                if v.index() >= n || starts[v.index()] != u32::MAX {
                    return Err(LayoutError::BadVar { var: v.0 });
                }
                starts[v.index()] = next;
                next += widths[v.index()];
            }
        }
        next = round(next);
        for v in 0..n {
            if starts[v] == u32::MAX {
                starts[v] = next;
                next += widths[v];
            }
        }
        Ok(Layout {
            starts,
            widths,
            total: round(next),
        })
    }

    /// The slots of `var` (its fields and internal state for an instance).
    #[inline]
    pub fn slots_of(&self, var: VarId) -> Range<u32> {
        let s = self.starts[var.index()];
        s..s + self.widths[var.index()]
    }

    /// The first slot of `var`.
    #[inline]
    pub fn start(&self, var: VarId) -> u32 {
        self.starts[var.index()]
    }

    /// Total number of slots of the variables (a machine adds its loop counters after them:
    /// the length of a state's slot array is [`Machine::slot_count`](super::Machine::slot_count)).
    pub fn slot_count(&self) -> u32 {
        self.total
    }

    /// Number of variables laid out.
    pub fn var_count(&self) -> usize {
        self.starts.len()
    }
}
