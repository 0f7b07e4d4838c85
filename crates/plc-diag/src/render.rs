//! Diagnostics as the command line shows them: in the style of rustc (rendered by
//! `codespan-reporting`), or as one JSON object per line for tools.
//!
//! A [`Shown`] is a diagnostic made ready to show, once, while the program text is at hand:
//! code, severity, message, the file, line and column, the byte span of the token at the
//! origin ([`super::span`]), the hint, the structural place (`rung R2 at rungs[1].ld[0]`) and
//! the excerpt of the line. It keeps no reference to the text, so it can travel in an error.
//! The text rendering is
//!
//! ```text
//! error[E0204]: undefined variable `B`
//!   --> p.json:3:20
//!   |
//! 3 |       {"contact": "B"},
//!   |                   ^^^ rung R2 at rungs[1].ld[0].contact
//!   |
//!   = help: did you mean `A`?
//! ```
//!
//! with the first line grep-friendly (`error[CODE]: message`) and colour only when asked
//! (the caller decides: a terminal, no `NO_COLOR`). The JSON keys are a contract documented in
//! docs/diagnostics.md. Line and column are those of the origin (1-based, the column in
//! characters), as in the one-line form of [`super::LoadError::in_file`].

use super::span::{self, Excerpt};
use super::{Diagnostic, LoadError, Origin, Severity};
use codespan_reporting::diagnostic as cs;
use codespan_reporting::files::{Error as FilesError, Files, Location};
use codespan_reporting::term::{self, termcolor, Chars, Config, Styles, StylesWriter};
use std::ops::Range;

/// The code of a file that cannot be parsed at all (JSON, XML or STL syntax).
pub const SYNTAX_CODE: &str = "E0100";

/// A diagnostic ready to show, with its excerpt (see the module comment).
#[derive(Clone, Debug, PartialEq)]
pub struct Shown {
    pub severity: Severity,
    pub code: &'static str,
    pub message: String,
    /// Where in the program's structure (`rung R2 at rungs[1].ld[0]`), if known.
    pub place: Option<String>,
    pub file: String,
    /// 1-based line and column (in characters) of the origin.
    pub position: Option<(u32, u32)>,
    /// The byte range of the token at the origin, in the file's text.
    pub span: Option<Range<usize>>,
    pub hint: Option<String>,
    excerpt: Option<Excerpt>,
    /// `file` as the text rendering shows it ([`super::printable`]).
    file_shown: String,
}

impl Shown {
    /// Every problem of `error`, whose origins are offsets into `text`, the text of `file`.
    pub fn load_error(file: &str, text: &str, error: &LoadError) -> Vec<Shown> {
        if let LoadError::Syntax {
            line,
            column,
            message,
        } = error
        {
            let at = span::offset_of(text, *line, *column);
            let position = Some((*line as u32, *column as u32));
            return vec![Shown::new(
                (Severity::Error, SYNTAX_CODE, message.clone()),
                file,
                text,
                (Origin::at(at), position),
            )];
        }
        let located = error.diagnostics().iter().map(|d| {
            let origin = d.location.origin;
            let position = d.location.position.or_else(|| origin.line_column(text));
            let mut s = Shown::new(
                (d.severity, d.code(), d.message()),
                file,
                text,
                (origin, position),
            );
            s.place = Some(d.location.to_string());
            s.hint = d.hint.clone();
            s
        });
        located.collect()
    }

    /// A warning with code `code` at `origin` of `text` (a reader's note).
    pub fn warning(
        code: &'static str,
        message: String,
        file: &str,
        text: &str,
        origin: Origin,
    ) -> Shown {
        let position = origin.line_column(text);
        Shown::new(
            (Severity::Warning, code, message),
            file,
            text,
            (origin, position),
        )
    }

    /// A diagnostic about no place in a text (a warning of a run, an error of the command).
    pub fn unplaced(severity: Severity, code: &'static str, message: String) -> Shown {
        Shown {
            severity,
            code,
            message,
            place: None,
            file: String::new(),
            position: None,
            span: None,
            hint: None,
            excerpt: None,
            file_shown: String::new(),
        }
    }

    fn new(
        (severity, code, message): (Severity, &'static str, String),
        file: &str,
        text: &str,
        (origin, position): (Origin, Option<(u32, u32)>),
    ) -> Shown {
        let span = origin
            .offset()
            .filter(|&o| o <= text.len())
            .map(|o| span::token_at(text, o));
        Shown {
            severity,
            code,
            message,
            place: None,
            file: file.to_owned(),
            position: position.filter(|_| span.is_some()),
            excerpt: span.clone().map(|s| {
                let mut e = span::excerpt(text, s);
                e.text = same_width(&e.text);
                e
            }),
            span,
            hint: None,
            file_shown: super::printable(file).into_owned(),
        }
    }

    /// The rendering in the style of rustc (ending with a blank line), with ANSI colours if
    /// `colour`.
    pub fn text(&self, colour: bool) -> String {
        let mut d = cs::Diagnostic::new(match self.severity {
            Severity::Error => cs::Severity::Error,
            Severity::Warning => cs::Severity::Warning,
        })
        .with_message(super::printable(&self.message));
        if !self.code.is_empty() {
            d = d.with_code(self.code);
        }
        let mut notes = Vec::new();
        match (&self.excerpt, self.position) {
            (Some(e), Some(_)) => {
                let label = cs::Label::primary((), e.span.clone());
                d = d.with_label(match &self.place {
                    Some(p) => label.with_message(super::printable(p)),
                    None => label,
                });
            }
            _ if !self.file.is_empty() => notes.push(match &self.place {
                Some(p) => format!(
                    "in {}: {}",
                    super::printable(&self.file),
                    super::printable(p)
                ),
                None => format!("in {}", super::printable(&self.file)),
            }),
            _ => {}
        }
        if let Some(h) = &self.hint {
            notes.push(format!("help: {}", super::printable(h)));
        }
        let d = d.with_notes(notes);
        let files = OneLine { shown: self };
        let config = Config {
            chars: Chars::ascii(),
            ..Config::default()
        };
        let rendered = if colour {
            let mut out = termcolor::Ansi::new(Vec::new());
            let styles = Styles::default();
            let mut w = StylesWriter::new(&mut out, &styles);
            term::emit_to_write_style(&mut w, &config, &files, &d)
                .map(|_| String::from_utf8_lossy(&out.into_inner()).into_owned())
        } else {
            term::emit_into_string(&config, &files, &d)
        };
        // The files are ours and complete: rendering cannot fail but on a bug.
        rendered.unwrap_or_else(|_| format!("{}: {}\n", self.code, self.message))
    }

    /// The JSON object (one line, no line break): `code`, `severity`, `message`, `file`,
    /// `line`, `column`, `span` (`start`, `end` in bytes), `hint`, `location` (null where
    /// unknown; docs/diagnostics.md).
    pub fn json(&self) -> String {
        let (line, column) = self.position.unzip();
        let none_if_empty = |s: &str| (!s.is_empty()).then(|| s.to_owned());
        serde_json::json!({
            "code": none_if_empty(self.code),
            "severity": match self.severity {
                Severity::Error => "error",
                Severity::Warning => "warning",
            },
            "message": self.message,
            "file": none_if_empty(&self.file),
            "line": line,
            "column": column,
            "span": self.span.as_ref().map(|s| serde_json::json!({"start": s.start, "end": s.end})),
            "hint": self.hint,
            "location": self.place,
        })
        .to_string()
    }
}

/// The excerpt line with each control character but tab (a terminal escape in the file) as `?`,
/// one per byte, so that the byte span of the caret still fits the line.
fn same_width(line: &str) -> String {
    line.chars()
        .flat_map(|c| {
            let (shown, n) = if c.is_control() && c != '\t' {
                ('?', c.len_utf8())
            } else {
                (c, 1)
            };
            std::iter::repeat_n(shown, n)
        })
        .collect()
}

impl Diagnostic {
    /// This diagnostic with `hint` (shown as `help:`).
    pub fn with_hint(mut self, hint: Option<String>) -> Diagnostic {
        self.hint = hint;
        self
    }
}

/// The one shown line of a [`Shown`], as the file database of `codespan-reporting`: line and
/// column are the origin's in the whole file, the source is the (maybe cut) excerpt.
struct OneLine<'s> {
    shown: &'s Shown,
}

impl<'a> Files<'a> for OneLine<'_> {
    type FileId = ();
    type Name = &'a str;
    type Source = &'a str;

    fn name(&'a self, (): ()) -> Result<&'a str, FilesError> {
        Ok(&self.shown.file_shown)
    }

    fn source(&'a self, (): ()) -> Result<&'a str, FilesError> {
        Ok(self.shown.excerpt.as_ref().map_or("", |e| e.text.as_str()))
    }

    fn line_index(&'a self, (): (), _: usize) -> Result<usize, FilesError> {
        Ok(0)
    }

    fn line_number(&'a self, (): (), _: usize) -> Result<usize, FilesError> {
        Ok(self.shown.position.map_or(1, |(l, _)| l as usize))
    }

    fn location(&'a self, (): (), _: usize) -> Result<Location, FilesError> {
        let (line, column) = self.shown.position.unwrap_or((1, 1));
        Ok(Location {
            line_number: line as usize,
            column_number: column as usize,
        })
    }

    fn line_range(&'a self, (): (), _: usize) -> Result<Range<usize>, FilesError> {
        Ok(0..self.source(())?.len())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::Invalid;

    #[test]
    fn an_error_shows_code_message_place_line_caret_and_help() {
        let text = "{\"rungs\": [\n  {\"id\": \"R1\", \"ld\": [{\"contact\": \"Cuont\"}]}]}";
        let at = text.find("\"Cuont\"").unwrap();
        let e = LoadError::invalid(
            Some("R1"),
            "rungs[0].ld[0].contact",
            Invalid::UndefinedVar {
                name: "Cuont".into(),
            },
        )
        .at(Origin::at(at))
        .locate(text);
        let LoadError::Invalid(d) = e else { panic!() };
        let e = LoadError::Invalid(Box::new(d.with_hint(Some("did you mean `Count`?".into()))));
        let shown = Shown::load_error("p.json", text, &e);
        assert_eq!(
            shown[0].text(false),
            "error[E0204]: undefined variable `Cuont`\n  --> p.json:2:35\n  |\n2 |   {\"id\": \"R1\", \"ld\": [{\"contact\": \"Cuont\"}]}]}\n  |                                   ^^^^^^^ rung R1 at rungs[0].ld[0].contact\n  |\n  = help: did you mean `Count`?\n\n"
        );
        assert_eq!(
            shown[0].json(),
            format!("{{\"code\":\"E0204\",\"severity\":\"error\",\"message\":\"undefined variable `Cuont`\",\"file\":\"p.json\",\"line\":2,\"column\":35,\"span\":{{\"start\":{at},\"end\":{}}},\"hint\":\"did you mean `Count`?\",\"location\":\"rung R1 at rungs[0].ld[0].contact\"}}", at + 7)
        );
        let coloured = shown[0].text(true);
        assert!(coloured.contains("\x1b["), "{coloured}");
    }

    #[test]
    fn a_syntax_error_and_a_warning_without_a_place() {
        let text = "{\"a\": 1 \"b\"}";
        let e = LoadError::Syntax {
            line: 1,
            column: 9,
            message: "expected `,` or `}`".into(),
        };
        let s = &Shown::load_error("p.json", text, &e)[0];
        assert_eq!(s.span, Some(8..11));
        assert_eq!(
            s.text(false),
            "error[E0100]: expected `,` or `}`\n  --> p.json:1:9\n  |\n1 | {\"a\": 1 \"b\"}\n  |         ^^^\n\n"
        );
        let w = Shown::unplaced(Severity::Warning, "W0101", "four threads".into());
        assert_eq!(w.text(false), "warning[W0101]: four threads\n\n");
        assert_eq!(
            w.json(),
            "{\"code\":\"W0101\",\"severity\":\"warning\",\"message\":\"four threads\",\"file\":null,\"line\":null,\"column\":null,\"span\":null,\"hint\":null,\"location\":null}"
        );
    }
}
