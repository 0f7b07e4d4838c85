//! FBD blocks of the standard function blocks SR, RS, R_TRIG, F_TRIG and CTUD (IEC 61131-3 2nd
//! ed., 2.5.2.3) → one rung each: the first BOOL input as a condition, then the box (which
//! takes the rest as operands), then the outputs, read through the instance's fields as for
//! the timers and counters (docs/fbd.md).
//!
//! Not here: the semantics (`crates/plc-exec/src/fb.rs`), the other blocks (`blocks`).

use super::{condition, Cx, Net, Result, Val};
use crate::model::*;
use plc_model::*;

impl Cx<'_> {
    /// SR, RS: `[contact S1/S, sr/rs B reset]`; output Q1.
    pub(super) fn bistable(
        &mut self,
        nx: &mut Net,
        b: BlockId,
        vals: &[(Val, &str)],
        kind: BistableKind,
        instance: &str,
    ) -> Result<Series> {
        let id = Some(nx.net.block(b).id);
        let inst = self.builtin_instance(nx, b, kind.fb(), instance)?;
        let what = "a bistable's input";
        let set = self.coerce(nx, &vals[0].0, Type::Bool, what, vals[0].1, id)?;
        let reset = self.coerce(nx, &vals[1].0, Type::Bool, what, vals[1].1, id)?;
        let mut first = condition(set, false);
        first.push(Element::Bistable {
            kind,
            instance: inst,
            reset,
        });
        self.instance_outputs(nx, b, inst, &[(Field::Q1, Type::Bool)], first)
    }

    /// R_TRIG, F_TRIG: `[contact CLK, r_trig/f_trig E]`; output Q.
    pub(super) fn trigger(
        &mut self,
        nx: &mut Net,
        b: BlockId,
        vals: &[(Val, &str)],
        kind: TriggerKind,
        instance: &str,
    ) -> Result<Series> {
        let id = Some(nx.net.block(b).id);
        let inst = self.builtin_instance(nx, b, kind.fb(), instance)?;
        let clk = self.coerce(nx, &vals[0].0, Type::Bool, "a CLK", vals[0].1, id)?;
        let mut first = condition(clk, false);
        first.push(Element::Trigger {
            kind,
            instance: inst,
        });
        self.instance_outputs(nx, b, inst, &[(Field::Q, Type::Bool)], first)
    }

    /// CTUD: `[contact CU, ctud C cd r ld pv]`; outputs QU, QD, CV.
    pub(super) fn ctud(
        &mut self,
        nx: &mut Net,
        b: BlockId,
        vals: &[(Val, &str)],
        instance: &str,
    ) -> Result<Series> {
        let id = Some(nx.net.block(b).id);
        let inst = self.builtin_instance(nx, b, FbKind::Ctud, instance)?;
        let what = "a counter's input";
        let mut ops = Vec::with_capacity(4);
        for (v, path) in &vals[..4] {
            ops.push(self.coerce(nx, v, Type::Bool, what, path, id)?);
        }
        let pv = self.coerce(nx, &vals[4].0, Type::Int, "a counter's PV", vals[4].1, id)?;
        let mut first = condition(ops[0], false);
        first.push(Element::Ctud {
            instance: inst,
            inputs: Box::new(CtudInputs {
                cd: ops[1],
                reset: ops[2],
                load: ops[3],
                pv,
            }),
        });
        let outs = [
            (Field::Qu, Type::Bool),
            (Field::Qd, Type::Bool),
            (Field::Cv, Type::Int),
        ];
        self.instance_outputs(nx, b, inst, &outs, first)
    }
}
