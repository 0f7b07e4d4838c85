//! What a diagnostic underlines: the extent of the token at its origin, and the excerpt of its
//! line that is shown.
//!
//! An [`Origin`](super::Origin) is one byte offset; the token that starts there is what the
//! reader wants underlined: a JSON string or key (with its quotes), a number, an identifier or
//! an STL operand (`I0.0`, `T#1s`, `%IX0.0`), the name of an XML tag (`<block` underlines
//! `block`), a JSON object or array when it closes on the same line, else the one character.
//! Invariants: a span never leaves the line it starts on, and always ends on a character
//! boundary. An excerpt is one line; a line longer than [`MAX_SHOWN`] characters (a minified
//! file on one line) is cut to [`CONTEXT`] characters either side of the span, with `...` where
//! it was cut, so a diagnostic stays a few lines whatever the file. It does not know formats
//! beyond these lexical shapes: the readers' origins say which token is meant.

use std::ops::Range;

/// A line up to this many characters is shown whole.
pub const MAX_SHOWN: usize = 100;
/// Characters kept either side of the span when a longer line is cut.
pub const CONTEXT: usize = 40;
/// The most characters of a span shown in a cut line (a longer span is cut too).
const MAX_SPAN: usize = 60;

/// The byte range of the token that starts at byte `at` of `text` (empty at the end of the
/// text; `at` is moved back to a character boundary).
pub fn token_at(text: &str, at: usize) -> Range<usize> {
    let mut at = at.min(text.len());
    while !text.is_char_boundary(at) {
        at -= 1;
    }
    let b = text.as_bytes();
    let line_end = text[at..].find('\n').map_or(text.len(), |i| at + i);
    let Some(&first) = b.get(at) else {
        return at..at;
    };
    let word = |c: u8| c.is_ascii_alphanumeric() || matches!(c, b'_' | b'#' | b'%' | b'.');
    let scan = |from: usize, ok: &dyn Fn(u8) -> bool| {
        (from..line_end).find(|&i| !ok(b[i])).unwrap_or(line_end)
    };
    let end = match first {
        b'"' => member_end(b, string_end(b, at, line_end), line_end),
        b'<' => {
            let name = (at + 1..line_end)
                .find(|&i| !matches!(b[i], b'/' | b'?' | b'!'))
                .unwrap_or(line_end);
            let end = scan(name, &|c| {
                c.is_ascii_alphanumeric() || matches!(c, b'_' | b':' | b'.' | b'-')
            });
            if end > name {
                return name..end;
            }
            at + 1
        }
        b'-' | b'0'..=b'9' => scan(at + 1, &|c| {
            c.is_ascii_alphanumeric() || matches!(c, b'.' | b'+' | b'-' | b'#' | b'_')
        }),
        b'{' | b'[' => bracket_end(b, at, line_end).unwrap_or(at + 1),
        c if word(c) => scan(at + 1, &word),
        _ => at + text[at..].chars().next().map_or(0, char::len_utf8),
    };
    at..end.min(line_end).max(at)
}

/// The end (after the closing quote) of the JSON string that opens at `at`, or the line end.
fn string_end(b: &[u8], at: usize, line_end: usize) -> usize {
    let mut i = at + 1;
    while i < line_end {
        match b[i] {
            b'\\' => i += 2,
            b'"' => return i + 1,
            _ => i += 1,
        }
    }
    line_end
}

/// The end of a JSON member whose key ends at `key_end`: after its value when that is a
/// string, a number, `true`, `false` or `null` on the same line (the member is the token:
/// `"out": "G1.RESULT"`), else `key_end` (not a key, or a key of an object or array).
fn member_end(b: &[u8], key_end: usize, line_end: usize) -> usize {
    let skip = |mut i: usize| {
        while i < line_end && b[i].is_ascii_whitespace() {
            i += 1;
        }
        i
    };
    let colon = skip(key_end);
    if colon >= line_end || b[colon] != b':' {
        return key_end;
    }
    let v = skip(colon + 1);
    match b.get(v) {
        Some(b'"') if v < line_end => string_end(b, v, line_end),
        Some(c) if v < line_end && (c.is_ascii_alphanumeric() || *c == b'-') => (v..line_end)
            .find(|&i| !(b[i].is_ascii_alphanumeric() || matches!(b[i], b'.' | b'+' | b'-')))
            .unwrap_or(line_end),
        _ => key_end,
    }
}

/// The end of the object or array that opens at `at`, if it closes on the same line.
fn bracket_end(b: &[u8], at: usize, line_end: usize) -> Option<usize> {
    let mut depth = 0usize;
    let mut i = at;
    while i < line_end {
        match b[i] {
            b'"' => {
                i = string_end(b, i, line_end);
                continue;
            }
            b'{' | b'[' => depth += 1,
            b'}' | b']' => {
                depth -= 1;
                if depth == 0 {
                    return Some(i + 1);
                }
            }
            _ => {}
        }
        i += 1;
    }
    None
}

/// The line of a span as shown: its text (maybe cut) and where the span is in it.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Excerpt {
    /// The shown text of the line (no line break; `...` where a long line was cut).
    pub text: String,
    /// The span, in bytes of `text`.
    pub span: Range<usize>,
}

/// The excerpt of the line that `span` (a range of `text`, on one line) starts on.
pub fn excerpt(text: &str, span: Range<usize>) -> Excerpt {
    let start = text[..span.start].rfind('\n').map_or(0, |i| i + 1);
    let end = text[span.start..]
        .find('\n')
        .map_or(text.len(), |i| span.start + i);
    let line = text[start..end]
        .strip_suffix('\r')
        .unwrap_or(&text[start..end]);
    // A span may start past the shown line: on the `\r` stripped from its end (or at the end
    // of a CR-only file, which is one line); it is then shown at the line's end.
    let s = (span.start - start).min(line.len());
    let e = (span.end - start).clamp(s, line.len());
    if line.chars().count() <= MAX_SHOWN {
        return Excerpt {
            text: line.to_owned(),
            span: s..e,
        };
    }
    let back = |from: usize, n: usize| {
        line[..from]
            .char_indices()
            .rev()
            .nth(n.saturating_sub(1))
            .map_or(0, |(i, _)| i)
    };
    let forward = |from: usize, n: usize| {
        line[from..]
            .char_indices()
            .nth(n)
            .map_or(line.len(), |(i, _)| from + i)
    };
    let e = e.min(forward(s, MAX_SPAN));
    let (from, to) = (back(s, CONTEXT), forward(e, CONTEXT));
    let prefix = if from > 0 { "..." } else { "" };
    let suffix = if to < line.len() { "..." } else { "" };
    Excerpt {
        text: format!("{prefix}{}{suffix}", &line[from..to]),
        span: s - from + prefix.len()..e - from + prefix.len(),
    }
}

/// The byte offset of 1-based `line` and `column` (in characters) in `text`, clipped to the
/// end of the line (a syntax error's place, which the parsers give as line and column).
pub fn offset_of(text: &str, line: usize, column: usize) -> usize {
    let start = match line {
        0 | 1 => 0,
        n => text
            .match_indices('\n')
            .nth(n - 2)
            .map_or(text.len(), |(i, _)| i + 1),
    };
    let line_end = text[start..].find('\n').map_or(text.len(), |i| start + i);
    text[start..line_end]
        .char_indices()
        .nth(column.saturating_sub(1))
        .map_or(line_end, |(i, _)| start + i)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn token(text: &str, at: usize) -> &str {
        &text[token_at(text, at)]
    }

    #[test]
    fn the_token_at_an_origin_is_a_string_number_word_tag_name_or_bracket() {
        let json = r#"{"contact": "St\"art", "n": -12.5e3, "ld": [1, 2]}"#;
        assert_eq!(token(json, 1), r#""contact": "St\"art""#);
        assert_eq!(token(json, 12), r#""St\"art""#);
        assert_eq!(token(json, 23), r#""n": -12.5e3"#);
        assert_eq!(token(json, 37), r#""ld""#);
        assert_eq!(token(json, 28), "-12.5e3");
        assert_eq!(token(json, 43), "[1, 2]");
        assert_eq!(token(json, 0), json);
        assert_eq!(token("{\n\"a\": 1}", 0), "{");
        let xml = "  <block localId=\"3\"/>\n</pou>";
        assert_eq!(token(xml, 2), "block");
        assert_eq!(token(xml, 23), "pou");
        assert_eq!(token("LD %IX0.0\n= T#1s", 3), "%IX0.0");
        assert_eq!(token("LD %IX0.0\n= T#1s", 12), "T#1s");
        assert_eq!(token("a = b", 2), "=");
        assert_eq!(token_at("ab", 2), 2..2);
        assert_eq!(token("\"open\nx", 0), "\"open");
    }

    #[test]
    fn a_short_line_is_shown_whole_and_a_long_one_cut_around_the_span() {
        let text = "first\n  \"x\": 1\r\nlast";
        let e = excerpt(text, 8..11);
        assert_eq!((e.text.as_str(), e.span.clone()), ("  \"x\": 1", 2..5));
        let long = format!("[{}\"bad\"{}]", "1,".repeat(100), ",2".repeat(100));
        let at = 201;
        let e = excerpt(&long, token_at(&long, at));
        assert_eq!(&e.text[e.span.clone()], "\"bad\"");
        assert_eq!(e.text.len(), 3 + CONTEXT + 5 + CONTEXT + 3);
        assert!(e.text.starts_with("...1,") && e.text.ends_with(",2..."));
    }

    #[test]
    fn a_span_after_the_trailing_cr_of_a_line_is_shown_at_its_end() {
        // CR-only line endings (old Mac files): the whole file is one line for the renderer.
        let long = format!("{{\r{}\r", "\"k\": 1,\r".repeat(30));
        for at in [long.len() - 1, long.len()] {
            let e = excerpt(&long, token_at(&long, at));
            assert_eq!(e.span, e.text.len()..e.text.len());
            assert_eq!(e.text.len(), 3 + CONTEXT);
            assert!(
                e.text.starts_with("...") && e.text.ends_with("1,\r"),
                "{:?}",
                e.text
            );
        }
        let short = "{\r\"k\": 1\r";
        let e = excerpt(short, token_at(short, short.len()));
        assert_eq!((e.text.as_str(), e.span), ("{\r\"k\": 1", 8..8));
    }

    #[test]
    fn line_and_column_give_the_byte_offset_clipped_to_the_line() {
        let text = "ab\nçd\n";
        assert_eq!(offset_of(text, 1, 1), 0);
        assert_eq!(offset_of(text, 2, 2), 5);
        assert_eq!(offset_of(text, 2, 9), 6);
        assert_eq!(offset_of(text, 3, 1), 7);
        assert_eq!(offset_of(text, 9, 1), 7);
    }
}
