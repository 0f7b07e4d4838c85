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
//! A file without a configuration (an S7-200 or JSON program of one main program and its
//! subroutines) selects a subroutine or interrupt routine instead: its body is the main body
//! and its variables program-wide, with the routines it calls, for the analysis of that one
//! routine.
//!
//! Invariants: the result differs from the input only in the main program's name, variables and
//! body and in the subroutines listed; nothing is resolved here (the resolver checks the result
//! as any file). Not here: selecting inside a PLCopen project (its reader selects before it
//! assembles the programs).

use super::{Body, Element, ElementKind, Program, RoutineKind};
use plc_model::Configuration;

/// Why a program cannot be selected.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum NotSelectable {
    /// The file has no configuration, and no subroutine of that name; its subroutines (and
    /// interrupt routines), in file order.
    NoConfiguration { subroutines: Vec<String> },
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
        return select_routine(p, select);
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

/// `p`, which has no configuration, with its subroutine or interrupt routine `select` (any case)
/// as the main program (`--pou SBR_0` on an S7-200 or JSON program): its body the main body, its
/// variables program-wide after the program's own; the main program's body goes, and so do the
/// routines the chosen one does not call, directly or through others. A local named like a program-wide variable is
/// declared twice, which the resolver reports.
fn select_routine<'a>(mut p: Program<'a>, select: &str) -> Result<Program<'a>, NotSelectable> {
    let Some(at) = p
        .subroutines
        .iter()
        .position(|s| s.name.eq_ignore_ascii_case(select))
    else {
        let subroutines = p.subroutines.iter().map(|s| s.name.to_string()).collect();
        return Err(NotSelectable::NoConfiguration { subroutines });
    };
    let chosen = p.subroutines.remove(at);
    // The routines the chosen one calls, directly or through others: they stay, the others go.
    let mut called: Vec<String> = Vec::new();
    let mut todo = vec![chosen.body.as_ref()];
    while let Some(body) = todo.pop() {
        let mut names = Vec::new();
        match body {
            Some(Body::Rungs(rungs)) => {
                for r in rungs {
                    calls(&r.ld, &mut names);
                }
            }
            // An FBD body calls no subroutine; none is a body not read.
            Some(Body::Fbd(_)) | None => {}
        }
        for n in names {
            if called.iter().any(|c| c.eq_ignore_ascii_case(&n)) {
                continue;
            }
            if let Some(s) = p
                .subroutines
                .iter()
                .find(|s| s.name.eq_ignore_ascii_case(&n))
            {
                todo.push(s.body.as_ref());
            }
            called.push(n);
        }
    }
    p.subroutines
        .retain(|s| called.iter().any(|c| c.eq_ignore_ascii_case(&s.name)));
    p.name = chosen.name;
    p.vars.extend(chosen.vars);
    p.body = chosen.body;
    Ok(p)
}

/// The names `series` calls (`call` elements, in branches too), in order.
fn calls(series: &[Element], names: &mut Vec<String>) {
    for e in series {
        match &e.kind {
            ElementKind::Call(name) => names.push(name.value.to_string()),
            ElementKind::Or(branches) | ElementKind::Branch(branches) => {
                for b in branches {
                    calls(b, names);
                }
            }
            _ => {}
        }
    }
}
