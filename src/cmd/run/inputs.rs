//! The per-scan input values of `plc-deps run`: the CSV and JSON inputs files, parsed and
//! checked against the program, with errors naming the file, line and column.

use super::config::count;
use crate::cmd::io::{read_text, CliError, FileRole};
use plc_model::{integer_cell, parse_int_literal, Program, Type, Value, VarClass, VarId, Wide};
use serde_json::Value as Json;
use std::path::Path;

/// Input values per scan: `rows[k]` holds the values that change at scan `k`; an input not in a
/// row (and every input after the last row) keeps its value.
///
/// An input the program writes (W0208) is the exception: the scan copies its *image* in before
/// every scan (the value the rows last gave it, else its initial value), as the Beremiz/OpenPLC
/// runtime copies the input image into located `%I` variables; [`InputTable::with_image`] puts
/// that copy into every row and into `tail`, the values of the scans after the last row.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct InputTable {
    pub rows: Vec<Vec<(VarId, Value)>>,
    /// What is written before each scan after the last row: the images of the written inputs.
    pub tail: Vec<(VarId, Value)>,
}

impl InputTable {
    /// The values written before scan `scan`.
    pub fn at(&self, scan: u64) -> &[(VarId, Value)] {
        self.rows
            .get(scan as usize)
            .map_or(self.tail.as_slice(), |r| r.as_slice())
    }

    /// The table with the input image of each of `written` (the inputs the program writes,
    /// `Program::written_inputs`) copied in before every scan: each row gets the image
    /// of every written input it does not set, and `tail` the images after the last row.
    pub fn with_image(mut self, p: &Program, written: &[VarId]) -> InputTable {
        if written.is_empty() {
            return self;
        }
        let mut image: Vec<(VarId, Value)> = written.iter().map(|&v| (v, p.var(v).init)).collect();
        for row in &mut self.rows {
            for (v, x) in row.iter() {
                if let Ok(k) = written.binary_search(v) {
                    image[k].1 = *x;
                }
            }
            for &(v, x) in &image {
                if !row.iter().any(|(w, _)| *w == v) {
                    row.push((v, x));
                }
            }
        }
        self.tail = image;
        self
    }
}

/// The input variables by name.
fn input_var(p: &Program, name: &str) -> Result<VarId, String> {
    match p.vars().iter().position(|v| v.name == name && !v.hidden) {
        Some(i) if p.vars()[i].class == VarClass::Input => Ok(p.vars().id(i)),
        Some(i) => Err(format!(
            "`{name}` is not an input variable (it is {})",
            match p.vars()[i].class {
                VarClass::Output => "an output",
                _ => "a memory variable",
            }
        )),
        None => {
            let inputs: Vec<&str> = p
                .vars()
                .iter()
                .filter(|v| v.class == VarClass::Input && !v.hidden)
                .map(|v| v.name.as_str())
                .collect();
            Err(format!(
                "unknown input variable `{name}` (inputs: {})",
                if inputs.is_empty() {
                    "none".to_string()
                } else {
                    inputs.join(", ")
                }
            ))
        }
    }
}

/// What the cells of the CSV are trimmed of: spaces and tabs (the C harness trims the same).
fn trim_cell(s: &str) -> &str {
    s.trim_matches([' ', '\t'])
}

/// Whether `t` is a REAL or LREAL cell: `[+-]` then digits with an optional `.` and fraction
/// (or `.` and digits), an optional exponent `e`/`E` `[+-]` digits; or `inf`, `infinity`, `nan`
/// in any case with an optional sign. No hexadecimal, no `_`, no spaces (the C harness checks
/// the same grammar before `strtof`/`strtod`, which read every text of it as Rust does).
fn is_real_text(t: &str) -> bool {
    let b = t.strip_prefix(['+', '-']).unwrap_or(t);
    if ["inf", "infinity", "nan"]
        .iter()
        .any(|w| b.eq_ignore_ascii_case(w))
    {
        return true;
    }
    let b = b.as_bytes();
    let digits = |i: &mut usize| {
        let from = *i;
        while *i < b.len() && b[*i].is_ascii_digit() {
            *i += 1;
        }
        *i - from
    };
    let mut i = 0;
    let mut n = digits(&mut i);
    if i < b.len() && b[i] == b'.' {
        i += 1;
        n += digits(&mut i);
    }
    if n == 0 {
        return false;
    }
    if i < b.len() && (b[i] == b'e' || b[i] == b'E') {
        i += 1;
        if i < b.len() && (b[i] == b'+' || b[i] == b'-') {
            i += 1;
        }
        if digits(&mut i) == 0 {
            return false;
        }
    }
    i == b.len()
}

/// A TIME cell, read as `plc-deps run` and the C harness read it.
#[derive(Debug, PartialEq)]
enum TimeCell {
    Ms(i32),
    /// Beyond the 32-bit milliseconds (checked on the exact value, before wholeness).
    OutOfRange,
    /// A literal whose value is not a whole number of milliseconds (or a number with more than
    /// 12 decimals after dropping trailing zeros, which never adds up to whole milliseconds).
    NotWholeMs,
    NotTime,
}

/// Reads a TIME cell: milliseconds `[+-]digits` (`_` between digits, as in an integer), or a
/// literal `T#`/`t#`/`TIME#`/`time#`, an optional `-`, then one or more numbers (digits, at
/// most one `.`, `_` anywhere) each followed by a unit `d`, `h`, `m`, `s` or `ms` in any case.
/// The accepted values are those of the program's TIME literals (`parse_time_literal`).
fn parse_time_cell(t: &str) -> TimeCell {
    const MAX: u128 = i32::MAX as u128;
    // Units of 10^-12 ms: every accepted number is whole in them (at most 12 decimals).
    const UNIT: u128 = 1_000_000_000_000;
    let in_range = |neg: bool, units: u128| {
        let ms = units / UNIT;
        // An exact value just past the bound is out of range even when not whole.
        let limit = if neg { MAX + 1 } else { MAX };
        ms < limit || (ms == limit && units.is_multiple_of(UNIT))
    };
    if !t.contains('#') {
        let (neg, body) = match t.as_bytes().first() {
            Some(b'-') => (true, &t[1..]),
            Some(b'+') => (false, &t[1..]),
            _ => (false, t),
        };
        if body.is_empty()
            || body.starts_with('_')
            || body.ends_with('_')
            || body.contains("__")
            || !body.bytes().all(|c| c.is_ascii_digit() || c == b'_')
        {
            return TimeCell::NotTime;
        }
        let v = body.bytes().filter(|&c| c != b'_').fold(0u128, |v, c| {
            v.saturating_mul(10).saturating_add((c - b'0') as u128)
        });
        return if in_range(neg, v.saturating_mul(UNIT)) {
            TimeCell::Ms(if neg { -(v as i64) } else { v as i64 } as i32)
        } else {
            TimeCell::OutOfRange
        };
    }
    let Some(rest) = ["T#", "t#", "TIME#", "time#"]
        .iter()
        .find_map(|p| t.strip_prefix(p))
    else {
        return TimeCell::NotTime;
    };
    let (neg, rest) = match rest.strip_prefix('-') {
        Some(r) => (true, r),
        None => (false, rest),
    };
    let b = rest.as_bytes();
    if b.is_empty() {
        return TimeCell::NotTime;
    }
    let (mut i, mut total, mut too_precise) = (0, 0u128, false);
    while i < b.len() {
        let (mut int, mut frac, mut frac_len, mut dots, mut digits) = (0u128, 0u128, 0, 0, 0);
        let mut frac_digits = Vec::new();
        while i < b.len() && (b[i].is_ascii_digit() || b[i] == b'.' || b[i] == b'_') {
            match b[i] {
                b'.' => dots += 1,
                b'_' => {}
                c if dots == 0 => {
                    int = int.saturating_mul(10).saturating_add((c - b'0') as u128);
                    digits += 1;
                }
                c => {
                    frac_digits.push(c - b'0');
                    digits += 1;
                }
            }
            i += 1;
        }
        if dots > 1 || digits == 0 {
            return TimeCell::NotTime;
        }
        while frac_digits.last() == Some(&0) {
            frac_digits.pop();
        }
        if frac_digits.len() > 12 {
            too_precise = true;
        } else {
            for d in &frac_digits {
                frac = frac * 10 + *d as u128;
                frac_len += 1;
            }
            frac *= 10u128.pow(12 - frac_len);
        }
        let from = i;
        while i < b.len() && !(b[i].is_ascii_digit() || b[i] == b'.') {
            i += 1;
        }
        let factor: u128 = match rest[from..i].to_ascii_lowercase().as_str() {
            "d" => 86_400_000,
            "h" => 3_600_000,
            "m" => 60_000,
            "s" => 1000,
            "ms" => 1,
            _ => return TimeCell::NotTime,
        };
        let part = int.saturating_mul(UNIT).saturating_add(frac);
        total = total.saturating_add(part.saturating_mul(factor));
    }
    if too_precise {
        TimeCell::NotWholeMs
    } else if !in_range(neg, total) {
        TimeCell::OutOfRange
    } else if total % UNIT != 0 {
        TimeCell::NotWholeMs
    } else {
        let ms = (total / UNIT) as i64;
        TimeCell::Ms(if neg { -ms } else { ms } as i32)
    }
}

/// Parses a cell or JSON string for an input of type `ty` (trimmed of spaces and tabs).
fn parse_value(ty: Type, s: &str) -> Result<Value, String> {
    let t = trim_cell(s);
    let bad = || format!("`{t}` is not a valid {ty}");
    Ok(match ty {
        Type::Bool => match t.to_ascii_lowercase().as_str() {
            "true" | "1" => Value::Bool(true),
            "false" | "0" => Value::Bool(false),
            _ => return Err(format!("`{t}` is not a BOOL (true, false, 1 or 0)")),
        },
        Type::Real if is_real_text(t) => Value::Real(t.parse().map_err(|_| bad())?),
        Type::Lreal if is_real_text(t) => {
            Value::Lreal(Wide::new(t.parse::<f64>().map_err(|_| bad())?.to_bits()))
        }
        ty if ty.is_int() || ty.is_bits() => {
            let range = || format!("`{t}` is not {}", integer_cell(ty));
            let v = parse_int_literal(t).ok_or_else(range)?;
            Value::int_of(ty, v).ok_or_else(range)?
        }
        Type::Time => match parse_time_cell(t) {
            TimeCell::Ms(ms) => Value::Time(ms),
            TimeCell::OutOfRange => {
                return Err(format!("`{t}` is out of the range of TIME (32-bit ms)"))
            }
            TimeCell::NotWholeMs => {
                return Err(format!(
                    "`{t}` is not a whole number of milliseconds (TIME counts milliseconds)"
                ))
            }
            TimeCell::NotTime if t.contains('#') => return Err(format!("`{t}` is not a TIME")),
            TimeCell::NotTime => {
                return Err(format!(
                    "`{t}` is not a TIME (milliseconds or a literal like T#1s)"
                ))
            }
        },
        _ => return Err(bad()),
    })
}

/// Where the CSV's lines start (byte offsets): a line ends with LF, CRLF or a lone CR, as a
/// record does for the `csv` crate.
fn line_starts(text: &str) -> Vec<usize> {
    let b = text.as_bytes();
    let mut starts = vec![0];
    for (i, &c) in b.iter().enumerate() {
        if c == b'\n' || (c == b'\r' && b.get(i + 1) != Some(&b'\n')) {
            starts.push(i + 1);
        }
    }
    starts
}

/// The 1-based line and column (in characters) of byte `at`.
fn line_col(text: &str, starts: &[usize], at: usize) -> (usize, usize) {
    let line = starts.partition_point(|&s| s <= at).max(1);
    let from = starts[line - 1];
    (line, text[from..at].chars().count() + 1)
}

/// One record of the CSV as the checker sees it: where each cell starts (byte offsets), or
/// `None` for a blank line (only spaces and tabs).
type Cells = Option<Vec<usize>>;

/// Checks the record starting at `*at` (after skipping empty lines) and moves past it; `Ok(None)`
/// at the end of the text. Refuses what the `csv` crate would read some other way: a quote that
/// is never closed, text after a closing quote (other than spaces and tabs), and a quote inside
/// a cell that does not start with one. On error: the byte offset and the message.
fn check_record(text: &str, at: &mut usize) -> Result<Option<Cells>, (usize, &'static str)> {
    let b = text.as_bytes();
    let mut i = *at;
    while i < b.len() && (b[i] == b'\n' || b[i] == b'\r') {
        i += 1;
    }
    if i == b.len() {
        *at = i;
        return Ok(None);
    }
    let end_of_line = |i: usize| i == b.len() || b[i] == b'\n' || b[i] == b'\r';
    let mut j = i;
    while j < b.len() && (b[j] == b' ' || b[j] == b'\t') {
        j += 1;
    }
    if end_of_line(j) {
        *at = j;
        return Ok(Some(None));
    }
    let mut starts = Vec::new();
    loop {
        starts.push(i);
        if i < b.len() && b[i] == b'"' {
            let open = i;
            i += 1;
            loop {
                match b.get(i) {
                    None => return Err((open, "a quoted cell is not closed")),
                    Some(b'"') if b.get(i + 1) == Some(&b'"') => i += 2,
                    Some(b'"') => break,
                    Some(_) => i += 1,
                }
            }
            i += 1;
            while i < b.len() && (b[i] == b' ' || b[i] == b'\t') {
                i += 1;
            }
            if !(end_of_line(i) || b[i] == b',') {
                return Err((i, "text after the closing quote of a cell"));
            }
        } else {
            while !(end_of_line(i) || b[i] == b',') {
                if b[i] == b'"' {
                    return Err((
                        i,
                        "a quote inside a cell that does not start with one \
                         (quote the whole cell and double the quote)",
                    ));
                }
                i += 1;
            }
        }
        if i < b.len() && b[i] == b',' {
            i += 1;
            continue;
        }
        *at = i;
        return Ok(Some(Some(starts)));
    }
}

/// Parses inputs in CSV (RFC 4180, read by the `csv` crate and checked by [`check_record`]): an
/// optional UTF-8 byte-order mark; a header row of input variable names, then one row per scan
/// (row k is scan k); lines end with LF, CRLF or CR; a cell may be quoted (`"a,b"`, `""` for a
/// quote, line ends inside); cells are trimmed of spaces and tabs; an empty cell or a missing
/// trailing cell keeps the input's value; blank lines are ignored. `file` names the file in
/// errors (`file:line:column: message`, the column of the cell's first character).
/// docs/scan.md, *Inputs*, is the contract, and the C harness (`plc_main.h`) reads the same.
pub fn parse_inputs_csv(p: &Program, text: &str, file: &str) -> Result<InputTable, CliError> {
    let text = text.strip_prefix('\u{feff}').unwrap_or(text);
    let starts = line_starts(text);
    let err = |at: usize, msg: String| {
        let (line, col) = line_col(text, &starts, at);
        CliError::Usage(format!("{file}:{line}:{col}: {msg}"))
    };
    let mut reader = csv::ReaderBuilder::new()
        .has_headers(false)
        .flexible(true)
        .from_reader(text.as_bytes());
    let mut record = csv::ByteRecord::new();
    let mut at = 0;
    // The next non-blank record: the checker's cell offsets with the crate's cells.
    type Cells = (Vec<usize>, Vec<String>);
    let mut next = || -> Result<Option<Cells>, CliError> {
        loop {
            let cells = check_record(text, &mut at).map_err(|(i, m)| err(i, m.to_string()))?;
            let read = reader.read_byte_record(&mut record).unwrap_or(false);
            match cells {
                None => return Ok(None),
                Some(None) => continue,
                Some(Some(cells)) if read && cells.len() == record.len() => {
                    let values = record
                        .iter()
                        .map(|c| trim_cell(&String::from_utf8_lossy(c)).to_string())
                        .collect();
                    return Ok(Some((cells, values)));
                }
                // The checker and the crate split every checked record alike.
                Some(Some(cells)) => {
                    return Err(err(cells[0], "the record cannot be read".to_string()))
                }
            }
        }
    };
    let Some((hcells, header)) = next()? else {
        return Ok(InputTable::default());
    };
    let mut columns: Vec<(VarId, String)> = Vec::new();
    for (&at, name) in hcells.iter().zip(header) {
        if name.is_empty() {
            return Err(err(at, "empty column name in the header".into()));
        }
        let v = input_var(p, &name).map_err(|m| err(at, m))?;
        if columns.iter().any(|(w, _)| *w == v) {
            return Err(err(at, format!("input `{name}` has two columns")));
        }
        columns.push((v, name));
    }
    let mut rows = Vec::new();
    while let Some((cells, values)) = next()? {
        if values.len() > columns.len() {
            return Err(err(
                cells[columns.len()],
                format!(
                    "{} in a row, the header has {}",
                    count(values.len() as u64, "value", "values"),
                    count(columns.len() as u64, "column", "columns")
                ),
            ));
        }
        let mut row = Vec::new();
        for ((&at, cell), (v, name)) in cells.iter().zip(&values).zip(&columns) {
            if cell.is_empty() {
                continue;
            }
            let value = parse_value(p.var(*v).ty, cell)
                .map_err(|m| err(at, format!("scan {}, column `{name}`: {m}", rows.len())))?;
            row.push((*v, value));
        }
        rows.push(row);
    }
    Ok(InputTable {
        rows,
        tail: Vec::new(),
    }
    .with_image(p, p.written_inputs()))
}

/// Parses inputs in JSON: an array with one object per scan (element k is scan k) mapping input
/// names to values — BOOL `true`/`false`, numbers, TIME as milliseconds or a `"T#…"` string;
/// a missing key or `null` keeps the input's value. Errors carry the line and column.
pub fn parse_inputs_json(p: &Program, text: &str, file: &str) -> Result<InputTable, CliError> {
    use serde::de::{DeserializeSeed, Error as _, MapAccess, SeqAccess, Visitor};
    use std::fmt;
    struct Rows<'a>(&'a Program);
    struct Row<'a>(&'a Program, usize);
    impl<'de> DeserializeSeed<'de> for Rows<'_> {
        type Value = Vec<Vec<(VarId, Value)>>;
        fn deserialize<D: serde::Deserializer<'de>>(self, d: D) -> Result<Self::Value, D::Error> {
            d.deserialize_seq(self)
        }
    }
    impl<'de> Visitor<'de> for Rows<'_> {
        type Value = Vec<Vec<(VarId, Value)>>;
        fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
            f.write_str("an array with one object of input values per scan")
        }
        fn visit_seq<A: SeqAccess<'de>>(self, mut seq: A) -> Result<Self::Value, A::Error> {
            let mut rows = Vec::new();
            while let Some(row) = seq.next_element_seed(Row(self.0, rows.len()))? {
                rows.push(row);
            }
            Ok(rows)
        }
    }
    impl<'de> DeserializeSeed<'de> for Row<'_> {
        type Value = Vec<(VarId, Value)>;
        fn deserialize<D: serde::Deserializer<'de>>(self, d: D) -> Result<Self::Value, D::Error> {
            d.deserialize_map(self)
        }
    }
    impl<'de> Visitor<'de> for Row<'_> {
        type Value = Vec<(VarId, Value)>;
        fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
            write!(f, "an object of input values for scan {}", self.1)
        }
        fn visit_map<A: MapAccess<'de>>(self, mut map: A) -> Result<Self::Value, A::Error> {
            let mut row: Vec<(VarId, Value)> = Vec::new();
            while let Some(name) = map.next_key::<String>()? {
                let v = input_var(self.0, &name)
                    .map_err(|m| A::Error::custom(format!("scan {}: {m}", self.1)))?;
                if row.iter().any(|(w, _)| *w == v) {
                    return Err(A::Error::custom(format!(
                        "scan {}: input `{name}` given twice",
                        self.1
                    )));
                }
                let raw: Json = map.next_value()?;
                let ty = self.0.var(v).ty;
                let value = match (&raw, ty) {
                    (Json::Null, _) => continue,
                    (Json::Bool(b), Type::Bool) => Ok(Value::Bool(*b)),
                    (Json::Number(n), Type::Real) => {
                        Ok(Value::Real(n.as_f64().unwrap_or(f64::NAN) as f32))
                    }
                    (Json::Number(n), Type::Lreal) => Ok(Value::Lreal(Wide::new(
                        n.as_f64().unwrap_or(f64::NAN).to_bits(),
                    ))),
                    // Integers exactly (a ULINT up to 2^64 - 1), range-checked as in the CSV.
                    (Json::Number(n), t)
                        if (t.is_int() || t.is_bits() || t == Type::Time)
                            && (n.is_i64() || n.is_u64()) =>
                    {
                        parse_value(ty, &n.to_string())
                    }
                    // TIME literals, and based or plain integers as strings (`"16#FF"`).
                    (Json::String(s), t)
                        if (t == Type::Time && s.contains('#')) || t.is_int() || t.is_bits() =>
                    {
                        parse_value(ty, s)
                    }
                    _ => Err(format!(
                        "{} is not {} {ty}",
                        describe_json(&raw),
                        if matches!(ty, Type::Int | Type::Lint | Type::Lword) {
                            "an"
                        } else {
                            "a"
                        }
                    )),
                };
                let value = value.map_err(|m| {
                    A::Error::custom(format!("scan {}, input `{name}`: {m}", self.1))
                })?;
                row.push((v, value));
            }
            Ok(row)
        }
    }
    let mut de = serde_json::Deserializer::from_str(text);
    let rows = Rows(p)
        .deserialize(&mut de)
        .and_then(|rows| de.end().map(|_| rows))
        .map_err(|e| {
            let msg = e.to_string();
            let msg = msg
                .rfind(" at line ")
                .map_or(msg.as_str(), |i| &msg[..i])
                .to_string();
            let (line, col) = json_place(text, e.line(), e.column());
            CliError::Usage(format!("{file}:{line}:{col}: {msg}"))
        })?;
    Ok(InputTable {
        rows,
        tail: Vec::new(),
    }
    .with_image(p, p.written_inputs()))
}

/// The line and column to report for a `serde_json` error at `line`:`column`. serde_json
/// counts the characters consumed on the line, so an error about a value it has only peeked at
/// (a top-level `{` instead of `[`) names the character before it: column 0 at the start of a
/// line, or the whitespace before the value. No JSON error is about whitespace, so the place is
/// the next character that is not whitespace (or the end of the text).
fn json_place(text: &str, line: usize, column: usize) -> (usize, usize) {
    if line == 0 {
        return (1, 1);
    }
    let from = text
        .split_inclusive('\n')
        .take(line - 1)
        .map(str::len)
        .sum::<usize>()
        .min(text.len());
    // The reported character (1-based `column`), or the line's start for column 0.
    let skip = column.saturating_sub(1);
    let at = text[from..]
        .char_indices()
        .nth(skip)
        .map_or(text.len(), |(i, _)| from + i);
    let (mut line, mut col) = (line, column.max(1));
    for c in text[at..].chars() {
        match c {
            '\n' => (line, col) = (line + 1, 1),
            ' ' | '\t' | '\r' => col += 1,
            _ => break,
        }
    }
    (line, col)
}

fn describe_json(v: &Json) -> String {
    match v {
        Json::Null => "null".into(),
        Json::Bool(b) => format!("{b}"),
        Json::Number(n) => format!("{n}"),
        Json::String(s) => format!("\"{s}\""),
        Json::Array(_) => "an array".into(),
        Json::Object(_) => "an object".into(),
    }
}

/// Reads an inputs file (JSON if it ends in `.json`, CSV otherwise; see [`read_text`] for what
/// is refused before parsing).
pub fn load_inputs(p: &Program, path: &Path) -> Result<InputTable, CliError> {
    let text = read_text(path, FileRole::Inputs)?;
    let file = path.display().to_string();
    if path
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("json"))
    {
        parse_inputs_json(p, &text, &file)
    } else {
        parse_inputs_csv(p, &text, &file)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use plc_model::parse_time_literal;

    #[test]
    fn time_cells_accept_the_program_literals_values() {
        for t in [
            "T#1s",
            "T#250ms",
            "TIME#1m30s",
            "T#1.5s",
            "T#-2s",
            "T#0.001s",
            "T#1.250_0s",
            "T#0.1s0.2s",
            "T#1_000ms",
            "T#.5s",
            "T#2.ms",
            "T#0.00001d",
            "t#1H",
            "time#1Ms",
            "T#24d20h31m23s647ms",
            "T#-24d20h31m23s648ms",
        ] {
            let ms = parse_time_literal(t).unwrap();
            assert_eq!(parse_time_cell(t), TimeCell::Ms(ms as i32), "{t}");
        }
        for (t, want) in [
            ("T#24d20h31m23s648ms", TimeCell::OutOfRange),
            ("T#-24d20h31m23s649ms", TimeCell::OutOfRange),
            ("T#2147483647.5ms", TimeCell::OutOfRange),
            ("T#2147483646.5ms", TimeCell::NotWholeMs),
            ("T#0.0000000000001s", TimeCell::NotWholeMs),
            ("T#0.4ms", TimeCell::NotWholeMs),
            ("T#1us", TimeCell::NotTime),
            ("T#", TimeCell::NotTime),
            ("T#1.2.3s", TimeCell::NotTime),
            ("2147483648", TimeCell::OutOfRange),
            ("-2147483648", TimeCell::Ms(i32::MIN)),
            (
                "99999999999999999999999999999999999999999",
                TimeCell::OutOfRange,
            ),
            ("1__0", TimeCell::NotTime),
            ("+1_0", TimeCell::Ms(10)),
            ("Time#1s", TimeCell::NotTime),
        ] {
            assert_eq!(parse_time_cell(t), want, "{t}");
        }
    }

    #[test]
    fn real_texts() {
        for t in [
            "1",
            "-1.5",
            ".5",
            "1.",
            "1e5",
            "1.E-5",
            "+inf",
            "NaN",
            "-Infinity",
        ] {
            assert!(is_real_text(t), "{t}");
        }
        for t in ["", ".", "e5", "1e", "0x1p3", "1_0", " 1", "infin", "1.5f"] {
            assert!(!is_real_text(t), "{t}");
        }
    }
}
