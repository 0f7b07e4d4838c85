//! plc-deps: dependence analysis, levelling and multicore scan of IEC 61131-3 ladder (LD) and
//! function block diagram (FBD) programs.
//!
//! The pipeline, one module per stage, each importing only from the stages before it:
//! [`read`] (the JSON program format → [`syntax`], the format-neutral surface syntax) →
//! [`resolve`] (names, types, structure, FBD ordering and lowering) → [`model`] (one resolved
//! program) → [`analysis`] (plain functions from the model to result values) → [`report`] (one
//! report document, rendered as text, JSON and DOT; the FBD order too) and [`exec`] (the
//! sequential interpreter and the parallel executor). [`cmd`] holds the commands (`report`,
//! `order`, `run`, `schema`, `gen`) on top. Beside the pipeline: [`diag`] the diagnostics every
//! stage reports (below everything), [`fbd`] the FBD model and its pure ordering and fragment
//! algorithms, [`graph`] the generic graph algorithms (CSR, SCCs, Semi-NCA dominators), and
//! [`synth`] the synthetic programs of `plc-deps gen`; [`write`] the surface syntax back out as
//! the JSON program format (`plc-deps convert`).
pub mod analysis;
pub mod cmd;
pub mod codegen;
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
pub mod write;
