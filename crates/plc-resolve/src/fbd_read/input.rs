//! One INPUT of a block: a variable or a constant (kept as written for the lowering), or an
//! arc `{"from": ID}` / `{"from": ID, "pin": "Q"}` resolved to a block of the same network and
//! one of its outputs.

use super::block::Net;
use super::util::list_or_none;
use super::{Draft, Result};
use plc_diag::Invalid;
use plc_fbd::model::*;
use plc_syntax::fbd as syn;
use plc_syntax::Scalar;

impl Net<'_, '_, '_> {
    /// The input `j` of block `d`, at `path`.
    pub(super) fn input(&self, d: &Draft, j: &syn::Input, path: &str) -> Result<Input> {
        match &j.from {
            syn::Connection::Invalid(e) => Err(self.problem(d, e, path)),
            syn::Connection::Variable(name) => Ok(Input::Variable(name.to_string())),
            syn::Connection::Constant(c) => match c {
                Scalar::Bool(b) => Ok(Input::Constant(Constant::Bool(*b))),
                Scalar::Number(n) => Ok(Input::Constant(Constant::Number(n.clone()))),
                Scalar::Str(s) => Ok(Input::Constant(Constant::Time(s.to_string()))),
                other => Err(self.err(
                    d,
                    path,
                    Invalid::Shape {
                        expected: "an operand or an arc {\"from\": BLOCK}",
                        found: other.kind(),
                    },
                )),
            },
            syn::Connection::Arc { block, pin } => self.arc(d, *block, pin.as_ref(), path),
        }
    }

    /// An arc from output `pin` (the first when `None`) of block `src`.
    fn arc(
        &self,
        d: &Draft,
        src: u32,
        pin: Option<&syn::Read<plc_syntax::Text>>,
        path: &str,
    ) -> Result<Input> {
        let from_path = format!("{path}.from");
        let b = *self.index.get(&src).ok_or_else(|| {
            self.err(
                d,
                &from_path,
                Invalid::UndefinedBlock {
                    id: src,
                    network: self.id.to_owned(),
                },
            )
        })?;
        let pins = &self.out_pins[b.index()];
        let op = format!("block {src} ({})", self.drafts[b.index()].op);
        let pin = match pin {
            None if pins.is_empty() => {
                return Err(self.err(
                    d,
                    &from_path,
                    Invalid::UnknownPin {
                        op,
                        dir: "output",
                        pin: "(any)".into(),
                        pins: "none".into(),
                    },
                ))
            }
            None => 0,
            Some(Err(e)) => return Err(self.problem(d, e, path)),
            // IEC 61131-3 names are case-insensitive (CODESYS writes `Out`); CODESYS names an
            // operator's single result `Out1`.
            Some(Ok(name)) => match pins
                .iter()
                .position(|x| x.eq_ignore_ascii_case(name))
                .or(
                    (pins.len() == 1 && pins[0] == "OUT" && name.eq_ignore_ascii_case("OUT1"))
                        .then_some(0),
                ) {
                Some(i) => i as u32,
                None => {
                    return Err(self.err(
                        d,
                        &format!("{path}.pin"),
                        Invalid::UnknownPin {
                            op,
                            dir: "output",
                            pin: name.to_string(),
                            pins: list_or_none(pins),
                        },
                    ))
                }
            },
        };
        Ok(Input::Arc { from: b, pin })
    }
}
