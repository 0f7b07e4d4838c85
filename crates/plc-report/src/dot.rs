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
//! Graphviz cannot lay out a graph of tens of thousands of nodes usefully: the command refuses to
//! draw more than [`MAX_RUNGS`] rungs before rendering (docs/report.md). A bigger program is drawn
//! a part at a time ([`Selection`]: one POU, or a range of rungs in file order): levels keep the
//! numbers of the whole schedule, and the far end of an edge that leaves the selection is drawn as
//! a grey dashed node outside the ranks, so what the part depends on stays visible.
//!
//! Deliberately not here: layout (Graphviz's), and which rungs exist (the selection is resolved
//! against the program by [`select_rungs`] before anything is rendered).

use super::document::{DependenceEntry, Report, TaskName};
use super::View;
use plc_model::Program;
use std::collections::{HashMap, HashSet};
use std::io::{self, Write};

/// The largest program the DOT report draws.
pub const MAX_RUNGS: usize = 2000;

/// `s` as a DOT string: quotes and backslashes escaped, and every control character but the
/// line feed (which callers turn into `\n`) written as its Rust escape (`\u{1b}`, shown as
/// text), so that no file text can end the string or reach a terminal raw.
fn quote(s: &str) -> String {
    let s = s.replace('\\', "\\\\").replace('"', "\\\"");
    let mut out = String::with_capacity(s.len() + 2);
    out.push('"');
    for c in s.chars() {
        if c.is_control() && c != '\n' {
            out.extend(c.escape_default().flat_map(|e| {
                let doubled = if e == '\\' { Some('\\') } else { None };
                std::iter::once(e).chain(doubled)
            }));
        } else {
            out.push(c);
        }
    }
    out.push('"');
    out
}

/// The part of a program the DOT report draws.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub enum Selection {
    /// Every rung.
    #[default]
    Whole,
    /// The rungs of one POU (the program, a subroutine, a function block instance).
    Pou(String),
    /// The rungs from `first` to `last` in file order, both included (`last` = `first` for one).
    Rungs { first: String, last: String },
}

/// The ids of the rungs `selection` names in `p`, in file order; `None` for the whole program.
/// An unknown POU or rung id, or a range whose end comes before its start, is an error message.
pub fn select_rungs(p: &Program, selection: &Selection) -> Result<Option<HashSet<String>>, String> {
    let position = |id: &str| {
        p.rungs()
            .iter()
            .position(|r| r.id == id)
            .ok_or_else(|| format!("--rungs: no rung `{id}` in the program"))
    };
    let range = match selection {
        Selection::Whole => return Ok(None),
        Selection::Pou(name) => match p.pous().iter().find(|u| u.name == *name) {
            Some(u) => u.rungs.start as usize..u.rungs.end as usize,
            None => {
                let names: Vec<&str> = p.pous().iter().map(|u| u.name.as_str()).collect();
                return Err(format!(
                    "--pou: no POU `{name}` in the program (POUs: {})",
                    names.join(", ")
                ));
            }
        },
        Selection::Rungs { first, last } => {
            let (a, b) = (position(first)?, position(last)?);
            if b < a {
                return Err(format!(
                    "--rungs {first}..{last}: `{last}` comes before `{first}` in the program"
                ));
            }
            a..b + 1
        }
    };
    Ok(Some(
        p.rungs()[range].iter().map(|r| r.id.clone()).collect(),
    ))
}

/// One drawn edge: every dependence between two rungs.
struct Edge<'a> {
    from: &'a str,
    to: &'a str,
    /// `flow x`, `anti y`, `control`, in listing order, without repeats.
    labels: Vec<String>,
    kinds: Vec<&'static str>,
}

/// The edges with at least one end that `drawn` keeps.
fn merged_edges<'a>(r: &Report<'a>, drawn: impl Fn(&str) -> bool) -> Vec<Edge<'a>> {
    let mut edges: Vec<Edge<'a>> = Vec::new();
    let mut index: HashMap<(&'a str, &'a str), usize> = HashMap::new();
    for d in r.dependences.iter() {
        let (kind, from, to, var) = match d {
            DependenceEntry::Data {
                kind,
                from,
                to,
                var,
            } => (kind, from, to, Some(var)),
            DependenceEntry::Control { kind, from, to, .. } => (kind, from, to, None),
        };
        if !drawn(from) && !drawn(to) {
            continue;
        }
        let label = match var {
            Some(var) => format!("{kind} {var}"),
            None => "control".into(),
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

/// Writes the dependence graph ranked by `view` (`View::All` draws the combined schedule), of
/// every rung or only of those in `only` (from [`select_rungs`]).
pub fn render_dot(
    r: &Report,
    view: View,
    only: Option<&HashSet<String>>,
    out: &mut impl Write,
) -> io::Result<()> {
    let drawn = |x: &str| only.is_none_or(|s| s.contains(x));
    writeln!(out, "digraph {} {{", quote(r.program))?;
    out.write_all(b"  graph [rankdir=TB, newrank=true, nodesep=0.3, ranksep=0.5];\n")?;
    if let Some(s) = only {
        writeln!(
            out,
            "  graph [labelloc=t, label={}];",
            quote(&format!(
                "{} of {} rungs drawn; grey dashed: the far end of an edge leaving them",
                super::text::thousands(s.len()),
                super::text::thousands(r.summary.rungs)
            ))
        )?;
    }
    out.write_all(b"  node [shape=box, style=rounded, fontname=\"Helvetica\"];\n")?;
    out.write_all(b"  edge [fontname=\"Helvetica\", fontsize=10];\n")?;
    let all_rungs: Vec<_> = r.rungs.iter().collect();
    let main = all_rungs.first().map(|e| e.pou).unwrap_or_default();
    let rungs: Vec<_> = all_rungs.into_iter().filter(|e| drawn(e.id)).collect();
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
    // Levels keep the whole schedule's numbers; a level with no drawn rung is left out.
    let mut shown_levels = Vec::new();
    for (l, g) in groups.iter().enumerate() {
        if !g.iter().any(|x| drawn(x)) {
            continue;
        }
        shown_levels.push(l + 1);
        writeln!(out, "  \"{what} {}\" [shape=plaintext, style=\"\"];", l + 1)?;
        write!(out, "  {{ rank=same; \"{what} {}\";", l + 1)?;
        for x in g.iter().filter(|x| drawn(x)) {
            write!(out, " {};", quote(x))?;
        }
        out.write_all(b" }\n")?;
    }
    for w in shown_levels.windows(2) {
        writeln!(
            out,
            "  \"{what} {}\" -> \"{what} {}\" [style=invis];",
            w[0], w[1]
        )?;
    }
    if view != View::Paper {
        for (i, lp) in r.loops.iter().enumerate() {
            let members: Vec<String> = lp
                .rungs
                .iter()
                .filter(|x| drawn(x))
                .map(|x| format!("{};", quote(x)))
                .collect();
            if members.is_empty() {
                continue;
            }
            writeln!(
                out,
                "  subgraph \"cluster_loop{i}\" {{ label=\"loop task\"; style=dashed; {} }}",
                members.join(" ")
            )?;
        }
        // Subroutine rungs run inside their caller's task; unreachable rungs never run.
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
        let never: Vec<&&str> = r.schedule.unreachable.iter().filter(|x| drawn(x)).collect();
        if !never.is_empty() {
            let members: Vec<String> = never.iter().map(|x| format!("{};", quote(x))).collect();
            writeln!(
                out,
                "  subgraph \"cluster_never\" {{ label=\"never runs\"; style=dotted; {} }}",
                members.join(" ")
            )?;
        }
    }
    for e in &rungs {
        let label = if e.pou == main {
            quote(e.id)
        } else {
            quote(&format!("{}\n({})", e.id, e.pou)).replace('\n', "\\n")
        };
        writeln!(out, "  {} [label={}];", quote(e.id), label)?;
    }
    let edges = merged_edges(r, drawn);
    let mut elsewhere = HashSet::new();
    for x in edges.iter().flat_map(|e| [e.from, e.to]) {
        if drawn(x) || !elsewhere.insert(x) {
            continue;
        }
        writeln!(
            out,
            "  {} [style=\"rounded,dashed\", color=grey, fontcolor=grey];",
            quote(x)
        )?;
    }
    for e in edges {
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

#[cfg(test)]
mod quote_tests {
    #[test]
    fn quoted_text_keeps_no_control_character() {
        assert_eq!(
            super::quote("a\"b\\c\u{1b}d\ne"),
            "\"a\\\"b\\\\c\\\\u{1b}d\ne\""
        );
    }
}
