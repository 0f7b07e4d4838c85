//! One block → its rung series: every standard FBD op (logic, compare, arithmetic, selection,
//! timers, counters, jumps, TSTART/TSTOP) as ladder elements. docs/fbd.md gives each rung.

use super::{condition, contact, steps, var_op, Cx, Net, PinSlot, Result, Val, ACCUMULATE_PT_MS};
use crate::model::*;
use plc_diag::{Invalid, LoadError};
use plc_model::untyped;
use plc_model::*;
use std::collections::HashMap;

impl Cx<'_> {
    /// The rung series of block `b`.
    pub(super) fn block(
        &mut self,
        nx: &mut Net,
        b: BlockId,
        labels: &HashMap<&str, usize>,
    ) -> Result<Series> {
        let net = nx.net;
        let blk = net.block(b);
        let id = Some(blk.id);
        // The connected inputs, in pin order.
        let mut vals: Vec<(Val, &str)> = Vec::with_capacity(blk.inputs.len());
        if !matches!(blk.op, Op::TStart | Op::TStop | Op::Call { .. }) {
            // Built-in ops have every input connected (checked by the reader).
            for (i, pin) in blk.inputs.iter().enumerate() {
                let input = pin.input.as_ref().ok_or_else(|| {
                    let op = blk.op.name().to_owned();
                    let kind = Invalid::Unconnected {
                        op,
                        pin: pin.name.clone(),
                    };
                    LoadError::fbd(&net.id, id, &pin.path, kind)
                })?;
                let slot = Some(PinSlot(b, i));
                vals.push((self.val(nx, input, &pin.path, id, slot)?, pin.path.as_str()));
            }
        }
        match &blk.op {
            Op::Compare(c) => self.compare(nx, b, &vals, *c),
            Op::Arith(op) => self.arith(nx, b, &vals, *op),
            Op::And | Op::Or | Op::Not => self.logic(nx, b, &vals),
            Op::Xor => self.xor(nx, b, &vals),
            Op::Move => self.move_block(nx, b, &vals),
            Op::Sel => self.sel(nx, b, &vals),
            Op::Max | Op::Min | Op::Limit => self.extreme(nx, b, &vals),
            Op::Timer { kind, instance } => self.timer(nx, b, &vals, *kind, instance),
            Op::Ctu { instance } | Op::Ctd { instance } => self.counter(nx, b, &vals, instance),
            Op::Bistable { kind, instance } => self.bistable(nx, b, &vals, *kind, instance),
            Op::Trigger { kind, instance } => self.trigger(nx, b, &vals, *kind, instance),
            Op::Ctud { instance } => self.ctud(nx, b, &vals, instance),
            Op::Jmp { .. } | Op::Ret => self.jump(nx, b, labels),
            Op::TStart | Op::TStop => self.accumulate(nx, b),
            Op::Call { fb, instance } => self.call(nx, b, fb, instance),
            Op::Function(f) => self.function(nx, b, &vals, *f),
        }
    }

    /// EQ … GE: `[compare OP a b, coil d]`; of n inputs the comparisons of each neighbouring
    /// pair in series (`GT(a, b, c)`: `[compare GT a b, compare GT b c, coil d]`).
    fn compare(
        &mut self,
        nx: &mut Net,
        b: BlockId,
        vals: &[(Val, &str)],
        c: CmpOp,
    ) -> Result<Series> {
        let net = nx.net;
        let blk = net.block(b);
        let id = Some(blk.id);
        let e = |path: &str, k| LoadError::fbd(&net.id, id, path, k);
        let ty = numeric(vals, None, "a comparison").map_err(|(p, k)| e(p, k))?;
        let mut ops = Vec::with_capacity(vals.len());
        for (v, path) in vals {
            ops.push(self.coerce(nx, v, ty, "a comparison", path, id)?);
        }
        let (d, rest) = self.dest(nx, b, 0, Type::Bool, &[])?;
        let mut s: Series = ops
            .windows(2)
            .map(|w| Element::Compare {
                op: c,
                a: w[0],
                b: w[1],
            })
            .collect();
        s.push(Element::Coil {
            var: d,
            negated: false,
        });
        s.extend(coils(&rest));
        Ok(s)
    }

    /// ADD … MOD: `[op a b → d]`, n inputs: `[op a b → d, op d c → d, …]`.
    fn arith(
        &mut self,
        nx: &mut Net,
        b: BlockId,
        vals: &[(Val, &str)],
        op: ArithOp,
    ) -> Result<Series> {
        let net = nx.net;
        let blk = net.block(b);
        let id = Some(blk.id);
        let e = |path: &str, k| LoadError::fbd(&net.id, id, path, k);
        let out_ty = self.first_out_type(nx, b)?;
        let ty = numeric_type(vals, out_ty);
        if !op.accepts(ty) {
            let (v, p) = vals
                .iter()
                .find(|(v, _)| v.ty().is_some())
                .unwrap_or(&vals[0]);
            return Err(e(
                p,
                Invalid::Type {
                    what: "this arithmetic block",
                    expected: op.expected().into(),
                    operand: v.text().to_owned(),
                    found: ty.to_string(),
                },
            ));
        }
        let ops = self.typed_all(nx, vals, ty, "an arithmetic block", id)?;
        let avoid: &[Operand] = if ops.len() > 2 { &ops[2..] } else { &[] };
        let (d, rest) = self.dest(nx, b, 0, ty, avoid)?;
        let mut s = vec![Element::Arith {
            op,
            a: ops[0],
            b: ops[1],
            out: d,
        }];
        for o in &ops[2..] {
            s.push(Element::Arith {
                op,
                a: var_op(d),
                b: *o,
                out: d,
            });
        }
        s.extend(moves(d, &rest));
        Ok(s)
    }

    /// AND, OR, XOR or NOT of bit strings or integers (an input or the output not a BOOL):
    /// the standard function, bit by bit ([`Function::And`] …); `None` for BOOLs.
    fn bitwise(
        &mut self,
        nx: &mut Net,
        b: BlockId,
        vals: &[(Val, &str)],
    ) -> Result<Option<Series>> {
        let func = match nx.net.block(b).op {
            Op::And => Function::And,
            Op::Or => Function::Or,
            Op::Xor => Function::Xor,
            _ => Function::Not,
        };
        let out_ty = self.first_out_type(nx, b)?;
        let mut types = vals.iter().filter_map(|(v, _)| v.ty()).chain(out_ty);
        if !types.any(|t| t != Type::Bool) {
            return Ok(None);
        }
        self.function(nx, b, vals, func).map(Some)
    }

    /// AND (contacts in series), OR (in parallel), NOT (a negated contact), then coils; of bit
    /// strings, the bitwise function.
    fn logic(&mut self, nx: &mut Net, b: BlockId, vals: &[(Val, &str)]) -> Result<Series> {
        if let Some(s) = self.bitwise(nx, b, vals)? {
            return Ok(s);
        }
        let net = nx.net;
        let blk = net.block(b);
        let id = Some(blk.id);
        let ops = self.typed_all(nx, vals, Type::Bool, "a logic block", id)?;
        let (d, rest) = self.dest(nx, b, 0, Type::Bool, &[])?;
        let mut s: Series = match blk.op {
            Op::And => ops.iter().flat_map(|o| condition(*o, false)).collect(),
            Op::Or => vec![Element::Or(
                ops.iter().map(|o| condition(*o, false)).collect(),
            )],
            _ => condition(ops[0], true),
        };
        s.push(Element::Coil {
            var: d,
            negated: false,
        });
        s.extend(coils(&rest));
        Ok(s)
    }

    /// XOR: `[or [[a, b negated], [a negated, b]], coil d]`, one such step per further input;
    /// of bit strings, the bitwise function.
    fn xor(&mut self, nx: &mut Net, b: BlockId, vals: &[(Val, &str)]) -> Result<Series> {
        if let Some(s) = self.bitwise(nx, b, vals)? {
            return Ok(s);
        }
        let net = nx.net;
        let blk = net.block(b);
        let id = Some(blk.id);
        let ops = self.typed_all(nx, vals, Type::Bool, "a logic block", id)?;
        let (d, rest) = self.dest(
            nx,
            b,
            0,
            Type::Bool,
            if ops.len() > 2 { &ops[2..] } else { &[] },
        )?;
        let xor = |a: Operand, bb: Operand| -> Series {
            let mut l = condition(a, false);
            l.extend(condition(bb, true));
            let mut r = condition(a, true);
            r.extend(condition(bb, false));
            vec![
                Element::Or(vec![l, r]),
                Element::Coil {
                    var: d,
                    negated: false,
                },
            ]
        };
        let mut parts = vec![xor(ops[0], ops[1])];
        for o in &ops[2..] {
            parts.push(xor(var_op(d), *o));
        }
        let mut s = steps(parts);
        s.extend(coils(&rest));
        Ok(s)
    }

    /// MOVE: `[move a → d]`.
    fn move_block(&mut self, nx: &mut Net, b: BlockId, vals: &[(Val, &str)]) -> Result<Series> {
        let net = nx.net;
        let blk = net.block(b);
        let id = Some(blk.id);
        let e = |path: &str, k| LoadError::fbd(&net.id, id, path, k);
        let out_ty = self.first_out_type(nx, b)?;
        let ty = vals[0]
            .0
            .ty()
            .or(out_ty)
            .unwrap_or_else(|| match &vals[0].0 {
                Val::Const(u, ..) => untyped::default_type(u),
                Val::Typed(_, t, _) => *t,
            });
        if matches!(ty, Type::Fb(_)) {
            return Err(e(
                vals[0].1,
                Invalid::Type {
                    what: "MOVE",
                    expected: "a value (an elementary type)".into(),
                    operand: vals[0].0.text().to_owned(),
                    found: ty.to_string(),
                },
            ));
        }
        let a = self.coerce(nx, &vals[0].0, ty, "MOVE", vals[0].1, id)?;
        let (d, rest) = self.dest(nx, b, 0, ty, &[])?;
        let mut s = vec![Element::Move { from: a, to: d }];
        s.extend(moves(d, &rest));
        Ok(s)
    }

    /// SEL: `branch [[move IN0 → d], [contact G, move IN1 → d]]`.
    fn sel(&mut self, nx: &mut Net, b: BlockId, vals: &[(Val, &str)]) -> Result<Series> {
        let net = nx.net;
        let blk = net.block(b);
        let id = Some(blk.id);
        let e = |path: &str, k| LoadError::fbd(&net.id, id, path, k);
        let g = self.coerce(nx, &vals[0].0, Type::Bool, "SEL's G", vals[0].1, id)?;
        let out_ty = self.first_out_type(nx, b)?;
        let ty = numeric_type(&vals[1..], out_ty);
        if matches!(ty, Type::Fb(_)) {
            return Err(e(
                vals[1].1,
                Invalid::Type {
                    what: "SEL",
                    expected: "a value (an elementary type)".into(),
                    operand: vals[1].0.text().to_owned(),
                    found: ty.to_string(),
                },
            ));
        }
        let in0 = self.coerce(nx, &vals[1].0, ty, "SEL", vals[1].1, id)?;
        let in1 = self.coerce(nx, &vals[2].0, ty, "SEL", vals[2].1, id)?;
        let (d, rest) = self.dest(nx, b, 0, ty, &[g, in1])?;
        let mut parts = vec![vec![Element::Move { from: in0, to: d }]];
        let mut second = condition(g, false);
        second.push(Element::Move { from: in1, to: d });
        parts.push(second);
        let mut s = steps(parts);
        s.extend(moves(d, &rest));
        Ok(s)
    }

    /// MAX, MIN (a move, then a compare and move per further input) and LIMIT.
    fn extreme(&mut self, nx: &mut Net, b: BlockId, vals: &[(Val, &str)]) -> Result<Series> {
        let net = nx.net;
        let blk = net.block(b);
        let id = Some(blk.id);
        let e = |path: &str, k| LoadError::fbd(&net.id, id, path, k);
        let out_ty = self.first_out_type(nx, b)?;
        let ty = numeric(vals, out_ty, "this block").map_err(|(p, k)| e(p, k))?;
        let ops = self.typed_all(nx, vals, ty, op_name_static(&blk.op), id)?;
        let (d, rest) = self.dest(nx, b, 0, ty, &ops)?;
        let dv = var_op(d);
        let cmp_move = |op: CmpOp, x: Operand| {
            vec![
                Element::Compare { op, a: x, b: dv },
                Element::Move { from: x, to: d },
            ]
        };
        let parts: Vec<Series> = match blk.op {
            Op::Limit => vec![
                vec![Element::Move {
                    from: ops[1],
                    to: d,
                }],
                vec![
                    Element::Compare {
                        op: CmpOp::Lt,
                        a: dv,
                        b: ops[0],
                    },
                    Element::Move {
                        from: ops[0],
                        to: d,
                    },
                ],
                vec![
                    Element::Compare {
                        op: CmpOp::Gt,
                        a: dv,
                        b: ops[2],
                    },
                    Element::Move {
                        from: ops[2],
                        to: d,
                    },
                ],
            ],
            _ => {
                let c = if blk.op == Op::Max {
                    CmpOp::Gt
                } else {
                    CmpOp::Lt
                };
                std::iter::once(vec![Element::Move {
                    from: ops[0],
                    to: d,
                }])
                .chain(ops[1..].iter().map(|&x| cmp_move(c, x)))
                .collect()
            }
        };
        let mut s = steps(parts);
        s.extend(moves(d, &rest));
        Ok(s)
    }

    /// TON, TOF, TP: `[contact IN, ton T pt]`, outputs read through the instance.
    fn timer(
        &mut self,
        nx: &mut Net,
        b: BlockId,
        vals: &[(Val, &str)],
        kind: TimerKind,
        instance: &str,
    ) -> Result<Series> {
        let net = nx.net;
        let blk = net.block(b);
        let id = Some(blk.id);
        let inst = self.builtin_instance(nx, b, kind.fb(), instance)?;
        let inp = self.coerce(nx, &vals[0].0, Type::Bool, "a timer's IN", vals[0].1, id)?;
        let pt = self.coerce(nx, &vals[1].0, Type::Time, "a timer's PT", vals[1].1, id)?;
        let mut first = condition(inp, false);
        first.push(Element::Timer {
            kind,
            instance: inst,
            pt,
        });
        self.instance_outputs(
            nx,
            b,
            inst,
            &[(Field::Q, Type::Bool), (Field::Et, Type::Time)],
            first,
        )
    }

    /// CTU, CTD: `[contact CU, ctu C pv R]` / `[contact CD, ctd C pv LD]`.
    fn counter(
        &mut self,
        nx: &mut Net,
        b: BlockId,
        vals: &[(Val, &str)],
        instance: &str,
    ) -> Result<Series> {
        let net = nx.net;
        let blk = net.block(b);
        let id = Some(blk.id);
        let fb = if matches!(blk.op, Op::Ctu { .. }) {
            FbKind::Ctu
        } else {
            FbKind::Ctd
        };
        let inst = self.builtin_instance(nx, b, fb, instance)?;
        let c = self.coerce(
            nx,
            &vals[0].0,
            Type::Bool,
            "a counter's input",
            vals[0].1,
            id,
        )?;
        let r = self.coerce(
            nx,
            &vals[1].0,
            Type::Bool,
            if fb == FbKind::Ctu {
                "a counter's reset"
            } else {
                "a counter's load"
            },
            vals[1].1,
            id,
        )?;
        let pv = self.coerce(nx, &vals[2].0, Type::Int, "a counter's PV", vals[2].1, id)?;
        let mut first = condition(c, false);
        first.push(if fb == FbKind::Ctu {
            Element::Ctu {
                instance: inst,
                pv,
                reset: r,
            }
        } else {
            Element::Ctd {
                instance: inst,
                pv,
                load: r,
            }
        });
        self.instance_outputs(
            nx,
            b,
            inst,
            &[(Field::Q, Type::Bool), (Field::Cv, Type::Int)],
            first,
        )
    }

    /// JMP and RET: `[contact cond, jmp <label>]` / `[contact cond, ret]`. A JMP's series stops
    /// before its jump: the network's lowering records it as a [`ForwardJump`](super::ForwardJump), which
    /// [`lower`](super::lower) adds once the labelled network's first rung is known.
    fn jump(&mut self, nx: &mut Net, b: BlockId, labels: &HashMap<&str, usize>) -> Result<Series> {
        let net = nx.net;
        let blk = net.block(b);
        let id = Some(blk.id);
        let e = |path: &str, k| LoadError::fbd(&net.id, id, path, k);
        let mut s = match &blk.cond {
            Some(c) => {
                let o = self.bool_input(nx, id, c, &format!("{}.cond", blk.path), "a condition")?;
                condition(o, false)
            }
            None => Vec::new(),
        };
        if let Op::Jmp { label } = &blk.op {
            if !labels.contains_key(label.as_str()) {
                return Err(e(
                    &format!("{}.label", blk.path),
                    Invalid::UndefinedLabel {
                        label: label.clone(),
                        pou: self.names.pou.clone(),
                    },
                ));
            }
        } else {
            s.push(Element::Ret);
        }
        Ok(s)
    }

    /// TSTART and TSTOP (module docs of the lowering).
    fn accumulate(&mut self, nx: &mut Net, b: BlockId) -> Result<Series> {
        let net = nx.net;
        let blk = net.block(b);
        let v = self.accumulated_var(net, blk)?;
        let a = &self.accumulators[&v];
        let acc = VarRef {
            var: a.acc,
            field: None,
        };
        let pt = Operand::Const(Value::Time(ACCUMULATE_PT_MS));
        let timer = Element::Timer {
            kind: TimerKind::Ton,
            instance: a.timer,
            pt,
        };
        Ok(if blk.op == Op::TStart {
            vec![Element::Branch(vec![
                vec![
                    contact(acc, true),
                    Element::Set(a.acc),
                    Element::Move {
                        from: Operand::Const(Value::Time(0)),
                        to: a.last,
                    },
                ],
                vec![contact(acc, false), timer],
            ])]
        } else {
            vec![Element::Reset(a.acc), contact(acc, false), timer]
        })
    }
}

/// Coils writing the power into each of `to` (a BOOL output's further variables).
fn coils(to: &[VarId]) -> impl Iterator<Item = Element> + '_ {
    to.iter().map(|&var| Element::Coil {
        var,
        negated: false,
    })
}

/// Moves of `from` into each of `to` (a numeric output's further variables).
fn moves(from: VarId, to: &[VarId]) -> impl Iterator<Item = Element> + '_ {
    to.iter().map(move |&v| Element::Move {
        from: var_op(from),
        to: v,
    })
}

/// The type of a numeric operation: the first input that has one, else `fallback` (the output
/// variable's), else REAL if a constant is REAL, else DINT (as ladder compares do).
fn numeric_type(vals: &[(Val, &str)], fallback: Option<Type>) -> Type {
    if let Some(t) = vals.iter().find_map(|(v, _)| v.ty()) {
        return t;
    }
    if let Some(t) = fallback {
        return t;
    }
    let real = vals
        .iter()
        .any(|(v, _)| matches!(v, Val::Const(u, ..) if untyped::default_type(u) == Type::Real));
    if real {
        Type::Real
    } else {
        Type::Dint
    }
}

/// The numeric type of the inputs (see [`numeric_type`]), or the error naming the input that
/// fixed a non-numeric type (its pin path and the kind).
fn numeric<'v>(
    vals: &[(Val, &'v str)],
    fallback: Option<Type>,
    what: &'static str,
) -> std::result::Result<Type, (&'v str, Invalid)> {
    let ty = numeric_type(vals, fallback);
    if ty.is_comparable() {
        return Ok(ty);
    }
    let (v, p) = vals
        .iter()
        .find(|(v, _)| v.ty().is_some())
        .unwrap_or(&vals[0]);
    Err((
        p,
        Invalid::Type {
            what,
            expected: COMPARABLE.into(),
            operand: v.text().to_owned(),
            found: ty.to_string(),
        },
    ))
}

/// The op name for messages that need a `&'static str`.
fn op_name_static(op: &Op) -> &'static str {
    match op {
        Op::Max => "MAX",
        Op::Min => "MIN",
        Op::Limit => "LIMIT",
        _ => "this block",
    }
}
