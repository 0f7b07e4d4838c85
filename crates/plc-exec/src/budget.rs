//! The scan budget: what a task of a scan may charge before its calls and loop-backs are refused.
//!
//! A scan without loops or calls runs each rung at most once, so only what can *repeat* is
//! charged: a subroutine call charges the callee's rung count, a loop-back (a NEXT back to its
//! FOR test, a taken backward jump) the rungs it goes back over (NEXT: the body and the NEXT
//! rung; a backward jump from rung `r` to `t`: `r − t + 1`). The charge is the most rungs the
//! event lets run before the next charge (a forward jump may skip some), so charges bound the
//! rungs a task runs: at most its own rungs plus its charges.
//!
//! The charges are counted per *task* of the scan — a main-program rung with everything it
//! calls, or a main-program loop (a strongly connected part of the main program's CFG, the
//! combined schedule's loop task) with everything it calls — not per scan. A task is entered at
//! most once per scan and the parallel executor runs each task whole on one worker, so a
//! per-task count is the same whichever worker runs it and whatever ran before: the sequential
//! walk, every parallel plan and the generated C refuse the same event with the same state. A
//! per-scan total would depend on every task before it in the sequential order, which a
//! parallel scan has not run yet.
//!
//! The count is kept in the scan's context, not in the state: it is reset when a charge comes
//! from a main-program rung of another task than the previous charge (at the first charge of a
//! task), and a new context starts every scan. Charges are taken only at calls and loop-backs,
//! so straight-line rungs pay nothing.
//!
//! This module computes the static part (the task of each main-program rung, the charges); the
//! interpreter (`run.rs`) and the C generator apply them. It does not decide what a refusal
//! does (see `Machine::exec`).

use plc_analysis::cfg::{control_flow_graph, EdgeKind};
use plc_graph::{strongly_connected_components, Csr};
use plc_model::{PouId, Program, RungId};

/// The default budget: rungs a task of a scan may charge (`--scan-budget`).
///
/// Ten million. A charge is at least one rung run, and a rung costs the interpreter 2–20 ns, so
/// a task that reaches it has run for 20 ms to 0.2 s in one scan — beyond a PLC's scan time by
/// far (a realistic scan is a few ms, its loops well under the default `--loop-cap` of 100 000
/// iterations of a short body, 10^5 × a few rungs) — and a runaway task is stopped after about
/// that long instead of never.
pub const DEFAULT_SCAN_BUDGET: u64 = 10_000_000;

/// The budget task of every rung: `Some(k)` for a main-program rung (the index of its strongly
/// connected component in the main program's CFG without call and return edges: a rung or a
/// loop), `None` for a subroutine's rung (charged to the task of the main rung that called it).
pub fn tasks(p: &Program) -> Vec<Option<u32>> {
    let cfg = control_flow_graph(p);
    let main = p.main().rungs.clone();
    let edges: Vec<(u32, u32)> = cfg
        .edges
        .iter()
        .filter(|e| {
            !matches!(e.kind, EdgeKind::Call | EdgeKind::Return)
                && main.contains(&e.from.raw())
                && main.contains(&e.to.raw())
        })
        .map(|e| (e.from.raw(), e.to.raw()))
        .collect();
    let sccs = strongly_connected_components(&Csr::from_edges(cfg.node_count(), &edges));
    (0..p.rungs().len() as u32)
        .map(|r| main.contains(&r).then(|| sccs.component_of(r)))
        .collect()
}

/// What a call of `pou` charges: its rung count (at least 1).
pub fn call_charge(p: &Program, pou: PouId) -> u32 {
    p.pou(pou).rungs.len().max(1) as u32
}

/// What a taken backward jump of rung `from` to rung `to` (`to <= from`) charges.
pub fn jump_back_charge(from: RungId, to: RungId) -> u32 {
    from.raw() - to.raw() + 1
}

/// What a NEXT at rung `next` back to the test of the FOR at rung `head` charges: the body and
/// the NEXT rung (the head rung's conditions are not evaluated again).
pub fn next_charge(head: RungId, next: RungId) -> u32 {
    next.raw() - head.raw()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_loop_is_one_task_and_a_plain_rung_its_own() {
        let p = plc_load::program_from_json(
            r#"{"program": "p", "vars": [{"name": "a", "type": "BOOL"}, {"name": "i", "type": "INT"}],
            "rungs": [{"id": "R1", "ld": [{"contact": "a"}, {"coil": "a"}]},
                      {"id": "R2", "ld": [{"for": {"var": "i", "from": 1, "to": 3}}]},
                      {"id": "R3", "ld": [{"contact": "a"}, {"coil": "a"}]},
                      {"id": "R4", "ld": [{"next": true}]},
                      {"id": "R5", "label": "L5", "ld": [{"contact": "a"}, {"jmp": "L5"}]}]}"#,
        )
        .unwrap();
        let t = tasks(&p);
        assert_eq!(t[1], t[2]);
        assert_eq!(t[2], t[3]);
        assert_ne!(t[0], t[1]);
        assert_ne!(t[4], t[3]);
        assert_ne!(t[4], t[0]);
        assert!(t.iter().all(Option::is_some));
        assert_eq!(next_charge(RungId::from_raw(1), RungId::from_raw(3)), 2);
        assert_eq!(
            jump_back_charge(RungId::from_raw(4), RungId::from_raw(4)),
            1
        );
    }
}
