//! Loading: a program file's text → its reader ([`plc_read`]: JSON, PLCopen TC6 XML or S7-200
//! STL) → the surface syntax ([`plc_syntax`]) → the resolver ([`plc_resolve`]) → one
//! resolved [`Program`] with its FBD bodies ([`Fbd`]).
//!
//! This is the one place where a reader and the resolver meet, so that neither imports the
//! other: the readers know only the syntax, the resolver only the syntax and the model.
//!
//! Invariants: a program loads whole or not at all; every error is one [`LoadError`] located in
//! the text (line and column, the rung or block). It does not read files or pick the format by
//! content: the commands do that (`cmd::io`).
#![forbid(unsafe_code)]

use plc_diag::LoadError;
use plc_fbd::Fbd;
use plc_model::Program;
use plc_read as read;
pub use plc_read::plcopen::Pick;
use plc_read::plcopen::{ExecOrder, Note};
use plc_resolve as resolve;

/// Parses and checks a program given as JSON text.
pub fn program_from_json(text: &str) -> Result<Program, LoadError> {
    program_and_fbd_from_json(text).map(|(p, _)| p)
}

/// Parses and checks a program given as JSON text, and returns with it the FBD bodies it was
/// written in (before lowering: their networks, execution orders and fragment trees).
///
/// The main program's rungs are resolved as they are read ([`resolve::Stream`]), so that
/// the whole syntax tree is never held; should that not resolve, the text is read again into
/// the whole tree, whose resolution gives the program or every error, as it always would.
pub fn program_and_fbd_from_json(text: &str) -> Result<(Program, Fbd), LoadError> {
    let whole = |syntax: &plc_syntax::Program<'_>| {
        resolve::resolve(text, syntax).map_err(|e| placed(text, e))
    };
    let mut stream = resolve::Stream::default();
    let syntax = if text.len() >= PIPE_FROM && two_cores() {
        plc_syntax::pipe::through_pipe(&mut stream, |sink| {
            read::json::parse_with(text, Some(sink))
        })?
    } else {
        read::json::parse_with(text, Some(&mut stream))?
    };
    let (mut p, f) = if !stream.took_rungs() {
        whole(&syntax)?
    } else if let Some(done) = stream.finish(&syntax) {
        done
    } else {
        drop(syntax);
        whole(&read::json::parse(text)?)?
    };
    // After the resolution: the configuration names the POUs it made.
    resolve::configuration::check(&mut p).map_err(|e| placed(text, e))?;
    Ok((p, f))
}

/// [`program_and_fbd_from_json`] with only the program `select` (any case) that a program
/// instance of the file's configuration runs, as the main program (`--pou`), as
/// [`plcopen_selected`] gives a project's program: the whole file is checked first (every error
/// it has), then the program alone is resolved; the configuration stays whole.
pub fn program_and_fbd_from_json_selected(
    text: &str,
    select: &str,
) -> Result<(Program, Fbd), LoadError> {
    use plc_syntax::select::{select_program, NotSelectable};
    let (whole, _) = program_and_fbd_from_json(text)?;
    let not_found = |message: String| {
        placed(
            text,
            LoadError::invalid(
                None,
                "configuration",
                plc_diag::Invalid::Configuration { message },
            ),
        )
    };
    let syntax = match select_program(read::json::parse(text)?, select) {
        Ok(s) => s,
        Err(NotSelectable::NoConfiguration { subroutines }) => {
            return Err(placed(
                text,
                LoadError::invalid(None, "", no_such_routine(select, &subroutines)),
            ))
        }
        Err(NotSelectable::Unknown { programs }) => {
            return Err(not_found(format!(
                "--pou {select}: no program instance runs a program of that name; they run {}",
                programs.join(", ")
            )))
        }
    };
    let (mut p, f) = resolve::resolve(text, &syntax).map_err(|e| placed(text, e))?;
    p.set_configuration(whole.configuration().cloned());
    p.set_dialect(whole.dialect());
    Ok((p, f))
}

/// `--pou NAME` on a program without a configuration that has no routine of that name.
fn no_such_routine(select: &str, subroutines: &[String]) -> plc_diag::Invalid {
    let has = match subroutines {
        [] => "it has none".to_owned(),
        names => format!("it has {}", names.join(", ")),
    };
    plc_diag::Invalid::Configuration {
        message: format!("--pou {select}: the program has no configuration, so --pou selects one of its subroutines, and no subroutine has that name; {has}"),
    }
}

/// An error of a JSON program placed at the value its path names.
fn placed(text: &str, e: LoadError) -> LoadError {
    e.refine(text, |t, p| {
        read::json::path_offset(t, p).map(|(start, _)| start)
    })
}

/// Files from this size on are read on one thread and resolved on another
/// ([`plc_syntax::pipe`]); below it, starting a thread costs more than it gains.
const PIPE_FROM: usize = 1 << 20;

fn two_cores() -> bool {
    std::thread::available_parallelism().is_ok_and(|n| n.get() > 1)
}

/// Builds a program from an already parsed JSON document (tests and benchmarks that build
/// programs with `serde_read::json::json!`). Loading from text is the fast path.
pub fn program_from_value(doc: &serde_json::Value) -> Result<Program, LoadError> {
    program_from_json(&doc.to_string())
}

/// [`program_from_value`], with the FBD bodies.
pub fn program_and_fbd_from_value(doc: &serde_json::Value) -> Result<(Program, Fbd), LoadError> {
    program_and_fbd_from_json(&doc.to_string())
}

/// Reads and resolves a PLCopen project: the program, its FBD bodies, and the reader's notes
/// (with one for each FBD body whose executionOrderIds order its blocks otherwise than plc-deps,
/// and one for what `run` could not execute).
pub fn plcopen(text: &str) -> Result<(Program, Fbd, Vec<Note>), LoadError> {
    plcopen_selected(text, Pick::default()).map(|r| {
        let notes = r.configurations.into_iter().chain(r.notes).collect();
        (r.program, r.fbd, notes)
    })
}

/// A PLCopen project read and resolved for a [`Pick`].
#[derive(Debug)]
pub struct PlcOpenRead {
    pub program: Program,
    pub fbd: Fbd,
    /// The reader's notes (W0501).
    pub notes: Vec<Note>,
    /// The project has several configurations and the pick chose none: which was read and
    /// which were not (W0502).
    pub configurations: Option<Note>,
}

/// [`plcopen`] with only the program POU `pick.pou` (any case), when given, as the main program
/// (`--pou`): an error listing the programs when the project has none of that name; and the
/// configuration `pick.configuration` (`--configuration`), an error listing them when the
/// project has none of that name.
pub fn plcopen_selected(text: &str, pick: Pick) -> Result<PlcOpenRead, LoadError> {
    let mut r = plcopen_all(text, pick, false)?;
    r.read.notes.extend(r.no_run.take());
    Ok(r.read)
}

/// [`plcopen_selected`] for code generation (`c`): each ST body that lowers to rungs is those
/// rungs, as `run` executes them ([`plcopen_for_run`]), instead of a stand-in per statement.
pub fn plcopen_lowered_selected(text: &str, pick: Pick) -> Result<PlcOpenRead, LoadError> {
    let mut r = plcopen_all(text, pick, true)?;
    r.read.notes.extend(r.no_run.take());
    Ok(r.read)
}

/// [`plcopen`] for `run`: an error (located) when the project has something `run` cannot execute
/// (a string in an LD or FBD body).
pub fn plcopen_for_run(text: &str) -> Result<(Program, Fbd, Vec<Note>), LoadError> {
    plcopen_for_run_selected(text, Pick::default()).map(|r| {
        let notes = r.configurations.into_iter().chain(r.notes).collect();
        (r.program, r.fbd, notes)
    })
}

/// [`plcopen_for_run`] with the program and configuration `pick`, as [`plcopen_selected`].
pub fn plcopen_for_run_selected(text: &str, pick: Pick) -> Result<PlcOpenRead, LoadError> {
    let r = plcopen_all(text, pick, true)?;
    match r.no_run {
        Some(n) => Err(read::plcopen::run_refusal(n, text)),
        None => Ok(r.read),
    }
}

/// The project read, and the note of what `run` cannot execute.
struct PlcOpenLoaded {
    read: PlcOpenRead,
    no_run: Option<Note>,
}

fn plcopen_all(text: &str, pick: Pick, exec: bool) -> Result<PlcOpenLoaded, LoadError> {
    let (_, mut notes, (p, f)) = plcopen_read(text, pick, exec)?;
    for x in &notes.exec_orders {
        if let Some(n) = exec_order_note(&f, x) {
            notes.list.push(n);
        }
    }
    let no_run = notes.no_run.into_iter().next().map(|(_, n)| n);
    Ok(PlcOpenLoaded {
        read: PlcOpenRead {
            program: p,
            fbd: f,
            notes: notes.list,
            configurations: notes.configurations,
        },
        no_run,
    })
}

/// The syntax of PLCopen `text` as the loaders read it ([`plcopen_read`]): what `convert`
/// writes.
pub fn plcopen_syntax(
    text: &str,
    pick: Pick,
    exec: bool,
) -> Result<plc_syntax::Program<'static>, LoadError> {
    plcopen_read(text, pick, exec).map(|(syntax, _, _)| syntax)
}

/// PLCopen `text` read and resolved. A function whose body the reader takes but the resolver
/// refuses (an AND of BYTEs, which the model does not have) is read again as a black box, as
/// before its calls were executed: once per such function.
fn plcopen_read(
    text: &str,
    pick: Pick,
    exec: bool,
) -> Result<
    (
        plc_syntax::Program<'static>,
        read::plcopen::Notes,
        (Program, Fbd),
    ),
    LoadError,
> {
    let mut refuse: Vec<(String, String)> = Vec::new();
    loop {
        let (syntax, notes) = read::plcopen::parse_refusing(text, pick, exec, refuse.clone())?;
        match resolve::resolve(text, &syntax) {
            Ok(pf) => return Ok((syntax, notes, pf)),
            Err(e) => match failed_function(&e) {
                Some(name) if !refuse.iter().any(|(n, _)| *n == name) => {
                    refuse.push((name, format!("its body does not load: {e}")));
                }
                _ => return Err(e),
            },
        }
    }
}

/// The function (lower case) whose body, executed as a function block type (`st__fn__F`), the
/// error `e` is in.
fn failed_function(e: &LoadError) -> Option<String> {
    let LoadError::Invalid(d) = e else {
        return None;
    };
    let rest = d.location.path.strip_prefix("function_blocks.st__fn__")?;
    let name = rest.split('.').next()?;
    Some(name.to_ascii_lowercase())
}

/// Compares the order of the file's executionOrderIds with the order plc-deps runs the same
/// blocks in (the FBD text-generation paper's sort, docs/fbd.md): a note with both if they differ.
fn exec_order_note(f: &Fbd, x: &ExecOrder) -> Option<Note> {
    let pou = f
        .pous
        .iter()
        .find(|p| p.networks.iter().any(|n| Some(&n.id) == x.networks.first()))?;
    let wanted: std::collections::HashSet<u32> = x.ids.iter().map(|&(_, l)| l).collect();
    let ours: Vec<u32> = pou
        .networks
        .iter()
        .zip(&pou.plans)
        .flat_map(|(n, plan)| plan.order.iter().map(move |&b| n.block(b).id))
        .filter(|id| wanted.contains(id))
        .collect();
    // Only the elements that are blocks here (an out variable is part of the block feeding it).
    let file: Vec<u32> = x
        .ids
        .iter()
        .map(|&(_, l)| l)
        .filter(|l| ours.contains(l))
        .collect();
    if ours == file {
        return None;
    }
    let show = |v: &[u32]| v.iter().map(u32::to_string).collect::<Vec<_>>().join(", ");
    Some(Note {
        origin: x.origin,
        message: format!(
            "pou {}, FBD: the file's executionOrderIds run localIds {}; plc-deps runs them {} (data flow first, ties by localId; `plc-deps order` shows the whole order)",
            pou.name,
            show(&file),
            show(&ours)
        ),
    })
}

/// Reads and resolves an STL file: the program and its (empty) FBD bodies.
pub fn stl(text: &str) -> Result<(Program, Fbd), LoadError> {
    let syntax = read::stl::parse(text)?;
    resolve::resolve(text, &syntax)
}

/// [`stl`] with the subroutine or interrupt routine `select` (any case) as the main program
/// (`--pou SBR_0`), as [`plc_syntax::select::select_program`] gives it.
pub fn stl_selected(text: &str, select: &str) -> Result<(Program, Fbd), LoadError> {
    use plc_syntax::select::{select_program, NotSelectable};
    stl(text)?;
    let syntax = match select_program(read::stl::parse(text)?, select) {
        Ok(s) => s,
        // An STL program has no configuration.
        Err(NotSelectable::NoConfiguration { subroutines: names })
        | Err(NotSelectable::Unknown { programs: names }) => {
            return Err(LoadError::invalid(
                None,
                "",
                no_such_routine(select, &names),
            ))
        }
    };
    resolve::resolve(text, &syntax)
}
