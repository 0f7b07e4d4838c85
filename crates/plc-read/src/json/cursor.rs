//! A cursor over JSON text (RFC 8259): the tokens the program reader needs, in one pass, with
//! the byte offset of every value at hand.
//!
//! Invariants: the cursor accepts exactly the JSON that `serde_json` reads into values (the same
//! grammar, whitespace, escapes — no lone surrogates —, numbers read by `serde_json` itself,
//! nesting below 128 levels) and
//! stops with [`Fail`] at the first byte that is not; it never says why — the caller asks
//! `serde_json` for the message, so that a syntax error reads the same whichever reader met it.
//! Strings without escapes borrow from the text; strings with escapes are decoded by
//! `serde_json` (rare in program files).
//!
//! Deliberately not here: what any value means (the readers in `ladder`, `element` and `mod`).

use plc_syntax::{Origin, Scalar, Text};
use std::borrow::Cow;

/// The text is not JSON here (the message comes from `serde_json`, see [`super::parse`]).
#[derive(Debug)]
pub(super) struct Fail;

pub(super) type P<T> = Result<T, Fail>;

/// `serde_json`'s nesting limit: documents nested deeper are refused.
const MAX_DEPTH: u32 = 128;

pub(super) struct Cursor<'a> {
    text: &'a str,
    pos: usize,
    depth: u32,
}

impl<'a> Cursor<'a> {
    /// A cursor at byte `pos` of `text` (after a byte-order mark, say).
    pub(super) fn new(text: &'a str, pos: usize) -> Cursor<'a> {
        Cursor {
            text,
            pos,
            depth: 0,
        }
    }

    #[inline]
    fn bytes(&self) -> &'a [u8] {
        self.text.as_bytes()
    }

    /// Skips whitespace and returns the next byte (none at the end).
    #[inline]
    pub(super) fn peek(&mut self) -> Option<u8> {
        let bytes = self.bytes();
        while let Some(&b) = bytes.get(self.pos) {
            if !matches!(b, b' ' | b'\n' | b'\r' | b'\t') {
                return Some(b);
            }
            self.pos += 1;
        }
        None
    }

    /// Where the next value starts (after whitespace).
    #[inline]
    pub(super) fn origin(&mut self) -> Origin {
        self.peek();
        Origin::at(self.pos)
    }

    /// The whole text.
    pub(super) fn text(&self) -> &'a str {
        self.text
    }

    /// The text from byte `start` to the cursor.
    pub(super) fn since(&self, start: usize) -> &'a str {
        &self.text[start..self.pos]
    }

    /// Bytes of text after the cursor.
    pub(super) fn remaining(&self) -> usize {
        self.text.len() - self.pos
    }

    pub(super) fn offset(&mut self) -> usize {
        self.peek();
        self.pos
    }

    /// The end of the document: only whitespace may follow.
    pub(super) fn end(&mut self) -> P<()> {
        match self.peek() {
            None => Ok(()),
            Some(_) => Err(Fail),
        }
    }

    fn enter(&mut self) -> P<()> {
        self.depth += 1;
        if self.depth > MAX_DEPTH {
            return Err(Fail);
        }
        self.pos += 1;
        Ok(())
    }

    /// At `{`: enters the object (then [`Cursor::key`] until it says the object ended).
    pub(super) fn begin_object(&mut self) -> P<()> {
        self.enter()
    }

    /// At `[`: enters the array (then [`Cursor::item`] until it says the array ended).
    pub(super) fn begin_array(&mut self) -> P<()> {
        self.enter()
    }

    /// The next key of the object entered last, with the cursor left at its value; `None` after
    /// the closing `}`. `first` is true before the first key (and is cleared).
    #[inline]
    pub(super) fn key(&mut self, first: &mut bool) -> P<Option<(Text<'a>, Origin)>> {
        let b = self.peek().ok_or(Fail)?;
        if b == b'}' {
            self.pos += 1;
            self.depth -= 1;
            return Ok(None);
        }
        if !std::mem::take(first) {
            if b != b',' {
                return Err(Fail);
            }
            self.pos += 1;
        }
        let origin = self.origin();
        let key = self.string()?;
        if self.peek() != Some(b':') {
            return Err(Fail);
        }
        self.pos += 1;
        self.peek();
        Ok(Some((key, origin)))
    }

    /// True with the cursor at the next item of the array entered last; false after the
    /// closing `]`. `first` is true before the first item (and is cleared).
    #[inline]
    pub(super) fn item(&mut self, first: &mut bool) -> P<bool> {
        let b = self.peek().ok_or(Fail)?;
        if b == b']' {
            self.pos += 1;
            self.depth -= 1;
            return Ok(false);
        }
        if !std::mem::take(first) {
            if b != b',' {
                return Err(Fail);
            }
            self.pos += 1;
            self.peek();
        }
        Ok(true)
    }

    /// At `"`: a string.
    #[inline]
    pub(super) fn string(&mut self) -> P<Text<'a>> {
        let bytes = self.bytes();
        if bytes.get(self.pos) != Some(&b'"') {
            return Err(Fail);
        }
        let start = self.pos + 1;
        let mut i = start;
        loop {
            match bytes.get(i) {
                None => return Err(Fail),
                Some(b'"') => {
                    self.pos = i + 1;
                    return Ok(Cow::Borrowed(&self.text[start..i]));
                }
                Some(b'\\') => return self.escaped(start - 1, i),
                Some(&b) if b < 0x20 => return Err(Fail),
                Some(_) => i += 1,
            }
        }
    }

    /// A string with escapes, from its opening quote at `open` (the first escape is at `i`).
    #[cold]
    fn escaped(&mut self, open: usize, mut i: usize) -> P<Text<'a>> {
        let bytes = self.bytes();
        loop {
            match bytes.get(i) {
                None => return Err(Fail),
                Some(b'"') => break,
                Some(b'\\') => i += 2,
                Some(_) => i += 1,
            }
        }
        let s: String = serde_json::from_str(&self.text[open..=i]).map_err(|_| Fail)?;
        self.pos = i + 1;
        Ok(Cow::Owned(s))
    }

    /// Any value, kept as a leaf: arrays and objects are checked and skipped, only their kind
    /// kept.
    pub(super) fn scalar(&mut self) -> P<Scalar<'a>> {
        match self.peek().ok_or(Fail)? {
            b'"' => self.string().map(Scalar::Str),
            b'{' => {
                self.skip()?;
                Ok(Scalar::Object)
            }
            b'[' => {
                self.skip()?;
                Ok(Scalar::Array)
            }
            b't' => self.literal(b"true", Scalar::Bool(true)),
            b'f' => self.literal(b"false", Scalar::Bool(false)),
            b'n' => self.literal(b"null", Scalar::Null),
            b'-' | b'0'..=b'9' => self.number(),
            _ => Err(Fail),
        }
    }

    fn literal(&mut self, word: &[u8], value: Scalar<'a>) -> P<Scalar<'a>> {
        if self.bytes()[self.pos..].starts_with(word) {
            self.pos += word.len();
            Ok(value)
        } else {
            Err(Fail)
        }
    }

    fn digits(&mut self) -> usize {
        let bytes = self.bytes();
        let start = self.pos;
        while bytes.get(self.pos).is_some_and(u8::is_ascii_digit) {
            self.pos += 1;
        }
        self.pos - start
    }

    /// A number (the JSON grammar checked here, the value read by `serde_json`).
    fn number(&mut self) -> P<Scalar<'a>> {
        let text = self.number_text()?;
        let n: serde_json::Number = serde_json::from_str(text).map_err(|_| Fail)?;
        Ok(Scalar::Number(n))
    }

    /// The text of a number, its grammar checked (not its range: skipping does not).
    fn number_text(&mut self) -> P<&'a str> {
        let start = self.pos;
        let bytes = self.bytes();
        if bytes[self.pos] == b'-' {
            self.pos += 1;
        }
        match bytes.get(self.pos) {
            Some(b'0') => self.pos += 1,
            Some(b'1'..=b'9') => {
                self.digits();
            }
            _ => return Err(Fail),
        }
        if bytes.get(self.pos) == Some(&b'.') {
            self.pos += 1;
            if self.digits() == 0 {
                return Err(Fail);
            }
        }
        if matches!(bytes.get(self.pos), Some(b'e' | b'E')) {
            self.pos += 1;
            if matches!(bytes.get(self.pos), Some(b'+' | b'-')) {
                self.pos += 1;
            }
            if self.digits() == 0 {
                return Err(Fail);
            }
        }
        Ok(self.since(start))
    }

    /// At `"`: skips a string, checking its escapes as `serde_json` does when it skips one
    /// (the hex digits of `\u`, not what they encode).
    fn skip_string(&mut self) -> P<()> {
        let bytes = self.bytes();
        let mut i = self.pos + 1;
        loop {
            match bytes.get(i) {
                None => return Err(Fail),
                Some(b'"') => {
                    self.pos = i + 1;
                    return Ok(());
                }
                Some(b'\\') => match bytes.get(i + 1) {
                    Some(b'"' | b'\\' | b'/' | b'b' | b'f' | b'n' | b'r' | b't') => i += 2,
                    Some(b'u') => {
                        let hex = bytes.get(i + 2..i + 6).ok_or(Fail)?;
                        if !hex.iter().all(u8::is_ascii_hexdigit) {
                            return Err(Fail);
                        }
                        i += 6;
                    }
                    _ => return Err(Fail),
                },
                Some(&b) if b < 0x20 => return Err(Fail),
                Some(_) => i += 1,
            }
        }
    }

    /// Skips any value (checking it), without recursion: skipped values may nest as deep as
    /// they like (as `serde_json` skips them).
    pub(super) fn skip(&mut self) -> P<()> {
        // The containers the cursor is in: true for an object.
        let mut open: Vec<bool> = Vec::new();
        loop {
            // At a value.
            match self.peek().ok_or(Fail)? {
                b'{' => {
                    self.pos += 1;
                    if self.peek() == Some(b'}') {
                        self.pos += 1;
                    } else {
                        open.push(true);
                        self.skip_key()?;
                        continue;
                    }
                }
                b'[' => {
                    self.pos += 1;
                    if self.peek() == Some(b']') {
                        self.pos += 1;
                    } else {
                        open.push(false);
                        continue;
                    }
                }
                b'"' => self.skip_string()?,
                b'-' | b'0'..=b'9' => {
                    self.number_text()?;
                }
                _ => {
                    self.scalar()?;
                }
            }
            // After a value: close what ends here, then on to the next value (or done).
            loop {
                let Some(&object) = open.last() else {
                    return Ok(());
                };
                match self.peek() {
                    Some(b',') => {
                        self.pos += 1;
                        if object {
                            self.skip_key()?;
                        }
                        break;
                    }
                    Some(b'}') if object => {
                        self.pos += 1;
                        open.pop();
                    }
                    Some(b']') if !object => {
                        self.pos += 1;
                        open.pop();
                    }
                    _ => return Err(Fail),
                }
            }
        }
    }

    /// A key and its colon, skipped.
    fn skip_key(&mut self) -> P<()> {
        if self.peek() != Some(b'"') {
            return Err(Fail);
        }
        self.skip_string()?;
        if self.peek() != Some(b':') {
            return Err(Fail);
        }
        self.pos += 1;
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn ok(text: &str) -> bool {
        let mut c = Cursor::new(text, 0);
        c.skip().and_then(|()| c.end()).is_ok()
    }

    #[test]
    fn accepts_what_serde_json_accepts() {
        let cases = [
            "{}",
            "[]",
            " { \"a\" : [1, -0, 0.5, 1e3, -2E-2, true, false, null, \"x\\ny\\u00e9\"] }\n",
            "[[[]]]",
            "{\"a\":}",
            "[1,]",
            "[01]",
            "[1.]",
            "[.5]",
            "[-]",
            "[1e]",
            "\"a\tb\"",
            "\"\\x\"",
            "\"\\ud800\"",
            "\"\\u12\"",
            "[1] 2",
            "{\"a\" 1}",
            "{1: 2}",
            "[tru]",
            "[1e999]",
            "",
            "{\"a\":1,}",
        ];
        // Skipping checks what serde_json checks when it skips (the syntax of escapes, any
        // depth), reading what it checks when it reads values (escapes decode, 128 levels).
        for text in cases {
            let serde = serde_json::from_str::<serde::de::IgnoredAny>(text).is_ok();
            assert_eq!(ok(text), serde, "{text:?}");
        }
        let leaves = [
            "1e999",
            "\"\\ud800\"",
            "\"\\u00e9\"",
            "-0",
            "01",
            "1.5e3",
            "nul",
        ];
        for text in leaves {
            let serde = serde_json::from_str::<serde_json::Value>(text).is_ok();
            let mut c = Cursor::new(text, 0);
            assert_eq!(c.scalar().and_then(|_| c.end()).is_ok(), serde, "{text:?}");
        }
        for depth in [127, 128, 200] {
            let text = "[".repeat(depth) + &"]".repeat(depth);
            let serde = serde_json::from_str::<serde::de::IgnoredAny>(&text).is_ok();
            assert_eq!(ok(&text), serde, "{depth}");
        }
    }

    #[test]
    fn strings_borrow_unless_escaped_and_numbers_read_as_serde_json_does() {
        let mut c = Cursor::new(r#""abc" "a\"b" -0 12 1.5"#, 0);
        assert!(matches!(c.scalar(), Ok(Scalar::Str(Cow::Borrowed("abc")))));
        match c.scalar() {
            Ok(Scalar::Str(Cow::Owned(s))) => assert_eq!(s, "a\"b"),
            other => panic!("{other:?}"),
        }
        for want in ["-0.0", "12", "1.5"] {
            match c.scalar() {
                Ok(Scalar::Number(n)) => assert_eq!(n.to_string(), want),
                other => panic!("{other:?}"),
            }
        }
        assert_eq!(c.origin(), Origin::at(22));
    }
}
