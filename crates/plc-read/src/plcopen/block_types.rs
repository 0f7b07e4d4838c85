//! The signatures a body's blocks are typed against, as plain data: the pins of a black box
//! ([`Sig`]), the stand-in function block types the reader made ([`BlackBox`], gathered in
//! `Notes::black_boxes`) and what a body's blocks may call ([`Ctx`]).
//!
//! Data only, below every reader of bodies and below `xml` (whose notes carry the black
//! boxes); how a block gets its signature and becomes a stand-in is `black_box`'s.

use plc_diag::Origin;
use std::collections::HashMap;

/// The pins of a black box: (name, model type) of its inputs and outputs.
#[derive(Clone, Debug, PartialEq)]
pub struct Sig {
    pub inputs: Vec<(String, String)>,
    pub outputs: Vec<(String, String)>,
}

/// A stand-in function block type the reader made, and the blocks that call it.
#[derive(Clone, Debug)]
pub struct BlackBox {
    pub name: String,
    pub op: String,
    pub sig: Sig,
    pub origin: Origin,
    pub sites: Vec<String>,
    /// Outputs whose type nothing tells (nothing reads them, or what reads them has no type),
    /// read as BOOL ([`super::black_box`]).
    pub guessed: Vec<String>,
}

/// What a body's blocks may call, and the types of the names it sees.
#[derive(Default)]
pub(super) struct Ctx {
    /// User functions of the project by name: their pins (the result is `OUT`).
    pub functions: HashMap<String, Sig>,
    /// Function block types the model has or the project defines, with their outputs' types.
    pub fbs: HashMap<String, Vec<(String, String)>>,
    /// The input pins' types of the function block types of the project and the library.
    pub fb_inputs: HashMap<String, Vec<(String, String)>>,
    /// The POU's variables and the globals it sees: lower-case name → model type.
    pub vars: HashMap<String, String>,
    /// The initial values of the POU's function block instances: lower-case instance name →
    /// (member as written, its literal) (`super::interface::FbInit`).
    pub inits: Inits,
    /// The project's functions whose calls are executed (lower-case name → name as declared):
    /// a block calling one calls its body ([`super::user_functions`]), not a black box.
    pub executed_functions: HashMap<String, String>,
}

/// The initial values of a POU's function block instances: lower-case instance name →
/// (member as written, its literal, where).
pub(super) type Inits = HashMap<String, Vec<(String, plc_syntax::Scalar<'static>, Origin)>>;

impl Ctx {
    /// The initial value instance `inst` declares for its input `pin` (matched
    /// in any case, as IEC names are), if it declares one.
    pub(super) fn init_of(
        &self,
        inst: &str,
        pin: &str,
    ) -> Option<(plc_syntax::Scalar<'static>, Origin)> {
        let members = self.inits.get(&inst.to_ascii_lowercase())?;
        members
            .iter()
            .find(|(m, _, _)| m.eq_ignore_ascii_case(pin))
            .map(|(_, v, at)| (v.clone(), *at))
    }
}
