//! The plan check of a dependence-driven plan, at plan time and in release builds: from the
//! *lowered instructions'* byte reads and writes (`Machine::rung_accesses`), every two items of
//! different workers that touch a common byte, one of them writing, are ordered by a chain of
//! waits and program order (happened-before, Lamport); two workers never write one 64-byte line
//! unordered; every decision a guard or entry reads was written by an item ordered before the
//! reader; and the waits cannot deadlock.
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
use crate::exec::{Machine, Span, LINE_BYTES};

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
pub(super) fn check_ordered(machine: &Machine, plan: &Plan) -> Result<(), String> {
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
/// writer.
struct Seen {
    workers: usize,
    writer: Vec<Option<At>>,
    readers: Vec<Option<usize>>,
    line_writer: Vec<Option<At>>,
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
    };
    let (mut reads, mut writes) = (Vec::new(), Vec::new());
    for &at in order {
        let it = &items[at.0][at.1];
        for t in it.tasks() {
            for &r in &plan.task_rungs[t.index()] {
                reads.clear();
                writes.clear();
                machine.rung_accesses(r, &mut reads, &mut writes);
                for b in reads.iter().flat_map(|&s| bytes(s)) {
                    seen.read(b, at, clocks, r.0)?;
                }
                for b in writes.iter().flat_map(|&s| bytes(s)) {
                    seen.write(b, at, clocks, r.0)?;
                }
            }
        }
    }
    Ok(())
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
        let line = &mut self.line_writer[b / LINE_BYTES as usize];
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
