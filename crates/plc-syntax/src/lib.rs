//! The surface syntax: what a program file says, before any name is resolved.
//!
//! Plain, format-neutral types for IEC 61131-3 program organisation units (clause 6.6: the
//! program, function block types, subroutines called like functions), their variable
//! declarations (6.5), ladder rungs with their series/parallel element trees (clause 8.2, LD) and
//! FBD bodies (8.3, [`fbd`]) kept as written. A reader (today `plc_read::json`; a PLCopen XML or STL
//! reader would fill the same types) produces them; `plc_resolve` turns them into the model.
//!
//! Invariants: every string borrows from the source text where it can (`Cow`); every node that
//! an error can name (POU, variable and each of its fields, rung, its id, label and series, each
//! element and each of its operands, FBD body, each [`Problem`]) carries an [`Origin`] — a byte
//! offset, 4 bytes — from which line and column are computed only when an error is reported.
//! A node's JSON path is its position in this tree (`rungs[2].ld[1].or[0][0]` is rung 2, element
//! 1, branch 0, element 0): the resolver renders it from the indices it walks, only on error, so
//! a million rungs cost no path strings. What the reader found malformed stays in the tree as a
//! [`Problem`] (where, relative to the node, and what), so that errors come out in program order
//! with the rung id known, and reading goes on after the first one.
//!
//! Deliberately not here: name resolution, types of operands, structural rules (those are the
//! resolver's), and anything JSON-specific beyond [`Scalar`] (a leaf as written, for messages).
#![forbid(unsafe_code)]

pub mod fbd;
pub mod pipe;
pub mod select;

use plc_diag::Invalid;
use plc_model::{ArithOp, BistableKind, CmpOp, TimerKind, TriggerKind};
use std::borrow::Cow;

pub use fbd::FbdBody;

/// A string of the source text (borrowed unless it had escapes).
pub type Text<'a> = Cow<'a, str>;

pub use plc_diag::Origin;

/// Something the reader found malformed: where (a path suffix relative to the node that holds
/// it, e.g. `.negated`, `.in[1]`, or "" for the node itself; and the origin of the most precise
/// node: the value, or the key of an unknown field) and what.
#[derive(Clone, Debug, PartialEq)]
pub struct Problem {
    pub at: String,
    pub origin: Origin,
    pub kind: Invalid,
}

impl Problem {
    pub fn new(at: impl Into<String>, origin: Origin, kind: Invalid) -> Box<Problem> {
        Box::new(Problem {
            at: at.into(),
            origin,
            kind,
        })
    }
}

/// A leaf of the tree with the place it starts.
#[derive(Clone, Debug, PartialEq)]
pub struct Located<T> {
    pub value: T,
    pub origin: Origin,
}

/// A name as written (a variable, an instance, a label, a subroutine).
pub type Name<'a> = Located<Text<'a>>;
/// An operand as written (a name, a number, a boolean, a TIME literal, or anything found instead).
pub type Operand<'a> = Located<Scalar<'a>>;

impl<'a> Name<'a> {
    /// A name made up by a reader (no place in the file).
    pub fn empty() -> Name<'a> {
        Located {
            value: Cow::Borrowed(""),
            origin: Origin::NONE,
        }
    }

    pub fn as_str(&self) -> &str {
        &self.value
    }
}

/// A leaf value as the file wrote it: operands, initial values, and the "found …" of messages.
#[derive(Clone, Debug, PartialEq)]
pub enum Scalar<'a> {
    Null,
    Bool(bool),
    Number(serde_json::Number),
    Str(Text<'a>),
    /// An array or object where a leaf was expected (its contents are not kept).
    Array,
    Object,
}

impl Scalar<'_> {
    /// A short description of the value's kind, for messages (`number 5`, `an array`).
    pub fn kind(&self) -> String {
        match self {
            Scalar::Null => "null".into(),
            Scalar::Bool(b) => format!("boolean {b}"),
            Scalar::Number(n) => format!("number {n}"),
            Scalar::Str(s) => format!("string \"{s}\""),
            Scalar::Array => "an array".into(),
            Scalar::Object => "an object".into(),
        }
    }

    /// The value as messages quote an operand: strings bare, the rest as JSON.
    pub fn display(&self) -> String {
        match self {
            Scalar::Str(s) => s.to_string(),
            other => other.json(),
        }
    }

    /// The value as JSON text.
    pub fn json(&self) -> String {
        match self {
            Scalar::Null => "null".into(),
            Scalar::Bool(b) => b.to_string(),
            Scalar::Number(n) => n.to_string(),
            Scalar::Str(s) => serde_json::Value::String(s.to_string()).to_string(),
            Scalar::Array => "[…]".into(),
            Scalar::Object => "{…}".into(),
        }
    }

    pub fn as_str(&self) -> Option<&str> {
        match self {
            Scalar::Str(s) => Some(s),
            _ => None,
        }
    }

    pub fn into_owned(self) -> Scalar<'static> {
        match self {
            Scalar::Null => Scalar::Null,
            Scalar::Bool(b) => Scalar::Bool(b),
            Scalar::Number(n) => Scalar::Number(n),
            Scalar::Str(s) => Scalar::Str(Cow::Owned(s.into_owned())),
            Scalar::Array => Scalar::Array,
            Scalar::Object => Scalar::Object,
        }
    }
}

/// A whole program file.
#[derive(Clone, Debug, Default)]
pub struct Program<'a> {
    /// Where the program object starts.
    pub origin: Origin,
    pub name: Text<'a>,
    /// Where the name is written (none when a reader made it up or does not say).
    pub name_origin: Origin,
    pub comment: Option<Text<'a>>,
    /// The program-wide variables.
    pub vars: Vec<Var<'a>>,
    /// The main program's body (`None`: the file has none, a problem is recorded).
    pub body: Option<Body<'a>>,
    pub subroutines: Vec<Subroutine<'a>>,
    pub function_blocks: Vec<FunctionBlock<'a>>,
    /// The PLCopen configuration (tasks and program instances), carried to the model unchanged.
    pub configuration: Option<plc_model::Configuration>,
    /// The dialect of the file's toolchain (PLCopen: by its editor; JSON and STL: IEC).
    pub dialect: plc_model::Dialect,
    /// Problems of the program object itself and of its non-rung parts, with absolute paths.
    pub problems: Vec<Problem>,
    /// The bodies the reader did not read as logic (it wrote stand-in rungs for them), by the
    /// name of their POU (a program, or a function block type), in file order.
    pub skipped: Vec<SkippedBody>,
}

/// A POU body a reader could not read as executable logic (PLCopen ST, IL, SFC): it stands in
/// the program as rungs that read and write what the body does (the analyses see them), but
/// nothing executes it ([`plc_model::Pou::skipped`]).
#[derive(Clone, Debug, PartialEq)]
pub struct SkippedBody {
    /// The POU's name (a program's, or a function block type's).
    pub pou: String,
    /// `ST`, `IL`, `SFC`.
    pub language: String,
    /// Where the body starts.
    pub origin: Origin,
    /// What in the body is not executed and where, when the reader names it (an ST body it
    /// could not lower to rungs).
    pub why: Option<(Origin, String)>,
}

/// A POU's body: ladder rungs or an FBD body.
#[derive(Clone, Debug)]
pub enum Body<'a> {
    Rungs(Vec<Rung<'a>>),
    Fbd(FbdBody<'a>),
}

/// A subroutine (called by `call`; IEC 61131-3 would make it a function without result), or an
/// interrupt routine (S7-200 `INTERRUPT_BLOCK`), which nothing calls.
#[derive(Clone, Debug)]
pub struct Subroutine<'a> {
    pub origin: Origin,
    pub kind: RoutineKind,
    pub name: Text<'a>,
    pub vars: Vec<Var<'a>>,
    pub body: Option<Body<'a>>,
}

/// What kind of routine a [`Subroutine`] is.
#[derive(Copy, Clone, Debug, PartialEq, Eq)]
pub enum RoutineKind {
    /// Runs where a `call` calls it.
    Subroutine,
    /// Runs when its event occurs: between any two rungs of the scan (S7-200 `INT`/`RETI`).
    /// Nothing calls it.
    Interrupt,
}

/// A user function block type (IEC 61131-3 6.6.3): its interface, its own data and its body.
#[derive(Clone, Debug)]
pub struct FunctionBlock<'a> {
    pub origin: Origin,
    pub name: Text<'a>,
    pub inputs: Vec<Var<'a>>,
    pub outputs: Vec<Var<'a>>,
    pub vars: Vec<Var<'a>>,
    pub body: Option<Body<'a>>,
}

/// A variable declaration as written (the type is a name: resolved against the standard types and
/// the file's function block types).
#[derive(Clone, Debug)]
pub struct Var<'a> {
    pub origin: Origin,
    pub name: Name<'a>,
    pub ty: Name<'a>,
    /// The class, with the origin of its value (none when absent).
    pub class: Located<VarClass>,
    /// Boxed: most declarations have none, and a million of them are read.
    pub init: Option<Box<Operand<'a>>>,
    /// Something malformed in the declaration (then the fields may be defaults).
    pub problem: Option<Box<Problem>>,
}

/// The declared class of a variable (`class`); `Memory` when absent.
#[derive(Copy, Clone, Debug, PartialEq, Eq)]
pub enum VarClass {
    Input,
    Output,
    Memory,
    /// No `class` given.
    Default,
}

/// Takes the main program's rungs one at a time, as a reader reads them, so that the reader
/// need not hold them all: a million rungs as syntax cost more memory than their text, and
/// memory first touched is time. A reader offers the rungs only when it has read the program's
/// variables and nothing before the rung array was malformed; the sink then takes the
/// variables and every rung, and the tree gets none of them (no `vars`, an empty
/// `Body::Rungs`): whatever the sink does with them, the rest of the tree stays the
/// format-neutral description of the file. A sink that finds it cannot use what it took (a
/// declaration that does not resolve, say) must say so to its own caller, which then reads the
/// file again without a sink. Taking without answering lets the sink work on another thread
/// while the reader goes on ([`pipe`]).
pub trait RungSink<'a> {
    /// At the start of the main program's rung array, with the variables read before it and an
    /// estimate of the number of rungs (for sizing only).
    fn start(&mut self, vars: Vec<Var<'a>>, rungs: usize);
    /// The next rung of the main program, in file order (only after `start`).
    fn rung(&mut self, rung: Rung<'a>);
    /// What the sink took is not what the file means after all (the file repeats `vars`
    /// or `rungs` later, and the last one counts): the sink must not use it.
    fn retract(&mut self);
}

/// A ladder rung.
#[derive(Clone, Debug)]
pub struct Rung<'a> {
    pub origin: Origin,
    pub id: Name<'a>,
    /// Boxed: few rungs have one.
    pub label: Option<Box<Name<'a>>>,
    pub comment: Option<Text<'a>>,
    pub ld: Series<'a>,
    /// Where the series (`ld`) starts.
    pub ld_origin: Origin,
    /// Something malformed in the rung object; `problem_in_rung`: the message names the rung id.
    pub problem: Option<Box<Problem>>,
    pub problem_in_rung: bool,
}

/// A series of elements, power flowing left to right.
pub type Series<'a> = Vec<Element<'a>>;

/// A ladder element as written, with where its object starts.
#[derive(Clone, Debug)]
pub struct Element<'a> {
    pub origin: Origin,
    pub kind: ElementKind<'a>,
}

/// The kinds of ladder elements (IEC 61131-3 8.2: contacts, coils, function block and function
/// calls; the control elements of S7-200: jumps, return, end, calls, FOR/NEXT). Kinds with
/// several operands are boxed, so that the common contacts and coils stay small.
#[derive(Clone, Debug)]
pub enum ElementKind<'a> {
    Contact {
        var: Name<'a>,
        negated: bool,
        edge: Option<Edge>,
    },
    Compare(Box<Compare<'a>>),
    Or(Vec<Series<'a>>),
    Coil {
        var: Name<'a>,
        negated: bool,
    },
    Set(Name<'a>),
    Reset(Name<'a>),
    Branch(Vec<Series<'a>>),
    Timer(Box<Timer<'a>>),
    /// CTU (`load` false: `aux` is R) or CTD (`aux` is LD).
    Counter(Box<Counter<'a>>),
    /// SR or RS: power in is S1/S, `reset` R/R1.
    Bistable(Box<Bistable<'a>>),
    /// R_TRIG or F_TRIG: power in is CLK.
    Trigger {
        kind: TriggerKind,
        instance: Name<'a>,
    },
    /// CTUD: power in is CU.
    Ctud(Box<Ctud<'a>>),
    Move(Box<Move<'a>>),
    Arith(Box<Arith<'a>>),
    /// A standard function box (`"op"` naming a function).
    Function(Box<FunctionCall<'a>>),
    Jmp(Name<'a>),
    Ret,
    End,
    Call(Name<'a>),
    For(Box<For<'a>>),
    Next,
    /// `{"range_fault": true}`: when powered, records an `index-range` fault of the scan (an
    /// array subscript outside its bounds, as the PLCopen ST reader lowers it); power out =
    /// power in.
    RangeFault,
    /// The element is malformed (`at` is relative to the element).
    Invalid(Box<Problem>),
}

/// `{"compare": OP, "a": A, "b": B}`.
#[derive(Clone, Debug)]
pub struct Compare<'a> {
    pub op: CmpOp,
    pub a: Operand<'a>,
    pub b: Operand<'a>,
}

/// `{"ton": T, "pt": PT}` and TOF, TP.
#[derive(Clone, Debug)]
pub struct Timer<'a> {
    pub kind: TimerKind,
    pub instance: Name<'a>,
    pub pt: Operand<'a>,
}

/// `{"ctu": C, "pv": PV, "reset": R}` or `{"ctd": C, "pv": PV, "load": LD}`.
#[derive(Clone, Debug)]
pub struct Counter<'a> {
    pub down: bool,
    pub instance: Name<'a>,
    pub pv: Operand<'a>,
    /// R of a CTU, LD of a CTD.
    pub aux: Operand<'a>,
}

/// `{"sr": B, "reset": R}` or `{"rs": B, "reset": R1}`.
#[derive(Clone, Debug)]
pub struct Bistable<'a> {
    pub kind: BistableKind,
    pub instance: Name<'a>,
    pub reset: Operand<'a>,
}

/// `{"ctud": C, "cd": CD, "reset": R, "load": LD, "pv": PV}`.
#[derive(Clone, Debug)]
pub struct Ctud<'a> {
    pub instance: Name<'a>,
    pub cd: Operand<'a>,
    pub reset: Operand<'a>,
    pub load: Operand<'a>,
    pub pv: Operand<'a>,
}

/// `{"move": FROM, "to": TO}`.
#[derive(Clone, Debug)]
pub struct Move<'a> {
    pub from: Operand<'a>,
    pub to: Name<'a>,
}

/// `{"op": OP, "in": [A, B], "out": OUT}`.
#[derive(Clone, Debug)]
pub struct Arith<'a> {
    pub op: ArithOp,
    pub a: Operand<'a>,
    pub b: Operand<'a>,
    pub out: Name<'a>,
}

/// `{"op": FUNC, "in": [A, …], "out": OUT}` of a standard function (`SQRT`, `INT_TO_REAL`, …).
#[derive(Clone, Debug)]
pub struct FunctionCall<'a> {
    pub func: plc_model::Function,
    pub args: Vec<Operand<'a>>,
    pub out: Name<'a>,
}

/// `{"for": {"var": V, "from": A, "to": B}}`.
#[derive(Clone, Debug)]
pub struct For<'a> {
    pub var: Name<'a>,
    pub from: Operand<'a>,
    pub to: Operand<'a>,
}

/// The edge of an edge contact.
#[derive(Copy, Clone, Debug, PartialEq, Eq)]
pub enum Edge {
    Rising,
    Falling,
}

impl<'a> ElementKind<'a> {
    /// True for the conditions (allowed inside `or`).
    pub fn is_condition(&self) -> bool {
        matches!(
            self,
            ElementKind::Contact { .. } | ElementKind::Compare(_) | ElementKind::Or(_)
        )
    }
}

// The common nodes stay small: a million-rung program holds millions of them.
const _: () = assert!(std::mem::size_of::<Element>() <= 48);
const _: () = assert!(std::mem::size_of::<Rung>() <= 112);
const _: () = assert!(std::mem::size_of::<Var>() <= 96);

/// True when an operand string is a TIME literal rather than a name (the model's, which the
/// FBD lowering shares).
pub use plc_model::is_time_literal;
