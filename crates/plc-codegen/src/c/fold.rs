//! The step-by-step shapes an n-input block is lowered to, recognised so that the C writes the
//! block as one expression into its destination instead of one store per step (the KASKAD
//! editor's own listing calls such stores redundant):
//!
//! - an arithmetic chain `d := a op b; d := d op c; …` (ADD, MUL … of n inputs, and any ladder
//!   rung with that shape) becomes `d = f(f(a, b), c)`;
//! - the MAX/MIN/LIMIT branch `[d := x0], [x1 > d: d := x1], …` (each later branch a compare
//!   of `d` with `xk` and a move of `xk`) becomes `d = _plc_max_T(_plc_max_T(x0, x1), …)`, a
//!   LIMIT `_plc_min_T(_plc_max_T(in, mn), mx)`.
//!
//! The fold is exact: no step reads `d` but as the running value (a later operand that is `d`
//! itself ends the chain), so nothing observes the intermediate stores; each step keeps its
//! own wrap-around, faults (in order, on the same rung) and float rounding
//! (`FLT_EVAL_METHOD == 0`); `_plc_max_T(m, x)` is `x > m ? x : m`, the lowered compare.
//!
//! Not here: writing the C (`ladder`), the lowering itself (`plc_fbd::lower`).

use plc_model::{CmpOp, Element, Operand, Series, VarId, VarRef};

fn whole(v: VarId) -> Operand {
    Operand::Var(VarRef {
        var: v,
        field: None,
    })
}

/// How many elements from the start of `s` form one arithmetic chain into one variable (0 or
/// 1: no chain).
pub(crate) fn arith_chain(s: &[Element]) -> usize {
    let Some(Element::Arith { out: d, .. }) = s.first() else {
        return 0;
    };
    let d = *d;
    1 + s[1..]
        .iter()
        .take_while(|e| {
            matches!(e, Element::Arith { a, b, out, .. }
                if *out == d && *a == whole(d) && *b != whole(d))
        })
        .count()
}

/// One later step of a MAX/MIN/LIMIT branch: the running value becomes `x` when `x` is greater
/// (`Max`) or smaller (`Min`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Pick {
    Max,
    Min,
}

/// A MAX/MIN/LIMIT branch: its destination, first value and later steps.
pub(crate) struct Extreme {
    pub out: VarId,
    pub first: Operand,
    pub steps: Vec<(Pick, Operand)>,
}

/// The fold of an output branch element's `branches`, when it has the MAX/MIN/LIMIT shape.
pub(crate) fn extreme(branches: &[Series]) -> Option<Extreme> {
    let [Element::Move { from: first, to: d }] = branches.first()?.as_slice() else {
        return None;
    };
    let dv = whole(*d);
    let steps: Option<Vec<(Pick, Operand)>> = branches[1..]
        .iter()
        .map(|b| match b.as_slice() {
            [Element::Compare { op, a, b }, Element::Move { from: x, to }]
                if to == d && *x != dv =>
            {
                // `x > d` or `d < x`: x wins as a maximum; `x < d` or `d > x`: as a minimum.
                match (op, *a == *x && *b == dv, *a == dv && *b == *x) {
                    (CmpOp::Gt, true, _) | (CmpOp::Lt, _, true) => Some((Pick::Max, *x)),
                    (CmpOp::Lt, true, _) | (CmpOp::Gt, _, true) => Some((Pick::Min, *x)),
                    _ => None,
                }
            }
            _ => None,
        })
        .collect();
    let steps = steps?;
    (!steps.is_empty()).then_some(Extreme {
        out: *d,
        first: *first,
        steps,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use plc_model::{ArithOp, Value};

    fn v(i: u32) -> Operand {
        whole(VarId::from_raw(i))
    }

    #[test]
    fn a_chain_ends_where_a_step_reads_its_destination_otherwise() {
        let step = |a, b| Element::Arith {
            op: ArithOp::Add,
            a,
            b,
            out: VarId::from_raw(0),
        };
        let s = [
            step(v(1), v(2)),
            step(v(0), v(3)),
            step(v(0), v(0)),
            step(v(0), v(4)),
        ];
        assert_eq!(arith_chain(&s), 2);
        assert_eq!(arith_chain(&s[2..]), 2);
        assert_eq!(arith_chain(&[Element::Ret]), 0);
    }

    #[test]
    fn limit_is_a_max_then_a_min() {
        let (d, x, mn, mx) = (
            VarId::from_raw(0),
            v(1),
            Operand::Const(Value::Int(0)),
            v(2),
        );
        let b = vec![
            vec![Element::Move { from: x, to: d }],
            vec![
                Element::Compare {
                    op: CmpOp::Lt,
                    a: whole(d),
                    b: mn,
                },
                Element::Move { from: mn, to: d },
            ],
            vec![
                Element::Compare {
                    op: CmpOp::Gt,
                    a: whole(d),
                    b: mx,
                },
                Element::Move { from: mx, to: d },
            ],
        ];
        let e = extreme(&b).unwrap();
        assert_eq!((e.out, e.first), (d, x));
        assert_eq!(e.steps, vec![(Pick::Max, mn), (Pick::Min, mx)]);
        // A step whose move writes another variable is no fold.
        let mut other = b.clone();
        other[2][1] = Element::Move {
            from: mx,
            to: VarId::from_raw(5),
        };
        assert!(extreme(&other).is_none());
    }
}
