//! Writing C text: [`push`] appends formatted text to a `String`, the buffer every emitter of
//! this back end writes into. Nothing else: what the text says is the emitters' (`ladder`,
//! `kernel`, `table`, `types`, `harness`, `parts`).

use std::fmt::Write as _;

/// Writes `text` into `out` (a `String`, cannot fail).
pub(crate) fn push(out: &mut String, text: std::fmt::Arguments<'_>) {
    out.write_fmt(text).expect("writing to a String");
}
