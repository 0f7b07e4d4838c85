//! Slicing: each level of the schedule cut into one slice of tasks per worker, under the
//! configured [`Slicing`] — contiguous runs, LPT, the locality partition (`partition`), or
//! whichever of them the cost model says finishes first — and the level's modelled parallel
//! makespan: per worker, its items' steps plus the lines it moves (`movement`) at
//! `line_cost` steps each; the heaviest worker decides.
//!
//! The levels are sliced in scan order, so that each level knows who wrote what it reads: the
//! slices of the levels before it, as if every level ran in parallel (which levels do is
//! decided afterwards, by `plan`'s dynamic programme; `plan` then models the movement of the
//! phases it actually built). It does not choose phases or place decisions.

use super::movement::Movement;
use super::partition::{self, Costs};
use super::tasks::{contiguous, lpt, Tasks};
use crate::parallel::config::{PlanConfig, Slicing, Strategy};
use crate::parallel::ids::TaskId;
use plc_analysis::Analysis;
use plc_model::Program;

/// What the plan decided for one level (for `--explain`).
#[derive(Clone, Debug)]
pub struct LevelPlan {
    /// Tasks of the level.
    pub tasks: usize,
    /// Σ task costs (steps).
    pub cost: u64,
    /// Whether the level is a parallel phase.
    pub parallel: bool,
    /// Modelled makespan of the parallel slices, data movement included (steps; `None` if it
    /// cannot run in parallel).
    pub makespan: Option<u64>,
    /// "contiguous", "lpt" or "locality" (parallel levels).
    pub slicing: &'static str,
    /// Per worker: tasks, items, modelled cost without data movement (parallel levels).
    pub workers: Vec<(usize, usize, u64)>,
    /// Per worker: the cache lines it reads that another worker wrote last (parallel levels).
    pub lines: Vec<u64>,
    /// Every slicing the model compared for the level and its modelled makespan (more than
    /// one under [`Slicing::Auto`]).
    pub compared: Vec<(&'static str, u64)>,
    /// Why.
    pub reason: String,
}

/// Slices of one level: the tasks of each worker, ascending.
pub(in crate::parallel) type Slices = Vec<Vec<TaskId>>;

/// One way to cut a level, evaluated.
struct Cut {
    slicing: Slicing,
    slices: Slices,
    workers: Vec<(usize, usize, u64)>,
    lines: Vec<u64>,
    makespan: u64,
}

/// Per level: its plan for `--explain`, and its parallel slices (`None`: it cannot run in
/// parallel).
pub(in crate::parallel) fn slice_levels(
    p: &Program,
    a: &Analysis,
    info: &Tasks<'_>,
    config: &PlanConfig,
    level_conflict: &[Option<String>],
) -> (Vec<LevelPlan>, Vec<Option<Slices>>) {
    let sched = &a.schedule;
    let threads = config.threads.max(1);
    let mut movement = Movement::new(p, a, threads);
    let mut level_plans = Vec::with_capacity(sched.levels.len());
    let mut level_slices = Vec::with_capacity(sched.levels.len());
    for (l, level) in sched.levels.iter().enumerate() {
        let weights: Vec<u64> = level.iter().map(|t| info.cost[t.index()]).collect();
        let mut lp = LevelPlan {
            tasks: level.len(),
            cost: weights.iter().sum(),
            parallel: false,
            makespan: None,
            slicing: "",
            workers: Vec::new(),
            lines: Vec::new(),
            compared: Vec::new(),
            reason: String::new(),
        };
        let forced = config.strategy == Strategy::AllParallel;
        let why_not = if let Some(why) = &level_conflict[l] {
            Some(why.clone())
        } else if threads == 1 && !forced {
            Some("one worker".into())
        } else if level.len() < 2 && !forced {
            Some("a single task".into())
        } else {
            None
        };
        if let Some(why) = why_not {
            lp.reason = why;
            movement.commit(std::slice::from_ref(level));
            level_slices.push(None);
            level_plans.push(lp);
            continue;
        }
        let (cut, compared) = best_cut(level, &weights, info, config, &movement);
        movement.commit(&cut.slices);
        lp.compared = compared;
        lp.makespan = Some(cut.makespan);
        lp.slicing = cut.slicing.name();
        lp.workers = cut.workers;
        lp.lines = cut.lines;
        level_slices.push(Some(cut.slices));
        level_plans.push(lp);
    }
    (level_plans, level_slices)
}

/// The configured slicing of `level`, or under [`Slicing::Auto`] the one with the smallest
/// modelled makespan (ties: contiguous, LPT, locality); and every slicing compared, with its
/// makespan.
fn best_cut(
    level: &[TaskId],
    weights: &[u64],
    info: &Tasks<'_>,
    config: &PlanConfig,
    movement: &Movement<'_>,
) -> (Cut, Vec<(&'static str, u64)>) {
    let threads = config.threads.max(1);
    let contig: Slices = contiguous(weights, threads)
        .into_iter()
        .map(|r| level[r].to_vec())
        .collect();
    let by_lpt = lpt(level, weights, threads);
    let kinds: &[Slicing] = match config.slicing {
        Slicing::Auto => &[Slicing::Contiguous, Slicing::Lpt, Slicing::Locality],
        Slicing::Contiguous => &[Slicing::Contiguous],
        Slicing::Lpt => &[Slicing::Lpt],
        Slicing::Locality => &[Slicing::Locality],
    };
    let mut best: Option<Cut> = None;
    let mut compared = Vec::with_capacity(kinds.len());
    for &kind in kinds {
        let slices = match kind {
            Slicing::Lpt => by_lpt.clone(),
            Slicing::Locality => locality(level, weights, info, config, movement, &contig, &by_lpt),
            Slicing::Contiguous | Slicing::Auto => contig.clone(),
        };
        let cut = Cut {
            slicing: kind,
            ..evaluate(slices, info, config, movement)
        };
        compared.push((kind.name(), cut.makespan));
        if best.as_ref().is_none_or(|b| cut.makespan < b.makespan) {
            best = Some(cut);
        }
    }
    (best.expect("at least one slicing"), compared)
}

/// A cut's per-worker items, costs and lines, and its makespan (named contiguous: the caller
/// names it).
fn evaluate(
    mut slices: Slices,
    info: &Tasks<'_>,
    config: &PlanConfig,
    movement: &Movement<'_>,
) -> Cut {
    slices.resize(config.threads.max(1), Vec::new());
    let workers: Vec<(usize, usize, u64)> = slices
        .iter()
        .map(|s| {
            let items = info.items(s, config.item_cost);
            (s.len(), items.len(), items.iter().map(|i| i.cost).sum())
        })
        .collect();
    let lines = movement.phase_lines(&slices);
    let makespan = worker_makespan(&workers, &lines, config.line_cost);
    Cut {
        slicing: Slicing::Contiguous,
        slices,
        workers,
        lines,
        makespan,
    }
}

/// The plans of levels cut by a partition made elsewhere (`slices`: per level, each worker's
/// tasks), evaluated as [`slice_levels`] evaluates its own cuts, in scan order, and named
/// `name`; `base` gives each level's tasks, cost and reason.
pub(in crate::parallel) fn evaluate_levels(
    p: &Program,
    a: &Analysis,
    info: &Tasks<'_>,
    config: &PlanConfig,
    slices: &[Slices],
    name: &'static str,
    base: &[LevelPlan],
) -> Vec<LevelPlan> {
    let mut movement = Movement::new(p, a, config.threads.max(1));
    base.iter()
        .zip(slices)
        .map(|(lp, s)| {
            let cut = evaluate(s.clone(), info, config, &movement);
            movement.commit(&cut.slices);
            LevelPlan {
                makespan: Some(cut.makespan),
                slicing: name,
                workers: cut.workers,
                lines: cut.lines,
                compared: Vec::new(),
                ..lp.clone()
            }
        })
        .collect()
}

/// The heaviest worker: its items' steps plus its moved lines at `line_cost`.
pub(in crate::parallel) fn worker_makespan(
    workers: &[(usize, usize, u64)],
    lines: &[u64],
    line_cost: u64,
) -> u64 {
    workers
        .iter()
        .zip(lines)
        .map(|(&(_, _, c), &n)| c + n * line_cost)
        .max()
        .unwrap_or(0)
}

/// The locality partition of `level` (`partition::locality`), its reference the better of the
/// contiguous and LPT slices by task weights.
fn locality(
    level: &[TaskId],
    weights: &[u64],
    info: &Tasks<'_>,
    config: &PlanConfig,
    movement: &Movement<'_>,
    contig: &Slices,
    by_lpt: &Slices,
) -> Slices {
    let threads = config.threads.max(1);
    let assign_of = |slices: &Slices| -> Vec<usize> {
        let mut out = vec![0usize; level.len()];
        for (w, s) in slices.iter().enumerate() {
            for t in s {
                let i = level
                    .binary_search(t)
                    .expect("a slice holds tasks of its level");
                out[i] = w;
            }
        }
        out
    };
    let (a_c, a_l) = (assign_of(contig), assign_of(by_lpt));
    let m = |a: &[usize]| partition::makespan(weights, a, threads);
    let reference = if m(&a_l) < m(&a_c) { a_l } else { a_c };
    let joins: Vec<bool> = (0..level.len())
        .map(|i| {
            i + 1 < level.len()
                && level[i + 1].raw() == level[i].raw() + 1
                && info.unguarded_single(level[i])
                && info.chains(level[i])
        })
        .collect();
    let affinity = movement.affinity(level);
    let part = partition::Level {
        weights,
        affinity: &affinity,
        joins: &joins,
        reference: &reference,
    };
    let costs = Costs {
        line_cost: config.line_cost,
        item_cost: config.item_cost,
    };
    let assign = partition::locality(&part, threads, costs);
    let mut slices: Slices = vec![Vec::new(); threads];
    for (i, &w) in assign.iter().enumerate() {
        slices[w].push(level[i]);
    }
    slices
}

#[cfg(test)]
mod tests {
    use crate::parallel::config::{PlanConfig, Slicing, Strategy};
    use crate::parallel::planning::plan::Plan;

    /// Four independent chains (`n` rungs each per level) over three levels; the second level
    /// lists the chains in the order 2, 3, 0, 1, the others 0, 1, 2, 3. Rung `x_k_l_j` reads
    /// `x_k_(l-1)_j`; level 1 reads variables nobody writes.
    fn chains(n: usize) -> plc_model::Program {
        let mut vars = Vec::new();
        let mut rungs = Vec::new();
        for k in 0..4 {
            for l in 0..4 {
                for j in 0..n {
                    vars.push(format!(r#"{{"name": "x{k}_{l}_{j}", "type": "BOOL"}}"#));
                }
            }
        }
        for (l, order) in [(1, [0, 1, 2, 3]), (2, [2, 3, 0, 1]), (3, [0, 1, 2, 3])] {
            for k in order {
                for j in 0..n {
                    rungs.push(format!(
                        r#"{{"id": "R{k}_{l}_{j}", "ld": [{{"contact": "x{k}_{}_{j}"}}, {{"coil": "x{k}_{l}_{j}"}}]}}"#,
                        l - 1
                    ));
                }
            }
        }
        let json = format!(
            r#"{{"program": "chains", "vars": [{}], "rungs": [{}]}}"#,
            vars.join(", "),
            rungs.join(", ")
        );
        plc_load::program_from_json(&json).expect("a valid program")
    }

    fn plan(p: &plc_model::Program, slicing: Slicing) -> Plan {
        let a = plc_analysis::analyse(p);
        let config = PlanConfig {
            strategy: Strategy::AllParallel,
            slicing,
            ..PlanConfig::new(2)
        };
        Plan::build(p, &a, &config)
    }

    #[test]
    fn the_locality_partition_keeps_each_chain_on_its_worker() {
        let p = chains(100);
        let local = plan(&p, Slicing::Locality);
        let contig = plan(&p, Slicing::Contiguous);
        assert!(local.sequential().is_none() && contig.sequential().is_none());
        let lines = |pl: &Plan| -> Vec<Vec<u64>> {
            pl.levels().iter().map(|lp| lp.lines.clone()).collect()
        };
        // Contiguous slicing puts chains 2, 3 on worker 0 in level 2: both workers fetch what
        // the other wrote (100 BOOLs of each of 2 chains: 4 lines each way), and again in level 3.
        assert_eq!(lines(&contig), [vec![0, 0], vec![4, 4], vec![4, 4]]);
        // The locality partition follows the producers: nothing moves.
        assert_eq!(lines(&local), [vec![0, 0], vec![0, 0], vec![0, 0]]);
        assert_eq!(local.levels()[1].slicing, "locality");
        // Each rung (one contact and a coil) is fused whole: 4 steps; one item of 12.
        let fused = PlanConfig::new(2).fused_rung_cost;
        assert_eq!(fused, 4);
        assert_eq!(
            local.levels()[1].workers,
            [(200, 1, 200 * fused + 12), (200, 1, 200 * fused + 12)]
        );
        // Auto slicing picks the locality cut where it moves less.
        let auto = plan(&p, Slicing::Auto);
        assert_eq!(lines(&auto), lines(&local));
        let (_, est_local) = local.estimates();
        let (_, est_contig) = contig.estimates();
        assert_eq!(
            est_contig - est_local,
            2 * 4 * PlanConfig::DEFAULT_LINE_COST
        );
    }
}
