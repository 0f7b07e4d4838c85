//! Block inputs and outputs: values of connected inputs (arcs, variables, constants) typed
//! on use, the variables an output is written to, hidden temps for outputs arcs read.

use super::{var_op, Cx, Net, PinSlot, Result, Val};
use crate::model::*;
use plc_diag::{Invalid, LoadError};
use plc_model::untyped::{self, Lookup, Untyped};
use plc_model::*;

impl Cx<'_> {
    /// The value connected to an input (`slot`: the input pin, when it is one).
    pub(super) fn val(
        &self,
        nx: &Net,
        input: &Input,
        path: &str,
        block: Option<u32>,
        slot: Option<PinSlot>,
    ) -> Result<Val> {
        match input {
            Input::Arc { from, pin } => {
                let src = nx.net.block(*from);
                let (o, t) = nx.values[from.index()][*pin as usize]
                    .expect("arcs come from blocks lowered earlier");
                Ok(Val::Typed(
                    o,
                    t,
                    format!("{}.{}", src.id, src.outputs[*pin as usize].name),
                ))
            }
            Input::Variable(name) => {
                let (r, t) = self
                    .env
                    .lookup(name)
                    .map_err(|k| LoadError::fbd(&nx.net.id, block, path, k))?;
                Ok(Val::Typed(Operand::Var(r), t, name.clone()))
            }
            Input::Constant(c) => {
                let env = &*self.env;
                let u = constant(c, &|n| env.lookup(n))
                    .map_err(|k| LoadError::fbd(&nx.net.id, block, path, k))?;
                Ok(Val::Const(u, c.text(), slot))
            }
        }
    }

    /// `v` as an operand of type `ty` (a constant recorded for its pin).
    pub(super) fn coerce(
        &self,
        nx: &mut Net,
        v: &Val,
        ty: Type,
        what: &'static str,
        path: &str,
        block: Option<u32>,
    ) -> Result<Operand> {
        let e = |k| LoadError::fbd(&nx.net.id, block, path, k);
        match v {
            Val::Typed(_, t, text) if *t != ty => Err(e(Invalid::Type {
                what,
                expected: ty.to_string(),
                operand: text.clone(),
                found: t.to_string(),
            })),
            Val::Typed(o, _, _) => Ok(*o),
            Val::Const(u, text, slot) => {
                let o = untyped::typed(u, ty, what, text).map_err(e)?;
                if let (Operand::Const(value), Some(slot)) = (o, slot) {
                    nx.constants.insert(*slot, value);
                }
                Ok(o)
            }
        }
    }

    pub(super) fn bool_input(
        &self,
        nx: &mut Net,
        block: Option<u32>,
        input: &Input,
        path: &str,
        what: &'static str,
    ) -> Result<Operand> {
        let v = self.val(nx, input, path, block, None)?;
        self.coerce(nx, &v, Type::Bool, what, path, block)
    }

    /// The variables output pin `pin` of `b` is written to, type-checked against `ty`.
    /// The type of the first variable block `b`'s first output writes, if it writes one (what
    /// an untyped input of an overloaded block takes its type from).
    ///
    /// A first output that writes no variable but feeds a data input of a block whose result
    /// has that input's type (ADD … MOD, MOVE, SEL's IN0/IN1, MAX, MIN, LIMIT) takes that
    /// block's type in turn, as Beremiz types the temporary between them from the variable at
    /// the end of the chain (`PLCGenerator.ComputeConnectionTypes`): `SEL(g, 50, 100)` feeding
    /// `SEL(h, …, 0)` that writes an INT is INT.
    pub(super) fn first_out_type(&self, nx: &Net, b: BlockId) -> Result<Option<Type>> {
        let mut at = b;
        // A chain visits each block at most once (arcs go forward in a network without loops).
        for _ in 0..nx.net.blocks.len() {
            if let Some(&v) = self.out_vars(nx, at, 0, None)?.first() {
                return Ok(Some(self.env.var(v).ty));
            }
            match nx.type_heir[at.index()] {
                Some(next) => at = next,
                None => return Ok(None),
            }
        }
        Ok(None)
    }

    pub(super) fn out_vars(
        &self,
        nx: &Net,
        b: BlockId,
        pin: usize,
        ty: Option<Type>,
    ) -> Result<Vec<VarId>> {
        let blk = nx.net.block(b);
        let mut out = Vec::new();
        for (name, path) in &blk.outputs[pin].vars {
            let e = |k| LoadError::fbd(&nx.net.id, Some(blk.id), path, k);
            let v = self.env.writable(name, "a block output").map_err(e)?;
            let vt = self.env.var(v).ty;
            if let Some(ty) = ty {
                if vt != ty {
                    return Err(e(Invalid::Type {
                        what: "a block output",
                        expected: ty.to_string(),
                        operand: name.clone(),
                        found: vt.to_string(),
                    }));
                }
            }
            out.push(v);
        }
        Ok(out)
    }

    /// A hidden temp `_<block>_<pin>` for output `pin` of `b`, which arcs read from now on.
    pub(super) fn temp(&mut self, nx: &mut Net, b: BlockId, pin: usize, ty: Type) -> Result<VarId> {
        let blk = nx.net.block(b);
        let name = format!(
            "{}_{}_{}",
            self.names.var_prefix, blk.id, blk.outputs[pin].name
        );
        let t = self
            .env
            .hidden(name, ty)
            .map_err(|k| LoadError::fbd(&nx.net.id, Some(blk.id), &blk.path, k))?;
        nx.values[b.index()][pin] = Some((var_op(t), ty));
        Ok(t)
    }

    /// Where a function-like block computes output `pin`: a temp when an arc reads it, when no
    /// variable takes it, or when the first variable is also an input of a block computed in
    /// several steps (`avoid`); otherwise the first variable. Returns it and the other variables.
    pub(super) fn dest(
        &mut self,
        nx: &mut Net,
        b: BlockId,
        pin: usize,
        ty: Type,
        avoid: &[Operand],
    ) -> Result<(VarId, Vec<VarId>)> {
        let vars = self.out_vars(nx, b, pin, Some(ty))?;
        let aliased = |v: VarId| avoid.iter().any(|o| o.var() == Some(v));
        if nx.used[b.index()][pin] || vars.is_empty() || aliased(vars[0]) {
            let t = self.temp(nx, b, pin, ty)?;
            Ok((t, vars))
        } else {
            Ok((vars[0], vars[1..].to_vec()))
        }
    }

    pub(super) fn typed_all(
        &self,
        nx: &mut Net,
        vals: &[(Val, &str)],
        ty: Type,
        what: &'static str,
        id: Option<u32>,
    ) -> Result<Vec<Operand>> {
        vals.iter()
            .map(|(v, p)| self.coerce(nx, v, ty, what, p, id))
            .collect()
    }
}

/// A constant as an operand (a string one is a literal or a name `lookup` resolves), read as
/// the resolver reads the same operand written in a rung.
pub(super) fn constant(c: &Constant, lookup: &Lookup<'_>) -> std::result::Result<Untyped, Invalid> {
    match c {
        Constant::Bool(b) => Ok(Untyped::Bool(*b)),
        Constant::Number(n) => Ok(Untyped::number(n.as_i64(), n.as_u64(), n.as_f64())),
        Constant::Time(s) => untyped::parse_text(s, lookup),
    }
}
