//! User function block types as the resolved program keeps them (IEC 61131-3 6.6.3): each
//! type's interface — inputs, outputs, own variables, nested instances of other types — and its
//! body, for an FBD body also in a *typed* form whose pins are arcs, variables of the type (or
//! of the program) and typed constants. A generator that emits one function per type (C), or
//! walks a type's networks into instruction list, starts here; the analyses and the executor
//! keep using the lowering, which expands every instance into its own POU
//! ([`super::FbInstance`]).
//!
//! Invariants: [`FbTypeId`] indexes [`super::Fbd::types`] (file order); a [`TypedBody`] has one
//! [`TypedNetwork`] per network of the type's [`super::FbdPou`] and one [`TypedBlock`] per block,
//! both by the same indices ([`BlockId`]); a typed block has one entry per input and output pin.
//!
//! Deliberately not here: a typed form for a type that nothing instantiates (its operands are
//! resolved per instance only: `body` says so with `typed: None`), and ladder bodies in typed
//! form (they are kept as rungs per instance).

use super::ids::BlockId;
use plc_model::{index_type, Field, Type, Value, VarId};

index_type!(
    /// A user function block type: index into [`super::Fbd::types`].
    FbTypeId
);

/// A user function block type.
#[derive(Clone, Debug, PartialEq)]
pub struct FbType {
    pub name: String,
    /// Declared `inputs`, in order.
    pub inputs: Vec<FbVar>,
    /// Declared `outputs`, in order.
    pub outputs: Vec<FbVar>,
    /// Own variables of `vars` that are not user instances (elementary, timers, counters).
    pub locals: Vec<FbVar>,
    /// Own variables of `vars` that are instances of user function block types.
    pub nested: Vec<Nested>,
    pub body: FbTypeBody,
}

/// A variable of a function block type's interface.
#[derive(Clone, Debug, PartialEq)]
pub struct FbVar {
    pub name: String,
    pub ty: Type,
    pub init: Value,
}

/// An instance of another user type inside a type.
#[derive(Clone, Debug, PartialEq)]
pub struct Nested {
    pub name: String,
    pub ty: FbTypeId,
}

/// The body of a function block type.
#[derive(Clone, Debug, PartialEq)]
pub enum FbTypeBody {
    /// FBD: `pou` indexes [`super::Fbd::pous`]; `typed` is its typed form (`None` when no
    /// instance of the type exists).
    Fbd {
        pou: usize,
        typed: Option<TypedBody>,
    },
    /// Ladder rungs (lowered per instance).
    Ladder,
}

/// An FBD body with typed pins; `V` is how variables are named (a type's own by default).
#[derive(Clone, Debug, PartialEq)]
pub struct TypedBody<V = TypedRef> {
    pub networks: Vec<TypedNetwork<V>>,
}

/// The typed blocks of one network, by [`BlockId`].
#[derive(Clone, Debug, PartialEq)]
pub struct TypedNetwork<V = TypedRef> {
    pub blocks: Vec<TypedBlock<V>>,
}

/// A block's pins, typed.
#[derive(Clone, Debug, PartialEq)]
pub struct TypedBlock<V = TypedRef> {
    /// Per input pin: what is connected (`None`: unconnected, keeps its value).
    pub inputs: Vec<Option<Pin<V>>>,
    /// The conditional arc (a JMP's or RET's own condition), BOOL.
    pub cond: Option<Pin<V>>,
    /// Per output pin: the variables it writes.
    pub outputs: Vec<Vec<V>>,
}

/// What an input pin reads.
#[derive(Clone, Debug, PartialEq)]
pub enum Pin<V = TypedRef> {
    /// Output `output` of block `block` of the same network.
    Arc {
        block: BlockId,
        output: u32,
    },
    Variable(V),
    /// A constant with the type the block gave it.
    Constant(Value),
}

/// A variable (or a timer's or counter's field) as a function block type's body names it.
#[derive(Copy, Clone, Debug, PartialEq, Eq)]
pub struct TypedRef {
    pub var: TypedVar,
    pub field: Option<Field>,
}

/// Whose variable a body names.
#[derive(Copy, Clone, Debug, PartialEq, Eq)]
pub enum TypedVar {
    /// The type's own input, output or local (index into [`FbType::inputs`], `outputs`,
    /// `locals`).
    Own(Slot),
    /// An input or output (`slot`, in the nested type's interface) of nested instance `nested`
    /// (index into [`FbType::nested`]).
    Member { nested: u32, slot: Slot },
    /// A program variable.
    Global(VarId),
}

/// A place in a type's interface.
#[derive(Copy, Clone, Debug, PartialEq, Eq)]
pub enum Slot {
    Input(u32),
    Output(u32),
    Local(u32),
}
