//! Function blocks of the editors' libraries that the model lacks, as black boxes: a project
//! that declares an instance of one (and does not define a POU of that name) gets a function
//! block type with the library's interface and one stand-in rung
//! ([`super::textual::stand_in`]) that reads every input and writes every output with its own
//! value. So the analysis sees the instance's inputs read and its outputs written, and `run`
//! leaves the outputs at their initial values (a note says so).
//!
//! The blocks: RTC of IEC 61131-3 (2.5.2.3.5: IN, PDT → Q, CDT; the real-time clock, which
//! Beremiz's standard library implements), its DT values read as DINT like every date and time;
//! Beremiz's LOGGER (TRIG, MSG, LEVEL) and its Python blocks python_eval, python_poll,
//! python_gear (TRIG, CODE [, N] → ACK, RESULT), their strings STRINGs.
//!
//! Deliberately not here: what the blocks compute (a clock has no value a scan could compute
//! without the PLC's time), nor what Python code returns.

use super::interface::name;
use super::textual::{stand_in, Read};
use super::xml::Note;
use plc_diag::Origin;
use plc_syntax::{Body, FunctionBlock, Located, Var, VarClass};
use std::borrow::Cow;

/// A library block: its name, its inputs and outputs (name, model type), and its source.
struct Block {
    name: &'static str,
    inputs: &'static [(&'static str, &'static str)],
    outputs: &'static [(&'static str, &'static str)],
    source: &'static str,
}

const PY_IN: &[(&str, &str)] = &[("TRIG", "BOOL"), ("CODE", "STRING")];
const PY_OUT: &[(&str, &str)] = &[("ACK", "BOOL"), ("RESULT", "STRING")];
const PY_SRC: &str = "Beremiz's py_ext library";

const BLOCKS: &[Block] = &[
    Block {
        name: "RTC",
        inputs: &[("IN", "BOOL"), ("PDT", "DINT")],
        outputs: &[("Q", "BOOL"), ("CDT", "DINT")],
        source: "IEC 61131-3 2.5.2.3.5",
    },
    Block {
        name: "python_eval",
        inputs: PY_IN,
        outputs: PY_OUT,
        source: PY_SRC,
    },
    Block {
        name: "python_poll",
        inputs: PY_IN,
        outputs: PY_OUT,
        source: PY_SRC,
    },
    Block {
        name: "python_gear",
        inputs: &[("N", "DINT"), ("TRIG", "BOOL"), ("CODE", "STRING")],
        outputs: PY_OUT,
        source: PY_SRC,
    },
    Block {
        name: "LOGGER",
        inputs: &[("TRIG", "BOOL"), ("MSG", "STRING"), ("LEVEL", "INT")],
        outputs: &[],
        source: "Beremiz's standard library (LEVEL: LOGLEVEL, read as INT)",
    },
];

/// Beremiz's `LOGLEVEL` enumeration (`(CRITICAL, WARNING, INFO, DEBUG)`), numbered as its
/// compiler numbers enumerations: the value a LOGGER's LEVEL pin fed by `name` reads.
pub(super) fn library_constant(block: &str, pin: &str, name: &str) -> Option<i64> {
    if block != "LOGGER" || pin != "LEVEL" {
        return None;
    }
    let name = name.trim();
    let name = name
        .strip_prefix("LOGLEVEL#")
        .or_else(|| name.strip_prefix("LogLevel#"))
        .unwrap_or(name);
    ["CRITICAL", "WARNING", "INFO", "DEBUG"]
        .iter()
        .position(|v| v.eq_ignore_ascii_case(name))
        .map(|i| i as i64)
}

/// True when `ty` is a library block this module stands in.
pub(super) fn is_library_fb(ty: &str) -> bool {
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
pub(super) fn stand_in_fb(
    ty: &str,
    at: Origin,
    instances: &[String],
) -> Option<(FunctionBlock<'static>, Note)> {
    let b = BLOCKS.iter().find(|b| b.name == ty)?;
    let pins = |v: &[(&str, &str)]| -> Vec<(String, String)> {
        v.iter()
            .map(|(n, t)| (n.to_string(), t.to_string()))
            .collect()
    };
    let fb = stand_in_type(ty, &pins(b.inputs), &pins(b.outputs), at);
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
    Some((fb, note))
}

/// Pins as (name, model type).
type Pins = Vec<(String, String)>;

/// The inputs and outputs (name, model type) of each library block, for typing what they read
/// and feed.
pub(super) fn pins() -> impl Iterator<Item = (&'static str, Pins, Pins)> {
    let own = |v: &[(&str, &str)]| -> Pins {
        v.iter()
            .map(|(n, t)| (n.to_string(), t.to_string()))
            .collect()
    };
    BLOCKS
        .iter()
        .map(move |b| (b.name, own(b.inputs), own(b.outputs)))
}

/// A black-box function block type `ty` with `inputs` and `outputs` (name, model type): one
/// stand-in rung reading every input and writing every output with its own value.
pub(super) fn stand_in_type(
    ty: &str,
    inputs: &[(String, String)],
    outputs: &[(String, String)],
    at: Origin,
) -> FunctionBlock<'static> {
    let reads: Vec<Read> = inputs
        .iter()
        .map(|(n, t)| Read {
            name: n.clone(),
            bool: t == "BOOL",
        })
        .collect();
    let writes: Vec<String> = outputs.iter().map(|(n, _)| n.clone()).collect();
    let body = stand_in(format!("{ty}.body"), at, &reads, &writes);
    FunctionBlock {
        origin: at,
        name: ty.to_owned().into(),
        inputs: inputs
            .iter()
            .map(|(n, t)| var(n, t, VarClass::Input, at))
            .collect(),
        outputs: outputs
            .iter()
            .map(|(n, t)| var(n, t, VarClass::Output, at))
            .collect(),
        vars: Vec::new(),
        body: Some(Body::Rungs(body.into_iter().collect())),
    }
}

/// The black-box type of a block the model lacks ([`super::black_box`]), with its note.
pub(super) fn black_box_type(b: &super::block_types::BlackBox) -> (FunctionBlock<'static>, Note) {
    let fb = stand_in_type(&b.name, &b.sig.inputs, &b.sig.outputs, b.origin);
    let show = |v: &[(String, String)]| {
        v.iter()
            .map(|(n, t)| format!("{n} {t}"))
            .collect::<Vec<_>>()
            .join(", ")
    };
    let note = Note {
        origin: b.origin,
        message: format!(
            "{} is read as a black box (a function block type {} reading its inputs {} and writing its outputs {}): the analysis sees those reads and writes; `run` does not compute it (its outputs keep their initial values). Called at: {}",
            b.op,
            b.name,
            show(&b.sig.inputs),
            show(&b.sig.outputs),
            b.sites.join("; ")
        ),
    };
    let mut note = note;
    if !b.guessed.is_empty() {
        note.message.push_str(&format!(
            ". Outputs that feed nothing, whose type nothing in the file tells, are read as BOOL: {}",
            b.guessed.join(", ")
        ));
    }
    (fb, note)
}
