//! Outputs of `plc-deps report`: the analysis rendered as text (for people), JSON (for tools,
//! normative keys, docs/report.md) and DOT (for Graphviz).
//!
//! Renderers take the program and its [`Analysis`] and return a `String`; they never print, so
//! the caller writes the output file whole or not at all. Shared naming and the explanation of
//! the differences between the paper's views and the combined schedule live here, so that every
//! format says the same thing.

mod dot;
mod json;
mod text;

pub use dot::render_dot;
pub use json::render_json;
pub use text::render_text;

use crate::analysis::{Analysis, ControlCause, DepKind, Warning};
use crate::model::*;

/// Which levellings a text or DOT report shows (JSON always carries all of them).
#[derive(Copy, Clone, Debug, PartialEq, Eq)]
pub enum View {
    /// The paper's data and control views.
    Paper,
    /// The correct combined schedule.
    Combined,
    /// Both.
    All,
}

/// Name of a CFG node: a rung id, `START` or `STOP`.
pub(crate) fn node_name(p: &Program, n: u32) -> &str {
    let rungs = p.rungs.len() as u32;
    if n < rungs {
        &p.rungs[n as usize].id
    } else if n == rungs {
        "START"
    } else {
        "STOP"
    }
}

/// The paper's control view as unique (from, to) pairs without self pairs, with one cause each.
pub(crate) fn paper_control_pairs(a: &Analysis) -> Vec<(RungId, RungId, ControlCause)> {
    let mut out: Vec<(RungId, RungId, ControlCause)> = Vec::new();
    for d in &a.paper_control {
        if d.from == d.to {
            continue;
        }
        if out
            .last()
            .is_some_and(|&(f, t, _)| f == d.from && t == d.to)
        {
            continue;
        }
        out.push((d.from, d.to, d.cause));
    }
    out
}

/// Rungs the paper's control view finds control dependent on themselves (loop heads, calls).
pub(crate) fn self_controlled(a: &Analysis) -> Vec<RungId> {
    let mut v: Vec<RungId> = a
        .paper_control
        .iter()
        .filter(|d| d.from == d.to)
        .map(|d| d.from)
        .collect();
    v.dedup();
    v
}

/// Level groups (0-based level → rung ids in program order) from per-rung levels.
pub(crate) fn rung_groups(levels: &[u32]) -> Vec<Vec<RungId>> {
    crate::analysis::levels::group_by_level(levels)
        .into_iter()
        .map(|g| g.into_iter().map(RungId).collect())
        .collect()
}

/// Level groups of the combined schedule: each task's rungs, tasks ordered by first rung.
pub(crate) fn combined_groups(a: &Analysis) -> Vec<Vec<Vec<RungId>>> {
    a.schedule
        .levels
        .iter()
        .map(|level| {
            let mut tasks: Vec<Vec<RungId>> = level
                .iter()
                .map(|&t| a.schedule.tasks[t as usize].rungs.clone())
                .collect();
            tasks.sort_unstable_by_key(|t| t[0]);
            tasks
        })
        .collect()
}

/// How the combined schedule places one rung differently from the paper's views, and why.
pub(crate) struct Difference {
    pub rung: RungId,
    pub data_level: u32,
    pub control_level: u32,
    /// `None` for rungs that are not units of the combined schedule.
    pub combined_level: Option<u32>,
    pub reasons: Vec<String>,
}

/// One entry per rung whose combined placement differs from a paper view.
pub(crate) fn differences(p: &Program, a: &Analysis) -> Vec<Difference> {
    let s = &a.schedule;
    let ids = |rs: &mut dyn Iterator<Item = RungId>| {
        rs.map(|r| p.rung(r).id.clone())
            .collect::<Vec<_>>()
            .join(", ")
    };
    let mut callers: Vec<Vec<RungId>> = vec![Vec::new(); p.pous.len()];
    for e in &a.cfg.edges {
        if e.kind == crate::analysis::EdgeKind::Call {
            let pou = p.rungs[e.to as usize].pou;
            callers[pou.index()].push(RungId(e.from));
        }
    }
    let mut out = Vec::new();
    for r in p.rung_ids() {
        let dl = a.data_levels[r.index()];
        let cl = a.control_levels[r.index()];
        let rung = p.rung(r);
        let Some(t) = s.task_of[r.index()] else {
            let reason = if rung.pou.index() != 0 {
                let c = &callers[rung.pou.index()];
                if c.is_empty() {
                    format!(
                        "in subroutine {}, which nothing calls",
                        p.pou(rung.pou).name
                    )
                } else {
                    format!("in subroutine {}: runs inside the calling rung's task ({}), not as a unit of its own", p.pou(rung.pou).name, ids(&mut c.iter().copied()))
                }
            } else {
                "can never run (unreachable from the start of the scan)".to_string()
            };
            out.push(Difference {
                rung: r,
                data_level: dl,
                control_level: cl,
                combined_level: None,
                reasons: vec![reason],
            });
            continue;
        };
        let task = &s.tasks[t as usize];
        let level = task.level;
        if level == dl && level == cl && !task.is_loop {
            continue;
        }
        let mut reasons = Vec::new();
        if task.is_loop {
            reasons.push(format!(
                "part of the loop {{{}}}, kept whole as one sequential task",
                ids(&mut task.rungs.iter().copied())
            ));
        }
        let controllers: Vec<u32> = task.guard.iter().map(|g| g.controller).collect();
        if level > dl && !controllers.is_empty() {
            reasons.push(format!(
                "runs only if {} decides so (control), which the data view ignores",
                ids(&mut controllers.iter().map(|&c| s.head(c)))
            ));
        }
        let data_preds: Vec<u32> = s.preds[t as usize]
            .iter()
            .copied()
            .filter(|q| !controllers.contains(q))
            .collect();
        if level > cl && !data_preds.is_empty() {
            reasons.push(format!(
                "must follow {} (data), which the control view ignores",
                ids(&mut data_preds.iter().take(4).map(|&c| s.head(c)))
            ));
        }
        if level < cl {
            let instance = a
                .paper_control
                .iter()
                .any(|d| d.to == r && matches!(d.cause, ControlCause::Instance { .. }));
            if instance {
                reasons.push("reads a timer or counter: the paper counts that as a control dependence, here it is the data dependence on the instance".into());
            }
        }
        if reasons.is_empty() {
            reasons.push(if level > dl.max(cl) {
                "both kinds of dependence together put it later than either view alone".into()
            } else {
                "levelled from the combined dependences".into()
            });
        }
        out.push(Difference {
            rung: r,
            data_level: dl,
            control_level: cl,
            combined_level: Some(level),
            reasons,
        });
    }
    out
}

/// An FBD network of the program: its (contiguous) rungs and the union of their IN and OUT.
pub(crate) struct Network {
    pub pou: PouId,
    pub id: String,
    pub rungs: Vec<RungId>,
    pub ins: Vec<VarId>,
    pub outs: Vec<VarId>,
}

/// The FBD networks, in program order (empty for a pure ladder program).
pub(crate) fn networks(p: &Program, a: &Analysis) -> Vec<Network> {
    let mut out: Vec<Network> = Vec::new();
    for r in p.rung_ids() {
        let rung = p.rung(r);
        let Some(net) = &rung.network else { continue };
        let same = out.last().is_some_and(|n| {
            n.pou == rung.pou && &n.id == net && n.rungs.last().is_some_and(|l| l.0 + 1 == r.0)
        });
        if !same {
            out.push(Network {
                pou: rung.pou,
                id: net.clone(),
                rungs: Vec::new(),
                ins: Vec::new(),
                outs: Vec::new(),
            });
        }
        let n = out.last_mut().expect("pushed above");
        n.rungs.push(r);
        n.ins.extend_from_slice(a.accesses.ins(r));
        n.outs.extend_from_slice(a.accesses.outs(r));
    }
    for n in &mut out {
        for l in [&mut n.ins, &mut n.outs] {
            l.sort_unstable();
            l.dedup();
        }
    }
    out
}

/// Human text of a warning.
pub(crate) fn warning_text(p: &Program, w: &Warning) -> String {
    let ids = |rs: &[RungId]| {
        let list = rs
            .iter()
            .map(|r| p.rung(*r).id.as_str())
            .collect::<Vec<_>>()
            .join(", ");
        if rs.len() == 1 {
            format!("rung {list}")
        } else {
            format!("rungs {list}")
        }
    };
    match w {
        Warning::Unreachable(rs) => format!("{} can never run (no path from the start of the scan reaches it)", ids(rs)),
        Warning::Endless(rs) => format!(
            "{} can never reach the end of the scan (an endless loop); the post-dominator tree treats the last of them as an exit",
            ids(rs)
        ),
        Warning::Uncalled(pou) => format!("subroutine {} is never called", p.pou(*pou).name),
    }
}

pub(crate) fn dep_kind_name(k: DepKind) -> &'static str {
    k.name()
}
