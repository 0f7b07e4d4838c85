//! Function blocks of the editors' libraries that the model lacks, as black boxes: a project
//! that declares an instance of one (and does not define a POU of that name) gets a function
//! block type with the library's interface and one stand-in rung
//! ([`super::textual::stand_in`]) that reads every input and writes every output with its own
//! value. So the analysis sees the instance's inputs read and its outputs written, and `run`
//! leaves the outputs at their initial values (a note says so).
//!
//! The blocks: RTC of IEC 61131-3 (2.5.2.3.5: IN, PDT → Q, CDT; the real-time clock, which
//! Beremiz's standard library implements), its DT values read as DINT like every date and time.
//!
//! Deliberately not here: what the blocks compute (a clock has no value a scan could compute
//! without the PLC's time), and blocks with string pins (the model has no strings).

use super::interface::name;
use super::textual::{stand_in, Read};
use super::xml::Note;
use crate::diag::Origin;
use crate::syntax::{Body, FunctionBlock, Located, Var, VarClass};
use std::borrow::Cow;

/// A library block: its name, its inputs and outputs (name, model type), and its source.
struct Block {
    name: &'static str,
    inputs: &'static [(&'static str, &'static str)],
    outputs: &'static [(&'static str, &'static str)],
    source: &'static str,
}

const BLOCKS: &[Block] = &[Block {
    name: "RTC",
    inputs: &[("IN", "BOOL"), ("PDT", "DINT")],
    outputs: &[("Q", "BOOL"), ("CDT", "DINT")],
    source: "IEC 61131-3 2.5.2.3.5",
}];

/// True when `ty` is a library block this module stands in.
pub fn is_library_fb(ty: &str) -> bool {
    BLOCKS.iter().any(|b| b.name == ty)
}

fn var(n: &str, ty: &str, class: VarClass, at: Origin) -> Var<'static> {
    Var {
        origin: at,
        name: name(n, at),
        ty: Located {
            value: Cow::Owned(ty.to_owned()),
            origin: at,
        },
        class: Located {
            value: class,
            origin: at,
        },
        init: None,
        problem: None,
    }
}

/// The stand-in function block type `ty` (an instance of it is declared at `at`, named
/// `instances` for the note), or `None` when `ty` is not a library block.
pub fn stand_in_fb(
    ty: &str,
    at: Origin,
    instances: &[String],
) -> Option<(FunctionBlock<'static>, Note)> {
    let b = BLOCKS.iter().find(|b| b.name == ty)?;
    let inputs: Vec<Var<'static>> = b
        .inputs
        .iter()
        .map(|(n, t)| var(n, t, VarClass::Input, at))
        .collect();
    let outputs: Vec<Var<'static>> = b
        .outputs
        .iter()
        .map(|(n, t)| var(n, t, VarClass::Output, at))
        .collect();
    let reads: Vec<Read> = b
        .inputs
        .iter()
        .map(|(n, t)| Read {
            name: (*n).to_owned(),
            bool: *t == "BOOL",
        })
        .collect();
    let writes: Vec<String> = b.outputs.iter().map(|(n, _)| (*n).to_owned()).collect();
    let body = stand_in(format!("{ty}.body"), at, &reads, &writes);
    let show = |v: &[(&str, &str)]| v.iter().map(|(n, _)| *n).collect::<Vec<_>>().join(", ");
    let note = Note {
        origin: at,
        message: format!(
            "{} {} of the library block {ty} ({}): a black box that reads its inputs {} and writes its outputs {}; `run` does not compute it (its outputs keep their initial values)",
            if instances.len() == 1 { "instance" } else { "instances" },
            instances.join(", "),
            b.source,
            show(b.inputs),
            show(b.outputs)
        ),
    };
    let fb = FunctionBlock {
        origin: at,
        name: ty.to_owned().into(),
        inputs,
        outputs,
        vars: Vec::new(),
        body: Some(Body::Rungs(body.into_iter().collect())),
    };
    Some((fb, note))
}
