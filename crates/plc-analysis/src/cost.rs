//! The per-rung cost model and the work/span/makespan figures of a schedule.
//!
//! Cost model (abstract "element steps", documented in docs/report.md): each contact, compare,
//! coil, set, reset, jump, ret, end or NEXT costs 1; `or` and `branch` cost 1 plus their
//! branches; a MOVE or arithmetic box 2; a timer or counter box 4; a FOR head 2; a CALL 1 plus
//! the whole cost of its subroutine. A rung inside FOR loops is multiplied by the loops' trip
//! counts when their bounds are constants (`to - from + 1`, at least 0); a loop with a bound that
//! is not constant, and a loop made by a backward jump, count once.
//!
//! Figures: work W = Σ task costs; span S = the longest cost-weighted path of the dependence DAG;
//! W/S bounds the speed-up of any schedule; the makespan for P cores comes from list scheduling
//! (highest bottom level first, Graham 1969 / Coffman) on the same DAG, O((V + E) log V) each.

use super::schedule::{Schedule, TaskId};
use plc_model::*;
use std::cmp::Reverse;
use std::collections::BinaryHeap;

/// Cost of every rung (calls included), before loop multipliers.
/// The most a rung's cost, a multiplier or a rung's cost times its multiplier is taken to be:
/// nested loops and calls multiply (100 nested FOR loops of two trips: 2^100), and sums of up
/// to 2^23 such costs must still fit in a `u64`.
pub const COST_MAX: u64 = 1 << 40;

pub fn rung_costs(p: &Program) -> Vec<u64> {
    // Callee-first: a POU's total is needed by its callers. POUs have no cycles.
    let mut total: Vec<Option<u64>> = vec![None; p.pous().len()];
    let mut cost = vec![0u64; p.rungs().len()];
    fn pou_total(
        p: &Program,
        pou: PouId,
        total: &mut Vec<Option<u64>>,
        cost: &mut Vec<u64>,
    ) -> u64 {
        if let Some(t) = total[pou.index()] {
            return t;
        }
        // Resolve callees first (depth bounded by the call-graph depth, which is small).
        let mut callees = Vec::new();
        for r in p.pou_rungs(pou) {
            walk_elements(&p.rung(r).series, &mut |e| {
                if let Element::Call { pou } = e {
                    callees.push(*pou);
                }
            });
        }
        for c in callees {
            pou_total(p, c, total, cost);
        }
        let totals: Vec<u64> = total.iter().map(|t| t.unwrap_or(0)).collect();
        for r in p.pou_rungs(pou) {
            cost[r.index()] = series_cost(&p.rung(r).series, &totals);
        }
        let mult = multipliers(p, pou);
        let t = p
            .pou_rungs(pou)
            .zip(mult)
            .map(|(r, m)| cost[r.index()].saturating_mul(m))
            .fold(0, u64::saturating_add)
            .min(COST_MAX);
        total[pou.index()] = Some(t);
        t
    }
    for pou in p.pous().ids() {
        pou_total(p, pou, &mut total, &mut cost);
    }
    for c in &mut cost {
        *c = (*c).min(COST_MAX);
    }
    cost
}

fn series_cost(series: &[Element], pou_totals: &[u64]) -> u64 {
    series
        .iter()
        .map(|e| match e {
            Element::Or(bs) | Element::Branch(bs) => bs
                .iter()
                .map(|b| series_cost(b, pou_totals))
                .fold(1, u64::saturating_add),
            Element::Move { .. }
            | Element::Arith { .. }
            | Element::Function { .. }
            | Element::For { .. } => 2,
            Element::Timer { .. }
            | Element::Ctu { .. }
            | Element::Ctd { .. }
            | Element::Ctud { .. } => 4,
            Element::Bistable { .. } | Element::Trigger { .. } => 2,
            Element::Call { pou } => pou_totals[pou.index()].saturating_add(1),
            _ => 1,
        })
        .fold(0, u64::saturating_add)
}

/// Constant trip count of a FOR head, if its bounds are constants.
pub fn trip_count(e: &Element) -> Option<u64> {
    // A FOR index is any integer type (ULINT bounds need more than i64).
    let int = |o: &Operand| match o {
        Operand::Const(v) => v.as_i128(),
        Operand::Var(_) => None,
    };
    match e {
        Element::For { bounds, .. } => {
            let n = (int(&bounds.to)? - int(&bounds.from)? + 1).clamp(0, u64::MAX as i128);
            Some(n as u64)
        }
        _ => None,
    }
}

/// Loop multiplier of each rung of `pou` (product of the constant trip counts of the FOR
/// bodies it is in; the FOR head and NEXT rungs count with the body).
pub fn multipliers(p: &Program, pou: PouId) -> Vec<u64> {
    let range = p.pou(pou).rungs.clone();
    let base = range.start;
    let mut mult = vec![1u64; range.len()];
    for r in range.clone() {
        if let Some(e @ Element::For { next, .. }) = p.rungs()[r as usize].series.last() {
            let trips = trip_count(e).unwrap_or(1);
            for b in r + 1..=next.raw() {
                mult[(b - base) as usize] = mult[(b - base) as usize]
                    .saturating_mul(trips)
                    .min(COST_MAX);
            }
        }
    }
    mult
}

/// Work, span and list-scheduling makespans of a task DAG.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct CostSummary {
    pub work: u64,
    pub span: u64,
    /// (P, makespan) for P = 1, 2, 4, 8.
    pub makespan: Vec<(u32, u64)>,
    /// Σ over levels of the level's makespan on P cores (LPT within a level, barrier between
    /// levels: what a level-by-level executor can reach), for P = 1, 2, 4, 8.
    pub level_makespan: Vec<(u32, u64)>,
}

/// Computes W, S and makespans; `preds[t]` are the tasks `t` must wait for (all earlier in the
/// task order), `levels` the task levels.
pub fn summarise(costs: &[u64], preds: &[Vec<TaskId>], levels: &[u32]) -> CostSummary {
    let n = costs.len();
    let work = costs.iter().sum();
    let mut finish = vec![0u64; n];
    for t in 0..n {
        let start = preds[t]
            .iter()
            .map(|&p| finish[p.index()])
            .max()
            .unwrap_or(0);
        finish[t] = start + costs[t];
    }
    let span = finish.iter().copied().max().unwrap_or(0);
    let dag = TaskDag::new(costs, preds);
    let cores = [1u32, 2, 4, 8];
    // One core runs everything back to back: its makespan is the work. The others are simulated,
    // in parallel (they are independent).
    use rayon::prelude::*;
    let makespan = cores
        .par_iter()
        .map(|&p| {
            (
                p,
                if p == 1 {
                    work
                } else {
                    let mut end = 0;
                    dag.schedule(costs, preds, p as usize, |s| end = end.max(s.finish));
                    end
                },
            )
        })
        .collect();
    let groups = super::levels::group_by_level(levels);
    let level_makespan = cores
        .iter()
        .map(|&p| {
            (
                p,
                groups
                    .iter()
                    .map(|g| lpt(g.iter().map(|&t| costs[t as usize]), p as usize))
                    .sum(),
            )
        })
        .collect();
    CostSummary {
        work,
        span,
        makespan,
        level_makespan,
    }
}

/// Longest-processing-time-first makespan of independent jobs on `p` machines.
fn lpt(jobs: impl Iterator<Item = u64>, p: usize) -> u64 {
    let mut jobs: Vec<u64> = jobs.collect();
    jobs.sort_unstable_by(|a, b| b.cmp(a));
    let mut machines: BinaryHeap<Reverse<u64>> = (0..p).map(|_| Reverse(0)).collect();
    for j in jobs {
        let Reverse(m) = machines.pop().expect("p > 0");
        machines.push(Reverse(m + j));
    }
    machines.into_iter().map(|Reverse(m)| m).max().unwrap_or(0)
}

/// One task's place in a list schedule: which core runs it, from when to when.
#[derive(Copy, Clone, Debug, PartialEq, Eq)]
pub struct Slot {
    pub task: TaskId,
    pub core: u32,
    pub start: u64,
    pub finish: u64,
}

/// The list schedule of a task DAG on `p` cores (`preds[t]`: what task `t` waits for), one slot
/// per task in start order. Its last finish is [`CostSummary::makespan`] for the same `p`.
pub fn list_schedule(costs: &[u64], preds: &[Vec<TaskId>], p: usize) -> Vec<Slot> {
    let mut slots = Vec::with_capacity(costs.len());
    TaskDag::new(costs, preds).schedule(costs, preds, p, |s| slots.push(s));
    slots
}

/// The cost of every task of `schedule`: the sum of its rungs' costs.
pub fn task_costs(schedule: &Schedule, rung_costs: &[u64]) -> Vec<u64> {
    schedule
        .tasks
        .iter()
        .map(|t| t.rungs.iter().map(|r| rung_costs[r.index()]).sum())
        .collect()
}

/// A task DAG's successor lists (compressed rows, built from the predecessor lists) and the
/// bottom level of each task (its cost plus the costliest path after it): the priorities of
/// list scheduling.
struct TaskDag {
    succ_start: Vec<u32>,
    succ: Vec<u32>,
    bottom: Vec<u64>,
}

impl TaskDag {
    fn new(costs: &[u64], preds: &[Vec<TaskId>]) -> TaskDag {
        let n = costs.len();
        let mut succ_start = vec![0u32; n + 1];
        for ps in preds {
            for &p in ps {
                succ_start[p.index() + 1] += 1;
            }
        }
        for i in 0..n {
            succ_start[i + 1] += succ_start[i];
        }
        let mut succ = vec![0u32; succ_start[n] as usize];
        let mut fill = succ_start.clone();
        for (t, ps) in preds.iter().enumerate() {
            for &p in ps {
                succ[fill[p.index()] as usize] = t as u32;
                fill[p.index()] += 1;
            }
        }
        let mut dag = TaskDag {
            succ_start,
            succ,
            bottom: vec![0; n],
        };
        for t in (0..n).rev() {
            let after = dag.successors(t).iter().map(|&s| dag.bottom[s as usize]);
            dag.bottom[t] = costs[t] + after.max().unwrap_or(0);
        }
        dag
    }

    fn successors(&self, t: usize) -> &[u32] {
        &self.succ[self.succ_start[t] as usize..self.succ_start[t + 1] as usize]
    }

    /// Greedy list scheduling (Graham 1969): whenever a core is free, the lowest-numbered free
    /// core takes the ready task with the highest bottom level (ties: the earlier task); every
    /// task finishing at one instant is released before cores are assigned again. Calls
    /// `started` for each task as it starts. O((V + E) log V).
    fn schedule(
        &self,
        costs: &[u64],
        preds: &[Vec<TaskId>],
        p: usize,
        mut started: impl FnMut(Slot),
    ) {
        let n = costs.len();
        let mut waiting: Vec<u32> = preds.iter().map(|ps| ps.len() as u32).collect();
        let mut ready: BinaryHeap<(u64, Reverse<u32>)> = (0..n)
            .filter(|&t| waiting[t] == 0)
            .map(|t| (self.bottom[t], Reverse(t as u32)))
            .collect();
        let mut free: BinaryHeap<Reverse<u32>> = (0..p as u32).map(Reverse).collect();
        // Running tasks by finish time, then task.
        let mut running: BinaryHeap<Reverse<(u64, u32, u32)>> = BinaryHeap::new();
        let mut now = 0u64;
        loop {
            while !free.is_empty() {
                let Some((_, Reverse(t))) = ready.pop() else {
                    break;
                };
                let Reverse(core) = free.pop().expect("checked");
                let finish = now + costs[t as usize];
                running.push(Reverse((finish, t, core)));
                started(Slot {
                    task: TaskId::new(t),
                    core,
                    start: now,
                    finish,
                });
            }
            let Some(&Reverse((f, _, _))) = running.peek() else {
                break;
            };
            now = f;
            while let Some(&Reverse((f2, t, core))) = running.peek() {
                if f2 != now {
                    break;
                }
                running.pop();
                free.push(Reverse(core));
                for &s in self.successors(t as usize) {
                    waiting[s as usize] -= 1;
                    if waiting[s as usize] == 0 {
                        ready.push((self.bottom[s as usize], Reverse(s)));
                    }
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn figures_of_a_small_dag() {
        // 0 → 2, 1 → 2, 3 independent; costs 2, 3, 1, 4.
        let costs = [2, 3, 1, 4];
        let preds = vec![vec![], vec![], vec![TaskId::new(0), TaskId::new(1)], vec![]];
        let s = summarise(&costs, &preds, &[0, 0, 1, 0]);
        assert_eq!(s.work, 10);
        assert_eq!(s.span, 4);
        assert_eq!(s.makespan, vec![(1, 10), (2, 6), (4, 4), (8, 4)]);
        // Levels {0,1,3} then {2}: LPT on 2 cores: 4 | 3+2 → 5, then 1.
        assert_eq!(s.level_makespan, vec![(1, 10), (2, 6), (4, 5), (8, 5)]);
    }

    #[test]
    fn the_list_schedule_places_each_task_on_a_core() {
        // The same DAG on 2 cores. Bottom levels 3, 4, 1, 4: tasks 1 and 3 start first (the tie
        // to the earlier task puts 1 on core 0), then 0 where 1 finished, then 2.
        let costs = [2, 3, 1, 4];
        let preds = vec![vec![], vec![], vec![TaskId::new(0), TaskId::new(1)], vec![]];
        let s = list_schedule(&costs, &preds, 2);
        let slot = |t: u32| *s.iter().find(|x| x.task == TaskId::new(t)).unwrap();
        assert_eq!((slot(1).core, slot(1).start), (0, 0));
        assert_eq!((slot(3).core, slot(3).start), (1, 0));
        assert_eq!((slot(0).core, slot(0).start), (0, 3));
        assert_eq!((slot(2).start, slot(2).finish), (5, 6));
        let makespan = s.iter().map(|x| x.finish).max();
        assert_eq!(makespan, Some(6), "the summary's makespan for P = 2");
    }
}
