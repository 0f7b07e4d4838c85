//! FBD bodies as written (IEC 61131-3 8.3, function block diagrams; the extended dialect of the
//! FBD text-generation paper): networks of blocks, each block with its op, its input pins
//! (connected to an arc from another block's output, a variable, or a constant), the variables
//! its output pins write, its conditional arc (`cond`), its control arcs (`after`), a JMP's label,
//! the instance a timer, counter or user function block runs on, and comments.
//!
//! Format-neutral: the JSON reader (`plc_read::json`) fills these types today; a PLCopen XML
//! reader would fill the same ones (blocks with typed pins, arcs between block outputs and
//! inputs, in/out variables, jumps, labels, returns).
//!
//! Invariants: every network, block, input pin and output variable carries an [`Origin`]. What
//! the reader found malformed stays in the tree as a [`Problem`] *at the part it concerns* — a
//! field is `Err(problem)` ([`Read`]), an input is [`Connection::Invalid`] — with `at` relative to
//! the node that holds it (`.label`, `.in[1]`, `.from`), so that the resolver reports it exactly
//! where its rules would have stopped, and reading goes on after it.
//!
//! Deliberately not here: block ids are not checked for uniqueness, ops and arcs are not
//! resolved, names are not checked for spelling or resolved, pins are not counted (all of that
//! is `plc_resolve::fbd_read`'s).

pub use super::is_time_literal;
use super::{Origin, Problem, Scalar, Text};

/// A part as read: its value, or what is malformed in it (`at` relative to the node holding it).
pub type Read<T> = Result<T, Box<Problem>>;

/// An FBD body (`{"networks": [...], "comment": …}`).
#[derive(Clone, Debug)]
pub struct FbdBody<'a> {
    pub origin: Origin,
    pub comment: Option<Text<'a>>,
    pub networks: Vec<Network<'a>>,
    /// The body itself is malformed (not an object, an unknown field, no `networks` array).
    pub problem: Option<Box<Problem>>,
}

/// A network: blocks joined by arcs, evaluated as one unit of its POU.
#[derive(Clone, Debug)]
pub struct Network<'a> {
    pub origin: Origin,
    /// `Err`: the network is not an object, or its id is missing or malformed (a message about
    /// it cannot name the network).
    pub id: Read<Text<'a>>,
    /// The name that makes the network a jump target.
    pub label: Option<Read<Text<'a>>>,
    pub comment: Option<Read<Text<'a>>>,
    /// `Err`: missing, not an array, or empty.
    pub blocks: Read<Vec<Block<'a>>>,
    /// The blocks (by id) that the depth-first execution order starts from, in this order: each
    /// runs after the blocks it depends on and before later ones (Beremiz's statement order of
    /// a PLCopen body; the JSON key `order`). The other blocks follow by id.
    pub order: Option<Read<Vec<Read<u32>>>>,
    /// An unknown field.
    pub problem: Option<Box<Problem>>,
}

/// A block as written.
#[derive(Clone, Debug)]
pub struct Block<'a> {
    pub origin: Origin,
    /// The execution number; `Err`: the block is not an object, or its id is missing or not a
    /// whole number (a message about it cannot name the block).
    pub id: Read<u32>,
    /// The op's name (a built-in op or a user function block type).
    pub op: Read<Text<'a>>,
    pub inputs: Option<Read<Inputs<'a>>>,
    pub outputs: Option<Read<Outputs<'a>>>,
    /// The instance a timer, counter or user function block runs on.
    pub instance: Option<Read<Text<'a>>>,
    /// The network a JMP goes to.
    pub label: Option<Read<Text<'a>>>,
    /// The conditional arc into the control input (a JMP's or RET's own condition).
    pub cond: Option<Input<'a>>,
    /// `cond` is the block's IEC 61131-3 EN input (2.5.1.2, PLCopen and the JSON key `en`): it
    /// decides whether this block alone runs, and blocks fed by it run in every scan. Without
    /// it, `cond` is a conditional arc that opens a fragment (the FBD text-generation paper).
    pub en: bool,
    /// Control arcs: the ids of the blocks whose control outputs feed the control input.
    pub after: Option<Read<Vec<Read<u32>>>>,
    pub comment: Option<Read<Text<'a>>>,
    /// An unknown field.
    pub problem: Option<Box<Problem>>,
}

/// The connected inputs of a block.
#[derive(Clone, Debug)]
pub enum Inputs<'a> {
    /// By position.
    List(Vec<Input<'a>>),
    /// By pin name, in file order (a repeated name keeps its first place and its last value).
    Named(Vec<(Text<'a>, Input<'a>)>),
}

/// What is connected to one input pin (or to the control input).
#[derive(Clone, Debug)]
pub struct Input<'a> {
    pub origin: Origin,
    pub from: Connection<'a>,
}

/// The source of an input.
#[derive(Clone, Debug)]
pub enum Connection<'a> {
    /// A data arc from output `pin` (the first when `None`) of block `block` of the network.
    Arc {
        block: u32,
        pin: Option<Read<Text<'a>>>,
    },
    /// A variable, a field (`T1.Q`) or a member of an instance (`G1.RESULT`), by name.
    Variable(Text<'a>),
    /// A number, a boolean or a TIME literal (`T#1s`), as written.
    Constant(Scalar<'a>),
    /// Malformed (`at` relative to the input).
    Invalid(Box<Problem>),
}

/// The variables a block's outputs write.
#[derive(Clone, Debug)]
pub enum Outputs<'a> {
    /// One variable: the first output.
    First(OutVar<'a>),
    /// By output position (`Ok(None)`: the pin is skipped).
    List(Vec<Read<Option<OutVar<'a>>>>),
    /// By output pin name, in file order.
    Named(Vec<(Text<'a>, Read<Targets<'a>>)>),
}

/// The variables one named output pin writes.
#[derive(Clone, Debug)]
pub enum Targets<'a> {
    One(OutVar<'a>),
    Many(Vec<Read<OutVar<'a>>>),
}

/// A variable an output pin writes.
#[derive(Clone, Debug)]
pub struct OutVar<'a> {
    pub origin: Origin,
    pub name: Text<'a>,
}
