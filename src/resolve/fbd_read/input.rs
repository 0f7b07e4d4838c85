//! One INPUT of a block: an operand (kept as JSON for the lowering), or an arc
//! `{"from": ID}` / `{"from": ID, "pin": "Q"}` resolved to a block of the same network and
//! one of its outputs.

use super::util::{kind_of, list_or_none, string};
use super::{Draft, Result};
use crate::diag::{Invalid, LoadError};
use crate::fbd::model::*;
use serde_json::Value as Json;
use std::collections::HashMap;

/// An INPUT: an operand, or `{"from": ID}` / `{"from": ID, "pin": "Q"}`.
pub(super) fn input(
    j: &Json,
    path: &str,
    network: &str,
    block: u32,
    index: &HashMap<u32, BlockId>,
    drafts: &[Draft],
    out_pins: &[Vec<String>],
) -> Result<Input> {
    let e = |q: String, k: Invalid| LoadError::fbd(network, Some(block), &q, k);
    match j {
        Json::Object(o) => {
            if let Some(k) = o.keys().find(|k| !["from", "pin"].contains(&k.as_str())) {
                return Err(e(
                    format!("{path}.{k}"),
                    Invalid::UnknownField {
                        field: k.clone(),
                        what: "an arc",
                        allowed: "from, pin".into(),
                    },
                ));
            }
            let from = o.get("from").ok_or_else(|| {
                e(
                    path.to_owned(),
                    Invalid::MissingField {
                        field: "from",
                        what: "an arc",
                    },
                )
            })?;
            let src = from
                .as_u64()
                .filter(|&n| n <= u32::MAX as u64)
                .ok_or_else(|| {
                    e(
                        format!("{path}.from"),
                        Invalid::Shape {
                            expected: "a block id",
                            found: kind_of(from),
                        },
                    )
                })? as u32;
            let b = *index.get(&src).ok_or_else(|| {
                e(
                    format!("{path}.from"),
                    Invalid::UndefinedBlock {
                        id: src,
                        network: network.to_owned(),
                    },
                )
            })?;
            let pins = &out_pins[b.index()];
            let opname = drafts[b.index()].op.name().to_owned();
            let pin = match o.get("pin") {
                None if pins.is_empty() => {
                    return Err(e(
                        format!("{path}.from"),
                        Invalid::UnknownPin {
                            op: format!("block {src} ({opname})"),
                            dir: "output",
                            pin: "(any)".into(),
                            pins: "none".into(),
                        },
                    ))
                }
                None => 0,
                Some(pj) => {
                    let pn = string(pj).map_err(|k| e(format!("{path}.pin"), k))?;
                    pins.iter().position(|x| x == pn).ok_or_else(|| {
                        e(
                            format!("{path}.pin"),
                            Invalid::UnknownPin {
                                op: format!("block {src} ({opname})"),
                                dir: "output",
                                pin: pn.to_owned(),
                                pins: list_or_none(pins),
                            },
                        )
                    })? as u32
                }
            };
            Ok(Input::Arc { from: b, pin })
        }
        Json::String(_) | Json::Number(_) | Json::Bool(_) => Ok(Input::Operand(j.clone())),
        other => Err(e(
            path.to_owned(),
            Invalid::Shape {
                expected: "an operand or an arc {\"from\": BLOCK}",
                found: kind_of(other),
            },
        )),
    }
}
