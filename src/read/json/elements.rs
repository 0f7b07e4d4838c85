//! Ladder elements: one JSON element → [`Element`] (contacts, coils, boxes, jumps, calls,
//! FOR/NEXT), series and branches with the placement rules of each kind.

use super::util::{array, boolean, check_keys, expect_type, flag, object, required, string};
use super::{Builder, Result};
use crate::model::*;
use crate::read::error::{Invalid, LoadError};
use serde_json::Value as Json;

/// What may appear in a series, by where the series is.
#[derive(Copy, Clone, PartialEq, Eq)]
pub(super) enum Place {
    /// The rung's own series.
    Top,
    /// A branch of `branch` (an output path).
    Branch,
    /// A branch of `or` (conditions only).
    Or,
}

pub(super) struct Scope<'s> {
    pub(super) pou: PouId,
    pub(super) rung_id: &'s str,
}

impl<'a> Builder<'a> {
    pub(super) fn series(
        &mut self,
        items: &[Json],
        path: &str,
        place: Place,
        s: &Scope,
    ) -> Result<Series> {
        let mut out = Vec::with_capacity(items.len());
        for (i, item) in items.iter().enumerate() {
            let p = format!("{path}[{i}]");
            let e = self.element(item, &p, s)?;
            let misplaced = |what: &'static str, place: &'static str| {
                Err(LoadError::invalid(
                    Some(s.rung_id),
                    &p,
                    Invalid::Misplaced { what, place },
                ))
            };
            match (&e, place) {
                (Element::For { .. }, Place::Top) if i + 1 == items.len() => {}
                (Element::For { .. }, _) => {
                    return misplaced("`for`", "except as the last element of a rung")
                }
                (Element::Next { .. }, Place::Top) if items.len() == 1 => {}
                (Element::Next { .. }, _) => {
                    return misplaced("`next`", "except alone in its rung")
                }
                (Element::Contact { .. } | Element::Compare { .. } | Element::Or(_), _) => {}
                (_, Place::Or) => {
                    return misplaced(
                        "this element",
                        "inside `or` (only contact, compare and or are)",
                    )
                }
                _ => {}
            }
            out.push(e);
        }
        Ok(out)
    }

    pub(super) fn branches(
        &mut self,
        v: &Json,
        path: &str,
        place: Place,
        s: &Scope,
    ) -> Result<Vec<Series>> {
        let arr = array(v, path, Some(s.rung_id))?;
        if arr.is_empty() {
            return Err(LoadError::invalid(
                Some(s.rung_id),
                path,
                Invalid::Shape {
                    expected: "at least one branch",
                    found: "an empty array".into(),
                },
            ));
        }
        let mut out = Vec::with_capacity(arr.len());
        for (i, b) in arr.iter().enumerate() {
            let p = format!("{path}[{i}]");
            let items = array(b, &p, Some(s.rung_id))?;
            out.push(self.series(items, &p, place, s)?);
        }
        Ok(out)
    }

    pub(super) fn element(&mut self, v: &Json, path: &str, s: &Scope) -> Result<Element> {
        let rid = Some(s.rung_id);
        let o = object(v, path, rid, "an element")?;
        let kind = ELEMENT_KINDS
            .iter()
            .find(|(k, _)| o.contains_key(*k))
            .ok_or_else(|| {
                let keys = o
                    .keys()
                    .map(|k| format!("\"{k}\": …"))
                    .collect::<Vec<_>>()
                    .join(", ");
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
                expect_type(
                    ty,
                    Type::Bool,
                    "a contact",
                    &self.vars[var.var.index()].name,
                )
                .map_err(|k| err("contact", k))?;
                let negated = match o.get("negated") {
                    Some(n) => boolean(n, &at("negated"), rid)?,
                    None => false,
                };
                let kind = match o.get("edge") {
                    None if negated => ContactKind::Negated,
                    None => ContactKind::Normal,
                    Some(_) if negated => {
                        return Err(err(
                            "edge",
                            Invalid::Misplaced {
                                what: "`edge`",
                                place: "together with `negated`",
                            },
                        ))
                    }
                    Some(e) => {
                        let memory = self.edge_memory(s);
                        match string(e, &at("edge"), rid)? {
                            "rising" => ContactKind::Rising { memory },
                            "falling" => ContactKind::Falling { memory },
                            other => {
                                return Err(err(
                                    "edge",
                                    Invalid::Shape {
                                        expected: "\"rising\" or \"falling\"",
                                        found: format!("\"{other}\""),
                                    },
                                ))
                            }
                        }
                    }
                };
                Element::Contact { var, kind }
            }
            "compare" => {
                let op = string(get("compare")?, &at("compare"), rid)?;
                let op = CmpOp::parse(op).ok_or_else(|| {
                    err(
                        "compare",
                        Invalid::Shape {
                            expected: "EQ, NE, LT, LE, GT or GE",
                            found: format!("\"{op}\""),
                        },
                    )
                })?;
                let (a, b) =
                    self.numeric_pair(get("a")?, get("b")?, path, s, "a comparison", |_| true)?;
                Element::Compare { op, a, b }
            }
            "or" => Element::Or(self.branches(get("or")?, &at("or"), Place::Or, s)?),
            "branch" => {
                Element::Branch(self.branches(get("branch")?, &at("branch"), Place::Branch, s)?)
            }
            "coil" => {
                let var =
                    self.writable(get("coil")?, &at("coil"), s, "a coil", Some(Type::Bool))?;
                let negated = match o.get("negated") {
                    Some(n) => boolean(n, &at("negated"), rid)?,
                    None => false,
                };
                Element::Coil { var, negated }
            }
            "set" => Element::Set(self.writable(
                get("set")?,
                &at("set"),
                s,
                "a set coil",
                Some(Type::Bool),
            )?),
            "reset" => Element::Reset(self.writable(
                get("reset")?,
                &at("reset"),
                s,
                "a reset coil",
                Some(Type::Bool),
            )?),
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
                let reset = self.operand_of(
                    get("reset")?,
                    &at("reset"),
                    s,
                    Type::Bool,
                    "a counter's reset",
                )?;
                Element::Ctu {
                    instance,
                    pv,
                    reset,
                }
            }
            "ctd" => {
                let instance = self.instance(get("ctd")?, &at("ctd"), s, FbKind::Ctd)?;
                let pv = self.operand_of(get("pv")?, &at("pv"), s, Type::Int, "a counter's PV")?;
                let load =
                    self.operand_of(get("load")?, &at("load"), s, Type::Bool, "a counter's load")?;
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
                let op = ArithOp::parse(name).ok_or_else(|| {
                    err(
                        "op",
                        Invalid::Shape {
                            expected: "ADD, SUB, MUL, DIV or MOD",
                            found: format!("\"{name}\""),
                        },
                    )
                })?;
                let out = self.writable(get("out")?, &at("out"), s, "an arithmetic box", None)?;
                let ty = self.vars[out.index()].ty;
                let ok = match op {
                    ArithOp::Add | ArithOp::Sub => ty.is_numeric(),
                    ArithOp::Mul | ArithOp::Div => {
                        matches!(ty, Type::Int | Type::Dint | Type::Real)
                    }
                    ArithOp::Mod => matches!(ty, Type::Int | Type::Dint),
                };
                if !ok {
                    return Err(err(
                        "out",
                        Invalid::Type {
                            what: "this arithmetic box",
                            expected: if op == ArithOp::Mod {
                                "INT or DINT".into()
                            } else {
                                "a numeric type".into()
                            },
                            operand: self.vars[out.index()].name.clone(),
                            found: ty.to_string(),
                        },
                    ));
                }
                let inputs = array(get("in")?, &at("in"), rid)?;
                if inputs.len() != 2 {
                    return Err(err(
                        "in",
                        Invalid::Shape {
                            expected: "two operands",
                            found: format!("{} operands", inputs.len()),
                        },
                    ));
                }
                let a = self.operand_of(
                    &inputs[0],
                    &format!("{path}.in[0]"),
                    s,
                    ty,
                    "an arithmetic box",
                )?;
                let b = self.operand_of(
                    &inputs[1],
                    &format!("{path}.in[1]"),
                    s,
                    ty,
                    "an arithmetic box",
                )?;
                Element::Arith { op, a, b, out }
            }
            "jmp" => {
                let label = string(get("jmp")?, &at("jmp"), rid)?;
                let target = *self.labels[s.pou.index()].get(label).ok_or_else(|| {
                    err(
                        "jmp",
                        Invalid::UndefinedLabel {
                            label: label.into(),
                            pou: self.pous[s.pou.index()].name.clone(),
                        },
                    )
                })?;
                Element::Jmp {
                    label: label.to_owned(),
                    target,
                }
            }
            "ret" => {
                flag(get("ret")?, &at("ret"), rid)?;
                Element::Ret
            }
            "end" => {
                flag(get("end")?, &at("end"), rid)?;
                if s.pou != PouId(0) {
                    return Err(err(
                        "end",
                        Invalid::Misplaced {
                            what: "`end`",
                            place: "in a subroutine (use `ret`)",
                        },
                    ));
                }
                Element::End
            }
            "next" => {
                flag(get("next")?, &at("next"), rid)?;
                Element::Next {
                    head: RungId(u32::MAX),
                }
            }
            "call" => {
                let name = string(get("call")?, &at("call"), rid)?;
                let pou = self
                    .pous
                    .iter()
                    .position(|p| p.kind == PouKind::Subroutine && p.callable && p.name == name)
                    .ok_or_else(|| {
                        err("call", Invalid::UndefinedSubroutine { name: name.into() })
                    })?;
                Element::Call {
                    pou: PouId(pou as u32),
                }
            }
            "for" => {
                let fp = at("for");
                let f = object(get("for")?, &fp, rid, "a FOR")?;
                check_keys(f, &["var", "from", "to"], "a FOR", &fp, rid)?;
                let var = self.writable(
                    required(f, "var", "a FOR", &fp, rid)?,
                    &format!("{fp}.var"),
                    s,
                    "a FOR",
                    None,
                )?;
                let ty = self.vars[var.index()].ty;
                if !matches!(ty, Type::Int | Type::Dint) {
                    return Err(LoadError::invalid(
                        rid,
                        &format!("{fp}.var"),
                        Invalid::Type {
                            what: "a FOR index",
                            expected: "INT or DINT".into(),
                            operand: self.vars[var.index()].name.clone(),
                            found: ty.to_string(),
                        },
                    ));
                }
                let from = self.operand_of(
                    required(f, "from", "a FOR", &fp, rid)?,
                    &format!("{fp}.from"),
                    s,
                    ty,
                    "a FOR bound",
                )?;
                let to = self.operand_of(
                    required(f, "to", "a FOR", &fp, rid)?,
                    &format!("{fp}.to"),
                    s,
                    ty,
                    "a FOR bound",
                )?;
                Element::For {
                    var,
                    from,
                    to,
                    next: RungId(u32::MAX),
                }
            }
            _ => unreachable!("ELEMENT_KINDS lists only handled keys"),
        })
    }

    pub(super) fn edge_memory(&mut self, s: &Scope) -> VarId {
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
