//! The parameters of the parallel plan: worker count, modelled barrier and item costs, and how
//! levels become phases and parallel levels become slices.

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
        }
    }
}
