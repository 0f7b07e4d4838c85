//! User function block types → C (IEC 61131-3 6.6.3; the FBD text-generation paper passes an
//! instance's data to its type's code): one struct per type holding its inputs, outputs, own
//! variables, hidden memories and nested instance structs, each instance a member of its owner
//! (the program's state or the owning instance's struct), and one function per type
//! `void _fb_<T>_body(_fb_<T> *self, _plc_state *_g, _plc_ctx *ctx)` (`_g`: the program's state,
//! for the globals the body names; `ctx`: time, loop cap, faults); a call passes `&self->inst`.
//!
//! The function is written from one instance's lowered rungs (so its semantics are the
//! interpreter's, by construction), following the type's FBD plan (fragment tree, one local per
//! data arc) or its ladder rungs, with the instance's members renamed `self->…`
//! ([`InstanceCtx`]). Invariant checked, not assumed: every instance of the type gives the same
//! text; instances that would not (none known) get a function of their own, so the C stays
//! exact. A type nothing instantiates gets no struct and no function (nothing could run it; its
//! typed body is `None`); a ladder-bodied type gets one function per type too, from its
//! instance's rungs. Not here: the POUs of the program (`super`), the harness.

use super::ladder::{c_type, Body, InstanceCtx, Shared};
use super::text::push;
use super::{fbd, names};
use plc_fbd::{Fbd, FbdPouKind};
use plc_model::{Program, VarId};
use std::collections::HashMap;

/// Where every instance and every variable lives in the C data.
pub(crate) struct Layout {
    /// Per instance (index into `Fbd::instances`): the instance that owns it (`None`: the
    /// program's state).
    pub owner: Vec<Option<usize>>,
    /// Per instance: its lvalue in `_plc_state` terms (`self->G1.INNER`).
    pub paths: Vec<String>,
    /// Per variable: its lvalue (`self->x`, `self->G1.IN`, `self->_h3`) and the instance it is
    /// a member of.
    pub vars: Vec<(String, Option<usize>)>,
}

/// The instance whose member `name` is: the longest instance name followed by `.` or `:`
/// (hidden edge memories of a ladder body are named after the instance's rungs, `G1:R1:edge1`),
/// with the separator's position.
fn owner_of(name: &str, by_name: &HashMap<&str, usize>) -> Option<(usize, usize)> {
    name.char_indices()
        .rev()
        .filter(|&(_, c)| c == '.' || c == ':')
        .find_map(|(i, _)| by_name.get(&name[..i]).map(|&k| (k, i)))
}

pub(crate) fn layout(p: &Program, fbd: &Fbd) -> Layout {
    let by_name: HashMap<&str, usize> = fbd
        .instances
        .iter()
        .enumerate()
        .map(|(k, i)| (i.name.as_str(), k))
        .collect();
    // Owners come before what they own (nested instances follow their owner).
    let mut owner = Vec::with_capacity(fbd.instances.len());
    let mut paths: Vec<String> = Vec::with_capacity(fbd.instances.len());
    for inst in &fbd.instances {
        let own = owner_of(&inst.name, &by_name).filter(|&(_, i)| inst.name.as_bytes()[i] == b'.');
        let path = match own {
            Some((o, i)) if o < paths.len() => {
                format!("{}.{}", paths[o], names::user_ident(&inst.name[i + 1..]))
            }
            _ => format!("self->{}", names::user_ident(&inst.name)),
        };
        owner.push(own.map(|(o, _)| o).filter(|&o| o < paths.len()));
        paths.push(path);
    }
    let vars = p
        .vars()
        .iter()
        .enumerate()
        .map(|(i, v)| match owner_of(&v.name, &by_name) {
            Some((k, at)) => {
                let rel = &v.name[at + 1..];
                let field = if v.name.as_bytes()[at] == b'.' {
                    names::user_ident(rel)
                } else {
                    format!("_h{}", names::encode_ident(rel))
                };
                (format!("{}.{field}", paths[k]), Some(k))
            }
            None if v.hidden => (format!("self->_h{i}"), None),
            None => (format!("self->{}", names::user_ident(&v.name)), None),
        })
        .collect();
    Layout { owner, paths, vars }
}

/// The C struct of type `t`.
pub(crate) fn struct_name(fbd: &Fbd, t: usize) -> String {
    format!("_fb_{}", names::encode_ident(&fbd.types[t].name))
}

/// The types that have instances, each after the types nested in it.
pub(crate) fn order(fbd: &Fbd, lay: &Layout) -> Vec<usize> {
    let n = fbd.types.len();
    let mut deps = vec![Vec::new(); n];
    let mut used = vec![false; n];
    for (k, inst) in fbd.instances.iter().enumerate() {
        used[inst.ty.index()] = true;
        if let Some(o) = lay.owner[k] {
            deps[fbd.instances[o].ty.index()].push(inst.ty.index());
        }
    }
    let mut out = Vec::new();
    let mut done = vec![false; n];
    fn visit(t: usize, deps: &[Vec<usize>], done: &mut [bool], out: &mut Vec<usize>) {
        if done[t] {
            return;
        }
        done[t] = true; // types do not nest themselves (the resolver refuses it)
        for &d in &deps[t] {
            visit(d, deps, done, out);
        }
        out.push(t);
    }
    for t in (0..n).filter(|&t| used[t]) {
        visit(t, &deps, &mut done, &mut out);
    }
    out
}

/// The struct definitions of the types in `order`, for `plc_program.h`.
/// `local_only`: per variable, whether the type's function holds it in a local (no member).
pub(crate) fn structs(
    p: &Program,
    fbd: &Fbd,
    lay: &Layout,
    order: &[usize],
    local_only: &[bool],
) -> String {
    let mut s = String::new();
    for &t in order {
        let mut fields: Vec<(String, String)> = Vec::new();
        let mut seen = std::collections::HashSet::new();
        for (i, (path, own)) in lay.vars.iter().enumerate() {
            let Some(k) = *own else { continue };
            if fbd.instances[k].ty.index() != t || local_only[i] {
                continue;
            }
            let field = path[lay.paths[k].len() + 1..].to_string();
            if seen.insert(field.clone()) {
                let v = &p.vars()[i];
                let rel = &v.name[fbd.instances[k].name.len() + 1..];
                let decl = format!("{} {field}; /* {} */", c_type(v.ty), names::comment(rel));
                fields.push((field, decl));
            }
        }
        for (k, own) in lay.owner.iter().enumerate() {
            let Some(o) = *own else { continue };
            if fbd.instances[o].ty.index() != t {
                continue;
            }
            let field = lay.paths[k][lay.paths[o].len() + 1..].to_string();
            if seen.insert(field.clone()) {
                let ty = struct_name(fbd, fbd.instances[k].ty.index());
                fields.push((
                    field.clone(),
                    format!("{ty} {field}; /* nested instance */"),
                ));
            }
        }
        let name = struct_name(fbd, t);
        push(
            &mut s,
            format_args!(
                "/* function block {} */\ntypedef struct {name} {{\n    \
                 uint32_t _rung0; /* its instance's first rung */\n    \
                 uint32_t _ctr0; /* its instance's first loop counter */\n",
                names::comment(&fbd.types[t].name)
            ),
        );
        for (_, decl) in fields {
            push(&mut s, format_args!("    {decl}\n"));
        }
        push(&mut s, format_args!("}} {name};\n\n"));
    }
    s
}

/// The first loop counter of the rungs from `rung0` on (0 when none has one).
pub(crate) fn ctr0(sh: &Shared, rungs: std::ops::Range<u32>) -> u32 {
    rungs
        .filter_map(|r| sh.counters[r as usize])
        .next()
        .unwrap_or(0)
}

/// The functions of type `t` (usually one) and the function of each of its instances, in
/// `sh.inst_fns`. `fbd_of`: POU index → index into `fbd.pous` of its FBD body.
pub(crate) fn functions(
    sh: &mut Shared,
    fbd: &Fbd,
    t: usize,
    fbd_of: &HashMap<usize, usize>,
) -> (String, String) {
    let insts: Vec<usize> = (0..fbd.instances.len())
        .filter(|&k| fbd.instances[k].ty.index() == t)
        .collect();
    let base = format!("_fb_{}_body", names::encode_ident(&fbd.types[t].name));
    let st = struct_name(fbd, t);
    // Texts without rung comments (they name the instance's rungs) decide who shares code.
    let mut groups: Vec<(String, usize)> = Vec::new();
    let mut of_inst = Vec::new();
    for &k in &insts {
        let text = body(sh, fbd, k, fbd_of, false);
        let g = match groups.iter().position(|(x, _)| *x == text) {
            Some(g) => g,
            None => {
                groups.push((text, k));
                groups.len() - 1
            }
        };
        of_inst.push(g);
    }
    let fname = |g: usize| {
        if g == 0 {
            base.clone()
        } else {
            format!("{base}_{g}")
        }
    };
    let (mut src, mut decls) = (
        String::from("#include \"plc_program.h\"\n\n"),
        String::new(),
    );
    for (g, (_, k)) in groups.iter().enumerate() {
        let f = fname(g);
        let sig = format!("void {f}({st} *self, _plc_state *_g, _plc_ctx *ctx)");
        let code = body(sh, fbd, *k, fbd_of, true);
        push(
            &mut src,
            format_args!(
                "/* function block {} (written from instance {}) */\n{sig} {{\n{code}}}\n\n",
                names::comment(&fbd.types[t].name),
                names::comment(&fbd.instances[*k].name)
            ),
        );
        push(&mut decls, format_args!("{sig};\n"));
    }
    for (&k, &g) in insts.iter().zip(&of_inst) {
        sh.inst_fns[k] = fname(g);
    }
    (src, decls)
}

/// The body of the type's function written from instance `k`'s rungs.
fn body(
    sh: &Shared,
    fbd: &Fbd,
    k: usize,
    fbd_of: &HashMap<usize, usize>,
    comments: bool,
) -> String {
    let p = sh.p;
    let inst = &fbd.instances[k];
    let rungs = p.pou(inst.pou).rungs.clone();
    let mut b = Body::new(sh, "return;", 1);
    b.comments = comments;
    b.inst = Some(InstanceCtx {
        prefix: format!("{}.", sh.inst_paths[k]),
        rung0: rungs.start,
        ctr0: ctr0(sh, rungs.clone()),
    });
    b.line("(void)self; (void)_g; (void)ctx;");
    match fbd_of.get(&inst.pou.index()) {
        Some(&fp) => {
            let fpou = &fbd.pous[fp];
            debug_assert_eq!(fpou.kind, FbdPouKind::FunctionBlock);
            let copy = fpou
                .copies
                .iter()
                .find(|c| c.pou == inst.pou)
                .expect("an instance's FBD body has its copy");
            let hidden: HashMap<&str, VarId> = p
                .vars()
                .iter_enumerated()
                .filter(|(_, v)| v.hidden && v.name.starts_with(inst.name.as_str()))
                .map(|(i, v)| (v.name.as_str(), i))
                .collect();
            let locals = fbd::locals(p, &hidden, fpou, &format!("{}.", inst.name));
            fbd::declare(&mut b, p, &locals);
            fbd::pou(&mut b, p, fpou, copy);
        }
        None => {
            for r in rungs {
                b.rung(p.rungs().id(r as usize));
            }
        }
    }
    b.finish()
}
