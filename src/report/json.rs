//! The JSON report (normative keys: docs/report.md). Keys named by the issue that introduced the
//! report (`program`, `rungs[].id/in/out`, `dependences[].kind/from/to/var`, `cfg.edges[]
//! .from/to/label`, `ipdom`, `levels.data/control/combined`, `cycles.*`, `cost.work/span/
//! makespan`) are a contract: add fields, never rename or drop these.

use super::*;
use crate::analysis::{Branch, ControlCause, Successor};
use serde_json::{json, Map, Value as Json};

fn label(b: Option<Branch>) -> Option<&'static str> {
    b.map(|b| match b {
        Branch::T => "T",
        Branch::F => "F",
    })
}

/// Renders the full analysis as pretty-printed JSON (with a trailing newline).
pub fn render_json(p: &Program, a: &Analysis) -> String {
    let id = |r: RungId| Json::from(p.rung(r).id.as_str());
    let var = |v: VarId| Json::from(p.var(v).name.as_str());
    let rungs: Vec<Json> = p
        .rung_ids()
        .map(|r| {
            let rung = p.rung(r);
            let mut o = Map::new();
            o.insert("id".into(), id(r));
            o.insert("pou".into(), p.pou(rung.pou).name.as_str().into());
            if let Some(l) = &rung.label {
                o.insert("label".into(), l.as_str().into());
            }
            o.insert(
                "in".into(),
                a.accesses.ins(r).iter().map(|&v| var(v)).collect(),
            );
            o.insert(
                "out".into(),
                a.accesses.outs(r).iter().map(|&v| var(v)).collect(),
            );
            o.insert("cost".into(), a.rung_costs[r.index()].into());
            Json::Object(o)
        })
        .collect();
    let edge_json = |i: u32| {
        let e = &a.cfg.edges[i as usize];
        let mut o = Map::new();
        o.insert("from".into(), node_name(p, e.from).into());
        o.insert("to".into(), node_name(p, e.to).into());
        if let Some(l) = label(e.label) {
            o.insert("label".into(), l.into());
        }
        Json::Object(o)
    };
    let mut dependences: Vec<Json> = a
        .data
        .iter()
        .map(|d| json!({"kind": d.kind.name(), "from": id(RungId(d.from)), "to": id(RungId(d.to)), "var": var(d.var)}))
        .collect();
    for (from, to, cause) in paper_control_pairs(a) {
        let mut o = Map::new();
        o.insert("kind".into(), "control".into());
        o.insert("from".into(), id(from));
        o.insert("to".into(), id(to));
        match cause {
            ControlCause::Branch { edge } => {
                o.insert("cause".into(), "branch".into());
                o.insert("edge".into(), edge_json(edge));
            }
            ControlCause::Instance { var: v } => {
                o.insert("cause".into(), "instance".into());
                o.insert("var".into(), var(v));
            }
        }
        dependences.push(Json::Object(o));
    }
    let edges: Vec<Json> = a
        .cfg
        .edges
        .iter()
        .map(|e| {
            let mut o = Map::new();
            o.insert("from".into(), node_name(p, e.from).into());
            o.insert("to".into(), node_name(p, e.to).into());
            if let Some(l) = label(e.label) {
                o.insert("label".into(), l.into());
            }
            o.insert("kind".into(), e.kind.name().into());
            Json::Object(o)
        })
        .collect();
    let mut ipdom = Map::new();
    for n in std::iter::once(a.cfg.start()).chain(0..p.rungs.len() as u32) {
        if let Some(d) = a.post_dominators.immediate(n) {
            ipdom.insert(node_name(p, n).into(), node_name(p, d).into());
        }
    }
    let groups = |levels: &[u32]| -> Json {
        rung_groups(levels)
            .into_iter()
            .map(|g| g.into_iter().map(id).collect::<Json>())
            .collect()
    };
    let combined: Json = combined_groups(a)
        .into_iter()
        .map(|level| {
            level
                .into_iter()
                .map(|task| {
                    if task.len() == 1 {
                        id(task[0])
                    } else {
                        task.into_iter().map(id).collect()
                    }
                })
                .collect::<Json>()
        })
        .collect();
    let s = &a.schedule;
    let tasks: Vec<Json> = s
        .tasks
        .iter()
        .map(|t| {
            let guard: Vec<Json> = t
                .guard
                .iter()
                .map(|g| {
                    let succ = match g.successor {
                        Successor::Task(x) => id(s.head(x)),
                        Successor::Stop => "STOP".into(),
                    };
                    json!({"controller": id(s.head(g.controller)), "successor": succ})
                })
                .collect();
            json!({
                "rungs": t.rungs.iter().map(|&r| id(r)).collect::<Vec<_>>(),
                "loop": t.is_loop,
                "level": t.level + 1,
                "entries": t.entries.iter().map(|&r| id(r)).collect::<Vec<_>>(),
                "guard": guard,
            })
        })
        .collect();
    let count = |levels: &[u32]| levels.iter().map(|&l| l + 1).max().unwrap_or(0);
    let cores = |v: &[(u32, u64)]| -> Json {
        let mut o = Map::new();
        for (p, m) in v {
            o.insert(p.to_string(), (*m).into());
        }
        Json::Object(o)
    };
    let c = &a.cost;
    let differences: Vec<Json> = differences(p, a)
        .into_iter()
        .map(|d| {
            json!({
                "rung": id(d.rung),
                "data_level": d.data_level + 1,
                "control_level": d.control_level + 1,
                "combined_level": d.combined_level.map(|l| l + 1),
                "reasons": d.reasons,
            })
        })
        .collect();
    let networks: Vec<Json> = networks(p, a)
        .into_iter()
        .map(|n| {
            json!({
                "pou": p.pou(n.pou).name,
                "id": n.id,
                "rungs": n.rungs.iter().map(|&r| id(r)).collect::<Vec<_>>(),
                "in": n.ins.iter().map(|&v| var(v)).collect::<Vec<_>>(),
                "out": n.outs.iter().map(|&v| var(v)).collect::<Vec<_>>(),
            })
        })
        .collect();
    let mut report = json!({
        "program": p.name,
        "rungs": rungs,
        "dependences": dependences,
        "self_control": self_controlled(a).into_iter().map(id).collect::<Vec<_>>(),
        "cfg": {"edges": edges},
        "ipdom": ipdom,
        "levels": {"data": groups(&a.data_levels), "control": groups(&a.control_levels), "combined": combined},
        "cycles": {
            "before": p.rungs.len(),
            "data": count(&a.data_levels),
            "control": count(&a.control_levels),
            "combined": s.levels.len(),
        },
        "cost": {
            "work": c.work,
            "span": c.span,
            "ideal_speedup": if c.span == 0 { 0.0 } else { round3(c.work as f64 / c.span as f64) },
            "makespan": cores(&c.makespan),
            "level_makespan": cores(&c.level_makespan),
        },
        "schedule": {"tasks": tasks, "unreachable": s.unreachable.iter().map(|&r| id(r)).collect::<Vec<_>>()},
        "differences": differences,
        "warnings": a.warnings.iter().map(|w| warning_text(p, w)).collect::<Vec<_>>(),
    });
    if !networks.is_empty() {
        report["networks"] = Json::Array(networks);
    }
    let mut out = serde_json::to_string_pretty(&report).expect("JSON values always serialise");
    out.push('\n');
    out
}

fn round3(x: f64) -> f64 {
    (x * 1000.0).round() / 1000.0
}
