//! One program of a program file with a configuration, alone (`--pou NAME`): the surface syntax
//! of that program as the main program, as a PLCopen project read with `--pou` gives it.
//!
//! A JSON program with a `configuration` (docs/format.md, "Configuration"; `plc-deps convert` of
//! a PLCopen project with several programs writes one) has a main program that calls each
//! program instance's program, and those programs as subroutines whose variables are their own.
//! Selecting one program makes its body the main program's, its variables program-wide (after the
//! file's own program-wide variables, the project's globals), and drops the subroutines that are
//! the other program instances' programs. Subroutines no instance runs stay: a program may call
//! them. The configuration stays whole (the report still names every task); the caller has
//! checked it against the whole file.
//!
//! Invariants: the result differs from the input only in the main program's name, variables and
//! body and in the subroutines listed; nothing is resolved here (the resolver checks the result
//! as any file). Not here: selecting inside a PLCopen project (its reader selects before it
//! assembles the programs).

use super::{Program, RoutineKind};
use plc_model::Configuration;

/// Why a program cannot be selected.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum NotSelectable {
    /// The file has no configuration, so no program instances to choose from.
    NoConfiguration,
    /// No program instance runs a program of that name; the programs the instances run.
    Unknown { programs: Vec<String> },
}

/// The names of the programs the configuration's instances run, each once, in the order written.
pub fn instance_programs(c: &Configuration) -> Vec<String> {
    let mut names: Vec<String> = Vec::new();
    for r in &c.resources {
        let tasked = r.tasks.iter().flat_map(|t| &t.instances);
        for i in tasked.chain(&r.instances) {
            if !names.contains(&i.program) {
                names.push(i.program.clone());
            }
        }
    }
    names
}

/// `p` with the program `select` (any case), which a program instance of its configuration runs,
/// as its main program.
pub fn select_program<'a>(mut p: Program<'a>, select: &str) -> Result<Program<'a>, NotSelectable> {
    let Some(c) = &p.configuration else {
        return Err(NotSelectable::NoConfiguration);
    };
    let programs = instance_programs(c);
    let Some(name) = programs.iter().find(|n| n.eq_ignore_ascii_case(select)) else {
        return Err(NotSelectable::Unknown { programs });
    };
    if p.name.eq_ignore_ascii_case(name) {
        // The main program itself: only the other programs go.
        p.subroutines.retain(|s| {
            s.kind != RoutineKind::Subroutine || !programs.contains(&s.name.to_string())
        });
        return Ok(p);
    }
    let Some(at) = p
        .subroutines
        .iter()
        .position(|s| s.kind == RoutineKind::Subroutine && s.name == name.as_str())
    else {
        return Err(NotSelectable::Unknown { programs });
    };
    let chosen = p.subroutines.remove(at);
    p.subroutines
        .retain(|s| s.kind != RoutineKind::Subroutine || !programs.contains(&s.name.to_string()));
    p.name = chosen.name;
    p.vars.extend(chosen.vars);
    p.body = chosen.body;
    Ok(p)
}
