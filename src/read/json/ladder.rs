//! Rungs and ladder elements of the JSON program format (docs/format.md) → [`syntax::Rung`],
//! streamed: an element's kind is decided by which key it has (`{"contact": "A", "negated":
//! true}`), so each element object is read into a handful of (key, value) slots and then
//! classified with the same rules, in the same order, as the format describes.
//!
//! Nothing here resolves a name or types an operand; what is malformed becomes a [`Problem`] in
//! the tree (relative to the element) and reading continues with the next element.

use super::scalar::{AnyScalar, Key};
use crate::diag::Invalid;
use crate::model::{ArithOp, CmpOp, TimerKind};
use crate::syntax::{Edge, Element, Origin, Problem, Rung, Scalar, Series, Text};
use serde::de::{Deserialize, Deserializer, MapAccess, SeqAccess, Visitor};
use std::borrow::Cow;
use std::fmt;

/// A rung object (its origin is set by the caller, who knows where its text starts).
pub(super) struct RungDe<'de>(pub Rung<'de>);

fn empty_rung<'de>() -> Rung<'de> {
    Rung {
        origin: Origin::NONE,
        id: Cow::Borrowed(""),
        label: None,
        comment: None,
        ld: Vec::new(),
        problem: None,
        problem_in_rung: false,
    }
}

impl<'de> Deserialize<'de> for RungDe<'de> {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        struct V;
        impl<'de> Visitor<'de> for V {
            type Value = RungDe<'de>;
            fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
                f.write_str("a rung")
            }
            fn visit_map<A: MapAccess<'de>>(self, mut map: A) -> Result<Self::Value, A::Error> {
                rung_map(&mut map).map(RungDe)
            }
            fn visit_seq<A: SeqAccess<'de>>(self, seq: A) -> Result<Self::Value, A::Error> {
                let found = super::scalar_of_seq(seq)?;
                Ok(RungDe(not_an_object(found, "an object (a rung)")))
            }
            fn visit_bool<E: serde::de::Error>(self, v: bool) -> Result<Self::Value, E> {
                Ok(RungDe(not_an_object(Scalar::Bool(v), "an object (a rung)")))
            }
            fn visit_i64<E: serde::de::Error>(self, v: i64) -> Result<Self::Value, E> {
                Ok(RungDe(not_an_object(
                    Scalar::Number(v.into()),
                    "an object (a rung)",
                )))
            }
            fn visit_u64<E: serde::de::Error>(self, v: u64) -> Result<Self::Value, E> {
                Ok(RungDe(not_an_object(
                    Scalar::Number(v.into()),
                    "an object (a rung)",
                )))
            }
            fn visit_f64<E: serde::de::Error>(self, v: f64) -> Result<Self::Value, E> {
                let s = serde_json::Number::from_f64(v).map_or(Scalar::Null, Scalar::Number);
                Ok(RungDe(not_an_object(s, "an object (a rung)")))
            }
            fn visit_str<E: serde::de::Error>(self, v: &str) -> Result<Self::Value, E> {
                Ok(RungDe(not_an_object(
                    Scalar::Str(Cow::Owned(v.to_owned())),
                    "an object (a rung)",
                )))
            }
            fn visit_unit<E: serde::de::Error>(self) -> Result<Self::Value, E> {
                Ok(RungDe(not_an_object(Scalar::Null, "an object (a rung)")))
            }
        }
        d.deserialize_any(V)
    }
}

fn not_an_object<'de>(found: Scalar<'de>, expected: &'static str) -> Rung<'de> {
    let mut r = empty_rung();
    r.problem = Some(Problem::new(
        "",
        Invalid::Shape {
            expected,
            found: found.kind(),
        },
    ));
    r
}

fn shape(at: impl Into<String>, expected: &'static str, found: &Scalar) -> Box<Problem> {
    Problem::new(
        at,
        Invalid::Shape {
            expected,
            found: found.kind(),
        },
    )
}

fn rung_map<'de, A: MapAccess<'de>>(map: &mut A) -> Result<Rung<'de>, A::Error> {
    let mut r = empty_rung();
    let (mut id, mut label, mut comment, mut ld) = (None, None, None, None);
    let mut unknown: Option<Text<'de>> = None;
    while let Some(Key(k)) = map.next_key::<Key<'de>>()? {
        match k.as_ref() {
            "id" => id = Some(map.next_value::<AnyScalar>()?.0),
            "label" => label = Some(map.next_value::<AnyScalar>()?.0),
            "comment" => comment = Some(map.next_value::<AnyScalar>()?.0),
            "ld" => ld = Some(map.next_value::<SeriesDe>()?.0),
            _ => {
                map.next_value::<serde::de::IgnoredAny>()?;
                unknown.get_or_insert(k);
            }
        }
    }
    let mut fail = |p: Box<Problem>, in_rung: bool| {
        if r.problem.is_none() {
            r.problem = Some(p);
            r.problem_in_rung = in_rung;
        }
    };
    if let Some(k) = unknown {
        fail(
            Problem::new(
                format!(".{k}"),
                Invalid::UnknownField {
                    field: k.into_owned(),
                    what: "a rung",
                    allowed: "id, label, comment, ld".into(),
                },
            ),
            false,
        );
    }
    match id {
        None => fail(
            Problem::new(
                "",
                Invalid::MissingField {
                    field: "id",
                    what: "a rung",
                },
            ),
            false,
        ),
        Some(Scalar::Str(s)) => {
            if s.is_empty() || s.chars().any(|c| c.is_whitespace() || c == '"') {
                fail(
                    Problem::new(
                        ".id",
                        Invalid::Shape {
                            expected: "a rung id without spaces or quotes",
                            found: format!("\"{s}\""),
                        },
                    ),
                    false,
                );
            }
            r.id = s;
        }
        Some(other) => fail(shape(".id", "a string", &other), false),
    }
    match label {
        None => {}
        Some(Scalar::Str(s)) => r.label = Some(s),
        Some(other) => fail(shape(".label", "a string", &other), true),
    }
    match ld {
        None => fail(
            Problem::new(
                "",
                Invalid::MissingField {
                    field: "ld",
                    what: "a rung",
                },
            ),
            true,
        ),
        Some(Ok(series)) => r.ld = series,
        Some(Err(found)) => fail(shape(".ld", "an array", &found), true),
    }
    match comment {
        None => {}
        Some(Scalar::Str(s)) => r.comment = Some(s),
        Some(other) => fail(shape(".comment", "a string", &other), true),
    }
    Ok(r)
}

/// A SERIES, or what was found instead of an array.
pub(super) struct SeriesDe<'de>(pub Result<Series<'de>, Scalar<'de>>);

impl<'de> Deserialize<'de> for SeriesDe<'de> {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        struct V;
        impl<'de> Visitor<'de> for V {
            type Value = SeriesDe<'de>;
            fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
                f.write_str("a series")
            }
            fn visit_seq<A: SeqAccess<'de>>(self, mut seq: A) -> Result<Self::Value, A::Error> {
                let mut out = Vec::with_capacity(seq.size_hint().unwrap_or(4));
                while let Some(ElementDe(e)) = seq.next_element::<ElementDe>()? {
                    out.push(e);
                }
                Ok(SeriesDe(Ok(out)))
            }
            fn visit_map<A: MapAccess<'de>>(self, map: A) -> Result<Self::Value, A::Error> {
                super::scalar_of_map(map).map(|s| SeriesDe(Err(s)))
            }
            fn visit_bool<E: serde::de::Error>(self, v: bool) -> Result<Self::Value, E> {
                Ok(SeriesDe(Err(Scalar::Bool(v))))
            }
            fn visit_i64<E: serde::de::Error>(self, v: i64) -> Result<Self::Value, E> {
                Ok(SeriesDe(Err(Scalar::Number(v.into()))))
            }
            fn visit_u64<E: serde::de::Error>(self, v: u64) -> Result<Self::Value, E> {
                Ok(SeriesDe(Err(Scalar::Number(v.into()))))
            }
            fn visit_f64<E: serde::de::Error>(self, v: f64) -> Result<Self::Value, E> {
                Ok(SeriesDe(Err(
                    serde_json::Number::from_f64(v).map_or(Scalar::Null, Scalar::Number)
                )))
            }
            fn visit_str<E: serde::de::Error>(self, v: &str) -> Result<Self::Value, E> {
                Ok(SeriesDe(Err(Scalar::Str(Cow::Owned(v.to_owned())))))
            }
            fn visit_unit<E: serde::de::Error>(self) -> Result<Self::Value, E> {
                Ok(SeriesDe(Err(Scalar::Null)))
            }
        }
        d.deserialize_any(V)
    }
}

/// Branches of `or` / `branch`: an array of SERIES (checked here: an array, each an array).
struct BranchesDe<'de>(Result<Vec<Series<'de>>, Box<Problem>>);

impl<'de> Deserialize<'de> for BranchesDe<'de> {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        // Read as an array of series; a non-array anywhere becomes a problem (path relative to
        // the value of the key).
        let SeriesOfSeries(r) = SeriesOfSeries::deserialize(d)?;
        Ok(BranchesDe(r))
    }
}

struct SeriesOfSeries<'de>(Result<Vec<Series<'de>>, Box<Problem>>);

impl<'de> Deserialize<'de> for SeriesOfSeries<'de> {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        struct V;
        impl<'de> Visitor<'de> for V {
            type Value = SeriesOfSeries<'de>;
            fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
                f.write_str("branches")
            }
            fn visit_seq<A: SeqAccess<'de>>(self, mut seq: A) -> Result<Self::Value, A::Error> {
                let mut out = Vec::new();
                let mut problem = None;
                let mut i = 0usize;
                while let Some(SeriesDe(s)) = seq.next_element::<SeriesDe>()? {
                    match s {
                        Ok(s) => out.push(s),
                        Err(found) => {
                            problem
                                .get_or_insert_with(|| shape(format!("[{i}]"), "an array", &found));
                        }
                    }
                    i += 1;
                }
                Ok(SeriesOfSeries(match problem {
                    Some(p) => Err(p),
                    None => Ok(out),
                }))
            }
            fn visit_map<A: MapAccess<'de>>(self, map: A) -> Result<Self::Value, A::Error> {
                let s = super::scalar_of_map(map)?;
                Ok(SeriesOfSeries(Err(shape("", "an array", &s))))
            }
            fn visit_bool<E: serde::de::Error>(self, v: bool) -> Result<Self::Value, E> {
                Ok(SeriesOfSeries(Err(shape("", "an array", &Scalar::Bool(v)))))
            }
            fn visit_i64<E: serde::de::Error>(self, v: i64) -> Result<Self::Value, E> {
                Ok(SeriesOfSeries(Err(shape(
                    "",
                    "an array",
                    &Scalar::Number(v.into()),
                ))))
            }
            fn visit_u64<E: serde::de::Error>(self, v: u64) -> Result<Self::Value, E> {
                Ok(SeriesOfSeries(Err(shape(
                    "",
                    "an array",
                    &Scalar::Number(v.into()),
                ))))
            }
            fn visit_f64<E: serde::de::Error>(self, v: f64) -> Result<Self::Value, E> {
                let s = serde_json::Number::from_f64(v).map_or(Scalar::Null, Scalar::Number);
                Ok(SeriesOfSeries(Err(shape("", "an array", &s))))
            }
            fn visit_str<E: serde::de::Error>(self, v: &str) -> Result<Self::Value, E> {
                let s = Scalar::Str(Cow::Owned(v.to_owned()));
                Ok(SeriesOfSeries(Err(shape("", "an array", &s))))
            }
            fn visit_unit<E: serde::de::Error>(self) -> Result<Self::Value, E> {
                Ok(SeriesOfSeries(Err(shape("", "an array", &Scalar::Null))))
            }
        }
        d.deserialize_any(V)
    }
}

/// The value of one key of an element object.
pub(super) enum Slot<'de> {
    Scalar(Scalar<'de>),
    /// `for`: the object's keys in file order, or the leaf found instead of an object.
    For(Result<ForSlots<'de>, Scalar<'de>>),
    Branches(Result<Vec<Series<'de>>, Box<Problem>>),
    /// `in` of an arithmetic box: the operands, or what was found instead of an array.
    List(Result<Vec<Scalar<'de>>, Scalar<'de>>),
}

struct ListDe<'de>(Result<Vec<Scalar<'de>>, Scalar<'de>>);

impl<'de> Deserialize<'de> for ListDe<'de> {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        match super::scalar::Container::deserialize(d)? {
            super::scalar::Container::Array(items) => {
                let mut out = Vec::with_capacity(items.len());
                for raw in items {
                    let AnyScalar(s) =
                        super::scalar::parse_raw(raw).map_err(serde::de::Error::custom)?;
                    out.push(s);
                }
                Ok(ListDe(Ok(out)))
            }
            super::scalar::Container::Object(_) => Ok(ListDe(Err(Scalar::Object))),
            super::scalar::Container::Other(s) => Ok(ListDe(Err(s))),
        }
    }
}

/// One element.
pub(super) struct ElementDe<'de>(pub Element<'de>);

impl<'de> Deserialize<'de> for ElementDe<'de> {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        struct V;
        impl<'de> Visitor<'de> for V {
            type Value = ElementDe<'de>;
            fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
                f.write_str("an element")
            }
            fn visit_map<A: MapAccess<'de>>(self, mut map: A) -> Result<Self::Value, A::Error> {
                let mut slots: Vec<(Text<'de>, Slot<'de>)> = Vec::with_capacity(3);
                while let Some(Key(k)) = map.next_key::<Key<'de>>()? {
                    let v = match k.as_ref() {
                        "or" | "branch" => Slot::Branches(map.next_value::<BranchesDe>()?.0),
                        "in" => Slot::List(map.next_value::<ListDe>()?.0),
                        "for" => Slot::For(map.next_value::<ForDe>()?.0),
                        _ => Slot::Scalar(map.next_value::<AnyScalar>()?.0),
                    };
                    match slots.iter_mut().find(|(q, _)| *q == k) {
                        Some(s) => s.1 = v,
                        None => slots.push((k, v)),
                    }
                }
                Ok(ElementDe(
                    super::element::classify(slots).unwrap_or_else(Element::Invalid),
                ))
            }
            fn visit_seq<A: SeqAccess<'de>>(self, seq: A) -> Result<Self::Value, A::Error> {
                let s = super::scalar_of_seq(seq)?;
                Ok(ElementDe(Element::Invalid(shape(
                    "",
                    "an object (an element)",
                    &s,
                ))))
            }
            fn visit_bool<E: serde::de::Error>(self, v: bool) -> Result<Self::Value, E> {
                Ok(not_element(Scalar::Bool(v)))
            }
            fn visit_i64<E: serde::de::Error>(self, v: i64) -> Result<Self::Value, E> {
                Ok(not_element(Scalar::Number(v.into())))
            }
            fn visit_u64<E: serde::de::Error>(self, v: u64) -> Result<Self::Value, E> {
                Ok(not_element(Scalar::Number(v.into())))
            }
            fn visit_f64<E: serde::de::Error>(self, v: f64) -> Result<Self::Value, E> {
                Ok(not_element(
                    serde_json::Number::from_f64(v).map_or(Scalar::Null, Scalar::Number),
                ))
            }
            fn visit_str<E: serde::de::Error>(self, v: &str) -> Result<Self::Value, E> {
                Ok(not_element(Scalar::Str(Cow::Owned(v.to_owned()))))
            }
            fn visit_unit<E: serde::de::Error>(self) -> Result<Self::Value, E> {
                Ok(not_element(Scalar::Null))
            }
        }
        d.deserialize_any(V)
    }
}

fn not_element<'de>(s: Scalar<'de>) -> ElementDe<'de> {
    ElementDe(Element::Invalid(shape("", "an object (an element)", &s)))
}

/// The object of a FOR (`{"var", "from", "to"}`) as its leaves, or the leaf found instead.
struct ForDe<'de>(Result<ForSlots<'de>, Scalar<'de>>);

/// The keys of a `for` object, in file order.
pub(super) type ForSlots<'de> = Vec<(Text<'de>, Scalar<'de>)>;

impl<'de> Deserialize<'de> for ForDe<'de> {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        match super::scalar::Container::deserialize(d)? {
            super::scalar::Container::Other(s) => Ok(ForDe(Err(s))),
            super::scalar::Container::Array(_) => Ok(ForDe(Err(Scalar::Array))),
            super::scalar::Container::Object(entries) => {
                let mut slots = Vec::with_capacity(entries.len());
                for (k, raw) in entries {
                    let AnyScalar(s) =
                        super::scalar::parse_raw(raw).map_err(serde::de::Error::custom)?;
                    slots.push((k, s));
                }
                Ok(ForDe(Ok(slots)))
            }
        }
    }
}

/// Kinds of elements by name (for the classifier).
pub(super) fn timer_kind(key: &str) -> Option<TimerKind> {
    match key {
        "ton" => Some(TimerKind::Ton),
        "tof" => Some(TimerKind::Tof),
        "tp" => Some(TimerKind::Tp),
        _ => None,
    }
}

pub(super) fn edge(s: &str) -> Option<Edge> {
    match s {
        "rising" => Some(Edge::Rising),
        "falling" => Some(Edge::Falling),
        _ => None,
    }
}

pub(super) fn cmp_op(s: &str) -> Option<CmpOp> {
    CmpOp::parse(s)
}

pub(super) fn arith_op(s: &str) -> Option<ArithOp> {
    ArithOp::parse(s)
}
