//! The JSON report: the [`Report`] document serialised as pretty-printed JSON, streamed to the
//! writer (no whole-output string). Keys are normative (docs/report.md): those of the report's
//! first version (`program`, `rungs[].id/in/out`, `dependences[].kind/from/to/var`,
//! `cfg.edges[].from/to/label`, `ipdom`, `levels.data/control/combined`, `cycles.*`,
//! `cost.work/span/makespan`) are a contract: add fields, never rename or drop these.

use super::document::Report;
use std::io::{self, Write};

/// Writes the report as pretty-printed JSON with a trailing newline.
pub fn render_json(report: &Report, out: &mut impl Write) -> io::Result<()> {
    serde_json::to_writer_pretty(&mut *out, report).map_err(io::Error::other)?;
    out.write_all(b"\n")
}
