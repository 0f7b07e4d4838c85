//! Readers: program files in → the surface syntax ([`plc_syntax`]). Nothing here resolves a
//! name: the `plc-load` crate, above this one, puts a reader and the resolver together.
//!
//! Three formats: S7-200 STL ([`stl`], docs/il.md), PLCopen TC6 XML ([`plcopen`], docs/plcopen.md) and the JSON program format
//! (docs/format.md, docs/fbd.md; [`json`]), which
//! reads the text into the syntax types in one pass (syntax errors carry line and column; a
//! byte-order mark is skipped), the resolver checks and resolves everything else (those errors
//! carry the rung id, the JSON path and the byte offset of the most precise node, whose line and
//! column are computed once the load has failed; an error found on the model, which has the
//! path of every node but not always its offset, is placed at the node its path names). Nothing is half-built: a program either loads
//! whole or not at all.
#![forbid(unsafe_code)]

pub mod json;
pub mod plcopen;
pub mod st;
pub mod stl;

pub use plc_diag::{Invalid, LoadError, Location};
