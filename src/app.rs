//! The commands behind the binary, as library functions over validated configurations.
//!
//! `main.rs` turns command-line arguments into these configs and calls one function; everything
//! here returns a [`CliError`] instead of printing or exiting, and writes an output file only when
//! the whole output is ready (written to a temporary file beside it, then renamed), so a failure
//! never leaves a half-written file.

use crate::analysis::{analyse, analyse_with, Analysis, AnalysisConfig, DependenceListing, Listed};
use crate::fbd::Fbd;
use crate::model::Program;
use crate::read::{program_from_json, LoadError};
use crate::report::{
    document_with, fbd_parts, render_dot, render_json, render_text, FbdParts, Rows, TextOptions,
    View, DOT_MAX_RUNGS,
};
use std::path::{Path, PathBuf};

/// An error of a command, with what the user needs to find its cause.
#[derive(Debug, thiserror::Error)]
pub enum CliError {
    /// The program file is not a valid program: `file:line:column: message` for syntax
    /// errors, `file: rung R at path: message` for the others.
    #[error("{file}{}{error}", if matches!(error, LoadError::Syntax { .. }) { ":" } else { ": " })]
    Load { file: String, error: LoadError },
    /// A file could not be read or written.
    #[error("{path}: {message}")]
    Io { path: String, message: String },
    /// An argument is not valid.
    #[error("{0}")]
    Usage(String),
}

impl CliError {
    /// Exit code: 2 for bad input (program, arguments), 1 for I/O failures.
    pub fn exit_code(&self) -> u8 {
        match self {
            CliError::Load { .. } | CliError::Usage(_) => 2,
            CliError::Io { .. } => 1,
        }
    }
}

/// Reads and checks a program file.
pub fn load_program(path: &Path) -> Result<Program, CliError> {
    let text = std::fs::read_to_string(path).map_err(|e| CliError::Io {
        path: path.display().to_string(),
        message: e.to_string(),
    })?;
    program_from_json(&text).map_err(|error| CliError::Load {
        file: path.display().to_string(),
        error,
    })
}

/// Reads and checks a program file, with its FBD bodies as written.
pub fn load_program_and_fbd(path: &Path) -> Result<(Program, Fbd), CliError> {
    let text = std::fs::read_to_string(path).map_err(|e| CliError::Io {
        path: path.display().to_string(),
        message: e.to_string(),
    })?;
    crate::read::program_and_fbd_from_json(&text).map_err(|error| CliError::Load {
        file: path.display().to_string(),
        error,
    })
}

/// Writes `contents` to `out` (atomically) or to standard output.
pub fn write_output(out: Option<&Path>, contents: &str) -> Result<(), CliError> {
    write_output_with(out, |w| w.write_all(contents.as_bytes()))
}

/// Streams output produced by `write` to `out` or to standard output. A file is written under a
/// temporary name beside `out` and renamed into place only when `write` succeeded, so a failure
/// never leaves a partial file.
pub fn write_output_with(
    out: Option<&Path>,
    write: impl FnOnce(&mut dyn std::io::Write) -> std::io::Result<()>,
) -> Result<(), CliError> {
    use std::io::Write;
    match out {
        None => {
            let mut stdout = std::io::BufWriter::new(std::io::stdout().lock());
            // A closed pipe (`| head`) is not an error worth reporting.
            let _ = write(&mut stdout).and_then(|_| stdout.flush());
            Ok(())
        }
        Some(path) => {
            let io = |e: std::io::Error| CliError::Io {
                path: path.display().to_string(),
                message: e.to_string(),
            };
            let mut tmp: PathBuf = path.to_path_buf();
            let name = format!(
                ".{}.tmp-{}",
                path.file_name()
                    .map(|n| n.to_string_lossy().into_owned())
                    .unwrap_or_default(),
                std::process::id()
            );
            tmp.set_file_name(name);
            let result = std::fs::File::create(&tmp).and_then(|f| {
                let mut w = std::io::BufWriter::new(f);
                write(&mut w)?;
                w.flush()
            });
            match result.and_then(|_| std::fs::rename(&tmp, path)) {
                Ok(()) => Ok(()),
                Err(e) => {
                    let _ = std::fs::remove_file(&tmp);
                    Err(io(e))
                }
            }
        }
    }
}

/// Output format of `report`.
#[derive(Copy, Clone, Debug, PartialEq, Eq)]
pub enum ReportFormat {
    Text,
    Json,
    Dot,
}

/// A validated `plc-deps report` invocation.
#[derive(Clone, Debug)]
pub struct ReportConfig {
    pub input: PathBuf,
    pub format: ReportFormat,
    /// The levellings text and DOT show.
    pub view: View,
    /// Rows per section of the text report.
    pub rows: Rows,
    /// Which data dependences are listed.
    pub analysis: AnalysisConfig,
    pub output: Option<PathBuf>,
}

/// Writes the report of `p` (with `fbd`, what its FBD lowering made) in `format`.
pub fn write_report(
    p: &Program,
    a: &Analysis,
    fbd: Option<&FbdParts>,
    format: ReportFormat,
    text: &TextOptions,
    out: &mut impl std::io::Write,
) -> std::io::Result<()> {
    let doc = document_with(p, a, fbd);
    match format {
        ReportFormat::Text => render_text(&doc, text, out),
        ReportFormat::Json => render_json(&doc, out),
        ReportFormat::Dot => render_dot(&doc, text.view, out),
    }
}

/// Renders the report of a loaded program and its FBD bodies with the default options (a
/// convenience for tests and small programs: the command streams instead).
pub fn render_report(p: &Program, fbd: &Fbd, format: ReportFormat, view: View) -> String {
    let a = analyse(p);
    let parts = fbd_parts(p, fbd);
    let mut out = Vec::new();
    let text = TextOptions {
        view,
        ..TextOptions::default()
    };
    write_report(p, &a, parts.as_ref(), format, &text, &mut out)
        .expect("writing to memory cannot fail");
    String::from_utf8(out).expect("reports are UTF-8")
}

/// `plc-deps report`. Warnings go to standard error as well as into the report.
pub fn report(c: &ReportConfig) -> Result<(), CliError> {
    let (p, fbd) = load_program_and_fbd(&c.input)?;
    let parts = fbd_parts(&p, &fbd);
    if c.format == ReportFormat::Dot && p.rungs.len() > DOT_MAX_RUNGS {
        return Err(CliError::Usage(format!(
            "{}: {} rungs are too many to draw ({} at most): Graphviz cannot lay out a graph this size usefully; use the text or JSON report",
            c.input.display(),
            p.rungs.len(),
            DOT_MAX_RUNGS
        )));
    }
    let a = analyse_with(&p, &c.analysis);
    for w in &a.warnings {
        eprintln!(
            "warning: {}: {}",
            c.input.display(),
            crate::report::warning_text(&p, w)
        );
    }
    if a.listed == Listed::Direct && c.analysis.dependences != DependenceListing::Direct {
        eprintln!(
            "warning: {}: {} data dependence pairs are more than --max-pairs allows; listing the {} direct ones (they imply the rest; --dependences all lists every pair)",
            c.input.display(),
            crate::report::text::thousands(a.counts.total() as usize),
            crate::report::text::thousands(a.data.len())
        );
    }
    let text = TextOptions {
        view: c.view,
        rows: c.rows,
    };
    write_output_with(c.output.as_deref(), |w| {
        let mut w = w;
        write_report(&p, &a, parts.as_ref(), c.format, &text, &mut w)
    })
}

/// Output format of `order`.
#[derive(Copy, Clone, Debug, PartialEq, Eq)]
pub enum OrderFormat {
    Text,
    Json,
    Dot,
}

/// A validated `plc-deps order` invocation.
#[derive(Clone, Debug)]
pub struct OrderConfig {
    pub input: PathBuf,
    pub format: OrderFormat,
    pub output: Option<PathBuf>,
}

/// Renders the execution order and fragment trees of a program's FBD networks.
pub fn render_order(p: &Program, fbd: &crate::fbd::Fbd, format: OrderFormat) -> String {
    match format {
        OrderFormat::Text => crate::fbd::render_order_text(p, fbd),
        OrderFormat::Json => crate::fbd::render_order_json(p, fbd),
        OrderFormat::Dot => crate::fbd::render_order_dot(p, fbd),
    }
}

/// `plc-deps order`: each FBD network's execution order and fragment tree. A cycle of arcs or
/// a fragment-rule violation is a load error naming the blocks (exit code 2).
pub fn order(c: &OrderConfig) -> Result<(), CliError> {
    let path = &c.input;
    let text = std::fs::read_to_string(path).map_err(|e| CliError::Io {
        path: path.display().to_string(),
        message: e.to_string(),
    })?;
    let (p, fbd) =
        crate::read::program_and_fbd_from_json(&text).map_err(|error| CliError::Load {
            file: path.display().to_string(),
            error,
        })?;
    write_output(c.output.as_deref(), &render_order(&p, &fbd, c.format))
}

/// The JSON Schema of the program format (`plc-deps schema`).
pub const PROGRAM_SCHEMA: &str = include_str!("../schema/program.schema.json");
