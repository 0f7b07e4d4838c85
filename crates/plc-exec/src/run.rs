//! The interpreter loop: one generic function over the store and the region predicate, and the
//! function blocks it calls. Every load and store is typed: a BOOL is a byte (0 or 1), an INT an
//! `i16`, DINT and TIME an `i32`, REAL an `f32`, at the addresses lowering put in the
//! instructions. Integer arithmetic wraps in the type's width (two's complement for the signed
//! types, modulo 2^n for the unsigned ones and the bit strings); a DIV or MOD by zero writes 0
//! and records a fault.
//!
//! The instruction fetch, the fused rungs' operand reads and the sequential store are
//! unchecked: `raw`'s `unsafe fn`s, whose preconditions this file argues from the machine's
//! [`CheckedCode`](super::raw::CheckedCode) (checked once, by its only constructor, when the
//! machine is built) and from how `exec` moves its instruction index. `exec` itself is an
//! `unsafe fn` private to this file; its two entry points ([`Machine::run_scan_in`],
//! [`Machine::resume`]) are here too.

use super::fuse::{lookup, FusedId, FusedRung};
use super::layout::{CV, ET, FLAGS, PREV, PT, PV, Q, START};
use super::lower::{Num, Op, Width};
use super::raw::Trusted;
use super::store::{Addr, Word};
use super::strings;
use super::value::{load_value, store_value};
use super::{BudgetSpent, Exit, Fault, FaultKind, Machine, ScanCtx, Store};
use plc_model::{ArithOp, CmpOp, RungId, TimerKind, Type, Value};

/// How a run of instructions ended.
#[derive(Copy, Clone, Debug, PartialEq, Eq)]
pub(crate) enum Flow {
    /// The POU ended (last rung done, or RET taken).
    Return,
    /// The scan ends (END).
    Stop,
    /// Control reached the start of a rung outside the region.
    Rung(RungId),
    /// Control reached the test of a FOR head outside the region.
    ForTest(RungId),
}

/// The region predicate for subroutines (always inside); a fn item, so nested calls do not
/// instantiate new closure types.
#[inline(always)]
pub(crate) fn everywhere(_: RungId) -> bool {
    true
}

// Timer flag bits.
const PREV_IN: u8 = 1;
const ACTIVE: u8 = 2; // TON: timing since IN rose; TOF: timing since IN fell; TP: pulsing.

/// `a OP b` (REAL: IEEE, NaN compares false except NE).
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

/// An integer representation and its wrapping arithmetic (the width's two's complement, or
/// modulo 2^n for an unsigned one).
trait Int: Word + PartialOrd {
    const ZERO: Self;
    const ONE: Self;
    fn add(self, b: Self) -> Self;
    fn sub(self, b: Self) -> Self;
    fn mul(self, b: Self) -> Self;
    /// Truncating division (`MIN / -1` wraps to `MIN`); `b` is not zero.
    fn div(self, b: Self) -> Self;
    /// The remainder with the sign of `self` (`MIN % -1` is 0); `b` is not zero.
    fn rem(self, b: Self) -> Self;
}

macro_rules! int {
    ($($t:ty),*) => {$(
        impl Int for $t {
            const ZERO: $t = 0;
            const ONE: $t = 1;
            #[inline(always)]
            fn add(self, b: $t) -> $t { self.wrapping_add(b) }
            #[inline(always)]
            fn sub(self, b: $t) -> $t { self.wrapping_sub(b) }
            #[inline(always)]
            fn mul(self, b: $t) -> $t { self.wrapping_mul(b) }
            #[inline(always)]
            fn div(self, b: $t) -> $t { self.wrapping_div(b) }
            #[inline(always)]
            fn rem(self, b: $t) -> $t { self.wrapping_rem(b) }
        }
    )*};
}

int!(i8, i16, i32, i64, u8, u16, u32, u64);

/// Runs `$e` with `$t` the Rust type of the integer representation `$num` (`$real` for REAL
/// and LREAL, with `$t` the float type).
macro_rules! by_num {
    ($num:expr, $t:ident => $e:expr, $real:expr) => {
        match $num {
            Num::I8 => {
                type $t = i8;
                $e
            }
            Num::I16 => {
                type $t = i16;
                $e
            }
            Num::I32 => {
                type $t = i32;
                $e
            }
            Num::I64 => {
                type $t = i64;
                $e
            }
            // `Bool` is never a `Num` (`lower::num_of`); as a byte it would be a `u8`.
            Num::U8 | Num::Bool => {
                type $t = u8;
                $e
            }
            Num::U16 => {
                type $t = u16;
                $e
            }
            Num::U32 => {
                type $t = u32;
                $e
            }
            Num::U64 => {
                type $t = u64;
                $e
            }
            Num::F32 => {
                #[allow(dead_code)]
                type $t = f32;
                $real
            }
            Num::F64 => {
                #[allow(dead_code)]
                type $t = f64;
                $real
            }
        }
    };
}

/// `a OP b` of two loaded operands of representation `num`.
#[inline(always)]
fn compare_at<S: Store + ?Sized>(st: &S, op: CmpOp, num: Num, a: Addr, b: Addr) -> bool {
    by_num!(
        num,
        T => compare(op, st.load::<T>(a), st.load::<T>(b)),
        compare(op, st.load::<T>(a), st.load::<T>(b))
    )
}

/// Copies the `T` at `from` to `to`.
#[inline(always)]
fn copy<T: Word, S: Store + ?Sized>(st: &mut S, from: Addr, to: Addr) {
    let v = st.load::<T>(from);
    st.store(to, v);
}

/// `out := a op b` in the integer representation `T`; false (and `out := 0`) for a DIV or MOD
/// by zero.
#[inline]
fn int_arith<T: Int, S: Store + ?Sized>(
    st: &mut S,
    op: ArithOp,
    a: Addr,
    b: Addr,
    out: Addr,
) -> bool {
    let (a, b) = (st.load::<T>(a), st.load::<T>(b));
    let r = match op {
        ArithOp::Add => Some(a.add(b)),
        ArithOp::Sub => Some(a.sub(b)),
        ArithOp::Mul => Some(a.mul(b)),
        ArithOp::Div | ArithOp::Mod if b == T::ZERO => None,
        ArithOp::Div => Some(a.div(b)),
        ArithOp::Mod => Some(a.rem(b)),
    };
    st.store(out, r.unwrap_or(T::ZERO));
    r.is_some()
}

/// `out := a op b` on REALs or LREALs (IEEE: no faults).
#[inline]
fn real_arith<T, S>(st: &mut S, op: ArithOp, a: Addr, b: Addr, out: Addr)
where
    T: Word + std::ops::Add<Output = T> + std::ops::Sub<Output = T> + std::ops::Mul<Output = T>,
    T: std::ops::Div<Output = T> + std::ops::Rem<Output = T>,
    S: Store + ?Sized,
{
    let (a, b) = (st.load::<T>(a), st.load::<T>(b));
    let r = match op {
        ArithOp::Add => a + b,
        ArithOp::Sub => a - b,
        ArithOp::Mul => a * b,
        ArithOp::Div => a / b,
        ArithOp::Mod => a % b,
    };
    st.store(out, r);
}

impl Machine {
    /// `out := func(args)` of one standard function box (`super::functions`).
    #[inline(never)]
    fn call_function<S: Store + ?Sized>(&self, st: &mut S, c: &super::lower::FuncCall) {
        if c.func.is_textual() {
            return string_function(st, c);
        }
        let mut buf = [Value::Bool(false); 8];
        let load = |&(at, ty): &(Addr, Type)| load_value(st, at, ty);
        let unit = self.code.dialect.time_unit_ms();
        let r = if let (plc_model::Function::Convert { from, to }, true) = (c.func, unit != 1) {
            super::functions::convert_time_in(load(&c.args[0]), from, to, unit)
        } else if c.args.len() <= buf.len() {
            for (slot, a) in buf.iter_mut().zip(c.args.iter()) {
                *slot = load(a);
            }
            super::functions::apply(c.func, &buf[..c.args.len()], c.ty)
        } else {
            let vals: Vec<Value> = c.args.iter().map(load).collect();
            super::functions::apply(c.func, &vals, c.ty)
        };
        store_value(st, c.out, r);
    }
}

/// A string function or a conversion to or from STRING (`strings::apply`): STRING arguments
/// read from their slots, the result stored in the output's.
#[cold]
fn string_function<S: Store + ?Sized>(st: &mut S, c: &super::lower::FuncCall) {
    let args: Vec<strings::Arg> = c
        .args
        .iter()
        .map(|&(at, ty)| match ty {
            Type::String => strings::Arg::Str(strings::load_str(st, at)),
            ty => strings::Arg::Val(load_value(st, at, ty)),
        })
        .collect();
    match strings::apply(c.func, &args, c.ty) {
        strings::Arg::Str(s) => strings::store_str(st, c.out, &s),
        strings::Arg::Val(v) => store_value(st, c.out, v),
    }
}

/// The FOR index at `at` incremented, wrapping in its representation.
#[inline]
fn increment<T: Int, S: Store + ?Sized>(st: &mut S, at: Addr) {
    let v = st.load::<T>(at).add(T::ONE);
    st.store(at, v);
}

/// Whether the FOR index at `var` is past the bound at `to`.
#[inline]
fn past<S: Store + ?Sized>(st: &S, num: Num, var: Addr, to: Addr) -> bool {
    by_num!(num, T => st.load::<T>(var) > st.load::<T>(to), false)
}

impl Machine {
    /// [`run_scan`](Self::run_scan) on a state's bare bytes ([`State::bytes_mut`](super::State::bytes_mut)).
    ///
    /// # Panics
    /// If `mem` has fewer than [`Machine::state_size`] bytes.
    #[inline]
    pub fn run_scan_in(&self, mem: &mut [u8], scan: u64, faults: &mut Vec<super::Fault>) {
        // SAFETY: `mem` goes only to `begin_scan`, which stores at `self.code`'s loop counters,
        // and `exec` on `self.code`, which loads and stores only at its instructions' addresses
        // (`Trusted::new`'s contract; it asserts the size).
        let mut mem = unsafe { Trusted::new(mem, &self.code) };
        self.begin_scan(&mut mem);
        let mut ctx = self.context(scan, faults);
        // SAFETY: `pou_entry[0]` (indexed with a bounds check) is the main program's entry, an
        // instruction index `self.code` holds.
        unsafe {
            self.exec(
                &mut mem,
                &mut ctx,
                self.code.pou_entry[0].index(),
                self.main_first,
                &everywhere,
            )
        };
    }

    /// Like [`run_from`](Self::run_from), starting where an earlier run left: at a rung, at a FOR
    /// test (without the head rung's conditions), or nowhere (`Exit::Stop` returns `Stop`).
    pub fn resume<S, F>(&self, store: &mut S, ctx: &mut ScanCtx<'_>, at: Exit, inside: F) -> Exit
    where
        S: Store + ?Sized,
        F: Fn(RungId) -> bool,
    {
        let (pc, rung) = match at {
            Exit::Stop => return Exit::Stop,
            Exit::Rung(r) => (self.code.rung_op[r.index()], r),
            Exit::ForTest(h) => {
                let Some(f) = self.code.for_of_head[h.index()] else {
                    panic!("rung {} is not a FOR head", h.raw());
                };
                if !inside(h) {
                    return at;
                }
                (self.code.fors[f.index()].test, h)
            }
        };
        // SAFETY: `pc` is a rung's start (`self.code.rung_op`) or a FOR loop's test
        // (`self.code.fors`), both indexed with a bounds check: an instruction index the code
        // holds.
        match unsafe { self.exec(store, ctx, pc.index(), rung, &inside) } {
            Flow::Return | Flow::Stop => Exit::Stop,
            Flow::Rung(r) => Exit::Rung(r),
            Flow::ForTest(h) => Exit::ForTest(h),
        }
    }

    /// Runs instructions from `pc` until the POU ends, the scan stops, or control reaches a rung
    /// (or FOR test) for which `inside` is false. `rung` is the rung `pc` belongs to (for faults
    /// before the first rung marker, i.e. when resuming at a FOR test).
    ///
    /// # Safety
    /// `pc` is an instruction index `self.code` holds: a POU's entry (`pou_entry`), a rung's
    /// start (`rung_op`) or a FOR test (`fors[_].test`).
    unsafe fn exec<S, F>(
        &self,
        st: &mut S,
        ctx: &mut ScanCtx<'_>,
        mut pc: usize,
        mut rung: RungId,
        inside: &F,
    ) -> Flow
    where
        S: Store + ?Sized,
        F: Fn(RungId) -> bool,
    {
        let ops = self.code.ops();
        let mut p: u64 = 1;
        let mut s: u64 = 0;
        let b = |st: &S, at: Addr| st.load::<u8>(at) as u64;
        loop {
            // SAFETY: `CheckedOps::at`'s contract: `pc` is an instruction index the code holds
            // (the first time: this function's contract; after a jump, a call's return or a FOR
            // exit or test: the `to` of the instruction just fetched, or a `test` or `exit` of
            // `self.code.fors`), or one past the instruction just fetched, which was not an
            // `EndPou` (an `EndPou` returns: the match below).
            let op = unsafe { ops.at(pc) };
            pc += 1;
            match op {
                Op::Rung { id } => {
                    if !inside(id) {
                        return Flow::Rung(id);
                    }
                    rung = id;
                    p = 1;
                }
                Op::Fused {
                    mut id,
                    mut f,
                    mut table,
                    mut neg,
                } => loop {
                    // A run of fused rungs stays in this loop: one well-predicted branch per
                    // rung instead of a dispatch through the jump table. The power is dead
                    // after a fused rung (the next instruction starts a rung or ends the POU).
                    if !inside(id) {
                        return Flow::Rung(id);
                    }
                    rung = id;
                    // SAFETY: `(f, table)` are the operands of the `Fused` instruction just
                    // fetched from `self.code` (before the loop or at its end).
                    unsafe { self.fused_rung(st, f, table, neg) };
                    // SAFETY: `pc` is one past the fused rung just fetched, not an `EndPou`
                    // (`CheckedOps::at`'s contract).
                    match unsafe { ops.at(pc) } {
                        Op::Fused {
                            id: i,
                            f: g,
                            table: t,
                            neg: n,
                        } => {
                            (id, f, table, neg) = (i, g, t, n);
                            pc += 1;
                        }
                        _ => break,
                    }
                },
                Op::FusedHead { id, f, table, neg } => {
                    if !inside(id) {
                        return Flow::Rung(id);
                    }
                    rung = id;
                    // SAFETY: the operands of the `FusedHead` just fetched from `self.code`.
                    p = unsafe { self.fused_power(st, f, table, neg) } as u64;
                }
                Op::Contact { neg, at } => p &= b(st, at) ^ neg as u64,
                Op::Contact2 { neg, a, b: c } => {
                    // Both BOOLs (each 0 or 1) must equal their negation bit's complement.
                    let bits = b(st, a) | b(st, c) << 1;
                    p &= ((bits ^ neg as u64) == 3) as u64;
                }
                Op::Contact3 { neg, a, b: x, c } => {
                    let bits = b(st, a) | b(st, x) << 1 | b(st, c) << 2;
                    p &= ((bits ^ neg as u64) == 7) as u64;
                }
                Op::ContactN { n, neg, s: sl } => {
                    let mut bits = 0u64;
                    for (k, &x) in sl.iter().enumerate() {
                        bits |= b(st, Addr(x as u32)) << k;
                    }
                    let mask = (1u64 << n) - 1;
                    p &= (((bits ^ neg as u64) & mask) == mask) as u64;
                }
                Op::Rising { at, mem } => {
                    let v = st.load::<u8>(at);
                    p &= (v & !st.load::<u8>(mem) & 1) as u64;
                    st.store(mem, v);
                }
                Op::Falling { at, mem } => {
                    let v = st.load::<u8>(at);
                    p &= (!v & st.load::<u8>(mem) & 1) as u64;
                    st.store(mem, v);
                }
                Op::Cmp { op, num, a, b } => p &= compare_at(st, op, num, a, b) as u64,
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
                Op::Coil { at, mode } => {
                    // Powered: bit 0 of the mode. Unpowered: bit 2, or no write (set/reset).
                    let m = mode as u64;
                    let (on, keep, off) = (m & 1, (m >> 1) & 1, (m >> 2) & 1);
                    if (p | (keep ^ 1)) != 0 {
                        st.store(at, ((p & on) | ((p ^ 1) & off)) as u8);
                    }
                }
                Op::Timer { kind, inst, pt } => {
                    let pt = st.load::<i32>(pt) as i64;
                    let late = self.code.dialect.timer_compares_after_edge();
                    let q = match kind {
                        TimerKind::Ton => ton(st, ctx.now, inst, pt, p != 0, late),
                        TimerKind::Tof => tof(st, ctx.now, inst, pt, p != 0, late),
                        TimerKind::Tp => tp(st, ctx.now, inst, pt, p != 0, late),
                    };
                    p = q as u64;
                }
                Op::Ctu { inst, pv, reset } => {
                    let pv = st.load::<i16>(pv);
                    let reset = st.load::<u8>(reset) != 0;
                    let stop = self.code.dialect.counters_stop_at_preset();
                    p = counter(st, inst, pv, p as u8, reset, true, stop) as u64;
                }
                Op::Ctd { inst, pv, load } => {
                    let pv = st.load::<i16>(pv);
                    let load = st.load::<u8>(load) != 0;
                    let stop = self.code.dialect.counters_stop_at_preset();
                    p = counter(st, inst, pv, p as u8, load, false, stop) as u64;
                }
                Op::Bistable { kind, inst, reset } => {
                    let reset = st.load::<u8>(reset) != 0;
                    p = super::fb::bistable(st, kind, inst, p != 0, reset) as u64;
                }
                Op::Trigger { kind, inst } => {
                    p = super::fb::trigger(st, kind, inst, p != 0) as u64;
                }
                Op::Ctud { inst, pins } => {
                    let pins = self.code.ctuds[pins.index()];
                    let stop = self.code.dialect.counters_stop_at_preset();
                    p = super::fb::ctud(st, inst, pins, p != 0, stop) as u64;
                }
                Op::Move { width, from, to } => {
                    if p != 0 {
                        match width {
                            Width::W1 => copy::<u8, S>(st, from, to),
                            Width::W2 => copy::<i16, S>(st, from, to),
                            Width::W4 => copy::<i32, S>(st, from, to),
                            Width::W8 => copy::<u64, S>(st, from, to),
                        }
                    }
                }
                Op::StrMove { from, to } => {
                    if p != 0 {
                        let s = strings::load_str(st, from);
                        strings::store_str(st, to, &s);
                    }
                }
                Op::StrCmp { op, a, b } => {
                    let o = strings::compare(&strings::load_str(st, a), &strings::load_str(st, b));
                    p &= compare(op, o, std::cmp::Ordering::Equal) as u64;
                }
                Op::Func { call } => {
                    if p != 0 {
                        self.call_function(st, &self.code.funcs[call.index()]);
                    }
                }
                Op::Arith { op, num, a, b, out } => {
                    if p != 0 {
                        let ok = by_num!(num, T => int_arith::<T, S>(st, op, a, b, out), {
                            real_arith::<T, S>(st, op, a, b, out);
                            true
                        });
                        if !ok {
                            ctx.faults.push(Fault {
                                scan: ctx.scan,
                                rung,
                                kind: FaultKind::DivByZero,
                            });
                        }
                    }
                }
                Op::Jmp { to } => {
                    if p != 0 {
                        pc = to.index();
                    }
                }
                Op::JmpBack { to, ctr, charge } => {
                    if p != 0 {
                        if self.loop_back(st, ctx, ctr, rung) && self.charge(ctx, rung, charge) {
                            pc = to.index();
                        } else {
                            // Refused: the jump acts as if it had no power.
                            p = 0;
                        }
                    }
                }
                Op::RangeFault => {
                    if p != 0 {
                        ctx.faults.push(Fault {
                            scan: ctx.scan,
                            rung,
                            kind: FaultKind::IndexRange,
                        });
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
                Op::Call { to, charge } => {
                    if p != 0
                        && self.charge(ctx, rung, charge)
                        // SAFETY: `to` is the target of a `Call` instruction of `self.code`
                        // (just fetched): an instruction index the code holds.
                        && unsafe { self.exec(st, ctx, to.index(), rung, &everywhere) }
                            != Flow::Return
                    {
                        return Flow::Stop;
                    }
                }
                Op::For { f } => {
                    let l = &self.code.fors[f.index()];
                    if p != 0 {
                        by_num!(l.num, T => copy::<T, S>(st, l.from, l.var), {});
                    } else {
                        pc = l.exit.index();
                    }
                }
                Op::ForTest { f } => {
                    let l = &self.code.fors[f.index()];
                    if past(st, l.num, l.var, l.to) {
                        pc = l.exit.index();
                    }
                }
                Op::Next { f } => {
                    let l = &self.code.fors[f.index()];
                    if !(self.loop_back(st, ctx, l.ctr, rung) && self.charge(ctx, rung, l.charge)) {
                        pc = l.exit.index();
                        continue;
                    }
                    by_num!(l.num, T => increment::<T, S>(st, l.var), {});
                    if !inside(l.head) {
                        return Flow::ForTest(l.head);
                    }
                    rung = l.head;
                    pc = l.test.index();
                }
                Op::EndPou => return Flow::Return,
            }
        }
    }

    /// Runs fused rung `f` (its instruction's other operands given): its output's new value
    /// looked up from its contacts and its old value, written without a branch.
    ///
    /// # Safety
    /// `(f, table)` are the operands of a `Fused` instruction of `self.code`.
    #[inline(always)]
    unsafe fn fused_rung<S: Store + ?Sized>(&self, st: &mut S, f: FusedId, table: u16, neg: u8) {
        // SAFETY: this function's contract is `fused_operands`'.
        let (r, t) = unsafe { self.code.fused_operands(f, table) };
        let old = st.load::<u8>(r.out) as usize;
        st.store(
            r.out,
            lookup(t, (contact_bits(st, r) ^ neg as usize) | old << 8),
        );
    }

    /// The power fused head `f` gives (its instruction's other operands given).
    ///
    /// # Safety
    /// `(f, table)` are the operands of a `FusedHead` instruction of `self.code`.
    #[inline(always)]
    unsafe fn fused_power<S: Store + ?Sized>(&self, st: &S, f: FusedId, table: u16, neg: u8) -> u8 {
        // SAFETY: this function's contract is `fused_operands`'.
        let (r, t) = unsafe { self.code.fused_operands(f, table) };
        lookup(t, contact_bits(st, r) ^ neg as usize)
    }

    /// Counts one loop-back of `rung` in its counter at `ctr`; returns whether it may loop back.
    /// The first refused loop-back of a scan records [`FaultKind::LoopCap`]; later ones (control
    /// can come back through another loop-back rung) are refused silently.
    #[inline]
    fn loop_back<S: Store + ?Sized>(
        &self,
        st: &mut S,
        ctx: &mut ScanCtx<'_>,
        ctr: Addr,
        rung: RungId,
    ) -> bool {
        let c = st.load::<u64>(ctr).wrapping_add(1);
        st.store(ctr, c);
        let cap = self.config.loop_cap as u64;
        if c <= cap {
            return true;
        }
        if c == cap + 1 {
            ctx.faults.push(Fault {
                scan: ctx.scan,
                rung,
                kind: FaultKind::LoopCap,
            });
        }
        false
    }
}

impl Machine {
    /// Charges `charge` rungs of the scan budget for a call or a loop-back at `rung`; returns
    /// whether it may go ahead. A charge at a main-program rung of another budget task than the
    /// previous charge starts that task's count from zero (`budget`). The charge that takes a
    /// task past the budget records [`FaultKind::ScanBudget`]; it and every later charge of the
    /// task in the scan are refused. Out of line: it runs only at calls and loop-backs, and
    /// `exec`'s loop stays smaller without it.
    #[inline(never)]
    fn charge(&self, ctx: &mut ScanCtx<'_>, rung: RungId, charge: u32) -> bool {
        if let Some(task) = self.budget_task[rung.index()] {
            if ctx.budget.task != Some(task) {
                ctx.budget = BudgetSpent {
                    task: Some(task),
                    rungs: 0,
                };
            }
        }
        let before = ctx.budget.rungs;
        let after = before.saturating_add(charge as u64);
        ctx.budget.rungs = after;
        let budget = self.config.scan_budget;
        if after <= budget {
            return true;
        }
        if before <= budget {
            ctx.faults.push(Fault {
                scan: ctx.scan,
                rung,
                kind: FaultKind::ScanBudget,
            });
        }
        false
    }
}

/// The bytes of a fused rung's contact slots, slot `k` in bit `k`.
#[inline(always)]
fn contact_bits<S: Store + ?Sized>(st: &S, r: &FusedRung) -> usize {
    let mut bits = 0usize;
    for (k, &at) in r.at.iter().enumerate() {
        bits |= (st.load::<u8>(at) as usize) << k;
    }
    bits
}

/// TON on the instance at `i`; returns Q. `late`: the call that sees IN rise only starts the
/// time, with Q FALSE, later calls compare, and once Q is TRUE it stays (with ET) until IN
/// falls ([`plc_model::Dialect::timer_compares_after_edge`], matiec's `lib/timer.txt`).
#[inline]
fn ton<S: Store + ?Sized>(st: &mut S, now: i64, i: Addr, pt: i64, input: bool, late: bool) -> bool {
    st.store(i.offset(PT), pt as i32);
    if !input {
        st.store(i.offset(Q), 0u8);
        st.store(i.offset(ET), 0i32);
        st.store(i.offset(FLAGS), 0u8);
        return false;
    }
    let start = if st.load::<u8>(i.offset(FLAGS)) & ACTIVE == 0 {
        st.store(i.offset(FLAGS), ACTIVE | PREV_IN);
        st.store(i.offset(START), now);
        if late {
            st.store(i.offset(Q), 0u8);
            return false;
        }
        now
    } else {
        if late && st.load::<u8>(i.offset(Q)) != 0 {
            // matiec's TON, once elapsed (its STATE 2), keeps Q and ET until IN falls, even if
            // a later call gives a longer PT.
            return true;
        }
        st.load::<i64>(i.offset(START))
    };
    let et = now.wrapping_sub(start).min(pt);
    let q = et >= pt;
    st.store(i.offset(ET), et as i32);
    st.store(i.offset(Q), q as u8);
    q
}

/// TOF on the instance at `i`; returns Q. `late`: the call that sees IN fall only starts the
/// time, with Q TRUE.
#[inline]
fn tof<S: Store + ?Sized>(st: &mut S, now: i64, i: Addr, pt: i64, input: bool, late: bool) -> bool {
    st.store(i.offset(PT), pt as i32);
    if input {
        st.store(i.offset(Q), 1u8);
        st.store(i.offset(ET), 0i32);
        st.store(i.offset(FLAGS), PREV_IN);
        return true;
    }
    let flags = st.load::<u8>(i.offset(FLAGS));
    let mut active = flags & ACTIVE != 0;
    let start = if flags & PREV_IN != 0 {
        active = true;
        st.store(i.offset(START), now);
        if late {
            st.store(i.offset(FLAGS), ACTIVE);
            return st.load::<u8>(i.offset(Q)) != 0;
        }
        now
    } else {
        st.load::<i64>(i.offset(START))
    };
    if active {
        let et = now.wrapping_sub(start).min(pt);
        st.store(i.offset(ET), et as i32);
        if et >= pt {
            st.store(i.offset(Q), 0u8);
            active = false;
        }
    }
    st.store(i.offset(FLAGS), if active { ACTIVE } else { 0 });
    st.load::<u8>(i.offset(Q)) != 0
}

/// TP on the instance at `i`; returns Q. `late`: the call that sees IN rise only starts the
/// pulse, with Q TRUE, and later calls compare.
#[inline]
fn tp<S: Store + ?Sized>(st: &mut S, now: i64, i: Addr, pt: i64, input: bool, late: bool) -> bool {
    st.store(i.offset(PT), pt as i32);
    let flags = st.load::<u8>(i.offset(FLAGS));
    let mut pulsing = flags & ACTIVE != 0;
    let mut q = false;
    let start = if !pulsing && input && flags & PREV_IN == 0 {
        pulsing = true;
        st.store(i.offset(START), now);
        if late {
            st.store(i.offset(Q), 1u8);
            st.store(i.offset(FLAGS), ACTIVE | PREV_IN);
            return true;
        }
        now
    } else {
        st.load::<i64>(i.offset(START))
    };
    if pulsing {
        let et = now.wrapping_sub(start);
        if et >= pt {
            st.store(i.offset(ET), pt as i32);
            pulsing = false;
        } else {
            st.store(i.offset(ET), et as i32);
            q = true;
        }
    }
    if !pulsing && !input {
        st.store(i.offset(ET), 0i32);
    }
    st.store(i.offset(Q), q as u8);
    st.store(
        i.offset(FLAGS),
        (if pulsing { ACTIVE } else { 0 }) | input as u8,
    );
    q
}

/// CTU (`up`) or CTD on the instance at `i`: `clock` is CU/CD (0 or 1), `preset` R (CTU) or LD
/// (CTD); returns Q. `stop_at_preset`: CTU counts only while `CV < PV`, CTD while `CV > 0`
/// ([`plc_model::Dialect::counters_stop_at_preset`]); else to the INT limits.
#[inline]
fn counter<S: Store + ?Sized>(
    st: &mut S,
    i: Addr,
    pv: i16,
    clock: u8,
    preset: bool,
    up: bool,
    stop_at_preset: bool,
) -> bool {
    st.store(i.offset(PV), pv);
    let rising = clock & !st.load::<u8>(i.offset(PREV)) & 1 != 0;
    st.store(i.offset(PREV), clock);
    let mut cv = st.load::<i16>(i.offset(CV));
    if up {
        if preset {
            cv = 0;
        } else if rising && cv < if stop_at_preset { pv } else { i16::MAX } {
            cv += 1;
        }
    } else if preset {
        cv = pv;
    } else if rising && cv > if stop_at_preset { 0 } else { i16::MIN } {
        cv -= 1;
    }
    st.store(i.offset(CV), cv);
    let q = if up { cv >= pv } else { cv <= 0 };
    st.store(i.offset(Q), q as u8);
    q
}
