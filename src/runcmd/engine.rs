//! The run itself: everything validated before the first scan, then the warm-up and the timed
//! sequential and parallel passes, with the per-scan bookkeeping (digests, faults, trace,
//! progress) and the report they add up to.

use super::compare::{canonical_slots, digest, first_difference};
use super::inputs::{load_inputs, InputTable};
use super::progress::Progress;
use super::trace::{cell, trace_columns, Trace};
use super::{RunConfig, RunMode};
use crate::analysis::analyse;
use crate::app::{load_program, CliError};
use crate::exec::parallel::{run_sequential, ParallelMachine, PlanConfig, ScanDriver};
use crate::exec::{ExecConfig, Fault, FaultKind, Layout, Machine, VarValue};
use crate::model::{Program, Type, VarClass, VarId, VarRef};
use serde_json::Value as Json;
use std::fmt::Write as _;
use std::io::Write;
use std::time::Duration;

/// Faults kept in the report (the count covers all).
const FAULTS_KEPT: usize = 1000;

/// What a run found.
#[derive(Clone, Debug)]
pub struct RunReport {
    pub program: String,
    pub scans: u64,
    pub cycle_ms: u32,
    pub threads: usize,
    /// Main-program rungs (for the rung-execution rate).
    pub rungs: usize,
    /// Output variables after the last scan.
    pub outputs: Vec<(String, VarValue)>,
    /// Every variable but the hidden edge memories, after the last scan.
    pub state: Vec<(String, VarValue)>,
    /// The first faults (at most 1000) and the total.
    pub faults: Vec<(u64, String, FaultKind)>,
    pub fault_count: u64,
    /// Per mode: (name, total scan time).
    pub modes: Vec<(&'static str, Duration)>,
    /// `Some` when both modes ran.
    pub identical: Option<bool>,
    pub first_difference: Option<Json>,
    /// The parallel plan (text, JSON) when asked for.
    pub explain: Option<(String, Json)>,
}

/// Per-scan bookkeeping shared by both modes.
struct Driver<'a> {
    inputs: &'a InputTable,
    canon: Vec<u32>,
    /// Digests of the reference run (filled), or to check against.
    digests: Vec<u128>,
    check: bool,
    first_mismatch: Option<u64>,
    total: Duration,
    faults: Vec<(u64, u32, FaultKind)>,
    fault_count: u64,
    trace: Option<Trace<'a>>,
    progress: &'a mut Progress,
}

impl<'a> Driver<'a> {
    fn new(
        inputs: &'a InputTable,
        m: &Machine,
        digests: Vec<u128>,
        check: bool,
        trace: Option<Trace<'a>>,
        progress: &'a mut Progress,
    ) -> Driver<'a> {
        Driver {
            inputs,
            canon: canonical_slots(m),
            digests,
            check,
            first_mismatch: None,
            total: Duration::ZERO,
            faults: Vec::new(),
            fault_count: 0,
            trace,
            progress,
        }
    }
}

impl ScanDriver for Driver<'_> {
    fn before_scan(&mut self, m: &Machine, scan: u64, slots: &mut [u64]) {
        m.set_inputs_in(slots, self.inputs.at(scan));
    }

    fn after_scan(
        &mut self,
        m: &Machine,
        scan: u64,
        slots: &[u64],
        faults: &[Fault],
        elapsed: Duration,
    ) {
        self.total += elapsed;
        let d = digest(slots, &self.canon, faults);
        if self.check {
            if self.first_mismatch.is_none() && self.digests.get(scan as usize) != Some(&d) {
                self.first_mismatch = Some(scan);
            }
        } else {
            self.digests.push(d);
        }
        self.fault_count += faults.len() as u64;
        for f in faults {
            if self.faults.len() < FAULTS_KEPT {
                self.faults.push((f.scan, f.rung.0, f.kind));
            }
        }
        if let Some(t) = &mut self.trace {
            if t.error.is_none() {
                t.line.clear();
                let _ = write!(
                    t.line,
                    "{scan},{}",
                    (scan as i64).wrapping_mul(m.config().cycle_ms as i64)
                );
                for &(slot, ty) in &t.cols {
                    t.line.push(',');
                    t.line.push_str(&cell(ty, slots[slot as usize]));
                }
                t.line.push('\n');
                if let Err(e) = t.out.write_all(t.line.as_bytes()) {
                    t.error = Some(e);
                }
            }
        }
        self.progress.tick();
    }
}

/// Untimed warm-up scans before each timed pass.
const WARM_UP: u64 = 16;

/// A driver that only writes the inputs (warm-up).
struct Inputs<'a>(&'a InputTable);

impl ScanDriver for Inputs<'_> {
    fn before_scan(&mut self, m: &Machine, scan: u64, slots: &mut [u64]) {
        m.set_inputs_in(slots, self.0.at(scan));
    }
    fn after_scan(&mut self, _: &Machine, _: u64, _: &[u64], _: &[Fault], _: Duration) {}
    fn wants_time(&self) -> bool {
        false
    }
}

/// Everything a run needs, checked: nothing after this fails but writing the trace.
pub(super) struct Prepared {
    p: Program,
    inputs: InputTable,
    scans: u64,
    seq: Option<Machine>,
    par: Option<ParallelMachine>,
    pool: Option<rayon::ThreadPool>,
    trace_cols: Option<Vec<(String, VarRef, Type)>>,
}

pub(super) fn prepare(c: &RunConfig) -> Result<Prepared, CliError> {
    if c.threads == 0 {
        return Err(CliError::Usage("--threads must be at least 1".into()));
    }
    if c.cycle_ms == 0 {
        return Err(CliError::Usage("--cycle must be positive".into()));
    }
    if c.scans == Some(0) {
        return Err(CliError::Usage("--scans must be at least 1".into()));
    }
    let p = load_program(&c.input)?;
    let inputs = match &c.inputs {
        Some(path) => load_inputs(&p, path)?,
        None => InputTable::default(),
    };
    let scans = c.scans.unwrap_or(if c.inputs.is_some() {
        inputs.rows.len().max(1) as u64
    } else {
        1000
    });
    let trace_cols = match &c.trace {
        Some(_) => Some(trace_columns(&p, c.trace_vars.as_deref())?),
        None => None,
    };
    let exec = ExecConfig {
        cycle_ms: c.cycle_ms,
        loop_cap: c.loop_cap,
    };
    let lower_error =
        |e: crate::exec::LowerError| CliError::Usage(format!("{}: {e}", c.input.display()));
    let seq = if c.mode != RunMode::Par {
        Some(Machine::new(&p, Layout::dense(&p), &exec).map_err(lower_error)?)
    } else {
        None
    };
    let par = if c.mode != RunMode::Seq || c.explain {
        let a = analyse(&p);
        Some(
            ParallelMachine::new(&p, &a, &exec, &PlanConfig::new(c.threads))
                .map_err(lower_error)?,
        )
    } else {
        None
    };
    let pool = match &par {
        Some(pm) if c.mode != RunMode::Seq && pm.plan().sequential().is_none() && c.threads > 1 => {
            Some(
                rayon::ThreadPoolBuilder::new()
                    .num_threads(c.threads - 1)
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
        trace_cols,
    })
}

/// Runs the prepared scans; `trace` receives the trace CSV (from the sequential run, or from the
/// parallel one when it runs alone).
pub(super) fn execute(
    pr: &Prepared,
    c: &RunConfig,
    trace: Option<&mut dyn Write>,
) -> (RunReport, Option<std::io::Error>) {
    let (p, inputs, scans) = (&pr.p, &pr.inputs, pr.scans);
    // The parallel machine may exist only for --explain.
    let run_par = if c.mode == RunMode::Seq {
        None
    } else {
        pr.par.as_ref()
    };
    let passes = pr.seq.is_some() as u64 + run_par.is_some() as u64;
    let mut progress = Progress::new(c.progress, scans * passes);
    let mut trace = trace;
    let mut modes = Vec::new();
    let mut digests = Vec::new();
    let mut report_state: Option<(Vec<u64>, bool)> = None; // (slots, of the parallel machine)
    let (mut faults, mut fault_count, mut first_mismatch, mut trace_error) =
        (Vec::new(), 0, None, None);
    // Untimed warm-up scans on a throwaway state before each timed pass, so that neither mode
    // pays for cold caches and branch predictors (or for the other mode's warm ones).
    let warm = scans.min(WARM_UP);
    if let Some(m) = &pr.seq {
        let mut st = m.initial_state();
        run_sequential(m, &mut st, 0..warm, &mut Inputs(inputs));
        progress.label = "seq";
        let progress = &mut progress;
        let t = match (&pr.trace_cols, trace.take()) {
            (Some(cols), Some(out)) => Some(Trace::new(m, cols, out)),
            _ => None,
        };
        let mut d = Driver::new(inputs, m, Vec::new(), false, t, progress);
        let mut st = m.initial_state();
        run_sequential(m, &mut st, 0..scans, &mut d);
        modes.push(("seq", d.total));
        digests = std::mem::take(&mut d.digests);
        faults = std::mem::take(&mut d.faults);
        fault_count = d.fault_count;
        trace_error = d.trace.and_then(|t| t.error);
        report_state = Some((st.slots, false));
    }
    if let Some(pm) = run_par {
        let mut st = pm.initial_state();
        pm.run(pr.pool.as_ref(), &mut st, 0..warm, &mut Inputs(inputs));
        progress.label = "par";
        let progress = &mut progress;
        let m = pm.machine();
        let t = match (&pr.trace_cols, trace.take()) {
            (Some(cols), Some(out)) => Some(Trace::new(m, cols, out)),
            _ => None,
        };
        let check = pr.seq.is_some();
        let mut d = Driver::new(inputs, m, std::mem::take(&mut digests), check, t, progress);
        let mut st = pm.initial_state();
        pm.run(pr.pool.as_ref(), &mut st, 0..scans, &mut d);
        modes.push(("par", d.total));
        first_mismatch = d.first_mismatch;
        if !check {
            faults = std::mem::take(&mut d.faults);
            fault_count = d.fault_count;
            trace_error = d.trace.and_then(|t| t.error);
            report_state = Some((st.slots, true));
        }
    }
    progress.finish();
    let (identical, first_difference) = match (&pr.seq, run_par) {
        (Some(s), Some(pm)) => match first_mismatch {
            None => (Some(true), None),
            Some(k) => (
                Some(false),
                Some(self::first_difference(
                    p,
                    s,
                    pm,
                    pr.pool.as_ref(),
                    inputs,
                    k,
                )),
            ),
        },
        _ => (None, None),
    };
    let (slots, on_par) = report_state.expect("one mode ran");
    let m: &Machine = if on_par {
        pr.par.as_ref().expect("par").machine()
    } else {
        pr.seq.as_ref().expect("seq")
    };
    let visible: Vec<VarId> = (0..p.vars.len() as u32)
        .map(VarId)
        .filter(|&v| !p.var(v).hidden)
        .collect();
    let state: Vec<(String, VarValue)> = visible
        .iter()
        .map(|&v| (p.var(v).name.clone(), m.value_in(&slots, v)))
        .collect();
    let outputs = visible
        .iter()
        .filter(|&&v| p.var(v).class == VarClass::Output)
        .map(|&v| (p.var(v).name.clone(), m.value_in(&slots, v)))
        .collect();
    let explain = if c.explain {
        pr.par.as_ref().map(|pm| (pm.explain(p), pm.explain_json()))
    } else {
        None
    };
    let report = RunReport {
        program: p.name.clone(),
        scans,
        cycle_ms: c.cycle_ms,
        threads: c.threads,
        rungs: p.main().rungs.len(),
        outputs,
        state,
        faults: faults
            .into_iter()
            .map(|(s, r, k)| (s, p.rungs[r as usize].id.clone(), k))
            .collect(),
        fault_count,
        modes,
        identical,
        first_difference,
        explain,
    };
    (report, trace_error)
}
