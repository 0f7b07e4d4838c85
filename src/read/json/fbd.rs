//! FBD bodies of the JSON program format (docs/fbd.md) → [`syntax::fbd`], without a value
//! tree: every node is read from its slice of the text with the reader's visitors
//! ([`Container`]: an array or object of raw slices, or the leaf found instead; [`AnyScalar`]:
//! a leaf), so each network, block, input and output variable gets the [`Origin`] of its slice.
//!
//! Every shape the format allows is checked here, in the order docs/fbd.md lists a node's
//! fields; what is malformed becomes a [`Problem`] at the part it concerns (see
//! [`syntax::fbd`]) and reading goes on. Deliberately not here: block ids, ops, arcs, pins,
//! labels and names (`crate::resolve::fbd_read`).

use super::scalar::{AnyScalar, Container};
use super::{get, raw, shape, Entries};
use crate::diag::{Invalid, LoadError};
use crate::syntax::fbd::*;
use crate::syntax::{Origin, Problem, Scalar, Text};
use serde_json::value::RawValue;

type Result<T> = std::result::Result<T, LoadError>;

const BODY_KEYS: &[&str] = &["networks", "comment"];
const NETWORK_KEYS: &[&str] = &["id", "label", "comment", "blocks"];
const BLOCK_KEYS: &[&str] = &[
    "id", "op", "in", "out", "instance", "cond", "after", "label", "comment",
];
const ARC_KEYS: &[&str] = &["from", "pin"];

/// Reads the `fbd` value `v`; `base` is the address of the start of the whole text.
pub(super) fn body<'de>(base: usize, v: &'de RawValue) -> Result<FbdBody<'de>> {
    FbdReader { base }.body(v)
}

struct FbdReader {
    base: usize,
}

/// A problem at `at` (relative to the node that holds it).
fn problem(at: impl Into<String>, kind: Invalid) -> Box<Problem> {
    Problem::new(at, kind)
}

fn unknown_key(e: &Entries, allowed: &[&str], what: &'static str) -> Option<Box<Problem>> {
    let (k, _) = e.iter().find(|(k, _)| !allowed.contains(&k.as_ref()))?;
    Some(problem(
        format!(".{k}"),
        Invalid::UnknownField {
            field: k.to_string(),
            what,
            allowed: allowed.join(", "),
        },
    ))
}

fn missing(field: &'static str, what: &'static str) -> Box<Problem> {
    problem("", Invalid::MissingField { field, what })
}

/// What a container holds when it is not the expected kind (arrays and objects by kind only).
fn found(c: Container) -> Scalar {
    match c {
        Container::Array(_) => Scalar::Array,
        Container::Object(_) => Scalar::Object,
        Container::Other(s) => s,
    }
}

/// A whole number that fits a block id.
fn block_id(s: &Scalar) -> Option<u32> {
    match s {
        Scalar::Number(n) => n.as_u64().and_then(|n| u32::try_from(n).ok()),
        _ => None,
    }
}

impl FbdReader {
    fn origin(&self, v: &RawValue) -> Origin {
        Origin::at(v.get().as_ptr() as usize - self.base)
    }

    fn container<'de>(&self, v: &'de RawValue) -> Result<Container<'de>> {
        raw(v, "fbd")
    }

    fn scalar<'de>(&self, v: &'de RawValue) -> Result<Scalar<'de>> {
        Ok(raw::<AnyScalar>(v, "fbd")?.0)
    }

    /// An optional string field `key`: `Err` at `.key` when it is not a string.
    fn text<'de>(&self, e: &Entries<'de>, key: &str) -> Result<Option<Read<Text<'de>>>> {
        let Some(v) = get(e, key) else {
            return Ok(None);
        };
        Ok(Some(match self.scalar(v)? {
            Scalar::Str(s) => Ok(s),
            other => Err(problem(format!(".{key}"), shape("a string", &other))),
        }))
    }

    fn body<'de>(&self, v: &'de RawValue) -> Result<FbdBody<'de>> {
        let mut body = FbdBody {
            origin: self.origin(v),
            comment: None,
            networks: Vec::new(),
            problem: None,
        };
        let e = match self.container(v)? {
            Container::Object(e) => e,
            other => {
                let expected = "an object (an FBD body: {\"networks\": [...]})";
                body.problem = Some(problem("", shape(expected, &found(other))));
                return Ok(body);
            }
        };
        body.problem = unknown_key(&e, BODY_KEYS, "an FBD body");
        if let Some(c) = get(&e, "comment") {
            // Not checked: a body's comment is free.
            if let Scalar::Str(s) = self.scalar(c)? {
                body.comment = Some(s);
            }
        }
        match get(&e, "networks") {
            None => {
                body.problem
                    .get_or_insert_with(|| missing("networks", "an FBD body"));
            }
            Some(n) => match self.container(n)? {
                Container::Array(items) => {
                    body.networks = items
                        .into_iter()
                        .map(|n| self.network(n))
                        .collect::<Result<_>>()?;
                }
                other => {
                    body.problem.get_or_insert_with(|| {
                        problem(".networks", shape("an array", &found(other)))
                    });
                }
            },
        }
        Ok(body)
    }

    fn network<'de>(&self, v: &'de RawValue) -> Result<Network<'de>> {
        let mut net = Network {
            origin: self.origin(v),
            id: Ok(Text::Borrowed("")),
            label: None,
            comment: None,
            blocks: Ok(Vec::new()),
            problem: None,
        };
        let e = match self.container(v)? {
            Container::Object(e) => e,
            other => {
                net.id = Err(problem("", shape("an object (a network)", &found(other))));
                return Ok(net);
            }
        };
        net.id = match get(&e, "id") {
            None => Err(missing("id", "a network")),
            Some(id) => match self.scalar(id)? {
                Scalar::Str(s)
                    if s.is_empty() || s.chars().any(|c| c.is_whitespace() || c == '"') =>
                {
                    Err(problem(
                        ".id",
                        Invalid::Shape {
                            expected: "a network id without spaces or quotes",
                            found: format!("\"{s}\""),
                        },
                    ))
                }
                Scalar::Str(s) => Ok(s),
                other => Err(problem(".id", shape("a string", &other))),
            },
        };
        net.problem = unknown_key(&e, NETWORK_KEYS, "a network");
        net.label = self.text(&e, "label")?;
        net.comment = self.text(&e, "comment")?;
        net.blocks = match get(&e, "blocks") {
            None => Err(missing("blocks", "a network")),
            Some(b) => match self.container(b)? {
                Container::Array(items) if items.is_empty() => Err(problem(
                    ".blocks",
                    Invalid::Shape {
                        expected: "at least one block",
                        found: "an empty array".into(),
                    },
                )),
                Container::Array(items) => Ok(items
                    .into_iter()
                    .map(|b| self.block(b))
                    .collect::<Result<_>>()?),
                other => Err(problem(".blocks", shape("an array", &found(other)))),
            },
        };
        Ok(net)
    }

    fn block<'de>(&self, v: &'de RawValue) -> Result<Block<'de>> {
        let mut b = Block {
            origin: self.origin(v),
            id: Ok(0),
            op: Ok(Text::Borrowed("")),
            inputs: None,
            outputs: None,
            instance: None,
            label: None,
            cond: None,
            after: None,
            comment: None,
            problem: None,
        };
        let e = match self.container(v)? {
            Container::Object(e) => e,
            other => {
                b.id = Err(problem("", shape("an object (a block)", &found(other))));
                return Ok(b);
            }
        };
        b.id = match get(&e, "id") {
            None => Err(missing("id", "a block")),
            Some(id) => {
                let s = self.scalar(id)?;
                block_id(&s).ok_or_else(|| {
                    problem(".id", shape("a block id (a whole number, 0 or more)", &s))
                })
            }
        };
        b.problem = unknown_key(&e, BLOCK_KEYS, "a block");
        b.op = match self.text(&e, "op")? {
            None => Err(missing("op", "a block")),
            Some(op) => op,
        };
        if let Some(i) = get(&e, "in") {
            b.inputs = Some(self.inputs(i)?);
        }
        if let Some(o) = get(&e, "out") {
            b.outputs = Some(self.outputs(o)?);
        }
        b.instance = self.text(&e, "instance")?;
        b.label = self.text(&e, "label")?;
        if let Some(c) = get(&e, "cond") {
            b.cond = Some(self.input(c)?);
        }
        if let Some(a) = get(&e, "after") {
            b.after = Some(self.after(a)?);
        }
        b.comment = self.text(&e, "comment")?;
        Ok(b)
    }

    fn inputs<'de>(&self, v: &'de RawValue) -> Result<Read<Inputs<'de>>> {
        Ok(match self.container(v)? {
            Container::Array(items) => Ok(Inputs::List(
                items
                    .into_iter()
                    .map(|i| self.input(i))
                    .collect::<Result<_>>()?,
            )),
            Container::Object(entries) => Ok(Inputs::Named(
                entries
                    .into_iter()
                    .map(|(k, i)| Ok((k, self.input(i)?)))
                    .collect::<Result<_>>()?,
            )),
            other => Err(problem(
                ".in",
                shape(
                    "an array of inputs or an object {PIN: input}",
                    &found(other),
                ),
            )),
        })
    }

    /// An INPUT: an arc `{"from": ID, "pin": PIN}`, a variable, or a constant.
    fn input<'de>(&self, v: &'de RawValue) -> Result<Input<'de>> {
        let origin = self.origin(v);
        let from = match self.container(v)? {
            Container::Object(e) => self.arc(&e)?,
            Container::Other(Scalar::Str(s)) if is_time_literal(&s) => {
                Connection::Constant(Scalar::Str(s))
            }
            Container::Other(Scalar::Str(s)) => Connection::Variable(s),
            Container::Other(s @ (Scalar::Number(_) | Scalar::Bool(_))) => Connection::Constant(s),
            other => Connection::Invalid(problem(
                "",
                shape("an operand or an arc {\"from\": BLOCK}", &found(other)),
            )),
        };
        Ok(Input { origin, from })
    }

    fn arc<'de>(&self, e: &Entries<'de>) -> Result<Connection<'de>> {
        if let Some(p) = unknown_key(e, ARC_KEYS, "an arc") {
            return Ok(Connection::Invalid(p));
        }
        let Some(from) = get(e, "from") else {
            return Ok(Connection::Invalid(missing("from", "an arc")));
        };
        let s = self.scalar(from)?;
        let Some(block) = block_id(&s) else {
            return Ok(Connection::Invalid(problem(
                ".from",
                shape("a block id", &s),
            )));
        };
        Ok(Connection::Arc {
            block,
            pin: self.text(e, "pin")?,
        })
    }

    fn out_var<'de>(
        &self,
        v: &'de RawValue,
    ) -> Result<std::result::Result<OutVar<'de>, Scalar<'de>>> {
        Ok(match self.scalar(v)? {
            Scalar::Str(name) => Ok(OutVar {
                origin: self.origin(v),
                name,
            }),
            other => Err(other),
        })
    }

    fn outputs<'de>(&self, v: &'de RawValue) -> Result<Read<Outputs<'de>>> {
        Ok(match self.container(v)? {
            Container::Other(Scalar::Str(name)) => Ok(Outputs::First(OutVar {
                origin: self.origin(v),
                name,
            })),
            Container::Array(items) => {
                let mut list = Vec::with_capacity(items.len());
                for (i, item) in items.into_iter().enumerate() {
                    list.push(match self.out_var(item)? {
                        Ok(var) => Ok(Some(var)),
                        Err(Scalar::Null) => Ok(None),
                        Err(other) => Err(problem(
                            format!(".out[{i}]"),
                            shape("a variable name or null", &other),
                        )),
                    });
                }
                Ok(Outputs::List(list))
            }
            Container::Object(entries) => {
                let mut named = Vec::with_capacity(entries.len());
                for (k, t) in entries {
                    let targets = self.targets(t, &k)?;
                    named.push((k, targets));
                }
                Ok(Outputs::Named(named))
            }
            other => Err(problem(
                ".out",
                shape(
                    "a variable name, an array or an object {PIN: variable}",
                    &found(other),
                ),
            )),
        })
    }

    /// The variables of output pin `pin` in `{PIN: "Var"}` / `{PIN: ["V1", "V2"]}`.
    fn targets<'de>(&self, v: &'de RawValue, pin: &str) -> Result<Read<Targets<'de>>> {
        Ok(match self.container(v)? {
            Container::Other(Scalar::Str(name)) => Ok(Targets::One(OutVar {
                origin: self.origin(v),
                name,
            })),
            Container::Array(items) => {
                let mut vars = Vec::with_capacity(items.len());
                for (m, item) in items.into_iter().enumerate() {
                    vars.push(self.out_var(item)?.map_err(|other| {
                        problem(format!(".out.{pin}[{m}]"), shape("a variable name", &other))
                    }));
                }
                Ok(Targets::Many(vars))
            }
            other => Err(problem(
                format!(".out.{pin}"),
                shape("a variable name or an array of them", &found(other)),
            )),
        })
    }

    fn after<'de>(&self, v: &'de RawValue) -> Result<Read<Vec<Read<u32>>>> {
        Ok(match self.container(v)? {
            Container::Array(items) => {
                let mut ids = Vec::with_capacity(items.len());
                for (i, item) in items.into_iter().enumerate() {
                    let s = self.scalar(item)?;
                    ids.push(
                        block_id(&s).ok_or_else(|| {
                            problem(format!(".after[{i}]"), shape("a block id", &s))
                        }),
                    );
                }
                Ok(ids)
            }
            other => Err(problem(
                ".after",
                shape("an array of block ids", &found(other)),
            )),
        })
    }
}
