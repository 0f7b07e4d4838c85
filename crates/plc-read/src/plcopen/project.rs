//! The project structure (TC6 `project`: `types/pous`, `types/dataTypes`,
//! `instances/configurations`) → one syntax [`Program`]: the program POUs, the function block
//! types, the global variables, and the order in which the tasks run the program instances.
//!
//! One program POU (instantiated at most once) is the main program: its variables and the
//! globals are the program's variables. Several program POUs become subroutines of the same
//! name, run by a main body of call rungs `<task>.<instance>` in task order — tasks by priority
//! (0 first, ties in file order), each task's program instances in file order, then the
//! resource's instances without a task (IEC 61131-3 6.8.2 gives each task its own interval;
//! plc-deps runs every instance once a scan in that order, and a note says so when there are
//! several tasks). Function block POUs become function block types.
//!
//! A function POU (it has a return type) is not part of the model: its calls in ST are black
//! boxes (the ST reader reads the arguments and writes what the call assigns), and a note says
//! its body is not read.
//!
//! A project with several configurations (IEC 61131-3 2.7: each a controller of its own) is
//! read for one of them, [`super::Pick::configuration`] or else the first in file order (a
//! note, W0502, names the others): its globals and program instances; the program POUs only the
//! others instantiate stay in the program as POUs no task runs, as any program no instance runs.
//!
//! Deliberately not here (errors naming the POU): a program instantiated twice,
//! several resources in one configuration, POUs with actions or transitions outside SFC.

use super::block_types::{Ctx, Sig};
use super::data_types::DataTypes;
use super::interface::{self, name, Interface, Known};
use super::xml::{add_data_note, attr, error, identifier, origin, Note, Notes, Tc6, R};
use super::{
    fb_actions, fbd, il_body, ld, ld_flow, library, matiec_lib, sfc, sfc_lower, st_body, st_scope,
    textual, user_functions,
};
use plc_diag::LoadError;
use plc_model::{Configuration, ProgramInstance, Resource, Task};
use plc_syntax::{
    Body, Element, ElementKind, FunctionBlock, Program, RoutineKind, Rung, Subroutine, Var,
};
use roxmltree::{Document, Node};
use std::collections::HashSet;

/// A program POU as read.
struct ProgramPou {
    name: String,
    origin: plc_diag::Origin,
    vars: Vec<Var<'static>>,
    body: Body<'static>,
}

/// Reads the whole project.
/// With `pick.pou`, only the program POU of that name (any case) is kept, as the main program;
/// with `pick.configuration`, that configuration's instances and globals are read.
pub(super) fn program(
    tc6: Tc6,
    doc: &Document,
    pick: super::Pick,
    notes: &mut Notes,
) -> R<Program<'static>> {
    let select = pick.pou;
    let root = doc.root_element();
    add_data_note(tc6, root, notes);
    if let Some(ch) = tc6.child(root, "contentHeader") {
        add_data_note(tc6, ch, notes);
    }
    let types = tc6.child(root, "types");
    let dialect = dialect_of(tc6, root);
    let known = Known {
        data_types: DataTypes::read(tc6, types.and_then(|t| tc6.child(t, "dataTypes")))?,
    };
    // The interfaces first, then the globals, then the bodies: an ST body resolves its names
    // against them all.
    let pous = types.and_then(|t| tc6.child(t, "pous"));
    let standard: Vec<Node> = pous
        .into_iter()
        .flat_map(|p| tc6.children(p, "pou"))
        .collect();
    let vendor = vendor_pous(tc6, root, &standard, notes);
    // matiec's library blocks the project uses and does not define, read as its own POUs.
    let own: Vec<&str> = standard
        .iter()
        .chain(&vendor)
        .filter_map(|p| p.attribute("name"))
        .collect();
    // Only in matiec's dialect: CODESYS's and TwinCAT's libraries have their own blocks of
    // these names (CODESYS's Util PID has other pins), which stay undefined black boxes.
    let added = (dialect == plc_model::Dialect::Matiec)
        .then(|| matiec_lib::added(tc6, root, &own, doc.input_text().len()))
        .flatten();
    let added_doc = match &added {
        Some(a) => Some(super::xml::parse(&a.text)?),
        None => None,
    };
    let library_pous: Vec<Node> = added_doc
        .iter()
        .flat_map(|d| tc6.children(d.root_element(), "pou"))
        .collect();
    let mut read = Vec::new();
    for pou in standard.into_iter().chain(vendor).chain(library_pous) {
        let raw = attr(pou, "name", "types/pous")?;
        let pname = identifier(raw, "POU", pou, "types/pous")?;
        let place = format!("pou {pname}");
        let kind = attr(pou, "pouType", &place)?;
        if !matches!(kind, "program" | "functionBlock" | "function") {
            return Err(error(
                origin(pou),
                &place,
                format!("unknown pouType `{kind}` of POU `{pname}`"),
            ));
        }
        let mut iface = interface::interface(tc6, tc6.child(pou, "interface"), &pname, &known)?;
        if kind == "function" {
            user_functions::add_result(&pname, &mut iface);
        }
        if kind == "functionBlock" {
            fb_actions::add_selector(tc6, pou, &mut iface);
        }
        read.push((pou, pname, kind, iface));
    }
    let mut later = Notes::default();
    let mut mapped_globals = Vec::new();
    let (mut globals, order, configuration) = instances(
        tc6,
        root,
        pick.configuration,
        &known,
        &mut later,
        &mut mapped_globals,
    )?;
    notes.configurations = later.configurations.take();
    undeclared_globals(&read, &mut globals, &mut mapped_globals, notes);
    let mapped: Vec<(Option<String>, interface::Mapped)> = read
        .iter()
        .flat_map(|(_, p, _, i)| i.mapped.iter().map(|m| (Some(p.clone()), m.clone())))
        .chain(mapped_globals.into_iter().map(|m| (None, m)))
        .collect();
    later.list.extend(interface::mapped_notes(&mapped));
    let global_types: Vec<(&str, &str)> = globals
        .iter()
        .chain(read.iter().flat_map(|r| &r.3.globals))
        .map(|v| (v.name.as_str(), v.ty.as_str()))
        .collect();
    let input_globals: HashSet<String> = globals
        .iter()
        .chain(read.iter().flat_map(|r| &r.3.globals))
        .filter(|v| v.class.value == plc_syntax::VarClass::Input)
        .map(|v| v.name.as_str().to_ascii_lowercase())
        .collect();
    let base = base_ctx(&read);
    // The project's function block types' pins, for ST calls and field accesses.
    let pins = |v: &[Var]| -> Vec<(String, String)> {
        v.iter()
            .map(|v| (v.name.as_str().to_owned(), v.ty.as_str().to_owned()))
            .collect()
    };
    let user_fbs: Vec<st_scope::FbPins> = read
        .iter()
        .filter(|r| r.2 == "functionBlock")
        .map(|(pou, n, _, i)| st_scope::FbPins {
            name: n.clone(),
            inputs: pins(&i.inputs)
                .into_iter()
                .filter(|(p, _)| p != fb_actions::SELECTOR)
                .collect(),
            outputs: pins(&i.outputs),
            actions: fb_actions::names(tc6, *pou),
        })
        .collect();
    // The functions first: which of them an ST body can call (user_functions).
    let scope_of = |iface: &Interface| {
        let mut scope = scope(iface, &global_types, &known, &user_fbs);
        scope.int_arithmetic_in_dint = dialect.int_arithmetic_in_dint();
        scope.inputs.extend(
            input_globals
                .iter()
                .filter(|g| iface.externals.iter().any(|e| e.eq_ignore_ascii_case(g)))
                .cloned(),
        );
        scope
    };
    let fn_list: Vec<(usize, String)> = read
        .iter()
        .enumerate()
        .filter(|(_, r)| r.2 == "function")
        .map(|(k, r)| (k, r.1.clone()))
        .collect();
    let mut sigs = user_functions::sigs(&read);
    for (f, why) in &notes.refuse_functions {
        if let Some(s) = sigs.get_mut(f) {
            s.refused.get_or_insert_with(|| why.clone());
        }
    }
    let mut fn_bodies =
        user_functions::read_all(&fn_list, &mut sigs, notes.exec, &mut |k, sigs, scratch| {
            let (pou, pname, _, iface) = &read[k];
            check_return(*pou, pname, "function", iface)?;
            let mut scope = scope_of(iface);
            scope.funcs = sigs.clone();
            let mut ctx = pou_ctx(&base, iface, &global_types);
            ctx.executed_functions = user_functions::executed(sigs);
            body(tc6, *pou, pname, iface, &scope, &ctx, scratch)
        });
    let mut fn_notes_at = Vec::new();
    let mut bodies = Vec::new();
    for (k, (pou, pname, kind, iface)) in read.iter().enumerate() {
        add_data_note(tc6, *pou, notes);
        check_return(*pou, pname, kind, iface)?;
        if *kind == "function" {
            fn_notes_at.push((k, notes.list.len()));
            bodies.push(None);
            continue;
        }
        let mut scope = scope_of(iface);
        scope.funcs = sigs.clone();
        let mut ctx = pou_ctx(&base, iface, &global_types);
        ctx.executed_functions = user_functions::executed(&sigs);
        bodies.push(Some(body(tc6, *pou, pname, iface, &scope, &ctx, notes)?));
    }
    // The functions some body calls, directly or through others, become types; each keeps
    // its note where it was.
    let used = user_functions::used(&notes.ld_vars, &fn_list, &fn_bodies);
    for &(k, at) in fn_notes_at.iter().rev() {
        let (pou, pname, _, _) = &read[k];
        let executed = used.contains(&pname.to_ascii_lowercase());
        match fn_bodies.remove(&k) {
            Some(r) if executed => {
                let mut list = vec![user_functions::executed_note(origin(*pou), pname)];
                list.extend(r.notes.list);
                notes.list.splice(at..at, list);
                notes.ld_vars.extend(r.notes.ld_vars);
                notes.black_boxes.extend(r.notes.black_boxes);
                notes.exec_orders.extend(r.notes.exec_orders);
                bodies[k] = Some(r.body);
            }
            _ => notes.list.insert(at, function_note(*pou, pname)),
        }
    }
    notes.list.extend(later.list);
    if let Some(a) = &added {
        // What the reader says about the library's own bodies: the one note instead.
        notes
            .list
            .retain(|n| !matiec_lib::in_library(n.origin, a.start));
        notes.push(a.note.clone());
    }
    let (mut programs, mut fbs) = (Vec::new(), Vec::new());
    for ((pou, pname, kind, iface), body) in read.into_iter().zip(bodies) {
        let place = format!("pou {pname}");
        // A function is called, not instantiated: it has no body in the model.
        let Some(body) = body else { continue };
        match kind {
            "program" => {
                let mut vars = iface.inputs;
                vars.extend(iface.outputs);
                vars.extend(iface.locals);
                vars.extend(iface.globals);
                vars.extend(notes.take_ld_vars(&pname));
                programs.push(ProgramPou {
                    name: pname,
                    origin: origin(pou),
                    vars,
                    body,
                });
            }
            "functionBlock" => {
                if let Some(g) = iface.globals.first() {
                    return Err(error(
                        g.origin,
                        &place,
                        format!("function block `{pname}` declares global variables"),
                    ));
                }
                fbs.push(FunctionBlock {
                    origin: origin(pou),
                    name: pname.clone().into(),
                    inputs: iface.inputs,
                    outputs: iface.outputs,
                    vars: iface
                        .locals
                        .into_iter()
                        .chain(notes.take_ld_vars(&pname))
                        .collect(),
                    body: Some(body),
                });
            }
            // A function some body calls (user_functions).
            _ => fbs.push(FunctionBlock {
                origin: origin(pou),
                name: user_functions::type_name(&pname).into(),
                inputs: iface.inputs,
                outputs: iface.outputs,
                vars: iface
                    .locals
                    .into_iter()
                    .chain(notes.take_ld_vars(&pname))
                    .collect(),
                body: Some(body),
            }),
        }
    }
    for b in std::mem::take(&mut notes.black_boxes) {
        let (fb, note) = library::black_box_type(&b);
        fbs.push(fb);
        notes.push(note);
    }
    library_fbs(&mut fbs, &programs, &globals, notes);
    opaque_types(&mut programs, &mut fbs, &mut globals, notes);
    if let Some(s) = select {
        // `run` runs the selected program alone: the others' bodies do not matter to it.
        let others: Vec<&str> = programs
            .iter()
            .map(|p| p.name.as_str())
            .filter(|n| !n.eq_ignore_ascii_case(s))
            .collect();
        notes
            .no_run
            .retain(|(pou, _)| !others.contains(&pou.as_str()));
    }
    let (programs, order) = match select {
        Some(s) => selected(root, programs, order, s)?,
        None => (programs, order),
    };
    let mut program = assemble(root, programs, fbs, globals, order)?;
    program.configuration = configuration;
    program.dialect = dialect;
    Ok(program)
}

/// The toolchain's dialect, by the editor the header names (docs/dialects.md).
fn dialect_of(tc6: Tc6, root: Node) -> plc_model::Dialect {
    let product = tc6
        .child(root, "fileHeader")
        .and_then(|h| h.attribute("productName"))
        .unwrap_or("");
    plc_model::Dialect::of_editor(product)
}

/// The POUs CODESYS and TwinCAT keep in vendor data rather than in `types/pous`: a TC6 `pou`
/// element as the child of an `addData/data` whose name ends in `/pou` (CODESYS puts its
/// programs in `resource/addData`, TwinCAT all its POUs in the project's application data,
/// leaving `types/pous` empty). They are read as the standard POUs are; one whose name a POU of
/// `types/pous` already has is left out. A note names those read.
fn vendor_pous<'a, 'i>(
    tc6: Tc6,
    root: Node<'a, 'i>,
    standard: &[Node<'a, 'i>],
    notes: &mut Notes,
) -> Vec<Node<'a, 'i>> {
    let named = |p: &Node, n: &str| {
        p.attribute("name")
            .is_some_and(|m| m.eq_ignore_ascii_case(n))
    };
    let mut found: Vec<Node> = Vec::new();
    for pou in root.descendants().filter(|n| tc6.is(*n, "pou")) {
        let in_data = pou.parent_element().is_some_and(|d| {
            tc6.is(d, "data")
                && d.attribute("name").is_some_and(|n| n.ends_with("/pou"))
                && d.parent_element().is_some_and(|a| tc6.is(a, "addData"))
        });
        let Some(name) = pou.attribute("name") else {
            continue;
        };
        if in_data
            && !standard.iter().any(|p| named(p, name))
            && !found.iter().any(|p| named(p, name))
        {
            found.push(pou);
        }
    }
    if let Some(first) = found.first() {
        let names: Vec<&str> = found.iter().filter_map(|p| p.attribute("name")).collect();
        notes.push(Note {
            origin: origin(*first),
            message: format!(
                "POUs read from vendor data (addData, as CODESYS and TwinCAT export them) rather than types/pous: {}",
                names.join(", ")
            ),
        });
    }
    found
}

/// Adds the stand-in type of each library block ([`super::library`]) that a variable is an
/// instance of and the project does not define, with its note.
fn library_fbs(
    fbs: &mut Vec<FunctionBlock<'static>>,
    programs: &[ProgramPou],
    globals: &[Var<'static>],
    notes: &mut Notes,
) {
    let mut uses: Vec<(String, plc_diag::Origin, Vec<String>)> = Vec::new();
    let fb_vars = fbs.iter().flat_map(|f| {
        f.inputs
            .iter()
            .chain(&f.outputs)
            .chain(&f.vars)
            .map(move |v| (f.name.to_string(), v))
    });
    let prog_vars = programs
        .iter()
        .flat_map(|p| p.vars.iter().map(move |v| (p.name.clone(), v)));
    let all: Vec<(String, &Var<'static>)> = fb_vars
        .chain(prog_vars)
        .chain(globals.iter().map(|v| (String::new(), v)))
        .collect();
    for (pou, v) in all {
        let ty = v.ty.as_str();
        if !library::is_library_fb(ty) || fbs.iter().any(|f| f.name.as_ref() == ty) {
            continue;
        }
        let who = if pou.is_empty() {
            v.name.as_str().to_owned()
        } else {
            format!("{pou}.{}", v.name.as_str())
        };
        match uses.iter_mut().find(|u| u.0 == ty) {
            Some(u) => u.2.push(who),
            None => uses.push((ty.to_owned(), v.origin, vec![who])),
        }
    }
    for (ty, at, who) in uses {
        if let Some((fb, note)) = library::stand_in_fb(&ty, at, &who) {
            fbs.push(fb);
            notes.push(note);
        }
    }
}

/// Variables of a type that nothing defines (not elementary, not a data type of the file or a
/// library, not a function block the model, the file or a black box has: a CODESYS library
/// type such as `JSONVAR`): each becomes a black box, a whole variable standing in as a DINT
/// without a value, so that the analysis sees its reads and writes; one note names the types
/// and their variables, and `run` refuses each POU that declares one (by name).
fn opaque_types(
    programs: &mut [ProgramPou],
    fbs: &mut [FunctionBlock<'static>],
    globals: &mut [Var<'static>],
    notes: &mut Notes,
) {
    let known: HashSet<String> = fbs.iter().map(|f| f.name.to_string()).collect();
    let mut found: Vec<(String, plc_diag::Origin, Vec<String>)> = Vec::new();
    let mut refuse: Vec<(String, plc_diag::Origin, String, String)> = Vec::new();
    let mut visit = |pou: &str, v: &mut Var<'static>| {
        let ty = v.ty.as_str();
        if plc_model::Type::parse(ty).is_some() || known.contains(ty) {
            return;
        }
        let ty = ty.to_owned();
        let who = if pou.is_empty() {
            v.name.as_str().to_owned()
        } else {
            format!("{pou}.{}", v.name.as_str())
        };
        match found.iter_mut().find(|f| f.0 == ty) {
            Some(f) => f.2.push(who),
            None => found.push((ty.clone(), v.ty.origin, vec![who])),
        }
        let owner = if pou.is_empty() { "(global)" } else { pou };
        refuse.push((owner.to_owned(), v.origin, v.name.as_str().to_owned(), ty));
        v.ty.value = std::borrow::Cow::Borrowed("DINT");
        v.init = None;
    };
    for p in programs.iter_mut() {
        for v in &mut p.vars {
            visit(&p.name, v);
        }
    }
    for f in fbs.iter_mut() {
        let name = f.name.to_string();
        for v in f.inputs.iter_mut().chain(&mut f.outputs).chain(&mut f.vars) {
            visit(&name, v);
        }
    }
    for v in globals.iter_mut() {
        visit("", v);
    }
    let Some(first) = found.first() else { return };
    let list: Vec<String> = found
        .iter()
        .map(|(t, _, who)| format!("{t}: {}", who.join(", ")))
        .collect();
    notes.push(Note {
        origin: first.1,
        message: format!("types that the file names and nobody defines (an editor's library types?) are read as black boxes: {}; each such variable is one whole variable without a value (a DINT stand-in), so the analysis sees its reads and writes, and `run` cannot execute the POUs that declare one", list.join("; ")),
    });
    for (pou, at, var, ty) in refuse {
        let pou = if pou == "(global)" {
            programs.first().map_or(pou, |p| p.name.clone())
        } else {
            pou
        };
        notes.no_run.push((pou.clone(), Note {
            origin: at,
            message: format!("pou {pou}: variable `{var}` is of type `{ty}`, which the file does not define (a black box without a value), so `run` cannot execute `{pou}`"),
        }));
    }
}

/// The program POU named `select` (any case) alone, with its instances: an error listing the
/// project's programs when none has that name.
fn selected<'a, 'i>(
    root: Node,
    programs: Vec<ProgramPou>,
    order: Order<'a, 'i>,
    select: &str,
) -> R<(Vec<ProgramPou>, Order<'a, 'i>)> {
    let names: Vec<&str> = programs.iter().map(|p| p.name.as_str()).collect();
    let Some(i) = names.iter().position(|n| n.eq_ignore_ascii_case(select)) else {
        return Err(error(
            origin(root),
            "types/pous",
            format!(
                "--pou {select}: the project has no program of that name; its programs are {}",
                names.join(", ")
            ),
        ));
    };
    let name = names[i].to_owned();
    let order = order.into_iter().filter(|o| o.1 == name).collect();
    let keep = programs.into_iter().nth(i).into_iter().collect();
    Ok((keep, order))
}

/// A function must have a return type (IEC 61131-3 6.6.2), and nothing else may have one.
fn check_return(pou: Node, pname: &str, kind: &str, iface: &Interface) -> R<()> {
    let place = format!("pou {pname}");
    match (kind == "function", iface.returns) {
        (true, Some(_)) | (false, None) => Ok(()),
        (true, None) => Err(error(
            origin(pou),
            &place,
            format!("function `{pname}` has no return type"),
        )),
        (false, Some(at)) => Err(error(
            at,
            &format!("{place}, returnType"),
            format!("POU `{pname}` is a {kind} but has a return type: only a function has one"),
        )),
    }
}

/// The note of a function POU: its calls are black boxes, its body is not read.
fn function_note(pou: Node, pname: &str) -> Note {
    Note {
        origin: origin(pou),
        message: format!("pou {pname}: a function; its body is not read: a call of it in an ST body is analysed as a black box through its arguments (the inputs it is given read, the result and the outputs assigned written), and `run` does not execute it"),
    }
}

/// The names an ST body of a POU with interface `iface` sees: its own variables and the globals
/// it declares external (`globals`: the name and type of every global of the project).
pub(super) fn scope(
    iface: &Interface,
    globals: &[(&str, &str)],
    known: &Known,
    fbs: &[st_scope::FbPins],
) -> st_scope::Scope {
    let mut s = st_scope::Scope::default();
    for f in fbs {
        s.fbs.insert(f.name.to_ascii_lowercase(), f.clone());
    }
    for v in iface
        .inputs
        .iter()
        .chain(&iface.outputs)
        .chain(&iface.locals)
        .chain(&iface.globals)
    {
        s.declare(v.name.as_str(), v.ty.as_str());
        if v.class.value == plc_syntax::VarClass::Input {
            s.inputs.insert(v.name.as_str().to_ascii_lowercase());
        }
    }
    for e in &iface.externals {
        for (n, t) in globals.iter().filter(|(n, _)| is_external(n, e)) {
            s.declare(n, t);
        }
    }
    for (t, v, i) in known.data_types.enum_values() {
        s.constant(&t, &v, i);
    }
    s
}

/// Puts the POUs together: one program as the main program, several as subroutines called in
/// task order.
fn assemble(
    root: Node,
    mut programs: Vec<ProgramPou>,
    fbs: Vec<FunctionBlock<'static>>,
    mut globals: Vec<Var<'static>>,
    order: Vec<(String, String, Node)>,
) -> R<Program<'static>> {
    let mut seen = HashSet::new();
    for (_, ty, n) in &order {
        if !programs.iter().any(|p| &p.name == ty) {
            return Err(error(
                origin(*n),
                "instances",
                format!("program instance of `{ty}`, which is not a program POU of the project"),
            ));
        }
        if !seen.insert(ty.clone()) {
            return Err(error(
                origin(*n),
                "instances",
                format!("program `{ty}` is instantiated twice: several instances of one program are not supported yet"),
            ));
        }
    }
    if programs.is_empty() {
        return Err(error(
            origin(root),
            "types/pous",
            "the project has no program POU",
        ));
    }
    let mut program = Program {
        origin: origin(root),
        name: "project".into(),
        function_blocks: fbs,
        ..Program::default()
    };
    if programs.len() == 1 {
        let p = programs.pop().expect("one program");
        globals.extend(p.vars);
        program.name = p.name.into();
        program.vars = globals;
        program.body = Some(p.body);
        return Ok(program);
    }
    let mut calls = Vec::new();
    for (task, ty, n) in &order {
        let at = origin(*n);
        calls.push(Rung {
            origin: at,
            id: name(format!("{task}.{ty}"), at),
            label: None,
            comment: None,
            ld: vec![Element {
                origin: at,
                kind: ElementKind::Call(name(ty.clone(), at)),
            }],
            ld_origin: at,
            problem: None,
            problem_in_rung: false,
        });
    }
    if calls.is_empty() {
        return Err(error(
            origin(root),
            "instances",
            "the project has several program POUs and no configuration that says which run: add a task with program instances",
        ));
    }
    program.vars = globals;
    program.body = Some(Body::Rungs(calls));
    program.subroutines = programs
        .into_iter()
        .map(|p| Subroutine {
            origin: p.origin,
            kind: RoutineKind::Subroutine,
            name: p.name.into(),
            vars: p.vars,
            body: Some(p.body),
        })
        .collect();
    Ok(program)
}

/// The body of POU `pou` as syntax: LD rungs, an FBD body, a stand-in rung per ST statement,
/// or an IL or SFC body through its interface.
fn body(
    tc6: Tc6,
    pou: Node,
    name: &str,
    iface: &Interface,
    scope: &st_scope::Scope,
    ctx: &Ctx,
    notes: &mut Notes,
) -> R<Body<'static>> {
    let place = format!("pou {name}");
    let Some(b) = tc6.child(pou, "body") else {
        return Err(error(
            origin(pou),
            &place,
            format!("POU `{name}` has no body"),
        ));
    };
    if tc6.children(pou, "body").count() > 1 {
        notes.push(Note {
            origin: origin(b),
            message: format!("{place}: only the first of its bodies is read (as Beremiz does)"),
        });
    }
    add_data_note(tc6, b, notes);
    let Some(lang) = tc6
        .elements(b)
        .find(|e| e.tag_name().name() != "documentation" && e.tag_name().name() != "addData")
    else {
        return Err(error(
            origin(b),
            &place,
            format!("the body of POU `{name}` is empty"),
        ));
    };
    let tag = lang.tag_name().name();
    let actions = match (tag, fb_actions::names(tc6, pou).is_empty()) {
        ("ST", false)
            if iface
                .inputs
                .iter()
                .any(|v| v.name.as_str() == fb_actions::SELECTOR) =>
        {
            fb_actions::bodies(tc6, pou, name)?
        }
        _ => Vec::new(),
    };
    if tag != "SFC" && actions.is_empty() {
        for extra in ["actions", "transitions"] {
            if let Some(a) = tc6.child(pou, extra) {
                return Err(error(
                    origin(a),
                    &place,
                    format!("POU `{name}` has {extra} but an {tag} body: actions and transitions are read only as part of SFC (not yet)"),
                ));
            }
        }
    }
    if let (Some(m), "LD" | "FBD") = (iface.mapped.iter().find(|m| m.text), tag) {
        notes.no_run.push((name.to_owned(), Note {
            origin: m.origin,
            message: format!("{place}: variable `{}` is a {}, for which plc-deps has no values: the analysis reads it as a whole variable, but `run` cannot execute the {tag} body of `{name}`", m.var, m.from),
        }));
    }
    if let (Some(n), "LD" | "FBD") = (string_literal(lang), tag) {
        notes.no_run.push((name.to_owned(), Note {
            origin: origin(n),
            message: format!("{place}: the {} localId {} is a string literal, for which plc-deps has no values: the analysis reads it as a constant, but `run` cannot execute the {tag} body of `{name}`", n.tag_name().name(), n.attribute("localId").unwrap_or("?")),
        }));
    }
    let array_element = lang.children().find(|n| {
        matches!(n.tag_name().name(), "inVariable" | "inOutVariable")
            && super::expression::reads_array_element(*n, &ctx.vars)
    });
    if let (Some(n), "LD" | "FBD") = (array_element, tag) {
        notes.no_run.push((name.to_owned(), Note {
            origin: origin(n),
            message: format!("{place}: the {} localId {} reads an array element, `{}`; the model holds an array as one value, so the analysis reads the whole array (and the subscripts), but `run` cannot execute the {tag} body of `{name}`", n.tag_name().name(), n.attribute("localId").unwrap_or("?"), super::pins::expression_text(n).trim()),
        }));
    }
    for i in &iface.fb_inits {
        for (m, v) in &i.members {
            let why = if ctx.input_pin(&i.fb, m).is_none() {
                format!("`{m}` is not an input of {} (the model gives an instance's inputs their declared values, nothing else)", i.fb)
            } else if !matches!(tag, "LD" | "FBD") {
                format!("the value is applied to the unconnected inputs of LD and FBD calls only, and the body is {tag}")
            } else {
                continue;
            };
            notes.no_run.push((name.to_owned(), Note {
                origin: v.origin,
                message: format!("{place}: the initial value of `{}.{m}`: {why}; so `run` cannot execute the {tag} body of `{name}`", i.instance),
            }));
        }
    }
    Ok(match tag {
        "LD" => ld_body(tc6, lang, name, ctx, notes)?,
        "FBD" => Body::Fbd(fbd::body(tc6, lang, name, ctx, notes)?),
        "ST" if !actions.is_empty() => Body::Rungs(st_body::rungs_with_actions(
            lang, &actions, name, scope, notes,
        )?),
        "ST" => Body::Rungs(st_body::rungs(lang, name, scope, notes)?),
        "SFC" => Body::Rungs(sfc_body(tc6, pou, lang, name, iface, scope, ctx, notes)),
        "IL" => {
            let reads: Vec<&Var> = iface.inputs.iter().collect();
            let writes: Vec<&Var> = iface
                .outputs
                .iter()
                .chain(&iface.locals)
                .chain(&iface.globals)
                .collect();
            let externals: Vec<String> = iface
                .externals
                .iter()
                .flat_map(|e| scope.fields_of(e))
                .collect();
            if tag == "IL" {
                return Ok(Body::Rungs(il_body::rungs(
                    lang, name, scope, &reads, &writes, &externals, notes,
                )?));
            }
            Body::Rungs(textual::through_interface(
                tag, lang, name, &reads, &writes, &externals, notes,
            ))
        }
        other => {
            return Err(error(
                origin(lang),
                &place,
                format!("unknown body language `{other}` of POU `{name}`"),
            ))
        }
    })
}

/// The rungs of SFC body `lang` of POU `pou` ([`sfc`], lowered by [`sfc_lower`]); when it
/// cannot be executed, the stand-in through its interface, marked skipped with the reason.
#[allow(clippy::too_many_arguments)]
fn sfc_body(
    tc6: Tc6,
    pou: Node,
    lang: Node,
    name: &str,
    iface: &Interface,
    scope: &st_scope::Scope,
    ctx: &Ctx,
    notes: &mut Notes,
) -> Vec<Rung<'static>> {
    let chart = sfc::chart(tc6, pou, lang);
    let (list, vars) = (notes.list.len(), notes.ld_vars.len());
    match sfc_lower::lower(tc6, &chart, name, scope, &ctx.inits, notes, origin(lang)) {
        Ok(l) => {
            notes.list.truncate(list);
            notes.ld_vars.truncate(vars);
            notes.push(Note {
                origin: origin(lang),
                message: format!(
                    "pou {name}: its SFC body ({} steps, {} transitions, {} actions) is executed by `run` and `c` as the rungs it is lowered to ({name}.step.S…, {name}.tr.T…, {name}.act.A…; docs/plcopen.md, SFC bodies)",
                    chart.steps.len(),
                    chart.transitions.len(),
                    chart.actions.len()
                ),
            });
            notes
                .ld_vars
                .extend(l.vars.into_iter().map(|v| (name.to_owned(), v)));
            l.rungs
        }
        Err((at, what)) => {
            notes.list.truncate(list);
            notes.ld_vars.truncate(vars);
            let reads: Vec<&Var> = iface.inputs.iter().collect();
            let writes: Vec<&Var> = iface
                .outputs
                .iter()
                .chain(&iface.locals)
                .chain(&iface.globals)
                .collect();
            let externals: Vec<String> = iface
                .externals
                .iter()
                .flat_map(|e| scope.fields_of(e))
                .collect();
            let rungs =
                textual::through_interface("SFC", lang, name, &reads, &writes, &externals, notes);
            if let Some(s) = notes.skipped.last_mut() {
                s.why = Some((at, what));
            }
            rungs
        }
    }
}

/// Task order of program instances: the instance's task and type.
type Order<'a, 'i> = Vec<(String, String, Node<'a, 'i>)>;

/// The global variables of the configuration and its resource, the task order of the program
/// instances, and the configuration as data.
type Instances<'a, 'i> = (Vec<Var<'static>>, Order<'a, 'i>, Option<Configuration>);

fn instances<'a, 'i>(
    tc6: Tc6,
    root: Node<'a, 'i>,
    choose: Option<&str>,
    known: &Known,
    notes: &mut Notes,
    mapped: &mut Vec<interface::Mapped>,
) -> R<Instances<'a, 'i>> {
    let mut globals = Vec::new();
    let order = Vec::new();
    let configurations: Vec<Node> = tc6
        .child(root, "instances")
        .and_then(|i| tc6.child(i, "configurations"))
        .into_iter()
        .flat_map(|c| tc6.children(c, "configuration"))
        .collect();
    let place = "instances/configuration";
    let Some(conf) = chosen(&configurations, choose, root, notes) else {
        // TwinCAT leaves `instances` empty and keeps its resource (tasks, global variable
        // lists) in the project's application data: read it as the resource of a configuration
        // of the same name.
        let Some(res) = tc6
            .children(root, "addData")
            .flat_map(|a| tc6.children(a, "data"))
            .find_map(|d| tc6.child(d, "resource"))
        else {
            return match choose {
                Some(c) => Err(unknown_configuration(root, c, &[])),
                None => Ok((globals, order, None)),
            };
        };
        let name = identifier(attr(res, "name", place)?, "resource", res, place)?;
        if let Some(c) = choose.filter(|c| !c.eq_ignore_ascii_case(&name)) {
            return Err(unknown_configuration(root, c, &[name.as_str()]));
        }
        notes.push(Note {
            origin: origin(res),
            message: "the resource is read from vendor data (addData, as TwinCAT exports it): the project's instances/configurations is empty".into(),
        });
        let configuration = Configuration {
            name,
            resources: Vec::new(),
        };
        return resource(tc6, res, configuration, known, notes, mapped, globals);
    };
    let conf = conf?;
    add_data_note(tc6, conf, notes);
    let configuration = Configuration {
        name: identifier(attr(conf, "name", place)?, "configuration", conf, place)?,
        resources: Vec::new(),
    };
    globals_of(tc6, conf, known, mapped, &mut globals)?;
    let resources: Vec<Node> = tc6.children(conf, "resource").collect();
    if resources.len() > 1 {
        return Err(error(
            origin(resources[1]),
            place,
            "several resources are not supported yet",
        ));
    }
    let Some(res) = resources.first().copied() else {
        return Ok((globals, order, Some(configuration)));
    };
    resource(tc6, res, configuration, known, notes, mapped, globals)
}

/// The configuration to read (IEC 61131-3 2.7: each configuration is a controller of its own,
/// and plc-deps runs one): the one named `choose` (any case; an error listing them when none
/// is), else the first in file order, with the note [`Notes::configurations`] when there are
/// others. `None` when the project has none.
fn chosen<'a, 'i>(
    configurations: &[Node<'a, 'i>],
    choose: Option<&str>,
    root: Node,
    notes: &mut Notes,
) -> Option<R<Node<'a, 'i>>> {
    let first = *configurations.first()?;
    let names: Vec<&str> = configurations
        .iter()
        .map(|c| c.attribute("name").unwrap_or(""))
        .collect();
    if let Some(c) = choose {
        return Some(match names.iter().position(|n| n.eq_ignore_ascii_case(c)) {
            Some(k) => Ok(configurations[k]),
            None => Err(unknown_configuration(root, c, &names)),
        });
    }
    if let [read, others @ ..] = &names[..] {
        if !others.is_empty() {
            notes.configurations = Some(Note {
                origin: origin(first),
                message: format!(
                    "the project has {} configurations (IEC 61131-3: each a controller of its own) and plc-deps reads one: `{read}`, the first in the file; not read: {} (their program POUs are analysed as POUs no task runs); choose one with --configuration NAME",
                    names.len(),
                    others
                        .iter()
                        .map(|n| format!("`{n}`"))
                        .collect::<Vec<_>>()
                        .join(", ")
                ),
            });
        }
    }
    Some(Ok(first))
}

/// `--configuration NAME` naming no configuration of the project (`names`: those it has).
fn unknown_configuration(root: Node, choose: &str, names: &[&str]) -> LoadError {
    let has = match names {
        [] => "it has none".to_owned(),
        _ => format!(
            "its configurations are {}",
            names
                .iter()
                .map(|n| format!("`{n}`"))
                .collect::<Vec<_>>()
                .join(", ")
        ),
    };
    let e = error(
        origin(root),
        "instances/configurations",
        format!("--configuration {choose}: the project has no configuration of that name; {has}"),
    );
    match plc_diag::suggest::did_you_mean(choose, names.iter().copied()) {
        Some(h) => e.with_hint(&h),
        None => e,
    }
}

/// The global variables of a configuration or resource, appended to `globals`.
fn globals_of(
    tc6: Tc6,
    node: Node,
    known: &Known,
    mapped: &mut Vec<interface::Mapped>,
    globals: &mut Vec<Var<'static>>,
) -> R<()> {
    let place = "instances/configuration";
    for gv in tc6.children(node, "globalVars") {
        let class = plc_syntax::VarClass::Default;
        let mut inits = Vec::new();
        globals.extend(interface::var_list(
            tc6, gv, class, place, known, mapped, &mut inits,
        )?);
        if let Some(i) = inits.first() {
            return Err(error(
                i.origin,
                place,
                format!("global function block instance `{}` has an initial value; initial values of global instances are not supported yet (those of a POU's instances are)", i.instance),
            ));
        }
    }
    Ok(())
}

/// The resource `res` of `configuration`: its globals (after those in `globals`), its tasks
/// and program instances in run order.
fn resource<'a, 'i>(
    tc6: Tc6,
    res: Node<'a, 'i>,
    mut configuration: Configuration,
    known: &Known,
    notes: &mut Notes,
    mapped: &mut Vec<interface::Mapped>,
    mut globals: Vec<Var<'static>>,
) -> R<Instances<'a, 'i>> {
    let place = "instances/configuration";
    let mut order = Vec::new();
    globals_of(tc6, res, known, mapped, &mut globals)?;
    let mut resource = Resource {
        name: identifier(attr(res, "name", place)?, "resource", res, place)?,
        ..Resource::default()
    };
    let mut tasks: Vec<(u32, Node)> = Vec::new();
    for t in tc6.children(res, "task") {
        let pr = t.attribute("priority").unwrap_or("0").trim();
        let pr: u32 = pr.parse().map_err(|_| {
            error(
                origin(t),
                place,
                format!("task priority `{pr}` is not a whole number"),
            )
        })?;
        tasks.push((pr, t));
    }
    tasks.sort_by_key(|(p, _)| *p);
    let mut described = Vec::new();
    for (pr, t) in &tasks {
        let tname = identifier(attr(*t, "name", place)?, "task", *t, place)?;
        let when = t
            .attribute("interval")
            .or(t.attribute("single"))
            .unwrap_or("-");
        described.push(format!("{tname} ({when}, priority {pr})"));
        let mut task = Task {
            name: tname.clone(),
            interval: t.attribute("interval").map(str::to_owned),
            single: t.attribute("single").map(str::to_owned),
            priority: *pr,
            instances: Vec::new(),
        };
        for pi in tc6.children(*t, "pouInstance") {
            task.instances.push(program_instance(pi, place)?);
            order.push((tname.clone(), instance_type(pi, place)?, pi));
        }
        resource.tasks.push(task);
    }
    for pi in tc6.children(res, "pouInstance") {
        resource.instances.push(program_instance(pi, place)?);
        order.push(("resource".into(), instance_type(pi, place)?, pi));
    }
    if tasks.len() > 1 {
        notes.push(Note {
            origin: origin(res),
            message: format!("tasks {} run one after another in every scan (in priority order), not each at its own interval", described.join(", ")),
        });
    }
    configuration.resources.push(resource);
    Ok((globals, order, Some(configuration)))
}

/// A `pouInstance` as data: its name (an IEC identifier) and its program.
fn program_instance(pi: Node, place: &str) -> R<ProgramInstance> {
    Ok(ProgramInstance {
        name: identifier(attr(pi, "name", place)?, "program instance", pi, place)?,
        program: instance_type(pi, place)?,
    })
}

/// The program a `pouInstance` runs (`typeName`; `type` in the pre-2.0 namespace).
fn instance_type(pi: Node, place: &str) -> R<String> {
    let ty = pi
        .attribute("typeName")
        .or(pi.attribute("type"))
        .ok_or_else(|| error(origin(pi), place, "pouInstance has no typeName"))?;
    // TwinCAT writes `<pouInstance name="MAIN" typeName="">`: the instance of program MAIN.
    let ty = match (ty.trim(), pi.attribute("name")) {
        ("", Some(n)) => n,
        _ => ty,
    };
    identifier(ty, "program", pi, place)
}

/// An LD body: its rungs, or, where the rung reader cannot express its wiring as series-parallel
/// rungs, the data-flow network Beremiz makes of it ([`ld_flow`]), with a note saying why. When
/// both fail, the rung reader's error.
fn ld_body(tc6: Tc6, lang: Node, name: &str, ctx: &Ctx, notes: &mut Notes) -> R<Body<'static>> {
    let (list, vars) = (notes.list.len(), notes.ld_vars.len());
    let why = match ld::rungs(tc6, lang, name, &ctx.inits, notes) {
        Ok(r) => return Ok(Body::Rungs(r)),
        Err(e) => e,
    };
    notes.list.truncate(list);
    notes.ld_vars.truncate(vars);
    match ld_flow::body(tc6, lang, name, ctx, notes) {
        Ok(b) => {
            let (at, what) = match &why {
                LoadError::Invalid(d) => (d.location.origin, d.to_string()),
                other => (origin(lang), other.to_string()),
            };
            notes.push(Note {
                origin: at,
                message: format!(
                    "pou {name}: its LD body is read as a data-flow network (FBD networks {name}.N1 …, each rung's power flow as boolean blocks, as Beremiz generates LD) because it is not series-parallel rungs of contacts, coils and boxes: {what}"
                ),
            });
            Ok(Body::Fbd(b))
        }
        Err(_) => Err(why),
    }
}

/// What any body of the project may call: its user functions (with their pins' types) and the
/// function block types of the project and of the library (with their outputs' types).
fn base_ctx(read: &[(Node, String, &str, Interface)]) -> Ctx {
    let pins = |v: &[Var]| -> Vec<(String, String)> {
        v.iter()
            .map(|v| (v.name.as_str().to_owned(), v.ty.as_str().to_owned()))
            .collect()
    };
    let mut ctx = Ctx::default();
    for (_, name, kind, iface) in read {
        match *kind {
            "function" => {
                let mut outputs = Vec::new();
                if let Some(t) = &iface.return_ty {
                    outputs.push(("OUT".to_owned(), t.clone()));
                }
                // The result (a variable named like the function) is `OUT`.
                outputs.extend(
                    pins(&iface.outputs)
                        .into_iter()
                        .filter(|(n, _)| !n.eq_ignore_ascii_case(name)),
                );
                let sig = Sig {
                    inputs: pins(&iface.inputs),
                    outputs,
                };
                ctx.functions.insert(name.clone(), sig);
            }
            "functionBlock" => {
                ctx.fbs.insert(name.clone(), pins(&iface.outputs));
                ctx.fb_inputs.insert(name.clone(), pins(&iface.inputs));
            }
            _ => {}
        }
    }
    for (name, inputs, outputs) in library::pins() {
        if !ctx.fbs.contains_key(name) {
            ctx.fbs.insert(name.to_owned(), outputs);
            ctx.fb_inputs.insert(name.to_owned(), inputs);
        }
    }
    ctx
}

/// [`base_ctx`] with the variables a POU sees (its own and the globals it names external).
fn pou_ctx(base: &Ctx, iface: &Interface, globals: &[(&str, &str)]) -> Ctx {
    let mut vars = std::collections::HashMap::new();
    for v in iface
        .inputs
        .iter()
        .chain(&iface.outputs)
        .chain(&iface.locals)
        .chain(&iface.globals)
    {
        vars.insert(
            v.name.as_str().to_ascii_lowercase(),
            v.ty.as_str().to_owned(),
        );
    }
    for (n, t) in globals {
        if iface.externals.iter().any(|e| is_external(n, e)) {
            vars.insert(n.to_ascii_lowercase(), t.to_string());
        }
    }
    let mut inits = std::collections::HashMap::new();
    for i in &iface.fb_inits {
        let members = i
            .members
            .iter()
            .map(|(m, v)| (m.clone(), v.value.clone(), v.origin))
            .collect();
        inits.insert(i.instance.to_ascii_lowercase(), members);
    }
    Ctx {
        functions: base.functions.clone(),
        fbs: base.fbs.clone(),
        fb_inputs: base.fb_inputs.clone(),
        vars,
        inits,
        executed_functions: std::collections::HashMap::new(),
    }
}

/// True when global variable `global` is external declaration `e` or, `e` being a structure
/// flattened into its fields, one of them (`Motor.Speed` of `Motor`).
fn is_external(global: &str, e: &str) -> bool {
    global.eq_ignore_ascii_case(e)
        || (global.len() > e.len()
            && matches!(global.as_bytes()[e.len()], b'.' | b'[')
            && global[..e.len()].eq_ignore_ascii_case(e))
}

/// The first `inVariable` of a graphical body whose expression is a WSTRING literal (`"…"`; a
/// STRING literal `'…'` has a value).
fn string_literal<'a, 'i>(lang: Node<'a, 'i>) -> Option<Node<'a, 'i>> {
    lang.children()
        .filter(|n| n.tag_name().name() == "inVariable")
        .find(|n| {
            n.children()
                .find(|c| c.tag_name().name() == "expression")
                .and_then(|c| c.text())
                .is_some_and(|t| super::pins::is_string_literal(t) && t.trim().starts_with('"'))
        })
}

/// Adds, as a global, each external variable whose global the file does not declare: Beremiz's
/// extensions declare some in code they generate (SVGHMI's `CURRENT_PAGE_0`), so a POU
/// names them external with their type. A note names them.
fn undeclared_globals(
    read: &[(Node, String, &str, Interface)],
    globals: &mut Vec<Var<'static>>,
    mapped: &mut Vec<interface::Mapped>,
    notes: &mut Notes,
) {
    for (_, pou, _, iface) in read {
        for v in &iface.external_decls {
            let n = v.name.as_str();
            let known = |g: &Var| g.name.as_str().eq_ignore_ascii_case(n);
            if globals.iter().any(known) || read.iter().any(|r| r.3.globals.iter().any(known)) {
                continue;
            }
            notes.push(Note {
                origin: v.origin,
                message: format!("pou {pou}: external variable `{n}` has no global declaration in the file (an editor extension declares it in code it generates, as Beremiz's SVGHMI does for CURRENT_PAGE_0): read as a global of its declared type {}", v.ty.as_str()),
            });
            globals.push(v.clone());
            mapped.extend(iface.external_mapped.iter().filter(|m| m.var == n).cloned());
        }
    }
}
