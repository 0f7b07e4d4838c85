//! The HTML report's level view: the combined schedule's levels as columns of rung cards, each
//! card drawing its rung ([`super::ladder`]), with the dependence edges between cards coloured
//! by kind and labelled with their variable. Beside it, the paper's data and control views
//! (Zhao & Yan, 2012) level by level with the rungs they place differently marked.
//!
//! Layout is computed here, in Rust: columns left to right (the levels, then subroutine rungs,
//! which run inside their caller's task, then rungs that can never run), cards top to bottom in
//! program order, a loop task's cards inside one dashed frame. Every card is `<g class="card"
//! id="rung-ID" data-rung data-level data-pou data-cost>`; every edge is `<g class="e KIND"
//! data-from data-to data-var>` (one per dependence the report lists, up to [`MAX_EDGES`]).
//!
//! Past [`MAX_DETAILED_RUNGS`] rungs the view collapses: each level becomes a one-line summary
//! (tasks, rungs, cost, its first rungs) and no card or edge is drawn; the page says so.
//!
//! Deliberately not here: the ladder drawing itself, and the interaction (the page's script).

use super::ladder::{block_size, draw_block, draw_rung, rung_size, Size, CHAR};
use super::{esc, thousands, HtmlInput};
use crate::document::{DependenceEntry, Report, TaskName};
use plc_fbd::{BlockId, Network};
use plc_model::RungId;
use std::collections::{HashMap, HashSet};
use std::io::{self, Write};

/// Beyond this many rungs the level view shows level summaries instead of cards.
pub const MAX_DETAILED_RUNGS: usize = 2000;
/// The most dependence edges drawn.
pub const MAX_EDGES: usize = 10_000;
/// Edges labels are shown (without hovering) up to this many edges.
const LABELLED_EDGES: usize = 150;
/// A card's width, unless its column holds a rung that would shrink below [`MIN_SCALE`] in it.
pub(super) const CARD_W: f64 = 230.0;
/// The smallest scale a drawing is shown at before its column widens (to [`MAX_CARD_W`] at
/// most): below it the drawing's 10 px text is under 8 px, unreadable.
const MIN_SCALE: f64 = 0.8;
/// The widest a column of cards gets for a long rung (past it, the drawing shrinks).
const MAX_CARD_W: f64 = 2.0 * CARD_W;
const COL_GAP: f64 = 90.0;
const HEADER: f64 = 18.0;
const TOP: f64 = 34.0;

/// What a card draws.
#[derive(Copy, Clone)]
enum Drawing<'a> {
    Ladder,
    Block(&'a Network, BlockId),
}

/// The frame drawn around a loop task's cards: its left edge, width, top and height.
struct Frame {
    x: f64,
    w: f64,
    y: f64,
    h: f64,
}

struct Card<'a> {
    rung: RungId,
    col: usize,
    x: f64,
    /// The card's width: its column's.
    w: f64,
    y: f64,
    h: f64,
    scale: f64,
    drawing: Drawing<'a>,
}

/// A column: its title and its items (one rung, or the rungs of one loop task).
struct Column<'a> {
    title: String,
    level: Option<usize>,
    items: Vec<Vec<&'a str>>,
}

fn columns<'a>(r: &Report<'a>) -> Vec<Column<'a>> {
    let mut cols: Vec<Column<'a>> = r
        .levels
        .combined
        .iter()
        .enumerate()
        .map(|(l, tasks)| Column {
            title: format!(
                "level {} · {}",
                l + 1,
                crate::words::plural(tasks.len(), "task", "tasks")
            ),
            level: Some(l + 1),
            items: tasks
                .iter()
                .map(|t| match t {
                    TaskName::Rung(x) => vec![*x],
                    TaskName::Loop(xs) => xs.clone(),
                })
                .collect(),
        })
        .collect();
    let placed: HashSet<&str> = cols
        .iter()
        .flat_map(|c| c.items.iter().flatten())
        .copied()
        .collect();
    let never: HashSet<&str> = r.schedule.unreachable.iter().copied().collect();
    let rest: Vec<&str> = r
        .rungs
        .iter()
        .map(|e| e.id)
        .filter(|x| !placed.contains(x) && !never.contains(x))
        .collect();
    if !rest.is_empty() {
        cols.push(Column {
            title: "subroutines (run inside their caller)".into(),
            level: None,
            items: rest.into_iter().map(|x| vec![x]).collect(),
        });
    }
    if !r.schedule.unreachable.is_empty() {
        cols.push(Column {
            title: "never runs".into(),
            level: None,
            items: r.schedule.unreachable.iter().map(|x| vec![*x]).collect(),
        });
    }
    cols
}

/// The FBD block each rung was lowered from, if any.
fn blocks<'a>(input: &HtmlInput<'_, 'a>) -> HashMap<RungId, (&'a Network, BlockId)> {
    let mut m = HashMap::new();
    let Some(fbd) = input.fbd else { return m };
    for pou in &fbd.pous {
        for copy in &pou.copies {
            for (net, rungs) in pou.networks.iter().zip(&copy.blocks) {
                for (b, &r) in net.blocks.ids().zip(rungs) {
                    m.insert(r, (net, b));
                }
            }
        }
    }
    m
}

/// Where the cards go: the cards by rung, the loop frames, each column's left edge and width,
/// and the canvas size.
struct Placed<'a> {
    cards: Vec<Option<Card<'a>>>,
    frames: Vec<Frame>,
    columns: Vec<(f64, f64)>,
    size: Size,
}

/// Places every card.
fn place<'a>(input: &HtmlInput<'_, 'a>, cols: &[Column]) -> Placed<'a> {
    let p = input.program;
    let ids: HashMap<&str, RungId> = p.rung_ids().map(|r| (p.rung(r).id.as_str(), r)).collect();
    let blocks = blocks(input);
    let mut cards: Vec<Option<Card<'a>>> = (0..p.rungs().len()).map(|_| None).collect();
    let mut frames = Vec::new();
    let mut height: f64 = 0.0;
    let drawing_of = |r: RungId| match blocks.get(&r) {
        Some(&(net, b)) => Drawing::Block(net, b),
        None => Drawing::Ladder,
    };
    let size_of = |d: Drawing<'a>, r: RungId| match d {
        Drawing::Ladder => rung_size(p, p.rung(r)),
        Drawing::Block(net, b) => block_size(net, net.block(b)),
    };
    let mut x = 0.0;
    let mut xs = Vec::with_capacity(cols.len());
    for (ci, col) in cols.iter().enumerate() {
        // The column is as wide as its longest drawing needs at MIN_SCALE, within bounds.
        let w = col
            .items
            .iter()
            .flatten()
            .filter_map(|id| ids.get(id))
            .map(|&r| size_of(drawing_of(r), r).w * MIN_SCALE + 12.0)
            .fold(CARD_W, f64::max)
            .min(MAX_CARD_W);
        if ci > 0 {
            x += COL_GAP;
        }
        xs.push((x, w));
        let mut y = TOP;
        for item in &col.items {
            let framed = item.len() > 1;
            let top = y;
            if framed {
                y += 16.0;
            }
            for id in item {
                let Some(&r) = ids.get(id) else {
                    continue;
                };
                let drawing = drawing_of(r);
                let size = size_of(drawing, r);
                let scale = f64::min(1.0, (w - 12.0) / size.w);
                let h = HEADER + size.h * scale + 6.0;
                cards[r.index()] = Some(Card {
                    rung: r,
                    col: ci,
                    x,
                    w,
                    y,
                    h,
                    scale,
                    drawing,
                });
                y += h + 8.0;
            }
            if framed {
                frames.push(Frame {
                    x: x - 4.0,
                    w: w + 8.0,
                    y: top,
                    h: y - top,
                });
                y += 8.0;
            }
        }
        height = height.max(y);
        x += w;
    }
    Placed {
        cards,
        frames,
        columns: xs,
        size: Size {
            w: x.max(CARD_W),
            h: height + 10.0,
        },
    }
}

/// Whether the level view draws the rungs as cards (else it summarises each level).
pub(super) fn draws_cards(r: &Report) -> bool {
    r.summary.rungs <= MAX_DETAILED_RUNGS
}

/// Writes the level view (cards and edges, or the level summaries of a large program).
pub(super) fn write_levels(out: &mut impl Write, input: &HtmlInput) -> io::Result<()> {
    let r = input.doc;
    if !draws_cards(r) {
        return write_summaries(out, r);
    }
    let cols = columns(r);
    let Placed {
        cards,
        frames,
        columns,
        size,
    } = place(input, &cols);
    let p = input.program;
    let n_edges = r.dependences.len();
    let many = if n_edges > LABELLED_EDGES {
        " many"
    } else {
        ""
    };
    writeln!(
        out,
        r#"<div class="scroll"><svg class="levels{many}" width="{:.0}" height="{:.0}" viewBox="0 0 {:.0} {:.0}">"#,
        size.w, size.h, size.w, size.h
    )?;
    for (ci, col) in cols.iter().enumerate() {
        let level = col
            .level
            .map(|l| format!(r#" data-level="{l}""#))
            .unwrap_or_default();
        writeln!(
            out,
            r#"<text class="colhdr"{level} x="{:.1}" y="18">{}</text>"#,
            columns[ci].0,
            esc(&col.title)
        )?;
    }
    for Frame { x, w, y, h } in frames {
        writeln!(
            out,
            r#"<rect class="loop" x="{x:.1}" y="{y:.1}" width="{w:.1}" height="{h:.1}" rx="6"/><text class="looplbl" x="{:.1}" y="{:.1}">loop task (one sequential task)</text>"#,
            x + 6.0,
            y + 12.0
        )?;
    }
    write_edges(out, r, &cards, p)?;
    out.write_all(b"<g class=\"cards\">\n")?;
    for c in cards.iter().flatten() {
        write_card(out, input, c)?;
    }
    out.write_all(b"</g>\n</svg></div>\n")?;
    if n_edges > MAX_EDGES {
        writeln!(
            out,
            "<p class=\"note\">{} dependences: the first {} are drawn (the JSON report lists them all).</p>",
            thousands(n_edges),
            thousands(MAX_EDGES)
        )?;
    }
    Ok(())
}

fn write_card(out: &mut impl Write, input: &HtmlInput, c: &Card) -> io::Result<()> {
    let p = input.program;
    let a = input.analysis;
    let rung = p.rung(c.rung);
    let id = esc(&rung.id);
    let level = a
        .schedule
        .task_of
        .get(c.rung.index())
        .copied()
        .flatten()
        .map(|t| format!(r#" data-level="{}""#, a.schedule.task(t).level + 1))
        .unwrap_or_default();
    let names = |vs: &[plc_model::VarId]| {
        let v: Vec<&str> = vs.iter().map(|&v| p.var(v).name.as_str()).collect();
        if v.is_empty() {
            "-".to_string()
        } else {
            v.join(" ")
        }
    };
    writeln!(
        out,
        r#"<g class="card" id="rung-{id}" data-rung="{id}"{level} data-pou="{}" data-cost="{}" transform="translate({:.1},{:.1})">"#,
        esc(&p.pou(rung.pou).name),
        a.rung_costs[c.rung.index()],
        c.x,
        c.y
    )?;
    writeln!(
        out,
        "<title>{id}{}: IN {} · OUT {}</title>",
        rung.comment
            .as_deref()
            .map(|s| format!(" — {}", esc(s)))
            .unwrap_or_default(),
        esc(&names(a.accesses.ins(c.rung))),
        esc(&names(a.accesses.outs(c.rung)))
    )?;
    writeln!(
        out,
        r#"<rect class="frame" width="{:.1}" height="{:.1}" rx="4"/><text class="hdr" x="6" y="13">{id}</text>"#,
        c.w, c.h
    )?;
    let mut meta = Vec::new();
    if let Some(l) = &rung.label {
        meta.push(format!("label {l}"));
    }
    if rung.pou.raw() != 0 {
        meta.push(p.pou(rung.pou).name.clone());
    }
    meta.push(format!("cost {}", a.rung_costs[c.rung.index()]));
    let meta = meta.join(" · ");
    // The meta line must not run into the title: it gets the card's width less the title's
    // (11 px bold, about 6.7 px a character) and a gap, and is cut with "…" past that (the
    // whole line is in the card's tooltip).
    let room = c.w - 12.0 - rung.id.chars().count() as f64 * 6.7 - 10.0;
    let fits = (room / CHAR).floor().max(1.0) as usize;
    let shown = if meta.chars().count() > fits {
        let mut cut: String = meta.chars().take(fits.saturating_sub(1)).collect();
        cut.push('…');
        cut
    } else {
        meta.clone()
    };
    writeln!(
        out,
        r#"<text class="meta" x="{:.1}" y="13" text-anchor="end"><title>{}</title>{}</text>"#,
        c.w - 6.0,
        esc(&meta),
        esc(&shown)
    )?;
    writeln!(
        out,
        r#"<g transform="translate(6,{HEADER}) scale({:.3})">"#,
        c.scale
    )?;
    match c.drawing {
        Drawing::Ladder => draw_rung(out, p, rung, (c.w - 12.0) / c.scale)?,
        Drawing::Block(net, b) => draw_block(out, net, net.block(b))?,
    }
    out.write_all(b"</g>\n</g>\n")
}

/// Anchor points and control offsets of an edge between two cards.
fn endpoints(a: &Card, b: &Card, k: f64) -> ((f64, f64), (f64, f64), f64, f64) {
    let (ya, yb) = (a.y + a.h / 2.0 + k, b.y + b.h / 2.0 + k);
    if a.col < b.col {
        ((a.x + a.w, ya), (b.x, yb), 1.0, -1.0)
    } else if a.col > b.col {
        ((a.x, ya), (b.x + b.w, yb), -1.0, 1.0)
    } else {
        ((a.x + a.w, ya), (b.x + b.w, yb), 1.0, 1.0)
    }
}

fn write_edges(
    out: &mut impl Write,
    r: &Report,
    cards: &[Option<Card>],
    p: &plc_model::Program,
) -> io::Result<()> {
    let ids: HashMap<&str, usize> = p
        .rungs()
        .iter()
        .enumerate()
        .map(|(i, r)| (r.id.as_str(), i))
        .collect();
    let card = |x: &str| ids.get(x).and_then(|&i| cards[i].as_ref());
    let mut seen: HashMap<(&str, &str), u32> = HashMap::new();
    let mut labels = LabelSpots::default();
    out.write_all(b"<g class=\"edges\">\n")?;
    for d in r.dependences.iter().take(MAX_EDGES) {
        let (kind, from, to, label) = match &d {
            DependenceEntry::Data {
                kind,
                from,
                to,
                var,
            } => (*kind, *from, *to, *var),
            DependenceEntry::Control {
                from,
                to,
                var,
                edge,
                cause,
                ..
            } => {
                let label = match (var, edge.as_ref().and_then(|e| e.label)) {
                    (Some(v), _) => *v,
                    (None, Some("T")) => "if T",
                    (None, Some("F")) => "if F",
                    (None, _) => cause,
                };
                ("control", *from, *to, label)
            }
        };
        let (Some(a), Some(b)) = (card(from), card(to)) else {
            continue;
        };
        let k = seen.entry((from, to)).or_insert(0);
        let offset = (*k as f64) * 5.0 - 5.0;
        *k += 1;
        let ((x1, y1), (x2, y2), s1, s2) = endpoints(a, b, offset);
        let dx = if a.col == b.col {
            40.0 + (y2 - y1).abs() * 0.15
        } else {
            ((x2 - x1).abs() / 2.0).max(30.0)
        };
        let (c1, c2) = ((x1 + s1 * dx, y1), (x2 + s2 * dx, y2));
        let mx = 0.125 * x1 + 0.375 * c1.0 + 0.375 * c2.0 + 0.125 * x2;
        let my = 0.125 * y1 + 0.375 * c1.1 + 0.375 * c2.1 + 0.125 * y2;
        // A label that would cover another is moved along the edge's middle, or, with no free
        // spot near it, shown only while its edge is highlighted.
        let (my, crowded) = match labels.place(mx, my - 2.0, label.chars().count()) {
            Some(y) => (y + 2.0, ""),
            None => (my, " crowded"),
        };
        writeln!(
            out,
            r#"<g class="e {kind}" data-from="{}" data-to="{}" data-var="{}"><title>{} → {}: {kind} {}</title><path d="M{x1:.1} {y1:.1}C{:.1} {:.1} {:.1} {:.1} {x2:.1} {y2:.1}"/><text class="elabel{crowded}" x="{mx:.1}" y="{:.1}" text-anchor="middle">{}</text></g>"#,
            esc(from),
            esc(to),
            esc(label),
            esc(from),
            esc(to),
            esc(label),
            c1.0,
            c1.1,
            c2.0,
            c2.1,
            my - 2.0,
            esc(label)
        )?;
    }
    out.write_all(b"</g>\n")
}

/// The boxes of the edge labels placed so far, so that no two overlap.
#[derive(Default)]
struct LabelSpots {
    /// (left, right, baseline) of each placed label.
    placed: Vec<(f64, f64, f64)>,
}

impl LabelSpots {
    /// Width of a character of a label (9 px text).
    const CHAR: f64 = 5.5;
    /// Height of a label's line.
    const LINE: f64 = 10.0;

    /// The baseline nearest `y` (tried as `y`, then a line below, above, two below, …) at
    /// which a label of `chars` characters centred on `x` overlaps no placed one, and records
    /// it; `None` when the four nearest lines on either side are taken.
    fn place(&mut self, x: f64, y: f64, chars: usize) -> Option<f64> {
        let half = chars as f64 * Self::CHAR / 2.0;
        let (left, right) = (x - half, x + half);
        let free = |b: f64| {
            self.placed
                .iter()
                .all(|&(l, r, pb)| r <= left || right <= l || (pb - b).abs() >= Self::LINE)
        };
        let spot = (0..9)
            .map(|k| {
                let step = f64::from((k + 1) / 2) * Self::LINE;
                if k % 2 == 1 {
                    y + step
                } else {
                    y - step
                }
            })
            .find(|&b| free(b))?;
        self.placed.push((left, right, spot));
        Some(spot)
    }
}

/// First `n` items of a list, then `(+K more)`.
fn some<'s>(items: impl ExactSizeIterator<Item = &'s str>, n: usize) -> String {
    let total = items.len();
    let mut s: Vec<String> = items.take(n).map(|x| esc(x).into_owned()).collect();
    if total > n {
        s.push(format!("… (+{} more)", thousands(total - n)));
    }
    s.join(" ")
}

fn write_summaries(out: &mut impl Write, r: &Report) -> io::Result<()> {
    writeln!(
        out,
        "<p class=\"note\">{} rungs: more than the {} this page draws as cards, so each level is summarised (no rung drawings, no edges). <code>--format dot --rungs A..B</code> draws a part; the JSON report has everything.</p>",
        thousands(r.summary.rungs),
        thousands(MAX_DETAILED_RUNGS)
    )?;
    out.write_all(b"<table class=\"lsum\"><tr><th>level</th><th>tasks</th><th>rungs</th><th>first rungs</th></tr>\n")?;
    for (l, tasks) in r.levels.combined.iter().enumerate() {
        let rungs: Vec<&str> = tasks
            .iter()
            .flat_map(|t| match t {
                TaskName::Rung(x) => vec![*x],
                TaskName::Loop(xs) => xs.clone(),
            })
            .collect();
        writeln!(
            out,
            "<tr data-level=\"{}\"><td>{}</td><td>{}</td><td>{}</td><td>{}</td></tr>",
            l + 1,
            l + 1,
            thousands(tasks.len()),
            thousands(rungs.len()),
            some(rungs.iter().copied(), 12)
        )?;
    }
    out.write_all(b"</table>\n")
}

/// The paper's data and control views beside the combined one, level by level; rungs the
/// combined schedule places differently are marked, with the reasons listed below.
pub(super) fn write_views(out: &mut impl Write, r: &Report) -> io::Result<()> {
    let collapsed = r.summary.rungs > MAX_DETAILED_RUNGS;
    let differing: HashSet<String> = if collapsed {
        HashSet::new()
    } else {
        r.differences.iter().map(|d| d.rung).collect()
    };
    let chip = |x: &str| {
        let class = if differing.contains(x) {
            "chip diff"
        } else {
            "chip"
        };
        format!(
            r#"<span class="{class}" data-rung="{0}">{0}</span>"#,
            esc(x)
        )
    };
    let cell = |xs: Option<&Vec<&str>>| match xs {
        None => String::new(),
        Some(xs) if collapsed => some(xs.iter().copied(), 8),
        Some(xs) => xs.iter().map(|x| chip(x)).collect::<Vec<_>>().join(" "),
    };
    let depth = r
        .levels
        .data
        .len()
        .max(r.levels.control.len())
        .max(r.levels.combined.len());
    out.write_all(b"<table class=\"views\"><tr><th>level</th><th>paper data view</th><th>paper control view</th><th>combined (correct)</th></tr>\n")?;
    for l in 0..depth {
        let combined = r.levels.combined.get(l).map(|tasks| {
            tasks
                .iter()
                .map(|t| match t {
                    TaskName::Rung(x) if collapsed => esc(x).into_owned(),
                    TaskName::Rung(x) => chip(x),
                    TaskName::Loop(xs) if collapsed => format!("{{{} …}}", esc(xs[0])),
                    TaskName::Loop(xs) => format!(
                        "<span class=\"looptask\">{{{}}}</span>",
                        xs.iter().map(|x| chip(x)).collect::<Vec<_>>().join(" ")
                    ),
                })
                .take(if collapsed { 8 } else { usize::MAX })
                .collect::<Vec<_>>()
                .join(" ")
        });
        writeln!(
            out,
            "<tr><td>{}</td><td>{}</td><td>{}</td><td>{}</td></tr>",
            l + 1,
            cell(r.levels.data.get(l)),
            cell(r.levels.control.get(l)),
            combined.unwrap_or_default()
        )?;
    }
    out.write_all(b"</table>\n")?;
    write_differences(out, r)
}

fn write_differences(out: &mut impl Write, r: &Report) -> io::Result<()> {
    let n = r.differences.len();
    if n == 0 {
        return out.write_all(
            b"<p>The combined schedule places every rung where both paper views do.</p>\n",
        );
    }
    writeln!(
        out,
        "<p>{} rungs placed differently from the paper's views (marked <span class=\"chip diff\">so</span> above):</p>",
        thousands(n)
    )?;
    out.write_all(b"<table class=\"diffs\"><tr><th>rung</th><th>data</th><th>control</th><th>combined</th><th>why</th></tr>\n")?;
    for d in r.differences.iter().take(200) {
        writeln!(
            out,
            "<tr data-rung=\"{0}\"><td>{0}</td><td>{1}</td><td>{2}</td><td>{3}</td><td>{4}</td></tr>",
            esc(&d.rung),
            d.data_level,
            d.control_level,
            d.combined_level.map_or("-".to_string(), |l| l.to_string()),
            esc(&d.reasons.join("; "))
        )?;
    }
    out.write_all(b"</table>\n")?;
    if n > 200 {
        writeln!(
            out,
            "<p class=\"note\">… and {} more (the JSON report lists them all).</p>",
            thousands(n - 200)
        )?;
    }
    Ok(())
}
