//! Fewer phases: consecutive parallel levels run as one parallel phase, without the barriers
//! between them, where the partition lets each worker run its share of the levels reading only
//! what its own earlier tasks of the phase wrote (producer → consumer affinity), and the few
//! tasks that need another worker's writes of the phase (the *halo*: at the border between two
//! workers' slices, and every task that depends on one) run after it, in one sequential phase
//! on worker 0, in task order. For stencil-like programs this is the split tiling of
//! Krishnamoorthy et al. (2007) cut down to its simplest form: one trapezoid per worker, the
//! inverted triangles between them afterwards.
//!
//! The rule, per variable, over the merged levels: a task stays in its worker's slice only if
//! every variable it reads is written in the phase by no other worker and by no halo task, and
//! every variable it writes is also read by no other worker and no halo task; otherwise it
//! joins the halo. Any dependence (data, anti or output) of a task on another worker's task or
//! on a halo task of the window is such a shared variable, so a slice task's producers of the
//! window are earlier tasks of its own slice (its worker runs the levels in order), and a halo
//! task's producers ran in the phase or earlier in the halo (task order is a topological order
//! of the scan's dependences). A level joins the window only if all its tasks are unguarded
//! with a single entry (they read no decision of the window) and call no subroutine (callers
//! share a subroutine's loop counters), and only if the cost model says the window with it
//! finishes sooner than the window and the level with a barrier between them. The plan check
//! (`check`) still proves every parallel phase against the lowered code.
//!
//! It does not re-slice the levels (the partition is `slicing`'s).

use super::phase::{Phase, PhaseKind};
use super::tasks::{Item, Tasks};
use crate::parallel::config::PlanConfig;
use crate::parallel::ids::TaskId;
use plc_analysis::Analysis;
use plc_model::{Element, Program, RungId};

/// The halo's "worker" in the maps below.
const HALO: u32 = u32::MAX;

/// Who touches a variable in the window.
#[derive(Copy, Clone, Default)]
struct Touch {
    /// The worker (or [`HALO`]) that writes it, if any.
    writer: Option<u32>,
    /// Its readers: bit `w` for worker `w` (workers beyond 62 share bit 62, which only makes
    /// the rule stricter), bit 63 for the halo.
    readers: u64,
}

fn bit(w: u32) -> u64 {
    if w == HALO {
        1 << 63
    } else {
        1 << w.min(62)
    }
}

/// The window being merged: its maps, its slices and halo, and their modelled costs.
struct Window {
    touch: Vec<Touch>,
    touched: Vec<u32>,
    /// Per worker: its tasks of the window, level after level.
    slices: Vec<Vec<TaskId>>,
    halo: Vec<TaskId>,
    /// Per worker: the modelled cost of its slice; the halo's.
    cost: Vec<u64>,
    halo_cost: u64,
    levels: std::ops::Range<usize>,
}

impl Window {
    fn clear(&mut self, threads: usize) {
        for &v in &self.touched {
            self.touch[v as usize] = Touch::default();
        }
        self.touched.clear();
        self.slices = vec![Vec::new(); threads];
        self.halo.clear();
        self.cost = vec![0; threads];
        self.halo_cost = 0;
    }

    fn add(&mut self, v: usize, w: u32, write: bool) {
        let t = &mut self.touch[v];
        if t.writer.is_none() && t.readers == 0 {
            self.touched.push(v as u32);
        }
        if write {
            t.writer = Some(w);
        } else {
            t.readers |= bit(w);
        }
    }

    /// Whether a task of worker `w` reading `ins` and writing `outs` must join the halo.
    fn needs_halo(&self, w: u32, ins: &[plc_model::VarId], outs: &[plc_model::VarId]) -> bool {
        let foreign_writer = |v: usize| self.touch[v].writer.is_some_and(|o| o != w);
        ins.iter().any(|v| foreign_writer(v.index()))
            || outs
                .iter()
                .any(|v| foreign_writer(v.index()) || self.touch[v.index()].readers & !bit(w) != 0)
    }

    /// The window's modelled time: its slowest slice, then (after a barrier) its halo.
    fn time(&self, barrier: u64) -> u64 {
        let halo = if self.halo.is_empty() {
            0
        } else {
            barrier + self.halo_cost
        };
        self.cost.iter().max().copied().unwrap_or(0) + halo
    }
}

/// Whether a rung calls a subroutine.
fn calls(p: &Program, r: RungId) -> bool {
    let mut found = false;
    plc_model::walk_elements(&p.rung(r).series, &mut |e| {
        found |= matches!(e, Element::Call { .. });
    });
    found
}

/// The most levels one window merges (bounds the planner's work; the halo grows with every
/// level, so long windows rarely pay).
const MAX_WINDOW: usize = 64;

/// The phases with runs of consecutive parallel phases (one level each, as `plan` builds them)
/// merged where the model says it pays: each run one parallel phase, then its halo (if any) as
/// a sequential phase. Of the windows starting at a level, the one the model gains most on is
/// kept (the first merge alone never pays: the halo's barrier replaces the one it saves).
pub(in crate::parallel) fn merge_phases(
    p: &Program,
    a: &Analysis,
    info: &Tasks<'_>,
    config: &PlanConfig,
    threads: usize,
    phases: Vec<Phase>,
) -> Vec<Phase> {
    let sched = &a.schedule;
    let rungs = |t: TaskId| sched.tasks[t.index()].rungs.iter().copied();
    let mergeable = |ph: &Phase| match &ph.kind {
        PhaseKind::Parallel(slices) => slices
            .iter()
            .flatten()
            .flat_map(Item::tasks)
            .all(|t| info.unguarded_single(t) && !rungs(t).any(|r| calls(p, r))),
        PhaseKind::Sequential(_) => false,
    };
    let makespan = |ph: &Phase| {
        (0..threads)
            .map(|w| ph.items_of(w).iter().map(|it| it.cost).sum::<u64>())
            .max()
            .unwrap_or(0)
    };
    let mut win = Window {
        touch: vec![Touch::default(); p.vars.len()],
        touched: Vec::new(),
        slices: Vec::new(),
        halo: Vec::new(),
        cost: Vec::new(),
        halo_cost: 0,
        levels: 0..0,
    };
    let b = config.barrier_cost;
    let mut out: Vec<Phase> = Vec::with_capacity(phases.len());
    let mut i = 0;
    while i < phases.len() {
        if !phases[i].is_parallel() {
            out.push(phases[i].clone());
            i += 1;
            continue;
        }
        // Grow a window from level i; keep the end the model gains most on.
        win.clear(threads);
        win.add_level(&phases[i], a, info, config);
        let (mut unmerged, mut best) = (makespan(&phases[i]), (i, 0u64));
        let mut j = i + 1;
        while j < phases.len() && j - i < MAX_WINDOW && mergeable(&phases[j]) {
            win.add_level(&phases[j], a, info, config);
            unmerged += b + makespan(&phases[j]);
            let merged = win.time(b);
            if unmerged > merged && unmerged - merged > best.1 {
                best = (j, unmerged - merged);
            }
            j += 1;
        }
        if best.0 == i {
            out.push(phases[i].clone());
            i += 1;
            continue;
        }
        win.clear(threads);
        for ph in &phases[i..=best.0] {
            win.add_level(ph, a, info, config);
        }
        close(&mut out, &mut win, info, config);
        i = best.0 + 1;
    }
    out
}

impl Window {
    /// Adds a parallel phase's level: each task to its worker's slice, or to the halo.
    fn add_level(&mut self, ph: &Phase, a: &Analysis, info: &Tasks<'_>, config: &PlanConfig) {
        let sched = &a.schedule;
        if self.halo.is_empty() && self.slices.iter().all(Vec::is_empty) {
            self.levels = ph.levels.clone();
        }
        self.levels.end = ph.levels.end;
        let mut halo_level = false;
        for w in 0..self.slices.len() {
            let mut level_tasks = false;
            for t in ph.items_of(w).iter().flat_map(Item::tasks) {
                let rungs = &sched.tasks[t.index()].rungs;
                let halo = rungs
                    .iter()
                    .any(|&r| self.needs_halo(w as u32, a.accesses.ins(r), a.accesses.outs(r)));
                let to = if halo { HALO } else { w as u32 };
                for &r in rungs {
                    for v in a.accesses.ins(r) {
                        self.add(v.index(), to, false);
                    }
                    for v in a.accesses.outs(r) {
                        self.add(v.index(), to, true);
                    }
                }
                let c = info.cost[t.index()];
                if halo {
                    self.halo.push(t);
                    self.halo_cost += c;
                    halo_level = true;
                } else {
                    self.slices[w].push(t);
                    self.cost[w] += c;
                    level_tasks = true;
                }
            }
            // About one item per worker and level (runs of consecutive tasks).
            if level_tasks {
                self.cost[w] += config.item_cost;
            }
        }
        if halo_level {
            self.halo_cost += config.item_cost;
        }
    }
}

/// Emits the open window: one parallel phase of its slices (the first level's items as the
/// slicing cut them, each later level's tasks of a worker as items of their own), then its
/// halo, sorted into task order, as a sequential phase.
fn close(out: &mut Vec<Phase>, win: &mut Window, info: &Tasks<'_>, config: &PlanConfig) {
    let items = win
        .slices
        .iter()
        .map(|ts| {
            // Items never span two levels: cut where the task order goes back or jumps.
            let mut items = Vec::new();
            let mut start = 0;
            for i in 1..=ts.len() {
                if i == ts.len() || ts[i].0 <= ts[i - 1].0 {
                    items.extend(info.items(&ts[start..i], config.item_cost));
                    start = i;
                }
            }
            items
        })
        .collect();
    out.push(Phase {
        kind: PhaseKind::Parallel(items),
        levels: win.levels.clone(),
        barrier_before: true,
        halo: false,
    });
    if !win.halo.is_empty() {
        win.halo.sort_unstable();
        out.push(Phase {
            kind: PhaseKind::Sequential(info.items(&win.halo, config.item_cost)),
            levels: win.levels.start + 1..win.levels.end,
            barrier_before: true,
            halo: true,
        });
    }
}
