//! Lowering: the model's element trees → one flat instruction array, once, at load.
//!
//! Every POU is a run of instructions: for each rung a [`Op::Rung`] marker then its elements in
//! evaluation order, and after its last rung an [`Op::EndPou`]. Falling through from one rung to
//! the next is just executing the next instruction. Jumps, calls and FOR exits carry
//! instruction indices, patched once all rungs are placed. Operands are slot indices, or (high
//! bit set) indices into a constant pool of already encoded values.
//!
//! The interpreter keeps the power flow in a register `p` (0 or 1) and the powers saved by
//! `or` and `branch` in a 64-bit stack `s` (an `or` uses two bits: its power in and the OR of
//! its branches so far; a `branch` one: its power in). Lowering refuses nesting deeper than that.

use super::layout::{field_offset, Layout};
use super::value::encode;
use crate::model::*;

/// Output modes of [`Op::Coil`]: bit 0 = the value written when powered, bit 1 = no write when
/// unpowered (set/reset), bit 2 = the value written when unpowered otherwise. One instruction
/// for every output keeps the dispatch after a rung's conditions uniform (set/reset among coils
/// made it mispredict: −15 % per rung on generated programs).
pub(crate) const OUT_COIL: u32 = 0b001;
pub(crate) const OUT_NCOIL: u32 = 0b100;
pub(crate) const OUT_SET: u32 = 0b011;
pub(crate) const OUT_RESET: u32 = 0b010;

/// Marks an operand as an index into the constant pool.
pub(crate) const CONST: u32 = 1 << 31;

/// Numeric representation of an arithmetic or FOR variable.
#[derive(Copy, Clone, Debug, PartialEq, Eq)]
pub(crate) enum Num {
    /// INT: wraps at 16 bits.
    I16,
    /// DINT, TIME: wrap at 32 bits.
    I32,
    /// REAL.
    F32,
}

impl Num {
    fn of(ty: Type) -> Num {
        match ty {
            Type::Int => Num::I16,
            Type::Real => Num::F32,
            _ => Num::I32,
        }
    }
}

/// One instruction. Small (16 bytes) and `Copy`; fields are slot indices (`u32`), operands
/// (`u32`, slot or [`CONST`]-marked pool index) and instruction indices.
#[derive(Copy, Clone, Debug)]
pub(crate) enum Op {
    /// Start of a rung: leave if the rung is outside the region being run; power := TRUE.
    Rung { id: u32 },
    /// Contact on a BOOL slot: `p &= slot ^ neg` (`neg` 0 or 1).
    Contact { neg: u8, slot: u32 },
    /// Two consecutive contacts (negation bits 0 and 1 of `neg`).
    Contact2 { neg: u8, a: u32, b: u32 },
    /// Three consecutive contacts (negation bits 0, 1 and 2 of `neg`).
    Contact3 { neg: u8, a: u32, b: u32, c: u32 },
    /// Four to six consecutive contacts on slots below 2^16 (negation bit k for contact k): one
    /// dispatch and 16 bytes for what is most of a typical rung. Entries past `n` repeat `s[0]`
    /// (a slot the rung reads anyway) and are masked out.
    ContactN { n: u8, neg: u8, s: [u16; 6] },
    /// Rising-edge contact with its memory slot.
    Rising { slot: u32, mem: u32 },
    /// Falling-edge contact with its memory slot.
    Falling { slot: u32, mem: u32 },
    /// Compare of two integer operands (INT, DINT, TIME: all sign-extended, compared as i64).
    CmpInt { op: CmpOp, a: u32, b: u32 },
    /// Compare of two REAL operands.
    CmpReal { op: CmpOp, a: u32, b: u32 },
    /// `or`: push power in and an empty OR.
    OrOpen,
    /// `or`, between branches: OR in this branch's power, restart from the power in.
    OrNext,
    /// `or`, after its last branch: power := the OR of all branches; pop.
    OrClose,
    /// `branch`: push the power in.
    BrOpen,
    /// `branch`, between branches: power := the power in.
    BrNext,
    /// `branch`, after its last branch: power := the power in; pop.
    BrClose,
    /// Any output (coil, negated coil, set, reset; `neg` is the mode, see [`OUT_COIL`]):
    /// powered, `slot := on`; unpowered, `slot := off` unless the mode keeps it.
    Coil { slot: u32, neg: u32 },
    /// Timer box on the instance starting at `inst`.
    Timer { kind: TimerKind, inst: u32, pt: u32 },
    /// CTU box.
    Ctu { inst: u32, pv: u32, reset: u32 },
    /// CTD box.
    Ctd { inst: u32, pv: u32, load: u32 },
    /// MOVE box.
    Move { from: u32, to: u32 },
    /// Arithmetic box.
    Arith {
        op: ArithOp,
        num: Num,
        a: u32,
        b: u32,
        out: u32,
    },
    /// Forward jump to the instruction index `to` (a `Rung`).
    Jmp { to: u32 },
    /// Backward (or same-rung) jump: a loop-back. Counts one iteration in the rung's loop counter
    /// slot `ctr`; past the cap the jump is refused: it acts as an unpowered jump (power := 0).
    JmpBack { to: u32, ctr: u32 },
    /// RET.
    Ret,
    /// END.
    End,
    /// CALL: run the POU whose first instruction is `to`.
    Call { to: u32 },
    /// FOR head (after the head rung's conditions): when powered, `var := from` and on to the
    /// [`Op::ForTest`] that always follows; otherwise to the loop's exit.
    For { f: u32 },
    /// FOR test: `var <= to` enters the body (next instruction), otherwise to the loop's exit.
    ForTest { f: u32 },
    /// NEXT: a loop-back counted in the loop's counter slot; `var += 1`, back to the FOR test.
    /// Past the cap: no increment, on to the loop's exit.
    Next { f: u32 },
    /// After the last rung of a POU.
    EndPou,
}

const _: () = assert!(std::mem::size_of::<Op>() <= 16);

/// One FOR/NEXT loop.
#[derive(Copy, Clone, Debug)]
pub(crate) struct ForLoop {
    /// The index variable's slot.
    pub var: u32,
    pub num: Num,
    pub from: u32,
    pub to: u32,
    /// Instruction index of its `ForTest`.
    pub test: u32,
    /// Instruction index of the loop exit (the rung after NEXT, or the POU's `EndPou`).
    pub exit: u32,
    /// The FOR head rung.
    pub head: u32,
    /// The loop counter slot of the NEXT rung.
    pub ctr: u32,
}

/// The lowered program.
pub(crate) struct Code {
    pub ops: Vec<Op>,
    pub consts: Vec<u64>,
    pub fors: Vec<ForLoop>,
    /// Instruction index of each rung's `Rung` marker.
    pub rung_op: Vec<u32>,
    /// For each rung: the index into `fors` if it is a FOR head.
    pub for_of_head: Vec<Option<u32>>,
    /// Instruction index of each POU's first instruction.
    pub pou_entry: Vec<u32>,
    /// Loop-back rungs (a NEXT, or a rung with a backward jump) and their counter slots, in rung
    /// order.
    pub counters: Vec<(u32, u32)>,
    /// Slots of the whole store: the layout's, then one 8-slot line per loop counter.
    pub slot_count: u32,
}

/// Why a program could not be lowered.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
pub enum LowerError {
    /// The layout was built for another program.
    #[error("the layout has {found} variables, the program {expected}")]
    LayoutMismatch {
        /// Variables in the program.
        expected: usize,
        /// Variables in the layout.
        found: usize,
    },
    /// `or`/`branch` nested deeper than the interpreter's 64-bit power stack.
    #[error("rung {rung}: `or`/`branch` nested too deeply ({bits} saved powers, at most 64)")]
    TooDeep {
        /// The rung's id.
        rung: String,
        /// Power-stack bits the rung needs.
        bits: u32,
    },
    /// The program has more than 2^31 slots, constants or instructions.
    #[error("the program is too large for 31-bit slot and instruction indices")]
    TooLarge,
}

struct Lowerer<'p> {
    p: &'p Program,
    layout: &'p Layout,
    code: Code,
    /// (instruction index, target rung) of jumps; (instruction, pou) of calls.
    jumps: Vec<(usize, RungId)>,
    calls: Vec<(usize, PouId)>,
    /// (for index, NEXT rung) to patch the exits.
    for_nexts: Vec<(usize, RungId)>,
    /// First slot of the loop counters (the layout's total rounded up to a cache line).
    counter_base: u32,
    depth: u32,
    max_depth: u32,
}

pub(crate) fn lower(p: &Program, layout: &Layout) -> Result<Code, LowerError> {
    if layout.var_count() != p.vars.len() {
        return Err(LowerError::LayoutMismatch {
            expected: p.vars.len(),
            found: layout.var_count(),
        });
    }
    if layout.slot_count() >= CONST {
        return Err(LowerError::TooLarge);
    }
    let mut l = Lowerer {
        p,
        layout,
        code: Code {
            ops: Vec::new(),
            consts: Vec::new(),
            fors: Vec::new(),
            rung_op: vec![0; p.rungs.len()],
            for_of_head: vec![None; p.rungs.len()],
            pou_entry: Vec::with_capacity(p.pous.len()),
            counters: Vec::new(),
            slot_count: 0,
        },
        jumps: Vec::new(),
        calls: Vec::new(),
        for_nexts: Vec::new(),
        counter_base: layout.slot_count().div_ceil(COUNTER_STRIDE) * COUNTER_STRIDE,
        depth: 0,
        max_depth: 0,
    };
    let mut pou_end = Vec::with_capacity(p.pous.len());
    for pou in &p.pous {
        l.code.pou_entry.push(l.code.ops.len() as u32);
        for r in pou.rungs.clone() {
            let rung = &p.rungs[r as usize];
            l.code.rung_op[r as usize] = l.code.ops.len() as u32;
            l.code.ops.push(Op::Rung { id: r });
            l.depth = 0;
            l.max_depth = 0;
            l.series(RungId(r), &rung.series);
            if l.max_depth > 64 {
                return Err(LowerError::TooDeep {
                    rung: rung.id.clone(),
                    bits: l.max_depth,
                });
            }
        }
        pou_end.push(l.code.ops.len() as u32);
        l.code.ops.push(Op::EndPou);
    }
    let total = l.counter_base as u64 + COUNTER_STRIDE as u64 * l.code.counters.len() as u64;
    if l.code.ops.len() >= CONST as usize
        || l.code.consts.len() >= CONST as usize
        || total >= CONST as u64
    {
        return Err(LowerError::TooLarge);
    }
    l.code.slot_count = if l.code.counters.is_empty() {
        layout.slot_count()
    } else {
        total as u32
    };
    let Lowerer {
        mut code,
        jumps,
        calls,
        for_nexts,
        ..
    } = l;
    for (at, target) in jumps {
        let to = code.rung_op[target.index()];
        match &mut code.ops[at] {
            Op::Jmp { to: t } | Op::JmpBack { to: t, .. } => *t = to,
            _ => unreachable!("jump patch on a jump"),
        }
    }

    for (at, pou) in calls {
        if let Op::Call { to } = &mut code.ops[at] {
            *to = code.pou_entry[pou.index()];
        }
    }
    for (f, next) in for_nexts {
        let pou = p.rung(next).pou;
        let after = next.0 + 1;
        code.fors[f].exit = if after < p.pou(pou).rungs.end {
            code.rung_op[after as usize]
        } else {
            pou_end[pou.index()]
        };
    }
    Ok(code)
}

/// Loop counters sit one per 8-slot (64-byte) line, so that loops run by different workers of a
/// parallel scan never write the same cache line.
pub(crate) const COUNTER_STRIDE: u32 = 8;

impl Lowerer<'_> {
    /// The loop counter slot of `rung`, allocated on first use (rungs are lowered in order, so
    /// a rung's counter is always the last one allocated, if any).
    fn counter(&mut self, rung: RungId) -> u32 {
        match self.code.counters.last() {
            Some(&(r, slot)) if r == rung.0 => slot,
            _ => {
                let slot = self.counter_base + COUNTER_STRIDE * self.code.counters.len() as u32;
                self.code.counters.push((rung.0, slot));
                slot
            }
        }
    }

    fn slot(&self, r: VarRef) -> u32 {
        self.layout.start(r.var) + r.field.map_or(0, field_offset)
    }

    fn operand(&mut self, o: &Operand) -> u32 {
        match o {
            Operand::Var(r) => self.slot(*r),
            Operand::Const(v) => {
                let bits = encode(*v);
                let i = match self.code.consts.iter().position(|&c| c == bits) {
                    Some(i) => i,
                    None => {
                        self.code.consts.push(bits);
                        self.code.consts.len() - 1
                    }
                };
                CONST | i as u32
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
    fn contact(&mut self, slot: u32, neg: u8) {
        match self.code.ops.last_mut() {
            Some(Op::Contact { neg: n, slot: a }) => {
                *self.code.ops.last_mut().unwrap() = Op::Contact2 {
                    neg: *n | neg << 1,
                    a: *a,
                    b: slot,
                }
            }
            Some(Op::Contact2 { neg: n, a, b }) => {
                *self.code.ops.last_mut().unwrap() = Op::Contact3 {
                    neg: *n | neg << 2,
                    a: *a,
                    b: *b,
                    c: slot,
                }
            }
            Some(&mut Op::Contact3 { neg: n, a, b, c })
                if a.max(b).max(c).max(slot) <= u16::MAX as u32 =>
            {
                let a = a as u16;
                *self.code.ops.last_mut().unwrap() = Op::ContactN {
                    n: 4,
                    neg: n | neg << 3,
                    s: [a, b as u16, c as u16, slot as u16, a, a],
                }
            }
            Some(Op::ContactN { n, neg: ng, s }) if *n < 6 && slot <= u16::MAX as u32 => {
                s[*n as usize] = slot as u16;
                *ng |= neg << *n;
                *n += 1;
            }
            _ => self.code.ops.push(Op::Contact { neg, slot }),
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

    fn element(&mut self, rung: RungId, e: &Element) {
        match e {
            Element::Contact { var, kind } => {
                let slot = self.slot(*var);
                let op = match kind {
                    ContactKind::Normal => return self.contact(slot, 0),
                    ContactKind::Negated => return self.contact(slot, 1),
                    ContactKind::Rising { memory } => Op::Rising {
                        slot,
                        mem: self.layout.start(*memory),
                    },
                    ContactKind::Falling { memory } => Op::Falling {
                        slot,
                        mem: self.layout.start(*memory),
                    },
                };
                self.push(op);
            }
            Element::Compare { op, a, b } => {
                let real = self.operand_type(a) == Type::Real;
                let (a, b) = (self.operand(a), self.operand(b));
                self.push(if real {
                    Op::CmpReal { op: *op, a, b }
                } else {
                    Op::CmpInt { op: *op, a, b }
                });
            }
            Element::Or(branches) => {
                self.grow(2);
                self.push(Op::OrOpen);
                for (i, b) in branches.iter().enumerate() {
                    if i > 0 {
                        self.push(Op::OrNext);
                    }
                    self.series(rung, b);
                }
                self.push(Op::OrClose);
                self.depth -= 2;
            }
            Element::Branch(branches) => {
                self.grow(1);
                self.push(Op::BrOpen);
                for (i, b) in branches.iter().enumerate() {
                    if i > 0 {
                        self.push(Op::BrNext);
                    }
                    self.series(rung, b);
                }
                self.push(Op::BrClose);
                self.depth -= 1;
            }
            Element::Coil { var, negated } => {
                let slot = self.layout.start(*var);
                self.push(Op::Coil {
                    slot,
                    neg: if *negated { OUT_NCOIL } else { OUT_COIL },
                });
            }
            Element::Set(v) => {
                let slot = self.layout.start(*v);
                self.push(Op::Coil { slot, neg: OUT_SET });
            }
            Element::Reset(v) => {
                let slot = self.layout.start(*v);
                self.push(Op::Coil {
                    slot,
                    neg: OUT_RESET,
                });
            }
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
            Element::Move { from, to } => {
                let from = self.operand(from);
                let to = self.layout.start(*to);
                self.push(Op::Move { from, to });
            }
            Element::Arith { op, a, b, out } => {
                let num = Num::of(self.p.var(*out).ty);
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
            Element::Jmp { target, .. } => {
                self.jumps.push((self.code.ops.len(), *target));
                if target.0 <= rung.0 {
                    let ctr = self.counter(rung);
                    self.push(Op::JmpBack { to: 0, ctr });
                } else {
                    self.push(Op::Jmp { to: 0 });
                }
            }
            Element::Ret => self.push(Op::Ret),
            Element::End => self.push(Op::End),
            Element::Call { pou } => {
                self.calls.push((self.code.ops.len(), *pou));
                self.push(Op::Call { to: 0 });
            }
            Element::For {
                var,
                from,
                to,
                next,
            } => {
                let f = self.code.fors.len();
                let (from, to) = (self.operand(from), self.operand(to));
                let test = self.code.ops.len() as u32 + 1;
                self.code.fors.push(ForLoop {
                    var: self.layout.start(*var),
                    num: Num::of(self.p.var(*var).ty),
                    from,
                    to,
                    test,
                    exit: 0,
                    head: rung.0,
                    ctr: 0,
                });
                self.code.for_of_head[rung.index()] = Some(f as u32);
                self.for_nexts.push((f, *next));
                self.push(Op::For { f: f as u32 });
                self.push(Op::ForTest { f: f as u32 });
            }
            Element::Next { head } => {
                // FOR heads come before their NEXT, so the head is already lowered.
                let f = self.code.for_of_head[head.index()]
                    .expect("the model puts a FOR head before its NEXT");
                let ctr = self.counter(rung);
                self.code.fors[f as usize].ctr = ctr;
                self.push(Op::Next { f });
            }
        }
    }
}
