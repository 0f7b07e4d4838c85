//! The bytes each rung's lowered instructions actually read and write: the ground truth a
//! parallel plan is checked against (`parallel::planning::check`), independent of the analysis' IN/OUT
//! sets the plan was built from.
//!
//! A rung's instructions run from its `Rung` marker to the next marker (or the end of its POU);
//! a CALL adds every instruction of the called POU, transitively (whole POUs: which of their
//! rungs run depends on the data, so all of them count). Every access is a span of bytes
//! (address, width), in the width the interpreter loads or stores; instance boxes touch every
//! byte of their instance; loop-backs their loop counter; FOR heads and tests their index.
//! Constants are read like variables (no instruction writes them). It deliberately
//! over-approximates (a contact after a taken jump still counts): a check on it can only be too
//! strict, never too lax.

use super::layout::{Repr, COUNTER_BYTES, CTUD_BYTES, TIMER_BYTES, TRIGGER_BYTES};
use super::lower::{Code, Op, Pc};
use super::store::Addr;
use super::strings::STR_SLOT;
use super::Machine;
use plc_model::{RungId, VarClass};

/// A span of bytes an instruction reads or writes: (first byte, width).
pub type Span = (Addr, u32);

impl Machine {
    /// Appends the byte spans `rung`'s instructions (and those of the POUs it calls) may read to
    /// `reads` and may write to `writes` (unsorted, maybe with repeats).
    pub fn rung_accesses(&self, rung: RungId, reads: &mut Vec<Span>, writes: &mut Vec<Span>) {
        let code: &Code = &self.code;
        let mut pous: Vec<Pc> = Vec::new();
        let start = code.rung_op[rung.index()].index();
        code.op_accesses(start, true, reads, writes, &mut pous);
        let mut i = 0;
        while i < pous.len() {
            code.op_accesses(pous[i].index(), false, reads, writes, &mut pous);
            i += 1;
        }
    }

    /// The byte spans of the program's inputs: what a driver writes before every scan.
    pub fn input_spans(&self) -> Vec<Span> {
        (self.vars.iter_enumerated())
            .filter(|(_, v)| v.class == VarClass::Input)
            .map(|(i, v)| {
                let at = self.layout.start(i);
                (at, super::layout::type_size(v.ty))
            })
            .collect()
    }
}

impl Code {
    /// One past the last byte any instruction (of any POU) or loop counter reads or writes
    /// (`raw::CheckedCode::new` checks it against the state size).
    ///
    /// # Panics
    /// If an instruction or operand index of the code is out of range (`CheckedCode::new`
    /// checks those first, with a message).
    pub(crate) fn access_end(&self) -> u64 {
        let (mut reads, mut writes, mut callees) = (Vec::new(), Vec::new(), Vec::new());
        let mut end = 0u64;
        for &entry in &self.pou_entry {
            reads.clear();
            writes.clear();
            self.op_accesses(entry.index(), false, &mut reads, &mut writes, &mut callees);
            for &(at, w) in reads.iter().chain(&writes) {
                end = end.max(at.0 as u64 + w as u64);
            }
        }
        for &(_, at) in &self.counters {
            end = end.max(at.0 as u64 + 8);
        }
        end
    }

    /// The accesses of the instructions from `pc` (a rung's start when `one_rung`) to the start
    /// of the next rung (`one_rung`) or to the end of the POU; callees not yet in `pous` are
    /// appended to it.
    fn op_accesses(
        &self,
        mut pc: usize,
        one_rung: bool,
        reads: &mut Vec<Span>,
        writes: &mut Vec<Span>,
        pous: &mut Vec<Pc>,
    ) {
        let byte = |a: Addr| (a, 1);
        let first = pc;
        loop {
            let op = self.ops[pc];
            pc += 1;
            match op {
                _ if one_rung && pc - 1 != first && op.starts_rung().is_some() => return,
                Op::EndPou => return,
                Op::Fused { f, .. } => {
                    // Every slot is loaded (padding included), and the output's old value.
                    let r = &self.fused[f.index()];
                    reads.extend(r.at.iter().map(|&a| byte(a)));
                    reads.push(byte(r.out));
                    writes.push(byte(r.out));
                }
                Op::FusedHead { f, .. } => {
                    let r = &self.fused[f.index()];
                    reads.extend(r.at.iter().map(|&a| byte(a)));
                }
                Op::Rung { .. }
                | Op::OrOpen
                | Op::OrNext
                | Op::OrClose
                | Op::BrOpen
                | Op::BrNext
                | Op::BrClose
                | Op::Jmp { .. }
                | Op::Ret
                | Op::RangeFault
                | Op::End => {}
                Op::Contact { at, .. } => reads.push(byte(at)),
                Op::Contact2 { a, b, .. } => reads.extend([byte(a), byte(b)]),
                Op::Contact3 { a, b, c, .. } => reads.extend([byte(a), byte(b), byte(c)]),
                Op::ContactN { s, .. } => reads.extend(s.iter().map(|&x| byte(Addr(x as u32)))),
                Op::Rising { at, mem } | Op::Falling { at, mem } => {
                    reads.extend([byte(at), byte(mem)]);
                    writes.push(byte(mem));
                }
                Op::Cmp { num, a, b, .. } => reads.extend([(a, num.width()), (b, num.width())]),
                Op::Coil { at, .. } => writes.push(byte(at)),
                Op::Timer { inst, pt, .. } => {
                    reads.extend([(inst, TIMER_BYTES), (pt, Repr::I32.width())]);
                    writes.push((inst, TIMER_BYTES));
                }
                Op::Ctu { inst, pv, reset: x } | Op::Ctd { inst, pv, load: x } => {
                    reads.extend([(inst, COUNTER_BYTES), (pv, Repr::I16.width()), byte(x)]);
                    writes.push((inst, COUNTER_BYTES));
                }
                Op::Bistable { inst, reset, .. } => {
                    reads.extend([byte(inst), byte(reset)]);
                    writes.push(byte(inst));
                }
                Op::Trigger { inst, .. } => {
                    reads.push((inst, TRIGGER_BYTES));
                    writes.push((inst, TRIGGER_BYTES));
                }
                Op::Ctud { inst, pins } => {
                    let c = self.ctuds[pins.index()];
                    reads.extend([(inst, CTUD_BYTES), (c.pv, Repr::I16.width())]);
                    reads.extend([byte(c.cd), byte(c.reset), byte(c.load)]);
                    writes.push((inst, CTUD_BYTES));
                }
                Op::Move { width, from, to } => {
                    let w = width.bytes();
                    reads.push((from, w));
                    writes.push((to, w));
                }
                Op::StrMove { from, to } => {
                    reads.push((from, STR_SLOT));
                    writes.push((to, STR_SLOT));
                }
                Op::StrCmp { a, b, .. } => reads.extend([(a, STR_SLOT), (b, STR_SLOT)]),
                Op::Func { call } => {
                    let c = &self.funcs[call.index()];
                    let width = |t| match t {
                        plc_model::Type::String => STR_SLOT,
                        t => Repr::of(t).map_or(1, Repr::width),
                    };
                    reads.extend(c.args.iter().map(|&(a, t)| (a, width(t))));
                    writes.push((c.out, width(c.ty)));
                }
                Op::Arith { num, a, b, out, .. } => {
                    let w = num.width();
                    reads.extend([(a, w), (b, w)]);
                    writes.push((out, w));
                }
                Op::JmpBack { ctr, .. } => {
                    reads.push((ctr, 8));
                    writes.push((ctr, 8));
                }
                Op::Call { to, .. } => {
                    if !pous.contains(&to) {
                        pous.push(to);
                    }
                }
                Op::For { f } => {
                    let l = &self.fors[f.index()];
                    let w = l.num.width();
                    reads.push((l.from, w));
                    writes.push((l.var, w));
                }
                Op::ForTest { f } => {
                    let l = &self.fors[f.index()];
                    let w = l.num.width();
                    reads.extend([(l.var, w), (l.to, w)]);
                }
                Op::Next { f } => {
                    let l = &self.fors[f.index()];
                    let w = l.num.width();
                    reads.extend([(l.var, w), (l.ctr, 8)]);
                    writes.extend([(l.var, w), (l.ctr, 8)]);
                }
            }
        }
    }
}
