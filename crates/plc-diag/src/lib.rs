//! Diagnostics: what is wrong with a program file, where, and how bad it is.
//!
//! Below every other module: readers and the resolver produce [`Diagnostic`]s, the loaders
//! return them wrapped in a [`LoadError`] (one, or several in program order, at most
//! [`MAX_ERRORS`]). A diagnostic is data — a stable code (`E0101`), a severity, the [`Location`]
//! (rung id, network and block, JSON path, and line and column where the reader knew them), the
//! [`Invalid`] kind and an optional hint — and is rendered only by `Display`, so the message of
//! each kind is written in one place. Where in the text a problem is, is an [`Origin`] (a byte
//! offset of the most precise node the producer knew); line and column are computed from the
//! offsets only when the errors are final ([`LoadError::locate`], one pass over the text for all
//! of them), so a program that loads pays nothing for them. It deliberately knows nothing about
//! files: the caller that opened the file adds its name ([`LoadError::in_file`]), and that
//! one-line rendering (`FILE:LINE:COLUMN: LOCATION: message`) has line and column. The command
//! line shows them in the style of rustc, or as JSON, through [`render::Shown`] (the source
//! line, a caret under the token at the origin ([`span`]), the hint, e.g. [`suggest`]'s
//! "did you mean"); every code is documented with an example in docs/diagnostics.md.
#![forbid(unsafe_code)]

mod error;
mod origin;
pub mod render;
pub mod span;
pub mod suggest;

pub use error::{Invalid, LoadError, Location, OP_NAMES};
pub use origin::Origin;
pub use render::{Shown, SYNTAX_CODE};

use std::fmt;

/// The most problems one load reports; later ones are dropped (the first are the useful ones).
pub const MAX_ERRORS: usize = 20;

/// How bad a diagnostic is.
#[derive(Copy, Clone, Debug, PartialEq, Eq)]
pub enum Severity {
    /// The program cannot be loaded.
    Error,
    /// The program loads, but something is probably not what was meant.
    Warning,
}

/// One problem: a stable code, a severity, where, what, and maybe how to fix it.
#[derive(Clone, Debug, PartialEq)]
pub struct Diagnostic {
    pub severity: Severity,
    pub location: Location,
    pub kind: Invalid,
    pub hint: Option<String>,
}

impl Diagnostic {
    pub fn error(location: Location, kind: Invalid) -> Diagnostic {
        Diagnostic {
            severity: Severity::Error,
            location,
            kind,
            hint: None,
        }
    }

    /// The stable code of the kind: `E01xx` shape of the file, `E02xx` names and types,
    /// `E03xx` structure (ids, labels, loops, calls), `E04xx` FBD networks and function blocks, `E05xx` PLCopen TC6 XML.
    pub fn code(&self) -> &'static str {
        self.kind.code()
    }

    /// The message without the location.
    pub fn message(&self) -> String {
        self.kind.to_string()
    }
}

impl fmt::Display for Diagnostic {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}: {}", self.location, self.kind)
    }
}

impl Invalid {
    /// The stable code of this kind (see [`Diagnostic::code`]).
    pub fn code(&self) -> &'static str {
        use Invalid::*;
        match self {
            Shape { .. } => "E0101",
            MissingField { .. } => "E0102",
            UnknownField { .. } => "E0103",
            UnknownElement { .. } => "E0104",
            BadName { .. } => "E0105",
            BadTime { .. } => "E0106",
            Misplaced { .. } => "E0107",
            Empty => "E0108",
            BadLiteral { .. } => "E0109",
            ControlChar { .. } => "E0110",
            UnknownType { .. } => "E0201",
            UnknownTypeOrFb { .. } => "E0202",
            DuplicateVar { .. } => "E0203",
            UndefinedVar { .. } => "E0204",
            UnknownFieldOf { .. } => "E0205",
            Type { .. } => "E0206",
            NotWritable { .. } => "E0207",
            Range { .. } => "E0208",
            InstanceValue { .. } => "E0209",
            UnknownMember { .. } => "E0210",
            DuplicateRung { .. } => "E0301",
            DuplicateLabel { .. } => "E0302",
            UndefinedLabel { .. } => "E0303",
            UndefinedSubroutine { .. } => "E0304",
            NextWithoutFor => "E0305",
            ForWithoutNext => "E0306",
            JumpIntoLoop { .. } => "E0307",
            Recursion { .. } => "E0308",
            Configuration { .. } => "E0309",
            UnknownOp { .. } => "E0401",
            UnknownPin { .. } => "E0402",
            PinCount { .. } => "E0403",
            Unconnected { .. } => "E0404",
            DuplicateBlock { .. } => "E0405",
            UndefinedBlock { .. } => "E0406",
            DuplicateNetwork { .. } => "E0407",
            DuplicateNetworkLabel { .. } => "E0408",
            Cycle { .. } => "E0409",
            FragmentRule { .. } => "E0410",
            FragmentSplit { .. } => "E0411",
            FbRecursion { .. } => "E0412",
            HiddenClash { .. } => "E0413",
            AccumulatedTwice { .. } => "E0414",
            PlcOpen { .. } => "E0501",
            Inconsistent { .. } => "E0901",
        }
    }
}

impl Invalid {
    /// The error of `text`, named `what` (`"rung id"`), when it holds a control character (C0,
    /// DEL or C1: [`char::is_control`]); `None` when it is printable.
    pub fn control_char(what: &'static str, text: &str) -> Option<Invalid> {
        let c = text.chars().find(|c| c.is_control())?;
        Some(Invalid::ControlChar {
            what,
            text: format!("{text:?}"),
            code: format!("U+{:04X}", c as u32),
        })
    }
}

/// `text` with every control character (C0, DEL, C1) but line feed and tab written as its Rust
/// escape (`\u{1b}`), so that file text quoted in a message cannot drive a terminal.
pub fn printable(text: &str) -> std::borrow::Cow<'_, str> {
    let escaped = |c: char| c.is_control() && c != '\n' && c != '\t';
    if !text.contains(escaped) {
        return std::borrow::Cow::Borrowed(text);
    }
    let mut out = String::with_capacity(text.len() + 8);
    for c in text.chars() {
        if escaped(c) {
            out.extend(c.escape_default());
        } else {
            out.push(c);
        }
    }
    std::borrow::Cow::Owned(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn control_characters_are_named_and_escaped() {
        assert_eq!(
            printable("a\u{1b}[2Jb\n\tc\u{9b}\u{7f}"),
            "a\\u{1b}[2Jb\n\tc\\u{9b}\\u{7f}"
        );
        assert!(matches!(
            printable("plain"),
            std::borrow::Cow::Borrowed("plain")
        ));
        assert_eq!(
            Invalid::control_char("rung id", "R\u{7}1").unwrap().to_string(),
            "rung id \"R\\u{7}1\" holds the control character U+0007 (names and ids are printable text)"
        );
        assert_eq!(Invalid::control_char("rung id", "R 1 ü"), None);
    }
}
