//! The tokens of Structured Text (IEC 61131-3, 3rd edition, 7.3 and the common elements of
//! 6.1–6.3): identifiers and keywords (case-insensitive), numeric, typed, time and string
//! literals, direct addresses (`%IX0.1`), operators and punctuation; comments `(* … *)` (which
//! may nest, as CODESYS allows), `// …`; pragmas `{ … }` and `{{ … }}` (Beremiz's C code) are
//! tokens of their own ([`Tok::Pragma`]), delimited as matiec delimits them
//! (`stage1_2/iec_flex.ll`: `"{"[^}]*"}"`, or `"{{"` up to the first `"}}"`).
//!
//! Comments: nested first; when a `(*` is then left unclosed, the text is read again with flat
//! comments (each `(*` closed by the first `*)`), which is how matiec reads them unless given
//! `-n` (and Beremiz does not give it): `(* a (* b *)` is one whole comment there.
//!
//! Every token has its byte offset in the text. A character that starts no token, an
//! unterminated comment or string: one error at its offset.
//!
//! Deliberately not here: the value of literals beyond their text (the parser and the resolver
//! type them), keywords as a closed list (the parser asks for the ones it needs).

/// A token and where it starts.
#[derive(Clone, Debug, PartialEq)]
pub struct Token<'a> {
    pub at: usize,
    pub kind: Tok<'a>,
}

#[derive(Clone, Debug, PartialEq)]
pub enum Tok<'a> {
    /// An identifier or keyword, as written.
    Ident(&'a str),
    /// A literal as written: `12`, `16#FF`, `2.5E3`, `INT#5`, `T#1s`, `TRUE`-free (those are
    /// identifiers), `'text'`.
    Literal(&'a str),
    /// `%IX0.1`, `%MW10`.
    Direct(&'a str),
    /// An operator or punctuation: `:=`, `=>`, `<=`, `>=`, `<>`, `**`, `..`, or one character.
    Sym(&'a str),
    /// A pragma as written, braces included: `{attribute 'x'}`, `{{ C code }}`.
    Pragma(&'a str),
}

/// A lexical error: where and what.
#[derive(Clone, Debug, PartialEq)]
pub struct LexError {
    pub at: usize,
    pub message: String,
}

const TWO: &[&str] = &[":=", "=>", "<=", ">=", "<>", "**", ".."];
const ONE: &str = "+-*/=<>()[],;:.&^#";

/// The tokens of `text`: comments nested, else (a `(*` left unclosed) flat as matiec reads
/// them.
pub fn tokens(text: &str) -> Result<Vec<Token<'_>>, LexError> {
    match tokens_with(text, true) {
        Err(e) if e.message.starts_with("a comment") => tokens_with(text, false).map_err(|_| e),
        r => r,
    }
}

/// The end of the pragma opened at `i`: `{{ … }}` up to the first `}}`, `{ … }` up to the
/// first `}` (matiec's two rules, the longer match first).
fn pragma_end(text: &str, i: usize) -> Option<usize> {
    if text[i..].starts_with("{{") {
        if let Some(n) = text[i + 2..].find("}}") {
            return Some(i + 2 + n + 2);
        }
    }
    text[i..].find('}').map(|n| i + n + 1)
}

fn tokens_with(text: &str, nested: bool) -> Result<Vec<Token<'_>>, LexError> {
    let b = text.as_bytes();
    let mut out = Vec::new();
    let mut i = 0;
    let err = |at: usize, m: &str| LexError {
        at,
        message: m.to_owned(),
    };
    while i < b.len() {
        let c = b[i];
        if c.is_ascii_whitespace() {
            i += 1;
        } else if text[i..].starts_with("(*") {
            let end = if nested {
                comment_end(text, i)
            } else {
                text[i + 2..].find("*)").map(|n| i + 2 + n + 2)
            };
            i = end.ok_or_else(|| err(i, "a comment `(*` is not closed"))?;
        } else if text[i..].starts_with("//") {
            i = text[i..].find('\n').map_or(b.len(), |n| i + n);
        } else if c == b'{' {
            let end = pragma_end(text, i).ok_or_else(|| err(i, "a pragma `{` is not closed"))?;
            out.push(Token {
                at: i,
                kind: Tok::Pragma(&text[i..end]),
            });
            i = end;
        } else if c == b'\'' || c == b'"' {
            let end = string_end(b, i).ok_or_else(|| err(i, "a string is not closed"))?;
            out.push(Token {
                at: i,
                kind: Tok::Literal(&text[i..end]),
            });
            i = end;
        } else if c == b'%' {
            let end = scan(b, i + 1, |c| {
                c.is_ascii_alphanumeric() || c == b'.' || c == b'_'
            });
            if end == i + 1 {
                return Err(err(i, "`%` starts no direct address"));
            }
            out.push(Token {
                at: i,
                kind: Tok::Direct(&text[i..end]),
            });
            i = end;
        } else if c.is_ascii_digit() {
            let end = number_end(b, i);
            out.push(Token {
                at: i,
                kind: Tok::Literal(&text[i..end]),
            });
            i = end;
        } else if c.is_ascii_alphabetic() || c == b'_' {
            let end = scan(b, i, |c| c.is_ascii_alphanumeric() || c == b'_');
            if b.get(end) == Some(&b'#') {
                // A typed or time literal: `INT#5`, `T#1h2m`, `16#FF` is a number (above).
                let lit_end = literal_tail(b, end + 1);
                out.push(Token {
                    at: i,
                    kind: Tok::Literal(&text[i..lit_end]),
                });
                i = lit_end;
            } else {
                out.push(Token {
                    at: i,
                    kind: Tok::Ident(&text[i..end]),
                });
                i = end;
            }
        } else if let Some(s) = TWO.iter().find(|s| text[i..].starts_with(**s)) {
            out.push(Token {
                at: i,
                kind: Tok::Sym(s),
            });
            i += 2;
        } else if ONE.as_bytes().contains(&c) {
            out.push(Token {
                at: i,
                kind: Tok::Sym(&text[i..i + 1]),
            });
            i += 1;
        } else {
            let ch = text[i..].chars().next().unwrap_or('?');
            return Err(err(i, &format!("`{ch}` starts no Structured Text token")));
        }
    }
    Ok(out)
}

fn scan(b: &[u8], mut i: usize, keep: impl Fn(u8) -> bool) -> usize {
    while i < b.len() && keep(b[i]) {
        i += 1;
    }
    i
}

/// The end of a `(* … *)` comment starting at `i` (comments may nest).
fn comment_end(text: &str, mut i: usize) -> Option<usize> {
    let mut depth = 0usize;
    while i < text.len() {
        if text[i..].starts_with("(*") {
            depth += 1;
            i += 2;
        } else if text[i..].starts_with("*)") {
            depth -= 1;
            i += 2;
            if depth == 0 {
                return Some(i);
            }
        } else {
            i += text[i..].chars().next().map_or(1, char::len_utf8);
        }
    }
    None
}

/// The end of a string literal opened at `i` (`$` escapes the next character; a doubled
/// quote is not special in IEC strings, `$'` is).
fn string_end(b: &[u8], i: usize) -> Option<usize> {
    let q = b[i];
    let mut j = i + 1;
    while j < b.len() {
        match b[j] {
            b'$' => j += 2,
            c if c == q => return Some(j + 1),
            _ => j += 1,
        }
    }
    None
}

/// A number: digits and `_`, a base `16#…`, a fraction, an exponent.
fn number_end(b: &[u8], i: usize) -> usize {
    let mut j = scan(b, i, |c| c.is_ascii_digit() || c == b'_');
    if b.get(j) == Some(&b'#') {
        return scan(b, j + 1, |c| c.is_ascii_hexdigit() || c == b'_');
    }
    if b.get(j) == Some(&b'.') && b.get(j + 1).is_some_and(|c| c.is_ascii_digit()) {
        j = scan(b, j + 1, |c| c.is_ascii_digit() || c == b'_');
    }
    if matches!(b.get(j), Some(b'e' | b'E')) {
        let k = j + 1 + usize::from(matches!(b.get(j + 1), Some(b'+' | b'-')));
        if b.get(k).is_some_and(|c| c.is_ascii_digit()) {
            j = scan(b, k, |c| c.is_ascii_digit());
        }
    }
    j
}

/// The rest of a typed or time literal after `#`: a number, a time or date (`1h2m3s`,
/// `2024-01-01`, `12:00:00`), a string or an identifier (an enumerated value).
fn literal_tail(b: &[u8], i: usize) -> usize {
    if matches!(b.get(i), Some(b'\'' | b'"')) {
        return string_end(b, i).unwrap_or(b.len());
    }
    let start = i + usize::from(matches!(b.get(i), Some(b'-' | b'+')));
    scan(b, start, |c| {
        c.is_ascii_alphanumeric() || matches!(c, b'_' | b'.' | b'#' | b':' | b'-')
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn kinds(text: &str) -> Vec<Tok<'_>> {
        tokens(text).unwrap().into_iter().map(|t| t.kind).collect()
    }

    #[test]
    fn literals_operators_comments_and_pragmas() {
        use Tok::*;
        assert_eq!(
            kinds("x := 16#FF + INT#-5 (* a (* nested *) one *) ** 2.5E3; // end\n{pragma} t := T#1h2m;"),
            vec![
                Ident("x"), Sym(":="), Literal("16#FF"), Sym("+"), Literal("INT#-5"),
                Sym("**"), Literal("2.5E3"), Sym(";"), Pragma("{pragma}"), Ident("t"), Sym(":="),
                Literal("T#1h2m"), Sym(";")
            ]
        );
        assert_eq!(
            kinds("IF a <> 'it$'s' THEN %QX0.1 := b >= 1..3; END_IF"),
            vec![
                Ident("IF"),
                Ident("a"),
                Sym("<>"),
                Literal("'it$'s'"),
                Ident("THEN"),
                Direct("%QX0.1"),
                Sym(":="),
                Ident("b"),
                Sym(">="),
                Literal("1"),
                Sym(".."),
                Literal("3"),
                Sym(";"),
                Ident("END_IF")
            ]
        );
    }

    #[test]
    fn unterminated_and_stray_characters_are_located() {
        assert_eq!(tokens("a := 1; (* open").unwrap_err().at, 8);
        assert_eq!(tokens("a := 'x").unwrap_err().at, 5);
        let e = tokens("a := b ? c").unwrap_err();
        assert_eq!(
            (e.at, e.message.as_str()),
            (7, "`?` starts no Structured Text token")
        );
    }
}
