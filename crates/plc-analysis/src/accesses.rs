//! IN and OUT sets of every rung (Zhao & Yan, 2012, §2 "data dependence": IN(S), OUT(S)).
//!
//! A rung's IN holds every variable it may read, OUT every variable it may write, including the
//! implicit state the paper's examples leave out:
//! - a timer or counter box reads and writes its whole instance (`T1`), and reads its operands;
//!   reading a field (`T1.Q`, `C1.CV`) reads the instance;
//! - an edge contact reads and writes its hidden edge memory (`R3:edge1`);
//! - set/reset coils and boxes are *possible* writes: they are in OUT even though they write only
//!   when powered (a dependence on a possible write is still a dependence);
//! - compare operands, box operands and FOR bounds are reads; a FOR/NEXT index is read and written;
//! - a CALL reads and writes everything its subroutine (and what that calls) may read and write.
//!
//! Sets are sorted, duplicate-free `VarId` lists stored flat (offsets + ids), one slice per rung.
//! Power flow itself is not a variable. Cost: O(elements + accesses), calls summarised per POU
//! in callee-first order (the call graph is acyclic, checked by the reader).

use plc_model::*;
use std::ops::Range;

/// Flat per-unit variable lists: `list(i)` is the sorted set of unit `i`.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct VarSets {
    offsets: Vec<u32>,
    vars: Vec<VarId>,
}

impl VarSets {
    /// Builds from one list per unit (each is sorted and deduplicated here).
    pub fn from_lists<I: IntoIterator<Item = Vec<VarId>>>(lists: I) -> VarSets {
        let mut s = VarSets {
            offsets: vec![0],
            vars: Vec::new(),
        };
        for mut l in lists {
            l.sort_unstable();
            l.dedup();
            s.vars.extend_from_slice(&l);
            s.offsets.push(s.vars.len() as u32);
        }
        s
    }
    /// Builds from lists that are already sorted and duplicate-free.
    pub fn from_sorted(lists: &[Vec<VarId>]) -> VarSets {
        let total = lists.iter().map(Vec::len).sum();
        let mut s = VarSets {
            offsets: Vec::with_capacity(lists.len() + 1),
            vars: Vec::with_capacity(total),
        };
        s.offsets.push(0);
        for l in lists {
            debug_assert!(l.windows(2).all(|w| w[0] < w[1]));
            s.vars.extend_from_slice(l);
            s.offsets.push(s.vars.len() as u32);
        }
        s
    }
    pub fn len(&self) -> usize {
        self.offsets.len() - 1
    }
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }
    /// The set of unit `i`.
    pub fn list(&self, i: usize) -> &[VarId] {
        &self.vars[self.offsets[i] as usize..self.offsets[i + 1] as usize]
    }
    /// Total number of entries over all units.
    pub fn total(&self) -> usize {
        self.vars.len()
    }
}

/// IN/OUT of every rung (indexed by `RungId`), calls included.
#[derive(Clone, Debug)]
pub struct Accesses {
    pub reads: VarSets,
    pub writes: VarSets,
}

impl Accesses {
    pub fn ins(&self, r: RungId) -> &[VarId] {
        self.reads.list(r.index())
    }
    pub fn outs(&self, r: RungId) -> &[VarId] {
        self.writes.list(r.index())
    }
}

/// Computes IN and OUT for every rung of the program.
pub fn accesses(p: &Program) -> Accesses {
    // Summaries of called subroutines, callees first (the call graph is acyclic).
    let mut summary: Vec<(Vec<VarId>, Vec<VarId>)> = vec![(Vec::new(), Vec::new()); p.pous().len()];
    // Per rung, in POU order; rungs are stored in listing order afterwards.
    // Per rung, where its reads and its writes lie in `all_reads` and `all_writes`.
    let mut read_at: Vec<Range<u32>> = vec![0..0; p.rungs().len()];
    let mut write_at: Vec<Range<u32>> = vec![0..0; p.rungs().len()];
    let (mut all_reads, mut all_writes) = (Vec::new(), Vec::new());
    let mut reads = Vec::new();
    let mut writes = Vec::new();
    for pou in callee_first_order(p) {
        let is_sub = pou.index() != 0;
        let (mut sub_r, mut sub_w) = (Vec::new(), Vec::new());
        for r in p.pou_rungs(pou) {
            one_rung(p, r, &summary, &mut reads, &mut writes);
            if is_sub {
                sub_r.extend_from_slice(&reads);
                sub_w.extend_from_slice(&writes);
            }
            let (rs, ws) = (all_reads.len() as u32, all_writes.len() as u32);
            all_reads.extend_from_slice(&reads);
            all_writes.extend_from_slice(&writes);
            read_at[r.index()] = rs..all_reads.len() as u32;
            write_at[r.index()] = ws..all_writes.len() as u32;
        }
        if is_sub {
            for l in [&mut sub_r, &mut sub_w] {
                l.sort_unstable();
                l.dedup();
            }
            summary[pou.index()] = (sub_r, sub_w);
        }
    }
    // Main first in listing order, and the callee-first order puts main last: re-lay in rung order.
    let gather = |all: &[VarId], at: &[Range<u32>]| {
        let mut s = VarSets {
            offsets: Vec::with_capacity(at.len() + 1),
            vars: Vec::with_capacity(all.len()),
        };
        s.offsets.push(0);
        for r in at {
            s.vars
                .extend_from_slice(&all[r.start as usize..r.end as usize]);
            s.offsets.push(s.vars.len() as u32);
        }
        s
    };
    Accesses {
        reads: gather(&all_reads, &read_at),
        writes: gather(&all_writes, &write_at),
    }
}

/// The sorted IN and OUT of one rung, into `reads` and `writes` (cleared first).
fn one_rung(
    p: &Program,
    r: RungId,
    summary: &[(Vec<VarId>, Vec<VarId>)],
    reads: &mut Vec<VarId>,
    writes: &mut Vec<VarId>,
) {
    reads.clear();
    writes.clear();
    rung_accesses(
        &p.rung(r).series,
        reads,
        writes,
        &mut |callee, reads, writes| {
            let (sr, sw) = &summary[callee.index()];
            reads.extend_from_slice(sr);
            writes.extend_from_slice(sw);
        },
    );
    if let Some(Element::Next { head }) = p.rung(r).series.last() {
        if let Some(Element::For { var, .. }) = p.rung(*head).series.last() {
            reads.push(*var);
            writes.push(*var);
        }
    }
    for l in [reads, writes] {
        l.sort_unstable();
        l.dedup();
    }
}

/// POUs ordered so that every callee comes before its callers.
fn callee_first_order(p: &Program) -> Vec<PouId> {
    let mut callees: Vec<Vec<PouId>> = vec![Vec::new(); p.pous().len()];
    for r in p.rung_ids() {
        walk_elements(&p.rung(r).series, &mut |e| {
            if let Element::Call { pou } = e {
                callees[p.rung(r).pou.index()].push(*pou);
            }
        });
    }
    let mut done = vec![false; p.pous().len()];
    let mut order = Vec::with_capacity(p.pous().len());
    for root in 0..p.pous().len() {
        if done[root] {
            continue;
        }
        let mut stack = vec![(root, 0usize)];
        done[root] = true;
        while let Some(&mut (pou, ref mut i)) = stack.last_mut() {
            if let Some(&c) = callees[pou].get(*i) {
                *i += 1;
                if !done[c.index()] {
                    done[c.index()] = true;
                    stack.push((c.index(), 0));
                }
            } else {
                order.push(p.pous().id(pou));
                stack.pop();
            }
        }
    }
    order
}

/// Appends the reads and writes of a series; `call` adds a callee's summary.
pub(crate) fn rung_accesses(
    series: &[Element],
    reads: &mut Vec<VarId>,
    writes: &mut Vec<VarId>,
    call: &mut impl FnMut(PouId, &mut Vec<VarId>, &mut Vec<VarId>),
) {
    let operand = |o: &Operand, reads: &mut Vec<VarId>| {
        if let Some(v) = o.var() {
            reads.push(v);
        }
    };
    for e in series {
        match e {
            Element::Contact { var, kind } => {
                reads.push(var.var);
                if let ContactKind::Rising { memory } | ContactKind::Falling { memory } = kind {
                    reads.push(*memory);
                    writes.push(*memory);
                }
            }
            Element::Compare { a, b, .. } => {
                operand(a, reads);
                operand(b, reads);
            }
            Element::Or(bs) | Element::Branch(bs) => {
                for b in bs {
                    rung_accesses(b, reads, writes, call);
                }
            }
            Element::Coil { var, .. } | Element::Set(var) | Element::Reset(var) => {
                writes.push(*var)
            }
            Element::Timer { instance, pt, .. } => {
                reads.push(*instance);
                writes.push(*instance);
                operand(pt, reads);
            }
            Element::Ctu {
                instance,
                pv,
                reset: other,
            }
            | Element::Ctd {
                instance,
                pv,
                load: other,
            } => {
                reads.push(*instance);
                writes.push(*instance);
                operand(pv, reads);
                operand(other, reads);
            }
            Element::Bistable {
                instance, reset, ..
            } => {
                reads.push(*instance);
                writes.push(*instance);
                operand(reset, reads);
            }
            Element::Trigger { instance, .. } => {
                reads.push(*instance);
                writes.push(*instance);
            }
            Element::Ctud { instance, inputs } => {
                reads.push(*instance);
                writes.push(*instance);
                for o in inputs.operands() {
                    operand(o, reads);
                }
            }
            Element::Move { from, to } => {
                operand(from, reads);
                writes.push(*to);
            }
            Element::Arith { a, b, out, .. } => {
                operand(a, reads);
                operand(b, reads);
                writes.push(*out);
            }
            Element::Function { args, out, .. } => {
                for a in args.iter() {
                    operand(a, reads);
                }
                writes.push(*out);
            }
            Element::Jmp { .. }
            | Element::Ret
            | Element::End
            | Element::Next { .. }
            | Element::RangeFault => {}
            Element::Call { pou } => call(*pou, reads, writes),
            Element::For { var, bounds, .. } => {
                operand(&bounds.from, reads);
                operand(&bounds.to, reads);
                reads.push(*var);
                writes.push(*var);
            }
        }
    }
}
