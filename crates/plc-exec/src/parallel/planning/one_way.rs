//! The one-way partition of the dependence-driven plan: workers form a chain, and a task runs
//! on a worker no earlier in the chain than the workers of everything it depends on. Worker 0
//! then never waits, worker 1 waits only for worker 0, and so on: a pipeline in which the
//! workers run ahead of one another instead of in lockstep. (With the levelled slicing, the
//! dependences cross the slice boundaries both ways, so at every level each worker waits for
//! the other: every wait costs a round trip between the cores.)
//!
//! Definitions. Levels are taken in scan order, and the tasks of a level in task order. A
//! task's *floor* is the latest worker (in chain order) of its predecessors, 0 without any.
//! Each level gives worker `j < n-1` a quota of `q · cost / n` steps: the tasks are handed
//! out in order, to the current worker until its quota is full, then to the next one, but
//! never below a task's floor; the last worker takes what is left. On programs whose data
//! flows between nearby lanes this keeps each worker's tasks in a few runs that shrink (the
//! early workers) or grow (the late ones) by the reading distance per level. `q` is found
//! by bisection so that the last worker's share of the scan is as close as possible to `1/n`.
//!
//! Within each worker's share of a level, the tasks that a later worker depends on (exports)
//! run first and the tasks that depend on an earlier worker (imports) last, so that the
//! follower finds its inputs ready and the leader does not hold it up.
//!
//! Complexity: O(B · (T + E)) for T tasks, E dependence pairs and B ≤ 24 bisection steps.
//!
//! It does not model time or check anything: `deps_plan` turns the assignment into items and
//! waits and models the scan, and `order_check` proves the plan against the lowered code.
//! On programs whose every task reads from across the whole level before it (random reads)
//! the floors push almost everything onto the last worker: the plan's model then shows no
//! gain, and the candidate is dropped or measured out.

use super::slicing::Slices;
use crate::parallel::ids::TaskId;

/// The one-way partition: per level, each worker's tasks in running order, and how many of
/// them, from the first, are exports.
#[derive(Clone, Debug, PartialEq, Eq)]
pub(in crate::parallel) struct OneWay {
    /// Per level, per worker: its tasks, exports first, imports last.
    pub slices: Vec<Slices>,
    /// Per level, per worker: the number of exports at the start of its slice.
    pub exports: Vec<Vec<u32>>,
}

/// The one-way partition of `levels` (the schedule's levels) for `threads` workers: `cost` is
/// each task's modelled steps, `preds` each task's predecessors, `whole[l]` whether level `l`
/// must go to one worker (tasks sharing loop counters, or a level of one task).
pub(in crate::parallel) fn one_way(
    levels: &[Vec<TaskId>],
    cost: &[u64],
    preds: &[Vec<TaskId>],
    whole: &[bool],
    threads: usize,
) -> OneWay {
    let n = threads.max(1);
    let total: u64 = cost.iter().sum();
    let target = total / n as u64;
    let assign = |q: f64| assign_with(levels, cost, preds, whole, n, q);
    let last_share = |worker: &[u32]| -> u64 {
        worker
            .iter()
            .zip(cost)
            .filter(|(&w, _)| w as usize == n - 1)
            .map(|(_, &c)| c)
            .sum()
    };
    // The last worker's share falls as q grows; find the q that brings it nearest `target`.
    let (mut lo, mut hi) = (0.0f64, n as f64);
    let mut best = (u64::MAX, 1.0f64);
    for _ in 0..24 {
        let q = (lo + hi) / 2.0;
        let share = last_share(&assign(q));
        let off = share.abs_diff(target);
        if off < best.0 {
            best = (off, q);
        }
        if share > target {
            lo = q;
        } else {
            hi = q;
        }
    }
    let worker = assign(best.1);
    order(levels, preds, &worker, n)
}

/// Each task's worker under quota factor `q`.
fn assign_with(
    levels: &[Vec<TaskId>],
    cost: &[u64],
    preds: &[Vec<TaskId>],
    whole: &[bool],
    n: usize,
    q: f64,
) -> Vec<u32> {
    let mut worker = vec![0u32; cost.len()];
    for (l, level) in levels.iter().enumerate() {
        let floor = |t: TaskId, worker: &[u32]| {
            preds[t.index()]
                .iter()
                .map(|p| worker[p.index()])
                .max()
                .unwrap_or(0)
        };
        if whole[l] {
            let w = level.iter().map(|&t| floor(t, &worker)).max().unwrap_or(0);
            for &t in level {
                worker[t.index()] = w;
            }
            continue;
        }
        let level_cost: u64 = level.iter().map(|t| cost[t.index()]).sum();
        let quota = (q * level_cost as f64 / n as f64) as u64;
        let mut cur = 0usize;
        let mut load = vec![0u64; n];
        for &t in level {
            while cur + 1 < n && load[cur] >= quota {
                cur += 1;
            }
            let w = cur.max(floor(t, &worker) as usize);
            worker[t.index()] = w as u32;
            load[w] += cost[t.index()];
        }
    }
    worker
}

/// Per level and worker, its tasks: exports first, imports last, otherwise in task order.
fn order(levels: &[Vec<TaskId>], preds: &[Vec<TaskId>], worker: &[u32], n: usize) -> OneWay {
    let mut export = vec![false; worker.len()];
    let mut import = vec![false; worker.len()];
    for (t, ps) in preds.iter().enumerate() {
        for p in ps {
            if worker[p.index()] != worker[t] {
                export[p.index()] = true;
                import[t] = true;
            }
        }
    }
    let mut out = OneWay {
        slices: Vec::with_capacity(levels.len()),
        exports: Vec::with_capacity(levels.len()),
    };
    for level in levels {
        let mut slices: Slices = vec![Vec::new(); n];
        for &t in level {
            slices[worker[t.index()] as usize].push(t);
        }
        for s in &mut slices {
            s.sort_by_key(|t| (import[t.index()], !export[t.index()]));
        }
        let exports = slices
            .iter()
            .map(|s| {
                s.iter()
                    .take_while(|t| export[t.index()] && !import[t.index()])
                    .count() as u32
            })
            .collect();
        out.slices.push(slices);
        out.exports.push(exports);
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    /// Levels of `width` tasks each; task `j` of level `l > 0` depends on the tasks of level
    /// `l - 1` that `reads(l, j)` names.
    fn graph(
        levels: usize,
        width: usize,
        reads: impl Fn(usize, usize) -> Vec<usize>,
    ) -> (Vec<Vec<TaskId>>, Vec<Vec<TaskId>>) {
        let id = |l: usize, j: usize| TaskId::from_raw((l * width + j) as u32);
        let lv = (0..levels)
            .map(|l| (0..width).map(|j| id(l, j)).collect())
            .collect();
        let mut preds = vec![Vec::new(); levels * width];
        for l in 1..levels {
            for j in 0..width {
                preds[id(l, j).index()] = reads(l, j).into_iter().map(|k| id(l - 1, k)).collect();
            }
        }
        (lv, preds)
    }

    /// Each task's worker in `ow`.
    fn workers(ow: &OneWay, tasks: usize) -> Vec<Option<usize>> {
        let mut w = vec![None; tasks];
        for slices in &ow.slices {
            for (k, s) in slices.iter().enumerate() {
                for t in s {
                    assert!(w[t.index()].is_none(), "task {} placed twice", t.raw());
                    w[t.index()] = Some(k);
                }
            }
        }
        w
    }

    /// A ring of 1000 lanes reading their neighbours two lanes either side, 20 levels, the shape
    /// of `plc-deps gen --reads local`: two workers split it within 1 % of half each, worker 0
    /// waits for nothing, and of the 95,000 dependences about 20 per level cross (near the two
    /// ends of worker 0's arc).
    #[test]
    fn a_ring_of_lanes_splits_in_half_one_way() {
        let w = 1000;
        let ring = |_: usize, j: usize| (0..5).map(|d| (j + w + d - 2) % w).collect();
        let (levels, preds) = graph(20, w, ring);
        let cost = vec![1u64; 20 * w];
        let ow = one_way(&levels, &cost, &preds, &[false; 20], 2);
        let worker = workers(&ow, cost.len());
        let last = worker.iter().filter(|&&k| k == Some(1)).count();
        assert!(
            (9_900..=10_100).contains(&last),
            "worker 1 has {last} of 20000"
        );
        let mut cross = 0;
        for (t, ps) in preds.iter().enumerate() {
            for p in ps {
                assert!(
                    worker[p.index()] <= worker[t],
                    "task {t} depends on a later worker"
                );
                cross += (worker[p.index()] != worker[t]) as usize;
            }
        }
        assert!(cross <= 19 * 24, "{cross} crossing dependences");
        // Worker 0's slice of level 1 starts with the tasks worker 1 reads at level 2.
        assert!(ow.exports[1][0] >= 4 && ow.exports[1][1] == 0);
    }

    proptest! {
        /// On random level graphs: every task is placed once, on a worker no earlier than its
        /// predecessors'; each slice has its exports first and its imports last; the export
        /// counts are the leading exports.
        #[test]
        fn every_dependence_goes_down_the_chain(
            levels in 1usize..6,
            width in 1usize..12,
            threads in 1usize..5,
            seed in any::<u64>(),
        ) {
            let pick = |l: usize, j: usize| {
                let mut x = seed ^ ((l * 131 + j) as u64).wrapping_mul(0x9E37_79B9_7F4A_7C15);
                (0..1 + (x % 3) as usize)
                    .map(|_| {
                        x = x.wrapping_mul(6_364_136_223_846_793_005).wrapping_add(1);
                        ((x >> 33) as usize) % width
                    })
                    .collect()
            };
            let (lv, preds) = graph(levels, width, pick);
            let cost: Vec<u64> = (0..levels * width).map(|t| 1 + (t as u64 * 7) % 5).collect();
            let whole: Vec<bool> = (0..levels).map(|l| (seed >> l) & 1 == 1 && l % 3 == 0).collect();
            let ow = one_way(&lv, &cost, &preds, &whole, threads);
            let worker = workers(&ow, cost.len());
            prop_assert!(worker.iter().all(Option::is_some));
            for (t, ps) in preds.iter().enumerate() {
                for p in ps {
                    prop_assert!(worker[p.index()] <= worker[t]);
                }
            }
            for (l, slices) in ow.slices.iter().enumerate() {
                if whole[l] {
                    prop_assert!(slices.iter().filter(|s| !s.is_empty()).count() <= 1);
                }
                for (k, s) in slices.iter().enumerate() {
                    let import = |t: &TaskId| preds[t.index()].iter().any(|p| worker[p.index()] != Some(k));
                    let export = |t: &TaskId| preds.iter().enumerate().any(|(u, ps)| {
                        worker[u] != Some(k) && ps.contains(t)
                    });
                    let keys: Vec<(bool, bool)> = s.iter().map(|t| (import(t), !export(t))).collect();
                    prop_assert!(keys.windows(2).all(|w| w[0] <= w[1]));
                    let lead = keys.iter().take_while(|&&(i, ne)| !i && !ne).count();
                    prop_assert_eq!(ow.exports[l][k] as usize, lead);
                }
            }
        }
    }
}
