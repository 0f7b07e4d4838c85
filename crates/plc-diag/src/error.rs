//! Load errors: what can be wrong with a program file, and where.
//!
//! Errors are data: a [`LoadError`] carries one or more [`Diagnostic`]s (each a [`Location`] —
//! rung id and JSON path, network and block, the [`Origin`] of the most precise node — and an
//! [`Invalid`] kind), or line and column for syntax errors; rendering happens only in `Display`,
//! in one place per kind. The file name is not part of the error: the caller that opened the file
//! adds it ([`LoadError::in_file`]), and with it the line and column ([`LoadError::locate`]).

use super::{origin, Diagnostic, Origin};
use std::fmt;

/// The op names of the FBD format, as the unknown-op message lists them (re-exported by
/// `plc_fbd`).
pub const OP_NAMES: &str = "EQ, NE, LT, LE, GT, GE, ADD, SUB, MUL, DIV, MOD, AND, OR, XOR, NOT, MOVE, SEL, MAX, MIN, LIMIT, TON, TOF, TP, CTU, CTD, SR, RS, R_TRIG, F_TRIG, CTUD, JMP, RET, TSTART, TSTOP, a standard function (ABS … ATAN, EXPT, SHL … ROR, MUX, A_TO_B, TRUNC)";

/// Where in the program file an error is.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Location {
    /// The id of the rung the error is in, if it is in one.
    pub rung: Option<String>,
    /// JSON path from the document root, e.g. `rungs[2].ld[1].or[0][0]`.
    pub path: String,
    /// For an error in an FBD network: the network id and, if the error is in a block, its id.
    pub network: Option<(String, Option<u32>)>,
    /// Where the most precise node the error names starts in the text (an operand, an element,
    /// a field, a variable, a rung, an FBD body).
    pub origin: Origin,
    /// Line and column (1-based) of `origin`, once [`LoadError::locate`] has computed them; not
    /// part of `Display` (which stays the path), but of [`LoadError::in_file`].
    pub position: Option<(u32, u32)>,
}

impl fmt::Display for Location {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        if let Some((network, block)) = &self.network {
            return match block {
                Some(b) => write!(f, "network {network} block {b} at {}", self.path),
                None => write!(f, "network {network} at {}", self.path),
            };
        }
        match &self.rung {
            Some(r) => write!(f, "rung {r} at {}", self.path),
            None => write!(
                f,
                "at {}",
                if self.path.is_empty() {
                    "top level"
                } else {
                    &self.path
                }
            ),
        }
    }
}

/// Everything that makes a program file unusable.
#[derive(Debug, PartialEq)]
pub enum LoadError {
    /// The file is not JSON (serde_json's message, with line and column, both 1-based).
    Syntax {
        line: usize,
        column: usize,
        message: String,
    },
    /// The JSON is well formed but the program is not valid: one problem.
    Invalid(Box<Diagnostic>),
    /// Several problems, in program order (at most [`super::MAX_ERRORS`]).
    Several(Vec<Diagnostic>),
}

impl std::error::Error for LoadError {}

impl fmt::Display for LoadError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            LoadError::Syntax {
                line,
                column,
                message,
            } => write!(f, "{line}:{column}: {message}"),
            LoadError::Invalid(d) => write!(f, "{d}"),
            LoadError::Several(ds) => {
                for (i, d) in ds.iter().enumerate() {
                    if i > 0 {
                        writeln!(f)?;
                    }
                    write!(f, "{d}")?;
                }
                Ok(())
            }
        }
    }
}

/// The ways a well-formed JSON document can fail to be a valid program.
#[derive(Clone, Debug, thiserror::Error, PartialEq)]
pub enum Invalid {
    #[error("expected {expected}, found {found}")]
    Shape {
        expected: &'static str,
        found: String,
    },
    #[error("missing field `{field}` in {what}")]
    MissingField {
        field: &'static str,
        what: &'static str,
    },
    #[error("unknown field `{field}` in {what} (allowed: {allowed})")]
    UnknownField {
        field: String,
        what: &'static str,
        allowed: String,
    },
    #[error("unknown element {{{keys}}} (an element has one of the keys contact, compare, or, coil, set, reset, branch, ton, tof, tp, ctu, ctd, ctud, sr, rs, r_trig, f_trig, move, op, jmp, ret, end, call, for, next, range_fault)")]
    UnknownElement { keys: String },
    #[error("`{name}` is not a valid name (letters, digits and _, not starting with a digit)")]
    BadName { name: String },
    #[error(
        "unknown type `{name}` (expected BOOL, SINT, INT, DINT, LINT, USINT, UINT, UDINT, ULINT, REAL, LREAL, BYTE, WORD, DWORD, LWORD, TIME, STRING, TON, TOF, TP, CTU, CTD, SR, RS, R_TRIG, F_TRIG or CTUD)"
    )]
    UnknownType { name: String },
    #[error("variable `{name}` is declared twice")]
    DuplicateVar { name: String },
    #[error("rung id `{id}` is used twice (first at {first})")]
    DuplicateRung { id: String, first: String },
    #[error("label `{label}` is used twice in {pou} (first on rung {first})")]
    DuplicateLabel {
        label: String,
        pou: String,
        first: String,
    },
    #[error("undefined variable `{name}`")]
    UndefinedVar { name: String },
    #[error("`{var}` of type {ty} has no field `{field}` (fields: {fields})")]
    UnknownFieldOf {
        var: String,
        ty: String,
        field: String,
        fields: &'static str,
    },
    #[error("undefined label `{label}` in {pou}")]
    UndefinedLabel { label: String, pou: String },
    #[error("undefined subroutine `{name}`")]
    UndefinedSubroutine { name: String },
    #[error("{what} needs {expected}, but `{operand}` is {found}")]
    Type {
        what: &'static str,
        expected: String,
        operand: String,
        found: String,
    },
    #[error("{what} cannot write `{var}`: {why}")]
    NotWritable {
        what: &'static str,
        var: String,
        why: &'static str,
    },
    #[error("constant {value} does not fit {ty}")]
    Range { value: String, ty: String },
    #[error("`{text}` is not a valid TIME literal (write e.g. \"T#1s\", \"T#250ms\")")]
    BadTime { text: String },
    #[error("`{text}` is not a valid literal (write e.g. \"16#FF\", \"2#1010\", \"UINT#5\", \"LREAL#1.5\")")]
    BadLiteral { text: String },
    /// A name or id that holds a control character (C0, DEL or C1): it would break the DOT,
    /// STL and C the tool writes and put escape sequences on a terminal. `text` is the name
    /// with its control characters escaped (`"R\u{1b}1"`), `code` the first one (`U+001B`).
    #[error("{what} {text} holds the control character {code} (names and ids are printable text)")]
    ControlChar {
        what: &'static str,
        text: String,
        code: String,
    },
    #[error("{what} is not allowed {place}")]
    Misplaced {
        what: &'static str,
        place: &'static str,
    },
    #[error("NEXT without a FOR")]
    NextWithoutFor,
    #[error("FOR without a NEXT")]
    ForWithoutNext,
    #[error("jump to `{label}` enters the body of the FOR on rung {head} from outside it")]
    JumpIntoLoop { label: String, head: String },
    /// A `configuration` that is malformed or does not fit the program (docs/format.md).
    #[error("{message}")]
    Configuration { message: String },
    #[error("subroutine `{name}` calls itself (call chain {chain})")]
    Recursion { name: String, chain: String },
    #[error("the program has no rungs")]
    Empty,
    // ---- FBD bodies and function blocks (docs/fbd.md)
    #[error("unknown op `{op}` (expected {names} or a function block)", names = OP_NAMES)]
    UnknownOp { op: String },
    #[error("{op} has no {dir} `{pin}` ({dir}s: {pins})")]
    UnknownPin {
        op: String,
        dir: &'static str,
        pin: String,
        pins: String,
    },
    #[error("{op} takes {expected}, found {found}")]
    PinCount {
        op: String,
        expected: String,
        found: usize,
    },
    #[error("{op} needs its input `{pin}` connected")]
    Unconnected { op: String, pin: String },
    #[error("block id {id} is used twice in this POU (first at {first})")]
    DuplicateBlock { id: u32, first: String },
    #[error("no block {id} in network {network}")]
    UndefinedBlock { id: u32, network: String },
    #[error("network id `{id}` is used twice (first at {first})")]
    DuplicateNetwork { id: String, first: String },
    #[error("label `{label}` is used twice in {pou} (first on network {first})")]
    DuplicateNetworkLabel {
        label: String,
        pou: String,
        first: String,
    },
    #[error("blocks {blocks} form a cycle of arcs; feed the value back through a variable instead (one block writes it, the other reads it)")]
    Cycle { blocks: String },
    #[error("block {block} (fragment {fragment}) {how} block {dep} (fragment {dep_fragment}), a fragment that is neither its own nor an ancestor of it: block {dep} may not have run when block {block} runs")]
    FragmentRule {
        block: u32,
        fragment: String,
        how: &'static str,
        dep: u32,
        dep_fragment: String,
    },
    #[error("fragment {fragment} cannot run as one block: the arcs {arcs} leave it and come back (a control arc from several sources orders a block after the fragment, and the fragment depends on that block)")]
    FragmentSplit { fragment: String, arcs: String },
    #[error("function block `{name}` contains an instance of itself (through {chain})")]
    FbRecursion { name: String, chain: String },
    #[error("`{name}` is declared, but the FBD body needs it for a hidden variable (names `_<block>_<pin>` and `_run_<network>_<fragment>` are reserved in FBD POUs)")]
    HiddenClash { name: String },
    #[error("internal error: the resolved program is inconsistent: {what}; please report it with the file")]
    Inconsistent { what: String },
    #[error("TIME variable `{var}` is accumulated (TSTART/TSTOP) in {first} and in {second}; accumulate it in one POU only")]
    AccumulatedTwice {
        var: String,
        first: String,
        second: String,
    },
    #[error("`{name}` is a function block instance; read its outputs as `{name}.OUTPUT`")]
    InstanceValue { name: String },
    #[error("`{instance}` ({fb}) has no input or output `{member}` (members: {members})")]
    UnknownMember {
        instance: String,
        fb: String,
        member: String,
        members: String,
    },
    #[error("unknown type `{name}` (expected BOOL, SINT, INT, DINT, LINT, USINT, UINT, UDINT, ULINT, REAL, LREAL, BYTE, WORD, DWORD, LWORD, TIME, TON, TOF, TP, CTU, CTD, SR, RS, R_TRIG, F_TRIG, CTUD or a function block: {fbs})")]
    UnknownTypeOrFb { name: String, fbs: String },
    // ---- PLCopen TC6 XML (docs/plcopen.md)
    /// What the PLCopen reader cannot take (the message names the element, its localId or name).
    #[error("{message}")]
    PlcOpen { message: String },
}

impl LoadError {
    pub fn invalid(rung: Option<&str>, path: &str, kind: Invalid) -> LoadError {
        LoadError::Invalid(Box::new(Diagnostic::error(
            Location {
                rung: rung.map(str::to_owned),
                path: path.to_owned(),
                network: None,
                origin: Origin::NONE,
                position: None,
            },
            kind,
        )))
    }

    /// An error in FBD network `network` (in block `block`, if given).
    pub fn fbd(network: &str, block: Option<u32>, path: &str, kind: Invalid) -> LoadError {
        LoadError::Invalid(Box::new(Diagnostic::error(
            Location {
                rung: None,
                path: path.to_owned(),
                network: Some((network.to_owned(), block)),
                origin: Origin::NONE,
                position: None,
            },
            kind,
        )))
    }

    /// The problems, in program order (none for a syntax error).
    pub fn diagnostics(&self) -> &[Diagnostic] {
        match self {
            LoadError::Syntax { .. } => &[],
            LoadError::Invalid(d) => std::slice::from_ref(d),
            LoadError::Several(ds) => ds,
        }
    }

    /// One error or several: `Several` only when there are two or more.
    pub fn from_diagnostics(mut ds: Vec<Diagnostic>) -> Option<LoadError> {
        match ds.len() {
            0 => None,
            1 => ds.pop().map(|d| LoadError::Invalid(Box::new(d))),
            _ => Some(LoadError::Several(ds)),
        }
    }

    /// The diagnostics of `self` appended to `out` (a syntax error cannot be).
    pub fn into_diagnostics(self) -> Result<Vec<Diagnostic>, LoadError> {
        match self {
            LoadError::Syntax { .. } => Err(self),
            LoadError::Invalid(d) => Ok(vec![*d]),
            LoadError::Several(ds) => Ok(ds),
        }
    }

    /// Renders every problem as `FILE:LINE:COLUMN: message` (syntax), `FILE:LINE:COLUMN:
    /// LOCATION: message` (located, see [`LoadError::locate`]) or `FILE: LOCATION: message`, one
    /// per line, each line after the first prefixed `error: ` like the first one is by the command
    /// line.
    pub fn in_file<'e>(&'e self, file: &'e str) -> impl fmt::Display + 'e {
        InFile { error: self, file }
    }

    /// Gives each problem `hint` (shown as `help:`), where it has none yet.
    pub fn with_hint(mut self, hint: &str) -> LoadError {
        let ds: &mut [Diagnostic] = match &mut self {
            LoadError::Syntax { .. } => return self,
            LoadError::Invalid(d) => std::slice::from_mut(&mut **d),
            LoadError::Several(ds) => ds,
        };
        for d in ds {
            d.hint = d.hint.take().or_else(|| Some(hint.to_owned()));
        }
        self
    }

    /// Gives each problem the origin of the node it is in, where it has none yet (so the
    /// innermost node that knows its place wins).
    pub fn at(mut self, origin: Origin) -> LoadError {
        let ds: &mut [Diagnostic] = match &mut self {
            LoadError::Syntax { .. } => return self,
            LoadError::Invalid(d) => std::slice::from_mut(&mut **d),
            LoadError::Several(ds) => ds,
        };
        for d in ds {
            d.location.origin = d.location.origin.or(origin);
        }
        self
    }

    /// Moves each problem's origin to the node its path names, where `node_of` (the format's
    /// path walker: where the node starts, with its key for a member of an object) finds one
    /// that the origin it has lies before, and computes the line and column of the moved ones:
    /// for problems found on the model, which keeps every node's path but not always its
    /// offset. A node starts after every node that contains it, so an origin before the named
    /// node is a container of it, and one at or after its start is already as precise.
    pub fn refine(
        mut self,
        text: &str,
        node_of: impl Fn(&str, &str) -> Option<usize>,
    ) -> LoadError {
        let ds: &mut [Diagnostic] = match &mut self {
            LoadError::Syntax { .. } => return self,
            LoadError::Invalid(d) => std::slice::from_mut(&mut **d),
            LoadError::Several(ds) => ds,
        };
        for d in ds.iter_mut() {
            let l = &mut d.location;
            let Some(start) = node_of(text, &l.path) else {
                continue;
            };
            if l.origin.offset().is_none_or(|o| o < start) {
                l.origin = Origin::at(start);
                l.position = None;
            }
        }
        self.locate(text)
    }

    /// Computes the line and column of every diagnostic's origin in `text` (the text the
    /// origins are offsets into), in one pass.
    pub fn locate(mut self, text: &str) -> LoadError {
        let ds: &mut [Diagnostic] = match &mut self {
            LoadError::Syntax { .. } => return self,
            LoadError::Invalid(d) => std::slice::from_mut(&mut **d),
            LoadError::Several(ds) => ds,
        };
        let origins: Vec<Origin> = ds.iter().map(|d| d.location.origin).collect();
        for (d, p) in ds.iter_mut().zip(origin::line_columns(text, &origins)) {
            d.location.position = d.location.position.or(p);
        }
        self
    }
}

struct InFile<'e> {
    error: &'e LoadError,
    file: &'e str,
}

impl fmt::Display for InFile<'_> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self.error {
            LoadError::Syntax { .. } => write!(f, "{}:{}", self.file, self.error),
            other => {
                for (i, d) in other.diagnostics().iter().enumerate() {
                    if i > 0 {
                        write!(f, "\nerror: ")?;
                    }
                    match d.location.position {
                        Some((line, column)) => write!(f, "{}:{line}:{column}: {d}", self.file)?,
                        None => write!(f, "{}: {d}", self.file)?,
                    }
                }
                Ok(())
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn renders_location_and_kind() {
        let e = LoadError::invalid(
            Some("R3"),
            "rungs[2].ld[0]",
            Invalid::UndefinedVar { name: "X".into() },
        );
        assert_eq!(
            e.to_string(),
            "rung R3 at rungs[2].ld[0]: undefined variable `X`"
        );
        let two = LoadError::Several(vec![e.diagnostics()[0].clone(), e.diagnostics()[0].clone()]);
        assert_eq!(
            two.in_file("p.json").to_string(),
            "p.json: rung R3 at rungs[2].ld[0]: undefined variable `X`\nerror: p.json: rung R3 at rungs[2].ld[0]: undefined variable `X`"
        );
        let e = LoadError::Syntax {
            line: 3,
            column: 7,
            message: "expected `,`".into(),
        };
        assert_eq!(e.to_string(), "3:7: expected `,`");
    }

    #[test]
    fn a_located_error_starts_with_line_and_column_in_its_file() {
        let text = "{\n  \"rungs\": [\n    {\"id\": \"R1\"}]}";
        let e = LoadError::invalid(Some("R1"), "rungs[0]", Invalid::Empty)
            .at(Origin::at(19))
            .at(Origin::at(0))
            .locate(text);
        assert_eq!(e.diagnostics()[0].location.position, Some((3, 5)));
        assert_eq!(
            e.in_file("p.json").to_string(),
            "p.json:3:5: rung R1 at rungs[0]: the program has no rungs"
        );
        assert_eq!(
            e.to_string(),
            "rung R1 at rungs[0]: the program has no rungs"
        );
    }
}
