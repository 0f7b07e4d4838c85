//! The text report: aligned tables for a person at a terminal, in the order a control engineer
//! reads them — the verdict (cycles before and after) first, then the levels and the cost, then
//! the evidence (IN/OUT, dependences, CFG, post-dominators, tasks, differences).
//!
//! Bounded by design: no column is wider than [`COLUMN_WIDTH`] characters (longer cells wrap
//! onto continuation lines), a level's rung list is cut after [`LEVEL_LINES`] lines
//! (`R1 R96 … (+4,812 more)`), and each section shows its first [`TextOptions::rows`] rows and
//! says how many it left out. With [`Rows::All`] every row is printed, wrapped, so the size is
//! linear in the content. The report's size therefore never depends on the widest cell of a
//! column or on the program's size beyond the row limit.

use super::document::{DependenceEntry, Report, TaskName};
pub(crate) use super::words::plural;
pub use super::words::thousands;
use super::View;
use std::io::{self, Write};

mod configuration;

/// No table column is wider than this; longer cells wrap.
pub const COLUMN_WIDTH: usize = 72;
/// A level's rung list is cut after this many lines unless every row is asked for.
pub const LEVEL_LINES: usize = 3;
/// Rows per section by default.
pub const DEFAULT_ROWS: usize = 200;
/// A loop task with more rungs than this is written `{R3 … R8}` in tables.
const LOOP_INLINE: usize = 8;

/// How many rows of each section the text report shows.
#[derive(Copy, Clone, Debug, PartialEq, Eq)]
pub enum Rows {
    /// The first N rows of each section, then a count of the rest.
    First(usize),
    /// Every row.
    All,
}

/// What the text report shows.
#[derive(Copy, Clone, Debug, PartialEq, Eq)]
pub struct TextOptions {
    /// The levellings shown.
    pub view: View,
    /// Rows per section.
    pub rows: Rows,
}

impl Default for TextOptions {
    fn default() -> Self {
        TextOptions {
            view: View::All,
            rows: Rows::First(DEFAULT_ROWS),
        }
    }
}

impl TextOptions {
    fn limit(&self) -> usize {
        match self.rows {
            Rows::First(n) => n,
            Rows::All => usize::MAX,
        }
    }
    fn level_lines(&self) -> Option<usize> {
        match self.rows {
            Rows::First(_) => Some(LEVEL_LINES),
            Rows::All => None,
        }
    }
}

/// Words joined by spaces, wrapped into lines of at most `width` characters (a longer word is a
/// line of its own), cut after `max_lines` lines with `… (+N more)` naming the words left out.
fn wrap_words<'w>(
    words: impl Iterator<Item = &'w str>,
    width: usize,
    max_lines: Option<usize>,
) -> Vec<String> {
    let mut lines: Vec<String> = Vec::new();
    let mut line = String::new();
    let mut words = words.peekable();
    while let Some(w) = words.next() {
        let fits = line.is_empty() || line.chars().count() + 1 + w.chars().count() <= width;
        if !fits {
            if max_lines.is_some_and(|m| lines.len() + 1 == m) {
                // Last allowed line: close it with the count of what is left.
                let rest = 1 + words.count();
                let more = format!("… (+{} more)", thousands(rest));
                while !line.is_empty() && line.chars().count() + 1 + more.chars().count() > width {
                    match line.rfind(' ') {
                        Some(i) => line.truncate(i),
                        None => break,
                    }
                }
                line.push(' ');
                line.push_str(&more);
                lines.push(line);
                return lines;
            }
            lines.push(std::mem::take(&mut line));
        }
        if !line.is_empty() {
            line.push(' ');
        }
        line.push_str(w);
    }
    if !line.is_empty() || lines.is_empty() {
        lines.push(line);
    }
    lines
}

/// A text wrapped at spaces into lines of at most `width` characters.
fn wrap(text: &str, width: usize) -> Vec<String> {
    if text.chars().count() <= width {
        return vec![text.to_owned()];
    }
    wrap_words(text.split(' '), width, None)
}

/// A table: a header row and rows of cells (each cell already split into lines), rendered
/// left-aligned with two spaces between columns and no trailing spaces.
struct Table {
    rows: Vec<Vec<Vec<String>>>,
}

impl Table {
    fn new(header: &[&str]) -> Table {
        Table {
            rows: vec![header.iter().map(|h| vec![h.to_string()]).collect()],
        }
    }
    /// A row of one-line cells, each wrapped at the column width.
    fn row(&mut self, cells: Vec<String>) {
        self.rows
            .push(cells.iter().map(|c| wrap(c, COLUMN_WIDTH)).collect());
    }
    /// A row of cells already split into lines.
    fn row_lines(&mut self, cells: Vec<Vec<String>>) {
        self.rows.push(cells);
    }
    fn render(&self, out: &mut impl Write) -> io::Result<()> {
        let cols = self.rows.iter().map(Vec::len).max().unwrap_or(0);
        let mut width = vec![0; cols];
        for r in &self.rows {
            for (i, c) in r.iter().enumerate() {
                for l in c {
                    width[i] = width[i].max(l.chars().count());
                }
            }
        }
        let mut line = String::new();
        for r in &self.rows {
            let height = r.iter().map(Vec::len).max().unwrap_or(1);
            for k in 0..height {
                line.clear();
                line.push_str("  ");
                for (i, c) in r.iter().enumerate() {
                    let cell = c.get(k).map(String::as_str).unwrap_or("");
                    line.push_str(cell);
                    if i + 1 < r.len() {
                        line.extend(std::iter::repeat_n(
                            ' ',
                            width[i] - cell.chars().count() + 2,
                        ));
                    }
                }
                writeln!(out, "{}", line.trim_end())?;
            }
        }
        Ok(())
    }
}

/// The line after a cut section.
fn more_rows(out: &mut impl Write, shown: usize, total: usize) -> io::Result<()> {
    if total > shown {
        writeln!(
            out,
            "  … {} more (`--full` shows every row)",
            plural(total - shown, "row", "rows")
        )?;
    }
    Ok(())
}

fn list(names: &[&str]) -> String {
    if names.is_empty() {
        "-".to_string()
    } else {
        names.join(" ")
    }
}

/// A task's name in a table: its rung, or `{R3 R5 R6}` for a loop (`{R3 … R9}` when long).
fn task_name(t: &TaskName) -> String {
    match t {
        TaskName::Rung(r) => (*r).to_owned(),
        TaskName::Loop(rs) if rs.len() <= LOOP_INLINE => format!("{{{}}}", rs.join(" ")),
        TaskName::Loop(rs) => format!("{{{} … {}}}", rs[0], rs[rs.len() - 1]),
    }
}

fn rung_task_name(rungs: &[&str], is_loop: bool) -> String {
    if is_loop || rungs.len() > 1 {
        task_name(&TaskName::Loop(rungs.to_vec()))
    } else {
        rungs[0].to_owned()
    }
}

/// Writes the text report.
pub fn render_text(r: &Report, o: &TextOptions, out: &mut impl Write) -> io::Result<()> {
    let paper = o.view != View::Combined;
    let combined = o.view != View::Paper;
    let s = &r.summary;
    let m = s.rungs;
    if let Some(f) = &r.fbd {
        let lowering = f.fragment_guards.len() + f.fragment_ends.len();
        writeln!(
            out,
            "{}: {} in {} ({} after lowering{})",
            r.program,
            plural(f.blocks, "block", "blocks"),
            plural(f.networks, "network", "networks"),
            plural(m, "rung", "rungs"),
            if lowering == 0 {
                String::new()
            } else {
                format!(
                    " with {} and {}; the levels below leave the landing rungs out",
                    plural(f.fragment_guards.len(), "fragment guard", "fragment guards"),
                    plural(
                        f.fragment_ends.len(),
                        "empty landing rung",
                        "empty landing rungs"
                    )
                )
            }
        )?;
    } else if s.main_rungs == m {
        writeln!(out, "{}: {}", r.program, plural(m, "rung", "rungs"))?;
    } else {
        let others = if r.interrupts.is_empty() {
            "subroutines"
        } else {
            "subroutines and interrupt routines"
        };
        writeln!(
            out,
            "{}: {} ({} in the main program, {} in {others})",
            r.program,
            plural(m, "rung", "rungs"),
            thousands(s.main_rungs),
            thousands(m - s.main_rungs)
        )?;
    }
    cycles(r, paper, combined, out)?;
    levels(r, o, paper, combined, out)?;
    if combined {
        cost(r, out)?;
    }
    rungs(r, o, out)?;
    networks(r, o, out)?;
    interrupts(r, o, out)?;
    configuration::configuration(r, o, out)?;
    dependences(r, o, out)?;
    cfg(r, o, out)?;
    post_dominators(r, o, out)?;
    if combined {
        loops(r, o, out)?;
        tasks(r, o, out)?;
        if paper {
            differences(r, o, out)?;
        }
    }
    if !r.skipped_pous.is_empty() {
        writeln!(out, "\nBodies not read as logic")?;
        for s in &r.skipped_pous {
            writeln!(out, "  {}", s.text())?;
        }
        writeln!(out, "  each {}", super::document::SKIPPED_MEANING)?;
    }
    if !r.warnings.is_empty() {
        writeln!(out, "\nWarnings")?;
        for (w, code) in r.warnings.iter().zip(&r.warning_codes) {
            writeln!(out, "  warning[{code}]: {w}")?;
        }
    }
    Ok(())
}

fn cycles(r: &Report, paper: bool, combined: bool, out: &mut impl Write) -> io::Result<()> {
    let m = r.cycles.before;
    let pct = |n: usize| crate::words::saved_percent(m, n);
    writeln!(
        out,
        "\nScan cycles (one rung per cycle before; one level per cycle after)"
    )?;
    let mut t = Table::new(&["schedule", "cycles", "saved"]);
    t.row(vec!["sequential".into(), thousands(m), String::new()]);
    if paper {
        let (d, c) = (r.cycles.data, r.cycles.control);
        t.row(vec!["paper data view".into(), thousands(d), pct(d)]);
        t.row(vec!["paper control view".into(), thousands(c), pct(c)]);
    }
    if combined {
        let k = r.cycles.combined;
        t.row(vec!["combined (correct)".into(), thousands(k), pct(k)]);
    }
    t.render(out)
}

fn levels(
    r: &Report,
    o: &TextOptions,
    paper: bool,
    combined: bool,
    out: &mut impl Write,
) -> io::Result<()> {
    writeln!(
        out,
        "\nLevels (rungs in one level may run at the same time; {{…}} is a loop run as one task)"
    )?;
    let l = r.shown_levels.as_ref().unwrap_or(&r.levels);
    let mut header = vec!["level"];
    if paper {
        header.extend(["paper data view", "paper control view"]);
    }
    if combined {
        header.push("combined");
    }
    let mut t = Table::new(&header);
    let rows = if paper {
        l.data.len().max(l.control.len())
    } else {
        0
    }
    .max(if combined { l.combined.len() } else { 0 });
    let cell = |g: Option<&Vec<&str>>| match g {
        Some(g) => wrap_words(g.iter().copied(), COLUMN_WIDTH, o.level_lines()),
        None => Vec::new(),
    };
    let shown = rows.min(o.limit());
    for i in 0..shown {
        let mut row = vec![vec![(i + 1).to_string()]];
        if paper {
            row.push(cell(l.data.get(i)));
            row.push(cell(l.control.get(i)));
        }
        if combined {
            let names: Vec<String> = l
                .combined
                .get(i)
                .map(|tasks| tasks.iter().map(task_name).collect())
                .unwrap_or_default();
            row.push(if names.is_empty() {
                Vec::new()
            } else {
                wrap_words(
                    names.iter().map(String::as_str),
                    COLUMN_WIDTH,
                    o.level_lines(),
                )
            });
        }
        t.row_lines(row);
    }
    t.render(out)?;
    if rows > shown {
        writeln!(
            out,
            "  … {} more (`--full` shows every level)",
            plural(rows - shown, "level", "levels")
        )?;
    }
    Ok(())
}

fn cost(r: &Report, out: &mut impl Write) -> io::Result<()> {
    let c = &r.cost;
    let ratio = |w: u64, s: u64| if s == 0 { 0.0 } else { w as f64 / s as f64 };
    writeln!(
        out,
        "\nCost of the combined schedule (model in docs/report.md)\n  work W = {}, span S = {}, ideal speed-up W/S = {:.2}",
        c.work,
        c.span,
        ratio(c.work, c.span)
    )?;
    let mut t = Table::new(&[
        "cores",
        "makespan",
        "speed-up",
        "level by level",
        "speed-up",
    ]);
    for ((cores, ms), (_, lm)) in c.makespan.0.iter().zip(&c.level_makespan.0) {
        t.row(vec![
            cores.to_string(),
            ms.to_string(),
            format!("{:.2}", ratio(c.work, *ms)),
            lm.to_string(),
            format!("{:.2}", ratio(c.work, *lm)),
        ]);
    }
    t.render(out)
}

fn rungs(r: &Report, o: &TextOptions, out: &mut impl Write) -> io::Result<()> {
    writeln!(
        out,
        "\nRungs (IN: may read, OUT: may write; calls include their subroutine)"
    )?;
    let mut t = Table::new(&["rung", "pou", "IN", "OUT", "cost"]);
    let shown = r.rungs.len().min(o.limit());
    for e in r.rungs.iter().take(shown) {
        t.row(vec![
            e.id.into(),
            e.pou.into(),
            list(&e.ins),
            list(&e.out),
            e.cost.to_string(),
        ]);
    }
    t.render(out)?;
    more_rows(out, shown, r.rungs.len())
}

fn networks(r: &Report, o: &TextOptions, out: &mut impl Write) -> io::Result<()> {
    if r.networks.is_empty() {
        return Ok(());
    }
    writeln!(
        out,
        "\nFBD networks (IN/OUT: the union over the network's block rungs)"
    )?;
    let mut t = Table::new(&["network", "pou", "rungs", "IN", "OUT"]);
    let shown = r.networks.len().min(o.limit());
    for n in r.networks.iter().take(shown) {
        let span = if n.rungs.len() == 1 {
            n.rungs[0].to_owned()
        } else {
            format!(
                "{} .. {} ({})",
                n.rungs[0],
                n.rungs[n.rungs.len() - 1],
                n.rungs.len()
            )
        };
        t.row(vec![
            n.id.into(),
            n.pou.into(),
            span,
            list(&n.ins),
            list(&n.out),
        ]);
    }
    t.render(out)?;
    more_rows(out, shown, r.networks.len())
}

/// Per interrupt routine, the variables it shares with the main program and who touches them.
fn interrupts(r: &Report, o: &TextOptions, out: &mut impl Write) -> io::Result<()> {
    // A rung list in one cell: cut to one line unless every row is asked for.
    let rungs = |ids: &[&str]| match o.rows {
        Rows::All => list(ids),
        Rows::First(_) if ids.is_empty() => list(ids),
        Rows::First(_) => wrap_words(ids.iter().copied(), 48, Some(1)).remove(0),
    };
    for i in &r.interrupts {
        writeln!(
            out,
            "\nInterrupt routine {} (it may run between any two rungs): {} shared with the main program",
            i.pou,
            plural(i.shared.len(), "variable", "variables")
        )?;
        if i.shared.is_empty() {
            continue;
        }
        let mut t = Table::new(&["variable", "interrupt", "main reads", "main writes"]);
        let shown = i.shared.len().min(o.limit());
        for s in i.shared.iter().take(shown) {
            let access = match (s.interrupt_reads, s.interrupt_writes) {
                (true, true) => "reads, writes",
                (false, true) => "writes",
                _ => "reads",
            };
            t.row(vec![
                s.var.into(),
                access.into(),
                rungs(&s.main_readers),
                rungs(&s.main_writers),
            ]);
        }
        t.render(out)?;
        more_rows(out, shown, i.shared.len())?;
    }
    Ok(())
}

fn dependences(r: &Report, o: &TextOptions, out: &mut impl Write) -> io::Result<()> {
    let c = &r.dependence_counts;
    let data_listed = r.dependences.len() - r.control_count;
    writeln!(
        out,
        "\nData dependences ({} flow, {} anti, {} output)",
        thousands(c.flow as usize),
        thousands(c.anti as usize),
        thousands(c.output as usize)
    )?;
    if r.dependences_listed == "direct" {
        writeln!(
            out,
            "  listing the {} direct pairs (last writer → reader, reader → next writer, writer → next writer), which imply all the others",
            thousands(data_listed)
        )?;
    }
    if data_listed == 0 {
        writeln!(out, "  none")?;
    } else {
        let mut t = Table::new(&["from", "to", "kind", "var"]);
        let shown = data_listed.min(o.limit());
        for d in r.dependences.iter().take(shown) {
            if let DependenceEntry::Data {
                kind,
                from,
                to,
                var,
            } = d
            {
                t.row(vec![from.into(), to.into(), kind.into(), var.into()]);
            }
        }
        t.render(out)?;
        more_rows(out, shown, data_listed)?;
    }

    writeln!(
        out,
        "\nControl dependences ({})",
        thousands(r.control_count)
    )?;
    if r.control_count == 0 {
        writeln!(out, "  none")?;
    } else {
        let mut t = Table::new(&["from", "to", "because of"]);
        let shown = r.control_count.min(o.limit());
        for d in r.dependences.iter().skip(data_listed).take(shown) {
            if let DependenceEntry::Control {
                from,
                to,
                edge,
                var,
                ..
            } = d
            {
                let why = match (edge, var) {
                    (Some(e), _) => format!(
                        "edge {} → {}{} ({})",
                        e.from,
                        e.to,
                        e.label.map(|l| format!(" ({l})")).unwrap_or_default(),
                        e.kind
                    ),
                    (None, v) => format!(
                        "reads {} (timer/counter, counted as control by the paper)",
                        v.unwrap_or_default()
                    ),
                };
                t.row(vec![from.into(), to.into(), why]);
            }
        }
        t.render(out)?;
        more_rows(out, shown, r.control_count)?;
    }
    if !r.self_control.is_empty() {
        let line = wrap_words(
            r.self_control.iter().copied(),
            COLUMN_WIDTH,
            o.level_lines(),
        );
        writeln!(
            out,
            "  control dependent on themselves (loop heads, calls; ignored for levels): {}",
            line.join("\n    ")
        )?;
    }
    Ok(())
}

fn cfg(r: &Report, o: &TextOptions, out: &mut impl Write) -> io::Result<()> {
    writeln!(out, "\nControl-flow graph")?;
    let mut t = Table::new(&["from", "to", "label", "kind"]);
    let edges = &r.cfg.edges;
    let shown = edges.len().min(o.limit());
    for e in edges.iter().take(shown) {
        t.row(vec![
            e.from.into(),
            e.to.into(),
            e.label.unwrap_or_default().into(),
            e.kind.into(),
        ]);
    }
    t.render(out)?;
    more_rows(out, shown, edges.len())
}

fn post_dominators(r: &Report, o: &TextOptions, out: &mut impl Write) -> io::Result<()> {
    writeln!(
        out,
        "\nPost-dominator tree (ipdom = immediate post-dominator; the root is STOP)"
    )?;
    let mut t = Table::new(&["node", "ipdom", "children"]);
    let nodes = &r.post_dominator_tree;
    let shown = nodes.len().min(o.limit());
    for n in nodes.iter().take(shown) {
        t.row_lines(vec![
            vec![n.node.into()],
            vec![n.ipdom.unwrap_or("-").into()],
            wrap_words(n.children.iter().copied(), COLUMN_WIDTH, o.level_lines()),
        ]);
    }
    t.render(out)?;
    more_rows(out, shown, nodes.len())
}

fn loops(r: &Report, o: &TextOptions, out: &mut impl Write) -> io::Result<()> {
    let long: Vec<_> = r
        .loops
        .iter()
        .filter(|l| l.rungs.len() > LOOP_INLINE)
        .collect();
    if long.is_empty() {
        return Ok(());
    }
    writeln!(out, "\nLoops (each kept whole as one sequential task)")?;
    let shown = long.len().min(o.limit());
    for l in long.iter().take(shown) {
        let lines = wrap_words(l.rungs.iter().copied(), COLUMN_WIDTH, o.level_lines());
        writeln!(
            out,
            "  loop at {} ({}) = {{{}}}",
            l.head,
            plural(l.rungs.len(), "rung", "rungs"),
            lines.join("\n    ")
        )?;
    }
    more_rows(out, shown, long.len())
}

fn tasks(r: &Report, o: &TextOptions, out: &mut impl Write) -> io::Result<()> {
    writeln!(
        out,
        "\nCombined schedule tasks (a task runs when its guard holds; \"always\" otherwise)"
    )?;
    let mut t = Table::new(&["level", "task", "guard"]);
    let all = &r.tasks_by_level;
    let shown = all.len().min(o.limit());
    for task in all.iter().take(shown) {
        let guard = if task.guard.is_empty() {
            "always".to_string()
        } else {
            task.guard
                .iter()
                .map(|g| format!("{} went to {}", g.controller, g.successor))
                .collect::<Vec<_>>()
                .join(" or ")
        };
        t.row(vec![
            task.level.to_string(),
            rung_task_name(&task.rungs, task.is_loop),
            guard,
        ]);
    }
    t.render(out)?;
    more_rows(out, shown, all.len())
}

fn differences(r: &Report, o: &TextOptions, out: &mut impl Write) -> io::Result<()> {
    writeln!(
        out,
        "\nWhere the combined schedule differs from the paper's views"
    )?;
    if r.differences.is_empty() {
        return writeln!(
            out,
            "  nowhere: every rung is at the same level in all three views"
        );
    }
    let mut t = Table::new(&["rung", "data", "control", "combined", "why"]);
    let shown = r.differences.len().min(o.limit());
    for d in r.differences.iter().take(shown) {
        t.row(vec![
            d.rung,
            d.data_level.to_string(),
            d.control_level.to_string(),
            d.combined_level
                .map(|l| l.to_string())
                .unwrap_or_else(|| "-".into()),
            d.reasons.join("; "),
        ]);
    }
    t.render(out)?;
    more_rows(out, shown, r.differences.len())
}
