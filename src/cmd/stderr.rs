//! Standard error's side of the command line that every command shares: the diagnostics format
//! of the process (text or JSON, set once), whether to colour, and printing a warning. Below
//! both [`super::errors`] (which prints a command's error in the same format) and
//! [`super::io`] (which warns about a reader's notes), so that neither imports the other back.
//!
//! Nothing here decides what is an error or its exit code (`CliError`, in `io`).

use plc_diag::Shown;
use std::io::Write;
use std::sync::OnceLock;

/// How diagnostics are printed.
#[derive(Copy, Clone, Debug, PartialEq, Eq)]
pub enum Format {
    /// For people: rustc style, coloured on a terminal.
    Text,
    /// For tools: one JSON object per line.
    Json,
}

static FORMAT: OnceLock<Format> = OnceLock::new();

/// Sets the format for the rest of the process (the first call wins; the default is text).
pub fn set_format(format: Format) {
    let _ = FORMAT.set(format);
}

/// The format set (text if none was).
pub(super) fn format() -> Format {
    *FORMAT.get().unwrap_or(&Format::Text)
}

/// Colour on standard error: a terminal, and `NO_COLOR` unset or empty.
pub fn colour() -> bool {
    use std::io::IsTerminal;
    std::io::stderr().is_terminal() && std::env::var_os("NO_COLOR").is_none_or(|v| v.is_empty())
}

/// Prints a warning on standard error, in the format set.
pub fn warn(w: &Shown) {
    let text = match format() {
        Format::Text => w.text(colour()),
        Format::Json => w.json() + "\n",
    };
    let _ = std::io::stderr().write_all(text.as_bytes());
}
