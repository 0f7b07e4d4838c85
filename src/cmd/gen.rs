//! `plc-deps gen`: a synthetic program (shape in docs/gen.md) for benchmarks and tests, written
//! to standard output or atomically to `-o`.

use super::io::write_output_with;
use super::CliError;
use plc_synth::{write_program, ConfigError, GenConfig, MAX_RUNGS};
use std::path::PathBuf;

/// A `plc-deps gen` invocation.
#[derive(Clone, Debug)]
pub struct GenCommand {
    pub config: GenConfig,
    /// `--levels L`: replaces `config.width` by `ceil(rungs / L)`.
    pub levels: Option<usize>,
    pub output: Option<PathBuf>,
}

/// `plc-deps gen`: checks the shape, then writes the program.
pub fn gen(c: &GenCommand) -> Result<(), CliError> {
    let mut config = c.config.clone();
    match c.levels {
        Some(0) => return Err(CliError::Usage("--levels must be at least 1".into())),
        Some(l) => config.width = config.rungs.div_ceil(l).max(1),
        None => {}
    }
    let c = &GenCommand {
        config,
        levels: None,
        output: c.output.clone(),
    };
    if c.config.width == 0 {
        return Err(CliError::Usage("--width must be at least 1".into()));
    }
    if let Err(e) = c.config.validate() {
        return Err(CliError::Usage(match e {
            ConfigError::NoRungs => {
                "--rungs must be at least 1 (a program has at least one rung)".into()
            }
            ConfigError::EmptyForBody => "--for-body must be at least 1".into(),
            ConfigError::TooManyRungs(n) => format!(
                "--rungs must be at most {MAX_RUNGS} (a larger program would pass the 2 GiB the readers read), not {n}"
            ),
            ConfigError::ForBodyTooLong(n) => format!(
                "--for-body must be at most {MAX_RUNGS} (the most rungs a program has), not {n}"
            ),
            ConfigError::HotFraction(f) => {
                format!("--hot-fraction must be in (0, 1] (a fraction of the rungs), not {f}")
            }
        }));
    }
    write_output_with(c.output.as_deref(), |w| write_program(&c.config, w))
}
