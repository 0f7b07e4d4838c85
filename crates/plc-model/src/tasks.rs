//! The configuration of a PLCopen project as plain data: its resources, their tasks (interval,
//! priority, single) and the program instances each task runs (IEC 61131-3 6.8.2, 6.8.3; TC6
//! `instances/configurations`).
//!
//! Carried from the reader through the resolver unchanged, so that reports and analyses can name
//! who runs what. Invariants (the reader and the resolver check them): every
//! [`ProgramInstance::program`] names a POU of the program (the main program, or a subroutine of
//! that name); tasks are in the order plc-deps runs them (priority, 0 first, ties in file order).
//!
//! It does not schedule anything: `run` runs every instance once a scan in task order.
//!
//! The JSON program format carries it as `configuration` (docs/format.md, "Configuration"), in
//! the shape the report's `configuration` key has: these types (de)serialise to exactly that,
//! unknown fields refused, absent optional fields read as `None`, no task or instance lists
//! read as empty, an absent priority as 0 (TC6's default).

use super::{PouId, PouKind, Program};

/// A configuration (TC6 `configuration`).
#[derive(Clone, Debug, Default, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Configuration {
    pub name: String,
    #[serde(default)]
    pub resources: Vec<Resource>,
}

/// A resource of a configuration: its tasks, and the program instances no task runs.
#[derive(Clone, Debug, Default, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Resource {
    pub name: String,
    /// In run order: by priority, ties in file order.
    #[serde(default)]
    pub tasks: Vec<Task>,
    /// The resource's own `pouInstance`s (run after every task's).
    #[serde(default)]
    pub instances: Vec<ProgramInstance>,
}

/// A task (TC6 `task`): when it runs, and what.
#[derive(Clone, Debug, Default, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Task {
    pub name: String,
    #[serde(default)]
    pub priority: u32,
    /// The `interval` attribute as written (`T#20ms`), if any.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub interval: Option<String>,
    /// The `single` attribute as written (the variable whose rising edge triggers it), if any.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub single: Option<String>,
    /// In file order.
    #[serde(default)]
    pub instances: Vec<ProgramInstance>,
}

/// One program instance (TC6 `pouInstance`): its name and the program POU it runs.
#[derive(Clone, Debug, Default, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ProgramInstance {
    pub name: String,
    pub program: String,
}

/// One program instance as run: its task (`None`: the resource runs it without a task), the
/// instance, and the POU of its program.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct ProgramRun {
    pub task: Option<String>,
    pub instance: String,
    pub program: String,
    pub pou: PouId,
}

impl Program {
    /// Every program instance of the configuration, in run order, with its POU (instances whose
    /// program is no POU of the model are left out; the resolver refuses them). Empty without
    /// a configuration.
    pub fn program_runs(&self) -> Vec<ProgramRun> {
        let Some(conf) = &self.configuration else {
            return Vec::new();
        };
        let pou = |name: &str| {
            self.pous
                .iter()
                .position(|p| p.name == name && p.kind != PouKind::Interrupt)
                .map(|i| PouId(i as u32))
        };
        let mut runs = Vec::new();
        for r in &conf.resources {
            let tasked = r
                .tasks
                .iter()
                .flat_map(|t| t.instances.iter().map(move |i| (Some(&t.name), i)));
            let own = r.instances.iter().map(|i| (None, i));
            for (task, i) in tasked.chain(own) {
                if let Some(p) = pou(&i.program) {
                    runs.push(ProgramRun {
                        task: task.cloned(),
                        instance: i.name.clone(),
                        program: i.program.clone(),
                        pou: p,
                    });
                }
            }
        }
        runs
    }
}
