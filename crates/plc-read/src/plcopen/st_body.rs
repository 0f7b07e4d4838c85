//! ST bodies (TC6 `ST`, its text in an XHTML element, usually as CDATA) → one stand-in rung per
//! top-level statement ([`super::textual::stand_in`]), from what the ST parser
//! ([`crate::st`], IEC 61131-3 7.3) finds each statement reads and writes.
//!
//! A statement `k` (1-based, in text order) of POU `P` is rung `P.stk`, located at the
//! statement's line and column in the XML file: the offsets of the ST text are translated to
//! offsets of the file through its CDATA sections, entity and character references and line
//! ends ([`file_offsets`]). A compound statement (IF, CASE, FOR, WHILE, REPEAT) is one rung with
//! everything any of its parts reads (conditions and bounds included) and writes. Names resolve
//! case-insensitively against the POU's declarations ([`Scope`]); a structure's field
//! (`s.f`, the ST parser's access path) is its own variable, a structure named whole reads or
//! writes every field, a field the structure lacks is an error naming the fields it has; a read of a standard function
//! block instance reads its first output field (`T1.Q`, `B.Q1`, `C.QU`), which the analysis
//! counts as reading the instance. A call of a standard function block instance (`T1(IN := x)`) is
//! its box in the stand-in (with constant operands: the
//! arguments are the statement's reads), which reads and writes the instance; a call of a user
//! instance is a `call` of its POU. The values of the project's enumerations are constants. Not
//! seen by the analysis, and named in the POU's note: writes of instances of types neither
//! standard nor the project's, reads of user function block instances, direct addresses
//! (`%IX0.1`); a call of a function (standard, of the project or
//! unknown) is a black box whose arguments are read and whose result and outputs are written where
//! the call assigns them. A name that is neither declared nor called (a
//! function) is an error at its statement; so is an ST syntax error, at its line and column.
//!
//! A pragma where a statement stands (`{…}`, Beremiz's C code `{{…}}`) is a statement plc-deps
//! cannot see into: its rung reads and writes every elementary variable the body sees, a
//! warning names its line, and `run`/`c` refuse the POU.
//!
//! For `run` and `c` ([`super::xml::Notes::exec`]) the same body is also lowered to executable
//! rungs ([`super::st_lower`]); when every statement lowers, those rungs (and their
//! temporaries) replace the stand-ins, otherwise the body is marked skipped with the construct
//! that does not lower and where it is, and `run`/`c` refuse it. The note says which.
//!
//! Deliberately not here: the lowering itself ([`super::st_lower`]), IL and SFC (through their
//! interface, [`super::textual`]).

use super::st_lower::{self, Lower};
use super::st_scope::{Decl, Scope};
use super::textual::{stand_in, Read};
use super::xml::{error, origin, Note, Notes, R};
use crate::st;
use plc_diag::Origin;
use plc_syntax::Rung;
use roxmltree::Node;

/// What the statements of a body leave out of the analysis, for the note.
#[derive(Default)]
struct Unseen {
    instances_written: Vec<String>,
    instances_read: Vec<String>,
    addresses: Vec<String>,
    functions: Vec<String>,
    /// The project's functions it calls, executed (seen through their bodies).
    user_functions: Vec<String>,
}

fn push_once(v: &mut Vec<String>, s: &str) {
    if !v.iter().any(|x| x == s) {
        v.push(s.to_owned());
    }
}

/// The rungs of ST body `node` of POU `pou`: one per top-level statement that reads or writes
/// something.
pub(super) fn rungs(
    node: Node,
    pou: &str,
    scope: &Scope,
    notes: &mut Notes,
) -> R<Vec<Rung<'static>>> {
    rungs_with_actions(node, &[], pou, scope, notes)
}

/// A part of a function block's body with actions ([`super::fb_actions`]).
enum Piece<'a, 'i> {
    /// The statements of an ST text.
    Texts(Node<'a, 'i>),
    /// The jumps to the actions (how many, where the first is).
    Dispatch(usize, Origin),
    /// The start of action `k` (1-based): a `ret` ending what comes before, then its label on
    /// the rung that puts the selector back to 0.
    Enter(usize, String, Origin),
}

/// [`rungs`] of the main body `node` of a function block and of its `actions`, one body
/// dispatching on the selector input ([`super::fb_actions`]); the statements are numbered on
/// from the main body's through each action's, in file order.
pub(super) fn rungs_with_actions(
    node: Node,
    actions: &[super::fb_actions::Action],
    pou: &str,
    scope: &Scope,
    notes: &mut Notes,
) -> R<Vec<Rung<'static>>> {
    let place = format!("pou {pou}, ST");
    let source = node.document().input_text();
    let mut out = Vec::new();
    let mut unseen = Unseen::default();
    let mut k = 0;
    let mut lower = Lower::new(scope, pou);
    let mut refused: Option<(Origin, String)> = None;
    // The instances the stand-ins call the project's functions through.
    let mut declared: Vec<String> = Vec::new();
    let mut pieces = Vec::new();
    if let Some(first) = actions.first() {
        pieces.push(Piece::Dispatch(actions.len(), first.origin));
    }
    pieces.push(Piece::Texts(node));
    for (i, a) in actions.iter().enumerate() {
        pieces.push(Piece::Enter(i + 1, a.name.clone(), a.origin));
        pieces.push(Piece::Texts(a.st));
    }
    for piece in pieces {
        let body = match piece {
            Piece::Texts(b) => b,
            other => {
                synthetic(other, pou, &mut out, &mut lower);
                continue;
            }
        };
        for t in body.descendants().filter(|d| d.is_text()) {
            let text = t.text().unwrap_or("");
            if text.trim().is_empty() {
                continue;
            }
            let map = file_offsets(source, t.range().start, text);
            let at = |off: usize| match &map {
                Some(m) => Origin::at(m.get(off).copied().unwrap_or(t.range().start)),
                None => origin(t),
            };
            let statements = st::statements(text)
                .map_err(|e| error(at(e.at), &place, format!("ST syntax error: {}", e.message)))?;
            if let (None, Some(p)) = (&refused, st_lower::first_pragma(text)) {
                refused = Some((
                    at(p),
                    "a pragma `{…}` (matiec copies its text, C code, into what it generates)"
                        .to_owned(),
                ));
            }
            lower.text(map.clone(), origin(t));
            lower.prepare(&statements);
            for s in &statements {
                k += 1;
                if refused.is_none() {
                    if let Err(r) = lower.top(k, s) {
                        refused = Some((lower.origin(r.at), r.what));
                    }
                }
                if s.kind == st::ast::Stmt::Empty {
                    continue;
                }
                let here = at(s.at);
                let a = st::accesses(s);
                let (mut reads, mut writes, boxes) =
                    resolve(&a, scope, &mut unseen, pou).map_err(|m| error(here, &place, m))?;
                if a.pragma {
                    everything(scope, &mut reads, &mut writes);
                    let (l, c) = here.line_column(source).unwrap_or((0, 0));
                    notes.push(Note {
                    origin: here,
                    message: format!("{place}: statement {k} (at {l}:{c}) holds a pragma `{{…}}`, C code that matiec copies into what it generates and plc-deps cannot see into: the analysis takes it as reading and writing every variable of `{pou}`, and `run` and `c` refuse `{pou}`"),
                });
                }
                let id = format!("{pou}.st{k}");
                let mut rung = stand_in(id.clone(), here, &reads, &writes);
                // The analysis sees a call of a user instance as the call of its POU (what its
                // body reads and writes); a run never executes it from a stand-in.
                if !notes.exec {
                    // A standard instance it calls or writes: its box, reading and writing it.
                    for (inst, ty) in &boxes {
                        let r = rung.get_or_insert_with(|| empty_rung(id.clone(), here));
                        r.ld.extend(standard_box(inst, ty, here));
                    }
                    let calls = user_calls(&a, scope);
                    for (inst, ty) in function_calls(&a, scope) {
                        if !declared.contains(&inst) {
                            notes
                                .ld_vars
                                .push((pou.to_owned(), instance_var(&inst, &ty, here)));
                            declared.push(inst.clone());
                        }
                    }
                    let fns = function_calls(&a, scope).into_iter().map(|(i, _)| i);
                    for inst in calls.into_iter().chain(fns) {
                        let r = rung.get_or_insert_with(|| empty_rung(id.clone(), here));
                        r.ld.push(plc_syntax::Element {
                            origin: here,
                            kind: plc_syntax::ElementKind::Call(plc_syntax::Located {
                                value: inst.into(),
                                origin: here,
                            }),
                        });
                    }
                }
                out.extend(rung);
            }
        }
    }
    lower.finish();
    let executed = match &refused {
        None => {
            "executed by `run` and `c` as the rungs it is lowered to (docs/plcopen.md, ST bodies)"
                .to_owned()
        }
        Some((at, what)) => {
            let (l, c) = at.line_column(source).unwrap_or((0, 0));
            format!("not executed by `run` or `c`: {what} at {l}:{c} is not executed yet")
        }
    };
    notes.push(Note {
        origin: origin(node),
        message: message(pou, k, &unseen, &executed) + &actions_note(actions),
    });
    match refused {
        Some(why) => notes.skipped.push(plc_syntax::SkippedBody {
            pou: pou.to_owned(),
            language: "ST".into(),
            origin: origin(node),
            why: Some(why),
        }),
        // `run` and `c` execute the lowered rungs; the analyses keep a rung per statement.
        None if notes.exec => {
            notes
                .ld_vars
                .extend(lower.vars.into_iter().map(|v| (pou.to_owned(), v)));
            return Ok(lower.rungs);
        }
        None => {}
    }
    Ok(out)
}

/// What the note of a function block's ST body says of its actions (nothing without).
fn actions_note(actions: &[super::fb_actions::Action]) -> String {
    if actions.is_empty() {
        return String::new();
    }
    let names: Vec<&str> = actions.iter().map(|a| a.name.as_str()).collect();
    format!(
        "; its actions {} are part of the body, after the main body's statements, numbered on from them: a call `Inst.A()` moves A's number into `Inst.{}` and calls the instance, which runs A (docs/plcopen.md, Actions of function blocks)",
        names.join(", "),
        super::fb_actions::SELECTOR
    )
}

/// A rung of a [`Piece`]: its label, if any, and its elements.
type LabelledRung = (Option<String>, Vec<plc_syntax::ElementKind<'static>>);

/// The rungs of a [`Piece`] that is not ST text, as stand-ins (`out`) and as lowered rungs.
fn synthetic(piece: Piece, pou: &str, out: &mut Vec<Rung<'static>>, lower: &mut Lower) {
    use super::fb_actions::{label, SELECTOR};
    use plc_syntax::{Compare, ElementKind, Move, Scalar};
    let (unit, here, rungs): (String, Origin, Vec<LabelledRung>) = match piece {
        Piece::Texts(_) => return,
        Piece::Dispatch(n, here) => {
            let l = |s: String| plc_syntax::Located {
                value: s.into(),
                origin: here,
            };
            let jumps = (1..=n)
                .map(|k| {
                    let cmp = ElementKind::Compare(Box::new(Compare {
                        op: plc_model::CmpOp::Eq,
                        a: plc_syntax::Located {
                            value: Scalar::Str(SELECTOR.into()),
                            origin: here,
                        },
                        b: plc_syntax::Located {
                            value: Scalar::Number((k as u64).into()),
                            origin: here,
                        },
                    }));
                    (None, vec![cmp, ElementKind::Jmp(l(label(k)))])
                })
                .collect();
            (format!("{pou}.actions"), here, jumps)
        }
        Piece::Enter(k, name, here) => {
            let reset = ElementKind::Move(Box::new(Move {
                from: plc_syntax::Located {
                    value: Scalar::Number(0u64.into()),
                    origin: here,
                },
                to: plc_syntax::Located {
                    value: SELECTOR.into(),
                    origin: here,
                },
            }));
            (
                format!("{pou}.{name}"),
                here,
                vec![
                    (None, vec![ElementKind::Ret]),
                    (Some(label(k)), vec![reset]),
                ],
            )
        }
    };
    lower.unit_at(unit.clone(), here);
    for (n, (lab, ld)) in rungs.into_iter().enumerate() {
        if let Some(x) = &lab {
            lower.put_label(x.clone());
        }
        lower.rung(ld.clone());
        let mut r = empty_rung(format!("{unit}.{}", n + 1), here);
        r.label = lab.map(|x| {
            Box::new(plc_syntax::Located {
                value: x.into(),
                origin: here,
            })
        });
        r.ld = ld
            .into_iter()
            .map(|kind| plc_syntax::Element { origin: here, kind })
            .collect();
        out.push(r);
    }
}

/// Adds to a statement holding a pragma every elementary variable the body sees (the POU's and
/// the globals it declares external), read, and written but for inputs (the scan writes those),
/// in name order: C code may touch any.
fn everything(scope: &Scope, reads: &mut Vec<Read>, writes: &mut Vec<String>) {
    let mut all: Vec<(&String, &String)> = scope
        .names
        .values()
        .filter_map(|d| match d {
            Decl::Elementary { name, ty } => Some((name, ty)),
            _ => None,
        })
        .collect();
    all.sort();
    for (name, ty) in all {
        if !reads.iter().any(|r| &r.name == name) {
            reads.push(Read {
                name: name.clone(),
                bool: ty == "BOOL",
            });
        }
        if !writes.contains(name) && !scope.inputs.contains(&name.to_ascii_lowercase()) {
            writes.push(name.clone());
        }
    }
}

/// The instances (and their types) through which statement accesses `a` call the project's
/// functions that execute ([`super::user_functions`]): the analysis sees such a call as the
/// call of the function's body, what it reads and writes (its arguments and the globals it
/// touches), as `run` executes it.
fn function_calls(a: &st::Accesses, scope: &Scope) -> Vec<(String, String)> {
    let mut v: Vec<(String, String)> = Vec::new();
    for c in &a.calls {
        if let Some(f) = scope.func(c).filter(|f| f.refused.is_none()) {
            let inst = st_lower::function_instance_name(&f.name);
            if !v.iter().any(|(i, _)| *i == inst) {
                v.push((inst, f.ty.clone()));
            }
        }
    }
    v
}

/// The declaration of instance `name` of function block type `ty`.
fn instance_var(name: &str, ty: &str, at: Origin) -> plc_syntax::Var<'static> {
    let l = |s: &str| plc_syntax::Located {
        value: std::borrow::Cow::Owned(s.to_owned()),
        origin: at,
    };
    plc_syntax::Var {
        origin: at,
        name: l(name),
        ty: l(ty),
        class: plc_syntax::Located {
            value: plc_syntax::VarClass::Memory,
            origin: at,
        },
        init: None,
        problem: None,
    }
}

/// The user function block instances statement accesses `a` calls, by their declared names.
fn user_calls(a: &st::Accesses, scope: &Scope) -> Vec<String> {
    let mut v = Vec::new();
    for c in &a.calls {
        if let Some(Decl::Instance { name, ty, .. }) = scope.get(c) {
            if scope.fb(ty).is_some() {
                push_once(&mut v, name);
            }
        }
    }
    v
}

fn empty_rung(id: String, at: Origin) -> Rung<'static> {
    let name = |s: String| plc_syntax::Located {
        value: s.into(),
        origin: at,
    };
    Rung {
        origin: at,
        id: name(id),
        label: None,
        comment: None,
        ld: Vec::new(),
        ld_origin: at,
        problem: None,
        problem_in_rung: false,
    }
}

fn message(pou: &str, statements: usize, unseen: &Unseen, executed: &str) -> String {
    let plural = if statements == 1 { "" } else { "s" };
    let mut m = format!("pou {pou}: its ST body is analysed per statement ({statements} top-level statement{plural}, rungs {pou}.st1 …, each reading and writing whole variables) and {executed}");
    let mut add = |what: &str, v: &[String]| {
        if !v.is_empty() {
            m.push_str(&format!("; {what}: {}", v.join(", ")));
        }
    };
    add(
        "the function block instances it calls are not seen as written",
        &unseen.instances_written,
    );
    add(
        "the user function block instances it reads are not seen",
        &unseen.instances_read,
    );
    add(
        "the direct addresses it uses are not seen",
        &unseen.addresses,
    );
    add(
        "the project's functions it calls are seen and executed through their bodies",
        &unseen.user_functions,
    );
    add(
        "the functions it calls are black boxes (the arguments read, the result and outputs written where the call assigns them)",
        &unseen.functions,
    );
    m
}

/// A statement's reads and writes as stand-in operands, and the standard function block
/// instances it calls or writes (name, type).
type Resolved = (Vec<Read>, Vec<String>, Vec<(String, String)>);

/// The box of standard function block instance `name` of type `ty`, with constant operands: in
/// a stand-in it reads and writes the instance (what a call `T1(IN := x, PT := t)` does; the
/// arguments are the stand-in's reads), `None` for another type.
fn standard_box(name: &str, ty: &str, at: Origin) -> Option<plc_syntax::Element<'static>> {
    use plc_model::{BistableKind, TimerKind, TriggerKind};
    use plc_syntax::{Bistable, Counter, Ctud, ElementKind, Timer};
    let inst = plc_syntax::Located {
        value: std::borrow::Cow::Owned(name.to_owned()),
        origin: at,
    };
    let konst = |v: plc_syntax::Scalar<'static>| plc_syntax::Located {
        value: v,
        origin: at,
    };
    let zero = || konst(plc_syntax::Scalar::Number(0.into()));
    let off = || konst(plc_syntax::Scalar::Bool(false));
    let timer = |kind| {
        ElementKind::Timer(Box::new(Timer {
            kind,
            instance: inst.clone(),
            pt: konst(plc_syntax::Scalar::Str("T#0s".into())),
        }))
    };
    let kind = match ty.to_ascii_uppercase().as_str() {
        "TON" => timer(TimerKind::Ton),
        "TOF" => timer(TimerKind::Tof),
        "TP" => timer(TimerKind::Tp),
        c @ ("CTU" | "CTD") => ElementKind::Counter(Box::new(Counter {
            down: c == "CTD",
            instance: inst,
            pv: zero(),
            aux: off(),
        })),
        "CTUD" => ElementKind::Ctud(Box::new(Ctud {
            instance: inst,
            cd: off(),
            reset: off(),
            load: off(),
            pv: zero(),
        })),
        b @ ("SR" | "RS") => ElementKind::Bistable(Box::new(Bistable {
            kind: if b == "SR" {
                BistableKind::SetDominant
            } else {
                BistableKind::ResetDominant
            },
            instance: inst,
            reset: off(),
        })),
        t @ ("R_TRIG" | "F_TRIG") => ElementKind::Trigger {
            kind: if t == "R_TRIG" {
                TriggerKind::Rising
            } else {
                TriggerKind::Falling
            },
            instance: inst,
        },
        _ => return None,
    };
    Some(plc_syntax::Element { origin: at, kind })
}

/// The reads and writes of a statement as stand-in operands, or the message of the first name
/// that is neither declared nor called (or a structure's field it does not have).
fn resolve(
    a: &st::Accesses,
    scope: &Scope,
    unseen: &mut Unseen,
    pou: &str,
) -> Result<Resolved, String> {
    let called = |n: &str| a.calls.iter().any(|c| c.eq_ignore_ascii_case(n));
    // Named by its first part, the variable that is not declared.
    let undeclared = |n: &str| {
        let n = if n.starts_with('%') {
            n
        } else {
            n.split('.').next().unwrap_or(n)
        };
        format!("`{n}` is not a variable of POU `{pou}` (nor a global it declares external), nor a function it calls")
    };
    let called = |n: &str| called(n.split('.').next().unwrap_or(n));
    for c in &a.calls {
        match scope.func(c) {
            Some(f) if f.refused.is_none() => push_once(&mut unseen.user_functions, &f.name),
            _ if scope.get(c).is_none() => push_once(&mut unseen.functions, c),
            _ => {}
        }
    }
    let mut reads = Vec::new();
    for n in &a.reads {
        let found = find(scope, n)?;
        // A field written whole keeps nothing of its structure: no read.
        let kept = a.kept.iter().any(|k| k.eq_ignore_ascii_case(n));
        match found {
            Some((Decl::Elementary { .. }, true)) if kept => {}
            Some((Decl::Elementary { name, ty }, _)) => reads.push(Read {
                name: name.clone(),
                bool: ty == "BOOL",
            }),
            Some((Decl::Instance { read: Some(r), .. }, _)) => reads.push(Read {
                name: r.name.clone(),
                bool: r.bool,
            }),
            Some((Decl::Instance { name, ty, .. }, false))
                if member(scope, name, ty, n).is_some() =>
            {
                if let Some((field, bool)) = member(scope, name, ty, n) {
                    reads.push(Read { name: field, bool });
                }
            }
            Some((
                Decl::Instance {
                    name,
                    ty,
                    read: None,
                },
                _,
            )) => {
                // A call of a user instance is seen as its POU's call (the stand-in's `call`).
                let called_user =
                    scope.fb(ty).is_some() && a.calls.iter().any(|c| c.eq_ignore_ascii_case(name));
                if !called_user {
                    push_once(&mut unseen.instances_read, name)
                }
            }
            Some((Decl::Structure { leaves }, _)) => {
                reads.extend(leaves.iter().map(|(name, ty)| Read {
                    name: name.clone(),
                    bool: ty == "BOOL",
                }))
            }
            Some((d @ Decl::Array { .. }, _)) => reads.extend(
                d.leaves()
                    .unwrap_or_default()
                    .into_iter()
                    .map(|(name, ty)| Read {
                        name,
                        bool: ty == "BOOL",
                    }),
            ),
            Some((Decl::Constant(_), _)) => {}
            None if n.starts_with('%') => push_once(&mut unseen.addresses, n),
            None if called(n) => {}
            None => return Err(undeclared(n)),
        }
    }
    let mut writes = Vec::new();
    let mut boxes: Vec<(String, String)> = Vec::new();
    for n in &a.writes {
        match find(scope, n)? {
            Some((Decl::Elementary { name, .. }, _)) => writes.push(name.clone()),
            Some((d @ Decl::Array { .. }, _)) => {
                writes.extend(d.leaves().unwrap_or_default().into_iter().map(|(n, _)| n))
            }
            Some((Decl::Instance { name, ty, .. }, false))
                if input(scope, name, ty, n).is_some() =>
            {
                if let Some(field) = input(scope, name, ty, n) {
                    writes.push(field);
                }
            }
            Some((Decl::Instance { ty, .. }, _)) if scope.fb(ty).is_some() => {
                // Called: the stand-in's `call` writes what the instance writes.
            }
            Some((Decl::Instance { name, ty, .. }, _)) => {
                match standard_box(name, ty, Origin::NONE) {
                    Some(_) if !boxes.iter().any(|(n, _)| n == name) => {
                        boxes.push((name.clone(), ty.clone()))
                    }
                    Some(_) => {}
                    None => push_once(&mut unseen.instances_written, name),
                }
            }
            Some((Decl::Structure { leaves }, _)) => {
                writes.extend(leaves.iter().map(|(name, _)| name.clone()))
            }
            Some((Decl::Constant(_), _)) => return Err(undeclared(n)),
            None if n.starts_with('%') => push_once(&mut unseen.addresses, n),
            None if called(n) => {}
            None => return Err(undeclared(n)),
        }
    }
    // A structure read whole and one of its fields read too: each field once.
    let mut seen = std::collections::HashSet::new();
    reads.retain(|r| seen.insert(r.name.clone()));
    seen.clear();
    writes.retain(|w| seen.insert(w.clone()));
    Ok((reads, writes, boxes))
}

/// What access path `n` names ([`Scope::find`]); an array element whose constant subscripts
/// are out of the array's bounds (`a[11]`, which the lowering refuses) is the whole array.
fn find<'s>(scope: &'s Scope, n: &str) -> Result<Option<(&'s Decl, bool)>, String> {
    match scope.find(n)? {
        None => match super::st_scope::split_element(n) {
            Some((array, _)) => scope.find(array),
            None => Ok(None),
        },
        found => Ok(found),
    }
}

/// Input or output `path` (`Inst.X`) of instance `name` of the project's function block type
/// `ty`: the variable (`Inst.X` as declared) and whether it is BOOL.
fn member(scope: &Scope, name: &str, ty: &str, path: &str) -> Option<(String, bool)> {
    let fb = scope.fb(ty)?;
    let field = path.get(name.len() + 1..)?;
    fb.inputs
        .iter()
        .chain(&fb.outputs)
        .find(|(n, _)| n.eq_ignore_ascii_case(field))
        .map(|(n, t)| (format!("{name}.{n}"), t == "BOOL"))
}

/// Input `path` (`Inst.X`) of instance `name` of the project's function block type `ty`
/// (an output is written only by the instance).
fn input(scope: &Scope, name: &str, ty: &str, path: &str) -> Option<String> {
    let field = path.get(name.len() + 1..)?;
    scope
        .fb(ty)?
        .inputs
        .iter()
        .find(|(n, _)| n.eq_ignore_ascii_case(field))
        .map(|(n, _)| format!("{name}.{n}"))
}

/// For each byte offset of `text` (and its end), the offset in `source` it was read from, when
/// `text` is what XML makes of `source` from `start` on: CDATA sections taken as they are,
/// entity and character references decoded, `\r\n` and `\r` read as `\n` (XML 1.0, 2.11).
/// `None` when the two do not agree (then statements are placed at the text's start).
pub(super) fn file_offsets(source: &str, start: usize, text: &str) -> Option<Vec<usize>> {
    let (s, t) = (source.as_bytes(), text.as_bytes());
    let mut map = Vec::with_capacity(t.len() + 1);
    let (mut i, mut j, mut cdata) = (start, 0, false);
    while j < t.len() {
        let rest = source.get(i..)?;
        if !cdata && rest.starts_with("<![CDATA[") {
            (i, cdata) = (i + 9, true);
        } else if cdata && rest.starts_with("]]>") {
            (i, cdata) = (i + 3, false);
        } else if !cdata && rest.starts_with('&') {
            let end = rest.find(';')?;
            let c = reference(&rest[1..end])?;
            let mut buf = [0u8; 4];
            let bytes = c.encode_utf8(&mut buf).as_bytes();
            if t.get(j..j + bytes.len())? != bytes {
                return None;
            }
            map.extend(std::iter::repeat_n(i, bytes.len()));
            (i, j) = (i + end + 1, j + bytes.len());
        } else if *s.get(i)? == b'\r' {
            if t[j] != b'\n' {
                return None;
            }
            map.push(i);
            i += if s.get(i + 1) == Some(&b'\n') { 2 } else { 1 };
            j += 1;
        } else if (!cdata && s[i] == b'<') || s[i] != t[j] {
            return None;
        } else {
            map.push(i);
            (i, j) = (i + 1, j + 1);
        }
    }
    map.push(i);
    Some(map)
}

/// The character an entity or character reference (between `&` and `;`) stands for.
fn reference(r: &str) -> Option<char> {
    Some(match r {
        "lt" => '<',
        "gt" => '>',
        "amp" => '&',
        "quot" => '"',
        "apos" => '\'',
        _ => {
            let n = if let Some(h) = r.strip_prefix("#x") {
                u32::from_str_radix(h, 16).ok()?
            } else {
                r.strip_prefix('#')?.parse().ok()?
            };
            char::from_u32(n)?
        }
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn offsets_go_through_cdata_references_and_line_ends() {
        let src = "<p>a &lt; b;\r\n<![CDATA[x<y]]>&#x41;</p>";
        let text = "a < b;\nx<yA";
        let m = file_offsets(src, 3, text).unwrap();
        assert_eq!(m[0], 3); // a
        assert_eq!(m[2], 5); // < from &lt;
        assert_eq!(m[4], 10); // b
        assert_eq!(m[6], 12); // \n from \r\n
        assert_eq!(m[7], 23); // x inside CDATA
        assert_eq!(m[8], 24); // < inside CDATA
        assert_eq!(m[10], 29); // A from &#x41;
        assert_eq!(m[11], 35); // the end
        assert_eq!(file_offsets(src, 3, "a > b"), None);
    }
}
