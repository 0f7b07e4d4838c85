//! The plan check run on every plan at plan time, in release builds too: from the *lowered
//! instructions'* actual byte reads and writes (`Machine::rung_accesses`), not from the access
//! sets the plan was built from, every parallel phase must satisfy
//! - no byte written by one worker is read or written by another worker (no data race), and
//! - no two workers write one 64-byte line of the state (no false sharing of writes: the
//!   layout's padding did its job). The line of a byte is its address / 64: a state's memory
//!   starts on a line (`exec::Mem`).
//!
//! A dependence-driven plan (one parallel phase whose workers order their items by ready
//! flags) is checked by `order_check` instead: conflicting accesses of different workers must
//! be ordered by its waits rather than absent.
//!
//! A plan that fails is not run: `ParallelMachine::new` drops it with a warning and the run
//! falls back to the sequential walk. Depends on the plan and the interpreter below it; it does
//! not fix plans.

use super::order_check::check_ordered;
use super::plan::Plan;
use crate::{Machine, Span, LINE_BYTES};
use plc_model::RungId;

/// Who touched a byte or a line last: (phase, worker).
type Owner = Option<(u32, u32)>;

/// The bytes of a span.
fn bytes((at, w): Span) -> std::ops::Range<usize> {
    at.index()..at.index() + w as usize
}

/// Checks `plan` against `machine`'s lowered code; the error names the phase, the workers and
/// the byte. A dependence-driven plan is checked for order instead (`order_check`).
pub(in crate::parallel) fn check_plan(machine: &Machine, plan: &Plan) -> Result<(), String> {
    if plan.ready.is_some() {
        return check_ordered(machine, plan);
    }
    let n = machine.state_size() as usize;
    let mut byte_writer: Vec<Owner> = vec![None; n];
    let mut line_writer: Vec<Owner> = vec![None; n.div_ceil(LINE_BYTES as usize)];
    let (mut reads, mut writes) = (Vec::new(), Vec::new());
    // Per worker of a phase: the spans it reads (checked once all writers are known).
    let mut read_by: Vec<Vec<Span>> = Vec::new();
    for (pi, ph) in plan.phases.iter().enumerate() {
        if !ph.is_parallel() {
            continue;
        }
        let pi = pi as u32;
        read_by.iter_mut().for_each(Vec::clear);
        for (w, it) in ph.all_items() {
            if read_by.len() <= w {
                read_by.resize(w + 1, Vec::new());
            }
            for r in item_rungs(plan, it) {
                reads.clear();
                writes.clear();
                machine.rung_accesses(r, &mut reads, &mut writes);
                read_by[w].extend_from_slice(&reads);
                let w = w as u32;
                for &span in &writes {
                    for b in bytes(span) {
                        let Some(byte) = byte_writer.get_mut(b) else {
                            return Err(format!(
                                "rung {} writes byte {b}, past the state",
                                r.raw()
                            ));
                        };
                        match *byte {
                            Some((p, w2)) if p == pi && w2 != w => {
                                return Err(format!(
                                    "phase {pi}: byte {b} written by workers {w2} and {w}"
                                ))
                            }
                            _ => *byte = Some((pi, w)),
                        }
                        let line = &mut line_writer[b / LINE_BYTES as usize];
                        match *line {
                            Some((p, w2)) if p == pi && w2 != w => {
                                return Err(format!(
                                "phase {pi}: workers {w2} and {w} both write the line of byte {b}"
                            ))
                            }
                            _ => *line = Some((pi, w)),
                        }
                    }
                }
            }
        }
        for (w, spans) in read_by.iter().enumerate() {
            for b in spans.iter().flat_map(|&s| bytes(s)) {
                if let Some(Some((p, w2))) = byte_writer.get(b) {
                    if *p == pi && *w2 != w as u32 {
                        return Err(format!(
                            "phase {pi}: byte {b} written by worker {w2} and read by worker {w}"
                        ));
                    }
                }
            }
        }
    }
    Ok(())
}

/// The rungs of an item's tasks.
fn item_rungs<'a>(plan: &'a Plan, it: &'a super::tasks::Item) -> impl Iterator<Item = RungId> + 'a {
    it.tasks()
        .flat_map(move |t| plan.task_rungs[t.index()].iter().copied())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::parallel::config::{PlanConfig, Strategy};
    use crate::{ExecConfig, Layout};

    /// Two independent rungs writing two BOOLs: a parallel level of two tasks.
    fn program() -> plc_model::Program {
        plc_load::program_from_json(
            r#"{"program": "p", "vars": [
                {"name": "a", "type": "BOOL", "class": "input"},
                {"name": "b", "type": "BOOL", "class": "input"},
                {"name": "x", "type": "BOOL", "class": "output"},
                {"name": "y", "type": "BOOL", "class": "output"}],
              "rungs": [{"id": "R1", "ld": [{"contact": "a"}, {"coil": "x"}]},
                        {"id": "R2", "ld": [{"contact": "b"}, {"coil": "y"}]}]}"#,
        )
        .unwrap()
    }

    /// The plan that runs every level in parallel on two workers.
    fn all_parallel(p: &plc_model::Program) -> Plan {
        let config = PlanConfig {
            strategy: Strategy::AllParallel,
            ..PlanConfig::new(2)
        };
        Plan::build(p, &plc_analysis::analyse(p), &config)
    }

    #[test]
    fn a_padded_layout_passes_and_a_dense_one_fails_on_the_shared_line() {
        let p = program();
        let plan = all_parallel(&p);
        assert_eq!(plan.parallel_phases(), 1);
        let groups = super::super::plan::layout_groups(&[&plan], p.vars());
        let padded = Machine::new(
            &p,
            Layout::from_groups(&p, &groups, LINE_BYTES).unwrap(),
            &ExecConfig::default(),
        )
        .unwrap();
        assert_eq!(check_plan(&padded, &plan), Ok(()));
        // x and y (bytes 2 and 3) on one line, written by workers 0 and 1 in phase 0.
        let dense = Machine::new(&p, Layout::dense(&p), &ExecConfig::default()).unwrap();
        assert_eq!(
            check_plan(&dense, &plan),
            Err("phase 0: workers 0 and 1 both write the line of byte 3".into())
        );
    }

    #[test]
    fn a_line_is_64_bytes_of_real_addresses() {
        let p = program();
        let plan = all_parallel(&p);
        let at = |x: u32, y: u32| {
            let layout = Layout::from_starts(&p, vec![0, 1, x, y], 128).unwrap();
            let m = Machine::new(&p, layout, &ExecConfig::default()).unwrap();
            assert_eq!(m.state_size(), 128);
            check_plan(&m, &plan)
        };
        // x (worker 0) and y (worker 1): bytes 63 and 64 are on two lines, 2 and 63 on one.
        assert_eq!(at(63, 64), Ok(()));
        assert_eq!(
            at(2, 63),
            Err("phase 0: workers 0 and 1 both write the line of byte 63".into())
        );
    }

    #[test]
    fn two_workers_writing_one_slot_fail() {
        let p = program();
        let a = plc_analysis::analyse(&p);
        let mut plan = Plan::build(
            &p,
            &a,
            &PlanConfig {
                strategy: Strategy::AllParallel,
                ..PlanConfig::new(2)
            },
        );
        // Pretend R2 reads x: give task 1 the rungs of both tasks (R1 then writes x on worker 0
        // and worker 1 both).
        plan.task_rungs[1] = vec![RungId::from_raw(0), RungId::from_raw(1)];
        let m = Machine::new(&p, Layout::dense(&p), &ExecConfig::default()).unwrap();
        let e = check_plan(&m, &plan).unwrap_err();
        assert_eq!(e, "phase 0: byte 2 written by workers 0 and 1");
    }
}
