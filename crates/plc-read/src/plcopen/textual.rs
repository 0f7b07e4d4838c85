//! Stand-in rungs for bodies plc-deps analyses but does not execute: IL and SFC bodies through
//! their declared interface, and each statement of an ST body ([`super::st_body`]).
//!
//! A stand-in rung reads what it reads (a contact for BOOL, `EQ x x` otherwise) and writes what
//! it writes with its own value (`move x → x`), each in its own branch from the rail. So the
//! dependence analysis sees exactly those reads and writes, while a `run` leaves the values
//! unchanged (the body is not executed: a note says so). Function block instances are not
//! written (only their own box writes them); the note names them.
//!
//! An IL or SFC body becomes one rung `<pou>.body` that reads every input and writes every
//! output, local and external variable — the most its interface lets it do.
//!
//! Deliberately not here: parsing IL, SFC steps and transitions (a later step).

use super::elementary::is_elementary;
use super::interface::name;
use super::xml::{origin, Note, Notes};
use plc_diag::Origin;
use plc_model::CmpOp;
use plc_syntax::{Compare, Element, ElementKind, Located, Move, Rung, Scalar, Var};
use roxmltree::Node;
use std::borrow::Cow;

/// A variable (or a field of an instance) a stand-in rung reads, and whether it is BOOL.
#[derive(Clone, Debug)]
pub(super) struct Read {
    pub name: String,
    pub bool: bool,
}

/// The stand-in rung `id` at `at` reading `reads` and writing `writes` with their own values;
/// none when it reads and writes nothing.
pub(super) fn stand_in(
    id: String,
    at: Origin,
    reads: &[Read],
    writes: &[String],
) -> Option<Rung<'static>> {
    let op = |n: &str| Located {
        value: Scalar::Str(Cow::Owned(n.to_owned())),
        origin: at,
    };
    let mut series: Vec<Vec<Element<'static>>> = Vec::new();
    for r in reads {
        let kind = if r.bool {
            ElementKind::Contact {
                var: name(r.name.as_str(), at),
                negated: false,
                edge: None,
            }
        } else {
            ElementKind::Compare(Box::new(Compare {
                op: CmpOp::Eq,
                a: op(&r.name),
                b: op(&r.name),
            }))
        };
        series.push(vec![Element { origin: at, kind }]);
    }
    for w in writes {
        series.push(vec![Element {
            origin: at,
            kind: ElementKind::Move(Box::new(Move {
                from: op(w),
                to: name(w.as_str(), at),
            })),
        }]);
    }
    let ld = match series.len() {
        0 => return None,
        1 => series.pop().unwrap_or_default(),
        _ => vec![Element {
            origin: at,
            kind: ElementKind::Branch(series),
        }],
    };
    Some(Rung {
        origin: at,
        id: name(id, at),
        label: None,
        comment: None,
        ld,
        ld_origin: at,
        problem: None,
        problem_in_rung: false,
    })
}

/// The rungs standing for a body in `lang` (IL, SFC) of POU `pou`: one, or none when the
/// interface has nothing to read or write.
pub(super) fn through_interface(
    lang: &str,
    body: Node,
    pou: &str,
    reads: &[&Var<'static>],
    writes: &[&Var<'static>],
    externals: &[String],
    notes: &mut Notes,
) -> Vec<Rung<'static>> {
    let at = origin(body);
    let reads: Vec<Read> = reads
        .iter()
        .map(|v| Read {
            name: v.name.as_str().to_owned(),
            bool: v.ty.as_str() == "BOOL",
        })
        .collect();
    let (elementary, instances): (Vec<&&Var>, Vec<&&Var>) =
        writes.iter().partition(|v| is_elementary(v.ty.as_str()));
    let written: Vec<String> = elementary
        .iter()
        .map(|v| v.name.as_str().to_owned())
        .chain(externals.iter().cloned())
        .collect();
    let mut message = format!(
        "pou {pou}: its {lang} body is not read yet; it is analysed through its interface (inputs read; outputs, locals and externals written) and not executed by `run`"
    );
    if !instances.is_empty() {
        let names: Vec<&str> = instances.iter().map(|v| v.name.as_str()).collect();
        message.push_str(&format!(
            "; the function block instances {} are not written",
            names.join(", ")
        ));
    }
    let rung = stand_in(format!("{pou}.body"), at, &reads, &written);
    if rung.is_none() {
        message.push_str("; the interface is empty, so the POU has no rung");
    }
    notes.push(Note {
        origin: at,
        message,
    });
    notes.skipped.push(plc_syntax::SkippedBody {
        pou: pou.to_owned(),
        language: lang.to_owned(),
        origin: at,
        why: None,
    });
    rung.into_iter().collect()
}
