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

use super::schedule::TaskId;
use crate::model::*;
use std::cmp::Reverse;
use std::collections::BinaryHeap;

/// Cost of every rung (calls included), before loop multipliers.
pub fn rung_costs(p: &Program) -> Vec<u64> {
    // Callee-first: a POU's total is needed by its callers. POUs have no cycles.
    let mut total: Vec<Option<u64>> = vec![None; p.pous.len()];
    let mut cost = vec![0u64; p.rungs.len()];
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
            .map(|(r, m)| cost[r.index()] * m)
            .sum();
        total[pou.index()] = Some(t);
        t
    }
    for pou in 0..p.pous.len() {
        pou_total(p, PouId(pou as u32), &mut total, &mut cost);
    }
    cost
}

fn series_cost(series: &[Element], pou_totals: &[u64]) -> u64 {
    series
        .iter()
        .map(|e| match e {
            Element::Or(bs) | Element::Branch(bs) => {
                1 + bs.iter().map(|b| series_cost(b, pou_totals)).sum::<u64>()
            }
            Element::Move { .. } | Element::Arith { .. } | Element::For { .. } => 2,
            Element::Timer { .. }
            | Element::Ctu { .. }
            | Element::Ctd { .. }
            | Element::Ctud { .. } => 4,
            Element::Bistable { .. } | Element::Trigger { .. } => 2,
            Element::Call { pou } => 1 + pou_totals[pou.index()],
            _ => 1,
        })
        .sum()
}

/// Constant trip count of a FOR head, if its bounds are constants.
pub fn trip_count(e: &Element) -> Option<u64> {
    let int = |o: &Operand| match o {
        Operand::Const(Value::Int(v)) => Some(*v as i64),
        Operand::Const(Value::Dint(v)) => Some(*v as i64),
        _ => None,
    };
    match e {
        Element::For { bounds, .. } => {
            Some((int(&bounds.to)? - int(&bounds.from)? + 1).max(0) as u64)
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
        if let Some(e @ Element::For { next, .. }) = p.rungs[r as usize].series.last() {
            let trips = trip_count(e).unwrap_or(1);
            for b in r + 1..=next.0 {
                mult[(b - base) as usize] = mult[(b - base) as usize].saturating_mul(trips);
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
    // Bottom levels for priorities; successors from preds.
    let mut succ_count = vec![0u32; n + 1];
    for ps in preds {
        for &p in ps {
            succ_count[p.index() + 1] += 1;
        }
    }
    for i in 0..n {
        succ_count[i + 1] += succ_count[i];
    }
    let mut succ = vec![0u32; succ_count[n] as usize];
    let mut fill = succ_count.clone();
    for (t, ps) in preds.iter().enumerate() {
        for &p in ps {
            succ[fill[p.index()] as usize] = t as u32;
            fill[p.index()] += 1;
        }
    }
    let successors = |t: usize| &succ[succ_count[t] as usize..succ_count[t + 1] as usize];
    let mut bottom = vec![0u64; n];
    for t in (0..n).rev() {
        bottom[t] = costs[t]
            + successors(t)
                .iter()
                .map(|&s| bottom[s as usize])
                .max()
                .unwrap_or(0);
    }
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
                    list_schedule(costs, preds, &successors, &bottom, p as usize)
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

/// Greedy list scheduling: whenever a core is free, it takes the ready task with the highest
/// bottom level (ties: earlier task).
fn list_schedule<'a>(
    costs: &[u64],
    preds: &[Vec<TaskId>],
    successors: &(dyn Fn(usize) -> &'a [u32] + Sync),
    bottom: &[u64],
    p: usize,
) -> u64 {
    let n = costs.len();
    let mut waiting: Vec<u32> = preds.iter().map(|ps| ps.len() as u32).collect();
    let mut ready: BinaryHeap<(u64, Reverse<u32>)> = (0..n)
        .filter(|&t| waiting[t] == 0)
        .map(|t| (bottom[t], Reverse(t as u32)))
        .collect();
    // Running tasks by finish time.
    let mut running: BinaryHeap<Reverse<(u64, u32)>> = BinaryHeap::new();
    let mut now = 0u64;
    let mut idle = p;
    let mut end = 0u64;
    loop {
        while idle > 0 {
            match ready.pop() {
                Some((_, Reverse(t))) => {
                    idle -= 1;
                    running.push(Reverse((now + costs[t as usize], t)));
                }
                None => break,
            }
        }
        let Some(Reverse((f, t))) = running.pop() else {
            break;
        };
        now = f;
        end = end.max(f);
        idle += 1;
        for &s in successors(t as usize) {
            waiting[s as usize] -= 1;
            if waiting[s as usize] == 0 {
                ready.push((bottom[s as usize], Reverse(s)));
            }
        }
        // Release every task finishing at the same instant before assigning again.
        while let Some(&Reverse((f2, t2))) = running.peek() {
            if f2 != now {
                break;
            }
            running.pop();
            idle += 1;
            for &s in successors(t2 as usize) {
                waiting[s as usize] -= 1;
                if waiting[s as usize] == 0 {
                    ready.push((bottom[s as usize], Reverse(s)));
                }
            }
        }
    }
    end
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn figures_of_a_small_dag() {
        // 0 → 2, 1 → 2, 3 independent; costs 2, 3, 1, 4.
        let costs = [2, 3, 1, 4];
        let preds = vec![vec![], vec![], vec![TaskId(0), TaskId(1)], vec![]];
        let s = summarise(&costs, &preds, &[0, 0, 1, 0]);
        assert_eq!(s.work, 10);
        assert_eq!(s.span, 4);
        assert_eq!(s.makespan, vec![(1, 10), (2, 6), (4, 4), (8, 4)]);
        // Levels {0,1,3} then {2}: LPT on 2 cores: 4 | 3+2 → 5, then 1.
        assert_eq!(s.level_makespan, vec![(1, 10), (2, 6), (4, 5), (8, 5)]);
    }
}
