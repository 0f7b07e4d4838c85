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
use plc_model::{Program, ProgramRun, VarId};
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::accesses::accesses;

    /// A program POU whose LD body copies global `read` into global `write`.
    fn pou(name: &str, read: &str, write: &str) -> String {
        let v = |n: &str| format!("<variable name=\"{n}\"><type><BOOL/></type></variable>");
        format!(
            "<pou name=\"{name}\" pouType=\"program\"><interface><externalVars>{}{}</externalVars></interface><body><LD>\
             <leftPowerRail localId=\"1\"><connectionPointOut formalParameter=\"\"/></leftPowerRail>\
             <contact localId=\"2\"><connectionPointIn><connection refLocalId=\"1\"/></connectionPointIn><connectionPointOut/><variable>{read}</variable></contact>\
             <coil localId=\"3\"><connectionPointIn><connection refLocalId=\"2\"/></connectionPointIn><connectionPointOut/><variable>{write}</variable></coil>\
             </LD></body></pou>",
            v(read),
            v(write)
        )
    }

    #[test]
    fn lists_the_globals_a_task_writes_and_another_touches() {
        // T1 runs A (G1 → G2); T2 runs B (G2 → G3); the resource itself runs C (G1 → G3).
        let globals: String = ["G1", "G2", "G3"]
            .iter()
            .map(|n| format!("<variable name=\"{n}\"><type><BOOL/></type></variable>"))
            .collect();
        let xml = format!(
            "<project xmlns=\"http://www.plcopen.org/xml/tc6_0201\"><types><pous>{}{}{}</pous></types><instances><configurations><configuration name=\"K\"><globalVars>{globals}</globalVars><resource name=\"R\">\
             <task name=\"T1\" priority=\"0\" interval=\"T#10ms\"><pouInstance name=\"a\" typeName=\"A\"/></task>\
             <task name=\"T2\" priority=\"1\" interval=\"T#50ms\"><pouInstance name=\"b\" typeName=\"B\"/></task>\
             <pouInstance name=\"c\" typeName=\"C\"/></resource></configuration></configurations></instances></project>",
            pou("A", "G1", "G2"),
            pou("B", "G2", "G3"),
            pou("C", "G1", "G3"),
        );
        let p = plc_load::plcopen(&xml).expect("loads").0;
        let s = task_sharing(&p, &accesses(&p));
        let names: Vec<(Option<&str>, &str)> = s
            .runs
            .iter()
            .map(|r| (r.task.as_deref(), r.instance.as_str()))
            .collect();
        assert_eq!(names, [(Some("T1"), "a"), (Some("T2"), "b"), (None, "c")]);
        let var = |n: &str| {
            p.vars()
                .id(p.vars().iter().position(|v| v.name == n).unwrap())
        };
        // G1 is only read (A, C): not listed. G2: A writes, B reads. G3: B and C (the
        // resource's own, a task of its own) both write it.
        assert_eq!(
            s.shared,
            [
                SharedGlobal {
                    var: var("G2"),
                    readers: vec![1],
                    writers: vec![0],
                },
                SharedGlobal {
                    var: var("G3"),
                    readers: vec![],
                    writers: vec![1, 2],
                },
            ]
        );
    }
}
