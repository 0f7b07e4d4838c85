//! C from ladder and FBD programs (the FBD text-generation paper's generator, extended to the
//! whole program): for every POU a header and a source file, for every user function block
//! type with instances a source file (`types`: one struct and one function per type), a runtime
//! header, the program's state and harness tables, the harness's driver, `main.c` and a
//! `Makefile`.
//!
//! Shape: the program's persistent data (every variable: globals, subroutine locals, timers,
//! counters, edge memories, the loop counters, and each top-level function block instance as a
//! struct member) is one struct `_plc_state` passed to every POU function as `self`; each POU is a function `_pou_<name>(self, ctx)`
//! (`ctx`: virtual time, scan, loop cap, fault sink). Ladder rungs are one block of statements
//! each (`ladder`); FBD networks are nested `if` blocks following their fragment trees, with
//! one local per data arc (`fbd`). A ladder POU's rungs of contacts, coils and simple boxes are rows of
//! tables of byte offsets, each run by a small loop specialised for the rung's shape (`rows`, `kernel`;
//! [`CConfig::rows`], the default), emitted in an order that groups them by dependence level
//! and shape within straight-line regions (`order`); the other rungs are statements. A ladder
//! POU of more than [`CConfig::chunk_rungs`] units (a rung of statements, a run of rows) is cut
//! into functions at boundaries no jump and no FOR loop crosses, in part files whose number is
//! bounded (`parts`), so the C compiler's time grows linearly with the program: at 100,000
//! rungs a build takes seconds with rows, minutes with every rung as statements (docs/c.md).
//!
//! Invariants: the generated program computes after every scan exactly the state and the faults
//! of the sequential interpreter (`plc_exec::Machine`) given the same inputs (tests:
//! `tests/c_codegen*.rs` compile it with `cc -std=c11 -Wall -Wextra -Werror -O2` and compare
//! every scan); every identifier and file name is made by `names` (no program name can change
//! the C's meaning or leave the output folder).
//!
//! Not here: writing the files (`crate::cmd::c`), reading the program.

mod fbd;
mod fold;
mod functions;
mod harness;
mod kernel;
mod ladder;
pub mod names;
mod order;
mod parallel;
mod parts;
mod rows;
mod runtime;
mod shape;
mod spelling;
mod table;
mod text;
mod types;

use ladder::{c_type, Body, Shared};
use parts::{chunks_per_file, ladder_files};
use plc_fbd::Fbd;
use plc_model::{walk_elements, Element, FbKind, PouKind, Program, Type, VarId};
use std::collections::HashMap;

pub use runtime::RUNTIME_H;

/// What `plc-deps c` was asked for.
#[derive(Clone, Debug)]
pub struct CConfig {
    /// The scan cycle the harness runs (`--cycle`), ms.
    pub cycle_ms: u32,
    /// Loop-backs per loop-back rung and scan (`--loop-cap`).
    pub loop_cap: u32,
    /// Rungs each task of a scan may charge (`--scan-budget`): the default of the generated
    /// `PLC_SCAN_BUDGET`.
    pub scan_budget: u64,
    /// Rungs per function of a large ladder POU.
    pub chunk_rungs: usize,
    /// Rungs of contacts and coils as rows of tables run by kernels specialised by shape
    /// (`rows`; `plc-deps c --statements` turns it off): `cc` takes seconds instead of minutes
    /// at 100,000 rungs, and the rows run as fast as the statements or faster (docs/c.md).
    pub rows: bool,
    /// Worker threads of the parallel scan (`--threads`): 1 (the default) writes the
    /// sequential program only; N ≥ 2 adds `plc_scan_parallel` and the runtime API
    /// (`parallel`, docs/c.md).
    pub threads: usize,
    /// With `threads` ≥ 2: every level of the schedule a parallel phase (the planner's
    /// `Strategy::AllParallel`), whatever the cost model says; for tests and measurements.
    pub parallel_all: bool,
}

impl Default for CConfig {
    fn default() -> Self {
        CConfig {
            cycle_ms: 10,
            loop_cap: 100_000,
            scan_budget: plc_exec::DEFAULT_SCAN_BUDGET,
            chunk_rungs: 64,
            rows: true,
            threads: 1,
            parallel_all: false,
        }
    }
}

/// One generated file: its name (no folder) and text.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct CFile {
    pub name: String,
    pub text: String,
}

/// The C of `p` (with its FBD bodies `fbd`), as files.
pub fn generate(p: &Program, fbd: &Fbd, cfg: &CConfig) -> Vec<CFile> {
    let lay = types::layout(p, fbd);
    let mut sh = shared(p, fbd, &lay);
    let copies = fbd_copies(p, fbd);
    sh.local_only = local_only(p, fbd, &copies);
    sh.at = member_offsets(p, &lay, &sh.local_only);
    let fbd_of: HashMap<usize, usize> = copies.iter().map(|(&k, (fp, _))| (k, *fp)).collect();
    // The function block types first (nested types before their owners: a call names the
    // function its callee's type got).
    let order = types::order(fbd, &lay);
    let (mut type_files, mut type_decls) = (Vec::new(), String::new());
    for &t in &order {
        let (text, decls) = types::functions(&mut sh, fbd, t, &fbd_of);
        let ty = &fbd.types[t].name;
        // A type whose body is not translated (its instances' POUs are skipped) says so.
        let skipped = fbd.instances.iter().find_map(|i| {
            let pou = p.pous().get(i.pou.index())?;
            (i.fb == *ty).then_some(pou.skipped.as_deref()?)
        });
        let note = skipped.map_or(String::new(), |s| {
            format!(
                "/* NOT EXECUTED: the {} body of function block {} is not translated; its functions run its stand-in rungs, which keep every value (plc-deps c --allow-skipped). */\n",
                names::comment(&s.language),
                names::comment(ty)
            )
        });
        type_files.push((
            format!("fb_{}", names::encode_file(ty, t)),
            format!("{note}{text}"),
        ));
        type_decls.push_str(&decls);
    }
    let structs = types::structs(p, fbd, &lay, &order, &sh.local_only);
    let stems: Vec<Option<String>> = p
        .pous()
        .iter()
        .enumerate()
        .map(|(i, pou)| {
            sh.inst_of_pou[i]
                .is_none()
                .then(|| format!("pou_{}", names::encode_file(&pou.name, i)))
        })
        .collect();
    let header = Header {
        stems: stems.iter().flatten().cloned().collect(),
        structs,
        type_decls,
        fbd,
        lay: &lay,
    };
    let mut files = vec![
        CFile {
            name: "plc_runtime.h".into(),
            text: RUNTIME_H.into(),
        },
        CFile {
            name: "plc_program.h".into(),
            text: program_header(p, &sh, &header, cfg.scan_budget),
        },
        CFile {
            name: "plc_program.c".into(),
            text: harness::program_source(p, &sh, &instance_inits(&sh, fbd), cfg),
        },
        CFile {
            name: "plc_main.h".into(),
            text: harness::PLC_MAIN_H.into(),
        },
    ];
    // The ladder POUs (those with a function of their own, not written from an FBD body).
    let ladder: Vec<bool> = (0..p.pous().len())
        .map(|i| stems[i].is_some() && !copies.contains_key(&i))
        .collect();
    let mut kernels = rows::Kernels::default();
    let acc = cfg.rows.then(|| plc_analysis::accesses(p));
    if cfg.rows {
        sh.rows = order::rows(&sh, &ladder, &mut kernels);
    }
    let plans: Vec<Option<order::Plan>> = (0..p.pous().len())
        .map(|i| ladder[i].then(|| order::plan(p, acc.as_ref(), &sh.rows, &sh.labels, i)))
        .collect();
    let per_file = chunks_per_file(p, &plans, cfg.chunk_rungs);
    let (mut objects, mut parts) = (Vec::new(), Vec::new());
    let mut data = parts::DataFiles {
        entry: kernels.entry_type(),
        files: Vec::new(),
    };
    for (i, pou) in p.pous().iter().enumerate() {
        let Some(stem) = &stems[i] else { continue };
        let f = &sh.pou_fns[i];
        let (sources, decls) = match (copies.get(&i), &plans[i]) {
            (Some((fp, prefix)), _) => {
                let body = fbd_function(p, &sh, fbd, *fp, prefix, i);
                let text = format!("#include \"plc_program.h\"\n\n{body}");
                (vec![(String::new(), text)], String::new())
            }
            (None, Some(plan)) => ladder_files(p, &sh, i, cfg, per_file, plan, &mut data),
            (None, None) => unreachable!("a POU with a stem is FBD or ladder"),
        };
        // A body that is not translated (`plc-deps c --allow-skipped`) says so where its
        // function is declared and defined.
        let note = pou.skipped.as_deref().map_or(String::new(), |s| {
            format!(
                "/* NOT EXECUTED: the {} body of POU {} is not translated; this function runs its stand-in rungs, which keep every value (plc-deps c --allow-skipped). */\n",
                names::comment(&s.language),
                names::comment(&pou.name)
            )
        });
        files.push(CFile {
            name: format!("{stem}.h"),
            text: format!(
                "/* POU {} */\n{note}void {f}(_plc_state *self, _plc_ctx *ctx);\n{decls}",
                names::comment(&pou.name)
            ),
        });
        for (suffix, text) in sources {
            if !suffix.is_empty() {
                parts.push(format!("{stem}{suffix}"));
            }
            objects.push(format!("{stem}{suffix}"));
            files.push(CFile {
                name: format!("{stem}{suffix}.c"),
                text: format!("{note}{text}"),
            });
        }
    }
    let par_files = (cfg.threads >= 2)
        .then(|| parallel::files(&sh, ladder[0], cfg, &mut data, &mut objects, &mut parts));
    data.files.extend(kernels.sources());
    for (stem, text) in data.files.into_iter().chain(type_files) {
        files.push(CFile {
            name: format!("{stem}.c"),
            text,
        });
        objects.push(stem);
    }
    let mut makefile = harness::makefile(&objects, &parts);
    let mut main_c = harness::MAIN_C.to_string();
    if let Some(par) = par_files {
        files.extend(par);
        main_c = harness::PAR_MAIN_C.to_string();
        makefile = harness::par_makefile(&makefile);
        let driver = files
            .iter_mut()
            .find(|f| f.name == "plc_main.h")
            .expect("the driver");
        driver.text = harness::par_main_h();
    }
    files.push(CFile {
        name: "main.c".into(),
        text: main_c,
    });
    files.push(CFile {
        name: "Makefile".into(),
        text: makefile,
    });
    files
}

/// The initializers of every instance's rung and loop counter bases (`.G1._rung0 = 12,`).
fn instance_inits(sh: &Shared, fbd: &Fbd) -> Vec<String> {
    let mut out = Vec::new();
    for (k, inst) in fbd.instances.iter().enumerate() {
        let rungs = sh.p.pou(inst.pou).rungs.clone();
        let path = sh.inst_paths[k].trim_start_matches("self->");
        let ctr0 = types::ctr0(sh, rungs.clone());
        if rungs.start != 0 {
            out.push(format!("    .{path}._rung0 = {},\n", rungs.start));
        }
        if ctr0 != 0 {
            out.push(format!("    .{path}._ctr0 = {ctr0},\n"));
        }
    }
    out
}

/// Names, labels and loop counters of the whole program.
fn shared<'a>(p: &'a Program, fbd: &Fbd, lay: &types::Layout) -> Shared<'a> {
    let vars = lay.vars.iter().map(|(path, _)| path.clone()).collect();
    let mut inst_of_pou = vec![None; p.pous().len()];
    for (k, inst) in fbd.instances.iter().enumerate() {
        inst_of_pou[inst.pou.index()] = Some(k);
    }
    let pou_fns = p
        .pous()
        .iter()
        .map(|pou| format!("_pou_{}", names::encode_ident(&pou.name)))
        .collect();
    let mut labels = vec![false; p.rungs().len()];
    let mut counters = vec![None; p.rungs().len()];
    let mut next = 0u32;
    for (i, r) in p.rungs().iter().enumerate() {
        let mut back = false;
        walk_elements(&r.series, &mut |e| match e {
            Element::Jmp { target, .. } => {
                labels[target.index()] = true;
                back |= target.index() <= i;
            }
            Element::Next { .. } => back = true,
            _ => {}
        });
        if back {
            counters[i] = Some(next);
            next += 1;
        }
    }
    Shared {
        p,
        vars,
        pou_fns,
        inst_of_pou,
        inst_paths: lay.paths.clone(),
        inst_fns: vec![String::new(); fbd.instances.len()],
        labels,
        counters,
        local_only: vec![false; p.vars().len()],
        at: Vec::new(),
        budget_task: plc_exec::budget::tasks(p),
        rows: vec![None; p.rungs().len()],
    }
}

/// A class of members whose offsets the generator computes: which types, their size and
/// alignment in bytes (x86-64 and AArch64; `plc_runtime.h` and `plc_program.h` assert them).
pub(crate) struct Class {
    pub is: fn(Type) -> bool,
    pub size: u32,
    pub align: u32,
}

/// The classes in the order `_plc_state` lists them: BOOLs, INTs, counter instances
/// (`_plc_counter`: CTU and CTD), timer instances (`_plc_timer`: TON, TOF, TP).
pub(crate) const CLASSES: [Class; 4] = [
    Class {
        is: |t| t == Type::Bool,
        size: 1,
        align: 1,
    },
    Class {
        is: |t| t == Type::Int,
        size: 2,
        align: 2,
    },
    Class {
        is: |t| matches!(t, Type::Fb(FbKind::Ctu | FbKind::Ctd)),
        size: 8,
        align: 2,
    },
    Class {
        is: |t| matches!(t, Type::Fb(FbKind::Ton | FbKind::Tof | FbKind::Tp)),
        size: 32,
        align: 8,
    },
];

/// Per variable: its byte offset in `_plc_state` if it is a member of the struct itself (not a
/// member of an instance's struct, not a local of an FBD function) of one of the [`CLASSES`].
/// The struct lists these members first, class by class, in variable order within a class: C
/// lays members out in order from offset 0, with no padding between members whose size is a
/// multiple of their alignment, and each class starting at the first offset after the class
/// before it that is a multiple of its alignment (`plc_program.h` asserts the sizes and
/// alignments, `plc_program.c` the offset of the last member of each class).
fn member_offsets(p: &Program, lay: &types::Layout, local_only: &[bool]) -> Vec<Option<u32>> {
    let member = |i: usize| lay.vars[i].1.is_none() && !local_only[i];
    let mut out = vec![None; p.vars().len()];
    let mut next = 0u32;
    for c in CLASSES {
        next = next.next_multiple_of(c.align);
        for (i, at) in out.iter_mut().enumerate() {
            if member(i) && (c.is)(p.vars()[i].ty) {
                *at = Some(next);
                next += c.size;
            }
        }
    }
    out
}

/// The program's hidden variables (the FBD lowering's arcs and run flags) by name.
fn hidden_vars(p: &Program) -> HashMap<&str, VarId> {
    p.vars()
        .iter_enumerated()
        .filter(|(_, v)| v.hidden)
        .map(|(i, v)| (v.name.as_str(), i))
        .collect()
}

/// The variables every FBD function holds in locals (arcs and run flags of each copy).
fn local_only(p: &Program, fbd: &Fbd, copies: &HashMap<usize, (usize, String)>) -> Vec<bool> {
    let hidden = hidden_vars(p);
    let mut out = vec![false; p.vars().len()];
    for (fp, prefix) in copies.values() {
        for (v, _) in fbd::locals(p, &hidden, &fbd.pous[*fp], prefix) {
            out[v.index()] = true;
        }
    }
    out
}

/// The number of loop counters.
fn counter_count(sh: &Shared) -> usize {
    sh.counters.iter().flatten().count()
}

/// What `plc_program.h` declares besides the program's variables.
struct Header<'a> {
    /// The POUs' file stems (instances have none: their types' functions run them).
    stems: Vec<String>,
    /// The function block types' structs, nested types first.
    structs: String,
    /// The function block types' functions.
    type_decls: String,
    fbd: &'a Fbd,
    lay: &'a types::Layout,
}

fn program_header(p: &Program, sh: &Shared, h: &Header, scan_budget: u64) -> String {
    let mut s = String::from(
        "/* plc_program.h: the persistent data of the program, generated by plc-deps. */\n\
         #ifndef PLC_PROGRAM_H\n#define PLC_PROGRAM_H\n#include \"plc_runtime.h\"\n\n\
         typedef struct _plc_state _plc_state;\n\n",
    );
    text::push(
        &mut s,
        format_args!(
            "/* Rungs each task of a scan may charge with its calls and loop-backs (docs/scan.md,\n   \
             `plc-deps c --scan-budget`); -DPLC_SCAN_BUDGET=N overrides it. */\n\
             #ifndef PLC_SCAN_BUDGET\n#define PLC_SCAN_BUDGET {scan_budget}ULL\n#endif\n\n"
        ),
    );
    s.push_str(&h.structs);
    s.push_str("struct _plc_state {\n");
    let mut fields = 0;
    // The BOOLs, INTs, counters and timers first, at the offsets `member_offsets` gives (the rows' tables hold
    // them).
    let mut known: Vec<usize> = (0..p.vars().len())
        .filter(|&i| sh.at[i].is_some())
        .collect();
    known.sort_by_key(|&i| sh.at[i]);
    let others = (0..p.vars().len())
        .filter(|&i| sh.at[i].is_none() && h.lay.vars[i].1.is_none() && !sh.local_only[i]);
    for i in known.into_iter().chain(others) {
        let v = &p.vars()[i];
        let field = sh.vars[i].trim_start_matches("self->");
        let ty = c_type(v.ty);
        fields += 1;
        text::push(
            &mut s,
            format_args!("    {ty} {field}; /* {} */\n", names::comment(&v.name)),
        );
    }
    for (k, inst) in h.fbd.instances.iter().enumerate() {
        if h.lay.owner[k].is_none() {
            let ty = types::struct_name(h.fbd, inst.ty.index());
            let field = h.lay.paths[k].trim_start_matches("self->");
            fields += 1;
            text::push(
                &mut s,
                format_args!(
                    "    {ty} {field}; /* instance {} */\n",
                    names::comment(&inst.name)
                ),
            );
        }
    }
    let k = counter_count(sh);
    if k > 0 {
        text::push(
            &mut s,
            format_args!("    uint64_t _ctr[{k}]; /* loop counters */\n"),
        );
    }
    if fields == 0 && k == 0 {
        s.push_str("    char _empty;\n");
    }
    s.push_str(
        "};\n\n_Static_assert(sizeof(bool) == 1 && sizeof(int16_t) == 2 && _Alignof(int16_t) == 2, \"the rows' offsets\");\n\
         _Static_assert(sizeof(_plc_counter) == 8 && _Alignof(_plc_counter) == 2 && sizeof(_plc_timer) == 32 && _Alignof(_plc_timer) == 8, \"the rows' offsets\");\n",
    );
    s.push_str("extern const _plc_state _plc_initial;\n");
    s.push_str("void _plc_scan(_plc_state *self, _plc_ctx *ctx);\n");
    s.push_str(&h.type_decls);
    s.push_str(harness::HEADER_DECLS);
    for stem in &h.stems {
        text::push(&mut s, format_args!("#include \"{stem}.h\"\n"));
    }
    s.push_str("#endif\n");
    s
}

/// The FBD body of each POU written in FBD: POU index → (index into `fbd.pous`, var prefix).
fn fbd_copies(p: &Program, fbd: &Fbd) -> HashMap<usize, (usize, String)> {
    let mut out = HashMap::new();
    for (i, fp) in fbd.pous.iter().enumerate() {
        for c in &fp.copies {
            let pou = p.pou(c.pou);
            let prefix = if pou.kind == PouKind::Main {
                String::new()
            } else if fbd.instances.iter().any(|inst| inst.pou == c.pou) {
                format!("{}.", pou.name)
            } else {
                format!("{}:", pou.name)
            };
            out.insert(c.pou.index(), (i, prefix));
        }
    }
    out
}

fn fbd_function(
    p: &Program,
    sh: &Shared,
    fbd: &Fbd,
    fp: usize,
    prefix: &str,
    pou: usize,
) -> String {
    let hidden = hidden_vars(p);
    let fpou = &fbd.pous[fp];
    let copy = fpou
        .copies
        .iter()
        .find(|c| c.pou.index() == pou)
        .expect("the copy of this POU");
    let mut b = Body::new(sh, "return;", 1);
    b.line("(void)self; (void)ctx;");
    let locals = fbd::locals(p, &hidden, fpou, prefix);
    fbd::declare(&mut b, p, &locals);
    fbd::pou(&mut b, p, fpou, copy);
    let f = &sh.pou_fns[pou];
    format!(
        "/* FBD {} {}: networks as fragment trees */\nvoid {f}(_plc_state *self, _plc_ctx *ctx) {{\n{}}}\n",
        fpou.kind.name(),
        names::comment(&fpou.name),
        b.finish()
    )
}
