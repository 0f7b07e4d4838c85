//! `plc-deps il FILE [-o OUT]`: the S7-200 STL of a program (`plc_codegen::il`), to standard
//! output or written atomically to OUT. A construct with no S7-200 instruction is one error
//! naming the file and the rung or block (exit code 2); nothing is written then.

use super::io::{check_output_path, load_program_for_c, write_output, CliError, FileRole};
use plc_codegen::il::generate;
use std::path::PathBuf;

/// A validated `plc-deps il` invocation.
#[derive(Clone, Debug)]
pub struct IlCommand {
    pub input: PathBuf,
    /// The configuration of a PLCopen project with several (`--configuration`); `None`: the
    /// first in file order.
    pub configuration: Option<String>,
    pub output: Option<PathBuf>,
}

/// `plc-deps il`: generates the STL and writes it.
pub fn il(cmd: &IlCommand) -> Result<(), CliError> {
    if let Some(out) = &cmd.output {
        check_output_path(out, FileRole::Output)?;
    }
    let (p, fbd) = load_program_for_c(&cmd.input, cmd.configuration.as_deref())?;
    super::skipped::refuse_skipped(&p, &cmd.input, false, None)?;
    let text = generate(&p, &fbd).map_err(|e| {
        let file = if cmd.input.as_os_str() == "-" {
            "<stdin>".to_string()
        } else {
            cmd.input.display().to_string()
        };
        CliError::Usage(format!("{file}: {e}"))
    })?;
    write_output(cmd.output.as_deref(), &text)
}
