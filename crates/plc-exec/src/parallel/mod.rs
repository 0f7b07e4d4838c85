//! The parallel scan: the combined schedule (`analysis::schedule`) run level by level on several
//! threads, with a result identical — every byte and every fault, every scan — to
//! [`Machine::run_scan`](crate::Machine::run_scan).
//!
//! # Shape
//! Granularity decides everything: a rung of 6 contacts and a coil costs about 3.5 ns, a level
//! of a thousand of them a few µs, so the executor must not pay a thread wake-up per level. The
//! workers are therefore entered **once per run** (one [`rayon::ThreadPool::in_place_scope`]
//! around all scans: the calling thread is worker 0, the pool supplies the others) and pass each
//! other the *phases* of every scan as claimed units (`units`: a worker runs its own slice, then
//! any slice nobody claimed, and a phase starts when the units before it are done, so a worker
//! without a core loses its slices instead of holding the others at a barrier):
//!
//! - a **parallel phase** is one level of the schedule, cut statically into one *slice* per
//!   worker, balanced on the cost model (`rung_cost`: what each rung costs the interpreter): contiguous runs of tasks
//!   (best for many small rungs: a slice of consecutive rungs is one call into the interpreter),
//!   LPT (best for a few large tasks) or the *locality partition* (each task towards the worker
//!   that wrote what it reads, within 1/16 of the better of the two: `partition`), whichever
//!   the model says finishes first — the model counting, besides steps, the cache lines each
//!   worker reads that another worker wrote (`movement`, at a per-line cost the run measures
//!   once on the machine: `calibrate`);
//! - a **sequential phase** is a run of consecutive levels that cannot pay for a barrier, merged
//!   and run by worker 0 alone, in task order;
//! - when nothing pays, the whole program runs as the sequential scan ([`Plan::sequential`]).
//!
//! The choice is a small dynamic programme over the levels (each level parallel or sequential,
//! a barrier at every change and between parallel levels; sequential levels next to each other
//! share their barriers): it minimises the modelled scan time `Σ parallel makespans + Σ
//! sequential costs + barriers × barrier_cost`, the makespans and sequential phases with their
//! moved lines × line_cost. With [`PlanKind::Model`] the plan is used only
//! if it beats the plain sequential scan by more than one barrier; with [`PlanKind::Auto`] the
//! run measures the sequential walk and the levelled plans on its first scans and keeps the
//! fastest, re-measuring as it goes (`choice`). `plc-deps run --explain` prints the decisions.
//!
//! Per scan: worker 0 writes the inputs and zeroes the loop counters; barrier; every phase (a
//! barrier before a parallel phase and after it); worker 0 then merges the faults (into the
//! sequential order: by task index), hands the state to the caller, and starts the next scan.
//!
//! # Why it is exact
//! - Tasks of one level never touch a variable that another task of the level writes (the
//!   schedule's guarantee), and the loop counters of main-program loops belong to one task
//!   each; a level whose tasks may share a subroutine's loop counters is run sequentially.
//!   Every plan is checked when it is built, in every build, against the lowered instructions'
//!   actual byte accesses (`check`): no byte written by a worker in a parallel phase is read or
//!   written by another worker of that phase, and no two workers write one 64-byte line; a plan
//!   that fails is not run.
//! - Control: after a task runs, the slot of its *decision* records where control left (the rung
//!   it went to, or the end of the scan); a task that does not run records [`Decision::NotRun`]. A task runs iff its guard is
//!   empty or one of its disjuncts holds (`decision(controller)` leads to `successor`); a loop
//!   task with several entries is entered at the rung its predecessor's decision names (the
//!   schedule places it after all its predecessors). Decisions are read only in later phases.
//! - A *run* of tasks `t, t+1, …, u` (consecutive in task order, same slice) is executed as one
//!   walk of the interpreter over their rungs when each of `t..u` has the next one as its only
//!   successor in the condensed CFG and `t+1..=u` are unguarded with a single entry: the walk
//!   then visits exactly these tasks in this order, as the sequential scan does.
//! - The iteration cap refuses a loop-back locally (see the [module semantics](super)); a refused
//!   backward jump continues in its rung as an unpowered jump, which the CFG already contains
//!   when the jump is conditional. For an unconditional backward jump of the main program the
//!   plan checks that every way on after a refusal is an edge the schedule already knows, and
//!   otherwise runs the program sequentially.
//!
//! # Layers, bottom to top
//! Each layer uses only the ones below it, never one above (checked by tests/it/par_layers.rs; the
//! `mod` lines below are alphabetical, as rustfmt sorts them):
//! 1. the basics: `ids` (typed indices and decisions), `config` (what the caller asks for),
//!    `pad` (a value on its own cache lines);
//! 2. `planning` (the candidate plans, the cost model, the partition, the check of every plan
//!    against the lowered code; its own `//!` lists its modules in order);
//! 3. `static_plan` (the planner as one call for other back ends: [`plan`], the plan as plain
//!    data, checked against the lowered code); `choice` (the measured choice among the
//!    candidates: which runs the next window of scans);
//! 4. `machine` (the running machine: the wait loop, the barrier, the ready flags, the claimed
//!    units, the shared memory, the workers' runs of the chosen plans);
//! 5. `explain` (what `--explain` and the JSON say of the plans and the run).
//!
//! # Memory
//! The state is one block of bytes, each value in its type's width (`exec::Layout`), starting
//! on a 64-byte line and shared by all workers without locks ([`SharedSlots`]: plain
//! loads and stores of each value's bytes; disjointness is the schedule's guarantee above,
//! checked on the lowered code of every plan before it runs, ordering comes from the
//! release/acquire hand-overs between phases). Its
//! layout ([`Layout::from_groups`](crate::Layout::from_groups) on 64-byte lines) groups
//! the variables by the set of (phase, worker) pairs that write them, so two workers never write
//! the same cache line in one phase; loop counters have a line each; decisions and fault
//! buffers are padded per worker.

mod choice;
mod config;
mod explain;
mod ids;
mod machine;
#[cfg(test)]
mod miri_tests;
mod pad;
mod planning;
mod static_plan;

pub use choice::{Chooser, Switch, Window, WindowRecord};
pub use config::{DepsPartition, LineCostSource, Measure, PlanConfig, PlanKind, Slicing, Strategy};
pub use explain::{ns_text, run_log_json};
pub use ids::{Decision, DecisionSlot, Next, TaskId};
pub use machine::{
    run_sequential, Candidate, ParallelMachine, RunCursor, RunLog, ScanDriver, SharedSlots,
    SpinBarrier,
};
pub use planning::{measure_handover, measure_line_cost, LevelPlan, LineTiming, Plan, Ready};
pub use static_plan::{
    plan, GuardTerm, ItemRegion, ScanItem, ScanPhase, ScanPlan, ScanPlanKind, WaitFor,
};
