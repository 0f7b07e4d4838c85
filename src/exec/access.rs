//! The slots each rung's lowered instructions actually read and write: the ground truth a
//! parallel plan is checked against (`parallel::check`), independent of the analysis' IN/OUT
//! sets the plan was built from.
//!
//! A rung's instructions run from its `Rung` marker to the next marker (or the end of its POU);
//! a CALL adds every instruction of the called POU, transitively (whole POUs: which of their
//! rungs run depends on the data, so all of them count). Instance boxes touch every slot of
//! their instance; loop-backs their loop counter; FOR heads and tests their index. Constants
//! are no slots. It deliberately over-approximates (a contact after a taken jump still counts):
//! a check on it can only be too strict, never too lax.

use super::layout::{COUNTER_SLOTS, TIMER_SLOTS};
use super::lower::{Op, CONST};
use super::Machine;
use crate::model::RungId;

impl Machine {
    /// Appends the slots `rung`'s instructions (and those of the POUs it calls) may read to
    /// `reads` and may write to `writes` (unsorted, maybe with repeats).
    pub fn rung_accesses(&self, rung: RungId, reads: &mut Vec<u32>, writes: &mut Vec<u32>) {
        let mut pous: Vec<u32> = Vec::new();
        let start = self.rung_op[rung.index()] as usize + 1;
        self.op_accesses(start, true, reads, writes, &mut pous);
        let mut i = 0;
        while i < pous.len() {
            self.op_accesses(pous[i] as usize, false, reads, writes, &mut pous);
            i += 1;
        }
    }

    /// The accesses of the instructions from `pc` to the next rung marker (`one_rung`) or to
    /// the end of the POU; callees not yet in `pous` are appended to it.
    fn op_accesses(
        &self,
        mut pc: usize,
        one_rung: bool,
        reads: &mut Vec<u32>,
        writes: &mut Vec<u32>,
        pous: &mut Vec<u32>,
    ) {
        let read = |x: u32, reads: &mut Vec<u32>| {
            if x & CONST == 0 {
                reads.push(x);
            }
        };
        loop {
            let op = self.ops[pc];
            pc += 1;
            match op {
                Op::Rung { .. } if one_rung => return,
                Op::EndPou => return,
                Op::Rung { .. }
                | Op::OrOpen
                | Op::OrNext
                | Op::OrClose
                | Op::BrOpen
                | Op::BrNext
                | Op::BrClose
                | Op::Jmp { .. }
                | Op::Ret
                | Op::End => {}
                Op::Contact { slot, .. } => reads.push(slot),
                Op::Contact2 { a, b, .. } => reads.extend([a, b]),
                Op::Contact3 { a, b, c, .. } => reads.extend([a, b, c]),
                Op::ContactN { s, .. } => reads.extend(s.iter().map(|&x| x as u32)),
                Op::Rising { slot, mem } | Op::Falling { slot, mem } => {
                    reads.extend([slot, mem]);
                    writes.push(mem);
                }
                Op::CmpInt { a, b, .. } | Op::CmpReal { a, b, .. } => {
                    read(a, reads);
                    read(b, reads);
                }
                Op::Coil { slot, .. } => writes.push(slot),
                Op::Timer { inst, pt, .. } => {
                    reads.extend(inst..inst + TIMER_SLOTS);
                    writes.extend(inst..inst + TIMER_SLOTS);
                    read(pt, reads);
                }
                Op::Ctu { inst, pv, reset: x } | Op::Ctd { inst, pv, load: x } => {
                    reads.extend(inst..inst + COUNTER_SLOTS);
                    writes.extend(inst..inst + COUNTER_SLOTS);
                    read(pv, reads);
                    read(x, reads);
                }
                Op::Move { from, to } => {
                    read(from, reads);
                    writes.push(to);
                }
                Op::Arith { a, b, out, .. } => {
                    read(a, reads);
                    read(b, reads);
                    writes.push(out);
                }
                Op::JmpBack { ctr, .. } => {
                    reads.push(ctr);
                    writes.push(ctr);
                }
                Op::Call { to } => {
                    if !pous.contains(&to) {
                        pous.push(to);
                    }
                }
                Op::For { f } => {
                    let l = &self.fors[f as usize];
                    read(l.from, reads);
                    writes.push(l.var);
                }
                Op::ForTest { f } => {
                    let l = &self.fors[f as usize];
                    reads.push(l.var);
                    read(l.to, reads);
                }
                Op::Next { f } => {
                    let l = &self.fors[f as usize];
                    reads.extend([l.var, l.ctr]);
                    writes.extend([l.var, l.ctr]);
                }
            }
        }
    }
}
