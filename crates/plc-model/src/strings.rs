//! IEC 61131-3 STRING values of the model: the literal syntax (6.3.3, `'…'` with `$` escapes)
//! and the interned bytes a string constant ([`Value::Str`](super::Value::Str)) names.
//!
//! A STRING is a sequence of bytes of at most [`STR_MAX_LEN`] (126, matiec's `STR_MAX_LEN` of
//! `lib/C/iec_types.h`: a length byte and a 126-byte body); a longer literal is cut to 126 bytes
//! as matiec's `__STRING_LITERAL` copy would. A constant's bytes are interned once per process
//! ([`intern`]) so that a [`Value`](super::Value) stays `Copy` and 12 bytes: the id is the
//! value, equal texts get equal ids, and the empty string is id 0 (the zero value). The table
//! only grows (by the distinct literals of the programs read), never shrinks.
//!
//! Not here: what the string functions compute (`plc_exec::strings`), WSTRING (not modelled).

use std::collections::HashMap;
use std::sync::{Mutex, OnceLock};

/// The maximum length of a STRING in bytes (matiec's `STR_MAX_LEN`).
pub const STR_MAX_LEN: usize = 126;

/// An interned string constant.
#[derive(Copy, Clone, Debug, PartialEq, Eq, Hash)]
pub struct StrId(pub u32);

#[derive(Default)]
struct Table {
    texts: Vec<&'static [u8]>,
    ids: HashMap<&'static [u8], u32>,
}

fn table() -> &'static Mutex<Table> {
    static T: OnceLock<Mutex<Table>> = OnceLock::new();
    T.get_or_init(|| {
        let mut t = Table::default();
        t.texts.push(b"");
        t.ids.insert(b"", 0);
        Mutex::new(t)
    })
}

/// The id of the string `bytes` (cut to [`STR_MAX_LEN`]).
pub fn intern(bytes: &[u8]) -> StrId {
    let bytes = &bytes[..bytes.len().min(STR_MAX_LEN)];
    let mut t = table().lock().unwrap_or_else(|e| e.into_inner());
    if let Some(&id) = t.ids.get(bytes) {
        return StrId(id);
    }
    let leaked: &'static [u8] = Box::leak(bytes.to_vec().into_boxed_slice());
    let id = t.texts.len() as u32;
    t.texts.push(leaked);
    t.ids.insert(leaked, id);
    StrId(id)
}

/// The bytes of an interned string (empty for an id [`intern`] never gave).
pub fn str_bytes(id: StrId) -> &'static [u8] {
    let t = table().lock().unwrap_or_else(|e| e.into_inner());
    t.texts.get(id.0 as usize).copied().unwrap_or(b"")
}

/// The bytes of IEC string literal `text` (`'…'`, quotes included; IEC 61131-3 6.3.3 Table 7):
/// `$$` `$'` `$L` `$N` `$P` `$R` `$T` (either case) and `$hh` (two hex digits); `"` stands
/// for itself. `None` when `text` is no single-quoted literal or an escape is bad.
pub fn parse_string_literal(text: &str) -> Option<Vec<u8>> {
    let body = text.strip_prefix('\'')?.strip_suffix('\'')?;
    let b = body.as_bytes();
    let mut out = Vec::with_capacity(b.len());
    let mut i = 0;
    while i < b.len() {
        let c = b[i];
        i += 1;
        match c {
            b'$' => {
                let e = *b.get(i)?;
                i += 1;
                out.push(match e.to_ascii_uppercase() {
                    b'$' => b'$',
                    b'\'' => b'\'',
                    b'"' => b'"',
                    b'L' | b'N' => b'\n',
                    b'P' => 0x0c,
                    b'R' => b'\r',
                    b'T' => b'\t',
                    h => {
                        let hi = (h as char).to_digit(16)?;
                        let lo = (*b.get(i)? as char).to_digit(16)?;
                        i += 1;
                        (hi * 16 + lo) as u8
                    }
                });
            }
            // A lone quote inside the body ends nothing in IEC: it must be written `$'`.
            b'\'' => return None,
            c => out.push(c),
        }
    }
    Some(out)
}

/// `bytes` written as an IEC string literal (`'…'`): printable ASCII as itself but `$` and
/// `'` (`$$`, `$'`), every other byte `$hh` — [`parse_string_literal`] reads it back.
pub fn string_literal(bytes: &[u8]) -> String {
    let mut s = String::with_capacity(bytes.len() + 2);
    s.push('\'');
    for &c in bytes {
        match c {
            b'$' => s.push_str("$$"),
            b'\'' => s.push_str("$'"),
            0x20..=0x7e => s.push(c as char),
            _ => s.push_str(&format!("${c:02X}")),
        }
    }
    s.push('\'');
    s
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn literals_and_escapes() {
        let p = |s| parse_string_literal(s);
        assert_eq!(p("''").unwrap(), b"");
        assert_eq!(p("'a$'b$$c'").unwrap(), b"a'b$c");
        assert_eq!(p("'$L$N$P$R$T$l'").unwrap(), b"\n\n\x0c\r\t\n");
        assert_eq!(p("'$41$0a'").unwrap(), b"A\n");
        assert_eq!(p("'\"'").unwrap(), b"\"");
        assert_eq!(p("'$4'"), None);
        assert_eq!(p("'a'b'"), None);
        assert_eq!(p("abc"), None);
        assert_eq!(string_literal(b"a'$\n"), "'a$'$$$0A'");
        assert_eq!(p(&string_literal(b"x\x00\xff")).unwrap(), b"x\x00\xff");
    }

    #[test]
    fn interning() {
        assert_eq!(intern(b""), StrId(0));
        let a = intern(b"hello");
        assert_eq!(intern(b"hello"), a);
        assert_eq!(str_bytes(a), b"hello");
        assert_eq!(str_bytes(intern(&[b'x'; 200])).len(), STR_MAX_LEN);
    }
}
