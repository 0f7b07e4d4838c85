//! FBD bodies → C: each network follows its fragment tree (the FBD text-generation paper) as
//! nested `if` blocks, blocks in execution order inside each; a compound control arc is a BOOL
//! run flag, a local reset at the network's start and set in each source fragment; every output
//! that feeds an arc is one local named from the block id and output number (`_8_0`).
//!
//! A block's statements come from the rung the FBD lowering (`plc_fbd::lower`) made of it (so its
//! semantics are the
//! interpreter's, by construction), but the structure comes from the [`Plan`]: the guard and
//! landing rungs of the lowering become the `if (…) {` and `}` of their fragment, never jumps.
//!
//! Invariant relied on: the rungs of one lowered network are, in order, one per step of its
//! plan (guard for `Enter`, the block's rung for `Block`, landing for `Leave`), except that a
//! block gated by its EN has its guard rung before its rung and its landing rung after it;
//! those two are written as ladder rungs (a `goto` over the block).

use super::ladder::{c_type, negate, Body};
use plc_fbd::{FbdPou, FragmentKind, LoweredCopy, Plan, Step};
use plc_model::{Program, RungId, VarId};
use std::collections::HashMap;

/// The variables of one lowered copy that become locals of its function: the arc temps
/// (`_<block>_<pin>`) and the run flags (`_run_<network>_<fragment>`), each with its local name.
pub(crate) fn locals(
    p: &Program,
    hidden: &HashMap<&str, VarId>,
    pou: &FbdPou,
    prefix: &str,
) -> Vec<(VarId, String)> {
    let mut out = Vec::new();
    for (k, (net, plan)) in pou.networks.iter().zip(&pou.plans).enumerate() {
        for blk in &net.blocks {
            for (j, pin) in blk.outputs.iter().enumerate() {
                let name = format!("{prefix}_{}_{}", blk.id, pin.name);
                if let Some(&v) = hidden.get(name.as_str()) {
                    out.push((v, format!("_{}_{j}", blk.id)));
                }
            }
        }
        for (f, frag) in plan.fragments.iter().enumerate() {
            if matches!(frag.kind, FragmentKind::Compound(_)) {
                let name = format!("{prefix}_run_{}_{}", net.id, frag.name);
                if let Some(&v) = hidden.get(name.as_str()) {
                    out.push((v, format!("_run{k}_{f}")));
                }
            }
        }
    }
    let _ = p;
    out
}

/// Declares the locals at the top of the function.
pub(crate) fn declare(b: &mut Body, p: &Program, locals: &[(VarId, String)]) {
    for (v, name) in locals {
        let t = p.var(*v).ty;
        // A STRING local is a struct: zeroed (the empty string) by `{0}`.
        let zero = if t == plc_model::Type::String {
            "{0}"
        } else {
            "0"
        };
        let ty = c_type(t);
        b.line(&format!("{ty} {name} = {zero}; (void){name};"));
        b.locals.insert(*v, name.clone());
    }
}

/// Emits the POU of `copy`: its networks as fragment trees, any other rung (the TIME
/// accumulation's) as a ladder rung.
pub(crate) fn pou(b: &mut Body, p: &Program, pou: &FbdPou, copy: &LoweredCopy) {
    let range = p.pou(copy.pou).rungs.clone();
    let mut r = range.start;
    while r < range.end {
        match copy
            .networks
            .iter()
            .position(|n| n.start == r && !n.is_empty())
        {
            Some(k) => {
                network(b, p, &pou.plans[k], copy.networks[k].start, &copy.blocks[k]);
                r = copy.networks[k].end;
            }
            None => {
                b.rung(p.rungs().id(r as usize));
                r += 1;
            }
        }
    }
}

fn network(b: &mut Body, p: &Program, plan: &Plan, start: u32, blocks: &[RungId]) {
    let mut cursor = start;
    for step in &plan.steps {
        let r = p.rungs().id(cursor as usize);
        cursor += 1;
        match *step {
            Step::Enter(f) => {
                b.label(r);
                let frag = &plan.fragments[f.index()];
                let comment = super::names::comment(&format!("{}: {}", frag.name, frag.condition));
                b.line(&format!("/* {comment} */"));
                let jump = b.guard(r, &p.rung(r).series);
                let cond = negate(&jump);
                b.line(&format!("if ({cond}) {{"));
                b.indent += 1;
            }
            Step::Block(blk) => {
                let target = blocks[blk.index()];
                // An EN guard before the block's rung, its landing after it.
                let gated = r != target;
                for g in r.raw()..target.raw() {
                    b.rung(p.rungs().id(g as usize));
                }
                b.rung(target);
                cursor = target.raw() + 1;
                if gated {
                    b.rung(p.rungs().id(cursor as usize));
                    cursor += 1;
                }
            }
            Step::Leave(_) => {
                b.indent -= 1;
                b.line("}");
                let series = &p.rung(r).series;
                if !series.is_empty() {
                    b.rung(r);
                }
            }
        }
    }
}
