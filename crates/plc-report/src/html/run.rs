//! The run section of `plc-deps run --format html`: what a run measured, beside what the report's
//! cost model predicts, on the same page as the program's report.
//!
//! [`RunFigures`] is plain data (the command fills it from its run report, docs/scan.md), so the
//! report module does not depend on the command. The section shows: the run's shape (scans,
//! cycle, threads and the workers planned for); the measured sequential and parallel scan rates
//! (µs per scan, scans per second, rungs per second) and their ratio with the number of scans it
//! is over, or "sequential fallback (why)" when every parallel scan was the sequential walk; the
//! plan the parallel pass chose (its candidates and the scans each ran); beside that the ideal —
//! W/S and, for P = 1, 2, 4, 8, the list-scheduling and level-by-level makespans of the report and
//! the speed-ups W/makespan they allow, the row of the run's worker count marked — with a bar
//! chart of the measured ratio against the model's for that P; whether every scan's state was the
//! same in both modes; the outputs after the last scan; and the faults (one row per distinct
//! fault, its rung a chip that highlights the rung on the page).
//!
//! Invariants: every text is escaped; the figures are shown as given (no timing is done here).
//! Deliberately not here: running anything, and the cost model itself (the figures come from the
//! report document, `cost`).

use super::{esc, thousands};
use crate::document::Report;
use crate::words::plural;
use std::io::{self, Write};

/// One mode's measured time.
#[derive(Clone, Debug, PartialEq)]
pub struct ModeFigures {
    /// `seq` or `par`.
    pub name: &'static str,
    /// Mean wall-clock time of one scan, ns.
    pub ns_per_scan: f64,
}

/// One distinct fault: a rung and a kind, how often, first and last scan.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct FaultRow {
    pub rung: String,
    pub kind: &'static str,
    pub count: u64,
    pub first_scan: u64,
    pub last_scan: u64,
}

/// What the parallel pass ran.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct PlanFigures {
    /// Which plans it could use (`auto`, `model`, `seq`, `par`, `deps`).
    pub kind: &'static str,
    /// Scans run on each candidate that ran (`seq`, `par-lpt`, `par-deps`, …), in candidate order.
    pub scans_on: Vec<(String, u64)>,
    /// The candidate that ran last.
    pub last: String,
    /// Changes of the running candidate.
    pub switches: usize,
    /// `Some(why)` when every scan was the sequential walk.
    pub fallback: Option<String>,
}

/// A run's figures, as the run report has them (docs/scan.md).
#[derive(Clone, Debug, PartialEq)]
pub struct RunFigures {
    pub scans: u64,
    pub cycle_ms: u32,
    pub threads: usize,
    /// Workers the parallel plan was made for.
    pub workers: usize,
    /// Main-program rungs (for the rung rate).
    pub rungs: usize,
    /// The modes that ran, `seq` first.
    pub modes: Vec<ModeFigures>,
    /// `None` when the parallel executor did not run.
    pub plan: Option<PlanFigures>,
    /// When both modes ran: the scans of each one's turn (they alternate in blocks).
    pub block_scans: Option<u64>,
    /// `Some` when both modes ran: was every scan's full state identical.
    pub identical: Option<bool>,
    /// The first difference, in words.
    pub first_difference: Option<String>,
    /// Output variables after the last scan: (name, value as text).
    pub outputs: Vec<(String, String)>,
    pub fault_count: u64,
    /// Every distinct fault, in order of first occurrence.
    pub faults: Vec<FaultRow>,
    /// The text of `--explain`, when asked for.
    pub explain: Option<String>,
    /// The run's warnings: (code, message).
    pub warnings: Vec<(&'static str, String)>,
}

impl RunFigures {
    fn mode(&self, name: &str) -> Option<f64> {
        self.modes
            .iter()
            .find(|m| m.name == name)
            .map(|m| m.ns_per_scan)
    }

    /// Measured sequential time over parallel time (`None` unless both ran and took time).
    pub fn speedup(&self) -> Option<f64> {
        match (self.mode("seq"), self.mode("par")) {
            (Some(s), Some(p)) if p > 0.0 && s > 0.0 => Some(s / p),
            _ => None,
        }
    }
}

/// Distinct faults listed on the page (the JSON report lists every one).
pub const FAULT_ROWS_SHOWN: usize = 200;
/// Output variables listed on the page (the JSON report lists every one).
pub const OUTPUT_ROWS_SHOWN: usize = 500;

/// Writes the run section.
pub(super) fn write_run(out: &mut impl Write, doc: &Report, run: &RunFigures) -> io::Result<()> {
    out.write_all(b"<section id=\"run\">\n<h2>Run: measured scan rates beside the model</h2>\n")?;
    writeln!(
        out,
        "<p>{} of {} ms (virtual time), {}{}.</p>",
        plural(run.scans as usize, "scan", "scans"),
        run.cycle_ms,
        plural(run.threads, "thread", "threads"),
        if run.workers != run.threads {
            format!(
                " (planned for {}, the cores there are)",
                plural(run.workers, "worker", "workers")
            )
        } else {
            String::new()
        }
    )?;
    super::page::write_warnings(out, run.warnings.iter().map(|(c, w)| (*c, w.as_str())))?;
    out.write_all(b"<div class=\"summary\">\n")?;
    write_rates(out, run)?;
    write_ideal(out, doc, run)?;
    write_ratio_bars(out, doc, run)?;
    out.write_all(b"</div>\n")?;
    match (run.identical, &run.first_difference) {
        (Some(true), _) => out.write_all(
            b"<p class=\"identical\">identical: yes, seq == par after every scan (full state and faults)</p>\n",
        )?,
        (Some(false), d) => writeln!(
            out,
            "<p class=\"note identical\">identical: NO, first difference: {}</p>",
            esc(d.as_deref().unwrap_or("(see the JSON report)"))
        )?,
        (None, _) => {}
    }
    write_outputs(out, run)?;
    write_faults(out, run)?;
    if let Some(text) = &run.explain {
        writeln!(
            out,
            "<details><summary>The parallel plan (--explain)</summary><pre>{}</pre></details>",
            esc(text)
        )?;
    }
    out.write_all(b"</section>\n")
}

/// The measured rates, one row per mode; the parallel row says how it compares or why it fell
/// back, and which plan ran.
pub(super) fn write_rates(out: &mut impl Write, run: &RunFigures) -> io::Result<()> {
    out.write_all("<div>\n<h3>Measured</h3>\n<table class=\"rates\"><tr><th>mode</th><th>µs/scan</th><th>scans/s</th><th>M rungs/s</th><th>against seq</th></tr>\n".as_bytes())?;
    for m in &run.modes {
        let per_s = if m.ns_per_scan > 0.0 {
            1e9 / m.ns_per_scan
        } else {
            0.0
        };
        let against = match (m.name, run.speedup(), &run.plan) {
            (
                "par",
                _,
                Some(PlanFigures {
                    fallback: Some(why),
                    ..
                }),
            ) => format!("sequential fallback ({})", esc(why)),
            ("par", Some(x), _) => format!(
                "<b class=\"ratio\">×{x:.2}</b> over {}{}",
                plural(run.scans as usize, "scan", "scans"),
                match run.block_scans {
                    Some(b) if b < run.scans => format!(
                        ", seq and par alternating every {}",
                        plural(b as usize, "scan", "scans")
                    ),
                    _ => String::new(),
                }
            ),
            _ => String::new(),
        };
        writeln!(
            out,
            "<tr class=\"mode-{0}\"><td>{0}</td><td>{1:.3}</td><td>{2}</td><td>{3:.1}</td><td>{against}</td></tr>",
            m.name,
            m.ns_per_scan / 1e3,
            thousands(per_s.round() as usize),
            per_s * run.rungs as f64 / 1e6
        )?;
    }
    out.write_all(b"</table>\n")?;
    if let Some(plan) = &run.plan {
        let ran: Vec<String> = plan
            .scans_on
            .iter()
            .filter(|(_, n)| *n > 0)
            .map(|(c, n)| {
                format!(
                    "<code>{}</code> {}",
                    esc(c),
                    plural(*n as usize, "scan", "scans")
                )
            })
            .collect();
        writeln!(
            out,
            "<p class=\"plan\">plan chosen (<code>--plan {}</code>): <b>{}</b>{}; ran {}{}.</p>",
            plan.kind,
            esc(&plan.last),
            match &plan.fallback {
                Some(why) => format!(", a sequential fallback ({})", esc(why)),
                None => String::new(),
            },
            if ran.is_empty() {
                "nothing".to_string()
            } else {
                ran.join(", ")
            },
            match plan.switches {
                0 => String::new(),
                1 => ", 1 switch".into(),
                n => format!(", {n} switches"),
            }
        )?;
    }
    out.write_all(b"</div>\n")
}

/// The model's figures: W, S, W/S and the makespans for P = 1, 2, 4, 8 with the speed-ups they
/// allow; the row of the run's workers marked.
fn write_ideal(out: &mut impl Write, doc: &Report, run: &RunFigures) -> io::Result<()> {
    let c = &doc.cost;
    writeln!(
        out,
        "<div>\n<h3>Ideal (the report's cost model)</h3>\n<p>W = {}, S = {}, W/S = {:.2}</p>",
        c.work, c.span, c.ideal_speedup
    )?;
    out.write_all(b"<table class=\"ideal\"><tr><th>P</th><th>makespan</th><th>W/makespan</th><th>level by level</th><th>W/level</th></tr>\n")?;
    let ratio = |m: u64| {
        if m == 0 {
            0.0
        } else {
            c.work as f64 / m as f64
        }
    };
    for (&(p, m), &(_, lm)) in c.makespan.0.iter().zip(&c.level_makespan.0) {
        let this = p as usize == run.workers;
        writeln!(
            out,
            "<tr{}><td>{p}{}</td><td>{m}</td><td>×{:.2}</td><td>{lm}</td><td>×{:.2}</td></tr>",
            if this { " class=\"this\"" } else { "" },
            if this { " (this run)" } else { "" },
            ratio(m),
            ratio(lm)
        )?;
    }
    out.write_all(b"</table>\n")?;
    if !c.makespan.0.iter().any(|&(p, _)| p as usize == run.workers) {
        writeln!(
            out,
            "<p class=\"legend\">The model gives P = 1, 2, 4, 8; this run had {}.</p>",
            plural(run.workers, "worker", "workers")
        )?;
    }
    out.write_all(b"</div>\n")
}

/// Bars: the measured ratio seq/par beside the model's W/makespan and W/level for the run's
/// worker count (when the model has it) and W/S.
fn write_ratio_bars(out: &mut impl Write, doc: &Report, run: &RunFigures) -> io::Result<()> {
    let c = &doc.cost;
    let at = |list: &[(u32, u64)]| {
        list.iter()
            .find(|&&(p, _)| p as usize == run.workers)
            .filter(|&&(_, m)| m > 0)
            .map(|&(_, m)| c.work as f64 / m as f64)
    };
    let mut bars: Vec<(String, f64, &str)> = Vec::new();
    if let Some(x) = run.speedup() {
        let fell_back = run.plan.as_ref().is_some_and(|p| p.fallback.is_some());
        let name = if fell_back {
            "measured (fallback)"
        } else {
            "measured"
        };
        bars.push((name.into(), x, "measured"));
    }
    if let Some(x) = at(&c.makespan.0) {
        bars.push((format!("model, P = {}", run.workers), x, "list"));
    }
    if let Some(x) = at(&c.level_makespan.0) {
        bars.push((format!("levels, P = {}", run.workers), x, "level"));
    }
    bars.push(("W/S".into(), c.ideal_speedup, "ideal"));
    // The scale is set by the bars for the run's P (and ×1); W/S, the bound for unboundedly
    // many cores, may be far beyond: it is then drawn to the edge and marked off scale.
    let top = bars[..bars.len() - 1]
        .iter()
        .map(|b| b.1)
        .fold(1.0, f64::max)
        * 1.25;
    let (label_w, plot_w, row_h) = (140.0, 240.0, 22.0);
    let h = 26.0 + row_h * bars.len() as f64;
    let w = label_w + plot_w + 120.0;
    writeln!(
        out,
        r#"<div><h3>Speed-up against one core</h3><svg class="ratios" width="{w:.0}" height="{h:.0}" viewBox="0 0 {w:.0} {h:.0}" role="img" aria-label="measured and ideal speed-up">"#
    )?;
    for (i, (name, x, class)) in bars.iter().enumerate() {
        let y = 6.0 + row_h * i as f64;
        let off = *x > top;
        let bw = plot_w * x.min(top) / top;
        writeln!(
            out,
            r#"<text x="{:.1}" y="{:.1}" text-anchor="end">{}</text><rect class="bar {class}" x="{label_w:.1}" y="{y:.1}" width="{bw:.1}" height="16"><title>{}: ×{x:.2}</title></rect><text x="{:.1}" y="{:.1}">×{x:.2}{}</text>"#,
            label_w - 6.0,
            y + 12.0,
            esc(name),
            esc(name),
            label_w + bw + 4.0,
            y + 12.0,
            if off { " (off scale)" } else { "" }
        )?;
    }
    let x1 = label_w + plot_w / top;
    writeln!(
        out,
        r#"<line class="axis one" x1="{x1:.1}" y1="2" x2="{x1:.1}" y2="{:.1}"/><text x="{x1:.1}" y="{:.1}" text-anchor="middle">×1</text>"#,
        h - 14.0,
        h - 2.0
    )?;
    out.write_all(b"</svg></div>\n")
}

/// The outputs after the last scan.
fn write_outputs(out: &mut impl Write, run: &RunFigures) -> io::Result<()> {
    writeln!(
        out,
        "<h3>Outputs after scan {}</h3>",
        run.scans.saturating_sub(1)
    )?;
    if run.outputs.is_empty() {
        return out.write_all(b"<p>(no output variables)</p>\n");
    }
    out.write_all(b"<table class=\"outputs\"><tr><th>variable</th><th>value</th></tr>\n")?;
    for (name, value) in run.outputs.iter().take(OUTPUT_ROWS_SHOWN) {
        writeln!(
            out,
            "<tr><td><code>{}</code></td><td><code>{}</code></td></tr>",
            esc(name),
            esc(value)
        )?;
    }
    out.write_all(b"</table>\n")?;
    if run.outputs.len() > OUTPUT_ROWS_SHOWN {
        writeln!(
            out,
            "<p class=\"legend\">… and {} more outputs (<code>outputs</code> in <code>--format json</code>).</p>",
            thousands(run.outputs.len() - OUTPUT_ROWS_SHOWN)
        )?;
    }
    Ok(())
}

/// The faults: the total, then one row per distinct fault (at most [`FAULT_ROWS_SHOWN`]).
fn write_faults(out: &mut impl Write, run: &RunFigures) -> io::Result<()> {
    if run.fault_count == 0 {
        return out.write_all(b"<h3>Faults</h3>\n<p class=\"faults\">none</p>\n");
    }
    writeln!(
        out,
        "<h3>Faults</h3>\n<p class=\"note faults\">{} {} ({} distinct)</p>",
        thousands(run.fault_count as usize),
        if run.fault_count == 1 {
            "fault"
        } else {
            "faults"
        },
        thousands(run.faults.len())
    )?;
    out.write_all(b"<table class=\"faults\"><tr><th>rung</th><th>kind</th><th>count</th><th>first scan</th><th>last scan</th></tr>\n")?;
    for f in run.faults.iter().take(FAULT_ROWS_SHOWN) {
        writeln!(
            out,
            r#"<tr><td><span class="chip" data-rung="{0}">{0}</span></td><td>{1}</td><td>{2}</td><td>{3}</td><td>{4}</td></tr>"#,
            esc(&f.rung),
            f.kind,
            f.count,
            f.first_scan,
            f.last_scan
        )?;
    }
    out.write_all(b"</table>\n")?;
    if run.faults.len() > FAULT_ROWS_SHOWN {
        writeln!(
            out,
            "<p class=\"legend\">… and {} more distinct faults (<code>fault_summary</code> in <code>--format json</code>).</p>",
            thousands(run.faults.len() - FAULT_ROWS_SHOWN)
        )?;
    }
    Ok(())
}
