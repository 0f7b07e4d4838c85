//! One FBD block of a network being read: its input pins, its output pins, and the fields
//! only some ops have (instance, label, condition, control arcs, comment), each checked against
//! its op and put into the op's variant. Arcs are resolved against the blocks of the same network
//! (the [`Net`] context); operands stay names and constants for the lowering. Errors carry the
//! network id, the block id and the JSON path.

use super::util::{list_or_none, pin_count_text, valid_name};
use super::{reported, Draft, FbSig, Result};
use plc_diag::{Invalid, LoadError};
use plc_fbd::model::*;
use plc_syntax::fbd as syn;
use plc_syntax::Text;
use std::collections::HashMap;

/// One network being read: what every block of it needs to resolve its arcs.
pub(super) struct Net<'n, 's, 'a> {
    pub(super) id: &'n str,
    pub(super) index: &'n HashMap<u32, BlockId>,
    pub(super) drafts: &'n [Draft<'s, 'a>],
    pub(super) out_pins: &'n [Vec<String>],
    pub(super) sig: &'n dyn Fn(&str) -> Option<FbSig>,
}

/// How messages name a field that only some blocks have.
struct FieldRule {
    field: &'static str,
    /// The blocks that need it (`a JMP`).
    needed_by: &'static str,
    /// The field as quoted in a message (`` `label` ``).
    quoted: &'static str,
    /// Where it does not belong.
    misplaced: &'static str,
}

const INSTANCE: FieldRule = FieldRule {
    field: "instance",
    needed_by: "a timer, counter or function block",
    quoted: "`instance`",
    misplaced: "on this block (only timers, counters and function blocks have one)",
};

const LABEL: FieldRule = FieldRule {
    field: "label",
    needed_by: "a JMP",
    quoted: "`label`",
    misplaced: "on a block other than JMP (label the network)",
};

type Field<'s, 'a> = Option<&'s syn::Read<Text<'a>>>;

impl Net<'_, '_, '_> {
    /// An error in block `d`.
    pub(super) fn err(&self, d: &Draft, path: &str, kind: Invalid) -> LoadError {
        LoadError::fbd(self.id, Some(d.id), path, kind)
    }

    /// A problem the reader recorded in block `d` (relative to `path`).
    pub(super) fn problem(&self, d: &Draft, p: &plc_syntax::Problem, path: &str) -> LoadError {
        reported(p, path, |q, k| self.err(d, q, k))
    }

    /// Block `b` (drafted as `d`): its input pins, its output pins, then its op with its
    /// instance or label, condition, control arcs, comment.
    pub(super) fn block(&self, b: BlockId, d: &Draft) -> Result<Block> {
        let inputs = self.inputs(d)?;
        let outputs = self.outputs(b, d)?;
        let op = self.op(d)?;
        let p = &d.path;
        let cond = match &d.syn.cond {
            None => None,
            Some(j) => Some(self.input(d, j, &format!("{p}.cond"))?),
        };
        let after = self.after(d)?;
        let comment = match &d.syn.comment {
            None => None,
            Some(Err(e)) => return Err(self.problem(d, e, p)),
            Some(Ok(c)) => Some(c.to_string()),
        };
        Ok(Block {
            id: d.id,
            op,
            path: p.clone(),
            origin: d.syn.origin,
            inputs,
            outputs,
            cond,
            en: d.syn.en && d.syn.cond.is_some(),
            after,
            comment,
        })
    }

    /// The input pins: by position or by name; every input of a built-in op connected.
    fn inputs(&self, d: &Draft) -> Result<Vec<InputPin>> {
        let p = &d.path;
        let declared: Option<Vec<String>> = (d.kind == OpKind::Call)
            .then(|| (self.sig)(d.op).map(|s| s.inputs).unwrap_or_default());
        if matches!(d.kind, OpKind::Jmp | OpKind::Ret) && d.syn.inputs.is_some() {
            return Err(self.err(
                d,
                &format!("{p}.in"),
                Invalid::Misplaced {
                    what: "`in`",
                    place: "on a JMP or RET (its condition is `cond`)",
                },
            ));
        }
        let inputs = match &d.syn.inputs {
            None => {
                let pins = declared.clone().unwrap_or_else(|| d.kind.input_pins(0));
                if declared.is_none() && !pins.is_empty() {
                    return Err(self.err(
                        d,
                        p,
                        Invalid::MissingField {
                            field: "in",
                            what: "a block with inputs",
                        },
                    ));
                }
                pins.into_iter()
                    .map(|name| InputPin {
                        name,
                        input: None,
                        path: p.clone(),
                    })
                    .collect()
            }
            Some(Err(e)) => return Err(self.problem(d, e, p)),
            Some(Ok(syn::Inputs::List(list))) => self.positional(d, list, declared.as_deref())?,
            Some(Ok(syn::Inputs::Named(map))) => self.named(d, map, declared.as_deref())?,
        };
        if declared.is_none() {
            if let Some(pin) = inputs.iter().find(|x| x.input.is_none()) {
                return Err(self.err(
                    d,
                    &format!("{p}.in"),
                    Invalid::Unconnected {
                        op: d.op.to_owned(),
                        pin: pin.name.clone(),
                    },
                ));
            }
        }
        Ok(inputs)
    }

    /// `"in": [A, B, …]`: the pins in order (a user function block's last ones may be left out).
    fn positional(
        &self,
        d: &Draft,
        list: &[syn::Input],
        declared: Option<&[String]>,
    ) -> Result<Vec<InputPin>> {
        let p = &d.path;
        let pins = match declared {
            Some(pins) => pins.to_vec(),
            None => d.kind.input_pins(list.len()),
        };
        let fits = if declared.is_some() {
            list.len() <= pins.len()
        } else {
            list.len() == pins.len()
        };
        if !fits {
            return Err(self.err(
                d,
                &format!("{p}.in"),
                Invalid::PinCount {
                    op: d.op.to_owned(),
                    expected: pin_count_text(d.kind, &pins),
                    found: list.len(),
                },
            ));
        }
        let mut inputs = Vec::with_capacity(pins.len());
        for (i, name) in pins.into_iter().enumerate() {
            let q = format!("{p}.in[{i}]");
            let (input, path) = match list.get(i) {
                Some(j) => (Some(self.input(d, j, &q)?), q),
                None => (None, format!("{p}.in")),
            };
            inputs.push(InputPin { name, input, path });
        }
        Ok(inputs)
    }

    /// The error for the first of the numbered `pins` that `map` leaves out: a gap, found
    /// before any pin is made (a file may give any number). `pins` are more than `map` gives.
    fn gap(
        &self,
        d: &Draft,
        map: &[(Text, syn::Input)],
        mut pins: impl Iterator<Item = String>,
    ) -> LoadError {
        let pin = pins
            .find(|pin| !map.iter().any(|(k, _)| *k == *pin))
            .expect("more pins than given: one is missing");
        let op = d.op.to_owned();
        self.err(
            d,
            &format!("{}.in", d.path),
            Invalid::Unconnected { op, pin },
        )
    }

    /// `"in": {PIN: A, …}`: extensible ops have `IN1..INn`, n the highest given.
    fn named(
        &self,
        d: &Draft,
        map: &[(Text, syn::Input)],
        declared: Option<&[String]>,
    ) -> Result<Vec<InputPin>> {
        let p = &d.path;
        let unknown = |k: &str, pins: String| {
            self.err(
                d,
                &format!("{p}.in.{k}"),
                Invalid::UnknownPin {
                    op: d.op.to_owned(),
                    dir: "input",
                    pin: k.to_owned(),
                    pins,
                },
            )
        };
        let pins = match declared {
            Some(pins) => pins.to_vec(),
            None if d.kind.extensible() => {
                let mut n = 0;
                for (k, _) in map {
                    let k = k.to_ascii_uppercase();
                    match k
                        .strip_prefix("IN")
                        .and_then(|x| x.parse::<usize>().ok())
                        .filter(|&x| x >= 1 && format!("IN{x}") == k)
                    {
                        Some(x) => n = n.max(x),
                        None => return Err(unknown(&k, "IN1, IN2, …".into())),
                    }
                }
                if n > map.len() {
                    return Err(self.gap(d, map, (1..=n).map(|i| format!("IN{i}"))));
                }
                d.kind.input_pins(n)
            }
            // MUX: K, IN0 … INn, n the highest given.
            None if d.kind == OpKind::Function(plc_model::Function::Mux) => {
                let n = map
                    .iter()
                    .filter_map(|(k, _)| {
                        k.to_ascii_uppercase()
                            .strip_prefix("IN")
                            .and_then(|x| x.parse::<usize>().ok())
                    })
                    .max()
                    .unwrap_or(1);
                let given = map
                    .iter()
                    .filter(|(k, _)| k.to_ascii_uppercase().starts_with("IN"))
                    .count();
                if n >= given {
                    return Err(self.gap(d, map, (0..=n).map(|i| format!("IN{i}"))));
                }
                d.kind.input_pins(n + 2)
            }
            None => d.kind.input_pins(0),
        };
        if let Some((k, _)) = map
            .iter()
            .find(|(k, _)| !pins.iter().any(|x| x.eq_ignore_ascii_case(k)))
        {
            return Err(unknown(k, list_or_none(&pins)));
        }
        let mut inputs = Vec::with_capacity(pins.len());
        for name in pins {
            let q = format!("{p}.in.{name}");
            let (input, path) = match map.iter().find(|(k, _)| k.eq_ignore_ascii_case(&name)) {
                Some((_, j)) => (Some(self.input(d, j, &q)?), q),
                None => (None, format!("{p}.in")),
            };
            inputs.push(InputPin { name, input, path });
        }
        Ok(inputs)
    }

    /// The output pins of block `b` and the variables each is written to.
    fn outputs(&self, b: BlockId, d: &Draft) -> Result<Vec<OutputPin>> {
        let p = &d.path;
        let pins = &self.out_pins[b.index()];
        let mut outputs: Vec<OutputPin> = pins
            .iter()
            .map(|n| OutputPin {
                name: n.clone(),
                vars: Vec::new(),
            })
            .collect();
        let Some(out) = &d.syn.outputs else {
            return Ok(outputs);
        };
        if pins.is_empty() {
            return Err(self.err(
                d,
                &format!("{p}.out"),
                Invalid::Misplaced {
                    what: "`out`",
                    place: "on a block without outputs",
                },
            ));
        }
        match out {
            Err(e) => return Err(self.problem(d, e, p)),
            Ok(syn::Outputs::First(v)) => outputs[0]
                .vars
                .push((v.name.to_string(), format!("{p}.out"))),
            Ok(syn::Outputs::List(list)) => {
                if list.len() > pins.len() {
                    return Err(self.err(
                        d,
                        &format!("{p}.out"),
                        Invalid::PinCount {
                            op: d.op.to_owned(),
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
                for (i, v) in list.iter().enumerate() {
                    match v {
                        Err(e) => return Err(self.problem(d, e, p)),
                        Ok(None) => {}
                        Ok(Some(v)) => outputs[i]
                            .vars
                            .push((v.name.to_string(), format!("{p}.out[{i}]"))),
                    }
                }
            }
            Ok(syn::Outputs::Named(map)) => {
                for (k, targets) in map {
                    let q = format!("{p}.out.{k}");
                    let Some(i) = pins.iter().position(|x| x.eq_ignore_ascii_case(k)).or((pins
                        .len()
                        == 1
                        && pins[0] == "OUT"
                        && k.eq_ignore_ascii_case("OUT1"))
                    .then_some(0)) else {
                        return Err(self.err(
                            d,
                            &q,
                            Invalid::UnknownPin {
                                op: d.op.to_owned(),
                                dir: "output",
                                pin: k.to_string(),
                                pins: pins.join(", "),
                            },
                        ));
                    };
                    match targets {
                        Err(e) => return Err(self.problem(d, e, p)),
                        Ok(syn::Targets::One(v)) => {
                            outputs[i].vars.push((v.name.to_string(), q.clone()))
                        }
                        Ok(syn::Targets::Many(vs)) => {
                            for (m, v) in vs.iter().enumerate() {
                                let v = v.as_ref().map_err(|e| self.problem(d, e, p))?;
                                outputs[i]
                                    .vars
                                    .push((v.name.to_string(), format!("{q}[{m}]")));
                            }
                        }
                    }
                }
            }
        }
        Ok(outputs)
    }

    /// The op with its data: the instance of a timer, counter or call, the label of a JMP
    /// (each refused on the other blocks).
    fn op(&self, d: &Draft) -> Result<Op> {
        Ok(match d.kind {
            OpKind::Timer(kind) => Op::Timer {
                kind,
                instance: self.instance(d)?,
            },
            OpKind::Ctu => Op::Ctu {
                instance: self.instance(d)?,
            },
            OpKind::Ctd => Op::Ctd {
                instance: self.instance(d)?,
            },
            OpKind::Bistable(kind) => Op::Bistable {
                kind,
                instance: self.instance(d)?,
            },
            OpKind::Trigger(kind) => Op::Trigger {
                kind,
                instance: self.instance(d)?,
            },
            OpKind::Ctud => Op::Ctud {
                instance: self.instance(d)?,
            },
            OpKind::Call => Op::Call {
                fb: d.op.to_owned(),
                instance: self.instance(d)?,
            },
            OpKind::Jmp => {
                self.refused(d, d.syn.instance.as_ref(), &INSTANCE)?;
                let label = self.required(d, d.syn.label.as_ref(), &LABEL)?;
                if !valid_name(&label) {
                    let path = format!("{}.label", d.path);
                    return Err(self.err(d, &path, Invalid::BadName { name: label }));
                }
                Op::Jmp { label }
            }
            OpKind::Compare(c) => self.plain(d, Op::Compare(c))?,
            OpKind::Arith(a) => self.plain(d, Op::Arith(a))?,
            OpKind::And => self.plain(d, Op::And)?,
            OpKind::Or => self.plain(d, Op::Or)?,
            OpKind::Xor => self.plain(d, Op::Xor)?,
            OpKind::Not => self.plain(d, Op::Not)?,
            OpKind::Move => self.plain(d, Op::Move)?,
            OpKind::Sel => self.plain(d, Op::Sel)?,
            OpKind::Max => self.plain(d, Op::Max)?,
            OpKind::Min => self.plain(d, Op::Min)?,
            OpKind::Limit => self.plain(d, Op::Limit)?,
            OpKind::Ret => self.plain(d, Op::Ret)?,
            OpKind::TStart => self.plain(d, Op::TStart)?,
            OpKind::TStop => self.plain(d, Op::TStop)?,
            OpKind::Function(f) => self.plain(d, Op::Function(f))?,
        })
    }

    /// The instance of a block that runs on one (and no label).
    fn instance(&self, d: &Draft) -> Result<String> {
        let instance = self.required(d, d.syn.instance.as_ref(), &INSTANCE)?;
        self.refused(d, d.syn.label.as_ref(), &LABEL)?;
        Ok(instance)
    }

    /// `op`, for a block that has neither instance nor label.
    fn plain(&self, d: &Draft, op: Op) -> Result<Op> {
        self.refused(d, d.syn.instance.as_ref(), &INSTANCE)?;
        self.refused(d, d.syn.label.as_ref(), &LABEL)?;
        Ok(op)
    }

    /// A field this block must have.
    fn required(&self, d: &Draft, field: Field, rule: &FieldRule) -> Result<String> {
        match field {
            Some(Ok(s)) => Ok(s.to_string()),
            Some(Err(e)) => Err(self.problem(d, e, &d.path)),
            None => Err(self.err(
                d,
                &d.path,
                Invalid::MissingField {
                    field: rule.field,
                    what: rule.needed_by,
                },
            )),
        }
    }

    /// A field this block may not have.
    fn refused(&self, d: &Draft, field: Field, rule: &FieldRule) -> Result<()> {
        match field {
            None => Ok(()),
            Some(_) => Err(self.err(
                d,
                &format!("{}.{}", d.path, rule.field),
                Invalid::Misplaced {
                    what: rule.quoted,
                    place: rule.misplaced,
                },
            )),
        }
    }

    /// The control arcs: block ids of the network, sorted, without duplicates.
    fn after(&self, d: &Draft) -> Result<Vec<BlockId>> {
        let p = &d.path;
        let list = match &d.syn.after {
            None => return Ok(Vec::new()),
            Some(Err(e)) => return Err(self.problem(d, e, p)),
            Some(Ok(list)) => list,
        };
        let mut after = Vec::with_capacity(list.len());
        for (i, src) in list.iter().enumerate() {
            let src = *src.as_ref().map_err(|e| self.problem(d, e, p))?;
            let b = *self.index.get(&src).ok_or_else(|| {
                self.err(
                    d,
                    &format!("{p}.after[{i}]"),
                    Invalid::UndefinedBlock {
                        id: src,
                        network: self.id.to_owned(),
                    },
                )
            })?;
            after.push(b);
        }
        after.sort_unstable();
        after.dedup();
        Ok(after)
    }
}
