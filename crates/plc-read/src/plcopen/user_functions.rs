//! The project's own functions (TC6 `pou pouType="function"`, IEC 61131-3 3rd ed., 6.6.2) made
//! callable from ST bodies: each function that an ST body calls becomes a function block type
//! of the model, `st__fn__F` (a compiler name: IEC identifiers have no double `_`), whose
//! inputs are the function's inputs, whose outputs are its outputs and its result (a variable
//! named like the function, as IEC and matiec have it: `F := a + b;`), whose variables are its
//! locals, and whose body is the function's body read as any POU's (ST, LD, FBD, IL). A body
//! that calls `F` calls it through one instance of that type, `st__F`
//! ([`super::st_lower`]'s `functions`): the arguments moved into the inputs, every other
//! variable of the function started from its initial value (its type's default without one),
//! a `call`, the result and the outputs moved out. That start on every call is what makes the
//! instance a function: nothing is kept between calls, as matiec's generated C declares a
//! function's variables, with their initial values, on each call (`generate_c.cc`,
//! `localinit_vf`; the result with its type's default).
//!
//! Which functions can be called is found before the other bodies are read: every function's
//! body is read (on notes of its own), and a function whose body cannot be read or executed,
//! or that calls itself directly or through others (IEC 61131-3 2.5: program organisation units
//! shall not be recursive), is refused with that reason; its callers' calls are then refused
//! naming it, and the reading starts again until nothing more is refused.
//!
//! Invariant: only the functions some body calls (directly or through other functions) become
//! types; the others keep the note they had (their bodies are not part of the model).
//! A block of an LD or FBD body that calls `F` is the same call on an instance of its own,
//! `F__<localId>` ([`super::black_box::rewrite`]; an FBD arc reads the instance's output when
//! its reader runs, so two calls must not share one); its `OUT` pin is the result `F`
//! ([`call_pins`]). A function whose body is read but refused by the resolver is read again as
//! a black box (`plc_load` names it in `Notes::refuse_functions`).
//!
//! An IL body calls a function as ST does: `super::il_body` translates `F x` and `F( a := x )`
//! into the ST call.
//!
//! Deliberately not here: VAR_IN_OUT of functions (refused).

use super::xml::{Note, Notes, R};
use plc_syntax::{Body, Element, ElementKind, Located, Move, Rung, Scalar, Var};
use std::borrow::Cow;
use std::collections::HashMap;

/// The function block type a function `f` is executed as.
pub(super) fn type_name(f: &str) -> String {
    format!("st__fn__{f}")
}

/// The functions of `sigs` whose calls are executed: lower-case name → name as declared.
pub(super) fn executed(sigs: &HashMap<String, FnSig>) -> HashMap<String, String> {
    sigs.iter()
        .filter(|(_, s)| s.refused.is_none())
        .map(|(k, s)| (k.clone(), s.name.clone()))
        .collect()
}

/// In `blocks` (one FBD network), the pins of the calls of functions executed as their type
/// ([`type_name`]): the result, which LD and FBD call `OUT` (or leave unnamed, the first
/// output), is the type's output named like the function.
pub(super) fn call_pins(blocks: &mut [plc_syntax::fbd::Block<'static>]) {
    use plc_syntax::fbd::{Connection, Inputs, Outputs};
    let result: HashMap<u32, String> = blocks
        .iter()
        .filter_map(|b| {
            let f = b.op.as_ref().ok()?.strip_prefix("st__fn__")?;
            Some((*b.id.as_ref().ok()?, f.to_owned()))
        })
        .collect();
    if result.is_empty() {
        return;
    }
    let is_out = |p: &Option<plc_syntax::fbd::Read<plc_syntax::Text<'static>>>| match p {
        None => true,
        Some(Ok(n)) => n.eq_ignore_ascii_case("OUT"),
        Some(Err(_)) => false,
    };
    for b in blocks.iter_mut() {
        let mut inputs: Vec<&mut plc_syntax::fbd::Input<'static>> = match &mut b.inputs {
            Some(Ok(Inputs::List(v))) => v.iter_mut().collect(),
            Some(Ok(Inputs::Named(v))) => v.iter_mut().map(|(_, i)| i).collect(),
            _ => Vec::new(),
        };
        inputs.extend(b.cond.as_mut());
        for i in inputs {
            if let Connection::Arc { block, pin } = &mut i.from {
                if let Some(f) = result.get(block) {
                    if is_out(pin) {
                        *pin = Some(Ok(Cow::Owned(f.clone())));
                    }
                }
            }
        }
        let Some(f) = b.id.as_ref().ok().and_then(|id| result.get(id)) else {
            continue;
        };
        if let Some(Ok(Outputs::Named(v))) = &mut b.outputs {
            for (pin, _) in v.iter_mut() {
                if pin.eq_ignore_ascii_case("OUT") {
                    *pin = Cow::Owned(f.clone());
                }
            }
        }
    }
}

/// A function of the project as a body may call it.
#[derive(Clone, Debug)]
pub(super) struct FnSig {
    /// The name as declared.
    pub name: String,
    /// The function block type it is executed as ([`type_name`]).
    pub ty: String,
    /// Inputs and outputs (name as declared, model type), in declaration order; the result
    /// is not among the outputs.
    pub inputs: Vec<(String, String)>,
    pub outputs: Vec<(String, String)>,
    /// The result's model type.
    pub ret: String,
    /// Every variable of the function (inputs, outputs, locals, the result) with its type and
    /// its initial value, which a call starts it from (`None`: the type's default).
    pub starts: Vec<(String, String, Option<Scalar<'static>>)>,
    /// Why a call of it cannot be executed.
    pub refused: Option<String>,
}

/// The signature of function `name` whose interface lists are `inputs`, `outputs` (the
/// result, named `name`, last) and `locals`.
pub(super) fn sig(
    name: &str,
    inputs: &[Var<'static>],
    outputs: &[Var<'static>],
    locals: &[Var<'static>],
    ret: Option<&str>,
) -> FnSig {
    let pins = |v: &[Var]| -> Vec<(String, String)> {
        v.iter()
            .filter(|v| !v.name.as_str().eq_ignore_ascii_case(name))
            .map(|v| (v.name.as_str().to_owned(), v.ty.as_str().to_owned()))
            .collect()
    };
    let starts = inputs
        .iter()
        .chain(outputs)
        .chain(locals)
        .map(|v| {
            (
                v.name.as_str().to_owned(),
                v.ty.as_str().to_owned(),
                v.init.as_ref().map(|i| i.value.clone()),
            )
        })
        .collect();
    let mut refused = None;
    if ret.is_none() {
        refused = Some("its result's type is not one the model executes".to_owned());
    }
    if let Some(v) = inputs.iter().chain(outputs).chain(locals).find(|v| {
        plc_model::Type::parse(v.ty.as_str()).is_none_or(|t| matches!(t, plc_model::Type::Fb(_)))
    }) {
        refused = Some(format!(
            "its variable `{}` is of type {}, which a call cannot start (only elementary variables are)",
            v.name.as_str(),
            v.ty.as_str()
        ));
    }
    FnSig {
        name: name.to_owned(),
        ty: type_name(name),
        inputs: pins(inputs),
        outputs: pins(outputs),
        ret: ret.unwrap_or("?").to_owned(),
        starts,
        refused,
    }
}

/// Reads the body of the function of a given index, its scope seeing the functions given.
pub(super) type ReadBody<'a> =
    dyn FnMut(usize, &HashMap<String, FnSig>, &mut Notes) -> R<Body<'static>> + 'a;

/// A function's body as read, with the notes its reading made.
pub(super) struct ReadFn {
    pub body: Body<'static>,
    pub notes: Notes,
}

/// Reads the bodies of functions `funcs` (an index the caller knows them by, and the name)
/// with `read_body`, until every function left callable reads and executes; `sigs` (by
/// lower-case name) gets each refused function's reason. Returns the bodies read.
pub(super) fn read_all(
    funcs: &[(usize, String)],
    sigs: &mut HashMap<String, FnSig>,
    exec: bool,
    read_body: &mut ReadBody,
) -> HashMap<usize, ReadFn> {
    loop {
        let mut done: HashMap<usize, ReadFn> = HashMap::new();
        let mut refused = Vec::new();
        for (i, name) in funcs {
            let key = name.to_ascii_lowercase();
            if sigs.get(&key).is_none_or(|s| s.refused.is_some()) {
                continue;
            }
            let mut notes = Notes {
                exec,
                ..Notes::default()
            };
            match read_body(*i, sigs, &mut notes) {
                Err(e) => refused.push((key, format!("its body is not read: {e}"))),
                Ok(mut body) => {
                    let started = start(&mut body, &sigs[&key]);
                    if let Err(why) = started {
                        refused.push((key, why));
                    } else if let Some((_, n)) = notes.no_run.first() {
                        refused.push((key, n.message.clone()));
                    } else if let Some(s) = notes.skipped.first() {
                        let why = match &s.why {
                            Some((_, w)) => {
                                format!("its {} body has {w}, which is not executed", s.language)
                            }
                            None => format!("its {} body is not executed", s.language),
                        };
                        refused.push((key, why));
                    } else {
                        done.insert(*i, ReadFn { body, notes });
                    }
                }
            }
        }
        // Recursion: a function that reaches itself through the instances its body declares.
        let calls = |i: usize| -> Vec<String> {
            done.get(&i)
                .map(|r| {
                    r.notes
                        .ld_vars
                        .iter()
                        .filter_map(|(_, v)| v.ty.as_str().strip_prefix("st__fn__"))
                        .map(|f| f.to_ascii_lowercase())
                        .collect()
                })
                .unwrap_or_default()
        };
        let by_key: HashMap<String, usize> = funcs
            .iter()
            .map(|(i, n)| (n.to_ascii_lowercase(), *i))
            .collect();
        for (i, name) in funcs {
            if !done.contains_key(i) {
                continue;
            }
            let me = name.to_ascii_lowercase();
            // Depth-first from `me`, the path kept, until `me` is met again.
            let mut stack = vec![(me.clone(), vec![sigs[&me].name.clone()])];
            let mut seen = Vec::new();
            while let Some((f, path)) = stack.pop() {
                let Some(&fi) = by_key.get(&f) else { continue };
                for g in calls(fi) {
                    let mut p = path.clone();
                    p.push(sigs.get(&g).map_or(g.clone(), |s| s.name.clone()));
                    if g == me {
                        refused.push((
                            me.clone(),
                            format!(
                                "it calls itself ({}), and IEC 61131-3 (2.5) forbids recursion",
                                p.join(" → ")
                            ),
                        ));
                        stack.clear();
                        break;
                    }
                    if !seen.contains(&g) {
                        seen.push(g.clone());
                        stack.push((g, p));
                    }
                }
            }
        }
        if refused.is_empty() {
            return done;
        }
        for (key, why) in refused {
            if let Some(s) = sigs.get_mut(&key) {
                s.refused.get_or_insert(why);
            }
        }
    }
}

/// The functions a body with extra variables `vars` calls (lower case), through the instances
/// the lowering declared.
pub(super) fn called<'a>(vars: impl Iterator<Item = &'a Var<'static>>) -> Vec<String> {
    vars.filter_map(|v| v.ty.as_str().strip_prefix("st__fn__"))
        .map(|f| f.to_ascii_lowercase())
        .collect()
}

/// The note of a function that some body calls.
pub(super) fn executed_note(at: plc_diag::Origin, name: &str) -> Note {
    Note {
        origin: at,
        message: format!("pou {name}: a function; its calls in ST bodies are executed as calls of its body (function block type {}, one instance per calling body, every variable started from its initial value on each call as matiec does); and in LD and FBD bodies likewise (one instance per block)", type_name(name)),
    }
}

/// Adds to function `name`'s outputs its result: a variable named like the function, of its
/// return type (IEC 61131-3 6.6.2.2: the body assigns it), when the model can read the type.
pub(super) fn add_result(name: &str, iface: &mut super::interface::Interface) {
    let (Some(ty), Some(at)) = (iface.return_ty.clone(), iface.returns) else {
        return;
    };
    let l = |s: String| plc_syntax::Located {
        value: std::borrow::Cow::Owned(s),
        origin: at,
    };
    iface.outputs.push(Var {
        origin: at,
        name: l(name.to_owned()),
        ty: l(ty),
        class: plc_syntax::Located {
            value: plc_syntax::VarClass::Output,
            origin: at,
        },
        init: None,
        problem: None,
    });
}

/// The signatures of the functions among the POUs `read` (name, kind, interface), by lower-case
/// name.
pub(super) fn sigs(
    read: &[(roxmltree::Node, String, &str, super::interface::Interface)],
) -> HashMap<String, FnSig> {
    read.iter()
        .filter(|r| r.2 == "function")
        .map(|(_, n, _, i)| {
            let mut s = sig(n, &i.inputs, &i.outputs, &i.locals, i.return_ty.as_deref());
            if let Some(g) = i.globals.first() {
                s.refused = Some(format!(
                    "it declares a global variable, `{}`",
                    g.name.as_str()
                ));
            }
            (n.to_ascii_lowercase(), s)
        })
        .collect()
}

/// The functions (lower case) that the bodies whose extra variables are `vars` call, directly
/// or through the functions of `funcs` read as `bodies`.
pub(super) fn used(
    vars: &[(String, Var<'static>)],
    funcs: &[(usize, String)],
    bodies: &HashMap<usize, ReadFn>,
) -> Vec<String> {
    let mut used = called(vars.iter().map(|(_, v)| v));
    let mut k = 0;
    while k < used.len() {
        let f = &used[k];
        let more = funcs
            .iter()
            .find(|(_, n)| n.eq_ignore_ascii_case(f))
            .and_then(|(i, _)| bodies.get(i))
            .map(|r| called(r.notes.ld_vars.iter().map(|(_, v)| v)))
            .unwrap_or_default();
        for g in more {
            if !used.contains(&g) {
                used.push(g);
            }
        }
        k += 1;
    }
    used
}

/// The default value of type `t` (IEC 61131-3 2.3.3.1, Table 13: 0, FALSE, T#0s, '').
pub(super) fn default_of(t: plc_model::Type) -> Scalar<'static> {
    use plc_model::Type;
    match t {
        Type::Bool => Scalar::Bool(false),
        Type::Time => Scalar::Str(Cow::Borrowed("T#0s")),
        Type::String => Scalar::Str(Cow::Borrowed("''")),
        _ => Scalar::Number(0.into()),
    }
}

/// The variables of function `sig` that a call starts, with their types and the values they
/// start from: its outputs, its result and its locals (its inputs the caller writes), each at
/// its initial value, its type's default without one.
fn start_values(sig: &FnSig) -> Result<Vec<(&str, plc_model::Type, Scalar<'static>)>, String> {
    let mut out = Vec::new();
    for (name, ty, init) in &sig.starts {
        if sig.inputs.iter().any(|(n, _)| n == name) {
            continue;
        }
        let Some(t) = plc_model::Type::parse(ty) else {
            return Err(format!("its variable `{name}` is of type {ty}"));
        };
        out.push((
            name.as_str(),
            t,
            init.clone().unwrap_or_else(|| default_of(t)),
        ));
    }
    Ok(out)
}

/// [`start`] for an FBD body (or an LD body read as data flow): a first network `F.start` of
/// MOVE blocks from the initial values.
fn start_network(body: &mut plc_syntax::FbdBody<'static>, sig: &FnSig) -> Result<(), String> {
    use plc_syntax::fbd::{Connection, Input, Network, OutVar};
    let at = body.origin;
    // Ids above every block id of the body (ids are unique in a POU).
    let first = body
        .networks
        .iter()
        .filter_map(|n| n.blocks.as_ref().ok())
        .flatten()
        .filter_map(|b| b.id.as_ref().ok().copied())
        .max()
        .unwrap_or(0)
        + 1;
    let mut blocks = Vec::new();
    for (k, (name, _, value)) in start_values(sig)?.into_iter().enumerate() {
        let from = Input {
            origin: at,
            from: Connection::Constant(value),
        };
        let to = OutVar {
            origin: at,
            name: Cow::Owned(name.to_owned()),
        };
        blocks.push(super::pins::move_block(first + k as u32, from, to, at));
    }
    if !blocks.is_empty() {
        body.networks.insert(
            0,
            Network {
                origin: at,
                id: Ok(Cow::Owned(format!("{}.start", sig.name))),
                label: None,
                comment: None,
                blocks: Ok(blocks),
                order: None,
                problem: None,
            },
        );
    }
    Ok(())
}

/// Puts before function `sig`'s body the rungs that start its outputs, its result and its
/// locals from their initial values on every call (its inputs the caller writes), as matiec's
/// generated C declares them; an FBD body (or an LD body read as data flow) gets them as its
/// first network ([`start_network`]).
fn start(body: &mut Body<'static>, sig: &FnSig) -> Result<(), String> {
    let rungs = match body {
        Body::Rungs(r) => r,
        Body::Fbd(f) => return start_network(f, sig),
    };
    let at = rungs.first().map_or(plc_diag::Origin::NONE, |r| r.origin);
    let l = |s: String| Located {
        value: Cow::Owned(s),
        origin: at,
    };
    let mut pre = Vec::new();
    for (name, t, value) in start_values(sig)? {
        let name = name.to_owned();
        let kind = match (t, &value) {
            (plc_model::Type::Bool, Scalar::Bool(true)) => ElementKind::Set(l(name)),
            (plc_model::Type::Bool, Scalar::Bool(false)) => ElementKind::Reset(l(name)),
            _ => ElementKind::Move(Box::new(Move {
                from: Located { value, origin: at },
                to: l(name),
            })),
        };
        pre.push(Rung {
            origin: at,
            id: l(format!("{}.start{}", sig.name, pre.len() + 1)),
            label: None,
            comment: None,
            ld: vec![Element { origin: at, kind }],
            ld_origin: at,
            problem: None,
            problem_in_rung: false,
        });
    }
    rungs.splice(0..0, pre);
    Ok(())
}
