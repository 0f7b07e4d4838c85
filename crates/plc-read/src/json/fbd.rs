//! FBD bodies of the JSON program format (docs/fbd.md) → [`syntax::fbd`], without a value
//! tree. The program reader's cursor has already checked the body's syntax (skipping it); this
//! reader walks it again, one container at a time ([`Container`]: the positions of an array's
//! items or an object's values, or the leaf found instead), so each network, block, input and
//! output variable gets the [`Origin`] of its value. FBD bodies are small next to ladder
//! programs: the second walk costs little.
//!
//! Every shape the format allows is checked here, in the order docs/fbd.md lists a node's
//! fields; what is malformed becomes a [`Problem`] at the part it concerns (see
//! [`syntax::fbd`]) and reading goes on. Deliberately not here: block ids, ops, arcs, pins,
//! labels and names (`plc_resolve::fbd_read`).

use super::cursor::{Cursor, P};
use super::shape;
use plc_diag::Invalid;
use plc_syntax::fbd::*;
use plc_syntax::{Origin, Problem, Scalar, Text};

type Result<T> = P<T>;

const BODY_KEYS: &[&str] = &["networks", "comment"];
const NETWORK_KEYS: &[&str] = &["id", "label", "comment", "blocks", "order"];
const BLOCK_KEYS: &[&str] = &[
    "id", "op", "in", "out", "instance", "cond", "en", "after", "label", "comment",
];
const ARC_KEYS: &[&str] = &["from", "pin"];

/// Reads the `fbd` value at the cursor (which it skips).
pub(super) fn body<'a>(c: &mut Cursor<'a>) -> P<FbdBody<'a>> {
    let at = c.offset();
    c.skip()?;
    FbdReader { text: c.text() }.body(Raw(at))
}

/// A value of the text, by the byte offset where it starts.
#[derive(Copy, Clone)]
struct Raw(usize);

impl Raw {
    fn origin(self) -> Origin {
        Origin::at(self.0)
    }
}

/// What a place that wants an array or an object found.
enum Container<'a> {
    Array(Vec<Raw>),
    /// Entries in file order (a repeated key keeps its first place and its last value).
    Object(Vec<(Text<'a>, Raw)>),
    Other(Scalar<'a>),
}

type Entries<'a> = Vec<(Text<'a>, Raw)>;

fn get(e: &Entries<'_>, key: &str) -> Option<Raw> {
    e.iter().find(|(k, _)| k == key).map(|(_, v)| *v)
}

struct FbdReader<'a> {
    text: &'a str,
}

/// A problem at `at` (relative to the node that holds it), whose value starts at `origin`.
fn problem(at: impl Into<String>, origin: Origin, kind: Invalid) -> Box<Problem> {
    Problem::new(at, origin, kind)
}

fn unknown_key(e: &Entries<'_>, allowed: &[&str], what: &'static str) -> Option<Box<Problem>> {
    let (k, v) = e.iter().find(|(k, _)| !allowed.contains(&k.as_ref()))?;
    Some(problem(
        format!(".{k}"),
        v.origin(),
        Invalid::UnknownField {
            field: k.to_string(),
            what,
            allowed: allowed.join(", "),
        },
    ))
}

fn missing(origin: Origin, field: &'static str, what: &'static str) -> Box<Problem> {
    problem("", origin, Invalid::MissingField { field, what })
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

impl<'a> FbdReader<'a> {
    /// The array or object at `v` (its items' positions), or the leaf found there.
    fn container(&self, v: Raw) -> Result<Container<'a>> {
        let mut c = Cursor::new(self.text, v.0);
        let mut first = true;
        match c.peek() {
            Some(b'[') => {
                c.begin_array()?;
                let mut items = Vec::new();
                while c.item(&mut first)? {
                    items.push(Raw(c.offset()));
                    c.skip()?;
                }
                Ok(Container::Array(items))
            }
            Some(b'{') => {
                c.begin_object()?;
                let mut entries: Entries<'a> = Vec::new();
                while let Some((k, _)) = c.key(&mut first)? {
                    let at = Raw(c.offset());
                    c.skip()?;
                    match entries.iter_mut().find(|(q, _)| *q == k) {
                        Some(slot) => slot.1 = at,
                        None => entries.push((k, at)),
                    }
                }
                Ok(Container::Object(entries))
            }
            _ => Ok(Container::Other(c.scalar()?)),
        }
    }

    /// The leaf at `v` (`Scalar::Array`/`Object` for a container).
    fn scalar(&self, v: Raw) -> Result<Scalar<'a>> {
        Ok(match self.container(v)? {
            Container::Other(s) => s,
            other => found(other),
        })
    }

    /// An optional string field `key`: `Err` at `.key` when it is not a string.
    fn text(&self, e: &Entries<'a>, key: &str) -> Result<Option<Read<Text<'a>>>> {
        let Some(v) = get(e, key) else {
            return Ok(None);
        };
        Ok(Some(match self.scalar(v)? {
            Scalar::Str(s) => Ok(s),
            other => Err(problem(
                format!(".{key}"),
                v.origin(),
                shape("a string", &other),
            )),
        }))
    }

    fn body(&self, v: Raw) -> Result<FbdBody<'a>> {
        let mut body = FbdBody {
            origin: v.origin(),
            comment: None,
            networks: Vec::new(),
            problem: None,
        };
        let e = match self.container(v)? {
            Container::Object(e) => e,
            other => {
                let expected = "an object (an FBD body: {\"networks\": [...]})";
                body.problem = Some(problem("", v.origin(), shape(expected, &found(other))));
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
                    .get_or_insert_with(|| missing(v.origin(), "networks", "an FBD body"));
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
                        problem(".networks", n.origin(), shape("an array", &found(other)))
                    });
                }
            },
        }
        Ok(body)
    }

    fn network(&self, v: Raw) -> Result<Network<'a>> {
        let mut net = Network {
            origin: v.origin(),
            id: Ok(Text::Borrowed("")),
            label: None,
            comment: None,
            blocks: Ok(Vec::new()),
            order: None,
            problem: None,
        };
        let e = match self.container(v)? {
            Container::Object(e) => e,
            other => {
                net.id = Err(problem(
                    "",
                    v.origin(),
                    shape("an object (a network)", &found(other)),
                ));
                return Ok(net);
            }
        };
        net.id = match get(&e, "id") {
            None => Err(missing(v.origin(), "id", "a network")),
            Some(id) => match self.scalar(id)? {
                Scalar::Str(s)
                    if s.is_empty() || s.chars().any(|c| c.is_whitespace() || c == '"') =>
                {
                    Err(problem(
                        ".id",
                        id.origin(),
                        Invalid::Shape {
                            expected: "a network id without spaces or quotes",
                            found: format!("\"{s}\""),
                        },
                    ))
                }
                Scalar::Str(s) => Ok(s),
                other => Err(problem(".id", id.origin(), shape("a string", &other))),
            },
        };
        net.problem = unknown_key(&e, NETWORK_KEYS, "a network");
        net.label = self.text(&e, "label")?;
        net.comment = self.text(&e, "comment")?;
        if let Some(o) = get(&e, "order") {
            net.order = Some(self.ids(o, "order")?);
        }
        net.blocks = match get(&e, "blocks") {
            None => Err(missing(v.origin(), "blocks", "a network")),
            Some(b) => match self.container(b)? {
                Container::Array(items) if items.is_empty() => Err(problem(
                    ".blocks",
                    b.origin(),
                    Invalid::Shape {
                        expected: "at least one block",
                        found: "an empty array".into(),
                    },
                )),
                Container::Array(items) => Ok(items
                    .into_iter()
                    .map(|b| self.block(b))
                    .collect::<Result<_>>()?),
                other => Err(problem(
                    ".blocks",
                    b.origin(),
                    shape("an array", &found(other)),
                )),
            },
        };
        Ok(net)
    }

    fn block(&self, v: Raw) -> Result<Block<'a>> {
        let mut b = Block {
            origin: v.origin(),
            id: Ok(0),
            op: Ok(Text::Borrowed("")),
            inputs: None,
            outputs: None,
            instance: None,
            label: None,
            cond: None,
            en: false,
            after: None,
            comment: None,
            problem: None,
        };
        let e = match self.container(v)? {
            Container::Object(e) => e,
            other => {
                b.id = Err(problem(
                    "",
                    v.origin(),
                    shape("an object (a block)", &found(other)),
                ));
                return Ok(b);
            }
        };
        b.id = match get(&e, "id") {
            None => Err(missing(v.origin(), "id", "a block")),
            Some(id) => {
                let s = self.scalar(id)?;
                block_id(&s).ok_or_else(|| {
                    problem(
                        ".id",
                        id.origin(),
                        shape("a block id (a whole number, 0 or more)", &s),
                    )
                })
            }
        };
        b.problem = unknown_key(&e, BLOCK_KEYS, "a block");
        b.op = match self.text(&e, "op")? {
            None => Err(missing(v.origin(), "op", "a block")),
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
        if let Some(c) = get(&e, "en") {
            if b.cond.is_some() {
                b.problem = Some(problem(
                    ".en",
                    c.origin(),
                    Invalid::Misplaced {
                        what: "`en`",
                        place: "together with `cond` (a block has one control input)",
                    },
                ));
            }
            b.cond = Some(self.input(c)?);
            b.en = true;
        }
        if let Some(a) = get(&e, "after") {
            b.after = Some(self.ids(a, "after")?);
        }
        b.comment = self.text(&e, "comment")?;
        Ok(b)
    }

    fn inputs(&self, v: Raw) -> Result<Read<Inputs<'a>>> {
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
                v.origin(),
                shape(
                    "an array of inputs or an object {PIN: input}",
                    &found(other),
                ),
            )),
        })
    }

    /// An INPUT: an arc `{"from": ID, "pin": PIN}`, a variable, or a constant.
    fn input(&self, v: Raw) -> Result<Input<'a>> {
        let origin = v.origin();
        let from = match self.container(v)? {
            Container::Object(e) => self.arc(&e, origin)?,
            Container::Other(Scalar::Str(s)) if is_time_literal(&s) => {
                Connection::Constant(Scalar::Str(s))
            }
            // A STRING literal (`"'text'"`) is a constant, typed where it is used.
            Container::Other(Scalar::Str(s)) if s.starts_with('\'') => {
                Connection::Constant(Scalar::Str(s))
            }
            Container::Other(Scalar::Str(s)) => Connection::Variable(s),
            Container::Other(s @ (Scalar::Number(_) | Scalar::Bool(_))) => Connection::Constant(s),
            other => Connection::Invalid(problem(
                "",
                origin,
                shape("an operand or an arc {\"from\": BLOCK}", &found(other)),
            )),
        };
        Ok(Input { origin, from })
    }

    fn arc(&self, e: &Entries<'a>, origin: Origin) -> Result<Connection<'a>> {
        if let Some(p) = unknown_key(e, ARC_KEYS, "an arc") {
            return Ok(Connection::Invalid(p));
        }
        let Some(from) = get(e, "from") else {
            return Ok(Connection::Invalid(missing(origin, "from", "an arc")));
        };
        let s = self.scalar(from)?;
        let Some(block) = block_id(&s) else {
            return Ok(Connection::Invalid(problem(
                ".from",
                from.origin(),
                shape("a block id", &s),
            )));
        };
        Ok(Connection::Arc {
            block,
            pin: self.text(e, "pin")?,
        })
    }

    fn out_var(&self, v: Raw) -> Result<std::result::Result<OutVar<'a>, Scalar<'a>>> {
        Ok(match self.scalar(v)? {
            Scalar::Str(name) => Ok(OutVar {
                origin: v.origin(),
                name,
            }),
            other => Err(other),
        })
    }

    fn outputs(&self, v: Raw) -> Result<Read<Outputs<'a>>> {
        Ok(match self.container(v)? {
            Container::Other(Scalar::Str(name)) => Ok(Outputs::First(OutVar {
                origin: v.origin(),
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
                            item.origin(),
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
                v.origin(),
                shape(
                    "a variable name, an array or an object {PIN: variable}",
                    &found(other),
                ),
            )),
        })
    }

    /// The variables of output pin `pin` in `{PIN: "Var"}` / `{PIN: ["V1", "V2"]}`.
    fn targets(&self, v: Raw, pin: &str) -> Result<Read<Targets<'a>>> {
        Ok(match self.container(v)? {
            Container::Other(Scalar::Str(name)) => Ok(Targets::One(OutVar {
                origin: v.origin(),
                name,
            })),
            Container::Array(items) => {
                let mut vars = Vec::with_capacity(items.len());
                for (m, item) in items.into_iter().enumerate() {
                    vars.push(self.out_var(item)?.map_err(|other| {
                        problem(
                            format!(".out.{pin}[{m}]"),
                            item.origin(),
                            shape("a variable name", &other),
                        )
                    }));
                }
                Ok(Targets::Many(vars))
            }
            other => Err(problem(
                format!(".out.{pin}"),
                v.origin(),
                shape("a variable name or an array of them", &found(other)),
            )),
        })
    }

    /// An array of block ids (the value of `key`).
    fn ids(&self, v: Raw, key: &str) -> Result<Read<Vec<Read<u32>>>> {
        Ok(match self.container(v)? {
            Container::Array(items) => {
                let mut ids = Vec::with_capacity(items.len());
                for (i, item) in items.into_iter().enumerate() {
                    let s = self.scalar(item)?;
                    ids.push(block_id(&s).ok_or_else(|| {
                        problem(
                            format!(".{key}[{i}]"),
                            item.origin(),
                            shape("a block id", &s),
                        )
                    }));
                }
                Ok(ids)
            }
            other => Err(problem(
                format!(".{key}"),
                v.origin(),
                shape("an array of block ids", &found(other)),
            )),
        })
    }
}
