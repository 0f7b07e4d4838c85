//! The parallel planner as one call another back end can make: [`plan`] turns a program, its
//! analysis and a [`PlanConfig`] into a [`ScanPlan`], plain data that a code generator (a C
//! back end emitting one function per worker, say) walks to emit the same parallel scan the
//! executor runs: phases (the schedule's levels) → workers → items (runs of tasks), and the
//! synchronisation points between them.
//!
//! # What a back end does with it
//! Per scan: write the inputs, zero the loop counters; then for each phase, in order: if
//! [`ScanPhase::barrier_before`], all workers meet at a barrier (release/acquire); each worker
//! `w` runs `phase.workers[w]` in order (a sequential phase has items for worker 0 only); after
//! the last phase, a barrier if [`ScanPlan::end_barrier`]. An item ([`ScanItem`]) runs iff its
//! guard is empty or one of its disjuncts holds (the decision recorded in `slot` leads to
//! `leads_to`); it starts at `entry` unless it has `entry_slots`, in which case it starts where
//! the one of those decisions that leads to its first task says; it runs its tasks' rungs as one
//! walk (control leaving them ends the item) and records where control left in `decision` if
//! that is `Some`. In a dependence-driven plan ([`ScanPlanKind::DependenceDriven`]: one phase)
//! an item first waits until each of its [`ScanItem::waits`] holds (worker `worker` has
//! published at least `done` items this scan) and, if [`ScanItem::publish`], publishes its
//! worker's count of finished items after it (release). Decisions are written and read only
//! across such synchronisation points; faults keep the sequential order when sorted by the
//! first task of the item that raised them.
//!
//! # Invariants
//! Every plan `plan` returns as parallel passed the same check the executor runs before it runs
//! a plan (`planning::check`), against this crate's lowering of the program (`ExecConfig::default()`,
//! the state on the plan's padded layout): in a parallel phase no variable byte written by one
//! worker is read or written by another; in a dependence-driven plan every such pair is ordered
//! by waits. A back end with its own layout must keep the plan's separation of variables (it
//! holds at the level of variables, the check proves it on bytes). A plan that fails is returned
//! as sequential with the reason. What this module does not do: measure (`--plan auto` chooses
//! among candidates by timing them on the run; here [`PlanKind::Auto`] means the model's plan),
//! lay out memory, or run anything.

use super::config::{PlanConfig, PlanKind};
use super::ids::{DecisionSlot, Next, TaskId};
use super::planning::{bools_first, candidate_plans, check_plan, layout_groups, Plan, Region};
use crate::{ExecConfig, Layout, LowerError, Machine, LINE_BYTES};
use plc_analysis::Analysis;
use plc_model::{Program, RungId};
use std::ops::Range;

/// The shape of a [`ScanPlan`].
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum ScanPlanKind {
    /// The whole scan runs as the sequential walk, for this reason (no phases).
    Sequential(String),
    /// Phases one after another, a barrier where [`ScanPhase::barrier_before`] says.
    Levelled,
    /// One parallel phase whose workers order their items by ready flags (`waits`, `publish`).
    DependenceDriven,
}

/// A static parallel scan: plain data, see the module documentation for how to run it.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct ScanPlan {
    /// Levelled, dependence-driven, or sequential (and why).
    pub kind: ScanPlanKind,
    /// The number of workers (worker 0 is the one that writes the inputs).
    pub workers: usize,
    /// The phases of a scan, in order (empty when sequential).
    pub phases: Vec<ScanPhase>,
    /// A barrier after the last phase.
    pub end_barrier: bool,
    /// The number of decision slots (each holds where control left one task).
    pub decision_slots: usize,
    /// The task of each main-program rung (`None`: a rung that never runs as part of a task).
    pub task_of_rung: Vec<Option<TaskId>>,
    /// The rungs of each task, in order.
    pub task_rungs: Vec<Vec<RungId>>,
}

/// One phase: the items each worker runs between two synchronisation points.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct ScanPhase {
    /// The schedule's levels it covers.
    pub levels: Range<usize>,
    /// All workers meet at a barrier before it.
    pub barrier_before: bool,
    /// Whether every worker has items (false: worker 0 alone, in task order).
    pub parallel: bool,
    /// Per worker, its items in the order it runs them (as many entries as workers).
    pub workers: Vec<Vec<ScanItem>>,
}

/// One walk of the interpreter: a run of consecutive tasks, or one guarded or multi-entry task.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct ScanItem {
    /// The tasks, `first..=last` in task order.
    pub first: TaskId,
    /// See `first`.
    pub last: TaskId,
    /// The rung it starts at (when it has no `entry_slots`).
    pub entry: RungId,
    /// The rungs control may reach without leaving the item: `Rungs(lo, hi)` the rungs
    /// `lo..hi`, `Tasks(lo, hi)` the rungs of tasks `lo..=hi`.
    pub inside: ItemRegion,
    /// Guard disjuncts; empty: always runs.
    pub guard: Vec<GuardTerm>,
    /// The decision slots of its entry predecessors (a loop task with several entries).
    pub entry_slots: Vec<DecisionSlot>,
    /// Where to record where control left it (a later item reads it).
    pub decision: Option<DecisionSlot>,
    /// Ready flags to wait for first (dependence-driven plans only).
    pub waits: Vec<WaitFor>,
    /// Publish this worker's count of finished items after it.
    pub publish: bool,
}

/// The rungs an item may run without leaving it.
#[derive(Copy, Clone, Debug, PartialEq, Eq)]
pub enum ItemRegion {
    /// Main-program rungs `lo..hi` (indices).
    Rungs(u32, u32),
    /// The rungs of tasks `lo..=hi`.
    Tasks(TaskId, TaskId),
}

/// A guard disjunct: the task whose decision is in `slot` led to `leads_to`.
#[derive(Copy, Clone, Debug, PartialEq, Eq)]
pub struct GuardTerm {
    /// The controller's decision slot.
    pub slot: DecisionSlot,
    /// Where it must have led.
    pub leads_to: Next,
}

/// Wait until worker `worker` has finished (published) at least `done` items of this scan.
#[derive(Copy, Clone, Debug, PartialEq, Eq)]
pub struct WaitFor {
    /// The worker waited for.
    pub worker: usize,
    /// Its finished items.
    pub done: u32,
}

/// The parallel scan of `program` (analysed as `analysis`) for `config.threads` workers:
/// the model's levelled plan ([`PlanKind::Model`], [`PlanKind::Auto`], [`PlanKind::Par`],
/// [`PlanKind::Exchange`]: the same phases), the dependence-driven plan ([`PlanKind::Deps`]),
/// or the sequential walk ([`PlanKind::Seq`]); checked against the lowered code before it is
/// returned (a plan that fails comes back sequential, with the check's message).
///
/// # Errors
/// The program does not lower ([`Machine::new`]'s errors).
pub fn plan(
    program: &Program,
    analysis: &Analysis,
    config: &PlanConfig,
) -> Result<ScanPlan, LowerError> {
    let kind = match config.kind {
        PlanKind::Auto | PlanKind::Exchange => PlanKind::Model,
        k => k,
    };
    let config = PlanConfig { kind, ..*config };
    let mut plan = candidate_plans(program, analysis, &config)
        .into_iter()
        .next()
        .expect("one plan for a kind other than auto");
    if plan.sequential.is_none() {
        let groups = bools_first(program, layout_groups(&[&plan], program.vars()));
        let layout = Layout::from_groups(program, &groups, LINE_BYTES)
            .expect("groups hold each variable once");
        let machine = Machine::new(program, layout, &ExecConfig::default())?;
        if let Err(e) = check_plan(&machine, &plan) {
            plan.sequential = Some(format!("the plan failed its check: {e}"));
        }
    } else {
        Machine::new(program, Layout::dense(program), &ExecConfig::default())?;
    }
    Ok(scan_plan(&plan))
}

/// The plain data of a built plan.
fn scan_plan(plan: &Plan) -> ScanPlan {
    let workers = plan.threads.max(1);
    let mut out = ScanPlan {
        kind: ScanPlanKind::Levelled,
        workers,
        phases: Vec::new(),
        end_barrier: false,
        decision_slots: plan.decision_slots,
        task_of_rung: plan.task_of_rung.clone(),
        task_rungs: plan.task_rungs.clone(),
    };
    if let Some(why) = &plan.sequential {
        out.kind = ScanPlanKind::Sequential(why.clone());
        return out;
    }
    if plan.ready.is_some() {
        out.kind = ScanPlanKind::DependenceDriven;
    }
    out.end_barrier = plan.end_barrier;
    out.phases = plan
        .phases
        .iter()
        .map(|ph| ScanPhase {
            levels: ph.levels.clone(),
            barrier_before: ph.barrier_before,
            parallel: ph.is_parallel(),
            workers: (0..workers)
                .map(|w| {
                    ph.items_of(w)
                        .iter()
                        .map(|it| ScanItem {
                            first: it.first,
                            last: it.last,
                            entry: it.start,
                            inside: match it.region {
                                Region::Rungs(lo, hi) => ItemRegion::Rungs(lo, hi),
                                Region::Tasks(lo, hi) => ItemRegion::Tasks(lo, hi),
                            },
                            guard: plan.guards[it.guard.start as usize..it.guard.end as usize]
                                .iter()
                                .map(|&(slot, leads_to)| GuardTerm { slot, leads_to })
                                .collect(),
                            entry_slots: plan.entry_slots
                                [it.entries.start as usize..it.entries.end as usize]
                                .to_vec(),
                            decision: it.decision,
                            waits: plan.waits[it.waits.start as usize..it.waits.end as usize]
                                .iter()
                                .map(|x| WaitFor {
                                    worker: x.worker as usize,
                                    done: x.done,
                                })
                                .collect(),
                            publish: it.publish,
                        })
                        .collect()
                })
                .collect(),
        })
        .collect();
    out
}
