//! What the planner knows about the tasks (costs, chains into runs, decisions, entries) and how
//! a parallel level is cut into slices: contiguous runs balanced by cost, or LPT.

use super::plan::{Item, Region, NONE};
use crate::analysis::Analysis;
use std::ops::Range;

/// Facts about the tasks the planner needs.
pub(super) struct Tasks<'a> {
    pub(super) a: &'a Analysis,
    pub(super) cost: Vec<u64>,
    /// The only condensed successor (task index), if there is exactly one and it is a task.
    pub(super) only_succ: Vec<u32>,
    pub(super) needs_decision: Vec<bool>,
    /// Tasks with a CFG edge into each multi-entry task.
    pub(super) entry_preds: Vec<Vec<u32>>,
}

impl Tasks<'_> {
    pub(super) fn unguarded_single(&self, t: u32) -> bool {
        let task = &self.a.schedule.tasks[t as usize];
        task.guard.is_empty() && task.entries.len() == 1
    }

    /// Whether `t` and `t + 1` can be one walk.
    pub(super) fn chains(&self, t: u32) -> bool {
        self.only_succ[t as usize] == t + 1
            && !self.needs_decision[t as usize]
            && self.unguarded_single(t + 1)
    }

    /// The items of a slice (tasks ascending).
    pub(super) fn items(&self, tasks: &[u32], item_cost: u64) -> Vec<Item> {
        let mut out = Vec::new();
        let mut i = 0;
        while i < tasks.len() {
            let mut j = i;
            if self.unguarded_single(tasks[i]) {
                while j + 1 < tasks.len() && tasks[j + 1] == tasks[j] + 1 && self.chains(tasks[j]) {
                    j += 1;
                }
            }
            out.push(self.item(tasks[i], tasks[j], item_cost));
            i = j + 1;
        }
        out
    }

    pub(super) fn item(&self, first: u32, last: u32, item_cost: u64) -> Item {
        let sched = &self.a.schedule;
        let (mut lo, mut hi, mut count) = (u32::MAX, 0u32, 0u64);
        for t in first..=last {
            for r in &sched.tasks[t as usize].rungs {
                lo = lo.min(r.0);
                hi = hi.max(r.0 + 1);
                count += 1;
            }
        }
        let region = if (hi - lo) as u64 == count {
            Region::Rungs(lo, hi)
        } else {
            Region::Tasks(first, last)
        };
        let task = &sched.tasks[first as usize];
        Item {
            first,
            last,
            start: task.entries[0].0,
            region,
            guard: 0..0,
            entries: 0..0,
            decision: NONE,
            cost: (first..=last).map(|t| self.cost[t as usize]).sum::<u64>() + item_cost,
        }
    }
}

/// Contiguous slices of `weights` into at most `p` parts minimising the heaviest part.
pub(super) fn contiguous(weights: &[u64], p: usize) -> Vec<Range<usize>> {
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
pub(super) fn lpt(tasks: &[u32], weights: &[u64], p: usize) -> Vec<Vec<u32>> {
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
