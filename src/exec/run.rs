//! The interpreter loop: one generic function over the store and the region predicate.

use super::layout::{ET, FLAGS, PREV, PT, Q, START};
use super::lower::{Num, Op, CONST};
use super::{Fault, FaultKind, Machine, ScanCtx, Store};
use crate::model::{ArithOp, CmpOp, RungId, TimerKind};

/// How a run of instructions ended.
#[derive(Copy, Clone, Debug, PartialEq, Eq)]
pub(crate) enum Flow {
    /// The POU ended (last rung done, or RET taken).
    Return,
    /// The scan ends (END).
    Stop,
    /// Control reached the start of a rung outside the region.
    Rung(u32),
    /// Control reached the test of a FOR head outside the region.
    ForTest(u32),
}

/// The region predicate for subroutines (always inside); a fn item, so nested calls do not
/// instantiate new closure types.
#[inline(always)]
pub(crate) fn everywhere(_: RungId) -> bool {
    true
}

// Timer flag bits.
const PREV_IN: u64 = 1;
const ACTIVE: u64 = 2; // TON: timing since IN rose; TOF: timing since IN fell; TP: pulsing.

/// `a OP b` for integers (as `i64`) and REAL (`f32`, IEEE: NaN compares false except NE).
#[inline(always)]
fn compare<T: PartialOrd>(op: CmpOp, a: T, b: T) -> bool {
    match op {
        CmpOp::Eq => a == b,
        CmpOp::Ne => a != b,
        CmpOp::Lt => a < b,
        CmpOp::Le => a <= b,
        CmpOp::Gt => a > b,
        CmpOp::Ge => a >= b,
    }
}

/// Truncates an integer result to the width of `num` (two's complement wrap), sign-extended.
#[inline(always)]
fn wrap(num: Num, v: i64) -> u64 {
    match num {
        Num::I16 => v as i16 as i64 as u64,
        _ => v as i32 as i64 as u64,
    }
}

impl Machine {
    /// An operand's bits: a slot, or a constant of the pool.
    #[inline(always)]
    fn src<S: Store + ?Sized>(&self, st: &S, x: u32) -> u64 {
        if x & CONST != 0 {
            self.consts[(x & !CONST) as usize]
        } else {
            st.get(x)
        }
    }

    /// Runs instructions from `pc` until the POU ends, the scan stops, or control reaches a rung
    /// (or FOR test) for which `inside` is false. `rung` is the rung `pc` belongs to (for faults
    /// before the first rung marker, i.e. when resuming at a FOR test).
    pub(crate) fn exec<S, F>(
        &self,
        st: &mut S,
        ctx: &mut ScanCtx<'_>,
        mut pc: usize,
        mut rung: u32,
        inside: &F,
    ) -> Flow
    where
        S: Store + ?Sized,
        F: Fn(RungId) -> bool,
    {
        let ops = &self.ops[..];
        let mut p: u64 = 1;
        let mut s: u64 = 0;
        loop {
            let op = ops[pc];
            pc += 1;
            match op {
                Op::Rung { id } => {
                    if !inside(RungId(id)) {
                        return Flow::Rung(id);
                    }
                    rung = id;
                    p = 1;
                }
                Op::Contact { neg, slot } => p &= st.get(slot) ^ neg as u64,
                Op::Contact2 { neg, a, b } => {
                    // Both BOOLs (each 0 or 1) must equal their negation bit's complement.
                    let bits = st.get(a) | st.get(b) << 1;
                    p &= ((bits ^ neg as u64) == 3) as u64;
                }
                Op::Contact3 { neg, a, b, c } => {
                    let bits = st.get(a) | st.get(b) << 1 | st.get(c) << 2;
                    p &= ((bits ^ neg as u64) == 7) as u64;
                }
                Op::ContactN { n, neg, s: sl } => {
                    let mut bits = 0u64;
                    for (k, &x) in sl.iter().enumerate() {
                        bits |= st.get(x as u32) << k;
                    }
                    let mask = (1u64 << n) - 1;
                    p &= (((bits ^ neg as u64) & mask) == mask) as u64;
                }
                Op::Rising { slot, mem } => {
                    let v = st.get(slot);
                    p &= v & !st.get(mem) & 1;
                    st.set(mem, v);
                }
                Op::Falling { slot, mem } => {
                    let v = st.get(slot);
                    p &= !v & st.get(mem) & 1;
                    st.set(mem, v);
                }
                Op::CmpInt { op, a, b } => {
                    p &= compare(op, self.src(st, a) as i64, self.src(st, b) as i64) as u64
                }
                Op::CmpReal { op, a, b } => {
                    let (a, b) = (
                        f32::from_bits(self.src(st, a) as u32),
                        f32::from_bits(self.src(st, b) as u32),
                    );
                    p &= compare(op, a, b) as u64;
                }
                Op::OrOpen => s = (s << 2) | (p << 1),
                Op::OrNext => {
                    s |= p;
                    p = (s >> 1) & 1;
                }
                Op::OrClose => {
                    p = (s | p) & 1;
                    s >>= 2;
                }
                Op::BrOpen => s = (s << 1) | p,
                Op::BrNext => p = s & 1,
                Op::BrClose => {
                    p = s & 1;
                    s >>= 1;
                }
                Op::Coil { slot, neg } => {
                    // Powered: bit 0 of the mode. Unpowered: bit 2, or no write (set/reset).
                    let (on, keep, off) =
                        (neg as u64 & 1, (neg as u64 >> 1) & 1, (neg as u64 >> 2) & 1);
                    if (p | (keep ^ 1)) != 0 {
                        st.set(slot, (p & on) | ((p ^ 1) & off));
                    }
                }
                Op::Timer { kind, inst, pt } => {
                    let pt = self.src(st, pt) as i64;
                    p = match kind {
                        TimerKind::Ton => ton(st, ctx.now, inst, pt, p),
                        TimerKind::Tof => tof(st, ctx.now, inst, pt, p),
                        TimerKind::Tp => tp(st, ctx.now, inst, pt, p),
                    };
                }
                Op::Ctu { inst, pv, reset } => {
                    let pv = self.src(st, pv) as i64;
                    let reset = self.src(st, reset) != 0;
                    p = counter(st, inst, pv, p, reset, true);
                }
                Op::Ctd { inst, pv, load } => {
                    let pv = self.src(st, pv) as i64;
                    let load = self.src(st, load) != 0;
                    p = counter(st, inst, pv, p, load, false);
                }
                Op::Move { from, to } => {
                    if p != 0 {
                        let v = self.src(st, from);
                        st.set(to, v);
                    }
                }
                Op::Arith { op, num, a, b, out } => {
                    if p != 0 {
                        let (a, b) = (self.src(st, a), self.src(st, b));
                        let v = match arith(op, num, a, b) {
                            Some(v) => v,
                            None => {
                                ctx.faults.push(Fault {
                                    scan: ctx.scan,
                                    rung: RungId(rung),
                                    kind: FaultKind::DivByZero,
                                });
                                0
                            }
                        };
                        st.set(out, v);
                    }
                }
                Op::Jmp { to } => {
                    if p != 0 {
                        pc = to as usize;
                    }
                }
                Op::JmpBack { to, ctr } => {
                    if p != 0 {
                        if self.loop_back(st, ctx, ctr, rung) {
                            pc = to as usize;
                        } else {
                            // Refused: the jump acts as if it had no power.
                            p = 0;
                        }
                    }
                }
                Op::Ret => {
                    if p != 0 {
                        return Flow::Return;
                    }
                }
                Op::End => {
                    if p != 0 {
                        return Flow::Stop;
                    }
                }
                Op::Call { to } => {
                    if p != 0 && self.exec(st, ctx, to as usize, rung, &everywhere) != Flow::Return
                    {
                        return Flow::Stop;
                    }
                }
                Op::For { f } => {
                    let l = &self.fors[f as usize];
                    if p != 0 {
                        let from = self.src(st, l.from);
                        st.set(l.var, from);
                    } else {
                        pc = l.exit as usize;
                    }
                }
                Op::ForTest { f } => {
                    let l = &self.fors[f as usize];
                    if st.get(l.var) as i64 > self.src(st, l.to) as i64 {
                        pc = l.exit as usize;
                    }
                }
                Op::Next { f } => {
                    let l = &self.fors[f as usize];
                    if !self.loop_back(st, ctx, l.ctr, rung) {
                        pc = l.exit as usize;
                        continue;
                    }
                    st.set(l.var, wrap(l.num, (st.get(l.var) as i64).wrapping_add(1)));
                    if !inside(RungId(l.head)) {
                        return Flow::ForTest(l.head);
                    }
                    rung = l.head;
                    pc = l.test as usize;
                }
                Op::EndPou => return Flow::Return,
            }
        }
    }

    /// Counts one loop-back of `rung` in its counter slot `ctr`; returns whether it may loop back.
    /// The first refused loop-back of a scan records [`FaultKind::LoopCap`]; later ones (control
    /// can come back through another loop-back rung) are refused silently.
    #[inline]
    fn loop_back<S: Store + ?Sized>(
        &self,
        st: &mut S,
        ctx: &mut ScanCtx<'_>,
        ctr: u32,
        rung: u32,
    ) -> bool {
        let c = st.get(ctr).wrapping_add(1);
        st.set(ctr, c);
        let cap = self.config.loop_cap as u64;
        if c <= cap {
            return true;
        }
        if c == cap + 1 {
            ctx.faults.push(Fault {
                scan: ctx.scan,
                rung: RungId(rung),
                kind: FaultKind::LoopCap,
            });
        }
        false
    }
}

/// `a op b` in the representation `num`; `None` for an integer DIV or MOD by zero.
#[inline]
fn arith(op: ArithOp, num: Num, a: u64, b: u64) -> Option<u64> {
    if num == Num::F32 {
        let (a, b) = (f32::from_bits(a as u32), f32::from_bits(b as u32));
        let r = match op {
            ArithOp::Add => a + b,
            ArithOp::Sub => a - b,
            ArithOp::Mul => a * b,
            ArithOp::Div => a / b,
            ArithOp::Mod => a % b,
        };
        return Some(r.to_bits() as u64);
    }
    // Operands are sign-extended 16- or 32-bit values: no i64 operation below overflows.
    let (a, b) = (a as i64, b as i64);
    let r = match op {
        ArithOp::Add => a + b,
        ArithOp::Sub => a - b,
        ArithOp::Mul => a * b,
        ArithOp::Div if b == 0 => return None,
        ArithOp::Mod if b == 0 => return None,
        ArithOp::Div => a / b,
        ArithOp::Mod => a % b,
    };
    Some(wrap(num, r))
}

/// TON on the instance at `i`; returns Q.
#[inline]
fn ton<S: Store + ?Sized>(st: &mut S, now: i64, i: u32, pt: i64, input: u64) -> u64 {
    st.set(i + PT, pt as u64);
    if input == 0 {
        st.set(i + Q, 0);
        st.set(i + ET, 0);
        st.set(i + FLAGS, 0);
        return 0;
    }
    let start = if st.get(i + FLAGS) & ACTIVE == 0 {
        st.set(i + FLAGS, ACTIVE | PREV_IN);
        st.set(i + START, now as u64);
        now
    } else {
        st.get(i + START) as i64
    };
    let et = now.wrapping_sub(start).min(pt);
    let q = (et >= pt) as u64;
    st.set(i + ET, et as u64);
    st.set(i + Q, q);
    q
}

/// TOF on the instance at `i`; returns Q.
#[inline]
fn tof<S: Store + ?Sized>(st: &mut S, now: i64, i: u32, pt: i64, input: u64) -> u64 {
    st.set(i + PT, pt as u64);
    if input != 0 {
        st.set(i + Q, 1);
        st.set(i + ET, 0);
        st.set(i + FLAGS, PREV_IN);
        return 1;
    }
    let flags = st.get(i + FLAGS);
    let mut active = flags & ACTIVE != 0;
    let start = if flags & PREV_IN != 0 {
        active = true;
        st.set(i + START, now as u64);
        now
    } else {
        st.get(i + START) as i64
    };
    if active {
        let et = now.wrapping_sub(start).min(pt);
        st.set(i + ET, et as u64);
        if et >= pt {
            st.set(i + Q, 0);
            active = false;
        }
    }
    st.set(i + FLAGS, if active { ACTIVE } else { 0 });
    st.get(i + Q)
}

/// TP on the instance at `i`; returns Q.
#[inline]
fn tp<S: Store + ?Sized>(st: &mut S, now: i64, i: u32, pt: i64, input: u64) -> u64 {
    st.set(i + PT, pt as u64);
    let flags = st.get(i + FLAGS);
    let mut pulsing = flags & ACTIVE != 0;
    let mut q = 0;
    let start = if !pulsing && input != 0 && flags & PREV_IN == 0 {
        pulsing = true;
        st.set(i + START, now as u64);
        now
    } else {
        st.get(i + START) as i64
    };
    if pulsing {
        let et = now.wrapping_sub(start);
        if et >= pt {
            st.set(i + ET, pt as u64);
            pulsing = false;
        } else {
            st.set(i + ET, et as u64);
            q = 1;
        }
    }
    if !pulsing && input == 0 {
        st.set(i + ET, 0);
    }
    st.set(i + Q, q);
    st.set(i + FLAGS, (if pulsing { ACTIVE } else { 0 }) | (input & 1));
    q
}

/// CTU (`up`) or CTD on the instance at `i`: `clock` is CU/CD, `preset` R (CTU) or LD (CTD).
#[inline]
fn counter<S: Store + ?Sized>(
    st: &mut S,
    i: u32,
    pv: i64,
    clock: u64,
    preset: bool,
    up: bool,
) -> u64 {
    st.set(i + PT, pv as u64);
    let rising = clock & !st.get(i + PREV) & 1 != 0;
    st.set(i + PREV, clock);
    let mut cv = st.get(i + ET) as i64;
    if up {
        if preset {
            cv = 0;
        } else if rising && cv < i16::MAX as i64 {
            cv += 1;
        }
    } else if preset {
        cv = pv;
    } else if rising && cv > i16::MIN as i64 {
        cv -= 1;
    }
    st.set(i + ET, cv as u64);
    let q = if up { cv >= pv } else { cv <= 0 } as u64;
    st.set(i + Q, q);
    q
}
