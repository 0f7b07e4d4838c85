//! Small helpers of the resolver: names, paths, type expectations, and the description of a
//! JSON value's kind (FBD bodies are still walked as JSON values).

use super::Result;
use crate::diag::{Invalid, LoadError};
use crate::model::Type;
use serde_json::Value as Json;

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

/// `path.key`, or `key` at the top level.
pub(super) fn join(path: &str, key: &str) -> String {
    if path.is_empty() {
        key.to_owned()
    } else {
        format!("{path}.{key}")
    }
}

pub(super) fn rung_path(pou_path: &str, i: usize) -> String {
    if pou_path.is_empty() {
        format!("rungs[{i}]")
    } else {
        format!("{pou_path}[{i}]")
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
