//! `plc-deps run`: runs a program's scans on virtual time, sequentially, in parallel or both, and
//! reports the outputs of the last scan, the faults, the speed of each mode and (with both) whether
//! every scan's full state was identical. The format of the inputs, the trace and the JSON report
//! is documented in docs/scan.md.
//!
//! Everything is validated before the first scan (program, inputs, trace variables, arguments);
//! a problem is one [`CliError`] naming the file, line and column (exit code 2), and no output
//! file is written.
//!
//! With `--mode both` the sequential run and the parallel run are timed separately, one after the
//! other, each with nothing else in its timed region (inputs, tracing, checking and progress are
//! outside it). Every scan's full state (all slots in a layout-independent order: every variable,
//! instance internals, edge memories and loop counters) and its faults are condensed into a
//! 128-bit digest; the parallel run's digest of each scan is compared with the sequential one's.
//! On the first mismatch both runs are replayed in lockstep, exactly, up to that scan to name the
//! first difference (variable and both values).

mod compare;
mod engine;
mod inputs;
mod output;
mod progress;
mod trace;

pub use engine::RunReport;
pub use inputs::{load_inputs, parse_inputs_csv, parse_inputs_json, InputTable};
pub use output::{render_json, render_text, run_json_deterministic};
pub use progress::Progress;

use crate::app::{write_output, write_output_with, CliError};
use crate::exec::ExecConfig;
use crate::model::parse_time_literal;
use engine::{execute, prepare};
use std::io::IsTerminal;
use std::path::PathBuf;

/// Which executors `run` uses.
#[derive(Copy, Clone, Debug, PartialEq, Eq)]
pub enum RunMode {
    /// The sequential interpreter only.
    Seq,
    /// The parallel executor only.
    Par,
    /// Both, timed separately, every scan checked seq == par.
    Both,
}

/// Output format of `run`.
#[derive(Copy, Clone, Debug, PartialEq, Eq)]
pub enum RunFormat {
    Text,
    Json,
}

/// A validated `plc-deps run` invocation.
#[derive(Clone, Debug)]
pub struct RunConfig {
    /// The program file.
    pub input: PathBuf,
    /// Number of scans; `None`: the number of input rows (at least 1), or 1000 without inputs.
    pub scans: Option<u64>,
    /// Input values per scan (CSV or JSON, by extension: `.json` is JSON, anything else CSV).
    pub inputs: Option<PathBuf>,
    /// Virtual scan period, ms (at least 1).
    pub cycle_ms: u32,
    /// Workers of the parallel executor (at least 1).
    pub threads: usize,
    pub mode: RunMode,
    /// Write the chosen variables after every scan to this CSV file.
    pub trace: Option<PathBuf>,
    /// The traced variables (names or instance fields `T1.Q`); `None`: every variable.
    pub trace_vars: Option<Vec<String>>,
    pub format: RunFormat,
    /// Describe the parallel plan.
    pub explain: bool,
    /// Loop-backs per loop-back rung and scan.
    pub loop_cap: u32,
    /// Write the report here instead of standard output.
    pub output: Option<PathBuf>,
    /// Show a progress bar on standard error (when it is a terminal and the run takes > 1 s).
    pub progress: bool,
}

impl RunConfig {
    /// Defaults for a program file: all scans of the inputs (or 1000), 10 ms, one worker per
    /// core, both modes, text, progress on a terminal.
    pub fn new(input: impl Into<PathBuf>) -> RunConfig {
        RunConfig {
            input: input.into(),
            scans: None,
            inputs: None,
            cycle_ms: 10,
            threads: std::thread::available_parallelism().map_or(1, |n| n.get()),
            mode: RunMode::Both,
            trace: None,
            trace_vars: None,
            format: RunFormat::Text,
            explain: false,
            loop_cap: ExecConfig::default().loop_cap,
            output: None,
            progress: std::io::stderr().is_terminal(),
        }
    }
}

/// Parses `--cycle`: a TIME literal with or without its `T#` prefix (`10ms`, `T#1s`, `1.5s`),
/// positive and at most 24 days (32-bit milliseconds).
pub fn parse_cycle(s: &str) -> Result<u32, CliError> {
    let t = s.trim();
    let literal = if t.to_ascii_uppercase().starts_with("T#")
        || t.to_ascii_uppercase().starts_with("TIME#")
    {
        t.to_string()
    } else {
        format!("T#{t}")
    };
    match parse_time_literal(&literal) {
        Some(ms) if ms >= 1 && ms <= i32::MAX as i64 => Ok(ms as u32),
        Some(_) => Err(CliError::Usage(format!(
            "--cycle {s}: the cycle must be a positive TIME of at most T#24d (e.g. 10ms, T#1s)"
        ))),
        None => Err(CliError::Usage(format!(
            "--cycle {s}: not a TIME (e.g. 10ms, T#250ms, 1s)"
        ))),
    }
}

/// Checks and loads everything a run needs, runs it, and returns the report (the trace file, if
/// any, is written whole, or not at all).
pub fn run_report(c: &RunConfig) -> Result<RunReport, CliError> {
    let pr = prepare(c)?;
    match &c.trace {
        Some(path) => {
            let mut result = None;
            write_output_with(Some(path), |w| {
                let (r, err) = execute(&pr, c, Some(w));
                result = Some(r);
                err.map_or(Ok(()), Err)
            })?;
            Ok(result.expect("the run finished"))
        }
        None => Ok(execute(&pr, c, None).0),
    }
}

/// `plc-deps run`.
pub fn run(c: &RunConfig) -> Result<(), CliError> {
    let r = run_report(c)?;
    let out = match c.format {
        RunFormat::Text => render_text(&r),
        RunFormat::Json => render_json(&r, false),
    };
    write_output(c.output.as_deref(), &out)
}

#[cfg(test)]
mod tests {
    use super::*;
    #[test]
    fn cycles() {
        assert_eq!(parse_cycle("10ms").unwrap(), 10);
        assert_eq!(parse_cycle("T#1.5s").unwrap(), 1500);
        assert_eq!(parse_cycle("time#1m").unwrap(), 60_000);
        assert!(parse_cycle("10").is_err());
        assert!(parse_cycle("0ms").is_err());
        assert!(parse_cycle("-5ms").is_err());
        assert!(parse_cycle("T#25d").is_err());
    }
}
