//! The resolver: surface syntax ([`plc_syntax`]) → the model ([`plc_model::Program`] and
//! the FBD bodies [`plc_fbd::Fbd`]).
//!
//! One place for every rule that needs more than one node (docs/format.md, docs/fbd.md):
//! declarations (names, types, classes, initial values; IEC 61131-3 6.5), name resolution
//! (subroutine or instance locals first, then program variables), operand typing, unique rung ids
//! (program-wide) and labels (per POU), FOR/NEXT nesting, no jump into a FOR body, no recursive
//! calls, `end` in the main program only, no writes to inputs or instance fields, FBD networks
//! (ids, arcs, labels; order and fragments by the pure algorithms of `plc_fbd`), user function
//! block types (no type containing itself) expanded into one POU per instance. The lowering of
//! FBD bodies into rungs is `plc_fbd`'s ([`plc_fbd::lower`]): the resolver gives it each POU's
//! scope through [`plc_fbd::lower::Env`] and keeps the rungs it returns.
//!
//! Errors are collected, in program order, up to [`MAX_ERRORS`], phase by phase: the reader's
//! problems and the declarations; instances and FBD lowering; rung ids and labels; elements (the
//! first problem of each rung); loops, jumps and calls. A phase with errors ends the resolution
//! (later phases would only report their consequences). Paths are rendered only for errors;
//! each error gets the origin of the most precise syntax node it names (operand, element, field,
//! variable, rung, FBD body), and their lines and columns are computed in one pass over the text
//! when the resolution fails ([`LoadError::locate`]). Names are looked up in [`table`]s that
//! cost one cache miss a lookup. Nothing is half-built: a program either resolves whole or not
//! at all.
//!
//! The main program's rungs are usually resolved as the reader reads them ([`Stream`], a
//! [`syntax::RungSink`]): a million rungs are then never held as syntax. That path gives the
//! same model or gives up, and the whole tree is resolved instead (which reports the errors):
//! errors always come from the phases above.
#![forbid(unsafe_code)]

pub mod configuration;
mod elements;
pub(crate) mod fbd_read;
mod function_blocks;
mod lowering;
mod names;
pub(crate) mod operand;
mod path;
mod stream;
mod structure;
mod table;
pub(crate) mod util;
mod vars;

pub use plc_fbd::ACCUMULATE_PT_MS;
pub use stream::Stream;

use fbd_read::FbSig;
use plc_diag::{Diagnostic, Invalid, LoadError, MAX_ERRORS};
use plc_fbd::{Fbd, FbdPou, FbdPouKind};
use plc_model::*;
use plc_syntax as syntax;
use std::borrow::Cow;
use util::{FastMap, FastSet};

use elements::{Place, Scope};
use lowering::relocate_jumps;
use path::At;
use table::NameTable;
use util::{check_label, check_name, check_printable, rung_path};

type Result<T> = std::result::Result<T, LoadError>;

/// Resolves a program read from `text` (the text gives the line and column of nodes for errors,
/// computed only when there are errors).
pub fn resolve(text: &str, syn: &syntax::Program<'_>) -> Result<(Program, Fbd)> {
    let (mut program, fbd) = resolve_syntax(syn).map_err(|e| e.locate(text))?;
    mark_skipped(&mut program, &fbd, &syn.skipped, text);
    Ok((program, fbd))
}

/// Marks each POU whose body was `skipped` (by its own name, or its function block type's for
/// an instance's POU), with the line and column of the body in `text`.
fn mark_skipped(program: &mut Program, fbd: &Fbd, skipped: &[syntax::SkippedBody], text: &str) {
    for s in skipped {
        for id in program.pous().ids() {
            let pou = program.pou(id);
            let of_type = |inst: &plc_fbd::FbInstance| inst.pou == id && inst.fb == s.pou;
            if pou.skipped.is_none() && (pou.name == s.pou || fbd.instances.iter().any(of_type)) {
                program.mark_skipped(
                    id,
                    SkippedBody {
                        language: s.language.clone(),
                        position: s.origin.line_column(text),
                        why: s.why.as_ref().map(|(at, what)| match at.line_column(text) {
                            Some((l, c)) => format!("{what} at {l}:{c}"),
                            None => what.clone(),
                        }),
                    },
                );
            }
        }
    }
}

fn resolve_syntax(syn: &syntax::Program<'_>) -> Result<(Program, Fbd)> {
    let mut b = Builder::default();
    let name = check_printable("program name", &syn.name, || "program".into(), None);
    if let Err(e) = name {
        b.report(e.at(syn.name_origin.or(syn.origin)));
    }
    for p in &syn.problems {
        b.report(LoadError::invalid(None, &p.at, p.kind.clone()).at(p.origin));
    }
    b.declarations(syn);
    b.resolve_declared(syn)
}

impl<'a> Builder<'a> {
    /// Everything after the declarations: instances, FBD lowering, the rungs, the structure.
    fn resolve_declared(self, syn: &'a syntax::Program<'a>) -> Result<(Program, Fbd)> {
        let mut b = self;
        b.phase_end()?;
        // Instances of user function blocks: one POU each, after the subroutines.
        let top_level: Vec<usize> = std::mem::take(&mut b.pending);
        for i in top_level {
            let r = b.expand(i, &mut Vec::new());
            b.collect(r);
        }
        b.phase_end()?;
        let r = b.lower_fbd();
        b.collect(r);
        b.phase_end()?;
        let mut bodies = std::mem::take(&mut b.fbd_bodies);
        // Copied: the ladder rungs still read instance members through `b.instances`.
        let mut instances: Vec<plc_fbd::FbInstance> = b
            .instances
            .iter()
            .filter_map(|i| {
                Some(plc_fbd::FbInstance {
                    pou: i.pou?,
                    name: i.display.clone(),
                    fb: i.fb.clone(),
                    ty: b.fb_types.id(*b.fb_index.get(&i.fb)?),
                    inputs: i.inputs.clone(),
                    outputs: i.outputs.clone(),
                })
            })
            .collect();
        instances.sort_by_key(|i| i.pou);
        let types = b.fb_type_models(&bodies);
        let mut program = b.build(syn.name.to_string(), syn.origin)?;
        program.set_configuration(syn.configuration.clone());
        program.set_dialect(syn.dialect);
        for body in &mut bodies {
            for copy in &mut body.copies {
                let start = program.pou(copy.pou).rungs.start;
                for r in &mut copy.networks {
                    *r = r.start + start..r.end + start;
                }
                for blocks in &mut copy.blocks {
                    for r in blocks.iter_mut() {
                        *r = r.shifted(start);
                    }
                }
            }
        }
        // Main program and subroutines first, then function block types (each in file order).
        let (mut pous, fbs): (Vec<FbdPou>, Vec<FbdPou>) = bodies
            .into_iter()
            .partition(|p| p.kind != FbdPouKind::FunctionBlock);
        pous.extend(fbs);
        Ok((
            program,
            Fbd {
                pous,
                instances,
                types,
            },
        ))
    }
}

struct PouDraft<'a> {
    name: String,
    kind: PouKind,
    /// JSON path of the rung array ("" means top-level `rungs`).
    path: String,
    rungs: &'a [syntax::Rung<'a>],
    /// Index into `Builder::fbd_bodies` when the body is FBD.
    fbd: Option<usize>,
    /// An FBD body after lowering (jump targets relative to the POU).
    lowered: Option<Vec<Rung>>,
    /// Prepended to rung ids (`G1:` for the POU of function block instance `G1`).
    prefix: String,
    /// Prepended to the names of hidden variables of an FBD body (`SBR:`, `G1.`).
    var_prefix: String,
    /// False for instances of function blocks: `call` cannot name them.
    callable: bool,
}

impl<'a> PouDraft<'a> {
    fn new(name: String, kind: PouKind, path: String) -> PouDraft<'a> {
        let var_prefix = if kind == PouKind::Main {
            String::new()
        } else {
            format!("{name}:")
        };
        PouDraft {
            name,
            kind,
            path,
            rungs: &[],
            fbd: None,
            lowered: None,
            prefix: String::new(),
            var_prefix,
            callable: true,
        }
    }
}

/// A user function block type: its declarations and body.
struct FbType<'a> {
    name: String,
    path: String,
    inputs: &'a [syntax::Var<'a>],
    outputs: &'a [syntax::Var<'a>],
    vars: &'a [syntax::Var<'a>],
    /// The ladder body, or the index of the FBD body in `Builder::fbd_bodies`.
    rungs: Option<&'a [syntax::Rung<'a>]>,
    fbd: Option<usize>,
    sig: FbSig,
    /// What the resolved program keeps of the type (its body's typed form once an instance
    /// of it is lowered).
    model: plc_fbd::FbType,
}

/// An instance of a user function block type.
struct InstanceDraft {
    /// `G1`, `SBR:G1`, `G1.INNER`.
    display: String,
    fb: String,
    /// JSON path of its declaration.
    path: String,
    /// Where its declaration and its name start.
    origin: syntax::Origin,
    name_origin: syntax::Origin,
    pou: Option<PouId>,
    inputs: Vec<(String, VarId)>,
    outputs: Vec<(String, VarId)>,
}

/// A program-wide rule (ids, labels, names) is kept per POU; every table is indexed by POU.
#[derive(Default)]
struct Builder<'a> {
    /// Problems found so far, in program order (at most [`MAX_ERRORS`]).
    errors: Vec<Diagnostic>,
    vars: Arena<VarId, Var>,
    /// Display names of all variables, built when the first hidden FBD variable is made (its
    /// name must not clash).
    var_names: Option<FastSet<String>>,
    globals: NameTable<VarId>,
    /// Per POU: its local variables.
    locals: Arena<PouId, NameTable<VarId>>,
    /// Program-wide and per-POU instances of user function blocks (index into `instances`).
    global_instances: NameTable<usize>,
    local_instances: Vec<NameTable<usize>>,
    instances: Vec<InstanceDraft>,
    /// Instances declared but not yet given their POU.
    pending: Vec<usize>,
    fb_types: Arena<plc_fbd::FbTypeId, FbType<'a>>,
    fb_index: FastMap<String, usize>,
    /// FBD bodies in reading order (function block types first, as they are read first), and
    /// where each starts in the text.
    fbd_bodies: Vec<FbdPou>,
    fbd_origins: Vec<syntax::Origin>,
    /// TIME variables accumulated by TSTART/TSTOP, with the POU that does it.
    accumulated: FastMap<VarId, PouId>,
    pous: Arena<PouId, PouDraft<'a>>,
    /// Per POU: label → rung.
    labels: Vec<FastMap<String, RungId>>,
    /// Per rung, during element resolution: number of edge contacts so far.
    edge_count: u32,
    /// The main program's rungs when they were resolved as the reader read them.
    streamed: Option<stream::Streamed<'a>>,
    /// The variable of the next edge contact, when it was made before the rung was resolved
    /// (a rung resolved after the rungs read after it: [`stream`]).
    edge_reserved: Option<Numbering<VarId>>,
    /// The first parts of the dotted variable names (a structure flattened into its fields,
    /// `Motor` of `Motor.Speed`) by scope (a POU, `None` for the program's), so that an
    /// unknown field of a structure is named as such.
    structure_roots: FastSet<(Option<PouId>, String)>,
    /// The input variables that coils, set/reset, moves and block outputs write
    /// ([`Program::written_inputs`]).
    written_inputs: std::cell::RefCell<Vec<VarId>>,
}

/// A ladder rung after pass 1: its id, its syntax and its (prefixed) id text.
type RungHead<'a> = (RungId, &'a syntax::Rung<'a>, String);

impl<'a> Builder<'a> {
    /// Records the problems of `e` (up to [`MAX_ERRORS`]).
    fn report(&mut self, e: LoadError) {
        if let Ok(ds) = e.into_diagnostics() {
            let room = MAX_ERRORS.saturating_sub(self.errors.len());
            for d in ds.into_iter().take(room) {
                let d = self.hinted(d);
                self.errors.push(d);
            }
        }
    }

    fn collect<T>(&mut self, r: Result<T>) -> Option<T> {
        match r {
            Ok(v) => Some(v),
            Err(e) => {
                self.report(e);
                None
            }
        }
    }

    /// Ends a phase: the errors so far, if any.
    fn phase_end(&mut self) -> Result<()> {
        match LoadError::from_diagnostics(std::mem::take(&mut self.errors)) {
            None => Ok(()),
            Some(e) => Err(e),
        }
    }

    /// Function block types, the program's variables, the main body, then each subroutine with
    /// its variables and body, in file order.
    fn declarations(&mut self, syn: &'a syntax::Program<'a>) {
        let r = self.function_block_types(&syn.function_blocks);
        self.collect(r);
        self.declare_main(syn.name.to_string(), &syn.vars);
        if let Some(body) = &syn.body {
            let r = self.body(0, body, "");
            self.collect(r);
        }
        self.declare_subroutines(syn);
    }

    /// The main program (named `name`) and its variables.
    fn declare_main(&mut self, name: String, vars: &[syntax::Var]) {
        self.pous
            .push(PouDraft::new(name, PouKind::Main, String::new()));
        self.locals.push(NameTable::default());
        self.local_instances.push(NameTable::default());
        // Sized up front: a million variables would otherwise be rehashed and moved twenty times.
        self.globals.reserve(vars.len());
        self.vars.reserve(vars.len());
        self.declare_vars(vars, "vars", None, false);
    }

    /// Each subroutine with its variables and body, in file order.
    fn declare_subroutines(&mut self, syn: &'a syntax::Program<'a>) {
        let name = &syn.name;
        for sub in &syn.subroutines {
            let (container, kind) = match sub.kind {
                syntax::RoutineKind::Subroutine => ("subroutines", PouKind::Subroutine),
                syntax::RoutineKind::Interrupt => ("interrupts", PouKind::Interrupt),
            };
            let path = format!("{container}.{}", sub.name);
            let r = check_name(&sub.name, || path.clone(), None).map_err(|e| e.at(sub.origin));
            if self.collect(r).is_none() {
                continue;
            }
            if sub.name == *name {
                self.report(
                    LoadError::invalid(
                        None,
                        &path,
                        Invalid::Misplaced {
                            what: "a subroutine named like the program",
                            place: "(rename one of them)",
                        },
                    )
                    .at(sub.origin),
                );
                continue;
            }
            let pou = self.pous.next_id();
            self.locals.push(NameTable::default());
            self.local_instances.push(NameTable::default());
            self.declare_vars(
                &sub.vars,
                &format!("{path}.vars"),
                Some((pou, format!("{}:", sub.name))),
                false,
            );
            self.pous.push(PouDraft::new(
                sub.name.to_string(),
                kind,
                format!("{path}.rungs"),
            ));
            if let Some(body) = &sub.body {
                let r = self.body(pou.index(), body, &path);
                self.collect(r);
            }
        }
    }

    /// The body of POU `pou`: rungs (kept for pass 1) or FBD (read and planned now).
    fn body(&mut self, pou: usize, body: &'a syntax::Body<'a>, path: &str) -> Result<()> {
        match body {
            syntax::Body::Rungs(rungs) => {
                self.pous[pou].rungs = rungs;
                Ok(())
            }
            syntax::Body::Fbd(f) => {
                let kind = if pou == 0 {
                    FbdPouKind::Main
                } else {
                    FbdPouKind::Subroutine
                };
                let at = util::join(path, "fbd");
                let fbd = self.read_fbd(f, &at, &self.pous[pou].name.clone(), kind)?;
                self.pous[pou].fbd = Some(self.fbd_bodies.len());
                self.fbd_bodies.push(fbd);
                self.fbd_origins.push(f.origin);
                Ok(())
            }
        }
    }

    /// Reads and plans an FBD body.
    fn read_fbd(
        &self,
        f: &syntax::FbdBody,
        path: &str,
        name: &str,
        kind: FbdPouKind,
    ) -> Result<FbdPou> {
        let index = &self.fb_index;
        let types = &self.fb_types;
        let sig = |n: &str| index.get(n).map(|&i| types[i].sig.clone());
        let cx = fbd_read::Context { sig: &sig };
        fbd_read::read_body(f, path, name, kind, &cx).map_err(|e| e.at(f.origin))
    }

    fn build(mut self, name: String, origin: syntax::Origin) -> Result<Program> {
        let streamed = self.streamed.as_ref().map_or(0, |s| s.rungs.len());
        if self.pous[0].fbd.is_none() && self.pous[0].rungs.is_empty() && streamed == 0 {
            return Err(LoadError::invalid(None, "rungs", Invalid::Empty).at(origin));
        }
        let (heads, next_id) = self.rung_heads();
        self.phase_end()?;
        // Pass 2: elements (the main program's are resolved already when it was streamed).
        let mut loops = structure::Loops::default();
        let mut rungs = match self.streamed.take() {
            Some(s) => self.settle(s, &mut loops)?,
            None => Vec::new(),
        };
        for pou_heads in &heads {
            loops.pair_pou(pou_heads.iter().filter_map(|(rid, syn, _)| {
                Some((*rid, structure::loop_end(&syn.ld)?, syn.ld.len()))
            }));
        }
        rungs.reserve(next_id as usize - rungs.len());
        // The syntax of each ladder rung and where it is (none for rungs lowered from FBD or
        // streamed), for the paths and places of structural errors.
        let pou_paths: Vec<String> = self.pous.iter().map(|p| p.path.clone()).collect();
        let mut places: Vec<Option<structure::Place>> = Vec::with_capacity(next_id as usize);
        places.resize_with(rungs.len(), || None);
        let mut pous: Arena<PouId, Pou> = Arena::with_capacity(self.pous.len());
        let mut start = 0u32;
        for (pi, pou) in self.pous.iter().enumerate() {
            let end = start
                + pou.rungs.len() as u32
                + pou.lowered.as_ref().map_or(0, |l| l.len() as u32)
                + if pi == 0 { streamed as u32 } else { 0 };
            pous.push(Pou {
                name: pou.name.clone(),
                kind: pou.kind,
                rungs: start..end,
                skipped: None,
            });
            start = end;
        }
        for (pi, pou_heads) in heads.into_iter().enumerate() {
            let pou = pous.id(pi);
            if let Some(lowered) = self.pous[pi].lowered.take() {
                let offset = pous[pi].rungs.start;
                for mut r in lowered {
                    r.pou = pou;
                    relocate_jumps(&mut r.series, offset);
                    rungs.push(r);
                    places.push(None);
                }
            }
            for (rid, syn, id) in pou_heads {
                let index = (rid.raw() - pous[pi].rungs.start) as usize;
                let partner = loops.partner(rid);
                let at = (pou_paths[pi].as_str(), index);
                let series = match self.ladder_series(pou, at, syn, &id, partner) {
                    Ok(s) => s,
                    Err(e) => {
                        self.report(e.at(syn.origin));
                        Vec::new()
                    }
                };
                places.push(Some(structure::Place {
                    rung: syn,
                    pou_path: &pou_paths[pi],
                    index,
                }));
                rungs.push(Rung {
                    id,
                    label: syn.label.as_ref().map(|l| l.value.to_string()),
                    comment: syn.comment.as_ref().map(|c| c.to_string()),
                    pou,
                    series,
                    lowered: None,
                    origin: syn.origin,
                });
            }
        }
        self.phase_end()?;
        let program = Program::new(ProgramParts {
            name,
            vars: self.vars,
            pous,
            rungs: Arena::from(rungs),
            configuration: None,
            dialect: plc_model::Dialect::default(),
            written_inputs: self.written_inputs.into_inner(),
        })
        .map_err(|e| LoadError::invalid(None, "", Invalid::Inconsistent { what: e.0 }))?;
        structure::check(&program, &places, loops)?;
        Ok(program)
    }

    /// The elements of ladder rung `index` of POU `pou` (whose rung array is at `pou_path`),
    /// whose id is `id`; `partner`: its FOR's NEXT or its NEXT's FOR.
    fn ladder_series(
        &mut self,
        pou: PouId,
        (pou_path, index): (&str, usize),
        syn: &syntax::Rung,
        id: &str,
        partner: Option<RungId>,
    ) -> Result<Series> {
        self.edge_count = 0;
        let scope = Scope {
            pou,
            rung_id: id,
            partner,
        };
        let base = At::rung(pou_path, index);
        let ld = base.key("ld");
        self.series(&syn.ld, &ld, Place::Top, &scope)
    }

    /// Pass 1: rung ids (program-wide) and labels (per POU); lowered FBD bodies: ids only, their
    /// labels are resolved. Returns the ladder rungs of each POU and the number of rungs.
    fn rung_heads(&mut self) -> (Vec<Vec<RungHead<'a>>>, u32) {
        // Where each id was first used: (POU, index of its rung) for ladder rungs, the path of
        // lowered rungs; rendered only for a duplicate.
        let total = self
            .pous
            .iter()
            .map(|p| p.rungs.len() + p.lowered.as_ref().map_or(0, Vec::len));
        let mut ids: FastMap<Cow<'a, str>, (usize, Option<usize>)> = FastMap::default();
        ids.reserve(total.sum());
        // The main program's ids when it was streamed.
        let streamed = self.streamed.as_ref();
        let main_id = |key: &str| {
            let s = streamed?;
            let i = s.ids.get(key, |i| s.rungs[i as usize].id.as_str())?;
            Some((0, Some(i as usize)))
        };
        let first_path = |pous: &[PouDraft], (pou, i): (usize, Option<usize>)| match i {
            Some(i) => rung_path(&pous[pou].path, i),
            None => String::new(),
        };
        let mut heads: Vec<Vec<RungHead<'a>>> = Vec::new();
        let mut numbering: Numbering<RungId> = Numbering::new();
        let mut errors = Vec::new();
        for (pi, pou) in self.pous.iter().enumerate() {
            let mut labels = FastMap::default();
            if let (0, Some(s)) = (pi, streamed) {
                labels = s.labels.clone();
                numbering.skip(s.rungs.len());
            }
            let mut pou_heads = Vec::with_capacity(pou.rungs.len());
            if let Some(lowered) = &pou.lowered {
                for r in lowered {
                    if let Some(first) = ids.get(r.id.as_str()).copied().or_else(|| main_id(&r.id))
                    {
                        let first = match first {
                            (p, None) => self.pous[p]
                                .lowered
                                .iter()
                                .flatten()
                                .find(|x| x.id == r.id)
                                .and_then(|x| x.block_path().map(str::to_owned))
                                .unwrap_or_default(),
                            other => first_path(&self.pous, other),
                        };
                        errors.push(LoadError::invalid(
                            Some(&r.id),
                            r.block_path().unwrap_or_default(),
                            Invalid::DuplicateRung {
                                id: r.id.clone(),
                                first,
                            },
                        ));
                    }
                    ids.insert(Cow::Owned(r.id.clone()), (pi, None));
                    numbering.skip(1);
                }
            }
            for (i, r) in pou.rungs.iter().enumerate() {
                let path = || rung_path(&pou.path, i);
                let key: Cow<'a, str> = if pou.prefix.is_empty() {
                    match &r.id.value {
                        Cow::Borrowed(s) => Cow::Borrowed(s),
                        Cow::Owned(s) => Cow::Owned(s.clone()),
                    }
                } else {
                    Cow::Owned(format!("{}{}", pou.prefix, r.id.value))
                };
                let id = key.to_string();
                if let Some(p) = &r.problem {
                    let rung = r.problem_in_rung.then_some(id.as_str());
                    let e =
                        LoadError::invalid(rung, &format!("{}{}", path(), p.at), p.kind.clone());
                    errors.push(e.at(p.origin).at(r.origin));
                    continue;
                }
                if let Err(e) =
                    check_printable("rung id", &r.id.value, || format!("{}.id", path()), None)
                {
                    errors.push(e.at(r.id.origin).at(r.origin));
                    continue;
                }
                if let Some(first) = ids.get(key.as_ref()).copied().or_else(|| main_id(&key)) {
                    let first = match first {
                        (p, None) => self.pous[p]
                            .lowered
                            .iter()
                            .flatten()
                            .find(|x| x.id == id)
                            .and_then(|x| x.block_path().map(str::to_owned))
                            .unwrap_or_default(),
                        other => first_path(&self.pous, other),
                    };
                    errors.push(
                        LoadError::invalid(
                            Some(&id),
                            &format!("{}.id", path()),
                            Invalid::DuplicateRung {
                                id: id.clone(),
                                first,
                            },
                        )
                        .at(r.id.origin),
                    );
                    continue;
                }
                ids.insert(key, (pi, Some(i)));
                let rid = numbering.next_id();
                if let Some(l) = &r.label {
                    let lp = format!("{}.label", path());
                    if let Err(e) = check_label(l.as_str(), || lp.clone(), Some(&id)) {
                        errors.push(e.at(l.origin));
                    } else if let Some(prev) = labels.insert(l.value.to_string(), rid) {
                        let first = pou_heads
                            .iter()
                            .find(|h: &&RungHead| h.0 == prev)
                            .map(|h| h.2.clone())
                            .unwrap_or_default();
                        errors.push(
                            LoadError::invalid(
                                Some(&id),
                                &lp,
                                Invalid::DuplicateLabel {
                                    label: l.value.to_string(),
                                    pou: pou.name.clone(),
                                    first,
                                },
                            )
                            .at(l.origin),
                        );
                    }
                }
                pou_heads.push((rid, r, id));
            }
            heads.push(pou_heads);
            self.labels.push(labels);
        }
        for e in errors {
            self.report(e);
        }
        (heads, numbering.count() as u32)
    }
}
