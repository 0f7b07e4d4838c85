//! One FBD block of a network being read: its input pins, its output pins, and the fields
//! only some ops have (instance, label, condition, control arcs, comment), each checked against
//! its op. Arcs are resolved against the blocks of the same network (the [`Net`] context);
//! operands stay JSON for the lowering. Errors carry the network id, the block id and the JSON
//! path.

use super::input::input;
use super::util::{conn_is_given, kind_of, list_or_none, name, pin_count_text, string, var_name};
use super::{Draft, FbSig, Result};
use crate::diag::{Invalid, LoadError};
use crate::fbd::model::*;
use serde_json::{Map, Value as Json};
use std::collections::HashMap;

/// One network being read: what every block of it needs to resolve its arcs.
pub(super) struct Net<'n, 'v> {
    pub(super) id: &'n str,
    pub(super) index: &'n HashMap<u32, BlockId>,
    pub(super) drafts: &'n [Draft<'v>],
    pub(super) out_pins: &'n [Vec<String>],
    pub(super) sig: &'n dyn Fn(&str) -> Option<FbSig>,
}

impl Net<'_, '_> {
    /// A block: its input pins, its output pins, then instance, label, condition, control arcs.
    pub(super) fn block(&self, d: &Draft) -> Result<Block> {
        let inputs = self.inputs(d)?;
        let outputs = self.outputs(d)?;
        self.rest(d, inputs, outputs)
    }

    /// The input pins: by position or by name; every input of a built-in op connected.
    fn inputs(&self, d: &Draft) -> Result<Vec<InputPin>> {
        let id = self.id;
        let be = |q: String, k: Invalid| LoadError::fbd(id, Some(d.id), &q, k);
        let p = &d.path;
        let o = d.o;
        let (index, drafts, out_pins) = (self.index, self.drafts, self.out_pins);
        let arc = |j: &Json, q: String| -> Result<Input> {
            input(j, &q, id, d.id, index, drafts, out_pins)
        };
        let declared: Option<Vec<String>> = match &d.op {
            Op::Call(fb) => Some((self.sig)(fb).map(|s| s.inputs).unwrap_or_default()),
            _ => None,
        };
        if matches!(d.op, Op::Jmp | Op::Ret) && o.contains_key("in") {
            return Err(be(
                format!("{p}.in"),
                Invalid::Misplaced {
                    what: "`in`",
                    place: "on a JMP or RET (its condition is `cond`)",
                },
            ));
        }
        let mut inputs: Vec<InputPin> = Vec::new();
        match o.get("in") {
            None => {
                let pins = declared.clone().unwrap_or_else(|| d.op.input_pins(0));
                if declared.is_none() && !pins.is_empty() {
                    return Err(be(
                        p.clone(),
                        Invalid::MissingField {
                            field: "in",
                            what: "a block with inputs",
                        },
                    ));
                }
                inputs = pins
                    .into_iter()
                    .map(|n| InputPin {
                        name: n,
                        input: None,
                        path: p.clone(),
                    })
                    .collect();
            }
            Some(Json::Array(list)) => {
                let pins = declared
                    .clone()
                    .unwrap_or_else(|| d.op.input_pins(list.len()));
                let fits = if declared.is_some() {
                    list.len() <= pins.len()
                } else {
                    list.len() == pins.len()
                };
                if !fits {
                    return Err(be(
                        format!("{p}.in"),
                        Invalid::PinCount {
                            op: d.op.name().to_owned(),
                            expected: pin_count_text(&d.op, &pins),
                            found: list.len(),
                        },
                    ));
                }
                for (i, pin) in pins.into_iter().enumerate() {
                    let q = format!("{p}.in[{i}]");
                    let conn = match list.get(i) {
                        Some(j) => Some(arc(j, q.clone())?),
                        None => None,
                    };
                    inputs.push(InputPin {
                        name: pin,
                        input: conn,
                        path: if conn_is_given(list.len(), i) {
                            q
                        } else {
                            format!("{p}.in")
                        },
                    });
                }
            }
            Some(Json::Object(map)) => {
                let pins = match &declared {
                    Some(pins) => pins.clone(),
                    None if d.op.extensible() => {
                        // IN1..INn, n = the highest given.
                        let mut n = 0;
                        for k in map.keys() {
                            match k
                                .strip_prefix("IN")
                                .and_then(|x| x.parse::<usize>().ok())
                                .filter(|&x| x >= 1 && format!("IN{x}") == *k)
                            {
                                Some(x) => n = n.max(x),
                                None => {
                                    return Err(be(
                                        format!("{p}.in.{k}"),
                                        Invalid::UnknownPin {
                                            op: d.op.name().to_owned(),
                                            dir: "input",
                                            pin: k.clone(),
                                            pins: "IN1, IN2, …".into(),
                                        },
                                    ))
                                }
                            }
                        }
                        d.op.input_pins(n)
                    }
                    None => d.op.input_pins(0),
                };
                for k in map.keys() {
                    if !pins.contains(k) {
                        return Err(be(
                            format!("{p}.in.{k}"),
                            Invalid::UnknownPin {
                                op: d.op.name().to_owned(),
                                dir: "input",
                                pin: k.clone(),
                                pins: list_or_none(&pins),
                            },
                        ));
                    }
                }
                for pin in pins {
                    let q = format!("{p}.in.{pin}");
                    let conn = match map.get(&pin) {
                        Some(j) => Some(arc(j, q.clone())?),
                        None => None,
                    };
                    let path = if conn.is_some() { q } else { format!("{p}.in") };
                    inputs.push(InputPin {
                        name: pin,
                        input: conn,
                        path,
                    });
                }
            }
            Some(other) => {
                return Err(be(
                    format!("{p}.in"),
                    Invalid::Shape {
                        expected: "an array of inputs or an object {PIN: input}",
                        found: kind_of(other),
                    },
                ))
            }
        }
        if declared.is_none() {
            if let Some(pin) = inputs.iter().find(|x| x.input.is_none()) {
                return Err(be(
                    format!("{p}.in"),
                    Invalid::Unconnected {
                        op: d.op.name().to_owned(),
                        pin: pin.name.clone(),
                    },
                ));
            }
        }
        Ok(inputs)
    }

    /// The output pins and the variables each is written to.
    fn outputs(&self, d: &Draft) -> Result<Vec<OutputPin>> {
        let id = self.id;
        let be = |q: String, k: Invalid| LoadError::fbd(id, Some(d.id), &q, k);
        let p = &d.path;
        let o = d.o;
        let (index, out_pins) = (self.index, self.out_pins);
        let pins = &out_pins[index[&d.id].index()];
        let mut outputs: Vec<OutputPin> = pins
            .iter()
            .map(|n| OutputPin {
                name: n.clone(),
                vars: Vec::new(),
            })
            .collect();
        if let Some(out) = o.get("out") {
            let op_ = d.op.name().to_owned();
            if pins.is_empty() {
                return Err(be(
                    format!("{p}.out"),
                    Invalid::Misplaced {
                        what: "`out`",
                        place: "on a block without outputs",
                    },
                ));
            }
            match out {
                Json::String(s) => outputs[0].vars.push((
                    var_name(s).map_err(|k| be(format!("{p}.out"), k))?,
                    format!("{p}.out"),
                )),
                Json::Array(list) => {
                    if list.len() > pins.len() {
                        return Err(be(
                            format!("{p}.out"),
                            Invalid::PinCount {
                                op: op_,
                                expected: format!(
                                    "at most {} output{} ({})",
                                    pins.len(),
                                    if pins.len() == 1 { "" } else { "s" },
                                    pins.join(", ")
                                ),
                                found: list.len(),
                            },
                        ));
                    }
                    for (i, j) in list.iter().enumerate() {
                        match j {
                            Json::Null => {}
                            Json::String(s) => outputs[i].vars.push((
                                var_name(s).map_err(|k| be(format!("{p}.out[{i}]"), k))?,
                                format!("{p}.out[{i}]"),
                            )),
                            other => {
                                return Err(be(
                                    format!("{p}.out[{i}]"),
                                    Invalid::Shape {
                                        expected: "a variable name or null",
                                        found: kind_of(other),
                                    },
                                ))
                            }
                        }
                    }
                }
                Json::Object(map) => {
                    for (k, j) in map {
                        let q = format!("{p}.out.{k}");
                        let i = pins.iter().position(|x| x == k).ok_or_else(|| {
                            be(
                                q.clone(),
                                Invalid::UnknownPin {
                                    op: op_.clone(),
                                    dir: "output",
                                    pin: k.clone(),
                                    pins: pins.join(", "),
                                },
                            )
                        })?;
                        match j {
                            Json::String(s) => outputs[i]
                                .vars
                                .push((var_name(s).map_err(|kd| be(q.clone(), kd))?, q.clone())),
                            Json::Array(vs) => {
                                for (m, v) in vs.iter().enumerate() {
                                    let s = v.as_str().ok_or_else(|| {
                                        be(
                                            format!("{q}[{m}]"),
                                            Invalid::Shape {
                                                expected: "a variable name",
                                                found: kind_of(v),
                                            },
                                        )
                                    })?;
                                    outputs[i].vars.push((
                                        var_name(s).map_err(|kd| be(format!("{q}[{m}]"), kd))?,
                                        format!("{q}[{m}]"),
                                    ));
                                }
                            }
                            other => {
                                return Err(be(
                                    q,
                                    Invalid::Shape {
                                        expected: "a variable name or an array of them",
                                        found: kind_of(other),
                                    },
                                ))
                            }
                        }
                    }
                }
                other => {
                    return Err(be(
                        format!("{p}.out"),
                        Invalid::Shape {
                            expected: "a variable name, an array or an object {PIN: variable}",
                            found: kind_of(other),
                        },
                    ))
                }
            }
        }
        Ok(outputs)
    }

    /// Instance, label, condition, control arcs and comment.
    fn rest(&self, d: &Draft, inputs: Vec<InputPin>, outputs: Vec<OutputPin>) -> Result<Block> {
        let id = self.id;
        let be = |q: String, k: Invalid| LoadError::fbd(id, Some(d.id), &q, k);
        let p = &d.path;
        let o = d.o;
        let (index, drafts, out_pins) = (self.index, self.drafts, self.out_pins);
        let arc = |j: &Json, q: String| -> Result<Input> {
            input(j, &q, id, d.id, index, drafts, out_pins)
        };
        let instance = match only_if(
            o,
            "instance",
            d.op.needs_instance(),
            FieldRule {
                needed_by: "a timer, counter or function block",
                quoted: "`instance`",
                misplaced: "on this block (only timers, counters and function blocks have one)",
            },
            p,
            &be,
        )? {
            Some(j) => Some(
                var_name(string(j).map_err(|k| be(format!("{p}.instance"), k))?)
                    .map_err(|k| be(format!("{p}.instance"), k))?,
            ),
            None => None,
        };
        let label = match only_if(
            o,
            "label",
            d.op == Op::Jmp,
            FieldRule {
                needed_by: "a JMP",
                quoted: "`label`",
                misplaced: "on a block other than JMP (label the network)",
            },
            p,
            &be,
        )? {
            Some(l) => Some(name(l).map_err(|k| be(format!("{p}.label"), k))?.to_owned()),
            None => None,
        };
        let cond = match o.get("cond") {
            None => None,
            Some(j) => Some(arc(j, format!("{p}.cond"))?),
        };
        let mut after = Vec::new();
        if let Some(a) = o.get("after") {
            let q = format!("{p}.after");
            let list = a.as_array().ok_or_else(|| {
                be(
                    q.clone(),
                    Invalid::Shape {
                        expected: "an array of block ids",
                        found: kind_of(a),
                    },
                )
            })?;
            for (i, j) in list.iter().enumerate() {
                let qi = format!("{q}[{i}]");
                let src = j
                    .as_u64()
                    .filter(|&n| n <= u32::MAX as u64)
                    .ok_or_else(|| {
                        be(
                            qi.clone(),
                            Invalid::Shape {
                                expected: "a block id",
                                found: kind_of(j),
                            },
                        )
                    })? as u32;
                let b = *index.get(&src).ok_or_else(|| {
                    be(
                        qi,
                        Invalid::UndefinedBlock {
                            id: src,
                            network: id.to_owned(),
                        },
                    )
                })?;
                after.push(b);
            }
            after.sort_unstable();
            after.dedup();
        }
        let comment = match o.get("comment") {
            None => None,
            Some(c) => Some(
                string(c)
                    .map_err(|k| be(format!("{p}.comment"), k))?
                    .to_owned(),
            ),
        };
        Ok(Block {
            id: d.id,
            op: d.op.clone(),
            path: p.clone(),
            inputs,
            outputs,
            instance,
            label,
            cond,
            after,
            comment,
        })
    }
}

/// How messages name a field that only some blocks have.
struct FieldRule {
    /// The blocks that need it (`a JMP`).
    needed_by: &'static str,
    /// The field as quoted in a message (`` `label` ``).
    quoted: &'static str,
    /// Where it does not belong.
    misplaced: &'static str,
}

/// A block field that exactly the blocks `needed` holds for have: missing where needed, or
/// present where not, is an error.
fn only_if<'v>(
    o: &'v Map<String, Json>,
    field: &'static str,
    needed: bool,
    rule: FieldRule,
    path: &str,
    be: &impl Fn(String, Invalid) -> LoadError,
) -> Result<Option<&'v Json>> {
    match (o.get(field), needed) {
        (Some(j), true) => Ok(Some(j)),
        (None, true) => Err(be(
            path.to_owned(),
            Invalid::MissingField {
                field,
                what: rule.needed_by,
            },
        )),
        (Some(_), false) => Err(be(
            format!("{path}.{field}"),
            Invalid::Misplaced {
                what: rule.quoted,
                place: rule.misplaced,
            },
        )),
        (None, false) => Ok(None),
    }
}
