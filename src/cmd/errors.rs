//! How the command line shows what went wrong, and what it warns about, on standard error.
//!
//! Two formats: text (a load error in the style of rustc, see [`plc_diag::render`]; any
//! other error as one `error: message` line) and JSON (one object per line, the keys of
//! docs/diagnostics.md), chosen once per process by [`set_format`] (the binary does, from the
//! command's `--format json`), so warnings printed in the middle of a command (a reader's
//! notes, a run's warnings) come in the same format as its error. Colour only when standard
//! error is a terminal and `NO_COLOR` is not set (<https://no-color.org>); piped output is
//! plain. The exit code is not decided here but by [`CliError::exit_code`].

use super::io::CliError;
use plc_diag::{Severity, Shown};
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

fn format() -> Format {
    *FORMAT.get().unwrap_or(&Format::Text)
}

/// Colour on standard error: a terminal, and `NO_COLOR` unset or empty.
pub fn colour() -> bool {
    use std::io::IsTerminal;
    std::io::stderr().is_terminal() && std::env::var_os("NO_COLOR").is_none_or(|v| v.is_empty())
}

/// The diagnostics of an error: its load diagnostics, or one without a place.
fn shown_of(e: &CliError) -> Vec<Shown> {
    match e {
        CliError::Load { shown, .. } if !shown.is_empty() => shown.clone(),
        other => vec![Shown::unplaced(Severity::Error, "", other.to_string())],
    }
}

/// The text of an error as the command line prints it, in `format`.
pub fn error_text(e: &CliError, format: Format, colour: bool) -> String {
    match (e, format) {
        (CliError::Load { shown, .. }, Format::Text) if !shown.is_empty() => {
            shown.iter().map(|s| s.text(colour)).collect()
        }
        (other, Format::Text) => format!("error: {}\n", plc_diag::printable(&other.to_string())),
        (_, Format::Json) => shown_of(e).iter().map(|s| s.json() + "\n").collect(),
    }
}

/// Prints an error on standard error, in the format set.
pub fn print_error(e: &CliError) {
    let _ = std::io::stderr().write_all(error_text(e, format(), colour()).as_bytes());
}

/// Prints a warning on standard error, in the format set.
pub fn warn(w: &Shown) {
    let text = match format() {
        Format::Text => w.text(colour()),
        Format::Json => w.json() + "\n",
    };
    let _ = std::io::stderr().write_all(text.as_bytes());
}
