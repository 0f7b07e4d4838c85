//! The commands behind the binary, one module each, as library functions over validated
//! configurations: [`report`], [`order`], [`run`], [`schema`], [`gen`], [`c`], [`il`],
//! [`convert`].
//!
//! `main.rs` turns command-line arguments into these configs and calls one function; everything
//! here returns a [`CliError`] (printed once, by `main`, through [`errors`], which also prints
//! the warnings) instead of printing an error or exiting. [`io`] reads inputs and writes outputs (atomically, never half-written);
//! [`progress`] shows long phases on a terminal; [`pages`] chooses the kind of memory pages the process gets. This is the top layer: nothing below imports it.

mod background;
pub mod c;
pub mod convert;
pub mod errors;
pub mod gen;
pub mod il;
pub mod io;
pub mod order;
// `prctl` (the one system call the standard library does not offer).
#[allow(unsafe_code)]
pub mod pages;
pub mod progress;
pub mod report;
pub mod run;
pub mod schema;
pub mod skipped;
// Mapping a file (memmap2); its caveat is argued at the call.
#[allow(unsafe_code)]
pub mod source;
mod stderr;
mod temp;

pub use io::{CliError, FileRole};
