//! `plc-deps convert`: any program file the tool reads (an S7-200 STL listing, a PLCopen TC6
//! XML export, or the JSON format itself) written as the JSON program format (docs/format.md), through the surface
//! syntax: what plc-deps understood of the file, in a form to read, diff and edit.
//!
//! The file is loaded first (so a file that does not load is refused with its errors, exit 2,
//! and nothing is written), then read into the syntax and written ([`plc_write::json`]);
//! the output reads back to the same model. A POU whose body the tool does not execute (an ST,
//! IL or SFC body read as stand-in rungs) is refused unless `--allow-skipped`: the JSON format
//! has no mark for a stand-in, so a run of the converted file could not know it skips code.

use super::io::{format_of, load_text_lowered, read_program_text, write_output_with, Format};
use super::CliError;
use plc_read::{json, stl};
use std::path::PathBuf;

/// A validated `plc-deps convert` invocation.
#[derive(Clone, Debug)]
pub struct ConvertConfig {
    pub input: PathBuf,
    /// Write the JSON even when a POU's body is only stand-in rungs.
    pub allow_skipped: bool,
    /// The configuration of a PLCopen project with several (`--configuration`); `None`: the
    /// first in file order.
    pub configuration: Option<String>,
    pub output: Option<PathBuf>,
}

/// `plc-deps convert`: the program as the JSON program format. The file's format is recognised
/// as every command recognises it ([`format_of`]: STL, PLCopen TC6 XML or JSON).
pub fn convert(c: &ConvertConfig) -> Result<(), CliError> {
    let (file, text) = read_program_text(&c.input)?;
    let (p, _) = load_text_lowered(file.clone(), &text, c.configuration.as_deref())?;
    super::skipped::refuse_skipped(&p, &c.input, c.allow_skipped, Some("write the JSON"))?;
    let syntax = match format_of(&file, &text) {
        Format::Stl => stl::parse(&text),
        Format::PlcOpen => plc_load::plcopen_syntax(
            &text,
            super::io::Pick {
                pou: None,
                configuration: c.configuration.as_deref(),
            },
            true,
        ),
        Format::Json => json::parse(&text),
    }
    .map_err(|error| CliError::load(file.clone(), &text, error))?;
    write_output_with(c.output.as_deref(), |mut w| {
        plc_write::json::program(&syntax, &mut w)
    })
}
