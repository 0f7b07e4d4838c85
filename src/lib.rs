//! plc-deps: dependence analysis, levelling and multicore scan of IEC 61131-3 ladder programs.
//!
//! The pipeline, one module per stage: [`read`] (JSON program format → [`syntax`], the surface
//! syntax) → [`resolve`] (names, types, structure, FBD planning and lowering) → [`model`] (one
//! resolved program) → [`analysis`] (plain functions from the model to result values) →
//! [`report`] (text, JSON, DOT). [`fbd`] holds the FBD model and its pure ordering and fragment
//! algorithms, [`graph`] the generic graph algorithms the analyses use, [`diag`] the diagnostics
//! every stage reports (below everything).
pub mod analysis;
pub mod cmd;
pub mod diag;
pub mod exec;
pub mod fbd;
pub mod graph;
pub mod model;
pub mod read;
pub mod report;
pub mod resolve;
pub mod syntax;
pub mod synth;
