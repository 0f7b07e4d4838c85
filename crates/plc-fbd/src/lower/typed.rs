//! The typed form of a lowered network ([`TypedNetwork`]): per block, what each input pin
//! reads — an arc, a variable of this POU's scope, or the constant as its block typed it —
//! and the variables each output writes. Built after the network is lowered, so every name it
//! looks up has already resolved; the resolver turns it into a function block type's own form.

use super::{Cx, Net, PinSlot};
use crate::model::*;
use crate::types::{Pin, TypedBlock, TypedNetwork};
use plc_model::untyped;
use plc_model::*;

impl Cx<'_> {
    pub(super) fn typed_network(&self, nx: &Net) -> TypedNetwork<VarRef> {
        let blocks = nx
            .net
            .blocks
            .iter_enumerated()
            .map(|(b, blk)| {
                let inputs = blk
                    .inputs
                    .iter()
                    .enumerate()
                    .map(|(i, p)| self.pin(nx, p.input.as_ref()?, Some(PinSlot(b, i))))
                    .collect();
                let cond = blk.cond.as_ref().and_then(|c| self.pin(nx, c, None));
                let outputs = blk
                    .outputs
                    .iter()
                    .map(|o| {
                        o.vars
                            .iter()
                            .filter_map(|(name, _)| self.env.writable(name, "a block output").ok())
                            .map(|var| VarRef { var, field: None })
                            .collect()
                    })
                    .collect();
                TypedBlock {
                    inputs,
                    cond,
                    outputs,
                }
            })
            .collect();
        TypedNetwork { blocks }
    }

    /// What `input` reads; a constant of a condition (`slot` `None`) is BOOL.
    fn pin(&self, nx: &Net, input: &Input, slot: Option<PinSlot>) -> Option<Pin<VarRef>> {
        Some(match input {
            Input::Arc { from, pin } => Pin::Arc {
                block: *from,
                output: *pin,
            },
            Input::Variable(name) => Pin::Variable(self.env.lookup(name).ok()?.0),
            Input::Constant(c) => match slot {
                Some(s) => Pin::Constant(*nx.constants.get(&s)?),
                None => {
                    let u = super::pins::constant(c, &|n| self.env.lookup(n)).ok()?;
                    match untyped::typed(&u, Type::Bool, "a condition", &c.text()).ok()? {
                        Operand::Const(v) => Pin::Constant(v),
                        Operand::Var(r) => Pin::Variable(r),
                    }
                }
            },
        })
    }
}
