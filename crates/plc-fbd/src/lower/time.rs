//! TSTART/TSTOP: the hidden variables and the update rung of each TIME variable a body
//! accumulates, one rung per variable at the start of the POU.

use super::{contact, field_op, var_op, Acc, Cx, Result, ACCUMULATE_PT_MS};
use crate::model::*;
use plc_diag::{Invalid, LoadError};
use plc_model::*;

impl Cx<'_> {
    /// The update rungs of every TIME variable this body accumulates, first use first.
    pub(super) fn accumulator_rungs(&mut self, fbd: &FbdPou) -> Result<()> {
        for (net, plan) in fbd.networks.iter().zip(&fbd.plans) {
            for &b in &plan.order {
                let blk = net.block(b);
                if !matches!(blk.op, Op::TStart | Op::TStop) {
                    continue;
                }
                let v = self.accumulated_var(net, blk)?;
                if self.accumulators.contains_key(&v) {
                    continue;
                }
                let e = |k| LoadError::fbd(&net.id, Some(blk.id), &blk.inputs[0].path, k);
                self.env.claim_accumulator(v).map_err(e)?;
                let name = self.env.var(v).name.clone();
                let acc = self
                    .env
                    .hidden(format!("{name}:acc"), Type::Bool)
                    .map_err(e)?;
                let timer = self
                    .env
                    .hidden(format!("{name}:timer"), Type::Fb(FbKind::Ton))
                    .map_err(e)?;
                let last = self
                    .env
                    .hidden(format!("{name}:last"), Type::Time)
                    .map_err(e)?;
                let pt = Operand::Const(Value::Time(ACCUMULATE_PT_MS));
                let series = vec![
                    contact(
                        VarRef {
                            var: acc,
                            field: None,
                        },
                        false,
                    ),
                    Element::Branch(vec![
                        vec![Element::Timer {
                            kind: TimerKind::Ton,
                            instance: timer,
                            pt,
                        }],
                        vec![Element::Arith {
                            op: ArithOp::Sub,
                            a: var_op(v),
                            b: var_op(last),
                            out: v,
                        }],
                        vec![Element::Arith {
                            op: ArithOp::Add,
                            a: var_op(v),
                            b: field_op(timer, Field::Et),
                            out: v,
                        }],
                        vec![Element::Move {
                            from: field_op(timer, Field::Et),
                            to: last,
                        }],
                    ]),
                ];
                let local = name
                    .strip_prefix(self.names.var_prefix.as_str())
                    .unwrap_or(&name);
                let id = format!("{}acc:{local}", self.names.rung_prefix);
                self.push(
                    id,
                    None,
                    Some(format!(
                        "brings {name} up to date while it accumulates (TSTART/TSTOP)"
                    )),
                    series,
                    (&blk.path, blk.origin),
                );
                self.accumulators.insert(v, Acc { acc, timer, last });
            }
        }
        Ok(())
    }

    pub(super) fn accumulated_var(&self, net: &Network, blk: &Block) -> Result<VarId> {
        let pin = &blk.inputs[0];
        let e = |k| LoadError::fbd(&net.id, Some(blk.id), &pin.path, k);
        let text = match &pin.input {
            Some(Input::Variable(s)) | Some(Input::Constant(Constant::Time(s))) => s.as_str(),
            Some(Input::Constant(c)) => {
                return Err(e(Invalid::Shape {
                    expected: "a TIME variable",
                    found: c.kind(),
                }))
            }
            _ => {
                return Err(e(Invalid::Shape {
                    expected: "a TIME variable",
                    found: "an arc".into(),
                }))
            }
        };
        let v = self.env.writable(text, "TSTART/TSTOP").map_err(e)?;
        let ty = self.env.var(v).ty;
        if ty != Type::Time {
            return Err(e(Invalid::Type {
                what: "TSTART/TSTOP",
                expected: "TIME".into(),
                operand: text.to_owned(),
                found: ty.to_string(),
            }));
        }
        Ok(v)
    }
}
