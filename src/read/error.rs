//! Load errors: what can be wrong with a program file, and where.
//!
//! Errors are data: a [`LoadError`] carries a [`Location`] (rung id and JSON path, or line and
//! column for syntax errors) and a kind; rendering happens only in `Display`, in one place per kind.
//! The file name is not part of the error: the caller that opened the file adds it.

use std::fmt;

/// Where in the program file an error is.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Location {
    /// The id of the rung the error is in, if it is in one.
    pub rung: Option<String>,
    /// JSON path from the document root, e.g. `rungs[2].ld[1].or[0][0]`.
    pub path: String,
}

impl fmt::Display for Location {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match &self.rung {
            Some(r) => write!(f, "rung {r} at {}", self.path),
            None => write!(f, "at {}", if self.path.is_empty() { "top level" } else { &self.path }),
        }
    }
}

/// Everything that makes a program file unusable.
#[derive(Debug, thiserror::Error, PartialEq)]
pub enum LoadError {
    /// The file is not JSON (serde_json's message, with line and column).
    #[error("{line}:{column}: {message}")]
    Syntax { line: usize, column: usize, message: String },
    /// The JSON is well formed but the program is not valid.
    #[error("{location}: {kind}")]
    Invalid { location: Location, kind: Invalid },
}

/// The ways a well-formed JSON document can fail to be a valid program.
#[derive(Debug, thiserror::Error, PartialEq)]
pub enum Invalid {
    #[error("expected {expected}, found {found}")]
    Shape { expected: &'static str, found: String },
    #[error("missing field `{field}` in {what}")]
    MissingField { field: &'static str, what: &'static str },
    #[error("unknown field `{field}` in {what} (allowed: {allowed})")]
    UnknownField { field: String, what: &'static str, allowed: String },
    #[error("unknown element {{{keys}}} (an element has one of the keys contact, compare, or, coil, set, reset, branch, ton, tof, tp, ctu, ctd, move, op, jmp, ret, end, call, for, next)")]
    UnknownElement { keys: String },
    #[error("`{name}` is not a valid name (letters, digits and _, not starting with a digit)")]
    BadName { name: String },
    #[error("unknown type `{name}` (expected BOOL, INT, DINT, REAL, TIME, TON, TOF, TP, CTU or CTD)")]
    UnknownType { name: String },
    #[error("variable `{name}` is declared twice")]
    DuplicateVar { name: String },
    #[error("rung id `{id}` is used twice (first at {first})")]
    DuplicateRung { id: String, first: String },
    #[error("label `{label}` is used twice in {pou} (first on rung {first})")]
    DuplicateLabel { label: String, pou: String, first: String },
    #[error("undefined variable `{name}`")]
    UndefinedVar { name: String },
    #[error("`{var}` of type {ty} has no field `{field}` (fields: {fields})")]
    UnknownFieldOf { var: String, ty: String, field: String, fields: &'static str },
    #[error("undefined label `{label}` in {pou}")]
    UndefinedLabel { label: String, pou: String },
    #[error("undefined subroutine `{name}`")]
    UndefinedSubroutine { name: String },
    #[error("{what} needs {expected}, but `{operand}` is {found}")]
    Type { what: &'static str, expected: String, operand: String, found: String },
    #[error("{what} cannot write `{var}`: {why}")]
    NotWritable { what: &'static str, var: String, why: &'static str },
    #[error("constant {value} does not fit {ty}")]
    Range { value: String, ty: String },
    #[error("`{text}` is not a valid TIME literal (write e.g. \"T#1s\", \"T#250ms\")")]
    BadTime { text: String },
    #[error("{what} is not allowed {place}")]
    Misplaced { what: &'static str, place: &'static str },
    #[error("NEXT without a FOR")]
    NextWithoutFor,
    #[error("FOR without a NEXT")]
    ForWithoutNext,
    #[error("jump to `{label}` enters the body of the FOR on rung {head} from outside it")]
    JumpIntoLoop { label: String, head: String },
    #[error("subroutine `{name}` calls itself (call chain {chain})")]
    Recursion { name: String, chain: String },
    #[error("the program has no rungs")]
    Empty,
}

impl LoadError {
    pub(crate) fn invalid(rung: Option<&str>, path: &str, kind: Invalid) -> LoadError {
        LoadError::Invalid {
            location: Location { rung: rung.map(str::to_owned), path: path.to_owned() },
            kind,
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
        assert_eq!(e.to_string(), "rung R3 at rungs[2].ld[0]: undefined variable `X`");
        let e = LoadError::Syntax { line: 3, column: 7, message: "expected `,`".into() };
        assert_eq!(e.to_string(), "3:7: expected `,`");
    }
}
