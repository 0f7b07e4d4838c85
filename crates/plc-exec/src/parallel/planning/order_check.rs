//! The plan check of a dependence-driven plan, at plan time and in release builds: from the
//! *lowered instructions'* byte reads and writes (`Machine::rung_accesses`), every two items of
//! different workers that touch a common byte, one of them writing, are ordered by a chain of
//! waits and program order (happened-before, Lamport); two workers never write one 64-byte line
//! unordered, unless every written byte of the line is written on several workers (those bytes'
//! writes are ordered by the byte rule, and such a line crosses between the cores whatever it
//! holds: the layout puts the variables written on several workers together); every decision
//! a guard or entry reads was written by an item ordered before the reader; and the waits
//! cannot deadlock.
//!
//! How: the items are walked in one order that respects every worker's order and every wait
//! (`ready::item_order`; none exists when the waits form a cycle). Each item gets a vector
//! clock (per worker, how many of its items are known finished when the item starts). Per
//! byte the walk keeps the last writer and, per worker, the latest reader since that write; a
//! write must come after both, a read after the last writer. By induction over the walk, all
//! the accesses of a byte are then totally ordered between writes, so checking these pairs
//! checks every pair. A plan that fails is not run (`ParallelMachine::new` drops it with a
//! warning). It does not fix plans.

use super::plan::{Phase, Plan};
use super::ready::{item_order, Wait};
use super::tasks::Item;
use crate::{Machine, Span, LINE_BYTES};

/// An item: (worker, index in the worker's items).
type At = (usize, usize);

/// Vector clocks of the items and the order they were walked in.
struct Clocks {
    /// Per worker and item: per worker, its items finished before this item starts.
    vc: Vec<Vec<Vec<u32>>>,
}

impl Clocks {
    /// Whether `x` happens before `y` (program order or a chain of waits).
    fn before(&self, x: At, y: At) -> bool {
        if x.0 == y.0 {
            x.1 < y.1
        } else {
            self.vc[y.0][y.1][x.0] as usize > x.1
        }
    }
}

/// The items of each worker (the plan's single phase).
fn worker_items(plan: &Plan) -> Result<Vec<&[Item]>, String> {
    match plan.phases.as_slice() {
        [ph @ Phase { .. }] if ph.is_parallel() => {
            Ok((0..plan.threads).map(|w| ph.items_of(w)).collect())
        }
        _ => Err("a dependence-driven plan has one parallel phase".into()),
    }
}

/// Checks the dependence-driven `plan` against `machine`'s lowered code; the error names the
/// workers, items and the byte, line or decision.
pub(in crate::parallel) fn check_ordered(machine: &Machine, plan: &Plan) -> Result<(), String> {
    let items = worker_items(plan)?;
    let waits_of = |w: usize, i: usize| -> Vec<Wait> {
        let r = &items[w][i].waits;
        plan.waits
            .get(r.start as usize..r.end as usize)
            .map_or_else(Vec::new, <[Wait]>::to_vec)
    };
    let counts: Vec<usize> = items.iter().map(|s| s.len()).collect();
    let order = item_order(&counts, waits_of)?;
    let p = items.len();
    let mut vc: Vec<Vec<Vec<u32>>> = counts.iter().map(|&n| vec![Vec::new(); n]).collect();
    for &(w, i) in &order {
        let mut c = if i > 0 {
            vc[w][i - 1].clone()
        } else {
            vec![0; p]
        };
        c[w] = i as u32;
        for x in waits_of(w, i) {
            let (o, j) = (x.worker as usize, x.done as usize - 1);
            for (a, b) in c.iter_mut().zip(&vc[o][j]) {
                *a = (*a).max(*b);
            }
            c[o] = c[o].max(x.done);
        }
        vc[w][i] = c;
    }
    let clocks = Clocks { vc };
    check_decisions(plan, &items, &clocks)?;
    check_bytes(machine, plan, &items, &order, &clocks)
}

/// Every decision slot a guard or entry reads is written by an item that happens before.
fn check_decisions(plan: &Plan, items: &[&[Item]], clocks: &Clocks) -> Result<(), String> {
    let mut writer: Vec<Option<At>> = vec![None; plan.decision_slots];
    for (w, slice) in items.iter().enumerate() {
        for (i, it) in slice.iter().enumerate() {
            if let Some(s) = it.decision {
                writer[s.index()] = Some((w, i));
            }
        }
    }
    for (w, slice) in items.iter().enumerate() {
        for (i, it) in slice.iter().enumerate() {
            let guards = plan.guards[it.guard.start as usize..it.guard.end as usize]
                .iter()
                .map(|g| g.0);
            let entries = plan.entry_slots[it.entries.start as usize..it.entries.end as usize]
                .iter()
                .copied();
            for s in guards.chain(entries) {
                match writer[s.index()] {
                    Some(x) if clocks.before(x, (w, i)) => {}
                    Some((o, j)) => {
                        return Err(format!(
                            "worker {w} item {i} reads the decision of worker {o} item {j} with no wait ordering them"
                        ))
                    }
                    None => {
                        return Err(format!(
                            "worker {w} item {i} reads decision slot {} that no item writes",
                            s.index()
                        ))
                    }
                }
            }
        }
    }
    Ok(())
}

/// Per byte: the last writer and the latest reader of each worker since; per line: the last
/// writer, and whether the line rule applies to it.
struct Seen {
    workers: usize,
    writer: Vec<Option<At>>,
    readers: Vec<Option<usize>>,
    line_writer: Vec<Option<At>>,
    /// Lines whose every written byte is written on several workers: exempt from the line rule.
    several_lines: Vec<bool>,
}

/// Calls `f` with every rung's lowered accesses, item by item in `order`.
fn each_rung(
    machine: &Machine,
    plan: &Plan,
    items: &[&[Item]],
    order: &[At],
    mut f: impl FnMut(At, u32, &[Span], &[Span]) -> Result<(), String>,
) -> Result<(), String> {
    let (mut reads, mut writes) = (Vec::new(), Vec::new());
    for &at in order {
        let it = &items[at.0][at.1];
        for t in it.tasks() {
            for &r in &plan.task_rungs[t.index()] {
                reads.clear();
                writes.clear();
                machine.rung_accesses(r, &mut reads, &mut writes);
                f(at, r.raw(), &reads, &writes)?;
            }
        }
    }
    Ok(())
}

/// Per line of a state of `n` bytes: whether it holds a written byte and every written byte of
/// it is written on two workers or more.
fn several_lines(
    machine: &Machine,
    plan: &Plan,
    items: &[&[Item]],
    order: &[At],
    n: usize,
) -> Result<Vec<bool>, String> {
    #[derive(Copy, Clone, PartialEq)]
    enum Writers {
        None,
        One(usize),
        Several,
    }
    let mut writers = vec![Writers::None; n];
    each_rung(machine, plan, items, order, |at, _, _, writes| {
        for b in writes.iter().flat_map(|&s| bytes(s)).filter(|&b| b < n) {
            writers[b] = match writers[b] {
                Writers::None => Writers::One(at.0),
                Writers::One(w) if w == at.0 => Writers::One(w),
                _ => Writers::Several,
            };
        }
        Ok(())
    })?;
    Ok(writers
        .chunks(LINE_BYTES as usize)
        .map(|line| {
            line.contains(&Writers::Several)
                && line
                    .iter()
                    .all(|&w| matches!(w, Writers::None | Writers::Several))
        })
        .collect())
}

/// The byte and line discipline, over the items in walk order.
fn check_bytes(
    machine: &Machine,
    plan: &Plan,
    items: &[&[Item]],
    order: &[At],
    clocks: &Clocks,
) -> Result<(), String> {
    let n = machine.state_size() as usize;
    let p = items.len();
    let mut seen = Seen {
        workers: p,
        writer: vec![None; n],
        readers: vec![None; n * p],
        line_writer: vec![None; n.div_ceil(LINE_BYTES as usize)],
        several_lines: several_lines(machine, plan, items, order, n)?,
    };
    each_rung(machine, plan, items, order, |at, rung, reads, writes| {
        for b in reads.iter().flat_map(|&s| bytes(s)) {
            seen.read(b, at, clocks, rung)?;
        }
        for b in writes.iter().flat_map(|&s| bytes(s)) {
            seen.write(b, at, clocks, rung)?;
        }
        Ok(())
    })
}

/// The bytes of a span.
fn bytes((at, w): Span) -> std::ops::Range<usize> {
    at.index()..at.index() + w as usize
}

fn unordered(kind: &str, b: usize, (o, j): At, (w, i): At, rung: u32) -> String {
    format!(
        "byte {b} {kind} by worker {o} item {j} and worker {w} item {i} (rung {rung}) with no wait ordering them"
    )
}

impl Seen {
    fn read(&mut self, b: usize, at: At, clocks: &Clocks, rung: u32) -> Result<(), String> {
        let Some(&last) = self.writer.get(b) else {
            return Err(format!("rung {rung} reads byte {b}, past the state"));
        };
        if let Some(x) = last {
            if x.0 != at.0 && !clocks.before(x, at) {
                return Err(unordered("written and read", b, x, at, rung));
            }
        }
        let r = &mut self.readers[b * self.workers + at.0];
        *r = Some(r.map_or(at.1, |j| j.max(at.1)));
        Ok(())
    }

    fn write(&mut self, b: usize, at: At, clocks: &Clocks, rung: u32) -> Result<(), String> {
        let Some(&last) = self.writer.get(b) else {
            return Err(format!("rung {rung} writes byte {b}, past the state"));
        };
        if let Some(x) = last {
            if x.0 != at.0 && !clocks.before(x, at) {
                return Err(unordered("written", b, x, at, rung));
            }
        }
        for o in 0..self.workers {
            let r = &mut self.readers[b * self.workers + o];
            if let Some(j) = r.take() {
                if o != at.0 && !clocks.before((o, j), at) {
                    return Err(unordered("read and written", b, (o, j), at, rung));
                }
            }
        }
        self.writer[b] = Some(at);
        let l = b / LINE_BYTES as usize;
        if self.several_lines[l] {
            return Ok(());
        }
        let line = &mut self.line_writer[l];
        if let Some(x) = *line {
            if x.0 != at.0 && !clocks.before(x, at) {
                return Err(format!(
                    "workers {} and {} both write the line of byte {b} with no wait ordering them (worker {} item {}, worker {} item {})",
                    x.0, at.0, x.0, x.1, at.0, at.1
                ));
            }
        }
        *line = Some(at);
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::parallel::config::{DepsPartition, PlanConfig, PlanKind, Slicing, Strategy};
    use crate::parallel::planning::{deps_plan, plan::layout_groups};
    use crate::{ExecConfig, Layout};
    use plc_model::Program;
    use proptest::prelude::*;

    /// R1 (a → x) and R2 (b → y) in level 0, R3 (x, y → z) in level 1: on two workers with
    /// contiguous slices R1 and R3 run on worker 0, R2 on worker 1, and R3 waits for R2.
    fn program() -> Program {
        plc_load::program_from_json(
            r#"{"program": "p", "vars": [
                {"name": "a", "type": "BOOL", "class": "input"},
                {"name": "b", "type": "BOOL", "class": "input"},
                {"name": "x", "type": "BOOL", "class": "output"},
                {"name": "y", "type": "BOOL", "class": "output"},
                {"name": "z", "type": "BOOL", "class": "output"}],
              "rungs": [{"id": "R1", "ld": [{"contact": "a"}, {"coil": "x"}]},
                        {"id": "R2", "ld": [{"contact": "b"}, {"coil": "y"}]},
                        {"id": "R3", "ld": [{"contact": "x"}, {"contact": "y"}, {"coil": "z"}]}]}"#,
        )
        .unwrap()
    }

    fn config(threads: usize, slicing: Slicing) -> PlanConfig {
        PlanConfig {
            strategy: Strategy::AllParallel,
            slicing,
            kind: PlanKind::Deps,
            deps_partition: DepsPartition::Levels,
            ..PlanConfig::new(threads)
        }
    }

    /// The machine on the plan's padded layout.
    fn machine(p: &Program, plan: &Plan) -> Machine {
        let groups = layout_groups(&[plan], p.vars());
        let layout = Layout::from_groups(p, &groups, LINE_BYTES).unwrap();
        Machine::new(p, layout, &ExecConfig::default()).unwrap()
    }

    #[test]
    fn the_plan_waits_for_the_producer_and_the_check_refuses_it_without_the_wait() {
        let p = program();
        let a = plc_analysis::analyse(&p);
        let mut plan = deps_plan::build(&p, &a, &config(2, Slicing::Contiguous));
        assert_eq!(plan.sequential(), None);
        let items = worker_items(&plan).unwrap();
        let tasks = |w: usize| -> Vec<u32> {
            items[w]
                .iter()
                .flat_map(|it| it.tasks().map(|t| t.raw()))
                .collect()
        };
        assert_eq!((tasks(0), tasks(1)), (vec![0, 2], vec![1]));
        assert_eq!(plan.waits, vec![Wait { worker: 1, done: 1 }]);
        assert_eq!(items[0][1].waits, 0..1);
        assert!(items[1][0].publish && !items[0][0].publish);
        let r = plan.ready().unwrap();
        assert_eq!(
            (r.waits_per_worker.clone(), r.cross_dependences),
            (vec![1, 0], 1)
        );
        let m = machine(&p, &plan);
        assert_eq!(check_ordered(&m, &plan), Ok(()));
        // The same plan without its wait: R3 reads y, which worker 1 writes, unordered (the walk
        // runs worker 0's items first: the read is seen before the write).
        let SlicesMut(slices) = parallel_mut(&mut plan);
        slices[0][1].waits = 0..0;
        let y = m.layout().start(plc_model::VarId::from_raw(3)).index();
        assert_eq!(
            check_ordered(&m, &plan),
            Err(format!(
                "byte {y} read and written by worker 0 item 1 and worker 1 item 0 (rung 1) with no wait ordering them"
            ))
        );
        // A wait on itself, or a cycle of waits, can never be satisfied.
        plan.waits = vec![Wait { worker: 0, done: 2 }];
        parallel_mut(&mut plan).0[1][0].waits = 0..1;
        parallel_mut(&mut plan).0[0][1].waits = 0..0;
        parallel_mut(&mut plan).0[0][0].waits = 0..0;
        plan.waits.push(Wait { worker: 1, done: 1 });
        parallel_mut(&mut plan).0[0][0].waits = 1..2;
        assert_eq!(
            check_ordered(&m, &plan),
            Err("worker 0 item 0 waits for items that can never finish (a cycle of waits)".into())
        );
    }

    /// x and y are each written on both workers (R1 and R4, R2 and R3), and worker 0's write
    /// of x (R1) and worker 1's of y (R2) are unordered: on one line they pass, as a line of
    /// variables written on several workers; with z (written by R1 only) on that line too,
    /// the line rule applies and refuses it.
    #[test]
    fn a_line_of_variables_written_on_several_workers_is_exempt_from_the_line_rule() {
        let program = |z: bool| {
            let coil_z = if z { r#", {"coil": "z"}"# } else { "" };
            plc_load::program_from_json(&format!(
                r#"{{"program": "p", "vars": [
                    {{"name": "a", "type": "BOOL", "class": "input"}},
                    {{"name": "b", "type": "BOOL", "class": "input"}},
                    {{"name": "x", "type": "BOOL", "class": "output"}},
                    {{"name": "y", "type": "BOOL", "class": "output"}},
                    {{"name": "z", "type": "BOOL", "class": "output"}}],
                  "rungs": [{{"id": "R1", "ld": [{{"contact": "a"}}, {{"coil": "x"}}{coil_z}]}},
                            {{"id": "R2", "ld": [{{"contact": "b"}}, {{"coil": "y"}}]}},
                            {{"id": "R3", "ld": [{{"contact": "a"}}, {{"coil": "y"}}]}},
                            {{"id": "R4", "ld": [{{"contact": "b"}}, {{"coil": "x"}}]}}]}}"#
            ))
            .unwrap()
        };
        for z in [false, true] {
            let p = program(z);
            let a = plc_analysis::analyse(&p);
            let plan = deps_plan::build(&p, &a, &config(2, Slicing::Contiguous));
            let items = worker_items(&plan).unwrap();
            let rungs = |w: usize| -> Vec<u32> {
                (items[w].iter().flat_map(|it| it.tasks()))
                    .flat_map(|t| plan.task_rungs[t.index()].iter().map(|r| r.raw()))
                    .collect()
            };
            assert_eq!((rungs(0), rungs(1)), (vec![0, 2], vec![1, 3]));
            // Every variable on one line.
            let m = Machine::new(&p, Layout::dense(&p), &ExecConfig::default()).unwrap();
            let x = m.layout().start(plc_model::VarId::from_raw(2)).index();
            let y = m.layout().start(plc_model::VarId::from_raw(3)).index();
            assert_eq!(x / LINE_BYTES as usize, y / LINE_BYTES as usize);
            let got = check_ordered(&m, &plan);
            if z {
                let e = got.unwrap_err();
                assert!(e.contains("both write the line of byte"), "{e}");
            } else {
                assert_eq!(got, Ok(()));
            }
        }
    }

    /// The items of the plan's parallel phase, mutable.
    struct SlicesMut<'a>(&'a mut Vec<Vec<Item>>);

    fn parallel_mut(plan: &mut Plan) -> SlicesMut<'_> {
        match &mut plan.phases[0].kind {
            super::super::plan::PhaseKind::Parallel(s) => SlicesMut(s),
            super::super::plan::PhaseKind::Sequential(_) => panic!("a parallel phase"),
        }
    }

    /// Happened-before by brute force: the transitive closure of program order and the waits.
    fn closure(items: &[&[Item]], waits: &[Wait]) -> Vec<Vec<Vec<bool>>> {
        let ids: Vec<At> = items
            .iter()
            .enumerate()
            .flat_map(|(w, s)| (0..s.len()).map(move |i| (w, i)))
            .collect();
        let index = |x: At| ids.iter().position(|&y| y == x).unwrap();
        let n = ids.len();
        let mut preds: Vec<Vec<usize>> = vec![Vec::new(); n];
        for (k, &(w, i)) in ids.iter().enumerate() {
            if i > 0 {
                preds[k].push(index((w, i - 1)));
            }
            let r = &items[w][i].waits;
            for x in &waits[r.start as usize..r.end as usize] {
                preds[k].push(index((x.worker as usize, x.done as usize - 1)));
            }
        }
        let mut hb = vec![vec![false; n]; n]; // hb[y][x]: x before y
        for y in 0..n {
            let mut stack = preds[y].clone();
            while let Some(x) = stack.pop() {
                if !hb[y][x] {
                    hb[y][x] = true;
                    stack.extend_from_slice(&preds[x]);
                }
            }
        }
        let mut out: Vec<Vec<Vec<bool>>> = Vec::new();
        for (k, &(w, i)) in ids.iter().enumerate() {
            if out.len() <= w {
                out.resize(w + 1, Vec::new());
            }
            if out[w].len() <= i {
                out[w].resize(i + 1, Vec::new());
            }
            out[w][i] = hb[k].clone();
        }
        out
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(48))]
        /// On generated programs with every feature, every pair of items of different workers
        /// that touch a common byte of the lowered code, one writing, is ordered by program
        /// order and waits (checked pair by pair, independently of the walk of the check).
        #[test]
        fn every_conflicting_cross_worker_pair_is_ordered(
            rungs in 20usize..160,
            width in 2usize..40,
            seed in 0u64..1000,
            threads in 2usize..5,
            slicing in prop_oneof![Just(Slicing::Contiguous), Just(Slicing::Lpt), Just(Slicing::Locality)],
            one_way in any::<bool>(),
        ) {
            let json = plc_synth::generate_string(
                &plc_synth::GenConfig::all_features(rungs, width, seed));
            let p = plc_load::program_from_json(&json).unwrap();
            let a = plc_analysis::analyse(&p);
            let partition = if one_way { DepsPartition::OneWay } else { DepsPartition::Levels };
            let plan = deps_plan::build(&p, &a, &PlanConfig {
                deps_partition: partition,
                ..config(threads, slicing)
            });
            prop_assume!(plan.sequential().is_none());
            prop_assert_eq!(plan.ready().map(|r| r.partition), Some(partition));
            let m = machine(&p, &plan);
            prop_assert_eq!(check_ordered(&m, &plan), Ok(()));
            let items = worker_items(&plan).unwrap();
            let ids: Vec<At> = items.iter().enumerate()
                .flat_map(|(w, s)| (0..s.len()).map(move |i| (w, i))).collect();
            let n = ids.len();
            let all = closure(&items, &plan.waits);
            let flat: Vec<&Vec<bool>> = ids.iter().map(|&(w, i)| &all[w][i]).collect();
            let mut acc: Vec<(Vec<usize>, Vec<usize>)> = Vec::new();
            for &(w, i) in &ids {
                let (mut r, mut wr) = (Vec::new(), Vec::new());
                let (mut rs, mut ws) = (Vec::new(), Vec::new());
                for t in items[w][i].tasks() {
                    for &rung in &plan.task_rungs[t.index()] {
                        m.rung_accesses(rung, &mut rs, &mut ws);
                    }
                }
                r.extend(rs.iter().flat_map(|&s| bytes(s)));
                wr.extend(ws.iter().flat_map(|&s| bytes(s)));
                acc.push((r, wr));
            }
            for x in 0..n {
                for y in 0..n {
                    if ids[x].0 == ids[y].0 || x == y {
                        continue;
                    }
                    let conflict = acc[x].1.iter().any(|b| acc[y].0.contains(b) || acc[y].1.contains(b));
                    if conflict {
                        prop_assert!(flat[y][x] || flat[x][y],
                            "items {:?} and {:?} conflict unordered", ids[x], ids[y]);
                    }
                }
            }
        }
    }
}
