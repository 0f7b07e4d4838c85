//! The running machine: a [`ParallelMachine`] (a [`Machine`] on one padded layout shared by its
//! candidate plans, the plans, and the candidates a run chooses from) and its runs: the workers
//! entered once per run; worker 0 (the calling thread) asks the measured choice (`choice`)
//! which candidate runs the next window of scans, runs sequential windows alone while the
//! others sleep on the window bell, and runs parallel windows with them: a levelled plan's as
//! claimed units (`claimed`), a dependence-driven plan's meeting at the barrier, a levelled
//! plan on private states handing over packed writes (`exchange`).
//!
//! Invariants: worker 0 alone talks to the driver and the chooser, between barriers; every
//! candidate but `par-exchange` works on the same state layout, so a switch between them needs
//! no copy. `par-exchange` runs on its plan's own layout when that differs (`relayout`): worker
//! 0 moves the state into it when its window follows another candidate's, the other workers
//! copy it into their private states, and worker 0 moves it back before another candidate's
//! window, at the end of the run, and after every scan whose driver wants the state; the
//! results are those of [`Machine::run_scan`], byte for byte and fault for fault, whichever
//! candidates ran. It does not plan nor check plans (`planning`); it runs what
//! [`ParallelMachine::new`] kept.
//!
//! # Modules, bottom to top
//! Each uses only the ones before it (and the layers below the machine: the basics, `planning`,
//! `choice`): `backoff` (the one wait loop: spin, yield, park),
//! `barrier`, `flags` (ready flags), `units` (claimed units, the window bell), `xlines`
//! (exchange lines), `shared` (lock-free shared memory), `driver` (the per-scan callbacks and
//! the sequential loop), `relayout` (a `par-exchange` plan's own layout, and a state moved
//! between it and the common one), `items` (one plan item on the shared state, the merged
//! faults), `exchange` (a levelled plan's scans on private states), `claimed` (a levelled
//! plan's scans as units), `workers` (worker 0's and the others' loops over a run's windows),
//! this module. `items`, `exchange`, `claimed` and `workers` are the second half of
//! [`ParallelMachine`]'s implementation, so they use this module's types as this module uses
//! their functions.

// `unsafe` is allowed only where `crate::raw`'s `unsafe fn`s (or `items`' `run_item`, built on
// them) are called, each call arguing its `# Safety` from the plan's discipline in its file.
mod backoff;
mod barrier;
#[allow(unsafe_code)]
mod claimed;
mod driver;
#[allow(unsafe_code)]
mod exchange;
mod flags;
#[allow(unsafe_code)]
mod items;
mod relayout;
mod run_log;
mod shared;
mod units;
#[allow(unsafe_code)]
mod workers;
mod xlines;

pub use barrier::SpinBarrier;
pub use driver::{run_sequential, ScanDriver};
pub use run_log::{Candidate, RunLog};
pub use shared::SharedSlots;

use crate::parallel::choice::{Chooser, Switch, WindowRecord};
use crate::parallel::config::{Measure, PlanConfig, PlanKind};
use crate::parallel::pad::Padded;
use crate::parallel::planning::candidate_plans;
use crate::parallel::planning::{bools_first, layout_groups, Plan};
use crate::parallel::planning::{check_plan, exchange_plan, find_remote_lines, Exchange};
use crate::{ExecConfig, Fault, Layout, LowerError, Machine, State, LINE_BYTES};
use flags::ReadyFlags;
use plc_analysis::Analysis;
use plc_model::{Program, VarId};
use relayout::OwnLayout;
use shared::{Decisions, FaultBuffer, Shared};
use std::ops::Range;
use std::time::Duration;
use units::{Units, WindowBell};
use xlines::XBuffer;

/// A program lowered for the parallel scan: a [`Machine`] on the candidates' common padded
/// layout, the plans, and the candidates a run chooses from. Immutable and `Sync`.
#[derive(Debug)]
pub struct ParallelMachine {
    pub(super) machine: Machine,
    /// `plans[0]` is the primary plan ([`plan`](Self::plan)).
    pub(super) plans: Vec<Plan>,
    /// Per plan: its exchange, for the plan a `par-exchange` candidate runs.
    pub(super) exchanges: Vec<Option<Exchange>>,
    /// Per plan: the own layout its `par-exchange` candidate runs on, when it differs from the
    /// common one (the exchange is then planned on it).
    pub(super) own: Vec<Option<OwnLayout>>,
    pub(super) candidates: Vec<Candidate>,
    pub(super) names: Vec<String>,
    pub(super) kind: PlanKind,
    pub(super) measure: Measure,
    /// Padding groups of the layout (for `--explain`).
    pub(super) layout_groups: usize,
    /// Why plans were dropped (a failed check), for the user.
    pub(super) warnings: Vec<String>,
}

impl ParallelMachine {
    /// Plans `program` (analysed as `analysis`) for `config.threads` workers: the candidate
    /// plans of `config.kind`, each checked against the lowered instructions' byte accesses
    /// (a plan that fails is dropped with a warning, see [`warnings`](Self::warnings)), lowered
    /// on one layout padded for all of them.
    pub fn new(
        program: &Program,
        analysis: &Analysis,
        exec: &ExecConfig,
        config: &PlanConfig,
    ) -> Result<ParallelMachine, LowerError> {
        let mut plans = candidate_plans(program, analysis, config);
        let levelled: Vec<&Plan> = plans.iter().filter(|p| p.sequential.is_none()).collect();
        let (layout, groups) = if levelled.is_empty() {
            (Layout::dense(program), 0)
        } else {
            let groups = bools_first(program, layout_groups(&levelled, program.vars()));
            let layout = Layout::from_groups(program, &groups, LINE_BYTES)
                .expect("groups hold each variable once");
            (layout, groups.len())
        };
        let machine = Machine::new(program, layout, exec)?;
        let mut warnings = Vec::new();
        for plan in &mut plans {
            if plan.sequential.is_some() {
                continue;
            }
            if let Err(e) = check_plan(&machine, plan) {
                warnings.push(format!(
                    "the parallel plan failed its check against the lowered code ({e}); running sequentially instead"
                ));
                plan.sequential = Some(format!("the plan failed its check: {e}"));
            } else {
                find_remote_lines(&machine, plan);
            }
        }
        if matches!(config.kind, PlanKind::Par | PlanKind::Exchange) {
            if let Some(plan) = plans
                .iter()
                .find(|p| p.sequential.is_none() && p.est_plan > p.est_sequential)
            {
                warnings.push(format!(
                    "--plan {} forces the levelled plan although the cost model expects it to be slower ({} steps per scan against {} for the sequential walk)",
                    config.kind.name(),
                    plan.est_plan,
                    plan.est_sequential
                ));
            }
        }
        let mut exchanges: Vec<Option<Exchange>> = vec![None; plans.len()];
        let mut own: Vec<Option<OwnLayout>> = plans.iter().map(|_| None).collect();
        let wants_exchange = matches!(config.kind, PlanKind::Auto | PlanKind::Exchange);
        let twin = plans
            .iter()
            .position(|p| p.sequential.is_none() && p.ready.is_none() && p.threads > 1);
        if let Some(i) = twin.filter(|_| wants_exchange) {
            let others = plans
                .iter()
                .enumerate()
                .any(|(k, p)| k != i && p.sequential.is_none());
            let mine = others
                .then(|| OwnLayout::new(program, exec, &machine, &plans[i]))
                .flatten();
            let on = mine.as_ref().map_or(&machine, |o| &o.machine);
            match exchange_plan(program, on, &plans[i]) {
                Ok(x) => {
                    exchanges[i] = Some(x);
                    own[i] = mine;
                }
                Err(why) if config.kind == PlanKind::Exchange => warnings.push(format!(
                    "the levelled plan cannot run on private states ({why}); running it on the shared state"
                )),
                Err(_) => {}
            }
        }
        let mut candidates = Vec::new();
        if config.kind == PlanKind::Auto || plans.iter().all(|p| p.sequential.is_some()) {
            candidates.push(Candidate::Sequential);
        }
        let mut names: Vec<String> = candidates.iter().map(|_| "seq".to_string()).collect();
        for (i, plan) in plans.iter().enumerate() {
            if plan.sequential.is_some() {
                continue;
            }
            let only_exchange = config.kind == PlanKind::Exchange && exchanges[i].is_some();
            if !only_exchange {
                candidates.push(Candidate::Levelled(i));
                names.push(
                    if plan.ready.is_some() {
                        "par-deps"
                    } else {
                        "par"
                    }
                    .to_string(),
                );
            }
            if exchanges[i].is_some() {
                candidates.push(Candidate::Exchange(i));
                names.push("par-exchange".to_string());
            }
        }
        Ok(ParallelMachine {
            machine,
            plans,
            exchanges,
            own,
            candidates,
            names,
            kind: config.kind,
            measure: config.measure,
            layout_groups: groups,
            warnings,
        })
    }

    /// The machine (on the plans' layout).
    pub fn machine(&self) -> &Machine {
        &self.machine
    }

    /// The primary plan: the cost model's (of [`PlanKind::Model`]), or the first levelled
    /// candidate.
    pub fn plan(&self) -> &Plan {
        &self.plans[0]
    }

    /// Every plan built (levelled or not).
    pub fn plans(&self) -> &[Plan] {
        &self.plans
    }

    /// The candidates a run chooses from (one for every kind but [`PlanKind::Auto`]).
    pub fn candidates(&self) -> &[Candidate] {
        &self.candidates
    }

    /// The name of candidate `i`.
    pub fn candidate_name(&self, i: usize) -> &str {
        &self.names[i]
    }

    /// Which plans a run may use.
    pub fn kind(&self) -> PlanKind {
        self.kind
    }

    /// `Some(why)` when every run is the sequential walk.
    pub fn sequential_reason(&self) -> Option<&str> {
        match self.candidates.as_slice() {
            [Candidate::Sequential] => Some(
                self.plans
                    .iter()
                    .find_map(|p| p.sequential.as_deref())
                    .unwrap_or("sequential plan requested"),
            ),
            _ => None,
        }
    }

    /// Plans dropped because they failed their check, in words.
    pub fn warnings(&self) -> &[String] {
        &self.warnings
    }

    /// The state at load.
    pub fn initial_state(&self) -> State {
        self.machine.initial_state()
    }

    /// Checks every levelled plan against the lowered instructions' byte accesses (what
    /// [`new`](Self::new) did); the analysis is not needed and not used.
    pub fn verify(&self, _p: &Program, _a: &Analysis) -> Result<(), String> {
        for plan in &self.plans {
            if plan.sequential.is_none() {
                check_plan(&self.machine, plan)?;
            }
        }
        Ok(())
    }

    /// One scan on the first candidate (enters the workers for this scan only; use
    /// [`run`](Self::run) for many).
    pub fn scan(
        &self,
        pool: Option<&rayon::ThreadPool>,
        state: &mut State,
        scan: u64,
        inputs: &[(VarId, plc_model::Value)],
        faults: &mut Vec<Fault>,
    ) {
        self.scan_on(0, pool, state, scan, inputs, faults)
    }

    /// One scan on candidate `candidate` (e.g. the one a [`RunLog`] says ran that scan).
    pub fn scan_on(
        &self,
        candidate: usize,
        pool: Option<&rayon::ThreadPool>,
        state: &mut State,
        scan: u64,
        inputs: &[(VarId, plc_model::Value)],
        faults: &mut Vec<Fault>,
    ) {
        struct One<'a> {
            inputs: &'a [(VarId, plc_model::Value)],
            faults: &'a mut Vec<Fault>,
        }
        impl ScanDriver for One<'_> {
            fn before_scan(&mut self, m: &Machine, _: u64, slots: &mut [u8]) {
                m.set_inputs_in(slots, self.inputs);
            }
            fn after_scan(&mut self, _: &Machine, _: u64, _: &[u8], faults: &[Fault], _: Duration) {
                self.faults.extend_from_slice(faults);
            }
            fn wants_time(&self) -> bool {
                false
            }
        }
        let mut one = One { inputs, faults };
        self.run_with(pool, state, scan..scan + 1, &mut one, Some(candidate));
    }

    /// Runs scans `scans` on `state`, choosing among the candidates as [`PlanKind`] says, and
    /// tells which ran when. The workers are entered once for all of them: the calling thread
    /// is worker 0 and `pool` supplies the others (it needs at least `threads − 1` threads, and
    /// may be `None` for one thread or when every candidate is sequential).
    ///
    /// # Panics
    /// If the pool is too small, if called from one of the pool's threads, or if `state` is not
    /// a state of this machine.
    pub fn run<D: ScanDriver + ?Sized>(
        &self,
        pool: Option<&rayon::ThreadPool>,
        state: &mut State,
        scans: Range<u64>,
        driver: &mut D,
    ) -> RunLog {
        self.run_with(pool, state, scans, driver, None)
    }

    /// Runs scans `scans` on candidate `candidate` alone (e.g. a segment of a [`RunLog`]), as
    /// [`run`](Self::run) does.
    pub fn run_on<D: ScanDriver + ?Sized>(
        &self,
        candidate: usize,
        pool: Option<&rayon::ThreadPool>,
        state: &mut State,
        scans: Range<u64>,
        driver: &mut D,
    ) -> RunLog {
        self.run_with(pool, state, scans, driver, Some(candidate))
    }

    fn run_with<D: ScanDriver + ?Sized>(
        &self,
        pool: Option<&rayon::ThreadPool>,
        state: &mut State,
        scans: Range<u64>,
        driver: &mut D,
        only: Option<usize>,
    ) -> RunLog {
        let mut run = self.cursor(scans.start, only);
        self.run_more(pool, state, &mut run, scans.end, driver);
        run.log
    }

    /// A run starting at scan `first` that [`run_more`](Self::run_more) goes on with, call
    /// after call: the measured choice and the log carry over, so a run may be cut into parts
    /// with other work between them (`plc-deps run --mode both` interleaves the sequential
    /// pass's scans with them) and choose as one run would.
    pub fn start_run(&self, first: u64) -> RunCursor {
        self.cursor(first, None)
    }

    fn cursor(&self, first: u64, only: Option<usize>) -> RunCursor {
        let allowed: Vec<usize> = match only {
            Some(c) => vec![c],
            None => (0..self.candidates.len()).collect(),
        };
        let log = RunLog {
            candidates: self.names.clone(),
            scans_on: vec![0; self.candidates.len()],
            estimates: vec![None; self.candidates.len()],
            switches: Vec::new(),
            last: allowed[0],
            segments: Vec::new(),
            waits: self
                .candidates
                .iter()
                .map(|c| match *c {
                    Candidate::Levelled(i) => self.plans[i].ready.as_ref().map(|r| r.waits()),
                    Candidate::Sequential | Candidate::Exchange(_) => None,
                })
                .collect(),
            windows: Vec::new(),
            windows_unlogged: 0,
        };
        RunCursor {
            chooser: Chooser::new(allowed.len(), self.measure, first),
            allowed,
            log,
            next: first,
        }
    }

    /// Runs the scans of `run` from where it stands to `end` (exclusive) on `state`, as
    /// [`run`](Self::run) does; the caller's `state` is in this machine's layout when it
    /// returns, as after a whole run. Nothing when `end` is not past where `run` stands.
    ///
    /// # Panics
    /// As [`run`](Self::run).
    pub fn run_more<D: ScanDriver + ?Sized>(
        &self,
        pool: Option<&rayon::ThreadPool>,
        state: &mut State,
        run: &mut RunCursor,
        end: u64,
        driver: &mut D,
    ) {
        assert_eq!(
            state.bytes().len(),
            self.machine.state_size() as usize,
            "state of another machine"
        );
        if end <= run.next {
            return;
        }
        let scans = run.next..end;
        run.next = end;
        let RunCursor {
            allowed,
            chooser,
            log,
            ..
        } = run;
        let allowed: &[usize] = allowed;
        let threads = self
            .plans
            .iter()
            .filter(|p| p.sequential.is_none())
            .map(|p| p.threads)
            .max();
        let threads = match (threads, allowed) {
            (Some(t), _)
                if allowed
                    .iter()
                    .any(|&c| self.candidates[c] != Candidate::Sequential) =>
            {
                t
            }
            _ => {
                log.scans_on[allowed[0]] += scans.end - scans.start;
                log.push_segment(scans.start, allowed[0]);
                run_sequential(&self.machine, state, scans, driver);
                return;
            }
        };
        let decision_slots = self
            .plans
            .iter()
            .map(|p| p.decision_slots)
            .max()
            .unwrap_or(0);
        let decisions = Decisions::new(decision_slots);
        let ready = ReadyFlags::new(threads);
        let per_scan = self
            .plans
            .iter()
            .map(|p| claimed::unit_layout(p).1)
            .max()
            .unwrap_or(1);
        let units = Units::new(per_scan);
        let bell = WindowBell::new(threads);
        let faults: Vec<FaultBuffer> = (0..threads)
            .map(|_| Padded::new(std::sync::Mutex::new(Vec::new())))
            .collect();
        let xbufs: Vec<Option<XBuffer>> = self
            .exchanges
            .iter()
            .map(|x| x.as_ref().map(XBuffer::new))
            .collect();
        // Worker 0's state in each own layout, for the run.
        let mut homes: Vec<Option<State>> = (self.own.iter())
            .map(|o| o.as_ref().map(|o| o.machine.initial_state()))
            .collect();
        let xhomes: Vec<Option<SharedSlots>> = (homes.iter_mut().zip(&self.own))
            .map(|(s, o)| match (s, o) {
                (Some(s), Some(o)) => Some(SharedSlots::new(s.bytes_mut(), &o.machine)),
                _ => None,
            })
            .collect();
        let shared = Shared {
            slots: SharedSlots::new(state.bytes_mut(), &self.machine),
            decisions: &decisions,
            faults: &faults,
            barrier: SpinBarrier::new(threads),
            ready: &ready,
            units: &units,
            bell: &bell,
            xbufs: &xbufs,
            xhomes: &xhomes,
        };
        let shared = &shared;
        if threads == 1 {
            self.leader(shared, scans, driver, chooser, allowed, log);
        } else {
            let pool = pool.expect("a thread pool for more than one worker");
            assert!(
                pool.current_thread_index().is_none(),
                "run the parallel executor from outside its pool (worker 0 is the calling thread)"
            );
            assert!(
                pool.current_num_threads() >= threads - 1,
                "the pool has {} threads, {} workers need {}",
                pool.current_num_threads(),
                threads,
                threads - 1
            );
            pool.in_place_scope(|s| {
                for w in 1..threads {
                    s.spawn(move |_| self.follower(w, shared));
                }
                self.leader(shared, scans, driver, chooser, allowed, log);
            });
        }
        for (i, &c) in allowed.iter().enumerate() {
            log.estimates[c] = chooser.estimates()[i];
        }
        log.switches = chooser
            .switches()
            .iter()
            .map(|s| Switch {
                from: allowed[s.from],
                to: allowed[s.to],
                ..s.clone()
            })
            .collect();
        log.last = allowed[chooser.current()];
        log.windows = chooser
            .windows()
            .iter()
            .map(|w| WindowRecord {
                candidate: allowed[w.candidate],
                ..w.clone()
            })
            .collect();
        log.windows_unlogged = chooser.windows_unlogged();
    }
}

/// Where a run cut into parts stands between them ([`ParallelMachine::start_run`]): the
/// measured choice, the log so far and the next scan.
#[derive(Clone, Debug)]
pub struct RunCursor {
    allowed: Vec<usize>,
    chooser: Chooser,
    log: RunLog,
    next: u64,
}

impl RunCursor {
    /// What the run did so far.
    pub fn log(&self) -> &RunLog {
        &self.log
    }

    /// The next scan to run.
    pub fn next_scan(&self) -> u64 {
        self.next
    }

    /// What the run did.
    pub fn into_log(self) -> RunLog {
        self.log
    }
}

/// Which scans of a window worker 0 times.
#[derive(Copy, Clone, Debug)]
struct Timing {
    /// Every scan (a probe, or a driver that wants every scan timed).
    all: bool,
    /// Otherwise every `every`-th scan.
    every: u64,
}

impl Timing {
    #[inline]
    fn wants(self, scan: u64) -> bool {
        self.all || scan.is_multiple_of(self.every)
    }
}

/// Per-worker scratch buffers, kept across windows.
#[derive(Default)]
struct Buffers {
    scratch: Vec<Fault>,
    merged: Vec<(u32, Fault)>,
    out: Vec<Fault>,
}

/// The driver type of workers that have none.
struct NoDriver;

impl ScanDriver for NoDriver {
    fn before_scan(&mut self, _: &Machine, _: u64, _: &mut [u8]) {}
    fn after_scan(&mut self, _: &Machine, _: u64, _: &[u8], _: &[Fault], _: Duration) {}
}
