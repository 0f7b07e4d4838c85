//! Small runs of the parallel machine on real worker threads, sized for Miri (`.ci/run` runs
//! the `miri_` tests under it): a two-level program on one and two workers, under the levelled,
//! the dependence-driven and the exchange plans, equal to the sequential scan byte for byte
//! after every scan. Under Miri they check the machine's shared-state code for data races and
//! undefined behaviour; in the ordinary test run they are one more differential case.

use super::{ParallelMachine, PlanConfig, PlanKind, ScanDriver};
use crate::{ExecConfig, Fault, Machine};
use plc_model::{Value, VarId};
use std::time::Duration;

/// Four independent rungs (one level), then two rungs reading their coils, then one more.
const PROGRAM: &str = r#"{"program": "miri",
  "vars": [
    {"name": "a", "type": "BOOL", "class": "input"}, {"name": "b", "type": "BOOL", "class": "input"},
    {"name": "c", "type": "BOOL", "class": "input"}, {"name": "d", "type": "BOOL", "class": "input"},
    {"name": "x1", "type": "BOOL"}, {"name": "x2", "type": "BOOL"},
    {"name": "x3", "type": "BOOL"}, {"name": "x4", "type": "BOOL"},
    {"name": "y1", "type": "BOOL"}, {"name": "y2", "type": "BOOL"},
    {"name": "q", "type": "BOOL", "class": "output"}
  ],
  "rungs": [
    {"id": "R1", "ld": [{"contact": "a"}, {"contact": "b"}, {"coil": "x1"}]},
    {"id": "R2", "ld": [{"contact": "c"}, {"coil": "x2"}]},
    {"id": "R3", "ld": [{"contact": "d", "negated": true}, {"coil": "x3"}]},
    {"id": "R4", "ld": [{"contact": "a"}, {"contact": "d"}, {"coil": "x4"}]},
    {"id": "R5", "ld": [{"contact": "x1"}, {"contact": "x2"}, {"coil": "y1"}]},
    {"id": "R6", "ld": [{"contact": "x3"}, {"contact": "x4", "negated": true}, {"coil": "y2"}]},
    {"id": "R7", "ld": [{"contact": "y1"}, {"contact": "y2"}, {"coil": "q"}]}
  ]}"#;

/// The inputs of scan `k`: the four bits of `k`.
fn inputs(scan: u64) -> Vec<(VarId, Value)> {
    (0..4u32)
        .map(|i| (VarId::from_raw(i), Value::Bool(scan >> i & 1 == 1)))
        .collect()
}

/// Writes the inputs and records the state after every scan.
struct Record(Vec<Vec<u8>>);

impl ScanDriver for Record {
    fn before_scan(&mut self, m: &Machine, scan: u64, slots: &mut [u8]) {
        m.set_inputs_in(slots, &inputs(scan));
    }
    fn after_scan(&mut self, _: &Machine, _: u64, slots: &[u8], _: &[Fault], _: Duration) {
        self.0.push(slots.to_vec());
    }
    fn wants_time(&self) -> bool {
        false
    }
}

/// Runs `scans` scans of the program under `kind` on `threads` workers and compares each
/// scan's state with the sequential scan's.
fn same_as_sequential(kind: PlanKind, threads: usize, scans: u64) {
    let p = plc_load::program_from_json(PROGRAM).expect("loads");
    let a = plc_analysis::analyse(&p);
    let exec = ExecConfig::default();
    let config = PlanConfig {
        kind,
        // Free barriers, waits and items: the plan is parallel even for seven rungs.
        barrier_cost: 0,
        wait_cost: 0,
        item_cost: 0,
        ..PlanConfig::new(threads)
    };
    let par = ParallelMachine::new(&p, &a, &exec, &config).expect("plans");
    // A forced plan may be modelled slower (a warning); none may fail its check.
    assert!(
        par.warnings()
            .iter()
            .all(|w| !w.contains("failed its check")),
        "{:?}",
        par.warnings()
    );
    if threads > 1 {
        assert_eq!(par.plan().sequential(), None, "{kind:?}: a parallel plan");
    }
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads - 1)
        .build()
        .expect("a pool");
    let mut state = par.initial_state();
    let mut run = Record(Vec::new());
    par.run(
        (threads > 1).then_some(&pool),
        &mut state,
        0..scans,
        &mut run,
    );
    let seq = Machine::new(&p, par.machine().layout().clone(), &exec).expect("lowers");
    let mut s = seq.initial_state();
    let mut faults = Vec::new();
    for scan in 0..scans {
        seq.set_inputs(&mut s, &inputs(scan));
        seq.run_scan(&mut s, scan, &mut faults);
        assert_eq!(run.0[scan as usize], s.bytes(), "{kind:?}, scan {scan}");
    }
    assert!(faults.is_empty());
    assert_eq!(state.bytes(), s.bytes());
}

#[test]
fn miri_one_worker_runs_the_sequential_scan() {
    same_as_sequential(PlanKind::Par, 1, 4);
}

#[test]
fn miri_two_workers_levelled() {
    same_as_sequential(PlanKind::Par, 2, 6);
}

#[test]
fn miri_two_workers_dependence_driven() {
    same_as_sequential(PlanKind::Deps, 2, 6);
}

#[test]
fn miri_two_workers_on_private_states() {
    same_as_sequential(PlanKind::Exchange, 2, 6);
}
