//! The HTML report's charts in inline SVG: the makespan bars for P = 1, 2, 4, 8 (list
//! scheduling and level by level, from the report's cost figures) and the Gantt chart of the
//! combined schedule on P cores.
//!
//! The Gantt chart draws the cost model's own list schedule (`analysis::cost::list_schedule`:
//! which core runs which task when), so its makespan is the report's `cost.makespan` for the
//! same P. Past [`GANTT_MAX_BARS`] tasks, consecutive
//! tasks of one core are merged into one busy bar, and the chart says so.
//!
//! Deliberately not here: measured times (this is the model's schedule, not a trace of
//! `plc-deps run`).

use super::esc;
use crate::document::Report;
use plc_analysis::cost::{list_schedule, task_costs, Slot};
use plc_analysis::Analysis;
use plc_model::Program;
use std::io::{self, Write};

/// More tasks than this and the Gantt chart merges each core's consecutive tasks.
pub const GANTT_MAX_BARS: usize = 2000;
const CHART_W: f64 = 900.0;

/// The makespan bars: for each P, the list-scheduling and the level-by-level makespan.
pub(super) fn write_bars(out: &mut impl Write, r: &Report) -> io::Result<()> {
    let work = r.cost.work.max(1) as f64;
    let (plot_h, group_w) = (120.0, 110.0);
    let h = plot_h + 60.0;
    let w = 60.0 + group_w * r.cost.makespan.0.len() as f64;
    writeln!(
        out,
        r#"<svg class="bars" width="{w:.0}" height="{h:.0}" viewBox="0 0 {w:.0} {h:.0}" role="img" aria-label="makespan per number of cores">"#
    )?;
    writeln!(
        out,
        r#"<text x="4" y="12">cost steps (W = {})</text>"#,
        r.cost.work
    )?;
    let pairs = r.cost.makespan.0.iter().zip(&r.cost.level_makespan.0);
    for (i, (&(p, m), &(_, lm))) in pairs.enumerate() {
        let gx = 50.0 + group_w * i as f64;
        for (j, (v, class)) in [(m, "list"), (lm, "level")].into_iter().enumerate() {
            let bh = plot_h * v as f64 / work;
            let x = gx + 8.0 + 40.0 * j as f64;
            let y = 34.0 + plot_h - bh;
            writeln!(
                out,
                r#"<rect class="bar {class}" x="{x:.1}" y="{y:.1}" width="34" height="{bh:.1}"><title>P = {p}: {v} ({class})</title></rect>"#
            )?;
            writeln!(
                out,
                r#"<text x="{:.1}" y="{:.1}" text-anchor="middle">{v}</text>"#,
                x + 17.0,
                y - 3.0
            )?;
        }
        let speedup = if m == 0 { 0.0 } else { work / m as f64 };
        writeln!(
            out,
            r#"<text x="{:.1}" y="{:.1}" text-anchor="middle">P = {p} (×{speedup:.2})</text>"#,
            gx + 45.0,
            plot_h + 50.0
        )?;
    }
    writeln!(
        out,
        r#"<line x1="48" y1="{0:.1}" x2="{1:.1}" y2="{0:.1}" class="axis"/>"#,
        34.0 + plot_h,
        w - 4.0
    )?;
    out.write_all(b"</svg>\n")?;
    out.write_all(b"<p class=\"legend\"><span class=\"sw list\"></span> list scheduling (makespan) <span class=\"sw level\"></span> level by level (a barrier after each level)</p>\n")
}

/// The Gantt chart of the combined schedule on `p` cores.
pub(super) fn write_gantt(
    out: &mut impl Write,
    prog: &Program,
    a: &Analysis,
    p: usize,
) -> io::Result<()> {
    let costs = task_costs(&a.schedule, &a.rung_costs);
    let slots = list_schedule(&costs, &a.schedule.preds, p);
    let makespan = slots.iter().map(|s| s.finish).max().unwrap_or(0);
    let merged = slots.len() > GANTT_MAX_BARS;
    let row = 26.0;
    let h = row * p as f64 + 30.0;
    let scale = CHART_W / makespan.max(1) as f64;
    writeln!(
        out,
        r#"<h3>P = {p}: makespan {makespan}{}</h3>"#,
        if merged {
            format!(
                " ({} tasks: each core's consecutive tasks drawn as one busy bar)",
                super::thousands(slots.len())
            )
        } else {
            String::new()
        }
    )?;
    writeln!(
        out,
        r#"<svg class="gantt" width="{:.0}" height="{h:.0}" viewBox="0 0 {:.0} {h:.0}">"#,
        CHART_W + 60.0,
        CHART_W + 60.0
    )?;
    for c in 0..p {
        writeln!(
            out,
            r#"<text x="2" y="{:.1}">core {}</text>"#,
            row * c as f64 + 17.0,
            c + 1
        )?;
    }
    if merged {
        let mut busy: Vec<Vec<(u64, u64)>> = vec![Vec::new(); p];
        for s in &slots {
            let b = &mut busy[s.core as usize];
            match b.last_mut() {
                Some(last) if last.1 == s.start => last.1 = s.finish,
                _ => b.push((s.start, s.finish)),
            }
        }
        for (c, b) in busy.iter().enumerate() {
            for &(s, f) in b {
                writeln!(
                    out,
                    r#"<rect class="busy" x="{:.1}" y="{:.1}" width="{:.2}" height="{:.1}"/>"#,
                    50.0 + s as f64 * scale,
                    row * c as f64 + 4.0,
                    ((f - s) as f64 * scale).max(0.5),
                    row - 6.0
                )?;
            }
        }
    } else {
        for s in &slots {
            write_slot(out, prog, a, s, scale, row)?;
        }
    }
    writeln!(
        out,
        r#"<text x="50" y="{:.1}">0</text><text x="{:.1}" y="{:.1}" text-anchor="end">{makespan}</text>"#,
        h - 6.0,
        50.0 + CHART_W,
        h - 6.0
    )?;
    out.write_all(b"</svg>\n")
}

fn write_slot(
    out: &mut impl Write,
    prog: &Program,
    a: &Analysis,
    s: &Slot,
    scale: f64,
    row: f64,
) -> io::Result<()> {
    let task = a.schedule.task(s.task);
    let head = &prog.rung(task.rungs[0]).id;
    let name = if task.is_loop {
        format!(
            "{{{} … {}}}",
            head,
            prog.rung(*task.rungs.last().expect("loop")).id
        )
    } else {
        head.clone()
    };
    let (x, w) = (
        50.0 + s.start as f64 * scale,
        (s.finish - s.start) as f64 * scale,
    );
    let y = row * s.core as f64 + 4.0;
    writeln!(
        out,
        r#"<g class="slot" data-rung="{}"><rect x="{x:.1}" y="{y:.1}" width="{:.2}" height="{:.1}"/><title>{} on core {}: {}..{} (level {})</title>"#,
        esc(head),
        w.max(0.5),
        row - 6.0,
        esc(&name),
        s.core + 1,
        s.start,
        s.finish,
        task.level + 1
    )?;
    if w >= super::ladder::text_w(&name) + 4.0 {
        writeln!(
            out,
            r#"<text x="{:.1}" y="{:.1}" text-anchor="middle">{}</text>"#,
            x + w / 2.0,
            y + 13.0,
            esc(&name)
        )?;
    }
    out.write_all(b"</g>\n")
}
