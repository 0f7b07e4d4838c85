//! The JSON program format → [`Program`]: field checks, name resolution, type checks.
//!
//! Follows docs/format.md (normative). Every object is checked for unknown fields; every name is
//! resolved (subroutine locals first, then program variables); every operand is typed. Errors name
//! the rung id and the JSON path. Structural rules checked here: unique rung ids (program-wide)
//! and labels (per POU), FOR/NEXT nesting, no jump into a FOR body, no recursive calls, `end` in
//! the main program only, no writes to inputs or to instance fields.

use super::error::{Invalid, LoadError};
use super::operand::{self, Untyped};
use crate::fbd::lower::{Env, InstanceRef, Names};
use crate::fbd::read::FbSig;
use crate::fbd::{Fbd, FbdPou, FbdPouKind, LoweredCopy};
use crate::model::*;
use serde_json::{Map, Value as Json};
use std::borrow::Cow;
use std::collections::{HashMap, HashSet};

type Result<T> = std::result::Result<T, LoadError>;

/// A short description of a JSON value's kind, for error messages.
pub(crate) fn kind_of(v: &Json) -> String {
    match v {
        Json::Null => "null".into(),
        Json::Bool(b) => format!("boolean {b}"),
        Json::Number(n) => format!("number {n}"),
        Json::String(s) => format!("string \"{s}\""),
        Json::Array(_) => "an array".into(),
        Json::Object(_) => "an object".into(),
    }
}

/// Builds a program from an already parsed JSON document.
pub fn program_from_value(doc: &Json) -> Result<Program> {
    program_and_fbd_from_value(doc).map(|(p, _)| p)
}

/// Builds a program from an already parsed JSON document, and returns with it its FBD bodies
/// (networks, orders, fragment trees, and where each copy was lowered to).
pub fn program_and_fbd_from_value(doc: &Json) -> Result<(Program, Fbd)> {
    let top = object(doc, "", None, "the program")?;
    check_keys(top, &["program", "vars", "rungs", "fbd", "subroutines", "function_blocks", "comment"], "the program", "", None)?;
    let name = string(required(top, "program", "the program", "", None)?, "program", None)?.to_owned();
    let mut b = Builder::default();
    if let Some(fbs) = top.get("function_blocks") {
        b.function_block_types(fbs)?;
    }
    b.pous.push(PouDraft::new(name.clone(), PouKind::Main, String::new()));
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
                return Err(LoadError::invalid(None, &path, Invalid::Misplaced {
                    what: "a subroutine named like the program",
                    place: "(rename one of them)",
                }));
            }
            let body = object(body, &path, None, "a subroutine")?;
            check_keys(body, &["vars", "rungs", "fbd", "comment"], "a subroutine", &path, None)?;
            let pou = PouId(b.pous.len() as u32);
            b.locals.push(HashMap::new());
            b.local_instances.push(HashMap::new());
            if let Some(vars) = body.get("vars") {
                b.declare_vars(vars, &format!("{path}.vars"), Some((pou, format!("{sname}:"))), false)?;
            }
            b.pous.push(PouDraft::new(sname.clone(), PouKind::Subroutine, format!("{path}.rungs")));
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
    let (mut pous, fbs): (Vec<FbdPou>, Vec<FbdPou>) = bodies.into_iter().partition(|p| p.kind != FbdPouKind::FunctionBlock);
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
        let var_prefix = if kind == PouKind::Main { String::new() } else { format!("{name}:") };
        PouDraft { name, kind, path, rungs: Vec::new(), fbd: None, lowered: None, prefix: String::new(), var_prefix, callable: true }
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

/// What may appear in a series, by where the series is.
#[derive(Copy, Clone, PartialEq, Eq)]
enum Place {
    /// The rung's own series.
    Top,
    /// A branch of `branch` (an output path).
    Branch,
    /// A branch of `or` (conditions only).
    Or,
}

struct Scope<'s> {
    pou: PouId,
    rung_id: &'s str,
}

impl<'a> Builder<'a> {
    /// Declares the variables of a scope: the program's (`scope` None) or a POU's, whose display
    /// names get the prefix (`SBR:`, or `G1.` for an instance). `elementary`: only BOOL, INT,
    /// DINT, REAL, TIME (inputs and outputs of function blocks). Variables of a user function block
    /// type are instances: recorded in `pending`, given their POU by [`Self::expand`].
    fn declare_vars(&mut self, vars: &Json, path: &str, scope: Option<(PouId, String)>, elementary: bool) -> Result<()> {
        for (i, v) in array(vars, path, None)?.iter().enumerate() {
            let p = format!("{path}[{i}]");
            let o = object(v, &p, None, "a variable")?;
            check_keys(o, &["name", "type", "class", "init", "comment"], "a variable", &p, None)?;
            let name = string(required(o, "name", "a variable", &p, None)?, &format!("{p}.name"), None)?;
            check_name(name, &format!("{p}.name"), None)?;
            let tname = string(required(o, "type", "a variable", &p, None)?, &format!("{p}.type"), None)?;
            let user_fb = Type::parse(tname).is_none() && self.fb_index.contains_key(tname);
            let ty = match Type::parse(tname) {
                Some(t) => t,
                None if user_fb => Type::Fb(FbKind::Ton), // placeholder: instances are not variables
                None if !self.fb_types.is_empty() => {
                    let fbs = self.fb_types.iter().map(|f| f.name.as_str()).collect::<Vec<_>>().join(", ");
                    return Err(LoadError::invalid(None, &format!("{p}.type"), Invalid::UnknownTypeOrFb { name: tname.into(), fbs }));
                }
                None => return Err(LoadError::invalid(None, &format!("{p}.type"), Invalid::UnknownType { name: tname.into() })),
            };
            if elementary && matches!(ty, Type::Fb(_)) {
                return Err(LoadError::invalid(None, &format!("{p}.type"), Invalid::Misplaced {
                    what: "a function block type",
                    place: "as an input or output of a function block (declare the instance in `vars`)",
                }));
            }
            let class = match o.get("class") {
                None => VarClass::Memory,
                Some(c) => match string(c, &format!("{p}.class"), None)? {
                    "input" => VarClass::Input,
                    "output" => VarClass::Output,
                    "memory" => VarClass::Memory,
                    other => {
                        return Err(LoadError::invalid(None, &format!("{p}.class"), Invalid::Shape {
                            expected: "\"input\", \"output\" or \"memory\"",
                            found: format!("\"{other}\""),
                        }))
                    }
                },
            };
            if matches!(ty, Type::Fb(_)) && class != VarClass::Memory {
                return Err(LoadError::invalid(None, &format!("{p}.class"), Invalid::Misplaced {
                    what: "an input or output class",
                    place: "on a function block instance",
                }));
            }
            let init = match o.get("init") {
                None => ty.zero(),
                Some(_) if matches!(ty, Type::Fb(_)) => {
                    return Err(LoadError::invalid(None, &format!("{p}.init"), Invalid::Misplaced {
                        what: "`init`",
                        place: "on a function block instance",
                    }))
                }
                Some(j) => {
                    let ip = format!("{p}.init");
                    let u = operand::parse(j, &|n| Err(Invalid::Shape { expected: "a constant", found: format!("name \"{n}\"") }))
                        .map_err(|k| LoadError::invalid(None, &ip, k))?;
                    match operand::typed(&u, ty, "the initial value", &j.to_string()) {
                        Ok(Operand::Const(v)) => v,
                        Ok(Operand::Var(_)) => unreachable!("constants only"),
                        Err(k) => return Err(LoadError::invalid(None, &ip, k)),
                    }
                }
            };
            let (table, instances) = match &scope {
                None => (&mut self.globals, &mut self.global_instances),
                Some((p, _)) => (&mut self.locals[p.index()], &mut self.local_instances[p.index()]),
            };
            if table.contains_key(name) || instances.contains_key(name) {
                return Err(LoadError::invalid(None, &format!("{p}.name"), Invalid::DuplicateVar { name: name.into() }));
            }
            let display = match &scope {
                None => name.to_owned(),
                Some((_, prefix)) => format!("{prefix}{name}"),
            };
            if user_fb {
                let idx = self.instances.len();
                instances.insert(name.to_owned(), idx);
                self.instances.push(InstanceDraft { display, fb: tname.to_owned(), path: p, pou: None, inputs: Vec::new(), outputs: Vec::new() });
                self.pending.push(idx);
                continue;
            }
            let id = VarId(self.vars.len() as u32);
            table.insert(name.to_owned(), id);
            self.vars.push(Var { name: display, ty, class, init, scope: scope.as_ref().map(|(p, _)| *p), hidden: false });
        }
        Ok(())
    }

    /// Reads `function_blocks`: names and pins first (bodies may use each other), then each
    /// type's declarations (checked on a scratch scope), its body and, for FBD, its networks.
    fn function_block_types(&mut self, fbs: &'a Json) -> Result<()> {
        let fbs = object(fbs, "function_blocks", None, "the function blocks")?;
        for (fname, body) in fbs {
            let path = format!("function_blocks.{fname}");
            check_name(fname, &path, None)?;
            if Type::parse(fname).is_some() {
                return Err(LoadError::invalid(None, &path, Invalid::Misplaced { what: "a function block named like a standard type", place: "(rename it)" }));
            }
            let o = object(body, &path, None, "a function block")?;
            check_keys(o, &["vars", "inputs", "outputs", "fbd", "rungs", "comment"], "a function block", &path, None)?;
            let names = |k: &str| -> Vec<String> {
                o.get(k).and_then(Json::as_array).into_iter().flatten().filter_map(|v| v.get("name").and_then(Json::as_str).map(str::to_owned)).collect()
            };
            let sig = FbSig { inputs: names("inputs"), outputs: names("outputs") };
            self.fb_index.insert(fname.clone(), self.fb_types.len());
            self.fb_types.push(FbType { name: fname.clone(), path, inputs: o.get("inputs"), outputs: o.get("outputs"), vars: o.get("vars"), rungs: None, fbd: None, sig });
        }
        // Declarations on a scratch scope (rolled back), and which types each type instantiates.
        let mut uses: Vec<Vec<(usize, String)>> = Vec::new();
        for f in 0..self.fb_types.len() {
            let (vars_mark, inst_mark) = (self.vars.len(), self.instances.len());
            let scratch = PouId(self.locals.len() as u32);
            self.locals.push(HashMap::new());
            self.local_instances.push(HashMap::new());
            let (path, prefix) = (self.fb_types[f].path.clone(), format!("{}.", self.fb_types[f].name));
            let decls = [("inputs", self.fb_types[f].inputs, true), ("outputs", self.fb_types[f].outputs, true), ("vars", self.fb_types[f].vars, false)];
            for (key, decl, elementary) in decls {
                if let Some(d) = decl {
                    self.declare_vars(d, &format!("{path}.{key}"), Some((scratch, prefix.clone())), elementary)?;
                }
            }
            uses.push(self.instances[inst_mark..].iter().map(|i| (self.fb_index[&i.fb], i.path.clone())).collect());
            self.vars.truncate(vars_mark);
            self.instances.truncate(inst_mark);
            self.pending.clear();
            self.locals.pop();
            self.local_instances.pop();
        }
        // No type may contain itself (directly or through others).
        for start in 0..self.fb_types.len() {
            let mut seen = vec![false; self.fb_types.len()];
            seen[start] = true;
            let mut stack: Vec<(usize, usize)> = vec![(start, 0)];
            while let Some(&mut (f, ref mut i)) = stack.last_mut() {
                if let Some((g, p)) = uses[f].get(*i) {
                    *i += 1;
                    if *g == start {
                        let mut chain: Vec<&str> = stack.iter().map(|&(x, _)| self.fb_types[x].name.as_str()).collect();
                        chain.push(&self.fb_types[start].name);
                        return Err(LoadError::invalid(None, p, Invalid::FbRecursion { name: self.fb_types[start].name.clone(), chain: chain.join(" → ") }));
                    }
                    if !seen[*g] {
                        seen[*g] = true;
                        stack.push((*g, 0));
                    }
                } else {
                    stack.pop();
                }
            }
        }
        // Bodies.
        for f in 0..self.fb_types.len() {
            let path = self.fb_types[f].path.clone();
            let o = fbs[&self.fb_types[f].name].as_object().expect("checked above");
            match (o.get("rungs"), o.get("fbd")) {
                (Some(_), Some(_)) => {
                    return Err(LoadError::invalid(None, &format!("{path}.fbd"), Invalid::Misplaced { what: "`fbd`", place: "together with `rungs` (a body is one of them)" }))
                }
                (Some(r), None) => self.fb_types[f].rungs = Some(array(r, &format!("{path}.rungs"), None)?),
                (None, Some(j)) => {
                    let index = &self.fb_index;
                    let types = &self.fb_types;
                    let sig = |n: &str| index.get(n).map(|&i| types[i].sig.clone());
                    let body = crate::fbd::read::read_body(j, &format!("{path}.fbd"), &self.fb_types[f].name, FbdPouKind::FunctionBlock, &sig)?;
                    self.fb_types[f].fbd = Some(self.fbd_bodies.len());
                    self.fbd_bodies.push(body);
                }
                (None, None) => return Err(LoadError::invalid(None, &path, Invalid::MissingField { field: "fbd` or `rungs", what: "a function block" })),
            }
        }
        Ok(())
    }

    /// The body of POU `pou`: `rungs` (ladder) or `fbd`.
    fn body(&mut self, pou: usize, o: &'a Map<String, Json>, path: &str, what: &'static str) -> Result<()> {
        let at = |k: &str| if path.is_empty() { k.to_owned() } else { format!("{path}.{k}") };
        match (o.get("rungs"), o.get("fbd")) {
            (Some(_), Some(_)) => Err(LoadError::invalid(None, &at("fbd"), Invalid::Misplaced { what: "`fbd`", place: "together with `rungs` (a body is one of them)" })),
            (None, Some(j)) => {
                let kind = if pou == 0 { FbdPouKind::Main } else { FbdPouKind::Subroutine };
                let index = &self.fb_index;
                let types = &self.fb_types;
                let sig = |n: &str| index.get(n).map(|&i| types[i].sig.clone());
                let body = crate::fbd::read::read_body(j, &at("fbd"), &self.pous[pou].name, kind, &sig)?;
                self.pous[pou].fbd = Some(self.fbd_bodies.len());
                self.fbd_bodies.push(body);
                Ok(())
            }
            (r, None) => {
                let r = r.ok_or_else(|| LoadError::invalid(None, path, Invalid::MissingField { field: "rungs", what }))?;
                self.pous[pou].rungs = array(r, &at("rungs"), None)?.iter().collect();
                Ok(())
            }
        }
    }

    /// Gives instance `idx` its POU: the function block's variables declared as `G1.name`, its
    /// body (ladder rungs now, FBD lowered later), nested instances right after it.
    fn expand(&mut self, idx: usize, stack: &mut Vec<String>) -> Result<()> {
        let f = self.fb_index[&self.instances[idx].fb];
        let (display, ipath) = (self.instances[idx].display.clone(), self.instances[idx].path.clone());
        if stack.contains(&self.fb_types[f].name) {
            let mut chain = stack.clone();
            chain.push(self.fb_types[f].name.clone());
            return Err(LoadError::invalid(None, &ipath, Invalid::FbRecursion { name: self.fb_types[f].name.clone(), chain: chain.join(" → ") }));
        }
        if self.pous.iter().any(|p| p.name == display) {
            return Err(LoadError::invalid(None, &format!("{ipath}.name"), Invalid::Misplaced {
                what: "a function block instance named like the program or a subroutine",
                place: "(rename one of them)",
            }));
        }
        let pou = PouId(self.pous.len() as u32);
        let t = &self.fb_types[f];
        let (path, inputs, outputs, vars, rungs, fbd) = (t.path.clone(), t.inputs, t.outputs, t.vars, t.rungs, t.fbd);
        let mut draft = PouDraft::new(display.clone(), PouKind::Subroutine, format!("{path}.rungs"));
        draft.rungs = rungs.map(|r| r.iter().collect()).unwrap_or_default();
        draft.fbd = fbd;
        draft.prefix = format!("{display}:");
        draft.var_prefix = format!("{display}.");
        draft.callable = false;
        self.pous.push(draft);
        self.locals.push(HashMap::new());
        self.local_instances.push(HashMap::new());
        let mark = self.pending.len();
        let prefix = format!("{display}.");
        for (key, decl, elementary) in [("inputs", inputs, true), ("outputs", outputs, true), ("vars", vars, false)] {
            if let Some(d) = decl {
                self.declare_vars(d, &format!("{path}.{key}"), Some((pou, prefix.clone())), elementary)?;
            }
        }
        let locals = &self.locals[pou.index()];
        let pins = |names: &[String]| names.iter().map(|n| (n.clone(), locals[n])).collect::<Vec<_>>();
        let (ins, outs) = (pins(&self.fb_types[f].sig.inputs), pins(&self.fb_types[f].sig.outputs));
        let inst = &mut self.instances[idx];
        inst.pou = Some(pou);
        inst.inputs = ins;
        inst.outputs = outs;
        stack.push(self.fb_types[f].name.clone());
        let nested: Vec<usize> = self.pending.drain(mark..).collect();
        for n in nested {
            self.expand(n, stack)?;
        }
        stack.pop();
        Ok(())
    }

    /// Lowers every FBD body: the main program's and subroutines' once, a function block type's
    /// once per instance.
    fn lower_fbd(&mut self) -> Result<()> {
        let mut bodies = std::mem::take(&mut self.fbd_bodies);
        for pou in 0..self.pous.len() {
            let Some(i) = self.pous[pou].fbd else { continue };
            let draft = &self.pous[pou];
            let names = Names { pou: draft.name.clone(), rung_prefix: draft.prefix.clone(), var_prefix: draft.var_prefix.clone() };
            let pid = PouId(pou as u32);
            let lowered = crate::fbd::lower::lower(&bodies[i], &mut PouEnv { b: self, pou: pid }, &names, pid)?;
            bodies[i].copies.push(LoweredCopy {
                pou: pid,
                networks: lowered.networks,
                blocks: lowered.blocks.into_iter().map(|bs| bs.into_iter().map(RungId).collect()).collect(),
            });
            self.pous[pou].lowered = Some(lowered.rungs);
        }
        self.fbd_bodies = bodies;
        Ok(())
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
                        return Err(LoadError::invalid(Some(&r.id), &r.path, Invalid::DuplicateRung { id: r.id.clone(), first: first.clone() }));
                    }
                    ids.insert(Cow::Borrowed(r.id.as_str()), r.path.clone());
                    next_id += 1;
                }
            }
            for (i, r) in pou.rungs.iter().enumerate() {
                let path = rung_path(&pou.path, i);
                let o = object(r, &path, None, "a rung")?;
                check_keys(o, &["id", "label", "comment", "ld"], "a rung", &path, None)?;
                let id = string(required(o, "id", "a rung", &path, None)?, &format!("{path}.id"), None)?;
                if id.is_empty() || id.chars().any(|c| c.is_whitespace() || c == '"') {
                    return Err(LoadError::invalid(None, &format!("{path}.id"), Invalid::Shape {
                        expected: "a rung id without spaces or quotes",
                        found: format!("\"{id}\""),
                    }));
                }
                let key: Cow<'_, str> = if pou.prefix.is_empty() { Cow::Borrowed(id) } else { Cow::Owned(format!("{}{id}", pou.prefix)) };
                let id = key.to_string();
                if let Some(first) = ids.get(key.as_ref()) {
                    return Err(LoadError::invalid(Some(&id), &format!("{path}.id"), Invalid::DuplicateRung { id: id.clone(), first: first.clone() }));
                }
                ids.insert(key, path.clone());
                let rid = RungId(next_id);
                next_id += 1;
                if let Some(l) = o.get("label") {
                    let lp = format!("{path}.label");
                    let l = string(l, &lp, Some(&id))?;
                    check_name(l, &lp, Some(&id))?;
                    if let Some(prev) = labels.insert(l.to_owned(), rid) {
                        let first = pou_heads.iter().find(|h: &&RungHead| h.0 == prev).map(|h| h.2.clone()).unwrap_or_default();
                        return Err(LoadError::invalid(Some(&id), &lp, Invalid::DuplicateLabel { label: l.into(), pou: pou.name.clone(), first }));
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
            let end = start + pou.rungs.len() as u32 + pou.lowered.as_ref().map_or(0, |l| l.len() as u32);
            pous.push(Pou { name: pou.name.clone(), kind: pou.kind, rungs: start..end });
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
                let ld = array(required(o, "ld", "a rung", &path, Some(id))?, &ldp, Some(id))?;
                self.edge_count = 0;
                let scope = Scope { pou, rung_id: id };
                let series = self.series(ld, &ldp, Place::Top, &scope)?;
                let label = o.get("label").and_then(Json::as_str).map(str::to_owned);
                let comment = match o.get("comment") {
                    None => None,
                    Some(c) => Some(string(c, &format!("{path}.comment"), Some(id))?.to_owned()),
                };
                rungs.push(Rung { id: id.clone(), label, comment, pou, series, path, network: None });
            }
        }
        let mut program = Program { name, vars: self.vars, pous, rungs };
        super::structure::check(&mut program)?;
        Ok(program)
    }

    /// A name a block or element writes, in the scope of `pou`: not an input, not a field, not
    /// a member or an instance.
    fn writable_name(&self, text: &str, pou: PouId, what: &'static str) -> std::result::Result<VarId, Invalid> {
        let (r, t) = self.lookup(text, pou)?;
        let var = &self.vars[r.var.index()];
        let fail = |why| Err(Invalid::NotWritable { what, var: text.to_owned(), why });
        if r.field.is_some() {
            return fail("instance fields are written only by their function block");
        }
        if text.contains('.') {
            return fail("it belongs to a function block instance (only the instance writes it)");
        }
        if var.class == VarClass::Input {
            return fail("it is an input (inputs are written by the scan, not the program)");
        }
        if matches!(t, Type::Fb(_)) {
            return fail("it is a function block instance");
        }
        Ok(r.var)
    }

    /// A member (input or output) of user function block instance `i`, read as `G1.NAME`.
    fn member(&self, i: usize, base: &str, field: Option<&str>) -> std::result::Result<(VarRef, Type), Invalid> {
        let inst = &self.instances[i];
        let Some(f) = field else { return Err(Invalid::InstanceValue { name: base.to_owned() }) };
        match inst.inputs.iter().chain(&inst.outputs).find(|(n, _)| n == f) {
            Some(&(_, v)) => Ok((VarRef { var: v, field: None }, self.vars[v.index()].ty)),
            None => Err(Invalid::UnknownMember {
                instance: base.to_owned(),
                fb: inst.fb.clone(),
                member: f.to_owned(),
                members: inst.inputs.iter().chain(&inst.outputs).map(|(n, _)| n.as_str()).collect::<Vec<_>>().join(", "),
            }),
        }
    }

    fn series(&mut self, items: &[Json], path: &str, place: Place, s: &Scope) -> Result<Series> {
        let mut out = Vec::with_capacity(items.len());
        for (i, item) in items.iter().enumerate() {
            let p = format!("{path}[{i}]");
            let e = self.element(item, &p, s)?;
            let misplaced = |what: &'static str, place: &'static str| Err(LoadError::invalid(Some(s.rung_id), &p, Invalid::Misplaced { what, place }));
            match (&e, place) {
                (Element::For { .. }, Place::Top) if i + 1 == items.len() => {}
                (Element::For { .. }, _) => return misplaced("`for`", "except as the last element of a rung"),
                (Element::Next { .. }, Place::Top) if items.len() == 1 => {}
                (Element::Next { .. }, _) => return misplaced("`next`", "except alone in its rung"),
                (Element::Contact { .. } | Element::Compare { .. } | Element::Or(_), _) => {}
                (_, Place::Or) => return misplaced("this element", "inside `or` (only contact, compare and or are)"),
                _ => {}
            }
            out.push(e);
        }
        Ok(out)
    }

    fn branches(&mut self, v: &Json, path: &str, place: Place, s: &Scope) -> Result<Vec<Series>> {
        let arr = array(v, path, Some(s.rung_id))?;
        if arr.is_empty() {
            return Err(LoadError::invalid(Some(s.rung_id), path, Invalid::Shape { expected: "at least one branch", found: "an empty array".into() }));
        }
        let mut out = Vec::with_capacity(arr.len());
        for (i, b) in arr.iter().enumerate() {
            let p = format!("{path}[{i}]");
            let items = array(b, &p, Some(s.rung_id))?;
            out.push(self.series(items, &p, place, s)?);
        }
        Ok(out)
    }

    fn element(&mut self, v: &Json, path: &str, s: &Scope) -> Result<Element> {
        let rid = Some(s.rung_id);
        let o = object(v, path, rid, "an element")?;
        let kind = ELEMENT_KINDS
            .iter()
            .find(|(k, _)| o.contains_key(*k))
            .ok_or_else(|| {
                let keys = o.keys().map(|k| format!("\"{k}\": …")).collect::<Vec<_>>().join(", ");
                LoadError::invalid(rid, path, Invalid::UnknownElement { keys })
            })?;
        let (key, allowed) = *kind;
        let what = element_what(key);
        check_keys(o, allowed, what, path, rid)?;
        let at = |k: &str| format!("{path}.{k}");
        let err = |k: &str, kind: Invalid| LoadError::invalid(rid, &at(k), kind);
        let get = |k: &'static str| required(o, k, what, path, rid);
        Ok(match key {
            "contact" => {
                let (var, ty) = self.var_ref(get("contact")?, &at("contact"), s)?;
                expect_type(ty, Type::Bool, "a contact", &self.vars[var.var.index()].name).map_err(|k| err("contact", k))?;
                let negated = match o.get("negated") {
                    Some(n) => boolean(n, &at("negated"), rid)?,
                    None => false,
                };
                let kind = match o.get("edge") {
                    None if negated => ContactKind::Negated,
                    None => ContactKind::Normal,
                    Some(_) if negated => return Err(err("edge", Invalid::Misplaced { what: "`edge`", place: "together with `negated`" })),
                    Some(e) => {
                        let memory = self.edge_memory(s);
                        match string(e, &at("edge"), rid)? {
                            "rising" => ContactKind::Rising { memory },
                            "falling" => ContactKind::Falling { memory },
                            other => return Err(err("edge", Invalid::Shape { expected: "\"rising\" or \"falling\"", found: format!("\"{other}\"") })),
                        }
                    }
                };
                Element::Contact { var, kind }
            }
            "compare" => {
                let op = string(get("compare")?, &at("compare"), rid)?;
                let op = CmpOp::parse(op).ok_or_else(|| err("compare", Invalid::Shape { expected: "EQ, NE, LT, LE, GT or GE", found: format!("\"{op}\"") }))?;
                let (a, b) = self.numeric_pair(get("a")?, get("b")?, path, s, "a comparison", |_| true)?;
                Element::Compare { op, a, b }
            }
            "or" => Element::Or(self.branches(get("or")?, &at("or"), Place::Or, s)?),
            "branch" => Element::Branch(self.branches(get("branch")?, &at("branch"), Place::Branch, s)?),
            "coil" => {
                let var = self.writable(get("coil")?, &at("coil"), s, "a coil", Some(Type::Bool))?;
                let negated = match o.get("negated") {
                    Some(n) => boolean(n, &at("negated"), rid)?,
                    None => false,
                };
                Element::Coil { var, negated }
            }
            "set" => Element::Set(self.writable(get("set")?, &at("set"), s, "a set coil", Some(Type::Bool))?),
            "reset" => Element::Reset(self.writable(get("reset")?, &at("reset"), s, "a reset coil", Some(Type::Bool))?),
            "ton" | "tof" | "tp" => {
                let kind = match key {
                    "ton" => TimerKind::Ton,
                    "tof" => TimerKind::Tof,
                    _ => TimerKind::Tp,
                };
                let instance = self.instance(get(key)?, &at(key), s, kind.fb())?;
                let pt = self.operand_of(get("pt")?, &at("pt"), s, Type::Time, "a timer's PT")?;
                Element::Timer { kind, instance, pt }
            }
            "ctu" => {
                let instance = self.instance(get("ctu")?, &at("ctu"), s, FbKind::Ctu)?;
                let pv = self.operand_of(get("pv")?, &at("pv"), s, Type::Int, "a counter's PV")?;
                let reset = self.operand_of(get("reset")?, &at("reset"), s, Type::Bool, "a counter's reset")?;
                Element::Ctu { instance, pv, reset }
            }
            "ctd" => {
                let instance = self.instance(get("ctd")?, &at("ctd"), s, FbKind::Ctd)?;
                let pv = self.operand_of(get("pv")?, &at("pv"), s, Type::Int, "a counter's PV")?;
                let load = self.operand_of(get("load")?, &at("load"), s, Type::Bool, "a counter's load")?;
                Element::Ctd { instance, pv, load }
            }
            "move" => {
                let to = self.writable(get("to")?, &at("to"), s, "a move", None)?;
                let ty = self.vars[to.index()].ty;
                let from = self.operand_of(get("move")?, &at("move"), s, ty, "a move")?;
                Element::Move { from, to }
            }
            "op" => {
                let name = string(get("op")?, &at("op"), rid)?;
                let op = ArithOp::parse(name).ok_or_else(|| err("op", Invalid::Shape { expected: "ADD, SUB, MUL, DIV or MOD", found: format!("\"{name}\"") }))?;
                let out = self.writable(get("out")?, &at("out"), s, "an arithmetic box", None)?;
                let ty = self.vars[out.index()].ty;
                let ok = match op {
                    ArithOp::Add | ArithOp::Sub => ty.is_numeric(),
                    ArithOp::Mul | ArithOp::Div => matches!(ty, Type::Int | Type::Dint | Type::Real),
                    ArithOp::Mod => matches!(ty, Type::Int | Type::Dint),
                };
                if !ok {
                    return Err(err("out", Invalid::Type {
                        what: "this arithmetic box",
                        expected: if op == ArithOp::Mod { "INT or DINT".into() } else { "a numeric type".into() },
                        operand: self.vars[out.index()].name.clone(),
                        found: ty.to_string(),
                    }));
                }
                let inputs = array(get("in")?, &at("in"), rid)?;
                if inputs.len() != 2 {
                    return Err(err("in", Invalid::Shape { expected: "two operands", found: format!("{} operands", inputs.len()) }));
                }
                let a = self.operand_of(&inputs[0], &format!("{path}.in[0]"), s, ty, "an arithmetic box")?;
                let b = self.operand_of(&inputs[1], &format!("{path}.in[1]"), s, ty, "an arithmetic box")?;
                Element::Arith { op, a, b, out }
            }
            "jmp" => {
                let label = string(get("jmp")?, &at("jmp"), rid)?;
                let target = *self.labels[s.pou.index()].get(label).ok_or_else(|| {
                    err("jmp", Invalid::UndefinedLabel { label: label.into(), pou: self.pous[s.pou.index()].name.clone() })
                })?;
                Element::Jmp { label: label.to_owned(), target }
            }
            "ret" => {
                flag(get("ret")?, &at("ret"), rid)?;
                Element::Ret
            }
            "end" => {
                flag(get("end")?, &at("end"), rid)?;
                if s.pou != PouId(0) {
                    return Err(err("end", Invalid::Misplaced { what: "`end`", place: "in a subroutine (use `ret`)" }));
                }
                Element::End
            }
            "next" => {
                flag(get("next")?, &at("next"), rid)?;
                Element::Next { head: RungId(u32::MAX) }
            }
            "call" => {
                let name = string(get("call")?, &at("call"), rid)?;
                let pou = self
                    .pous
                    .iter()
                    .position(|p| p.kind == PouKind::Subroutine && p.callable && p.name == name)
                    .ok_or_else(|| err("call", Invalid::UndefinedSubroutine { name: name.into() }))?;
                Element::Call { pou: PouId(pou as u32) }
            }
            "for" => {
                let fp = at("for");
                let f = object(get("for")?, &fp, rid, "a FOR")?;
                check_keys(f, &["var", "from", "to"], "a FOR", &fp, rid)?;
                let var = self.writable(required(f, "var", "a FOR", &fp, rid)?, &format!("{fp}.var"), s, "a FOR", None)?;
                let ty = self.vars[var.index()].ty;
                if !matches!(ty, Type::Int | Type::Dint) {
                    return Err(LoadError::invalid(rid, &format!("{fp}.var"), Invalid::Type {
                        what: "a FOR index",
                        expected: "INT or DINT".into(),
                        operand: self.vars[var.index()].name.clone(),
                        found: ty.to_string(),
                    }));
                }
                let from = self.operand_of(required(f, "from", "a FOR", &fp, rid)?, &format!("{fp}.from"), s, ty, "a FOR bound")?;
                let to = self.operand_of(required(f, "to", "a FOR", &fp, rid)?, &format!("{fp}.to"), s, ty, "a FOR bound")?;
                Element::For { var, from, to, next: RungId(u32::MAX) }
            }
            _ => unreachable!("ELEMENT_KINDS lists only handled keys"),
        })
    }

    fn edge_memory(&mut self, s: &Scope) -> VarId {
        self.edge_count += 1;
        let id = VarId(self.vars.len() as u32);
        self.vars.push(Var {
            name: format!("{}:edge{}", s.rung_id, self.edge_count),
            ty: Type::Bool,
            class: VarClass::Memory,
            init: Value::Bool(false),
            scope: None,
            hidden: true,
        });
        id
    }

    fn lookup(&self, text: &str, pou: PouId) -> std::result::Result<(VarRef, Type), Invalid> {
        let (base, field) = match text.split_once('.') {
            Some((b, f)) => (b, Some(f)),
            None => (text, None),
        };
        let id = match self.locals[pou.index()].get(base) {
            Some(&id) => id,
            None => {
                if let Some(&i) = self.local_instances[pou.index()].get(base) {
                    return self.member(i, base, field);
                }
                match self.globals.get(base) {
                    Some(&id) => id,
                    None => match self.global_instances.get(base) {
                        Some(&i) => return self.member(i, base, field),
                        None => return Err(Invalid::UndefinedVar { name: base.to_owned() }),
                    },
                }
            }
        };
        operand::field_ref(id, text, self.vars[id.index()].ty, field)
    }

    fn var_ref(&self, v: &Json, path: &str, s: &Scope) -> Result<(VarRef, Type)> {
        let text = string(v, path, Some(s.rung_id))?;
        self.lookup(text, s.pou).map_err(|k| LoadError::invalid(Some(s.rung_id), path, k))
    }

    fn untyped(&self, v: &Json, path: &str, s: &Scope) -> Result<Untyped> {
        operand::parse(v, &|n| self.lookup(n, s.pou)).map_err(|k| LoadError::invalid(Some(s.rung_id), path, k))
    }

    fn operand_of(&self, v: &Json, path: &str, s: &Scope, ty: Type, what: &'static str) -> Result<Operand> {
        let u = self.untyped(v, path, s)?;
        operand::typed(&u, ty, what, &display_json(v)).map_err(|k| LoadError::invalid(Some(s.rung_id), path, k))
    }

    /// Two operands of one numeric type (the type of whichever fixes one).
    fn numeric_pair(&self, a: &Json, b: &Json, path: &str, s: &Scope, what: &'static str, accept: fn(Type) -> bool) -> Result<(Operand, Operand)> {
        let (pa, pb) = (format!("{path}.a"), format!("{path}.b"));
        let ua = self.untyped(a, &pa, s)?;
        let ub = self.untyped(b, &pb, s)?;
        let ty = ua.ty().or(ub.ty()).unwrap_or_else(|| operand::default_type(&ua).max_numeric(operand::default_type(&ub)));
        if !ty.is_numeric() || !accept(ty) {
            let (p, j) = if ua.ty().is_some() { (&pa, a) } else { (&pb, b) };
            return Err(LoadError::invalid(Some(s.rung_id), p, Invalid::Type { what, expected: "INT, DINT, REAL or TIME".into(), operand: display_json(j), found: ty.to_string() }));
        }
        let oa = operand::typed(&ua, ty, what, &display_json(a)).map_err(|k| LoadError::invalid(Some(s.rung_id), &pa, k))?;
        let ob = operand::typed(&ub, ty, what, &display_json(b)).map_err(|k| LoadError::invalid(Some(s.rung_id), &pb, k))?;
        Ok((oa, ob))
    }

    /// A variable that an element writes: not an input, not a field, of type `ty` if given.
    fn writable(&self, v: &Json, path: &str, s: &Scope, what: &'static str, ty: Option<Type>) -> Result<VarId> {
        let text = string(v, path, Some(s.rung_id))?;
        let id = self.writable_name(text, s.pou, what).map_err(|k| LoadError::invalid(Some(s.rung_id), path, k))?;
        let var = &self.vars[id.index()];
        if let Some(ty) = ty {
            expect_type(var.ty, ty, what, &var.name).map_err(|k| LoadError::invalid(Some(s.rung_id), path, k))?;
        }
        Ok(id)
    }

    fn instance(&self, v: &Json, path: &str, s: &Scope, fb: FbKind) -> Result<VarId> {
        let (r, t) = self.var_ref(v, path, s)?;
        if r.field.is_some() || t != Type::Fb(fb) {
            return Err(LoadError::invalid(Some(s.rung_id), path, Invalid::Type {
                what: "this box",
                expected: format!("a {} instance", Type::Fb(fb)),
                operand: display_json(v),
                found: t.to_string(),
            }));
        }
        Ok(r.var)
    }
}

/// The lowering's view of one POU's scope.
struct PouEnv<'b, 'a> {
    b: &'b mut Builder<'a>,
    pou: PouId,
}

impl Env for PouEnv<'_, '_> {
    fn lookup(&self, text: &str) -> std::result::Result<(VarRef, Type), Invalid> {
        self.b.lookup(text, self.pou)
    }

    fn writable(&self, text: &str, what: &'static str) -> std::result::Result<VarId, Invalid> {
        self.b.writable_name(text, self.pou, what)
    }

    fn instance(&self, text: &str) -> std::result::Result<InstanceRef, Invalid> {
        let b = &*self.b;
        let user = |i: usize| {
            let inst = &b.instances[i];
            InstanceRef::User { pou: inst.pou.expect("expanded before lowering"), fb: inst.fb.clone(), inputs: inst.inputs.clone(), outputs: inst.outputs.clone() }
        };
        let var = |id: VarId| match b.vars[id.index()].ty {
            Type::Fb(k) => InstanceRef::Builtin(id, k),
            t => InstanceRef::Other(t),
        };
        let pou = self.pou.index();
        if !text.contains('.') {
            if let Some(&id) = b.locals[pou].get(text) {
                return Ok(var(id));
            }
            if let Some(&i) = b.local_instances[pou].get(text) {
                return Ok(user(i));
            }
            if let Some(&id) = b.globals.get(text) {
                return Ok(var(id));
            }
            if let Some(&i) = b.global_instances.get(text) {
                return Ok(user(i));
            }
        }
        let (_, t) = b.lookup(text, self.pou)?;
        Ok(InstanceRef::Other(t))
    }

    fn var(&self, v: VarId) -> &Var {
        &self.b.vars[v.index()]
    }

    fn hidden(&mut self, name: String, ty: Type) -> std::result::Result<VarId, Invalid> {
        let b = &mut *self.b;
        let names = b.var_names.get_or_insert_with(|| b.vars.iter().map(|v| v.name.clone()).collect());
        if !names.insert(name.clone()) {
            return Err(Invalid::HiddenClash { name });
        }
        let id = VarId(self.b.vars.len() as u32);
        let scope = if self.pou.index() == 0 { None } else { Some(self.pou) };
        self.b.vars.push(Var { name, ty, class: VarClass::Memory, init: ty.zero(), scope, hidden: true });
        Ok(id)
    }

    fn claim_accumulator(&mut self, v: VarId) -> std::result::Result<(), Invalid> {
        match self.b.accumulated.get(&v) {
            Some(&other) if other != self.pou => Err(Invalid::AccumulatedTwice {
                var: self.b.vars[v.index()].name.clone(),
                first: self.b.pous[other.index()].name.clone(),
                second: self.b.pous[self.pou.index()].name.clone(),
            }),
            _ => {
                self.b.accumulated.insert(v, self.pou);
                Ok(())
            }
        }
    }
}

/// Makes the POU-relative jump targets of a lowered rung absolute.
fn relocate_jumps(series: &mut Series, offset: u32) {
    for e in series {
        match e {
            Element::Jmp { target, .. } => target.0 += offset,
            Element::Or(bs) | Element::Branch(bs) => bs.iter_mut().for_each(|b| relocate_jumps(b, offset)),
            _ => {}
        }
    }
}

trait MaxNumeric {
    fn max_numeric(self, other: Type) -> Type;
}
impl MaxNumeric for Type {
    fn max_numeric(self, other: Type) -> Type {
        if self == Type::Real || other == Type::Real {
            Type::Real
        } else {
            self
        }
    }
}

/// Element kind keys, in the order they are recognised, with the keys each kind allows.
/// `ctu`/`ctd` come before `reset` because a counter has a `reset` operand.
const ELEMENT_KINDS: &[(&str, &[&str])] = &[
    ("ctu", &["ctu", "pv", "reset"]),
    ("ctd", &["ctd", "pv", "load"]),
    ("contact", &["contact", "negated", "edge"]),
    ("compare", &["compare", "a", "b"]),
    ("or", &["or"]),
    ("coil", &["coil", "negated"]),
    ("set", &["set"]),
    ("reset", &["reset"]),
    ("branch", &["branch"]),
    ("ton", &["ton", "pt"]),
    ("tof", &["tof", "pt"]),
    ("tp", &["tp", "pt"]),
    ("move", &["move", "to"]),
    ("op", &["op", "in", "out"]),
    ("jmp", &["jmp"]),
    ("ret", &["ret"]),
    ("end", &["end"]),
    ("call", &["call"]),
    ("for", &["for"]),
    ("next", &["next"]),
];

fn element_what(key: &str) -> &'static str {
    match key {
        "contact" => "a contact",
        "compare" => "a compare contact",
        "or" => "an or",
        "coil" => "a coil",
        "set" => "a set coil",
        "reset" => "a reset coil",
        "branch" => "a branch",
        "ton" => "a TON box",
        "tof" => "a TOF box",
        "tp" => "a TP box",
        "ctu" => "a CTU box",
        "ctd" => "a CTD box",
        "move" => "a move box",
        "op" => "an arithmetic box",
        "jmp" => "a jump",
        "ret" => "a return",
        "end" => "an end",
        "call" => "a call",
        "for" => "a FOR",
        _ => "a NEXT",
    }
}

fn rung_path(pou_path: &str, i: usize) -> String {
    if pou_path.is_empty() {
        format!("rungs[{i}]")
    } else {
        format!("{pou_path}[{i}]")
    }
}

fn display_json(v: &Json) -> String {
    match v {
        Json::String(s) => s.clone(),
        other => other.to_string(),
    }
}

fn expect_type(found: Type, expected: Type, what: &'static str, name: &str) -> std::result::Result<(), Invalid> {
    if found == expected {
        Ok(())
    } else {
        Err(Invalid::Type { what, expected: expected.to_string(), operand: name.to_owned(), found: found.to_string() })
    }
}

fn object<'v>(v: &'v Json, path: &str, rung: Option<&str>, what: &'static str) -> Result<&'v Map<String, Json>> {
    v.as_object().ok_or_else(|| {
        LoadError::invalid(rung, path, Invalid::Shape { expected: what_object(what), found: kind_of(v) })
    })
}

fn what_object(what: &'static str) -> &'static str {
    match what {
        "the program" => "a JSON object (the program)",
        "a variable" => "an object (a variable)",
        "a rung" => "an object (a rung)",
        "an element" => "an object (an element)",
        "a subroutine" => "an object (a subroutine)",
        "the subroutines" => "an object of subroutines",
        _ => "an object",
    }
}

fn array<'v>(v: &'v Json, path: &str, rung: Option<&str>) -> Result<&'v [Json]> {
    v.as_array()
        .map(Vec::as_slice)
        .ok_or_else(|| LoadError::invalid(rung, path, Invalid::Shape { expected: "an array", found: kind_of(v) }))
}

fn string<'v>(v: &'v Json, path: &str, rung: Option<&str>) -> Result<&'v str> {
    v.as_str().ok_or_else(|| LoadError::invalid(rung, path, Invalid::Shape { expected: "a string", found: kind_of(v) }))
}

fn boolean(v: &Json, path: &str, rung: Option<&str>) -> Result<bool> {
    v.as_bool().ok_or_else(|| LoadError::invalid(rung, path, Invalid::Shape { expected: "true or false", found: kind_of(v) }))
}

/// A marker field such as `"ret": true`.
fn flag(v: &Json, path: &str, rung: Option<&str>) -> Result<()> {
    match v {
        Json::Bool(true) => Ok(()),
        other => Err(LoadError::invalid(rung, path, Invalid::Shape { expected: "true", found: kind_of(other) })),
    }
}

fn required<'v>(o: &'v Map<String, Json>, key: &'static str, what: &'static str, path: &str, rung: Option<&str>) -> Result<&'v Json> {
    o.get(key).ok_or_else(|| LoadError::invalid(rung, path, Invalid::MissingField { field: key, what }))
}

fn check_keys(o: &Map<String, Json>, allowed: &[&str], what: &'static str, path: &str, rung: Option<&str>) -> Result<()> {
    match o.keys().find(|k| !allowed.contains(&k.as_str())) {
        None => Ok(()),
        Some(k) => {
            let p = if path.is_empty() { k.clone() } else { format!("{path}.{k}") };
            Err(LoadError::invalid(rung, &p, Invalid::UnknownField { field: k.clone(), what, allowed: allowed.join(", ") }))
        }
    }
}

fn check_name(name: &str, path: &str, rung: Option<&str>) -> Result<()> {
    let mut chars = name.chars();
    let ok = matches!(chars.next(), Some(c) if c.is_ascii_alphabetic() || c == '_')
        && chars.all(|c| c.is_ascii_alphanumeric() || c == '_');
    if ok {
        Ok(())
    } else {
        Err(LoadError::invalid(rung, path, Invalid::BadName { name: name.into() }))
    }
}
