//! How the command line shows what went wrong, and what it warns about, on standard error.
//!
//! Two formats: text (a load error in the style of rustc, see [`plc_diag::render`]; any
//! other error as one `error: message` line) and JSON (one object per line, the keys of
//! docs/diagnostics.md), chosen once per process by [`set_format`] (the binary does, from the
//! command's `--format json`), so warnings printed in the middle of a command (a reader's
//! notes, a run's warnings) come in the same format as its error. Colour only when standard
//! error is a terminal and `NO_COLOR` is not set (<https://no-color.org>); piped output is
//! plain. The exit code is not decided here but by [`CliError::exit_code`]. The format, the
//! colour and the warnings are `super::stderr`'s (re-exported here), so that `io`, which
//! warns, does not import this module, which names `io`'s [`CliError`].

use super::io::CliError;
use super::stderr::format;
pub use super::stderr::{colour, set_format, warn, Format};
use plc_diag::{Severity, Shown};
use std::io::Write;

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
