//! The text report: aligned tables for a terminal, in the order a control engineer reads them —
//! the verdict (cycles before and after) first, then the levels, then the evidence.

use super::*;
use crate::analysis::{Branch, ControlCause, DepKind, Successor};
use std::fmt::Write;

/// A plain table: a header row and rows of cells, rendered left-aligned with two spaces between
/// columns and no trailing spaces.
struct Table {
    rows: Vec<Vec<String>>,
}

impl Table {
    fn new(header: &[&str]) -> Table {
        Table {
            rows: vec![header.iter().map(|h| h.to_string()).collect()],
        }
    }
    fn row(&mut self, cells: Vec<String>) {
        self.rows.push(cells);
    }
    fn render(&self, out: &mut String) {
        let cols = self.rows.iter().map(Vec::len).max().unwrap_or(0);
        let mut width = vec![0; cols];
        for r in &self.rows {
            for (i, c) in r.iter().enumerate() {
                width[i] = width[i].max(c.chars().count());
            }
        }
        for r in &self.rows {
            let mut line = String::from("  ");
            for (i, c) in r.iter().enumerate() {
                line.push_str(c);
                if i + 1 < r.len() {
                    line.extend(std::iter::repeat_n(' ', width[i] - c.chars().count() + 2));
                }
            }
            out.push_str(line.trim_end());
            out.push('\n');
        }
    }
}

fn join<T: AsRef<str>>(items: impl IntoIterator<Item = T>, sep: &str) -> String {
    let v: Vec<String> = items.into_iter().map(|s| s.as_ref().to_owned()).collect();
    v.join(sep)
}

/// Renders the report as text. `view` selects the levellings shown.
pub fn render_text(p: &Program, a: &Analysis, view: View) -> String {
    let paper = view != View::Combined;
    let combined = view != View::Paper;
    let id = |r: RungId| p.rung(r).id.as_str();
    let mut o = String::new();
    let m = p.rungs.len();
    let main = p.main().rungs.len();
    let _ = writeln!(
        o,
        "{}: {} rung{}{}",
        p.name,
        m,
        if m == 1 { "" } else { "s" },
        if main == m {
            String::new()
        } else {
            format!(" ({main} in the main program, {} in subroutines)", m - main)
        }
    );
    let count = |levels: &[u32]| levels.iter().map(|&l| l as usize + 1).max().unwrap_or(0);
    let (nd, nc, nk) = (
        count(&a.data_levels),
        count(&a.control_levels),
        a.schedule.levels.len(),
    );
    let pct = |n: usize| {
        if m == 0 {
            0.0
        } else {
            100.0 * (m as f64 - n as f64) / m as f64
        }
    };

    o.push_str("\nScan cycles (one rung per cycle before; one level per cycle after)\n");
    let mut t = Table::new(&["schedule", "cycles", "saved"]);
    t.row(vec!["sequential".into(), m.to_string(), String::new()]);
    if paper {
        t.row(vec![
            "paper data view".into(),
            nd.to_string(),
            format!("{:.0} %", pct(nd)),
        ]);
        t.row(vec![
            "paper control view".into(),
            nc.to_string(),
            format!("{:.0} %", pct(nc)),
        ]);
    }
    if combined {
        t.row(vec![
            "combined (correct)".into(),
            nk.to_string(),
            format!("{:.0} %", pct(nk)),
        ]);
    }
    t.render(&mut o);

    o.push_str(
        "\nLevels (rungs in one level may run at the same time; {…} is a loop run as one task)\n",
    );
    let data_g = rung_groups(&a.data_levels);
    let ctrl_g = rung_groups(&a.control_levels);
    let comb_g = combined_groups(a);
    let mut header = vec!["level"];
    if paper {
        header.extend(["paper data view", "paper control view"]);
    }
    if combined {
        header.push("combined");
    }
    let mut t = Table::new(&header);
    let rows = if paper {
        data_g.len().max(ctrl_g.len())
    } else {
        0
    }
    .max(if combined { comb_g.len() } else { 0 });
    let names = |g: Option<&Vec<RungId>>| {
        g.map(|g| join(g.iter().map(|&r| id(r)), " "))
            .unwrap_or_default()
    };
    for l in 0..rows {
        let mut row = vec![(l + 1).to_string()];
        if paper {
            row.push(names(data_g.get(l)));
            row.push(names(ctrl_g.get(l)));
        }
        if combined {
            row.push(
                comb_g
                    .get(l)
                    .map(|tasks| {
                        join(
                            tasks.iter().map(|task| {
                                if task.len() == 1 {
                                    id(task[0]).to_owned()
                                } else {
                                    format!("{{{}}}", join(task.iter().map(|&r| id(r)), " "))
                                }
                            }),
                            " ",
                        )
                    })
                    .unwrap_or_default(),
            );
        }
        t.row(row);
    }
    t.render(&mut o);

    if combined {
        let c = &a.cost;
        let ratio = |w: u64, s: u64| if s == 0 { 0.0 } else { w as f64 / s as f64 };
        let _ = writeln!(
            o,
            "\nCost of the combined schedule (model in docs/report.md)\n  work W = {}, span S = {}, ideal speed-up W/S = {:.2}",
            c.work,
            c.span,
            ratio(c.work, c.span)
        );
        let mut t = Table::new(&[
            "cores",
            "makespan",
            "speed-up",
            "level by level",
            "speed-up",
        ]);
        for ((cores, ms), (_, lm)) in c.makespan.iter().zip(&c.level_makespan) {
            t.row(vec![
                cores.to_string(),
                ms.to_string(),
                format!("{:.2}", ratio(c.work, *ms)),
                lm.to_string(),
                format!("{:.2}", ratio(c.work, *lm)),
            ]);
        }
        t.render(&mut o);
    }

    o.push_str("\nRungs (IN: may read, OUT: may write; calls include their subroutine)\n");
    let mut t = Table::new(&["rung", "pou", "IN", "OUT", "cost"]);
    for r in p.rung_ids() {
        let v = |vs: &[VarId]| {
            if vs.is_empty() {
                "-".to_string()
            } else {
                join(vs.iter().map(|&x| p.var(x).name.as_str()), " ")
            }
        };
        t.row(vec![
            id(r).into(),
            p.pou(p.rung(r).pou).name.clone(),
            v(a.accesses.ins(r)),
            v(a.accesses.outs(r)),
            a.rung_costs[r.index()].to_string(),
        ]);
    }
    t.render(&mut o);

    let nets = networks(p, a);
    if !nets.is_empty() {
        o.push_str("\nFBD networks (IN/OUT: the union over the network's block rungs)\n");
        let mut t = Table::new(&["network", "pou", "rungs", "IN", "OUT"]);
        for n in &nets {
            let v = |vs: &[VarId]| {
                if vs.is_empty() {
                    "-".to_string()
                } else {
                    join(vs.iter().map(|&x| p.var(x).name.as_str()), " ")
                }
            };
            let first = id(n.rungs[0]);
            let last = id(*n.rungs.last().expect("a network has rungs"));
            let span = if n.rungs.len() == 1 {
                first.to_owned()
            } else {
                format!("{first} .. {last} ({})", n.rungs.len())
            };
            t.row(vec![
                n.id.clone(),
                p.pou(n.pou).name.clone(),
                span,
                v(&n.ins),
                v(&n.outs),
            ]);
        }
        t.render(&mut o);
    }

    let n_of = |k: DepKind| a.data.iter().filter(|d| d.kind == k).count();
    let _ = writeln!(
        o,
        "\nData dependences ({} flow, {} anti, {} output)",
        n_of(DepKind::Flow),
        n_of(DepKind::Anti),
        n_of(DepKind::Output)
    );
    if a.data.is_empty() {
        o.push_str("  none\n");
    } else {
        let mut t = Table::new(&["from", "to", "kind", "var"]);
        let mut sorted = a.data.clone();
        sorted.sort_unstable_by_key(|d| (d.from, d.to, d.kind, d.var));
        for d in sorted {
            t.row(vec![
                id(RungId(d.from)).into(),
                id(RungId(d.to)).into(),
                dep_kind_name(d.kind).into(),
                p.var(d.var).name.clone(),
            ]);
        }
        t.render(&mut o);
    }

    let cpairs = paper_control_pairs(a);
    let _ = writeln!(o, "\nControl dependences ({})", cpairs.len());
    if cpairs.is_empty() {
        o.push_str("  none\n");
    } else {
        let mut t = Table::new(&["from", "to", "because of"]);
        for (f, to, cause) in &cpairs {
            let why = match cause {
                ControlCause::Branch { edge } => {
                    let e = &a.cfg.edges[*edge as usize];
                    format!(
                        "edge {} → {}{} ({})",
                        node_name(p, e.from),
                        node_name(p, e.to),
                        label_suffix(e.label),
                        e.kind.name()
                    )
                }
                ControlCause::Instance { var } => format!(
                    "reads {} (timer/counter, counted as control by the paper)",
                    p.var(*var).name
                ),
            };
            t.row(vec![id(*f).into(), id(*to).into(), why]);
        }
        t.render(&mut o);
    }
    let selfs = self_controlled(a);
    if !selfs.is_empty() {
        let _ = writeln!(
            o,
            "  control dependent on themselves (loop heads, calls; ignored for levels): {}",
            join(selfs.iter().map(|&r| id(r)), " ")
        );
    }

    o.push_str("\nControl-flow graph\n");
    let mut t = Table::new(&["from", "to", "label", "kind"]);
    for e in &a.cfg.edges {
        t.row(vec![
            node_name(p, e.from).into(),
            node_name(p, e.to).into(),
            label_suffix(e.label).trim().trim_matches(['(', ')']).into(),
            e.kind.name().into(),
        ]);
    }
    t.render(&mut o);

    o.push_str("\nPost-dominator tree (ipdom = immediate post-dominator; the root is STOP)\n");
    let mut t = Table::new(&["node", "ipdom", "children"]);
    for n in std::iter::once(a.cfg.start())
        .chain(0..m as u32)
        .chain(std::iter::once(a.cfg.stop()))
    {
        let ip = a
            .post_dominators
            .immediate(n)
            .map(|d| node_name(p, d).to_owned())
            .unwrap_or_else(|| "-".into());
        let kids = join(
            a.post_dominators
                .children(n)
                .iter()
                .map(|&k| node_name(p, k)),
            " ",
        );
        t.row(vec![node_name(p, n).into(), ip, kids]);
    }
    t.render(&mut o);

    if combined {
        let s = &a.schedule;
        o.push_str(
            "\nCombined schedule tasks (a task runs when its guard holds; \"always\" otherwise)\n",
        );
        let mut t = Table::new(&["level", "task", "guard"]);
        for (l, level) in s.levels.iter().enumerate() {
            for &ti in level {
                let task = &s.tasks[ti as usize];
                let name = if task.rungs.len() == 1 {
                    id(task.rungs[0]).to_owned()
                } else {
                    format!("{{{}}}", join(task.rungs.iter().map(|&r| id(r)), " "))
                };
                let guard = if task.guard.is_empty() {
                    "always".to_string()
                } else {
                    join(
                        task.guard.iter().map(|g| {
                            let to = match g.successor {
                                Successor::Task(x) => id(s.head(x)).to_owned(),
                                Successor::Stop => "STOP".into(),
                            };
                            format!("{} went to {}", id(s.head(g.controller)), to)
                        }),
                        " or ",
                    )
                };
                t.row(vec![(l + 1).to_string(), name, guard]);
            }
        }
        t.render(&mut o);
        if paper {
            let diffs = differences(p, a);
            o.push_str("\nWhere the combined schedule differs from the paper's views\n");
            if diffs.is_empty() {
                o.push_str("  nowhere: every rung is at the same level in all three views\n");
            } else {
                let mut t = Table::new(&["rung", "data", "control", "combined", "why"]);
                for d in diffs {
                    t.row(vec![
                        id(d.rung).into(),
                        (d.data_level + 1).to_string(),
                        (d.control_level + 1).to_string(),
                        d.combined_level
                            .map(|l| (l + 1).to_string())
                            .unwrap_or_else(|| "-".into()),
                        d.reasons.join("; "),
                    ]);
                }
                t.render(&mut o);
            }
        }
    }
    if !a.warnings.is_empty() {
        o.push_str("\nWarnings\n");
        for w in &a.warnings {
            let _ = writeln!(o, "  warning: {}", warning_text(p, w));
        }
    }
    o
}

fn label_suffix(l: Option<Branch>) -> &'static str {
    match l {
        Some(Branch::T) => " (T)",
        Some(Branch::F) => " (F)",
        None => "",
    }
}
