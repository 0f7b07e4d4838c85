//! Small helpers of the FBD reader: JSON kinds and strings, names, unknown-field checks, and
//! the texts of pin-count messages.

use crate::diag::Invalid;
use crate::fbd::model::*;
use serde_json::{Map, Value as Json};

pub(super) fn conn_is_given(given: usize, i: usize) -> bool {
    i < given
}

pub(super) fn pin_count_text(op: &Op, pins: &[String]) -> String {
    if matches!(op, Op::Call(_)) {
        format!("at most {} inputs ({})", pins.len(), list_or_none(pins))
    } else if op.extensible() {
        "two or more inputs".into()
    } else if pins.len() == 1 {
        format!("one input ({})", pins[0])
    } else {
        format!("{} inputs ({})", pins.len(), pins.join(", "))
    }
}

pub(super) fn list_or_none(pins: &[String]) -> String {
    if pins.is_empty() {
        "none".into()
    } else {
        pins.join(", ")
    }
}

/// The ladder reader's description of a JSON value's kind, shared so both readers say the same.
pub(crate) use crate::resolve::util::kind_of;

pub(super) fn string(v: &Json) -> std::result::Result<&str, Invalid> {
    v.as_str().ok_or_else(|| Invalid::Shape {
        expected: "a string",
        found: kind_of(v),
    })
}

/// A name (labels): letters, digits and `_`, not starting with a digit.
pub(super) fn name(v: &Json) -> std::result::Result<&str, Invalid> {
    let s = string(v)?;
    if valid_name(s) {
        Ok(s)
    } else {
        Err(Invalid::BadName { name: s.to_owned() })
    }
}

/// A variable a block writes or runs on; resolved (and refused, with the reason) by the lowering.
pub(super) fn var_name(s: &str) -> std::result::Result<String, Invalid> {
    Ok(s.to_owned())
}

pub(crate) fn valid_name(s: &str) -> bool {
    let mut chars = s.chars();
    matches!(chars.next(), Some(c) if c.is_ascii_alphabetic() || c == '_')
        && chars.all(|c| c.is_ascii_alphanumeric() || c == '_')
}

pub(super) fn check_keys(
    o: &Map<String, Json>,
    allowed: &[&str],
    what: &'static str,
    path: &str,
) -> std::result::Result<(), (String, Invalid)> {
    match o.keys().find(|k| !allowed.contains(&k.as_str())) {
        None => Ok(()),
        Some(k) => Err((
            format!("{path}.{k}"),
            Invalid::UnknownField {
                field: k.clone(),
                what,
                allowed: allowed.join(", "),
            },
        )),
    }
}
