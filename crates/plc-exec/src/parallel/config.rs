//! The parameters of the parallel plan: worker count, modelled barrier, item and line costs, how
//! levels become phases and parallel levels become slices, which candidate plans a run may use
//! ([`PlanKind`]) and how the measured choice among them re-measures ([`Measure`]).
//! Plain data at the bottom of the parallel module; nothing here decides anything.

/// Which plans a run may use (`run --plan`: the variants are the command line's values, their
/// doc comments not its help).
#[derive(Copy, Clone, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "clap", derive(clap::ValueEnum))]
pub enum PlanKind {
    /// Measured: the sequential walk, the levelled plans (contiguous, LPT and locality
    /// slicing) and the dependence-driven plan that the cost model says may gain are timed on
    /// the run's first scans, the fastest runs, and the choice is re-measured as the run goes
    /// (`plc-deps run --plan auto`, the default).
    #[cfg_attr(feature = "clap", value(help = None::<&str>))]
    Auto,
    /// The cost model decides, once, with no measurement (the levelled plan if it beats the
    /// sequential scan by a modelled barrier, else the sequential walk).
    #[cfg_attr(feature = "clap", value(help = None::<&str>))]
    Model,
    /// Always the sequential walk.
    #[cfg_attr(feature = "clap", value(help = None::<&str>))]
    Seq,
    /// Always the levelled plan of the cost model's phases, even if the model says it does not
    /// pay (the sequential walk only when no level can run in parallel at all).
    #[cfg_attr(feature = "clap", value(help = None::<&str>))]
    Par,
    /// Always the dependence-driven plan (`deps_plan`): each worker runs its tasks of every
    /// level in order and waits, before a task, only for the tasks it depends on that run on
    /// another worker (ready flags instead of a barrier per level).
    #[cfg_attr(feature = "clap", value(help = None::<&str>))]
    Deps,
    /// Always the levelled plan (as `Par`) with every worker on a private copy of the state,
    /// handing the others what it wrote after each phase, BOOLs packed as bits (`par-exchange`);
    /// the levelled plan on the shared state when its phases cannot run that way.
    #[cfg_attr(feature = "clap", value(help = None::<&str>))]
    Exchange,
}

impl PlanKind {
    /// `auto`, `model`, `seq`, `par`, `deps`, `exchange`.
    pub fn name(self) -> &'static str {
        match self {
            PlanKind::Auto => "auto",
            PlanKind::Model => "model",
            PlanKind::Seq => "seq",
            PlanKind::Par => "par",
            PlanKind::Deps => "deps",
            PlanKind::Exchange => "exchange",
        }
    }
}

/// How the measured choice ([`PlanKind::Auto`]) measures, in scans (`choice`).
#[derive(Copy, Clone, Debug, PartialEq, Eq)]
pub struct Measure {
    /// Scans at the start of each visit of a candidate that its time does not count (they pay
    /// for moving state and code between the cores after a switch).
    pub warm_scans: u64,
    /// Timed scans per visit after those (their median is the visit's time).
    pub probe_scans: u64,
    /// Rounds (one visit of each measured candidate) before a measurement may stop: it stops
    /// when the choice after a round is the choice after the round before.
    pub min_rounds: u64,
    /// Rounds at most per measurement.
    pub max_rounds: u64,
    /// Scans on the chosen candidate before the first re-measurement, and after a switch.
    pub min_interval: u64,
    /// The longest stretch between re-measurements (the interval doubles while the choice
    /// holds).
    pub max_interval: u64,
    /// What a re-measurement may cost, per mille of the time the scans between two of them
    /// take on the chosen candidate: the interval is at least the number of scans that makes
    /// the next re-measurement's expected extra time (its visits of slower candidates, priced at
    /// their last measurement) this fraction of theirs (capped at `max_interval`). 0: no floor.
    pub budget_permille: u64,
    /// Scans per window while a parallel candidate runs (the machine looks at the scan times
    /// after each window, to re-measure when they jump).
    pub chunk: u64,
    /// Time every `sample_every`-th scan while nothing else times them.
    pub sample_every: u64,
}

impl Default for Measure {
    /// Visits of 1 warm-up and 2 timed scans, 3 to 8 rounds, re-measure after 128 scans
    /// doubling up to 2048 (and no sooner than a re-measurement costs 1.5 % of the time between
    /// them), windows of 32 scans, every 8th scan timed.
    fn default() -> Self {
        Measure {
            warm_scans: 1,
            probe_scans: 2,
            min_rounds: 3,
            max_rounds: 8,
            min_interval: 128,
            max_interval: 2048,
            budget_permille: 15,
            chunk: 32,
            sample_every: 8,
        }
    }
}

/// Which tasks run on which worker in the dependence-driven plan ([`PlanKind::Deps`]).
#[derive(Copy, Clone, Debug, PartialEq, Eq)]
pub enum DepsPartition {
    /// The one-way partition when its modelled scan is at most 1/32 longer than the level
    /// slices' (the model prices a wait, not the lockstep of workers that wait for each other
    /// at every level), else the level slices (the default).
    Auto,
    /// Each level cut as the levelled plan cuts it ([`Slicing`]): dependences cross between
    /// the workers both ways.
    Levels,
    /// A chain of workers, each task on a worker no earlier than the workers of everything it
    /// depends on (`planning::one_way`): worker 0 never waits, the others follow it.
    OneWay,
}

impl DepsPartition {
    /// `auto`, `levels`, `one-way`.
    pub fn name(self) -> &'static str {
        match self {
            DepsPartition::Auto => "auto",
            DepsPartition::Levels => "levels",
            DepsPartition::OneWay => "one-way",
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
    /// Contiguous, LPT or locality, whichever the cost model (with data movement) says
    /// finishes first (ties: contiguous, then LPT).
    Auto,
    /// Contiguous runs of tasks in task order, balanced by cost.
    Contiguous,
    /// Longest processing time first: each task to the least loaded worker.
    Lpt,
    /// Each task towards the worker that wrote what it reads, within a balance bound (the
    /// heaviest load at most 1/16 over the better of contiguous and LPT; `partition`).
    Locality,
}

impl Slicing {
    /// `auto`, `contiguous`, `lpt`, `locality`.
    pub fn name(self) -> &'static str {
        match self {
            Slicing::Auto => "auto",
            Slicing::Contiguous => "contiguous",
            Slicing::Lpt => "lpt",
            Slicing::Locality => "locality",
        }
    }
}

/// Where the modelled cost of a moved cache line came from.
#[derive(Copy, Clone, Debug, PartialEq, Eq)]
pub enum LineCostSource {
    /// The built-in default ([`PlanConfig::DEFAULT_LINE_COST`]).
    Default,
    /// Measured on this machine at plan time (`calibrate`): ns per line read from another
    /// core's cache and from the own cache, in tenths of a ns.
    Measured {
        /// A line another core wrote, 0.1 ns.
        remote_tenths_ns: u64,
        /// A line in the reader's own cache, 0.1 ns.
        local_tenths_ns: u64,
    },
    /// The default, because the measurement gave up (the two threads could not run at once:
    /// a busy machine).
    GaveUp,
    /// Set by the caller.
    Given,
}

/// Parameters of the plan. Costs are in steps of about 1 ns on the machine the defaults were
/// measured on (a 2-core AMD EPYC): a rung the interpreter runs fused costs
/// [`fused_rung_cost`](Self::fused_rung_cost), anything else the analysis' element steps times
/// [`step_tenths`](Self::step_tenths) / 10 (`rung_cost`).
#[derive(Copy, Clone, Debug, PartialEq, Eq)]
pub struct PlanConfig {
    /// Number of workers (threads), at least 1.
    pub threads: usize,
    /// Modelled cost of one barrier (all workers meeting), in steps.
    pub barrier_cost: u64,
    /// Modelled cost of one wait of the dependence-driven plan (a worker reading another's
    /// ready flag: about one moved line and a spin), in steps.
    pub wait_cost: u64,
    /// Modelled overhead of one item (one call into the interpreter: a run of tasks, or one
    /// guarded task), in steps.
    pub item_cost: u64,
    /// Modelled cost of one cache line a worker reads that another worker wrote last, in
    /// steps (`movement`).
    pub line_cost: u64,
    /// Modelled cost of a rung the interpreter runs as one fused table lookup (`exec::fuse`:
    /// at most eight plain contacts and one output), in steps (`rung_cost`).
    pub fused_rung_cost: u64,
    /// Steps per element step of the analysis' cost model for everything not fused, in tenths.
    pub step_tenths: u64,
    /// The hand-over between two cores measured at plan time (`calibrate`), in ns, that
    /// `barrier_cost` was set from (`None`: the default barrier).
    pub handover_ns: Option<u64>,
    /// Where `line_cost` came from (for `--explain`).
    pub line_cost_source: LineCostSource,
    /// How levels become phases.
    pub strategy: Strategy,
    /// How parallel levels are sliced.
    pub slicing: Slicing,
    /// Which tasks run on which worker in the dependence-driven plan.
    pub deps_partition: DepsPartition,
    /// Which plans a run may use (the library's default is [`PlanKind::Model`]: one plan,
    /// decided by the model; `plc-deps run` defaults to [`PlanKind::Auto`]).
    pub kind: PlanKind,
    /// How [`PlanKind::Auto`] measures.
    pub measure: Measure,
    /// The fewest tasks of a piece `par-exchange` cuts from an item to run it before the
    /// hand-over of the phase before (`planning::early`; 16: a walk of its own costs about as
    /// much as a few tasks). At least 1.
    pub early_min_tasks: u32,
}

impl PlanConfig {
    /// The default cost of a moved line, in steps: on the 2-core AMD EPYC of the other
    /// defaults a line another core wrote costs ≈ 20 ns more to read than a line in the own
    /// cache when several such reads overlap (the interpreter's reads are independent loads).
    pub const DEFAULT_LINE_COST: u64 = 20;

    /// The defaults for `threads` workers, measured on a 2-core AMD EPYC: a barrier of two
    /// spinning workers takes 100–150 ns: 120 steps; a wait on a ready flag 40 steps (a line from
    /// the other core and the spin that notices it, not measured separately); an item (a call
    /// into the interpreter) ≈ 12 steps; a moved line
    /// [`DEFAULT_LINE_COST`](Self::DEFAULT_LINE_COST). A rung fused whole 4 steps and an element
    /// step of the rest 1.5 (thread CPU time of `examples/interp_cpu`, 5 repetitions: 4.6 ns
    /// per rung on `gen --rungs 20000 --width 1000`, 90 % of whose rungs are fused whole, and
    /// 6.0 on the same with `--timers`, solved for the two: 3.7 ns a fused rung; the element step
    /// from the unfused interpreter's 8.6–9.5 ns per 6-step rung).
    pub fn new(threads: usize) -> PlanConfig {
        PlanConfig {
            threads: threads.max(1),
            barrier_cost: 120,
            wait_cost: 40,
            item_cost: 12,
            line_cost: Self::DEFAULT_LINE_COST,
            fused_rung_cost: 4,
            step_tenths: 15,
            handover_ns: None,
            line_cost_source: LineCostSource::Default,
            strategy: Strategy::Auto,
            slicing: Slicing::Auto,
            deps_partition: DepsPartition::Auto,
            kind: PlanKind::Model,
            measure: Measure::default(),
            early_min_tasks: 16,
        }
    }
}
