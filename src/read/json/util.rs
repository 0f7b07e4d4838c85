//! Small JSON helpers shared by the reader: typed access to objects, arrays, strings and
//! flags with located errors, unknown-field and name checks, paths and value display.

use super::Result;
use crate::model::Type;
use crate::read::error::{Invalid, LoadError};
use serde_json::{Map, Value as Json};

/// A short description of a JSON value's kind, for error messages.
pub(crate) fn kind_of(v: &Json) -> String {
    match v {
        Json::Null => "null".into(),
        Json::Bool(b) => format!("boolean {b}"),
        Json::Number(n) => format!("number {n}"),
        Json::String(s) => format!("string \"{s}\""),
        Json::Array(_) => "an array".into(),
        Json::Object(_) => "an object".into(),
    }
}

pub(super) fn rung_path(pou_path: &str, i: usize) -> String {
    if pou_path.is_empty() {
        format!("rungs[{i}]")
    } else {
        format!("{pou_path}[{i}]")
    }
}

pub(super) fn display_json(v: &Json) -> String {
    match v {
        Json::String(s) => s.clone(),
        other => other.to_string(),
    }
}

pub(super) fn expect_type(
    found: Type,
    expected: Type,
    what: &'static str,
    name: &str,
) -> std::result::Result<(), Invalid> {
    if found == expected {
        Ok(())
    } else {
        Err(Invalid::Type {
            what,
            expected: expected.to_string(),
            operand: name.to_owned(),
            found: found.to_string(),
        })
    }
}

pub(super) fn object<'v>(
    v: &'v Json,
    path: &str,
    rung: Option<&str>,
    what: &'static str,
) -> Result<&'v Map<String, Json>> {
    v.as_object().ok_or_else(|| {
        LoadError::invalid(
            rung,
            path,
            Invalid::Shape {
                expected: what_object(what),
                found: kind_of(v),
            },
        )
    })
}

pub(super) fn what_object(what: &'static str) -> &'static str {
    match what {
        "the program" => "a JSON object (the program)",
        "a variable" => "an object (a variable)",
        "a rung" => "an object (a rung)",
        "an element" => "an object (an element)",
        "a subroutine" => "an object (a subroutine)",
        "the subroutines" => "an object of subroutines",
        _ => "an object",
    }
}

pub(super) fn array<'v>(v: &'v Json, path: &str, rung: Option<&str>) -> Result<&'v [Json]> {
    v.as_array().map(Vec::as_slice).ok_or_else(|| {
        LoadError::invalid(
            rung,
            path,
            Invalid::Shape {
                expected: "an array",
                found: kind_of(v),
            },
        )
    })
}

pub(super) fn string<'v>(v: &'v Json, path: &str, rung: Option<&str>) -> Result<&'v str> {
    v.as_str().ok_or_else(|| {
        LoadError::invalid(
            rung,
            path,
            Invalid::Shape {
                expected: "a string",
                found: kind_of(v),
            },
        )
    })
}

pub(super) fn boolean(v: &Json, path: &str, rung: Option<&str>) -> Result<bool> {
    v.as_bool().ok_or_else(|| {
        LoadError::invalid(
            rung,
            path,
            Invalid::Shape {
                expected: "true or false",
                found: kind_of(v),
            },
        )
    })
}

/// A marker field such as `"ret": true`.
pub(super) fn flag(v: &Json, path: &str, rung: Option<&str>) -> Result<()> {
    match v {
        Json::Bool(true) => Ok(()),
        other => Err(LoadError::invalid(
            rung,
            path,
            Invalid::Shape {
                expected: "true",
                found: kind_of(other),
            },
        )),
    }
}

pub(super) fn required<'v>(
    o: &'v Map<String, Json>,
    key: &'static str,
    what: &'static str,
    path: &str,
    rung: Option<&str>,
) -> Result<&'v Json> {
    o.get(key)
        .ok_or_else(|| LoadError::invalid(rung, path, Invalid::MissingField { field: key, what }))
}

pub(super) fn check_keys(
    o: &Map<String, Json>,
    allowed: &[&str],
    what: &'static str,
    path: &str,
    rung: Option<&str>,
) -> Result<()> {
    match o.keys().find(|k| !allowed.contains(&k.as_str())) {
        None => Ok(()),
        Some(k) => {
            let p = if path.is_empty() {
                k.clone()
            } else {
                format!("{path}.{k}")
            };
            Err(LoadError::invalid(
                rung,
                &p,
                Invalid::UnknownField {
                    field: k.clone(),
                    what,
                    allowed: allowed.join(", "),
                },
            ))
        }
    }
}

pub(super) fn check_name(name: &str, path: &str, rung: Option<&str>) -> Result<()> {
    let mut chars = name.chars();
    let ok = matches!(chars.next(), Some(c) if c.is_ascii_alphabetic() || c == '_')
        && chars.all(|c| c.is_ascii_alphanumeric() || c == '_');
    if ok {
        Ok(())
    } else {
        Err(LoadError::invalid(
            rung,
            path,
            Invalid::BadName { name: name.into() },
        ))
    }
}
