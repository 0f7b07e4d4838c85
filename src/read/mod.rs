//! Readers: program files in → one resolved [`crate::model::Program`] out.
//!
//! Only the JSON program format (docs/format.md) exists so far. Reading is two steps: serde_json
//! parses the text (syntax errors carry line and column), then [`json`] walks the document,
//! checks every field, resolves names and types, and builds the model (those errors carry the
//! rung id and JSON path). Nothing is half-built: a program either loads whole or not at all.

mod error;
mod json;
pub(crate) mod operand;
mod structure;

pub use error::{Invalid, LoadError, Location};
pub(crate) use json::kind_of;
pub use json::{program_and_fbd_from_value, program_from_value};

use crate::model::Program;

/// Parses and checks a program given as JSON text.
pub fn program_from_json(text: &str) -> Result<Program, LoadError> {
    let value: serde_json::Value = serde_json::from_str(text).map_err(|e| LoadError::Syntax {
        line: e.line(),
        column: e.column(),
        message: strip_position(&e.to_string()),
    })?;
    program_from_value(&value)
}

/// Parses and checks a program given as JSON text, and returns with it the FBD bodies it was
/// written in (before lowering: their networks, execution orders and fragment trees).
pub fn program_and_fbd_from_json(text: &str) -> Result<(Program, crate::fbd::Fbd), LoadError> {
    let value: serde_json::Value = serde_json::from_str(text).map_err(|e| LoadError::Syntax {
        line: e.line(),
        column: e.column(),
        message: strip_position(&e.to_string()),
    })?;
    program_and_fbd_from_value(&value)
}

/// serde_json appends " at line L column C"; the location is carried separately.
fn strip_position(message: &str) -> String {
    match message.rfind(" at line ") {
        Some(i) => message[..i].to_owned(),
        None => message.to_owned(),
    }
}
