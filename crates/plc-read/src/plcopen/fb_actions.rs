//! Actions of function blocks called from ST (TC6 `pou/actions/action`, each with a body of its
//! own, besides the POU's main body): CODESYS and TwinCAT let ST code call them as
//! `Inst.A();`, which runs A's body on instance `Inst`'s variables and not the main body
//! (CODESYS manual, "Action" object; IEC 61131-3 3rd ed. 6.6.3 allows actions of function blocks
//! only in SFC, CODESYS extends it).
//!
//! The model has no actions, and the resolver expands each instance into its own POU, so an
//! action is read as a part of its function block's body, selected on entry: the type gets an
//! INT input `st__action` (a compiler name: IEC identifiers have no double `_`), and its body is
//! a dispatch (`st__action = k` jumps to action `k`, 1-based in file order), the main body,
//! then each action: a `ret` ending what comes before, its label on a rung that puts the
//! selector back to 0, and its statements. `Inst.A()` moves `k` into `Inst.st__action` and calls
//! `Inst`; every other call of the instance finds 0 and runs the main body. This keeps one
//! POU per instance, so the action reads and writes the instance's own variables, and the
//! analyses see what it reads and writes through the call, as they see any call of the
//! instance (the call is seen to run the main body or any action: the selector is a value).
//! Chosen over a POU per action sharing the instance's variables, which the resolver's
//! expansion (one POU, its variables `Inst.X`) does not have.
//!
//! Deliberately not here (errors, or refusals of `run` and `c`): an action whose body is not
//! ST (SFC actions of a function block are read with its SFC body, [`super::sfc`]), a main body
//! that is not ST, a call of an action with arguments, and a call of an action from its own
//! function block's body (`A();`), which the analyses read as a call of an unknown function.

use super::interface::Interface;
use super::xml::{error, origin, Tc6, R};
use plc_diag::Origin;
use plc_syntax::{Located, Var, VarClass};
use roxmltree::Node;
use std::borrow::Cow;

/// The name of the INT input that selects what a call of the instance runs: 0 the main body,
/// `k` its `k`-th action.
pub(super) const SELECTOR: &str = "st__action";

/// An action of a function block: its name and the ST element of its body.
pub(super) struct Action<'a, 'i> {
    pub name: String,
    pub st: Node<'a, 'i>,
    pub origin: Origin,
}

/// The body language of `pou`'s main body (the first element of its first `body`).
fn main_language<'a>(tc6: Tc6, pou: Node<'a, '_>) -> Option<&'a str> {
    let b = tc6.child(pou, "body")?;
    tc6.elements(b)
        .find(|e| e.tag_name().name() != "documentation" && e.tag_name().name() != "addData")
        .map(|e| e.tag_name().name())
}

fn action_nodes<'a, 'i>(tc6: Tc6, pou: Node<'a, 'i>) -> Vec<Node<'a, 'i>> {
    tc6.child(pou, "actions")
        .into_iter()
        .flat_map(|a| tc6.children(a, "action"))
        .collect()
}

/// The names of the actions of function block `pou` that ST calls run, in file order: those
/// of a POU whose main body is ST (none otherwise).
pub(super) fn names(tc6: Tc6, pou: Node) -> Vec<String> {
    if pou.attribute("pouType") != Some("functionBlock") || main_language(tc6, pou) != Some("ST") {
        return Vec::new();
    }
    action_nodes(tc6, pou)
        .iter()
        .map(|a| a.attribute("name").unwrap_or("").to_owned())
        .collect()
}

/// Adds the selector input to the interface of function block `pou` when it has actions ST
/// calls run ([`names`]).
pub(super) fn add_selector(tc6: Tc6, pou: Node, iface: &mut Interface) {
    if names(tc6, pou).is_empty() {
        return;
    }
    let at = tc6.child(pou, "actions").map_or(origin(pou), origin);
    let l = |s: &str| Located {
        value: Cow::Owned(s.to_owned()),
        origin: at,
    };
    iface.inputs.push(Var {
        origin: at,
        name: l(SELECTOR),
        ty: l("INT"),
        class: Located {
            value: VarClass::Input,
            origin: at,
        },
        init: None,
        problem: None,
    });
}

/// The actions of function block `pou` (named `name`), each with its ST body: an error for an
/// action without a name or whose body is not ST.
pub(super) fn bodies<'a, 'i>(tc6: Tc6, pou: Node<'a, 'i>, name: &str) -> R<Vec<Action<'a, 'i>>> {
    let place = format!("pou {name}, actions");
    let mut out = Vec::new();
    for a in action_nodes(tc6, pou) {
        let Some(an) = a.attribute("name").filter(|n| !n.trim().is_empty()) else {
            return Err(error(origin(a), &place, "an action without a name"));
        };
        let lang = tc6.child(a, "body").and_then(|b| {
            tc6.elements(b).find(|e| {
                e.tag_name().name() != "documentation" && e.tag_name().name() != "addData"
            })
        });
        match lang {
            Some(st) if st.tag_name().name() == "ST" => out.push(Action {
                name: an.to_owned(),
                st,
                origin: origin(a),
            }),
            Some(other) => {
                return Err(error(
                    origin(other),
                    &place,
                    format!(
                        "action `{an}` of function block `{name}` has an {} body: an action called from ST is read only with an ST body (not yet)",
                        other.tag_name().name()
                    ),
                ))
            }
            None => {
                return Err(error(
                    origin(a),
                    &place,
                    format!("action `{an}` of function block `{name}` has no body"),
                ))
            }
        }
    }
    Ok(out)
}

/// The label of action `k` (1-based) in its function block's body.
pub(super) fn label(k: usize) -> String {
    format!("st__act{k}")
}
