//! What an `inVariable` (or `inOutVariable` read as a source) gives to a pin when its
//! `expression` is more than a literal or a variable: an ST expression (IEC 61131-3 7.3.2, read
//! by the ST parser, [`crate::st::parser::expression`]) made into the blocks that compute
//! it, added to the body ([`Added`]) — `a + b * 2` is `ADD(a, MUL(b, 2))`, `NOT x AND y` is
//! `AND(NOT(x), y)`, `-x` is `SUB(0, x)` (`-3` the literal), comparisons their comparison
//! blocks; an integer sub-expression of literals alone (`2 * 3`) is folded into the literal it
//! makes, so that its use types it. So its reads are exactly its variables, and `run` computes it
//! as the blocks do (literals typed by their use).
//!
//! A function block instance's output (`t.Q`) is the field reference the model has for it; a
//! structure's field (`s.f`, `s.inner.f`) is passed on as such: it is the name of the field's
//! own variable ([`super::data_types`]), and so is an element of constant subscripts of a
//! scalarised array (`a[3]`, `a[1 + 2]`: [`Added::elements`]). Any other array element
//! (`a[i]`) reads the whole array and the variables of its subscripts: the model holds an array
//! as one value of its element type (docs/plcopen.md, "Data types"), so the element stands in as
//! `SEL(NE(i, i), a, a)` — the value `a`, with `i` read — and `run` refuses the body (the
//! reader's note says why, `super::project`); a scalarised array's elements stand in for `a`,
//! each read through a `SEL(FALSE, …)`.
//!
//! Deliberately not here: function calls and `**` (the model has no EXPT) in an expression,
//! direct addresses and dereferences (one error each, naming the expression).

use super::interface::literal;
use super::pins::{expression_text, Added};
use super::xml::{element_name, error, is_identifier, origin, R};
use crate::st::ast::{BinaryOp, Expr, Place, Selector, UnaryOp};
use plc_diag::{LoadError, Origin};
use plc_syntax::fbd::{Connection, Input};
use plc_syntax::Scalar;
use roxmltree::Node;
use std::borrow::Cow;

/// What in variable `node` (in `place`, its pin at `at`) gives: its literal, its variable, or
/// the output of the blocks its expression is made into.
pub(super) fn block_input(a: &mut Added, node: Node, place: &str, at: Origin) -> R<Input<'static>> {
    let text = expression_text(node);
    if !text.contains('[') {
        if let Ok(simple) = super::pins::block_input(node, place, at) {
            return Ok(simple);
        }
    }
    let shown = shortened(text.trim());
    let bad = |why: String| error(origin(node), place, format!("expression `{shown}`: {why}"));
    let e = crate::st::parser::expression(text).map_err(|e| bad(e.message))?;
    Lower { a, at, bad: &bad }.expr(&e)
}

/// An expression as an error quotes it: whole up to 60 characters, else its first 60 and `…`
/// (an expression of 10,000 parentheses is not repeated in its error).
fn shortened(text: &str) -> Cow<'_, str> {
    match text.char_indices().nth(60) {
        Some((i, _)) => Cow::Owned(format!("{}…", &text[..i])),
        None => Cow::Borrowed(text),
    }
}

/// Whether in variable `node` reads an array element that is not the variable of a scalarised
/// array's element (`vars`: the POU's variables by lower-case name): a subscript that is not
/// constant, or an array plc-deps holds as one value.
pub(super) fn reads_array_element(
    node: Node,
    vars: &std::collections::HashMap<String, String>,
) -> bool {
    let text = expression_text(node);
    if !text.contains('[') {
        return false;
    }
    fn known(e: &Expr, vars: &std::collections::HashMap<String, String>) -> bool {
        match e {
            Expr::Literal(_) => true,
            Expr::Var(p) => {
                !p.selectors.iter().any(|s| matches!(s, Selector::Index(_)))
                    || element_name(p).is_some_and(|n| vars.contains_key(&n.to_ascii_lowercase()))
            }
            Expr::Unary(_, x) => known(x, vars),
            Expr::Binary(_, a, b) => known(a, vars) && known(b, vars),
            Expr::Call { .. } => true,
        }
    }
    match crate::st::parser::expression(text) {
        Ok(e) => !known(&e, vars),
        Err(_) => true,
    }
}

struct Lower<'l, F> {
    a: &'l mut Added,
    at: Origin,
    bad: &'l F,
}

impl<F: Fn(String) -> LoadError> Lower<'_, F> {
    fn expr(&mut self, e: &Expr) -> R<Input<'static>> {
        let at = self.at;
        Ok(match e {
            Expr::Literal(s) => match literal(s) {
                Some(v) => Input {
                    origin: at,
                    from: Connection::Constant(v),
                },
                None => return Err((self.bad)(format!("`{s}` is not a literal plc-deps reads"))),
            },
            Expr::Var(p) => self.place(p)?,
            Expr::Unary(UnaryOp::Not, x) => {
                let x = self.expr(x)?;
                self.a.not(x, at)
            }
            Expr::Unary(UnaryOp::Plus, x) => self.expr(x)?,
            Expr::Unary(UnaryOp::Neg, x) => {
                // A negative literal is a literal (typed by its use, as `-3` is).
                if let Some(v) = negative_literal(x) {
                    return Ok(Input {
                        origin: at,
                        from: Connection::Constant(v),
                    });
                }
                let zero = Input {
                    origin: at,
                    from: Connection::Constant(Scalar::Number(0.into())),
                };
                let x = self.expr(x)?;
                if let Some(v) = fold(BinaryOp::Sub, &zero, &x) {
                    return Ok(v);
                }
                self.a.add("SUB", vec![("IN1", zero), ("IN2", x)], at)
            }
            Expr::Binary(op, l, r) => {
                let name = op_name(*op).ok_or_else(|| {
                    (self.bad)("`**` has no block in plc-deps (no EXPT)".to_owned())
                })?;
                let (l, r) = (self.expr(l)?, self.expr(r)?);
                if let Some(v) = fold(*op, &l, &r) {
                    return Ok(v);
                }
                self.a.add(name, vec![("IN1", l), ("IN2", r)], at)
            }
            Expr::Call { callee, .. } => {
                return Err((self.bad)(format!(
                    "a call of `{}` in an in variable is not read yet (draw it as a block)",
                    callee.base
                )))
            }
        })
    }

    /// A variable, a field of one, or an array element (see the module's comment).
    fn place(&mut self, p: &Place) -> R<Input<'static>> {
        let at = self.at;
        if let Some(n) =
            element_name(p).filter(|n| self.a.elements.contains(&n.to_ascii_lowercase()))
        {
            return Ok(Input {
                origin: at,
                from: Connection::Variable(Cow::Owned(n)),
            });
        }
        let mut name = p.base.clone();
        let mut subscripts = Vec::new();
        for s in &p.selectors {
            match s {
                Selector::Field(f) if subscripts.is_empty() => {
                    name.push('.');
                    name.push_str(f);
                }
                // A field of an element: the whole array, as for the element.
                Selector::Field(_) => {}
                Selector::Index(ix) => subscripts.extend(ix.iter()),
                Selector::Deref => {
                    return Err((self.bad)("a dereference (`^`) is not read".to_owned()))
                }
            }
        }
        if !name.split('.').all(is_identifier) {
            return Err((self.bad)(format!(
                "`{name}` is not a variable or a field of one"
            )));
        }
        // A scalarised array (`name` has no variable, its elements have): its elements stand
        // in for it, each read (in name order).
        let prefix = format!("{}[", name.to_ascii_lowercase());
        let mut parts: Vec<&String> = self
            .a
            .elements
            .iter()
            .filter(|e| e.starts_with(&prefix))
            .collect();
        parts.sort();
        let parts: Vec<String> = parts.into_iter().cloned().collect();
        let var = || Input {
            origin: at,
            from: Connection::Variable(Cow::Owned(
                parts.first().cloned().unwrap_or_else(|| name.clone()),
            )),
        };
        let mut value = var();
        for e in parts.iter().skip(1) {
            let zero = Input {
                origin: at,
                from: Connection::Constant(Scalar::Bool(false)),
            };
            let next = Input {
                origin: at,
                from: Connection::Variable(Cow::Owned(e.clone())),
            };
            value = self
                .a
                .add("SEL", vec![("G", zero), ("IN0", value), ("IN1", next)], at);
        }
        for ix in subscripts {
            let i = self.expr(ix)?;
            let never = self.a.add("NE", vec![("IN1", i.clone()), ("IN2", i)], at);
            value = self.a.add(
                "SEL",
                vec![("G", never), ("IN0", value), ("IN1", var())],
                at,
            );
        }
        Ok(value)
    }
}

/// `l op r` as one integer literal, when both are integer literals and the operator is
/// arithmetic with a result (no division by zero, nothing beyond 64 bits): a constant expression
/// (IEC 61131-3 7.3.2), so the result stays an untyped literal that its use types, as `6` would
/// be (`a + 2 * 3` on an INT is INT). Division truncates toward zero and MOD takes the sign of
/// the dividend, as the blocks do. Real literals are not folded: the block computes them in the
/// type of its use, with that type's rounding.
fn fold(op: BinaryOp, l: &Input, r: &Input) -> Option<Input<'static>> {
    let int = |i: &Input| match &i.from {
        Connection::Constant(Scalar::Number(n)) => n.as_i64(),
        _ => None,
    };
    let (a, b) = (int(l)?, int(r)?);
    let v = match op {
        BinaryOp::Add => a.checked_add(b),
        BinaryOp::Sub => a.checked_sub(b),
        BinaryOp::Mul => a.checked_mul(b),
        BinaryOp::Div => a.checked_div(b),
        BinaryOp::Mod => a.checked_rem(b),
        _ => None,
    }?;
    Some(Input {
        origin: l.origin,
        from: Connection::Constant(Scalar::Number(v.into())),
    })
}

/// `-x` as a literal, when `x` is a number literal.
fn negative_literal(x: &Expr) -> Option<Scalar<'static>> {
    match x {
        Expr::Literal(l) => literal(&format!("-{l}")),
        _ => None,
    }
}

/// The block of a binary operator (`None`: `**`, which the model has no block for).
fn op_name(op: BinaryOp) -> Option<&'static str> {
    use BinaryOp::*;
    Some(match op {
        Power => return None,
        Mul => "MUL",
        Div => "DIV",
        Mod => "MOD",
        Add => "ADD",
        Sub => "SUB",
        Lt => "LT",
        Gt => "GT",
        Le => "LE",
        Ge => "GE",
        Eq => "EQ",
        Ne => "NE",
        And => "AND",
        Xor => "XOR",
        Or => "OR",
    })
}
