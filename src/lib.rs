//! plc-deps: dependence analysis, levelling and multicore scan of IEC 61131-3 ladder (LD) and
//! function block diagram (FBD) programs.
//!
//! The pipeline, one module per stage, each importing only from the stages before it:
//! [`read`] (the JSON program format, PLCopen TC6 XML and S7-200 STL → [`syntax`], the
//! format-neutral surface syntax) → [`resolve`] (names, types, structure, FBD ordering and
//! lowering) → [`model`] (one resolved program; [`load`] joins a reader and the resolver) →
//! [`analysis`] (plain functions from the model to result values) → [`report`] (one report
//! document, rendered as text, JSON, DOT and HTML; the FBD order too), [`exec`] (the sequential
//! interpreter and the parallel executor) and [`codegen`] (C and S7-200 Instruction List).
//! [`cmd`] holds the commands (`report`, `order`, `run`, `schema`, `convert`, `c`, `il`, `gen`)
//! on top. Beside the pipeline: [`diag`] the diagnostics every stage reports and their one
//! renderer (below everything), [`hint`] the cache prefetch hints (below everything too), [`fbd`] the FBD model and its pure ordering and fragment
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
pub mod hint;
pub mod load;
pub mod model;
pub mod read;
pub mod report;
pub mod resolve;
pub mod syntax;
pub mod synth;
pub mod write;
