//! The text report's sections for a PLCopen configuration: the tasks of each resource and the
//! program instances they run, the instances analysed, and the globals programs of different
//! tasks share (docs/report.md). Layout only: the data is [`crate::configuration`]'s.

use super::{list, more_rows, plural, Table, TextOptions};
use crate::configuration::{analysed_text, run_label, InstanceEntry, ProgramRunEntry};
use crate::document::Report;
use std::io::{self, Write};

/// A PLCopen project's tasks and what each runs, the program instances analysed, and the
/// globals programs of different tasks share.
pub(super) fn configuration(r: &Report, o: &TextOptions, out: &mut impl Write) -> io::Result<()> {
    let Some(c) = &r.configuration else {
        return Ok(());
    };
    let run = run_label;
    let instances = |v: &[InstanceEntry]| {
        let named: Vec<String> = v
            .iter()
            .map(|i| format!("{} ({})", i.name, i.program))
            .collect();
        list(&named.iter().map(String::as_str).collect::<Vec<_>>())
    };
    for res in &c.resources {
        writeln!(
            out,
            "\nTasks of configuration {}, resource {}: {}",
            c.name,
            res.name,
            plural(res.tasks.len(), "task", "tasks")
        )?;
        let mut t = Table::new(&[
            "task",
            "priority",
            "interval",
            "single",
            "program instances",
        ]);
        for task in &res.tasks {
            t.row(vec![
                task.name.into(),
                task.priority.to_string(),
                task.interval.unwrap_or("-").into(),
                task.single.unwrap_or("-").into(),
                instances(&task.instances),
            ]);
        }
        if !res.instances.is_empty() {
            t.row(vec![
                "(no task)".into(),
                "-".into(),
                "-".into(),
                "-".into(),
                instances(&res.instances),
            ]);
        }
        t.render(out)?;
    }
    writeln!(out, "Analysed: {}", analysed_text(c, &r.programs))?;
    // With one task (or none), nothing is shared between tasks.
    let Some(shared) = r.task_sharing.as_ref().filter(|_| c.several_tasks()) else {
        return Ok(());
    };
    writeln!(
        out,
        "\nGlobals shared between tasks (one task may see another's half-finished scan): {}",
        plural(shared.len(), "variable", "variables")
    )?;
    if shared.is_empty() {
        return Ok(());
    }
    let mut t = Table::new(&["variable", "read by", "written by"]);
    let shown = shared.len().min(o.limit());
    let runs = |v: &[ProgramRunEntry]| v.iter().map(run).collect::<Vec<_>>();
    for s in shared.iter().take(shown) {
        let (rd, wr) = (runs(&s.readers), runs(&s.writers));
        let lines = |v: Vec<String>| {
            if v.is_empty() {
                vec!["-".to_owned()]
            } else {
                v
            }
        };
        t.row_lines(vec![vec![s.var.to_owned()], lines(rd), lines(wr)]);
    }
    t.render(out)?;
    more_rows(out, shown, shared.len())
}
