//! Names of the generated C: every identifier and file name comes from a program name through
//! one of the injective encodings below, so that no program name can change the meaning of the C
//! or write outside the output folder.
//!
//! Invariants:
//! - a user name is kept as written only when it is a C identifier that does not start with `_`
//!   and is neither a C keyword nor a name the included standard headers may define as a macro;
//!   any other name becomes `_u` + [`encode_ident`] of it (injective, so two names never meet);
//! - every name the generator makes up starts with `_` and never with `_u`, so it meets neither
//!   a kept user name nor an encoded one;
//! - file names use [`encode_file`]: lower-case letters, digits and `_` only (case-folded, so two
//!   POUs never share a file on a case-insensitive file system), no `.`/`/`, at most 80 bytes.
//!
//! Not here: what a name denotes (the emitters decide), C string literals ([`c_string`]) which
//! quote any text byte by byte.

/// C11/C23 keywords and the macros of `<stdbool.h> <stdint.h> <stdio.h> <stdlib.h> <string.h>
/// <math.h>` that a struct member or local could collide with, plus the parameter names of the
/// generated functions.
const RESERVED: &[&str] = &[
    "auto",
    "break",
    "case",
    "char",
    "const",
    "continue",
    "default",
    "do",
    "double",
    "else",
    "enum",
    "extern",
    "float",
    "for",
    "goto",
    "if",
    "inline",
    "int",
    "long",
    "register",
    "restrict",
    "return",
    "short",
    "signed",
    "sizeof",
    "static",
    "struct",
    "switch",
    "typedef",
    "union",
    "unsigned",
    "void",
    "volatile",
    "while",
    "bool",
    "true",
    "false",
    "alignas",
    "alignof",
    "constexpr",
    "nullptr",
    "static_assert",
    "thread_local",
    "typeof",
    "typeof_unqual",
    "asm",
    "fortran",
    "NULL",
    "EOF",
    "BUFSIZ",
    "FILENAME_MAX",
    "FOPEN_MAX",
    "L_tmpnam",
    "TMP_MAX",
    "SEEK_SET",
    "SEEK_CUR",
    "SEEK_END",
    "stdin",
    "stdout",
    "stderr",
    "EXIT_SUCCESS",
    "EXIT_FAILURE",
    "RAND_MAX",
    "MB_CUR_MAX",
    "errno",
    "assert",
    "offsetof",
    "HUGE_VAL",
    "HUGE_VALF",
    "HUGE_VALL",
    "INFINITY",
    "NAN",
    "FP_NAN",
    "FP_INFINITE",
    "FP_ZERO",
    "FP_SUBNORMAL",
    "FP_NORMAL",
    "FP_FAST_FMA",
    "FP_FAST_FMAF",
    "FP_ILOGB0",
    "FP_ILOGBNAN",
    "MATH_ERRNO",
    "MATH_ERREXCEPT",
    "math_errhandling",
    "fpclassify",
    "isfinite",
    "isinf",
    "isnan",
    "isnormal",
    "signbit",
    "isgreater",
    "isgreaterequal",
    "isless",
    "islessequal",
    "islessgreater",
    "isunordered",
    "getc",
    "putc",
    "getchar",
    "putchar",
    "self",
    "ctx",
    "main",
    "unix",
    "linux",
    "i386",
];

fn is_reserved(s: &str) -> bool {
    RESERVED.contains(&s)
        || s.starts_with("INT")
        || s.starts_with("UINT")
        || s.starts_with("SIZE_")
        || s.starts_with("PTRDIFF_")
        || s.starts_with("WCHAR_")
        || s.starts_with("WINT_")
        || s.starts_with("SIG_ATOMIC_")
        || s.starts_with("PRI")
        || s.starts_with("SCN")
        || s.starts_with("M_")
        || s.starts_with("__")
}

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

/// The C identifier of a user name (a variable, a struct member): the name itself when that is
/// safe, else `_u` + its encoding.
pub fn user_ident(name: &str) -> String {
    if is_plain_identifier(name) && !is_reserved(name) {
        name.to_string()
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
    let mut out = String::with_capacity(text.len() + 2);
    out.push('"');
    for b in text.bytes() {
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
        assert_eq!(user_ident("Var1"), "Var1");
        assert_eq!(user_ident("int"), "_uint");
        assert_eq!(user_ident("_x"), "_u__x");
        assert_eq!(user_ident("a.b"), "_ua_046b");
        assert_eq!(user_ident("INT16_MAX"), "_uINT16__MAX");
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
