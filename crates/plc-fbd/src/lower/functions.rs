//! FBD blocks of the standard functions (ABS … ATAN, EXPT, SHL … ROR, MUX, `*_TO_*`, TRUNC) →
//! one rung `[function F args → d]` then moves into the output's further variables, typed by
//! the function's rule (`plc_model::Function::types`) from the inputs' own types and the
//! first output variable's (docs/fbd.md).
//!
//! Not here: what the function computes (`plc_exec::functions`).

use super::{Cx, Net, Result, Val};
use crate::model::*;
use plc_diag::{Invalid, LoadError};
use plc_model::untyped;
use plc_model::*;

impl Cx<'_> {
    /// A standard function block: `[function F a… → d, move d → v…]`.
    pub(super) fn function(
        &mut self,
        nx: &mut Net,
        b: BlockId,
        vals: &[(Val, &str)],
        func: Function,
    ) -> Result<Series> {
        let net = nx.net;
        let id = Some(net.block(b).id);
        let out_ty = self.first_out_type(nx, b)?;
        let own: Vec<(Option<Type>, bool)> = vals
            .iter()
            .map(|(v, _)| match v {
                Val::Typed(_, t, _) => (Some(*t), false),
                Val::Const(u, ..) => (u.ty(), untyped::default_type(u) == Type::Real),
            })
            .collect();
        let typing = func.types(&own, out_ty).map_err(|m| {
            let (path, operand) = match m.arg {
                Some(i) => (vals[i].1.to_owned(), vals[i].0.text().to_owned()),
                None => (net.block(b).path.clone(), "OUT".to_owned()),
            };
            LoadError::fbd(
                &net.id,
                id,
                &path,
                Invalid::Type {
                    what: "this function's operand",
                    expected: format!("{} ({})", m.expected, func.name()),
                    operand,
                    found: m.found.to_string(),
                },
            )
        })?;
        let mut args = Vec::with_capacity(vals.len());
        for ((v, path), ty) in vals.iter().zip(&typing.args) {
            args.push(self.coerce(nx, v, *ty, "a function's input", path, id)?);
        }
        let (d, rest) = self.dest(nx, b, 0, typing.out, &args)?;
        let mut s = vec![Element::Function {
            func,
            args: args.into_boxed_slice(),
            out: d,
        }];
        s.extend(rest.iter().map(|&v| Element::Move {
            from: super::var_op(d),
            to: v,
        }));
        Ok(s)
    }
}
