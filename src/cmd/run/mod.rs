//! `plc-deps run`: runs a program's scans on virtual time, sequentially, in parallel or both, and
//! reports the outputs of the last scan, the faults, the speed of each mode and (with both) whether
//! every scan's full state was identical. The format of the inputs, the trace and the JSON report
//! is documented in docs/scan.md.
//!
//! Everything is validated before the first scan (arguments, the `-o` and `--trace` paths,
//! program, inputs, trace variables); a problem is one [`CliError`] naming the file, line and
//! column (exit code 2), and no output file is written. Warnings ([`RunWarning`]) are data,
//! printed by [`run`] on standard error before the first scan; progress ([`Progress`]) is shown
//! on standard error when it is a terminal.
//!
//! With `--mode both` the sequential run and the parallel run are timed separately, one after the
//! other, each with nothing else in its timed region (inputs, tracing, checking and progress are
//! outside it). Every scan's full state (all slots in a layout-independent order: every variable,
//! instance internals, edge memories and loop counters) and its faults are condensed into a
//! 128-bit digest; the parallel run's digest of each scan is compared with the sequential one's.
//! On the first mismatch both runs are replayed in lockstep, exactly, up to that scan to name the
//! first difference (variable and both values).
//!
//! # Modules, bottom to top
//! Each uses only the ones before it (checked by tests/it/par_layers.rs): `config` (the
//! arguments and warnings), `trace` (the trace file's columns), `inputs` (the input table),
//! `compare` (digests and the lockstep replay to the first difference), `engine` (preparing
//! and running the scans), `output` (the text, JSON and HTML renderings of a report), then this
//! module (declared alphabetically below: rustfmt sorts them).
mod bookkeeping;
mod compare;
mod config;
mod engine;
mod inputs;
mod output;
mod trace;

pub use crate::cmd::progress::Progress;
pub use config::{parse_cycle, RunConfig, RunFormat, RunMode, RunWarning};
pub use engine::{FaultSummary, RunReport};
pub use inputs::{load_inputs, parse_inputs_csv, parse_inputs_json, InputTable};
pub use output::{render_json, render_text, run_figures, write_html};

use crate::cmd::io::{write_file_as, write_output, write_output_with, CliError, FileRole};
use engine::{execute, prepare, Prepared};

/// Checks and loads everything a run needs, runs it, and returns the report (the trace file, if
/// any, is written whole, or not at all). Quiet: no progress, warnings dropped.
pub fn run_report(c: &RunConfig) -> Result<RunReport, CliError> {
    run_report_with(c, &Progress::new(false), &mut |_| {})
}

/// [`run_report`] with progress, and `warn` called with each warning before the first scan.
pub fn run_report_with(
    c: &RunConfig,
    progress: &Progress,
    warn: &mut dyn FnMut(&RunWarning),
) -> Result<RunReport, CliError> {
    run_kept(c, progress, warn).map(|(_, r)| r)
}

/// [`run_report_with`], keeping what was prepared (the HTML page draws the program).
fn run_kept(
    c: &RunConfig,
    progress: &Progress,
    warn: &mut dyn FnMut(&RunWarning),
) -> Result<(Prepared, RunReport), CliError> {
    let pr = prepare(c, progress)?;
    for w in &pr.warnings {
        warn(w);
    }
    match &c.trace {
        Some(path) => {
            let mut result = None;
            write_file_as(path, FileRole::Trace, |w| {
                let (r, err) = execute(&pr, c, Some(w), progress);
                result = Some(r);
                err.map_or(Ok(()), Err)
            })?;
            let r = result.expect("the run finished");
            Ok((pr, r))
        }
        None => {
            let r = execute(&pr, c, None, progress).0;
            Ok((pr, r))
        }
    }
}

/// `plc-deps run`: warnings on standard error, the report on standard output or `-o`; then,
/// if the run faulted or its modes differed, a [`CliError::Run`] (exit code 1) saying so.
pub fn run(c: &RunConfig) -> Result<(), CliError> {
    let progress = Progress::new(c.progress);
    let (pr, r) = run_kept(c, &progress, &mut |w| {
        crate::cmd::errors::warn(&plc_diag::Shown::unplaced(
            plc_diag::Severity::Warning,
            w.code(),
            w.to_string(),
        ))
    })?;
    match c.format {
        RunFormat::Text => write_output(c.output.as_deref(), &render_text(&r))?,
        RunFormat::Json => write_output(c.output.as_deref(), &render_json(&r, false))?,
        RunFormat::Html => {
            let (p, a, fbd) = pr.page_parts().expect("prepared for the HTML page");
            let _phase = progress.phase("writing the page");
            write_output_with(c.output.as_deref(), |w| {
                write_html(p, a, fbd, &r, &pr.warnings, w)
            })?
        }
    }
    match failure(&r) {
        Some(why) => Err(CliError::Run(why)),
        None => Ok(()),
    }
}

/// Why a run that ran failed: its sequential and parallel runs differed (`identical` false),
/// or a scan faulted (any fault: a DIV or MOD by zero, a loop-back past the cap); none for a
/// clean run.
pub fn failure(r: &RunReport) -> Option<String> {
    if r.identical == Some(false) {
        let at = r
            .first_difference
            .as_ref()
            .and_then(|d| Some((d.get("scan")?.as_u64()?, d.get("variable")?.as_str()?)));
        return Some(match at {
            Some((scan, var)) => format!(
                "the sequential and parallel runs differ (first in scan {scan}, variable {var}; first_difference in the report)"
            ),
            None => "the sequential and parallel runs differ (first_difference in the report)".into(),
        });
    }
    let first = r.fault_summary.first()?;
    Some(format!(
        "the run faulted: {} (first: {} on rung {} in scan {}; faults in the report)",
        config::count(r.fault_count, "fault", "faults"),
        first.kind.name(),
        first.rung,
        first.first_scan
    ))
}

/// The deterministic JSON of a run (timing fields zero; the default line cost, not a measured
/// one): what `analyses/*/run.json` holds.
pub fn run_json_deterministic(c: &RunConfig) -> Result<String, CliError> {
    let c = RunConfig {
        progress: false,
        trace: None,
        calibrate: false,
        ..c.clone()
    };
    Ok(render_json(&run_report(&c)?, true))
}
