//! STRING values in state memory and what the string functions compute, as matiec's C library
//! does (`lib/C/iec_std_lib.h`, `lib/C/iec_std_functions.h`); the C runtime
//! (`crates/plc-codegen/src/c/runtime.rs`, `_plc_str_*`) mirrors it operation for operation.
//!
//! A STRING variable is a fixed slot of [`STR_SLOT`] bytes: its length (0..=126) at byte 0 and
//! its body at bytes 1..=126; a store writes every byte of the slot (the body past the length
//! and byte 127 zero), so the state — and its digest — depend only on the value. Strings live
//! only in STRING slots: a program without STRING variables has no slot and runs as before.
//!
//! Semantics (matiec, cited per function below): comparison is `__str_cmp` (bytewise `memcmp`
//! of the common length, then the longer is greater); CONCAT, INSERT, REPLACE truncate at
//! [`STR_MAX_LEN`]; LEFT, RIGHT, MID, DELETE, INSERT, REPLACE with a negative length or
//! position give the empty string (matiec's `TEST_EN_COND` returns `__INIT_STRING`, ENO false);
//! conversions to STRING print as `__bool_to_string` (`TRUE`/`FALSE`), `__sint_to_string` /
//! `__uint_to_string` (`%lld` / `%llu`) and `__bit_to_string` (`16#%llx`); STRING_TO_BOOL is
//! `__string_to_bool`, STRING_TO_<integer or bit string> `__pstring_to_sint` (then the C cast,
//! i.e. wrapping to the target width).
//!
//! Not here: WSTRING, REAL and TIME texts (the model refuses their conversions by name).

use super::store::{Addr, Store};
use plc_model::{str_bytes, Function, Type, Value, STR_MAX_LEN};
use std::cmp::Ordering;

/// Bytes of a STRING slot in the state (length byte, 126-byte body, one pad byte).
pub const STR_SLOT: u32 = 128;

/// A STRING value: at most [`STR_MAX_LEN`] bytes.
#[derive(Copy, Clone, PartialEq, Eq)]
pub struct StrBuf {
    len: u8,
    body: [u8; STR_MAX_LEN],
}

impl std::fmt::Debug for StrBuf {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(&plc_model::string_literal(self.bytes()))
    }
}

impl StrBuf {
    /// The empty string.
    pub const EMPTY: StrBuf = StrBuf {
        len: 0,
        body: [0; STR_MAX_LEN],
    };

    /// The string of `b` (cut to [`STR_MAX_LEN`]).
    pub fn new(b: &[u8]) -> StrBuf {
        let mut s = StrBuf::EMPTY;
        s.push(b);
        s
    }

    /// Its bytes.
    pub fn bytes(&self) -> &[u8] {
        &self.body[..self.len as usize]
    }

    /// Appends as much of `b` as fits.
    fn push(&mut self, b: &[u8]) {
        let n = b.len().min(STR_MAX_LEN - self.len as usize);
        let at = self.len as usize;
        self.body[at..at + n].copy_from_slice(&b[..n]);
        self.len += n as u8;
    }

    /// The text as JSON and CSV show it: each byte one character (Latin-1), so every value
    /// has one text and ASCII reads as itself.
    pub fn text(&self) -> String {
        self.bytes().iter().map(|&b| b as char).collect()
    }
}

/// The STRING at `at`.
pub fn load_str<S: Store + ?Sized>(st: &S, at: Addr) -> StrBuf {
    let mut s = StrBuf::EMPTY;
    s.len = st.load::<u8>(at).min(STR_MAX_LEN as u8);
    for i in 0..s.len as usize {
        s.body[i] = st.load::<u8>(at.offset(1 + i as u32));
    }
    s
}

/// Writes `s` at `at`: every byte of the slot.
pub fn store_str<S: Store + ?Sized>(st: &mut S, at: Addr, s: &StrBuf) {
    st.store(at, s.len);
    for i in 0..STR_MAX_LEN {
        let b = if i < s.len as usize { s.body[i] } else { 0 };
        st.store(at.offset(1 + i as u32), b);
    }
    st.store(at.offset(STR_SLOT - 1), 0u8);
}

/// The STRING of a constant (`Value::Str`); any other value the empty string.
pub fn of_value(v: Value) -> StrBuf {
    match v {
        Value::Str(id) => StrBuf::new(str_bytes(id)),
        _ => StrBuf::EMPTY,
    }
}

/// matiec's `__str_cmp`: `memcmp` of the common length, else the longer is greater.
pub fn compare(a: &StrBuf, b: &StrBuf) -> Ordering {
    let n = a.len.min(b.len) as usize;
    a.body[..n].cmp(&b.body[..n]).then(a.len.cmp(&b.len))
}

/// An argument or result of a string function: a STRING or another value.
#[derive(Copy, Clone, Debug)]
pub enum Arg {
    /// A STRING.
    Str(StrBuf),
    /// Any other value.
    Val(Value),
}

impl Arg {
    fn s(&self) -> StrBuf {
        match self {
            Arg::Str(s) => *s,
            Arg::Val(v) => of_value(*v),
        }
    }
    fn int(&self) -> i128 {
        match self {
            Arg::Val(v) => v.as_i128().unwrap_or(0),
            Arg::Str(_) => 0,
        }
    }
}

/// `func(args)` (a string function or a conversion to or from STRING) as a value of type `out`.
pub fn apply(func: Function, args: &[Arg], out: Type) -> Arg {
    use Function::*;
    let s = |i: usize| args[i].s();
    let n = |i: usize| args[i].int();
    let string = Arg::Str;
    match func {
        // CONCAT (iec_std_functions.h): each input appended while room remains.
        Concat => {
            let mut r = StrBuf::EMPTY;
            for a in args {
                r.push(a.s().bytes());
            }
            string(r)
        }
        // LEN: `__len`, IN.len, cast to the output's integer type.
        Len => int_value(s(0).len as i128, out),
        // LEFT: L < 0 gives ""; else the first min(L, len) bytes.
        Left => {
            let (a, l) = (s(0), n(1));
            if l < 0 {
                return string(StrBuf::EMPTY);
            }
            let l = (l as usize).min(a.len as usize);
            string(StrBuf::new(&a.bytes()[..l]))
        }
        // RIGHT: the last min(L, len) bytes.
        Right => {
            let (a, l) = (s(0), n(1));
            if l < 0 {
                return string(StrBuf::EMPTY);
            }
            let l = (l as usize).min(a.len as usize);
            string(StrBuf::new(&a.bytes()[a.len as usize - l..]))
        }
        // MID: if P <= len, min(L, len - P + 1) bytes from index P - 1; else "". (matiec's
        // P = 0 reads from index -1; here P = 0 is read as P = 1, the one defined choice.)
        Mid => {
            let (a, l, p) = (s(0), n(1), n(2));
            if l < 0 || p < 0 || p > a.len as i128 {
                return string(StrBuf::EMPTY);
            }
            let p = (p.max(1) - 1) as usize;
            let l = (l as usize).min(a.len as usize - p);
            string(StrBuf::new(&a.bytes()[p..p + l]))
        }
        // INSERT: `__insert`: IN1's first min(P, len1) bytes, IN2, the rest of IN1, cut at 126.
        Insert => {
            let (a, b, p) = (s(0), s(1), n(2));
            if p < 0 {
                return string(StrBuf::EMPTY);
            }
            let p = (p as u8 as usize).min(a.len as usize);
            let mut r = StrBuf::new(&a.bytes()[..p]);
            r.push(b.bytes());
            r.push(&a.bytes()[p..]);
            string(r)
        }
        // DELETE: `__delete`: IN's bytes before P (all if P > len), then those after P + L - 1.
        Delete => {
            let (a, l, p) = (s(0), n(1), n(2));
            if l < 0 || p < 0 {
                return string(StrBuf::EMPTY);
            }
            let (l, p) = (l as u8 as usize, p as u8 as usize);
            let keep = if p > a.len as usize {
                a.len as usize
            } else {
                p.max(1) - 1
            };
            let mut r = StrBuf::new(&a.bytes()[..keep]);
            if a.len as usize > keep + l {
                r.push(&a.bytes()[keep + l..]);
            }
            string(r)
        }
        // REPLACE: `__replace`: IN1 before P, min(L, len2) bytes of IN2, then IN1 from byte
        // P - 1 + L (a `__strlen_t`, so modulo 256, as matiec's `P += L`).
        Replace => {
            let (a, b, l, p) = (s(0), s(1), n(2), n(3));
            if l < 0 || p < 0 {
                return string(StrBuf::EMPTY);
            }
            let (l, p) = (l as u8 as usize, p as u8 as usize);
            let keep = if p > a.len as usize {
                a.len as usize
            } else {
                p.max(1) - 1
            };
            let mut r = StrBuf::new(&a.bytes()[..keep]);
            r.push(&b.bytes()[..l.min(b.len as usize)]);
            let after = (keep + l) as u8 as usize;
            if (r.len as usize) < STR_MAX_LEN && after < a.len as usize {
                r.push(&a.bytes()[after..]);
            }
            string(r)
        }
        // FIND: `__pfind`, its scan exactly: on a mismatch after `count2` matching bytes it
        // resumes `count2 + 1` further on (so `FIND('aab', 'ab')` is 0 in matiec too); 0 when
        // IN2 is empty or longer than IN1, else the 1-based position of the match.
        Find => {
            let (a, b) = (s(0), s(1));
            let (a, b) = (a.bytes(), b.bytes());
            let at = if b.is_empty() || a.len() < b.len() {
                0
            } else {
                let (mut c1, mut c2) = (0usize, 0usize);
                while c1 + c2 < a.len() && c2 < b.len() {
                    if a[c1 + c2] != b[c2] {
                        c1 += c2 + 1;
                        c2 = 0;
                    } else {
                        c2 += 1;
                    }
                }
                if c2 == b.len() {
                    c1 + 1
                } else {
                    0
                }
            };
            int_value(at as i128, out)
        }
        Convert {
            from,
            to: Type::String,
        } => string(to_string(args[0], from)),
        Convert { to, .. } => Arg::Val(from_string(&s(0), to)),
        _ => Arg::Val(out.zero()),
    }
}

/// An integer result of type `out`, wrapped to its width (the C cast).
fn int_value(v: i128, out: Type) -> Arg {
    Arg::Val(Value::from_bits(out, v as u64))
}

/// `<from>_TO_STRING` of `a`: `__bool_to_string`, `__sint_to_string` (`%lld`),
/// `__uint_to_string` (`%llu`), `__bit_to_string` (`16#%llx`).
fn to_string(a: Arg, from: Type) -> StrBuf {
    let Arg::Val(v) = a else { return a.s() };
    let text = match v {
        Value::Bool(b) => (if b { "TRUE" } else { "FALSE" }).to_owned(),
        v if from.is_bits() => format!("16#{:x}", v.to_bits()),
        v => v.as_i128().unwrap_or(0).to_string(),
    };
    StrBuf::new(text.as_bytes())
}

/// `STRING_TO_<to>` of `s`: `__string_to_bool` for BOOL, else `__pstring_to_sint` cast to the
/// target's width.
fn from_string(s: &StrBuf, to: Type) -> Value {
    if to == Type::Bool {
        let b = s.bytes();
        return Value::Bool(if b.len() == 1 {
            b == b"1"
        } else {
            b.eq_ignore_ascii_case(b"TRUE")
        });
    }
    Value::from_bits(to, string_to_int(s.bytes()) as u64)
}

/// matiec's `__pstring_to_sint`, digit by digit: `2#`, `8#`, `16#` prefixes read the digits of
/// their base from the right (others skipped, at most 64 bits); otherwise decimal digits from
/// the right, a `.` or any byte above it resetting the value (at most 20 digits), negative
/// when the first byte is `-`. Wrapping arithmetic, as the C's 64-bit integers on the hosts
/// matiec targets.
pub fn string_to_int(b: &[u8]) -> i64 {
    let n = b.len();
    if n < 1 {
        return 0;
    }
    let based = |skip: usize, bits: u32, digit: fn(u8) -> Option<u64>| -> i64 {
        let mut res: u64 = 0;
        let mut shift = 0u32;
        let mut l = n - 1;
        while l >= skip && shift < 64 {
            if let Some(d) = digit(b[l]) {
                res |= d.wrapping_shl(shift);
                shift += bits;
            }
            if l == 0 {
                break;
            }
            l -= 1;
        }
        res as i64
    };
    if n > 1 && b[0] == b'2' && b[1] == b'#' {
        // matiec shifts an `int` here (`(c - '0') << shift`): past bit 31 that is undefined C;
        // this reads it as the 64-bit shift the other bases use.
        return based(2, 1, |c| {
            matches!(c, b'0'..=b'1').then(|| (c - b'0') as u64)
        });
    }
    if n > 1 && b[0] == b'8' && b[1] == b'#' {
        return based(2, 3, |c| {
            matches!(c, b'0'..=b'7').then(|| (c - b'0') as u64)
        });
    }
    if n > 2 && b[0] == b'1' && b[1] == b'6' && b[2] == b'#' {
        return based(3, 4, |c| (c as char).to_digit(16).map(u64::from));
    }
    let sign: i64 = if b[0] == b'-' { -1 } else { 1 };
    let (mut res, mut fac, mut shift) = (0i64, sign, 0u32);
    let mut l = n;
    while l > 0 && shift < 20 {
        let c = b[l - 1];
        if c.is_ascii_digit() {
            res = res.wrapping_add(((c - b'0') as i64).wrapping_mul(fac));
            fac = fac.wrapping_mul(10);
            shift += 1;
        } else if c >= b'.' {
            res = 0;
            fac = sign;
            shift = 0;
        }
        l -= 1;
    }
    res
}

#[cfg(test)]
mod tests {
    use super::*;

    fn st(s: &str) -> Arg {
        Arg::Str(StrBuf::new(s.as_bytes()))
    }
    fn int(v: i16) -> Arg {
        Arg::Val(Value::Int(v))
    }
    fn text(a: Arg) -> String {
        match a {
            Arg::Str(s) => s.text(),
            Arg::Val(v) => v.to_string(),
        }
    }

    #[test]
    fn functions_as_matiec() {
        let f =
            |name: &str, args: &[Arg], out| text(apply(Function::parse(name).unwrap(), args, out));
        let s = Type::String;
        assert_eq!(f("CONCAT", &[st("ab"), st("cd"), st("e")], s), "abcde");
        let long = "x".repeat(100);
        assert_eq!(f("CONCAT", &[st(&long), st(&long)], s).len(), 126);
        assert_eq!(f("LEN", &[st("hello")], Type::Int), "5");
        assert_eq!(f("LEFT", &[st("hello"), int(2)], s), "he");
        assert_eq!(f("LEFT", &[st("hello"), int(9)], s), "hello");
        assert_eq!(f("LEFT", &[st("hello"), int(-1)], s), "");
        assert_eq!(f("RIGHT", &[st("hello"), int(3)], s), "llo");
        assert_eq!(f("MID", &[st("hello"), int(2), int(2)], s), "el");
        assert_eq!(f("MID", &[st("hello"), int(9), int(4)], s), "lo");
        assert_eq!(f("MID", &[st("hello"), int(2), int(6)], s), "");
        assert_eq!(f("INSERT", &[st("hello"), st("XY"), int(2)], s), "heXYllo");
        assert_eq!(f("DELETE", &[st("hello"), int(2), int(2)], s), "hlo");
        assert_eq!(
            f("REPLACE", &[st("hello"), st("XYZ"), int(2), int(2)], s),
            "hXYlo",
            "matiec's __replace copies at most L bytes of IN2"
        );
        assert_eq!(f("FIND", &[st("hello"), st("ll")], Type::Int), "3");
        assert_eq!(f("FIND", &[st("hello"), st("z")], Type::Int), "0");
        assert_eq!(
            f("FIND", &[st("aab"), st("ab")], Type::Int),
            "0",
            "matiec's __pfind"
        );
        assert_eq!(f("INT_TO_STRING", &[int(-42)], s), "-42");
        assert_eq!(
            f("BOOL_TO_STRING", &[Arg::Val(Value::Bool(true))], s),
            "TRUE"
        );
        assert_eq!(
            f("WORD_TO_STRING", &[Arg::Val(Value::Word(255))], s),
            "16#ff"
        );
        assert_eq!(f("STRING_TO_INT", &[st("-123")], Type::Int), "-123");
        assert_eq!(f("STRING_TO_INT", &[st("16#1F")], Type::Int), "31");
        // matiec's __pstring_to_sint reads from the right and restarts at any byte >= '.':
        // "5", then '.' restarts, then "12".
        assert_eq!(f("STRING_TO_INT", &[st("12.5")], Type::Int), "12");
        assert_eq!(f("STRING_TO_BOOL", &[st("true")], Type::Bool), "TRUE");
        assert_eq!(
            compare(&StrBuf::new(b"ab"), &StrBuf::new(b"abc")),
            Ordering::Less
        );
        assert_eq!(
            compare(&StrBuf::new(b"b"), &StrBuf::new(b"abc")),
            Ordering::Greater
        );
    }
}
