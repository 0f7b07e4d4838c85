//! The `configuration` of a JSON program (docs/format.md, "Configuration") → the model's
//! [`Configuration`], which the syntax carries unchanged (as it does a PLCopen file's).
//!
//! The value is small and rare (one per file), so it is not walked node by node like the rest
//! of the format: the cursor skips it, and `serde_json` reads the skipped text into the model's
//! types (unknown fields refused, optional fields may be absent or `null`). A value it refuses is
//! one [`Problem`] at `configuration`, placed where `serde_json` stopped in the file, with its
//! message. Deliberately not here: whether the names are identifiers and each instance's program
//! is a POU of the file — the resolver checks that (`plc_resolve::configuration`).

use super::cursor::{Cursor, P};
use plc_diag::Invalid;
use plc_model::Configuration;
use plc_syntax::{Origin, Problem};

/// Reads the value at the cursor (the cursor moves past it).
pub(super) fn configuration(c: &mut Cursor<'_>) -> P<Result<Configuration, Problem>> {
    let start = c.offset();
    c.skip()?;
    let text = c.since(start);
    Ok(serde_json::from_str(text).map_err(|e| {
        let message = e.to_string();
        let message = match message.rfind(" at line ") {
            Some(i) => message[..i].to_owned(),
            None => message,
        };
        Problem {
            at: "configuration".into(),
            origin: Origin::at(start + offset_of(text, e.line(), e.column())),
            kind: Invalid::Configuration { message },
        }
    }))
}

/// The byte offset in `text` of `serde_json`'s line and column (both from 1; a column 0 is the
/// start of the line).
fn offset_of(text: &str, line: usize, column: usize) -> usize {
    let line_start: usize = text
        .split_inclusive('\n')
        .take(line.saturating_sub(1))
        .map(str::len)
        .sum();
    (line_start + column.saturating_sub(1)).min(text.len())
}

#[cfg(test)]
mod tests {
    use super::offset_of;

    #[test]
    fn the_offset_of_a_line_and_column() {
        assert_eq!(offset_of("ab\ncd", 1, 2), 1);
        assert_eq!(offset_of("ab\ncd", 2, 1), 3);
        assert_eq!(offset_of("ab\ncd", 2, 0), 3);
        assert_eq!(offset_of("ab\ncd", 9, 9), 5);
    }
}
