//! Writers: the surface syntax ([`plc_syntax`]) out as a program file, the inverse of
//! [`plc_read`]. Today one format, the JSON program format ([`json`], docs/format.md and
//! docs/fbd.md), which `plc-deps convert` writes from any file the tool reads (a PLCopen TC6
//! XML export, say), so that what plc-deps understood of a file can be read, diffed and edited.
//!
//! Invariant: a program that loads, written and read back, resolves to the same model
//! (`tests/it/convert.rs` checks it on every committed PLCopen file and every worked example).
//!
//! Deliberately not here: checking the program (the caller loads it first: a syntax tree with
//! problems in it is refused, not written), and writing the model or the analysis (those are
//! reports: the `plc-report` crate).
#![forbid(unsafe_code)]

pub mod json;
