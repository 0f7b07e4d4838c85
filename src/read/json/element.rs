//! Classifying one element object: which kind (by the key it has, in the format's order —
//! `ctu`/`ctd` before `reset`, since a counter has a `reset` operand), which keys it may have, and
//! the shape of each field. Names and operands are left to the resolver.

use super::ladder::{arith_op, cmp_op, edge, timer_kind, ForSlots, Slot};
use crate::diag::Invalid;
use crate::syntax::{self, Element, Problem, Scalar, Text};

type Slots<'de> = Vec<(Text<'de>, Slot<'de>)>;

/// Element kind keys, in the order they are recognised, with the keys each kind allows.
const ELEMENT_KINDS: &[(&str, &[&str])] = &[
    ("ctu", &["ctu", "pv", "reset"]),
    ("ctd", &["ctd", "pv", "load"]),
    ("contact", &["contact", "negated", "edge"]),
    ("compare", &["compare", "a", "b"]),
    ("or", &["or"]),
    ("coil", &["coil", "negated"]),
    ("set", &["set"]),
    ("reset", &["reset"]),
    ("branch", &["branch"]),
    ("ton", &["ton", "pt"]),
    ("tof", &["tof", "pt"]),
    ("tp", &["tp", "pt"]),
    ("move", &["move", "to"]),
    ("op", &["op", "in", "out"]),
    ("jmp", &["jmp"]),
    ("ret", &["ret"]),
    ("end", &["end"]),
    ("call", &["call"]),
    ("for", &["for"]),
    ("next", &["next"]),
];

fn element_what(key: &str) -> &'static str {
    match key {
        "contact" => "a contact",
        "compare" => "a compare contact",
        "or" => "an or",
        "coil" => "a coil",
        "set" => "a set coil",
        "reset" => "a reset coil",
        "branch" => "a branch",
        "ton" => "a TON box",
        "tof" => "a TOF box",
        "tp" => "a TP box",
        "ctu" => "a CTU box",
        "ctd" => "a CTD box",
        "move" => "a move box",
        "op" => "an arithmetic box",
        "jmp" => "a jump",
        "ret" => "a return",
        "end" => "an end",
        "call" => "a call",
        "for" => "a FOR",
        _ => "a NEXT",
    }
}

type R<T> = Result<T, Box<Problem>>;

fn shape(at: impl Into<String>, expected: &'static str, found: &Scalar) -> Box<Problem> {
    Problem::new(
        at,
        Invalid::Shape {
            expected,
            found: found.kind(),
        },
    )
}

/// The fields of one element object, taken out by key.
struct Fields<'de> {
    slots: Slots<'de>,
    what: &'static str,
}

impl<'de> Fields<'de> {
    fn take(&mut self, key: &'static str) -> Option<Slot<'de>> {
        let i = self.slots.iter().position(|(k, _)| k == key)?;
        Some(self.slots.swap_remove(i).1)
    }
    fn required(&mut self, key: &'static str) -> R<Slot<'de>> {
        self.take(key).ok_or_else(|| {
            Problem::new(
                "",
                Invalid::MissingField {
                    field: key,
                    what: self.what,
                },
            )
        })
    }
    /// A required leaf (operand).
    fn operand(&mut self, key: &'static str) -> R<Scalar<'de>> {
        match self.required(key)? {
            Slot::Scalar(s) => Ok(s),
            _ => Ok(Scalar::Array),
        }
    }
    /// A required string.
    fn string(&mut self, key: &'static str) -> R<Text<'de>> {
        match self.operand(key)? {
            Scalar::Str(s) => Ok(s),
            other => Err(shape(format!(".{key}"), "a string", &other)),
        }
    }
    /// An optional `true`/`false`.
    fn boolean(&mut self, key: &'static str) -> R<bool> {
        match self.take(key) {
            None => Ok(false),
            Some(Slot::Scalar(Scalar::Bool(b))) => Ok(b),
            Some(Slot::Scalar(other)) => Err(shape(format!(".{key}"), "true or false", &other)),
            Some(_) => Err(shape(format!(".{key}"), "true or false", &Scalar::Array)),
        }
    }
    /// A marker such as `"ret": true`.
    fn flag(&mut self, key: &'static str) -> R<()> {
        match self.operand(key)? {
            Scalar::Bool(true) => Ok(()),
            other => Err(shape(format!(".{key}"), "true", &other)),
        }
    }
    fn branches(&mut self, key: &'static str) -> R<Vec<crate::syntax::Series<'de>>> {
        match self.required(key)? {
            Slot::Branches(Ok(b)) if b.is_empty() => Err(Problem::new(
                format!(".{key}"),
                Invalid::Shape {
                    expected: "at least one branch",
                    found: "an empty array".into(),
                },
            )),
            Slot::Branches(Ok(b)) => Ok(b),
            Slot::Branches(Err(mut p)) => {
                p.at = format!(".{key}{}", p.at);
                Err(p)
            }
            _ => Err(shape(format!(".{key}"), "an array", &Scalar::Object)),
        }
    }
}

/// Which element an object is, with its fields checked for shape.
pub(super) fn classify(slots: Slots<'_>) -> R<Element<'_>> {
    let Some(&(key, allowed)) = ELEMENT_KINDS
        .iter()
        .find(|(k, _)| slots.iter().any(|(q, _)| q == k))
    else {
        let keys = slots
            .iter()
            .map(|(k, _)| format!("\"{k}\": …"))
            .collect::<Vec<_>>()
            .join(", ");
        return Err(Problem::new("", Invalid::UnknownElement { keys }));
    };
    let what = element_what(key);
    if let Some((k, _)) = slots.iter().find(|(k, _)| !allowed.contains(&k.as_ref())) {
        return Err(Problem::new(
            format!(".{k}"),
            Invalid::UnknownField {
                field: k.to_string(),
                what,
                allowed: allowed.join(", "),
            },
        ));
    }
    let mut f = Fields { slots, what };
    Ok(match key {
        "contact" => contact(&mut f)?,
        "compare" => {
            let op = f.string("compare")?;
            let op = cmp_op(&op).ok_or_else(|| {
                Problem::new(
                    ".compare",
                    Invalid::Shape {
                        expected: "EQ, NE, LT, LE, GT or GE",
                        found: format!("\"{op}\""),
                    },
                )
            })?;
            let a = f.operand("a")?;
            let b = f.operand("b")?;
            Element::Compare(Box::new(syntax::Compare { op, a, b }))
        }
        "or" => Element::Or(f.branches("or")?),
        "branch" => Element::Branch(f.branches("branch")?),
        "coil" => {
            let var = f.string("coil")?;
            let negated = f.boolean("negated")?;
            Element::Coil { var, negated }
        }
        "set" => Element::Set(f.string("set")?),
        "reset" => Element::Reset(f.string("reset")?),
        "ton" | "tof" | "tp" => {
            let instance = f.string(key)?;
            let pt = f.operand("pt")?;
            Element::Timer(Box::new(syntax::Timer {
                kind: timer_kind(key).unwrap_or(crate::model::TimerKind::Ton),
                instance,
                pt,
            }))
        }
        "ctu" => {
            let instance = f.string("ctu")?;
            let pv = f.operand("pv")?;
            let aux = f.operand("reset")?;
            Element::Counter(Box::new(syntax::Counter {
                down: false,
                instance,
                pv,
                aux,
            }))
        }
        "ctd" => {
            let instance = f.string("ctd")?;
            let pv = f.operand("pv")?;
            let aux = f.operand("load")?;
            Element::Counter(Box::new(syntax::Counter {
                down: true,
                instance,
                pv,
                aux,
            }))
        }
        "move" => {
            let to = f.string("to")?;
            let from = f.operand("move")?;
            Element::Move(Box::new(syntax::Move { from, to }))
        }
        "op" => arith(&mut f)?,
        "jmp" => Element::Jmp(f.string("jmp")?),
        "ret" => {
            f.flag("ret")?;
            Element::Ret
        }
        "end" => {
            f.flag("end")?;
            Element::End
        }
        "next" => {
            f.flag("next")?;
            Element::Next
        }
        "call" => Element::Call(f.string("call")?),
        _ => for_loop(&mut f)?,
    })
}

fn contact<'de>(f: &mut Fields<'de>) -> R<Element<'de>> {
    let var = f.string("contact")?;
    let negated = f.boolean("negated")?;
    let edge = match f.take("edge") {
        None => None,
        Some(_) if negated => {
            return Err(Problem::new(
                ".edge",
                Invalid::Misplaced {
                    what: "`edge`",
                    place: "together with `negated`",
                },
            ))
        }
        Some(Slot::Scalar(Scalar::Str(s))) => Some(edge(&s).ok_or_else(|| {
            Problem::new(
                ".edge",
                Invalid::Shape {
                    expected: "\"rising\" or \"falling\"",
                    found: format!("\"{s}\""),
                },
            )
        })?),
        Some(Slot::Scalar(other)) => return Err(shape(".edge", "a string", &other)),
        Some(_) => return Err(shape(".edge", "a string", &Scalar::Array)),
    };
    Ok(Element::Contact { var, negated, edge })
}

fn arith<'de>(f: &mut Fields<'de>) -> R<Element<'de>> {
    let name = f.string("op")?;
    let op = arith_op(&name).ok_or_else(|| {
        Problem::new(
            ".op",
            Invalid::Shape {
                expected: "ADD, SUB, MUL, DIV or MOD",
                found: format!("\"{name}\""),
            },
        )
    })?;
    let out = f.string("out")?;
    let inputs = match f.required("in")? {
        Slot::List(Ok(list)) => list,
        Slot::List(Err(found)) => return Err(shape(".in", "an array", &found)),
        _ => return Err(shape(".in", "an array", &Scalar::Object)),
    };
    let [a, b]: [Scalar; 2] = inputs.try_into().map_err(|v: Vec<Scalar>| {
        Problem::new(
            ".in",
            Invalid::Shape {
                expected: "two operands",
                found: format!("{} operands", v.len()),
            },
        )
    })?;
    Ok(Element::Arith(Box::new(syntax::Arith { op, a, b, out })))
}

fn for_loop<'de>(f: &mut Fields<'de>) -> R<Element<'de>> {
    let slots: ForSlots<'de> = match f.required("for")? {
        Slot::For(Ok(slots)) => slots,
        Slot::For(Err(found)) => return Err(shape(".for", "an object", &found)),
        _ => return Err(shape(".for", "an object", &Scalar::Array)),
    };
    if let Some((k, _)) = slots
        .iter()
        .find(|(k, _)| !["var", "from", "to"].contains(&k.as_ref()))
    {
        return Err(Problem::new(
            format!(".for.{k}"),
            Invalid::UnknownField {
                field: k.to_string(),
                what: "a FOR",
                allowed: "var, from, to".into(),
            },
        ));
    }
    let mut slots = slots;
    let mut get = |key: &'static str| -> R<Scalar<'de>> {
        let i = slots.iter().position(|(k, _)| k == key).ok_or_else(|| {
            Problem::new(
                ".for",
                Invalid::MissingField {
                    field: key,
                    what: "a FOR",
                },
            )
        })?;
        Ok(slots.swap_remove(i).1)
    };
    let var = match get("var")? {
        Scalar::Str(s) => s,
        other => return Err(shape(".for.var", "a string", &other)),
    };
    let from = get("from")?;
    let to = get("to")?;
    Ok(Element::For(Box::new(syntax::For { var, from, to })))
}
