//! Why the combined schedule places a rung differently from the paper's two views (Zhao & Yan,
//! 2012): the reasons the report's "differences" section gives, rung by rung.
//!
//! [`Explainer::differing`] finds the rungs that differ without building any text (it is a
//! per-rung comparison of levels); [`Explainer::difference`] builds one rung's reasons when a
//! renderer asks for them. A loop is named once, by its first rung (`the loop at R5`); its
//! members are listed in the report's `loops`, not repeated in every member's reason.
//!
//! The document (`super::document`) uses this module; this module does not use the document:
//! [`DifferenceEntry`], an entry of the report's `differences`, is defined here, where it is
//! made.

use plc_analysis::{schedule::TaskId, Analysis, ControlCause, EdgeKind};
use plc_model::*;

/// Why a rung's combined level differs from a paper view's: an entry of the report's
/// `differences` (its fields are the JSON keys, docs/report.md).
#[derive(serde::Serialize)]
pub struct DifferenceEntry {
    pub rung: String,
    pub data_level: u32,
    pub control_level: u32,
    pub combined_level: Option<u32>,
    pub reasons: Vec<String>,
}

/// Precomputed context for explaining differences.
pub(crate) struct Explainer<'a> {
    p: &'a Program,
    a: &'a Analysis,
    /// For each POU, the rungs that call it.
    callers: Vec<Vec<RungId>>,
    /// Rungs the paper finds control dependent through a timer or counter read.
    instance_read: Vec<bool>,
}

impl<'a> Explainer<'a> {
    pub(crate) fn new(p: &'a Program, a: &'a Analysis) -> Self {
        let mut callers: Vec<Vec<RungId>> = vec![Vec::new(); p.pous().len()];
        for e in &a.cfg.edges {
            if e.kind == EdgeKind::Call {
                let pou = p.rungs()[e.to.index()].pou;
                callers[pou.index()].push(p.rungs().id(e.from.index()));
            }
        }
        let mut instance_read = vec![false; p.rungs().len()];
        for d in &a.paper_control {
            if matches!(d.cause, ControlCause::Instance { .. }) {
                instance_read[d.to.index()] = true;
            }
        }
        Explainer {
            p,
            a,
            callers,
            instance_read,
        }
    }

    /// The rungs whose combined placement differs from a paper view, in program order.
    pub(crate) fn differing(&self) -> Vec<RungId> {
        let (a, s) = (self.a, &self.a.schedule);
        self.p
            .rung_ids()
            .filter(|r| match s.task_of[r.index()] {
                None => true,
                Some(t) => {
                    let task = s.task(t);
                    task.is_loop
                        || task.level != a.data_levels[r.index()]
                        || task.level != a.control_levels[r.index()]
                }
            })
            .collect()
    }

    fn ids(&self, rs: impl Iterator<Item = RungId>) -> String {
        rs.map(|r| self.p.rung(r).id.as_str())
            .collect::<Vec<_>>()
            .join(", ")
    }

    /// Why `r` (one of [`Explainer::differing`]) is placed as it is.
    pub(crate) fn difference(&self, r: RungId) -> DifferenceEntry {
        let (p, a, s) = (self.p, self.a, &self.a.schedule);
        let dl = a.data_levels[r.index()];
        let cl = a.control_levels[r.index()];
        let rung = p.rung(r);
        let entry = |combined_level: Option<u32>, reasons: Vec<String>| DifferenceEntry {
            rung: rung.id.clone(),
            data_level: dl + 1,
            control_level: cl + 1,
            combined_level: combined_level.map(|l| l + 1),
            reasons,
        };
        let Some(t) = s.task_of[r.index()] else {
            let reason = if rung.pou.index() != 0 {
                let c = &self.callers[rung.pou.index()];
                if p.pou(rung.pou).kind == PouKind::Interrupt {
                    format!(
                        "in interrupt routine {}, which runs when its event occurs (not in the schedule)",
                        p.pou(rung.pou).name
                    )
                } else if c.is_empty() {
                    format!(
                        "in subroutine {}, which nothing calls",
                        p.pou(rung.pou).name
                    )
                } else {
                    format!(
                        "in subroutine {}: runs inside the calling rung's task ({}), not as a unit of its own",
                        p.pou(rung.pou).name,
                        self.ids(c.iter().copied())
                    )
                }
            } else {
                "can never run (unreachable from the start of the scan)".to_string()
            };
            return entry(None, vec![reason]);
        };
        let task = s.task(t);
        let level = task.level;
        let mut reasons = Vec::new();
        if task.is_loop {
            reasons.push(format!(
                "part of the loop at {}, kept whole as one sequential task",
                p.rung(task.rungs[0]).id
            ));
        }
        let controllers: Vec<TaskId> = task.guard.iter().map(|g| g.controller).collect();
        if level > dl && !controllers.is_empty() {
            reasons.push(format!(
                "runs only if {} decides so (control), which the data view ignores",
                self.ids(controllers.iter().map(|&c| s.head(c)))
            ));
        }
        let data_preds: Vec<TaskId> = s.preds[t.index()]
            .iter()
            .copied()
            .filter(|q| !controllers.contains(q))
            .collect();
        if level > cl && !data_preds.is_empty() {
            reasons.push(format!(
                "must follow {} (data), which the control view ignores",
                self.ids(data_preds.iter().take(4).map(|&c| s.head(c)))
            ));
        }
        if level < cl && self.instance_read[r.index()] {
            reasons.push("reads a timer or counter: the paper counts that as a control dependence, here it is the data dependence on the instance".into());
        }
        if reasons.is_empty() {
            reasons.push(if level > dl.max(cl) {
                "both kinds of dependence together put it later than either view alone".into()
            } else {
                "levelled from the combined dependences".into()
            });
        }
        entry(Some(level), reasons)
    }
}
