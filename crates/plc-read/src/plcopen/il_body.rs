//! IL bodies (TC6 `IL`, IEC 61131-3 Instruction List, 3rd edition 7.2 / 2nd edition 3.2)
//! made executable: the instructions ([`super::il_parse`]) translated into ST statements
//! ([`crate::st::ast`]) and lowered by the ST lowering ([`super::st_lower`]), so that `run`
//! and `c` execute them with the same machinery as ST, LD and FBD.
//!
//! The current result (CR, 7.2.2) is kept as an ST expression built from what was loaded and
//! the operators that followed (`LD a  ADD b  GT 5` is `(a + b) > 5`), typed as matiec's stage 3
//! types it: by what was loaded, the operators' rules, BOOL after a comparison. It becomes a
//! compiler temporary `il__N` (a POU-local variable: IEC names have no `__`) when a later
//! instruction would change what it reads (`ST`, `S`, `R` of a variable it reads, `CAL`, a
//! deferred operand that stores), and at a label where it is used: each such label has one
//! temporary that every jump to it and the fall-through into it assign (matiec's
//! `__IL_DEFVAR`, one CR shared by every path, generate_c_il.cc). Instruction `k` (1-based,
//! deferred operands' instructions included in theirs) of POU `P` is the unit of rungs
//! `P.ilk.1`, `P.ilk.2`, …; label `L` is the rung label `il__L`.
//!
//! The instructions, as matiec's generate_c_il.cc executes them:
//! - `LD x` / `LDN x`: CR := x / NOT x; `ST x` / `STN x`: x := CR / NOT CR (CR unchanged);
//!   `S x` / `R x` of a BOOL: x := TRUE / FALSE when CR is TRUE; `S`/`R` of an instance and
//!   `S1 R1 CLK CU CD PV IN PT inst`: the instance called with that input := CR (an implicit
//!   call, `XXX_CAL_operator`; a BOOL input a call leaves out keeps its last value, as in ST);
//! - `NOT`; `AND ANDN OR ORN XOR XORN ADD SUB MUL DIV MOD GT GE EQ NE LE LT` with an operand
//!   or a deferred operand `OP( … )` (its list evaluated from its own operand, then CR := CR OP
//!   result, `il_expression_c`); `N` negates the operand;
//! - a function name: CR := F(CR, operands…) (`il_function_call_c`: CR the first input);
//!   a function of the project likewise (CR its first input, the operands its next inputs,
//!   then its outputs in declaration order, as matiec binds them), or called formally
//!   `F( EN := e, IN1 := x, OUT => y, ENO => ok )` (`il_formal_funct_call_c`: CR is no input),
//!   CR := its result; either is the ST call of the function ([`super::user_functions`],
//!   EN/ENO as in ST) into a temporary at that instruction, so that a call whose result no
//!   instruction uses is still made, once, where it is written;
//! - `JMP JMPC JMPCN L`, `RET RETC RETCN` (a jump to the body's end), `CAL CALC CALCN
//!   inst(…)`: as ST's jump, RETURN and call statements; none changes CR (stage 3 keeps the
//!   previous instruction's type for them).
//!
//! Invariants: a body is executed whole or not at all. What cannot be executed (a syntax
//! error, an instruction the translation or the lowering does not handle, a CR used where no
//! instruction set it, a jump to a label the body lacks) is a [`Refusal`] naming it and where
//! it is; `run` and `c` then refuse the POU with it. The analysis keeps the interface's
//! stand-in rung (every input read; outputs, locals and externals written).
//!
//! Deliberately not here: analysis per instruction (the interface stands for the body),
//! formal calls of standard functions `LIMIT(MN := …)`, an instruction list as a call
//! argument, user function block calls other than `CAL` (the lowering refuses them), S7-200
//! STL (`crate::stl`).

use super::il_parse::{self, Cond, Instr, Item, Op};
use super::st_body::file_offsets;
use super::st_lower::{self, Lower, Refusal};
use super::st_scope::{Decl, Scope};
use super::textual::{stand_in, Read};
use super::user_functions::FnSig;
use super::xml::{origin, Note, Notes, R};
use crate::st::ast::*;
use plc_diag::Origin;
use plc_model::{Function, Type};
use plc_syntax::{Rung, Var, VarClass};
use roxmltree::Node;
use std::borrow::Cow;
use std::collections::{HashMap, HashSet};

type L<T> = Result<T, Refusal>;

fn refuse<T>(at: usize, what: impl Into<String>) -> L<T> {
    Err(Refusal {
        at,
        what: what.into(),
    })
}

/// The rungs of IL body `node` of POU `pou`: the lowered instructions when `run` or `c` asks
/// ([`Notes::exec`]) and every instruction lowers, otherwise the interface's stand-in rung.
#[allow(clippy::too_many_arguments)]
pub(super) fn rungs(
    node: Node,
    pou: &str,
    scope: &Scope,
    reads: &[&Var<'static>],
    writes: &[&Var<'static>],
    externals: &[String],
    notes: &mut Notes,
) -> R<Vec<Rung<'static>>> {
    let at = origin(node);
    let source = node.document().input_text();
    let texts: Vec<Node> = node
        .descendants()
        .filter(|d| d.is_text() && !d.text().unwrap_or("").trim().is_empty())
        .collect();
    let outcome = match texts.as_slice() {
        [] => Ok((Vec::new(), Vec::new())),
        [t] => {
            let text = t.text().unwrap_or("");
            let map = file_offsets(source, t.range().start, text);
            let place = |off: usize| match &map {
                Some(m) => Origin::at(m.get(off).copied().unwrap_or(t.range().start)),
                None => origin(*t),
            };
            lower(text, pou, scope, map.clone(), origin(*t)).map_err(|r| (place(r.at), r.what))
        }
        [_, second, ..] => Err((
            origin(*second),
            "an IL body split by XHTML markup into several texts".to_owned(),
        )),
    };
    // The analysis: the interface's stand-in (as for an SFC body, [`super::textual`]).
    let reads: Vec<Read> = reads
        .iter()
        .map(|v| Read {
            name: v.name.as_str().to_owned(),
            bool: v.ty.as_str() == "BOOL",
        })
        .collect();
    let (elementary, instances): (Vec<&&Var>, Vec<&&Var>) = writes
        .iter()
        .partition(|v| super::elementary::is_elementary(v.ty.as_str()));
    let written: Vec<String> = elementary
        .iter()
        .map(|v| v.name.as_str().to_owned())
        .chain(externals.iter().cloned())
        .collect();
    let executed = match &outcome {
        Ok(_) => "executed by `run` and `c` as the rungs its instructions are lowered to (docs/plcopen.md, IL bodies)".to_owned(),
        Err((at, what)) => {
            let (l, c) = at.line_column(source).unwrap_or((0, 0));
            format!("not executed by `run` or `c`: {what} at {l}:{c} is not executed yet")
        }
    };
    let mut message = format!(
        "pou {pou}: its IL body is analysed through its interface (inputs read; outputs, locals and externals written) and {executed}"
    );
    if !instances.is_empty() {
        let names: Vec<&str> = instances.iter().map(|v| v.name.as_str()).collect();
        message.push_str(&format!(
            "; the function block instances {} are not written",
            names.join(", ")
        ));
    }
    let rung = stand_in(format!("{pou}.body"), at, &reads, &written);
    notes.push(Note {
        origin: at,
        message,
    });
    match outcome {
        Err(why) => notes.skipped.push(plc_syntax::SkippedBody {
            pou: pou.to_owned(),
            language: "IL".into(),
            origin: at,
            why: Some(why),
        }),
        Ok((rungs, vars)) if notes.exec => {
            notes
                .ld_vars
                .extend(vars.into_iter().map(|v| (pou.to_owned(), v)));
            return Ok(rungs);
        }
        Ok(_) => {}
    }
    Ok(rung.into_iter().collect())
}

/// IL text `text` lowered to rungs and the temporaries they use (the CR's and the lowering's).
fn lower(
    text: &str,
    pou: &str,
    scope: &Scope,
    map: Option<Vec<usize>>,
    base: Origin,
) -> L<(Vec<Rung<'static>>, Vec<Var<'static>>)> {
    let items = il_parse::parse(text).map_err(|e| Refusal {
        at: e.at,
        what: format!("IL syntax error ({})", e.message),
    })?;
    let mut tr = Tr {
        scope: scope.clone(),
        temps: Vec::new(),
        out: Vec::new(),
        cr: Cr::None("no instruction before it sets it"),
        reach: true,
        labels: HashMap::new(),
        live: HashMap::new(),
        k: 0,
    };
    for (i, it) in items.iter().enumerate() {
        if let Item::Label(l, at) = it {
            if tr.live.contains_key(l) {
                return refuse(*at, format!("a second label `{l}`"));
            }
            let live = live_from(&items, i + 1, &mut HashSet::new());
            tr.live.insert(l.clone(), live);
        }
    }
    tr.items(&items, true)?;
    // matiec keeps IL's current result in a variable of the operand's type, so each
    // instruction's arithmetic is cut to that type (no `int` promotion across instructions).
    tr.scope.int_arithmetic_in_dint = false;
    let mut lw = Lower::new(&tr.scope, pou);
    lw.text(map, base);
    // A BOOL input a call leaves out keeps its value in a variable of its own, as in ST
    // (`CALC C1(CU := …, PV := …)` without R). Only the calls (CALC and CALCN in an IF): not
    // what reads an input, as `LD T1.PT`, which stays refused.
    let stmts: Vec<Statement> = (tr.out.iter())
        .filter_map(|p| match p {
            Piece::Stmt(_, s) if matches!(s.kind, Stmt::Call { .. } | Stmt::If { .. }) => {
                Some((**s).clone())
            }
            _ => None,
        })
        .collect();
    lw.prepare(&stmts);
    let mut unit = 0;
    for p in &tr.out {
        match p {
            Piece::Stmt(k, s) => {
                if *k != unit {
                    unit = *k;
                    lw.unit("il", *k);
                }
                lw.more(s)?;
            }
            Piece::Jump(k, at, cond, l) => {
                if *k != unit {
                    unit = *k;
                    lw.unit("il", *k);
                }
                lw.jump(*at, cond.as_ref(), l)?;
            }
            Piece::Label(l) => lw.label_next(l),
        }
    }
    lw.finish();
    let mut vars = tr.vars(base);
    vars.append(&mut lw.vars);
    Ok((lw.rungs, vars))
}

/// Whether the CR is used, from item `j` on, before an instruction sets it.
fn live_from(items: &[Item], mut j: usize, seen: &mut HashSet<String>) -> bool {
    while let Some(it) = items.get(j) {
        j += 1;
        let Item::Instr(i) = it else { continue };
        match &i.op {
            Op::Ld { .. } | Op::FormalCall { .. } | Op::Ret(Cond::Always) => return false,
            Op::Cal {
                cond: Cond::Always, ..
            } => {}
            Op::Jmp(Cond::Always, l) => {
                if !seen.insert(l.clone()) {
                    return false;
                }
                return match items
                    .iter()
                    .position(|x| matches!(x, Item::Label(m, _) if m == l))
                {
                    Some(p) => live_from(items, p + 1, seen),
                    None => false,
                };
            }
            _ => return true,
        }
    }
    false
}

/// The current result: an expression, or none (and why).
#[derive(Clone, Debug)]
enum Cr {
    None(&'static str),
    Val(Expr),
}

/// What the translation produces, in order: statements of instruction `k`, jumps (`k`, the
/// offset, the condition, the label) and labels.
enum Piece {
    Stmt(usize, Box<Statement>),
    Jump(usize, usize, Option<Expr>, String),
    Label(String),
}

struct Tr {
    /// The POU's names and the CR temporaries.
    scope: Scope,
    temps: Vec<(String, Type)>,
    out: Vec<Piece>,
    cr: Cr,
    /// Whether the instruction being translated can be reached by falling through.
    reach: bool,
    /// Each live label's CR temporary, once a path into it has set it.
    labels: HashMap<String, (String, Type)>,
    /// Each label, and whether the CR is used after it.
    live: HashMap<String, bool>,
    /// The current top-level instruction (1-based).
    k: usize,
}

fn var(name: &str, at: usize) -> Expr {
    Expr::Var(Place {
        base: name.to_owned(),
        base_at: at,
        selectors: Vec::new(),
    })
}

fn not(e: Expr) -> Expr {
    Expr::Unary(UnaryOp::Not, Box::new(e))
}

fn is_temp(e: &Expr) -> bool {
    matches!(e, Expr::Var(p) if p.base.starts_with("il__") && p.selectors.is_empty())
}

/// The first names of the variables `e` reads (lower case).
fn reads(e: &Expr, out: &mut Vec<String>) {
    match e {
        Expr::Literal(_) => {}
        Expr::Var(p) => {
            out.push(p.base.to_ascii_lowercase());
            for s in &p.selectors {
                if let Selector::Index(ix) = s {
                    ix.iter().for_each(|x| reads(x, out));
                }
            }
        }
        Expr::Unary(_, x) => reads(x, out),
        Expr::Binary(_, a, b) => {
            reads(a, out);
            reads(b, out);
        }
        Expr::Call { args, .. } => {
            for a in args {
                if let Arg::Input { value, .. } = a {
                    reads(value, out);
                }
            }
        }
    }
}

impl Tr {
    /// Whether instructions `items` write anything (so that a CR kept as an expression must be
    /// computed before them): a call of the project's function may write its outputs' targets
    /// and globals.
    fn stores(&self, items: &[Item]) -> bool {
        items.iter().any(|it| match it {
            Item::Label(..) => false,
            Item::Instr(i) => {
                let pure = match &i.op {
                    Op::Ld { .. } | Op::Not | Op::Binary { .. } => true,
                    Op::Function { name, .. } => self.scope.func(name).is_none(),
                    _ => false,
                };
                !pure || i.nested.as_deref().is_some_and(|n| self.stores(n))
            }
        })
    }

    fn stmt(&mut self, at: usize, kind: Stmt) {
        self.out
            .push(Piece::Stmt(self.k, Box::new(Statement { at, kind })));
    }

    fn temp(&mut self, ty: Type, at: usize) -> Expr {
        let n = format!("il__{}", self.temps.len() + 1);
        self.scope.declare(&n, &ty.to_string());
        self.temps.push((n.clone(), ty));
        var(&n, at)
    }

    fn vars(&self, at: Origin) -> Vec<Var<'static>> {
        let loc = |s: String| plc_syntax::Located {
            value: Cow::Owned(s),
            origin: at,
        };
        self.temps
            .iter()
            .map(|(n, t)| Var {
                origin: at,
                name: loc(n.clone()),
                ty: loc(t.to_string()),
                class: plc_syntax::Located {
                    value: VarClass::Memory,
                    origin: at,
                },
                init: None,
                problem: None,
            })
            .collect()
    }

    /// The CR, for instruction `i` that uses it.
    fn cr(&self, i: &Instr) -> L<Expr> {
        match &self.cr {
            Cr::Val(e) => Ok(e.clone()),
            Cr::None(why) => refuse(
                i.at,
                format!("`{}` without a current result ({why})", i.name),
            ),
        }
    }

    /// The CR computed into a temporary now, unless it is a literal or a temporary already
    /// (or, `only`, unless it reads none of the names `only` gives).
    fn settle(&mut self, at: usize, only: Option<&str>) -> L<()> {
        let Cr::Val(e) = &self.cr else { return Ok(()) };
        if is_temp(e) || matches!(e, Expr::Literal(_)) {
            return Ok(());
        }
        let mut r = Vec::new();
        reads(e, &mut r);
        let r: Vec<String> = r.into_iter().filter(|n| !n.starts_with("il__")).collect();
        if r.is_empty() {
            return Ok(());
        }
        if let Some(w) = only {
            if !r.iter().any(|n| n.eq_ignore_ascii_case(w)) {
                return Ok(());
            }
        }
        let e = e.clone();
        let Some(ty) = self.type_of(&e) else {
            return refuse(
                at,
                "a current result whose type the translation cannot tell",
            );
        };
        let t = self.temp(ty, at);
        let Expr::Var(p) = &t else { unreachable!() };
        self.stmt(
            at,
            Stmt::Assign {
                target: p.clone(),
                value: e,
            },
        );
        self.cr = Cr::Val(t);
        Ok(())
    }

    /// Before a jump to, or the fall-through into, label `l` whose CR is used: the CR into
    /// the label's temporary.
    fn enter_label(&mut self, at: usize, l: &str) -> L<()> {
        if !self.live.get(l).copied().unwrap_or(false) {
            return Ok(());
        }
        let e = match &self.cr {
            Cr::Val(e) => e.clone(),
            Cr::None(why) => {
                return refuse(
                    at,
                    format!("the current result at label `{l}`, used after it ({why})"),
                )
            }
        };
        // An untyped literal takes the type another path gave the label.
        let Some(ty) = self.type_of(&e).or(self.labels.get(l).map(|x| x.1)) else {
            return refuse(
                at,
                format!("the current result at label `{l}`: its type cannot be told (an untyped literal?)"),
            );
        };
        let name = match self.labels.get(l) {
            Some((n, t)) if *t == ty => n.clone(),
            Some((_, t)) => {
                return refuse(
                    at,
                    format!("the current result at label `{l}`: {ty} on this path, {t} on another"),
                )
            }
            None => {
                let Expr::Var(p) = self.temp(ty, at) else {
                    unreachable!()
                };
                self.labels.insert(l.to_owned(), (p.base.clone(), ty));
                p.base
            }
        };
        if !matches!(&e, Expr::Var(p) if p.base == name) {
            self.stmt(
                at,
                Stmt::Assign {
                    target: Place {
                        base: name.clone(),
                        base_at: at,
                        selectors: Vec::new(),
                    },
                    value: e,
                },
            );
        }
        self.cr = Cr::Val(var(&name, at));
        Ok(())
    }

    fn items(&mut self, items: &[Item], top: bool) -> L<()> {
        for it in items {
            match it {
                Item::Label(l, at) => {
                    if self.reach {
                        self.enter_label(*at, l)?;
                    }
                    self.out.push(Piece::Label(format!("il__{l}")));
                    self.reach = true;
                    self.cr = if !self.live[l] {
                        Cr::None("after a label")
                    } else {
                        match self.labels.get(l) {
                            Some((n, _)) => Cr::Val(var(n, *at)),
                            None => Cr::None("a label reached only by later jumps"),
                        }
                    };
                }
                Item::Instr(i) => {
                    if top {
                        self.k += 1;
                    }
                    self.instr(i, top)?;
                }
            }
        }
        Ok(())
    }

    fn place_of(i: &Instr) -> L<Place> {
        match &i.operand {
            Some(Expr::Var(p)) => Ok(p.clone()),
            _ => refuse(i.at, format!("`{}` of a literal", i.name)),
        }
    }

    fn cond_expr(&self, i: &Instr, c: Cond) -> L<Option<Expr>> {
        Ok(match c {
            Cond::Always => None,
            Cond::IfTrue => Some(self.cr(i)?),
            Cond::IfFalse => Some(not(self.cr(i)?)),
        })
    }

    /// `kind` as a statement, under the condition `c` of the CR.
    fn guarded(&mut self, i: &Instr, c: Cond, kind: Stmt) -> L<()> {
        match self.cond_expr(i, c)? {
            None => self.stmt(i.at, kind),
            Some(e) => self.stmt(
                i.at,
                Stmt::If {
                    arms: vec![(e, vec![Statement { at: i.at, kind }])],
                    otherwise: Vec::new(),
                },
            ),
        }
        Ok(())
    }

    fn instr(&mut self, i: &Instr, top: bool) -> L<()> {
        let at = i.at;
        match &i.op {
            Op::Ld { neg } => {
                let e = i.operand.clone().unwrap_or(Expr::Literal(String::new()));
                self.cr = Cr::Val(if *neg { not(e) } else { e });
            }
            Op::St { neg } => {
                let target = Self::place_of(i)?;
                self.cr(i)?;
                self.settle(at, Some(&target.base))?;
                let cr = self.cr(i)?;
                if let (Some(a), Some(b)) =
                    (self.type_of(&cr), self.type_of(&Expr::Var(target.clone())))
                {
                    if a != b {
                        return refuse(
                            at,
                            format!(
                                "`{}` of a {a} current result into {b} `{}`",
                                i.name, target.base
                            ),
                        );
                    }
                }
                let value = if *neg { not(cr.clone()) } else { cr.clone() };
                self.stmt(
                    at,
                    Stmt::Assign {
                        target: target.clone(),
                        value,
                    },
                );
                // The stored variable holds the CR now: later uses read it, not the expression.
                let elementary = matches!(
                    self.scope.find(&path(&target)),
                    Ok(Some((Decl::Elementary { .. }, true)))
                );
                if !*neg
                    && elementary
                    && !is_temp(&cr)
                    && !matches!(cr, Expr::Literal(_) | Expr::Var(_))
                {
                    self.cr = Cr::Val(Expr::Var(target));
                }
            }
            Op::Set | Op::Reset => {
                let target = Self::place_of(i)?;
                let instance = matches!(
                    self.scope.find(&path(&target)),
                    Ok(Some((Decl::Instance { .. }, true)))
                );
                let cr = self.cr(i)?;
                if instance {
                    // matiec: `S inst` is the call of `inst` with its input S := CR.
                    self.settle(at, None)?;
                    let cr = self.cr(i)?;
                    let input = if matches!(i.op, Op::Set) { "S" } else { "R" };
                    self.stmt(at, call(target, input, cr));
                } else {
                    let _ = cr;
                    self.settle(at, Some(&target.base))?;
                    let value = Expr::Literal(
                        if matches!(i.op, Op::Set) {
                            "TRUE"
                        } else {
                            "FALSE"
                        }
                        .into(),
                    );
                    self.guarded(i, Cond::IfTrue, Stmt::Assign { target, value })?;
                }
            }
            Op::FbInput(input) => {
                let target = Self::place_of(i)?;
                self.cr(i)?;
                self.settle(at, None)?;
                let cr = self.cr(i)?;
                self.stmt(at, call(target, input, cr));
            }
            Op::Not => {
                let cr = self.cr(i)?;
                self.cr = Cr::Val(not(cr));
            }
            Op::Binary { op, neg } => {
                let left = self.cr(i)?;
                let mut right = match &i.nested {
                    None => i.operand.clone().unwrap_or(Expr::Literal(String::new())),
                    Some(list) => {
                        if self.stores(list) {
                            self.settle(at, None)?;
                        }
                        let outer = self.cr.clone();
                        self.cr = match &i.operand {
                            Some(e) => Cr::Val(e.clone()),
                            None => Cr::None("a deferred operand's list starts without one"),
                        };
                        self.items(list, false)?;
                        let inner = match &self.cr {
                            Cr::Val(e) => e.clone(),
                            Cr::None(why) => {
                                return refuse(
                                    at,
                                    format!(
                                        "`{}( … )` whose list leaves no current result ({why})",
                                        i.name
                                    ),
                                )
                            }
                        };
                        self.cr = outer;
                        inner
                    }
                };
                let left = if i.nested.is_some() {
                    self.cr(i)?
                } else {
                    left
                };
                if *neg {
                    right = not(right);
                }
                self.cr = Cr::Val(Expr::Binary(*op, Box::new(left), Box::new(right)));
            }
            Op::FormalCall { name, args } => {
                let Some(sig) = self.scope.func(name).cloned() else {
                    return refuse(
                        at,
                        format!("the formal call of function `{name}` in IL (only the project's functions are called formally in IL)"),
                    );
                };
                if args
                    .iter()
                    .any(|a| matches!(a, Arg::Input { name: None, .. }))
                {
                    return refuse(
                        at,
                        format!("an informal argument in the formal call of function `{name}` (IEC 61131-3 7.2.3: `F( … )` in IL takes formal arguments)"),
                    );
                }
                self.user_call(i, name, &sig, args.clone())?;
            }
            Op::Function { name, args } => {
                let cr = self.cr(i)?;
                if let Some(sig) = self.scope.func(name).cloned() {
                    let args = informal(i, &sig, cr, args)?;
                    return self.user_call(i, name, &sig, args);
                }
                let mut all = vec![Arg::Input {
                    name: None,
                    value: cr,
                }];
                all.extend(args.iter().map(|a| Arg::Input {
                    name: None,
                    value: a.clone(),
                }));
                self.cr = Cr::Val(Expr::Call {
                    callee: Place {
                        base: name.clone(),
                        base_at: at,
                        selectors: Vec::new(),
                    },
                    args: all,
                });
            }
            Op::Jmp(c, l) => {
                if !top {
                    return refuse(
                        at,
                        format!("`{}` inside a deferred operand's parentheses", i.name),
                    );
                }
                if !self.live.contains_key(l) {
                    return refuse(at, format!("`{} {l}`: the body has no label `{l}`", i.name));
                }
                if *c != Cond::Always {
                    self.cr(i)?;
                }
                self.enter_label(at, l)?;
                let cond = self.cond_expr(i, *c)?;
                self.out
                    .push(Piece::Jump(self.k, at, cond, format!("il__{l}")));
                if *c == Cond::Always {
                    self.reach = false;
                    self.cr = Cr::None("after an unconditional JMP");
                }
            }
            Op::Ret(c) => {
                self.guarded(i, *c, Stmt::Return)?;
                if *c == Cond::Always {
                    self.reach = false;
                    self.cr = Cr::None("after an unconditional RET");
                }
            }
            Op::Cal { cond, fb, args } => {
                self.settle(at, None)?;
                self.guarded(
                    i,
                    *cond,
                    Stmt::Call {
                        callee: fb.clone(),
                        args: args.clone(),
                    },
                )?;
            }
        }
        Ok(())
    }

    /// The call of the project's function `name` (`sig`) with `args`, made at instruction `i`
    /// into a new temporary of its result type, which becomes the CR (matiec's
    /// `__IL_DEFVAR = F(…)`).
    fn user_call(&mut self, i: &Instr, name: &str, sig: &FnSig, args: Vec<Arg>) -> L<()> {
        if let Some(why) = &sig.refused {
            return refuse(
                i.at,
                format!(
                    "the call of function `{}`, which is not executed: {why}",
                    sig.name
                ),
            );
        }
        let Some(ty) = Type::parse(&sig.ret).filter(|t| !matches!(t, Type::Fb(_))) else {
            return refuse(
                i.at,
                format!("the call of function `{}` of type {}", sig.name, sig.ret),
            );
        };
        let t = self.temp(ty, i.at);
        let Expr::Var(target) = &t else {
            unreachable!()
        };
        let value = Expr::Call {
            callee: Place {
                base: name.to_owned(),
                base_at: i.at,
                selectors: Vec::new(),
            },
            args,
        };
        self.stmt(
            i.at,
            Stmt::Assign {
                target: target.clone(),
                value,
            },
        );
        self.cr = Cr::Val(t);
        Ok(())
    }

    /// The type of `e` as matiec's stage 3 gives it, when the translation can tell.
    fn type_of(&self, e: &Expr) -> Option<Type> {
        match e {
            Expr::Literal(s) => {
                let u = s.to_ascii_uppercase();
                if u == "TRUE" || u == "FALSE" {
                    Some(Type::Bool)
                } else if plc_syntax::is_time_literal(s) {
                    Some(Type::Time)
                } else {
                    let (prefix, _) = s.split_once('#')?;
                    Type::parse(&prefix.to_ascii_uppercase()).filter(|t| !matches!(t, Type::Fb(_)))
                }
            }
            Expr::Var(p) => match self.scope.find(&path(p)).ok()?? {
                (Decl::Elementary { ty, .. }, true) => Type::parse(ty),
                (Decl::Instance { name, ty, .. }, false) => {
                    st_lower::field_type(ty, &path(p)[name.len() + 1..].to_ascii_uppercase())
                }
                _ => None,
            },
            Expr::Unary(_, x) => self.type_of(x),
            Expr::Binary(op, a, b) => match op {
                BinaryOp::Lt
                | BinaryOp::Gt
                | BinaryOp::Le
                | BinaryOp::Ge
                | BinaryOp::Eq
                | BinaryOp::Ne => Some(Type::Bool),
                _ => self.type_of(a).or_else(|| self.type_of(b)),
            },
            Expr::Call { callee, args } => {
                let vals: Vec<&Expr> = args
                    .iter()
                    .filter_map(|a| match a {
                        Arg::Input { value, .. } => Some(value),
                        Arg::Output { .. } => None,
                    })
                    .collect();
                let name = callee.base.to_ascii_uppercase();
                let any = |from: usize| vals.iter().skip(from).find_map(|v| self.type_of(v));
                match name.as_str() {
                    "MAX" | "MIN" | "LIMIT" | "MOVE" => any(0),
                    "SEL" | "MUX" => any(1),
                    _ => {
                        let f = Function::parse(&name)?;
                        let own: Vec<(Option<Type>, bool)> = vals
                            .iter()
                            .map(|v| {
                                (
                                    self.type_of(v),
                                    matches!(v, Expr::Literal(l) if l.contains('.')),
                                )
                            })
                            .collect();
                        f.types(&own, None).ok().map(|t| t.out)
                    }
                }
            }
        }
    }
}

/// The arguments of the informal call of the project's function `sig` at instruction `i`: the
/// CR `cr` its first input, the operands `ops` its next inputs, then its outputs, in
/// declaration order (matiec's `il_function_call_c`: the first parameter that is not EN or ENO
/// takes the CR, the operands the parameters that follow).
fn informal(i: &Instr, sig: &FnSig, cr: Expr, ops: &[Expr]) -> L<Vec<Arg>> {
    let Some((first, _)) = sig.inputs.first() else {
        return refuse(
            i.at,
            format!(
                "`{}` as an IL operator: function `{}` has no input to take the current result",
                i.name, sig.name
            ),
        );
    };
    let mut args = vec![Arg::Input {
        name: Some(first.clone()),
        value: cr,
    }];
    for (k, op) in ops.iter().enumerate() {
        if let Some((pin, _)) = sig.inputs.get(k + 1) {
            args.push(Arg::Input {
                name: Some(pin.clone()),
                value: op.clone(),
            });
            continue;
        }
        let Some((pin, _)) = sig.outputs.get(k + 1 - sig.inputs.len()) else {
            return refuse(
                i.at,
                format!(
                    "{} operands of `{}`: function `{}` takes {} at most (its inputs after the current result, then its outputs)",
                    ops.len(),
                    i.name,
                    sig.name,
                    sig.inputs.len() - 1 + sig.outputs.len()
                ),
            );
        };
        let Expr::Var(target) = op else {
            return refuse(
                i.at,
                format!(
                    "operand {} of `{}` goes to output `{pin}` of function `{}`, and is not a variable",
                    k + 1,
                    i.name,
                    sig.name
                ),
            );
        };
        args.push(Arg::Output {
            name: pin.clone(),
            target: target.clone(),
        });
    }
    Ok(args)
}

/// `a.b.c` of a place of fields.
fn path(p: &Place) -> String {
    let mut s = p.base.clone();
    for sel in &p.selectors {
        if let Selector::Field(f) = sel {
            s.push('.');
            s.push_str(f);
        }
    }
    s
}

/// The call of instance `inst` with its input `input` := `value`.
fn call(inst: Place, input: &str, value: Expr) -> Stmt {
    Stmt::Call {
        callee: inst,
        args: vec![Arg::Input {
            name: Some(input.to_owned()),
            value,
        }],
    }
}
