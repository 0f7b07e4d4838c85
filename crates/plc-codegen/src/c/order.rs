//! The order in which a ladder POU's rungs are emitted, and each rung's row (`rows`), so that
//! rows of one kernel follow each other in long runs.
//!
//! Rungs keep sequential semantics. The rungs of a straight-line region — no jump, label a
//! jump targets, FOR, NEXT, CALL, RET or END inside, and no rung that may record a fault (an
//! integer DIV or MOD by a variable or zero; a standard function), whose faults must keep their
//! order — are levelled
//! by their data dependences (flow, anti and output, from the rungs' IN and OUT sets,
//! `plc_analysis::accesses`, with the ASAP levelling `plc_analysis::dependences::Leveller`
//! — the levelling the parallel scan relies on, Zhao & Yan 2012): two rungs of one level have
//! no dependence between them, so any order of a level's rungs, after every rung of the levels
//! before it, computes the same state as the program order. Within a level the rungs written
//! as statements come first in program order, then the rows grouped by kernel (in the order the
//! kernels were first met), each group in program order. A rung that bounds a region gets a
//! level above every rung before it, and the rungs after it levels above its own, so no rung
//! crosses it.
//!
//! Not here: what a row is (`rows`), the cutting into functions (`mod`).

use super::ladder::Shared;
use super::rows::Kernels;
use super::shape::Row;
use plc_analysis::dependences::Leveller;
use plc_analysis::Accesses;
use plc_model::{walk_elements, ArithOp, Element, Operand, Program, RungId};

/// A POU's emission order and, per position, the weight of its rung in a chunk function (a
/// rung written as statements: 1; a row: 1 when it starts a run, else 0).
pub(crate) struct Plan {
    pub order: Vec<RungId>,
    pub weight: Vec<usize>,
}

/// Every rung's row (`None`: statements), for the ladder POUs `ladder` (true per POU).
pub(crate) fn rows(sh: &Shared, ladder: &[bool], kernels: &mut Kernels) -> Vec<Option<Row>> {
    let p = sh.p;
    let mut out = vec![None; p.rungs().len()];
    for (i, pou) in p.pous().iter().enumerate() {
        if !ladder[i] {
            continue;
        }
        for r in pou.rung_ids() {
            out[r.index()] = kernels.row(sh, r);
        }
    }
    out
}

/// The plan of POU `pou`; `reorder`: group rows by level and kernel (else program order).
pub(crate) fn plan(
    p: &Program,
    acc: Option<&Accesses>,
    rows: &[Option<Row>],
    labels: &[bool],
    pou: usize,
) -> Plan {
    let range = p.pous()[pou].rungs.clone();
    let mut order: Vec<RungId> = p.pous()[pou].rung_ids().collect();
    if let Some(acc) = acc {
        let mut lev = Leveller::new(p.vars().len());
        let (mut floor, mut top) = (0u32, 0u32);
        let mut key = Vec::with_capacity(order.len());
        for &r in &order {
            let level = if bounds_region(p, labels, r) {
                let l = lev.place(acc.ins(r), acc.outs(r), top + 1);
                floor = l + 1;
                l
            } else {
                lev.place(acc.ins(r), acc.outs(r), floor)
            };
            top = top.max(level);
            let class = rows[r.index()].as_ref().map_or(0, |row| row.kernel + 1);
            key.push((level, class));
        }
        let mut idx: Vec<usize> = (0..order.len()).collect();
        idx.sort_by_key(|&i| key[i]);
        order = idx
            .into_iter()
            .map(|i| p.rungs().id(range.start as usize + i))
            .collect();
    }
    let mut weight = Vec::with_capacity(order.len());
    let mut prev = None;
    for &r in &order {
        let k = rows[r.index()].as_ref().map(|row| row.kernel);
        weight.push(usize::from(k.is_none() || k != prev));
        prev = k;
    }
    Plan { order, weight }
}

/// Whether rung `r` bounds a straight-line region (see the module doc).
fn bounds_region(p: &Program, labels: &[bool], r: RungId) -> bool {
    if labels[r.index()] {
        return true;
    }
    let mut bound = false;
    walk_elements(&p.rung(r).series, &mut |e| {
        bound |= match e {
            e if e.transfers_control() => true,
            Element::Function { .. } => true,
            // DIV or MOD by a non-zero constant never records a fault.
            Element::Arith { op, b, .. } => {
                matches!(op, ArithOp::Div | ArithOp::Mod)
                    && !matches!(b, Operand::Const(v) if v.to_bits() != 0)
            }
            _ => false,
        }
    });
    bound
}
