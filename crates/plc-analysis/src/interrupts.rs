//! What each interrupt routine shares with the main program.
//!
//! An interrupt routine (S7-200 `INT`, ended by `RETI`) is not called by the program: it runs
//! when its event occurs, which may be between any two rungs of the scan. Zhao & Yan name
//! INT/IRET among the sources of control dependence in a ladder program, beside jumps, loops,
//! calls and timers; but no edge of the control-flow graph can say where an interrupt runs. So the analysis treats each
//! interrupt routine as a POU of its own (its rungs are levelled and scheduled like those of a
//! subroutine nothing calls) and lists, for each, the variables it shares with the main
//! program: those that either side writes while the other reads or writes them. Each of them
//! can change under the main program between two of its rungs (or the interrupt can see a
//! half-updated set), which is what a reviewer of a parallel or reordered scan must check.
//!
//! The main program's accesses are those of its rungs, a `call` rung counting everything the
//! subroutine it calls (transitively) reads and writes. Variables both sides only read are not
//! listed: nothing can change them between two rungs. Granularity is the whole variable, as in
//! the rest of the analysis. O(Σ accesses · log) per interrupt routine.
//!
//! Deliberately not here: when interrupts are enabled (`ENI`/`DISI`) or attached (`ATCH`):
//! every interrupt routine is taken as able to run anywhere.

use super::accesses::Accesses;
use plc_model::{PouId, PouKind, Program, RungId, VarId};
use std::collections::BTreeMap;

/// One variable an interrupt routine shares with the main program.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct SharedVar {
    pub var: VarId,
    /// Whether the interrupt routine reads it, and whether it writes it.
    pub interrupt_reads: bool,
    pub interrupt_writes: bool,
    /// The main program's rungs that read it, and that write it, in program order.
    pub main_readers: Vec<RungId>,
    pub main_writers: Vec<RungId>,
}

/// What one interrupt routine shares with the main program.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct InterruptSharing {
    pub pou: PouId,
    /// In variable order.
    pub shared: Vec<SharedVar>,
}

/// The sharing of every interrupt routine of `p`, in POU order.
pub fn interrupt_sharing(p: &Program, acc: &Accesses) -> Vec<InterruptSharing> {
    let interrupts: Vec<_> = p
        .pous()
        .iter_enumerated()
        .filter(|(_, pou)| pou.kind == PouKind::Interrupt)
        .map(|(i, _)| i)
        .collect();
    if interrupts.is_empty() {
        return Vec::new();
    }
    // Per variable, the main program's readers and writers.
    let mut main: BTreeMap<VarId, (Vec<RungId>, Vec<RungId>)> = BTreeMap::new();
    for r in p.pou_rungs(p.main_id()) {
        for &v in acc.ins(r) {
            main.entry(v).or_default().0.push(r);
        }
        for &v in acc.outs(r) {
            main.entry(v).or_default().1.push(r);
        }
    }
    interrupts
        .into_iter()
        .map(|pou| {
            let mut own: BTreeMap<VarId, (bool, bool)> = BTreeMap::new();
            for r in p.pou_rungs(pou) {
                for &v in acc.ins(r) {
                    own.entry(v).or_default().0 = true;
                }
                for &v in acc.outs(r) {
                    own.entry(v).or_default().1 = true;
                }
            }
            let shared = own
                .into_iter()
                .filter_map(|(var, (reads, writes))| {
                    let (readers, writers) = main.get(&var)?;
                    (writes || !writers.is_empty()).then(|| SharedVar {
                        var,
                        interrupt_reads: reads,
                        interrupt_writes: writes,
                        main_readers: readers.clone(),
                        main_writers: writers.clone(),
                    })
                })
                .collect();
            InterruptSharing { pou, shared }
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::accesses::accesses;

    fn load(json: &str) -> Program {
        plc_load::program_and_fbd_from_json(json).expect("loads").0
    }

    #[test]
    fn lists_what_either_side_writes_and_who_touches_it() {
        let p = load(
            r#"{"program": "P",
              "vars": [{"name": "A", "type": "BOOL", "class": "input"}, {"name": "X", "type": "BOOL"},
                       {"name": "Y", "type": "BOOL"}, {"name": "Z", "type": "BOOL"}],
              "rungs": [{"id": "R1", "ld": [{"contact": "A"}, {"coil": "X"}]},
                        {"id": "R2", "ld": [{"contact": "Y"}, {"contact": "A"}, {"coil": "Z"}]},
                        {"id": "R3", "ld": [{"call": "S"}]}],
              "subroutines": {"S": {"rungs": [{"id": "S1", "ld": [{"contact": "Z"}, {"coil": "X"}]}]}},
              "interrupts": {"INT0": {"rungs": [{"id": "I1", "ld": [{"contact": "A"}, {"contact": "X"}, {"coil": "Y"}]}]}}}"#,
        );
        let sharing = interrupt_sharing(&p, &accesses(&p));
        assert_eq!(sharing.len(), 1);
        assert_eq!(p.pou(sharing[0].pou).name, "INT0");
        let id = |name: &str| {
            p.rungs()
                .id(p.rungs().iter().position(|r| r.id == name).unwrap())
        };
        let var = |name: &str| {
            p.vars()
                .id(p.vars().iter().position(|v| v.name == name).unwrap())
        };
        // A is only read by both: not listed. X: the interrupt reads it, R1 and the call in R3
        // (through S) write it. Y: the interrupt writes it, R2 reads it.
        assert_eq!(
            sharing[0].shared,
            vec![
                SharedVar {
                    var: var("X"),
                    interrupt_reads: true,
                    interrupt_writes: false,
                    main_readers: vec![],
                    main_writers: vec![id("R1"), id("R3")],
                },
                SharedVar {
                    var: var("Y"),
                    interrupt_reads: false,
                    interrupt_writes: true,
                    main_readers: vec![id("R2")],
                    main_writers: vec![],
                },
            ]
        );
    }

    #[test]
    fn a_program_without_interrupts_has_no_sharing() {
        let p = load(
            r#"{"program": "P", "vars": [{"name": "X", "type": "BOOL"}],
              "rungs": [{"id": "R1", "ld": [{"contact": "X"}, {"coil": "X"}]}],
              "subroutines": {"S": {"rungs": [{"id": "S1", "ld": [{"coil": "X"}]}]}}}"#,
        );
        assert!(interrupt_sharing(&p, &accesses(&p)).is_empty());
    }
}
