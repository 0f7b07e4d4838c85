//! Function block instances in a network: built-in timers and counters (read through their
//! fields), and calls of user function block instances (each its own POU).

use super::{field_op, steps, var_op, Cx, InstanceRef, Net, PinSlot, Result};
use crate::model::*;
use plc_diag::{Invalid, LoadError};
use plc_model::*;

impl Cx<'_> {
    pub(super) fn builtin_instance(
        &self,
        nx: &Net,
        b: BlockId,
        fb: FbKind,
        name: &str,
    ) -> Result<VarId> {
        let blk = nx.net.block(b);
        let path = format!("{}.instance", blk.path);
        let e = |k| LoadError::fbd(&nx.net.id, Some(blk.id), &path, k);
        match self.env.instance(name).map_err(e)? {
            InstanceRef::Builtin(v, k) if k == fb => Ok(v),
            other => Err(e(Invalid::Type {
                what: "this block",
                expected: format!("a {} instance", Type::Fb(fb)),
                operand: name.to_owned(),
                found: instance_type(&other),
            })),
        }
    }

    /// A timer or counter rung: `first` (its condition and box), then its outputs: arcs read the
    /// instance's fields; variables get moves.
    pub(super) fn instance_outputs(
        &mut self,
        nx: &mut Net,
        b: BlockId,
        inst: VarId,
        fields: &[(Field, Type)],
        first: Series,
    ) -> Result<Series> {
        let mut parts = vec![first];
        for (pin, &(f, ty)) in fields.iter().enumerate() {
            nx.values[b.index()][pin] = Some((field_op(inst, f), ty));
            for v in self.out_vars(nx, b, pin, Some(ty))? {
                parts.push(vec![Element::Move {
                    from: field_op(inst, f),
                    to: v,
                }]);
            }
        }
        Ok(steps(parts))
    }

    /// A user function block call: inputs moved into the instance, `call`, outputs moved out.
    pub(super) fn call(
        &mut self,
        nx: &mut Net,
        b: BlockId,
        fb: &str,
        name: &str,
    ) -> Result<Series> {
        let net = nx.net;
        let blk = net.block(b);
        let id = Some(blk.id);
        let path = format!("{}.instance", blk.path);
        let e = |k| LoadError::fbd(&net.id, id, &path, k);
        let (pou, inputs, outputs) = match self.env.instance(name).map_err(e)? {
            InstanceRef::User {
                pou,
                fb: t,
                inputs,
                outputs,
            } if t == fb => (pou, inputs, outputs),
            other => {
                return Err(e(Invalid::Type {
                    what: "this block",
                    expected: format!("a {fb} instance"),
                    operand: name.to_owned(),
                    found: instance_type(&other),
                }))
            }
        };
        let mut s = Vec::new();
        for (i, (pin, (_, var))) in blk.inputs.iter().zip(&inputs).enumerate() {
            if let Some(input) = &pin.input {
                let ty = self.env.var(*var).ty;
                let v = self.val(nx, input, &pin.path, id, Some(PinSlot(b, i)))?;
                let from = self.coerce(nx, &v, ty, "a function block input", &pin.path, id)?;
                s.push(Element::Move { from, to: *var });
            }
        }
        s.push(Element::Call { pou });
        for (pin, (_, var)) in outputs.iter().enumerate() {
            let ty = self.env.var(*var).ty;
            let vars = self.out_vars(nx, b, pin, Some(ty))?;
            if nx.used[b.index()][pin] {
                let t = self.temp(nx, b, pin, ty)?;
                s.push(Element::Move {
                    from: var_op(*var),
                    to: t,
                });
            }
            s.extend(vars.into_iter().map(|v| Element::Move {
                from: var_op(*var),
                to: v,
            }));
        }
        Ok(s)
    }
}

fn instance_type(i: &InstanceRef) -> String {
    match i {
        InstanceRef::Builtin(_, k) => Type::Fb(*k).to_string(),
        InstanceRef::User { fb, .. } => fb.clone(),
        InstanceRef::Other(t) => t.to_string(),
    }
}
