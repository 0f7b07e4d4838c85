//! The shape of a row and the row itself, as data: a shape is what a kernel computes (the
//! condition items in their canonical order, the outputs and boxes in order, `rows` says how a
//! rung becomes one), a row is a rung's kernel and its slots.
//!
//! Invariant: a shape's `slots()` is the number of slots of every row of its kernel, in the
//! order the kernel (`kernel`) reads them. Plain data only: not here which rungs are rows and
//! how their slots are found (`rows`), nor the C of a kernel (`kernel`) or of a table (`table`).

/// A condition item of a shape, in its canonical order (derived `Ord`: positive contacts,
/// negated contacts, contacts inside ORs, edges, compares, ORs).
#[derive(Clone, Debug, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub(super) enum Item {
    /// A Normal (false) or Negated (true) contact of the top-level AND (slot: the BOOL; which
    /// one it is goes into the row's pattern word).
    Lit(bool),
    /// A contact inside an OR (slots: the BOOL, 0 Normal or 1 Negated).
    Contact,
    /// An edge contact (slots: the BOOL, its memory, 0 rising or 1 falling).
    Edge,
    /// A comparison of two INTs, each a variable or a constant (true) (slots: the operands,
    /// the operator's mask, `rows::cmp_mask`).
    Cmp(bool, bool),
    /// An OR of ANDs (each with at least one item).
    Or(Vec<Vec<Item>>),
}

impl Item {
    fn slots(&self) -> usize {
        match self {
            Item::Lit(_) => 1,
            Item::Contact => 2,
            Item::Edge | Item::Cmp(..) => 3,
            Item::Or(bs) => bs.iter().flatten().map(Item::slots).sum(),
        }
    }
}

/// An output of a shape, or a box (which passes power on, or its Q for a timer or counter).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub(super) enum Out {
    /// A coil, negated coil, set or reset of a BOOL: which one is data (slots: the BOOL, the
    /// kind 0–3, looked up in `_pou__bit` with the power and the old value).
    Bit,
    /// An INT move from a variable or a constant (true) (slots: target, source).
    Move(bool),
    /// INT ADD, SUB or MUL (wrapping) of variables or constants (true) (slots: target, the
    /// operator 0–2, the operands).
    Arith(bool, bool),
    /// INT DIV or MOD of variables or constants (true) (slots: target, the operator 0–1, the
    /// operands, the rung a division by zero names in its fault).
    DivMod(bool, bool),
    /// A TON, TOF or TP with a constant preset; its Q is the power on (slots: the instance,
    /// the kind 0–2, the preset in ms).
    Timer,
    /// A CTU or CTD with a PV and a reset (CTU) or load (CTD) that are variables or constants
    /// (true); its Q is the power on (slots: the instance, the kind 0–1, PV, reset or load).
    Counter(bool, bool),
}

impl Out {
    /// Its slots: the target, then the rest.
    pub(super) fn slots(self) -> usize {
        match self {
            Out::Bit | Out::Move(_) => 2,
            Out::Timer => 3,
            Out::Arith(..) | Out::Counter(..) => 4,
            Out::DivMod(..) => 5,
        }
    }

    /// Whether the power after it is the box's Q (not the power before it).
    pub(super) fn takes_q(self) -> bool {
        matches!(self, Out::Timer | Out::Counter(..))
    }
}

/// The shape of a row: what its kernel computes.
#[derive(Clone, Debug, PartialEq, Eq, Hash)]
pub(super) struct Shape {
    /// The contacts of the top-level AND (Normal or Negated: which ones is data, the row's
    /// pattern word).
    pub lits: usize,
    /// The other items of the top-level AND, sorted.
    pub cond: Vec<Item>,
    /// The outputs and boxes in order (an output branch's paths are outputs that keep the
    /// power, so in order too).
    pub outs: Vec<Out>,
}

impl Shape {
    pub(super) fn slots(&self) -> usize {
        self.out_slots()
            + self.lits
            + usize::from(self.lits > 0)
            + self.cond.iter().map(Item::slots).sum::<usize>()
    }

    pub(super) fn out_slots(&self) -> usize {
        self.outs.iter().map(|o| o.slots()).sum()
    }
}

/// A rung as a row: its kernel and its slots (the offsets of its BOOLs).
#[derive(Clone, Debug)]
pub(crate) struct Row {
    pub kernel: u32,
    pub slots: Vec<u32>,
}
