//! The JSON report: the [`Report`] document serialised through serde straight into the writer
//! (no whole-output string, no `serde_json::Value`). The document's `#[derive(Serialize)]`
//! structs are the one definition of the keys (docs/report.md, docs/report.schema.json); keys of
//! the report's first version (`program`, `rungs[].id/in/out`, `dependences[].kind/from/to/var`,
//! `cfg.edges[].from/to/label`, `ipdom`, `levels.data/control/combined`, `cycles.*`,
//! `cost.work/span/makespan`) are a contract: add fields, never rename or drop these.
//!
//! Layout: the report's top-level object and the objects inside it one key per line, indented by
//! two spaces; a list one element per line, each element (a rung, a dependence, an edge, a
//! level, a task) written whole on its line (`{"id": "R1", "pou": "p", "in": ["x1"], ...}`);
//! lists of plain values on one line (`"unreachable": ["R2", "R7"]`). That is about a third of the
//! bytes of fully pretty-printed JSON for the same document (a million-rung report is written in
//! seconds), one entry per line for `grep` and diffs; any JSON parser reads both alike.
//!
//! The serialiser here is the whole writer: a value knows from where it sits (its [`Place`])
//! whether it is laid out over lines or on one, so no stack of open containers is kept. Strings
//! are escaped as `serde_json` escapes them (one that needs escaping is handed to it), numbers
//! are written by `serde_json`'s formatter. Writing a million-rung report takes about 2 s, within
//! a tenth of the hand-written writer this replaced (serde_json with a custom `Formatter` took
//! half as long again: escaping byte by byte and the formatter's per-token state). Not supported
//! (the document has none): enum variants with data, bytes, map keys other than strings.

use super::document::Report;
use serde::ser::{self, Impossible, Serialize};
use serde_json::ser::{CompactFormatter, Formatter};
use std::fmt;
use std::io::{self, Write};

/// Writes the report as JSON with a trailing newline.
pub fn render_json(report: &Report, out: &mut impl Write) -> io::Result<()> {
    report
        .serialize(Value {
            out: &mut *out,
            place: Place::Lines(0),
            before: Before::Nothing,
        })
        .map_err(|Error(e)| e)?;
    out.write_all(b"\n")
}

/// Where a value sits, which decides its layout.
#[derive(Copy, Clone)]
enum Place {
    /// Inside `depth` containers laid out over lines (0: the top level): an object's keys each
    /// on a line, a list's elements each on a line when they are containers.
    Lines(usize),
    /// In a list's element: everything on one line.
    OneLine,
}

/// What is written before a value: nothing (a key's value, the top level), or a list element's
/// separator.
enum Before<'a> {
    Nothing,
    /// An element of a list on one line.
    Inline {
        first: bool,
    },
    /// An element of a list laid out over lines at `depth`: a container starts a line, and so
    /// does every element after one (`multiline`, the list's); plain values before that share
    /// the list's line.
    Lines {
        first: bool,
        depth: usize,
        multiline: &'a mut bool,
    },
}

/// The serialiser of one value.
struct Value<'a, W: ?Sized> {
    out: &'a mut W,
    place: Place,
    before: Before<'a>,
}

/// A write error (or a value the layout cannot write).
#[derive(Debug)]
struct Error(io::Error);

impl fmt::Display for Error {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        self.0.fmt(f)
    }
}

impl std::error::Error for Error {}

impl ser::Error for Error {
    fn custom<T: fmt::Display>(msg: T) -> Self {
        Error(io::Error::other(msg.to_string()))
    }
}

impl From<io::Error> for Error {
    fn from(e: io::Error) -> Self {
        Error(e)
    }
}

const SPACES: &[u8; 128] = &[b' '; 128];

/// What comes before a value or a key: nothing, `, `, or a line break (`\n` before the first
/// element or key, `,\n` before the others) and the indentation of `depth` levels. (Each is
/// written with constant-length writes: a `BufWriter` takes those as a store, where a write of
/// a length known only at run time is a call to `memcpy`.)
#[derive(Copy, Clone)]
enum Separator {
    Nothing,
    Comma,
    Line { first: bool, depth: usize },
}

impl Separator {
    // The common separators inline, the line break out of line: a serialiser's methods are
    // called once for every value of the report.
    #[inline(always)]
    fn write<W: ?Sized + Write>(self, w: &mut W) -> io::Result<()> {
        match self {
            Separator::Nothing => Ok(()),
            Separator::Comma => w.write_all(b", "),
            Separator::Line { first, depth } => Self::line(w, first, depth),
        }
    }

    #[inline(never)]
    fn line<W: ?Sized + Write>(w: &mut W, first: bool, depth: usize) -> io::Result<()> {
        if first {
            w.write_all(b"\n")?;
        } else {
            w.write_all(b",\n")?;
        }
        let mut n = 2 * depth;
        while n > 0 {
            let k = n.min(SPACES.len());
            w.write_all(&SPACES[..k])?;
            n -= k;
        }
        Ok(())
    }
}

/// True if `s` is written between quotes as it is (`serde_json` escapes nothing in it: no
/// control character, quote or backslash). Eight bytes at a time: a word has a byte below
/// 0x20 iff `(x - 0x20…20) & !x & 0x80…80` is not zero, and a byte equal to `c` iff `x ^ c…c`
/// has a zero byte (both exact as booleans; Anderson's bit twiddling hacks, "hasless" and
/// "haszero"); the tail byte by byte.
#[inline(always)]
fn plain(s: &str) -> bool {
    const ONES: u64 = 0x0101_0101_0101_0101;
    const HIGH: u64 = 0x8080_8080_8080_8080;
    let zero_byte = |x: u64| x.wrapping_sub(ONES) & !x & HIGH != 0;
    let mut words = s.as_bytes().chunks_exact(8);
    for w in &mut words {
        let x = u64::from_le_bytes(w.try_into().expect("eight bytes"));
        if x.wrapping_sub(0x20 * ONES) & !x & HIGH != 0
            || zero_byte(x ^ (b'"' as u64 * ONES))
            || zero_byte(x ^ (b'\\' as u64 * ONES))
        {
            return false;
        }
    }
    (words.remainder().iter()).all(|&b| b >= 0x20 && b != b'"' && b != b'\\')
}

/// `sep`, then `s` as a JSON string escaped as `serde_json` escapes it, then `after`, which
/// starts with the closing quote (`"`, or `": ` after a key).
#[inline(always)]
fn string<W: ?Sized + Write, const N: usize>(
    out: &mut W,
    sep: Separator,
    s: &str,
    after: &[u8; N],
) -> Result<(), Error> {
    if plain(s) {
        sep.write(out)?;
        out.write_all(b"\"")?;
        out.write_all(s.as_bytes())?;
        out.write_all(after)?;
    } else {
        sep.write(out)?;
        serde_json::to_writer(&mut *out, s).map_err(|e| Error(e.into()))?;
        out.write_all(&after[1..])?;
    }
    Ok(())
}

impl<'a, W: ?Sized + Write> Value<'a, W> {
    /// The separator before the value; `container`: the value is an object or a list.
    #[inline(always)]
    fn separator(&mut self, container: bool) -> Separator {
        match &mut self.before {
            Before::Nothing | Before::Inline { first: true } => Separator::Nothing,
            Before::Inline { first: false } => Separator::Comma,
            Before::Lines {
                first,
                depth,
                multiline,
            } => {
                if container || **multiline {
                    **multiline = true;
                    Separator::Line {
                        first: *first,
                        depth: *depth,
                    }
                } else if *first {
                    Separator::Nothing
                } else {
                    Separator::Comma
                }
            }
        }
    }

    fn scalar(mut self, bytes: &[u8]) -> Result<(), Error> {
        self.separator(false).write(self.out)?;
        self.out.write_all(bytes)?;
        Ok(())
    }

    fn list(mut self) -> Result<List<'a, W>, Error> {
        self.separator(true).write(self.out)?;
        self.out.write_all(b"[")?;
        Ok(List {
            out: self.out,
            place: self.place,
            first: true,
            multiline: false,
        })
    }

    fn object(mut self) -> Result<Object<'a, W>, Error> {
        self.separator(true).write(self.out)?;
        self.out.write_all(b"{")?;
        Ok(Object {
            out: self.out,
            place: self.place,
            first: true,
        })
    }
}

macro_rules! numbers {
    ($($method:ident: $t:ty => $write:ident),* $(,)?) => {
        $(fn $method(mut self, v: $t) -> Result<(), Error> {
            self.separator(false).write(self.out)?;
            CompactFormatter.$write(self.out, v)?;
            Ok(())
        })*
    };
}

impl<'a, W: ?Sized + Write> ser::Serializer for Value<'a, W> {
    type Ok = ();
    type Error = Error;
    type SerializeSeq = List<'a, W>;
    type SerializeTuple = List<'a, W>;
    type SerializeTupleStruct = List<'a, W>;
    type SerializeTupleVariant = Impossible<(), Error>;
    type SerializeMap = Object<'a, W>;
    type SerializeStruct = Object<'a, W>;
    type SerializeStructVariant = Impossible<(), Error>;

    fn serialize_bool(self, v: bool) -> Result<(), Error> {
        self.scalar(if v { b"true" } else { b"false" })
    }
    numbers!(
        serialize_i8: i8 => write_i8, serialize_i16: i16 => write_i16,
        serialize_i32: i32 => write_i32, serialize_i64: i64 => write_i64,
        serialize_i128: i128 => write_i128, serialize_u8: u8 => write_u8,
        serialize_u16: u16 => write_u16, serialize_u32: u32 => write_u32,
        serialize_u64: u64 => write_u64, serialize_u128: u128 => write_u128,
    );
    fn serialize_f32(self, v: f32) -> Result<(), Error> {
        self.serialize_f64(f64::from(v))
    }
    fn serialize_f64(mut self, v: f64) -> Result<(), Error> {
        // As serde_json: NaN and the infinities are null.
        if !v.is_finite() {
            return self.serialize_unit();
        }
        self.separator(false).write(self.out)?;
        CompactFormatter.write_f64(self.out, v)?;
        Ok(())
    }
    fn serialize_char(self, v: char) -> Result<(), Error> {
        self.serialize_str(v.encode_utf8(&mut [0; 4]))
    }
    fn serialize_str(mut self, v: &str) -> Result<(), Error> {
        let sep = self.separator(false);
        string(self.out, sep, v, b"\"")
    }
    fn serialize_bytes(self, _: &[u8]) -> Result<(), Error> {
        Err(ser::Error::custom("the report has no bytes"))
    }
    fn serialize_none(self) -> Result<(), Error> {
        self.serialize_unit()
    }
    fn serialize_some<T: ?Sized + Serialize>(self, v: &T) -> Result<(), Error> {
        v.serialize(self)
    }
    fn serialize_unit(self) -> Result<(), Error> {
        self.scalar(b"null")
    }
    fn serialize_unit_struct(self, _: &'static str) -> Result<(), Error> {
        self.serialize_unit()
    }
    fn serialize_unit_variant(self, _: &'static str, _: u32, v: &'static str) -> Result<(), Error> {
        self.serialize_str(v)
    }
    fn serialize_newtype_struct<T: ?Sized + Serialize>(
        self,
        _: &'static str,
        v: &T,
    ) -> Result<(), Error> {
        v.serialize(self)
    }
    fn serialize_newtype_variant<T: ?Sized + Serialize>(
        self,
        _: &'static str,
        _: u32,
        _: &'static str,
        _: &T,
    ) -> Result<(), Error> {
        Err(ser::Error::custom(
            "the report has no enum variant with data",
        ))
    }
    fn serialize_seq(self, _: Option<usize>) -> Result<List<'a, W>, Error> {
        self.list()
    }
    fn serialize_tuple(self, _: usize) -> Result<List<'a, W>, Error> {
        self.list()
    }
    fn serialize_tuple_struct(self, _: &'static str, _: usize) -> Result<List<'a, W>, Error> {
        self.list()
    }
    fn serialize_tuple_variant(
        self,
        _: &'static str,
        _: u32,
        _: &'static str,
        _: usize,
    ) -> Result<Self::SerializeTupleVariant, Error> {
        Err(ser::Error::custom(
            "the report has no enum variant with data",
        ))
    }
    fn serialize_map(self, _: Option<usize>) -> Result<Object<'a, W>, Error> {
        self.object()
    }
    fn serialize_struct(self, _: &'static str, _: usize) -> Result<Object<'a, W>, Error> {
        self.object()
    }
    fn serialize_struct_variant(
        self,
        _: &'static str,
        _: u32,
        _: &'static str,
        _: usize,
    ) -> Result<Self::SerializeStructVariant, Error> {
        Err(ser::Error::custom(
            "the report has no enum variant with data",
        ))
    }
}

/// An open list.
struct List<'a, W: ?Sized> {
    out: &'a mut W,
    place: Place,
    first: bool,
    /// Laid out over lines, an element on each (see [`Before::Lines`]).
    multiline: bool,
}

impl<W: ?Sized + Write> List<'_, W> {
    fn element<T: ?Sized + Serialize>(&mut self, v: &T) -> Result<(), Error> {
        let first = std::mem::take(&mut self.first);
        let before = match self.place {
            Place::OneLine => Before::Inline { first },
            Place::Lines(depth) => Before::Lines {
                first,
                depth: depth + 1,
                multiline: &mut self.multiline,
            },
        };
        v.serialize(Value {
            out: &mut *self.out,
            place: Place::OneLine,
            before,
        })
    }

    fn close(self) -> Result<(), Error> {
        if let (Place::Lines(depth), true) = (self.place, self.multiline) {
            Separator::Line { first: true, depth }.write(self.out)?;
        }
        self.out.write_all(b"]")?;
        Ok(())
    }
}

impl<W: ?Sized + Write> ser::SerializeSeq for List<'_, W> {
    type Ok = ();
    type Error = Error;
    fn serialize_element<T: ?Sized + Serialize>(&mut self, v: &T) -> Result<(), Error> {
        self.element(v)
    }
    fn end(self) -> Result<(), Error> {
        self.close()
    }
}

impl<W: ?Sized + Write> ser::SerializeTuple for List<'_, W> {
    type Ok = ();
    type Error = Error;
    fn serialize_element<T: ?Sized + Serialize>(&mut self, v: &T) -> Result<(), Error> {
        self.element(v)
    }
    fn end(self) -> Result<(), Error> {
        self.close()
    }
}

impl<W: ?Sized + Write> ser::SerializeTupleStruct for List<'_, W> {
    type Ok = ();
    type Error = Error;
    fn serialize_field<T: ?Sized + Serialize>(&mut self, v: &T) -> Result<(), Error> {
        self.element(v)
    }
    fn end(self) -> Result<(), Error> {
        self.close()
    }
}

/// An open object.
struct Object<'a, W: ?Sized> {
    out: &'a mut W,
    place: Place,
    first: bool,
}

impl<W: ?Sized + Write> Object<'_, W> {
    /// The separator before the next key (and marks the object as no longer empty).
    #[inline(always)]
    fn key_separator(&mut self) -> Separator {
        let first = std::mem::take(&mut self.first);
        match self.place {
            Place::OneLine if first => Separator::Nothing,
            Place::OneLine => Separator::Comma,
            Place::Lines(depth) => Separator::Line {
                first,
                depth: depth + 1,
            },
        }
    }

    /// Writes the separator before a key, the key and `: `.
    fn key(&mut self, key: &str) -> Result<(), Error> {
        let sep = self.key_separator();
        string(self.out, sep, key, b"\": ")
    }

    /// [`key`](Self::key) for a structure's field: the name of a field of the report's own
    /// types, which needs no escaping (the schema test checks every key the report emits).
    #[inline(always)]
    fn static_key(&mut self, key: &'static str) -> Result<(), Error> {
        debug_assert!(plain(key), "a field name needs escaping: {key}");
        self.key_separator().write(self.out)?;
        self.out.write_all(b"\"")?;
        self.out.write_all(key.as_bytes())?;
        self.out.write_all(b"\": ")?;
        Ok(())
    }

    /// The serialiser of the value of the key just written.
    fn value(&mut self) -> Value<'_, W> {
        Value {
            out: &mut *self.out,
            place: match self.place {
                Place::OneLine => Place::OneLine,
                Place::Lines(depth) => Place::Lines(depth + 1),
            },
            before: Before::Nothing,
        }
    }

    fn close(self) -> Result<(), Error> {
        if let (Place::Lines(depth), false) = (self.place, self.first) {
            Separator::Line { first: true, depth }.write(self.out)?;
        }
        self.out.write_all(b"}")?;
        Ok(())
    }
}

impl<W: ?Sized + Write> ser::SerializeStruct for Object<'_, W> {
    type Ok = ();
    type Error = Error;
    fn serialize_field<T: ?Sized + Serialize>(
        &mut self,
        key: &'static str,
        v: &T,
    ) -> Result<(), Error> {
        self.static_key(key)?;
        v.serialize(self.value())
    }
    fn end(self) -> Result<(), Error> {
        self.close()
    }
}

impl<W: ?Sized + Write> ser::SerializeMap for Object<'_, W> {
    type Ok = ();
    type Error = Error;
    fn serialize_key<T: ?Sized + Serialize>(&mut self, key: &T) -> Result<(), Error> {
        key.serialize(Key(self))
    }
    fn serialize_value<T: ?Sized + Serialize>(&mut self, v: &T) -> Result<(), Error> {
        v.serialize(self.value())
    }
    fn end(self) -> Result<(), Error> {
        self.close()
    }
}

/// The serialiser of a map's key: a string.
struct Key<'o, 'a, W: ?Sized>(&'o mut Object<'a, W>);

fn not_a_string_key() -> Error {
    ser::Error::custom("a map key of the report is a string")
}

impl<W: ?Sized + Write> ser::Serializer for Key<'_, '_, W> {
    type Ok = ();
    type Error = Error;
    type SerializeSeq = Impossible<(), Error>;
    type SerializeTuple = Impossible<(), Error>;
    type SerializeTupleStruct = Impossible<(), Error>;
    type SerializeTupleVariant = Impossible<(), Error>;
    type SerializeMap = Impossible<(), Error>;
    type SerializeStruct = Impossible<(), Error>;
    type SerializeStructVariant = Impossible<(), Error>;

    fn serialize_str(self, v: &str) -> Result<(), Error> {
        self.0.key(v)
    }
    fn serialize_bool(self, _: bool) -> Result<(), Error> {
        Err(not_a_string_key())
    }
    fn serialize_i8(self, _: i8) -> Result<(), Error> {
        Err(not_a_string_key())
    }
    fn serialize_i16(self, _: i16) -> Result<(), Error> {
        Err(not_a_string_key())
    }
    fn serialize_i32(self, _: i32) -> Result<(), Error> {
        Err(not_a_string_key())
    }
    fn serialize_i64(self, _: i64) -> Result<(), Error> {
        Err(not_a_string_key())
    }
    fn serialize_u8(self, _: u8) -> Result<(), Error> {
        Err(not_a_string_key())
    }
    fn serialize_u16(self, _: u16) -> Result<(), Error> {
        Err(not_a_string_key())
    }
    fn serialize_u32(self, _: u32) -> Result<(), Error> {
        Err(not_a_string_key())
    }
    fn serialize_u64(self, _: u64) -> Result<(), Error> {
        Err(not_a_string_key())
    }
    fn serialize_f32(self, _: f32) -> Result<(), Error> {
        Err(not_a_string_key())
    }
    fn serialize_f64(self, _: f64) -> Result<(), Error> {
        Err(not_a_string_key())
    }
    fn serialize_char(self, v: char) -> Result<(), Error> {
        self.serialize_str(v.encode_utf8(&mut [0; 4]))
    }
    fn serialize_bytes(self, _: &[u8]) -> Result<(), Error> {
        Err(not_a_string_key())
    }
    fn serialize_none(self) -> Result<(), Error> {
        Err(not_a_string_key())
    }
    fn serialize_some<T: ?Sized + Serialize>(self, _: &T) -> Result<(), Error> {
        Err(not_a_string_key())
    }
    fn serialize_unit(self) -> Result<(), Error> {
        Err(not_a_string_key())
    }
    fn serialize_unit_struct(self, _: &'static str) -> Result<(), Error> {
        Err(not_a_string_key())
    }
    fn serialize_unit_variant(self, _: &'static str, _: u32, v: &'static str) -> Result<(), Error> {
        self.serialize_str(v)
    }
    fn serialize_newtype_struct<T: ?Sized + Serialize>(
        self,
        _: &'static str,
        v: &T,
    ) -> Result<(), Error> {
        v.serialize(self)
    }
    fn serialize_newtype_variant<T: ?Sized + Serialize>(
        self,
        _: &'static str,
        _: u32,
        _: &'static str,
        _: &T,
    ) -> Result<(), Error> {
        Err(not_a_string_key())
    }
    fn serialize_seq(self, _: Option<usize>) -> Result<Self::SerializeSeq, Error> {
        Err(not_a_string_key())
    }
    fn serialize_tuple(self, _: usize) -> Result<Self::SerializeTuple, Error> {
        Err(not_a_string_key())
    }
    fn serialize_tuple_struct(
        self,
        _: &'static str,
        _: usize,
    ) -> Result<Self::SerializeTupleStruct, Error> {
        Err(not_a_string_key())
    }
    fn serialize_tuple_variant(
        self,
        _: &'static str,
        _: u32,
        _: &'static str,
        _: usize,
    ) -> Result<Self::SerializeTupleVariant, Error> {
        Err(not_a_string_key())
    }
    fn serialize_map(self, _: Option<usize>) -> Result<Self::SerializeMap, Error> {
        Err(not_a_string_key())
    }
    fn serialize_struct(self, _: &'static str, _: usize) -> Result<Self::SerializeStruct, Error> {
        Err(not_a_string_key())
    }
    fn serialize_struct_variant(
        self,
        _: &'static str,
        _: u32,
        _: &'static str,
        _: usize,
    ) -> Result<Self::SerializeStructVariant, Error> {
        Err(not_a_string_key())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn json_of(text: &str) -> String {
        let (p, fbd) = plc_load::program_and_fbd_from_json(text).expect("loads");
        let a = plc_analysis::analyse(&p);
        let parts = crate::fbd_parts(&p, &fbd);
        let doc = crate::document_with(&p, &a, parts.as_ref());
        let mut out = Vec::new();
        render_json(&doc, &mut out).expect("writes");
        String::from_utf8(out).expect("UTF-8")
    }

    /// Strings that need escaping (a control character is refused in names: E0110), a label,
    /// control dependences with edges: the layout of every kind of list.
    #[test]
    fn the_layout_of_objects_lists_and_escaped_strings() {
        let json = json_of(
            r#"{"program": "P\"\\/", "vars": [{"name": "A", "type": "BOOL"}],
                "rungs": [{"id": "R\\1", "ld": [{"contact": "A"}, {"jmp": "L"}]},
                          {"id": "R2é", "ld": [{"coil": "A"}]},
                          {"id": "R3", "label": "L", "ld": [{"contact": "A"}, {"coil": "A"}]}]}"#,
        );
        let lines: Vec<&str> = json.lines().collect();
        assert_eq!(lines[0], "{");
        assert_eq!(lines[1], r#"  "program": "P\"\\/","#);
        assert_eq!(lines[2], r#"  "rungs": ["#);
        assert_eq!(
            lines[3],
            r#"    {"id": "R\\1", "pou": "P\"\\/", "in": ["A"], "out": [], "cost": 2},"#
        );
        assert_eq!(
            lines[5],
            r#"    {"id": "R3", "pou": "P\"\\/", "label": "L", "in": ["A"], "out": ["A"], "cost": 2}"#
        );
        assert_eq!(lines[6], "  ],");
        assert!(json.contains(
            r#"{"kind": "control", "from": "R\\1", "to": "R2é", "cause": "branch", "edge": {"from": "R\\1", "to": "R2é", "label": "F"}}"#
        ), "{json}");
        assert!(
            json.contains("\n  \"cfg\": {\n    \"edges\": [\n      {\"from\": \"START\""),
            "{json}"
        );
        assert!(json.contains("\n  \"self_control\": [],\n"), "{json}");
        assert!(json.contains("\n  \"cost\": {\n    \"work\": "), "{json}");
        assert!(
            json.contains("\n    \"makespan\": {\n      \"1\": "),
            "{json}"
        );
        assert!(json.ends_with("\n}\n"));
        let value: serde_json::Value = serde_json::from_str(&json).expect("JSON");
        assert_eq!(value["rungs"][1]["id"], "R2é");
    }

    /// Lists of plain values share a line; a list whose elements are lists or objects has one
    /// element per line, and everything inside an element stays on its line; NaN is null as
    /// in `serde_json`.
    /// The word-at-a-time check says what the byte-by-byte rule says, for every ASCII byte and
    /// a multi-byte character at every position of strings of 1 to 24 bytes.
    #[test]
    fn plain_is_the_byte_rule() {
        let reference = |s: &str| s.bytes().all(|b| b >= 0x20 && b != b'"' && b != b'\\');
        let mut specials: Vec<String> = (0u8..0x80).map(|b| (b as char).to_string()).collect();
        specials.push("é".into());
        specials.push("\u{7f}".into());
        for len in 1..=24 {
            for at in 0..len {
                for c in &specials {
                    let s = format!("{}{c}{}", "a".repeat(at), "z".repeat(len - at - 1));
                    assert_eq!(plain(&s), reference(&s), "{s:?}");
                }
            }
        }
        assert!(plain("") && plain("a_long_plain_field_name_of_the_report"));
    }

    #[test]
    fn plain_values_share_a_line_and_containers_do_not() {
        #[derive(serde::Serialize)]
        struct Doc {
            plain: Vec<u32>,
            nested: Vec<Vec<u32>>,
            mixed: Vec<serde_json::Value>,
            empty: Vec<u32>,
            map: std::collections::BTreeMap<&'static str, f64>,
            none: Option<bool>,
        }
        let doc = Doc {
            plain: vec![1, 2],
            nested: vec![vec![1], vec![]],
            mixed: vec![1.into(), serde_json::json!({"a": [true]}), 2.into()],
            empty: vec![],
            map: [("x", 0.5), ("y", f64::NAN)].into(),
            none: None,
        };
        let mut out = Vec::new();
        doc.serialize(Value {
            out: &mut out,
            place: Place::Lines(0),
            before: Before::Nothing,
        })
        .expect("writes");
        assert_eq!(
            String::from_utf8(out).unwrap(),
            "{\n  \"plain\": [1, 2],\n  \"nested\": [\n    [1],\n    []\n  ],\n  \"mixed\": [1,\n    {\"a\": [true]},\n    2\n  ],\n  \"empty\": [],\n  \"map\": {\n    \"x\": 0.5,\n    \"y\": null\n  },\n  \"none\": null\n}"
        );
    }
}
