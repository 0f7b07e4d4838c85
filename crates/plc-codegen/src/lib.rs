//! Code generators: text that a controller runs, generated from the typed surface of a program
//! (ladder rungs as series/parallel element trees, FBD networks as fragment trees), not from
//! the interpreter's lowered instructions.
//!
//! - [`c`]: C for every POU, a runtime header and a harness (the FBD text-generation paper).
//! - [`il`]: S7-200 Instruction List (Zhou & Zhang 2015); read back by `plc_read::stl`.
//!
//! Layer: uses `model`, `fbd`; nothing here imports `cmd`, `exec` or `report`.
#![forbid(unsafe_code)]

pub mod c;
pub mod il;
