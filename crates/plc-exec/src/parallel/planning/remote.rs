//! Remote lines: for every worker's slice of a levelled plan's parallel phases, the state's
//! cache lines it will find in another core's cache, so that the machine can prefetch them
//! when the slice starts (`plc_hint`) and their transfers overlap instead of each stalling
//! the rung that needs it.
//!
//! Why: on the shared two-vCPU host, running the second worker on a private copy of the state
//! (every result wrong, timing comparable) took gen 20k's levelled plan from 77–89 µs to
//! 59–63 µs per scan; the difference is the lines that cross between the cores each scan, about
//! 70 read and 190 written by another core than the one holding them, ~100 ns apiece. A store
//! to a line another core holds stalls the stores behind it (x86 commits them in order) until
//! the line comes; `PREFETCHW` at the start of the slice fetches all of them at once.
//!
//! Definitions. Walk the phases in scan order, twice (the second walk sees what the previous
//! scan left behind), keeping for every line the worker that wrote it last and the workers that
//! read it since. Worker 0 writes the inputs' lines before every scan and reads the whole state
//! after it (the run's driver: the digest of every scan, the trace). In a parallel phase, the
//! slice of worker `w`
//! - *reads remotely* a line it reads whose last writer is another worker and which `w` has
//!   not read since that write;
//! - *writes remotely* a line it writes whose last writer is another worker or which another
//!   worker has read since the last write.
//!
//! The slices of one phase run at the same time: each is judged against the state before the
//! phase, then all of them are applied. A slice another worker takes over (`claimed`) keeps
//! its lines; the hint is then only less useful. Accesses come from the lowered instructions
//! (`Machine::rung_accesses`), with the real layout: the same ground truth as the plan check.
//!
//! A dependence-driven plan has one phase whose items wait for each other one by one: its
//! items are walked in one order that respects every wait (`ready::item_order`), and only the
//! lines an item writes are kept (reads at the start would fetch lines not written yet); the
//! machine prefetches them one item ahead. The items of different workers run at the same time
//! in any interleaving the waits allow, so these lines are a guess from one of them.
//!
//! Cost: one pass over every rung's accesses per walk, O(accesses + lines) time and memory.
//! Not here: any decision (the lines are a hint).

use super::phase::{Phase, PhaseKind, RemoteLines};
use super::plan::Plan;
use super::ready::item_order;
use crate::{Machine, Span, LINE_BYTES};

/// What the walk knows of one line.
#[derive(Copy, Clone, Debug, Default)]
struct Line {
    /// The worker that wrote it last, if any did.
    writer: Option<u32>,
    /// Workers that read it since (bit `min(w, 63)`).
    readers: u64,
}

fn bit(w: u32) -> u64 {
    1 << w.min(63)
}

/// The lines of `spans`, appended to `out`.
fn lines_of(spans: &[Span], out: &mut Vec<u32>) {
    for &(at, width) in spans {
        let first = at.index() / LINE_BYTES as usize;
        let last = (at.index() + width.max(1) as usize - 1) / LINE_BYTES as usize;
        out.extend(first as u32..=last as u32);
    }
}

/// The lines one slice reads and writes (sorted, distinct).
fn slice_lines(machine: &Machine, plan: &Plan, items: &[super::tasks::Item]) -> [Vec<u32>; 2] {
    let (mut reads, mut writes) = (Vec::new(), Vec::new());
    let (mut rl, mut wl) = (Vec::new(), Vec::new());
    for t in items.iter().flat_map(|it| it.tasks()) {
        for &r in &plan.task_rungs[t.index()] {
            reads.clear();
            writes.clear();
            machine.rung_accesses(r, &mut reads, &mut writes);
            lines_of(&reads, &mut rl);
            lines_of(&writes, &mut wl);
        }
    }
    for l in [&mut rl, &mut wl] {
        l.sort_unstable();
        l.dedup();
    }
    [rl, wl]
}

/// Fills `plan.remote` (a levelled plan) or `plan.item_remote` (a dependence-driven plan) for
/// `machine`'s layout (nothing for a sequential plan).
pub(in crate::parallel) fn find_remote_lines(machine: &Machine, plan: &mut Plan) {
    if plan.sequential.is_some() {
        return;
    }
    if plan.ready.is_some() {
        plan.item_remote = item_remote_lines(machine, plan);
        return;
    }
    let mut lines =
        vec![Line::default(); (machine.state_size() as usize).div_ceil(LINE_BYTES as usize)];
    let mut inputs = Vec::new();
    lines_of(&machine.input_spans(), &mut inputs);
    // Per phase, per worker: its slice's (reads, writes).
    let touched: Vec<Vec<(u32, [Vec<u32>; 2])>> = plan
        .phases
        .iter()
        .map(|ph: &Phase| {
            ph.slices()
                .into_iter()
                .map(|(w, items)| (w as u32, slice_lines(machine, plan, items)))
                .collect()
        })
        .collect();
    let mut remote = vec![Vec::new(); plan.phases.len()];
    for walk in 0..2 {
        for &l in &inputs {
            lines[l as usize] = Line {
                writer: Some(0),
                readers: 0,
            };
        }
        for (pi, slices) in touched.iter().enumerate() {
            if walk == 1 && matches!(plan.phases[pi].kind, PhaseKind::Parallel(_)) {
                remote[pi] = slices
                    .iter()
                    .map(|(w, [rl, wl])| remote_of(&lines, *w, rl, wl))
                    .collect();
            }
            for (w, [rl, wl]) in slices {
                for &l in rl {
                    lines[l as usize].readers |= bit(*w);
                }
                for &l in wl {
                    lines[l as usize] = Line {
                        writer: Some(*w),
                        readers: 0,
                    };
                }
            }
        }
        // The driver looks at the whole state on worker 0 after the scan.
        lines.iter_mut().for_each(|l| l.readers |= bit(0));
    }
    plan.remote = remote;
}

/// Per worker, per item of a dependence-driven plan's phase: the lines it writes that another
/// core holds, from two walks of the items in one order its waits allow.
fn item_remote_lines(machine: &Machine, plan: &Plan) -> Vec<Vec<RemoteLines>> {
    let Some(ph) = plan.phases.first() else {
        return Vec::new();
    };
    let slices = ph.slices();
    let counts: Vec<usize> = slices.iter().map(|(_, items)| items.len()).collect();
    let waits_of = |w: usize, i: usize| {
        let r = &slices[w].1[i].waits;
        plan.waits[r.start as usize..r.end as usize].to_vec()
    };
    let Ok(order) = item_order(&counts, waits_of) else {
        return Vec::new();
    };
    let touched: Vec<Vec<[Vec<u32>; 2]>> = slices
        .iter()
        .map(|(_, items)| {
            items
                .iter()
                .map(|it| slice_lines(machine, plan, std::slice::from_ref(it)))
                .collect()
        })
        .collect();
    let mut lines =
        vec![Line::default(); (machine.state_size() as usize).div_ceil(LINE_BYTES as usize)];
    let mut inputs = Vec::new();
    lines_of(&machine.input_spans(), &mut inputs);
    let mut out: Vec<Vec<RemoteLines>> = counts
        .iter()
        .map(|&n| vec![RemoteLines::default(); n])
        .collect();
    for walk in 0..2 {
        for &l in &inputs {
            lines[l as usize] = Line {
                writer: Some(0),
                readers: 0,
            };
        }
        for &(w, i) in &order {
            let [rl, wl] = &touched[w][i];
            if walk == 1 {
                out[w][i].writes = remote_of(&lines, w as u32, rl, wl).writes;
            }
            for &l in rl {
                lines[l as usize].readers |= bit(w as u32);
            }
            for &l in wl {
                lines[l as usize] = Line {
                    writer: Some(w as u32),
                    readers: 0,
                };
            }
        }
        lines.iter_mut().for_each(|l| l.readers |= bit(0));
    }
    out
}

/// The remote lines of worker `w`'s slice reading `rl` and writing `wl`, given `lines`.
fn remote_of(lines: &[Line], w: u32, rl: &[u32], wl: &[u32]) -> RemoteLines {
    let other_writer = |x: &Line| x.writer.is_some_and(|v| v != w);
    RemoteLines {
        reads: rl
            .iter()
            .copied()
            .filter(|&l| {
                let x = &lines[l as usize];
                other_writer(x) && x.readers & bit(w) == 0
            })
            .collect(),
        writes: wl
            .iter()
            .copied()
            .filter(|&l| {
                let x = &lines[l as usize];
                other_writer(x) || x.readers & !bit(w) != 0
            })
            .collect(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::parallel::config::{PlanConfig, Strategy};
    use crate::{ExecConfig, Layout};

    /// Level 1: R1 `a → x`, R2 `b → y`; level 2: R3 and R4 both read x and y (so whoever runs
    /// them reads one line the other worker wrote). Every variable on its own line.
    fn machine_and_plan() -> (Machine, Plan) {
        machine_and(Plan::build)
    }

    /// The same program under `build`.
    fn machine_and(
        build: impl Fn(&plc_model::Program, &plc_analysis::Analysis, &PlanConfig) -> Plan,
    ) -> (Machine, Plan) {
        let p = plc_load::program_from_json(
            r#"{"program": "p", "vars": [
                {"name": "a", "type": "BOOL", "class": "input"},
                {"name": "b", "type": "BOOL", "class": "input"},
                {"name": "x", "type": "BOOL", "class": "memory"},
                {"name": "y", "type": "BOOL", "class": "memory"},
                {"name": "z", "type": "BOOL", "class": "output"},
                {"name": "u", "type": "BOOL", "class": "output"}],
              "rungs": [{"id": "R1", "ld": [{"contact": "a"}, {"coil": "x"}]},
                        {"id": "R2", "ld": [{"contact": "b"}, {"coil": "y"}]},
                        {"id": "R3", "ld": [{"contact": "x"}, {"contact": "y"}, {"coil": "z"}]},
                        {"id": "R4", "ld": [{"contact": "y"}, {"contact": "x"}, {"coil": "u"}]}]}"#,
        )
        .unwrap();
        let config = PlanConfig {
            strategy: Strategy::AllParallel,
            ..PlanConfig::new(2)
        };
        let plan = build(&p, &plc_analysis::analyse(&p), &config);
        let layout = Layout::from_starts(&p, (0..6).map(|i| i * 64).collect(), 6 * 64).unwrap();
        (
            Machine::new(&p, layout, &ExecConfig::default()).unwrap(),
            plan,
        )
    }

    #[test]
    fn the_lines_another_core_wrote_or_holds_per_slice() {
        let (m, mut plan) = machine_and_plan();
        assert_eq!(plan.parallel_phases(), 2);
        find_remote_lines(&m, &mut plan);
        let counts: Vec<Vec<(usize, usize)>> = (plan.remote.iter())
            .map(|ph| ph.iter().map(|s| (s.reads.len(), s.writes.len())).collect())
            .collect();
        // Level 1: worker 1 reads the input line worker 0 wrote before the scan; each writes a
        // line both read in level 2. Level 2: each reads the other's line of level 1; worker 1's
        // output line was read by worker 0 after the previous scan (the driver), worker 0's not.
        assert_eq!(counts, vec![vec![(0, 1), (1, 1)], vec![(1, 0), (1, 1)]]);
        assert_eq!(plan.remote_lines(), (3, 3));
        // The lines are real: level 2's reads are the lines of x (2) and y (3).
        let reads: Vec<u32> = plan.remote[1]
            .iter()
            .flat_map(|s| s.reads.clone())
            .collect();
        assert_eq!(
            reads
                .iter()
                .copied()
                .collect::<std::collections::BTreeSet<u32>>(),
            [2, 3].into()
        );
    }

    /// The dependence-driven plan on the level slices: worker 0 runs R1 then R3, worker 1 R2
    /// then R4. Per item, the lines it writes that the other core holds: x (line 2, read by R4
    /// on worker 1) and y (3, read by R3 on worker 0), and u (5): worker 1's output, read by
    /// the driver on worker 0 after the previous scan; not z (4), worker 0's own.
    #[test]
    fn a_dependence_driven_plans_items_write_lines_the_other_core_holds() {
        let (m, mut plan) = machine_and(|p, a, config| {
            let config = PlanConfig {
                deps_partition: crate::parallel::config::DepsPartition::Levels,
                slicing: crate::parallel::config::Slicing::Contiguous,
                ..*config
            };
            super::super::deps_plan::build(p, a, &config)
        });
        assert!(plan.sequential.is_none());
        find_remote_lines(&m, &mut plan);
        assert!(plan.remote.is_empty());
        let writes: Vec<Vec<Vec<u32>>> = (plan.item_remote.iter())
            .map(|w| w.iter().map(|it| it.writes.clone()).collect())
            .collect();
        assert_eq!(writes, vec![vec![vec![2], vec![]], vec![vec![3], vec![5]]]);
        assert_eq!(plan.remote_lines(), (0, 3));
    }

    #[test]
    fn a_sequential_plan_has_none() {
        let (m, mut plan) = machine_and_plan();
        plan.sequential = Some("test".into());
        find_remote_lines(&m, &mut plan);
        assert!(plan.remote.is_empty());
    }
}
