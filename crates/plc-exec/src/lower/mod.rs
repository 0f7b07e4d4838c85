//! Lowering: the model's element trees → one flat instruction array, once, at load.
//!
//! Every POU is a run of instructions: for each rung a [`Op::Rung`] marker then its elements in
//! evaluation order (or, where the rung's shape allows, one [`Op::Fused`] for the whole rung or
//! an [`Op::FusedHead`] for its marker and leading contacts: the `fuse` module), and after its
//! last rung an [`Op::EndPou`]. Falling through from one rung to
//! the next is just executing the next instruction. Jumps, calls and FOR exits carry
//! instruction indices ([`Pc`]), patched once all rungs are placed. Operands are byte addresses
//! ([`Addr`]) in the state: a variable's (from the [`Layout`]), or a constant's: constants live
//! in the state too, after the loop counters, written once by `Machine::initial_state` and
//! never again, so an operand is always a plain typed load (no constant pool, no tag bit).
//!
//! The state's memory is therefore: the layout's variables; from the next 64-byte line, one line
//! per loop counter (a `u64`); then the constants, each aligned to its width.
//!
//! The interpreter keeps the power flow in a register `p` (0 or 1) and the powers saved by
//! `or` and `branch` in a 64-bit stack `s` (an `or` uses two bits: its power in and the OR of
//! its branches so far; a `branch` one: its power in). Lowering refuses nesting deeper than that.

mod code;

pub use code::LowerError;
pub(crate) use code::*;

use super::fb::{CtudId, CtudPins};
use super::fuse::{self, FusedId, Tables};
use super::layout::{field_offset, type_align, Layout};
use super::line::LINE_BYTES;
use super::store::Addr;
use plc_model::*;

struct Lowerer<'p> {
    p: &'p Program,
    layout: &'p Layout,
    code: Code,
    /// (instruction, target rung) of jumps; (instruction, pou) of calls.
    jumps: Vec<(usize, RungId)>,
    calls: Vec<(usize, PouId)>,
    /// (loop, NEXT rung) to patch the exits.
    for_nexts: Vec<(ForId, RungId)>,
    /// The loop counter of each loop-back rung (see [`loop_counters`]).
    counter_of: Vec<Option<Addr>>,
    /// Where the next constant goes (past the loop counters).
    next_const: u64,
    /// The fused rungs' truth tables, shared by shape.
    tables: Tables,
    /// Whether to emit fused instructions.
    fuse: bool,
    depth: u32,
    max_depth: u32,
}

/// Whether `series` (of rung `rung`) holds a loop-back: a NEXT, or a jump to `rung` or an
/// earlier rung.
fn loops_back(rung: RungId, series: &[Element]) -> bool {
    series.iter().any(|e| match e {
        Element::Next { .. } => true,
        Element::Jmp { target, .. } => *target <= rung,
        Element::Or(bs) | Element::Branch(bs) => bs.iter().any(|b| loops_back(rung, b)),
        _ => false,
    })
}

/// The loop counters: one `u64` per loop-back rung, each on its own 64-byte line from the line
/// after the layout's variables (so that loops run by different workers of a parallel scan
/// never write one cache line), in rung order; and the end of the last one.
fn loop_counters(p: &Program, layout: &Layout) -> (Vec<(RungId, Addr)>, u64) {
    let mut next = layout.size().next_multiple_of(LINE_BYTES) as u64;
    let mut counters = Vec::new();
    for (r, rung) in p.rungs().iter_enumerated() {
        if loops_back(r, &rung.series) {
            counters.push((r, Addr(next.min(u32::MAX as u64) as u32)));
            next += LINE_BYTES as u64;
        }
    }
    (counters, next)
}

/// Lowers `p` with `layout`; `fuse` chooses the fused instructions (the `fuse` module) where a
/// rung allows them (off: only the general instructions, the reference they are tested against).
/// The code is not checked here: `raw::CheckedCode::new`, which the machine keeps it in, checks
/// what the interpreter's unchecked reads rely on.
pub(crate) fn lower(p: &Program, layout: &Layout, fuse: bool) -> Result<Code, LowerError> {
    if layout.var_count() != p.vars().len() {
        return Err(LowerError::LayoutMismatch {
            expected: p.vars().len(),
            found: layout.var_count(),
        });
    }
    let (counters, counters_end) = loop_counters(p, layout);
    let mut counter_of = vec![None; p.rungs().len()];
    for &(r, at) in &counters {
        counter_of[r.index()] = Some(at);
    }
    let mut l = Lowerer {
        p,
        layout,
        code: Code {
            ops: Vec::new(),
            consts: Vec::new(),
            fors: Vec::new(),
            ctuds: Vec::new(),
            funcs: Vec::new(),
            fused: Vec::new(),
            tables: Vec::new(),
            rung_op: vec![Pc::new(0); p.rungs().len()],
            for_of_head: vec![None; p.rungs().len()],
            pou_entry: Vec::with_capacity(p.pous().len()),
            counters,
            size: 0,
            dialect: p.dialect(),
        },
        jumps: Vec::new(),
        calls: Vec::new(),
        for_nexts: Vec::new(),
        counter_of,
        next_const: counters_end,
        tables: Tables::default(),
        fuse,
        depth: 0,
        max_depth: 0,
    };
    let mut pou_end = Vec::with_capacity(p.pous().len());
    for pou_id in p.pous().ids() {
        l.code.pou_entry.push(l.pc());
        for r in p.pou_rungs(pou_id) {
            let rung = &p.rungs()[r];
            l.code.rung_op[r.index()] = l.pc();
            let done = l.fused(r, &rung.series);
            if done == 0 {
                l.code.ops.push(Op::Rung { id: r });
            }
            l.depth = 0;
            l.max_depth = 0;
            l.series(r, &rung.series[done..]);
            if l.max_depth > 64 {
                return Err(LowerError::TooDeep {
                    rung: rung.id.clone(),
                    bits: l.max_depth,
                });
            }
        }
        pou_end.push(l.pc());
        l.code.ops.push(Op::EndPou);
    }
    // The whole state (and one more value past it) must have 32-bit addresses.
    if l.code.ops.len() >= u32::MAX as usize || l.next_const + 8 >= u32::MAX as u64 {
        return Err(LowerError::TooLarge);
    }
    l.code.size = l.next_const as u32;
    let Lowerer {
        mut code,
        jumps,
        calls,
        for_nexts,
        tables,
        ..
    } = l;
    code.tables = tables.tables;
    for (at, target) in jumps {
        let to = code.rung_op[target.index()];
        match &mut code.ops[at] {
            Op::Jmp { to: t } | Op::JmpBack { to: t, .. } => *t = to,
            _ => unreachable!("jump patch on a jump"),
        }
    }
    for (at, pou) in calls {
        if let Op::Call { to, .. } = &mut code.ops[at] {
            *to = code.pou_entry[pou.index()];
        }
    }
    for (f, next) in for_nexts {
        let pou = p.rung(next).pou;
        let after = next.raw() + 1;
        code.fors[f.index()].exit = if after < p.pou(pou).rungs.end {
            code.rung_op[after as usize]
        } else {
            pou_end[pou.index()]
        };
    }
    Ok(code)
}

impl Lowerer<'_> {
    /// The next instruction's index.
    fn pc(&self) -> Pc {
        Pc::new(self.code.ops.len() as u32)
    }

    /// The loop counter of loop-back rung `rung`.
    fn counter(&self, rung: RungId) -> Addr {
        self.counter_of[rung.index()].expect("a loop-back rung has a counter")
    }

    fn addr(&self, r: VarRef) -> Addr {
        var_addr(self.layout, r)
    }

    fn operand(&mut self, o: &Operand) -> Addr {
        match o {
            Operand::Var(r) => self.addr(*r),
            Operand::Const(v) => {
                // Equal constants of one type share their bytes (`Value` equality would merge
                // 0.0 with -0.0 and never NaN with itself: compare the stored bits).
                let same = |c: &Value| c.ty() == v.ty() && bits(*c) == bits(*v);
                if let Some(&(at, _)) = self.code.consts.iter().find(|(_, c)| same(c)) {
                    return at;
                }
                let align = type_align(v.ty()) as u64;
                let at = self.next_const.next_multiple_of(align);
                // A scalar's size is its alignment; a STRING's is its slot.
                self.next_const = at + align.max(super::layout::type_size(v.ty()) as u64);
                let at = Addr(at.min(u32::MAX as u64) as u32);
                self.code.consts.push((at, *v));
                at
            }
        }
    }

    fn operand_type(&self, o: &Operand) -> Type {
        match o {
            Operand::Const(v) => v.ty(),
            Operand::Var(r) => {
                let ty = self.p.var(r.var).ty;
                match (ty, r.field) {
                    (Type::Fb(fb), Some(f)) => {
                        Field::lookup(fb, f.name()).map_or(Type::Bool, |(_, t)| t)
                    }
                    (ty, _) => ty,
                }
            }
        }
    }

    fn push(&mut self, op: Op) {
        self.code.ops.push(op);
    }

    /// Emits a plain contact, fused with the previous instruction when that is a plain contact
    /// (or a pair). Sound because no jump or FOR ever targets a contact instruction.
    fn contact(&mut self, at: Addr, neg: u8) {
        let short = |a: Addr| u16::try_from(a.0).ok();
        match self.code.ops.last_mut() {
            Some(&mut Op::Contact { neg: n, at: a }) => {
                *self.code.ops.last_mut().unwrap() = Op::Contact2 {
                    neg: n | neg << 1,
                    a,
                    b: at,
                }
            }
            Some(&mut Op::Contact2 { neg: n, a, b }) => {
                *self.code.ops.last_mut().unwrap() = Op::Contact3 {
                    neg: n | neg << 2,
                    a,
                    b,
                    c: at,
                }
            }
            Some(&mut Op::Contact3 { neg: n, a, b, c }) => {
                match (short(a), short(b), short(c), short(at)) {
                    (Some(a), Some(b), Some(c), Some(d)) => {
                        *self.code.ops.last_mut().unwrap() = Op::ContactN {
                            n: 4,
                            neg: n | neg << 3,
                            s: [a, b, c, d, a, a],
                        }
                    }
                    _ => self.code.ops.push(Op::Contact { neg, at }),
                }
            }
            Some(Op::ContactN { n, neg: ng, s }) if *n < 6 && short(at).is_some() => {
                s[*n as usize] = at.0 as u16;
                *ng |= neg << *n;
                *n += 1;
            }
            _ => self.code.ops.push(Op::Contact { neg, at }),
        }
    }

    fn grow(&mut self, bits: u32) {
        self.depth += bits;
        self.max_depth = self.max_depth.max(self.depth);
    }

    fn series(&mut self, rung: RungId, series: &[Element]) {
        for e in series {
            self.element(rung, e);
        }
    }

    /// `or` / `branch`: the opening, the separators between branches and the closing.
    fn branches(&mut self, rung: RungId, branches: &[Series], ops: [Op; 3], bits: u32) {
        self.grow(bits);
        self.push(ops[0]);
        for (i, b) in branches.iter().enumerate() {
            if i > 0 {
                self.push(ops[1]);
            }
            self.series(rung, b);
        }
        self.push(ops[2]);
        self.depth -= bits;
    }

    /// Starts rung `rung` with a fused instruction if its shape allows (`fuse`): the whole rung
    /// as one [`Op::Fused`], or its leading contacts as an [`Op::FusedHead`]. Returns how many
    /// of its elements that took (0: none, and no instruction was emitted).
    fn fused(&mut self, rung: RungId, series: &[Element]) -> usize {
        if !self.fuse {
            return 0;
        }
        let (layout, tables) = (self.layout, &mut self.tables);
        let addr = |r: VarRef| var_addr(layout, r);
        let Some(start) = fuse::start(series, tables, addr, |v| layout.start(v)) else {
            return 0;
        };
        let f = FusedId::new(self.code.fused.len() as u32);
        self.code.fused.push(start.operands);
        let (id, table, neg) = (rung, start.table, start.neg);
        self.push(match start.whole {
            true => Op::Fused { id, f, table, neg },
            false => Op::FusedHead { id, f, table, neg },
        });
        start.taken
    }

    fn coil(&mut self, var: VarId, mode: u8) {
        let at = self.layout.start(var);
        self.push(Op::Coil { at, mode });
    }

    fn element(&mut self, rung: RungId, e: &Element) {
        match e {
            Element::Contact { var, kind } => {
                let at = self.addr(*var);
                let op = match kind {
                    ContactKind::Normal => return self.contact(at, 0),
                    ContactKind::Negated => return self.contact(at, 1),
                    ContactKind::Rising { memory } => Op::Rising {
                        at,
                        mem: self.layout.start(*memory),
                    },
                    ContactKind::Falling { memory } => Op::Falling {
                        at,
                        mem: self.layout.start(*memory),
                    },
                };
                self.push(op);
            }
            Element::Compare { op, a, b } if self.operand_type(a) == Type::String => {
                let (a, b) = (self.operand(a), self.operand(b));
                self.push(Op::StrCmp { op: *op, a, b });
            }
            Element::Compare { op, a, b } => {
                let num = num_of(self.operand_type(a));
                let (a, b) = (self.operand(a), self.operand(b));
                self.push(Op::Cmp { op: *op, num, a, b });
            }
            Element::Or(bs) => self.branches(rung, bs, [Op::OrOpen, Op::OrNext, Op::OrClose], 2),
            Element::Branch(bs) => {
                self.branches(rung, bs, [Op::BrOpen, Op::BrNext, Op::BrClose], 1)
            }
            Element::Coil { var, negated } => {
                self.coil(*var, if *negated { OUT_NCOIL } else { OUT_COIL })
            }
            Element::Set(v) => self.coil(*v, OUT_SET),
            Element::Reset(v) => self.coil(*v, OUT_RESET),
            Element::Timer { kind, instance, pt } => {
                let inst = self.layout.start(*instance);
                let pt = self.operand(pt);
                self.push(Op::Timer {
                    kind: *kind,
                    inst,
                    pt,
                });
            }
            Element::Ctu {
                instance,
                pv,
                reset,
            } => {
                let inst = self.layout.start(*instance);
                let (pv, reset) = (self.operand(pv), self.operand(reset));
                self.push(Op::Ctu { inst, pv, reset });
            }
            Element::Ctd { instance, pv, load } => {
                let inst = self.layout.start(*instance);
                let (pv, load) = (self.operand(pv), self.operand(load));
                self.push(Op::Ctd { inst, pv, load });
            }
            Element::Bistable {
                kind,
                instance,
                reset,
            } => {
                let inst = self.layout.start(*instance);
                let reset = self.operand(reset);
                self.push(Op::Bistable {
                    kind: *kind,
                    inst,
                    reset,
                });
            }
            Element::Trigger { kind, instance } => {
                let inst = self.layout.start(*instance);
                self.push(Op::Trigger { kind: *kind, inst });
            }
            Element::Ctud { instance, inputs } => {
                let inst = self.layout.start(*instance);
                let pins = CtudPins {
                    cd: self.operand(&inputs.cd),
                    reset: self.operand(&inputs.reset),
                    load: self.operand(&inputs.load),
                    pv: self.operand(&inputs.pv),
                };
                let id = CtudId::new(self.code.ctuds.len() as u32);
                self.code.ctuds.push(pins);
                self.push(Op::Ctud { inst, pins: id });
            }
            Element::Move { from, to } if self.p.var(*to).ty == Type::String => {
                let from = self.operand(from);
                let to = self.layout.start(*to);
                self.push(Op::StrMove { from, to });
            }
            Element::Move { from, to } => {
                let width = Width::of(self.p.var(*to).ty);
                let from = self.operand(from);
                let to = self.layout.start(*to);
                self.push(Op::Move { width, from, to });
            }
            Element::Arith { op, a, b, out } => {
                let num = num_of(self.p.var(*out).ty);
                let (a, b) = (self.operand(a), self.operand(b));
                let out = self.layout.start(*out);
                self.push(Op::Arith {
                    op: *op,
                    num,
                    a,
                    b,
                    out,
                });
            }
            Element::Function { func, args, out } => {
                let args = args
                    .iter()
                    .map(|a| (self.operand(a), operand_type(self.p, a)))
                    .collect();
                let call = FuncCall {
                    func: *func,
                    args,
                    out: self.layout.start(*out),
                    ty: self.p.var(*out).ty,
                };
                let id = FuncId::new(self.code.funcs.len() as u32);
                self.code.funcs.push(call);
                self.push(Op::Func { call: id });
            }
            Element::Jmp { target, .. } => {
                self.jumps.push((self.code.ops.len(), *target));
                if *target <= rung {
                    let ctr = self.counter(rung);
                    let charge = crate::budget::jump_back_charge(rung, *target);
                    self.push(Op::JmpBack {
                        to: Pc::new(0),
                        ctr,
                        charge,
                    });
                } else {
                    self.push(Op::Jmp { to: Pc::new(0) });
                }
            }
            Element::Ret => self.push(Op::Ret),
            Element::RangeFault => self.push(Op::RangeFault),
            Element::End => self.push(Op::End),
            Element::Call { pou } => {
                self.calls.push((self.code.ops.len(), *pou));
                let charge = crate::budget::call_charge(self.p, *pou);
                self.push(Op::Call {
                    to: Pc::new(0),
                    charge,
                });
            }
            Element::For { var, bounds, next } => {
                let f = ForId::new(self.code.fors.len() as u32);
                let (from, to) = (self.operand(&bounds.from), self.operand(&bounds.to));
                let test = Pc::new(self.pc().raw() + 1);
                self.code.fors.push(ForLoop {
                    var: self.layout.start(*var),
                    num: num_of(self.p.var(*var).ty),
                    from,
                    to,
                    test,
                    exit: Pc::new(0),
                    head: rung,
                    ctr: Addr(0),
                    charge: crate::budget::next_charge(rung, *next),
                });
                self.code.for_of_head[rung.index()] = Some(f);
                self.for_nexts.push((f, *next));
                self.push(Op::For { f });
                self.push(Op::ForTest { f });
            }
            Element::Next { head } => {
                // FOR heads come before their NEXT, so the head is already lowered.
                let f = self.code.for_of_head[head.index()]
                    .expect("the model puts a FOR head before its NEXT");
                self.code.fors[f.index()].ctr = self.counter(rung);
                self.push(Op::Next { f });
            }
        }
    }
}

/// The address of a variable or instance field.
fn var_addr(layout: &Layout, r: VarRef) -> Addr {
    layout.start(r.var).offset(r.field.map_or(0, field_offset))
}

/// The type of an operand.
fn operand_type(p: &Program, o: &Operand) -> Type {
    match o {
        Operand::Const(v) => v.ty(),
        Operand::Var(r) => match (p.var(r.var).ty, r.field) {
            (Type::Fb(fb), Some(f)) => Field::lookup(fb, f.name()).map_or(Type::Bool, |(_, t)| t),
            (t, _) => t,
        },
    }
}

/// The stored bits of a scalar (to tell constants apart).
fn bits(v: Value) -> u64 {
    v.to_bits()
}
