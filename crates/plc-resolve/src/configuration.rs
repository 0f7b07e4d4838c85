//! The rules a `configuration` of the JSON program format must keep (docs/format.md,
//! "Configuration"): the configuration, resource, task and program instance names are names
//! (letters, digits and `_`), and each program instance runs a POU of the program (the main
//! program, or a subroutine, by its name; not an interrupt routine). Tasks are put in the order
//! they run in ([`plc_model::Configuration`]'s invariant): by priority, 0 first, ties in the
//! order written.
//!
//! Called by the JSON loader on the resolved program (`plc_load`), not by [`super::resolve`]
//! itself: a PLCopen project read with `--pou` keeps its whole configuration while only the
//! selected program is in the model, and its reader has checked the configuration against the
//! whole project already. Errors carry the JSON path of the name they are about
//! (`configuration.resources[0].tasks[1].instances[0].program`), which the loader places.

use super::util::check_name;
use super::Result;
use plc_diag::{Invalid, LoadError, MAX_ERRORS};
use plc_model::{PouKind, Program, ProgramInstance};

/// Checks `p`'s configuration (if any) and puts its tasks in run order: every error, up to
/// [`MAX_ERRORS`], or none.
pub fn check(p: &mut Program) -> Result<()> {
    let Some(mut c) = p.configuration().cloned() else {
        return Ok(());
    };
    for r in &mut c.resources {
        r.tasks.sort_by_key(|t| t.priority);
    }
    p.set_configuration(Some(c));
    let c = p.configuration().expect("set above");
    let mut errors = Vec::new();
    let mut name = |n: &str, path: String| {
        if let Err(e) = check_name(n, || path, None) {
            errors.push(e);
        }
    };
    name(&c.name, "configuration.name".into());
    let runs = |i: &ProgramInstance, path: String, errors: &mut Vec<LoadError>| {
        if let Err(e) = instance(p, i, &path) {
            errors.push(e);
        }
    };
    let mut instances: Vec<(&ProgramInstance, String)> = Vec::new();
    for (ri, r) in c.resources.iter().enumerate() {
        let rp = format!("configuration.resources[{ri}]");
        name(&r.name, format!("{rp}.name"));
        for (ti, t) in r.tasks.iter().enumerate() {
            let tp = format!("{rp}.tasks[{ti}]");
            name(&t.name, format!("{tp}.name"));
            for (ii, i) in t.instances.iter().enumerate() {
                instances.push((i, format!("{tp}.instances[{ii}]")));
            }
        }
        for (ii, i) in r.instances.iter().enumerate() {
            instances.push((i, format!("{rp}.instances[{ii}]")));
        }
    }
    for (i, path) in instances {
        runs(i, path, &mut errors);
    }
    let ds: Vec<_> = errors
        .into_iter()
        .filter_map(|e| e.into_diagnostics().ok())
        .flatten()
        .take(MAX_ERRORS)
        .collect();
    match LoadError::from_diagnostics(ds) {
        None => Ok(()),
        Some(e) => Err(e),
    }
}

/// One program instance at `path`: its name, and that its program is a POU that can run.
fn instance(p: &Program, i: &ProgramInstance, path: &str) -> Result<()> {
    check_name(&i.name, || format!("{path}.name"), None)?;
    let runs = |kind: PouKind| kind != PouKind::Interrupt;
    if p.pous()
        .iter()
        .any(|pou| pou.name == i.program && runs(pou.kind))
    {
        return Ok(());
    }
    let pous: Vec<&str> = p
        .pous()
        .iter()
        .filter(|pou| runs(pou.kind))
        .map(|pou| pou.name.as_str())
        .collect();
    Err(LoadError::invalid(
        None,
        &format!("{path}.program"),
        Invalid::Configuration {
            message: format!(
                "program instance `{}` runs `{}`, which is not a program or subroutine of this file (they are {})",
                i.name,
                i.program,
                pous.join(", ")
            ),
        },
    ))
}
