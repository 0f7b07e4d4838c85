//! The FBD model: networks of blocks joined by arcs, as read from the program file (before any
//! name is resolved), and the plan of each network (execution order and conditional fragments).
//!
//! Blocks of a network live in a dense `Vec` sorted by their user id and are addressed by
//! [`BlockId`] (the index), so "ties by block id" is "ties by index". What only some ops have (a
//! timer's instance, a JMP's label, the type of a call) is data of their [`Op`] variant. Operands
//! are kept by name or as written ([`Input`]): a function block type's body is read once and
//! resolved once per instance.

use plc_model::{
    ArithOp, BistableKind, CmpOp, Function, PouId, RungId, TimerKind, TriggerKind, VarId,
};
use std::ops::Range;

pub use super::ids::BlockId;
use plc_model::{index_type, Arena};

index_type!(
    /// A conditional fragment of one network: index into [`Plan::fragments`]; 0 is the root.
    FragmentId
);

/// Every FBD body of a program: the main program and subroutines written in FBD, then the
/// function block types written in FBD, in file order.
#[derive(Clone, Debug, Default)]
pub struct Fbd {
    pub pous: Vec<FbdPou>,
    /// Every instance of a user function block type (with an FBD or a ladder body), in the order
    /// their POUs follow the subroutines: the instance → type map.
    pub instances: Vec<FbInstance>,
    /// Every user function block type, in file order.
    pub types: Vec<super::types::FbType>,
}

/// One instance of a user function block type and the POU it was expanded into.
#[derive(Clone, Debug)]
pub struct FbInstance {
    /// `G1`, `SBR:G1` (declared in a subroutine), `G1.INNER` (nested): also its POU's name.
    pub name: String,
    /// The function block type (its name and its index).
    pub fb: String,
    pub ty: super::types::FbTypeId,
    pub pou: PouId,
    /// Its input and output variables by pin name, in declaration order.
    pub inputs: Vec<(String, VarId)>,
    pub outputs: Vec<(String, VarId)>,
}

/// What an FBD body belongs to.
#[derive(Copy, Clone, Debug, PartialEq, Eq)]
pub enum FbdPouKind {
    Main,
    Subroutine,
    FunctionBlock,
}

impl FbdPouKind {
    pub fn name(self) -> &'static str {
        match self {
            FbdPouKind::Main => "program",
            FbdPouKind::Subroutine => "subroutine",
            FbdPouKind::FunctionBlock => "function block",
        }
    }
}

/// One FBD body with the plan of each network and where the lowered program holds it.
#[derive(Clone, Debug)]
pub struct FbdPou {
    /// The program, subroutine or function block type name.
    pub name: String,
    pub kind: FbdPouKind,
    /// JSON path of the `fbd` object.
    pub path: String,
    pub networks: Vec<Network>,
    /// Per network: its execution order and fragment tree.
    pub plans: Vec<Plan>,
    /// The lowered copies: one for the main program or a subroutine, one per instance of a
    /// function block type (none for a type nothing instantiates).
    pub copies: Vec<LoweredCopy>,
}

/// Where one copy of an FBD body is in the lowered [`plc_model::Program`].
#[derive(Clone, Debug)]
pub struct LoweredCopy {
    /// The POU that holds it (the instance's POU for a function block).
    pub pou: PouId,
    /// Per network: its rungs (contiguous).
    pub networks: Vec<Range<u32>>,
    /// Per network, per block: the rung the block became.
    pub blocks: Vec<Vec<RungId>>,
}

/// One network: blocks joined by arcs; evaluated as one unit of the POU's body.
#[derive(Clone, Debug)]
pub struct Network {
    pub id: String,
    /// Jump target name (unique in the POU).
    pub label: Option<String>,
    pub comment: Option<String>,
    /// JSON path of the network.
    pub path: String,
    /// Where the network starts in the program's text.
    pub origin: plc_diag::Origin,
    /// Sorted by [`Block::id`].
    pub blocks: Arena<BlockId, Block>,
    /// The blocks the depth-first order starts from first, in this order (Beremiz's statement
    /// order of a PLCopen body); empty: by id.
    pub roots: Vec<BlockId>,
}

impl Network {
    pub fn block(&self, b: BlockId) -> &Block {
        &self.blocks[b.index()]
    }
    /// The block with user id `id`.
    pub fn find(&self, id: u32) -> Option<BlockId> {
        self.blocks
            .binary_search_by_key(&id, |b| b.id)
            .ok()
            .map(|i| BlockId::new(i as u32))
    }
    /// Every block `b` depends on (data and conditional arcs, control arcs), sorted, no duplicates.
    pub fn predecessors(&self, b: BlockId) -> Vec<BlockId> {
        let blk = self.block(b);
        let mut p: Vec<BlockId> = blk.arc_sources().chain(blk.after.iter().copied()).collect();
        p.sort_unstable();
        p.dedup();
        p
    }
}

/// A block: an operator, function, standard or user function block, or a control block.
#[derive(Clone, Debug)]
pub struct Block {
    /// The user's id (an execution number of an FBD editor), unique in its POU.
    pub id: u32,
    /// The operation, with what only it has (a timer's instance, a JMP's label, …).
    pub op: Op,
    /// JSON path of the block.
    pub path: String,
    /// Where the block starts in the program's text.
    pub origin: plc_diag::Origin,
    /// One entry per input pin of the op.
    pub inputs: Vec<InputPin>,
    /// One entry per output pin.
    pub outputs: Vec<OutputPin>,
    /// The conditional arc into the control input (for JMP and RET: their condition).
    pub cond: Option<Input>,
    /// `cond` is the IEC 61131-3 EN input (2.5.1.2): when it is FALSE this block alone does not
    /// run (a function's arc outputs read its type's initial value, as matiec's `TEST_EN`
    /// returns it; a function block keeps its outputs), and the blocks it feeds still run. It
    /// opens no fragment.
    pub en: bool,
    /// Control arcs from these blocks' control outputs (sorted, no duplicates).
    pub after: Vec<BlockId>,
    pub comment: Option<String>,
}

impl Block {
    /// The blocks whose outputs feed this block's inputs or its control input (with repeats).
    pub fn arc_sources(&self) -> impl Iterator<Item = BlockId> + '_ {
        self.inputs
            .iter()
            .filter_map(|p| p.input.as_ref())
            .chain(self.cond.as_ref())
            .filter_map(Input::source)
    }
    /// True when `cond` is the block's own condition (JMP, RET) rather than a conditional arc
    /// that opens a fragment.
    pub fn cond_is_own(&self) -> bool {
        matches!(self.op, Op::Jmp { .. } | Op::Ret)
    }
    /// True when `cond` is a conditional arc that opens a fragment: neither the block's own
    /// condition (JMP, RET) nor its EN.
    pub fn cond_opens_fragment(&self) -> bool {
        self.cond.is_some() && !self.en && !self.cond_is_own()
    }
    /// The index of output pin `name`.
    pub fn output_pin(&self, name: &str) -> Option<u32> {
        self.outputs
            .iter()
            .position(|p| p.name == name)
            .map(|i| i as u32)
    }
}

/// An input pin and what is connected to it.
#[derive(Clone, Debug, PartialEq)]
pub struct InputPin {
    pub name: String,
    /// `None`: unconnected (allowed for inputs of user function blocks: they keep their value).
    pub input: Option<Input>,
    /// JSON path of the connection (or of the block's `in`).
    pub path: String,
}

/// An output pin and the variables it is written to (with their JSON paths).
#[derive(Clone, Debug, PartialEq)]
pub struct OutputPin {
    pub name: String,
    pub vars: Vec<(String, String)>,
}

/// What is connected to an input pin or to the control input. Names and constants stay as
/// written: a function block type's body is resolved once per instance.
#[derive(Clone, Debug, PartialEq)]
pub enum Input {
    /// A variable, a field (`T1.Q`) or a member of a user instance (`G1.RESULT`), by name.
    Variable(String),
    /// A constant, typed by the block that reads it.
    Constant(Constant),
    /// A data arc from output pin `pin` of block `from`.
    Arc { from: BlockId, pin: u32 },
}

impl Input {
    pub fn source(&self) -> Option<BlockId> {
        match self {
            Input::Arc { from, .. } => Some(*from),
            Input::Variable(_) | Input::Constant(_) => None,
        }
    }
}

/// A constant as written, before the block that reads it gives it a type.
#[derive(Clone, Debug, PartialEq)]
pub enum Constant {
    Bool(bool),
    Number(serde_json::Number),
    /// A TIME literal (`T#1s`), checked when it is typed.
    Time(String),
}

impl Constant {
    /// The constant as messages and fragment names quote it (`T#1s`, `10`, `true`).
    pub fn text(&self) -> String {
        match self {
            Constant::Bool(b) => b.to_string(),
            Constant::Number(n) => n.to_string(),
            Constant::Time(s) => s.clone(),
        }
    }

    /// The constant's kind, as messages name a JSON value's (`boolean true`, `number 5`).
    pub fn kind(&self) -> String {
        match self {
            Constant::Bool(b) => format!("boolean {b}"),
            Constant::Number(n) => format!("number {n}"),
            Constant::Time(s) => format!("string \"{s}\""),
        }
    }
}

/// The kind of an operation, without its data: what pins and messages depend on.
#[derive(Copy, Clone, Debug, PartialEq, Eq)]
pub enum OpKind {
    Compare(CmpOp),
    Arith(ArithOp),
    And,
    Or,
    Xor,
    Not,
    Move,
    Sel,
    Max,
    Min,
    Limit,
    Timer(TimerKind),
    Ctu,
    Ctd,
    Bistable(BistableKind),
    Trigger(TriggerKind),
    Ctud,
    Jmp,
    Ret,
    TStart,
    TStop,
    /// A user function block type (its pins are the type's).
    Call,
    /// A standard function (`plc_model::Function`).
    Function(Function),
}

/// The operation of a block, with the data only it has.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum Op {
    /// EQ NE LT LE GT GE on two numeric inputs; output BOOL.
    Compare(CmpOp),
    /// ADD SUB MUL DIV MOD (ADD and MUL take two or more inputs).
    Arith(ArithOp),
    /// AND, OR, XOR on two or more BOOLs; NOT on one.
    And,
    Or,
    Xor,
    Not,
    Move,
    /// SEL(G, IN0, IN1): IN1 when G, else IN0.
    Sel,
    /// MAX, MIN of two or more numeric inputs.
    Max,
    Min,
    /// LIMIT(MN, IN, MX).
    Limit,
    /// TON TOF TP on `instance`: inputs IN, PT; outputs Q, ET.
    Timer {
        kind: TimerKind,
        instance: String,
    },
    /// CTU (CU, R, PV) on `instance`; outputs Q, CV.
    Ctu {
        instance: String,
    },
    /// CTD (CD, LD, PV) on `instance`; outputs Q, CV.
    Ctd {
        instance: String,
    },
    /// SR (S1, R) or RS (S, R1) on `instance`; output Q1.
    Bistable {
        kind: BistableKind,
        instance: String,
    },
    /// R_TRIG or F_TRIG (CLK) on `instance`; output Q.
    Trigger {
        kind: TriggerKind,
        instance: String,
    },
    /// CTUD (CU, CD, R, LD, PV) on `instance`; outputs QU, QD, CV.
    Ctud {
        instance: String,
    },
    /// Jump to the network labelled `label` when `cond` holds (always without `cond`).
    Jmp {
        label: String,
    },
    /// Return from the POU when `cond` holds (always without `cond`).
    Ret,
    /// Start / stop accumulating elapsed time in a TIME variable (KASKAD's TIMER_CONTROL).
    TStart,
    TStop,
    /// A call of user function block type `fb` on `instance`.
    Call {
        fb: String,
        instance: String,
    },
    /// A standard function: ABS … ATAN, EXPT, SHL … ROR, MUX (`K, IN0, …`), `*_TO_*`, TRUNC.
    Function(Function),
}

/// The op names of the format, as the error message lists them.
pub use plc_diag::OP_NAMES;

impl OpKind {
    /// A built-in op by its name (user function blocks are resolved by the reader).
    pub fn parse(s: &str) -> Option<OpKind> {
        if let Some(c) = CmpOp::parse(s) {
            return Some(OpKind::Compare(c));
        }
        if let Some(a) = ArithOp::parse(s) {
            return Some(OpKind::Arith(a));
        }
        Some(match s {
            "AND" => OpKind::And,
            "OR" => OpKind::Or,
            "XOR" => OpKind::Xor,
            "NOT" => OpKind::Not,
            "MOVE" => OpKind::Move,
            "SEL" => OpKind::Sel,
            "MAX" => OpKind::Max,
            "MIN" => OpKind::Min,
            "LIMIT" => OpKind::Limit,
            "TON" => OpKind::Timer(TimerKind::Ton),
            "TOF" => OpKind::Timer(TimerKind::Tof),
            "TP" => OpKind::Timer(TimerKind::Tp),
            "CTU" => OpKind::Ctu,
            "CTD" => OpKind::Ctd,
            "SR" => OpKind::Bistable(BistableKind::SetDominant),
            "RS" => OpKind::Bistable(BistableKind::ResetDominant),
            "R_TRIG" => OpKind::Trigger(TriggerKind::Rising),
            "F_TRIG" => OpKind::Trigger(TriggerKind::Falling),
            "CTUD" => OpKind::Ctud,
            "JMP" => OpKind::Jmp,
            "RET" => OpKind::Ret,
            "TSTART" => OpKind::TStart,
            "TSTOP" => OpKind::TStop,
            _ => return Function::parse(s).map(OpKind::Function),
        })
    }

    /// The name of a built-in op (`None` for a call: its name is its type's).
    pub fn name(self) -> Option<&'static str> {
        Some(match self {
            OpKind::Compare(c) => c.name(),
            OpKind::Arith(a) => a.name(),
            OpKind::And => "AND",
            OpKind::Or => "OR",
            OpKind::Xor => "XOR",
            OpKind::Not => "NOT",
            OpKind::Move => "MOVE",
            OpKind::Sel => "SEL",
            OpKind::Max => "MAX",
            OpKind::Min => "MIN",
            OpKind::Limit => "LIMIT",
            OpKind::Timer(TimerKind::Ton) => "TON",
            OpKind::Timer(TimerKind::Tof) => "TOF",
            OpKind::Timer(TimerKind::Tp) => "TP",
            OpKind::Ctu => "CTU",
            OpKind::Ctd => "CTD",
            OpKind::Bistable(BistableKind::SetDominant) => "SR",
            OpKind::Bistable(BistableKind::ResetDominant) => "RS",
            OpKind::Trigger(TriggerKind::Rising) => "R_TRIG",
            OpKind::Trigger(TriggerKind::Falling) => "F_TRIG",
            OpKind::Ctud => "CTUD",
            OpKind::Jmp => "JMP",
            OpKind::Ret => "RET",
            OpKind::TStart => "TSTART",
            OpKind::TStop => "TSTOP",
            OpKind::Call => return None,
            OpKind::Function(f) => f.static_name(),
        })
    }

    /// True for ops that take two or more inputs `IN1..INn` (the comparisons but NE too:
    /// `GT(IN1, IN2, IN3)` is `IN1 > IN2 AND IN2 > IN3`, IEC 61131-3 2.5.1.5.4).
    pub fn extensible(self) -> bool {
        matches!(
            self,
            OpKind::Arith(ArithOp::Add | ArithOp::Mul)
                | OpKind::Compare(CmpOp::Eq | CmpOp::Gt | CmpOp::Ge | CmpOp::Lt | CmpOp::Le)
                | OpKind::And
                | OpKind::Or
                | OpKind::Xor
                | OpKind::Max
                | OpKind::Min
        ) || matches!(self, OpKind::Function(f) if f.extensible() && f != Function::Mux)
    }

    /// Whether the op needs an `instance`.
    pub fn needs_instance(self) -> bool {
        matches!(
            self,
            OpKind::Timer(_)
                | OpKind::Ctu
                | OpKind::Ctd
                | OpKind::Bistable(_)
                | OpKind::Trigger(_)
                | OpKind::Ctud
                | OpKind::Call
        )
    }

    /// Input pin names of a built-in op given `n` positional inputs (extensible ops: `IN1..INn`).
    pub fn input_pins(self, n: usize) -> Vec<String> {
        let fixed: &[&str] = match self {
            _ if self.extensible() => return (1..=n.max(2)).map(|i| format!("IN{i}")).collect(),
            OpKind::Compare(_) | OpKind::Arith(ArithOp::Sub | ArithOp::Div | ArithOp::Mod) => {
                &["IN1", "IN2"]
            }
            OpKind::Not | OpKind::Move | OpKind::TStart | OpKind::TStop => &["IN"],
            OpKind::Sel => &["G", "IN0", "IN1"],
            OpKind::Limit => &["MN", "IN", "MX"],
            OpKind::Timer(_) => &["IN", "PT"],
            OpKind::Ctu => &["CU", "R", "PV"],
            OpKind::Ctd => &["CD", "LD", "PV"],
            OpKind::Bistable(BistableKind::SetDominant) => &["S1", "R"],
            OpKind::Bistable(BistableKind::ResetDominant) => &["S", "R1"],
            OpKind::Trigger(_) => &["CLK"],
            OpKind::Ctud => &["CU", "CD", "R", "LD", "PV"],
            OpKind::Function(f) => return f.input_names(n),
            OpKind::Jmp
            | OpKind::Ret
            | OpKind::Call
            | OpKind::Arith(_)
            | OpKind::And
            | OpKind::Or
            | OpKind::Xor
            | OpKind::Max
            | OpKind::Min => &[],
        };
        fixed.iter().map(|s| s.to_string()).collect()
    }

    /// Output pin names of a built-in op.
    pub fn output_pins(self) -> &'static [&'static str] {
        match self {
            OpKind::Timer(_) => &["Q", "ET"],
            OpKind::Ctu | OpKind::Ctd => &["Q", "CV"],
            OpKind::Bistable(_) => &["Q1"],
            OpKind::Trigger(_) => &["Q"],
            OpKind::Ctud => &["QU", "QD", "CV"],
            OpKind::Jmp | OpKind::Ret | OpKind::TStart | OpKind::TStop | OpKind::Call => &[],
            _ => &["OUT"],
        }
    }
}

impl Op {
    pub fn kind(&self) -> OpKind {
        match self {
            Op::Compare(c) => OpKind::Compare(*c),
            Op::Arith(a) => OpKind::Arith(*a),
            Op::And => OpKind::And,
            Op::Or => OpKind::Or,
            Op::Xor => OpKind::Xor,
            Op::Not => OpKind::Not,
            Op::Move => OpKind::Move,
            Op::Sel => OpKind::Sel,
            Op::Max => OpKind::Max,
            Op::Min => OpKind::Min,
            Op::Limit => OpKind::Limit,
            Op::Timer { kind, .. } => OpKind::Timer(*kind),
            Op::Ctu { .. } => OpKind::Ctu,
            Op::Ctd { .. } => OpKind::Ctd,
            Op::Bistable { kind, .. } => OpKind::Bistable(*kind),
            Op::Trigger { kind, .. } => OpKind::Trigger(*kind),
            Op::Ctud { .. } => OpKind::Ctud,
            Op::Jmp { .. } => OpKind::Jmp,
            Op::Ret => OpKind::Ret,
            Op::TStart => OpKind::TStart,
            Op::TStop => OpKind::TStop,
            Op::Call { .. } => OpKind::Call,
            Op::Function(f) => OpKind::Function(*f),
        }
    }

    /// The op's name as the file writes it (a call: its function block type).
    pub fn name(&self) -> &str {
        match self {
            Op::Call { fb, .. } => fb,
            other => other.kind().name().unwrap_or_default(),
        }
    }

    /// The instance a timer, counter or user function block runs on.
    pub fn instance(&self) -> Option<&str> {
        match self {
            Op::Timer { instance, .. }
            | Op::Ctu { instance }
            | Op::Ctd { instance }
            | Op::Bistable { instance, .. }
            | Op::Trigger { instance, .. }
            | Op::Ctud { instance }
            | Op::Call { instance, .. } => Some(instance),
            _ => None,
        }
    }
}

/// The execution order and conditional fragments of one network (the FBD text-generation paper).
#[derive(Clone, Debug)]
pub struct Plan {
    /// The depth-first topological order (before regrouping).
    pub topological: Vec<BlockId>,
    /// The execution order: the topological order regrouped so that every fragment is
    /// contiguous (a fragment's own blocks and its child fragments, each as early as its arcs
    /// allow).
    pub order: Vec<BlockId>,
    /// The fragment tree; `fragments[0]` is the root, the others in creation order.
    pub fragments: Arena<FragmentId, Fragment>,
    /// Per block: its fragment.
    pub fragment_of: Vec<FragmentId>,
    /// The nesting of the execution order: what the lowering turns into `if` blocks.
    pub steps: Vec<Step>,
}

impl Plan {
    /// The fragments in the order their bodies start in the execution order (the root first):
    /// a pre-order of the tree.
    pub fn fragment_order(&self) -> Vec<FragmentId> {
        std::iter::once(FragmentId(0))
            .chain(self.steps.iter().filter_map(|s| {
                if let Step::Enter(f) = s {
                    Some(*f)
                } else {
                    None
                }
            }))
            .collect()
    }
}

/// One step of the regrouped order.
#[derive(Copy, Clone, Debug, PartialEq, Eq)]
pub enum Step {
    /// A (non-root) fragment starts: its condition is tested here.
    Enter(FragmentId),
    Block(BlockId),
    /// The fragment ends.
    Leave(FragmentId),
}

/// A conditional fragment: blocks that run under one condition.
#[derive(Clone, Debug)]
pub struct Fragment {
    /// `root`, `F(3)` (conditional on block 3's output), `F(Var)` (on a variable), `FC`,
    /// `FC2`, … (compound control arcs).
    pub name: String,
    pub parent: Option<FragmentId>,
    pub depth: u32,
    pub kind: FragmentKind,
    /// Human-readable condition: `always`, `3.OUT`, `Var`, `F(3) OR F(4)`.
    pub condition: String,
    /// Its own blocks, in execution order.
    pub blocks: Vec<BlockId>,
}

/// How a fragment's condition is formed.
#[derive(Clone, Debug, PartialEq)]
pub enum FragmentKind {
    Root,
    /// A conditional arc (or variable) into the control inputs of its blocks.
    Conditional(Input),
    /// A compound control arc: runs when at least one of these fragments ran.
    Compound(Vec<FragmentId>),
}
