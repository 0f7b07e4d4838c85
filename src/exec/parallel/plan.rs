//! The static plan: the schedule's levels turned into phases and per-worker slices of items
//! (the dynamic programme over the levels, contiguous or LPT slicing, decision slots, guards and
//! entries), the layout groups, and the plan's accessors.

use super::calls::{call_closure, is_loop_back, rung_callees, uncovered_refusal};
use super::config::{PlanConfig, Slicing, Strategy};
use super::tasks::{contiguous, lpt, Tasks};
use crate::analysis::{schedule::TaskId, Analysis, EdgeKind, Successor};
use crate::model::{PouId, Program, VarId};
use std::collections::HashMap;
use std::ops::Range;

pub(super) const NONE: u32 = u32::MAX;
/// Decision value: the task did not run this scan.
pub(super) const NOT_RUN: u32 = u32::MAX;
/// Decision value: control left to the end of the scan.
pub(super) const STOP: u32 = u32::MAX - 1;
/// Decision value flag: control left to the FOR test of this head rung (never for tasks of the
/// combined schedule, but encoded exactly anyway).
pub(super) const FOR_TEST: u32 = 1 << 31;
/// Decision slots per 64-byte line.
pub(super) const DECISION_LINE: usize = 16;

/// Which rungs a walk of the interpreter may visit.
#[derive(Copy, Clone, Debug, PartialEq, Eq)]
pub(super) enum Region {
    /// Rungs `lo..hi` (the run's rungs are exactly this range).
    Rungs(u32, u32),
    /// Rungs whose task is in `lo..=hi`.
    Tasks(u32, u32),
}

/// One call into the interpreter: a run of tasks `first..=last`, or one guarded or
/// multi-entry task.
#[derive(Clone, Debug)]
pub(super) struct Item {
    pub(super) first: u32,
    pub(super) last: u32,
    /// The entry rung (single-entry tasks).
    pub(super) start: u32,
    pub(super) region: Region,
    /// Guard disjuncts: range into `Plan::guards`; empty: always runs.
    pub(super) guard: Range<u32>,
    /// Entry predecessors' decision slots (multi-entry loop tasks): range into
    /// `Plan::entry_slots`; empty: enter at `start`.
    pub(super) entries: Range<u32>,
    /// Decision slot of `last`, or NONE.
    pub(super) decision: u32,
    /// Modelled cost (tasks + item overhead).
    pub(super) cost: u64,
}

/// One phase of a scan.
#[derive(Clone, Debug)]
pub(super) struct Phase {
    pub(super) parallel: bool,
    /// The levels it runs.
    pub(super) levels: Range<usize>,
    /// Meet at the barrier before running it.
    pub(super) barrier_before: bool,
    /// Items per worker (a sequential phase has only worker 0's).
    pub(super) slices: Vec<Vec<Item>>,
}

/// What the plan decided for one level (for `--explain`).
#[derive(Clone, Debug)]
pub struct LevelPlan {
    /// Tasks of the level.
    pub tasks: usize,
    /// Σ task costs (steps).
    pub cost: u64,
    /// Whether the level is a parallel phase.
    pub parallel: bool,
    /// Modelled makespan of the parallel slices (steps; `None` if it cannot run in parallel).
    pub makespan: Option<u64>,
    /// "contiguous" or "lpt" (parallel levels).
    pub slicing: &'static str,
    /// Per worker: tasks, items, modelled cost (parallel levels).
    pub workers: Vec<(usize, usize, u64)>,
    /// Why.
    pub reason: String,
}

/// A static plan: phases, slices, decision slots and the padded layout. Built once per program
/// and thread count by [`ParallelMachine::new`](super::ParallelMachine::new).
#[derive(Clone, Debug)]
pub struct Plan {
    pub(super) threads: usize,
    pub(super) config: PlanConfig,
    /// `Some(reason)` when the whole program runs as the sequential scan.
    pub(super) sequential: Option<String>,
    pub(super) phases: Vec<Phase>,
    pub(super) end_barrier: bool,
    pub(super) levels: Vec<LevelPlan>,
    /// Task of each rung (main-program rungs that run), else NONE.
    pub(super) task_of_rung: Vec<u32>,
    /// Guard disjuncts: (decision slot of the controller, successor task or STOP).
    pub(super) guards: Vec<(u32, u32)>,
    /// Decision slots of entry predecessors.
    pub(super) entry_slots: Vec<u32>,
    pub(super) decision_slots: usize,
    /// Layout groups (variables written by one (phase, worker) set).
    pub(super) groups: Vec<Vec<VarId>>,
    /// Modelled scan costs: sequential, and this plan's.
    pub(super) est_sequential: u64,
    pub(super) est_plan: u64,
}

impl Plan {
    pub(super) fn build(p: &Program, a: &Analysis, config: &PlanConfig) -> Plan {
        let sched = &a.schedule;
        let nt = sched.tasks.len();
        let threads = config.threads.max(1);
        // Task numbers as plain indices, the way this planner works with them.
        let sched_levels: Vec<Vec<u32>> = sched
            .levels
            .iter()
            .map(|l| l.iter().map(|t| t.0).collect())
            .collect();
        let mut task_of_rung = vec![NONE; p.rungs.len()];
        for (r, t) in sched.task_of.iter().enumerate() {
            if let Some(t) = t {
                task_of_rung[r] = t.0;
            }
        }
        // Condensed successors and entry predecessors from the main program's live CFG edges.
        let n = p.rungs.len() as u32;
        let stop = a.cfg.stop().0;
        let mut succs: Vec<Vec<u32>> = vec![Vec::new(); nt];
        let mut entry_preds: Vec<Vec<u32>> = vec![Vec::new(); nt];
        for e in &a.cfg.edges {
            if matches!(e.kind, EdgeKind::Call | EdgeKind::Return) || e.from.0 >= n {
                continue;
            }
            let ta = task_of_rung[e.from.0 as usize];
            if ta == NONE {
                continue;
            }
            let tb = if e.to.0 == stop {
                STOP
            } else if e.to.0 < n {
                task_of_rung[e.to.0 as usize]
            } else {
                continue;
            };
            if tb == ta || tb == NONE {
                continue;
            }
            succs[ta as usize].push(tb);
            if tb != STOP && sched.tasks[tb as usize].entries.len() > 1 {
                entry_preds[tb as usize].push(ta);
            }
        }
        let mut needs_decision = vec![false; nt];
        for t in 0..nt {
            succs[t].sort_unstable();
            succs[t].dedup();
            entry_preds[t].sort_unstable();
            entry_preds[t].dedup();
            for &q in &entry_preds[t] {
                needs_decision[q as usize] = true;
            }
            for g in &sched.tasks[t].guard {
                needs_decision[g.controller.index()] = true;
            }
        }
        let only_succ: Vec<u32> = succs
            .iter()
            .map(|s| {
                if s.len() == 1 && s[0] != STOP {
                    s[0]
                } else {
                    NONE
                }
            })
            .collect();
        let cost: Vec<u64> = sched
            .tasks
            .iter()
            .map(|t| {
                t.rungs
                    .iter()
                    .map(|r| a.rung_costs[r.index()])
                    .sum::<u64>()
                    .max(1)
            })
            .collect();
        let info = Tasks {
            a,
            cost,
            only_succ,
            needs_decision,
            entry_preds,
        };
        let est_sequential: u64 = info.cost.iter().sum();

        // Levels that must not run in parallel: tasks sharing a subroutine's loop counters.
        let closure = call_closure(p);
        let pou_loops: Vec<bool> = (0..p.pous.len())
            .map(|pou| p.pou_rungs(PouId(pou as u32)).any(|r| is_loop_back(p, r)))
            .collect();
        let mut level_conflict: Vec<Option<String>> = vec![None; sched.levels.len()];
        for (l, level) in sched_levels.iter().enumerate() {
            let mut user: HashMap<u32, u32> = HashMap::new();
            'level: for &t in level {
                let mut pous: Vec<u32> = Vec::new();
                for &r in &sched.tasks[t as usize].rungs {
                    pous.extend(
                        rung_callees(p, &closure, r)
                            .into_iter()
                            .filter(|&c| pou_loops[c as usize]),
                    );
                }
                pous.sort_unstable();
                pous.dedup();
                for c in pous {
                    if let Some(&other) = user.get(&c) {
                        level_conflict[l] = Some(format!(
                            "tasks {} and {} both call {}, whose loop counters they would share",
                            p.rung(sched.head(TaskId(other))).id,
                            p.rung(sched.head(TaskId(t))).id,
                            p.pous[c as usize].name
                        ));
                        break 'level;
                    }
                    user.insert(c, t);
                }
            }
        }

        // Per level: sequential cost, parallel slices and makespan.
        let mut level_plans = Vec::with_capacity(sched.levels.len());
        let mut level_slices: Vec<Option<Vec<Vec<u32>>>> = Vec::with_capacity(sched.levels.len());
        for (l, level) in sched_levels.iter().enumerate() {
            let weights: Vec<u64> = level.iter().map(|&t| info.cost[t as usize]).collect();
            let c: u64 = weights.iter().sum();
            let mut lp = LevelPlan {
                tasks: level.len(),
                cost: c,
                parallel: false,
                makespan: None,
                slicing: "",
                workers: Vec::new(),
                reason: String::new(),
            };
            let forced = config.strategy == Strategy::AllParallel;
            if let Some(why) = &level_conflict[l] {
                lp.reason = why.clone();
                level_slices.push(None);
            } else if (threads == 1 || level.len() < 2) && !forced {
                lp.reason = if threads == 1 {
                    "one worker".into()
                } else {
                    "a single task".into()
                };
                level_slices.push(None);
            } else {
                let slice_cost = |s: &[u32]| -> (usize, u64) {
                    let items = info.items(s, config.item_cost);
                    (items.len(), items.iter().map(|i| i.cost).sum())
                };
                let contig: Vec<Vec<u32>> = contiguous(&weights, threads)
                    .into_iter()
                    .map(|r| level[r].to_vec())
                    .collect();
                let by_lpt = lpt(level, &weights, threads);
                let ms = |sl: &[Vec<u32>]| sl.iter().map(|s| slice_cost(s).1).max().unwrap_or(0);
                let (m_c, m_l) = (ms(&contig), ms(&by_lpt));
                let (mut slices, name, m) = match config.slicing {
                    Slicing::Contiguous => (contig, "contiguous", m_c),
                    Slicing::Lpt => (by_lpt, "lpt", m_l),
                    Slicing::Auto if m_l < m_c => (by_lpt, "lpt", m_l),
                    Slicing::Auto => (contig, "contiguous", m_c),
                };
                slices.resize(threads, Vec::new());
                lp.makespan = Some(m);
                lp.slicing = name;
                lp.workers = slices
                    .iter()
                    .map(|s| {
                        let (items, cost) = slice_cost(s);
                        (s.len(), items, cost)
                    })
                    .collect();
                level_slices.push(Some(slices));
            }
            level_plans.push(lp);
        }

        // Phases: each level parallel (P) or sequential (S); a barrier between any two phases,
        // before a leading P and after a trailing P; adjacent S levels form one phase.
        let b = config.barrier_cost;
        let nl = sched.levels.len();
        const INF: u64 = u64::MAX / 4;
        // best[l][s], s = 0 (S) or 1 (P); from[l][s] = state of level l - 1.
        let mut best = vec![[INF; 2]; nl];
        let mut from = vec![[0usize; 2]; nl];
        for l in 0..nl {
            let c_s = level_plans[l].cost + config.item_cost;
            let c_p = match (config.strategy, level_plans[l].makespan) {
                (Strategy::Sequential, _) | (_, None) => INF,
                (_, Some(m)) => m,
            };
            for s in 0..2 {
                let own = if s == 0 { c_s } else { c_p };
                if own >= INF {
                    continue;
                }
                if l == 0 {
                    best[0][s] = own + if s == 1 { b } else { 0 };
                    continue;
                }
                for prev in 0..2 {
                    let barrier = if prev == 1 || s == 1 { b } else { 0 };
                    let v = best[l - 1][prev].saturating_add(own + barrier);
                    if v < best[l][s] {
                        best[l][s] = v;
                        from[l][s] = prev;
                    }
                }
            }
            if config.strategy == Strategy::AllParallel && best[l][1] < INF {
                best[l][0] = INF; // force P wherever possible
            }
        }
        let mut choice = vec![0usize; nl];
        let mut est_plan = 0;
        if nl > 0 {
            let end = |s: usize| best[nl - 1][s].saturating_add(if s == 1 { b } else { 0 });
            let mut s = if end(1) < end(0) { 1 } else { 0 };
            est_plan = end(s);
            for l in (0..nl).rev() {
                choice[l] = s;
                s = from[l][s];
            }
        }
        let any_parallel = choice.contains(&1);
        let sequential = if let Some(why) = uncovered_refusal(p, a, &task_of_rung) {
            Some(why)
        } else if config.strategy == Strategy::Sequential {
            Some("sequential strategy requested".into())
        } else if threads == 1 && config.strategy == Strategy::Auto {
            Some("one worker".into())
        } else if !any_parallel {
            Some("no level saves more than the barriers it needs".into())
        } else if config.strategy == Strategy::Auto && est_plan + b > est_sequential {
            Some(format!(
                "the best plan ({est_plan} steps per scan with barriers) does not beat the sequential scan ({est_sequential} steps) by a barrier"
            ))
        } else {
            None
        };
        for (l, lp) in level_plans.iter_mut().enumerate() {
            lp.parallel = sequential.is_none() && choice[l] == 1;
            if lp.reason.is_empty() {
                lp.reason = match (lp.parallel, lp.makespan) {
                    (true, Some(m)) => format!(
                        "saves {} steps, more than a barrier ({b})",
                        lp.cost.saturating_sub(m)
                    ),
                    (false, Some(m)) if sequential.is_some() => {
                        format!("the whole program runs sequentially (makespan {m})")
                    }
                    (false, Some(m)) if lp.cost.saturating_sub(m) <= b => format!(
                        "saves {} steps, not more than a barrier ({b}): sequential",
                        lp.cost.saturating_sub(m)
                    ),
                    (false, Some(m)) => format!(
                        "saves {} steps, less than the barriers it would add between its \
                         neighbours (barrier {b}): sequential",
                        lp.cost.saturating_sub(m)
                    ),
                    _ => String::new(),
                };
            }
        }
        let mut plan = Plan {
            threads,
            config: *config,
            sequential,
            phases: Vec::new(),
            end_barrier: false,
            levels: level_plans,
            task_of_rung,
            guards: Vec::new(),
            entry_slots: Vec::new(),
            decision_slots: 0,
            groups: Vec::new(),
            est_sequential,
            est_plan: if any_parallel {
                est_plan
            } else {
                est_sequential
            },
        };
        if plan.sequential.is_some() {
            return plan;
        }

        // Phases and their items.
        let mut l = 0;
        while l < nl {
            if choice[l] == 1 {
                let slices = level_slices[l].take().expect("parallel level has slices");
                let items = slices
                    .iter()
                    .map(|s| info.items(s, config.item_cost))
                    .collect();
                plan.phases.push(Phase {
                    parallel: true,
                    levels: l..l + 1,
                    barrier_before: true,
                    slices: items,
                });
                l += 1;
            } else {
                let start = l;
                while l < nl && choice[l] == 0 {
                    l += 1;
                }
                let mut tasks: Vec<u32> =
                    sched_levels[start..l].iter().flatten().copied().collect();
                tasks.sort_unstable();
                let barrier_before = start > 0; // after a P phase
                plan.phases.push(Phase {
                    parallel: false,
                    levels: start..l,
                    barrier_before,
                    slices: vec![info.items(&tasks, config.item_cost)],
                });
            }
        }
        plan.end_barrier = plan.phases.last().is_some_and(|ph| ph.parallel);

        // Decision slots, grouped per (phase, worker) and padded to a line.
        let mut slot_of_task = vec![NONE; nt];
        let mut next = 0usize;
        for ph in &plan.phases {
            for slice in &ph.slices {
                let before = next;
                for it in slice {
                    for t in it.first..=it.last {
                        if info.needs_decision[t as usize] {
                            slot_of_task[t as usize] = next as u32;
                            next += 1;
                        }
                    }
                }
                if next > before {
                    next = next.div_ceil(DECISION_LINE) * DECISION_LINE;
                }
            }
        }
        plan.decision_slots = next;
        for ph in &mut plan.phases {
            for slice in &mut ph.slices {
                for it in slice {
                    debug_assert!(
                        (it.first..it.last).all(|t| slot_of_task[t as usize] == NONE),
                        "only the last task of a run decides"
                    );
                    it.decision = slot_of_task[it.last as usize];
                    let task = &sched.tasks[it.first as usize];
                    let g0 = plan.guards.len() as u32;
                    for g in &task.guard {
                        let succ = match g.successor {
                            Successor::Task(s) => s.0,
                            Successor::Stop => STOP,
                        };
                        plan.guards.push((slot_of_task[g.controller.index()], succ));
                    }
                    it.guard = g0..plan.guards.len() as u32;
                    if task.entries.len() > 1 {
                        let e0 = plan.entry_slots.len() as u32;
                        for &q in &info.entry_preds[it.first as usize] {
                            plan.entry_slots.push(slot_of_task[q as usize]);
                        }
                        it.entries = e0..plan.entry_slots.len() as u32;
                    }
                }
            }
        }

        // Layout groups: variables keyed by the (phase, worker) pairs that write them.
        let mut key_of: Vec<Vec<(u32, u32)>> = vec![Vec::new(); p.vars.len()];
        for (pi, ph) in plan.phases.iter().enumerate() {
            if !ph.parallel {
                continue;
            }
            for (w, slice) in ph.slices.iter().enumerate() {
                for it in slice {
                    for t in it.first..=it.last {
                        for r in &sched.tasks[t as usize].rungs {
                            for &v in a.accesses.outs(*r) {
                                let key = &mut key_of[v.index()];
                                if key.last() != Some(&(pi as u32, w as u32)) {
                                    key.push((pi as u32, w as u32));
                                }
                            }
                        }
                    }
                }
            }
        }
        let mut group_of: HashMap<&[(u32, u32)], usize> = HashMap::new();
        let mut order: Vec<(u32, u32, usize)> = Vec::new(); // (first pair, group) for ordering
        let mut groups: Vec<Vec<VarId>> = Vec::new();
        for (v, key) in key_of.iter().enumerate() {
            if key.is_empty() {
                continue;
            }
            let g = *group_of.entry(key.as_slice()).or_insert_with(|| {
                groups.push(Vec::new());
                order.push((key[0].0, key[0].1, groups.len() - 1));
                groups.len() - 1
            });
            groups[g].push(VarId(v as u32));
        }
        order.sort_unstable();
        plan.groups = order
            .into_iter()
            .map(|(_, _, g)| std::mem::take(&mut groups[g]))
            .collect();
        plan
    }

    /// The number of workers.
    pub fn threads(&self) -> usize {
        self.threads
    }

    /// `Some(reason)` when the whole program runs as the sequential scan.
    pub fn sequential(&self) -> Option<&str> {
        self.sequential.as_deref()
    }

    /// The per-level decisions.
    pub fn levels(&self) -> &[LevelPlan] {
        &self.levels
    }

    /// Number of phases per scan (0 when sequential).
    pub fn phase_count(&self) -> usize {
        self.phases.len()
    }

    /// Number of parallel phases per scan.
    pub fn parallel_phases(&self) -> usize {
        self.phases.iter().filter(|p| p.parallel).count()
    }

    /// Barriers per scan.
    pub fn barriers_per_scan(&self) -> usize {
        self.phases.iter().filter(|p| p.barrier_before).count() + self.end_barrier as usize
    }

    /// Modelled steps per scan: (sequential scan, this plan).
    pub fn estimates(&self) -> (u64, u64) {
        (self.est_sequential, self.est_plan)
    }

    /// The configuration it was built with.
    pub fn config(&self) -> &PlanConfig {
        &self.config
    }
}
