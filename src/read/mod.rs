//! Readers: program files in → the surface syntax ([`crate::syntax`]) → through the resolver
//! ([`crate::resolve`]) one resolved [`crate::model::Program`] out.
//!
//! Three formats: S7-200 STL ([`stl`], docs/il.md), PLCopen TC6 XML ([`plcopen`], docs/plcopen.md) and the JSON program format
//! (docs/format.md, docs/fbd.md; [`json`]), which
//! reads the text into the syntax types in one pass (syntax errors carry line and column; a
//! byte-order mark is skipped), the resolver checks and resolves everything else (those errors
//! carry the rung id, the JSON path and the byte offset of the most precise node, whose line and
//! column are computed once the load has failed; an error found on the model, which has the
//! path of every node but not always its offset, is placed at the node its path names). Nothing is half-built: a program either loads
//! whole or not at all.

pub mod json;
pub mod plcopen;
pub mod st;
pub mod stl;

pub use crate::diag::{Invalid, LoadError, Location};

use crate::fbd::Fbd;
use crate::model::Program;

/// Parses and checks a program given as JSON text.
pub fn program_from_json(text: &str) -> Result<Program, LoadError> {
    program_and_fbd_from_json(text).map(|(p, _)| p)
}

/// Parses and checks a program given as JSON text, and returns with it the FBD bodies it was
/// written in (before lowering: their networks, execution orders and fragment trees).
///
/// The main program's rungs are resolved as they are read ([`crate::resolve::Stream`]), so that
/// the whole syntax tree is never held; should that not resolve, the text is read again into
/// the whole tree, whose resolution gives the program or every error, as it always would.
pub fn program_and_fbd_from_json(text: &str) -> Result<(Program, Fbd), LoadError> {
    let whole = |syntax: &crate::syntax::Program<'_>| {
        crate::resolve::resolve(text, syntax)
            .map_err(|e| e.refine(text, |t, p| json::path_offset(t, p).map(|(start, _)| start)))
    };
    let mut stream = crate::resolve::Stream::default();
    let syntax = if text.len() >= PIPE_FROM && two_cores() {
        crate::syntax::pipe::through_pipe(&mut stream, |sink| json::parse_with(text, Some(sink)))?
    } else {
        json::parse_with(text, Some(&mut stream))?
    };
    if !stream.took_rungs() {
        return whole(&syntax);
    }
    if let Some(done) = stream.finish(&syntax) {
        return Ok(done);
    }
    drop(syntax);
    whole(&json::parse(text)?)
}

/// Files from this size on are read on one thread and resolved on another
/// ([`crate::syntax::pipe`]); below it, starting a thread costs more than it gains.
const PIPE_FROM: usize = 1 << 20;

fn two_cores() -> bool {
    std::thread::available_parallelism().is_ok_and(|n| n.get() > 1)
}

/// Builds a program from an already parsed JSON document (tests and benchmarks that build
/// programs with `serde_json::json!`). Loading from text is the fast path.
pub fn program_from_value(doc: &serde_json::Value) -> Result<Program, LoadError> {
    program_from_json(&doc.to_string())
}

/// [`program_from_value`], with the FBD bodies.
pub fn program_and_fbd_from_value(doc: &serde_json::Value) -> Result<(Program, Fbd), LoadError> {
    program_and_fbd_from_json(&doc.to_string())
}
