//! The report's entries for a PLCopen configuration: its resources, their tasks and the program
//! instances each runs, the program instances analysed, and the globals that programs of
//! different tasks share ([`plc_analysis::task_sharing`]). Plain borrowed data that the JSON
//! renderer serialises (keys `configuration`, `programs`, `task_sharing`, docs/report.md) and
//! the text renderer lays out; nothing here is computed beyond naming.

use plc_analysis::Analysis;
use plc_model::{Configuration, Program, ProgramInstance, ProgramRun};

/// A PLCopen configuration.
#[derive(serde::Serialize)]
pub struct ConfigurationEntry<'a> {
    pub name: &'a str,
    pub resources: Vec<ResourceEntry<'a>>,
}

/// A resource: its tasks in run order, and the program instances it runs without a task.
#[derive(serde::Serialize)]
pub struct ResourceEntry<'a> {
    pub name: &'a str,
    pub tasks: Vec<TaskEntryPlc<'a>>,
    pub instances: Vec<InstanceEntry<'a>>,
}

/// A task of a resource (its attributes as written) and the program instances it runs.
#[derive(serde::Serialize)]
pub struct TaskEntryPlc<'a> {
    pub name: &'a str,
    pub priority: u32,
    pub interval: Option<&'a str>,
    pub single: Option<&'a str>,
    pub instances: Vec<InstanceEntry<'a>>,
}

/// A program instance: its name and its program.
#[derive(serde::Serialize)]
pub struct InstanceEntry<'a> {
    pub name: &'a str,
    pub program: &'a str,
}

/// A program instance as run: its task (`None`: the resource's own), name and program.
#[derive(serde::Serialize)]
pub struct ProgramRunEntry<'a> {
    pub task: Option<&'a str>,
    pub instance: &'a str,
    pub program: &'a str,
}

/// A global that programs of different tasks share, and who reads and who writes it.
#[derive(serde::Serialize)]
pub struct TaskSharedEntry<'a> {
    pub var: &'a str,
    pub readers: Vec<ProgramRunEntry<'a>>,
    pub writers: Vec<ProgramRunEntry<'a>>,
}

pub fn configuration_entry(c: &Configuration) -> ConfigurationEntry<'_> {
    ConfigurationEntry {
        name: &c.name,
        resources: c
            .resources
            .iter()
            .map(|r| ResourceEntry {
                name: &r.name,
                tasks: r
                    .tasks
                    .iter()
                    .map(|t| TaskEntryPlc {
                        name: &t.name,
                        priority: t.priority,
                        interval: t.interval.as_deref(),
                        single: t.single.as_deref(),
                        instances: instances(&t.instances),
                    })
                    .collect(),
                instances: instances(&r.instances),
            })
            .collect(),
    }
}

pub fn run_entry(r: &ProgramRun) -> ProgramRunEntry<'_> {
    ProgramRunEntry {
        task: r.task.as_deref(),
        instance: &r.instance,
        program: &r.program,
    }
}

/// A program instance as the text outputs name it: `task.instance (program)`, or
/// `instance (program)` for the resource's own.
pub fn run_label(e: &ProgramRunEntry) -> String {
    match e.task {
        Some(t) => format!("{t}.{} ({})", e.instance, e.program),
        None => format!("{} ({})", e.instance, e.program),
    }
}

impl ConfigurationEntry<'_> {
    /// How many program instances the configuration has, under tasks or not.
    pub fn instance_count(&self) -> usize {
        self.resources
            .iter()
            .map(|r| r.instances.len() + r.tasks.iter().map(|t| t.instances.len()).sum::<usize>())
            .sum()
    }

    /// Whether programs of different tasks can share anything: more than one task, counting
    /// the resource's own instances as one.
    pub fn several_tasks(&self) -> bool {
        let groups: usize = self
            .resources
            .iter()
            .map(|r| r.tasks.len() + usize::from(!r.instances.is_empty()))
            .sum();
        groups > 1
    }
}

/// Which program instances of `c` were analysed (`programs`, in run order), in words: `the only
/// program instance: T.i (P)`, `all 4 program instances, in task order: …`, `1 program instance
/// of 4: …`.
pub fn analysed_text(c: &ConfigurationEntry, programs: &[ProgramRunEntry]) -> String {
    let total = c.instance_count();
    let plural = crate::words::plural;
    let which = if total == 1 && programs.len() == 1 {
        "the only program instance".to_owned()
    } else if programs.len() == total {
        format!(
            "all {}, in task order",
            plural(total, "program instance", "program instances")
        )
    } else {
        format!(
            "{} of {total}",
            plural(programs.len(), "program instance", "program instances")
        )
    };
    let names: Vec<String> = programs.iter().map(run_label).collect();
    format!("{which}: {}", names.join(", "))
}

pub fn task_shared_entries<'a>(
    p: &'a Program,
    a: &'a Analysis,
) -> Option<Vec<TaskSharedEntry<'a>>> {
    let ts = &a.task_sharing;
    p.configuration().as_ref()?;
    let runs = |v: &[usize]| v.iter().map(|&i| run_entry(&ts.runs[i])).collect();
    Some(
        ts.shared
            .iter()
            .map(|s| TaskSharedEntry {
                var: &p.var(s.var).name,
                readers: runs(&s.readers),
                writers: runs(&s.writers),
            })
            .collect(),
    )
}

fn instances(v: &[ProgramInstance]) -> Vec<InstanceEntry<'_>> {
    v.iter()
        .map(|i| InstanceEntry {
            name: &i.name,
            program: &i.program,
        })
        .collect()
}
