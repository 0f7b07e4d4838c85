//! Ladder elements: one syntax element → [`Element`] (contacts, coils, boxes, jumps, calls,
//! FOR/NEXT), series and branches with the placement rules of each kind (IEC 61131-3 8.2; the
//! S7-200 FOR/NEXT shape: FOR last in its rung, NEXT alone in its rung).

use super::path::At;
use super::util::expect_type;
use super::{Builder, Result};
use plc_diag::{Invalid, LoadError, Origin};
use plc_model::*;
use plc_syntax::{self as syntax, Edge};

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
    /// The rung's FOR's NEXT, or its NEXT's FOR (none: not a loop end, or unpaired, which the
    /// structural checks report).
    pub(super) partner: Option<RungId>,
}

impl<'a> Builder<'a> {
    pub(super) fn series(
        &mut self,
        items: &[syntax::Element],
        at: &At,
        place: Place,
        s: &Scope,
    ) -> Result<Series> {
        let mut out = Vec::with_capacity(items.len());
        for (i, item) in items.iter().enumerate() {
            let p = at.index(i);
            let misplaced = |what: &'static str, place: &'static str| {
                Err(LoadError::invalid(
                    Some(s.rung_id),
                    &p.with(""),
                    Invalid::Misplaced { what, place },
                )
                .at(item.origin))
            };
            // Placement first only where the old element had no errors of its own to report.
            let e = self.element(item, &p, s)?;
            use syntax::ElementKind as S;
            match (&item.kind, place) {
                (S::For(_), Place::Top) if i + 1 == items.len() => {}
                (S::For(_), _) => {
                    return misplaced("`for`", "except as the last element of a rung")
                }
                (S::Next, Place::Top) if items.len() == 1 => {}
                (S::Next, _) => return misplaced("`next`", "except alone in its rung"),
                (k, _) if k.is_condition() => {}
                (_, Place::Or) => {
                    return misplaced(
                        "this element",
                        "inside `or` (only contact, compare and or are)",
                    )
                }
                _ => {}
            }
            out.extend(e);
        }
        Ok(out)
    }

    fn branches(
        &mut self,
        branches: &[syntax::Series],
        at: &At,
        place: Place,
        s: &Scope,
    ) -> Result<Vec<Series>> {
        let mut out = Vec::with_capacity(branches.len());
        for (i, b) in branches.iter().enumerate() {
            out.push(self.series(b, &at.index(i), place, s)?);
        }
        Ok(out)
    }

    /// The element `e` resolved; `None` only for a FOR or NEXT without a partner (the rung is
    /// refused by the structural checks, which say why).
    pub(super) fn element(
        &mut self,
        e: &syntax::Element,
        at: &At,
        s: &Scope,
    ) -> Result<Option<Element>> {
        use syntax::ElementKind as S;
        let rid = Some(s.rung_id);
        let err = |k: &str, origin: Origin, kind: Invalid| {
            LoadError::invalid(rid, &at.with(&format!(".{k}")), kind).at(origin)
        };
        let key = |k: &'static str| at.key(k);
        Ok(Some(match &e.kind {
            S::Invalid(p) => {
                let err = LoadError::invalid(rid, &at.with(&p.at), p.kind.clone());
                return Err(err.at(p.origin).at(e.origin));
            }
            S::Contact {
                var: name,
                negated,
                edge,
            } => {
                let (var, ty) = self.var_ref(name, &key("contact"), s)?;
                expect_type(
                    ty,
                    Type::Bool,
                    "a contact",
                    &self.vars[var.var.index()].name,
                )
                .map_err(|k| err("contact", name.origin, k))?;
                let kind = match (edge, negated) {
                    (None, true) => ContactKind::Negated,
                    (None, false) => ContactKind::Normal,
                    (Some(Edge::Rising), _) => ContactKind::Rising {
                        memory: self.edge_memory(s),
                    },
                    (Some(Edge::Falling), _) => ContactKind::Falling {
                        memory: self.edge_memory(s),
                    },
                };
                Element::Contact { var, kind }
            }
            S::Compare(c) => {
                let (a, b) = self.numeric_pair(&c.a, &c.b, at, s, "a comparison")?;
                Element::Compare { op: c.op, a, b }
            }
            S::Or(bs) => Element::Or(self.branches(bs, &key("or"), Place::Or, s)?),
            S::Branch(bs) => {
                Element::Branch(self.branches(bs, &key("branch"), Place::Branch, s)?)
            }
            S::Coil { var, negated } => {
                let var = self.writable(var, &key("coil"), s, "a coil", Some(Type::Bool))?;
                Element::Coil {
                    var,
                    negated: *negated,
                }
            }
            S::Set(v) => {
                Element::Set(self.writable(v, &key("set"), s, "a set coil", Some(Type::Bool))?)
            }
            S::Reset(v) => Element::Reset(self.writable(
                v,
                &key("reset"),
                s,
                "a reset coil",
                Some(Type::Bool),
            )?),
            S::Timer(t) => {
                let instance = self.instance(&t.instance, &key(t.kind.name()), s, t.kind.fb())?;
                let pt = self.operand_of(&t.pt, &key("pt"), s, Type::Time, "a timer's PT")?;
                Element::Timer {
                    kind: t.kind,
                    instance,
                    pt,
                }
            }
            S::Counter(c) if !c.down => {
                let instance = self.instance(&c.instance, &key("ctu"), s, FbKind::Ctu)?;
                let pv = self.operand_of(&c.pv, &key("pv"), s, Type::Int, "a counter's PV")?;
                let reset =
                    self.operand_of(&c.aux, &key("reset"), s, Type::Bool, "a counter's reset")?;
                Element::Ctu {
                    instance,
                    pv,
                    reset,
                }
            }
            S::Counter(c) => {
                let instance = self.instance(&c.instance, &key("ctd"), s, FbKind::Ctd)?;
                let pv = self.operand_of(&c.pv, &key("pv"), s, Type::Int, "a counter's PV")?;
                let load =
                    self.operand_of(&c.aux, &key("load"), s, Type::Bool, "a counter's load")?;
                Element::Ctd { instance, pv, load }
            }
            S::Bistable(b) => {
                let name = match b.kind {
                    BistableKind::SetDominant => "sr",
                    BistableKind::ResetDominant => "rs",
                };
                let instance = self.instance(&b.instance, &key(name), s, b.kind.fb())?;
                let reset =
                    self.operand_of(&b.reset, &key("reset"), s, Type::Bool, "a bistable's reset")?;
                Element::Bistable {
                    kind: b.kind,
                    instance,
                    reset,
                }
            }
            S::Trigger { kind, instance } => {
                let name = match kind {
                    TriggerKind::Rising => "r_trig",
                    TriggerKind::Falling => "f_trig",
                };
                let instance = self.instance(instance, &key(name), s, kind.fb())?;
                Element::Trigger {
                    kind: *kind,
                    instance,
                }
            }
            S::Ctud(c) => {
                let instance = self.instance(&c.instance, &key("ctud"), s, FbKind::Ctud)?;
                let pin = |o, k, what| self.operand_of(o, &key(k), s, Type::Bool, what);
                let cd = pin(&c.cd, "cd", "a counter's CD")?;
                let reset = pin(&c.reset, "reset", "a counter's reset")?;
                let load = pin(&c.load, "load", "a counter's load")?;
                let pv = self.operand_of(&c.pv, &key("pv"), s, Type::Int, "a counter's PV")?;
                Element::Ctud {
                    instance,
                    inputs: Box::new(CtudInputs {
                        cd,
                        reset,
                        load,
                        pv,
                    }),
                }
            }
            S::Move(m) => {
                let to = self.writable(&m.to, &key("to"), s, "a move", None)?;
                let ty = self.vars[to.index()].ty;
                let from = self.operand_of(&m.from, &key("move"), s, ty, "a move")?;
                Element::Move { from, to }
            }
            S::Arith(x) => self.arith(x.op, &x.a, &x.b, &x.out, at, s)?,
            S::Function(c) => self.function(c, at, s)?,
            S::Jmp(label) => {
                let target = *self.labels[s.pou.index()]
                    .get(label.as_str())
                    .ok_or_else(|| {
                        err(
                            "jmp",
                            label.origin,
                            Invalid::UndefinedLabel {
                                label: label.value.to_string(),
                                pou: self.pous[s.pou.index()].name.clone(),
                            },
                        )
                    })?;
                Element::Jmp {
                    label: label.value.to_string(),
                    target,
                }
            }
            S::Ret => Element::Ret,
            S::RangeFault => Element::RangeFault,
            S::End => {
                if s.pou.index() != 0 {
                    return Err(err(
                        "end",
                        e.origin,
                        Invalid::Misplaced {
                            what: "`end`",
                            place: "in a subroutine (use `ret`)",
                        },
                    ));
                }
                Element::End
            }
            S::Next => match s.partner {
                Some(head) => Element::Next { head },
                None => return Ok(None),
            },
            S::Call(name) => {
                let is_interrupt =
                    |p: &super::PouDraft| p.kind == PouKind::Interrupt && p.name == name.as_str();
                if self.pous.iter().any(is_interrupt) {
                    return Err(err(
                        "call",
                        name.origin,
                        Invalid::Misplaced {
                            what: "a call of an interrupt routine",
                            place: "(nothing calls an interrupt routine: it runs when its event occurs)",
                        },
                    ));
                }
                // A user function block instance the POU sees (its own, else a global one) is
                // called as its POU (IEC 61131-3 6.6.3: an ST `Inst();` with its inputs set).
                let instance = self.local_instances[s.pou.index()]
                    .get(name.as_str())
                    .or_else(|| self.global_instances.get(name.as_str()))
                    .and_then(|&i| self.instances[i].pou);
                let pou = self
                    .pous
                    .iter()
                    .position(|p| {
                        p.kind == PouKind::Subroutine && p.callable && p.name == name.as_str()
                    })
                    .or(instance.map(|p| p.index()))
                    .ok_or_else(|| {
                        err(
                            "call",
                            name.origin,
                            Invalid::UndefinedSubroutine {
                                name: name.value.to_string(),
                            },
                        )
                    })?;
                Element::Call {
                    pou: self.pous.id(pou),
                }
            }
            S::For(f) => {
                let (name, from, to) = (&f.var, &f.from, &f.to);
                let fp = key("for");
                let var = self.writable(name, &fp.key("var"), s, "a FOR", None)?;
                let ty = self.vars[var.index()].ty;
                if !ty.is_int() {
                    return Err(LoadError::invalid(
                        rid,
                        &fp.with(".var"),
                        Invalid::Type {
                            what: "a FOR index",
                            expected: "an integer (SINT … LINT, USINT … ULINT)".into(),
                            operand: self.vars[var.index()].name.clone(),
                            found: ty.to_string(),
                        },
                    )
                    .at(name.origin));
                }
                let from = self.operand_of(from, &fp.key("from"), s, ty, "a FOR bound")?;
                let to = self.operand_of(to, &fp.key("to"), s, ty, "a FOR bound")?;
                let Some(next) = s.partner else {
                    return Ok(None);
                };
                Element::For {
                    var,
                    bounds: Box::new(ForBounds { from, to }),
                    next,
                }
            }
        }))
    }

    fn arith(
        &mut self,
        op: ArithOp,
        a: &syntax::Operand,
        b: &syntax::Operand,
        name: &syntax::Name,
        at: &At,
        s: &Scope,
    ) -> Result<Element> {
        let out = self.writable(name, &at.key("out"), s, "an arithmetic box", None)?;
        let ty = self.vars[out.index()].ty;
        if !op.accepts(ty) {
            return Err(LoadError::invalid(
                Some(s.rung_id),
                &at.with(".out"),
                Invalid::Type {
                    what: "this arithmetic box",
                    expected: op.expected().into(),
                    operand: self.vars[out.index()].name.clone(),
                    found: ty.to_string(),
                },
            )
            .at(name.origin));
        }
        let inp = at.key("in");
        let a = self.operand_of(a, &inp.index(0), s, ty, "an arithmetic box")?;
        let b = self.operand_of(b, &inp.index(1), s, ty, "an arithmetic box")?;
        Ok(Element::Arith { op, a, b, out })
    }

    /// A standard function box: the output is writable, the arguments typed by the function's
    /// rule (`Function::types`) from their own types and the output's.
    fn function(&mut self, c: &syntax::FunctionCall, at: &At, s: &Scope) -> Result<Element> {
        let what = "a function box";
        let out = self.writable(&c.out, &at.key("out"), s, what, None)?;
        let out_ty = self.vars[out.index()].ty;
        let inp = at.key("in");
        let mut untyped = Vec::with_capacity(c.args.len());
        for (i, a) in c.args.iter().enumerate() {
            untyped.push(self.untyped(a, &inp.index(i), s)?);
        }
        let own: Vec<(Option<Type>, bool)> = untyped
            .iter()
            .map(|u| (u.ty(), super::operand::default_type(u) == Type::Real))
            .collect();
        let typing = c.func.types(&own, Some(out_ty)).map_err(|m| {
            let (path, origin, operand) = match m.arg {
                Some(i) => (inp.index(i), c.args[i].origin, c.args[i].value.display()),
                None => (at.key("out"), c.out.origin, c.out.value.to_string()),
            };
            LoadError::invalid(
                Some(s.rung_id),
                &path.with(""),
                Invalid::Type {
                    what: "this function's operand",
                    expected: format!("{} ({})", m.expected, c.func.name()),
                    operand,
                    found: m.found.to_string(),
                },
            )
            .at(origin)
        })?;
        let mut args = Vec::with_capacity(c.args.len());
        for (i, (a, ty)) in c.args.iter().zip(&typing.args).enumerate() {
            args.push(self.operand_of(a, &inp.index(i), s, *ty, what)?);
        }
        Ok(Element::Function {
            func: c.func,
            args: args.into_boxed_slice(),
            out,
        })
    }

    /// The hidden memory of the next edge contact of the rung in scope (made now, or taken
    /// from those made in advance for it).
    pub(super) fn edge_memory(&mut self, s: &Scope) -> VarId {
        self.edge_count += 1;
        if let Some(next) = self.edge_reserved.as_mut() {
            return next.next_id();
        }
        self.vars.push(edge_var(s.rung_id, self.edge_count))
    }
}

/// The hidden memory of edge contact `k` (from 1) of rung `rung_id`.
pub(super) fn edge_var(rung_id: &str, k: u32) -> Var {
    Var {
        name: format!("{rung_id}:edge{k}"),
        ty: Type::Bool,
        class: VarClass::Memory,
        init: Value::Bool(false),
        scope: None,
        hidden: true,
    }
}
