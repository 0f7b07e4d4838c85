//! The global variables that programs of different tasks share.
//!
//! A PLCopen resource runs its program instances under tasks (IEC 61131-3 6.8.2), each with its
//! own interval and priority; on a multicore controller two tasks may run at once, and even on
//! one core a higher-priority task may pre-empt another between two of its rungs. A global
//! variable (`VAR_GLOBAL`, reached through `VAR_EXTERNAL`) that a program of one task writes
//! while a program of another task reads or writes it is where one task can see another's
//! half-finished scan. This lists them, with which program instance (and task) reads and which
//! writes each — the approach of [`super::interrupts`], with tasks in place of the interrupt
//! routine and the main program.
//!
//! A program's accesses are those of its POU's rungs, a `call` rung counting everything its
//! callee (transitively) reads and writes. Globals are the program-wide variables the reader
//! did not make up (in a project of several programs, each program's own variables are scoped
//! to its POU). Variables every task only reads are not listed: nothing can change them. The
//! resource's instances without a task count as one task of their own. Granularity is the
//! whole variable. O(Σ accesses · log).
//!
//! Deliberately not here: whether the tasks can actually overlap (their intervals and
//! priorities): every pair of tasks is taken as able to.

use super::accesses::Accesses;
use crate::model::{Program, ProgramRun, VarId};
use std::collections::BTreeMap;

/// One global that programs of different tasks share, where at least one writes it.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct SharedGlobal {
    pub var: VarId,
    /// Indices into [`TaskSharing::runs`] of the program instances that read it, in run order.
    pub readers: Vec<usize>,
    /// Likewise, those that write it.
    pub writers: Vec<usize>,
}

/// The program instances of the configuration and the globals shared across their tasks.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct TaskSharing {
    /// In run order ([`Program::program_runs`]).
    pub runs: Vec<ProgramRun>,
    /// In variable order.
    pub shared: Vec<SharedGlobal>,
}

/// The globals of `p` shared by programs of different tasks.
pub fn task_sharing(p: &Program, acc: &Accesses) -> TaskSharing {
    let runs = p.program_runs();
    // Per global, the runs that read it and that write it.
    let mut touched: BTreeMap<VarId, (Vec<usize>, Vec<usize>)> = BTreeMap::new();
    for (i, run) in runs.iter().enumerate() {
        let mut own: BTreeMap<VarId, (bool, bool)> = BTreeMap::new();
        for r in p.pou_rungs(run.pou) {
            for &v in acc.ins(r) {
                own.entry(v).or_default().0 = true;
            }
            for &v in acc.outs(r) {
                own.entry(v).or_default().1 = true;
            }
        }
        for (v, (reads, writes)) in own {
            let var = p.var(v);
            if var.scope.is_some() || var.hidden {
                continue;
            }
            let e = touched.entry(v).or_default();
            if reads {
                e.0.push(i);
            }
            if writes {
                e.1.push(i);
            }
        }
    }
    let shared = touched
        .into_iter()
        .filter(|(_, (readers, writers))| {
            let mut tasks: Vec<&Option<String>> = readers
                .iter()
                .chain(writers)
                .map(|&i| &runs[i].task)
                .collect();
            tasks.sort();
            tasks.dedup();
            !writers.is_empty() && tasks.len() > 1
        })
        .map(|(var, (readers, writers))| SharedGlobal {
            var,
            readers,
            writers,
        })
        .collect();
    TaskSharing { runs, shared }
}
