//! The program model: one resolved, type-checked representation of a ladder program that every
//! analysis and every output works from.
//!
//! Readers (`plc_read`) and the resolver (`plc_resolve`) turn a file into a [`Program`]; nothing
//! downstream ever sees names that are not resolved. Invariants a `Program` always holds (the
//! resolver establishes them; [`Program::new`], its only constructor, checks the first and the
//! third, and its fields are private, so nothing downstream can break them):
//! - variables, rungs and POUs live in [`Arena`]s that hand out the opaque ids [`VarId`],
//!   [`RungId`] and [`PouId`] ([`arena`]); `pous[0]` is the main program; the rungs of a POU are
//!   a contiguous [`RungId`] range, POUs in file order (main first, then subroutines); every id
//!   an element names is one the program holds;
//! - every operand has a known IEC type and every element's operands have the types it needs;
//! - every `jmp` names a rung of the same POU, every FOR has its NEXT in the same POU (properly
//!   nested) and no jump enters a FOR body from outside it; no subroutine calls itself, directly or
//!   through others, and `end` appears only in the main program;
//! - each edge contact owns a hidden BOOL memory variable (named `R3:edge1`), so edge state is
//!   an ordinary variable for the analyses and the scan.
//!
//! It deliberately carries no analysis results: those are separate values computed from it.
//! Element semantics follow IEC 61131-3 (LD, §4.2) and the S7-200 shapes of Zhao & Yan (2012).
#![forbid(unsafe_code)]

pub mod arena;
mod dialect;
mod function;
mod strings;
mod tasks;
mod types;
pub use arena::{Arena, Idx, Numbering};
pub mod untyped;
pub use dialect::Dialect;
pub use function::*;
pub use strings::*;
pub use tasks::*;
pub use types::*;

use plc_diag::Origin;
use std::ops::Range;

index_type!(
    /// A variable: index into [`Program::vars`].
    VarId
);
index_type!(
    /// A rung of any POU: index into [`Program::rungs`], in listing order.
    RungId
);
index_type!(
    /// A program organisation unit: index into [`Program::pous`]; 0 is the main program.
    PouId
);

impl VarId {
    /// The same variable once the variables before it in its arena grew by `by` (a reader that
    /// numbers hidden variables while it reads and places them after the declarations at the
    /// end). [`Program::new`] checks that every variable id it is given names a variable.
    pub fn shifted(self, by: u32) -> VarId {
        VarId(self.0 + by)
    }
}

impl RungId {
    /// A POU-relative rung id (the `i`-th rung of a body lowered on its own) made absolute: the
    /// same rung once the body's rungs start at `start`.
    pub fn shifted(self, start: u32) -> RungId {
        RungId(self.0 + start)
    }
    /// The `i`-th rung of a body lowered on its own (an FBD body before it is placed in its
    /// POU): meaningful only once [`shifted`](RungId::shifted) to where the body starts.
    /// [`Program::new`] checks that every rung id it is given names a rung of its POU.
    pub fn relative(i: u32) -> RungId {
        RungId(i)
    }
}

/// A whole resolved program. Made only by [`Program::new`], which checks the invariants the
/// module documentation lists that concern ids and ranges; afterwards only its configuration,
/// dialect and skipped bodies can change, so nothing downstream can break them.
#[derive(Clone, Debug)]
pub struct Program {
    name: String,
    vars: Arena<VarId, Var>,
    pous: Arena<PouId, Pou>,
    rungs: Arena<RungId, Rung>,
    configuration: Option<Configuration>,
    dialect: Dialect,
    written_inputs: Vec<VarId>,
}

/// What a [`Program`] is made of, before [`Program::new`] checks it.
#[derive(Clone, Debug, Default)]
pub struct ProgramParts {
    pub name: String,
    pub vars: Arena<VarId, Var>,
    /// `pous[0]` is the main program; their rung ranges follow one another from 0 and cover
    /// every rung.
    pub pous: Arena<PouId, Pou>,
    pub rungs: Arena<RungId, Rung>,
    /// The PLCopen configuration that runs the program's POUs (tasks and program instances);
    /// `None` for programs without one (JSON, STL, a project without instances).
    pub configuration: Option<Configuration>,
    /// Whose rules `run` and `c` follow where toolchains differ (docs/dialects.md): the
    /// reader's choice by the file's editor, or the command line's `--dialect`.
    pub dialect: Dialect,
    /// The input variables the program itself writes (a coil, set/reset, move or block output
    /// on an input, which matiec accepts): the scan copies the input image into them before
    /// every scan, as the Beremiz/OpenPLC runtime copies its input image into the located `%I`
    /// variables (docs/scan.md; warning W0208). An instance's inputs, which its calls set, are
    /// not among them. Any order; [`Program::new`] sorts them.
    pub written_inputs: Vec<VarId>,
}

/// The main program or one subroutine.
#[derive(Clone, Debug)]
pub struct Pou {
    pub name: String,
    pub kind: PouKind,
    /// The POU's rungs, contiguous in [`Program::rungs`].
    pub rungs: Range<u32>,
    /// `Some` when the POU's body was not read as logic (a PLCopen ST, IL or SFC body): its
    /// rungs are stand-ins that read and write what the body does, for the analyses, and keep
    /// every value when run. `run` and `c` refuse such a POU unless told to skip it.
    pub skipped: Option<Box<SkippedBody>>,
}

impl Pou {
    /// The POU's rung ids, in program order.
    pub fn rung_ids(&self) -> impl DoubleEndedIterator<Item = RungId> + ExactSizeIterator {
        self.rungs.clone().map(RungId)
    }
}

/// A POU body that no command executes (see [`Pou::skipped`]).
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct SkippedBody {
    /// The body's language as the file names it (`ST`, `IL`, `SFC`).
    pub language: String,
    /// Line and column (1-based) of the body in the program file.
    pub position: Option<(u32, u32)>,
    /// What in the body is not executed, with its line and column (`the call of function
    /// \`F\` at 12:3`), when the reader names one (an ST body it could not lower).
    pub why: Option<String>,
}

#[derive(Copy, Clone, Debug, PartialEq, Eq)]
pub enum PouKind {
    Main,
    Subroutine,
    /// An interrupt routine: nothing calls it; it runs when its event occurs, which may be
    /// between any two rungs of the scan. `plc-deps run` raises no interrupt events.
    Interrupt,
}

/// A declared (or hidden) variable.
#[derive(Clone, Debug)]
pub struct Var {
    /// Display name: the declared name for globals, `SBR_0:name` for subroutine locals,
    /// `R3:edge1` for the hidden memory of an edge contact.
    pub name: String,
    pub ty: Type,
    pub class: VarClass,
    pub init: Value,
    /// The subroutine that declared it, `None` for program-wide variables.
    pub scope: Option<PouId>,
    /// True for variables the reader made up (edge memories).
    pub hidden: bool,
}

#[derive(Copy, Clone, Debug, PartialEq, Eq)]
pub enum VarClass {
    Input,
    Output,
    Memory,
}

/// One rung: a series of elements through which power flows left to right.
#[derive(Clone, Debug)]
pub struct Rung {
    pub id: String,
    pub label: Option<String>,
    pub comment: Option<String>,
    pub pou: PouId,
    pub series: Series,
    /// For a rung lowered from an FBD block (or a fragment guard of it): what it was lowered
    /// from. Ladder rungs have none (and pay one pointer for it): the resolver renders their
    /// path (`rungs[3]`) from where they are, only when an error names them.
    pub lowered: Option<Box<LoweredFrom>>,
    /// Where the rung starts in the program's text (for a rung lowered from FBD: its block, or
    /// its network for a fragment's guard and landing); none for a rung the tool made up. It
    /// places the analysis warnings about the rung.
    pub origin: Origin,
}

/// Where a rung lowered from an FBD body comes from.
#[derive(Clone, Debug)]
pub struct LoweredFrom {
    /// The path of the block it was lowered from (`fbd.networks[0].blocks[2]`).
    pub block_path: String,
    /// The id of its network, once the network is lowered. The rungs of one network are
    /// contiguous.
    pub network: Option<String>,
}

impl Rung {
    /// For a rung lowered from an FBD block: the path of that block.
    pub fn block_path(&self) -> Option<&str> {
        self.lowered.as_ref().map(|l| l.block_path.as_str())
    }
    /// For a rung lowered from an FBD network: the network's id.
    pub fn network(&self) -> Option<&str> {
        self.lowered.as_ref().and_then(|l| l.network.as_deref())
    }
}

/// A series of elements; power flows through them in order.
pub type Series = Vec<Element>;

/// A ladder element after resolution.
#[derive(Clone, Debug)]
pub enum Element {
    /// A contact on a BOOL (variable or field).
    Contact { var: VarRef, kind: ContactKind },
    /// A comparison of two numeric operands of the same type; passes power when true.
    Compare { op: CmpOp, a: Operand, b: Operand },
    /// Parallel condition branches: power out is the OR of each branch's power out.
    Or(Vec<Series>),
    /// Output coil: writes the power (or its negation) to a BOOL.
    Coil { var: VarId, negated: bool },
    /// Set coil: writes TRUE when powered.
    Set(VarId),
    /// Reset coil: writes FALSE when powered.
    Reset(VarId),
    /// Output branches: each series receives the same power (LPS/LRD/LPP); power out is unchanged.
    Branch(Vec<Series>),
    /// TON/TOF/TP instance call; power in is IN, power out is Q.
    Timer {
        kind: TimerKind,
        instance: VarId,
        pt: Operand,
    },
    /// Up counter; power in is CU, power out is Q.
    Ctu {
        instance: VarId,
        pv: Operand,
        reset: Operand,
    },
    /// Down counter; power in is CD, power out is Q.
    Ctd {
        instance: VarId,
        pv: Operand,
        load: Operand,
    },
    /// SR/RS bistable (IEC 61131-3 2.5.2.3.1); power in is S1 (SR) or S (RS), `reset` is R (SR)
    /// or R1 (RS), power out is Q1.
    Bistable {
        kind: BistableKind,
        instance: VarId,
        reset: Operand,
    },
    /// R_TRIG/F_TRIG edge detector (IEC 61131-3 2.5.2.3.2); power in is CLK, power out is Q.
    Trigger { kind: TriggerKind, instance: VarId },
    /// Up-down counter (IEC 61131-3 2.5.2.3.3); power in is CU, power out is QU. Its four other
    /// inputs are boxed: the counter is rare, and inline they would make every element 56 bytes
    /// instead of 32.
    Ctud {
        instance: VarId,
        inputs: Box<CtudInputs>,
    },
    /// MOVE box: when powered, `to := from`; power out = power in (ENO).
    Move { from: Operand, to: VarId },
    /// Arithmetic box: when powered, `out := a op b`; power out = power in (ENO).
    Arith {
        op: ArithOp,
        a: Operand,
        b: Operand,
        out: VarId,
    },
    /// Standard function box (`crate::Function`): when powered,
    /// `out := func(args…)`; power out = power in (ENO). The arguments have the types
    /// [`Function::types`] gives (boxed: an element stays 32 bytes).
    Function {
        func: Function,
        args: Box<[Operand]>,
        out: VarId,
    },
    /// Jump, taken when powered, to the rung that carries the label.
    Jmp { label: String, target: RungId },
    /// Return: when powered, ends this POU for this scan.
    Ret,
    /// End: when powered, ends the scan (main program only).
    End,
    /// Subroutine call, when powered.
    Call { pou: PouId },
    /// When powered, records an index-range fault of the scan (an array subscript outside
    /// its bounds); power out = power in. Reads and writes nothing.
    RangeFault,
    /// FOR head (last element of its rung). When powered: `var := from`, then loop while
    /// `var <= to`; the body is the rungs up to `next`.
    For {
        var: VarId,
        /// `from` and `to`, boxed so that an element stays 32 bytes (loops are rare).
        bounds: Box<ForBounds>,
        next: RungId,
    },
    /// NEXT (alone in its rung): `var += 1` and back to the FOR head's test.
    Next { head: RungId },
}

impl Element {
    /// True for the elements that send control elsewhere than the next rung: a jump, a return,
    /// an end, a call, and the two ends of a FOR loop.
    pub fn transfers_control(&self) -> bool {
        matches!(
            self,
            Element::Jmp { .. }
                | Element::Ret
                | Element::End
                | Element::Call { .. }
                | Element::For { .. }
                | Element::Next { .. }
        )
    }
}

/// The inputs of an up-down counter besides CU (its power in).
#[derive(Clone, Debug)]
pub struct CtudInputs {
    pub cd: Operand,
    pub reset: Operand,
    pub load: Operand,
    pub pv: Operand,
}

impl CtudInputs {
    /// CD, R, LD and PV, in that order.
    pub fn operands(&self) -> [&Operand; 4] {
        [&self.cd, &self.reset, &self.load, &self.pv]
    }
}

/// The bounds of a FOR head: `var := from`, loop while `var <= to`.
#[derive(Clone, Debug)]
pub struct ForBounds {
    pub from: Operand,
    pub to: Operand,
}

/// How a contact reads its BOOL.
#[derive(Copy, Clone, Debug, PartialEq, Eq)]
pub enum ContactKind {
    Normal,
    Negated,
    /// Passes power for one evaluation when the BOOL went FALSE→TRUE since the contact's last
    /// evaluation; `memory` is the hidden variable holding the previous value.
    Rising {
        memory: VarId,
    },
    Falling {
        memory: VarId,
    },
}

impl Program {
    /// Checks `parts` and makes the program: POUs (at least the main one) whose rung ranges
    /// follow one another from 0 and cover every rung; every rung in the POU it names; every
    /// variable, rung and POU id an element, a variable's scope or the written inputs name held
    /// by the program; every jump, FOR and NEXT target in its own POU. The resolver establishes
    /// all of this; a failure here is a defect of the reader or resolver that made `parts`, and
    /// the message says which rule broke where.
    pub fn new(parts: ProgramParts) -> Result<Program, InvalidProgram> {
        let ProgramParts {
            name,
            vars,
            pous,
            rungs,
            configuration,
            dialect,
            mut written_inputs,
        } = parts;
        check_parts(&vars, &pous, &rungs, &written_inputs)?;
        written_inputs.sort_unstable();
        written_inputs.dedup();
        Ok(Program {
            name,
            vars,
            pous,
            rungs,
            configuration,
            dialect,
            written_inputs,
        })
    }

    /// The program's name (the file's, or the PLCopen project's).
    pub fn name(&self) -> &str {
        &self.name
    }
    /// Every variable, indexed by [`VarId`].
    pub fn vars(&self) -> &Arena<VarId, Var> {
        &self.vars
    }
    /// Every POU, indexed by [`PouId`]; the first is the main program.
    pub fn pous(&self) -> &Arena<PouId, Pou> {
        &self.pous
    }
    /// Every rung of every POU, in listing order, indexed by [`RungId`].
    pub fn rungs(&self) -> &Arena<RungId, Rung> {
        &self.rungs
    }
    /// The PLCopen configuration that runs the program's POUs (tasks and program instances);
    /// `None` for programs without one (JSON, STL, a project without instances).
    pub fn configuration(&self) -> Option<&Configuration> {
        self.configuration.as_ref()
    }
    /// Whose rules `run` and `c` follow where toolchains differ (docs/dialects.md).
    pub fn dialect(&self) -> Dialect {
        self.dialect
    }
    /// The input variables the program itself writes, ascending (see
    /// [`ProgramParts::written_inputs`]).
    pub fn written_inputs(&self) -> &[VarId] {
        &self.written_inputs
    }
    /// Replaces the configuration (a reader that reads it after the POUs).
    pub fn set_configuration(&mut self, configuration: Option<Configuration>) {
        self.configuration = configuration;
    }
    /// Replaces the dialect (the file's editor, or the command line's `--dialect`).
    pub fn set_dialect(&mut self, dialect: Dialect) {
        self.dialect = dialect;
    }
    /// Marks POU `pou`'s body as not read as logic: its rungs are stand-ins (see [`Pou::skipped`]).
    pub fn mark_skipped(&mut self, pou: PouId, body: SkippedBody) {
        self.pous[pou].skipped = Some(Box::new(body));
    }
    /// Takes the program apart (for a transformation that makes a new one with
    /// [`Program::new`]).
    pub fn into_parts(self) -> ProgramParts {
        ProgramParts {
            name: self.name,
            vars: self.vars,
            pous: self.pous,
            rungs: self.rungs,
            configuration: self.configuration,
            dialect: self.dialect,
            written_inputs: self.written_inputs,
        }
    }

    /// The main program.
    pub fn main(&self) -> &Pou {
        &self.pous[0]
    }
    pub fn var(&self, id: VarId) -> &Var {
        &self.vars[id]
    }
    pub fn rung(&self, id: RungId) -> &Rung {
        &self.rungs[id]
    }
    pub fn pou(&self, id: PouId) -> &Pou {
        &self.pous[id]
    }
    /// The main program's id.
    pub fn main_id(&self) -> PouId {
        self.pous.id(0)
    }
    /// All rung ids in listing order.
    pub fn rung_ids(&self) -> impl DoubleEndedIterator<Item = RungId> + ExactSizeIterator {
        self.rungs.ids()
    }
    /// The rung ids of one POU, in program order.
    pub fn pou_rungs(
        &self,
        pou: PouId,
    ) -> impl DoubleEndedIterator<Item = RungId> + ExactSizeIterator {
        self.pous[pou].rungs.clone().map(RungId)
    }
    /// The first rung of POU `pou`, if it has any.
    pub fn first_rung(&self, pou: PouId) -> Option<RungId> {
        let r = &self.pous[pou].rungs;
        (r.start < r.end).then_some(RungId(r.start))
    }
    /// The POU that holds rung `r`.
    pub fn pou_of(&self, r: RungId) -> PouId {
        self.rungs[r].pou
    }
    /// Display text of a variable reference (`T1.Q`).
    pub fn var_ref_name(&self, r: VarRef) -> String {
        match r.field {
            None => self.var(r.var).name.clone(),
            Some(f) => format!("{}.{}", self.var(r.var).name, f.name()),
        }
    }
}

/// A [`ProgramParts`] that breaks an invariant of [`Program`]: the message says which and where.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct InvalidProgram(pub String);

impl std::fmt::Display for InvalidProgram {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "the resolved program is inconsistent: {}", self.0)
    }
}

impl std::error::Error for InvalidProgram {}

fn check_parts(
    vars: &[Var],
    pous: &Arena<PouId, Pou>,
    rungs: &Arena<RungId, Rung>,
    written_inputs: &[VarId],
) -> Result<(), InvalidProgram> {
    let bad = |m: String| Err(InvalidProgram(m));
    if pous.is_empty() {
        return bad("no main program".into());
    }
    let mut next = 0u32;
    for (p, pou) in pous.iter_enumerated() {
        if pou.rungs.start != next || pou.rungs.end < pou.rungs.start {
            return bad(format!(
                "POU `{}`'s rungs {:?} do not follow on from {next}",
                pou.name, pou.rungs
            ));
        }
        next = pou.rungs.end;
        for r in pou.rungs.clone() {
            if rungs.get(r as usize).is_some_and(|rung| rung.pou != p) {
                return bad(format!(
                    "rung {r} lies in POU `{}` but names another",
                    pou.name
                ));
            }
        }
    }
    if next as usize != rungs.len() {
        return bad(format!(
            "the POUs hold {next} rungs, the program {}",
            rungs.len()
        ));
    }
    let var_ok = |v: VarId| v.index() < vars.len();
    for v in vars {
        if v.scope.is_some_and(|s| s.index() >= pous.len()) {
            return bad(format!(
                "variable `{}` is scoped to a POU the program does not hold",
                v.name
            ));
        }
    }
    if let Some(v) = written_inputs.iter().find(|v| !var_ok(**v)) {
        return bad(format!("written input {} is not a variable", v.0));
    }
    for rung in rungs.iter() {
        let range = &pous[rung.pou].rungs;
        let in_pou = |r: RungId| range.contains(&r.0);
        let mut fault: Option<String> = None;
        walk_elements(&rung.series, &mut |e| {
            if fault.is_some() {
                return;
            }
            let mut ok = true;
            element_vars(e, &mut |v| ok &= var_ok(v));
            let target_ok = match e {
                Element::Jmp { target, .. } => in_pou(*target),
                Element::For { next, .. } => in_pou(*next),
                Element::Next { head } => in_pou(*head),
                Element::Call { pou } => pou.index() < pous.len(),
                _ => true,
            };
            if !ok {
                fault = Some(format!(
                    "rung `{}` names a variable the program does not hold",
                    rung.id
                ));
            } else if !target_ok {
                fault = Some(format!(
                    "rung `{}` transfers control outside its POU's rungs",
                    rung.id
                ));
            }
        });
        if let Some(m) = fault {
            return bad(m);
        }
    }
    Ok(())
}

/// Calls `f` on every variable element `e` itself names (not those of nested series).
fn element_vars(e: &Element, f: &mut impl FnMut(VarId)) {
    let op = |o: &Operand, f: &mut dyn FnMut(VarId)| {
        if let Some(v) = o.var() {
            f(v)
        }
    };
    match e {
        Element::Contact { var, kind } => {
            f(var.var);
            if let ContactKind::Rising { memory } | ContactKind::Falling { memory } = kind {
                f(*memory)
            }
        }
        Element::Compare { a, b, .. } => {
            op(a, f);
            op(b, f)
        }
        Element::Coil { var, .. } | Element::Set(var) | Element::Reset(var) => f(*var),
        Element::Timer { instance, pt, .. } => {
            f(*instance);
            op(pt, f)
        }
        Element::Ctu {
            instance,
            pv,
            reset,
        } => {
            f(*instance);
            op(pv, f);
            op(reset, f)
        }
        Element::Ctd { instance, pv, load } => {
            f(*instance);
            op(pv, f);
            op(load, f)
        }
        Element::Bistable {
            instance, reset, ..
        } => {
            f(*instance);
            op(reset, f)
        }
        Element::Trigger { instance, .. } => f(*instance),
        Element::Ctud { instance, inputs } => {
            f(*instance);
            for o in inputs.operands() {
                op(o, f)
            }
        }
        Element::Move { from, to } => {
            op(from, f);
            f(*to)
        }
        Element::Arith { a, b, out, .. } => {
            op(a, f);
            op(b, f);
            f(*out)
        }
        Element::Function { args, out, .. } => {
            for a in args.iter() {
                op(a, f)
            }
            f(*out)
        }
        Element::For { var, bounds, .. } => {
            f(*var);
            op(&bounds.from, f);
            op(&bounds.to, f)
        }
        Element::Or(_)
        | Element::Branch(_)
        | Element::Jmp { .. }
        | Element::Ret
        | Element::End
        | Element::Call { .. }
        | Element::Next { .. }
        | Element::RangeFault => {}
    }
}

/// Calls `f` on every element of `series`, depth first, in evaluation order.
pub fn walk_elements<'a>(series: &'a [Element], f: &mut impl FnMut(&'a Element)) {
    for e in series {
        f(e);
        match e {
            Element::Or(branches) | Element::Branch(branches) => {
                for b in branches {
                    walk_elements(b, f);
                }
            }
            _ => {}
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A million-rung program holds about seven million elements: each byte of `Element` is
    /// seven megabytes of memory to fault in while loading. Rare, large variants are boxed.
    #[test]
    fn an_element_is_32_bytes() {
        assert_eq!(std::mem::size_of::<Element>(), 32);
    }

    fn var(name: &str) -> Var {
        Var {
            name: name.into(),
            ty: Type::Bool,
            class: VarClass::Memory,
            init: Value::Bool(false),
            scope: None,
            hidden: false,
        }
    }

    fn rung(id: &str, pou: PouId, series: Series) -> Rung {
        Rung {
            id: id.into(),
            label: None,
            comment: None,
            pou,
            series,
            lowered: None,
            origin: Origin::NONE,
        }
    }

    /// A main program of two rungs and a subroutine of one, over variables A and B.
    fn parts() -> ProgramParts {
        let vars: Arena<VarId, Var> = [var("A"), var("B")].into_iter().collect();
        let mut pous: Arena<PouId, Pou> = Arena::new();
        let main = pous.push(Pou {
            name: "main".into(),
            kind: PouKind::Main,
            rungs: 0..2,
            skipped: None,
        });
        let sub = pous.push(Pou {
            name: "SBR".into(),
            kind: PouKind::Subroutine,
            rungs: 2..3,
            skipped: None,
        });
        let (a, b) = (vars.id(0), vars.id(1));
        let contact = Element::Contact {
            var: VarRef {
                var: a,
                field: None,
            },
            kind: ContactKind::Normal,
        };
        let rungs: Arena<RungId, Rung> = [
            rung(
                "R1",
                main,
                vec![contact.clone(), Element::Call { pou: sub }],
            ),
            rung(
                "R2",
                main,
                vec![
                    contact.clone(),
                    Element::Coil {
                        var: b,
                        negated: false,
                    },
                ],
            ),
            rung("S1", sub, vec![contact, Element::Set(b)]),
        ]
        .into_iter()
        .collect();
        ProgramParts {
            name: "p".into(),
            vars,
            pous,
            rungs,
            written_inputs: vec![b, a, b],
            ..ProgramParts::default()
        }
    }

    #[test]
    fn a_consistent_program_is_made_and_its_written_inputs_sorted() {
        let p = Program::new(parts()).expect("consistent");
        assert_eq!(p.rung_ids().count(), 3);
        assert_eq!(p.written_inputs(), [p.vars().id(0), p.vars().id(1)]);
        assert_eq!(
            p.pou_rungs(p.pous().id(1)).collect::<Vec<_>>(),
            [p.rungs().id(2)]
        );
        assert_eq!(p.first_rung(p.main_id()), Some(p.rungs().id(0)));
    }

    #[test]
    fn program_new_refuses_what_breaks_an_invariant() {
        let refused = |change: &dyn Fn(&mut ProgramParts), why: &str| {
            let mut bad = parts();
            change(&mut bad);
            let e = Program::new(bad).expect_err(why);
            assert!(e.0.contains(why), "{e}");
        };
        refused(&|p| p.pous[1].rungs = 3..3, "do not follow on");
        refused(&|p| p.pous[0].rungs = 0..1, "do not follow on");
        refused(&|p| p.rungs[2].pou = p.pous.id(0), "names another");
        refused(&|p| p.pous = Arena::new(), "no main program");
        // A variable id from a bigger arena.
        let mut more: Arena<VarId, Var> = Arena::new();
        let far = (0..3)
            .map(|i| more.push(var(&i.to_string())))
            .last()
            .unwrap();
        refused(
            &|p| p.rungs[1].series.push(Element::Reset(far)),
            "names a variable",
        );
        refused(&|p| p.written_inputs.push(far), "written input");
        // A jump from the subroutine into the main program.
        let into_main = |p: &mut ProgramParts| {
            let target = p.rungs.id(0);
            p.rungs[2].series.push(Element::Jmp {
                label: "L".into(),
                target,
            });
        };
        refused(&into_main, "outside its POU");
    }

    /// The same for rungs: what only FBD-lowered rungs carry is behind one pointer.
    #[test]
    fn a_rung_is_112_bytes() {
        assert_eq!(std::mem::size_of::<Rung>(), 112);
    }
}
