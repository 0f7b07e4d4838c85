//! Which work of a worker's phase on a private state can run *before* the hand-over of the
//! phase before (`par-exchange`): the tasks that touch nothing another worker wrote in that
//! phase. A worker runs them, then waits for and unpacks the others' writes, then runs the
//! rest; so it waits only where it needs what another worker wrote, and workers that finish a
//! phase at different times go on instead of meeting at every level. In a program whose rungs
//! read what nearby rungs wrote (`plc-deps gen`'s default), a contiguous slice needs the
//! other worker's writes only at its two ends.
//!
//! The work is cut finer than the plan's items: an item that chains several tasks (one walk of
//! the interpreter) is cut into pieces at task boundaries where the next task is a single rung
//! (its entry is that rung, so a walk can start there), and each piece is early or late; an
//! early piece of fewer than `PlanConfig::early_min_tasks` tasks (16) is not cut from its item
//! (a walk costs about as much as a few tasks), so a program whose rungs read at random from
//! the level before keeps its items whole. About half-way through its early work a worker asks
//! the CPU for the lines it will take at the hand-over ([`Split::prefetch_after`]).
//!
//! Invariants (what makes the results the sequential walk's): an early piece reads and writes
//! no byte another worker wrote in the phase before (it neither reads a value still to arrive
//! nor writes a byte the unpacking will overwrite), has no guard or entries (it reads no
//! decision another worker may be writing), and does not conflict with any late piece before
//! it in the plan's order (writes nothing one reads or writes, reads nothing one writes), so
//! moving it ahead of them changes no value anyone reads. Within the early and within the late
//! pieces the plan's order is kept. Accesses are the lowered instructions' byte reads and
//! writes (`Machine::rung_accesses`), as for the exchange's keys. The first phase has no
//! phase before: all its work is late.
//!
//! Costs O(bytes accessed) per phase; it decides no slices (the plan has).

use super::plan::Plan;
use super::tasks::{Item, Region};
use crate::parallel::ids::TaskId;
use crate::{Machine, Span};

/// One worker's work of one phase, in the order it runs it.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub(in crate::parallel) struct Split {
    /// The pieces, the early ones first, each part in the plan's order.
    pub items: Vec<Item>,
    /// How many of `items` run before the hand-over.
    pub early: u32,
    /// After how many of the early items the worker asks the CPU to fetch the others' lines
    /// of the phase before (about half of the early work: by then they are likely written, and
    /// the transfer overlaps the rest of it instead of stalling the hand-over).
    pub prefetch_after: Option<u32>,
}

const READ: u8 = 1;
const WRITTEN: u8 = 2;

/// What the late pieces so far of one (phase, worker) do to each state byte.
struct Late {
    /// Per state byte: [`READ`], [`WRITTEN`] or both.
    marks: Vec<u8>,
    /// The bytes `marks` marks.
    touched: Vec<u32>,
}

impl Late {
    /// Holds work back: later work must not overtake it where they conflict.
    fn hold(&mut self, reads: &[Span], writes: &[Span]) {
        for (spans, mark) in [(reads, READ), (writes, WRITTEN)] {
            for b in bytes_of(spans) {
                if self.marks[b] == 0 {
                    self.touched.push(b as u32);
                }
                self.marks[b] |= mark;
            }
        }
    }

    /// Forgets every mark.
    fn clear(&mut self) {
        for &b in &self.touched {
            self.marks[b as usize] = 0;
        }
        self.touched.clear();
    }
}

/// The marks the split of one plan keeps over the state's bytes.
pub(super) struct Splitter {
    /// Per state byte: 1 + the worker that wrote it in the phase before, 0 if none did.
    owner: Vec<u32>,
    late: Late,
    /// The accesses of the task at hand.
    reads: Vec<Span>,
    writes: Vec<Span>,
}

fn bytes_of(spans: &[Span]) -> impl Iterator<Item = usize> + '_ {
    spans
        .iter()
        .flat_map(|&(at, n)| at.0 as usize..(at.0 + n) as usize)
}

/// A piece being built: its tasks, whether early, and its accesses while early (kept so that
/// it can still be held back whole).
struct Piece {
    first: TaskId,
    last: TaskId,
    early: bool,
    reads: Vec<Span>,
    writes: Vec<Span>,
}

impl Piece {
    /// Fewer tasks than an early piece cut from its item must have (`early_min_tasks`).
    fn short(&self, min: u32) -> bool {
        self.last.raw() - self.first.raw() + 1 < min
    }
}

impl Splitter {
    /// Marks for a state of `size` bytes.
    pub(super) fn new(size: usize) -> Splitter {
        Splitter {
            owner: vec![0; size],
            late: Late {
                marks: vec![0; size],
                touched: Vec::new(),
            },
            reads: Vec::new(),
            writes: Vec::new(),
        }
    }

    /// Whether the task at hand, of worker `w`, may run ahead of the late pieces before it and
    /// of the hand-over.
    fn may_go_first(&self, w: usize) -> bool {
        let other = |b: usize| self.owner[b] != 0 && self.owner[b] != w as u32 + 1;
        let late = &self.late.marks;
        bytes_of(&self.reads).all(|b| !other(b) && late[b] & WRITTEN == 0)
            && bytes_of(&self.writes).all(|b| !other(b) && late[b] == 0)
    }

    /// Task `t`'s accesses into `self.reads` and `self.writes`.
    fn task_accesses(&mut self, machine: &Machine, plan: &Plan, t: TaskId) {
        self.reads.clear();
        self.writes.clear();
        for &r in &plan.task_rungs[t.index()] {
            machine.rung_accesses(r, &mut self.reads, &mut self.writes);
        }
    }

    /// Worker `w`'s split of `items`, its items of one phase (`first`: the plan's first);
    /// every task's byte writes go to `on_writes` on the way (the caller's key).
    pub(super) fn split(
        &mut self,
        machine: &Machine,
        plan: &Plan,
        (w, items): (usize, &[Item]),
        first: bool,
        mut on_writes: impl FnMut(&[Span]),
    ) -> Split {
        let min = plan.config.early_min_tasks.max(1);
        let (mut early, mut late) = (Vec::new(), Vec::new());
        for it in items {
            let whole = first || !it.guard.is_empty() || !it.entries.is_empty();
            let mut runs: Vec<Piece> = Vec::new();
            for t in it.tasks() {
                self.task_accesses(machine, plan, t);
                on_writes(&self.writes);
                let free = !whole && self.may_go_first(w);
                let cut = !whole && t != it.first && plan.task_rungs[t.index()].len() == 1;
                match runs.last_mut() {
                    Some(p) if p.early == free || !cut || (p.early && p.short(min)) => {
                        if p.early && !free {
                            // The task cannot start a piece, or the early piece is too short
                            // to be worth a walk of its own: hold the piece back whole.
                            self.late.hold(&p.reads, &p.writes);
                            (p.reads, p.writes) = (Vec::new(), Vec::new());
                            p.early = false;
                        }
                        p.last = t;
                    }
                    _ => runs.push(Piece {
                        first: t,
                        last: t,
                        early: free,
                        reads: Vec::new(),
                        writes: Vec::new(),
                    }),
                }
                let p = runs.last_mut().expect("a piece was just made or extended");
                if p.early {
                    p.reads.extend_from_slice(&self.reads);
                    p.writes.extend_from_slice(&self.writes);
                } else {
                    self.late.hold(&self.reads, &self.writes);
                }
            }
            // A short early piece cut from the end of an item is held back too.
            let cut_off = runs.len() > 1;
            if let Some(p) = runs
                .last_mut()
                .filter(|p| p.early && p.short(min) && cut_off)
            {
                self.late.hold(&p.reads, &p.writes);
                p.early = false;
            }
            // Late pieces next to each other are one walk.
            let mut pieces: Vec<Piece> = Vec::new();
            for r in runs {
                match pieces.last_mut() {
                    Some(q) if !q.early && !r.early => q.last = r.last,
                    _ => pieces.push(r),
                }
            }
            for p in pieces {
                push_piece(plan, it, p, &mut early, &mut late);
            }
        }
        self.late.clear();
        let prefetch_after = prefetch_point(plan, &mut early, min);
        Split {
            early: early.len() as u32,
            prefetch_after,
            items: early.into_iter().chain(late).collect(),
        }
    }

    /// The next phase: the bytes each worker wrote in the phase `before` are forgotten, those
    /// each wrote in the phase `now` recorded.
    pub(super) fn next_phase(&mut self, before: &[Vec<u32>], now: &[Vec<u32>]) {
        for &b in before.iter().flatten() {
            self.owner[b as usize] = 0;
        }
        for (w, bytes) in now.iter().enumerate() {
            for &b in bytes {
                self.owner[b as usize] = w as u32 + 1;
            }
        }
    }
}

/// Piece `p` of item `it` as an item of its own, onto `early` or `late`.
fn push_piece(plan: &Plan, it: &Item, p: Piece, early: &mut Vec<Item>, late: &mut Vec<Item>) {
    let item = sub_item(plan, it, p.first, p.last);
    if p.early { early } else { late }.push(item);
}

/// Tasks `first..=last` of item `it` as an item of their own: it starts where `it` does if
/// `first` is `it`'s first task, else at `first`'s one rung (the caller's condition); it
/// records `it`'s decision if it holds `it`'s last task.
fn sub_item(plan: &Plan, it: &Item, first: TaskId, last: TaskId) -> Item {
    if first == it.first && last == it.last {
        return it.clone();
    }
    let (mut lo, mut hi, mut count) = (u32::MAX, 0u32, 0u32);
    for t in first.raw()..=last.raw() {
        for r in &plan.task_rungs[t as usize] {
            lo = lo.min(r.raw());
            hi = hi.max(r.raw() + 1);
            count += 1;
        }
    }
    Item {
        first,
        last,
        start: if first == it.first {
            it.start
        } else {
            plan.task_rungs[first.index()][0]
        },
        region: if hi - lo == count {
            Region::Rungs(lo, hi)
        } else {
            Region::Tasks(first, last)
        },
        decision: if last == it.last { it.decision } else { None },
        // A piece's cost is not used: the exchange balances nothing.
        cost: 0,
        ..it.clone()
    }
}

/// Where in `early` (pieces, in order) the worker prefetches the others' lines: after the piece
/// that ends closest past half of the early tasks, cutting that piece in two at a single-rung
/// task when it is long; `None` when there is no early work before which it would be worth it.
fn prefetch_point(plan: &Plan, early: &mut Vec<Item>, min: u32) -> Option<u32> {
    let tasks = |it: &Item| it.last.raw() - it.first.raw() + 1;
    let total: u32 = early.iter().map(tasks).sum();
    if total < 2 * min {
        return None;
    }
    let mut before = 0;
    for i in 0..early.len() {
        let it = &early[i];
        let n = tasks(it);
        if before + n >= total / 2 {
            let want = it.first.raw() + (total / 2).saturating_sub(before);
            let at = (want..=it.last.raw())
                .map(TaskId::from_raw)
                .find(|&t| t != it.first && plan.task_rungs[t.index()].len() == 1);
            if let Some(at) = at.filter(|_| n >= min) {
                let (a, b) = (
                    sub_item(plan, it, it.first, TaskId::from_raw(at.raw() - 1)),
                    sub_item(plan, it, at, it.last),
                );
                early.splice(i..=i, [a, b]);
            }
            return Some(i as u32 + 1).filter(|&k| (k as usize) < early.len());
        }
        before += n;
    }
    None
}

#[cfg(test)]
mod tests {
    use super::super::exchange::exchange_plan;
    use super::*;
    use crate::parallel::config::{PlanConfig, Slicing, Strategy};
    use crate::{ExecConfig, Layout, LINE_BYTES};

    /// Two levels of 40 rungs: `A{j}` := input `I{j % 8}`, then `B{j}` := `A{j}` (and `A{19}`
    /// besides for `B20` when `cross`), cut in two contiguous slices of 20.
    fn plan_of(cross: bool, early_min_tasks: u32) -> (Plan, Vec<Split>) {
        let mut vars: Vec<String> = (0..8)
            .map(|i| format!(r#"{{"name": "I{i}", "type": "BOOL", "class": "input"}}"#))
            .collect();
        let mut rungs = Vec::new();
        for j in 0..40 {
            vars.push(format!(r#"{{"name": "A{j}", "type": "BOOL"}}"#));
            vars.push(format!(
                r#"{{"name": "B{j}", "type": "BOOL", "class": "output"}}"#
            ));
            rungs.push(format!(
                r#"{{"id": "A{j}", "ld": [{{"contact": "I{}"}}, {{"coil": "A{j}"}}]}}"#,
                j % 8
            ));
        }
        for j in 0..40 {
            let extra = if cross && j == 20 {
                r#"{"contact": "A19"}, "#
            } else {
                ""
            };
            rungs.push(format!(
                r#"{{"id": "B{j}", "ld": [{extra}{{"contact": "A{j}"}}, {{"coil": "B{j}"}}]}}"#
            ));
        }
        let json = format!(
            r#"{{"program": "p", "vars": [{}], "rungs": [{}]}}"#,
            vars.join(","),
            rungs.join(",")
        );
        let p = plc_load::program_from_json(&json).unwrap();
        let a = plc_analysis::analyse(&p);
        let config = PlanConfig {
            strategy: Strategy::AllParallel,
            slicing: Slicing::Contiguous,
            early_min_tasks,
            ..PlanConfig::new(2)
        };
        let plan = Plan::build(&p, &a, &config);
        assert_eq!(plan.phases.len(), 2);
        let groups = super::super::plan::bools_first(
            &p,
            super::super::plan::layout_groups(&[&plan], p.vars()),
        );
        let layout = Layout::from_groups(&p, &groups, LINE_BYTES).unwrap();
        let m = Machine::new(&p, layout, &ExecConfig::default()).unwrap();
        let x = exchange_plan(&p, &m, &plan).unwrap();
        (plan, x.splits)
    }

    /// The tasks of a split's early and late items.
    fn tasks(s: &Split) -> (Vec<u32>, Vec<u32>) {
        let of = |items: &[Item]| {
            items
                .iter()
                .flat_map(|it| it.tasks())
                .map(|t| t.raw())
                .collect()
        };
        let (early, late) = s.items.split_at(s.early as usize);
        (of(early), of(late))
    }

    #[test]
    fn a_slice_that_reads_only_its_own_writes_runs_before_the_hand_over() {
        let (plan, splits) = plan_of(false, 16);
        // The first phase has no phase before: all late.
        for (w, split) in splits.iter().enumerate().take(2) {
            let (early, late) = tasks(split);
            assert!(early.is_empty());
            assert_eq!(
                late,
                plan.phases[0]
                    .items_of(w)
                    .iter()
                    .flat_map(|it| it.tasks())
                    .map(|t| t.raw())
                    .collect::<Vec<_>>()
            );
        }
        // In the second, each worker's B rungs read only the A rungs it ran: all early, in
        // order; 20 tasks are too few to cut for a prefetch half-way (2 × 16) ...
        for w in 0..2 {
            let s = &splits[2 + w];
            let (early, late) = tasks(s);
            let all: Vec<u32> = plan.phases[1]
                .items_of(w)
                .iter()
                .flat_map(|it| it.tasks())
                .map(|t| t.raw())
                .collect();
            assert_eq!((early, late), (all, vec![]));
            assert_eq!((s.early, s.prefetch_after), (1, None));
        }
        // ... but with pieces of 4 tasks they are cut in the middle, the prefetch between.
        let (plan, splits) = plan_of(false, 4);
        for w in 0..2 {
            let s = &splits[2 + w];
            assert_eq!((s.early, s.prefetch_after), (2, Some(1)));
            let (a, b) = (&s.items[0], &s.items[1]);
            assert_eq!(
                (a.last.raw() - a.first.raw() + 1, b.first.raw()),
                (10, a.last.raw() + 1)
            );
            // The second piece starts at its first task's rung; the first records no decision.
            assert_eq!(b.start, plan.task_rungs[b.first.index()][0]);
            assert_eq!(a.decision, None);
        }
    }

    #[test]
    fn a_task_that_reads_the_other_workers_write_waits_and_short_pieces_stay_whole() {
        // B20 reads A19, which worker 0 wrote: worker 1 holds B20 back and runs B21..B39 first.
        let (plan, splits) = plan_of(true, 16);
        // Rungs A0..A39 then B0..B39: B20 is rung 60.
        let b20 = plan.task_of_rung[60].unwrap().raw();
        let w1 = (0..2)
            .find(|&w| {
                plan.phases[1]
                    .items_of(w)
                    .iter()
                    .any(|it| it.tasks().any(|t| t.raw() == b20))
            })
            .unwrap();
        let (early, late) = tasks(&splits[2 + w1]);
        assert_eq!(late, vec![b20]);
        assert_eq!(early.len(), 19);
        assert!(!early.contains(&b20));
        // The other worker reads nothing of worker 1's: all early.
        let (early0, late0) = tasks(&splits[2 + (1 - w1)]);
        assert_eq!((early0.len(), late0.len()), (20, 0));
        // With pieces of at least 20 tasks, the 19 cannot be cut off: the slice waits whole.
        let (_, splits) = plan_of(true, 20);
        let (early, late) = tasks(&splits[2 + w1]);
        assert_eq!((early.len(), late.len()), (0, 20));
        assert_eq!(splits[2 + w1].prefetch_after, None);
    }
}
