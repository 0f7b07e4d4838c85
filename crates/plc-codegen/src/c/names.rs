//! Names of the generated C: every identifier and file name comes from a program name through
//! one of the injective encodings below, so that no program name can change the meaning of the C
//! or write outside the output folder.
//!
//! Invariants:
//! - every user name gets a prefix: a C identifier that does not start with `_` becomes `_v_` +
//!   the name as written (`self->_v_Start`), any other `_u` + [`encode_ident`] of it (injective,
//!   so two names never meet). An identifier that starts with `_` and a lower-case letter is
//!   never a macro of a C library header (the C standard leaves that space to programs outside
//!   file scope, and user names are only struct members), so no header, whatever its feature
//!   macros (`P_tmpdir`, `WNOHANG`, `M_PI`, `errno`, `stdin`, `NULL` without `-std=c11`), and no
//!   keyword can change the C's meaning;
//! - every name the generator makes up starts with `_` and never with `_u` or `_v`, so it meets
//!   no user name;
//! - file names use [`encode_file`]: lower-case letters, digits and `_` only (case-folded, so two
//!   POUs never share a file on a case-insensitive file system), no `.`/`/`, at most 80 bytes.
//!
//! Not here: what a name denotes (the emitters decide), C string literals ([`c_string`]) which
//! quote any text byte by byte.

/// True for `[A-Za-z][A-Za-z0-9_]*`.
fn is_plain_identifier(s: &str) -> bool {
    let mut b = s.bytes();
    matches!(b.next(), Some(c) if c.is_ascii_alphabetic())
        && b.all(|c| c.is_ascii_alphanumeric() || c == b'_')
}

/// Letters and digits as they are, `_` as `__`, any other byte as `_` and three decimal digits.
pub fn encode_ident(s: &str) -> String {
    let mut out = String::with_capacity(s.len() + 4);
    for b in s.bytes() {
        match b {
            b'_' => out.push_str("__"),
            c if c.is_ascii_alphanumeric() => out.push(c as char),
            c => out.push_str(&format!("_{c:03}")),
        }
    }
    out
}

/// The C identifier of a user name (a struct member): `_v_` + the name when it is a plain
/// identifier, else `_u` + its encoding.
pub fn user_ident(name: &str) -> String {
    if is_plain_identifier(name) {
        format!("_v_{name}")
    } else {
        format!("_u{}", encode_ident(name))
    }
}

/// A file-name stem: lower-case letters and digits as they are, `_` as `__`, an upper-case letter
/// as `_` + its lower case, any other byte as `_` + three decimal digits. Longer than 64 bytes:
/// cut at 64 and `-` + `index` appended (no encoding makes a `-`, so it stays unique).
pub fn encode_file(s: &str, index: usize) -> String {
    let mut out = String::with_capacity(s.len() + 4);
    for b in s.bytes() {
        match b {
            b'_' => out.push_str("__"),
            c if c.is_ascii_lowercase() || c.is_ascii_digit() => out.push(c as char),
            c if c.is_ascii_uppercase() => {
                out.push('_');
                out.push(c.to_ascii_lowercase() as char);
            }
            c => out.push_str(&format!("_{c:03}")),
        }
    }
    if out.len() > 64 {
        out.truncate(64);
        out.push_str(&format!("-{index}"));
    }
    out
}

/// A C string literal holding `text` exactly: printable ASCII but `"`, `\` and `?` (trigraphs)
/// as it is, every other byte as a three-digit octal escape.
pub fn c_string(text: &str) -> String {
    c_bytes(text.as_bytes())
}

/// A C string literal holding the bytes `bytes` exactly (as [`c_string`]; any byte but printable
/// ASCII as an octal escape, so a NUL is `\000`).
pub fn c_bytes(bytes: &[u8]) -> String {
    let mut out = String::with_capacity(bytes.len() + 2);
    out.push('"');
    for &b in bytes {
        if (0x20..0x7f).contains(&b) && b != b'"' && b != b'\\' && b != b'?' {
            out.push(b as char);
        } else {
            out.push_str(&format!("\\{b:03o}"));
        }
    }
    out.push('"');
    out
}

/// Text safe inside a C comment: printable ASCII only, `*/` broken up, anything else `?`.
pub fn comment(text: &str) -> String {
    let s: String = text
        .chars()
        .map(|c| if (' '..='~').contains(&c) { c } else { '?' })
        .collect();
    s.replace("*/", "*?/").replace("/*", "/?*")
}

/// `text` as a JSON string (with its quotes), escaped as `serde_json` escapes it.
pub fn json_string(text: &str) -> String {
    serde_json::to_string(text).expect("a string always serializes")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn identifiers() {
        assert_eq!(user_ident("Var1"), "_v_Var1");
        assert_eq!(user_ident("int"), "_v_int");
        assert_eq!(user_ident("P_tmpdir"), "_v_P_tmpdir");
        assert_eq!(user_ident("_x"), "_u__x");
        assert_eq!(user_ident("a.b"), "_ua_046b");
        assert_eq!(user_ident("INT16_MAX"), "_v_INT16_MAX");
        assert_ne!(user_ident("a_b"), user_ident("a.b"));
    }

    #[test]
    fn files_and_strings() {
        assert_eq!(encode_file("Main", 0), "_main");
        assert_eq!(encode_file("../x", 0), "_046_046_047x");
        assert_ne!(encode_file("A", 0), encode_file("a", 1));
        assert_eq!(encode_file(&"a".repeat(100), 7).len(), 66);
        assert_eq!(c_string("a\"b\n"), "\"a\\042b\\012\"");
        assert_eq!(comment("x */ y"), "x *?/ y");
    }
}
