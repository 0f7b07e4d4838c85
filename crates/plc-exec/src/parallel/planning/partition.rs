//! The locality-aware partition of one parallel level: each task tends to run on the worker
//! that wrote what it reads (producer → consumer affinity), within a balance bound.
//!
//! Three steps, all on the level's tasks in task order:
//! 1. **Affinity path.** Ignoring balance, the cheapest assignment of the tasks to workers,
//!    where a task costs the bytes it reads from other workers' last writes (at `line_cost`
//!    steps per 64 bytes) and every break of a would-be item (two consecutive tasks that one
//!    walk of the interpreter could run, put on different workers) beyond the reference's
//!    number of breaks costs one `item_cost`: a shortest path over (task, worker, breaks)
//!    states (Viterbi), O(tasks × workers³). Ties go to the reference partition's worker, so a
//!    level whose tasks read nothing written by the workers keeps the reference partition.
//! 2. **Units.** The path cut into units: maximal runs of consecutive tasks on one worker, at
//!    most `total / (16 × workers)` in weight each, so that balance can be repaired finely.
//! 3. **Balance repair** (the move step of Fiduccia & Mattheyses 1982, on one objective):
//!    while the heaviest worker is over the bound, move one of its units to the lightest
//!    worker, choosing the move that loses least (affinity bytes that become remote, and items
//!    the move adds; ties: a unit the reference puts there), and only moves that lower the
//!    heavier of the two loads.
//!
//! **The bound.** The heaviest worker's load (Σ task weights) is at most the reference's heaviest
//! load plus a sixteenth (ε = 1/16, [`SLACK`]), the reference being the better of contiguous
//! slicing and LPT (Graham 1969) on the same weights. If the repair cannot reach it, the
//! partition *is* the reference (also when the path breaks into more than [`MAX_UNITS`]
//! units). Every task is assigned to exactly one worker. It does not know
//! about variables or lines (the caller turns them into `affinity`) nor decide whether the level
//! runs in parallel (see `plan`).

/// The balance bound's slack: heaviest load ≤ reference + reference / `SLACK`.
pub(in crate::parallel) const SLACK: u64 = 16;

/// Breaks of items per worker the affinity path may make for free (as many as the reference
/// makes, up to this).
const FREE_BREAKS_PER_WORKER: usize = 4;

/// The most units the repair works with (each move looks at all of them): a level whose
/// affinity path breaks into more keeps the reference partition.
const MAX_UNITS: usize = 4096;

/// Units per worker that the repair works with (at least).
const UNITS_PER_WORKER: u64 = 16;

/// One level as the partition sees it (`n` tasks in task order, `p` workers).
pub(in crate::parallel) struct Level<'a> {
    /// Cost of each task (steps).
    pub(in crate::parallel) weights: &'a [u64],
    /// `affinity[i * p + w]`: the bytes task `i` reads that worker `w` wrote last.
    pub(in crate::parallel) affinity: &'a [u64],
    /// `joins[i]`: tasks `i` and `i + 1` are one item when they run on one worker.
    pub(in crate::parallel) joins: &'a [bool],
    /// The reference partition: the worker of each task.
    pub(in crate::parallel) reference: &'a [usize],
}

/// The costs the partition trades, in steps.
#[derive(Copy, Clone, Debug)]
pub(in crate::parallel) struct Costs {
    /// One cache line moved between workers.
    pub(in crate::parallel) line_cost: u64,
    /// One more item (a call into the interpreter).
    pub(in crate::parallel) item_cost: u64,
}

/// The heaviest load of `assign` (worker per task) over `p` workers.
pub(in crate::parallel) fn makespan(weights: &[u64], assign: &[usize], p: usize) -> u64 {
    loads(weights, assign, p).into_iter().max().unwrap_or(0)
}

fn loads(weights: &[u64], assign: &[usize], p: usize) -> Vec<u64> {
    let mut load = vec![0u64; p];
    for (i, &w) in assign.iter().enumerate() {
        load[w] += weights[i];
    }
    load
}

/// The bound on the heaviest load, given the reference's.
pub(in crate::parallel) fn bound(reference: u64) -> u64 {
    reference + reference / SLACK
}

/// The locality partition of `level` over `p` workers: the worker of each task.
pub(in crate::parallel) fn locality(level: &Level<'_>, p: usize, costs: Costs) -> Vec<usize> {
    let n = level.weights.len();
    if n == 0 || p < 2 {
        return level.reference.to_vec();
    }
    let mut assign = affinity_path(level, p, costs);
    let limit = bound(makespan(level.weights, level.reference, p));
    let units = units(level, &assign, p);
    if units.len() > MAX_UNITS {
        return level.reference.to_vec();
    }
    repair(level, p, costs, &units, &mut assign, limit);
    if makespan(level.weights, &assign, p) > limit {
        return level.reference.to_vec();
    }
    assign
}

/// Step 1: the cheapest assignment ignoring balance (costs in 1/128 steps: a byte is 1/64 of a
/// line, and the tie-break towards the reference half a unit). The path may break items as
/// often as the reference does (at most [`FREE_BREAKS_PER_WORKER`] per worker) for free —
/// balance needs them, wherever they fall; every further break costs an item. States are
/// (task, worker, free breaks used).
fn affinity_path(level: &Level<'_>, p: usize, costs: Costs) -> Vec<usize> {
    let n = level.weights.len();
    let aff = |i: usize, w: usize| level.affinity[i * p + w];
    let own = |i: usize, w: usize| -> u64 {
        let total: u64 = (0..p).map(|x| aff(i, x)).sum();
        (total - aff(i, w)) * costs.line_cost * 2 + u64::from(w != level.reference[i])
    };
    let free = (1..n)
        .filter(|&i| level.joins[i - 1] && level.reference[i] != level.reference[i - 1])
        .count()
        .min(FREE_BREAKS_PER_WORKER * p);
    let brk = costs.item_cost * 64 * 2;
    let k = free + 1;
    let state = |w: usize, used: usize| w * k + used;
    const INF: u64 = u64::MAX / 4;
    let mut best = vec![INF; p * k];
    for w in 0..p {
        best[state(w, 0)] = own(0, w);
    }
    // from[i][state]: the state of task i - 1.
    let mut from = vec![0u32; n * p * k];
    let mut next = vec![INF; p * k];
    for i in 1..n {
        next.fill(INF);
        for q in 0..p {
            for used in 0..k {
                let v = best[state(q, used)];
                if v >= INF {
                    continue;
                }
                for w in 0..p {
                    let (to, step) = if q == w || !level.joins[i - 1] {
                        (used, 0)
                    } else if used < free {
                        (used + 1, 0)
                    } else {
                        (used, brk)
                    };
                    let cand = v + step + own(i, w);
                    let s = state(w, to);
                    if cand < next[s] {
                        next[s] = cand;
                        from[i * p * k + s] = state(q, used) as u32;
                    }
                }
            }
        }
        std::mem::swap(&mut best, &mut next);
    }
    let mut s = (0..p * k).min_by_key(|&s| (best[s], s)).expect("p > 0");
    let mut out = vec![0usize; n];
    for i in (0..n).rev() {
        out[i] = s / k;
        s = from[i * p * k + s] as usize;
    }
    out
}

/// Step 2: runs of consecutive tasks of one worker, cut at a weight cap: ranges of tasks.
fn units(level: &Level<'_>, assign: &[usize], p: usize) -> Vec<std::ops::Range<usize>> {
    let total: u64 = level.weights.iter().sum();
    let cap = total.div_ceil(p as u64 * UNITS_PER_WORKER).max(1);
    let mut out = Vec::new();
    let (mut start, mut sum) = (0, 0u64);
    for i in 0..assign.len() {
        let w = level.weights[i];
        if i > start && (assign[i] != assign[i - 1] || sum + w > cap) {
            out.push(start..i);
            start = i;
            sum = 0;
        }
        sum += w;
    }
    out.push(start..assign.len());
    out
}

/// Step 3: moves units from the heaviest to the lightest worker until the heaviest is within
/// `limit` or no move lowers it.
fn repair(
    level: &Level<'_>,
    p: usize,
    costs: Costs,
    units: &[std::ops::Range<usize>],
    assign: &mut [usize],
    limit: u64,
) {
    let weights: Vec<u64> = units
        .iter()
        .map(|r| level.weights[r.clone()].iter().sum())
        .collect();
    let affinity: Vec<u64> = units
        .iter()
        .flat_map(|r| (0..p).map(move |w| r.clone().map(|i| level.affinity[i * p + w]).sum()))
        .collect();
    let weight = |u: usize| weights[u];
    let aff = |u: usize, w: usize| affinity[u * p + w];
    // Items joined with unit `u` on worker `w` (its neighbours there, if one walk).
    let joins_on = |assign: &[usize], u: usize, w: usize| -> u64 {
        let r = &units[u];
        let left = r.start > 0 && level.joins[r.start - 1] && assign[r.start - 1] == w;
        let right = r.end < assign.len() && level.joins[r.end - 1] && assign[r.end] == w;
        u64::from(left) + u64::from(right)
    };
    let mut load = loads(level.weights, assign, p);
    for _ in 0..units.len() * p {
        let h = (0..p)
            .max_by_key(|&w| (load[w], usize::MAX - w))
            .expect("p > 0");
        let l = (0..p).min_by_key(|&w| (load[w], w)).expect("p > 0");
        if load[h] <= limit {
            return;
        }
        let gap = load[h] - load[l];
        let best = (0..units.len())
            .filter(|&u| assign[units[u].start] == h && weight(u) < gap)
            .min_by_key(|&u| {
                let lost = (aff(u, h) as i128 - aff(u, l) as i128) * costs.line_cost as i128;
                let items = joins_on(assign, u, h) as i128 - joins_on(assign, u, l) as i128;
                let off_reference = level.reference[units[u].start] != l;
                (
                    lost + items * costs.item_cost as i128 * 64,
                    off_reference,
                    u,
                )
            });
        let Some(u) = best else {
            return;
        };
        for i in units[u].clone() {
            assign[i] = l;
        }
        let w = weight(u);
        load[h] -= w;
        load[l] += w;
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    const COSTS: Costs = Costs {
        line_cost: 20,
        item_cost: 12,
    };

    /// Contiguous halves, as the reference.
    fn halves(n: usize) -> Vec<usize> {
        (0..n).map(|i| usize::from(i >= n / 2)).collect()
    }

    #[test]
    fn without_affinity_it_is_the_reference() {
        let w = [3u64; 10];
        let aff = [0u64; 20];
        let joins = [true; 10];
        let r = halves(10);
        let level = Level {
            weights: &w,
            affinity: &aff,
            joins: &joins,
            reference: &r,
        };
        assert_eq!(locality(&level, 2, COSTS), r);
    }

    #[test]
    fn chains_stay_with_their_producer_when_the_order_is_swapped() {
        // Tasks 0..4 read what worker 1 wrote, tasks 4..8 what worker 0 wrote: the reference
        // (halves) puts every task away from its producer; the partition swaps the halves.
        let w = [5u64; 8];
        let mut aff = vec![0u64; 16];
        for i in 0..8 {
            aff[i * 2 + usize::from(i < 4)] = 4;
        }
        let joins = [true; 8];
        let r = halves(8);
        let level = Level {
            weights: &w,
            affinity: &aff,
            joins: &joins,
            reference: &r,
        };
        assert_eq!(locality(&level, 2, COSTS), [1, 1, 1, 1, 0, 0, 0, 0]);
    }

    #[test]
    fn one_producer_for_everything_is_repaired_to_the_bound() {
        // Every task reads worker 0's output: the path puts all on 0, the repair moves the tail.
        let w = [1u64; 32];
        let aff: Vec<u64> = (0..64).map(|k| if k % 2 == 0 { 1 } else { 0 }).collect();
        let joins = [true; 32];
        let r = halves(32);
        let level = Level {
            weights: &w,
            affinity: &aff,
            joins: &joins,
            reference: &r,
        };
        let a = locality(&level, 2, COSTS);
        assert!(makespan(&w, &a, 2) <= bound(16), "{a:?}");
        // Moved from the end, one run per worker: two items.
        let breaks = a.windows(2).filter(|x| x[0] != x[1]).count();
        assert_eq!(breaks, 1, "{a:?}");
    }

    fn arb_level() -> impl Strategy<Value = (usize, Vec<u64>, Vec<u64>, Vec<bool>)> {
        (2usize..5, 1usize..60).prop_flat_map(|(p, n)| {
            (
                Just(p),
                proptest::collection::vec(1u64..50, n),
                proptest::collection::vec(0u64..20, n * p),
                proptest::collection::vec(any::<bool>(), n),
            )
        })
    }

    /// The simple reference: LPT's assignment (each task to the least loaded worker, heaviest
    /// first).
    fn lpt_assign(w: &[u64], p: usize) -> Vec<usize> {
        let mut order: Vec<usize> = (0..w.len()).collect();
        order.sort_by(|&a, &b| w[b].cmp(&w[a]).then(a.cmp(&b)));
        let mut load = vec![0u64; p];
        let mut out = vec![0; w.len()];
        for i in order {
            let k = (0..p).min_by_key(|&k| (load[k], k)).unwrap();
            load[k] += w[i];
            out[i] = k;
        }
        out
    }

    proptest! {
        #[test]
        fn every_task_once_and_the_bound_holds((p, w, aff, joins) in arb_level()) {
            let r = lpt_assign(&w, p);
            let level = Level { weights: &w, affinity: &aff, joins: &joins, reference: &r };
            let a = locality(&level, p, COSTS);
            prop_assert_eq!(a.len(), w.len());
            prop_assert!(a.iter().all(|&k| k < p));
            prop_assert!(makespan(&w, &a, p) <= bound(makespan(&w, &r, p)));
        }

        #[test]
        fn tasks_that_read_one_worker_only_stay_there_when_that_is_balanced(
            p in 2usize..5, per in 1usize..12, weight in 1u64..30,
        ) {
            // Chain k: tasks k*per..(k+1)*per, one walk, reading only worker (k+1)%p's output
            // (the previous level ran the chains shifted by one). Equal weights: the bound
            // holds with each chain on its producer.
            let n = p * per;
            let w = vec![weight; n];
            let mut aff = vec![0u64; n * p];
            let home = |i: usize| (i / per + 1) % p;
            for i in 0..n {
                aff[i * p + home(i)] = 8;
            }
            let joins: Vec<bool> = (0..n).map(|i| (i + 1) % per != 0).collect();
            let r: Vec<usize> = (0..n).map(|i| i / per).collect();
            let level = Level { weights: &w, affinity: &aff, joins: &joins, reference: &r };
            let a = locality(&level, p, COSTS);
            for i in 0..n {
                prop_assert_eq!(a[i], home(i), "task {} in {:?}", i, a);
            }
        }
    }
}
