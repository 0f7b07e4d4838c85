//! plc-deps: dependence analysis, levelling and multicore scan of IEC 61131-3 ladder (LD) and
//! function block diagram (FBD) programs.
//!
//! The library is a workspace of crates, one per layer of the pipeline; each depends only on
//! the layers below it, and Cargo refuses a dependency the other way (it would be a cycle).
//! This facade re-exports each layer under its stage name, so a user needs one dependency.
//! From the bottom (docs/design/architecture.md has the map):
//! - beside every stage: [`diag`] (diagnostics as data, source text, the one renderer),
//!   [`graph`] (CSR, SCCs, Semi-NCA dominators), [`hint`] (cache prefetch hints), [`synth`]
//!   (the synthetic programs of `plc-deps gen`);
//! - [`model`]: the vocabulary (IEC types, operators, standard functions) and the resolved
//!   program; [`fbd`]: FBD bodies, their order and fragments;
//! - [`syntax`] (the format-neutral surface syntax) → [`read`] (the JSON program format,
//!   PLCopen TC6 XML, S7-200 STL) and [`write`] (the syntax back out as JSON) → [`resolve`]
//!   (names, types, structure, FBD lowering) → [`load`] (a reader joined to the resolver);
//! - [`analysis`] (plain functions from the model to result values) → [`report`] (one report
//!   document, rendered as text, JSON, DOT and HTML), [`exec`] (the sequential interpreter and
//!   the parallel executor) → [`codegen`] (C and S7-200 Instruction List);
//! - [`cmd`], in this crate: the commands (`report`, `order`, `run`, `schema`, `convert`, `c`,
//!   `il`, `gen`) that `main.rs` parses arguments for.
// `unsafe` only in the two modules of `cmd` that allow it by name (mapping a file, `prctl`).
#![deny(unsafe_code)]

pub use plc_analysis as analysis;
pub use plc_codegen as codegen;
pub use plc_diag as diag;
pub use plc_exec as exec;
pub use plc_fbd as fbd;
pub use plc_graph as graph;
pub use plc_hint as hint;
pub use plc_load as load;
pub use plc_model as model;
pub use plc_read as read;
pub use plc_report as report;
pub use plc_resolve as resolve;
pub use plc_syntax as syntax;
pub use plc_synth as synth;
pub use plc_write as write;

pub mod cmd;
