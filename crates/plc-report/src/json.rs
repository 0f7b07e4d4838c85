//! The JSON report: the [`Report`] document serialised as JSON, streamed to the writer (no
//! whole-output string). Keys are normative (docs/report.md): those of the report's first
//! version (`program`, `rungs[].id/in/out`, `dependences[].kind/from/to/var`,
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
//! The top-level object is written here key by key, in the order of [`Report`]'s fields; the
//! entries of the three longest lists (rungs, dependences, CFG edges: millions of lines for a
//! million rungs) are written straight into the writer ([`entries`]), everything else through
//! `serde_json` with [`ReportFormatter`]. The bytes are those of serialising the whole
//! [`Report`] with `serde_json` and the formatter, which the tests check.

mod entries;

use super::document::Report;
use serde::Serialize;
use serde_json::ser::Formatter;
use std::io::{self, Write};

/// Writes the report as JSON with a trailing newline.
pub fn render_json(report: &Report, out: &mut impl Write) -> io::Result<()> {
    let mut first = true;
    let mut key = |out: &mut dyn Write, k: &str| -> io::Result<()> {
        out.write_all(if std::mem::take(&mut first) {
            b"\n  \""
        } else {
            b",\n  \""
        })?;
        out.write_all(k.as_bytes())?;
        out.write_all(b"\": ")
    };
    out.write_all(b"{")?;
    key(out, "program")?;
    value(out, &report.program)?;
    key(out, "rungs")?;
    entries::list(out, 1, report.rungs.iter(), entries::rung)?;
    key(out, "dependences")?;
    entries::list(out, 1, report.dependences.iter(), entries::dependence)?;
    key(out, "dependences_listed")?;
    value(out, &report.dependences_listed)?;
    key(out, "dependence_counts")?;
    value(out, &report.dependence_counts)?;
    key(out, "self_control")?;
    value(out, &report.self_control)?;
    key(out, "cfg")?;
    out.write_all(b"{\n    \"edges\": ")?;
    entries::list(out, 2, report.cfg.edges.iter(), entries::cfg_edge)?;
    out.write_all(b"\n  }")?;
    key(out, "ipdom")?;
    value(out, &report.ipdom)?;
    key(out, "levels")?;
    value(out, &report.levels)?;
    key(out, "cycles")?;
    value(out, &report.cycles)?;
    key(out, "cost")?;
    value(out, &report.cost)?;
    key(out, "schedule")?;
    value(out, &report.schedule)?;
    key(out, "loops")?;
    value(out, &report.loops)?;
    key(out, "differences")?;
    value(out, &report.differences)?;
    key(out, "warnings")?;
    value(out, &report.warnings)?;
    if !report.warning_codes.is_empty() {
        key(out, "warning_codes")?;
        value(out, &report.warning_codes)?;
    }
    if !report.networks.is_empty() {
        key(out, "networks")?;
        value(out, &report.networks)?;
    }
    if !report.interrupts.is_empty() {
        key(out, "interrupts")?;
        value(out, &report.interrupts)?;
    }
    if let Some(c) = &report.configuration {
        key(out, "configuration")?;
        value(out, c)?;
    }
    if !report.programs.is_empty() {
        key(out, "programs")?;
        value(out, &report.programs)?;
    }
    if let Some(t) = &report.task_sharing {
        key(out, "task_sharing")?;
        value(out, t)?;
    }
    if let Some(fbd) = &report.fbd {
        key(out, "fbd")?;
        value(out, fbd)?;
    }
    if !report.skipped_pous.is_empty() {
        key(out, "skipped_pous")?;
        value(out, &report.skipped_pous)?;
    }
    out.write_all(b"\n}\n")
}

/// Writes `v` as the value of a key of the top-level object.
fn value<W: Write + ?Sized, T: Serialize + ?Sized>(out: &mut W, v: &T) -> io::Result<()> {
    let mut ser = serde_json::Serializer::with_formatter(out, ReportFormatter::in_object(1));
    v.serialize(&mut ser).map_err(io::Error::other)
}

/// One open array or object.
struct Frame {
    is_array: bool,
    /// Written on one line: an element of a list, or inside one.
    inline: bool,
    /// An object has a key, or an array an element on its own line.
    multiline: bool,
    /// An array element is about to be written; `Some(first)`.
    pending: Option<bool>,
}

/// Pretty objects, inline scalar arrays (see the module documentation).
#[derive(Default)]
pub struct ReportFormatter {
    stack: Vec<Frame>,
}

const SPACES: &[u8; 128] = &[b' '; 128];

pub(super) fn indent<W: ?Sized + Write>(w: &mut W, depth: usize) -> io::Result<()> {
    let mut n = 2 * depth;
    while n > 0 {
        let k = n.min(SPACES.len());
        w.write_all(&SPACES[..k])?;
        n -= k;
    }
    Ok(())
}

impl ReportFormatter {
    /// The formatter for a value inside `depth` objects written one key per line.
    fn in_object(depth: usize) -> ReportFormatter {
        let frame = || Frame {
            is_array: false,
            inline: false,
            multiline: true,
            pending: None,
        };
        ReportFormatter {
            stack: (0..depth).map(|_| frame()).collect(),
        }
    }

    /// A container opened now is written on one line: it is a list's element, or inside one.
    fn nested_inline(&self) -> bool {
        self.stack.last().is_some_and(|f| f.inline || f.is_array)
    }

    /// Writes the separator before an array element, once its kind is known.
    fn before_value<W: ?Sized + Write>(&mut self, w: &mut W, container: bool) -> io::Result<()> {
        let depth = self.stack.len();
        let Some(top) = self.stack.last_mut() else {
            return Ok(());
        };
        let Some(first) = top.pending.take() else {
            return Ok(());
        };
        if top.inline {
            return if first { Ok(()) } else { w.write_all(b", ") };
        }
        if container || top.multiline {
            top.multiline = true;
            w.write_all(if first { b"\n" } else { b",\n" })?;
            indent(w, depth)
        } else if first {
            Ok(())
        } else {
            w.write_all(b", ")
        }
    }
}

macro_rules! scalar {
    ($($name:ident: $t:ty),* $(,)?) => {
        $(fn $name<W: ?Sized + Write>(&mut self, w: &mut W, value: $t) -> io::Result<()> {
            self.before_value(w, false)?;
            serde_json::ser::CompactFormatter.$name(w, value)
        })*
    };
}

impl Formatter for ReportFormatter {
    fn write_null<W: ?Sized + Write>(&mut self, w: &mut W) -> io::Result<()> {
        self.before_value(w, false)?;
        w.write_all(b"null")
    }
    scalar!(
        write_bool: bool, write_i8: i8, write_i16: i16, write_i32: i32, write_i64: i64,
        write_i128: i128, write_u8: u8, write_u16: u16, write_u32: u32, write_u64: u64,
        write_u128: u128, write_f32: f32, write_f64: f64, write_number_str: &str,
        write_raw_fragment: &str,
    );
    fn begin_string<W: ?Sized + Write>(&mut self, w: &mut W) -> io::Result<()> {
        self.before_value(w, false)?;
        w.write_all(b"\"")
    }
    fn begin_array<W: ?Sized + Write>(&mut self, w: &mut W) -> io::Result<()> {
        self.before_value(w, true)?;
        let inline = self.nested_inline();
        self.stack.push(Frame {
            is_array: true,
            inline,
            multiline: false,
            pending: None,
        });
        w.write_all(b"[")
    }
    fn begin_array_value<W: ?Sized + Write>(&mut self, _w: &mut W, first: bool) -> io::Result<()> {
        if let Some(top) = self.stack.last_mut() {
            top.pending = Some(first);
        }
        Ok(())
    }
    fn end_array_value<W: ?Sized + Write>(&mut self, _w: &mut W) -> io::Result<()> {
        Ok(())
    }
    fn end_array<W: ?Sized + Write>(&mut self, w: &mut W) -> io::Result<()> {
        let frame = self.stack.pop();
        if frame.is_some_and(|f| f.multiline && !f.inline) {
            w.write_all(b"\n")?;
            indent(w, self.stack.len())?;
        }
        w.write_all(b"]")
    }
    fn begin_object<W: ?Sized + Write>(&mut self, w: &mut W) -> io::Result<()> {
        self.before_value(w, true)?;
        let inline = self.nested_inline();
        self.stack.push(Frame {
            is_array: false,
            inline,
            multiline: false,
            pending: None,
        });
        w.write_all(b"{")
    }
    fn begin_object_key<W: ?Sized + Write>(&mut self, w: &mut W, first: bool) -> io::Result<()> {
        let depth = self.stack.len();
        if let Some(top) = self.stack.last_mut() {
            debug_assert!(!top.is_array);
            top.multiline = true;
            if top.inline {
                return if first { Ok(()) } else { w.write_all(b", ") };
            }
        }
        w.write_all(if first { b"\n" } else { b",\n" })?;
        indent(w, depth)
    }
    fn end_object_key<W: ?Sized + Write>(&mut self, _w: &mut W) -> io::Result<()> {
        Ok(())
    }
    fn begin_object_value<W: ?Sized + Write>(&mut self, w: &mut W) -> io::Result<()> {
        w.write_all(b": ")
    }
    fn end_object_value<W: ?Sized + Write>(&mut self, _w: &mut W) -> io::Result<()> {
        Ok(())
    }
    fn end_object<W: ?Sized + Write>(&mut self, w: &mut W) -> io::Result<()> {
        let frame = self.stack.pop();
        if frame.is_some_and(|f| f.multiline && !f.inline) {
            w.write_all(b"\n")?;
            indent(w, self.stack.len())?;
        }
        w.write_all(b"}")
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The report as `serde_json` serialises the whole document with the formatter.
    fn reference(report: &Report) -> String {
        let mut out = Vec::new();
        let mut ser = serde_json::Serializer::with_formatter(&mut out, ReportFormatter::default());
        report.serialize(&mut ser).expect("serialises");
        out.push(b'\n');
        String::from_utf8(out).expect("UTF-8")
    }

    fn check(text: &str) {
        let (p, fbd) = plc_load::program_and_fbd_from_json(text).expect("loads");
        let a = plc_analysis::analyse(&p);
        let parts = crate::fbd_parts(&p, &fbd);
        let doc = crate::document_with(&p, &a, parts.as_ref());
        let mut out = Vec::new();
        render_json(&doc, &mut out).expect("writes");
        let written = String::from_utf8(out).expect("UTF-8");
        assert_eq!(written, reference(&doc));
    }

    #[test]
    fn the_written_report_is_the_serialised_document_byte_for_byte() {
        let dir = concat!(env!("CARGO_MANIFEST_DIR"), "/../../analyses");
        let mut checked = 0;
        for entry in std::fs::read_dir(dir).expect("analyses/") {
            let path = entry.expect("entry").path().join("program.json");
            if let Ok(text) = std::fs::read_to_string(&path) {
                check(&text);
                checked += 1;
            }
        }
        assert!(checked >= 10, "{checked} examples");
        // Strings that need escaping (a control character is refused in names: E0110), a
        // label, control dependences with edges.
        check(
            r#"{"program": "P\"\\/", "vars": [{"name": "A", "type": "BOOL"}],
                "rungs": [{"id": "R\\1", "ld": [{"contact": "A"}, {"jmp": "L"}]},
                          {"id": "R2é", "ld": [{"coil": "A"}]},
                          {"id": "R3", "label": "L", "ld": [{"contact": "A"}, {"coil": "A"}]}]}"#,
        );
    }
}
