//! The JSON program format → [`Program`]: field checks, name resolution, type checks.
//!
//! Follows docs/format.md (normative). Every object is checked for unknown fields; every name is
//! resolved (subroutine locals first, then program variables); every operand is typed. Errors name
//! the rung id and the JSON path. Structural rules checked here: unique rung ids (program-wide)
//! and labels (per POU), FOR/NEXT nesting, no jump into a FOR body, no recursive calls, `end` in
//! the main program only, no writes to inputs or to instance fields.

use super::error::{Invalid, LoadError};
use super::operand::{self, Untyped};
use crate::model::*;
use serde_json::{Map, Value as Json};
use std::collections::HashMap;

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
    let top = object(doc, "", None, "the program")?;
    check_keys(top, &["program", "vars", "rungs", "subroutines", "comment"], "the program", "", None)?;
    let name = string(required(top, "program", "the program", "", None)?, "program", None)?.to_owned();
    let mut b = Builder::default();
    b.pous.push(PouDraft { name: name.clone(), kind: PouKind::Main, path: String::new(), rungs: Vec::new() });
    b.locals.push(HashMap::new());
    if let Some(vars) = top.get("vars") {
        b.declare_vars(vars, "vars", None)?;
    }
    let main_rungs = array(required(top, "rungs", "the program", "", None)?, "rungs", None)?;
    b.pous[0].rungs = main_rungs.iter().collect();
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
            check_keys(body, &["vars", "rungs", "comment"], "a subroutine", &path, None)?;
            let pou = PouId(b.pous.len() as u32);
            b.locals.push(HashMap::new());
            if let Some(vars) = body.get("vars") {
                b.declare_vars(vars, &format!("{path}.vars"), Some((pou, sname)))?;
            }
            let rungs_path = format!("{path}.rungs");
            let rungs = array(required(body, "rungs", "a subroutine", &path, None)?, &rungs_path, None)?;
            b.pous.push(PouDraft { name: sname.clone(), kind: PouKind::Subroutine, path: rungs_path, rungs: rungs.iter().collect() });
        }
    }
    b.build(name)
}

struct PouDraft<'a> {
    name: String,
    kind: PouKind,
    /// JSON path of the rung array ("" means top-level `rungs`).
    path: String,
    rungs: Vec<&'a Json>,
}

#[derive(Default)]
struct Builder<'a> {
    vars: Vec<Var>,
    globals: HashMap<String, VarId>,
    /// Per POU: its local variables.
    locals: Vec<HashMap<String, VarId>>,
    pous: Vec<PouDraft<'a>>,
    /// Per POU: label → rung.
    labels: Vec<HashMap<String, RungId>>,
    /// Per rung, during element resolution: number of edge contacts so far.
    edge_count: u32,
}

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
    fn declare_vars(&mut self, vars: &Json, path: &str, scope: Option<(PouId, &str)>) -> Result<()> {
        for (i, v) in array(vars, path, None)?.iter().enumerate() {
            let p = format!("{path}[{i}]");
            let o = object(v, &p, None, "a variable")?;
            check_keys(o, &["name", "type", "class", "init", "comment"], "a variable", &p, None)?;
            let name = string(required(o, "name", "a variable", &p, None)?, &format!("{p}.name"), None)?;
            check_name(name, &format!("{p}.name"), None)?;
            let tname = string(required(o, "type", "a variable", &p, None)?, &format!("{p}.type"), None)?;
            let ty = Type::parse(tname)
                .ok_or_else(|| LoadError::invalid(None, &format!("{p}.type"), Invalid::UnknownType { name: tname.into() }))?;
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
            let table = match scope {
                None => &mut self.globals,
                Some((p, _)) => &mut self.locals[p.index()],
            };
            if table.contains_key(name) {
                return Err(LoadError::invalid(None, &format!("{p}.name"), Invalid::DuplicateVar { name: name.into() }));
            }
            let id = VarId(self.vars.len() as u32);
            table.insert(name.to_owned(), id);
            let display = match scope {
                None => name.to_owned(),
                Some((_, pou)) => format!("{pou}:{name}"),
            };
            self.vars.push(Var { name: display, ty, class, init, scope: scope.map(|(p, _)| p), hidden: false });
        }
        Ok(())
    }

    fn build(mut self, name: String) -> Result<Program> {
        if self.pous[0].rungs.is_empty() {
            return Err(LoadError::invalid(None, "rungs", Invalid::Empty));
        }
        // Pass 1: rung ids and labels.
        let mut ids: HashMap<&str, String> = HashMap::new();
        let mut heads: Vec<(RungId, &'a Map<String, Json>, String, PouId)> = Vec::new();
        let mut next_id = 0u32;
        for (pi, pou) in self.pous.iter().enumerate() {
            let mut labels = HashMap::new();
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
                if let Some(first) = ids.get(id) {
                    return Err(LoadError::invalid(Some(id), &format!("{path}.id"), Invalid::DuplicateRung { id: id.into(), first: first.clone() }));
                }
                ids.insert(id, path.clone());
                let rid = RungId(next_id);
                next_id += 1;
                if let Some(l) = o.get("label") {
                    let lp = format!("{path}.label");
                    let l = string(l, &lp, Some(id))?;
                    check_name(l, &lp, Some(id))?;
                    if let Some(prev) = labels.insert(l.to_owned(), rid) {
                        let first = heads[prev.index()].2.clone();
                        return Err(LoadError::invalid(Some(id), &lp, Invalid::DuplicateLabel { label: l.into(), pou: pou.name.clone(), first }));
                    }
                }
                heads.push((rid, o, id.to_owned(), PouId(pi as u32)));
            }
            self.labels.push(labels);
        }
        // Pass 2: elements.
        let mut rungs = Vec::with_capacity(heads.len());
        let mut pous = Vec::with_capacity(self.pous.len());
        let mut start = 0u32;
        for pou in &self.pous {
            let end = start + pou.rungs.len() as u32;
            pous.push(Pou { name: pou.name.clone(), kind: pou.kind, rungs: start..end });
            start = end;
        }
        for (rid, o, id, pou) in &heads {
            let path = rung_path(&self.pous[pou.index()].path, (rid.0 - pous[pou.index()].rungs.start) as usize);
            let ldp = format!("{path}.ld");
            let ld = array(required(o, "ld", "a rung", &path, Some(id))?, &ldp, Some(id))?;
            self.edge_count = 0;
            let scope = Scope { pou: *pou, rung_id: id };
            let series = self.series(ld, &ldp, Place::Top, &scope)?;
            let label = o.get("label").and_then(Json::as_str).map(str::to_owned);
            let comment = match o.get("comment") {
                None => None,
                Some(c) => Some(string(c, &format!("{path}.comment"), Some(id))?.to_owned()),
            };
            rungs.push(Rung { id: id.clone(), label, comment, pou: *pou, series, path });
        }
        let mut program = Program { name, vars: self.vars, pous, rungs };
        super::structure::check(&mut program)?;
        Ok(program)
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
                    .position(|p| p.kind == PouKind::Subroutine && p.name == name)
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
        let id = self.locals[pou.index()]
            .get(base)
            .or_else(|| self.globals.get(base))
            .copied()
            .ok_or_else(|| Invalid::UndefinedVar { name: base.to_owned() })?;
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
        let (r, t) = self.var_ref(v, path, s)?;
        let var = &self.vars[r.var.index()];
        let fail = |why| Err(LoadError::invalid(Some(s.rung_id), path, Invalid::NotWritable { what, var: display_json(v), why }));
        if r.field.is_some() {
            return fail("instance fields are written only by their function block");
        }
        if var.class == VarClass::Input {
            return fail("it is an input (inputs are written by the scan, not the program)");
        }
        if matches!(t, Type::Fb(_)) {
            return fail("it is a function block instance");
        }
        if let Some(ty) = ty {
            expect_type(t, ty, what, &var.name).map_err(|k| LoadError::invalid(Some(s.rung_id), path, k))?;
        }
        Ok(r.var)
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
