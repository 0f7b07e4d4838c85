//! The DOT report: the dependence graph for Graphviz. Rungs are nodes, ranked by level (one
//! `rank=same` subgraph per level, levels stacked top to bottom by invisible edges); flow edges
//! are solid black, anti dashed blue, output dotted red, control bold green; a loop task of the
//! combined schedule is a cluster. Output renders with `dot` without warnings (tested).

use super::*;
use crate::analysis::DepKind;
use std::fmt::Write;

fn quote(s: &str) -> String {
    format!("\"{}\"", s.replace('\\', "\\\\").replace('"', "\\\""))
}

/// Renders the dependence graph; ranks follow the combined schedule, or the paper's data view
/// for `View::Paper`.
pub fn render_dot(p: &Program, a: &Analysis, view: View) -> String {
    let mut o = String::new();
    let _ = writeln!(o, "digraph {} {{", quote(&p.name));
    o.push_str("  graph [rankdir=TB, newrank=true, nodesep=0.3, ranksep=0.5];\n");
    o.push_str("  node [shape=box, style=rounded, fontname=\"Helvetica\"];\n");
    o.push_str("  edge [fontname=\"Helvetica\", fontsize=10];\n");
    let id = |r: RungId| quote(&p.rung(r).id);
    // Ranks.
    let groups: Vec<Vec<RungId>> = if view == View::Paper {
        rung_groups(&a.data_levels)
    } else {
        let mut g: Vec<Vec<RungId>> = combined_groups(a)
            .into_iter()
            .map(|l| l.into_iter().flatten().collect())
            .collect();
        let others: Vec<RungId> = p
            .rung_ids()
            .filter(|r| a.schedule.task_of[r.index()].is_none())
            .collect();
        if !others.is_empty() {
            g.push(others);
        }
        g
    };
    for (l, g) in groups.iter().enumerate() {
        let _ = writeln!(o, "  \"level {}\" [shape=plaintext, style=\"\"];", l + 1);
        let _ = write!(o, "  {{ rank=same; \"level {}\";", l + 1);
        for &r in g {
            let _ = write!(o, " {};", id(r));
        }
        o.push_str(" }\n");
    }
    for l in 1..groups.len() {
        let _ = writeln!(o, "  \"level {}\" -> \"level {}\" [style=invis];", l, l + 1);
    }
    if view != View::Paper {
        for (i, t) in a
            .schedule
            .tasks
            .iter()
            .enumerate()
            .filter(|(_, t)| t.is_loop)
        {
            let _ = writeln!(
                o,
                "  subgraph \"cluster_loop{}\" {{ label=\"loop task\"; style=dashed; {} }}",
                i,
                t.rungs
                    .iter()
                    .map(|&r| format!("{};", id(r)))
                    .collect::<Vec<_>>()
                    .join(" ")
            );
        }
    }
    for r in p.rung_ids() {
        let rung = p.rung(r);
        let pou = if rung.pou.index() == 0 {
            String::new()
        } else {
            format!("\\n({})", p.pou(rung.pou).name)
        };
        let _ = writeln!(
            o,
            "  {} [label={}];",
            id(r),
            quote(&format!("{}{}", rung.id, pou)).replace("\\\\n", "\\n")
        );
    }
    for d in &a.data {
        let style = match d.kind {
            DepKind::Flow => "color=black",
            DepKind::Anti => "color=blue, style=dashed",
            DepKind::Output => "color=red, style=dotted",
            DepKind::Control => "color=darkgreen, style=bold",
        };
        let _ = writeln!(
            o,
            "  {} -> {} [label={}, {}];",
            id(RungId(d.from)),
            id(RungId(d.to)),
            quote(&format!("{} {}", d.kind.name(), p.var(d.var).name)),
            style
        );
    }
    for (f, t, _) in paper_control_pairs(a) {
        let _ = writeln!(
            o,
            "  {} -> {} [label=\"control\", color=darkgreen, style=bold];",
            id(f),
            id(t)
        );
    }
    o.push_str("  legend [shape=note, style=\"\", label=\"flow: black, solid\\lanti: blue, dashed\\loutput: red, dotted\\lcontrol: green, bold\\l\"];\n");
    o.push_str("}\n");
    o
}
