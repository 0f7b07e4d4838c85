//! `plc-deps convert`: any program file the tool reads (a PLCopen TC6 XML export, or the JSON
//! format itself) written as the JSON program format (docs/format.md), through the surface
//! syntax: what plc-deps understood of the file, in a form to read, diff and edit.
//!
//! The file is loaded first (so a file that does not load is refused with its errors, exit 2,
//! and nothing is written), then read into the syntax and written ([`crate::write::json`]);
//! the output reads back to the same model.

use super::io::{load_text, read_program_text, write_output_with};
use super::CliError;
use crate::read::plcopen;
use std::path::PathBuf;

/// A validated `plc-deps convert` invocation.
#[derive(Clone, Debug)]
pub struct ConvertConfig {
    pub input: PathBuf,
    pub output: Option<PathBuf>,
}

/// `plc-deps convert`: the program as the JSON program format.
pub fn convert(c: &ConvertConfig) -> Result<(), CliError> {
    let (file, text) = read_program_text(&c.input)?;
    load_text(file.clone(), &text)?;
    let load_error = |error| CliError::load(file.clone(), &text, error);
    if plcopen::looks_like_xml(&text) {
        let (syntax, _) = plcopen::parse(&text).map_err(load_error)?;
        write_output_with(c.output.as_deref(), |mut w| {
            crate::write::json::program(&syntax, &mut w)
        })
    } else {
        let syntax = crate::read::json::parse(&text).map_err(load_error)?;
        write_output_with(c.output.as_deref(), |mut w| {
            crate::write::json::program(&syntax, &mut w)
        })
    }
}
