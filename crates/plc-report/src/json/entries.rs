//! The entries of the JSON report's longest lists, written straight into the writer: a rung
//! (`{"id": …, "pou": …, "in": […], "out": […], "cost": …}`), a dependence and a CFG edge, each
//! whole on its line, with exactly the bytes `serde_json` and [`super::ReportFormatter`] give
//! the same entry (strings escaped as `serde_json` escapes them; a string that needs escaping
//! is handed to it). Nothing here decides what an entry says: `super::super::document` does.

use super::indent;
use crate::document::{CfgEdgeEntry, DependenceEntry, EdgeRef, RungEntry};
use std::io::{self, Write};

/// A list of entries as the value of a key at `depth` (1: of the top-level object): `[`, each
/// entry on its own line indented one level deeper, `]` on its own line (`[]` when empty).
pub(super) fn list<W: Write + ?Sized, T>(
    out: &mut W,
    depth: usize,
    items: impl Iterator<Item = T>,
    entry: fn(&mut W, &T) -> io::Result<()>,
) -> io::Result<()> {
    out.write_all(b"[")?;
    let mut first = true;
    for item in items {
        out.write_all(if std::mem::take(&mut first) {
            b"\n"
        } else {
            b",\n"
        })?;
        indent(out, depth + 1)?;
        entry(out, &item)?;
    }
    if !first {
        out.write_all(b"\n")?;
        indent(out, depth)?;
    }
    out.write_all(b"]")
}

/// A JSON string, escaped as `serde_json` escapes it.
fn string<W: Write + ?Sized>(out: &mut W, s: &str) -> io::Result<()> {
    if s.bytes().all(|b| b >= 0x20 && b != b'"' && b != b'\\') {
        out.write_all(b"\"")?;
        out.write_all(s.as_bytes())?;
        out.write_all(b"\"")
    } else {
        serde_json::to_writer(out, s).map_err(io::Error::other)
    }
}

/// `"key": "value"`, after `, ` unless it is the object's first key.
fn field<W: Write + ?Sized>(out: &mut W, first: bool, key: &str, value: &str) -> io::Result<()> {
    key_of(out, first, key)?;
    string(out, value)
}

fn key_of<W: Write + ?Sized>(out: &mut W, first: bool, key: &str) -> io::Result<()> {
    if !first {
        out.write_all(b", ")?;
    }
    out.write_all(b"\"")?;
    out.write_all(key.as_bytes())?;
    out.write_all(b"\": ")
}

/// A list of strings on one line: `["a", "b"]`.
fn strings<W: Write + ?Sized>(out: &mut W, items: &[&str]) -> io::Result<()> {
    out.write_all(b"[")?;
    for (i, s) in items.iter().enumerate() {
        if i > 0 {
            out.write_all(b", ")?;
        }
        string(out, s)?;
    }
    out.write_all(b"]")
}

/// A number in decimal.
fn number<W: Write + ?Sized>(out: &mut W, mut n: u64) -> io::Result<()> {
    let mut buf = [0u8; 20];
    let mut i = buf.len();
    loop {
        i -= 1;
        buf[i] = b'0' + (n % 10) as u8;
        n /= 10;
        if n == 0 {
            break;
        }
    }
    out.write_all(&buf[i..])
}

pub(super) fn rung<W: Write + ?Sized>(out: &mut W, r: &RungEntry) -> io::Result<()> {
    out.write_all(b"{")?;
    field(out, true, "id", r.id)?;
    field(out, false, "pou", r.pou)?;
    if let Some(l) = r.label {
        field(out, false, "label", l)?;
    }
    key_of(out, false, "in")?;
    strings(out, &r.ins)?;
    key_of(out, false, "out")?;
    strings(out, &r.out)?;
    key_of(out, false, "cost")?;
    number(out, r.cost)?;
    out.write_all(b"}")
}

pub(super) fn dependence<W: Write + ?Sized>(out: &mut W, d: &DependenceEntry) -> io::Result<()> {
    out.write_all(b"{")?;
    match d {
        DependenceEntry::Data {
            kind,
            from,
            to,
            var,
        } => {
            field(out, true, "kind", kind)?;
            field(out, false, "from", from)?;
            field(out, false, "to", to)?;
            field(out, false, "var", var)?;
        }
        DependenceEntry::Control {
            kind,
            from,
            to,
            cause,
            edge,
            var,
        } => {
            field(out, true, "kind", kind)?;
            field(out, false, "from", from)?;
            field(out, false, "to", to)?;
            field(out, false, "cause", cause)?;
            if let Some(e) = edge {
                key_of(out, false, "edge")?;
                edge_ref(out, e)?;
            }
            if let Some(v) = var {
                field(out, false, "var", v)?;
            }
        }
    }
    out.write_all(b"}")
}

fn edge_ref<W: Write + ?Sized>(out: &mut W, e: &EdgeRef) -> io::Result<()> {
    out.write_all(b"{")?;
    field(out, true, "from", e.from)?;
    field(out, false, "to", e.to)?;
    if let Some(l) = e.label {
        field(out, false, "label", l)?;
    }
    out.write_all(b"}")
}

pub(super) fn cfg_edge<W: Write + ?Sized>(out: &mut W, e: &CfgEdgeEntry) -> io::Result<()> {
    out.write_all(b"{")?;
    field(out, true, "from", e.from)?;
    field(out, false, "to", e.to)?;
    if let Some(l) = e.label {
        field(out, false, "label", l)?;
    }
    field(out, false, "kind", e.kind)?;
    out.write_all(b"}")
}
