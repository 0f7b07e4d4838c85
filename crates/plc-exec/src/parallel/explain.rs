//! `plc-deps run --explain`: the plan in words and as JSON. The top of the parallel module:
//! it reads the machine and its plan and changes nothing.

use super::config::{DepsPartition, LineCostSource};
use super::machine::{Candidate, ParallelMachine, RunLog};
use super::planning::Plan;
use plc_model::Program;
use serde_json::json;
use std::fmt::Write as _;

impl ParallelMachine {
    /// `plc-deps run --explain`: the plan in words (the primary plan; the candidates of a
    /// measured choice are listed first).
    pub fn explain(&self, p: &Program) -> String {
        let plan = &self.plans[0];
        let c = &plan.config;
        let mut s = String::new();
        let names: Vec<&str> = self.names.iter().map(String::as_str).collect();
        let _ = writeln!(
            s,
            "plan kind: {} ({}: {})",
            self.kind.name(),
            count(names.len(), "candidate"),
            names.join(", ")
        );
        if let Some(why) = self.sequential_reason() {
            let _ = writeln!(s, "every scan runs the sequential walk: {why}");
        }
        for w in &self.warnings {
            let _ = writeln!(s, "warning: {w}");
        }
        let barrier = match c.handover_ns {
            Some(h) => format!("measured: 3 hand-overs of {h} ns"),
            None => "default".into(),
        };
        let _ = writeln!(s, "parallel plan: {}, {}, cost model: barrier {} steps ({barrier}), item {} steps, line {} steps ({}), fused rung {} steps, other element steps x{:.1}, strategy {:?}, slicing {:?}",
            count(plan.threads, "worker"), count(plan.levels.len(), "level"), c.barrier_cost, c.item_cost, c.line_cost, line_source(c.line_cost_source), c.fused_rung_cost, c.step_tenths as f64 / 10.0, c.strategy, c.slicing);
        let (seq, est) = plan.estimates();
        let _ = writeln!(
            s,
            "modelled scan: sequential {seq} steps, this plan {est} steps ({:.2}x, {} moved lines)",
            seq as f64 / est.max(1) as f64,
            plan.phase_lines.iter().flatten().sum::<u64>()
        );
        self.explain_candidates(&mut s);
        self.explain_deps(&mut s);
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
        explain_levels(plan, &mut s);
        self.explain_layout(p, &mut s);
        s
    }

    /// Every candidate besides the primary plan: its modelled scan, and for `par-exchange`
    /// its plan, layout and hand-over.
    fn explain_candidates(&self, s: &mut String) {
        for (i, c) in self.candidates.iter().enumerate() {
            match *c {
                Candidate::Levelled(k) if k > 0 => {
                    let other = &self.plans[k];
                    let _ = writeln!(
                        s,
                        "  candidate {}: modelled {} steps per scan ({} moved lines)",
                        self.names[i],
                        other.est_plan,
                        other.phase_lines.iter().flatten().sum::<u64>()
                    );
                }
                Candidate::Exchange(k) => {
                    if let Some(x) = &self.exchanges[k] {
                        let of = match self
                            .candidates
                            .iter()
                            .position(|&c| c == Candidate::Levelled(k))
                        {
                            Some(j) => format!("{}'s plan", self.names[j]),
                            None => "the levelled plan".to_string(),
                        };
                        let layout = match &self.own[k] {
                            Some(o) => format!(
                                ", on a layout of its own ({} variable groups, {} bytes; {} runs of bytes move the state to and from the common layout)",
                                o.groups,
                                o.machine.state_size(),
                                o.relayout.runs()
                            ),
                            None => String::new(),
                        };
                        let _ = writeln!(
                            s,
                            "  candidate {}: {of} with each worker on a private state{layout}, handing over {} words in {} lines per scan (BOOLs as bits; each line carries its scan's number); {} of {} items run before their phase's hand-over (they touch nothing the others wrote in the phase before)",
                            self.names[i],
                            x.words(),
                            x.lines(),
                            x.early_items().0,
                            x.early_items().1
                        );
                    }
                }
                _ => {}
            }
        }
    }

    /// The primary plan's sequential phases and the state's padding.
    fn explain_layout(&self, p: &Program, s: &mut String) {
        let plan = &self.plans[0];
        if plan.sequential.is_none() {
            for (i, ph) in plan.phases.iter().enumerate() {
                let moved = plan
                    .phase_lines
                    .get(i)
                    .and_then(|l| l.first())
                    .copied()
                    .unwrap_or(0);
                if !ph.is_parallel() && ph.levels.len() > 1 {
                    let _ = writeln!(s, "  phase {}: levels {}..={} merged into one sequential phase (worker 0, task order), {} moved", i + 1, ph.levels.start + 1, ph.levels.end, count(moved, "line"));
                } else if !ph.is_parallel() && moved > 0 {
                    let _ = writeln!(
                        s,
                        "  phase {}: level {} sequential (worker 0), {} moved",
                        i + 1,
                        ph.levels.start + 1,
                        count(moved, "line")
                    );
                }
            }
            let dense: u32 = p.vars().iter().map(|v| crate::type_size(v.ty)).sum();
            let m = &self.machine;
            let _ = writeln!(
                s,
                "padding: {} variable groups on 64-byte lines (one per set of (phase, worker) writers); {} bytes for {} bytes of variables, {} loop counters (a line each), {} decision slots",
                self.layout_groups,
                m.layout().size(),
                dense,
                m.loop_counters().len(),
                plan.decision_slots
            );
            let (reads, writes) = plan.remote_lines();
            let _ = writeln!(
                s,
                "prefetched when a slice starts (an item of the dependence-driven plan: one item ahead), per scan: {} another core wrote, to read; {} another core holds, to write",
                count(reads, "line"),
                count(writes, "line")
            );
        } else {
            let _ = writeln!(s, "padding: none (dense layout)");
        }
    }

    /// The dependence-driven plan, if one was built: its waits per worker and modelled scan.
    fn explain_deps(&self, s: &mut String) {
        let Some((plan, r)) = self
            .plans
            .iter()
            .find_map(|p| p.ready.as_ref().map(|r| (p, r)))
        else {
            return;
        };
        if let Some(why) = &plan.sequential {
            let _ = writeln!(s, "dependence-driven plan (par-deps): not run: {why}");
            return;
        }
        let per: Vec<String> = (0..plan.threads)
            .map(|w| {
                format!(
                    "w{w} {}/{} waits/{} publishing",
                    count(r.items_per_worker[w], "item"),
                    r.waits_per_worker[w],
                    r.publishing_per_worker[w]
                )
            })
            .collect();
        let _ = writeln!(
            s,
            "dependence-driven plan (par-deps, {}): {} per scan instead of a barrier per level ({} cross-worker dependences, the latest producer per worker kept): {}",
            partition_words(r.partition),
            count(r.waits(), "wait"),
            r.cross_dependences,
            per.join(", ")
        );
        let _ = writeln!(
            s,
            "  modelled scan: critical path {} steps (wait {} steps each) + 2 barriers ({}) = {} steps, sequential {} steps",
            r.critical_path,
            plan.config.wait_cost,
            plan.config.barrier_cost,
            plan.est_plan,
            plan.est_sequential
        );
    }

    /// The dependence-driven plan as JSON (`null` if none was built).
    fn deps_json(&self) -> serde_json::Value {
        let Some((plan, r)) = self
            .plans
            .iter()
            .find_map(|p| p.ready.as_ref().map(|r| (p, r)))
        else {
            return serde_json::Value::Null;
        };
        json!({
            "candidate": "par-deps",
            "sequential": plan.sequential,
            "waits_per_scan": r.waits(),
            "waits_per_worker": r.waits_per_worker,
            "items_per_worker": r.items_per_worker,
            "publishing_per_worker": r.publishing_per_worker,
            "cross_dependences": r.cross_dependences,
            "critical_path": r.critical_path,
            "partition": r.partition.name(),
            "wait_cost": plan.config.wait_cost,
            "modelled_steps": {"sequential": plan.est_sequential, "plan": plan.est_plan},
        })
    }

    /// What a run chose, in words: the candidates' measured times, the scans each ran, and
    /// every switch (`plc-deps run --explain`, after the run).
    pub fn explain_run(&self, log: &RunLog) -> String {
        let mut s = String::new();
        let total: u64 = log.scans_on.iter().sum();
        let _ = writeln!(
            s,
            "plan choice (--plan {}) over {}:",
            self.kind.name(),
            count(total, "scan")
        );
        for (i, name) in log.candidates.iter().enumerate() {
            let est = log.estimates[i].map_or("not measured".to_string(), |ns| {
                format!("measured {} per scan", ns_text(ns))
            });
            let _ = writeln!(s, "  {name}: {}, {est}", count(log.scans_on[i], "scan"));
        }
        if log.switches.is_empty() {
            let _ = writeln!(
                s,
                "  no switch: {} ran throughout",
                log.candidates[log.last]
            );
        }
        for sw in &log.switches {
            let _ = writeln!(
                s,
                "  switch at scan {}: {} -> {} ({})",
                sw.scan, log.candidates[sw.from], log.candidates[sw.to], sw.why
            );
        }
        explain_windows(&mut s, log);
        s
    }

    /// Whether candidate `i` is the sequential walk.
    pub fn is_sequential(&self, i: usize) -> bool {
        self.candidates[i] == Candidate::Sequential
    }

    /// The plan as JSON (`plc-deps run --explain --format json`).
    pub fn explain_json(&self) -> serde_json::Value {
        let plan = &self.plans[0];
        let (seq, est) = plan.estimates();
        json!({
            "kind": self.kind.name(),
            "candidates": self.names,
            "sequential_fallback": self.sequential_reason(),
            "threads": plan.threads,
            "sequential": plan.sequential,
            "barrier_cost": plan.config.barrier_cost,
            "item_cost": plan.config.item_cost,
            "line_cost": plan.config.line_cost,
            "line_cost_source": line_source(plan.config.line_cost_source),
            "modelled_steps": {"sequential": seq, "plan": est},
            "phases": plan.phase_count(),
            "parallel_phases": plan.parallel_phases(),
            "barriers_per_scan": plan.barriers_per_scan(),
            "slots": self.machine.state_size().div_ceil(8),
            "state_bytes": self.machine.state_size(),
            "layout_groups": self.layout_groups,
            "decision_slots": plan.decision_slots,
            "remote_lines": {"reads": plan.remote_lines().0, "writes": plan.remote_lines().1},
            "deps": self.deps_json(),
            "exchange": self.exchanges.iter().zip(&self.own).find_map(|(x, o)| x.as_ref().map(|x| json!({
                "words": x.words(),
                "lines": x.lines(),
                "early_items": x.early_items().0,
                "items": x.early_items().1,
                "own_layout": o.as_ref().map(|o| json!({
                    "layout_groups": o.groups,
                    "state_bytes": o.machine.state_size(),
                })),
            }))),
            "levels": plan.levels.iter().map(|lp| json!({
                "tasks": lp.tasks,
                "cost": lp.cost,
                "parallel": lp.parallel,
                "makespan": lp.makespan,
                "slicing": if lp.parallel { Some(lp.slicing) } else { None },
                "compared": lp.compared.iter().map(|&(name, m)| (name.to_string(), json!(m))).collect::<serde_json::Map<_, _>>(),
                "workers": lp.workers.iter().enumerate().map(|(w, &(t, i, c))| json!({"tasks": t, "items": i, "cost": c, "lines": lp.lines.get(w).copied().unwrap_or(0)})).collect::<Vec<_>>(),
                "reason": lp.reason,
            })).collect::<Vec<_>>(),
        })
    }
}

/// The run's logged windows, one line each: a measurement's runs of one-scan windows of one
/// candidate are joined into one line (the visit: its scans' times in order, the first a warm-up).
fn explain_windows(s: &mut String, log: &RunLog) {
    if log.windows.is_empty() {
        return;
    }
    let _ = writeln!(
        s,
        "  windows (first scan, candidate, scans: median / min of the timed scans){}:",
        if log.windows_unlogged > 0 {
            format!(", {} more not logged", log.windows_unlogged)
        } else {
            String::new()
        }
    );
    let mut i = 0;
    while i < log.windows.len() {
        let w = &log.windows[i];
        let name = &log.candidates[w.candidate];
        if w.measuring {
            let mut j = i;
            let mut times = Vec::new();
            while j < log.windows.len()
                && log.windows[j].measuring
                && log.windows[j].candidate == w.candidate
                && log.windows[j].scan == w.scan + (j - i) as u64
            {
                times.extend(log.windows[j].median_ns.map(ns_text));
                j += 1;
            }
            let _ = writeln!(s, "    {:>6} {name} measured: {}", w.scan, times.join(", "));
            i = j;
        } else {
            let t = match (w.median_ns, w.min_ns) {
                (Some(m), Some(n)) => format!("{} / {}", ns_text(m), ns_text(n)),
                _ => "not timed".to_string(),
            };
            let _ = writeln!(s, "    {:>6} {name} x{}: {t}", w.scan, w.scans);
            i += 1;
        }
    }
}

/// A time in ns as text (`850 ns`, `12.3 µs`, `4.56 ms`).
pub fn ns_text(ns: u64) -> String {
    let f = ns as f64;
    if f >= 1e6 {
        format!("{:.2} ms", f / 1e6)
    } else if f >= 1e3 {
        format!("{:.1} µs", f / 1e3)
    } else {
        format!("{ns} ns")
    }
}

/// The run log as JSON (the `plan_run` of `plc-deps run --format json`); `deterministic`
/// zeroes what depends on timing (measured times; scans per candidate and switches when there
/// is more than one candidate). With a dependence-driven candidate, `waits_per_scan` gives its
/// waits per scan (a property of the plan, not of timing). Not deterministic: `windows` and
/// `windows_unlogged`, the windows of scans as they ran with their times.
pub fn run_log_json(log: &RunLog, deterministic: bool) -> serde_json::Value {
    let timed = deterministic && log.candidates.len() > 1;
    let mut doc = json!({
        "candidates": log.candidates,
        "scans": log.candidates.iter().zip(&log.scans_on)
            .map(|(n, &k)| (n.clone(), json!(if timed { 0 } else { k })))
            .collect::<serde_json::Map<_, _>>(),
        "ns_per_scan": log.candidates.iter().zip(&log.estimates)
            .map(|(n, e)| (n.clone(), if deterministic { json!(0) } else { json!(e) }))
            .collect::<serde_json::Map<_, _>>(),
        "last": if timed { serde_json::Value::Null } else { json!(log.candidates[log.last]) },
        "switches": if timed { Vec::new() } else {
            log.switches.iter().map(|s| json!({
                "scan": s.scan, "from": log.candidates[s.from], "to": log.candidates[s.to], "why": s.why,
            })).collect::<Vec<_>>()
        },
    });
    // Timing only: left out of the deterministic form.
    if !deterministic {
        doc["windows"] = json!(log
            .windows
            .iter()
            .map(|w| json!({
                "scan": w.scan,
                "candidate": log.candidates[w.candidate],
                "scans": w.scans,
                "measuring": w.measuring,
                "timed": w.timed,
                "median_ns": w.median_ns,
                "min_ns": w.min_ns,
            }))
            .collect::<Vec<_>>());
        doc["windows_unlogged"] = json!(log.windows_unlogged);
    }
    // Only with a dependence-driven candidate: the waits per scan of each such candidate.
    let waits: serde_json::Map<String, serde_json::Value> = log
        .candidates
        .iter()
        .zip(&log.waits)
        .filter_map(|(n, w)| w.map(|w| (n.clone(), json!(w))))
        .collect();
    if !waits.is_empty() {
        doc["waits_per_scan"] = serde_json::Value::Object(waits);
    }
    doc
}

/// Where the line cost came from, in words.
fn line_source(src: LineCostSource) -> String {
    match src {
        LineCostSource::Default => "default".into(),
        LineCostSource::GaveUp => {
            "default: the measurement gave up, the other core was busy".into()
        }
        LineCostSource::Given => "given".into(),
        LineCostSource::Measured {
            remote_tenths_ns,
            local_tenths_ns,
        } => format!(
            "measured: a line from the other core {:.1} ns, from the own cache {:.1} ns",
            remote_tenths_ns as f64 / 10.0,
            local_tenths_ns as f64 / 10.0
        ),
    }
}

/// `1 task`, `2 tasks`.
fn count(n: impl TryInto<u64>, one: &str) -> String {
    let n: u64 = n.try_into().unwrap_or(u64::MAX);
    format!("{n} {one}{}", if n == 1 { "" } else { "s" })
}

/// The dependence-driven plan's partition, in words.
fn partition_words(p: DepsPartition) -> &'static str {
    match p {
        DepsPartition::OneWay => {
            "one-way partition: each worker depends only on the workers before it"
        }
        DepsPartition::Levels | DepsPartition::Auto => "each level sliced as the levelled plan",
    }
}

/// The primary plan's levels (the first 500): tasks, cost, and for a parallel level its
/// slicing, makespan, moved lines and each worker's share.
fn explain_levels(plan: &Plan, s: &mut String) {
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
            let moved: u64 = lp.lines.iter().sum();
            let others: Vec<String> = lp
                .compared
                .iter()
                .filter(|(name, _)| *name != lp.slicing)
                .map(|(name, m)| format!("{name} {m}"))
                .collect();
            let others = if others.is_empty() {
                String::new()
            } else {
                format!(" [{}]", others.join(", "))
            };
            let _ = write!(
                s,
                " ({}, makespan {m}{others}, {} moved):",
                lp.slicing,
                count(moved, "line")
            );
            for (w, (tasks, items, cost)) in lp.workers.iter().enumerate() {
                let _ = write!(
                    s,
                    " w{w} {}/{}/{cost}+{}",
                    count(*tasks, "task"),
                    count(*items, "item"),
                    count(lp.lines.get(w).copied().unwrap_or(0), "line")
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
}
