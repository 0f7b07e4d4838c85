//! The HTML report: one self-contained page (inline CSS, inline SVG, a small inline script; no
//! URL to anything outside the file) that an engineer can open in a browser and show a
//! colleague — the fourth renderer of the report document, beside text, JSON and DOT.
//!
//! The page, top to bottom ([`page`] writes the skeleton): the summary (rungs, scan cycles
//! before and after for each view, the cost figures and the makespan for P = 1, 2, 4, 8 as a
//! bar chart, [`charts`]); the combined schedule's levels as columns of rung cards, each
//! drawing its rung as a ladder or its FBD block ([`ladder`]), with the dependence edges
//! ([`levels`]); the paper's views beside the combined one, differences marked (Zhao & Yan,
//! 2012); the Gantt chart of the list schedule on 2 and 4 cores; the CFG with T/F edges and the
//! post-dominator tree, laid out in Rust by a simple Sugiyama scheme ([`layout`], [`graphs`]).
//! Hovering or clicking a rung (a card, a chip, a Gantt bar, a CFG node) highlights it, what it
//! depends on and what depends on it, everywhere on the page. The page of `plc-deps run` is the
//! same page with a section of the run's measured figures after the summary ([`run`]). A program
//! with a configuration (tasks and program instances) has a section of its tasks and of the
//! globals programs of different tasks share next ([`tasks`]).
//!
//! Invariants: the page is well-formed XML as well as HTML (the tests parse it), every attribute
//! and text is escaped, every rung card has `id="rung-ID"`, and it is written to an
//! `impl Write` as it is made (never built whole in memory). Size is bounded: past
//! [`MAX_DETAILED_RUNGS`] rungs the levels are summaries, past [`MAX_GRAPH_NODES`] the graphs are
//! not drawn, past [`charts::GANTT_MAX_BARS`] tasks the Gantt chart merges busy time, each
//! saying so on the page (docs/html.md).
//!
//! Deliberately not here: anything the report document does not say (no new analysis), and
//! any network access (no fonts, scripts or images from elsewhere).

mod charts;
mod graphs;
mod ladder;
mod layout;
mod levels;
mod page;
mod run;
mod tasks;

pub use charts::GANTT_MAX_BARS;
pub use graphs::MAX_GRAPH_NODES;
pub use levels::{MAX_DETAILED_RUNGS, MAX_EDGES};
pub use run::{
    FaultRow, ModeFigures, PlanFigures, RunFigures, FAULT_ROWS_SHOWN, OUTPUT_ROWS_SHOWN,
};
pub use tasks::SHARED_ROWS_SHOWN;

use super::document::Report;
use plc_analysis::Analysis;
use plc_fbd::Fbd;
use plc_model::Program;
use std::borrow::Cow;
use std::io::{self, Write};

pub(crate) use super::text::thousands;

/// What the HTML report is made from: the report document and what it was built from (the
/// page draws the rungs themselves and replays the schedule, which the document does not hold).
pub struct HtmlInput<'r, 'a> {
    pub doc: &'r Report<'a>,
    pub program: &'a Program,
    pub analysis: &'a Analysis,
    /// The FBD bodies as written, to draw a block's rung as the block (`None`: ladder only).
    pub fbd: Option<&'a Fbd>,
}

/// Escapes text for an HTML (and XML) text node or a quoted attribute.
/// A control character but line feed, tab and carriage return (which XML does not allow, even
/// as a reference) is written as its Rust escape (`\u{1b}`), as text.
pub(crate) fn esc(s: &str) -> Cow<'_, str> {
    let special = |c: char| {
        matches!(c, '&' | '<' | '>' | '"' | '\'')
            || (c.is_control() && !matches!(c, '\n' | '\t' | '\r'))
    };
    if !s.contains(special) {
        return Cow::Borrowed(s);
    }
    let mut o = String::with_capacity(s.len() + 8);
    for c in s.chars() {
        match c {
            '&' => o.push_str("&amp;"),
            '<' => o.push_str("&lt;"),
            '>' => o.push_str("&gt;"),
            '"' => o.push_str("&quot;"),
            '\'' => o.push_str("&#39;"),
            c if special(c) => o.extend(c.escape_default()),
            c => o.push(c),
        }
    }
    Cow::Owned(o)
}

/// Writes the HTML report of `input`.
pub fn render_html(input: &HtmlInput, out: &mut impl Write) -> io::Result<()> {
    write_page(input, None, out)
}

/// Writes the page of `plc-deps run --format html`: the report page of the program with the
/// run's section (measured rates beside the model, outputs, faults) after the summary.
pub fn render_run_html(
    input: &HtmlInput,
    run: &RunFigures,
    out: &mut impl Write,
) -> io::Result<()> {
    write_page(input, Some(run), out)
}

/// The POUs whose bodies were not read as logic, and what that means, when there are any.
fn write_skipped(out: &mut impl Write, r: &Report) -> io::Result<()> {
    if r.skipped_pous.is_empty() {
        return Ok(());
    }
    out.write_all(b"<section id=\"skipped\">\n<h2>Bodies not read as logic</h2>\n<ul>\n")?;
    for s in &r.skipped_pous {
        writeln!(out, "<li>{}</li>", esc(&s.text()))?;
    }
    writeln!(
        out,
        "</ul>\n<p>Each is {}.</p>\n</section>",
        esc(super::document::SKIPPED_MEANING)
    )
}

/// The page, with the run section when there is a run.
fn write_page(input: &HtmlInput, run: Option<&RunFigures>, out: &mut impl Write) -> io::Result<()> {
    let r = input.doc;
    page::write_head(out, r.program, if run.is_some() { "run" } else { "report" })?;
    page::write_summary(out, r)?;
    write_skipped(out, r)?;
    if let Some(run) = run {
        run::write_run(out, r, run)?;
    }
    tasks::write_tasks(out, r)?;
    out.write_all(b"<section id=\"levels\">\n<h2>Levels of the combined schedule</h2>\n")?;
    // Rungs are drawn as cards (which the legend and the info line are about) only up to
    // a size; a larger program's levels are summaries.
    let cards = levels::draws_cards(r);
    if cards {
        page::write_level_legend(out)?;
    }
    levels::write_levels(out, input)?;
    out.write_all(b"</section>\n<section id=\"views\">\n<h2>The paper's views beside the combined schedule</h2>\n")?;
    levels::write_views(out, r)?;
    out.write_all(b"</section>\n<section id=\"gantt\">\n<h2>Schedule on P cores (list scheduling, cost model)</h2>\n")?;
    for p in [2, 4] {
        charts::write_gantt(out, input.program, input.analysis, p)?;
    }
    out.write_all(
        b"</section>\n<section id=\"graphs\">\n<h2>Control flow and post-dominators</h2>\n",
    )?;
    graphs::write_graphs(out, input.program, input.analysis)?;
    out.write_all(b"</section>\n")?;
    page::write_foot(out, cards)
}

#[cfg(test)]
mod tests;
