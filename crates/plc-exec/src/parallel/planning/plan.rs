//! The static plan of one candidate: the schedule's levels turned into phases and per-worker
//! slices of items (a dynamic programme over the levels on the cost model, the slices from
//! `slicing`), the data movement of the phases as built and the modelled scan, the decision
//! slots, guards and entries that carry control between tasks, and the variables each (phase,
//! worker) writes (the layout's padding groups); and the candidate plans of a measured run.
//!
//! Follows Zhao & Yan's data levelling (levels run one after another, the rungs of a level in
//! parallel) on the *combined* schedule: data and control dependences together, loops kept whole.
//! Invariants: every task of the schedule is in exactly one phase; in a
//! parallel phase each worker's items are ascending in task order within each of its levels,
//! the levels in order; a task has a decision slot iff a later guard or
//! entry reads it. It does not measure anything (see `choice`) and does not check the plan
//! against the lowered code (see `check`).

use super::calls::{call_closure, is_loop_back, rung_callees, uncovered_refusal};
use super::movement::Movement;
pub(in crate::parallel) use super::phase::{Phase, PhaseKind, RemoteLines};
use super::ready::{Ready, Wait};
use super::rung_cost::interpreter_costs;
use super::slicing::{slice_levels, worker_makespan, LevelPlan};
use super::tasks::{Item, Tasks};
use crate::parallel::config::{PlanConfig, PlanKind, Strategy};
use crate::parallel::ids::{DecisionSlot, Next, TaskId};
use plc_analysis::{Analysis, EdgeKind, Successor};
use plc_model::{Arena, Program, RungId, Var, VarId};
use std::collections::HashMap;

/// Decision slots per 64-byte line.
pub(in crate::parallel) const DECISION_LINE: usize = 16;

/// A static plan: phases, slices, decision slots and the variables each (phase, worker) writes.
/// Built once per program, thread count and configuration.
#[derive(Clone, Debug)]
pub struct Plan {
    pub(in crate::parallel) threads: usize,
    pub(in crate::parallel) config: PlanConfig,
    /// `Some(reason)` when the whole program runs as the sequential scan.
    pub(in crate::parallel) sequential: Option<String>,
    pub(in crate::parallel) phases: Vec<Phase>,
    pub(in crate::parallel) end_barrier: bool,
    /// Per phase, per worker: the lines its slice finds in another core's cache (empty until
    /// the machine that runs the plan finds them: they depend on its layout; `remote`).
    pub(in crate::parallel) remote: Vec<Vec<RemoteLines>>,
    /// A dependence-driven plan's: per worker, per item, the lines the item writes that
    /// another core holds (`remote`; reads left empty), prefetched one item ahead.
    pub(in crate::parallel) item_remote: Vec<Vec<RemoteLines>>,
    pub(in crate::parallel) levels: Vec<LevelPlan>,
    /// Task of each rung (main-program rungs that run).
    pub(in crate::parallel) task_of_rung: Vec<Option<TaskId>>,
    /// The rungs of each task (the schedule's).
    pub(in crate::parallel) task_rungs: Vec<Vec<RungId>>,
    /// Guard disjuncts: (decision slot of the controller, where it must have led).
    pub(in crate::parallel) guards: Vec<(DecisionSlot, Next)>,
    /// Decision slots of entry predecessors.
    pub(in crate::parallel) entry_slots: Vec<DecisionSlot>,
    pub(in crate::parallel) decision_slots: usize,
    /// Per variable: the (phase, worker) pairs of parallel phases that write it.
    pub(in crate::parallel) write_keys: Vec<Vec<(u32, u32)>>,
    /// Per phase and worker: the cache lines it reads that another worker wrote last
    /// (`movement`; empty when no level runs in parallel).
    pub(in crate::parallel) phase_lines: Vec<Vec<u64>>,
    /// Modelled scan costs: sequential, and this plan's (data movement included).
    pub(in crate::parallel) est_sequential: u64,
    pub(in crate::parallel) est_plan: u64,
    /// The waits of the items of a dependence-driven plan (`Item::waits` index it).
    pub(in crate::parallel) waits: Vec<Wait>,
    /// `Some` for a dependence-driven plan (`deps_plan`): one parallel phase whose workers
    /// order their items by ready flags; the plan check then proves the order instead of the
    /// disjointness of the workers (`order_check`).
    pub(in crate::parallel) ready: Option<Ready>,
}

impl Plan {
    /// The remote lines of a scan, summed over every slice: (to read, to write).
    pub(in crate::parallel) fn remote_lines(&self) -> (usize, usize) {
        let slices = self.remote.iter().chain(&self.item_remote).flatten();
        slices.fold((0, 0), |(r, w), l| (r + l.reads.len(), w + l.writes.len()))
    }

    pub(in crate::parallel) fn build(p: &Program, a: &Analysis, config: &PlanConfig) -> Plan {
        let sched = &a.schedule;
        let threads = config.threads.max(1);
        let task_of_rung: Vec<Option<TaskId>> = sched.task_of.clone();
        let info = task_facts(p, a, &task_of_rung, config);
        let est_sequential: u64 = info.cost.iter().sum();
        let level_conflict = level_conflicts(p, a);
        let (mut level_plans, mut level_slices) =
            slice_levels(p, a, &info, config, &level_conflict);
        let (choice, _) = choose_phases(&level_plans, config);
        let any_parallel = choice.contains(&true);
        let mut phases = if any_parallel {
            build_phases(a, &info, config, &choice, &mut level_slices)
        } else {
            Vec::new()
        };
        let mut phase_lines = phase_movement(p, a, &phases, threads);
        let est_plan = if any_parallel {
            modelled_scan(&phases, &phase_lines, &mut level_plans, config)
        } else {
            est_sequential
        };
        let sequential = sequential_reason(p, a, config, any_parallel, est_plan, est_sequential);
        explain_levels(&mut level_plans, &choice, sequential.is_some(), config);
        if sequential.is_some() {
            phases.clear();
            phase_lines.clear();
        }
        let mut plan = Plan {
            threads,
            config: *config,
            sequential,
            phases,
            end_barrier: false,
            remote: Vec::new(),
            item_remote: Vec::new(),
            levels: level_plans,
            task_of_rung,
            task_rungs: sched.tasks.iter().map(|t| t.rungs.clone()).collect(),
            guards: Vec::new(),
            entry_slots: Vec::new(),
            decision_slots: 0,
            write_keys: vec![Vec::new(); p.vars().len()],
            phase_lines,
            est_sequential,
            est_plan,
            waits: Vec::new(),
            ready: None,
        };
        if plan.sequential.is_some() {
            return plan;
        }
        plan.end_barrier = plan.phases.last().is_some_and(Phase::is_parallel);
        plan.place_decisions(a, &info);
        plan.write_keys = write_keys(p, a, &plan.phases);
        plan
    }

    /// Decision slots, grouped per (phase, worker) and padded to a line; then each item's
    /// decision, guard and entries.
    pub(in crate::parallel) fn place_decisions(&mut self, a: &Analysis, info: &Tasks<'_>) {
        let sched = &a.schedule;
        let mut slot_of_task: Vec<Option<DecisionSlot>> = vec![None; sched.tasks.len()];
        let mut next = 0usize;
        for ph in &self.phases {
            let slices: Vec<&[Item]> = match &ph.kind {
                PhaseKind::Parallel(s) => s.iter().map(|v| v.as_slice()).collect(),
                PhaseKind::Sequential(items) => vec![items.as_slice()],
            };
            for slice in slices {
                let before = next;
                for t in slice.iter().flat_map(Item::tasks) {
                    if info.needs_decision[t.index()] {
                        slot_of_task[t.index()] = Some(DecisionSlot(next as u32));
                        next += 1;
                    }
                }
                if next > before {
                    next = next.div_ceil(DECISION_LINE) * DECISION_LINE;
                }
            }
        }
        self.decision_slots = next;
        let slot = |t: TaskId| {
            slot_of_task[t.index()]
                .expect("a task read by a later guard or entry has a decision slot")
        };
        let (guards, entry_slots) = (&mut self.guards, &mut self.entry_slots);
        for ph in &mut self.phases {
            let slices: Vec<&mut Vec<Item>> = match &mut ph.kind {
                PhaseKind::Parallel(s) => s.iter_mut().collect(),
                PhaseKind::Sequential(items) => vec![items],
            };
            for it in slices.into_iter().flatten() {
                debug_assert!(
                    (it.first.raw()..it.last.raw()).all(|t| slot_of_task[t as usize].is_none()),
                    "only the last task of a run decides"
                );
                it.decision = slot_of_task[it.last.index()];
                let task = &sched.tasks[it.first.index()];
                let g0 = guards.len() as u32;
                for g in &task.guard {
                    let succ = match g.successor {
                        Successor::Task(s) => Next::Task(s),
                        Successor::Stop => Next::Stop,
                    };
                    guards.push((slot(g.controller), succ));
                }
                it.guard = g0..guards.len() as u32;
                if task.entries.len() > 1 {
                    let e0 = entry_slots.len() as u32;
                    for &q in &info.entry_preds[it.first.index()] {
                        entry_slots.push(slot(q));
                    }
                    it.entries = e0..entry_slots.len() as u32;
                }
            }
        }
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
        self.phases.iter().filter(|p| p.is_parallel()).count()
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

    /// The dependence-driven plan's waits and model (`None` for a levelled plan).
    pub fn ready(&self) -> Option<&Ready> {
        self.ready.as_ref()
    }
}

/// Costs, only successors, decisions and entry predecessors of the tasks, from the main
/// program's live CFG edges condensed to tasks.
pub(in crate::parallel) fn task_facts<'a>(
    p: &Program,
    a: &'a Analysis,
    task_of: &[Option<TaskId>],
    config: &PlanConfig,
) -> Tasks<'a> {
    let rung_cost = interpreter_costs(p, a, config);
    let sched = &a.schedule;
    let nt = sched.tasks.len();
    let n = p.rungs().len() as u32;
    let stop = a.cfg.stop().raw();
    let mut succs: Vec<Vec<Next>> = vec![Vec::new(); nt];
    let mut entry_preds: Vec<Vec<TaskId>> = vec![Vec::new(); nt];
    for e in &a.cfg.edges {
        if matches!(e.kind, EdgeKind::Call | EdgeKind::Return) || e.from.raw() >= n {
            continue;
        }
        let Some(ta) = task_of[e.from.raw() as usize] else {
            continue;
        };
        let tb = if e.to.raw() == stop {
            Next::Stop
        } else if e.to.raw() < n {
            match task_of[e.to.raw() as usize] {
                Some(tb) if tb != ta => Next::Task(tb),
                _ => continue,
            }
        } else {
            continue;
        };
        succs[ta.index()].push(tb);
        if let Next::Task(tb) = tb {
            if sched.tasks[tb.index()].entries.len() > 1 {
                entry_preds[tb.index()].push(ta);
            }
        }
    }
    let mut needs_decision = vec![false; nt];
    for t in 0..nt {
        succs[t].sort_unstable();
        succs[t].dedup();
        entry_preds[t].sort_unstable();
        entry_preds[t].dedup();
        for &q in &entry_preds[t] {
            needs_decision[q.index()] = true;
        }
        for g in &sched.tasks[t].guard {
            needs_decision[g.controller.index()] = true;
        }
    }
    let only_succ = succs
        .iter()
        .map(|s| match s.as_slice() {
            [Next::Task(t)] => Some(*t),
            _ => None,
        })
        .collect();
    let cost = sched
        .tasks
        .iter()
        .map(|t| {
            t.rungs
                .iter()
                .map(|r| rung_cost[r.index()])
                .sum::<u64>()
                .max(1)
        })
        .collect();
    Tasks {
        a,
        cost,
        only_succ,
        needs_decision,
        entry_preds,
    }
}

/// Per level: why it must not run in parallel (tasks sharing a subroutine's loop counters).
pub(in crate::parallel) fn level_conflicts(p: &Program, a: &Analysis) -> Vec<Option<String>> {
    let sched = &a.schedule;
    let closure = call_closure(p);
    let pou_loops: Vec<bool> = (p.pous().ids())
        .map(|pou| p.pou_rungs(pou).any(|r| is_loop_back(p, r)))
        .collect();
    let mut level_conflict: Vec<Option<String>> = vec![None; sched.levels.len()];
    for (l, level) in sched.levels.iter().enumerate() {
        let mut user: HashMap<u32, TaskId> = HashMap::new();
        'level: for &t in level {
            let mut pous: Vec<u32> = Vec::new();
            for &r in &sched.task(t).rungs {
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
                        p.pous()[c as usize].name
                    ));
                    break 'level;
                }
                user.insert(c, t);
            }
        }
    }
    level_conflict
}

/// Why the whole program runs as the sequential scan, if it does.
pub(in crate::parallel) fn sequential_reason(
    p: &Program,
    a: &Analysis,
    config: &PlanConfig,
    any_parallel: bool,
    est_plan: u64,
    est_sequential: u64,
) -> Option<String> {
    let b = config.barrier_cost;
    if let Some(why) = uncovered_refusal(p, a, &a.schedule.task_of) {
        Some(why)
    } else if config.strategy == Strategy::Sequential {
        Some("sequential strategy requested".into())
    } else if config.kind == PlanKind::Seq {
        Some("the sequential walk was asked for (--plan seq)".into())
    } else if config.threads <= 1 && config.strategy != Strategy::AllParallel {
        Some("one worker".into())
    } else if !any_parallel && config.strategy == Strategy::AllParallel {
        Some("no level can run in parallel (every level is one task, or its tasks share a subroutine's loop counters)".into())
    } else if !any_parallel {
        Some("no level saves more than the barriers it needs".into())
    } else if config.strategy == Strategy::Auto
        && config.kind == PlanKind::Model
        && est_plan + b > est_sequential
    {
        Some(format!(
            "the best plan ({est_plan} steps per scan with barriers and data movement) does not beat the sequential scan ({est_sequential} steps) by a barrier"
        ))
    } else if config.strategy == Strategy::Auto
        && config.kind == PlanKind::Auto
        && est_plan >= est_sequential
    {
        Some(format!(
            "the cost model sees no gain to measure ({est_plan} steps per scan with barriers and data movement, sequential {est_sequential})"
        ))
    } else {
        None
    }
}

/// Per phase and worker of `phases`, in scan order: the lines it moves (`movement`).
fn phase_movement(p: &Program, a: &Analysis, phases: &[Phase], threads: usize) -> Vec<Vec<u64>> {
    let mut movement = Movement::new(p, a, threads);
    phases
        .iter()
        .map(|ph| {
            let slices: Vec<Vec<TaskId>> = match &ph.kind {
                PhaseKind::Parallel(s) => s
                    .iter()
                    .map(|items| items.iter().flat_map(Item::tasks).collect())
                    .collect(),
                PhaseKind::Sequential(items) => vec![items.iter().flat_map(Item::tasks).collect()],
            };
            let lines = movement.phase_lines(&slices);
            movement.commit(&slices);
            lines
        })
        .collect()
}

/// The modelled scan of the phases as built: Σ parallel makespans (data movement included) +
/// Σ sequential levels' costs and their moved lines + barriers. Sets each parallel level's
/// lines and makespan.
fn modelled_scan(
    phases: &[Phase],
    phase_lines: &[Vec<u64>],
    levels: &mut [LevelPlan],
    config: &PlanConfig,
) -> u64 {
    let b = config.barrier_cost;
    let mut est = 0;
    for (ph, lines) in phases.iter().zip(phase_lines) {
        est += if ph.barrier_before { b } else { 0 };
        if ph.is_parallel() {
            let lp = &mut levels[ph.levels.start];
            lp.lines = lines.clone();
            let m = worker_makespan(&lp.workers, lines, config.line_cost);
            lp.makespan = Some(m);
            est += m;
        } else {
            let own: u64 = levels[ph.levels.clone()]
                .iter()
                .map(|lp| lp.cost + config.item_cost)
                .sum();
            est += own + lines.iter().sum::<u64>() * config.line_cost;
        }
    }
    if phases.last().is_some_and(Phase::is_parallel) {
        est += b;
    }
    est
}

/// Each level parallel (true) or sequential: the dynamic programme minimising the modelled scan
/// (a barrier between any two phases, before a leading parallel phase and after a trailing one;
/// adjacent sequential levels form one phase). Returns the choice and its modelled cost.
fn choose_phases(level_plans: &[LevelPlan], config: &PlanConfig) -> (Vec<bool>, u64) {
    let b = config.barrier_cost;
    let nl = level_plans.len();
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
    let mut choice = vec![false; nl];
    let mut est_plan = 0;
    if nl > 0 {
        let end = |s: usize| best[nl - 1][s].saturating_add(if s == 1 { b } else { 0 });
        let mut s = if end(1) < end(0) { 1 } else { 0 };
        est_plan = end(s);
        for l in (0..nl).rev() {
            choice[l] = s == 1;
            s = from[l][s];
        }
    }
    (choice, est_plan)
}

/// The reasons `--explain` gives for each level.
fn explain_levels(
    levels: &mut [LevelPlan],
    choice: &[bool],
    sequential: bool,
    config: &PlanConfig,
) {
    let b = config.barrier_cost;
    let forced = config.strategy == Strategy::AllParallel;
    for (l, lp) in levels.iter_mut().enumerate() {
        lp.parallel = !sequential && choice[l];
        if !lp.reason.is_empty() {
            continue;
        }
        lp.reason = match (lp.parallel, lp.makespan) {
            (true, Some(m)) if forced => format!(
                "forced (--plan {}): modelled makespan {m} against {} sequential, plus a barrier ({b})",
                config.kind.name(),
                lp.cost
            ),
            (true, Some(m)) => format!(
                "saves {} steps, more than a barrier ({b})",
                lp.cost.saturating_sub(m)
            ),
            (false, Some(m)) if sequential => {
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

/// The phases and their items.
fn build_phases(
    a: &Analysis,
    info: &Tasks<'_>,
    config: &PlanConfig,
    choice: &[bool],
    level_slices: &mut [Option<Vec<Vec<TaskId>>>],
) -> Vec<Phase> {
    let sched = &a.schedule;
    let nl = choice.len();
    let mut out = Vec::new();
    let mut l = 0;
    while l < nl {
        if choice[l] {
            let slices = level_slices[l].take().expect("a parallel level has slices");
            let items = slices
                .iter()
                .map(|s| info.items(s, config.item_cost))
                .collect();
            out.push(Phase {
                kind: PhaseKind::Parallel(items),
                levels: l..l + 1,
                barrier_before: true,
            });
            l += 1;
        } else {
            let start = l;
            while l < nl && !choice[l] {
                l += 1;
            }
            let mut tasks: Vec<TaskId> = sched.levels[start..l].iter().flatten().copied().collect();
            tasks.sort_unstable();
            out.push(Phase {
                kind: PhaseKind::Sequential(info.items(&tasks, config.item_cost)),
                levels: start..l,
                barrier_before: start > 0, // after a parallel phase
            });
        }
    }
    out
}

/// Per variable: the (phase, worker) pairs of parallel phases whose tasks write it.
fn write_keys(p: &Program, a: &Analysis, phases: &[Phase]) -> Vec<Vec<(u32, u32)>> {
    let sched = &a.schedule;
    let mut key_of: Vec<Vec<(u32, u32)>> = vec![Vec::new(); p.vars().len()];
    for (pi, ph) in phases.iter().enumerate() {
        if !ph.is_parallel() {
            continue;
        }
        for (w, it) in ph.all_items() {
            for t in it.tasks() {
                for r in &sched.tasks[t.index()].rungs {
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
    key_of
}

/// Layout groups for several plans run on one state: variables keyed by every (plan, phase,
/// worker) that writes them, one group per distinct key, groups ordered by their first writer.
/// Variables of different groups never share a line once the layout aligns each group.
pub(in crate::parallel) fn layout_groups(
    plans: &[&Plan],
    vars: &Arena<VarId, Var>,
) -> Vec<Vec<VarId>> {
    let mut group_of: HashMap<Vec<(u32, u32, u32)>, usize> = HashMap::new();
    let mut order: Vec<((u32, u32, u32), usize)> = Vec::new();
    let mut groups: Vec<Vec<VarId>> = Vec::new();
    for (v, var) in vars.ids().enumerate() {
        let key: Vec<(u32, u32, u32)> = plans
            .iter()
            .enumerate()
            .flat_map(|(c, plan)| {
                plan.write_keys
                    .get(v)
                    .into_iter()
                    .flatten()
                    .map(move |&(ph, w)| (c as u32, ph, w))
            })
            .collect();
        let Some(&first) = key.first() else {
            continue;
        };
        let g = *group_of.entry(key).or_insert_with(|| {
            groups.push(Vec::new());
            order.push((first, groups.len() - 1));
            groups.len() - 1
        });
        groups[g].push(var);
    }
    order.sort_unstable();
    order
        .into_iter()
        .map(|(_, g)| std::mem::take(&mut groups[g]))
        .collect()
}

/// The layout's groups reordered for the interpreter's fused contacts, which address bytes
/// below 2^16 only (four to six contacts in one instruction): the variables no plan writes
/// (inputs, constants read by many rungs) first, then every group's BOOLs, then the rest of
/// every group (INTs, REALs, instances), each part a group of its own. Splitting a group keeps
/// its writer set, so no line gets a second writer; it costs at most a line of padding per
/// group. On gen 100k (188 KB of state) the plain order put the inputs after 64 KiB and left
/// most rungs without fused contacts: 1.6–1.8× the sequential walk's time per rung.
pub(in crate::parallel) fn bools_first(p: &Program, groups: Vec<Vec<VarId>>) -> Vec<Vec<VarId>> {
    let mut written = vec![false; p.vars().len()];
    for &v in groups.iter().flatten() {
        written[v.index()] = true;
    }
    let is_bool = |v: &VarId| p.var(*v).ty == plc_model::Type::Bool;
    let unwritten: Vec<VarId> = p.vars().ids().filter(|v| !written[v.index()]).collect();
    let split = |g: &[VarId]| -> (Vec<VarId>, Vec<VarId>) { g.iter().partition(|v| is_bool(v)) };
    let (unwritten_bools, unwritten_rest) = split(&unwritten);
    let (bools, rest): (Vec<Vec<VarId>>, Vec<Vec<VarId>>) = groups.iter().map(|g| split(g)).unzip();
    std::iter::once(unwritten_bools)
        .chain(bools)
        .chain(std::iter::once(unwritten_rest))
        .chain(rest)
        .filter(|g| !g.is_empty())
        .collect()
}
