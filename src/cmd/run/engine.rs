//! The run itself: everything validated before the first scan (arguments, output and trace
//! paths, program, inputs, trace variables), then the warm-up and the timed sequential and
//! parallel passes, with the per-scan bookkeeping (digests, faults and their summary, trace,
//! progress) and the report they add up to. It prints nothing: warnings are returned as data.

use super::bookkeeping::{Digests, Driver, FaultTally, Inputs, TurnDigests};
use super::compare::first_difference;
use super::config::{RunConfig, RunFormat, RunMode, RunWarning};
use super::inputs::{load_inputs, InputTable};
use super::trace::{trace_columns, Trace};
use crate::cmd::io::{check_output_path, load_program_for_run_selecting, CliError, FileRole, Pick};
use crate::cmd::progress::Progress;
use plc_analysis::{analyse, Analysis};
use plc_exec::parallel::{
    run_sequential, Candidate, ParallelMachine, PlanConfig, PlanKind, RunLog,
};
use plc_exec::{ExecConfig, FaultKind, Layout, Machine, State, VarValue};
use plc_fbd::Fbd;
use plc_model::{PouKind, Program, ProgramRun, Type, VarClass, VarId, VarRef};
use plc_report::configuration::configuration_entry;
use serde_json::Value as Json;
use std::io::Write;
use std::time::{Duration, Instant};

/// What a run found.
#[derive(Clone, Debug)]
pub struct RunReport {
    pub program: String,
    /// The POUs whose bodies were not executed (`--allow-skipped`), in POU order.
    pub skipped: Vec<crate::cmd::skipped::SkippedPou>,
    pub scans: u64,
    pub cycle_ms: u32,
    pub threads: usize,
    /// Workers the parallel executor was planned for: `threads`, at most the cores.
    pub workers: usize,
    /// Main-program rungs (for the rung-execution rate).
    pub rungs: usize,
    /// Output variables after the last scan.
    pub outputs: Vec<(String, VarValue)>,
    /// Every variable but the hidden edge memories, after the last scan.
    pub state: Vec<(String, VarValue)>,
    /// The first faults (at most 1000) and the total.
    pub faults: Vec<(u64, String, FaultKind)>,
    pub fault_count: u64,
    /// Every distinct fault (rung and kind), in the order of their first occurrence.
    pub fault_summary: Vec<FaultSummary>,
    /// Per mode: (name, total scan time).
    pub modes: Vec<(&'static str, Duration)>,
    /// Per mode, as `modes`: the ns per scan of each of its timing windows (a pass's scans in
    /// up to 8 equal windows; none when it ran fewer than 8 scans).
    pub windows: Vec<Vec<f64>>,
    /// Which plans the parallel executor could use.
    pub plan_kind: PlanKind,
    /// What the parallel pass ran (when it ran).
    pub plan_run: Option<RunLog>,
    /// `Some(why)` when every scan of the parallel pass was the sequential walk.
    pub sequential_fallback: Option<String>,
    /// When both modes ran: the scans of each one's turn (they alternate in blocks of this
    /// many scans, the last maybe shorter, so that a change of the machine's speed hits both).
    pub block_scans: Option<u64>,
    /// `Some` when both modes ran.
    pub identical: Option<bool>,
    pub first_difference: Option<Json>,
    /// The parallel plan (text, JSON) when asked for.
    pub explain: Option<(String, Json)>,
    /// The program instances of the configuration that each scan runs, in run order (none
    /// without a configuration), and how many instances the configuration has in all (more
    /// than run when `--pou` selected one program).
    pub instances: Vec<ProgramRun>,
    pub configured_instances: usize,
}

/// One distinct fault of a run: a rung and a kind, how often, and the first and last scan.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct FaultSummary {
    pub rung: String,
    pub kind: FaultKind,
    pub count: u64,
    pub first_scan: u64,
    pub last_scan: u64,
}

/// The options given that this run does not use: `--plan` (other than the default) when only
/// the sequential walk runs and nothing is explained, `--alternate` unless both modes run.
fn unused_options(c: &RunConfig) -> Vec<RunWarning> {
    let mut out = Vec::new();
    if c.mode == RunMode::Seq && c.plan != PlanKind::Auto && !c.explain {
        out.push(RunWarning::Unused {
            option: format!("--plan {}", c.plan.name()),
            why: "with --mode seq: only the sequential walk runs (give --mode par or both)",
        });
    }
    if let Some(n) = c.alternate.filter(|_| c.mode != RunMode::Both) {
        out.push(RunWarning::Unused {
            option: format!("--alternate {n}"),
            why: "unless both modes run (--mode both): it sets the scans of each one's turn",
        });
    }
    out
}

/// Untimed warm-up scans before each timed pass.
const WARM_UP: u64 = 16;

/// With both modes, each takes turns of at least this long (by the sequential warm-up's time
/// per scan) ...
const BLOCK_TIME: Duration = Duration::from_millis(20);
/// ... and the run is cut into at most this many turns of each.
const BLOCKS_MAX: u64 = 64;

/// The scans of each mode's turn when both run: `alternate` (`--alternate N`) if given, else as
/// many as take [`BLOCK_TIME`] on the sequential walk (`warm_time` over `warm` scans) and no
/// fewer than a [`BLOCKS_MAX`]-th of the run; never more than the run (a run shorter than a
/// turn is one turn of each) nor fewer than 1. A turn costs the parallel pass a wake-up of its
/// workers and both passes cold caches for a scan, a few tens of µs: under 0.5 % of a turn of
/// 20 ms.
fn turn_scans(alternate: Option<u64>, warm_time: Duration, warm: u64, scans: u64) -> u64 {
    let by_default = || {
        let per_scan = warm_time.as_nanos() / u128::from(warm.max(1));
        let by_time = (BLOCK_TIME.as_nanos() / per_scan.max(1)).max(1);
        let by_count = scans.div_ceil(BLOCKS_MAX);
        u64::try_from(by_time).unwrap_or(u64::MAX).max(by_count)
    };
    alternate.unwrap_or_else(by_default).clamp(1, scans.max(1))
}

/// Everything a run needs, checked: nothing after this fails but writing the trace.
pub(super) struct Prepared {
    p: Program,
    inputs: InputTable,
    scans: u64,
    seq: Option<Machine>,
    par: Option<ParallelMachine>,
    pool: Option<rayon::ThreadPool>,
    workers: usize,
    trace_cols: Option<Vec<(String, VarRef, Type)>>,
    /// For the HTML page only (kept only then): the analysis and the FBD bodies as written.
    page: Option<(Analysis, Fbd)>,
    /// What the user should know before the run starts.
    pub(super) warnings: Vec<RunWarning>,
}

impl Prepared {
    /// What the HTML page draws besides the run: the program, its analysis and its FBD bodies
    /// (`None` unless the format is HTML).
    pub(super) fn page_parts(&self) -> Option<(&Program, &Analysis, &Fbd)> {
        self.page.as_ref().map(|(a, f)| (&self.p, a, f))
    }
}

/// Checks the arguments alone, before any file is touched.
fn check_arguments(c: &RunConfig) -> Result<(), CliError> {
    if c.threads == 0 {
        return Err(CliError::Usage("--threads must be at least 1".into()));
    }
    if c.cycle_ms == 0 {
        return Err(CliError::Usage("--cycle must be positive".into()));
    }
    if c.scans == Some(0) {
        return Err(CliError::Usage("--scans must be at least 1".into()));
    }
    if c.alternate == Some(0) {
        return Err(CliError::Usage("--alternate must be at least 1".into()));
    }
    if c.trace_vars.is_some() && c.trace.is_none() {
        return Err(CliError::Usage(
            "--trace-vars chooses the columns of the trace file: give --trace FILE too".into(),
        ));
    }
    if c.input.as_os_str() == "-" && c.inputs.as_ref().is_some_and(|i| i.as_os_str() == "-") {
        return Err(CliError::Usage(
            "the program and --inputs cannot both be read from standard input (-)".into(),
        ));
    }
    if let (Some(o), Some(t)) = (&c.output, &c.trace) {
        if o == t {
            return Err(CliError::Usage(format!(
                "-o and --trace name the same file {}",
                o.display()
            )));
        }
    }
    Ok(())
}

pub(super) fn prepare(c: &RunConfig, progress: &Progress) -> Result<Prepared, CliError> {
    check_arguments(c)?;
    if let Some(o) = &c.output {
        check_output_path(o, FileRole::Output)?;
    }
    if let Some(t) = &c.trace {
        check_output_path(t, FileRole::Trace)?;
    }
    let (mut p, fbd) = {
        let _phase = progress.phase(&format!("reading {}", c.input.display()));
        load_program_for_run_selecting(
            &c.input,
            Pick {
                pou: c.program.as_deref(),
                configuration: c.configuration.as_deref(),
            },
        )?
    };
    if let Some(d) = c.dialect {
        p.set_dialect(d);
    }
    let what = Some("run the rest of the project");
    crate::cmd::skipped::refuse_skipped(&p, &c.input, c.allow_skipped, what)?;
    let mut warnings: Vec<RunWarning> = p
        .pous()
        .iter()
        .filter(|pou| pou.kind == PouKind::Interrupt)
        .map(|pou| RunWarning::InterruptNotRun(pou.name.clone()))
        .collect();
    let inputs = match &c.inputs {
        Some(path) => {
            let _phase = progress.phase(&format!("reading {}", path.display()));
            load_inputs(&p, path)?
        }
        None => InputTable::default(),
    };
    let scans = c.scans.unwrap_or(if c.inputs.is_some() {
        inputs.rows.len().max(1) as u64
    } else {
        1000
    });
    if let (Some(path), true) = (&c.inputs, inputs.rows.is_empty()) {
        warnings.push(RunWarning::NoInputRows {
            file: path.display().to_string(),
            scans,
            scans_given: c.scans.is_some(),
        });
    }
    let trace_cols = match &c.trace {
        Some(_) => Some(trace_columns(&p, c.trace_vars.as_deref())?),
        None => None,
    };
    let _phase = progress.phase("preparing the executors");
    let exec = ExecConfig {
        cycle_ms: c.cycle_ms,
        loop_cap: c.loop_cap,
        scan_budget: c.scan_budget,
    };
    let lower_error =
        |e: plc_exec::LowerError| CliError::Usage(format!("{}: {e}", c.input.display()));
    let seq = if c.mode != RunMode::Par {
        Some(Machine::new(&p, Layout::dense(&p), &exec).map_err(lower_error)?)
    } else {
        None
    };
    let cores = std::thread::available_parallelism().map_or(1, |n| n.get());
    let workers = c.threads.min(cores);
    if c.threads > cores && c.mode != RunMode::Seq {
        warnings.push(RunWarning::Oversubscribed {
            threads: c.threads,
            cores,
        });
    }
    warnings.extend(unused_options(c));
    let html = c.format == RunFormat::Html;
    let needs_par = c.mode != RunMode::Seq || c.explain;
    let analysis = (needs_par || html).then(|| analyse(&p));
    // The inputs the program writes get their image copied in before every scan (W0208).
    let inputs = inputs.with_image(&p, p.written_inputs());
    let par = if let (true, Some(a)) = (needs_par, &analysis) {
        Some(
            ParallelMachine::new(
                &p,
                a,
                &exec,
                &PlanConfig {
                    kind: c.plan,
                    ..if c.calibrate && c.plan != PlanKind::Seq {
                        PlanConfig::new(workers).calibrated()
                    } else {
                        PlanConfig::new(workers)
                    }
                },
            )
            .map_err(lower_error)?,
        )
    } else {
        None
    };
    if let Some(pm) = &par {
        warnings.extend(pm.warnings().iter().cloned().map(RunWarning::Plan));
    }
    let pool = match &par {
        Some(pm)
            if c.mode != RunMode::Seq
                && workers > 1
                && pm
                    .candidates()
                    .iter()
                    .any(|k| matches!(k, Candidate::Levelled(_) | Candidate::Exchange(_))) =>
        {
            Some(
                rayon::ThreadPoolBuilder::new()
                    .num_threads(workers - 1)
                    .thread_name(|i| format!("plc-worker-{}", i + 1))
                    .build()
                    .map_err(|e| CliError::Threads(e.to_string()))?,
            )
        }
        _ => None,
    };
    Ok(Prepared {
        p,
        inputs,
        scans,
        seq,
        par,
        pool,
        workers,
        trace_cols,
        page: analysis.filter(|_| html).map(|a| (a, fbd)),
        warnings,
    })
}

/// How many windows a pass's scans are timed in, for the spread of the measurement.
const TIMING_WINDOWS: u64 = 8;

/// What one pass (one mode) leaves for the report.
struct Pass {
    total: Duration,
    /// ns per scan of each timing window.
    window_ns: Vec<f64>,
    first_mismatch: Option<u64>,
    faults: Vec<(u64, u32, FaultKind)>,
    fault_count: u64,
    tally: FaultTally,
    trace_error: Option<std::io::Error>,
    state: State,
    /// What the parallel executor ran.
    log: Option<RunLog>,
}

impl Pass {
    fn of(d: Driver<'_>, state: State, log: Option<RunLog>) -> Pass {
        Pass {
            total: d.total,
            window_ns: d
                .windows
                .iter()
                .map(|w| w.as_nanos() as f64 / d.window_scans as f64)
                .collect(),
            first_mismatch: d.first_mismatch,
            faults: d.faults,
            fault_count: d.fault_count,
            tally: d.tally,
            trace_error: d.trace.and_then(|t| t.error),
            state,
            log,
        }
    }
}

/// Runs the prepared scans; `trace` receives the trace CSV (from the sequential run, or from the
/// parallel one when it runs alone).
pub(super) fn execute(
    pr: &Prepared,
    c: &RunConfig,
    trace: Option<&mut dyn Write>,
    progress: &Progress,
) -> (RunReport, Option<std::io::Error>) {
    let (inputs, scans) = (&pr.inputs, pr.scans);
    // The parallel machine may exist only for --explain.
    let run_par = if c.mode == RunMode::Seq {
        None
    } else {
        pr.par.as_ref()
    };
    let mut trace = trace;
    // Untimed warm-up scans on a throwaway state before each timed pass, so that neither mode
    // pays for cold caches and branch predictors (or for the other mode's warm ones); the
    // sequential one also says how long a scan takes, for the turns below.
    let warm = scans.min(WARM_UP);
    let mut seq_warm = Duration::ZERO;
    let mut seq = pr.seq.as_ref().map(|m| {
        {
            let _phase = progress.phase("seq: warm-up scans");
            let mut st = m.initial_state();
            let t = Instant::now();
            run_sequential(m, &mut st, 0..warm, &mut Inputs(inputs));
            seq_warm = t.elapsed();
        }
        let t = match (&pr.trace_cols, trace.take()) {
            (Some(cols), Some(out)) => Some(Trace::new(m, cols, out)),
            _ => None,
        };
        let bar = progress.bar("seq", scans, "scans");
        let digests = match run_par {
            Some(_) => Digests::Record(TurnDigests::default()),
            None => Digests::Skip,
        };
        (
            m,
            Driver::new(inputs, m, digests, t, bar, scans / TIMING_WINDOWS),
            m.initial_state(),
        )
    });
    let mut par = run_par.map(|pm| {
        {
            let _phase = progress.phase("par: warm-up scans");
            let mut st = pm.initial_state();
            pm.run(pr.pool.as_ref(), &mut st, 0..warm, &mut Inputs(inputs));
        }
        let m = pm.machine();
        let t = match (&pr.trace_cols, trace.take()) {
            (Some(cols), Some(out)) => Some(Trace::new(m, cols, out)),
            _ => None,
        };
        let digests = match seq {
            Some(_) => Digests::Check(TurnDigests::default()),
            None => Digests::Skip,
        };
        let bar = progress.bar("par", scans, "scans");
        let d = Driver::new(inputs, m, digests, t, bar, scans / TIMING_WINDOWS);
        (pm, d, pm.initial_state(), pm.start_run(0))
    });
    // The two passes take turns, block by block, so that a change of the machine's speed
    // during the run (another process, the host) hits both alike; the parallel pass goes on
    // with one measured choice across its turns.
    let block = match (&seq, &par) {
        (Some(_), Some(_)) => turn_scans(c.alternate, seq_warm, warm, scans),
        _ => scans.max(1),
    };
    let mut at = 0;
    while at < scans {
        let end = scans.min(at.saturating_add(block));
        if let Some((m, d, st)) = &mut seq {
            if let Digests::Record(ds) = &mut d.digests {
                ds.start_turn(end - at);
            }
            run_sequential(m, st, at..end, d);
            // The turn's digests move to the parallel pass, which checks them chunk by chunk.
            if let (Digests::Record(ds), Some((_, pd, ..))) = (&mut d.digests, &mut par) {
                if ds.in_acc > 0 {
                    let last = ds.take();
                    ds.chunks.push(last);
                }
                if let Digests::Check(check) = &mut pd.digests {
                    check.start_turn(end - at);
                    std::mem::swap(&mut check.chunks, &mut ds.chunks);
                }
            }
        }
        if let Some((pm, d, st, run)) = &mut par {
            pm.run_more(pr.pool.as_ref(), st, run, end, d);
            if let Digests::Check(ds) = &mut d.digests {
                if ds.in_acc > 0 {
                    let last = ds.take();
                    if !ds.matches(last) && d.first_mismatch.is_none() {
                        d.first_mismatch = Some(end - 1);
                    }
                }
            }
        }
        at = end;
    }
    let seq = seq.map(|(_, d, st)| Pass::of(d, st, None));
    let par = par.map(|(_, d, st, run)| Pass::of(d, st, Some(run.into_log())));
    let (identical, first_difference) = match (&pr.seq, run_par, &par) {
        (Some(s), Some(pm), Some(pass)) => match pass.first_mismatch {
            None => (Some(true), None),
            Some(k) => {
                let _phase = progress.phase("replaying both modes to the first difference");
                (
                    Some(false),
                    Some(self::first_difference(
                        &pr.p,
                        s,
                        pm,
                        pr.pool.as_ref(),
                        pass.log.as_ref().expect("the parallel pass logs its plans"),
                        inputs,
                        k,
                    )),
                )
            }
        },
        _ => (None, None),
    };
    let plan_run = par.as_ref().and_then(|p| p.log.clone());
    let mut modes = Vec::new();
    modes.extend(seq.as_ref().map(|s| ("seq", s.total)));
    modes.extend(par.as_ref().map(|p| ("par", p.total)));
    let windows: Vec<Vec<f64>> = seq
        .iter()
        .chain(par.iter())
        .map(|p| p.window_ns.clone())
        .collect();
    // The report (faults, trace, state) comes from the sequential run when it ran.
    let (pass, m) = match (seq, par) {
        (Some(s), _) => (s, pr.seq.as_ref().expect("seq")),
        (None, Some(p)) => (p, pr.par.as_ref().expect("par").machine()),
        (None, None) => unreachable!("one mode ran"),
    };
    let explain = if c.explain {
        pr.par.as_ref().map(|pm| {
            let (mut text, mut json) = (pm.explain(&pr.p), pm.explain_json());
            if let Some(log) = &plan_run {
                text.push('\n');
                text.push_str(&pm.explain_run(log));
                json["run"] = plc_exec::parallel::run_log_json(log, false);
            }
            (text, json)
        })
    } else {
        None
    };
    let sequential_fallback = match (run_par, &plan_run) {
        (Some(pm), Some(log)) => fallback_reason(pm, log),
        _ => None,
    };
    let both = modes.len() == 2;
    let extra = Extra {
        modes,
        windows,
        block_scans: both.then_some(block),
        identical,
        first_difference,
        explain,
        plan_run,
        sequential_fallback,
    };
    let mut pass = pass;
    let trace_error = pass.trace_error.take();
    (report(pr, c, m, pass, extra), trace_error)
}

/// What the report adds to the pass it shows.
struct Extra {
    modes: Vec<(&'static str, Duration)>,
    windows: Vec<Vec<f64>>,
    block_scans: Option<u64>,
    identical: Option<bool>,
    first_difference: Option<Json>,
    explain: Option<(String, Json)>,
    plan_run: Option<RunLog>,
    sequential_fallback: Option<String>,
}

/// `Some(why)` when every scan of the parallel pass ran the sequential walk.
fn fallback_reason(pm: &ParallelMachine, log: &RunLog) -> Option<String> {
    let parallel_scans: u64 = (0..log.candidates.len())
        .filter(|&i| !pm.is_sequential(i))
        .map(|i| log.scans_on[i])
        .sum();
    if parallel_scans > 0 {
        return None;
    }
    Some(match pm.sequential_reason() {
        Some(why) => why.to_string(),
        None => {
            let times: Vec<String> = log
                .candidates
                .iter()
                .zip(&log.estimates)
                .filter_map(|(n, e)| e.map(|ns| format!("{n} {ns} ns")))
                .collect();
            format!(
                "measured per scan: {}; the sequential walk was fastest",
                times.join(", ")
            )
        }
    })
}

/// The report of a run from the pass it shows.
fn report(pr: &Prepared, c: &RunConfig, m: &Machine, pass: Pass, extra: Extra) -> RunReport {
    let p = &pr.p;
    let Extra {
        modes,
        windows,
        block_scans,
        identical,
        first_difference,
        explain,
        plan_run,
        sequential_fallback,
    } = extra;
    let slots = pass.state.bytes();
    let visible: Vec<VarId> = p.vars().ids().filter(|&v| !p.var(v).hidden).collect();
    let state: Vec<(String, VarValue)> = visible
        .iter()
        .map(|&v| (p.var(v).name.clone(), m.value_in(slots, v)))
        .collect();
    let outputs = visible
        .iter()
        .filter(|&&v| p.var(v).class == VarClass::Output)
        .map(|&v| (p.var(v).name.clone(), m.value_in(slots, v)))
        .collect();
    let rung_id = |r: u32| p.rungs()[r as usize].id.clone();
    RunReport {
        program: p.name().to_owned(),
        skipped: crate::cmd::skipped::skipped_pous(p),
        instances: p.program_runs(),
        configured_instances: p
            .configuration()
            .as_ref()
            .map_or(0, |c| configuration_entry(c).instance_count()),
        scans: pr.scans,
        cycle_ms: c.cycle_ms,
        threads: c.threads,
        workers: pr.workers,
        rungs: p.main().rungs.len(),
        outputs,
        state,
        faults: pass
            .faults
            .into_iter()
            .map(|(s, r, k)| (s, rung_id(r), k))
            .collect(),
        fault_count: pass.fault_count,
        fault_summary: pass
            .tally
            .rows
            .into_iter()
            .map(|(r, kind, count, first_scan, last_scan)| FaultSummary {
                rung: rung_id(r),
                kind,
                count,
                first_scan,
                last_scan,
            })
            .collect(),
        modes,
        windows,
        plan_kind: c.plan,
        plan_run,
        sequential_fallback,
        block_scans,
        identical,
        first_difference,
        explain,
    }
}

#[cfg(test)]
mod tests {
    use super::super::bookkeeping::{TurnDigests, DIGESTS_KEPT};
    use super::turn_scans;
    use std::time::Duration;

    #[test]
    fn a_turn_is_about_twenty_ms_of_the_sequential_walk_within_the_run() {
        let us = Duration::from_micros;
        // 100 µs a scan (10 warm-up scans in 1 ms): 200 scans make 20 ms.
        assert_eq!(turn_scans(None, us(1_000), 10, 10_000), 200);
        // ... but never fewer than a 64th of the run: 1,000,000 / 64.
        assert_eq!(turn_scans(None, us(1_000), 10, 1_000_000), 15_625);
        // 0.4 µs a scan would make 50,000 scans a turn: a run of 1,000 is one turn.
        assert_eq!(turn_scans(None, us(4), 10, 1_000), 1_000);
        // No scans, or a zero warm-up: still a positive turn.
        assert_eq!(turn_scans(None, Duration::ZERO, 0, 0), 1);
        // --alternate N is taken as it is, within the run.
        assert_eq!(turn_scans(Some(7), us(1_000), 10, 10_000), 7);
        assert_eq!(turn_scans(Some(5_000), us(1_000), 10, 1_000), 1_000);
    }

    #[test]
    fn a_turn_keeps_at_most_digests_kept_whatever_its_length() {
        for scans in [1u64, 4096, 4097, 1_000_000, 1 << 32] {
            let (mut rec, mut check) = (TurnDigests::default(), TurnDigests::default());
            rec.start_turn(scans);
            // Feed the first million scans (or all): the chunks recorded so far stay within
            // the bound, and a whole turn of `scans` would end at exactly the bound or less.
            let fed = scans.min(1_000_000);
            for k in 0..fed {
                if let Some(c) = rec.fold(u128::from(k) * 7 + 1) {
                    rec.chunks.push(c);
                }
            }
            assert!(rec.chunks.len() as u64 <= DIGESTS_KEPT, "{scans}");
            assert_eq!(rec.chunks.len() as u64, fed / rec.per, "{scans}");
            assert!(scans.div_ceil(rec.per) <= DIGESTS_KEPT, "{scans}");
            // The same digests check; one changed digest fails its chunk only.
            check.start_turn(scans);
            std::mem::swap(&mut check.chunks, &mut rec.chunks);
            let bad = fed / 2;
            let mut failed = Vec::new();
            for k in 0..fed {
                let d = u128::from(k) * 7 + 1 + u128::from(k == bad);
                if let Some(c) = check.fold(d) {
                    if !check.matches(c) {
                        failed.push(k);
                    }
                }
            }
            let want: Vec<u64> = if fed / check.per > bad / check.per {
                vec![(bad / check.per + 1) * check.per - 1]
            } else {
                Vec::new()
            };
            assert_eq!(failed, want, "{scans}");
        }
    }
}
