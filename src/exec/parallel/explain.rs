//! `plc-deps run --explain`: the plan in words and as JSON. The top of the parallel module:
//! it reads the machine and its plan and changes nothing.

use super::machine::ParallelMachine;
use crate::model::Program;
use std::fmt::Write as _;

impl ParallelMachine {
    /// `plc-deps run --explain`: the plan in words.
    pub fn explain(&self, p: &Program) -> String {
        let plan = &self.plan;
        let c = &plan.config;
        let mut s = String::new();
        let _ = writeln!(s, "parallel plan: {}, {}, cost model: barrier {} steps, item {} steps, strategy {:?}, slicing {:?}",
            count(plan.threads, "worker"), count(plan.levels.len(), "level"), c.barrier_cost, c.item_cost, c.strategy, c.slicing);
        let (seq, est) = plan.estimates();
        let _ = writeln!(
            s,
            "modelled scan: sequential {seq} steps, this plan {est} steps ({:.2}x)",
            seq as f64 / est.max(1) as f64
        );
        if let Some(why) = &plan.sequential {
            let _ = writeln!(
                s,
                "decision: the whole program runs as the sequential scan: {why}"
            );
        } else {
            let _ = writeln!(
                s,
                "decision: {} per scan ({} parallel), {} per scan",
                count(plan.phase_count(), "phase"),
                plan.parallel_phases(),
                count(plan.barriers_per_scan(), "barrier")
            );
        }
        let shown = plan.levels.len().min(500);
        for (l, lp) in plan.levels.iter().take(shown).enumerate() {
            let kind = if lp.parallel {
                "parallel"
            } else {
                "sequential"
            };
            let _ = write!(
                s,
                "  level {:>3}: {:>6} task{}, cost {:>8}, {kind}",
                l + 1,
                lp.tasks,
                if lp.tasks == 1 { " " } else { "s" },
                lp.cost
            );
            if let (true, Some(m)) = (lp.parallel, lp.makespan) {
                let _ = write!(s, " ({}, makespan {m}):", lp.slicing);
                for (w, (tasks, items, cost)) in lp.workers.iter().enumerate() {
                    let _ = write!(
                        s,
                        " w{w} {}/{}/{cost}",
                        count(*tasks, "task"),
                        count(*items, "item")
                    );
                    if w + 1 < lp.workers.len() {
                        s.push(',');
                    }
                }
            }
            if !lp.reason.is_empty() {
                let _ = write!(s, " — {}", lp.reason);
            }
            s.push('\n');
        }
        if shown < plan.levels.len() {
            let _ = writeln!(s, "  ... {} more levels", plan.levels.len() - shown);
        }
        if plan.sequential.is_none() {
            for (i, ph) in plan.phases.iter().enumerate() {
                if !ph.is_parallel() && ph.levels.len() > 1 {
                    let _ = writeln!(s, "  phase {}: levels {}..={} merged into one sequential phase (worker 0, task order)", i + 1, ph.levels.start + 1, ph.levels.end);
                }
            }
            let dense: u32 = p.vars.iter().map(|v| crate::exec::slot_width(v.ty)).sum();
            let m = &self.machine;
            let _ = writeln!(
                s,
                "padding: {} variable groups on 64-byte lines (one per set of (phase, worker) writers); {} slots for {} of data, {} loop counters (a line each), {} decision slots",
                self.layout_groups,
                m.layout().slot_count(),
                dense,
                m.loop_counters().len(),
                plan.decision_slots
            );
        } else {
            let _ = writeln!(s, "padding: none (dense layout)");
        }
        s
    }

    /// The plan as JSON (`plc-deps run --explain --format json`).
    pub fn explain_json(&self) -> serde_json::Value {
        use serde_json::json;
        let plan = &self.plan;
        let (seq, est) = plan.estimates();
        json!({
            "threads": plan.threads,
            "sequential": plan.sequential,
            "barrier_cost": plan.config.barrier_cost,
            "item_cost": plan.config.item_cost,
            "modelled_steps": {"sequential": seq, "plan": est},
            "phases": plan.phase_count(),
            "parallel_phases": plan.parallel_phases(),
            "barriers_per_scan": plan.barriers_per_scan(),
            "slots": self.machine.slot_count(),
            "layout_groups": self.layout_groups,
            "decision_slots": plan.decision_slots,
            "levels": plan.levels.iter().map(|lp| json!({
                "tasks": lp.tasks,
                "cost": lp.cost,
                "parallel": lp.parallel,
                "makespan": lp.makespan,
                "slicing": if lp.parallel { Some(lp.slicing) } else { None },
                "workers": lp.workers.iter().map(|&(t, i, c)| json!({"tasks": t, "items": i, "cost": c})).collect::<Vec<_>>(),
                "reason": lp.reason,
            })).collect::<Vec<_>>(),
        })
    }
}

/// `1 task`, `2 tasks`.
fn count(n: impl TryInto<u64>, one: &str) -> String {
    let n: u64 = n.try_into().unwrap_or(u64::MAX);
    format!("{n} {one}{}", if n == 1 { "" } else { "s" })
}
