//! ST, IL and SFC bodies, until plc-deps reads them: the POU is analysed through its declared
//! interface, with a warning naming the POU and the body's line.
//!
//! The body becomes one rung `<pou>.body` that reads every input (a contact for BOOL, `EQ x x`
//! otherwise) and writes every output, local and external variable with its own value
//! (`move x → x`). So the dependence analysis sees what the interface lets the body read and
//! write — the most it can do — while a `run` leaves those values unchanged (the body is not
//! executed: the warning says so). Function block instances among the locals are not written
//! (only their own box writes them); the warning names them.
//!
//! Deliberately not here: parsing ST or IL, SFC steps and transitions (a later step).

use super::interface::name;
use super::xml::{origin, Note, Notes};
use crate::model::CmpOp;
use crate::syntax::{Compare, Element, ElementKind, Located, Move, Rung, Scalar, Var};
use roxmltree::Node;
use std::borrow::Cow;

const ELEMENTARY: &[&str] = &["BOOL", "INT", "DINT", "REAL", "TIME"];

/// The rungs standing for a body in `lang` (ST, IL, SFC) of POU `pou`: one, or none when the
/// interface has nothing to read or write.
pub fn through_interface(
    lang: &str,
    body: Node,
    pou: &str,
    reads: &[&Var<'static>],
    writes: &[&Var<'static>],
    externals: &[String],
    notes: &mut Notes,
) -> Vec<Rung<'static>> {
    let at = origin(body);
    let mut series = Vec::new();
    for v in reads {
        let var = name(v.name.as_str(), v.origin);
        let kind = if v.ty.as_str() == "BOOL" {
            ElementKind::Contact {
                var,
                negated: false,
                edge: None,
            }
        } else {
            let op = || Located {
                value: Scalar::Str(Cow::Owned(v.name.as_str().to_owned())),
                origin: v.origin,
            };
            ElementKind::Compare(Box::new(Compare {
                op: CmpOp::Eq,
                a: op(),
                b: op(),
            }))
        };
        series.push(vec![Element { origin: at, kind }]);
    }
    let mut skipped = Vec::new();
    let written = writes
        .iter()
        .filter_map(|v| {
            if ELEMENTARY.contains(&v.ty.as_str()) {
                Some(v.name.as_str().to_owned())
            } else {
                skipped.push(v.name.as_str().to_owned());
                None
            }
        })
        .chain(externals.iter().cloned());
    for w in written {
        series.push(vec![Element {
            origin: at,
            kind: ElementKind::Move(Box::new(Move {
                from: Located {
                    value: Scalar::Str(Cow::Owned(w.clone())),
                    origin: at,
                },
                to: name(w, at),
            })),
        }]);
    }
    let mut message = format!(
        "pou {pou}: its {lang} body is not read yet; it is analysed through its interface (inputs read; outputs, locals and externals written) and not executed by `run`"
    );
    if !skipped.is_empty() {
        message.push_str(&format!(
            "; the function block instances {} are not written",
            skipped.join(", ")
        ));
    }
    if series.is_empty() {
        message.push_str("; the interface is empty, so the POU has no rung");
    }
    notes.push(Note {
        origin: at,
        message,
    });
    if series.is_empty() {
        return Vec::new();
    }
    let ld = if series.len() == 1 {
        series.pop().unwrap_or_default()
    } else {
        vec![Element {
            origin: at,
            kind: ElementKind::Branch(series),
        }]
    };
    vec![Rung {
        origin: at,
        id: name(format!("{pou}.body"), at),
        label: None,
        comment: None,
        ld,
        ld_origin: at,
        problem: None,
        problem_in_rung: false,
    }]
}
