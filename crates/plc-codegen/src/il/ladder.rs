//! Ladder rungs → S7-200 STL networks: the series/parallel element tree of each rung is walked
//! left to right with the logic stack holding the power (Zhou & Zhang 2015 for the stack
//! shapes; the S7-200 system manual's STL forms of each LAD element).
//!
//! A series loads its first condition (LD/LDN, LDW= …, `LD x` + `EU` for an edge contact) and
//! ANDs the rest (A/AN, AW= …); an `or` in first place is its branches joined by O/ON or OLD,
//! elsewhere it is loaded and joined by ALD. Outputs act on the top of the stack: `=`, `S x, 1`,
//! `R x, 1`, a negated coil `NOT`/`=`/`NOT`; output branches are LPS/LRD/LPP (the power after
//! the branch element is one more branch). A timer or counter in the middle of a series is
//! followed by `LD T`: its Q is the power from there on. A series that starts with an output
//! loads `SM0.0` (always on). Arithmetic is the S7-200 two-operand form: `out := a op b` is
//! `MOVW a, out` then `+I b, out`.
//!
//! `out := a - out`, `out := a / out` and MOD go through a scratch word of the result's type,
//! declared by the generator (`Names::scratch`).
//!
//! Not here: TP timers (the S7-200 has TON, TONR and TOF; a TP built of them would not be the
//! instance with its Q and ET), `b := a MOD b`, BOOL moves, a timer's Q feeding
//! more elements inside an output branch: each one error naming the rung.

use super::{check, IlError, Names, Net};
use plc_model::*;

/// The networks of a ladder POU: one per rung, titled with the rung id.
pub(super) fn pou(p: &Program, names: &Names, pou: PouId) -> Result<Vec<(String, Net)>, IlError> {
    let kind = p.pou(pou).kind;
    let mut nets = Vec::new();
    for r in p.pou_rungs(pou) {
        let rung = p.rung(r);
        let place = format!("rung {}", rung.id);
        let mut e = Emit {
            names,
            net: Net::default(),
            place: &place,
            kind,
        };
        if let Some(l) = &rung.label {
            e.net.emit("LBL", &[l], 0);
        }
        e.series(&rung.series, false, false)?;
        check(&place, &e.net)?;
        nets.push((rung.id.clone(), e.net));
    }
    Ok(nets)
}

struct Emit<'a> {
    names: &'a Names<'a>,
    net: Net,
    place: &'a str,
    /// The POU's kind, for how a RET is written.
    kind: PouKind,
}

fn word_suffix(ty: Type) -> Option<&'static str> {
    match ty {
        Type::Int => Some("W"),
        Type::Dint | Type::Time => Some("D"),
        Type::Real => Some("R"),
        _ => None,
    }
}

/// The S7-200 instruction of a bitwise function of an INT or DINT, and the move of its type:
/// ANDW/ORW/XORW/INVW and the D forms.
fn bitwise_instruction(func: Function, ty: Type) -> Option<(&'static str, &'static str)> {
    let word = match ty {
        Type::Int => true,
        Type::Dint => false,
        _ => return None,
    };
    let (w, d) = match func {
        Function::And => ("ANDW", "ANDD"),
        Function::Or => ("ORW", "ORD"),
        Function::Xor => ("XORW", "XORD"),
        Function::Not => ("INVW", "INVD"),
        _ => return None,
    };
    Some(if word { (w, "MOVW") } else { (d, "MOVD") })
}

impl Emit<'_> {
    fn fail<T>(&self, message: impl Into<String>) -> Result<T, IlError> {
        Err(IlError {
            place: self.place.to_string(),
            message: message.into(),
        })
    }

    fn operand_type(&self, o: &Operand) -> Type {
        match o {
            Operand::Const(v) => v.ty(),
            Operand::Var(r) => match r.field {
                None => self.names.p.var(r.var).ty,
                Some(Field::Q | Field::Q1 | Field::Qu | Field::Qd) => Type::Bool,
                Some(Field::Et | Field::Pt) => Type::Time,
                Some(Field::Cv | Field::Pv) => Type::Int,
            },
        }
    }

    /// Emits `series`; `loaded`: a value is on the stack already (the series ANDs into it);
    /// `in_branch`: the series is one output branch (it must leave the stack as it found it).
    fn series(&mut self, series: &[Element], loaded: bool, in_branch: bool) -> Result<(), IlError> {
        let mut loaded = loaded;
        let base = self.net.depth;
        for (i, e) in series.iter().enumerate() {
            let rest = &series[i + 1..];
            if let Some(done) = self.condition(e, loaded)? {
                loaded = done;
                continue;
            }
            if !loaded && !matches!(e, Element::Next { .. }) {
                self.net.emit("LD", &["SM0.0"], 1);
                loaded = true;
            }
            self.action(e, rest)?;
            if let Element::Branch(_) = e {
                break;
            }
        }
        if in_branch && self.net.depth > base {
            return self.fail("a timer's or counter's Q feeds more elements inside an output branch: no S7-200 form (not yet: move them to a rung of their own reading the Q)");
        }
        Ok(())
    }

    /// Emits a condition element (`None` if `e` is not one): loads it, or ANDs it into the value.
    fn condition(&mut self, e: &Element, loaded: bool) -> Result<Option<bool>, IlError> {
        match e {
            Element::Contact { var, kind } => {
                let name = self.names.bit(*var);
                match kind {
                    ContactKind::Normal => self.load_or(loaded, "LD", "A", &name),
                    ContactKind::Negated => self.load_or(loaded, "LDN", "AN", &name),
                    ContactKind::Rising { .. } | ContactKind::Falling { .. } => {
                        self.net.emit("LD", &[&name], 1);
                        let edge = if matches!(kind, ContactKind::Rising { .. }) {
                            "EU"
                        } else {
                            "ED"
                        };
                        self.net.emit(edge, &[], 0);
                        if loaded {
                            self.net.emit("ALD", &[], -1);
                        }
                    }
                }
            }
            Element::Compare { op, a, b } => {
                let ty = self.operand_type(a);
                let Some(sfx) = word_suffix(ty) else {
                    return self.fail(format!("a compare of {ty} has no S7-200 instruction"));
                };
                let (la, lb) = (self.names.operand(a), self.names.operand(b));
                let sym = op.symbol();
                let (load, and) = (format!("LD{sfx}{sym}"), format!("A{sfx}{sym}"));
                self.load_or(loaded, &load, &and, &format!("{la}, {lb}"));
            }
            Element::Or(branches) => {
                if loaded {
                    self.or(branches)?;
                    self.net.emit("ALD", &[], -1);
                } else {
                    self.or(branches)?;
                }
            }
            _ => return Ok(None),
        }
        Ok(Some(true))
    }

    fn load_or(&mut self, loaded: bool, load: &str, and: &str, arg: &str) {
        if loaded {
            self.net.emit(and, &[arg], 0);
        } else {
            self.net.emit(load, &[arg], 1);
        }
    }

    /// Pushes the OR of `branches` (each a series of conditions).
    fn or(&mut self, branches: &[Series]) -> Result<(), IlError> {
        for (k, b) in branches.iter().enumerate() {
            if k > 0 {
                if let [single] = &b[..] {
                    if self.or_single(single) {
                        continue;
                    }
                }
            }
            let mut loaded = false;
            for e in b {
                loaded = self.condition(e, loaded)?.unwrap_or(loaded);
            }
            if !loaded {
                self.net.emit("LD", &["SM0.0"], 1);
            }
            if k > 0 {
                self.net.emit("OLD", &[], -1);
            }
        }
        Ok(())
    }

    /// ORs a single plain contact or compare into the top (`O x`, `ON x`, `OW= a, b`).
    fn or_single(&mut self, e: &Element) -> bool {
        match e {
            Element::Contact {
                var,
                kind: kind @ (ContactKind::Normal | ContactKind::Negated),
            } => {
                let op = if *kind == ContactKind::Normal {
                    "O"
                } else {
                    "ON"
                };
                let name = self.names.bit(*var);
                self.net.emit(op, &[&name], 0);
                true
            }
            Element::Compare { op, a, b } => match word_suffix(self.operand_type(a)) {
                Some(sfx) => {
                    let arg = format!("{}, {}", self.names.operand(a), self.names.operand(b));
                    self.net.emit(&format!("O{sfx}{}", op.symbol()), &[&arg], 0);
                    true
                }
                None => false,
            },
            _ => false,
        }
    }

    /// Emits an output, box or control element on the value on top of the stack; `rest` is
    /// what follows it in its series.
    fn action(&mut self, e: &Element, rest: &[Element]) -> Result<(), IlError> {
        let n = self.names;
        match e {
            Element::Coil { var, negated } => {
                if *negated {
                    self.net.emit("NOT", &[], 0);
                    self.net.emit("=", &[n.var(*var)], 0);
                    self.net.emit("NOT", &[], 0);
                } else {
                    self.net.emit("=", &[n.var(*var)], 0);
                }
            }
            Element::Set(v) => self.net.emit("S", &[n.var(*v), "1"], 0),
            Element::Reset(v) => self.net.emit("R", &[n.var(*v), "1"], 0),
            Element::Branch(branches) => self.branch(branches, rest)?,
            Element::Timer { kind, instance, pt } => {
                let op = match kind {
                    TimerKind::Ton => "TON",
                    TimerKind::Tof => "TOF",
                    TimerKind::Tp => {
                        return self.fail(
                            "TP has no S7-200 instruction (the S7-200 has TON, TONR and TOF)",
                        )
                    }
                };
                self.net.emit(op, &[n.var(*instance), &n.operand(pt)], 0);
                self.q_after(*instance, rest);
            }
            Element::Ctu {
                instance,
                pv,
                reset,
            } => self.counter("CTU", *instance, pv, reset, rest),
            Element::Ctd { instance, pv, load } => self.counter("CTD", *instance, pv, load, rest),
            Element::Move { from, to } => {
                let op = match n.p.var(*to).ty {
                    Type::Int => "MOVW",
                    Type::Dint | Type::Time => "MOVD",
                    Type::Real => "MOVR",
                    ty => return self.fail(format!("a MOVE of {ty} has no S7-200 instruction")),
                };
                self.net.emit(op, &[&n.operand(from), n.var(*to)], 0);
            }
            Element::Arith { op, a, b, out } => self.arith(*op, a, b, *out)?,
            Element::Function { func, args, out } => self.function(*func, args, *out)?,
            Element::Jmp { label, .. } => self.net.emit("JMP", &[label], 0),
            Element::Ret => match self.kind {
                PouKind::Main => self.net.emit("END", &[], 0),
                PouKind::Subroutine => self.net.emit("CRET", &[], 0),
                PouKind::Interrupt => self.net.emit("CRETI", &[], 0),
            },
            Element::End => self.net.emit("END", &[], 0),
            Element::RangeFault => {
                return self.fail(
                    "an index-range fault (an array subscript outside its bounds) has no S7-200 instruction",
                )
            }
            Element::Call { pou } => self.net.emit("CALL", &[&n.p.pou(*pou).name], 0),
            Element::For { var, bounds, .. } => self.net.emit(
                "FOR",
                &[n.var(*var), &n.operand(&bounds.from), &n.operand(&bounds.to)],
                0,
            ),
            Element::Next { .. } => self.net.emit("NEXT", &[], 0),
            Element::Bistable { .. } | Element::Trigger { .. } | Element::Ctud { .. } => {
                return self.fail(
                    "SR, RS, R_TRIG, F_TRIG and CTUD boxes have no S7-200 instruction (write them with S/R, EU/ED and CTUD counters by hand)",
                )
            }
            Element::Contact { .. } | Element::Compare { .. } | Element::Or(_) => {
                unreachable!("conditions are emitted by `condition`")
            }
        }
        Ok(())
    }

    /// After a timer or counter with more elements after it: its Q is the power from here.
    fn q_after(&mut self, instance: VarId, rest: &[Element]) {
        if !rest.is_empty() {
            self.net.emit("LD", &[self.names.var(instance)], 1);
        }
    }

    fn counter(&mut self, op: &str, inst: VarId, pv: &Operand, aux: &Operand, rest: &[Element]) {
        match aux {
            Operand::Const(Value::Bool(true)) => self.net.emit("LD", &["SM0.0"], 1),
            Operand::Const(_) => self.net.emit("LDN", &["SM0.0"], 1),
            Operand::Var(r) => {
                let bit = self.names.bit(*r);
                self.net.emit("LD", &[&bit], 1)
            }
        }
        let pv = self.names.operand(pv);
        self.net.emit(op, &[self.names.var(inst), &pv], -1);
        self.q_after(inst, rest);
    }

    /// `out := a op b` in the S7-200's two-operand form (`+I IN, OUT` is `OUT := OUT + IN`):
    /// `MOVW a, out` then `+I b, out`, or `+I b, out` alone when `a` is `out`. `out := a - out`
    /// and `out := a / out` go through the scratch word `s` of out's type (`MOVW a, s`,
    /// `-I out, s`, `MOVW s, out`); a MOD too, since the S7-200 has no remainder instruction
    /// that plc-deps models (its DIV leaves the remainder in the high word of a double word):
    /// [`Emit::modulo`].
    fn arith(&mut self, op: ArithOp, a: &Operand, b: &Operand, out: VarId) -> Result<(), IlError> {
        let n = self.names;
        let ty = n.p.var(out).ty;
        let (sfx, mov) = match ty {
            Type::Int => ("I", "MOVW"),
            Type::Dint | Type::Time => ("D", "MOVD"),
            Type::Real => ("R", "MOVR"),
            _ => return self.fail(format!("arithmetic on {ty} has no S7-200 instruction")),
        };
        let sym = match op {
            ArithOp::Add => "+",
            ArithOp::Sub => "-",
            ArithOp::Mul => "*",
            ArithOp::Div => "/",
            ArithOp::Mod => return self.modulo(a, b, out, sfx, mov),
        };
        let is_out =
            |o: &Operand| matches!(o, Operand::Var(r) if r.var == out && r.field.is_none());
        let instr = format!("{sym}{sfx}");
        let target = n.var(out);
        if is_out(a) {
            self.net.emit(&instr, &[&n.operand(b), target], 0);
        } else if is_out(b) && matches!(op, ArithOp::Sub | ArithOp::Div) {
            let s = n.scratch(ty);
            self.net.emit(mov, &[&n.operand(a), s], 0);
            self.net.emit(&instr, &[target, s], 0);
            self.net.emit(mov, &[s, target], 0);
        } else if is_out(b) {
            self.net.emit(&instr, &[&n.operand(a), target], 0);
        } else {
            self.net.emit(mov, &[&n.operand(a), target], 0);
            self.net.emit(&instr, &[&n.operand(b), target], 0);
        }
        Ok(())
    }

    /// A standard function box: the S7-200 instruction where one computes exactly what the
    /// model does (AND, OR, XOR, NOT of an INT or DINT: [`Emit::bitwise`]; SQRT, LN, EXP, SIN,
    /// COS, TAN `IN, OUT`; SLW/SRW/RLW/RRW and the D forms
    /// `OUT, N` after a move of IN for a constant N in 0..=255, the byte count S7-200 takes;
    /// I_DI, DI_R, ROUND and TRUNC `IN, OUT`); anything else is an error naming the function.
    fn function(&mut self, func: Function, args: &[Operand], out: VarId) -> Result<(), IlError> {
        let n = self.names;
        let ty = n.p.var(out).ty;
        let target = n.var(out);
        if let Some((instr, mov)) = bitwise_instruction(func, ty) {
            self.bitwise(instr, mov, args, out);
            return Ok(());
        }
        let unary = match func {
            Function::Sqrt => Some("SQRT"),
            Function::Ln => Some("LN"),
            Function::Exp => Some("EXP"),
            Function::Sin => Some("SIN"),
            Function::Cos => Some("COS"),
            Function::Tan => Some("TAN"),
            Function::Convert {
                from: Type::Int,
                to: Type::Dint,
            } => Some("I_DI"),
            Function::Convert {
                from: Type::Dint,
                to: Type::Real,
            } => Some("DI_R"),
            Function::Convert {
                from: Type::Real,
                to: Type::Dint,
            } => Some("ROUND"),
            Function::Trunc if ty == Type::Dint => Some("TRUNC"),
            _ => None,
        };
        if let Some(instr) = unary {
            self.net.emit(instr, &[&n.operand(&args[0]), target], 0);
            return Ok(());
        }
        if func == super::INT_TO_REAL {
            // Exact: every INT is a DINT, and every DINT of INT's range a REAL.
            let s = n.scratch(Type::Dint);
            self.net.emit("I_DI", &[&n.operand(&args[0]), s], 0);
            self.net.emit("DI_R", &[s, target], 0);
            return Ok(());
        }
        let shift = match (func, ty) {
            (Function::Shl, Type::Int) => Some(("SLW", "MOVW")),
            (Function::Shr, Type::Int) => Some(("SRW", "MOVW")),
            (Function::Rol, Type::Int) => Some(("RLW", "MOVW")),
            (Function::Ror, Type::Int) => Some(("RRW", "MOVW")),
            (Function::Shl, Type::Dint) => Some(("SLD", "MOVD")),
            (Function::Shr, Type::Dint) => Some(("SRD", "MOVD")),
            (Function::Rol, Type::Dint) => Some(("RLD", "MOVD")),
            (Function::Ror, Type::Dint) => Some(("RRD", "MOVD")),
            _ => None,
        };
        let count = match args.get(1) {
            Some(Operand::Const(Value::Int(k))) => Some(*k as i64),
            Some(Operand::Const(Value::Dint(k))) => Some(*k as i64),
            _ => None,
        };
        match (shift, count) {
            (Some((instr, mov)), Some(k)) if (0..=255).contains(&k) => {
                let is_out = matches!(&args[0], Operand::Var(r) if r.var == out && r.field.is_none());
                if !is_out {
                    self.net.emit(mov, &[&n.operand(&args[0]), target], 0);
                }
                self.net.emit(instr, &[target, &k.to_string()], 0);
                Ok(())
            }
            (Some(_), _) => self.fail(format!(
                "{} with a count that is not a constant 0..255 is not expressible in S7-200 IL (its shifts take a byte count)",
                func.name()
            )),
            // A conversion's name says both types; MUX is named with the type it selects
            // (its first input is the selector K); any other function with the type of what
            // it is given.
            _ if matches!(func, Function::Convert { .. }) => self.fail(format!(
                "{} is not expressible in S7-200 IL",
                func.name()
            )),
            _ if matches!(func, Function::Mux) => self.fail(format!(
                "{} of {ty} is not expressible in S7-200 IL",
                func.name()
            )),
            _ => self.fail(format!(
                "{} of {} is not expressible in S7-200 IL",
                func.name(),
                args.first().map_or(ty, |a| self.operand_type(a))
            )),
        }
    }

    /// `out := IN1 op IN2 op …` in the S7-200's two-operand form (`ANDW IN1, OUT` is
    /// `OUT := IN1 AND OUT`): the operation is commutative, so an input that is `out` itself
    /// goes first and needs no move (`ANDW a, out` for `out := a AND out`); otherwise
    /// `MOVW IN1, out`, then `ANDW INk, out` for each further input. NOT: `MOVW IN, out`,
    /// `INVW out`.
    fn bitwise(&mut self, instr: &str, mov: &str, args: &[Operand], out: VarId) {
        let n = self.names;
        let target = n.var(out);
        let is_out =
            |a: &Operand| matches!(a, Operand::Var(r) if r.var == out && r.field.is_none());
        let first = args.iter().position(is_out).unwrap_or(0);
        if !is_out(&args[first]) {
            self.net.emit(mov, &[&n.operand(&args[first]), target], 0);
        }
        if instr.starts_with("INV") {
            self.net.emit(instr, &[target], 0);
            return;
        }
        for (i, a) in args.iter().enumerate() {
            if i != first {
                self.net.emit(instr, &[&n.operand(a), target], 0);
            }
        }
    }

    /// `out := a MOD b` as `a - (a / b) * b` (DIV truncates, so the remainder takes the sign of
    /// `a`, as MOD does), through the scratch word `s`: `MOVW a, s`, `/I b, s`, `*I b, s`,
    /// `MOVW a, out`, `-I s, out`. The `/I` faults on a zero `b` as the MOD does, once; a
    /// variable `b` then needs `out := 0` (`a - 0` is `a`): `LPS`, `AW= b, 0`, `MOVW 0, out`,
    /// `LPP`. Wrap-around: only `-32768 / -1` overflows, and `-32768 - -32768` gives the 0 it
    /// should.
    fn modulo(
        &mut self,
        a: &Operand,
        b: &Operand,
        out: VarId,
        sfx: &str,
        mov: &str,
    ) -> Result<(), IlError> {
        let n = self.names;
        let ty = n.p.var(out).ty;
        let target = n.var(out);
        if ty == Type::Real {
            // The loader refuses MOD of REAL (IEC 61131-3: ANY_INT); kept as an error here.
            return self.fail("MOD of REAL has no S7-200 instruction");
        }
        let b_var = matches!(b, Operand::Var(_));
        if matches!(b, Operand::Var(r) if r.var == out && r.field.is_none()) {
            return self.fail(format!(
                "`{target} := {} MOD {target}` has no S7-200 form (the zero test of the divisor would read the result: write the result to another variable)",
                n.operand(a)
            ));
        }
        let s = n.scratch(ty);
        let (la, lb) = (n.operand(a), n.operand(b));
        self.net.emit(mov, &[&la, s], 0);
        self.net.emit(&format!("/{sfx}"), &[&lb, s], 0);
        self.net.emit(&format!("*{sfx}"), &[&lb, s], 0);
        if !matches!(a, Operand::Var(r) if r.var == out && r.field.is_none()) {
            self.net.emit(mov, &[&la, target], 0);
        }
        self.net.emit(&format!("-{sfx}"), &[s, target], 0);
        let zero = matches!(b, Operand::Const(Value::Int(0) | Value::Dint(0)));
        if zero {
            // A constant zero divisor: the `/` faulted; the MOD gives 0.
            self.net.emit(mov, &["0", target], 0);
        } else if b_var {
            let cmp = word_suffix(ty).expect("an integer type");
            self.net.lps();
            self.net
                .emit(&format!("A{cmp}="), &[&format!("{lb}, 0")], 0);
            self.net.emit(mov, &["0", target], 0);
            self.net.lpp();
        }
        Ok(())
    }

    /// Output branches: LPS, the first, LRD, …, LPP, the last; what follows the branch element
    /// in its series is one more branch (it gets the same power).
    fn branch(&mut self, branches: &[Series], rest: &[Element]) -> Result<(), IlError> {
        let mut all: Vec<&[Element]> = branches.iter().map(|b| &b[..]).collect();
        if !rest.is_empty() {
            all.push(rest);
        }
        let k = all.len();
        if k == 1 {
            return self.series(all[0], true, false);
        }
        for (i, b) in all.iter().enumerate() {
            match i {
                0 => self.net.lps(),
                _ if i + 1 == k => self.net.lpp(),
                _ => self.net.lrd(),
            }
            let last = i + 1 == k;
            self.series(b, true, !last)?;
        }
        Ok(())
    }
}
