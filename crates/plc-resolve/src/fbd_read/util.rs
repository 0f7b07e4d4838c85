//! Small helpers of the FBD reader: names and the texts of pin-count messages.

use plc_fbd::model::OpKind;

pub(super) fn pin_count_text(op: OpKind, pins: &[String]) -> String {
    if op == OpKind::Call {
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

/// A name (labels): letters, digits and `_`, not starting with a digit.
pub(crate) fn valid_name(s: &str) -> bool {
    let mut chars = s.chars();
    matches!(chars.next(), Some(c) if c.is_ascii_alphabetic() || c == '_')
        && chars.all(|c| c.is_ascii_alphanumeric() || c == '_')
}
