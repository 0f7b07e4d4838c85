//! The parameters of the parallel plan: worker count, modelled barrier and item costs, how
//! levels become phases and parallel levels become slices, which candidate plans a run may use
//! ([`PlanKind`]) and how the measured choice among them re-measures ([`Measure`]).
//! Plain data at the bottom of the parallel module; nothing here decides anything.

/// Which plans a run may use.
#[derive(Copy, Clone, Debug, PartialEq, Eq)]
pub enum PlanKind {
    /// Measured: the sequential walk and the levelled plans (contiguous and LPT slicing) that
    /// the cost model says may gain are timed on the run's first scans, the fastest runs, and
    /// the choice is re-measured as the run goes (`plc-deps run --plan auto`, the default).
    Auto,
    /// The cost model decides, once, with no measurement (the levelled plan if it beats the
    /// sequential scan by a modelled barrier, else the sequential walk).
    Model,
    /// Always the sequential walk.
    Seq,
    /// Always the levelled plan of the cost model's phases, even if the model says it does not
    /// pay (the sequential walk only when no level can run in parallel at all).
    Par,
}

impl PlanKind {
    /// `auto`, `model`, `seq`, `par`.
    pub fn name(self) -> &'static str {
        match self {
            PlanKind::Auto => "auto",
            PlanKind::Model => "model",
            PlanKind::Seq => "seq",
            PlanKind::Par => "par",
        }
    }
}

/// How the measured choice ([`PlanKind::Auto`]) measures, in scans.
#[derive(Copy, Clone, Debug, PartialEq, Eq)]
pub struct Measure {
    /// Scans timed per candidate and measurement (the first warms its caches up).
    pub probe_scans: u64,
    /// Scans on the chosen candidate before the first re-measurement, and after a switch.
    pub min_interval: u64,
    /// The longest stretch between re-measurements (the interval doubles while the choice
    /// holds).
    pub max_interval: u64,
    /// Scans per window while a parallel candidate runs (the machine looks at the scan times
    /// after each window, to re-measure when they jump).
    pub chunk: u64,
    /// Time every `sample_every`-th scan while nothing else times them.
    pub sample_every: u64,
}

impl Default for Measure {
    /// 4 scans per probe, re-measure after 128 scans doubling up to 2048, windows of 32 scans,
    /// every 8th scan timed.
    fn default() -> Self {
        Measure {
            probe_scans: 4,
            min_interval: 128,
            max_interval: 2048,
            chunk: 32,
            sample_every: 8,
        }
    }
}

/// How levels are turned into phases.
#[derive(Copy, Clone, Debug, PartialEq, Eq)]
pub enum Strategy {
    /// The cost model decides (the default).
    Auto,
    /// Every level that may run in parallel is a parallel phase, whatever it costs (for tests:
    /// exercises the barriers, decisions and slices as much as possible).
    AllParallel,
    /// The whole program runs as the sequential scan.
    Sequential,
}

/// How a parallel level is cut into slices.
#[derive(Copy, Clone, Debug, PartialEq, Eq)]
pub enum Slicing {
    /// Contiguous or LPT, whichever the cost model says finishes first (ties: contiguous).
    Auto,
    /// Contiguous runs of tasks in task order, balanced by cost.
    Contiguous,
    /// Longest processing time first: each task to the least loaded worker.
    Lpt,
}

/// Parameters of the plan. Costs are in the cost model's element steps (a contact is 1; on the
/// machine the defaults were measured on, a step takes 0.5–2 ns).
#[derive(Copy, Clone, Debug, PartialEq, Eq)]
pub struct PlanConfig {
    /// Number of workers (threads), at least 1.
    pub threads: usize,
    /// Modelled cost of one barrier (all workers meeting), in steps.
    pub barrier_cost: u64,
    /// Modelled overhead of one item (one call into the interpreter: a run of tasks, or one
    /// guarded task), in steps.
    pub item_cost: u64,
    /// How levels become phases.
    pub strategy: Strategy,
    /// How parallel levels are sliced.
    pub slicing: Slicing,
    /// Which plans a run may use (the library's default is [`PlanKind::Model`]: one plan,
    /// decided by the model; `plc-deps run` defaults to [`PlanKind::Auto`]).
    pub kind: PlanKind,
    /// How [`PlanKind::Auto`] measures.
    pub measure: Measure,
}

impl PlanConfig {
    /// The defaults for `threads` workers, measured on a 2-core AMD EPYC: a barrier of two
    /// spinning workers takes 100–150 ns, a step of generated programs 0.5–2 ns (≈ 1 ns for
    /// 1,000 rungs): barrier 120 steps; an item (a call into the interpreter) ≈ 12 steps.
    pub fn new(threads: usize) -> PlanConfig {
        PlanConfig {
            threads: threads.max(1),
            barrier_cost: 120,
            item_cost: 12,
            strategy: Strategy::Auto,
            slicing: Slicing::Auto,
            kind: PlanKind::Model,
            measure: Measure::default(),
        }
    }
}
