//! The per-scan input values of `plc-deps run`: the CSV and JSON inputs files, parsed and
//! checked against the program, with errors naming the file, line and column.

use super::config::{count, time_refusal};
use crate::cmd::io::{read_text, CliError, FileRole};
use crate::model::{
    int_range, parse_int_literal, parse_time_literal, Program, Type, Value, VarClass, VarId, Wide,
};
use serde_json::Value as Json;
use std::path::Path;

/// Input values per scan: `rows[k]` holds the values that change at scan `k`; an input not in a
/// row (and every input after the last row) keeps its value.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct InputTable {
    pub rows: Vec<Vec<(VarId, Value)>>,
}

impl InputTable {
    /// The values written before scan `scan`.
    pub fn at(&self, scan: u64) -> &[(VarId, Value)] {
        self.rows.get(scan as usize).map_or(&[], |r| r.as_slice())
    }
}

/// The input variables by name.
fn input_var(p: &Program, name: &str) -> Result<VarId, String> {
    match p.vars.iter().position(|v| v.name == name && !v.hidden) {
        Some(i) if p.vars[i].class == VarClass::Input => Ok(VarId(i as u32)),
        Some(i) => Err(format!(
            "`{name}` is not an input variable (it is {})",
            match p.vars[i].class {
                VarClass::Output => "an output",
                _ => "a memory variable",
            }
        )),
        None => {
            let inputs: Vec<&str> = p
                .vars
                .iter()
                .filter(|v| v.class == VarClass::Input)
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

/// Parses a cell or JSON string for an input of type `ty`.
fn parse_value(ty: Type, s: &str) -> Result<Value, String> {
    let t = s.trim();
    let bad = || format!("`{t}` is not a valid {ty}");
    Ok(match ty {
        Type::Bool => match t.to_ascii_lowercase().as_str() {
            "true" | "1" => Value::Bool(true),
            "false" | "0" => Value::Bool(false),
            _ => return Err(format!("`{t}` is not a BOOL (true, false, 1 or 0)")),
        },
        Type::Real => Value::Real(t.parse().map_err(|_| bad())?),
        Type::Lreal => Value::Lreal(Wide::new(t.parse::<f64>().map_err(|_| bad())?.to_bits())),
        ty if ty.is_int() || ty.is_bits() => {
            let (lo, hi) = int_range(ty);
            // "an INT", "an LINT", "a UINT", "a DWORD" (as the names are spoken).
            let article = if matches!(ty, Type::Int | Type::Lint | Type::Lword) {
                "an"
            } else {
                "a"
            };
            let range = || format!("`{t}` is not {article} {ty} ({lo}..{hi})");
            let v = parse_int_literal(t).ok_or_else(range)?;
            Value::int_of(ty, v).ok_or_else(range)?
        }
        Type::Time => {
            let ms = if let Some(ms) = parse_int_literal(t).filter(|_| !t.contains('#')) {
                Some(ms as i64)
            } else {
                parse_time_literal(t)
            };
            match ms {
                Some(ms) if ms >= i32::MIN as i64 && ms <= i32::MAX as i64 => {
                    Value::Time(ms as i32)
                }
                Some(_) => return Err(format!("`{t}` is out of the range of TIME (32-bit ms)")),
                None if t.contains('#') => {
                    return Err(format!("`{t}` is {}", time_refusal(t)));
                }
                None => {
                    return Err(format!(
                        "`{t}` is not a TIME (milliseconds or a literal like T#1s)"
                    ))
                }
            }
        }
        _ => return Err(bad()),
    })
}

/// Splits a CSV line into (1-based start column, field) pairs; `"…"` quotes with `""` escapes.
fn csv_fields(line: &str) -> Result<Vec<(usize, String)>, (usize, String)> {
    let chars: Vec<char> = line.chars().collect();
    let mut out = Vec::new();
    let mut i = 0;
    loop {
        let start = i + 1;
        let mut field = String::new();
        if i < chars.len() && chars[i] == '"' {
            i += 1;
            loop {
                match chars.get(i) {
                    None => return Err((start, "unterminated quoted field".into())),
                    Some('"') if chars.get(i + 1) == Some(&'"') => {
                        field.push('"');
                        i += 2;
                    }
                    Some('"') => {
                        i += 1;
                        break;
                    }
                    Some(&c) => {
                        field.push(c);
                        i += 1;
                    }
                }
            }
            while i < chars.len() && chars[i] != ',' {
                if !chars[i].is_whitespace() {
                    return Err((i + 1, "unexpected text after a quoted field".into()));
                }
                i += 1;
            }
        } else {
            while i < chars.len() && chars[i] != ',' {
                field.push(chars[i]);
                i += 1;
            }
        }
        out.push((start, field.trim().to_string()));
        if i >= chars.len() {
            return Ok(out);
        }
        i += 1; // the comma
    }
}

/// Parses inputs in CSV: a header row of input variable names, then one row per scan (row k is
/// scan k); an empty cell or a missing trailing cell keeps the input's value; blank lines are
/// ignored. `file` names the file in errors (`file:line:column: message`).
pub fn parse_inputs_csv(p: &Program, text: &str, file: &str) -> Result<InputTable, CliError> {
    let err = |line: usize, col: usize, msg: String| {
        CliError::Usage(format!("{file}:{line}:{col}: {msg}"))
    };
    let text = text.strip_prefix('\u{feff}').unwrap_or(text);
    let mut lines = text
        .lines()
        .enumerate()
        .map(|(i, l)| (i + 1, l.strip_suffix('\r').unwrap_or(l)))
        .filter(|(_, l)| !l.trim().is_empty());
    let Some((hline, header)) = lines.next() else {
        return Ok(InputTable::default());
    };
    let mut columns: Vec<(VarId, String)> = Vec::new();
    for (col, name) in csv_fields(header).map_err(|(c, m)| err(hline, c, m))? {
        if name.is_empty() {
            return Err(err(hline, col, "empty column name in the header".into()));
        }
        let v = input_var(p, &name).map_err(|m| err(hline, col, m))?;
        if columns.iter().any(|(w, _)| *w == v) {
            return Err(err(hline, col, format!("input `{name}` has two columns")));
        }
        columns.push((v, name));
    }
    let mut rows = Vec::new();
    for (line, l) in lines {
        let fields = csv_fields(l).map_err(|(c, m)| err(line, c, m))?;
        if fields.len() > columns.len() {
            return Err(err(
                line,
                fields[columns.len()].0,
                format!(
                    "{} in a row, the header has {}",
                    count(fields.len() as u64, "value", "values"),
                    count(columns.len() as u64, "column", "columns")
                ),
            ));
        }
        let mut row = Vec::new();
        for ((col, cell), (v, name)) in fields.iter().zip(&columns) {
            if cell.is_empty() {
                continue;
            }
            let value = parse_value(p.var(*v).ty, cell).map_err(|m| {
                err(
                    line,
                    *col,
                    format!("scan {}, column `{name}`: {m}", rows.len()),
                )
            })?;
            row.push((*v, value));
        }
        rows.push(row);
    }
    Ok(InputTable { rows })
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
            CliError::Usage(format!("{file}:{}:{}: {msg}", e.line(), e.column()))
        })?;
    Ok(InputTable { rows })
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
    #[test]
    fn csv_splitting() {
        let f = |l: &str| {
            csv_fields(l)
                .unwrap()
                .into_iter()
                .map(|(c, s)| format!("{c}:{s}"))
                .collect::<Vec<_>>()
        };
        assert_eq!(f("a, b ,,c"), ["1:a", "3:b", "7:", "8:c"]);
        assert_eq!(
            f(r#""x,y","say ""hi""" ,z"#),
            ["1:x,y", "7:say \"hi\"", "21:z"]
        );
        assert!(csv_fields(r#""open"#).is_err());
        assert!(csv_fields(r#""a"b"#).is_err());
    }
}
