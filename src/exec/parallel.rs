//! The parallel scan: the combined schedule (`analysis::schedule`) run level by level on several
//! threads, with a result identical — every slot and every fault, every scan — to
//! [`Machine::run_scan`].
//!
//! # Shape
//! Granularity decides everything: a rung of 6 contacts and a coil costs about 3.5 ns, a level
//! of a thousand of them a few µs, so the executor must not pay a thread wake-up per level. The
//! workers are therefore entered **once per run** (one [`rayon::ThreadPool::in_place_scope`]
//! around all scans: the calling thread is worker 0, the pool supplies the others) and meet at a
//! spinning barrier ([`SpinBarrier`]) between the *phases* of every scan:
//!
//! - a **parallel phase** is one level of the schedule, cut statically into one *slice* per
//!   worker, balanced on the cost model (`Analysis::rung_costs`): contiguous runs of tasks
//!   (best for many small rungs: a slice of consecutive rungs is one call into the interpreter)
//!   or LPT (best for a few large tasks), whichever the model says finishes first;
//! - a **sequential phase** is a run of consecutive levels that cannot pay for a barrier, merged
//!   and run by worker 0 alone, in task order;
//! - when nothing pays, the whole program runs as the sequential scan ([`Plan::sequential`]).
//!
//! The choice is a small dynamic programme over the levels (each level parallel or sequential,
//! a barrier at every change and between parallel levels; sequential levels next to each other
//! share their barriers): it minimises the modelled scan time `Σ parallel makespans + Σ
//! sequential costs + barriers × barrier_cost`, and the plan is used only if it beats the plain
//! sequential scan by more than one barrier. `plc-deps run --explain` prints the decisions.
//!
//! Per scan: worker 0 writes the inputs and zeroes the loop counters; barrier; every phase (a
//! barrier before a parallel phase and after it); worker 0 then merges the faults (into the
//! sequential order: by task index), hands the state to the caller, and starts the next scan.
//!
//! # Why it is exact
//! - Tasks of one level never touch a variable that another task of the level writes (the
//!   schedule's guarantee), and the loop counters of main-program loops belong to one task
//!   each; a level whose tasks may share a subroutine's loop counters is run sequentially.
//!   [`ParallelMachine::verify`] checks, slot by slot, that no slot written by a worker in a
//!   parallel phase is read or written by another worker of that phase (debug builds check it at
//!   construction).
//! - Control: after a task runs, the slot of its *decision* records where control left (the rung
//!   it went to, or STOP); a task that does not run records NOT_RUN. A task runs iff its guard is
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
//! # Memory
//! The state is one slot array shared by all workers without locks ([`SharedSlots`]: a raw
//! pointer; disjointness is the schedule's guarantee above, ordering comes from the barrier's
//! release/acquire). Its layout ([`Layout::from_groups`], 8-slot = 64-byte lines) groups the
//! variables by the set of (phase, worker) pairs that write them, so two workers never write the
//! same cache line in one phase; loop counters have a line each; decisions and fault buffers are
//! padded per worker.

use super::{ExecConfig, Exit, Fault, Layout, LowerError, Machine, State, Store};
use crate::analysis::{Analysis, EdgeKind, Successor};
use crate::model::{Element, PouId, Program, RungId, VarId};
use std::cell::UnsafeCell;
use std::collections::HashMap;
use std::fmt::Write as _;
use std::ops::Range;
use std::sync::atomic::{AtomicBool, AtomicU32, AtomicU64, Ordering};
use std::time::{Duration, Instant};

// ---------------------------------------------------------------- configuration

/// How levels are turned into phases.
#[derive(Copy, Clone, Debug, PartialEq, Eq)]
pub enum Strategy {
    /// The cost model decides (the default).
    Auto,
    /// Every level that may run in parallel is a parallel phase, whatever it costs (for tests:
    /// exercises the barriers, decisions and slices as much as possible).
    AllParallel,
    /// The whole program runs as the sequential scan.
    Sequential,
}

/// How a parallel level is cut into slices.
#[derive(Copy, Clone, Debug, PartialEq, Eq)]
pub enum Slicing {
    /// Contiguous or LPT, whichever the cost model says finishes first (ties: contiguous).
    Auto,
    /// Contiguous runs of tasks in task order, balanced by cost.
    Contiguous,
    /// Longest processing time first: each task to the least loaded worker.
    Lpt,
}

/// Parameters of the plan. Costs are in the cost model's element steps (a contact is 1; on the
/// machine the defaults were measured on, a step takes 0.5–2 ns).
#[derive(Copy, Clone, Debug, PartialEq, Eq)]
pub struct PlanConfig {
    /// Number of workers (threads), at least 1.
    pub threads: usize,
    /// Modelled cost of one barrier (all workers meeting), in steps.
    pub barrier_cost: u64,
    /// Modelled overhead of one item (one call into the interpreter: a run of tasks, or one
    /// guarded task), in steps.
    pub item_cost: u64,
    /// How levels become phases.
    pub strategy: Strategy,
    /// How parallel levels are sliced.
    pub slicing: Slicing,
}

impl PlanConfig {
    /// The defaults for `threads` workers, measured on a 2-core AMD EPYC: a barrier of two
    /// spinning workers takes 100–150 ns, a step of generated programs 0.5–2 ns (≈ 1 ns for
    /// 1,000 rungs): barrier 120 steps; an item (a call into the interpreter) ≈ 12 steps.
    pub fn new(threads: usize) -> PlanConfig {
        PlanConfig {
            threads: threads.max(1),
            barrier_cost: 120,
            item_cost: 12,
            strategy: Strategy::Auto,
            slicing: Slicing::Auto,
        }
    }
}

// ---------------------------------------------------------------- the plan

const NONE: u32 = u32::MAX;
/// Decision value: the task did not run this scan.
const NOT_RUN: u32 = u32::MAX;
/// Decision value: control left to the end of the scan.
const STOP: u32 = u32::MAX - 1;
/// Decision value flag: control left to the FOR test of this head rung (never for tasks of the
/// combined schedule, but encoded exactly anyway).
const FOR_TEST: u32 = 1 << 31;
/// Decision slots per 64-byte line.
const DECISION_LINE: usize = 16;

/// Which rungs a walk of the interpreter may visit.
#[derive(Copy, Clone, Debug, PartialEq, Eq)]
enum Region {
    /// Rungs `lo..hi` (the run's rungs are exactly this range).
    Rungs(u32, u32),
    /// Rungs whose task is in `lo..=hi`.
    Tasks(u32, u32),
}

/// One call into the interpreter: a run of tasks `first..=last`, or one guarded or
/// multi-entry task.
#[derive(Clone, Debug)]
struct Item {
    first: u32,
    last: u32,
    /// The entry rung (single-entry tasks).
    start: u32,
    region: Region,
    /// Guard disjuncts: range into `Plan::guards`; empty: always runs.
    guard: Range<u32>,
    /// Entry predecessors' decision slots (multi-entry loop tasks): range into
    /// `Plan::entry_slots`; empty: enter at `start`.
    entries: Range<u32>,
    /// Decision slot of `last`, or NONE.
    decision: u32,
    /// Modelled cost (tasks + item overhead).
    cost: u64,
}

/// One phase of a scan.
#[derive(Clone, Debug)]
struct Phase {
    parallel: bool,
    /// The levels it runs.
    levels: Range<usize>,
    /// Meet at the barrier before running it.
    barrier_before: bool,
    /// Items per worker (a sequential phase has only worker 0's).
    slices: Vec<Vec<Item>>,
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
/// and thread count by [`ParallelMachine::new`].
#[derive(Clone, Debug)]
pub struct Plan {
    threads: usize,
    config: PlanConfig,
    /// `Some(reason)` when the whole program runs as the sequential scan.
    sequential: Option<String>,
    phases: Vec<Phase>,
    end_barrier: bool,
    levels: Vec<LevelPlan>,
    /// Task of each rung (main-program rungs that run), else NONE.
    task_of_rung: Vec<u32>,
    /// Guard disjuncts: (decision slot of the controller, successor task or STOP).
    guards: Vec<(u32, u32)>,
    /// Decision slots of entry predecessors.
    entry_slots: Vec<u32>,
    decision_slots: usize,
    /// Layout groups (variables written by one (phase, worker) set).
    groups: Vec<Vec<VarId>>,
    /// Modelled scan costs: sequential, and this plan's.
    est_sequential: u64,
    est_plan: u64,
}

/// Facts about the tasks the planner needs.
struct Tasks<'a> {
    a: &'a Analysis,
    cost: Vec<u64>,
    /// The only condensed successor (task index), if there is exactly one and it is a task.
    only_succ: Vec<u32>,
    needs_decision: Vec<bool>,
    /// Tasks with a CFG edge into each multi-entry task.
    entry_preds: Vec<Vec<u32>>,
}

impl Tasks<'_> {
    fn unguarded_single(&self, t: u32) -> bool {
        let task = &self.a.schedule.tasks[t as usize];
        task.guard.is_empty() && task.entries.len() == 1
    }

    /// Whether `t` and `t + 1` can be one walk.
    fn chains(&self, t: u32) -> bool {
        self.only_succ[t as usize] == t + 1
            && !self.needs_decision[t as usize]
            && self.unguarded_single(t + 1)
    }

    /// The items of a slice (tasks ascending).
    fn items(&self, tasks: &[u32], item_cost: u64) -> Vec<Item> {
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

    fn item(&self, first: u32, last: u32, item_cost: u64) -> Item {
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
fn contiguous(weights: &[u64], p: usize) -> Vec<Range<usize>> {
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
fn lpt(tasks: &[u32], weights: &[u64], p: usize) -> Vec<Vec<u32>> {
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

/// Subroutines (transitively) called from each POU, and whether each POU has loop-back rungs.
fn call_closure(p: &Program) -> Vec<Vec<u32>> {
    let direct: Vec<Vec<u32>> = (0..p.pous.len())
        .map(|pou| {
            let mut calls = Vec::new();
            for r in p.pou_rungs(PouId(pou as u32)) {
                crate::model::walk_elements(&p.rung(r).series, &mut |e| {
                    if let Element::Call { pou } = e {
                        calls.push(pou.0);
                    }
                });
            }
            calls.sort_unstable();
            calls.dedup();
            calls
        })
        .collect();
    let mut closure: Vec<Option<Vec<u32>>> = vec![None; p.pous.len()];
    fn visit(pou: usize, direct: &[Vec<u32>], closure: &mut Vec<Option<Vec<u32>>>) -> Vec<u32> {
        if let Some(c) = &closure[pou] {
            return c.clone();
        }
        let mut all = Vec::new();
        for &c in &direct[pou] {
            all.push(c);
            all.extend(visit(c as usize, direct, closure));
        }
        all.sort_unstable();
        all.dedup();
        closure[pou] = Some(all.clone());
        all
    }
    (0..p.pous.len())
        .map(|pou| visit(pou, &direct, &mut closure))
        .collect()
}

/// Subroutines called (transitively) from a rung.
fn rung_callees(p: &Program, closure: &[Vec<u32>], r: RungId) -> Vec<u32> {
    let mut out = Vec::new();
    crate::model::walk_elements(&p.rung(r).series, &mut |e| {
        if let Element::Call { pou } = e {
            out.push(pou.0);
            out.extend_from_slice(&closure[pou.index()]);
        }
    });
    out.sort_unstable();
    out.dedup();
    out
}

/// Whether rung `r` holds a loop-back (a NEXT, or a backward jump).
fn is_loop_back(p: &Program, r: RungId) -> bool {
    let mut found = false;
    crate::model::walk_elements(&p.rung(r).series, &mut |e| match e {
        Element::Next { .. } => found = true,
        Element::Jmp { target, .. } if target.0 <= r.0 => found = true,
        _ => {}
    });
    found
}

/// The first main-program rung whose loop-cap refusal could lead where the schedule does not
/// expect control to go, with the reason; `None` if there is none.
fn uncovered_refusal(p: &Program, a: &Analysis, task_of: &[u32]) -> Option<String> {
    let n = p.rungs.len() as u32;
    let stop = a.cfg.stop();
    // Live CFG edges of the main program, by (task of source, target node).
    let mut edges: std::collections::HashSet<(u32, u32)> = std::collections::HashSet::new();
    for e in &a.cfg.edges {
        if matches!(e.kind, EdgeKind::Call | EdgeKind::Return)
            || e.from >= n
            || task_of[e.from as usize] == NONE
        {
            continue;
        }
        edges.insert((task_of[e.from as usize], e.to));
    }
    let main = p.main().rungs.clone();
    let mut found = Vec::new();
    for r in main.clone() {
        let t = task_of[r as usize];
        if t == NONE {
            continue;
        }
        let rung = p.rung(RungId(r));
        let next = if r + 1 < main.end { r + 1 } else { stop };
        let targets: Vec<u32> = match rung.series.last() {
            // A refused NEXT goes on to the rung after it: the FOR head's loop exit, which is in
            // the same task; checked like the others all the same.
            Some(Element::Next { .. }) => vec![next],
            _ => {
                found.clear();
                crate::analysis::cfg::transfers(&rung.series, &mut found);
                let unconditional_back = found.iter().any(|&(tr, always)| {
                    always && matches!(tr, crate::analysis::cfg::Transfer::Jump(x) if x.0 <= r)
                });
                if !unconditional_back {
                    continue; // a conditional backward jump's "not taken" paths are CFG edges
                }
                // After a refusal the rest of the rung runs: any of its transfers, or onwards.
                let mut ts = vec![next];
                crate::model::walk_elements(&rung.series, &mut |e| match e {
                    Element::Jmp { target, .. } => ts.push(target.0),
                    Element::Ret | Element::End => ts.push(stop),
                    _ => {}
                });
                ts
            }
        };
        for x in targets {
            let covered = if x == stop {
                edges.contains(&(t, stop))
            } else {
                task_of[x as usize] == t || (task_of[x as usize] != NONE && edges.contains(&(t, x)))
            };
            if !covered {
                let to = if x == stop {
                    "the end of the scan".to_string()
                } else {
                    format!("rung {}", p.rung(RungId(x)).id)
                };
                return Some(format!(
                    "rung {} loops back unconditionally; if the iteration cap refuses it, control goes on to {to}, a way the schedule does not know",
                    rung.id
                ));
            }
        }
    }
    None
}

impl Plan {
    fn build(p: &Program, a: &Analysis, config: &PlanConfig) -> Plan {
        let sched = &a.schedule;
        let nt = sched.tasks.len();
        let threads = config.threads.max(1);
        let mut task_of_rung = vec![NONE; p.rungs.len()];
        for (r, t) in sched.task_of.iter().enumerate() {
            if let Some(t) = t {
                task_of_rung[r] = *t;
            }
        }
        // Condensed successors and entry predecessors from the main program's live CFG edges.
        let n = p.rungs.len() as u32;
        let stop = a.cfg.stop();
        let mut succs: Vec<Vec<u32>> = vec![Vec::new(); nt];
        let mut entry_preds: Vec<Vec<u32>> = vec![Vec::new(); nt];
        for e in &a.cfg.edges {
            if matches!(e.kind, EdgeKind::Call | EdgeKind::Return) || e.from >= n {
                continue;
            }
            let ta = task_of_rung[e.from as usize];
            if ta == NONE {
                continue;
            }
            let tb = if e.to == stop {
                STOP
            } else if e.to < n {
                task_of_rung[e.to as usize]
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
                needs_decision[g.controller as usize] = true;
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
        for (l, level) in sched.levels.iter().enumerate() {
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
                            p.rung(sched.head(other)).id,
                            p.rung(sched.head(t)).id,
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
        for (l, level) in sched.levels.iter().enumerate() {
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
                    sched.levels[start..l].iter().flatten().copied().collect();
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
                            Successor::Task(s) => s,
                            Successor::Stop => STOP,
                        };
                        plan.guards
                            .push((slot_of_task[g.controller as usize], succ));
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

// ---------------------------------------------------------------- the machine

/// A program lowered for the parallel scan: a [`Machine`] on the plan's padded layout, and the
/// [`Plan`]. Immutable and `Sync`.
#[derive(Debug)]
pub struct ParallelMachine {
    machine: Machine,
    plan: Plan,
}

/// What a caller of [`ParallelMachine::run`] (or [`run_sequential`]) does around each scan. Both
/// methods are called on the calling thread, with exclusive access to the state.
pub trait ScanDriver {
    /// Before scan `scan`: write its inputs (`Machine::set_inputs_in`).
    fn before_scan(&mut self, machine: &Machine, scan: u64, slots: &mut [u64]);
    /// After scan `scan`: the state, the scan's faults in sequential order, and the time the
    /// scan took (inputs and this call excluded).
    fn after_scan(
        &mut self,
        machine: &Machine,
        scan: u64,
        slots: &[u64],
        faults: &[Fault],
        elapsed: Duration,
    );
    /// Whether the driver wants each scan timed (two clock reads per scan); `elapsed` is zero
    /// otherwise.
    fn wants_time(&self) -> bool {
        true
    }
}

/// Runs scans `scans` of the sequential interpreter on `state`, timing each one.
pub fn run_sequential<D: ScanDriver + ?Sized>(
    machine: &Machine,
    state: &mut State,
    scans: Range<u64>,
    driver: &mut D,
) {
    let mut faults = Vec::new();
    let timed = driver.wants_time();
    for scan in scans {
        driver.before_scan(machine, scan, &mut state.slots);
        faults.clear();
        let t0 = timed.then(Instant::now);
        machine.run_scan(state, scan, &mut faults);
        let elapsed = t0.map(|t| t.elapsed()).unwrap_or_default();
        driver.after_scan(machine, scan, &state.slots, &faults, elapsed);
    }
}

impl ParallelMachine {
    /// Plans `program` (analysed as `analysis`) for `config.threads` workers and lowers it on the
    /// plan's layout. In debug builds, also [`verify`](Self::verify)s the plan.
    pub fn new(
        program: &Program,
        analysis: &Analysis,
        exec: &ExecConfig,
        config: &PlanConfig,
    ) -> Result<ParallelMachine, LowerError> {
        let plan = Plan::build(program, analysis, config);
        let layout = if plan.sequential.is_some() {
            Layout::dense(program)
        } else {
            Layout::from_groups(program, &plan.groups, 8).expect("groups hold each variable once")
        };
        let machine = Machine::new(program, layout, exec)?;
        let pm = ParallelMachine { machine, plan };
        #[cfg(debug_assertions)]
        if let Err(e) = pm.verify(program, analysis) {
            panic!("parallel plan of {} is unsafe: {e}", program.name);
        }
        Ok(pm)
    }

    /// The machine (on the plan's layout).
    pub fn machine(&self) -> &Machine {
        &self.machine
    }

    /// The plan.
    pub fn plan(&self) -> &Plan {
        &self.plan
    }

    /// The state at load.
    pub fn initial_state(&self) -> State {
        self.machine.initial_state()
    }

    /// Checks, slot by slot, that in every parallel phase no slot written by one worker is read
    /// or written by another (variables through the rungs' IN/OUT sets, calls included; loop
    /// counters of the task's own and called loop-back rungs), and that no two tasks of a
    /// parallel phase write a variable the other reads or writes (the schedule's guarantee).
    pub fn verify(&self, p: &Program, a: &Analysis) -> Result<(), String> {
        let sched = &a.schedule;
        let layout = self.machine.layout();
        let closure = call_closure(p);
        let counter: HashMap<u32, u32> = self
            .machine
            .loop_counters()
            .map(|(r, s)| (r.0, s))
            .collect();
        let n_slots = self.machine.slot_count() as usize;
        // Per slot: (phase stamp, writer task, writer worker); readers checked against it.
        let mut stamp = vec![u32::MAX; n_slots];
        let mut writer = vec![(0u32, 0u32); n_slots];
        let task_slots = |t: u32| -> (Vec<u32>, Vec<u32>) {
            let (mut reads, mut writes) = (Vec::new(), Vec::new());
            for &r in &sched.tasks[t as usize].rungs {
                for &v in a.accesses.ins(r) {
                    reads.extend(layout.slots_of(v));
                }
                for &v in a.accesses.outs(r) {
                    writes.extend(layout.slots_of(v));
                }
                let mut rungs = vec![r];
                for c in rung_callees(p, &closure, r) {
                    rungs.extend(p.pou_rungs(PouId(c)));
                }
                for x in rungs {
                    if let Some(&s) = counter.get(&x.0) {
                        writes.push(s);
                    }
                }
            }
            (reads, writes)
        };
        let name = |t: u32| p.rung(sched.head(t)).id.clone();
        for (pi, ph) in self.plan.phases.iter().enumerate() {
            if !ph.parallel {
                continue;
            }
            let mut per_task: Vec<(u32, u32, Vec<u32>, Vec<u32>)> = Vec::new();
            for (w, slice) in ph.slices.iter().enumerate() {
                for it in slice {
                    for t in it.first..=it.last {
                        let (r, wr) = task_slots(t);
                        per_task.push((t, w as u32, r, wr));
                    }
                }
            }
            for (t, w, _, writes) in &per_task {
                for &s in writes {
                    let s = s as usize;
                    if stamp[s] == pi as u32 && writer[s].0 != *t {
                        let (t2, w2) = writer[s];
                        return Err(format!("phase {pi}: slot {s} written by tasks {} (worker {w2}) and {} (worker {w})", name(t2), name(*t)));
                    }
                    stamp[s] = pi as u32;
                    writer[s] = (*t, *w);
                }
            }
            for (t, w, reads, _) in &per_task {
                for &s in reads {
                    let s = s as usize;
                    if stamp[s] == pi as u32 && writer[s].0 != *t {
                        let (t2, w2) = writer[s];
                        return Err(format!("phase {pi}: slot {s} written by task {} (worker {w2}) and read by {} (worker {w})", name(t2), name(*t)));
                    }
                }
            }
        }
        Ok(())
    }

    /// One scan (enters the workers for this scan only; use [`run`](Self::run) for many).
    pub fn scan(
        &self,
        pool: Option<&rayon::ThreadPool>,
        state: &mut State,
        scan: u64,
        inputs: &[(VarId, crate::model::Value)],
        faults: &mut Vec<Fault>,
    ) {
        struct One<'a> {
            inputs: &'a [(VarId, crate::model::Value)],
            faults: &'a mut Vec<Fault>,
        }
        impl ScanDriver for One<'_> {
            fn before_scan(&mut self, m: &Machine, _: u64, slots: &mut [u64]) {
                m.set_inputs_in(slots, self.inputs);
            }
            fn after_scan(
                &mut self,
                _: &Machine,
                _: u64,
                _: &[u64],
                faults: &[Fault],
                _: Duration,
            ) {
                self.faults.extend_from_slice(faults);
            }
        }
        self.run(pool, state, scan..scan + 1, &mut One { inputs, faults });
    }

    /// Runs scans `scans` on `state`. The workers are entered once for all of them: the calling
    /// thread is worker 0 and `pool` supplies the others (it needs at least `threads − 1` threads,
    /// and may be `None` for one thread or a sequential plan).
    ///
    /// # Panics
    /// If the pool is too small, if called from one of the pool's threads, or if `state` is not
    /// a state of this machine.
    pub fn run<D: ScanDriver + ?Sized>(
        &self,
        pool: Option<&rayon::ThreadPool>,
        state: &mut State,
        scans: Range<u64>,
        driver: &mut D,
    ) {
        assert_eq!(
            state.slots.len(),
            self.machine.slot_count() as usize,
            "state of another machine"
        );
        if self.plan.sequential.is_some() {
            return run_sequential(&self.machine, state, scans, driver);
        }
        let threads = self.plan.threads;
        let decisions: Vec<AtomicU32> = (0..self.plan.decision_slots)
            .map(|_| AtomicU32::new(NOT_RUN))
            .collect();
        let faults: Vec<FaultBuffer> = (0..threads)
            .map(|_| Padded(UnsafeCell::new(Vec::new())))
            .collect();
        let shared = Shared {
            slots: SharedSlots {
                ptr: state.slots.as_mut_ptr(),
                len: state.slots.len(),
            },
            decisions: &decisions,
            faults: &faults,
            barrier: SpinBarrier::new(threads),
        };
        let shared = &shared;
        if threads == 1 {
            return self.worker(0, shared, scans, Some(driver));
        }
        let pool = pool.expect("a thread pool for more than one worker");
        assert!(
            pool.current_thread_index().is_none(),
            "run the parallel executor from outside its pool (worker 0 is the calling thread)"
        );
        assert!(
            pool.current_num_threads() >= threads - 1,
            "the pool has {} threads, {} workers need {}",
            pool.current_num_threads(),
            threads,
            threads - 1
        );
        pool.in_place_scope(|s| {
            for w in 1..threads {
                let scans = scans.clone();
                s.spawn(move |_| self.worker(w, shared, scans, None::<&mut D>));
            }
            self.worker(0, shared, scans, Some(driver));
        });
    }

    /// One worker's whole run. Worker 0 also runs the sequential phases and talks to the driver.
    fn worker<D: ScanDriver + ?Sized>(
        &self,
        w: usize,
        sh: &Shared<'_>,
        scans: Range<u64>,
        mut driver: Option<&mut D>,
    ) {
        let body = std::panic::AssertUnwindSafe(|| {
            let mut store = sh.slots;
            let mut epoch = 0u64;
            let mut scratch: Vec<Fault> = Vec::new();
            let mut merged: Vec<(u32, Fault)> = Vec::new();
            let mut out: Vec<Fault> = Vec::new();
            for scan in scans {
                let mut t0 = None;
                if let Some(d) = driver.as_deref_mut() {
                    // SAFETY: the other workers wait at the next barrier (or have not started):
                    // worker 0 has the slots to itself until it reaches that barrier.
                    let slots =
                        unsafe { std::slice::from_raw_parts_mut(sh.slots.ptr, sh.slots.len) };
                    d.before_scan(&self.machine, scan, slots);
                    t0 = d.wants_time().then(Instant::now);
                    self.machine.begin_scan(&mut store);
                }
                let mut ctx = self.machine.context(scan, &mut scratch);
                for ph in &self.plan.phases {
                    if ph.barrier_before && !sh.barrier.wait(w, &mut epoch) {
                        return;
                    }
                    let items: &[Item] = if ph.parallel {
                        &ph.slices[w]
                    } else if w == 0 {
                        &ph.slices[0]
                    } else {
                        &[]
                    };
                    for it in items {
                        self.run_item(it, &mut store, &mut ctx, sh);
                        if !ctx.faults.is_empty() {
                            // SAFETY: only worker `w` touches its fault buffer during a scan;
                            // worker 0 reads it after the scan's last barrier.
                            let buf = unsafe { &mut *sh.faults[w].0.get() };
                            buf.extend(ctx.faults.drain(..).map(|f| (it.first, f)));
                        }
                    }
                }
                if self.plan.end_barrier && !sh.barrier.wait(w, &mut epoch) {
                    return;
                }
                if let Some(d) = driver.as_deref_mut() {
                    let elapsed = t0.map(|t| t.elapsed()).unwrap_or_default();
                    // SAFETY: every other worker has passed the scan's last barrier and waits at
                    // the next scan's first one: worker 0 has the buffers and slots to itself.
                    merged.clear();
                    for f in sh.faults.iter() {
                        // SAFETY: as above; no other reference to the buffer exists now.
                        let buf = unsafe { &mut *f.0.get() };
                        merged.append(buf);
                    }
                    merged.sort_by_key(|&(t, _)| t); // stable: a task's faults keep their order
                    out.clear();
                    out.extend(merged.iter().map(|&(_, f)| f));
                    // SAFETY: as above: nobody writes the slots until worker 0 reaches the next
                    // barrier, after the driver returned.
                    let slots = unsafe { std::slice::from_raw_parts(sh.slots.ptr, sh.slots.len) };
                    d.after_scan(&self.machine, scan, slots, &out, elapsed);
                }
            }
        });
        if let Err(panic) = std::panic::catch_unwind(body) {
            sh.barrier.poison();
            std::panic::resume_unwind(panic);
        }
    }

    #[inline]
    fn decision_of(&self, sh: &Shared<'_>, slot: u32) -> u32 {
        // Relaxed: written in an earlier phase, ordered by the barrier in between.
        sh.decisions[slot as usize].load(Ordering::Relaxed)
    }

    /// The successor (task or STOP) a decision leads to; NOT_RUN stays NOT_RUN.
    #[inline]
    fn successor_of(&self, d: u32) -> u32 {
        match d {
            NOT_RUN | STOP => d,
            _ => self.plan.task_of_rung[(d & !FOR_TEST) as usize],
        }
    }

    #[inline]
    fn run_item(
        &self,
        it: &Item,
        store: &mut SharedSlots,
        ctx: &mut super::ScanCtx<'_>,
        sh: &Shared<'_>,
    ) {
        let plan = &self.plan;
        if !it.guard.is_empty() {
            let holds = plan.guards[it.guard.start as usize..it.guard.end as usize]
                .iter()
                .any(|&(slot, succ)| self.successor_of(self.decision_of(sh, slot)) == succ);
            if !holds {
                if it.decision != NONE {
                    sh.decisions[it.decision as usize].store(NOT_RUN, Ordering::Relaxed);
                }
                return;
            }
        }
        let at = if it.entries.is_empty() {
            Exit::Rung(RungId(it.start))
        } else {
            let mut at = None;
            for &slot in &plan.entry_slots[it.entries.start as usize..it.entries.end as usize] {
                let d = self.decision_of(sh, slot);
                if d != NOT_RUN && d != STOP && self.successor_of(d) == it.first {
                    debug_assert!(at.is_none(), "task {} entered twice", it.first);
                    at = Some(if d & FOR_TEST != 0 {
                        Exit::ForTest(RungId(d & !FOR_TEST))
                    } else {
                        Exit::Rung(RungId(d))
                    });
                }
            }
            match at {
                Some(at) => at,
                None => {
                    // No predecessor led here: the sequential scan does not run it either.
                    if it.decision != NONE {
                        sh.decisions[it.decision as usize].store(NOT_RUN, Ordering::Relaxed);
                    }
                    return;
                }
            }
        };
        let exit = match it.region {
            Region::Rungs(lo, hi) => self
                .machine
                .resume(store, ctx, at, |r| lo <= r.0 && r.0 < hi),
            Region::Tasks(lo, hi) => {
                let task_of = &plan.task_of_rung;
                self.machine.resume(store, ctx, at, |r| {
                    let t = task_of[r.index()];
                    lo <= t && t <= hi
                })
            }
        };
        if it.decision != NONE {
            let d = match exit {
                Exit::Stop => STOP,
                Exit::Rung(r) => r.0,
                Exit::ForTest(h) => h.0 | FOR_TEST,
            };
            sh.decisions[it.decision as usize].store(d, Ordering::Relaxed);
        }
    }

    /// `plc-deps run --explain`: the plan in words.
    pub fn explain(&self, p: &Program) -> String {
        let plan = &self.plan;
        let c = &plan.config;
        let mut s = String::new();
        let _ = writeln!(s, "parallel plan: {} worker(s), {} levels, cost model: barrier {} steps, item {} steps, strategy {:?}, slicing {:?}",
            plan.threads, plan.levels.len(), c.barrier_cost, c.item_cost, c.strategy, c.slicing);
        let (seq, est) = plan.estimates();
        let _ = writeln!(
            s,
            "modelled scan: sequential {seq} steps, this plan {est} steps ({:.2}x)",
            seq as f64 / est.max(1) as f64
        );
        if let Some(why) = &plan.sequential {
            let _ = writeln!(
                s,
                "decision: the whole program runs as the sequential scan: {why}"
            );
        } else {
            let _ = writeln!(
                s,
                "decision: {} phases per scan ({} parallel), {} barriers per scan",
                plan.phase_count(),
                plan.parallel_phases(),
                plan.barriers_per_scan()
            );
        }
        let shown = plan.levels.len().min(500);
        for (l, lp) in plan.levels.iter().take(shown).enumerate() {
            let kind = if lp.parallel {
                "parallel"
            } else {
                "sequential"
            };
            let _ = write!(
                s,
                "  level {:>3}: {:>6} tasks, cost {:>8}, {kind}",
                l + 1,
                lp.tasks,
                lp.cost
            );
            if let (true, Some(m)) = (lp.parallel, lp.makespan) {
                let _ = write!(s, " ({}, makespan {m}):", lp.slicing);
                for (w, (tasks, items, cost)) in lp.workers.iter().enumerate() {
                    let _ = write!(s, " w{w} {tasks} tasks/{items} items/{cost}");
                    if w + 1 < lp.workers.len() {
                        s.push(',');
                    }
                }
            }
            if !lp.reason.is_empty() {
                let _ = write!(s, " — {}", lp.reason);
            }
            s.push('\n');
        }
        if shown < plan.levels.len() {
            let _ = writeln!(s, "  ... {} more levels", plan.levels.len() - shown);
        }
        if plan.sequential.is_none() {
            for (i, ph) in plan.phases.iter().enumerate() {
                if !ph.parallel && ph.levels.len() > 1 {
                    let _ = writeln!(s, "  phase {}: levels {}..={} merged into one sequential phase (worker 0, task order)", i + 1, ph.levels.start + 1, ph.levels.end);
                }
            }
            let dense: u32 = p.vars.iter().map(|v| super::slot_width(v.ty)).sum();
            let m = &self.machine;
            let _ = writeln!(
                s,
                "padding: {} variable groups on 64-byte lines (one per set of (phase, worker) writers); {} slots for {} of data, {} loop counters (a line each), {} decision slots",
                plan.groups.len(),
                m.layout().slot_count(),
                dense,
                m.loop_counters().len(),
                plan.decision_slots
            );
        } else {
            let _ = writeln!(s, "padding: none (dense layout)");
        }
        s
    }

    /// The plan as JSON (`plc-deps run --explain --format json`).
    pub fn explain_json(&self) -> serde_json::Value {
        use serde_json::json;
        let plan = &self.plan;
        let (seq, est) = plan.estimates();
        json!({
            "threads": plan.threads,
            "sequential": plan.sequential,
            "barrier_cost": plan.config.barrier_cost,
            "item_cost": plan.config.item_cost,
            "modelled_steps": {"sequential": seq, "plan": est},
            "phases": plan.phase_count(),
            "parallel_phases": plan.parallel_phases(),
            "barriers_per_scan": plan.barriers_per_scan(),
            "slots": self.machine.slot_count(),
            "layout_groups": plan.groups.len(),
            "decision_slots": plan.decision_slots,
            "levels": plan.levels.iter().map(|lp| json!({
                "tasks": lp.tasks,
                "cost": lp.cost,
                "parallel": lp.parallel,
                "makespan": lp.makespan,
                "slicing": if lp.parallel { Some(lp.slicing) } else { None },
                "workers": lp.workers.iter().map(|&(t, i, c)| json!({"tasks": t, "items": i, "cost": c})).collect::<Vec<_>>(),
                "reason": lp.reason,
            })).collect::<Vec<_>>(),
        })
    }
}

// ---------------------------------------------------------------- shared memory

/// Pads its content to its own 128-byte block (two cache lines: also keeps the adjacent-line
/// prefetcher from coupling neighbours).
#[repr(align(128))]
struct Padded<T>(T);

/// The slot array shared by all workers, without locks.
#[derive(Copy, Clone)]
pub struct SharedSlots {
    ptr: *mut u64,
    len: usize,
}

// SAFETY: a `SharedSlots` is only created by `ParallelMachine::run` from the `&mut State` it
// holds for the whole run, and used by the workers under the plan's discipline: in a parallel
// phase, no slot written by one worker is read or written by another (checked by
// `ParallelMachine::verify`, from the schedule's guarantee), so there are no data races; between
// phases the barrier's release/acquire orders all accesses.
unsafe impl Send for SharedSlots {}
// SAFETY: as above.
unsafe impl Sync for SharedSlots {}

#[cold]
#[inline(never)]
fn out_of_range(slot: u32, len: usize) -> ! {
    panic!("slot {slot} out of range ({len} slots)")
}

impl Store for SharedSlots {
    #[inline(always)]
    fn get(&self, slot: u32) -> u64 {
        if slot as usize >= self.len {
            out_of_range(slot, self.len);
        }
        // SAFETY: in bounds (checked); no other worker writes this slot in this phase (the plan's
        // discipline, see the `Sync` impl).
        unsafe { self.ptr.add(slot as usize).read() }
    }
    #[inline(always)]
    fn set(&mut self, slot: u32, v: u64) {
        if slot as usize >= self.len {
            out_of_range(slot, self.len);
        }
        // SAFETY: in bounds (checked); no other worker reads or writes this slot in this phase.
        unsafe { self.ptr.add(slot as usize).write(v) }
    }
}

/// One worker's faults of the current scan, each with the first task of the item that raised it
/// (the key of the sequential order).
type FaultBuffer = Padded<UnsafeCell<Vec<(u32, Fault)>>>;

struct Shared<'a> {
    slots: SharedSlots,
    decisions: &'a [AtomicU32],
    faults: &'a [FaultBuffer],
    barrier: SpinBarrier,
}

// SAFETY: the fault buffers are each used by one worker during a scan and by worker 0 between
// scans, with the barrier ordering the hand-over (see `ParallelMachine::worker`).
unsafe impl Sync for Shared<'_> {}

/// A spinning barrier for a fixed set of workers: each worker publishes the number of barriers
/// it has reached in its own cache line and waits until every other worker has reached as many
/// (no shared counter to fight over: one line transfer per worker pair). Spins with
/// `spin_loop`, then yields, so that it behaves when there are more workers than cores.
pub struct SpinBarrier {
    epochs: Box<[Padded<AtomicU64>]>,
    poisoned: AtomicBool,
}

impl SpinBarrier {
    /// A barrier for `n` workers.
    pub fn new(n: usize) -> SpinBarrier {
        SpinBarrier {
            epochs: (0..n).map(|_| Padded(AtomicU64::new(0))).collect(),
            poisoned: AtomicBool::new(false),
        }
    }

    /// Worker `w` arrives (its count in `epoch`) and waits for all; false if a worker panicked.
    #[inline]
    pub fn wait(&self, w: usize, epoch: &mut u64) -> bool {
        *epoch += 1;
        let e = *epoch;
        self.epochs[w].0.store(e, Ordering::Release);
        for (i, other) in self.epochs.iter().enumerate() {
            if i == w {
                continue;
            }
            let mut spins = 0u32;
            while other.0.load(Ordering::Acquire) < e {
                if spins < 2000 {
                    spins += 1;
                    std::hint::spin_loop();
                } else {
                    if self.poisoned.load(Ordering::Relaxed) {
                        return false;
                    }
                    std::thread::yield_now();
                }
            }
        }
        true
    }

    /// Releases every waiter for good (a worker panicked).
    pub fn poison(&self) {
        self.poisoned.store(true, Ordering::Relaxed);
    }
}
