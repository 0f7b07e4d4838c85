//! plc-deps: dependence analysis, levelling and multicore scan of IEC 61131-3 ladder programs.
//!
//! The pipeline, one module per stage: [`read`] (JSON program format) → [`model`] (one resolved
//! program) → [`analysis`] (plain functions from the model to result values) → [`report`]
//! (text, JSON, DOT). [`graph`] holds the generic graph algorithms the analyses use.
pub mod analysis;
pub mod cmd;
pub mod exec;
pub mod fbd;
pub mod graph;
pub mod model;
pub mod read;
pub mod report;
pub mod synth;
