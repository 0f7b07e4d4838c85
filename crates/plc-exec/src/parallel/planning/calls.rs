//! Facts about calls and loop-backs the planner needs: the call closure of each POU, the
//! subroutines a rung calls, loop-back rungs, and whether a refused loop-back of the main
//! program can continue along an edge the schedule does not know.
//!
//! Pure functions of the program and its analysis (CALL/SBR and JMP/LBL as sources of control
//! dependence, Zhao & Yan); depends only on the typed indices below it. It does not plan.

use crate::parallel::ids::TaskId;
use plc_analysis::cfg::{self, Transfer};
use plc_analysis::{Analysis, EdgeKind};
use plc_model::{Element, Program, RungId};

/// Subroutines (transitively) called from each POU, and whether each POU has loop-back rungs.
pub(in crate::parallel) fn call_closure(p: &Program) -> Vec<Vec<u32>> {
    let direct: Vec<Vec<u32>> = (p.pous().ids())
        .map(|pou| {
            let mut calls = Vec::new();
            for r in p.pou_rungs(pou) {
                plc_model::walk_elements(&p.rung(r).series, &mut |e| {
                    if let Element::Call { pou } = e {
                        calls.push(pou.raw());
                    }
                });
            }
            calls.sort_unstable();
            calls.dedup();
            calls
        })
        .collect();
    let mut closure: Vec<Option<Vec<u32>>> = vec![None; p.pous().len()];
    fn visit(pou: usize, direct: &[Vec<u32>], closure: &mut Vec<Option<Vec<u32>>>) -> Vec<u32> {
        if let Some(c) = &closure[pou] {
            return c.clone();
        }
        let mut all = Vec::new();
        for &c in &direct[pou] {
            all.push(c);
            all.extend(visit(c as usize, direct, closure));
        }
        all.sort_unstable();
        all.dedup();
        closure[pou] = Some(all.clone());
        all
    }
    (0..p.pous().len())
        .map(|pou| visit(pou, &direct, &mut closure))
        .collect()
}

/// Subroutines called (transitively) from a rung.
pub(in crate::parallel) fn rung_callees(p: &Program, closure: &[Vec<u32>], r: RungId) -> Vec<u32> {
    let mut out = Vec::new();
    plc_model::walk_elements(&p.rung(r).series, &mut |e| {
        if let Element::Call { pou } = e {
            out.push(pou.raw());
            out.extend_from_slice(&closure[pou.index()]);
        }
    });
    out.sort_unstable();
    out.dedup();
    out
}

/// Whether rung `r` holds a loop-back (a NEXT, or a backward jump).
pub(in crate::parallel) fn is_loop_back(p: &Program, r: RungId) -> bool {
    let mut found = false;
    plc_model::walk_elements(&p.rung(r).series, &mut |e| match e {
        Element::Next { .. } => found = true,
        Element::Jmp { target, .. } if target.raw() <= r.raw() => found = true,
        _ => {}
    });
    found
}

/// The first main-program rung whose loop-cap refusal could lead where the schedule does not
/// expect control to go, with the reason; `None` if there is none.
pub(in crate::parallel) fn uncovered_refusal(
    p: &Program,
    a: &Analysis,
    task_of: &[Option<TaskId>],
) -> Option<String> {
    let n = p.rungs().len() as u32;
    let stop = a.cfg.stop().raw();
    // Live CFG edges of the main program, by (task of source, target node).
    let mut edges: std::collections::HashSet<(TaskId, u32)> = std::collections::HashSet::new();
    for e in &a.cfg.edges {
        if matches!(e.kind, EdgeKind::Call | EdgeKind::Return) || e.from.raw() >= n {
            continue;
        }
        if let Some(t) = task_of[e.from.raw() as usize] {
            edges.insert((t, e.to.raw()));
        }
    }
    let main = p.main().rungs.clone();
    let mut found = Vec::new();
    for r in main.clone() {
        let Some(t) = task_of[r as usize] else {
            continue;
        };
        let rid = p.rungs().id(r as usize);
        let rung = p.rung(rid);
        let next = if r + 1 < main.end { r + 1 } else { stop };
        let targets: Vec<u32> = match rung.series.last() {
            // A refused NEXT goes on to the rung after it: the FOR head's loop exit, which is in
            // the same task; checked like the others all the same.
            Some(Element::Next { .. }) => vec![next],
            _ => {
                found.clear();
                let terminated = cfg::transfers(&rung.series, &mut found);
                if !cfg::ends_in_loop_back(&found, terminated, rid) {
                    continue; // a conditional backward jump's "not taken" paths are CFG edges
                }
                // After a refusal the rest of the rung runs: its transfers up to the next
                // unconditional one, or onwards when there is none.
                found.clear();
                let ends = cfg::transfers_refusing(&rung.series, Some(rid), &mut found);
                let mut ts: Vec<u32> = found
                    .iter()
                    .filter_map(|&(tr, _)| match tr {
                        Transfer::Jump(x) => Some(x.raw()),
                        Transfer::Ret | Transfer::End => Some(stop),
                        Transfer::Call(_) => None,
                    })
                    .collect();
                if !ends {
                    ts.push(next);
                }
                ts
            }
        };
        for x in targets {
            let covered = if x == stop {
                edges.contains(&(t, stop))
            } else {
                match task_of[x as usize] {
                    Some(tx) => tx == t || edges.contains(&(t, x)),
                    None => false,
                }
            };
            if !covered {
                let to = if x == stop {
                    "the end of the scan".to_string()
                } else {
                    format!("rung {}", p.rungs()[x as usize].id)
                };
                return Some(format!(
                    "rung {} loops back unconditionally; if the iteration cap refuses it, control goes on to {to}, a way the schedule does not know",
                    rung.id
                ));
            }
        }
    }
    None
}
