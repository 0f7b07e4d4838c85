//! The DOT report: the dependence graph for Graphviz, drawn for one levelling.
//!
//! Rungs are nodes, ranked by level (one `rank=same` subgraph per level, levels stacked top to
//! bottom by invisible edges). `View::Combined` ranks by the combined schedule: a loop task is a
//! dashed cluster, a subroutine's rungs (which run inside their calling rung's task, at no level
//! of their own) are a cluster per subroutine beside the ranks, and rungs that can never run a
//! cluster of their own. `View::Paper` ranks by the paper's data view. All dependences between
//! the same two rungs are one edge labelled with every kind and variable (flow solid black, anti
//! dashed blue, output dotted red, control bold green; an edge of several kinds is drawn in all
//! their colours). Output renders with `dot` without warnings (tested).
//!
//! Graphviz cannot lay out a graph of tens of thousands of nodes usefully: the command refuses a
//! program above [`MAX_RUNGS`] rungs before rendering (docs/report.md).

use super::document::{DependenceEntry, Report, TaskName};
use super::View;
use std::collections::HashMap;
use std::io::{self, Write};

/// The largest program the DOT report draws.
pub const MAX_RUNGS: usize = 2000;

fn quote(s: &str) -> String {
    format!("\"{}\"", s.replace('\\', "\\\\").replace('"', "\\\""))
}

/// One drawn edge: every dependence between two rungs.
struct Edge<'a> {
    from: &'a str,
    to: &'a str,
    /// `flow x`, `anti y`, `control`, in listing order, without repeats.
    labels: Vec<String>,
    kinds: Vec<&'static str>,
}

fn merged_edges<'a>(r: &Report<'a>) -> Vec<Edge<'a>> {
    let mut edges: Vec<Edge<'a>> = Vec::new();
    let mut index: HashMap<(&'a str, &'a str), usize> = HashMap::new();
    for d in r.dependences.iter() {
        let (kind, from, to, label) = match d {
            DependenceEntry::Data {
                kind,
                from,
                to,
                var,
            } => (kind, from, to, format!("{kind} {var}")),
            DependenceEntry::Control { kind, from, to, .. } => (kind, from, to, "control".into()),
        };
        let i = *index.entry((from, to)).or_insert_with(|| {
            edges.push(Edge {
                from,
                to,
                labels: Vec::new(),
                kinds: Vec::new(),
            });
            edges.len() - 1
        });
        let e = &mut edges[i];
        if !e.labels.contains(&label) {
            e.labels.push(label);
        }
        if !e.kinds.contains(&kind) {
            e.kinds.push(kind);
        }
    }
    edges
}

fn colour(kind: &str) -> &'static str {
    match kind {
        "flow" => "black",
        "anti" => "blue",
        "output" => "red",
        _ => "darkgreen",
    }
}

fn style(kinds: &[&str]) -> String {
    let colours: Vec<&str> = kinds.iter().map(|k| colour(k)).collect();
    let line = match kinds {
        ["anti"] => ", style=dashed",
        ["output"] => ", style=dotted",
        ["control"] => ", style=bold",
        _ => "",
    };
    format!("color=\"{}\"{line}", colours.join(":"))
}

/// Writes the dependence graph ranked by `view` (`View::All` draws the combined schedule).
pub fn render_dot(r: &Report, view: View, out: &mut impl Write) -> io::Result<()> {
    writeln!(out, "digraph {} {{", quote(r.program))?;
    out.write_all(b"  graph [rankdir=TB, newrank=true, nodesep=0.3, ranksep=0.5];\n")?;
    out.write_all(b"  node [shape=box, style=rounded, fontname=\"Helvetica\"];\n")?;
    out.write_all(b"  edge [fontname=\"Helvetica\", fontsize=10];\n")?;
    let rungs: Vec<_> = r.rungs.iter().collect();
    let (groups, what): (Vec<Vec<&str>>, &str) = if view == View::Paper {
        (r.levels.data.clone(), "data level")
    } else {
        let g = r
            .levels
            .combined
            .iter()
            .map(|l| {
                l.iter()
                    .flat_map(|t| match t {
                        TaskName::Rung(x) => vec![*x],
                        TaskName::Loop(xs) => xs.clone(),
                    })
                    .collect()
            })
            .collect();
        (g, "level")
    };
    for (l, g) in groups.iter().enumerate() {
        writeln!(out, "  \"{what} {}\" [shape=plaintext, style=\"\"];", l + 1)?;
        write!(out, "  {{ rank=same; \"{what} {}\";", l + 1)?;
        for x in g {
            write!(out, " {};", quote(x))?;
        }
        out.write_all(b" }\n")?;
    }
    for l in 1..groups.len() {
        writeln!(
            out,
            "  \"{what} {}\" -> \"{what} {}\" [style=invis];",
            l,
            l + 1
        )?;
    }
    if view != View::Paper {
        for (i, lp) in r.loops.iter().enumerate() {
            let members: Vec<String> = lp.rungs.iter().map(|x| format!("{};", quote(x))).collect();
            writeln!(
                out,
                "  subgraph \"cluster_loop{i}\" {{ label=\"loop task\"; style=dashed; {} }}",
                members.join(" ")
            )?;
        }
        // Subroutine rungs run inside their caller's task; unreachable rungs never run.
        let main = rungs.first().map(|e| e.pou).unwrap_or_default();
        let mut pous: Vec<(&str, Vec<&str>)> = Vec::new();
        for e in rungs.iter().filter(|e| e.pou != main) {
            match pous.iter_mut().find(|(p, _)| *p == e.pou) {
                Some((_, v)) => v.push(e.id),
                None => pous.push((e.pou, vec![e.id])),
            }
        }
        for (i, (pou, members)) in pous.iter().enumerate() {
            let members: Vec<String> = members.iter().map(|x| format!("{};", quote(x))).collect();
            writeln!(
                out,
                "  subgraph \"cluster_sub{i}\" {{ label={}; style=dotted; {} }}",
                quote(&format!("subroutine {pou} (runs inside its caller's task)")),
                members.join(" ")
            )?;
        }
        if !r.schedule.unreachable.is_empty() {
            let members: Vec<String> = r
                .schedule
                .unreachable
                .iter()
                .map(|x| format!("{};", quote(x)))
                .collect();
            writeln!(
                out,
                "  subgraph \"cluster_never\" {{ label=\"never runs\"; style=dotted; {} }}",
                members.join(" ")
            )?;
        }
    }
    let main = rungs.first().map(|e| e.pou).unwrap_or_default();
    for e in &rungs {
        let label = if e.pou == main {
            quote(e.id)
        } else {
            quote(&format!("{}\n({})", e.id, e.pou)).replace('\n', "\\n")
        };
        writeln!(out, "  {} [label={}];", quote(e.id), label)?;
    }
    for e in merged_edges(r) {
        writeln!(
            out,
            "  {} -> {} [label={}, {}];",
            quote(e.from),
            quote(e.to),
            quote(&e.labels.join("\n")).replace('\n', "\\n"),
            style(&e.kinds)
        )?;
    }
    out.write_all(b"  legend [shape=note, style=\"\", label=\"flow: black, solid\\lanti: blue, dashed\\loutput: red, dotted\\lcontrol: green, bold\\l\"];\n")?;
    out.write_all(b"}\n")
}
