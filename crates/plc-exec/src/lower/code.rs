//! The interpreter's instruction set and the lowered program ([`Code`]): what lowering
//! (the parent module) produces and the machine runs. Plain data: each instruction's operands
//! are state addresses ([`Addr`]) and instruction indices ([`Pc`]), checked once after lowering
//! by `raw::CheckedCode::new`, the only way a machine holds code.
//!
//! Not here: how the model becomes these instructions (the parent), nor how they run
//! (`super::super::run`).

use super::super::fb::{CtudId, CtudPins};
use super::super::fuse::{FusedId, FusedRung, Table};
use super::super::layout::Repr;
use super::super::store::Addr;
use plc_model::*;

/// Output modes of [`Op::Coil`] (the `output_mode` module).
pub(crate) use super::super::output_mode::{OUT_COIL, OUT_NCOIL, OUT_RESET, OUT_SET};

index_type!(
    /// An instruction: index into the machine's instruction array.
    Pc
);
index_type!(
    /// A FOR/NEXT loop: index into the machine's loops.
    ForId
);
index_type!(
    /// A standard function call: index into the machine's `funcs`.
    FuncId
);

/// The operands of a standard function box (`Element::Function`): each argument's address and
/// type, the output's.
#[derive(Clone, Debug)]
pub(crate) struct FuncCall {
    pub func: Function,
    pub args: Box<[(Addr, Type)]>,
    pub out: Addr,
    pub ty: Type,
}

/// Numeric representation of a compare, an arithmetic box or a FOR index: the stored
/// representation ([`Repr`], one list of variants for both), never `Bool` ([`num_of`]).
pub(crate) type Num = Repr;

/// The numeric representation of an operand of type `ty`: its stored representation; BOOL and
/// instance types as DINT.
pub(super) fn num_of(ty: Type) -> Num {
    match Repr::of(ty) {
        Some(Repr::Bool) | None => Repr::I32,
        Some(r) => r,
    }
}

/// Bytes a MOVE copies: the width of its type (for an instance, whose first stored value is
/// its Q, that byte).
#[derive(Copy, Clone, Debug, PartialEq, Eq)]
pub(crate) enum Width {
    W1,
    W2,
    W4,
    W8,
}

impl Width {
    pub(super) fn of(ty: Type) -> Width {
        match Repr::of(ty).map_or(1, Repr::width) {
            1 => Width::W1,
            2 => Width::W2,
            4 => Width::W4,
            _ => Width::W8,
        }
    }

    /// The bytes copied.
    pub(crate) fn bytes(self) -> u32 {
        match self {
            Width::W1 => 1,
            Width::W2 => 2,
            Width::W4 => 4,
            Width::W8 => 8,
        }
    }
}

/// One instruction. Small (16 bytes) and `Copy`; operands are byte addresses of the state.
#[derive(Copy, Clone, Debug)]
pub(crate) enum Op {
    /// Start of a rung: leave if the rung is outside the region being run; power := TRUE.
    Rung { id: RungId },
    /// A whole rung of plain contacts and one output (the `fuse` module), in place of its
    /// `Rung` marker and everything after it: leave if the rung is outside the region; the
    /// output at `fused[f].out` := bit `(index ^ neg) | old << 8` of table `table`, the index
    /// packing the bytes of `fused[f].at`, `old` the output's value.
    Fused {
        id: RungId,
        f: FusedId,
        table: u16,
        neg: u8,
    },
    /// The start of a rung whose first elements are plain contacts (the `fuse` module), in
    /// place of its `Rung` marker and those contacts: leave if the rung is outside the region;
    /// power := bit `index ^ neg` of table `table` (a coil's: bit 8 does not count), the index
    /// packing the bytes of `fused[f].at`. The rest of the rung follows.
    FusedHead {
        id: RungId,
        f: FusedId,
        table: u16,
        neg: u8,
    },
    /// Contact on a BOOL byte: `p &= v ^ neg` (`neg` 0 or 1).
    Contact { neg: u8, at: Addr },
    /// Two consecutive contacts (negation bits 0 and 1 of `neg`).
    Contact2 { neg: u8, a: Addr, b: Addr },
    /// Three consecutive contacts (negation bits 0, 1 and 2 of `neg`).
    Contact3 { neg: u8, a: Addr, b: Addr, c: Addr },
    /// Four to six consecutive contacts on bytes below 2^16 (negation bit k for contact k): one
    /// dispatch and 16 bytes for what is most of a typical rung. Entries past `n` repeat `s[0]`
    /// (a byte the rung reads anyway) and are masked out.
    ContactN { n: u8, neg: u8, s: [u16; 6] },
    /// Rising-edge contact with its memory byte.
    Rising { at: Addr, mem: Addr },
    /// Falling-edge contact with its memory byte.
    Falling { at: Addr, mem: Addr },
    /// Compare of two operands of one numeric type.
    Cmp {
        op: CmpOp,
        num: Num,
        a: Addr,
        b: Addr,
    },
    /// `or`: push power in and an empty OR.
    OrOpen,
    /// `or`, between branches: OR in this branch's power, restart from the power in.
    OrNext,
    /// `or`, after its last branch: power := the OR of all branches; pop.
    OrClose,
    /// `branch`: push the power in.
    BrOpen,
    /// `branch`, between branches: power := the power in.
    BrNext,
    /// `branch`, after its last branch: power := the power in; pop.
    BrClose,
    /// Any output (coil, negated coil, set, reset; `mode` as [`OUT_COIL`]): powered,
    /// `v := on`; unpowered, `v := off` unless the mode keeps it.
    Coil { at: Addr, mode: u8 },
    /// Timer box on the instance at `inst`.
    Timer {
        kind: TimerKind,
        inst: Addr,
        pt: Addr,
    },
    /// CTU box.
    Ctu { inst: Addr, pv: Addr, reset: Addr },
    /// CTD box.
    Ctd { inst: Addr, pv: Addr, load: Addr },
    /// SR/RS box on the instance at `inst`; power in is S1/S, `reset` R/R1.
    Bistable {
        kind: BistableKind,
        inst: Addr,
        reset: Addr,
    },
    /// R_TRIG/F_TRIG box on the instance at `inst`; power in is CLK.
    Trigger { kind: TriggerKind, inst: Addr },
    /// CTUD box on the instance at `inst`; power in is CU, the other operands in `ctuds`.
    Ctud { inst: Addr, pins: CtudId },
    /// MOVE box.
    Move { width: Width, from: Addr, to: Addr },
    /// A STRING copied (its whole slot, `strings::STR_SLOT` bytes) when powered.
    StrMove { from: Addr, to: Addr },
    /// A comparison of two STRINGs (`strings::compare`, matiec's `__str_cmp`).
    StrCmp { op: CmpOp, a: Addr, b: Addr },
    /// Standard function box: operands and output in `funcs`.
    Func { call: FuncId },
    /// Arithmetic box.
    Arith {
        op: ArithOp,
        num: Num,
        a: Addr,
        b: Addr,
        out: Addr,
    },
    /// Forward jump to the instruction `to` (a `Rung`).
    Jmp { to: Pc },
    /// Backward (or same-rung) jump: a loop-back. Counts one iteration in the rung's loop counter
    /// at `ctr`, then charges `charge` rungs to the scan budget (`budget`); past the cap or the
    /// budget the jump is refused: it acts as an unpowered jump (power := 0).
    JmpBack { to: Pc, ctr: Addr, charge: u32 },
    /// RET.
    Ret,
    /// When powered, records an index-range fault of the scan at this rung.
    RangeFault,
    /// END.
    End,
    /// CALL: charge `charge` rungs to the scan budget, then (unless refused) run the POU whose
    /// first instruction is `to`.
    Call { to: Pc, charge: u32 },
    /// FOR head (after the head rung's conditions): when powered, `var := from` and on to the
    /// [`Op::ForTest`] that always follows; otherwise to the loop's exit.
    For { f: ForId },
    /// FOR test: `var <= to` enters the body (next instruction), otherwise to the loop's exit.
    ForTest { f: ForId },
    /// NEXT: a loop-back counted in the loop's counter; `var += 1`, back to the FOR test.
    /// Past the cap: no increment, on to the loop's exit.
    Next { f: ForId },
    /// After the last rung of a POU.
    EndPou,
}

const _: () = assert!(std::mem::size_of::<Op>() <= 16);

impl Op {
    /// The rung this instruction starts, if it starts one (a marker or a fused rung).
    pub(crate) fn starts_rung(&self) -> Option<RungId> {
        match *self {
            Op::Rung { id } | Op::Fused { id, .. } | Op::FusedHead { id, .. } => Some(id),
            _ => None,
        }
    }
}

/// One FOR/NEXT loop.
#[derive(Copy, Clone, Debug)]
pub(crate) struct ForLoop {
    /// The index variable.
    pub var: Addr,
    pub num: Num,
    pub from: Addr,
    pub to: Addr,
    /// Its `ForTest`.
    pub test: Pc,
    /// The loop exit (the rung after NEXT, or the POU's `EndPou`).
    pub exit: Pc,
    /// The FOR head rung.
    pub head: RungId,
    /// The loop counter of the NEXT rung.
    pub ctr: Addr,
    /// What a loop-back charges to the scan budget (`budget::next_charge`).
    pub charge: u32,
}

/// The lowered program.
#[derive(Debug)]
pub(crate) struct Code {
    pub ops: Vec<Op>,
    /// The constants and where they live (written by `Machine::initial_state`).
    pub consts: Vec<(Addr, Value)>,
    pub fors: Vec<ForLoop>,
    /// The operands of each CTUD box but CU.
    pub ctuds: Vec<CtudPins>,
    pub funcs: Vec<FuncCall>,
    /// The operands of each fused rung.
    pub fused: Vec<FusedRung>,
    /// The fused rungs' truth tables.
    pub tables: Vec<Table>,
    /// Each rung's `Rung` marker.
    pub rung_op: Vec<Pc>,
    /// For each rung: its loop if it is a FOR head.
    pub for_of_head: Vec<Option<ForId>>,
    /// Each POU's first instruction.
    pub pou_entry: Vec<Pc>,
    /// Loop-back rungs (a NEXT, or a rung with a backward jump) and their counters, in rung
    /// order.
    pub counters: Vec<(RungId, Addr)>,
    /// Bytes of the whole state: variables, loop counters, constants.
    pub size: u32,
    /// The rules where toolchains differ (counters, timers, TIME conversions).
    pub dialect: plc_model::Dialect,
}

/// Why a program could not be lowered.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
pub enum LowerError {
    /// The layout was built for another program.
    #[error("the layout has {found} variables, the program {expected}")]
    LayoutMismatch {
        /// Variables in the program.
        expected: usize,
        /// Variables in the layout.
        found: usize,
    },
    /// `or`/`branch` nested deeper than the interpreter's 64-bit power stack.
    #[error("rung {rung}: `or`/`branch` nested too deeply ({bits} saved powers, at most 64)")]
    TooDeep {
        /// The rung's id.
        rung: String,
        /// Power-stack bits the rung needs.
        bits: u32,
    },
    /// The program's state or instructions do not fit 32-bit addresses and indices.
    #[error("the program is too large for 32-bit state addresses and instruction indices")]
    TooLarge,
}
