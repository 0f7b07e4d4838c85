//! The FBD model: networks of blocks joined by arcs, as read from the program file (before any
//! name is resolved), and the plan of each network (execution order and conditional fragments).
//!
//! Blocks of a network live in a dense `Vec` sorted by their user id and are addressed by
//! [`BlockId`] (the index), so "ties by block id" is "ties by index". Operands are kept as the JSON
//! the file wrote: a function block type's body is read once and resolved once per instance.

use crate::model::{ArithOp, CmpOp, PouId, RungId, TimerKind, VarId};
use std::ops::Range;

use crate::model::index_type;

index_type!(
    /// A block of one network: index into [`Network::blocks`] (blocks sorted by id).
    BlockId
);
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
}

/// One instance of a user function block type and the POU it was expanded into.
#[derive(Clone, Debug)]
pub struct FbInstance {
    /// `G1`, `SBR:G1` (declared in a subroutine), `G1.INNER` (nested): also its POU's name.
    pub name: String,
    /// The function block type.
    pub fb: String,
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

/// Where one copy of an FBD body is in the lowered [`crate::model::Program`].
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
    /// Sorted by [`Block::id`].
    pub blocks: Vec<Block>,
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
            .map(|i| BlockId(i as u32))
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
    pub op: Op,
    /// JSON path of the block.
    pub path: String,
    /// One entry per input pin of the op.
    pub inputs: Vec<InputPin>,
    /// One entry per output pin.
    pub outputs: Vec<OutputPin>,
    /// The instance a timer, counter or user function block runs on.
    pub instance: Option<String>,
    /// The jump target of a JMP.
    pub label: Option<String>,
    /// The conditional arc into the control input (for JMP and RET: their condition).
    pub cond: Option<Input>,
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
        matches!(self.op, Op::Jmp | Op::Ret)
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

/// What is connected to an input pin or to the control input.
#[derive(Clone, Debug, PartialEq)]
pub enum Input {
    /// An OPERAND as in ladder (variable or field name, number, boolean, TIME literal).
    Operand(serde_json::Value),
    /// A data arc from output pin `pin` of block `from`.
    Arc { from: BlockId, pin: u32 },
}

impl Input {
    pub fn source(&self) -> Option<BlockId> {
        match self {
            Input::Arc { from, .. } => Some(*from),
            Input::Operand(_) => None,
        }
    }
}

/// The operation of a block.
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
    /// TON TOF TP on an instance: inputs IN, PT; outputs Q, ET.
    Timer(TimerKind),
    /// CTU (CU, R, PV) and CTD (CD, LD, PV) on an instance; outputs Q, CV.
    Ctu,
    Ctd,
    /// Jump to the network labelled `label` when `cond` holds (always without `cond`).
    Jmp,
    /// Return from the POU when `cond` holds (always without `cond`).
    Ret,
    /// Start / stop accumulating elapsed time in a TIME variable (KASKAD's TIMER_CONTROL).
    TStart,
    TStop,
    /// A call of a user function block type (with an instance of it).
    Call(String),
}

/// The op names of the format, as the error message lists them.
pub use crate::diag::OP_NAMES;

impl Op {
    /// A built-in op by its name (user function blocks are resolved by the reader).
    pub fn parse(s: &str) -> Option<Op> {
        if let Some(c) = CmpOp::parse(s) {
            return Some(Op::Compare(c));
        }
        if let Some(a) = ArithOp::parse(s) {
            return Some(Op::Arith(a));
        }
        Some(match s {
            "AND" => Op::And,
            "OR" => Op::Or,
            "XOR" => Op::Xor,
            "NOT" => Op::Not,
            "MOVE" => Op::Move,
            "SEL" => Op::Sel,
            "MAX" => Op::Max,
            "MIN" => Op::Min,
            "LIMIT" => Op::Limit,
            "TON" => Op::Timer(TimerKind::Ton),
            "TOF" => Op::Timer(TimerKind::Tof),
            "TP" => Op::Timer(TimerKind::Tp),
            "CTU" => Op::Ctu,
            "CTD" => Op::Ctd,
            "JMP" => Op::Jmp,
            "RET" => Op::Ret,
            "TSTART" => Op::TStart,
            "TSTOP" => Op::TStop,
            _ => return None,
        })
    }

    pub fn name(&self) -> &str {
        match self {
            Op::Compare(c) => c.name(),
            Op::Arith(a) => a.name(),
            Op::And => "AND",
            Op::Or => "OR",
            Op::Xor => "XOR",
            Op::Not => "NOT",
            Op::Move => "MOVE",
            Op::Sel => "SEL",
            Op::Max => "MAX",
            Op::Min => "MIN",
            Op::Limit => "LIMIT",
            Op::Timer(TimerKind::Ton) => "TON",
            Op::Timer(TimerKind::Tof) => "TOF",
            Op::Timer(TimerKind::Tp) => "TP",
            Op::Ctu => "CTU",
            Op::Ctd => "CTD",
            Op::Jmp => "JMP",
            Op::Ret => "RET",
            Op::TStart => "TSTART",
            Op::TStop => "TSTOP",
            Op::Call(fb) => fb,
        }
    }

    /// True for ops that take two or more inputs `IN1..INn`.
    pub fn extensible(&self) -> bool {
        matches!(
            self,
            Op::Arith(ArithOp::Add | ArithOp::Mul) | Op::And | Op::Or | Op::Xor | Op::Max | Op::Min
        )
    }

    /// Whether the op needs an `instance`.
    pub fn needs_instance(&self) -> bool {
        matches!(self, Op::Timer(_) | Op::Ctu | Op::Ctd | Op::Call(_))
    }

    /// Input pin names of a built-in op given `n` positional inputs (extensible ops: `IN1..INn`).
    pub fn input_pins(&self, n: usize) -> Vec<String> {
        let fixed: &[&str] = match self {
            Op::Compare(_) | Op::Arith(ArithOp::Sub | ArithOp::Div | ArithOp::Mod) => {
                &["IN1", "IN2"]
            }
            _ if self.extensible() => return (1..=n.max(2)).map(|i| format!("IN{i}")).collect(),
            Op::Not | Op::Move | Op::TStart | Op::TStop => &["IN"],
            Op::Sel => &["G", "IN0", "IN1"],
            Op::Limit => &["MN", "IN", "MX"],
            Op::Timer(_) => &["IN", "PT"],
            Op::Ctu => &["CU", "R", "PV"],
            Op::Ctd => &["CD", "LD", "PV"],
            Op::Jmp
            | Op::Ret
            | Op::Call(_)
            | Op::Arith(_)
            | Op::And
            | Op::Or
            | Op::Xor
            | Op::Max
            | Op::Min => &[],
        };
        fixed.iter().map(|s| s.to_string()).collect()
    }

    /// Output pin names of a built-in op.
    pub fn output_pins(&self) -> &'static [&'static str] {
        match self {
            Op::Timer(_) => &["Q", "ET"],
            Op::Ctu | Op::Ctd => &["Q", "CV"],
            Op::Jmp | Op::Ret | Op::TStart | Op::TStop | Op::Call(_) => &[],
            _ => &["OUT"],
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
    pub fragments: Vec<Fragment>,
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
