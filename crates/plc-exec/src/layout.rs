//! Where each variable lives in a state's memory: a byte address per variable, every value in its
//! type's width and aligned to it.
//!
//! Widths are a function of the type ([`Repr`]): BOOL 1 byte (0 or 1), SINT, USINT and BYTE 1,
//! INT, UINT and WORD 2, DINT, UDINT, DWORD, REAL and TIME 4, LINT, ULINT, LWORD and LREAL 8. An instance is a small fixed struct whose fields sit at fixed offsets
//! ([`field_offset`]): a timer (TON, TOF, TP) is Q (1 byte) at 0, its state flags at 1, ET at 4,
//! PT at 8 and its start time (8 bytes, ms) at 16 — [`TIMER_BYTES`] in all, aligned to 8; a
//! counter (CTU, CTD) is Q at 0, the CU/CD of its previous evaluation at 1, CV at 2 and PV at 4
//! — [`COUNTER_BYTES`], aligned to 2. A bistable (SR, RS) is Q1 at 0 ([`BISTABLE_BYTES`]); an
//! edge detector (R_TRIG, F_TRIG) Q at 0 and its memory M at 1 ([`TRIGGER_BYTES`]); an up-down
//! counter (CTUD) QU at 0, the CU (bit 0) and CD (bit 1) of its previous evaluation at 1, CV at
//! 2, PV at 4 and QD at 6 ([`CTUD_BYTES`], aligned to 2). [`parts`] lists every stored value of a
//! type.
//!
//! The interpreter never assumes variables are dense or in declaration order: a parallel
//! executor can permute and pad them (so that variables written by different workers sit on
//! different cache lines) with [`Layout::from_groups`] or [`Layout::from_starts`]. A layout does
//! not place the machine's constants and loop counters (lowering appends them) and does no
//! access itself (`store`).

use super::store::Addr;
use plc_model::{FbKind, Field, Program, Type, VarId};
use std::ops::Range;

/// How a scalar type is stored.
#[derive(Copy, Clone, Debug, PartialEq, Eq)]
pub enum Repr {
    /// BOOL: one byte, 0 or 1.
    Bool,
    /// SINT: 8-bit two's complement.
    I8,
    /// INT: 16-bit two's complement.
    I16,
    /// DINT, TIME (ms): 32-bit two's complement.
    I32,
    /// LINT: 64-bit two's complement.
    I64,
    /// USINT, BYTE: 8-bit unsigned.
    U8,
    /// UINT, WORD: 16-bit unsigned.
    U16,
    /// UDINT, DWORD: 32-bit unsigned.
    U32,
    /// ULINT, LWORD: 64-bit unsigned.
    U64,
    /// REAL: IEEE 754 single.
    F32,
    /// LREAL: IEEE 754 double.
    F64,
}

impl Repr {
    /// The representation of a scalar type; `None` for an instance type.
    pub fn of(ty: Type) -> Option<Repr> {
        match ty {
            Type::Bool => Some(Repr::Bool),
            Type::Sint => Some(Repr::I8),
            Type::Int => Some(Repr::I16),
            Type::Dint | Type::Time => Some(Repr::I32),
            Type::Lint => Some(Repr::I64),
            Type::Usint | Type::Byte => Some(Repr::U8),
            Type::Uint | Type::Word => Some(Repr::U16),
            Type::Udint | Type::Dword => Some(Repr::U32),
            Type::Ulint | Type::Lword => Some(Repr::U64),
            Type::Real => Some(Repr::F32),
            Type::Lreal => Some(Repr::F64),
            // A STRING is a slot of bytes, not a scalar word (`strings`).
            Type::String | Type::Fb(_) => None,
        }
    }

    /// Width (and alignment) in bytes.
    pub fn width(self) -> u32 {
        match self {
            Repr::Bool | Repr::I8 | Repr::U8 => 1,
            Repr::I16 | Repr::U16 => 2,
            Repr::I32 | Repr::U32 | Repr::F32 => 4,
            Repr::I64 | Repr::U64 | Repr::F64 => 8,
        }
    }
}

/// Bytes of a timer instance.
pub const TIMER_BYTES: u32 = 24;
/// Bytes of a counter instance.
pub const COUNTER_BYTES: u32 = 6;

/// Bytes of an SR or RS instance.
pub(crate) const BISTABLE_BYTES: u32 = 1;
/// Bytes of an R_TRIG or F_TRIG instance.
pub(crate) const TRIGGER_BYTES: u32 = 2;
/// Bytes of a CTUD instance.
pub(crate) const CTUD_BYTES: u32 = 8;

/// Offsets inside an instance (the readable fields are also at [`field_offset`]).
pub(crate) const Q: u32 = 0;
pub(crate) const FLAGS: u32 = 1; // timers: state bits (u8)
pub(crate) const PREV: u32 = 1; // counters: CU/CD of the previous evaluation (u8)
pub(crate) const CV: u32 = 2; // counters: i16
pub(crate) const PV: u32 = 4; // counters: i16
pub(crate) const ET: u32 = 4; // timers: i32 ms
pub(crate) const PT: u32 = 8; // timers: i32 ms
pub(crate) const START: u32 = 16; // timers: start time, i64 ms
pub(crate) const MEM: u32 = 1; // R_TRIG, F_TRIG: M (u8)
pub(crate) const QD: u32 = 6; // CTUD: QD (u8)

const TIMER_PARTS: [(u32, u32); 5] = [(Q, 1), (FLAGS, 1), (ET, 4), (PT, 4), (START, 8)];
const COUNTER_PARTS: [(u32, u32); 4] = [(Q, 1), (PREV, 1), (CV, 2), (PV, 2)];
const TRIGGER_PARTS: [(u32, u32); 2] = [(Q, 1), (MEM, 1)];
const CTUD_PARTS: [(u32, u32); 5] = [(Q, 1), (PREV, 1), (CV, 2), (PV, 2), (QD, 1)];
const SCALAR_PARTS: [[(u32, u32); 1]; 4] = [[(0, 1)], [(0, 2)], [(0, 4)], [(0, 8)]];
/// A STRING slot as 16 words of 8 bytes (length byte, body, pad: `strings::STR_SLOT`).
const STRING_PARTS: [(u32, u32); 16] = {
    let mut p = [(0, 8); 16];
    let mut i = 0;
    while i < 16 {
        p[i] = (8 * i as u32, 8);
        i += 1;
    }
    p
};

// Every part aligned to its width, inside its instance.
const _: () = {
    let mut i = 0;
    while i < TIMER_PARTS.len() {
        let (o, w) = TIMER_PARTS[i];
        assert!(o % w == 0 && o + w <= TIMER_BYTES);
        i += 1;
    }
    let mut i = 0;
    while i < COUNTER_PARTS.len() {
        let (o, w) = COUNTER_PARTS[i];
        assert!(o % w == 0 && o + w <= COUNTER_BYTES);
        i += 1;
    }
    let mut i = 0;
    while i < CTUD_PARTS.len() {
        let (o, w) = CTUD_PARTS[i];
        assert!(o % w == 0 && o + w <= CTUD_BYTES);
        i += 1;
    }
    assert!(MEM < TRIGGER_BYTES);
};

/// Every value a variable of type `ty` stores, as (offset, width) in bytes, in offset order: one
/// for a scalar; an instance's fields and internal state.
pub fn parts(ty: Type) -> &'static [(u32, u32)] {
    match ty {
        Type::Fb(FbKind::Ton | FbKind::Tof | FbKind::Tp) => &TIMER_PARTS,
        Type::Fb(FbKind::Ctu | FbKind::Ctd) => &COUNTER_PARTS,
        Type::Fb(FbKind::Sr | FbKind::Rs) => &SCALAR_PARTS[0],
        Type::Fb(FbKind::RTrig | FbKind::FTrig) => &TRIGGER_PARTS,
        Type::Fb(FbKind::Ctud) => &CTUD_PARTS,
        Type::String => &STRING_PARTS,
        scalar => match Repr::of(scalar).map_or(1, Repr::width) {
            1 => &SCALAR_PARTS[0],
            2 => &SCALAR_PARTS[1],
            4 => &SCALAR_PARTS[2],
            _ => &SCALAR_PARTS[3],
        },
    }
}

/// Bytes a variable of type `ty` takes.
pub fn type_size(ty: Type) -> u32 {
    match ty {
        Type::Fb(FbKind::Ton | FbKind::Tof | FbKind::Tp) => TIMER_BYTES,
        Type::Fb(FbKind::Ctu | FbKind::Ctd) => COUNTER_BYTES,
        Type::Fb(FbKind::Sr | FbKind::Rs) => BISTABLE_BYTES,
        Type::Fb(FbKind::RTrig | FbKind::FTrig) => TRIGGER_BYTES,
        Type::Fb(FbKind::Ctud) => CTUD_BYTES,
        Type::String => super::strings::STR_SLOT,
        scalar => Repr::of(scalar).map_or(1, Repr::width),
    }
}

/// The alignment of a variable of type `ty`: its widest part.
pub fn type_align(ty: Type) -> u32 {
    parts(ty).iter().map(|&(_, w)| w).max().unwrap_or(1)
}

/// Offset of an instance field from the instance's address: Q, Q1 and QU 0, CV 2, ET and PV 4,
/// QD 6, PT 8.
pub fn field_offset(field: Field) -> u32 {
    match field {
        Field::Q | Field::Q1 | Field::Qu => Q,
        Field::Qd => QD,
        Field::Cv => CV,
        Field::Et => ET,
        Field::Pv => PV,
        Field::Pt => PT,
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
    /// A variable's bytes go past the total.
    #[error("variable {var} (bytes {start}..{end}) does not fit in {total} bytes")]
    OutOfRange {
        /// Variable index.
        var: u32,
        /// First byte.
        start: u32,
        /// One past its last byte.
        end: u32,
        /// Total bytes of the layout.
        total: u32,
    },
    /// Two variables share a byte.
    #[error("variables {a} and {b} overlap")]
    Overlap {
        /// One variable index.
        a: u32,
        /// The other.
        b: u32,
    },
    /// A variable starts at an address that is not a multiple of its alignment.
    #[error("variable {var} at byte {start} is not aligned to {align} bytes")]
    Misaligned {
        /// Variable index.
        var: u32,
        /// Its first byte.
        start: u32,
        /// Its alignment.
        align: u32,
    },
    /// A variable index is not a variable of the program, or is listed twice.
    #[error("variable {var} is unknown or listed twice")]
    BadVar {
        /// Variable index.
        var: u32,
    },
    /// An alignment of zero bytes, or one that is not a power of two.
    #[error("alignment must be a power of two bytes")]
    BadAlign,
}

/// The address of each variable: `bytes_of(v) = start(v) .. start(v) + size(v)`.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Layout {
    starts: Vec<Addr>,
    sizes: Vec<u32>,
    total: u32,
}

/// Sizes and alignments of the program's variables.
fn shapes(p: &Program) -> (Vec<u32>, Vec<u32>) {
    p.vars()
        .iter()
        .map(|v| (type_size(v.ty), type_align(v.ty)))
        .unzip()
}

/// Places `vars` one after the other from `next`, narrowest alignment first (BOOLs first, then
/// INTs, …; declaration order within one alignment), each at the lowest address its alignment
/// allows; returns the end. Narrow first keeps the BOOLs that contacts read at low addresses
/// (the interpreter fuses contacts on addresses below 2^16) and packed together.
fn place(vars: &[VarId], sizes: &[u32], aligns: &[u32], starts: &mut [Addr], mut next: u32) -> u32 {
    let mut order = vars.to_vec();
    order.sort_by_key(|v| aligns[v.index()]); // stable
    for v in order {
        next = next.next_multiple_of(aligns[v.index()]);
        starts[v.index()] = Addr(next);
        next += sizes[v.index()];
    }
    next
}

impl Layout {
    /// Every variable packed, narrowest alignment first (declaration order within one
    /// alignment), with only the padding alignment needs.
    pub fn dense(p: &Program) -> Layout {
        let (sizes, aligns) = shapes(p);
        let all: Vec<VarId> = p.vars().ids().collect();
        let mut starts = vec![Addr(0); sizes.len()];
        let total = place(&all, &sizes, &aligns, &mut starts, 0);
        Layout {
            starts,
            sizes,
            total,
        }
    }

    /// A layout from explicit first bytes (`starts[v]` for variable `v`) and a total size in
    /// bytes. Gaps (padding) are allowed; overlaps, misaligned variables and bytes past `total`
    /// are not.
    pub fn from_starts(p: &Program, starts: Vec<u32>, total: u32) -> Result<Layout, LayoutError> {
        let (sizes, aligns) = shapes(p);
        if starts.len() != sizes.len() {
            return Err(LayoutError::WrongLength {
                expected: sizes.len(),
                found: starts.len(),
            });
        }
        let mut order: Vec<u32> = (0..starts.len() as u32).collect();
        order.sort_unstable_by_key(|&v| starts[v as usize]);
        let mut prev: Option<(u32, u32)> = None; // (var, end)
        for &v in &order {
            let (start, align) = (starts[v as usize], aligns[v as usize]);
            if start % align != 0 {
                return Err(LayoutError::Misaligned {
                    var: v,
                    start,
                    align,
                });
            }
            let end = start as u64 + sizes[v as usize] as u64;
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
            starts: starts.into_iter().map(Addr).collect(),
            sizes,
            total,
        })
    }

    /// Groups of variables, each group packed (as [`dense`](Self::dense) packs) from a multiple
    /// of `align` bytes; the variables in no group follow, in a last aligned group. The total is
    /// rounded up to `align`. With `align = 64` (a cache line; state memory starts on one),
    /// variables of different groups never share a cache line.
    pub fn from_groups(
        p: &Program,
        groups: &[Vec<VarId>],
        align: u32,
    ) -> Result<Layout, LayoutError> {
        if !align.is_power_of_two() {
            return Err(LayoutError::BadAlign);
        }
        let n = p.vars().len();
        let (sizes, aligns) = shapes(p);
        let mut starts = vec![Addr(0); n];
        let mut placed = vec![false; n];
        let mut next = 0u32;
        for g in groups {
            for &v in g {
                if v.index() >= n || placed[v.index()] {
                    return Err(LayoutError::BadVar { var: v.raw() });
                }
                placed[v.index()] = true;
            }
            next = place(
                g,
                &sizes,
                &aligns,
                &mut starts,
                next.next_multiple_of(align),
            );
        }
        let rest: Vec<VarId> = p.vars().ids().filter(|v| !placed[v.index()]).collect();
        next = place(
            &rest,
            &sizes,
            &aligns,
            &mut starts,
            next.next_multiple_of(align),
        );
        Ok(Layout {
            starts,
            sizes,
            total: next.next_multiple_of(align),
        })
    }

    /// The bytes of `var` (its fields and internal state for an instance).
    #[inline]
    pub fn bytes_of(&self, var: VarId) -> Range<u32> {
        let s = self.starts[var.index()].0;
        s..s + self.sizes[var.index()]
    }

    /// The address of `var`.
    #[inline]
    pub fn start(&self, var: VarId) -> Addr {
        self.starts[var.index()]
    }

    /// Total bytes of the variables (a machine adds its constants and loop counters after them:
    /// the length of a state's memory is [`Machine::state_size`](super::Machine::state_size)).
    pub fn size(&self) -> u32 {
        self.total
    }

    /// Number of variables laid out.
    pub fn var_count(&self) -> usize {
        self.starts.len()
    }
}
