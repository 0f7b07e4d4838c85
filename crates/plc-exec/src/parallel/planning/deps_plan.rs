//! The dependence-driven plan: ready flags instead of a barrier per level. Each worker runs
//! its tasks of all levels in level order, in one parallel phase per scan, and before a task
//! waits only for the tasks it depends on that run on another worker — the latest of them per
//! other worker, and only when no earlier wait of the worker already implies it (a vector clock
//! per worker, in the manner of Lamport's happened-before). A worker publishes "I have finished
//! my k-th item of this scan" as one counter (`flags`); a wait reads it.
//!
//! Which worker runs a task ([`DepsPartition`]): the levelled plan's slice of its level
//! (`slicing`: contiguous, LPT or locality), where dependences cross between the workers both
//! ways, so that at every level each worker may wait for the other (a lockstep of round trips
//! between the cores); or the one-way partition (`one_way`), where a worker depends only on the
//! workers before it in a chain, worker 0 never waits and the others follow it. Under
//! [`DepsPartition::Auto`] the one-way partition is taken when its modelled scan is at most
//! 1/32 longer (the model prices each wait, not the lockstep): on `plc-deps gen` programs it is
//! as balanced as the slices and has a quarter of their waits; on programs whose tasks read from
//! across the whole level before (random reads) it piles up on the last worker and loses. In
//! the one-way partition a wait for one of a level's exports waits for all of them (they run
//! first), and items end after every task a wait names, so that it is published at once.
//!
//! Which pairs are ordered: the schedule's `preds` (flow, anti and output dependences over the
//! task accesses, the guards' controllers and the entry predecessors of multi-entry loops: what
//! the levels respect), plus, for tasks that call one subroutine with loops (whose loop
//! counters they share), each user after the previous one in level order. Levels that the
//! levelled plan cannot slice (one task, or tasks sharing such counters) go to one worker: a
//! single task to the worker of its latest predecessor, several to worker 0 (in the one-way
//! partition: all to the latest worker of their predecessors).
//!
//! The cost model, deliberately simple: the critical path over the items with this assignment
//! (each item's steps and item overhead, the lines its level's slice moves at the start of the
//! slice, `wait_cost` per wait), plus the scan's two barriers (the start, after worker 0 wrote
//! the inputs, and the end). It ignores contention on the flags and lines moved by waits.
//!
//! Invariants: each worker's items are in level order and split before every task that waits;
//! a wait names another worker's item that publishes. The plan is proven against the lowered
//! code by `order_check` before it runs; this module does not check anything.

use super::calls::{call_closure, is_loop_back, rung_callees};
use super::one_way::{one_way, OneWay};
use super::plan::{level_conflicts, sequential_reason, task_facts, Phase, PhaseKind, Plan};
use super::ready::{item_order, Ready, Wait};
use super::slicing::{evaluate_levels, slice_levels, LevelPlan, Slices};
use super::tasks::{Item, Tasks};
use crate::parallel::config::{DepsPartition, PlanConfig};
use crate::parallel::ids::TaskId;
use plc_analysis::Analysis;
use plc_model::Program;

/// The assignment: each task's worker and position in its worker's list, and the lists.
struct Assignment {
    worker: Vec<u32>,
    pos: Vec<u32>,
    lists: Vec<Vec<TaskId>>,
}

/// Builds the dependence-driven plan of `config` (its kind is not looked at).
pub(in crate::parallel) fn build(p: &Program, a: &Analysis, config: &PlanConfig) -> Plan {
    let sched = &a.schedule;
    let threads = config.threads.max(1);
    let info = task_facts(p, a, &sched.task_of, config);
    let est_sequential: u64 = info.cost.iter().sum();
    let conflicts = level_conflicts(p, a);
    let (levels, slices) = slice_levels(p, a, &info, config, &conflicts);
    let preds = task_preds(p, a);
    let by_levels = || {
        let asg = assign(a, threads, &slices, &preds);
        partitioned(&info, config, asg, &preds, None, levels.clone())
    };
    let by_chain = || {
        let whole: Vec<bool> = slices.iter().map(Option::is_none).collect();
        let ow = one_way(&sched.levels, &info.cost, &preds, &whole, threads);
        let chain: Vec<Option<Slices>> = ow.slices.iter().cloned().map(Some).collect();
        let asg = assign(a, threads, &chain, &preds);
        let round = export_ends(&asg, &ow);
        let chain_levels = evaluate_levels(p, a, &info, config, &ow.slices, "one-way", &levels);
        partitioned(&info, config, asg, &preds, Some(&round), chain_levels)
    };
    let part = match config.deps_partition {
        DepsPartition::Levels => by_levels(),
        DepsPartition::OneWay => by_chain(),
        DepsPartition::Auto if threads < 2 => by_levels(),
        DepsPartition::Auto => {
            let (l, c) = (by_levels(), by_chain());
            if c.est_plan * 32 <= l.est_plan * 33 {
                c
            } else {
                l
            }
        }
    };
    let (partition, mut levels, asg) = (part.partition, part.levels, part.asg);
    let (items, waits, cross) = (part.items, part.waits, part.cross);
    let (critical_path, est_plan) = (part.critical_path, part.est_plan);
    let any_parallel = items.iter().skip(1).any(|s| !s.is_empty());
    let sequential = sequential_reason(p, a, config, any_parallel, est_plan, est_sequential);
    for (l, lp) in levels.iter_mut().enumerate() {
        lp.parallel = sequential.is_none() && slices[l].is_some();
        if lp.parallel {
            lp.reason = "dependence-driven: its slices wait only for their producers".into();
        }
    }
    let ready = Ready {
        waits_per_worker: items
            .iter()
            .map(|s| s.iter().map(|it| it.waits.len() as u64).sum())
            .collect(),
        items_per_worker: items.iter().map(|s| s.len() as u64).collect(),
        publishing_per_worker: items
            .iter()
            .map(|s| s.iter().filter(|it| it.publish).count() as u64)
            .collect(),
        cross_dependences: cross,
        critical_path,
        partition,
    };
    let mut plan = Plan {
        threads,
        config: *config,
        sequential,
        phases: Vec::new(),
        end_barrier: false,
        remote: Vec::new(),
        item_remote: Vec::new(),
        levels,
        task_of_rung: sched.task_of.clone(),
        task_rungs: sched.tasks.iter().map(|t| t.rungs.clone()).collect(),
        guards: Vec::new(),
        entry_slots: Vec::new(),
        decision_slots: 0,
        write_keys: vec![Vec::new(); p.vars().len()],
        phase_lines: Vec::new(),
        est_sequential,
        est_plan,
        waits: Vec::new(),
        ready: Some(ready),
    };
    if plan.sequential.is_some() {
        return plan;
    }
    plan.phases = vec![Phase {
        kind: PhaseKind::Parallel(items),
        levels: 0..sched.levels.len(),
        barrier_before: true,
    }];
    plan.end_barrier = true;
    plan.waits = waits;
    plan.phase_lines = vec![plan.levels.iter().fold(vec![0; threads], |mut acc, lp| {
        for (w, n) in lp.lines.iter().enumerate() {
            acc[w] += n;
        }
        acc
    })];
    plan.place_decisions(a, &info);
    plan.write_keys = write_keys(p, a, &asg);
    plan
}

/// One partition of the tasks, its items and waits, and its modelled scan.
struct Partitioned {
    partition: DepsPartition,
    /// The levels as this partition cuts them (for the model's moved lines and `--explain`).
    levels: Vec<LevelPlan>,
    asg: Assignment,
    items: Vec<Vec<Item>>,
    waits: Vec<Wait>,
    cross: u64,
    critical_path: u64,
    est_plan: u64,
}

/// The items, waits and modelled scan of assignment `asg` (`round`: see `items_and_waits`).
fn partitioned(
    info: &Tasks<'_>,
    config: &PlanConfig,
    asg: Assignment,
    preds: &[Vec<TaskId>],
    round: Option<&[Vec<u32>]>,
    levels: Vec<LevelPlan>,
) -> Partitioned {
    let sched = &info.a.schedule;
    let (items, waits, cross) = items_and_waits(info, config, &asg, preds, round);
    let (critical_path, est_plan) = model(
        &items,
        &waits,
        |t| sched.task(t).level as usize,
        &levels,
        config,
    );
    Partitioned {
        levels,
        partition: if round.is_some() {
            DepsPartition::OneWay
        } else {
            DepsPartition::Levels
        },
        asg,
        items,
        waits,
        cross,
        critical_path,
        est_plan,
    }
}

/// Per worker and position in its list, the count of its tasks a waiter on that position
/// waits for instead: the end of the block of exports the position is in (the one-way
/// partition puts a level's exports first, so one wait covers all of them), else the
/// position itself plus one.
fn export_ends(asg: &Assignment, ow: &OneWay) -> Vec<Vec<u32>> {
    let mut round: Vec<Vec<u32>> = asg
        .lists
        .iter()
        .map(|l| (1..=l.len() as u32).collect())
        .collect();
    let mut at = vec![0u32; asg.lists.len()];
    for (slices, exports) in ow.slices.iter().zip(&ow.exports) {
        for (w, (s, &e)) in slices.iter().zip(exports).enumerate() {
            let start = at[w];
            for p in start..start + e {
                round[w][p as usize] = start + e;
            }
            at[w] += s.len() as u32;
        }
    }
    round
}

/// Per task, the earlier tasks it must follow: the schedule's, and the previous user (in level
/// order) of each subroutine with loops it calls.
fn task_preds(p: &Program, a: &Analysis) -> Vec<Vec<TaskId>> {
    let sched = &a.schedule;
    let mut preds = sched.preds.clone();
    let closure = call_closure(p);
    let loops: Vec<bool> = (p.pous().ids())
        .map(|pou| p.pou_rungs(pou).any(|r| is_loop_back(p, r)))
        .collect();
    let mut last_user: Vec<Option<TaskId>> = vec![None; p.pous().len()];
    for &t in sched.levels.iter().flatten() {
        let mut pous: Vec<u32> = sched
            .task(t)
            .rungs
            .iter()
            .flat_map(|&r| rung_callees(p, &closure, r))
            .filter(|&c| loops[c as usize])
            .collect();
        pous.sort_unstable();
        pous.dedup();
        for c in pous {
            if let Some(q) = last_user[c as usize].replace(t) {
                if !preds[t.index()].contains(&q) {
                    preds[t.index()].push(q);
                }
            }
        }
    }
    preds
}

/// Each task's worker: its level's slice, or for a level without slices the worker of the
/// latest-placed predecessor of its single task (worker 0 for several tasks).
fn assign(
    a: &Analysis,
    threads: usize,
    slices: &[Option<Slices>],
    preds: &[Vec<TaskId>],
) -> Assignment {
    let sched = &a.schedule;
    let nt = sched.tasks.len();
    let mut worker = vec![0u32; nt];
    // Order of placement, for "latest" (every predecessor is placed before its task).
    let mut placed: Vec<Option<u32>> = vec![None; nt];
    let mut lists: Vec<Vec<TaskId>> = vec![Vec::new(); threads];
    let mut pos = vec![0u32; nt];
    let mut n = 0u32;
    for (l, level) in sched.levels.iter().enumerate() {
        let per_worker: Vec<Vec<TaskId>> = match &slices[l] {
            Some(s) => s.clone(),
            None if level.len() == 1 => {
                let w = preds[level[0].index()]
                    .iter()
                    .max_by_key(|q| placed[q.index()])
                    .map_or(0, |q| worker[q.index()] as usize);
                let mut s = vec![Vec::new(); threads];
                s[w] = level.clone();
                s
            }
            None => {
                let mut s = vec![Vec::new(); threads];
                s[0] = level.clone();
                s
            }
        };
        for (w, tasks) in per_worker.into_iter().enumerate() {
            for t in tasks {
                worker[t.index()] = w as u32;
                pos[t.index()] = lists[w].len() as u32;
                placed[t.index()] = Some(n);
                n += 1;
                lists[w].push(t);
            }
        }
    }
    Assignment { worker, pos, lists }
}

/// Each worker's items, split before every task that waits, their waits (the latest needed
/// producer per other worker, unless already implied), and the number of cross-worker
/// dependences before that reduction.
fn items_and_waits(
    info: &Tasks<'_>,
    config: &PlanConfig,
    asg: &Assignment,
    preds: &[Vec<TaskId>],
    round: Option<&[Vec<u32>]>,
) -> (Vec<Vec<Item>>, Vec<Wait>, u64) {
    let threads = asg.lists.len();
    let nt = asg.worker.len();
    // Per task: what its worker knows has finished once it ends (tasks per worker).
    let mut after: Vec<Vec<u32>> = vec![Vec::new(); nt];
    let mut known: Vec<Vec<u32>> = vec![vec![0; threads]; threads];
    let mut task_waits: Vec<Vec<(usize, u32)>> = vec![Vec::new(); nt];
    let mut cross = 0u64;
    // Level by level, each worker's tasks of the level in its list's order (the order it runs
    // them in: the one-way partition reorders a level's tasks); tasks of one level are
    // independent, so how the workers interleave within a level does not matter.
    let sched = &info.a.schedule;
    let mut next = vec![0usize; threads];
    let mut order = Vec::with_capacity(nt);
    for l in 0..sched.levels.len() {
        for (w, list) in asg.lists.iter().enumerate() {
            while next[w] < list.len() && sched.task(list[next[w]]).level as usize == l {
                order.push(list[next[w]]);
                next[w] += 1;
            }
        }
    }
    for &t in &order {
        let w = asg.worker[t.index()] as usize;
        let mut need = vec![0u32; threads];
        for q in &preds[t.index()] {
            let wq = asg.worker[q.index()] as usize;
            if wq != w {
                cross += 1;
                let p = asg.pos[q.index()];
                let k = round.map_or(p + 1, |r| r[wq][p as usize]);
                if known[w][wq] < k {
                    need[wq] = need[wq].max(k);
                }
            }
        }
        for (wq, &k) in need.iter().enumerate() {
            if k > 0 {
                task_waits[t.index()].push((wq, k));
                let producer = asg.lists[wq][k as usize - 1];
                for (x, y) in known[w].iter_mut().zip(&after[producer.index()]) {
                    *x = (*x).max(*y);
                }
            }
        }
        known[w][w] = asg.pos[t.index()] + 1;
        after[t.index()] = known[w].clone();
    }
    // Items: a new segment at every task that waits, and after every task a wait waits for
    // (so that it is published as soon as it is done); a segment's first item carries its
    // waits.
    let mut published: Vec<Vec<bool>> = asg.lists.iter().map(|l| vec![false; l.len()]).collect();
    for ws in &task_waits {
        for &(wq, k) in ws {
            published[wq][k as usize - 1] = true;
        }
    }
    let mut items: Vec<Vec<Item>> = vec![Vec::new(); threads];
    let mut item_of_pos: Vec<Vec<u32>> = vec![Vec::new(); threads];
    for (w, list) in asg.lists.iter().enumerate() {
        let mut start = 0;
        while start < list.len() {
            let mut end = start + 1;
            while end < list.len()
                && task_waits[list[end].index()].is_empty()
                && !published[w][end - 1]
            {
                end += 1;
            }
            for it in info.items(&list[start..end], config.item_cost) {
                let n = (it.first.raw()..=it.last.raw()).count();
                item_of_pos[w].extend(std::iter::repeat_n(items[w].len() as u32, n));
                items[w].push(it);
            }
            start = end;
        }
    }
    let mut waits = Vec::new();
    for w in 0..threads {
        let mut i = 0;
        for it in items[w].iter_mut() {
            let w0 = waits.len() as u32;
            for &(wq, k) in &task_waits[asg.lists[w][i].index()] {
                let done = item_of_pos[wq][k as usize - 1] + 1;
                waits.push(Wait {
                    worker: wq as u32,
                    done,
                });
            }
            it.waits = w0..waits.len() as u32;
            i += (it.first.raw()..=it.last.raw()).count();
        }
    }
    for x in &waits {
        items[x.worker as usize][x.done as usize - 1].publish = true;
    }
    (items, waits, cross)
}

/// The modelled scan: (critical path, critical path + the scan's two barriers).
fn model(
    items: &[Vec<Item>],
    waits: &[Wait],
    task_level: impl Fn(TaskId) -> usize,
    levels: &[LevelPlan],
    config: &PlanConfig,
) -> (u64, u64) {
    let counts: Vec<usize> = items.iter().map(Vec::len).collect();
    let waits_of = |w: usize, i: usize| {
        let r = &items[w][i].waits;
        waits[r.start as usize..r.end as usize].to_vec()
    };
    let order = item_order(&counts, waits_of).expect("the planner's waits follow its order");
    let mut finish: Vec<Vec<u64>> = counts.iter().map(|&n| vec![0; n]).collect();
    for (w, i) in order {
        let it = &items[w][i];
        let mut start = if i > 0 { finish[w][i - 1] } else { 0 };
        for x in waits_of(w, i) {
            start = start.max(finish[x.worker as usize][x.done as usize - 1] + config.wait_cost);
        }
        // The lines a slice moves, once, at its first item.
        let l = task_level(it.first);
        let first_of_level = i == 0 || task_level(items[w][i - 1].first) != l;
        let lines = if first_of_level {
            levels[l].lines.get(w).copied().unwrap_or(0) * config.line_cost
        } else {
            0
        };
        finish[w][i] = start + it.cost + lines;
    }
    let critical = finish
        .iter()
        .filter_map(|f| f.last().copied())
        .max()
        .unwrap_or(0);
    (critical, critical + 2 * config.barrier_cost)
}

/// Per variable: its writer worker, or [`SEVERAL`] for a variable written on several workers.
///
/// The variables written on several workers share lines with each other (within the other
/// plans' groups): each one's writes are ordered by the plan's waits, and its line crosses
/// between the cores whatever else it holds, so the order check exempts such lines from its
/// line rule. Keying each by its writing tasks instead gave each a line of its own: on gen 20k
/// (7,723 variables written by two rungs four levels apart) that padded a few single-BOOL lines
/// into every level, the state grew from 45 to 51 KB, past a 48 KB L1, and the levelled plan on
/// private states, which touches all of it, ran 5 % slower for a plan it was not running.
fn write_keys(p: &Program, a: &Analysis, asg: &Assignment) -> Vec<Vec<(u32, u32)>> {
    let sched = &a.schedule;
    let mut writer: Vec<Option<u32>> = vec![None; p.vars().len()];
    for (t, task) in sched.tasks.iter().enumerate() {
        for r in &task.rungs {
            for &v in a.accesses.outs(*r) {
                let w = asg.worker[t];
                let k = &mut writer[v.index()];
                *k = match *k {
                    None => Some(w),
                    Some(o) if o == w => Some(w),
                    Some(_) => Some(SEVERAL),
                };
            }
        }
    }
    writer
        .into_iter()
        .map(|w| w.map(|w| (0, w)).into_iter().collect())
        .collect()
}

/// The layout key's worker of a variable written on several workers.
const SEVERAL: u32 = u32::MAX;
