//! Differential property test of the parallel scan: for thousands of random programs (every
//! element kind, forward and backward jumps, FOR loops, calls, timers, counters, set/reset,
//! edges; `tests/it/common`) and random input sequences, the parallel executor with 1, 2 and 4
//! workers leaves exactly the sequential scan's slot array — and the same faults, in the same
//! order — after every scan. The sequential reference runs on the same (padded) layout, so the
//! full slot arrays compare directly, loop counters and hidden state included.
//!
//! The plans are forced to be as parallel as possible (every level a parallel phase, or the cost
//! model with free barriers) and alternate contiguous, LPT and locality slicing, so that barriers,
//! decisions, guards, multi-entry loops and runs of tasks are all exercised; a small loop cap
//! makes the cap's refusals frequent. One thread pool serves every case.

use crate::common;

use common::Recorder;

use plc_deps::analysis::analyse;
use plc_deps::exec::parallel::{
    Candidate, DepsPartition, Measure, ParallelMachine, PlanConfig, PlanKind, ScanDriver, Slicing,
    Strategy,
};
use plc_deps::exec::{ExecConfig, Fault, FaultKind, Machine};
use plc_deps::model::{Program, Value, VarClass, VarId};
use std::time::Duration;

const PROGRAMS: u64 = 2000;
const SCANS: u64 = 30;
const THREADS: [usize; 3] = [1, 2, 4];

/// Random inputs per scan: the BOOL inputs, the INT input `k` (often 0: DIV/MOD faults) and the
/// LINT input `kl` (`common::random_input`).
fn input_table(p: &Program, seed: u64, scans: u64) -> Vec<Vec<(VarId, Value)>> {
    let mut rng = common::Rng::new(seed ^ 0xABCD);
    let inputs: Vec<VarId> = (0..p.vars().len() as u32)
        .map(VarId::from_raw)
        .filter(|&v| p.var(v).class == VarClass::Input)
        .collect();
    (0..scans)
        .map(|_| {
            let mut row = Vec::new();
            for &v in &inputs {
                if rng.chance(20) {
                    continue; // sometimes an input keeps its value
                }
                let value = common::random_input(p.var(v).ty, &mut rng);
                row.push((v, value));
            }
            row
        })
        .collect()
}

#[derive(Default)]
struct Stats {
    cases: u64,
    parallel_cases: u64,
    parallel_phases: u64,
    loop_cap_faults: u64,
    div_faults: u64,
    budget_faults: u64,
    /// Cases where the run mixed the sequential walk and a levelled plan.
    mixed_runs: u64,
    switches: u64,
    /// Cases that ran a dependence-driven plan, and its waits per scan.
    deps_cases: u64,
    deps_waits: u64,
    /// Dependence-driven plans on the one-way partition.
    one_way_cases: u64,
    /// Cases that ran scans on private states (`par-exchange`).
    exchange_cases: u64,
    /// Of those, cases whose plan runs some work before its phase's hand-over.
    early_cases: u64,
    /// Cases whose `par-exchange` candidate has a layout of its own (the state moved between
    /// two layouts).
    own_layout_cases: u64,
}

/// A driver that reads the state only through the machine it is given, in whichever layout:
/// records every scan's canonical values and faults.
struct Canonical<'a> {
    inputs: &'a [Vec<(VarId, Value)>],
    values: Vec<Vec<u8>>,
    faults: Vec<Vec<Fault>>,
}

/// The bytes of `m`'s canonical values in `slots` (a state of `m`'s layout), in order.
fn canonical_bytes(m: &Machine, slots: &[u8]) -> Vec<u8> {
    (m.canonical_values().iter())
        .flat_map(|&(at, w)| slots[at.index()..at.index() + w as usize].iter().copied())
        .collect()
}

impl ScanDriver for Canonical<'_> {
    fn before_scan(&mut self, m: &Machine, scan: u64, slots: &mut [u8]) {
        m.set_inputs_in(slots, &self.inputs[scan as usize]);
    }
    fn after_scan(&mut self, m: &Machine, _: u64, slots: &[u8], faults: &[Fault], _: Duration) {
        self.values.push(canonical_bytes(m, slots));
        self.faults.push(faults.to_vec());
    }
    fn reads_any_layout(&self) -> bool {
        true
    }
}

/// A driver that writes the inputs and reads nothing back: the parallel executor may leave the
/// caller's state behind while a plan runs on its own layout, and must bring it up to date by
/// the end of the run.
struct Blind<'a>(&'a [Vec<(VarId, Value)>]);

impl ScanDriver for Blind<'_> {
    fn before_scan(&mut self, m: &Machine, scan: u64, slots: &mut [u8]) {
        m.set_inputs_in(slots, &self.0[scan as usize]);
    }
    fn after_scan(&mut self, _: &Machine, _: u64, _: &[u8], _: &[Fault], _: Duration) {}
    fn wants_state(&self) -> bool {
        false
    }
}

/// Runs one program under one plan configuration and compares every scan.
#[allow(clippy::too_many_arguments)]
fn check(
    p: &Program,
    label: &str,
    config: &PlanConfig,
    exec: &ExecConfig,
    scans: u64,
    seed: u64,
    pool: &rayon::ThreadPool,
    stats: &mut Stats,
) {
    let inputs = input_table(p, seed, scans);
    check_with(p, label, config, exec, &inputs, pool, stats)
}

fn check_with(
    p: &Program,
    label: &str,
    config: &PlanConfig,
    exec: &ExecConfig,
    inputs: &[Vec<(VarId, Value)>],
    pool: &rayon::ThreadPool,
    stats: &mut Stats,
) {
    let scans = inputs.len() as u64;
    let a = analyse(p);
    let par = ParallelMachine::new(p, &a, exec, config).unwrap_or_else(|e| panic!("{label}: {e}"));
    if let Err(e) = par.verify(p, &a) {
        panic!("{label}: unsafe plan: {e}\n{}", par.explain(p));
    }
    // A plan that failed its check was dropped with a warning: that is a planner bug here (a
    // forced plan's "modelled slower" warning is not).
    assert!(
        par.warnings()
            .iter()
            .all(|w| w.contains("forces the levelled plan although")),
        "{label}: {:?}\n{}",
        par.warnings(),
        par.explain(p)
    );
    let seq = Machine::new(p, par.machine().layout().clone(), exec).unwrap();
    let mut rec = Recorder {
        inputs,
        states: Vec::new(),
        faults: Vec::new(),
    };
    let mut state = par.initial_state();
    let log = par.run(Some(pool), &mut state, 0..scans, &mut rec);
    assert_eq!(
        log.scans_on.iter().sum::<u64>(),
        scans,
        "{label}: every scan on a candidate"
    );
    let on = |seq: bool| -> u64 {
        (0..log.candidates.len())
            .filter(|&i| (par.candidates()[i] == Candidate::Sequential) == seq)
            .map(|i| log.scans_on[i])
            .sum()
    };
    if on(true) > 0 && on(false) > 0 {
        stats.mixed_runs += 1;
    }
    stats.switches += log.switches.len() as u64;
    let on_private_states = (0..log.candidates.len())
        .any(|i| matches!(par.candidates()[i], Candidate::Exchange(_)) && log.scans_on[i] > 0);
    stats.exchange_cases += on_private_states as u64;
    let early = &par.explain_json()["exchange"]["early_items"];
    stats.early_cases += (on_private_states && early.as_u64() > Some(0)) as u64;
    let own_layout = !par.explain_json()["exchange"]["own_layout"].is_null();
    stats.own_layout_cases += own_layout as u64;
    assert_eq!(
        rec.states.len() as u64,
        scans,
        "{label}: one callback per scan"
    );
    let mut s = seq.initial_state();
    assert_eq!(s.bytes(), par.initial_state().bytes());
    stats.cases += 1;
    if par.plan().sequential().is_none() {
        stats.parallel_cases += 1;
        stats.parallel_phases += par.plan().parallel_phases() as u64;
    }
    if let Some(r) = par
        .plans()
        .iter()
        .filter(|pl| pl.sequential().is_none())
        .find_map(|pl| pl.ready())
    {
        stats.deps_cases += 1;
        stats.deps_waits += r.waits();
        stats.one_way_cases += (r.partition == DepsPartition::OneWay) as u64;
    }
    for scan in 0..scans {
        let mut faults = Vec::new();
        seq.scan(&mut s, scan, &inputs[scan as usize], &mut faults);
        let got = &rec.states[scan as usize];
        if got[..] != *s.bytes() {
            let byte = got.iter().zip(s.bytes()).position(|(a, b)| a != b).unwrap();
            let var = (0..p.vars().len() as u32)
                .map(VarId::from_raw)
                .find(|&v| seq.layout().bytes_of(v).contains(&(byte as u32)));
            panic!(
                "{label}: state differs after scan {scan} at byte {byte} ({}): par {:#x}, seq {:#x}\n{}",
                var.map_or("loop counter, constant or padding".to_string(), |v| p.var(v).name.clone()),
                got[byte],
                s.bytes()[byte],
                par.explain(p)
            );
        }
        assert_eq!(
            rec.faults[scan as usize], faults,
            "{label}: faults of scan {scan}"
        );
        stats.loop_cap_faults += faults
            .iter()
            .filter(|f| f.kind == FaultKind::LoopCap)
            .count() as u64;
        stats.div_faults += faults
            .iter()
            .filter(|f| f.kind == FaultKind::DivByZero)
            .count() as u64;
        stats.budget_faults += faults
            .iter()
            .filter(|f| f.kind == FaultKind::ScanBudget)
            .count() as u64;
    }
    if own_layout {
        // The same run for a driver that does not read the state: the same final state.
        let mut blind = par.initial_state();
        par.run(Some(pool), &mut blind, 0..scans, &mut Blind(inputs));
        assert!(
            blind.bytes() == s.bytes(),
            "{label}: final state of a run whose driver does not read the state"
        );
        // Scans one at a time, two on `par-exchange` (its own layout) and one on the
        // sequential walk (the common one), the state moved at every call.
        let x = (par.candidates().iter())
            .position(|c| matches!(c, Candidate::Exchange(_)))
            .expect("an exchange candidate");
        let walk = (par.candidates().iter())
            .position(|c| *c == Candidate::Sequential)
            .expect("the sequential walk among auto's candidates");
        // Windows of 4 scans alternating between the two for a driver that does not read the
        // state (the caller's state is brought up to date at the end of each), and for one that
        // reads any layout (it sees the own one, value for value the sequential walk's).
        let mut blind = par.initial_state();
        let mut direct = par.initial_state();
        let mut canon = Canonical {
            inputs,
            values: Vec::new(),
            faults: Vec::new(),
        };
        for (k, first) in (0..scans).step_by(4).enumerate() {
            let on = if k % 2 == 0 { x } else { walk };
            let r = first..(first + 4).min(scans);
            par.run_on(on, Some(pool), &mut blind, r.clone(), &mut Blind(inputs));
            par.run_on(on, Some(pool), &mut direct, r, &mut canon);
        }
        assert!(
            blind.bytes() == s.bytes() && direct.bytes() == s.bytes(),
            "{label}: final state of windows alternating between the layouts"
        );
        let mut auto = par.initial_state();
        let mut canon_auto = Canonical {
            inputs,
            values: Vec::new(),
            faults: Vec::new(),
        };
        par.run(Some(pool), &mut auto, 0..scans, &mut canon_auto);
        assert!(
            auto.bytes() == s.bytes(),
            "{label}: final state, any layout"
        );
        // The auto run cut into parts of 1 to 7 scans (`run --mode both` takes turns so), one
        // measured choice across them: every scan as the walk's, and every scan run once.
        let mut parts = par.initial_state();
        let mut canon_parts = Canonical {
            inputs,
            values: Vec::new(),
            faults: Vec::new(),
        };
        let mut run = par.start_run(0);
        let mut end = 0;
        while end < scans {
            end = scans.min(end + 1 + (end * 7 + scans) % 7);
            par.run_more(Some(pool), &mut parts, &mut run, end, &mut canon_parts);
        }
        assert!(
            parts.bytes() == s.bytes() && run.log().scans_on.iter().sum::<u64>() == scans,
            "{label}: final state of an auto run cut into parts"
        );
        for (scan, state) in rec.states.iter().enumerate() {
            let want = canonical_bytes(par.machine(), state);
            for (what, c) in [
                ("windows", &canon),
                ("auto", &canon_auto),
                ("parts", &canon_parts),
            ] {
                assert!(
                    c.values[scan] == want && c.faults[scan] == rec.faults[scan],
                    "{label}: scan {scan} seen by a driver that reads any layout ({what})"
                );
            }
        }
        let (mut a, mut b) = (par.initial_state(), seq.initial_state());
        for scan in 0..scans {
            let on = if scan % 3 == 2 { walk } else { x };
            let (mut fa, mut fb) = (Vec::new(), Vec::new());
            let input = &inputs[scan as usize];
            par.scan_on(on, Some(pool), &mut a, scan, input, &mut fa);
            seq.scan(&mut b, scan, input, &mut fb);
            assert!(
                a.bytes() == b.bytes() && fa == fb,
                "{label}: scan {scan} on candidate {on}, one scan at a time"
            );
        }
    }
}

fn configs(threads: usize, seed: u64) -> PlanConfig {
    let mut c = PlanConfig::new(threads);
    match seed % 5 {
        0 => {
            c.strategy = Strategy::AllParallel;
            c.slicing = Slicing::Contiguous;
        }
        1 => {
            c.strategy = Strategy::AllParallel;
            c.slicing = Slicing::Lpt;
        }
        4 => {
            c.strategy = Strategy::AllParallel;
            c.slicing = Slicing::Locality;
        }
        2 => {
            // The cost model with free barriers and items: parallel wherever a level has two tasks,
            // sequential phases in between.
            c.barrier_cost = 0;
            c.item_cost = 0;
            c.slicing = Slicing::Auto;
        }
        _ => {
            c.strategy = Strategy::AllParallel;
            c.slicing = Slicing::Auto;
        }
    }
    c
}

/// A pool of `threads` threads for the checks.
fn pool(threads: usize) -> rayon::ThreadPool {
    rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .unwrap()
}

/// The scans of the random-program tests: a loop cap low enough that their loops reach it,
/// and a scan budget that their nested loops and calls reach now and then.
const RANDOM_EXEC: ExecConfig = ExecConfig {
    cycle_ms: 10,
    loop_cap: 12,
    scan_budget: 200,
};

/// The random programs (24 rungs at most) of seeds `base + seed` for `seed` in `0..count` that
/// load, with `seed`.
fn random_programs(base: u64, count: u64) -> impl Iterator<Item = (u64, Program)> {
    (0..count).filter_map(move |seed| {
        let json = common::random_program(base + seed, 24);
        plc_deps::load::program_from_json(&json)
            .ok()
            .map(|p| (seed, p))
    })
}

#[test]
fn parallel_scan_equals_sequential_scan_on_random_programs() {
    let pool = pool(3);
    let exec = RANDOM_EXEC;
    let mut stats = Stats::default();
    let mut loaded = 0;
    for (seed, p) in random_programs(0, PROGRAMS) {
        loaded += 1;
        for threads in THREADS {
            let config = configs(threads, seed + threads as u64);
            let label = format!(
                "seed {seed}, {threads} threads, {:?}/{:?}",
                config.strategy, config.slicing
            );
            check(&p, &label, &config, &exec, SCANS, seed, &pool, &mut stats);
        }
    }
    eprintln!(
        "{loaded} programs, {} cases ({} with parallel phases, {} parallel phases), faults: {} loop-cap, {} div-by-zero, {} scan-budget",
        stats.cases, stats.parallel_cases, stats.parallel_phases, stats.loop_cap_faults, stats.div_faults, stats.budget_faults
    );
    assert!(
        loaded >= PROGRAMS * 3 / 4,
        "only {loaded} random programs loaded"
    );
    assert!(
        stats.parallel_cases >= stats.cases / 2,
        "too few parallel plans: {} of {}",
        stats.parallel_cases,
        stats.cases
    );
    assert!(
        stats.loop_cap_faults > 0 && stats.div_faults > 0 && stats.budget_faults > 0,
        "faults are exercised"
    );
}

/// The dependence-driven plan (ready flags instead of barriers) on random programs with 1, 2,
/// 4 and 8 workers, every level sliced (forced) under each slicing: the state after every scan
/// and the faults are the sequential scan's, and most cases really run with waits.
#[test]
fn dependence_driven_plan_equals_sequential_scan_on_random_programs() {
    let pool = pool(7);
    let exec = RANDOM_EXEC;
    let mut stats = Stats::default();
    let mut loaded = 0;
    for (seed, p) in random_programs(90_000, 800) {
        loaded += 1;
        for threads in [1, 2, 4, 8] {
            let mut config = configs(threads, seed + threads as u64);
            config.kind = PlanKind::Deps;
            config.deps_partition = match (seed / 2) % 3 {
                0 => DepsPartition::Levels,
                1 => DepsPartition::OneWay,
                _ => DepsPartition::Auto,
            };
            let label = format!(
                "seed {seed}, {threads} threads, --plan deps, {:?}/{:?}/{:?}",
                config.strategy, config.slicing, config.deps_partition
            );
            check(&p, &label, &config, &exec, SCANS, seed, &pool, &mut stats);
        }
    }
    eprintln!(
        "{loaded} programs, {} cases, {} dependence-driven ({} waits per scan in all), faults: {} loop-cap, {} div-by-zero",
        stats.cases, stats.deps_cases, stats.deps_waits, stats.loop_cap_faults, stats.div_faults
    );
    assert!(loaded >= 600, "only {loaded} random programs loaded");
    assert!(
        stats.deps_cases >= stats.cases / 3,
        "too few dependence-driven plans: {} of {}",
        stats.deps_cases,
        stats.cases
    );
    assert!(stats.deps_waits > stats.deps_cases, "waits are exercised");
    assert!(
        stats.one_way_cases >= stats.deps_cases / 4,
        "too few one-way partitions: {} of {}",
        stats.one_way_cases,
        stats.deps_cases
    );
    assert!(
        stats.loop_cap_faults > 0 && stats.div_faults > 0,
        "faults are exercised"
    );
}

/// The levelled plan on private states (`--plan exchange`: each worker hands the others what
/// it wrote after each phase, BOOLs packed as bits) on random programs with 2, 3, 4 and 8
/// workers, under each slicing: the state after every scan and
/// the faults are the sequential scan's, and most cases really run that way.
#[test]
fn exchange_plan_equals_sequential_scan_on_random_programs() {
    let pool = pool(7);
    let exec = RANDOM_EXEC;
    let mut stats = Stats::default();
    let mut loaded = 0;
    for (seed, p) in random_programs(130_000, 500) {
        loaded += 1;
        for threads in [2, 3, 4, 8] {
            let mut config = configs(threads, seed + threads as u64);
            config.kind = PlanKind::Exchange;
            // Half of the cases cut early work from items at any task, not only in runs of 16.
            config.early_min_tasks = if seed % 2 == 1 { 1 } else { 16 };
            let label = format!(
                "seed {seed}, {threads} threads, --plan exchange, {:?}/{:?}, early pieces of {}+ tasks",
                config.strategy, config.slicing, config.early_min_tasks
            );
            check(&p, &label, &config, &exec, SCANS, seed, &pool, &mut stats);
        }
    }
    eprintln!(
        "{loaded} programs, {} cases, {} on private states ({} with early work), faults: {} loop-cap, {} div-by-zero",
        stats.cases,
        stats.exchange_cases,
        stats.early_cases,
        stats.loop_cap_faults,
        stats.div_faults
    );
    assert!(
        stats.early_cases >= stats.exchange_cases / 4,
        "too few runs with work before the hand-over: {} of {}",
        stats.early_cases,
        stats.exchange_cases
    );
    assert!(loaded >= 370, "only {loaded} random programs loaded");
    assert!(
        stats.exchange_cases >= stats.cases / 3,
        "too few runs on private states: {} of {}",
        stats.exchange_cases,
        stats.cases
    );
    assert!(
        stats.loop_cap_faults > 0 && stats.div_faults > 0,
        "faults are exercised"
    );
}

/// Measuring that re-measures every few scans: the run switches between the sequential walk
/// and the levelled plans all the time, whichever is faster.
fn restless() -> Measure {
    Measure {
        warm_scans: 0,
        probe_scans: 1,
        min_rounds: 1,
        max_rounds: 2,
        min_interval: 1,
        max_interval: 3,
        budget_permille: 0,
        chunk: 2,
        sample_every: 1,
    }
}

#[test]
fn every_plan_kind_with_up_to_eight_workers_equals_the_sequential_scan() {
    let pool = pool(7);
    let exec = RANDOM_EXEC;
    let mut stats = Stats::default();
    for (seed, p) in random_programs(50_000, 400) {
        for threads in [2, 8] {
            for kind in [
                PlanKind::Seq,
                PlanKind::Model,
                PlanKind::Par,
                PlanKind::Deps,
                PlanKind::Exchange,
                PlanKind::Auto,
            ] {
                let mut config = configs(threads, seed);
                config.kind = kind;
                if kind == PlanKind::Auto {
                    config.measure = restless();
                }
                let label = format!(
                    "seed {seed}, {threads} threads, --plan {}, {:?}/{:?}",
                    kind.name(),
                    config.strategy,
                    config.slicing
                );
                check(&p, &label, &config, &exec, SCANS, seed, &pool, &mut stats);
            }
        }
    }
    eprintln!(
        "{} cases, {} mixing the sequential walk and a levelled plan, {} switches, {} on private states ({} with an own layout)",
        stats.cases, stats.mixed_runs, stats.switches, stats.exchange_cases, stats.own_layout_cases
    );
    assert!(
        stats.mixed_runs >= 100,
        "switching is exercised: {}",
        stats.mixed_runs
    );
    // `--plan auto` with several levelled candidates runs `par-exchange` on its own layout,
    // the state moved between the layouts at every switch.
    assert!(
        stats.own_layout_cases >= 100,
        "own layouts are exercised: {}",
        stats.own_layout_cases
    );
}

#[test]
fn parallel_scan_equals_sequential_scan_on_generated_programs() {
    // Larger programs of the generator with every knob on (timers, counters, FOR loops, forward
    // jumps, END, calls), under the default cost model and forced parallelism.
    let pool = pool(3);
    let exec = ExecConfig::default();
    let mut stats = Stats::default();
    for (rungs, width, seed) in [(600, 40, 1), (2000, 100, 2), (300, 300, 3), (1500, 8, 4)] {
        let json = plc_deps::synth::generate_string(&plc_deps::synth::GenConfig::all_features(
            rungs, width, seed,
        ));
        let p = plc_deps::load::program_from_json(&json).unwrap();
        for threads in [2, 4] {
            for config in [
                PlanConfig::new(threads),
                configs(threads, 0),
                configs(threads, 1),
                configs(threads, 2),
                configs(threads, 4),
                PlanConfig {
                    kind: PlanKind::Exchange,
                    ..configs(threads, 3)
                },
            ] {
                let label = format!(
                    "gen {rungs}/{width}/{seed}, {threads} threads, --plan {}, {:?}/{:?}",
                    config.kind.name(),
                    config.strategy,
                    config.slicing
                );
                check(&p, &label, &config, &exec, 60, seed, &pool, &mut stats);
            }
        }
    }
    // The default cost model finds these levels too small for 2 cores; the others are parallel.
    assert!(
        stats.parallel_cases >= stats.cases * 3 / 4,
        "{} of {} parallel",
        stats.parallel_cases,
        stats.cases
    );
    // Every program with every thread count also ran on private states.
    assert_eq!(stats.exchange_cases, 8, "runs on private states");
}

#[test]
fn worked_examples_with_their_inputs_under_forced_parallel_plans() {
    let pool = pool(3);
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("analyses");
    let mut stats = Stats::default();
    for dir in [
        "example-a",
        "example-b",
        "conveyor",
        "mixing-station",
        "packaging-line",
    ] {
        let p = plc_deps::load::program_from_json(
            &std::fs::read_to_string(root.join(dir).join("program.json")).unwrap(),
        )
        .unwrap();
        let table =
            plc_deps::cmd::run::load_inputs(&p, &root.join(dir).join("inputs.csv")).unwrap();
        // The committed inputs, then the rows again: 2 × 20–50 scans.
        let inputs: Vec<Vec<(VarId, Value)>> = table
            .rows
            .iter()
            .chain(table.rows.iter())
            .cloned()
            .collect();
        for exec in [
            ExecConfig {
                cycle_ms: 1000,
                loop_cap: 100_000,
                scan_budget: plc_deps::exec::DEFAULT_SCAN_BUDGET,
            },
            ExecConfig {
                cycle_ms: 10,
                loop_cap: 2,
                scan_budget: plc_deps::exec::DEFAULT_SCAN_BUDGET,
            },
        ] {
            for threads in [2, 4] {
                for k in 0..5 {
                    let config = configs(threads, k);
                    let label = format!(
                        "{dir}, {threads} threads, {:?}/{:?}, cap {}",
                        config.strategy, config.slicing, exec.loop_cap
                    );
                    check_with(&p, &label, &config, &exec, &inputs, &pool, &mut stats);
                }
            }
        }
    }
    assert!(
        stats.parallel_cases >= stats.cases / 2,
        "{} of {} parallel",
        stats.parallel_cases,
        stats.cases
    );
}

#[test]
fn wide_program_gets_a_parallel_plan_and_a_chain_falls_back() {
    let wide = plc_deps::synth::generate_string(&plc_deps::synth::GenConfig {
        rungs: 4000,
        width: 200,
        ..Default::default()
    });
    let p = plc_deps::load::program_from_json(&wide).unwrap();
    let a = analyse(&p);
    let par = ParallelMachine::new(&p, &a, &ExecConfig::default(), &PlanConfig::new(2)).unwrap();
    let plan = par.plan();
    assert!(plan.sequential().is_none(), "{}", par.explain(&p));
    assert_eq!(
        plan.parallel_phases(),
        a.schedule.levels.len(),
        "every level of a wide program pays"
    );
    assert!(par.explain(&p).contains("contiguous"));
    // A chain: each rung reads the previous rung's coil; no level has two tasks.
    let chain = chain_program(50);
    let p = plc_deps::load::program_from_json(&chain).unwrap();
    let a = analyse(&p);
    let par = ParallelMachine::new(&p, &a, &ExecConfig::default(), &PlanConfig::new(2)).unwrap();
    assert!(par.plan().sequential().is_some(), "{}", par.explain(&p));
    assert_eq!(par.machine().layout(), &plc_deps::exec::Layout::dense(&p));
}

/// `n` rungs, rung i reads the coil of rung i − 1 (and an input).
fn chain_program(n: usize) -> String {
    let mut vars = vec![serde_json::json!({"name": "go", "type": "BOOL", "class": "input"})];
    let mut rungs = Vec::new();
    for i in 0..n {
        vars.push(serde_json::json!({"name": format!("c{i}"), "type": "BOOL", "class": if i + 1 == n { "output" } else { "memory" }}));
        let prev = if i == 0 {
            "go".to_string()
        } else {
            format!("c{}", i - 1)
        };
        rungs.push(serde_json::json!({"id": format!("R{i}"), "ld": [{"contact": prev}, {"contact": "go"}, {"coil": format!("c{i}")}]}));
    }
    serde_json::json!({"program": "chain", "vars": vars, "rungs": rungs}).to_string()
}

#[test]
fn unconditional_backward_jump_refusal_is_a_cfg_edge_and_runs_in_parallel() {
    // R2 jumps back unconditionally: only a refusal of the iteration cap goes on to R3, along
    // the CFG's `refused` edge, so the schedule puts R3 after the loop and the plan can run
    // R0 beside the loop.
    let json = r#"{
      "program": "endless",
      "vars": [{"name": "n", "type": "DINT"}, {"name": "a", "type": "BOOL", "class": "input"},
               {"name": "x", "type": "BOOL"}, {"name": "after", "type": "BOOL"}],
      "rungs": [
        {"id": "R0", "ld": [{"contact": "a"}, {"coil": "x"}]},
        {"id": "R1", "label": "L", "ld": [{"op": "ADD", "in": ["n", 1], "out": "n"}]},
        {"id": "R2", "ld": [{"jmp": "L"}]},
        {"id": "R3", "ld": [{"contact": "x"}, {"coil": "after"}]}
      ]
    }"#;
    let p = plc_deps::load::program_from_json(json).unwrap();
    let a = analyse(&p);
    let refused: Vec<(u32, u32)> = a
        .cfg
        .edges
        .iter()
        .filter(|e| e.kind == plc_deps::analysis::EdgeKind::Refused)
        .map(|e| (e.from.raw(), e.to.raw()))
        .collect();
    assert_eq!(refused, [(2, 3)]);
    let exec = ExecConfig {
        cycle_ms: 10,
        loop_cap: 7,
        scan_budget: plc_deps::exec::DEFAULT_SCAN_BUDGET,
    };
    let mut config = PlanConfig::new(2);
    config.strategy = Strategy::AllParallel;
    let par = ParallelMachine::new(&p, &a, &exec, &config).unwrap();
    assert_eq!(par.plan().sequential(), None);
    let mut stats = Stats::default();
    check(&p, "endless", &config, &exec, 5, 7, &pool(3), &mut stats);
    assert_eq!(stats.loop_cap_faults, 5);
}

#[test]
fn a_refused_loop_back_followed_by_an_unconditional_jump_runs_in_parallel() {
    // R2's jump back to L sits in a branch; after it the rung jumps to F unconditionally. When
    // the iteration cap refuses the loop-back, the rest of the rung runs and takes that jump:
    // control never falls through to R3, so the CFG has no edge R2 -> R3 and the plan needs
    // none (a check that assumed one would fall back to the sequential walk).
    let json = r#"{
      "program": "loop-then-jump",
      "vars": [{"name": "n", "type": "DINT"}, {"name": "m", "type": "DINT"},
               {"name": "a", "type": "BOOL", "class": "input"}, {"name": "x", "type": "BOOL"},
               {"name": "skipped", "type": "BOOL"}, {"name": "after", "type": "BOOL"}],
      "rungs": [
        {"id": "R0", "ld": [{"contact": "a"}, {"coil": "x"}]},
        {"id": "R1", "label": "L", "ld": [{"op": "ADD", "in": ["n", 1], "out": "n"}]},
        {"id": "R2", "ld": [{"branch": [[{"jmp": "L"}], [{"op": "ADD", "in": ["m", 1], "out": "m"}]]},
                            {"jmp": "F"}]},
        {"id": "R3", "ld": [{"contact": "x"}, {"coil": "skipped"}]},
        {"id": "R4", "label": "F", "ld": [{"contact": "x"}, {"coil": "after"}]}
      ]
    }"#;
    let p = plc_deps::load::program_from_json(json).unwrap();
    let a = analyse(&p);
    let mut from_r2: Vec<u32> = a
        .cfg
        .edges
        .iter()
        .filter(|e| e.from.raw() == 2)
        .map(|e| e.to.raw())
        .collect();
    from_r2.sort_unstable();
    assert_eq!(from_r2, [1, 4]);
    let exec = ExecConfig {
        cycle_ms: 10,
        loop_cap: 5,
        scan_budget: plc_deps::exec::DEFAULT_SCAN_BUDGET,
    };
    let mut stats = Stats::default();
    for kind in [PlanKind::Par, PlanKind::Deps, PlanKind::Exchange] {
        let mut config = PlanConfig::new(2);
        config.strategy = Strategy::AllParallel;
        config.kind = kind;
        let par = ParallelMachine::new(&p, &a, &exec, &config).unwrap();
        assert_eq!(par.plan().sequential(), None, "{kind:?}");
        check(
            &p,
            "loop-then-jump",
            &config,
            &exec,
            4,
            11,
            &pool(3),
            &mut stats,
        );
    }
    assert_eq!(stats.loop_cap_faults, 3 * 4);
}

#[test]
fn one_scan_at_a_time_equals_a_run() {
    let json =
        plc_deps::synth::generate_string(&plc_deps::synth::GenConfig::all_features(800, 50, 9));
    let p = plc_deps::load::program_from_json(&json).unwrap();
    let a = analyse(&p);
    let pool = pool(3);
    // The cost model's plan, and the levelled plan on private states (each one-scan run copies
    // the state into the other workers' private states first).
    for kind in [PlanKind::Model, PlanKind::Exchange] {
        let config = match kind {
            PlanKind::Exchange => PlanConfig {
                kind,
                ..configs(2, 3) // every level parallel: the model finds them too small
            },
            _ => PlanConfig::new(2),
        };
        let par = ParallelMachine::new(&p, &a, &ExecConfig::default(), &config).unwrap();
        if kind == PlanKind::Exchange {
            assert_eq!(par.candidate_name(0), "par-exchange");
        }
        let inputs = input_table(&p, 9, 40);
        let mut rec = Recorder {
            inputs: &inputs,
            states: Vec::new(),
            faults: Vec::new(),
        };
        let mut whole = par.initial_state();
        par.run(Some(&pool), &mut whole, 0..40, &mut rec);
        let mut single = par.initial_state();
        for scan in 0..40u64 {
            let mut faults = Vec::new();
            par.scan(
                Some(&pool),
                &mut single,
                scan,
                &inputs[scan as usize],
                &mut faults,
            );
            assert_eq!(single.bytes(), rec.states[scan as usize], "{kind:?}");
            assert_eq!(faults, rec.faults[scan as usize], "{kind:?}");
        }
    }
}

/// Four independent chains of `n` rungs per level over three levels, the second level listing
/// the chains in the order 2, 3, 0, 1: contiguous slicing puts every chain of level 2 on the
/// other worker, the locality partition keeps each on its producer.
fn swapped_chains(n: usize) -> String {
    let mut vars = Vec::new();
    let mut rungs = Vec::new();
    for k in 0..4 {
        for j in 0..n {
            vars.push(
                serde_json::json!({"name": format!("in{k}_{j}"), "type": "BOOL", "class": "input"}),
            );
            for l in 1..4 {
                vars.push(serde_json::json!({"name": format!("x{k}_{l}_{j}"), "type": "BOOL"}));
            }
        }
    }
    for (l, order) in [(1, [0, 1, 2, 3]), (2, [2, 3, 0, 1]), (3, [0, 1, 2, 3])] {
        for k in order {
            for j in 0..n {
                let from = if l == 1 {
                    format!("in{k}_{j}")
                } else {
                    format!("x{k}_{}_{j}", l - 1)
                };
                rungs.push(serde_json::json!({"id": format!("R{k}_{l}_{j}"),
                    "ld": [{"contact": from}, {"contact": format!("x{k}_{l}_{j}"), "negated": true},
                           {"coil": format!("x{k}_{l}_{j}")}]}));
            }
        }
    }
    serde_json::json!({"program": "chains", "vars": vars, "rungs": rungs}).to_string()
}

/// The model's slicing keeps each chain on its producer (locality), and the measured plan
/// times the contiguous levelled plan (no longer the locality one: `par-locality` was never
/// kept, see `planning/candidates.rs`) and stays exact.
#[test]
fn the_measured_plan_times_the_locality_partition_and_stays_exact() {
    let p = plc_deps::load::program_from_json(&swapped_chains(100)).unwrap();
    let a = analyse(&p);
    let model = |slicing| {
        let config = PlanConfig {
            kind: PlanKind::Model,
            slicing,
            ..PlanConfig::new(2)
        };
        let par = ParallelMachine::new(&p, &a, &ExecConfig::default(), &config).unwrap();
        par.plans()[0].estimates().1
    };
    let (contiguous, locality) = (model(Slicing::Contiguous), model(Slicing::Locality));
    assert!(locality < contiguous, "{contiguous} vs {locality}");
    assert_eq!(model(Slicing::Auto), locality);
    let config = PlanConfig {
        kind: PlanKind::Auto,
        measure: restless(),
        ..PlanConfig::new(2)
    };
    let par = ParallelMachine::new(&p, &a, &ExecConfig::default(), &config).unwrap();
    let names: Vec<&str> = (0..par.candidates().len())
        .map(|i| par.candidate_name(i))
        .collect();
    assert_eq!(
        names,
        ["seq", "par", "par-exchange", "par-deps"],
        "{}",
        par.explain(&p)
    );
    let pool = pool(3);
    let mut stats = Stats::default();
    check(
        &p,
        "swapped chains, --plan auto",
        &config,
        &ExecConfig::default(),
        200,
        7,
        &pool,
        &mut stats,
    );
    // The first round of measurement runs every candidate on scans of the run, whatever the
    // timings: the run mixed the walk and the levelled plans.
    assert_eq!(stats.mixed_runs, 1);
}
