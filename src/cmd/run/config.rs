//! The `plc-deps run` invocation as data: modes, formats, the validated [`RunConfig`], the
//! warnings a run can give, and the small parsers and wordings every other part of the command
//! uses. The bottom of the command: it depends on nothing else in it.

use crate::cmd::io::CliError;
use plc_exec::parallel::PlanKind;
use plc_exec::ExecConfig;
use plc_model::parse_time_literal;
use std::io::IsTerminal;
use std::path::PathBuf;

/// Which executors `run` uses (`--mode`: the variants are the command line's values, their doc
/// comments not its help).
#[derive(Copy, Clone, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum RunMode {
    /// The sequential interpreter only.
    #[value(help = None::<&str>)]
    Seq,
    /// The parallel executor only.
    #[value(help = None::<&str>)]
    Par,
    /// Both, timed separately, every scan checked seq == par.
    #[value(help = None::<&str>)]
    Both,
}

/// Output format of `run` (`--format`: the variants are the command line's values, a variant's
/// doc comment its help).
#[derive(Copy, Clone, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum RunFormat {
    Text,
    Json,
    /// The report page of the program with the run's figures (docs/html.md).
    Html,
}

/// A validated `plc-deps run` invocation.
#[derive(Clone, Debug)]
pub struct RunConfig {
    /// The program file (`-`: standard input).
    pub input: PathBuf,
    /// Number of scans; `None`: the number of input rows (at least 1), or 1000 without inputs.
    pub scans: Option<u64>,
    /// Input values per scan (CSV or JSON, by extension: `.json` is JSON, anything else CSV).
    pub inputs: Option<PathBuf>,
    /// Virtual scan period, whole ms (at least 1).
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
    /// Which plans the parallel executor may use (default: measured, `auto`).
    pub plan: PlanKind,
    /// Loop-backs per loop-back rung and scan.
    pub loop_cap: u32,
    /// Rungs each task of a scan may charge (`--scan-budget`).
    pub scan_budget: u64,
    /// With both modes, the scans of each one's turn (`--alternate`); `None`: about 20 ms of
    /// the sequential walk's scans, and at least a 64th of the run.
    pub alternate: Option<u64>,
    /// Write the report here instead of standard output.
    pub output: Option<PathBuf>,
    /// Show progress on standard error (default: when it is a terminal); a phase appears once it
    /// has taken half a second.
    pub progress: bool,
    /// The program of a PLCopen project to run (`--pou`); `None`: every program instance, in
    /// task order.
    pub program: Option<String>,
    /// The configuration of a PLCopen project with several (`--configuration`); `None`: the
    /// first in file order.
    pub configuration: Option<String>,
    /// `--allow-skipped`: run a project whose ST, IL or SFC bodies are not executed (the
    /// report lists them); false: such a project is refused.
    pub allow_skipped: bool,
    /// `--dialect`: whose rules to follow where toolchains differ (docs/dialects.md);
    /// `None`: the file's (its editor's for PLCopen, IEC for JSON and STL).
    pub dialect: Option<plc_model::Dialect>,
    /// Measure the cost of a moved cache line before planning (a few ms; default on), instead
    /// of the built-in default.
    pub calibrate: bool,
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
            plan: PlanKind::Auto,
            loop_cap: ExecConfig::default().loop_cap,
            scan_budget: ExecConfig::default().scan_budget,
            alternate: None,
            output: None,
            progress: std::io::stderr().is_terminal(),
            calibrate: true,
            program: None,
            configuration: None,
            allow_skipped: false,
            dialect: None,
        }
    }
}

/// Something the user should know about a run that still runs (printed as `warning[W01xx]: …`).
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
pub enum RunWarning {
    /// More `--threads` than cores: the plan is made for the cores that exist.
    #[error(
        "--threads {threads} is more than the {cores} {} of this machine: planning for {cores} {}",
        if *cores == 1 { "core" } else { "cores" },
        if *cores == 1 { "worker" } else { "workers" }
    )]
    Oversubscribed { threads: usize, cores: usize },
    /// What the planner says of the parallel plan: it failed its check against the lowered code
    /// and is not used, a forced plan (`--plan par|exchange`) is modelled slower than the
    /// sequential walk, or the exchange plan runs on the shared state.
    #[error("{0}")]
    Plan(String),
    /// The `--inputs` file has no rows: every input keeps its initial value.
    #[error(
        "--inputs {file} has no rows: every input keeps its initial value{}",
        if *scans_given { String::new() } else {
            format!("; running {} (give --scans N for more)", count(*scans, "scan", "scans"))
        }
    )]
    NoInputRows {
        file: String,
        scans: u64,
        scans_given: bool,
    },
    /// The program has an interrupt routine, which the scans never run.
    #[error("interrupt routine {0} never runs here: plc-deps run raises no interrupt events (`plc-deps report` lists what it shares with the main program)")]
    InterruptNotRun(String),
    /// An option given that the run does not use (`--plan` with `--mode seq`, `--alternate`
    /// unless both modes run).
    #[error("{option} has no effect {why}")]
    Unused { option: String, why: &'static str },
}

impl RunWarning {
    /// The stable code of this warning (docs/diagnostics.md).
    pub fn code(&self) -> &'static str {
        match self {
            RunWarning::Oversubscribed { .. } => "W0101",
            RunWarning::Plan(_) => "W0102",
            RunWarning::NoInputRows { .. } => "W0103",
            RunWarning::InterruptNotRun(_) => "W0104",
            RunWarning::Unused { .. } => "W0105",
        }
    }
}

/// `n` and the noun in the singular or plural (`1 scan`, `2 scans`).
pub(crate) fn count(n: u64, one: &str, many: &str) -> String {
    format!("{n} {}", if n == 1 { one } else { many })
}

/// Why a TIME text is refused: not a TIME at all, or not a whole number of milliseconds (the
/// two reasons `parse_time_literal` refuses one; with every digit made 0 the second parses).
pub(crate) fn time_refusal(literal: &str) -> &'static str {
    let zeroed: String = literal
        .chars()
        .map(|c| if c.is_ascii_digit() { '0' } else { c })
        .collect();
    if parse_time_literal(&zeroed).is_some() {
        "not a whole number of milliseconds (TIME counts milliseconds)"
    } else {
        "not a TIME"
    }
}

/// Parses `--cycle`: a TIME literal with or without its `T#` prefix (`10ms`, `T#1s`, `1.5s`),
/// a whole number of milliseconds, positive and at most 24 days (32-bit milliseconds).
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
            "--cycle {s}: {} (e.g. 10ms, T#250ms, 1s)",
            time_refusal(&literal)
        ))),
    }
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
        assert_eq!(
            parse_cycle("0.5ms").unwrap_err().to_string(),
            "--cycle 0.5ms: not a whole number of milliseconds (TIME counts milliseconds) \
             (e.g. 10ms, T#250ms, 1s)"
        );
        assert_eq!(
            parse_cycle("fast").unwrap_err().to_string(),
            "--cycle fast: not a TIME (e.g. 10ms, T#250ms, 1s)"
        );
    }
}
