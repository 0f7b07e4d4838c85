//! What the planner knows about the tasks (costs, chains into runs, decisions, entries), the
//! unit of work a worker runs ([`Item`]), and how a parallel level is cut into slices:
//! contiguous runs balanced by cost, or LPT (longest processing time first).
//!
//! Invariants: an item's tasks are consecutive in task order and, when more than one, each leads
//! only to the next (one walk of the interpreter visits exactly them, in the sequential order).
//! Depends only on the analysis and the typed indices; it does not choose phases (see `plan`).

use crate::parallel::ids::{DecisionSlot, TaskId};
use plc_analysis::Analysis;
use plc_model::RungId;
use std::ops::Range;

/// Which rungs a walk of the interpreter may visit.
#[derive(Copy, Clone, Debug, PartialEq, Eq)]
pub(in crate::parallel) enum Region {
    /// Rungs `lo..hi` (the run's rungs are exactly this range).
    Rungs(u32, u32),
    /// Rungs whose task is in `lo..=hi`.
    Tasks(TaskId, TaskId),
}

/// One call into the interpreter: a run of tasks `first..=last`, or one guarded or
/// multi-entry task.
#[derive(Clone, Debug, PartialEq, Eq)]
pub(in crate::parallel) struct Item {
    pub(in crate::parallel) first: TaskId,
    pub(in crate::parallel) last: TaskId,
    /// The entry rung (single-entry tasks).
    pub(in crate::parallel) start: RungId,
    pub(in crate::parallel) region: Region,
    /// Guard disjuncts: range into `Plan::guards`; empty: always runs.
    pub(in crate::parallel) guard: Range<u32>,
    /// Entry predecessors' decision slots (multi-entry loop tasks): range into
    /// `Plan::entry_slots`; empty: enter at `start`.
    pub(in crate::parallel) entries: Range<u32>,
    /// Decision slot of `last`, if a later task reads where control left it.
    pub(in crate::parallel) decision: Option<DecisionSlot>,
    /// Ready flags to wait for before it runs (dependence-driven plans): range into
    /// `Plan::waits`; empty in levelled plans.
    pub(in crate::parallel) waits: Range<u32>,
    /// Publish the worker's ready flag after it (a later item of another worker waits for it).
    pub(in crate::parallel) publish: bool,
    /// Modelled cost (tasks + item overhead).
    pub(in crate::parallel) cost: u64,
}

impl Item {
    /// The tasks of the item, in order.
    pub(in crate::parallel) fn tasks(&self) -> impl Iterator<Item = TaskId> {
        (self.first.raw()..=self.last.raw()).map(TaskId::from_raw)
    }
}

/// Facts about the tasks the planner needs.
pub(in crate::parallel) struct Tasks<'a> {
    pub(in crate::parallel) a: &'a Analysis,
    pub(in crate::parallel) cost: Vec<u64>,
    /// The only condensed successor, if there is exactly one and it is a task.
    pub(in crate::parallel) only_succ: Vec<Option<TaskId>>,
    pub(in crate::parallel) needs_decision: Vec<bool>,
    /// Tasks with a CFG edge into each multi-entry task.
    pub(in crate::parallel) entry_preds: Vec<Vec<TaskId>>,
}

impl Tasks<'_> {
    pub(in crate::parallel) fn unguarded_single(&self, t: TaskId) -> bool {
        let task = &self.a.schedule.tasks[t.index()];
        task.guard.is_empty() && task.entries.len() == 1
    }

    /// Whether `t` and `t + 1` can be one walk.
    pub(in crate::parallel) fn chains(&self, t: TaskId) -> bool {
        let next = TaskId::from_raw(t.raw() + 1);
        self.only_succ[t.index()] == Some(next)
            && !self.needs_decision[t.index()]
            && self.unguarded_single(next)
    }

    /// The items of a slice (tasks ascending).
    pub(in crate::parallel) fn items(&self, tasks: &[TaskId], item_cost: u64) -> Vec<Item> {
        let mut out = Vec::new();
        let mut i = 0;
        while i < tasks.len() {
            let mut j = i;
            if self.unguarded_single(tasks[i]) {
                while j + 1 < tasks.len()
                    && tasks[j + 1].raw() == tasks[j].raw() + 1
                    && self.chains(tasks[j])
                {
                    j += 1;
                }
            }
            out.push(self.item(tasks[i], tasks[j], item_cost));
            i = j + 1;
        }
        out
    }

    fn item(&self, first: TaskId, last: TaskId, item_cost: u64) -> Item {
        let sched = &self.a.schedule;
        let (mut lo, mut hi, mut count) = (u32::MAX, 0u32, 0u64);
        for t in first.raw()..=last.raw() {
            for r in &sched.tasks[t as usize].rungs {
                lo = lo.min(r.raw());
                hi = hi.max(r.raw() + 1);
                count += 1;
            }
        }
        let region = if (hi - lo) as u64 == count {
            Region::Rungs(lo, hi)
        } else {
            Region::Tasks(first, last)
        };
        let task = &sched.tasks[first.index()];
        Item {
            first,
            last,
            start: task.entries[0],
            region,
            guard: 0..0,
            entries: 0..0,
            decision: None,
            waits: 0..0,
            publish: false,
            cost: (first.raw()..=last.raw())
                .map(|t| self.cost[t as usize])
                .sum::<u64>()
                + item_cost,
        }
    }
}

/// Contiguous slices of `weights` into at most `p` parts minimising the heaviest part.
pub(in crate::parallel) fn contiguous(weights: &[u64], p: usize) -> Vec<Range<usize>> {
    let total: u64 = weights.iter().sum();
    let max = weights.iter().copied().max().unwrap_or(0);
    let parts = |cap: u64| -> Vec<Range<usize>> {
        let mut out = Vec::new();
        let (mut start, mut sum) = (0, 0u64);
        for (i, &w) in weights.iter().enumerate() {
            if sum + w > cap && i > start {
                out.push(start..i);
                start = i;
                sum = 0;
            }
            sum += w;
        }
        out.push(start..weights.len());
        out
    };
    let (mut lo, mut hi) = (max.max(total.div_ceil(p as u64)), total.max(1));
    while lo < hi {
        let mid = lo + (hi - lo) / 2;
        if parts(mid).len() <= p {
            hi = mid;
        } else {
            lo = mid + 1;
        }
    }
    parts(lo)
}

/// LPT: tasks (with weights) to `p` workers; each worker's tasks ascending.
pub(in crate::parallel) fn lpt(tasks: &[TaskId], weights: &[u64], p: usize) -> Vec<Vec<TaskId>> {
    let mut order: Vec<usize> = (0..tasks.len()).collect();
    order.sort_by(|&a, &b| weights[b].cmp(&weights[a]).then(a.cmp(&b)));
    let mut load = vec![0u64; p];
    let mut out = vec![Vec::new(); p];
    for i in order {
        let w = (0..p).min_by_key(|&w| (load[w], w)).expect("p > 0");
        load[w] += weights[i];
        out[w].push(tasks[i]);
    }
    for s in &mut out {
        s.sort_unstable();
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    #[test]
    fn contiguous_balances_the_heaviest_part() {
        assert_eq!(contiguous(&[1, 1, 1, 1], 2), vec![0..2, 2..4]);
        assert_eq!(contiguous(&[5, 1, 1, 1, 1, 1], 2), vec![0..1, 1..6]);
        assert_eq!(contiguous(&[3], 4), vec![0..1]);
    }
    #[test]
    fn lpt_gives_each_task_to_the_least_loaded_worker() {
        let t: Vec<TaskId> = (0..4).map(TaskId::from_raw).collect();
        assert_eq!(
            lpt(&t, &[5, 4, 3, 3], 2),
            vec![
                vec![TaskId::from_raw(0), TaskId::from_raw(3)],
                vec![TaskId::from_raw(1), TaskId::from_raw(2)]
            ]
        );
    }
}
