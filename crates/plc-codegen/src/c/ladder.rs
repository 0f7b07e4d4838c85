//! Ladder rungs → C statements: the series/parallel element tree of each rung becomes
//! statements over a power value, one block of statements per rung.
//!
//! Power is carried as a C expression while it is pure (contacts, compares, ORs of them:
//! `self->a & !self->b & (self->x < 5)`) and put into a local `_pN` only before an element
//! that writes (a coil, a box, a call), so a rung of contacts and a coil is one assignment and
//! no value is stored twice. The expression uses `&` and `|` on 0/1 values, not `&&` and `||`:
//! it has no side effects to skip, and without branches a rung costs the same whatever its
//! inputs (a branch on an input that changes every scan is mispredicted about half the time;
//! GCC also compiles the branch-free form in about a fifth of the time). A set coil is `x |= p`,
//! a reset `x &= !p`, for the same reason. Edge contacts compute their pulse into a local and update their
//! memory at every evaluation, in order, as the interpreter does. Jumps are `goto` (a backward
//! jump through the loop cap), FOR/NEXT is a C `for` (the NEXT asks the loop cap before it
//! increments), calls are calls, RET and END return.
//!
//! Semantics: docs/scan.md, element by element as `crates/plc-exec/src/run.rs` runs them. Not here: the
//! nesting of FBD fragments (`fbd`), files and the harness (`mod`, `harness`).

pub(crate) use super::spelling::{c_const, c_type, negate, num_suffix};
use super::{fold, names};
use plc_model::*;
use std::borrow::Cow;
use std::collections::HashMap;

/// Power as the emitter holds it.
#[derive(Clone, Debug)]
enum Pw {
    True,
    False,
    /// A pure C expression (reads only, no side effects).
    Expr(String),
    /// A local that holds it.
    Local(String),
}

/// What a POU's code needs to know about the whole program.
pub(crate) struct Shared<'a> {
    pub p: &'a Program,
    /// The C lvalue of each variable (`self->Var1`).
    pub vars: Vec<String>,
    /// The C function of each POU.
    pub pou_fns: Vec<String>,
    /// Per POU: the user function block instance it was expanded into (index into
    /// `Fbd::instances`), whose calls go to its type's function with its struct.
    pub inst_of_pou: Vec<Option<usize>>,
    /// Per instance: its struct as an lvalue of `_plc_state` (`self->G1.INNER`).
    pub inst_paths: Vec<String>,
    /// Per instance: the function of its type that runs it (set type by type, nested first).
    pub inst_fns: Vec<String>,
    /// Rungs that some jump targets.
    pub labels: Vec<bool>,
    /// Per rung: its loop counter index, for loop-back rungs.
    pub counters: Vec<Option<u32>>,
    /// Per variable: held in a local of an FBD function only (an arc or a run flag), so no
    /// struct has a member for it.
    pub local_only: Vec<bool>,
    /// Per variable: its byte offset in `_plc_state` if it is a BOOL, INT, counter or timer
    /// member of it (they come first in the struct, `member_offsets`).
    pub at: Vec<Option<u32>>,
    /// Per rung: its row, if it is written as one (`rows`).
    pub rows: Vec<Option<super::shape::Row>>,
    /// Per rung: its scan budget task (`plc_exec::budget::tasks`).
    pub budget_task: Vec<Option<u32>>,
}

/// The statements of one C function being written.
pub(crate) struct Body<'a> {
    pub sh: &'a Shared<'a>,
    /// Variables held in locals of this function (FBD arcs, run flags).
    pub locals: HashMap<VarId, String>,
    pub out: String,
    pub indent: usize,
    tmp: u32,
    /// The statement that ends the POU (`return;` or `return true;`).
    pub ret: &'static str,
    /// Rungs some emitted `goto` names (only their labels are written: GCC refuses unused ones).
    pub used_labels: std::collections::HashSet<u32>,
    /// Set for the function of a user function block type: whose rungs are emitted.
    pub inst: Option<InstanceCtx>,
    /// Whether each rung gets a comment with its id (off to compare instances' code).
    pub comments: bool,
    /// Set where rungs of contacts and coils become rows of tables (`rows`).
    pub rows: Option<super::table::Tables>,
    /// The power locals (`bool _pN = …;`) whose value is a box's call: [`Body::finish`] keeps
    /// the call of one that nothing reads (every other power local is a pure expression).
    calls: std::collections::HashSet<String>,
}

/// The instance whose lowered rungs a function block type's function is written from: its
/// members become `self->…` (the type's struct), every other variable `_g->…` (the program's
/// state), rungs and loop counters are numbered from the instance's first ones (their bases are
/// members of the struct), so every instance of the type gives the same text.
pub(crate) struct InstanceCtx {
    /// The instance's struct in `_plc_state` terms, with a final dot (`self->G1.`).
    pub prefix: String,
    /// The instance POU's first rung.
    pub rung0: u32,
    /// Its first loop counter.
    pub ctr0: u32,
}

fn is_condition(e: &Element) -> bool {
    match e {
        Element::Contact { .. } | Element::Compare { .. } => true,
        Element::Or(bs) => bs.iter().all(|b| b.iter().all(is_condition)),
        _ => false,
    }
}

fn and(pw: Pw, e: String) -> Pw {
    match pw {
        Pw::True => Pw::Expr(e),
        Pw::False => Pw::False,
        Pw::Expr(x) | Pw::Local(x) => Pw::Expr(format!("{} & {e}", lead(x))),
    }
}

/// The first operand of a `&` or `|` chain: a negation in parentheses (GCC's `-Wparentheses`
/// reads `!a & b` as a typo for `!(a & b)`; a later operand is not taken so).
fn lead(x: String) -> String {
    if x.starts_with('!') {
        format!("({x})")
    } else {
        x
    }
}

impl<'a> Body<'a> {
    pub(super) fn new(sh: &'a Shared<'a>, ret: &'static str, indent: usize) -> Body<'a> {
        Body {
            sh,
            locals: HashMap::new(),
            out: String::new(),
            indent,
            tmp: 0,
            ret,
            used_labels: Default::default(),
            inst: None,
            comments: true,
            rows: None,
            calls: Default::default(),
        }
    }

    /// A `_plc_state` lvalue (`self->x`) as this function names it.
    fn place(&self, e: &str) -> String {
        match &self.inst {
            None => e.to_string(),
            Some(c) => match e.strip_prefix(c.prefix.as_str()) {
                Some(rest) => format!("self->{rest}"),
                None => match e.strip_prefix("self->") {
                    Some(rest) => format!("_g->{rest}"),
                    None => e.to_string(),
                },
            },
        }
    }

    /// The program's state in this function.
    fn state(&self) -> &'static str {
        if self.inst.is_some() {
            "_g"
        } else {
            "self"
        }
    }

    /// Rung `r` as a fault names it (an index into `_plc_rung_ids`).
    fn rung_no(&self, r: RungId) -> String {
        match &self.inst {
            None => r.raw().to_string(),
            Some(c) if r.raw() == c.rung0 => "self->_rung0".to_string(),
            Some(c) => format!("self->_rung0 + {}", r.raw() - c.rung0),
        }
    }

    /// The test that charges `charge` rungs of the scan budget at rung `r` (`_plc_charge`;
    /// task 0 for a subroutine's rung: charged to the task that called it).
    fn charge(&self, r: RungId, charge: u32) -> String {
        let task = self.sh.budget_task[r.index()].map_or(0, |t| t + 1);
        let no = self.rung_no(r);
        format!("_plc_charge(ctx, {task}, {charge}, PLC_SCAN_BUDGET, {no})")
    }

    /// The number of rung `r`'s label (`_L<n>`).
    fn label_no(&self, r: u32) -> u32 {
        r - self.inst.as_ref().map_or(0, |c| c.rung0)
    }

    /// Writes one line at the current indentation (after the call of the rows before it).
    pub(super) fn line(&mut self, text: &str) {
        if let Some(call) = self.rows.as_mut().and_then(|r| r.take_call()) {
            self.raw_line(&call);
        }
        self.raw_line(text);
    }

    /// Writes the call of the run of rows not yet called, if any.
    pub(super) fn flush_rows(&mut self) {
        if let Some(call) = self.rows.as_mut().and_then(|r| r.take_call()) {
            self.raw_line(&call);
        }
    }

    fn raw_line(&mut self, text: &str) {
        for _ in 0..self.indent {
            self.out.push_str("    ");
        }
        self.out.push_str(text);
        self.out.push('\n');
    }

    fn fresh(&mut self, stem: &str) -> String {
        self.tmp += 1;
        format!("_{stem}{}", self.tmp)
    }

    pub(super) fn var(&self, v: VarId) -> String {
        match self.locals.get(&v) {
            Some(l) => l.clone(),
            None => self.place(&self.sh.vars[v.index()]),
        }
    }

    fn var_ref(&self, r: VarRef) -> String {
        match r.field {
            None => self.var(r.var),
            Some(f) => format!("{}.{}", self.var(r.var), f.name()),
        }
    }

    fn operand(&self, o: &Operand) -> String {
        match o {
            Operand::Var(r) => self.var_ref(*r),
            Operand::Const(v) => c_const(*v),
        }
    }

    /// Puts an expression power into a local.
    fn materialize(&mut self, pw: Pw) -> Pw {
        match pw {
            Pw::Expr(e) => {
                let l = self.fresh("p");
                self.line(&format!("bool {l} = {e};"));
                Pw::Local(l)
            }
            other => other,
        }
    }

    fn text(pw: &Pw) -> String {
        match pw {
            Pw::True => "1".into(),
            Pw::False => "0".into(),
            Pw::Expr(e) | Pw::Local(e) => e.clone(),
        }
    }

    /// `stmt` when powered (nothing without power).
    fn when(&mut self, pw: &Pw, stmt: &str) {
        match pw {
            Pw::True => self.line(stmt),
            Pw::False => {}
            p => {
                let c = Self::text(p);
                self.line(&format!("if ({c}) {stmt}"));
            }
        }
    }

    /// Emits `series` from power `pw`; returns the power out. `tail`: nothing reads the power
    /// out, so the last element need not keep it.
    fn series(&mut self, rung: RungId, series: &[Element], mut pw: Pw, tail: bool) -> PwOut {
        let n = series.len();
        let mut i = 0;
        while i < n {
            // An arithmetic chain into one variable (an n-input block) is one statement.
            let k = fold::arith_chain(&series[i..]).max(1);
            let last = tail && i + k == n;
            pw = match k {
                1 => self.element(rung, &series[i], pw, last),
                _ => self.arith_steps(rung, &series[i..i + k], pw, last),
            };
            i += k;
        }
        PwOut(pw)
    }

    /// `out := …` of one or more arithmetic steps into one variable, as one expression
    /// (`fold::arith_chain`).
    fn arith_steps(&mut self, rung: RungId, steps: &[Element], pw: Pw, last: bool) -> Pw {
        let pw = if last { pw } else { self.materialize(pw) };
        let mut value = String::new();
        let mut target = None;
        for e in steps {
            let Element::Arith { op, a, b, out } = e else {
                unreachable!("an arithmetic chain has only arithmetic steps")
            };
            let ty = self.sh.p.var(*out).ty;
            let a = match target {
                None => self.operand(a),
                // REAL and LREAL steps are infix: the running value in parentheses.
                Some(_) if ty.is_real() => format!("({value})"),
                Some(_) => value,
            };
            value = self.arith(rung, *op, &a, &self.operand(b), ty);
            target = Some(*out);
        }
        let out = target.expect("at least one step");
        let stmt = format!("{} = {value};", self.var(out));
        self.when(&pw, &stmt);
        pw
    }

    /// `out := MAX/MIN/LIMIT(…)` of an output branch with that shape, as one expression.
    fn extreme(&mut self, x: &fold::Extreme, pw: Pw) -> Pw {
        let pw = self.materialize(pw);
        let w = num_suffix(self.sh.p.var(x.out).ty);
        let mut value = self.operand(&x.first);
        for (pick, o) in &x.steps {
            let f = match pick {
                fold::Pick::Max => "max",
                fold::Pick::Min => "min",
            };
            value = format!("_plc_{f}_{w}({value}, {})", self.operand(o));
        }
        let stmt = format!("{} = {value};", self.var(x.out));
        self.when(&pw, &stmt);
        pw
    }

    fn element(&mut self, rung: RungId, e: &Element, pw: Pw, last: bool) -> Pw {
        let keep = |b: &mut Self, pw: Pw| if last { pw } else { b.materialize(pw) };
        match e {
            Element::Contact { var, kind } => {
                let v = self.var_ref(*var);
                match kind {
                    ContactKind::Normal => and(pw, v),
                    ContactKind::Negated => and(pw, negate(&v)),
                    ContactKind::Rising { memory } | ContactKind::Falling { memory } => {
                        let m = self.var(*memory);
                        if matches!(pw, Pw::False) {
                            // No power: only the memory is updated.
                            self.line(&format!("{m} = {v};"));
                            return Pw::False;
                        }
                        let l = self.fresh("e");
                        let pulse = if matches!(kind, ContactKind::Rising { .. }) {
                            format!("{v} & !{m}")
                        } else {
                            format!("(!{v}) & {m}")
                        };
                        // `(void)`: an OR with a TRUE branch needs no pulse but still updates.
                        self.line(&format!("bool {l} = {pulse}; (void){l};"));
                        self.line(&format!("{m} = {v};"));
                        and(pw, l)
                    }
                }
            }
            Element::Compare { op, a, b } => {
                let t = self.compare(super::spelling::cmp_symbol(*op), a, b);
                and(pw, t)
            }
            Element::Or(branches) => self.or(rung, branches, pw),
            Element::Coil { var, negated } => {
                let pw = keep(self, pw);
                let v = self.var(*var);
                let c = Self::text(&pw);
                let val = if *negated { negate(&c) } else { c };
                self.line(&format!("{v} = {val};"));
                pw
            }
            Element::Set(v) | Element::Reset(v) => {
                let pw = keep(self, pw);
                let set = matches!(e, Element::Set(_));
                let v = self.var(*v);
                // Without a branch: a set ORs the power in, a reset ANDs its negation (a
                // branch on an input that changes every scan is mispredicted half the time).
                match &pw {
                    Pw::True => self.line(&format!("{v} = {};", u8::from(set))),
                    Pw::False => {}
                    p if set => self.line(&format!("{v} |= {};", Self::text(p))),
                    p => self.line(&format!("{v} &= {};", negate(&Self::text(p)))),
                }
                pw
            }
            Element::Branch(branches) => {
                let text = |x: &fold::Extreme| self.sh.p.var(x.out).ty == Type::String;
                if let Some(x) = fold::extreme(branches).filter(|x| !text(x)) {
                    return self.extreme(&x, pw);
                }
                let pw = self.materialize(pw);
                for b in branches {
                    self.series(rung, b, pw.clone(), true);
                }
                pw
            }
            Element::Timer { kind, instance, pt } => {
                let f = match kind {
                    TimerKind::Ton => "_plc_ton",
                    TimerKind::Tof => "_plc_tof",
                    TimerKind::Tp => "_plc_tp",
                };
                let call = format!(
                    "{f}(&{}, ctx->now, {}, {}, {})",
                    self.var(*instance),
                    self.operand(pt),
                    Self::text(&pw),
                    u8::from(self.sh.p.dialect().timer_compares_after_edge())
                );
                self.boxed(call, last)
            }
            Element::Ctu {
                instance,
                pv,
                reset,
            }
            | Element::Ctd {
                instance,
                pv,
                load: reset,
            } => {
                let f = if matches!(e, Element::Ctu { .. }) {
                    "_plc_ctu"
                } else {
                    "_plc_ctd"
                };
                let call = format!(
                    "{f}(&{}, {}, {}, {}, {})",
                    self.var(*instance),
                    self.operand(pv),
                    Self::text(&pw),
                    self.operand(reset),
                    u8::from(self.sh.p.dialect().counters_stop_at_preset())
                );
                self.boxed(call, last)
            }
            Element::Bistable {
                kind,
                instance,
                reset,
            } => {
                let f = match kind {
                    BistableKind::SetDominant => "_plc_sr",
                    BistableKind::ResetDominant => "_plc_rs",
                };
                let call = format!(
                    "{f}(&{}, {}, {})",
                    self.var(*instance),
                    Self::text(&pw),
                    self.operand(reset)
                );
                self.boxed(call, last)
            }
            Element::Trigger { kind, instance } => {
                let f = match kind {
                    TriggerKind::Rising => "_plc_r_trig",
                    TriggerKind::Falling => "_plc_f_trig",
                };
                let call = format!("{f}(&{}, {})", self.var(*instance), Self::text(&pw));
                self.boxed(call, last)
            }
            Element::Ctud { instance, inputs } => {
                let call = format!(
                    "_plc_ctud(&{}, {}, {}, {}, {}, {}, {})",
                    self.var(*instance),
                    self.operand(&inputs.pv),
                    Self::text(&pw),
                    self.operand(&inputs.cd),
                    self.operand(&inputs.reset),
                    self.operand(&inputs.load),
                    u8::from(self.sh.p.dialect().counters_stop_at_preset())
                );
                self.boxed(call, last)
            }
            Element::Move { from, to } => {
                let pw = keep(self, pw);
                if *from
                    == Operand::Var(VarRef {
                        var: *to,
                        field: None,
                    })
                {
                    // A move of a variable onto itself changes nothing (and a box's Q local
                    // before it may have no other reader).
                    if let Pw::Local(l) = &pw {
                        self.line(&format!("(void){l};"));
                    }
                    return pw;
                }
                let stmt = format!("{} = {};", self.var(*to), self.operand(from));
                self.when(&pw, &stmt);
                pw
            }
            Element::Arith { .. } => self.arith_steps(rung, std::slice::from_ref(e), pw, last),
            Element::Function { func, args, out } => {
                let pw = keep(self, pw);
                let args: Vec<(String, Type)> = args
                    .iter()
                    .map(|a| (self.operand(a), self.operand_type(a).unwrap_or(Type::Bool)))
                    .collect();
                let ty = self.sh.p.var(*out).ty;
                let unit = self.sh.p.dialect().time_unit_ms();
                let value = super::functions::expr(*func, &args, ty, unit);
                let stmt = format!("{} = {value};", self.var(*out));
                self.when(&pw, &stmt);
                pw
            }
            Element::Jmp { target, .. } => {
                let goto = format!("goto _L{};", self.label_no(target.raw()));
                if !matches!(pw, Pw::False) {
                    self.used_labels.insert(self.label_no(target.raw()));
                }
                if target.raw() <= rung.raw() {
                    let ctr = self.counter(rung);
                    let no = self.rung_no(rung);
                    let charge =
                        self.charge(rung, plc_exec::budget::jump_back_charge(rung, *target));
                    let stmt = format!("if (_plc_loop_back(&{ctr}, ctx, {no}) && {charge}) {goto}");
                    self.when(&pw, &stmt);
                } else {
                    self.when(&pw, &goto);
                }
                Pw::False
            }
            Element::Ret | Element::End => {
                let r = self.ret;
                self.when(&pw, r);
                Pw::False
            }
            Element::RangeFault => {
                let stmt = format!("_plc_fault(ctx, {}, _PLC_INDEX_RANGE);", self.rung_no(rung));
                self.when(&pw, &stmt);
                pw
            }
            Element::Call { pou } => {
                let pw = self.materialize(pw);
                let g = self.state();
                let stmt = match self.sh.inst_of_pou[pou.index()] {
                    Some(k) => format!(
                        "{}(&{}, {g}, ctx);",
                        self.sh.inst_fns[k],
                        self.place(&self.sh.inst_paths[k])
                    ),
                    None => format!("{}({g}, ctx);", self.sh.pou_fns[pou.index()]),
                };
                let charge = self.charge(rung, plc_exec::budget::call_charge(self.sh.p, *pou));
                let stmt = format!("if ({charge}) {stmt}");
                self.when(&pw, &stmt);
                pw
            }
            Element::For { .. } | Element::Next { .. } => {
                unreachable!("FOR and NEXT are emitted by the rung")
            }
        }
    }

    /// A timer or counter call: its Q is the power out.
    fn boxed(&mut self, call: String, last: bool) -> Pw {
        if last {
            self.line(&format!("{call};"));
            return Pw::False;
        }
        let l = self.fresh("p");
        self.line(&format!("bool {l} = {call};"));
        self.calls.insert(l.clone());
        Pw::Local(l)
    }

    fn or(&mut self, rung: RungId, branches: &[Series], pw: Pw) -> Pw {
        let mut terms = Vec::new();
        if branches.iter().all(|b| b.iter().all(is_condition)) {
            // Every branch is pure but for edge memories, which nothing else reads: OR the
            // branches from TRUE and AND the power in.
            for b in branches {
                match self.series(rung, b, Pw::True, false).0 {
                    Pw::True => terms.push("1".to_string()),
                    Pw::False => {}
                    Pw::Expr(e) | Pw::Local(e) if e.contains(" & ") => terms.push(format!("({e})")),
                    Pw::Expr(e) | Pw::Local(e) => terms.push(e),
                }
            }
            if terms.iter().any(|t| t == "1") {
                return pw;
            }
            if terms.is_empty() {
                return Pw::False;
            }
            terms[0] = lead(std::mem::take(&mut terms[0]));
            return and(pw, format!("({})", terms.join(" | ")));
        }
        let pw = self.materialize(pw);
        for b in branches {
            let out = self.series(rung, b, pw.clone(), false).0;
            let out = self.materialize(out);
            terms.push(Self::text(&out));
        }
        terms[0] = lead(std::mem::take(&mut terms[0]));
        Pw::Expr(format!("({})", terms.join(" | ")))
    }

    /// `a op b` in type `ty` (operands as C text).
    fn arith(&self, rung: RungId, op: ArithOp, a: &str, b: &str, ty: Type) -> String {
        if ty.is_real() {
            let fmod = if ty == Type::Real { "fmodf" } else { "fmod" };
            return match op {
                ArithOp::Add => format!("{a} + {b}"),
                ArithOp::Sub => format!("{a} - {b}"),
                ArithOp::Mul => format!("{a} * {b}"),
                ArithOp::Div => format!("{a} / {b}"),
                ArithOp::Mod => format!("{fmod}({a}, {b})"),
            };
        }
        let w = num_suffix(ty);
        let name = op.name().to_ascii_lowercase();
        match op {
            ArithOp::Div | ArithOp::Mod => {
                format!("_plc_{name}_{w}({a}, {b}, ctx, {})", self.rung_no(rung))
            }
            _ => format!("_plc_{name}_{w}({a}, {b})"),
        }
    }

    /// `(a OP b)`; through `_plc_cmp` when a constant sits at its type's limit (where GCC's
    /// `-Wtype-limits` would call the test always true or false).
    fn compare(&self, sym: &str, a: &Operand, b: &Operand) -> String {
        if self.operand_type(a) == Some(Type::String) {
            // matiec's `__str_cmp`, as `plc_exec::strings::compare`.
            let (x, y) = (self.operand(a), self.operand(b));
            return format!("(_plc_str_cmp({x}, {y}) {sym} 0)");
        }
        let at_limit = |o: &Operand| match o {
            Operand::Const(v) => {
                let (lo, hi) = int_range(v.ty());
                v.as_i128().is_some_and(|i| i == lo || i == hi)
            }
            Operand::Var(_) => false,
        };
        let (x, y) = (self.operand(a), self.operand(b));
        let relational = sym != "==" && sym != "!=";
        if x == y || (relational && (at_limit(a) || at_limit(b))) {
            // GCC calls `x == x` tautological (it is not for a NaN) and a test against a type's
            // limit always true or false: a function of the runtime compares instead.
            let f = match sym {
                "==" => "eq",
                "!=" => "ne",
                "<" => "lt",
                "<=" => "le",
                ">" => "gt",
                _ => "ge",
            };
            let w = match self.operand_type(a) {
                Some(t @ (Type::Real | Type::Lreal)) => num_suffix(t),
                Some(t) if t.is_unsigned() || t.is_bits() => "u64",
                _ => "i64",
            };
            return format!("_plc_{f}_{w}({x}, {y})");
        }
        format!("({x} {sym} {y})")
    }

    fn operand_type(&self, o: &Operand) -> Option<Type> {
        match o {
            Operand::Const(v) => Some(v.ty()),
            Operand::Var(r) => match (self.sh.p.var(r.var).ty, r.field) {
                (Type::Fb(fb), Some(f)) => Field::lookup(fb, f.name()).map(|(_, t)| t),
                (t, _) => Some(t),
            },
        }
    }

    fn counter(&self, rung: RungId) -> String {
        let k = self.sh.counters[rung.index()].expect("a loop-back rung has a counter");
        match &self.inst {
            None => format!("self->_ctr[{k}]"),
            Some(c) => format!("_g->_ctr[self->_ctr0 + {}]", k - c.ctr0),
        }
    }

    /// One rung: its label if a jump targets it, a comment, its statements. A FOR head opens
    /// `if (power) { var = from; for (; var <= to; ) {`, which its NEXT rung closes.
    pub(super) fn rung(&mut self, r: RungId) {
        let rung = self.sh.p.rung(r);
        self.label(r);
        if self.inst.is_none() && self.locals.is_empty() {
            if let (Some(t), Some(row)) = (self.rows.as_mut(), &self.sh.rows[r.index()]) {
                if let Some(call) = t.push(row, &names::comment(&rung.id)) {
                    self.raw_line(&call);
                }
                return;
            }
        }
        if self.comments {
            self.line(&format!("/* {} */", names::comment(&rung.id)));
        }
        match rung.series.last() {
            Some(Element::For { var, bounds, .. }) => {
                let ForBounds { from, to } = &**bounds;
                let head = &rung.series[..rung.series.len() - 1];
                let pw = self.series(r, head, Pw::True, false).0;
                let v = self.var(*var);
                let test = self.compare(
                    "<=",
                    &Operand::Var(VarRef {
                        var: *var,
                        field: None,
                    }),
                    to,
                );
                let from = self.operand(from);
                match pw {
                    Pw::True => self.line("{"),
                    Pw::False => self.line("if (0) {"),
                    p => {
                        let c = Self::text(&p);
                        self.line(&format!("if ({c}) {{"))
                    }
                }
                self.indent += 1;
                self.line(&format!("{v} = {from};"));
                self.line(&format!("for (; {test}; ) {{"));
                self.indent += 1;
            }
            Some(Element::Next { head }) => {
                let Some(Element::For { var, .. }) = self.sh.p.rung(*head).series.last() else {
                    unreachable!("a NEXT's head rung ends in FOR")
                };
                let v = self.var(*var);
                let ctr = self.counter(r);
                let w = num_suffix(self.sh.p.var(*var).ty);
                let no = self.rung_no(r);
                let charge = self.charge(r, plc_exec::budget::next_charge(*head, r));
                self.line(&format!(
                    "if (!(_plc_loop_back(&{ctr}, ctx, {no}) && {charge})) break;"
                ));
                self.line(&format!("{v} = _plc_add_{w}({v}, 1);"));
                self.indent -= 1;
                self.line("}");
                self.indent -= 1;
                self.line("}");
            }
            _ => {
                self.series(r, &rung.series, Pw::True, true);
            }
        }
    }

    /// The label of rung `r`, if a jump targets it (removed by [`Body::finish`] if no emitted
    /// `goto` names it).
    pub(super) fn label(&mut self, r: RungId) {
        if self.sh.labels[r.index()] {
            let l = format!("_L{}: ;", self.label_no(r.raw()));
            self.line(&l);
        }
    }

    /// The function body, without the labels no `goto` names and without power locals nothing
    /// reads (a rung whose branches end without an output, a contact after a box: `-Wall
    /// -Werror` refuses an unused variable). Such a local's line goes, or becomes its call
    /// (`_plc_ton(…);`) when it holds a box's Q; a local read only by a removed one goes too.
    pub(super) fn finish(mut self) -> String {
        self.flush_rows();
        let mut lines: Vec<Option<Cow<str>>> = self.out.lines().map(|l| Some(l.into())).collect();
        let mut reads: HashMap<&str, usize> = HashMap::new();
        for id in power_locals(&self.out) {
            *reads.entry(id).or_default() += 1;
        }
        // Backwards: a local's readers come after its declaration, so they are settled first.
        for line in lines.iter_mut().rev() {
            let Some(text) = line.as_deref() else {
                continue;
            };
            let t = text.trim_start();
            let Some((name, init)) = t
                .strip_prefix("bool ")
                .and_then(|d| d.strip_suffix(';'))
                .and_then(|d| d.split_once(" = "))
            else {
                continue;
            };
            if reads.get(name) != Some(&1) {
                continue;
            }
            if self.calls.contains(name) {
                let indent = &text[..text.len() - t.len()];
                *line = Some(format!("{indent}{init};").into());
            } else {
                for id in power_locals(init) {
                    if let Some(n) = reads.get_mut(id) {
                        *n -= 1;
                    }
                }
                *line = None;
            }
        }
        let mut out = String::with_capacity(self.out.len());
        for line in lines.iter().flatten() {
            let t = line.trim_start();
            if let Some(n) = t.strip_prefix("_L").and_then(|x| x.strip_suffix(": ;")) {
                if n.parse().is_ok_and(|n: u32| !self.used_labels.contains(&n)) {
                    continue;
                }
            }
            out.push_str(line);
            out.push('\n');
        }
        out
    }

    /// The statements of `series` up to its final jump, and the power that takes the jump.
    pub(super) fn guard(&mut self, r: RungId, series: &[Element]) -> String {
        let body = match series.last() {
            Some(Element::Jmp { .. }) => &series[..series.len() - 1],
            _ => series,
        };
        let pw = self.series(r, body, Pw::True, false).0;
        Self::text(&pw)
    }
}

/// The power locals (`_p12`, as [`Body::materialize`] and [`Body::boxed`] name them) that `text`
/// names, once per occurrence. No other name has that form (a program's names that start with
/// `_` are encoded: `names`).
fn power_locals(text: &str) -> impl Iterator<Item = &str> {
    text.split(|c: char| !(c.is_ascii_alphanumeric() || c == '_'))
        .filter(|id| {
            id.strip_prefix("_p")
                .is_some_and(|n| !n.is_empty() && n.bytes().all(|b| b.is_ascii_digit()))
        })
}

/// The power at the end of a series.
pub(crate) struct PwOut(Pw);
