//! The JSON program format → [`Program`]: field checks, name resolution, type checks.
//!
//! Follows docs/format.md (normative). Every object is checked for unknown fields; every name is
//! resolved (subroutine locals first, then program variables); every operand is typed. Errors name
//! the rung id and the JSON path. Structural rules checked here: unique rung ids (program-wide)
//! and labels (per POU), FOR/NEXT nesting, no jump into a FOR body, no recursive calls, `end` in
//! the main program only, no writes to inputs or to instance fields.

mod elements;
mod function_blocks;
mod lowering;
mod names;
mod util;
mod vars;

use super::error::{Invalid, LoadError};
use crate::fbd::read::FbSig;
use crate::fbd::{Fbd, FbdPou, FbdPouKind};
use crate::model::*;
use serde_json::{Map, Value as Json};
use std::borrow::Cow;
use std::collections::{HashMap, HashSet};

use elements::{Place, Scope};
use lowering::relocate_jumps;
pub(crate) use util::kind_of;
use util::{array, check_keys, check_name, object, required, rung_path, string};

type Result<T> = std::result::Result<T, LoadError>;

/// Builds a program from an already parsed JSON document.
pub fn program_from_value(doc: &Json) -> Result<Program> {
    program_and_fbd_from_value(doc).map(|(p, _)| p)
}

/// Builds a program from an already parsed JSON document, and returns with it its FBD bodies
/// (networks, orders, fragment trees, and where each copy was lowered to).
pub fn program_and_fbd_from_value(doc: &Json) -> Result<(Program, Fbd)> {
    let top = object(doc, "", None, "the program")?;
    check_keys(
        top,
        &[
            "program",
            "vars",
            "rungs",
            "fbd",
            "subroutines",
            "function_blocks",
            "comment",
        ],
        "the program",
        "",
        None,
    )?;
    let name = string(
        required(top, "program", "the program", "", None)?,
        "program",
        None,
    )?
    .to_owned();
    let mut b = Builder::default();
    if let Some(fbs) = top.get("function_blocks") {
        b.function_block_types(fbs)?;
    }
    b.pous
        .push(PouDraft::new(name.clone(), PouKind::Main, String::new()));
    b.locals.push(HashMap::new());
    b.local_instances.push(HashMap::new());
    if let Some(vars) = top.get("vars") {
        b.declare_vars(vars, "vars", None, false)?;
    }
    b.body(0, top, "", "the program")?;
    if let Some(subs) = top.get("subroutines") {
        let subs = object(subs, "subroutines", None, "the subroutines")?;
        for (sname, body) in subs {
            let path = format!("subroutines.{sname}");
            check_name(sname, &path, None)?;
            if sname == &name {
                return Err(LoadError::invalid(
                    None,
                    &path,
                    Invalid::Misplaced {
                        what: "a subroutine named like the program",
                        place: "(rename one of them)",
                    },
                ));
            }
            let body = object(body, &path, None, "a subroutine")?;
            check_keys(
                body,
                &["vars", "rungs", "fbd", "comment"],
                "a subroutine",
                &path,
                None,
            )?;
            let pou = PouId(b.pous.len() as u32);
            b.locals.push(HashMap::new());
            b.local_instances.push(HashMap::new());
            if let Some(vars) = body.get("vars") {
                b.declare_vars(
                    vars,
                    &format!("{path}.vars"),
                    Some((pou, format!("{sname}:"))),
                    false,
                )?;
            }
            b.pous.push(PouDraft::new(
                sname.clone(),
                PouKind::Subroutine,
                format!("{path}.rungs"),
            ));
            b.body(pou.index(), body, &path, "a subroutine")?;
        }
    }
    // Instances of user function blocks: one POU each, after the subroutines.
    let top_level: Vec<usize> = std::mem::take(&mut b.pending);
    for i in top_level {
        b.expand(i, &mut Vec::new())?;
    }
    b.lower_fbd()?;
    let mut bodies = std::mem::take(&mut b.fbd_bodies);
    let program = b.build(name)?;
    for body in &mut bodies {
        for copy in &mut body.copies {
            let start = program.pou(copy.pou).rungs.start;
            for r in &mut copy.networks {
                *r = r.start + start..r.end + start;
            }
            for blocks in &mut copy.blocks {
                for r in blocks.iter_mut() {
                    r.0 += start;
                }
            }
        }
    }
    // Main program and subroutines first, then function block types (each in file order).
    let (mut pous, fbs): (Vec<FbdPou>, Vec<FbdPou>) = bodies
        .into_iter()
        .partition(|p| p.kind != FbdPouKind::FunctionBlock);
    pous.extend(fbs);
    Ok((program, Fbd { pous }))
}

struct PouDraft<'a> {
    name: String,
    kind: PouKind,
    /// JSON path of the rung array ("" means top-level `rungs`).
    path: String,
    rungs: Vec<&'a Json>,
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
            rungs: Vec::new(),
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
    inputs: Option<&'a Json>,
    outputs: Option<&'a Json>,
    vars: Option<&'a Json>,
    /// The ladder body, or the index of the FBD body in `Builder::fbd_bodies`.
    rungs: Option<&'a [Json]>,
    fbd: Option<usize>,
    sig: FbSig,
}

/// An instance of a user function block type.
struct InstanceDraft {
    /// `G1`, `SBR:G1`, `G1.INNER`.
    display: String,
    fb: String,
    /// JSON path of its declaration.
    path: String,
    pou: Option<PouId>,
    inputs: Vec<(String, VarId)>,
    outputs: Vec<(String, VarId)>,
}

#[derive(Default)]
struct Builder<'a> {
    vars: Vec<Var>,
    /// Display names of all variables, built when the first hidden FBD variable is made (its
    /// name must not clash).
    var_names: Option<HashSet<String>>,
    globals: HashMap<String, VarId>,
    /// Per POU: its local variables.
    locals: Vec<HashMap<String, VarId>>,
    /// Program-wide and per-POU instances of user function blocks (index into `instances`).
    global_instances: HashMap<String, usize>,
    local_instances: Vec<HashMap<String, usize>>,
    instances: Vec<InstanceDraft>,
    /// Instances declared but not yet given their POU.
    pending: Vec<usize>,
    fb_types: Vec<FbType<'a>>,
    fb_index: HashMap<String, usize>,
    /// FBD bodies in reading order (function block types first, as they are read first).
    fbd_bodies: Vec<FbdPou>,
    /// TIME variables accumulated by TSTART/TSTOP, with the POU that does it.
    accumulated: HashMap<VarId, PouId>,
    pous: Vec<PouDraft<'a>>,
    /// Per POU: label → rung.
    labels: Vec<HashMap<String, RungId>>,
    /// Per rung, during element resolution: number of edge contacts so far.
    edge_count: u32,
}

/// A ladder rung after pass 1: its id, its JSON object and its (prefixed) id text.
type RungHead<'a> = (RungId, &'a Map<String, Json>, String);

impl<'a> Builder<'a> {
    /// The body of POU `pou`: `rungs` (ladder) or `fbd`.
    fn body(
        &mut self,
        pou: usize,
        o: &'a Map<String, Json>,
        path: &str,
        what: &'static str,
    ) -> Result<()> {
        let at = |k: &str| {
            if path.is_empty() {
                k.to_owned()
            } else {
                format!("{path}.{k}")
            }
        };
        match (o.get("rungs"), o.get("fbd")) {
            (Some(_), Some(_)) => Err(LoadError::invalid(
                None,
                &at("fbd"),
                Invalid::Misplaced {
                    what: "`fbd`",
                    place: "together with `rungs` (a body is one of them)",
                },
            )),
            (None, Some(j)) => {
                let kind = if pou == 0 {
                    FbdPouKind::Main
                } else {
                    FbdPouKind::Subroutine
                };
                let index = &self.fb_index;
                let types = &self.fb_types;
                let sig = |n: &str| index.get(n).map(|&i| types[i].sig.clone());
                let body =
                    crate::fbd::read::read_body(j, &at("fbd"), &self.pous[pou].name, kind, &sig)?;
                self.pous[pou].fbd = Some(self.fbd_bodies.len());
                self.fbd_bodies.push(body);
                Ok(())
            }
            (r, None) => {
                let r = r.ok_or_else(|| {
                    LoadError::invalid(
                        None,
                        path,
                        Invalid::MissingField {
                            field: "rungs",
                            what,
                        },
                    )
                })?;
                self.pous[pou].rungs = array(r, &at("rungs"), None)?.iter().collect();
                Ok(())
            }
        }
    }

    fn build(mut self, name: String) -> Result<Program> {
        if self.pous[0].fbd.is_none() && self.pous[0].rungs.is_empty() {
            return Err(LoadError::invalid(None, "rungs", Invalid::Empty));
        }
        // Pass 1: rung ids and labels (lowered FBD bodies: ids only, their labels are resolved).
        let mut ids: HashMap<Cow<'_, str>, String> = HashMap::new();
        let mut heads: Vec<Vec<RungHead<'a>>> = Vec::new();
        let mut next_id = 0u32;
        for pou in &self.pous {
            let mut labels = HashMap::new();
            let mut pou_heads = Vec::new();
            if let Some(lowered) = &pou.lowered {
                for r in lowered {
                    if let Some(first) = ids.get(r.id.as_str()) {
                        return Err(LoadError::invalid(
                            Some(&r.id),
                            &r.path,
                            Invalid::DuplicateRung {
                                id: r.id.clone(),
                                first: first.clone(),
                            },
                        ));
                    }
                    ids.insert(Cow::Borrowed(r.id.as_str()), r.path.clone());
                    next_id += 1;
                }
            }
            for (i, r) in pou.rungs.iter().enumerate() {
                let path = rung_path(&pou.path, i);
                let o = object(r, &path, None, "a rung")?;
                check_keys(o, &["id", "label", "comment", "ld"], "a rung", &path, None)?;
                let id = string(
                    required(o, "id", "a rung", &path, None)?,
                    &format!("{path}.id"),
                    None,
                )?;
                if id.is_empty() || id.chars().any(|c| c.is_whitespace() || c == '"') {
                    return Err(LoadError::invalid(
                        None,
                        &format!("{path}.id"),
                        Invalid::Shape {
                            expected: "a rung id without spaces or quotes",
                            found: format!("\"{id}\""),
                        },
                    ));
                }
                let key: Cow<'_, str> = if pou.prefix.is_empty() {
                    Cow::Borrowed(id)
                } else {
                    Cow::Owned(format!("{}{id}", pou.prefix))
                };
                let id = key.to_string();
                if let Some(first) = ids.get(key.as_ref()) {
                    return Err(LoadError::invalid(
                        Some(&id),
                        &format!("{path}.id"),
                        Invalid::DuplicateRung {
                            id: id.clone(),
                            first: first.clone(),
                        },
                    ));
                }
                ids.insert(key, path.clone());
                let rid = RungId(next_id);
                next_id += 1;
                if let Some(l) = o.get("label") {
                    let lp = format!("{path}.label");
                    let l = string(l, &lp, Some(&id))?;
                    check_name(l, &lp, Some(&id))?;
                    if let Some(prev) = labels.insert(l.to_owned(), rid) {
                        let first = pou_heads
                            .iter()
                            .find(|h: &&RungHead| h.0 == prev)
                            .map(|h| h.2.clone())
                            .unwrap_or_default();
                        return Err(LoadError::invalid(
                            Some(&id),
                            &lp,
                            Invalid::DuplicateLabel {
                                label: l.into(),
                                pou: pou.name.clone(),
                                first,
                            },
                        ));
                    }
                }
                pou_heads.push((rid, o, id));
            }
            heads.push(pou_heads);
            self.labels.push(labels);
        }
        // Pass 2: elements.
        let mut rungs = Vec::with_capacity(next_id as usize);
        let mut pous = Vec::with_capacity(self.pous.len());
        let mut start = 0u32;
        for pou in &self.pous {
            let end =
                start + pou.rungs.len() as u32 + pou.lowered.as_ref().map_or(0, |l| l.len() as u32);
            pous.push(Pou {
                name: pou.name.clone(),
                kind: pou.kind,
                rungs: start..end,
            });
            start = end;
        }
        for (pi, pou_heads) in heads.iter().enumerate() {
            let pou = PouId(pi as u32);
            if let Some(lowered) = self.pous[pi].lowered.take() {
                let offset = pous[pi].rungs.start;
                for mut r in lowered {
                    r.pou = pou;
                    relocate_jumps(&mut r.series, offset);
                    rungs.push(r);
                }
            }
            for (rid, o, id) in pou_heads {
                let path = rung_path(&self.pous[pi].path, (rid.0 - pous[pi].rungs.start) as usize);
                let ldp = format!("{path}.ld");
                let ld = array(
                    required(o, "ld", "a rung", &path, Some(id))?,
                    &ldp,
                    Some(id),
                )?;
                self.edge_count = 0;
                let scope = Scope { pou, rung_id: id };
                let series = self.series(ld, &ldp, Place::Top, &scope)?;
                let label = o.get("label").and_then(Json::as_str).map(str::to_owned);
                let comment = match o.get("comment") {
                    None => None,
                    Some(c) => Some(string(c, &format!("{path}.comment"), Some(id))?.to_owned()),
                };
                rungs.push(Rung {
                    id: id.clone(),
                    label,
                    comment,
                    pou,
                    series,
                    path,
                    network: None,
                });
            }
        }
        let mut program = Program {
            name,
            vars: self.vars,
            pous,
            rungs,
        };
        super::structure::check(&mut program)?;
        Ok(program)
    }
}
