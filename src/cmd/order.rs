//! `plc-deps order`: each FBD network's execution order and conditional fragment tree, as
//! text, JSON or DOT (the renderers are in `plc_report::order`).

use super::io::{read_program_text, write_output};
use super::CliError;
use plc_model::Program;
use std::path::PathBuf;

/// Output format of `order` (`--format`: the variants are the command line's values).
#[derive(Copy, Clone, Debug, PartialEq, Eq, clap::ValueEnum)]
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
    /// The configuration of a PLCopen project with several (`--configuration`); `None`: the
    /// first in file order.
    pub configuration: Option<String>,
    pub output: Option<PathBuf>,
}

/// Renders the execution order and fragment trees of a program's FBD networks.
pub fn render_order(p: &Program, fbd: &plc_fbd::Fbd, format: OrderFormat) -> String {
    match format {
        OrderFormat::Text => plc_report::order::render_order_text(p, fbd),
        OrderFormat::Json => plc_report::order::render_order_json(p, fbd),
        OrderFormat::Dot => plc_report::order::render_order_dot(p, fbd),
    }
}

/// `plc-deps order`: each FBD network's execution order and fragment tree. A cycle of arcs or
/// a fragment-rule violation is a load error naming the blocks (exit code 2).
pub fn order(c: &OrderConfig) -> Result<(), CliError> {
    let (file, text) = read_program_text(&c.input)?;
    let pick = super::io::Pick {
        pou: None,
        configuration: c.configuration.as_deref(),
    };
    let (p, fbd) = super::io::load_text_selecting(file, &text, pick)?;
    write_output(c.output.as_deref(), &render_order(&p, &fbd, c.format))
}
