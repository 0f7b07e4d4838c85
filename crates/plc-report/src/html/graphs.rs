//! The HTML report's CFG and post-dominator tree (Zhao & Yan, 2012: the CFG ⟨V, E, T/F,
//! START, STOP⟩ with one node per rung, and the tree rooted at STOP) as inline SVG, laid out by
//! [`super::layout`] in Rust.
//!
//! CFG edges carry their T/F label; a loop-back edge (one the layout reversed) is drawn dashed;
//! edges are coloured by kind (fallthrough, jump, call and return, loop). Tree edges run from a
//! node's immediate post-dominator down to it. Nodes carry `data-rung`, so hovering or clicking
//! one highlights that rung everywhere on the page. Graphs of more than [`MAX_GRAPH_NODES`]
//! nodes are not drawn (the page says so and points to the JSON and DOT reports).
//!
//! Deliberately not here: the layout algorithm (`layout`) and the analyses themselves.

use super::esc;
use super::ladder::text_w;
use super::layout::{layered, Layered, NODE_H};
use plc_analysis::{Analysis, Branch};
use plc_model::Program;
use std::io::{self, Write};

/// The largest CFG (nodes: rungs + START + STOP) the page draws.
pub const MAX_GRAPH_NODES: usize = 600;

fn node_widths(p: &Program) -> Vec<f64> {
    let m = p.rungs().len() as u32;
    (0..m + 2)
        .map(|n| text_w(crate::node_name(p, n)) + 14.0)
        .collect()
}

/// Writes the CFG and the post-dominator tree side by side, or why they are not drawn.
pub(super) fn write_graphs(out: &mut impl Write, p: &Program, a: &Analysis) -> io::Result<()> {
    let nodes = p.rungs().len() + 2;
    if nodes > MAX_GRAPH_NODES {
        return writeln!(
            out,
            "<p class=\"note\">The CFG and the post-dominator tree have {} nodes: more than the {} this page draws. The JSON report lists them (<code>cfg</code>, <code>ipdom</code>); <code>--format dot --rungs A..B</code> draws a part of the dependence graph.</p>",
            super::thousands(nodes),
            MAX_GRAPH_NODES
        );
    }
    let widths = node_widths(p);
    let cfg_edges: Vec<(usize, usize)> = a
        .cfg
        .edges
        .iter()
        .map(|e| (e.from.raw() as usize, e.to.raw() as usize))
        .collect();
    let cfg = layered(&widths, &cfg_edges);
    let m = p.rungs().len() as u32;
    let tree_edges: Vec<(usize, usize)> = (0..m + 2)
        .filter_map(|n| {
            a.post_dominators
                .immediate(n)
                .map(|d| (d as usize, n as usize))
        })
        .collect();
    let tree = layered(&widths, &tree_edges);
    out.write_all(b"<div class=\"graphs\">\n<figure>\n")?;
    writeln!(
        out,
        "<figcaption>Control-flow graph: {} nodes, {} edges (T/F: the branch taken; dashed: back to a loop head; {} crossings)</figcaption>",
        nodes,
        cfg_edges.len(),
        cfg.crossings
    )?;
    let labels: Vec<(&str, Option<&str>)> = a
        .cfg
        .edges
        .iter()
        .map(|e| {
            let label = e.label.map(|b| match b {
                Branch::T => "T",
                Branch::F => "F",
            });
            (e.kind.name(), label)
        })
        .collect();
    write_graph(out, p, &cfg, &widths, &labels, "cfg")?;
    out.write_all(b"</figure>\n<figure>\n")?;
    writeln!(
        out,
        "<figcaption>Post-dominator tree (rooted at STOP; each node under its immediate post-dominator)</figcaption>"
    )?;
    let plain: Vec<(&str, Option<&str>)> = tree_edges.iter().map(|_| ("tree", None)).collect();
    write_graph(out, p, &tree, &widths, &plain, "pdom")?;
    out.write_all(b"</figure>\n</div>\n")
}

fn write_graph(
    out: &mut impl Write,
    p: &Program,
    l: &Layered,
    widths: &[f64],
    labels: &[(&str, Option<&str>)],
    class: &str,
) -> io::Result<()> {
    let (w, h) = (l.width + 20.0, l.height + 20.0);
    writeln!(
        out,
        r#"<svg class="graph {class}" width="{w:.0}" height="{h:.0}" viewBox="-10 -10 {w:.0} {h:.0}">"#
    )?;
    for (pts, ((kind, label), back)) in l.edges.iter().zip(labels.iter().zip(&l.back)) {
        if pts.len() < 2 {
            continue;
        }
        let d: Vec<String> = pts.iter().map(|(x, y)| format!("{x:.1},{y:.1}")).collect();
        let dash = if *back { " back" } else { "" };
        writeln!(
            out,
            r#"<polyline class="g {kind}{dash}" points="{}" marker-end="url(#arrow)"/>"#,
            d.join(" ")
        )?;
        if let Some(t) = label {
            let (x0, y0) = pts[0];
            let (x1, y1) = pts[1];
            writeln!(
                out,
                r#"<text class="tf" x="{:.1}" y="{:.1}">{t}</text>"#,
                x0 + (x1 - x0) * 0.3 + 3.0,
                y0 + (y1 - y0) * 0.3 + 4.0
            )?;
        }
    }
    for (n, &(x, y)) in l.pos.iter().enumerate() {
        let name = crate::node_name(p, n as u32);
        let rung = if n < p.rungs().len() {
            format!(r#" data-rung="{}""#, esc(name))
        } else {
            String::new()
        };
        writeln!(
            out,
            r#"<g class="node"{rung}><rect x="{x:.1}" y="{y:.1}" width="{:.1}" height="{NODE_H}" rx="4"/><text x="{:.1}" y="{:.1}" text-anchor="middle">{}</text></g>"#,
            widths[n],
            x + widths[n] / 2.0,
            y + 15.0,
            esc(name)
        )?;
    }
    out.write_all(b"</svg>\n")
}
