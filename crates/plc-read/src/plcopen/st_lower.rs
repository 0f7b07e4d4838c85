//! ST bodies made executable: each statement of an ST body (IEC 61131-3, 3rd edition, 7.3.3,
//! as matiec compiles it) LOWERED to ladder rungs of the syntax's vocabulary
//! ([`plc_syntax::ElementKind`]), so that `run` (sequential and parallel) and `c` execute it
//! with the executor's own semantics (integer overflow wraps, an integer DIV or MOD by zero
//! gives 0 and a `div-by-zero` fault, loops are bounded by the loop cap: docs/scan.md).
//!
//! Statement `k` (1-based, top level, text order) of POU `P` becomes the rungs `P.stk.1`,
//! `P.stk.2`, … (a nested statement's rungs belong to its top-level statement), each located
//! at the statement. Compiler temporaries are POU-local variables named `st__N` (`N` from 1)
//! and one never-written BOOL `st__false`: IEC 61131-3 identifiers have no double `_`, so they
//! cannot clash with a user's name. Labels are `st__LN`.
//!
//! The lowering, clause by clause:
//! - expressions (7.3.2): a BOOL expression is a series of conditions — a BOOL variable a
//!   contact, `NOT` a negated contact (or the condition computed into a temporary and negated),
//!   `AND` a series, `OR` an `or`, `XOR` and `=`/`<>` of BOOLs two branches, a comparison of
//!   other types a `compare`; any other expression is computed into temporaries by `op` boxes
//!   (ADD SUB MUL DIV MOD, EXPT for `**`, SUB from 0 for unary `-`; AND OR XOR NOT of bit
//!   strings as the standard functions) and standard functions (ABS … ATAN, EXPT, SHL … ROR,
//!   MUX, `*_TO_*`, TRUNC; MAX, MIN, LIMIT, SEL and MOVE as compares and moves). A literal takes
//!   the type of the other operand (or of the assignment's target), as IEC and matiec type it.
//! - in a file of matiec's dialect, arithmetic of SINT, INT, USINT and UINT is computed in DINT
//!   and converted to its type where it is assigned or passed, and a comparison compares the
//!   DINT values: matiec's C computes it in `int` (C11 6.3.1.1, the integer promotions).
//!   An argument of a conversion's input takes the input's type (`INT_TO_DINT(297 / 2)` is INT).
//! - `:=`: a BOOL target a coil (TRUE a set, FALSE a reset), another a move, or the last box
//!   of its expression writing the target directly.
//! - IF/ELSIF/ELSE and CASE (values, ranges `a..b`, lists, ELSE; the selector evaluated once
//!   into a temporary, as matiec's `__case_expression`): conditional jumps over labelled rungs.
//! - WHILE, REPEAT: a backward jump; FOR with or without BY: the control variable set, the
//!   final value and the increment evaluated once before the loop into temporaries (IEC
//!   61131-3 7.3.3.4.2), the loop left when `v > end` (BY > 0) or `v < end` (BY <= 0) before
//!   each iteration, `v := v + BY` after it (the rule of matiec's generated C before its 2024
//!   change, which skips a one-trip loop; docs/plcopen.md says so). EXIT jumps past the
//!   innermost loop, CONTINUE to its next test, RETURN is `ret`.
//! - calls of standard function block instances (TON TOF TP, CTU CTD CTUD, R_TRIG F_TRIG,
//!   SR RS) with formal arguments: the instance's box, its first BOOL input as the power, its
//!   other inputs as operands, its outputs `Q => y` moved or coiled after it; `T1.Q`, `T1.ET`,
//!   `C1.CV` … read the instance's fields. Inputs left out keep their last values ([`calls`]:
//!   the inputs the body leaves out or names get a POU variable `st__T1__IN` holding them).
//! - calls of instances of the project's function blocks (`Inst(X := e, Q => y)`): the inputs
//!   moved into the instance's variables, a `call` of its POU, the outputs moved out; its
//!   inputs and outputs as variables (`Inst.X := e`, `y := Inst.Q`) ([`calls`]).
//! - enumeration values (`RED`, `COLOR#RED`, CASE labels) as their integers (the enumeration
//!   is INT, numbered as matiec numbers it: [`super::data_types`]).
//! - `a := b` of two structures: a move per field; of two arrays: a move per element
//!   ([`calls`]).
//! - calls of the project's functions (`y := F(a, b)`, formal, `=>` outputs, EN/ENO, nested,
//!   as statements): the inputs moved into the body's instance of the function's type, a
//!   `call`, the result and outputs moved out ([`functions`], [`super::user_functions`]).
//! - informal arguments of function block calls, bound in declaration order; formal arguments
//!   of standard functions put in their pins' order ([`functions`]).
//! - STRING literals (`'a$'b'`) and variables: moves, comparisons, the string functions and
//!   conversions the model has ([`functions`]).
//! - array elements (IEC 61131-3 6.4.4.5; the reader scalarises an array of an elementary type
//!   into one variable per element, `a[3]`, [`super::data_types`]): constant subscripts (integer
//!   literals, `+ - *` of them, enumeration values) name the element's variable, and one out of
//!   the bounds is refused; other subscripts are evaluated once into temporaries and the access
//!   is a SELECTION, one rung per element it may choose (a compare per variable subscript): a
//!   read moves the chosen element into a temporary that first gets the type's default, a write
//!   moves the value (evaluated once, first) into it. A subscript outside its bounds reads the
//!   default, writes nothing, and records an `index-range` fault on the statement's bounds rung
//!   (a range-fault element, docs/plcopen.md, Arrays).
//!
//! Invariants: a body is lowered whole or not at all; what the lowering does not handle is a
//! [`Refusal`] naming the construct and where it is, and then the body keeps its stand-in
//! rungs and `run`/`c` refuse it with that reason (never a silently skipped statement).
//!
//! Deliberately not here (refused): pragmas `{…}` (matiec pastes their text, often C, into its
//! output), recursive calls of functions, an instance as a value, writes of an instance's
//! outputs, arrays held as one whole variable (of structures, strings, …), a variable
//! subscript as a call's output or a FOR variable, an array as a whole but in `a := b`,
//! dereferences, direct addresses, WSTRINGs.

#[path = "st_calls.rs"]
mod calls;
#[path = "st_functions.rs"]
mod functions;

use super::interface::literal;
use super::st_scope::{Decl, Scope};
use crate::st::ast::*;
use plc_diag::Origin;
use plc_model::{ArithOp, BistableKind, CmpOp, Function, TimerKind, TriggerKind, Type};
use plc_syntax::{
    Arith, Bistable, Compare, Counter, Ctud, Element, ElementKind, FunctionCall, Located, Move,
    Name, Operand, Rung, Scalar, Timer, Var, VarClass,
};
use std::borrow::Cow;

/// Why a body cannot be lowered: the construct and the ST offset where it is.
#[derive(Debug)]
pub(super) struct Refusal {
    pub at: usize,
    pub what: String,
}

type L<T> = Result<T, Refusal>;

fn refuse<T>(at: usize, what: impl Into<String>) -> L<T> {
    Err(Refusal {
        at,
        what: what.into(),
    })
}

/// A value an operand carries: a literal (typed by its use) or a variable with its type.
#[derive(Clone, Debug)]
enum Val {
    Lit(Scalar<'static>),
    Var(String, Type),
}

impl Val {
    fn ty(&self) -> Option<Type> {
        match self {
            Val::Var(_, t) => Some(*t),
            Val::Lit(Scalar::Bool(_)) => Some(Type::Bool),
            Val::Lit(Scalar::Str(s)) if plc_syntax::is_time_literal(s) => Some(Type::Time),
            Val::Lit(Scalar::Str(s)) if s.starts_with('\'') => Some(Type::String),
            Val::Lit(_) => None,
        }
    }
    fn is_real_literal(&self) -> bool {
        matches!(self, Val::Lit(Scalar::Number(n)) if !n.is_i64() && !n.is_u64())
    }
}

/// The lowering of one ST body.
pub(super) struct Lower<'s> {
    scope: &'s Scope,
    pou: String,
    /// The rungs so far.
    pub rungs: Vec<Rung<'static>>,
    /// The temporaries declared so far.
    pub vars: Vec<Var<'static>>,
    temps: usize,
    labels: usize,
    /// The id of the current top-level statement's rungs (`P.st3`) and how many it has.
    stmt: String,
    in_stmt: usize,
    /// Where the current statement is in the file, and its offset in the ST text.
    here: Origin,
    at: usize,
    /// The file offset of each offset of the current ST text (none: all at `base`).
    map: Option<Vec<usize>>,
    base: Origin,
    /// The label the next rung carries.
    pending: Option<String>,
    /// The innermost loops: (label CONTINUE jumps to, label EXIT jumps to).
    loops: Vec<(String, String)>,
    false_var: bool,
    /// The variables holding inputs of standard instances ([`calls`]).
    held: Vec<String>,
    /// The instances the body calls the project's functions through ([`functions`]).
    pub fn_instances: Vec<String>,
}

type Series = Vec<ElementKind<'static>>;

/// What a place denotes ([`Lower::locate`]).
enum Access {
    /// One variable and its type.
    One(String, Type),
    /// An element of an array chosen by subscripts not all constant.
    Select(Select),
}

/// An array element chosen by subscripts not all constant.
struct Select {
    /// The array's name (for messages).
    array: String,
    /// The elements' type.
    ty: Type,
    elements: Vec<super::st_scope::Element>,
    /// Each dimension's bounds.
    dims: Vec<(i64, i64)>,
    /// Each subscript, with its value when it is constant.
    subs: Vec<(Expr, Option<i64>)>,
}

/// A subscript evaluated: its constant, or the variable holding its value.
type Sub = Result<i64, Val>;

/// The most elements a variable subscript may choose among.
const MAX_SELECTED: usize = 4096;

impl<'s> Lower<'s> {
    pub(super) fn new(scope: &'s Scope, pou: &str) -> Lower<'s> {
        Lower {
            scope,
            pou: pou.to_owned(),
            rungs: Vec::new(),
            vars: Vec::new(),
            temps: 0,
            labels: 0,
            stmt: String::new(),
            in_stmt: 0,
            here: Origin::NONE,
            at: 0,
            map: None,
            base: Origin::NONE,
            pending: None,
            loops: Vec::new(),
            false_var: false,
            held: Vec::new(),
            fn_instances: Vec::new(),
        }
    }

    /// The ST text the next statements come from: the file offset of each of its offsets
    /// (`None`: every statement at `base`).
    pub(super) fn text(&mut self, map: Option<Vec<usize>>, base: Origin) {
        self.map = map;
        self.base = base;
    }

    /// Where ST offset `off` of the current text is in the file.
    pub(super) fn origin(&self, off: usize) -> Origin {
        match &self.map {
            Some(m) => m.get(off).map_or(self.base, |&o| Origin::at(o)),
            None => self.base,
        }
    }

    /// Lowers top-level statement `k` (1-based).
    pub(super) fn top(&mut self, k: usize, s: &Statement) -> L<()> {
        self.unit("st", k);
        self.statement(s)
    }

    /// Starts unit `k` (1-based) of kind `tag`: the rungs that follow are `P.<tag>k.1`,
    /// `P.<tag>k.2`, … (an IL instruction is the unit `P.ilk`, [`super::il_body`]).
    pub(super) fn unit(&mut self, tag: &str, k: usize) {
        self.stmt = format!("{}.{tag}{k}", self.pou);
        self.in_stmt = 0;
    }

    /// Lowers one more statement into the current unit.
    pub(super) fn more(&mut self, s: &Statement) -> L<()> {
        self.statement(s)
    }

    /// Puts label `l` (a name no other label of the body has) on the next rung.
    pub(super) fn label_next(&mut self, l: &str) {
        self.place(l.to_owned());
    }

    /// A jump to label `l` at ST offset `at`, when `cond` holds (`None`: always), in the
    /// current unit.
    pub(super) fn jump(&mut self, at: usize, cond: Option<&Expr>, l: &str) -> L<()> {
        self.at = at;
        self.here = self.origin(at);
        let mut ld = match cond {
            Some(c) => self.cond(c)?,
            None => Vec::new(),
        };
        ld.push(self.jmp(l));
        self.emit(ld);
        Ok(())
    }

    // ---- for bodies lowered piece by piece (SFC: super::sfc_lower) ----

    /// Starts unit `id` (its rungs `id.1`, `id.2`, …), located at `here`, its ST text (if
    /// any) given next by [`Lower::text`].
    pub(super) fn unit_at(&mut self, id: String, here: Origin) {
        self.stmt = id;
        self.in_stmt = 0;
        self.here = here;
        self.map = None;
        self.base = here;
    }

    /// Lowers the statements of the current unit (nested, as if one compound statement).
    pub(super) fn lower_statements(&mut self, body: &[Statement]) -> L<()> {
        self.statements(body)
    }

    /// BOOL expression `e` as a series of conditions (rungs for its temporaries emitted first).
    pub(super) fn condition(&mut self, e: &Expr) -> L<Vec<ElementKind<'static>>> {
        self.cond(e)
    }

    /// `e` as an operand of type `ty` (a literal typed by it, a variable, or a temporary).
    pub(super) fn operand_of(&mut self, e: &Expr, ty: Type) -> L<Operand<'static>> {
        let v = self.value(e, Some(ty))?;
        Ok(self.operand(&v))
    }

    /// Emits a rung of the current unit.
    pub(super) fn rung(&mut self, ld: Vec<ElementKind<'static>>) {
        self.emit(ld)
    }

    /// A new label, and placing one on the next rung.
    pub(super) fn new_label(&mut self) -> String {
        self.label()
    }
    pub(super) fn put_label(&mut self, l: String) {
        self.place(l)
    }

    /// A new BOOL temporary.
    pub(super) fn bool_temp_var(&mut self) -> String {
        self.temp(Type::Bool)
    }

    /// Ends the body: a label still pending gets an empty landing rung.
    pub(super) fn finish(&mut self) {
        if self.pending.is_some() {
            self.emit(Vec::new());
        }
    }

    fn name(&self, s: &str) -> Name<'static> {
        Located {
            value: Cow::Owned(s.to_owned()),
            origin: self.here,
        }
    }

    fn operand(&self, v: &Val) -> Operand<'static> {
        Located {
            value: match v {
                Val::Lit(s) => s.clone(),
                Val::Var(n, _) => Scalar::Str(Cow::Owned(n.clone())),
            },
            origin: self.here,
        }
    }

    fn emit(&mut self, ld: Series) {
        self.in_stmt += 1;
        let here = self.here;
        let label = self.pending.take().map(|l| Box::new(self.name(&l)));
        self.rungs.push(Rung {
            origin: here,
            id: self.name(&format!("{}.{}", self.stmt, self.in_stmt)),
            label,
            comment: None,
            ld: ld
                .into_iter()
                .map(|kind| Element { origin: here, kind })
                .collect(),
            ld_origin: here,
            problem: None,
            problem_in_rung: false,
        });
    }

    fn label(&mut self) -> String {
        self.labels += 1;
        format!("st__L{}", self.labels)
    }

    /// Puts `l` on the next rung.
    fn place(&mut self, l: String) {
        if self.pending.is_some() {
            self.emit(Vec::new());
        }
        self.pending = Some(l);
    }

    fn jmp(&self, l: &str) -> ElementKind<'static> {
        ElementKind::Jmp(self.name(l))
    }

    fn declare(&mut self, name: &str, ty: Type) {
        let here = self.here;
        self.vars.push(Var {
            origin: here,
            name: self.name(name),
            ty: self.name(&ty.to_string()),
            class: Located {
                value: VarClass::Memory,
                origin: here,
            },
            init: None,
            problem: None,
        });
    }

    /// Declares `name`, an instance of function block type `ty`.
    fn declare_instance(&mut self, name: &str, ty: &str) {
        self.declare(name, Type::Bool);
        if let Some(v) = self.vars.last_mut() {
            v.ty = Located {
                value: Cow::Owned(ty.to_owned()),
                origin: v.ty.origin,
            };
        }
    }

    fn temp(&mut self, ty: Type) -> String {
        self.temps += 1;
        let n = format!("st__{}", self.temps);
        self.declare(&n, ty);
        n
    }

    /// A contact that never passes power (`negated`: always passes).
    fn constant(&mut self, value: bool) -> ElementKind<'static> {
        if !self.false_var {
            self.false_var = true;
            self.declare("st__false", Type::Bool);
        }
        ElementKind::Contact {
            var: self.name("st__false"),
            negated: value,
            edge: None,
        }
    }

    fn contact(&self, var: &str, negated: bool) -> ElementKind<'static> {
        ElementKind::Contact {
            var: self.name(var),
            negated,
            edge: None,
        }
    }

    // ---- statements ----

    fn statements(&mut self, body: &[Statement]) -> L<()> {
        body.iter().try_for_each(|s| self.statement(s))
    }

    fn statement(&mut self, s: &Statement) -> L<()> {
        self.at = s.at;
        self.here = self.origin(s.at);
        match &s.kind {
            Stmt::Empty => Ok(()),
            Stmt::Pragma { .. } => refuse(
                s.at,
                "a pragma `{…}` (matiec copies its text, C code, into what it generates)",
            ),
            Stmt::Assign { target, value } => self.assign(target, value),
            Stmt::Call { callee, args } => self.fb_call(callee, args),
            Stmt::If { arms, otherwise } => {
                if let ([(cond, body)], []) = (arms.as_slice(), otherwise.as_slice()) {
                    if self.guarded(cond, body)? {
                        return Ok(());
                    }
                }
                let end = self.label();
                for (i, (cond, body)) in arms.iter().enumerate() {
                    let next = self.label();
                    let c = self.cond(cond)?;
                    let mut ld = self.negate(c);
                    ld.push(self.jmp(&next));
                    self.emit(ld);
                    self.statements(body)?;
                    if i + 1 < arms.len() || !otherwise.is_empty() {
                        let j = self.jmp(&end);
                        self.emit(vec![j]);
                    }
                    self.place(next);
                }
                self.statements(otherwise)?;
                self.place(end);
                Ok(())
            }
            Stmt::Case {
                selector,
                arms,
                otherwise,
            } => self.case(s.at, selector, arms, otherwise),
            Stmt::While { cond, body } => {
                let (top, end) = (self.label(), self.label());
                self.place(top.clone());
                let c = self.cond(cond)?;
                let mut ld = self.negate(c);
                ld.push(self.jmp(&end));
                self.emit(ld);
                self.loops.push((top.clone(), end.clone()));
                self.statements(body)?;
                self.loops.pop();
                let j = self.jmp(&top);
                self.emit(vec![j]);
                self.place(end);
                Ok(())
            }
            Stmt::Repeat { body, until } => {
                let (top, test, end) = (self.label(), self.label(), self.label());
                self.place(top.clone());
                self.loops.push((test.clone(), end.clone()));
                self.statements(body)?;
                self.loops.pop();
                self.place(test);
                let c = self.cond(until)?;
                let mut ld = self.negate(c);
                ld.push(self.jmp(&top));
                self.emit(ld);
                self.place(end);
                Ok(())
            }
            Stmt::For {
                var,
                from,
                to,
                by,
                body,
            } => self.for_loop(var, from, to, by.as_ref(), body),
            Stmt::Exit | Stmt::Continue => {
                let exit = matches!(s.kind, Stmt::Exit);
                let Some((cont, end)) = self.loops.last().cloned() else {
                    let what = if exit { "EXIT" } else { "CONTINUE" };
                    return refuse(s.at, format!("{what} outside a loop"));
                };
                let j = self.jmp(if exit { &end } else { &cont });
                self.emit(vec![j]);
                Ok(())
            }
            Stmt::Return => {
                self.emit(vec![ElementKind::Ret]);
                Ok(())
            }
        }
    }

    /// `IF cond THEN body END_IF` whose body lowers to rungs that do nothing without power
    /// (moves, arithmetic and function boxes, set and reset after their conditions; no coil,
    /// no block, no jump or label): the condition put in front of the body's one rung, or
    /// computed once into a temporary whose contact is put in front of each rung, instead of
    /// a jump over the body. Returns false, having emitted nothing, when the body is not so.
    fn guarded(&mut self, cond: &Expr, body: &[Statement]) -> L<bool> {
        // Only assignments are tried (a nested statement has labels, and trying it would
        // lower it twice at every depth).
        if !body
            .iter()
            .all(|s| matches!(s.kind, Stmt::Assign { .. } | Stmt::Empty))
        {
            return Ok(false);
        }
        let (rungs, temps, labels, vars, in_stmt, false_var, held) = (
            self.rungs.len(),
            self.temps,
            self.labels,
            self.vars.len(),
            self.in_stmt,
            self.false_var,
            self.held.len(),
        );
        let pending = self.pending.take();
        // Everything lowering the condition and the body may have changed, as it was.
        let undo = |me: &mut Self, pending: Option<String>| {
            me.rungs.truncate(rungs);
            me.vars.truncate(vars);
            me.held.truncate(held);
            (me.temps, me.labels, me.in_stmt) = (temps, labels, in_stmt);
            me.false_var = false_var;
            me.pending = pending;
        };
        let c = self.cond(cond)?;
        let first = self.rungs.len();
        match self.statements(body) {
            Ok(()) if self.pending.is_none() => {}
            other => {
                undo(self, pending);
                return other.map(|()| false);
            }
        }
        let inert = first < self.rungs.len()
            && self.rungs[first..]
                .iter()
                .all(|r| r.label.is_none() && r.ld.iter().all(|e| inert(&e.kind)));
        if !inert {
            undo(self, pending);
            return Ok(false);
        }
        let guard = if self.rungs.len() - first == 1 {
            c
        } else {
            let flag = self.temp(Type::Bool);
            let mut ld = c;
            ld.push(ElementKind::Coil {
                var: self.name(&flag),
                negated: false,
            });
            let at = self.here;
            let rung = Rung {
                origin: at,
                id: self.name(""),
                label: None,
                comment: None,
                ld: ld
                    .into_iter()
                    .map(|kind| Element { origin: at, kind })
                    .collect(),
                ld_origin: at,
                problem: None,
                problem_in_rung: false,
            };
            self.rungs.insert(first, rung);
            self.in_stmt += 1;
            vec![self.contact(&flag, false)]
        };
        let skip = usize::from(self.rungs.len() - first > 1 && guard.len() == 1);
        for r in &mut self.rungs[first + skip..] {
            let here = r.origin;
            let mut ld: Vec<Element<'static>> = guard
                .iter()
                .map(|k| Element {
                    origin: here,
                    kind: k.clone(),
                })
                .collect();
            ld.append(&mut r.ld);
            r.ld = ld;
        }
        // The rungs from the first of the condition's on, numbered in order again.
        let base = in_stmt + (self.rungs.len() - rungs);
        let mut k = in_stmt;
        for r in &mut self.rungs[rungs..] {
            k += 1;
            r.id.value = Cow::Owned(format!("{}.{k}", self.stmt));
        }
        debug_assert_eq!(k, base);
        self.in_stmt = k;
        if let Some(l) = pending {
            // The statement's first rung carries the label that waited for it.
            let name = Box::new(self.name(&l));
            match self.rungs.get_mut(rungs) {
                Some(r) => r.label = Some(name),
                None => self.pending = Some(l),
            }
        }
        Ok(true)
    }

    fn assign(&mut self, target: &Place, value: &Expr) -> L<()> {
        if self.structure_assign(target.base_at, target, value)? {
            return Ok(());
        }
        if let Access::Select(sel) = self.locate(target)? {
            return self.select_write(sel, value);
        }
        let (name, ty) = self.written(target)?;
        self.assign_to(&name, ty, value)
    }

    /// `name := value` of a variable `name` of type `ty`.
    fn assign_to(&mut self, name: &str, ty: Type, value: &Expr) -> L<()> {
        let name = name.to_owned();
        if ty == Type::Bool {
            match bool_literal(value) {
                Some(true) => self.emit(vec![ElementKind::Set(self.name(&name))]),
                Some(false) => self.emit(vec![ElementKind::Reset(self.name(&name))]),
                None => {
                    let mut ld = self.cond(value)?;
                    ld.push(ElementKind::Coil {
                        var: self.name(&name),
                        negated: false,
                    });
                    self.emit(ld);
                }
            }
            return Ok(());
        }
        let v = self.value_into(value, Some(ty), Some(&name))?;
        if let Some(v) = v {
            let m = ElementKind::Move(Box::new(Move {
                from: self.operand(&v),
                to: self.name(&name),
            }));
            self.emit(vec![m]);
        }
        Ok(())
    }

    fn case(
        &mut self,
        at: usize,
        selector: &Expr,
        arms: &[(Vec<CaseLabel>, Vec<Statement>)],
        otherwise: &[Statement],
    ) -> L<()> {
        let v = self.value(selector, None)?;
        let Some(ty) = v.ty() else {
            return refuse(at, "a CASE on a literal");
        };
        if ty == Type::Bool {
            return refuse(at, "a CASE on a BOOL");
        }
        // The selector once, as matiec's `__case_expression`.
        let sel = self.held(v, ty);
        let end = self.label();
        let mut targets = Vec::new();
        for (labels, _) in arms {
            let l = self.label();
            let mut branches = Vec::new();
            for c in labels {
                branches.push(match c {
                    CaseLabel::One(e) => {
                        let x = self.case_value(e, ty)?;
                        vec![self.compare(CmpOp::Eq, &sel, &x)]
                    }
                    CaseLabel::Range(a, b) => {
                        let (a, b) = (self.case_value(a, ty)?, self.case_value(b, ty)?);
                        vec![
                            self.compare(CmpOp::Ge, &sel, &a),
                            self.compare(CmpOp::Le, &sel, &b),
                        ]
                    }
                });
            }
            let mut ld = if branches.len() == 1 {
                branches.pop().unwrap_or_default()
            } else {
                vec![ElementKind::Or(to_series(self, branches))]
            };
            ld.push(self.jmp(&l));
            self.emit(ld);
            targets.push(l);
        }
        self.statements(otherwise)?;
        let j = self.jmp(&end);
        self.emit(vec![j]);
        for ((_, body), l) in arms.iter().zip(targets) {
            self.place(l);
            self.statements(body)?;
            let j = self.jmp(&end);
            self.emit(vec![j]);
        }
        self.place(end);
        Ok(())
    }

    /// A CASE label: a literal (or a constant expression of literals) of the selector's type.
    fn case_value(&mut self, e: &Expr, ty: Type) -> L<Val> {
        match self.value(e, Some(ty))? {
            v @ Val::Lit(_) => Ok(v),
            _ => refuse(self.at, "a CASE label that is not a literal"),
        }
    }

    fn for_loop(
        &mut self,
        var: &Place,
        from: &Expr,
        to: &Expr,
        by: Option<&Expr>,
        body: &[Statement],
    ) -> L<()> {
        let (v, ty) = self.written(var)?;
        if !ty.is_int() {
            return refuse(
                var.base_at,
                format!("FOR on `{v}` of type {ty} (not an integer)"),
            );
        }
        let vv = Val::Var(v.clone(), ty);
        // v := from; the final value and the increment once, before the loop.
        self.assign(var, from)?;
        let end = self.once(to, ty)?;
        let step = match by {
            None => Val::Lit(Scalar::Number(1.into())),
            Some(b) => self.once(b, ty)?,
        };
        let (test, cont, out) = (self.label(), self.label(), self.label());
        self.place(test.clone());
        let positive = match &step {
            Val::Lit(Scalar::Number(n)) => Some(n.as_f64().unwrap_or(0.0) > 0.0),
            _ => None,
        };
        let zero = Val::Lit(Scalar::Number(0.into()));
        let mut ld = match positive {
            Some(true) => vec![self.compare(CmpOp::Gt, &vv, &end)],
            Some(false) => vec![self.compare(CmpOp::Lt, &vv, &end)],
            None => vec![ElementKind::Or(to_series(
                self,
                vec![
                    vec![
                        self.compare(CmpOp::Gt, &step, &zero),
                        self.compare(CmpOp::Gt, &vv, &end),
                    ],
                    vec![
                        self.compare(CmpOp::Le, &step, &zero),
                        self.compare(CmpOp::Lt, &vv, &end),
                    ],
                ],
            ))],
        };
        ld.push(self.jmp(&out));
        self.emit(ld);
        self.loops.push((cont.clone(), out.clone()));
        self.statements(body)?;
        self.loops.pop();
        self.place(cont);
        let add = ElementKind::Arith(Box::new(Arith {
            op: ArithOp::Add,
            a: self.operand(&vv),
            b: self.operand(&step),
            out: self.name(&v),
        }));
        let back = self.jmp(&test);
        self.emit(vec![add, back]);
        self.place(out);
        Ok(())
    }

    /// `e` evaluated now, kept in a temporary unless it is a literal.
    /// `v` held in a temporary of type `ty`, so that later writes of its variables do not
    /// change it (a compiler temporary already is one).
    fn held(&mut self, v: Val, ty: Type) -> Val {
        if matches!(&v, Val::Var(n, _) if n.starts_with("st__")) {
            return v;
        }
        let t = self.temp(ty);
        let m = ElementKind::Move(Box::new(Move {
            from: self.operand(&v),
            to: self.name(&t),
        }));
        self.emit(vec![m]);
        Val::Var(t, ty)
    }

    fn once(&mut self, e: &Expr, ty: Type) -> L<Val> {
        let v = self.value(e, Some(ty))?;
        if matches!(v, Val::Lit(_)) {
            return Ok(v);
        }
        let t = self.temp(ty);
        let m = ElementKind::Move(Box::new(Move {
            from: self.operand(&v),
            to: self.name(&t),
        }));
        self.emit(vec![m]);
        Ok(Val::Var(t, ty))
    }

    /// A call of a standard function block instance (its inputs formal, all given).
    fn fb_call(&mut self, callee: &Place, args: &[Arg]) -> L<()> {
        let at = callee.base_at;
        // A function called as a statement, its result dropped.
        if self.user_function_call(callee, args, None, None)?.is_some() {
            return Ok(());
        }
        if self.action_call(callee, args)? {
            return Ok(());
        }
        let (inst, ty) = match self.scope.find(&place_path(callee)) {
            Ok(Some((Decl::Instance { name, ty, .. }, true))) if callee.selectors.is_empty() => {
                (name.clone(), ty.clone())
            }
            _ => {
                return refuse(
                    at,
                    format!(
                        "the call of `{}` (only instances of the standard function blocks are executed)",
                        callee.base
                    ),
                )
            }
        };
        let pin_names: Vec<String> = match (self.scope.fb(&ty), calls::std_pins(&ty)) {
            (Some(fb), _) => fb.inputs.iter().map(|(n, _)| n.clone()).collect(),
            (None, Some(ps)) => ps.iter().map(|(n, _)| n.to_string()).collect(),
            (None, None) => Vec::new(),
        };
        // A user function block's outputs take the informal arguments past its inputs.
        let out_names: Vec<String> = match self.scope.fb(&ty) {
            Some(fb) => fb.outputs.iter().map(|(n, _)| n.clone()).collect(),
            None => Vec::new(),
        };
        let args = &*functions::name_informal(at, &inst, &pin_names, &out_names, args)?;
        if let Some(fb) = self.scope.fb(&ty).cloned() {
            return self.user_fb_call(at, &inst, &fb, args);
        }
        let mut inputs: Vec<(String, &Expr)> = Vec::new();
        let mut outputs: Vec<(String, &Place)> = Vec::new();
        for a in args {
            match a {
                Arg::Input {
                    name: Some(n),
                    value,
                } => inputs.push((n.to_ascii_uppercase(), value)),
                Arg::Input { name: None, .. } => {
                    return refuse(at, format!("an informal argument in the call of `{inst}`"))
                }
                Arg::Output { name, target } => outputs.push((name.to_ascii_uppercase(), target)),
            }
        }
        let Some(typed) = calls::std_pins(&ty) else {
            return refuse(
                at,
                format!("the call of `{inst}`, an instance of {ty} (only the standard function blocks and the project's are executed)"),
            );
        };
        let pins: Vec<&str> = typed.iter().map(|(p, _)| *p).collect();
        for (n, _) in &inputs {
            if !pins.contains(&n.as_str()) {
                return refuse(
                    at,
                    format!(
                        "input `{n}` in the call of `{inst}` ({ty} has inputs {})",
                        pins.join(", ")
                    ),
                );
            }
        }
        // Each input: the expression given, stored into its holding variable when it has one
        // (then the variable is the operand); left out, the holding variable or, for PT and
        // PV, the instance's own field.
        let mut vals: Vec<Val> = Vec::new();
        let mut first: Option<Series> = None;
        for (k, &(pin, pty)) in typed.iter().enumerate() {
            let given = inputs.iter().find(|(n, _)| n == pin).map(|(_, e)| *e);
            let held = self.held_var(&inst, pin);
            let v = match (given, held) {
                (Some(e), None) if k == 0 => {
                    // The power flow of the box, as the condition itself.
                    first = Some(self.cond(e)?);
                    Val::Lit(Scalar::Bool(true))
                }
                (Some(e), Some(h)) => {
                    self.assign_to(&h, pty, e)?;
                    Val::Var(h, pty)
                }
                (Some(e), None) if pty == Type::Bool => self.bool_operand(e)?,
                (Some(e), None) => self.value(e, Some(pty))?,
                (None, Some(h)) => Val::Var(h, pty),
                (None, None) if pty != Type::Bool => Val::Var(format!("{inst}.{pin}"), pty),
                (None, None) => {
                    return refuse(at, format!("the call of `{inst}` without its input {pin}"))
                }
            };
            vals.push(v);
        }
        let mut ld = match &vals[0] {
            _ if first.is_some() => first.unwrap_or_default(),
            Val::Lit(Scalar::Bool(b)) => vec![self.constant(*b)],
            Val::Var(n, _) => vec![self.contact(n, false)],
            Val::Lit(_) => return refuse(at, format!("a non-BOOL literal as {}", pins[0])),
        };
        let rest = &vals[1..];
        let inst_name = self.name(&inst);
        let el = match ty.as_str() {
            "TON" | "TOF" | "TP" => {
                let pt = rest[0].clone();
                let kind = match ty.as_str() {
                    "TON" => TimerKind::Ton,
                    "TOF" => TimerKind::Tof,
                    _ => TimerKind::Tp,
                };
                ElementKind::Timer(Box::new(Timer {
                    kind,
                    instance: inst_name,
                    pt: self.operand(&pt),
                }))
            }
            "CTU" | "CTD" => {
                let (aux, pv) = (rest[0].clone(), rest[1].clone());
                ElementKind::Counter(Box::new(Counter {
                    down: ty == "CTD",
                    instance: inst_name,
                    pv: self.operand(&pv),
                    aux: self.operand(&aux),
                }))
            }
            "CTUD" => {
                let (cd, reset, load, pv) = (
                    rest[0].clone(),
                    rest[1].clone(),
                    rest[2].clone(),
                    rest[3].clone(),
                );
                ElementKind::Ctud(Box::new(Ctud {
                    instance: inst_name,
                    cd: self.operand(&cd),
                    reset: self.operand(&reset),
                    load: self.operand(&load),
                    pv: self.operand(&pv),
                }))
            }
            "R_TRIG" | "F_TRIG" => ElementKind::Trigger {
                kind: if ty == "R_TRIG" {
                    TriggerKind::Rising
                } else {
                    TriggerKind::Falling
                },
                instance: inst_name,
            },
            _ => {
                let reset = rest[0].clone();
                ElementKind::Bistable(Box::new(Bistable {
                    kind: if ty == "SR" {
                        BistableKind::SetDominant
                    } else {
                        BistableKind::ResetDominant
                    },
                    instance: inst_name,
                    reset: self.operand(&reset),
                }))
            }
        };
        ld.push(el);
        self.emit(ld);
        for (pin, target) in outputs {
            let Some(fty) = field_type(&ty, &pin) else {
                return refuse(
                    at,
                    format!("output `{pin}` in the call of `{inst}` ({ty} has no such output)"),
                );
            };
            let (name, tty) = self.written(target)?;
            let field = format!("{inst}.{pin}");
            if tty != fty {
                return refuse(
                    target.base_at,
                    format!("`{pin} => {name}`: {name} is {tty}, the output {fty}"),
                );
            }
            if fty == Type::Bool {
                let c = self.contact(&field, false);
                self.emit(vec![
                    c,
                    ElementKind::Coil {
                        var: self.name(&name),
                        negated: false,
                    },
                ]);
            } else {
                let m = ElementKind::Move(Box::new(Move {
                    from: self.operand(&Val::Var(field, fty)),
                    to: self.name(&name),
                }));
                self.emit(vec![m]);
            }
        }
        Ok(())
    }

    /// A BOOL operand of a box: a literal, a variable, or the expression in a temporary.
    fn bool_operand(&mut self, e: &Expr) -> L<Val> {
        if let Some(b) = bool_literal(e) {
            return Ok(Val::Lit(Scalar::Bool(b)));
        }
        if let Expr::Var(p) = e {
            let (n, t) = self.read(p)?;
            if t == Type::Bool {
                return Ok(Val::Var(n, t));
            }
        }
        self.bool_temp(e)
    }

    /// The condition `e` computed into a new BOOL temporary.
    fn bool_temp(&mut self, e: &Expr) -> L<Val> {
        let mut ld = self.cond(e)?;
        let t = self.temp(Type::Bool);
        ld.push(ElementKind::Coil {
            var: self.name(&t),
            negated: false,
        });
        self.emit(ld);
        Ok(Val::Var(t, Type::Bool))
    }

    // ---- places ----

    /// What `p` reads: an elementary variable, a structure's field, an array's element (a
    /// variable subscript selects it into a temporary, [`Lower::select_read`]), or an
    /// instance's output.
    fn read(&mut self, p: &Place) -> L<(String, Type)> {
        match self.locate(p)? {
            Access::One(n, t) => Ok((n, t)),
            Access::Select(sel) => self.select_read(sel),
        }
    }

    /// What `p` writes: an elementary variable, a structure's field or an array's element of
    /// constant subscripts (a variable subscript is written by [`Lower::assign`] only).
    fn written(&self, p: &Place) -> L<(String, Type)> {
        if !p.selectors.iter().any(|s| matches!(s, Selector::Index(_))) {
            return self.resolve(p, true);
        }
        match self.locate(p)? {
            Access::One(n, t) => Ok((n, t)),
            Access::Select(sel) => refuse(
                p.base_at,
                format!(
                    "the element of `{}` chosen by a variable subscript as the target of a call's output or a FOR (only an assignment writes one)",
                    sel.array
                ),
            ),
        }
    }

    /// What `p` denotes: one variable (with its type), or an array element chosen by
    /// subscripts that are not all constant.
    fn locate(&self, p: &Place) -> L<Access> {
        let Some(ix) = p
            .selectors
            .iter()
            .position(|s| matches!(s, Selector::Index(_)))
        else {
            let (n, t) = self.resolve(p, false)?;
            return Ok(Access::One(n, t));
        };
        let at = p.base_at;
        let Selector::Index(subs) = &p.selectors[ix] else {
            return refuse(at, "a subscript");
        };
        let array_place = Place {
            base: p.base.clone(),
            base_at: p.base_at,
            selectors: p.selectors[..ix].to_vec(),
        };
        let path = place_path(&array_place);
        if p.base.starts_with('%')
            || ix > 0
                && !array_place
                    .selectors
                    .iter()
                    .all(|s| matches!(s, Selector::Field(_)))
        {
            return refuse(at, format!("the array element `{path}[…]`"));
        }
        let (name, elements) = match self.scope.find(&path) {
            Ok(Some((Decl::Array { name, elements }, true))) => (name.clone(), elements.clone()),
            _ => {
                return refuse(
                    at,
                    format!("the array element `{path}[…]` (`{path}` is not an array of an elementary type with integer bounds, which plc-deps scalarises)"),
                )
            }
        };
        if ix + 1 != p.selectors.len() {
            return refuse(
                at,
                format!("a selector after the array element `{path}[…]`"),
            );
        }
        let rank = elements.first().map_or(0, |e| e.index.len());
        if subs.len() != rank {
            return refuse(
                at,
                format!(
                    "`{path}` with {} subscripts (it has {rank} dimensions)",
                    subs.len()
                ),
            );
        }
        let ty = match elements.first().and_then(|e| Type::parse(&e.ty)) {
            Some(t) if !matches!(t, Type::Fb(_)) => t,
            _ => {
                return refuse(
                    at,
                    format!("the elements of `{path}`, whose type the model does not execute"),
                )
            }
        };
        let dims: Vec<(i64, i64)> = (0..rank)
            .map(|d| {
                let ks = elements.iter().map(|e| e.index[d]);
                (ks.clone().min().unwrap_or(0), ks.max().unwrap_or(0))
            })
            .collect();
        let mut fixed = Vec::new();
        for e in subs {
            let k = match crate::st::constant(e) {
                Some(k) => Some(k),
                None => match e {
                    Expr::Var(q) => self.enum_value(q)?,
                    _ => None,
                },
            };
            fixed.push(k);
        }
        for (d, k) in fixed.iter().enumerate() {
            if let Some(k) = k {
                let (lo, hi) = dims[d];
                if *k < lo || *k > hi {
                    return refuse(
                        at,
                        format!("the subscript {k} of `{path}`, outside its bounds {lo}..{hi} (IEC 61131-3 6.4.4.5)"),
                    );
                }
            }
        }
        if let Some(k) = fixed.iter().copied().collect::<Option<Vec<i64>>>() {
            let el = elements.iter().find(|e| e.index == k);
            return match el {
                Some(e) => Ok(Access::One(e.name.clone(), ty)),
                None => refuse(at, format!("the element `{path}{k:?}`")),
            };
        }
        Ok(Access::Select(Select {
            array: name,
            ty,
            elements,
            dims,
            subs: subs.iter().cloned().zip(fixed).collect(),
        }))
    }

    /// The subscripts of `sel` evaluated (constants as they are, the others into integer
    /// temporaries unless already one), with the series of compares that passes power when
    /// any is outside its dimension's bounds (`None`: none can be).
    fn subscripts(&mut self, sel: &Select) -> L<(Vec<Sub>, Option<Series>)> {
        let mut out = Vec::new();
        let mut outside: Vec<Series> = Vec::new();
        for (d, (e, k)) in sel.subs.iter().enumerate() {
            if let Some(k) = k {
                out.push(Ok(*k));
                continue;
            }
            let v = self.value(e, None)?;
            let ty = match &v {
                Val::Lit(Scalar::Number(n)) => {
                    let (lo, hi) = sel.dims[d];
                    match n.as_i64() {
                        Some(k) if (lo..=hi).contains(&k) => out.push(Ok(k)),
                        _ => {
                            return refuse(
                                self.at,
                                format!("the subscript {n} of `{}`, outside its bounds {lo}..{hi} or not an integer", sel.array),
                            )
                        }
                    }
                    continue;
                }
                Val::Var(_, t) if t.is_int() => *t,
                _ => {
                    return refuse(
                        self.at,
                        format!("a subscript of `{}` that is not an integer", sel.array),
                    )
                }
            };
            let v = self.held(v, ty);
            let (lo, hi) = sel.dims[d];
            let fits = |k: i64| plc_model::Value::int_of(ty, k.into()).is_some();
            if fits(lo) && fits(lo - 1) {
                let b = Val::Lit(Scalar::Number(lo.into()));
                outside.push(vec![self.compare(CmpOp::Lt, &v, &b)]);
            } else if !fits(lo) && lo > 0 {
                return refuse(self.at, format!("a subscript of type {ty}, which cannot reach the bounds {lo}..{hi} of `{}`", sel.array));
            }
            if fits(hi) && fits(hi + 1) {
                let b = Val::Lit(Scalar::Number(hi.into()));
                outside.push(vec![self.compare(CmpOp::Gt, &v, &b)]);
            }
            out.push(Err(v));
        }
        let series = match outside.len() {
            0 => None,
            1 => outside.pop(),
            _ => Some(vec![ElementKind::Or(to_series(self, outside))]),
        };
        Ok((out, series))
    }

    /// For each element `sel` may choose: its variable and the compares that pass power when the
    /// subscripts `subs` choose it (elements a constant subscript rules out, or whose
    /// subscripts a variable's type cannot hold, left out).
    fn choices(&self, sel: &Select, subs: &[Sub]) -> L<Vec<(String, Series)>> {
        let mut out = Vec::new();
        'el: for e in &sel.elements {
            let mut c = Vec::new();
            for (d, s) in subs.iter().enumerate() {
                match s {
                    Ok(k) if *k == e.index[d] => {}
                    Ok(_) => continue 'el,
                    Err(v) => {
                        let k = e.index[d];
                        if v.ty()
                            .is_some_and(|t| plc_model::Value::int_of(t, k.into()).is_none())
                        {
                            continue 'el;
                        }
                        c.push(self.compare(CmpOp::Eq, v, &Val::Lit(Scalar::Number(k.into()))));
                    }
                }
            }
            out.push((e.name.clone(), c));
        }
        if out.len() > MAX_SELECTED {
            return refuse(
                self.at,
                format!("a variable subscript of `{}` choosing among {} elements (more than the {MAX_SELECTED} plc-deps lowers to a selection)", sel.array, out.len()),
            );
        }
        Ok(out)
    }

    /// The rung that records an `index-range` fault of the scan at this statement's rung when
    /// a subscript is outside its bounds (docs/plcopen.md, Arrays).
    fn range_fault(&mut self, outside: Option<Series>) {
        let Some(mut ld) = outside else { return };
        ld.push(ElementKind::RangeFault);
        self.emit(ld);
    }

    /// A read of the element `sel` chooses, into a new temporary: the type's default first
    /// (what an out-of-bounds read gives, with the fault), then the chosen element's value.
    fn select_read(&mut self, sel: Select) -> L<(String, Type)> {
        let (subs, outside) = self.subscripts(&sel)?;
        let choices = self.choices(&sel, &subs)?;
        self.range_fault(outside);
        let t = self.temp(sel.ty);
        let tn = self.name(&t);
        if sel.ty == Type::Bool {
            self.emit(vec![ElementKind::Reset(tn.clone())]);
            for (n, mut c) in choices {
                c.push(self.contact(&n, false));
                c.push(ElementKind::Set(tn.clone()));
                self.emit(c);
            }
        } else {
            let zero = match sel.ty {
                Type::Time => Val::Lit(Scalar::Str(Cow::Borrowed("T#0s"))),
                t if t.is_int() || t.is_bits() => Val::Lit(Scalar::Number(0.into())),
                _ => Val::Lit(Scalar::Number(
                    serde_json::Number::from_f64(0.0).unwrap_or(0.into()),
                )),
            };
            let m = ElementKind::Move(Box::new(Move {
                from: self.operand(&zero),
                to: tn.clone(),
            }));
            self.emit(vec![m]);
            for (n, mut c) in choices {
                c.push(ElementKind::Move(Box::new(Move {
                    from: self.operand(&Val::Var(n, sel.ty)),
                    to: tn.clone(),
                })));
                self.emit(c);
            }
        }
        Ok((t, sel.ty))
    }

    /// `a[i] := value` with a subscript that is not constant: the value once, the subscripts
    /// once, then a conditional write of each element it may choose (none, and a fault, when a
    /// subscript is outside its bounds).
    fn select_write(&mut self, sel: Select, value: &Expr) -> L<()> {
        let v = if sel.ty == Type::Bool {
            Val::Var(self.bool_contact(value)?, Type::Bool)
        } else {
            let v = self.value(value, Some(sel.ty))?;
            match v {
                Val::Var(ref n, _) if !n.starts_with("st__") => {
                    let t = self.temp(sel.ty);
                    let m = ElementKind::Move(Box::new(Move {
                        from: self.operand(&v),
                        to: self.name(&t),
                    }));
                    self.emit(vec![m]);
                    Val::Var(t, sel.ty)
                }
                v => v,
            }
        };
        let (subs, outside) = self.subscripts(&sel)?;
        let choices = self.choices(&sel, &subs)?;
        self.range_fault(outside);
        for (n, mut c) in choices {
            if let Val::Var(b, Type::Bool) = &v {
                let set = vec![self.contact(b, false), ElementKind::Set(self.name(&n))];
                let reset = vec![self.contact(b, true), ElementKind::Reset(self.name(&n))];
                c.push(ElementKind::Branch(to_series(self, vec![set, reset])));
            } else {
                c.push(ElementKind::Move(Box::new(Move {
                    from: self.operand(&v),
                    to: self.name(&n),
                })));
            }
            self.emit(c);
        }
        Ok(())
    }

    fn resolve(&self, p: &Place, write: bool) -> L<(String, Type)> {
        let at = p.base_at;
        if p.base.starts_with('%') {
            return refuse(at, format!("the direct address `{}`", p.base));
        }
        for s in &p.selectors {
            match s {
                Selector::Index(_) => {
                    return refuse(at, format!("the array element `{}[…]`", place_path(p)))
                }
                Selector::Deref => {
                    return refuse(at, format!("the dereference `{}^`", place_path(p)))
                }
                Selector::Field(_) => {}
            }
        }
        let path = place_path(p);
        match self.scope.find(&path) {
            Ok(Some((Decl::Elementary { name, ty }, true))) => match Type::parse(ty) {
                Some(t) if !matches!(t, Type::Fb(_)) => Ok((name.clone(), t)),
                _ => refuse(
                    at,
                    format!("`{path}` of type {ty}, which the model does not execute"),
                ),
            },
            Ok(Some((Decl::Instance { name, ty, .. }, false))) => {
                let field = path[name.len() + 1..].to_ascii_uppercase();
                if field.contains('.') {
                    return refuse(at, format!("`{path}`: a field of a field of an instance"));
                }
                self.instance_field(at, name, ty, &field, write)
            }
            Ok(Some((Decl::Instance { .. }, _))) => refuse(
                at,
                format!("`{path}`: an instance (or its input) as a value"),
            ),
            Ok(Some((Decl::Constant(_), _))) => refuse(
                at,
                format!("the enumeration value `{path}` where a variable is needed"),
            ),
            Ok(Some((Decl::Structure { .. }, _))) => {
                refuse(at, format!("the structure `{path}` as a whole"))
            }
            Ok(Some((Decl::Array { .. }, _))) => {
                refuse(at, format!("the array `{path}` as a whole"))
            }
            _ => refuse(at, format!("`{path}`, which is not a variable of the POU")),
        }
    }

    /// The integer of enumeration value `p` (IEC 61131-3 6.4.4.2; numbered as matiec and
    /// [`super::data_types`] do), `None` when `p` is not one.
    fn enum_value(&self, p: &Place) -> L<Option<i64>> {
        if !p.selectors.is_empty() {
            return Ok(None);
        }
        match self.scope.get(&p.base) {
            Some(Decl::Constant(Some(i))) => Ok(Some(*i)),
            Some(Decl::Constant(None)) => refuse(
                p.base_at,
                format!(
                    "the enumeration value `{}`, which several enumerations have with different values (write TYPE#{})",
                    p.base, p.base
                ),
            ),
            _ => Ok(None),
        }
    }

    // ---- conditions ----

    /// `e` as a series of conditions that passes power when `e` is TRUE.
    fn cond(&mut self, e: &Expr) -> L<Series> {
        if let Some(b) = bool_literal(e) {
            return Ok(vec![self.constant(b)]);
        }
        match e {
            Expr::Var(p) => {
                let (n, t) = self.read(p)?;
                if t != Type::Bool {
                    return refuse(p.base_at, format!("`{n}` of type {t} as a condition"));
                }
                Ok(vec![self.contact(&n, false)])
            }
            Expr::Unary(UnaryOp::Not, x) => {
                let c = self.cond(x)?;
                Ok(self.negate(c))
            }
            Expr::Binary(BinaryOp::And, a, b) if self.is_bool(a) => {
                let mut c = self.cond(a)?;
                c.extend(self.cond(b)?);
                Ok(c)
            }
            Expr::Binary(BinaryOp::Or, a, b) if self.is_bool(a) => {
                let (x, y) = (self.cond(a)?, self.cond(b)?);
                Ok(vec![ElementKind::Or(to_series(self, vec![x, y]))])
            }
            Expr::Binary(op @ (BinaryOp::Xor | BinaryOp::Eq | BinaryOp::Ne), a, b)
                if self.is_bool(a) || self.is_bool(b) =>
            {
                let x = self.bool_contact(a)?;
                let y = self.bool_contact(b)?;
                let same = *op == BinaryOp::Eq;
                let (x1, y1) = (self.contact(&x, false), self.contact(&y, !same));
                let (x2, y2) = (self.contact(&x, true), self.contact(&y, same));
                Ok(vec![ElementKind::Or(to_series(
                    self,
                    vec![vec![x1, y1], vec![x2, y2]],
                ))])
            }
            Expr::Binary(op, a, b)
                if cmp_op(*op).is_some()
                    && (self.narrow_arith(a, None) || self.narrow_arith(b, None)) =>
            {
                // matiec's C compares the `int` values of its sides: both widened to DINT.
                let op = cmp_op(*op).unwrap_or(CmpOp::Eq);
                let nat = self.natural(a, None).or(self.natural(b, None));
                let l = self.widened(a, nat)?;
                let r = self.widened(b, nat)?;
                Ok(vec![self.compare(op, &l, &r)])
            }
            Expr::Binary(op, a, b) if cmp_op(*op).is_some() => {
                let op = cmp_op(*op).unwrap_or(CmpOp::Eq);
                let mut l = self.value(a, None)?;
                let r = self.value(b, l.ty())?;
                if l.ty().is_none() {
                    l = self.value(a, r.ty())?;
                }
                if l.ty().is_none() && r.ty().is_none() {
                    return refuse(self.at, "a comparison of two literals");
                }
                Ok(vec![self.compare(op, &l, &r)])
            }
            _ => {
                let v = self.value(e, Some(Type::Bool))?;
                match v {
                    Val::Var(n, Type::Bool) => Ok(vec![self.contact(&n, false)]),
                    // `1` or `0` where a BOOL is expected (matiec types them BOOL).
                    Val::Lit(Scalar::Bool(b)) => Ok(vec![self.constant(b)]),
                    other => refuse(
                        self.at,
                        format!(
                            "a condition of type {}",
                            other.ty().map_or("?".into(), |t| t.to_string())
                        ),
                    ),
                }
            }
        }
    }

    // ---- matiec's integer promotion ----

    /// Whether `e` is arithmetic (`+ - * / MOD`) whose IEC type is narrower than C's `int`
    /// (SINT, INT, USINT, UINT) in a project whose toolchain computes it in `int`
    /// ([`Scope::int_arithmetic_in_dint`]): matiec writes `a * b` of two INTs as C's `a * b`,
    /// which C computes in `int` (C11 6.3.1.1, the integer promotions), and the value is cut to
    /// INT only where it is stored or passed (`i := a * b`, `INT_TO_DINT(a * b)`), so
    /// `w <= i * 258` compares the full product.
    fn narrow_arith(&self, e: &Expr, want: Option<Type>) -> bool {
        self.scope.int_arithmetic_in_dint
            && matches!(
                e,
                Expr::Binary(op, ..) if arith_op(*op).is_some()
            )
            && self
                .natural(e, want)
                .is_some_and(|t| matches!(t, Type::Sint | Type::Int | Type::Usint | Type::Uint))
    }

    /// The IEC type of `e` where its operands say it without computing anything (`None`: a
    /// literal, or a call whose type only its lowering knows).
    fn natural(&self, e: &Expr, want: Option<Type>) -> Option<Type> {
        match e {
            Expr::Var(p) => match self.enum_value(p) {
                Ok(None) => match self.locate(p) {
                    Ok(Access::One(_, t)) => Some(t),
                    Ok(Access::Select(sel)) => Some(sel.ty),
                    Err(_) => None,
                },
                _ => None,
            },
            Expr::Unary(UnaryOp::Neg | UnaryOp::Plus, x) => self.natural(x, want),
            Expr::Binary(
                BinaryOp::Add | BinaryOp::Sub | BinaryOp::Mul | BinaryOp::Div | BinaryOp::Mod,
                a,
                b,
            ) => self.natural(a, None).or(self.natural(b, None)).or(want),
            Expr::Call { callee, .. } if callee.selectors.is_empty() => {
                match Function::parse(&callee.base.to_ascii_uppercase()) {
                    Some(Function::Convert { to, .. }) => Some(to),
                    _ => None,
                }
            }
            _ => None,
        }
    }

    /// `e` (arithmetic of type `nat`, narrower than `int`) computed in DINT: the DINT value and
    /// `nat`.
    fn wide(&mut self, e: &Expr, want: Option<Type>) -> L<(Val, Type)> {
        let nat = self.natural(e, want).unwrap_or(Type::Dint);
        let Expr::Binary(op, a, b) = e else {
            return Ok((self.widened(e, Some(nat))?, nat));
        };
        let Some(arith) = arith_op(*op) else {
            return Ok((self.widened(e, Some(nat))?, nat));
        };
        let l = self.widened(a, Some(nat))?;
        let r = self.widened(b, Some(nat))?;
        let d = self.temp(Type::Dint);
        let el = ElementKind::Arith(Box::new(Arith {
            op: arith,
            a: self.operand(&l),
            b: self.operand(&r),
            out: self.name(&d),
        }));
        self.emit(vec![el]);
        Ok((Val::Var(d, Type::Dint), nat))
    }

    /// An operand of `int` arithmetic or comparison as DINT: narrower arithmetic computed wide
    /// ([`Self::wide`]), a narrower value converted, a literal as it is.
    fn widened(&mut self, e: &Expr, nat: Option<Type>) -> L<Val> {
        if self.narrow_arith(e, nat) {
            return Ok(self.wide(e, nat)?.0);
        }
        let v = self.value(e, nat)?;
        match v {
            Val::Var(n, t @ (Type::Sint | Type::Int | Type::Usint | Type::Uint)) => {
                let d = self.temp(Type::Dint);
                let el = ElementKind::Function(Box::new(FunctionCall {
                    func: Function::Convert {
                        from: t,
                        to: Type::Dint,
                    },
                    args: vec![self.operand(&Val::Var(n, t))],
                    out: self.name(&d),
                }));
                self.emit(vec![el]);
                Ok(Val::Var(d, Type::Dint))
            }
            other => Ok(other),
        }
    }

    /// A BOOL operand as the name of a variable a contact reads (a literal 0/1 or TRUE/FALSE as
    /// the never-written `st__false`'s value, `e` otherwise computed into a temporary).
    fn bool_contact(&mut self, e: &Expr) -> L<String> {
        if let Some(b) = bool_literal(e).or(match e {
            Expr::Literal(s) if s == "0" => Some(false),
            Expr::Literal(s) if s == "1" => Some(true),
            _ => None,
        }) {
            let t = self.temp(Type::Bool);
            let el = if b {
                ElementKind::Set(self.name(&t))
            } else {
                ElementKind::Reset(self.name(&t))
            };
            self.emit(vec![el]);
            return Ok(t);
        }
        match self.bool_operand(e)? {
            Val::Var(n, _) => Ok(n),
            Val::Lit(_) => refuse(self.at, "a BOOL literal where a variable is needed"),
        }
    }

    fn compare(&self, op: CmpOp, a: &Val, b: &Val) -> ElementKind<'static> {
        ElementKind::Compare(Box::new(Compare {
            op,
            a: self.operand(a),
            b: self.operand(b),
        }))
    }

    /// The series that passes power when `c` does not.
    fn negate(&mut self, mut c: Series) -> Series {
        if c.len() == 1 {
            match &mut c[0] {
                ElementKind::Contact {
                    negated,
                    edge: None,
                    ..
                } => {
                    *negated = !*negated;
                    return c;
                }
                ElementKind::Compare(cmp) => {
                    cmp.op = match cmp.op {
                        CmpOp::Eq => CmpOp::Ne,
                        CmpOp::Ne => CmpOp::Eq,
                        CmpOp::Lt => CmpOp::Ge,
                        CmpOp::Ge => CmpOp::Lt,
                        CmpOp::Gt => CmpOp::Le,
                        CmpOp::Le => CmpOp::Gt,
                    };
                    return c;
                }
                _ => {}
            }
        }
        let t = self.temp(Type::Bool);
        c.push(ElementKind::Coil {
            var: self.name(&t),
            negated: false,
        });
        self.emit(c);
        vec![self.contact(&t, true)]
    }

    /// Whether `e` is a BOOL expression (statically, from its variables and operators).
    fn is_bool(&self, e: &Expr) -> bool {
        match e {
            Expr::Literal(_) => bool_literal(e).is_some(),
            Expr::Var(p) => matches!(
                self.locate(p),
                Ok(Access::One(_, Type::Bool)) | Ok(Access::Select(Select { ty: Type::Bool, .. }))
            ),
            Expr::Unary(UnaryOp::Not, x) => self.is_bool(x),
            Expr::Unary(..) => false,
            Expr::Binary(op, a, b) => match op {
                BinaryOp::And | BinaryOp::Or | BinaryOp::Xor => self.is_bool(a) || self.is_bool(b),
                _ => cmp_op(*op).is_some(),
            },
            Expr::Call { callee, .. } => {
                callee.base.to_ascii_uppercase().ends_with("_TO_BOOL")
                    || self
                        .scope
                        .func(&callee.base)
                        .is_some_and(|f| f.ret.eq_ignore_ascii_case("BOOL"))
            }
        }
    }

    // ---- values ----

    fn value(&mut self, e: &Expr, want: Option<Type>) -> L<Val> {
        match self.value_into(e, want, None)? {
            Some(v) => Ok(v),
            // Every path returns its value when it has no target to write.
            None => refuse(self.at, "an expression without a value"),
        }
    }

    /// `e` as an operand (`want`: the type its use gives a literal). With `out`, a box that
    /// computes `e` writes `out` directly and `None` is returned.
    fn value_into(&mut self, e: &Expr, want: Option<Type>, out: Option<&str>) -> L<Option<Val>> {
        let dest = |me: &mut Self, ty: Type| -> String {
            match out {
                Some(o) => o.to_owned(),
                None => me.temp(ty),
            }
        };
        let done = |name: String, ty: Type| match out {
            Some(_) => None,
            None => Some(Val::Var(name, ty)),
        };
        if let (Some(Type::Bool), Expr::Literal(s)) = (want, e) {
            if s == "0" || s == "1" {
                return Ok(Some(Val::Lit(Scalar::Bool(s == "1"))));
            }
        }
        // A call computes its value itself (`cond` of a BOOL call asks for its value here).
        if self.is_bool(e) && !matches!(e, Expr::Call { .. }) {
            if let Some(b) = bool_literal(e) {
                return Ok(Some(Val::Lit(Scalar::Bool(b))));
            }
            if let Expr::Var(p) = e {
                return Ok(Some(Val::Var(self.read(p)?.0, Type::Bool)));
            }
            return Ok(Some(self.bool_temp(e)?));
        }
        match e {
            Expr::Literal(s) if s.starts_with('\'') || s.starts_with('"') => {
                functions::string_literal(self.at, s).map(|v| Some(Val::Lit(v)))
            }
            Expr::Literal(s) => match (literal(s), self.scope.enum_literal(s)) {
                (_, Some(i)) => Ok(Some(Val::Lit(Scalar::Number(i.into())))),
                (Some(v), _) => Ok(Some(Val::Lit(v))),
                (None, None) => refuse(self.at, format!("the literal `{s}`")),
            },
            Expr::Var(p) => {
                if let Some(i) = self.enum_value(p)? {
                    return Ok(Some(Val::Lit(Scalar::Number(i.into()))));
                }
                let (n, t) = self.read(p)?;
                Ok(Some(Val::Var(n, t)))
            }
            Expr::Unary(UnaryOp::Plus, x) => self.value_into(x, want, out),
            Expr::Unary(UnaryOp::Neg, x) => {
                if let Expr::Literal(l) = &**x {
                    if let Some(v) = literal(&format!("-{l}")) {
                        return Ok(Some(Val::Lit(v)));
                    }
                }
                let v = self.value(x, want)?;
                let Some(ty) = v.ty().or(want) else {
                    return refuse(self.at, "a negation without a type");
                };
                let d = dest(self, ty);
                let el = ElementKind::Arith(Box::new(Arith {
                    op: ArithOp::Sub,
                    a: self.operand(&Val::Lit(Scalar::Number(0.into()))),
                    b: self.operand(&v),
                    out: self.name(&d),
                }));
                self.emit(vec![el]);
                Ok(done(d, ty))
            }
            Expr::Unary(UnaryOp::Not, x) => self.function(Function::Not, &[x], want, out),
            Expr::Binary(..) if self.narrow_arith(e, want) => {
                // matiec's C: computed in `int`, cut to the expression's type where it is used.
                let (w, nat) = self.wide(e, want)?;
                let d = dest(self, nat);
                let el = ElementKind::Function(Box::new(FunctionCall {
                    func: Function::Convert {
                        from: Type::Dint,
                        to: nat,
                    },
                    args: vec![self.operand(&w)],
                    out: self.name(&d),
                }));
                self.emit(vec![el]);
                Ok(done(d, nat))
            }
            Expr::Binary(op, a, b) => {
                let arith = match arith_op(*op) {
                    Some(a) => a,
                    None => {
                        let f = match op {
                            BinaryOp::Power => Function::Expt,
                            BinaryOp::And => Function::And,
                            BinaryOp::Or => Function::Or,
                            BinaryOp::Xor => Function::Xor,
                            _ => return refuse(self.at, "a comparison as a non-BOOL value"),
                        };
                        return self.function(f, &[a, b], want, out);
                    }
                };
                let mut l = self.value(a, want)?;
                let r = self.value(b, l.ty().or(want))?;
                if l.ty().is_none() && r.ty().is_some() {
                    l = self.value(a, r.ty())?;
                }
                let ty = match l.ty().or(r.ty()).or(want) {
                    Some(t) => t,
                    None if l.is_real_literal() || r.is_real_literal() => Type::Real,
                    None => Type::Dint,
                };
                let d = dest(self, ty);
                let el = ElementKind::Arith(Box::new(Arith {
                    op: arith,
                    a: self.operand(&l),
                    b: self.operand(&r),
                    out: self.name(&d),
                }));
                self.emit(vec![el]);
                Ok(done(d, ty))
            }
            Expr::Call { callee, args } => self.call(callee, args, want, out),
        }
    }

    fn call(
        &mut self,
        callee: &Place,
        args: &[Arg],
        want: Option<Type>,
        out: Option<&str>,
    ) -> L<Option<Val>> {
        let at = callee.base_at;
        let fname = callee.base.to_ascii_uppercase();
        if let Some(done) = self.user_function_call(callee, args, want, out)? {
            return Ok(done);
        }
        let args = functions::formal_order(at, &fname, args)?;
        let mut values: Vec<&Expr> = Vec::new();
        for a in args.iter() {
            match a {
                Arg::Input { value, .. } => values.push(value),
                Arg::Output { .. } => {
                    return refuse(
                        at,
                        format!(
                            "an output argument in the call of function `{}`",
                            callee.base
                        ),
                    )
                }
            }
        }
        if !callee.selectors.is_empty() {
            return refuse(at, format!("the call of `{}`", place_path(callee)));
        }
        let n = values.len();
        match fname.as_str() {
            "MOVE" if n == 1 => self.value_into(values[0], want, out),
            "MAX" | "MIN" if n >= 2 => {
                let mut acc = self.value(values[0], want)?;
                for (i, e) in values[1..].iter().enumerate() {
                    let v = self.value(e, acc.ty().or(want))?;
                    let last = i + 2 == n;
                    acc = self.pick(&fname, acc, v, want, if last { out } else { None })?;
                }
                Ok(match out {
                    Some(_) => None,
                    None => Some(acc),
                })
            }
            "LIMIT" if n == 3 => {
                let mn = self.value(values[0], want)?;
                let x = self.value(values[1], mn.ty().or(want))?;
                let mx = self.value(values[2], x.ty().or(mn.ty()).or(want))?;
                let lo = self.pick("MAX", mn, x, want, None)?;
                let r = self.pick("MIN", lo, mx, want, out)?;
                Ok(match out {
                    Some(_) => None,
                    None => Some(r),
                })
            }
            "SEL" if n == 3 => {
                let g = self.bool_contact(values[0])?;
                let a = self.value(values[1], want)?;
                let b = self.value(values[2], a.ty().or(want))?;
                let Some(ty) = a.ty().or(b.ty()).or(want) else {
                    return refuse(at, "SEL of two literals without a type");
                };
                let d = match out {
                    Some(o) => o.to_owned(),
                    None => self.temp(ty),
                };
                let (c0, c1) = (self.contact(&g, true), self.contact(&g, false));
                let m0 = ElementKind::Move(Box::new(Move {
                    from: self.operand(&a),
                    to: self.name(&d),
                }));
                let m1 = ElementKind::Move(Box::new(Move {
                    from: self.operand(&b),
                    to: self.name(&d),
                }));
                let el = ElementKind::Branch(to_series(self, vec![vec![c0, m0], vec![c1, m1]]));
                self.emit(vec![el]);
                Ok(match out {
                    Some(_) => None,
                    None => Some(Val::Var(d, ty)),
                })
            }
            // The arithmetic standard functions (IEC 61131-3 Table 29): ADD and MUL of two or
            // more inputs, SUB, DIV, MOD of two, as the operators they are.
            "ADD" | "MUL" | "SUB" | "DIV" | "MOD"
                if n == 2 || (n > 2 && matches!(fname.as_str(), "ADD" | "MUL")) =>
            {
                let op = match fname.as_str() {
                    "ADD" => BinaryOp::Add,
                    "MUL" => BinaryOp::Mul,
                    "SUB" => BinaryOp::Sub,
                    "DIV" => BinaryOp::Div,
                    _ => BinaryOp::Mod,
                };
                let mut e = values[0].clone();
                for v in &values[1..] {
                    e = Expr::Binary(op, Box::new(e), Box::new((*v).clone()));
                }
                self.value_into(&e, want, out)
            }
            _ => match Function::parse(&fname) {
                Some(f) => self.function(f, &values, want, out),
                None => refuse(
                    at,
                    format!(
                        "the call of function `{}` (only the standard functions are executed)",
                        callee.base
                    ),
                ),
            },
        }
    }

    /// MAX or MIN of two values: `[branch [[a >= b, move a], [a < b, move b]]]` (MIN: `<=`).
    fn pick(&mut self, f: &str, a: Val, b: Val, want: Option<Type>, out: Option<&str>) -> L<Val> {
        let Some(ty) = a.ty().or(b.ty()).or(want) else {
            return refuse(self.at, format!("{f} of literals without a type"));
        };
        let d = match out {
            Some(o) => o.to_owned(),
            None => self.temp(ty),
        };
        let first = if f == "MAX" { CmpOp::Ge } else { CmpOp::Le };
        // The comparison into a flag first: a move may write an operand (`x := MAX(x, 5)`).
        let c1 = self.compare(first, &a, &b);
        let keep = self.temp(Type::Bool);
        let flag = ElementKind::Coil {
            var: self.name(&keep),
            negated: false,
        };
        self.emit(vec![c1, flag]);
        let m0 = ElementKind::Move(Box::new(Move {
            from: self.operand(&a),
            to: self.name(&d),
        }));
        let m1 = ElementKind::Move(Box::new(Move {
            from: self.operand(&b),
            to: self.name(&d),
        }));
        let (k0, k1) = (self.contact(&keep, false), self.contact(&keep, true));
        let el = ElementKind::Branch(to_series(self, vec![vec![k0, m0], vec![k1, m1]]));
        self.emit(vec![el]);
        Ok(Val::Var(d, ty))
    }

    /// A standard function of `args`, its output typed by the function's rule.
    fn function(
        &mut self,
        f: Function,
        args: &[&Expr],
        want: Option<Type>,
        out: Option<&str>,
    ) -> L<Option<Val>> {
        let mut vals = Vec::with_capacity(args.len());
        for (i, a) in args.iter().enumerate() {
            // A pin of one exact type (a conversion's input, a string function's) types its
            // argument, as matiec types `INT_TO_DINT(297 / 2)` INT; a generic pin takes the
            // first typed argument's type.
            let hint = match f.pin(i) {
                plc_model::Pin::Own(plc_model::Class::Exact(t)) => Some(t),
                _ => vals.iter().find_map(|v: &Val| v.ty()),
            };
            vals.push(self.value(a, hint)?);
        }
        // Untyped literals of a generic pin take the first typed argument's type.
        let own: Vec<(Option<Type>, bool)> =
            vals.iter().map(|v| (v.ty(), v.is_real_literal())).collect();
        let out_ty = match f.types(&own, want) {
            Ok(t) => t.out,
            Err(_) => match f.types(&own, None) {
                Ok(t) => t.out,
                Err(m) => {
                    return refuse(
                        self.at,
                        format!(
                            "{}: an operand of type {} where {} is needed",
                            f.name(),
                            m.found,
                            m.expected
                        ),
                    )
                }
            },
        };
        let d = match out {
            Some(o) if want == Some(out_ty) => o.to_owned(),
            _ => self.temp(out_ty),
        };
        let args = vals.iter().map(|v| self.operand(v)).collect();
        let el = ElementKind::Function(Box::new(FunctionCall {
            func: f,
            args,
            out: self.name(&d),
        }));
        self.emit(vec![el]);
        Ok(match out {
            Some(o) if o == d => None,
            _ => Some(Val::Var(d, out_ty)),
        })
    }
}

/// The arithmetic operation of an arithmetic operator (`+ - * / MOD`).
fn arith_op(op: BinaryOp) -> Option<ArithOp> {
    Some(match op {
        BinaryOp::Add => ArithOp::Add,
        BinaryOp::Sub => ArithOp::Sub,
        BinaryOp::Mul => ArithOp::Mul,
        BinaryOp::Div => ArithOp::Div,
        BinaryOp::Mod => ArithOp::Mod,
        _ => return None,
    })
}

/// Whether element `k` does nothing without power: a condition, or a move, arithmetic or
/// function box, set or reset (a coil writes FALSE, a block runs its instance).
fn inert(k: &ElementKind) -> bool {
    match k {
        ElementKind::Contact { .. }
        | ElementKind::Compare(_)
        | ElementKind::Move(_)
        | ElementKind::Arith(_)
        | ElementKind::Function(_)
        | ElementKind::Set(_)
        | ElementKind::Reset(_) => true,
        ElementKind::Or(s) | ElementKind::Branch(s) => {
            s.iter().all(|series| series.iter().all(|e| inert(&e.kind)))
        }
        _ => false,
    }
}

/// Series of kinds as the branches of an `or` or a `branch`, located at the statement.
fn to_series(me: &Lower, v: Vec<Series>) -> Vec<Vec<Element<'static>>> {
    v.into_iter()
        .map(|s| {
            s.into_iter()
                .map(|kind| Element {
                    origin: me.here,
                    kind,
                })
                .collect()
        })
        .collect()
}

fn bool_literal(e: &Expr) -> Option<bool> {
    match e {
        Expr::Literal(s)
            if s.eq_ignore_ascii_case("TRUE")
                || s.eq_ignore_ascii_case("BOOL#TRUE")
                || s == "BOOL#1" =>
        {
            Some(true)
        }
        Expr::Literal(s)
            if s.eq_ignore_ascii_case("FALSE")
                || s.eq_ignore_ascii_case("BOOL#FALSE")
                || s == "BOOL#0" =>
        {
            Some(false)
        }
        _ => None,
    }
}

fn cmp_op(op: BinaryOp) -> Option<CmpOp> {
    Some(match op {
        BinaryOp::Eq => CmpOp::Eq,
        BinaryOp::Ne => CmpOp::Ne,
        BinaryOp::Lt => CmpOp::Lt,
        BinaryOp::Le => CmpOp::Le,
        BinaryOp::Gt => CmpOp::Gt,
        BinaryOp::Ge => CmpOp::Ge,
        _ => return None,
    })
}

/// The instance through which a body calls the project's function `f`.
pub(super) fn function_instance_name(f: &str) -> String {
    functions::instance_name(f)
}

/// `a.b.c` of a place of fields only.
fn place_path(p: &Place) -> String {
    let mut s = p.base.clone();
    for sel in &p.selectors {
        if let Selector::Field(f) = sel {
            s.push('.');
            s.push_str(f);
        }
    }
    s
}

/// The type of output `field` of a standard function block of type `fb` (IEC 61131-3 2nd ed.,
/// 2.5.2.3: CV is INT).
pub(super) fn field_type(fb: &str, field: &str) -> Option<Type> {
    Some(match (fb, field) {
        ("TON" | "TOF" | "TP", "Q") => Type::Bool,
        ("TON" | "TOF" | "TP", "ET") => Type::Time,
        ("CTU" | "CTD", "Q") => Type::Bool,
        ("CTU" | "CTD" | "CTUD", "CV") => Type::Int,
        ("CTUD", "QU" | "QD") => Type::Bool,
        ("R_TRIG" | "F_TRIG", "Q") => Type::Bool,
        ("SR" | "RS", "Q1") => Type::Bool,
        _ => return None,
    })
}

/// The offset of the first pragma `{…}` of ST text `text` (outside comments and strings).
pub(super) fn first_pragma(text: &str) -> Option<usize> {
    let b = text.as_bytes();
    let mut i = 0;
    let mut depth = 0usize;
    while i < b.len() {
        if depth > 0 {
            if b[i..].starts_with(b"*)") {
                depth -= 1;
                i += 2;
            } else if b[i..].starts_with(b"(*") {
                depth += 1;
                i += 2;
            } else {
                i += 1;
            }
            continue;
        }
        match b[i] {
            b'(' if b[i..].starts_with(b"(*") => {
                depth = 1;
                i += 2;
            }
            b'/' if b[i..].starts_with(b"//") => {
                i = b[i..]
                    .iter()
                    .position(|&c| c == b'\n')
                    .map_or(b.len(), |n| i + n);
            }
            q @ (b'\'' | b'"') => {
                i += 1;
                while i < b.len() && b[i] != q {
                    i += if b[i] == b'$' { 2 } else { 1 };
                }
                i += 1;
            }
            b'{' => return Some(i),
            _ => i += 1,
        }
    }
    None
}

#[cfg(test)]
mod tests {
    use super::first_pragma;

    #[test]
    fn a_pragma_is_found_outside_comments_and_strings_only() {
        assert_eq!(first_pragma("x := 1; (* {not} *) // {no}\ny := '{';"), None);
        assert_eq!(
            first_pragma("(* (* {nested} *) *) x := 1;\n{SetFbVar(OUT,1)}"),
            Some(29)
        );
        assert_eq!(first_pragma("s := 'it$'s'; {p}"), Some(14));
        // Bytes, not characters: a comment or string with non-ASCII text (a panic once, on
        // a real export's `ó`).
        assert_eq!(first_pragma("(* válvula ó *) x := 'ñ'; {p}"), Some(29));
        assert_eq!(first_pragma("// ó\n(*ó*)"), None);
    }
}
