//! Data movement in the cost model: how many cache lines a worker reads that another worker
//! wrote earlier in the scan, under a *modelled* layout (each writer group on its own 64-byte
//! lines, variables in declaration order at their byte widths).
//!
//! Every level of a levelled plan reads what earlier levels wrote; when the writer ran on
//! another core, each such line has to come over from that core's cache (and goes back, as an
//! invalidation, when the writer writes it again next scan). The cost model of steps and
//! barriers does not see this; [`Movement`] walks the plan's phases in scan order, remembers
//! for every variable the worker that wrote it last and the line it lives on, and counts, per
//! worker of a phase, the *distinct* lines it reads whose last writer was another worker and
//! that it has not read since that write (a line once fetched stays in the reader's cache until
//! it is written again).
//!
//! The layout is modelled, not read: a writer group is the (phase, worker) of a variable's last
//! write (the real layout, `layout_groups`, keys by every writer of every candidate plan, so its
//! groups are these or finer); inside a group variables follow in declaration order at
//! [`var_bytes`] each — the widths of the compact storage (BOOL a byte, INT 2, DINT/REAL/TIME 4).
//! [`var_bytes`] and [`Movement::commit`] are the one place that knows this, so that they can
//! read the real layout instead. What it does not model: values carried from the previous scan
//! (a variable read before it is written in the scan counts as local, except inputs, which
//! worker 0 writes at the start of every scan), the writer's cost of taking a line back that
//! others read (an invalidation, next scan), lines evicted by capacity, and prefetching.

use crate::parallel::ids::TaskId;
use plc_analysis::Analysis;
use plc_model::{Program, Type, VarClass, VarId};
use std::collections::HashMap;

/// Bytes of a cache line (the state's, [`crate::LINE_BYTES`]).
pub(in crate::parallel) const LINE_BYTES: u64 = crate::LINE_BYTES as u64;

/// The bytes of a variable of type `ty`, as the compact state stores it
/// ([`crate::type_size`]: BOOL 1, INT 2, DINT/REAL/TIME 4, a timer or counter its fields).
pub(in crate::parallel) fn var_bytes(ty: Type) -> u64 {
    u64::from(crate::type_size(ty))
}

/// Where a variable's value was last written: by which worker, on which modelled line.
#[derive(Copy, Clone, Debug, PartialEq, Eq)]
struct Written {
    worker: u32,
    /// A line id, unique over the whole walk (group number and line within the group).
    line: u64,
}

/// The walk over a plan's phases, in scan order.
pub(in crate::parallel) struct Movement<'a> {
    p: &'a Program,
    a: &'a Analysis,
    threads: usize,
    last: Vec<Option<Written>>,
    /// Per line read by workers other than its writer: those workers (bit `min(w, 63)`).
    seen: HashMap<u64, u64>,
    groups: u64,
}

/// The bit of worker `w` in a set of readers.
fn bit(w: usize) -> u64 {
    1 << w.min(63)
}

impl<'a> Movement<'a> {
    /// The start of a scan: worker 0 has written the inputs (one group); nothing else counts.
    pub(in crate::parallel) fn new(
        p: &'a Program,
        a: &'a Analysis,
        threads: usize,
    ) -> Movement<'a> {
        let mut m = Movement {
            p,
            a,
            threads: threads.max(1),
            last: vec![None; p.vars().len()],
            seen: HashMap::new(),
            groups: 0,
        };
        let inputs: Vec<VarId> = p
            .vars()
            .ids()
            .filter(|v| p.var(*v).class == VarClass::Input)
            .collect();
        m.place(0, &inputs);
        m
    }

    /// The variables the tasks read, each once, ascending.
    fn reads(&self, tasks: &[TaskId]) -> Vec<VarId> {
        let sched = &self.a.schedule;
        let mut vars: Vec<VarId> = tasks
            .iter()
            .flat_map(|t| sched.tasks[t.index()].rungs.iter())
            .flat_map(|&r| self.a.accesses.ins(r).iter().copied())
            .collect();
        vars.sort_unstable();
        vars.dedup();
        vars
    }

    /// Per task and worker (`affinity[i * threads + w]`): the bytes task `tasks[i]` reads that
    /// worker `w` wrote last.
    pub(in crate::parallel) fn affinity(&self, tasks: &[TaskId]) -> Vec<u64> {
        let sched = &self.a.schedule;
        let mut out = vec![0u64; tasks.len() * self.threads];
        for (i, t) in tasks.iter().enumerate() {
            let mut vars: Vec<VarId> = sched.tasks[t.index()]
                .rungs
                .iter()
                .flat_map(|&r| self.a.accesses.ins(r).iter().copied())
                .collect();
            vars.sort_unstable();
            vars.dedup();
            for v in vars {
                if let Some(w) = self.last[v.index()] {
                    out[i * self.threads + w.worker as usize] += var_bytes(self.p.var(v).ty);
                }
            }
        }
        out
    }

    /// The distinct lines worker `w` reads, running `tasks`, that another worker wrote last and
    /// `w` has not read since.
    fn fetched(&self, tasks: &[TaskId], w: usize) -> Vec<u64> {
        let mut lines: Vec<u64> = self
            .reads(tasks)
            .into_iter()
            .filter_map(|v| self.last[v.index()])
            .filter(|x| x.worker as usize != w)
            .map(|x| x.line)
            .filter(|l| self.seen.get(l).is_none_or(|r| r & bit(w) == 0))
            .collect();
        lines.sort_unstable();
        lines.dedup();
        lines
    }

    /// How many lines worker `w` fetches running `tasks` ([`fetched`](Self::fetched)).
    pub(in crate::parallel) fn lines(&self, tasks: &[TaskId], w: usize) -> u64 {
        self.fetched(tasks, w).len() as u64
    }

    /// Per worker of a phase (`slices[w]`), the lines it moves ([`lines`](Self::lines)).
    pub(in crate::parallel) fn phase_lines(&self, slices: &[Vec<TaskId>]) -> Vec<u64> {
        slices
            .iter()
            .enumerate()
            .map(|(w, s)| self.lines(s, w))
            .collect()
    }

    /// The phase `slices` ran (`slices[w]` on worker `w`): the lines they fetched are now in
    /// their caches, and their writes become the last ones.
    pub(in crate::parallel) fn commit(&mut self, slices: &[Vec<TaskId>]) {
        let sched = &self.a.schedule;
        for (w, s) in slices.iter().enumerate() {
            for line in self.fetched(s, w) {
                *self.seen.entry(line).or_insert(0) |= bit(w);
            }
        }
        for (w, s) in slices.iter().enumerate() {
            let mut vars: Vec<VarId> = s
                .iter()
                .flat_map(|t| sched.tasks[t.index()].rungs.iter())
                .flat_map(|&r| self.a.accesses.outs(r).iter().copied())
                .collect();
            vars.sort_unstable();
            vars.dedup();
            self.place(w as u32, &vars);
        }
    }

    /// `vars` (ascending) written last by `worker`, as one new group in declaration order.
    fn place(&mut self, worker: u32, vars: &[VarId]) {
        if vars.is_empty() {
            return;
        }
        let group = self.groups << 32;
        self.groups += 1;
        let mut offset = 0u64;
        for &v in vars {
            self.last[v.index()] = Some(Written {
                worker,
                line: group | (offset / LINE_BYTES),
            });
            offset += var_bytes(self.p.var(v).ty);
        }
    }
}
