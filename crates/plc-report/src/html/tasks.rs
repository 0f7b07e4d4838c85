//! The HTML report's tasks section, for a program with a configuration (a PLCopen project's, or
//! the JSON format's): the configuration and each resource's tasks in run order (priority,
//! interval, single, the program instances each runs; a row for the instances the resource
//! runs without a task), the program instances analysed, and the globals that programs of
//! different tasks share with who reads and who writes each (docs/report.md; the analysis is
//! [`plc_analysis::task_sharing`]).
//!
//! Layout only: the data and its wording are the report document's
//! ([`crate::configuration`]), the same the text and JSON reports give. The table of
//! shared globals is bounded ([`SHARED_ROWS_SHOWN`]), saying how many more there are.
//! Deliberately not here: linking instances to rungs (a program's rungs are in the levels).

use super::{esc, thousands};
use crate::configuration::{analysed_text, run_label, InstanceEntry, ProgramRunEntry};
use crate::document::Report;
use std::io::{self, Write};

/// Rows of the table of globals shared between tasks shown on the page.
pub const SHARED_ROWS_SHOWN: usize = 500;

/// Writes `<section id="tasks">` (nothing without a configuration).
pub(super) fn write_tasks(out: &mut impl Write, r: &Report) -> io::Result<()> {
    let Some(c) = &r.configuration else {
        return Ok(());
    };
    writeln!(
        out,
        "<section id=\"tasks\">\n<h2>Tasks of configuration {}</h2>",
        esc(c.name)
    )?;
    for res in &c.resources {
        writeln!(
            out,
            "<h3>Resource {}</h3>\n<table class=\"tasks\"><tr><th>task</th><th>priority</th><th>interval</th><th>single</th><th>program instances</th></tr>",
            esc(res.name)
        )?;
        for t in &res.tasks {
            writeln!(
                out,
                "<tr><td>{}</td><td>{}</td><td>{}</td><td>{}</td><td>{}</td></tr>",
                esc(t.name),
                t.priority,
                esc(t.interval.unwrap_or("-")),
                esc(t.single.unwrap_or("-")),
                instances(&t.instances)
            )?;
        }
        if !res.instances.is_empty() {
            writeln!(
                out,
                "<tr class=\"own\"><td>(no task)</td><td>-</td><td>-</td><td>-</td><td>{}</td></tr>",
                instances(&res.instances)
            )?;
        }
        out.write_all(b"</table>\n")?;
    }
    writeln!(
        out,
        "<p class=\"analysed\">Analysed: {}.</p>",
        esc(&analysed_text(c, &r.programs))
    )?;
    match r.task_sharing.as_ref().filter(|_| c.several_tasks()) {
        Some(shared) => write_shared(out, shared)?,
        None => out.write_all(b"<p>One task: nothing is shared between tasks.</p>\n")?,
    }
    out.write_all(b"</section>\n")
}

/// The globals programs of different tasks share: a table, or a line saying there are none.
fn write_shared(
    out: &mut impl Write,
    shared: &[crate::configuration::TaskSharedEntry],
) -> io::Result<()> {
    writeln!(
        out,
        "<h3>Globals shared between tasks</h3>\n<p>Each is written by a program of one task and read or written by a program of another: on a multicore controller, or when a task of higher priority pre-empts another, one task can see the other's half-finished scan. {} shared.</p>",
        match shared.len() {
            0 => "No global is".to_owned(),
            1 => "1 global is".to_owned(),
            n => format!("{} globals are", thousands(n)),
        }
    )?;
    if shared.is_empty() {
        return Ok(());
    }
    out.write_all(
        b"<table class=\"shared\"><tr><th>variable</th><th>read by</th><th>written by</th></tr>\n",
    )?;
    let runs = |v: &[ProgramRunEntry]| {
        if v.is_empty() {
            return "-".to_owned();
        }
        let names: Vec<String> = v.iter().map(|e| esc(&run_label(e)).into_owned()).collect();
        names.join("<br/>")
    };
    for s in shared.iter().take(SHARED_ROWS_SHOWN) {
        writeln!(
            out,
            "<tr><td><code>{}</code></td><td>{}</td><td>{}</td></tr>",
            esc(s.var),
            runs(&s.readers),
            runs(&s.writers)
        )?;
    }
    out.write_all(b"</table>\n")?;
    if shared.len() > SHARED_ROWS_SHOWN {
        writeln!(
            out,
            "<p class=\"note\">… and {} more (the JSON report's <code>task_sharing</code> has every one).</p>",
            thousands(shared.len() - SHARED_ROWS_SHOWN)
        )?;
    }
    Ok(())
}

/// Program instances as `name (program)`, separated by commas (escaped).
fn instances(v: &[InstanceEntry]) -> String {
    if v.is_empty() {
        return "-".to_owned();
    }
    let named: Vec<String> = v
        .iter()
        .map(|i| format!("{} ({})", esc(i.name), esc(i.program)))
        .collect();
    named.join(", ")
}
