//! Rungs and ladder elements of the JSON program format (docs/format.md) → [`syntax::Rung`]: an
//! element's kind is decided by which key it has (`{"contact": "A", "negated": true}`), so each
//! element object is read into a handful of (key, value) slots on the reader's scratch stack and
//! then classified ([`super::element`]) with the same rules, in the same order, as the format
//! describes. A series is collected on the scratch stack of elements and stored in a `Vec` of
//! its exact size.
//!
//! Nothing here resolves a name or types an operand; what is malformed becomes a [`Problem`] in
//! the tree (relative to the element, with the origin of the most precise node) and reading
//! continues with the next element.

use super::cursor::P;
use super::element::{classify, ForSlots, Slot, SlotEntry};
use super::{shape, Reader};
use plc_diag::Invalid;
use plc_syntax::{
    Element, ElementKind, Located, Name, Operand, Origin, Problem, Rung, Scalar, Series, Text,
};

fn problem(
    at: impl Into<String>,
    origin: Origin,
    expected: &'static str,
    found: &Scalar,
) -> Box<Problem> {
    Problem::new(at, origin, shape(expected, found))
}

impl<'a> Reader<'a, '_> {
    /// The value of `rungs` at `path`: an array of rungs, or `None` (with a problem).
    /// `streamed`: each rung goes to the sink as it is read, and the array is left empty.
    pub(super) fn rungs(&mut self, path: &str, streamed: bool) -> P<Option<Vec<Rung<'a>>>> {
        let origin = self.c.origin();
        if self.c.peek() != Some(b'[') {
            let found = self.c.scalar()?;
            self.problem(path, origin, shape("an array", &found));
            return Ok(None);
        }
        // Room for as many rungs as the rest of the text holds at 128 bytes a rung (a generated
        // rung takes about 220): pages of the room a program does not use are never touched, and
        // a million rungs are not moved twenty times as the vector doubles.
        let mut rungs = Vec::with_capacity(if streamed {
            0
        } else {
            self.c.remaining() / 128
        });
        self.c.begin_array()?;
        let mut first = true;
        while self.c.item(&mut first)? {
            let rung = self.rung()?;
            match self.sink.as_deref_mut() {
                Some(sink) if streamed => sink.rung(rung),
                _ => rungs.push(rung),
            }
        }
        Ok(Some(rungs))
    }

    fn rung(&mut self) -> P<Rung<'a>> {
        let origin = self.c.origin();
        let mut r = Rung {
            origin,
            id: Name::empty(),
            label: None,
            comment: None,
            ld: Vec::new(),
            ld_origin: Origin::NONE,
            problem: None,
            problem_in_rung: false,
        };
        if self.c.peek() != Some(b'{') {
            let found = self.c.scalar()?;
            r.problem = Some(problem("", origin, "an object (a rung)", &found));
            return Ok(r);
        }
        let (mut id, mut label, mut comment, mut ld) = (None, None, None, None);
        let mut unknown: Option<(Text<'a>, Origin)> = None;
        self.c.begin_object()?;
        let mut first = true;
        while let Some((k, key_origin)) = self.c.key(&mut first)? {
            let at = self.c.origin();
            match k.as_ref() {
                "id" => id = Some((self.c.scalar()?, at)),
                "label" => label = Some((self.c.scalar()?, at)),
                "comment" => comment = Some((self.c.scalar()?, at)),
                "ld" => ld = Some((self.series()?, at)),
                _ => {
                    self.c.skip()?;
                    unknown.get_or_insert((k, key_origin));
                }
            }
        }
        let mut fail = |p: Box<Problem>, in_rung: bool| {
            if r.problem.is_none() {
                r.problem = Some(p);
                r.problem_in_rung = in_rung;
            }
        };
        if let Some((k, o)) = unknown {
            let p = super::unknown_field(
                format!(".{k}"),
                o,
                &k,
                "a rung",
                &["id", "label", "comment", "ld"],
            );
            fail(Box::new(p), false);
        }
        let missing = |field| {
            let kind = Invalid::MissingField {
                field,
                what: "a rung",
            };
            Problem::new("", origin, kind)
        };
        match id {
            None => fail(missing("id"), false),
            Some((Scalar::Str(s), o)) => {
                if s.is_empty() || s.chars().any(|c| c.is_whitespace() || c == '"') {
                    let kind = Invalid::Shape {
                        expected: "a rung id without spaces or quotes",
                        found: format!("\"{s}\""),
                    };
                    fail(Problem::new(".id", o, kind), false);
                }
                r.id = Located {
                    value: s,
                    origin: o,
                };
            }
            Some((other, o)) => fail(problem(".id", o, "a string", &other), false),
        }
        match label {
            None => {}
            Some((Scalar::Str(s), o)) => {
                r.label = Some(Box::new(Located {
                    value: s,
                    origin: o,
                }))
            }
            Some((other, o)) => fail(problem(".label", o, "a string", &other), true),
        }
        match ld {
            None => fail(missing("ld"), true),
            Some((Ok(series), o)) => {
                r.ld = series;
                r.ld_origin = o;
            }
            Some((Err(found), o)) => fail(problem(".ld", o, "an array", &found), true),
        }
        match comment {
            None => {}
            Some((Scalar::Str(s), _)) => r.comment = Some(s),
            Some((other, o)) => fail(problem(".comment", o, "a string", &other), true),
        }
        Ok(r)
    }

    /// A SERIES, or what was found instead of an array.
    pub(super) fn series(&mut self) -> P<Result<Series<'a>, Scalar<'a>>> {
        if self.c.peek() != Some(b'[') {
            return self.c.scalar().map(Err);
        }
        let mark = self.elements.len();
        self.c.begin_array()?;
        let mut first = true;
        while self.c.item(&mut first)? {
            let e = self.element()?;
            self.elements.push(e);
        }
        Ok(Ok(self.elements.drain(mark..).collect()))
    }

    /// Branches of `or` / `branch`: an array of SERIES (a problem, relative to the value, for a
    /// non-array anywhere; the first one is kept).
    pub(super) fn branches(&mut self) -> P<Result<Vec<Series<'a>>, Box<Problem>>> {
        let origin = self.c.origin();
        if self.c.peek() != Some(b'[') {
            let found = self.c.scalar()?;
            return Ok(Err(problem("", origin, "an array", &found)));
        }
        let mut out = Vec::with_capacity(2);
        let mut bad = None;
        let mut i = 0usize;
        self.c.begin_array()?;
        let mut first = true;
        while self.c.item(&mut first)? {
            let at = self.c.origin();
            match self.series()? {
                Ok(s) => out.push(s),
                Err(found) => {
                    bad.get_or_insert_with(|| problem(format!("[{i}]"), at, "an array", &found));
                }
            }
            i += 1;
        }
        Ok(match bad {
            Some(p) => Err(p),
            None => Ok(out),
        })
    }

    /// `in` of an arithmetic box: the operands, or what was found instead of an array.
    fn list(&mut self) -> P<Result<Vec<Operand<'a>>, Scalar<'a>>> {
        if self.c.peek() != Some(b'[') {
            return self.c.scalar().map(Err);
        }
        let mut out = Vec::with_capacity(2);
        self.c.begin_array()?;
        let mut first = true;
        while self.c.item(&mut first)? {
            let origin = self.c.origin();
            let value = self.c.scalar()?;
            out.push(Located { value, origin });
        }
        Ok(Ok(out))
    }

    /// The object of a FOR (`{"var", "from", "to"}`) as its leaves, or the leaf found instead.
    fn for_object(&mut self) -> P<Result<ForSlots<'a>, Scalar<'a>>> {
        if self.c.peek() != Some(b'{') {
            return self.c.scalar().map(Err);
        }
        let mut slots: ForSlots<'a> = Vec::with_capacity(3);
        self.c.begin_object()?;
        let mut first = true;
        while let Some((k, key_origin)) = self.c.key(&mut first)? {
            let origin = self.c.origin();
            let value = Located {
                value: self.c.scalar()?,
                origin,
            };
            match slots.iter_mut().find(|(q, _, _)| *q == k) {
                Some(s) => s.2 = value,
                None => slots.push((k, key_origin, value)),
            }
        }
        Ok(Ok(slots))
    }

    /// One element (its slots on the scratch stack while it is read).
    fn element(&mut self) -> P<Element<'a>> {
        let origin = self.c.origin();
        if self.c.peek() != Some(b'{') {
            let found = self.c.scalar()?;
            let kind = ElementKind::Invalid(problem("", origin, "an object (an element)", &found));
            return Ok(Element { origin, kind });
        }
        let mark = self.slots.len();
        self.c.begin_object()?;
        let mut first = true;
        while let Some((key, key_origin)) = self.c.key(&mut first)? {
            let at = self.c.origin();
            let slot = match key.as_ref() {
                "or" | "branch" => Slot::Branches(self.branches()?),
                "in" => Slot::List(self.list()?),
                "for" => Slot::For(self.for_object()?),
                _ => Slot::Scalar(Located {
                    value: self.c.scalar()?,
                    origin: at,
                }),
            };
            match self.slots[mark..].iter_mut().find(|s| s.key == key) {
                Some(s) => {
                    s.slot = slot;
                    s.origin = at;
                }
                None => self.slots.push(SlotEntry {
                    key,
                    key_origin,
                    origin: at,
                    slot,
                }),
            }
        }
        let kind = classify(&mut self.slots, mark, origin).unwrap_or_else(ElementKind::Invalid);
        self.slots.truncate(mark);
        Ok(Element { origin, kind })
    }
}
