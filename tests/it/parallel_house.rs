//! The parallel machine's house: the planner as one call for another back end
//! (`exec::parallel::plan`, the plan as plain data), walked here as a back end would walk it —
//! phases in order, each worker's items, the guards, entries, decisions and ready-flag waits —
//! on one thread, against the sequential scan, every scan. (The executor's import order is
//! checked with every crate's by `module_cycles`.)

use plc_deps::analysis::analyse;
use plc_deps::exec::parallel::Decision;
use plc_deps::exec::parallel::{
    plan, ItemRegion, Next, PlanConfig, PlanKind, ScanItem, ScanPlan, ScanPlanKind, Strategy,
};
use plc_deps::exec::{ExecConfig, Exit, Fault, Layout, Machine};
use plc_deps::model::{Program, RungId};

fn gen(config: &plc_deps::synth::GenConfig) -> Program {
    plc_deps::load::program_from_json(&plc_deps::synth::generate_string(config)).unwrap()
}

/// Where a decision leads: the task of the rung control went to, or the end of the scan.
fn leads_to(sp: &ScanPlan, d: Decision) -> Option<Next> {
    match d {
        Decision::NotRun => None,
        Decision::Stop => Some(Next::Stop),
        Decision::Rung(r) | Decision::ForTest(r) => {
            sp.task_of_rung[r.raw() as usize].map(Next::Task)
        }
    }
}

/// Runs one item as the module documentation of `static_plan` says a back end does.
fn run_item(
    m: &Machine,
    sp: &ScanPlan,
    it: &ScanItem,
    mem: &mut [u8],
    ctx: &mut plc_deps::exec::ScanCtx<'_>,
    decisions: &mut [Decision],
) {
    let holds = it.guard.is_empty()
        || it
            .guard
            .iter()
            .any(|g| leads_to(sp, decisions[g.slot.index()]) == Some(g.leads_to));
    let start = if !holds {
        None
    } else if it.entry_slots.is_empty() {
        Some(Exit::Rung(it.entry))
    } else {
        it.entry_slots.iter().find_map(|s| {
            let d = decisions[s.index()];
            (leads_to(sp, d) == Some(Next::Task(it.first))).then_some(match d {
                Decision::ForTest(h) => Exit::ForTest(h),
                Decision::Rung(r) => Exit::Rung(r),
                _ => unreachable!("a decision that leads to a task names a rung"),
            })
        })
    };
    let Some(at) = start else {
        if let Some(s) = it.decision {
            decisions[s.index()] = Decision::NotRun;
        }
        return;
    };
    let exit = match it.inside {
        ItemRegion::Rungs(lo, hi) => {
            m.resume(mem, ctx, at, |r: RungId| lo <= r.raw() && r.raw() < hi)
        }
        ItemRegion::Tasks(lo, hi) => m.resume(mem, ctx, at, |r: RungId| {
            sp.task_of_rung[r.raw() as usize].is_some_and(|t| lo <= t && t <= hi)
        }),
    };
    if let Some(s) = it.decision {
        decisions[s.index()] = match exit {
            Exit::Stop => Decision::Stop,
            Exit::Rung(r) => Decision::Rung(r),
            Exit::ForTest(h) => Decision::ForTest(h),
        };
    }
}

/// The items of one scan in an order a back end's workers could run them in: phase by phase;
/// within a phase, each worker's items in order, a worker going on while its waits hold.
fn serial_order(sp: &ScanPlan) -> Vec<&ScanItem> {
    let mut out = Vec::new();
    for ph in &sp.phases {
        let mut next = vec![0usize; ph.workers.len()];
        loop {
            let mut moved = false;
            for w in 0..ph.workers.len() {
                while let Some(it) = ph.workers[w].get(next[w]) {
                    if !it.waits.iter().all(|x| next[x.worker] >= x.done as usize) {
                        break;
                    }
                    out.push(it);
                    next[w] += 1;
                    moved = true;
                }
            }
            if !moved {
                break;
            }
        }
        assert!(
            next.iter()
                .zip(&ph.workers)
                .all(|(&n, items)| n == items.len()),
            "every item of the phase runs (no cycle of waits)"
        );
    }
    out
}

/// Walks `sp` for `scans` scans and compares state and faults with the sequential scan after
/// every scan.
fn walk_equals_sequential(p: &Program, sp: &ScanPlan, scans: u64, label: &str) {
    let exec = ExecConfig::default();
    let m = Machine::new(p, Layout::dense(p), &exec).unwrap();
    let (mut seq, mut walked) = (m.initial_state(), m.initial_state());
    let mut decisions = vec![Decision::NotRun; sp.decision_slots];
    let order = serial_order(sp);
    for scan in 0..scans {
        let mut want = Vec::new();
        m.run_scan(&mut seq, scan, &mut want);
        let mem = walked.bytes_mut();
        m.begin_scan(mem);
        let mut got: Vec<(u32, Fault)> = Vec::new();
        let mut buf = Vec::new();
        for it in &order {
            let mut ctx = m.context(scan, &mut buf);
            run_item(&m, sp, it, mem, &mut ctx, &mut decisions);
            got.extend(buf.drain(..).map(|f| (it.first.raw(), f)));
        }
        got.sort_by_key(|&(t, _)| t);
        let got: Vec<Fault> = got.into_iter().map(|(_, f)| f).collect();
        assert_eq!(got, want, "{label}: faults of scan {scan}");
        assert!(walked == seq, "{label}: state after scan {scan}");
    }
}

/// Every task of the schedule is in exactly one item of one phase.
fn covers_every_task_once(sp: &ScanPlan, tasks: usize, label: &str) {
    let mut seen = vec![0u32; tasks];
    for ph in &sp.phases {
        assert_eq!(ph.workers.len(), sp.workers, "{label}");
        for (w, items) in ph.workers.iter().enumerate() {
            assert!(ph.parallel || w == 0 || items.is_empty(), "{label}");
            for it in items {
                for t in it.first.raw()..=it.last.raw() {
                    seen[t as usize] += 1;
                }
            }
        }
    }
    assert!(seen.iter().all(|&n| n == 1), "{label}: {seen:?}");
}

#[test]
fn the_plan_as_data_walked_as_a_back_end_would_equals_the_sequential_scan() {
    for (rungs, width, seed) in [(1500, 60, 1), (800, 40, 2), (1200, 100, 3)] {
        let p = gen(&plc_deps::synth::GenConfig::all_features(
            rungs, width, seed,
        ));
        let a = analyse(&p);
        for (kind, threads) in [(PlanKind::Par, 2), (PlanKind::Par, 3), (PlanKind::Deps, 2)] {
            let config = PlanConfig {
                kind,
                strategy: Strategy::AllParallel,
                ..PlanConfig::new(threads)
            };
            let sp = plan(&p, &a, &config).unwrap();
            let label = format!("gen {rungs}/{width}/{seed}, {} on {threads}", kind.name());
            let want = if kind == PlanKind::Deps {
                ScanPlanKind::DependenceDriven
            } else {
                ScanPlanKind::Levelled
            };
            assert_eq!(sp.kind, want, "{label}");
            assert_eq!(sp.workers, threads, "{label}");
            assert!(sp.phases.iter().any(|ph| ph.parallel), "{label}");
            covers_every_task_once(&sp, a.schedule.tasks.len(), &label);
            if kind == PlanKind::Deps {
                assert_eq!(sp.phases.len(), 1, "{label}");
                let items = sp.phases[0].workers.iter().flatten();
                assert!(items.clone().any(|it| !it.waits.is_empty()), "{label}");
                assert!(items.clone().any(|it| it.publish), "{label}");
            } else {
                assert!(
                    sp.phases.iter().all(|ph| ph
                        .workers
                        .iter()
                        .flatten()
                        .all(|it| it.waits.is_empty())),
                    "{label}"
                );
            }
            walk_equals_sequential(&p, &sp, 25, &label);
        }
    }
}

#[test]
fn the_plan_as_data_has_the_machines_phases_and_barriers() {
    let p = gen(&plc_deps::synth::GenConfig {
        rungs: 4000,
        width: 200,
        ..Default::default()
    });
    let a = analyse(&p);
    let config = PlanConfig {
        kind: PlanKind::Par,
        ..PlanConfig::new(2)
    };
    let sp = plan(&p, &a, &config).unwrap();
    let par =
        plc_deps::exec::parallel::ParallelMachine::new(&p, &a, &ExecConfig::default(), &config)
            .unwrap();
    let machine_plan = par.plan();
    assert_eq!(sp.kind, ScanPlanKind::Levelled);
    assert_eq!(sp.phases.len(), machine_plan.phase_count());
    let barriers =
        sp.phases.iter().filter(|ph| ph.barrier_before).count() + sp.end_barrier as usize;
    assert_eq!(barriers, machine_plan.barriers_per_scan());
    assert_eq!(
        sp.phases.iter().filter(|ph| ph.parallel).count(),
        machine_plan.parallel_phases()
    );
    walk_equals_sequential(&p, &sp, 5, "gen 4000/200");
}

#[test]
fn a_chain_and_the_seq_kind_plan_the_sequential_walk() {
    let chain = plc_deps::load::program_from_json(
        r#"{"program": "chain", "vars": [{"name": "go", "type": "BOOL", "class": "input"},
            {"name": "a", "type": "BOOL"}, {"name": "b", "type": "BOOL"}],
            "rungs": [{"id": "R0", "ld": [{"contact": "go"}, {"coil": "a"}]},
                      {"id": "R1", "ld": [{"contact": "a"}, {"coil": "b"}]}]}"#,
    )
    .unwrap();
    let a = analyse(&chain);
    let sp = plan(&chain, &a, &PlanConfig::new(2)).unwrap();
    assert!(
        matches!(sp.kind, ScanPlanKind::Sequential(ref why) if !why.is_empty()),
        "{:?}",
        sp.kind
    );
    assert!(sp.phases.is_empty());
    let p = gen(&plc_deps::synth::GenConfig {
        rungs: 2000,
        width: 100,
        ..Default::default()
    });
    let a = analyse(&p);
    let seq = PlanConfig {
        kind: PlanKind::Seq,
        ..PlanConfig::new(2)
    };
    let sp = plan(&p, &a, &seq).unwrap();
    assert!(
        matches!(sp.kind, ScanPlanKind::Sequential(_)),
        "{:?}",
        sp.kind
    );
}
