//! The parallel scan in C (`plc-deps c --threads N`, N ≥ 2): the interpreter's planner's plan
//! (`plc_exec::parallel::plan`, one planner for two back ends) written as one C function per
//! worker over its share of every phase's tasks, with a barrier before every phase the plan
//! says, N − 1 pthreads created once (`plc_init`, `_plc_par_start`), and the runtime API
//! `plc_init`, `plc_scan`, `plc_scan_parallel`, `plc_scan_adaptive` (docs/c.md).
//!
//! Files it adds to the sequential program's (which it leaves as they are): `plc_parallel.h`
//! (the workers' context and the task functions' declarations), `plc_parallel.c` (the plan in
//! its header comment, the barrier, the workers, the fault merge, the adaptive choice, the
//! API), `plc_api.h` (the API), `plc_par_part<N>.c` (the tasks' code, cut into functions of about
//! [`CConfig::chunk_rungs`] units at task boundaries, in at most eight files, rows as in the
//! sequential program); and it replaces `main.c`, `plc_main.h` (the driver runs the parallel
//! scan, or with `--time` the three scans side by side) and the `Makefile` (`-pthread`).
//!
//! Invariants: the parallel scan computes after every scan the same state and the same faults in
//! the same order as `_plc_scan` (and so as the sequential interpreter). Why: the plan is the
//! one the executor runs, checked by the planner against the lowered code's byte accesses; it
//! is checked again here against the C's accesses at the level of variables (no variable one
//! worker writes in a phase is read or written by another in that phase; no subroutine with
//! loop counters is called by two workers of a phase), and a plan that fails, or that needs
//! what this generator does not write (control decisions of the main program: a jump, RET or
//! END that leaves a task; a dependence-driven plan; an FBD main program), makes
//! `plc_scan_parallel` the sequential scan, with the reason in `plc_parallel.c`. Tasks of one
//! parallel phase are one level of the schedule, independent of each other, so a worker's tasks
//! are emitted in any order (single-rung rows grouped by kernel, as `order` does); faults are
//! buffered per worker with the task that raised them and replayed in task order, which is the
//! sequential order (tasks are numbered in program order and each runs on one worker). Each
//! worker has its own `_plc_ctx` (on its own cache lines), so the scan budget counts each task
//! (a strongly connected part of the main program, `plc_exec::budget::tasks`, which stays on one
//! worker) as the sequential scan does.
//!
//! Not here: measuring the plan on the machine (the adaptive choice in the generated C measures
//! the two entry points), a layout of the state by worker (the struct keeps the sequential
//! layout: the header counts the cache lines that move between workers), point-to-point ready
//! flags (a barrier per phase only).

use super::ladder::{Body, Shared};
use super::parts::DataFiles;
use super::table::Tables;
use super::text::push;
use super::{CConfig, CFile};
use plc_exec::parallel::{plan, PlanConfig, ScanPlan, ScanPlanKind, Strategy};
use plc_model::{walk_elements, Element, PouId, Program, RungId, VarClass};

/// The plan as the C writes it: per phase, its barrier and each worker's tasks in order.
struct Split {
    plan: ScanPlan,
    phases: Vec<PhaseC>,
}

struct PhaseC {
    barrier: bool,
    parallel: bool,
    /// Per worker, the tasks it runs, in emission order.
    workers: Vec<Vec<u32>>,
}

/// The most part files of the tasks' code, and the fewest chunk functions in one.
const MAX_PART_FILES: usize = 8;
const MIN_CHUNKS_PER_FILE: usize = 16;

/// The files of the parallel scan (see the module doc); `objects` and `parts` get the new
/// sources' stems, `data` the rows' data files.
pub(crate) fn files(
    sh: &Shared,
    main_is_ladder: bool,
    cfg: &CConfig,
    data: &mut DataFiles,
    objects: &mut Vec<String>,
    parts: &mut Vec<String>,
) -> Vec<CFile> {
    let p = sh.p;
    let threads = cfg.threads.max(2);
    let split = if main_is_ladder {
        split(sh, threads, cfg.parallel_all)
    } else {
        Err(
            "the main program is written in FBD: its C is one function of fragment trees, \
             not of tasks"
                .to_string(),
        )
    };
    let mut out = Vec::new();
    let mut chunk_decls = String::new();
    let mut worker_code = vec![String::new(); threads];
    let mut header = String::new();
    let mut task_table = String::new();
    match &split {
        Ok(s) => {
            let code = chunks(sh, s, cfg, data, &mut chunk_decls, objects, parts, &mut out);
            worker_code = code;
            header = describe(p, sh, s);
            task_table = task_of_rung(p, &s.plan);
        }
        Err(why) => {
            push(
                &mut header,
                format_args!(
                    " * Plan: sequential ({}): plc_scan_parallel runs the sequential scan.\n",
                    super::names::comment(why)
                ),
            );
        }
    }
    out.push(CFile {
        name: "plc_parallel.h".into(),
        text: format!(
            "/* plc_parallel.h: the workers of the parallel scan (plc-deps c --threads; docs/c.md). */\n\
             #ifndef PLC_PARALLEL_H\n#define PLC_PARALLEL_H\n#include \"plc_program.h\"\n\n\
             #define PLC_THREADS {threads}\n\n{WORKER_DECLS}{chunk_decls}#endif\n"
        ),
    });
    out.push(CFile {
        name: "plc_parallel.c".into(),
        text: parallel_source(
            sh,
            split.as_ref().ok(),
            &header,
            &worker_code,
            &task_table,
            threads,
        ),
    });
    objects.push("plc_parallel".into());
    out.push(CFile {
        name: "plc_api.h".into(),
        text: API_H.replacen(
            "#include \"plc_program.h\"\n",
            &format!("#include \"plc_program.h\"\n\n#define PLC_THREADS {threads}\n"),
            1,
        ),
    });
    out
}

/// The plan for `threads` workers, mapped to tasks and checked; the reason it runs sequentially
/// otherwise.
fn split(sh: &Shared, threads: usize, all: bool) -> Result<Split, String> {
    let p = sh.p;
    let a = plc_analysis::analyse(p);
    let mut config = PlanConfig::new(threads);
    if all {
        config.strategy = Strategy::AllParallel;
    }
    let sp = plan(p, &a, &config).map_err(|e| e.to_string())?;
    match &sp.kind {
        ScanPlanKind::Sequential(why) => return Err(format!("the planner: {why}")),
        ScanPlanKind::DependenceDriven => {
            return Err("a dependence-driven plan (ready flags) is not generated".into())
        }
        ScanPlanKind::Levelled => {}
    }
    let main = p.main().rungs.clone();
    let mut phases = Vec::new();
    for ph in &sp.phases {
        let mut workers = Vec::new();
        for items in &ph.workers {
            let mut tasks = Vec::new();
            for it in items {
                if !it.guard.is_empty()
                    || !it.entry_slots.is_empty()
                    || it.decision.is_some()
                    || !it.waits.is_empty()
                {
                    return Err(
                        "the plan has control decisions of the main program (a jump, \
                                RET or END that leaves a task), which this generator does not \
                                write"
                            .into(),
                    );
                }
                tasks.extend(it.first.raw()..=it.last.raw());
            }
            // The rungs of each task stay in it: no RET or END, every jump inside the task.
            for &t in &tasks {
                let rungs = &sp.task_rungs[t as usize];
                for r in rungs {
                    let mut bad = false;
                    walk_elements(&p.rung(*r).series, &mut |e| match e {
                        Element::Ret | Element::End => bad = true,
                        Element::Jmp { target, .. } => bad |= !rungs.contains(target),
                        _ => {}
                    });
                    if bad || !main.contains(&r.raw()) {
                        return Err(format!(
                            "rung {} leaves its task (RET, END or a jump out of it)",
                            super::names::comment(&p.rung(*r).id)
                        ));
                    }
                }
            }
            if ph.parallel {
                // One level: the tasks are independent; rows of one kernel together.
                let key = |t: &u32| match sp.task_rungs[*t as usize].as_slice() {
                    [r] => sh.rows[r.index()].as_ref().map_or(0, |row| row.kernel + 1),
                    _ => 0,
                };
                tasks.sort_by_key(key);
            }
            workers.push(tasks);
        }
        phases.push(PhaseC {
            barrier: ph.barrier_before,
            parallel: ph.parallel,
            workers,
        });
    }
    if !phases.iter().any(|ph| ph.parallel && ph.barrier) {
        return Err("the plan has no parallel phase".into());
    }
    let s = Split { plan: sp, phases };
    check(p, sh, &a.accesses, &s)?;
    Ok(s)
}

/// The check of the plan against the C's accesses (module doc); the first conflict.
fn check(p: &Program, sh: &Shared, acc: &plc_analysis::Accesses, s: &Split) -> Result<(), String> {
    let callees = counter_callees(p, sh);
    let mut writer = vec![(u32::MAX, 0u32); p.vars().len()];
    let mut caller = vec![(u32::MAX, 0u32); p.pous().len()];
    for (k, ph) in s.phases.iter().enumerate() {
        if !ph.parallel {
            continue;
        }
        let k = k as u32;
        let rungs = |w: usize| {
            ph.workers[w]
                .iter()
                .flat_map(|&t| s.plan.task_rungs[t as usize].iter().copied())
        };
        for w in 0..ph.workers.len() {
            for r in rungs(w) {
                for &v in acc.outs(r) {
                    let x = &mut writer[v.index()];
                    if x.0 == k && x.1 != w as u32 {
                        return Err(conflict(p, v, k));
                    }
                    *x = (k, w as u32);
                }
                for q in &callees[r.index()] {
                    let x = &mut caller[q.index()];
                    if x.0 == k && x.1 != w as u32 {
                        return Err(format!(
                            "POU {} (it has loop counters) is called by two workers in phase {k}",
                            super::names::comment(&p.pou(*q).name)
                        ));
                    }
                    *x = (k, w as u32);
                }
            }
        }
        for w in 0..ph.workers.len() {
            for r in rungs(w) {
                for &v in acc.ins(r) {
                    let x = writer[v.index()];
                    if x.0 == k && x.1 != w as u32 {
                        return Err(conflict(p, v, k));
                    }
                }
            }
        }
    }
    Ok(())
}

fn conflict(p: &Program, v: plc_model::VarId, k: u32) -> String {
    format!(
        "the plan failed the C's check: variable {} is written by one worker and accessed by \
         another in phase {k}",
        super::names::comment(&p.var(v).name)
    )
}

/// Per rung: the POUs with loop counters it calls, directly or through other calls.
fn counter_callees(p: &Program, sh: &Shared) -> Vec<Vec<PouId>> {
    let calls_of = |r: usize| {
        let mut out = Vec::new();
        walk_elements(&p.rungs()[r].series, &mut |e| {
            if let Element::Call { pou } = e {
                out.push(*pou);
            }
        });
        out
    };
    // Per POU: every POU it reaches (itself included), by a walk of the acyclic call graph.
    let reach = |start: PouId| {
        let mut seen = vec![false; p.pous().len()];
        let mut stack = vec![start];
        while let Some(q) = stack.pop() {
            if std::mem::replace(&mut seen[q.index()], true) {
                continue;
            }
            for r in p.pou(q).rungs.clone() {
                stack.extend(calls_of(r as usize));
            }
        }
        seen
    };
    let has_ctr: Vec<bool> = p
        .pous()
        .iter()
        .map(|pou| pou.rungs.clone().any(|r| sh.counters[r as usize].is_some()))
        .collect();
    let mut memo: Vec<Option<Vec<PouId>>> = vec![None; p.pous().len()];
    (0..p.rungs().len())
        .map(|r| {
            let mut out = Vec::new();
            for q in calls_of(r) {
                let list = memo[q.index()].get_or_insert_with(|| {
                    let seen = reach(q);
                    (p.pous().ids())
                        .filter(|&i| seen[i.index()] && has_ctr[i.index()])
                        .collect()
                });
                out.extend(list.iter().copied());
            }
            out
        })
        .collect()
}

/// Whether rung `r` calls a POU (its faults may name rungs outside the main program).
fn calls(p: &Program, r: RungId) -> bool {
    let mut any = false;
    walk_elements(&p.rung(r).series, &mut |e| {
        any |= matches!(e, Element::Call { .. })
    });
    any
}

/// The tasks' code: chunk functions in part files; per worker, the C of its scan (barriers
/// and chunk calls).
#[allow(clippy::too_many_arguments)]
fn chunks(
    sh: &Shared,
    s: &Split,
    cfg: &CConfig,
    data: &mut DataFiles,
    decls: &mut String,
    objects: &mut Vec<String>,
    parts: &mut Vec<String>,
    out: &mut Vec<CFile>,
) -> Vec<String> {
    let p = sh.p;
    let limit = cfg.chunk_rungs.max(1);
    // All chunks, in order: (phase, worker, tasks).
    let mut list: Vec<(usize, usize, Vec<u32>)> = Vec::new();
    for (k, ph) in s.phases.iter().enumerate() {
        for (w, tasks) in ph.workers.iter().enumerate() {
            let (mut cur, mut units, mut prev) = (Vec::new(), 0usize, None);
            for &t in tasks {
                if units >= limit {
                    list.push((k, w, std::mem::take(&mut cur)));
                    units = 0;
                }
                for r in &s.plan.task_rungs[t as usize] {
                    let kern = sh.rows[r.index()].as_ref().map(|row| row.kernel);
                    units += usize::from(kern.is_none() || kern != prev || !cfg.rows);
                    prev = kern;
                }
                cur.push(t);
            }
            if !cur.is_empty() {
                list.push((k, w, cur));
            }
        }
    }
    let per_file = MIN_CHUNKS_PER_FILE.max(list.len().div_ceil(MAX_PART_FILES));
    let head = "#include \"plc_parallel.h\"\n\n";
    for (n, group) in list.chunks(per_file).enumerate() {
        let mut text = String::new();
        let mut t = cfg.rows.then(|| Tables::new(data.files.len(), data.entry));
        for (j, (_, _, tasks)) in group.iter().enumerate() {
            let id = n * per_file + j;
            let mut b = Body::new(sh, "return;", 1);
            b.rows = t.take();
            b.line("(void)self; (void)ctx;");
            for &task in tasks {
                for &r in &s.plan.task_rungs[task as usize] {
                    if calls(p, r) {
                        b.line(&format!("_plc_par_task(ctx, {task});"));
                    }
                    b.rung(r);
                }
            }
            b.flush_rows();
            t = b.rows.take();
            push(
                &mut text,
                format_args!(
                    "void _plc_pc{id}(void *_self, _plc_ctx *ctx) {{\n    _plc_state *self = _self;\n{}}}\n\n",
                    b.finish()
                ),
            );
            push(
                decls,
                format_args!("void _plc_pc{id}(void *_self, _plc_ctx *ctx);\n"),
            );
        }
        let rows = match t {
            Some(t) => {
                data.files.extend(t.data_file());
                t.declarations()
            }
            None => String::new(),
        };
        let stem = format!("plc_par_part{n}");
        objects.push(stem.clone());
        parts.push(stem.clone());
        out.push(CFile {
            name: format!("{stem}.c"),
            text: format!("{head}{rows}/* The parallel scan's tasks, part {n} */\n{text}"),
        });
    }
    // Each worker's scan.
    let workers = s.plan.workers;
    let mut code = vec![String::new(); workers];
    let mut id = 0usize;
    let mut started = vec![false; workers];
    started[0] = true;
    for (k, ph) in s.phases.iter().enumerate() {
        for (w, c) in code.iter_mut().enumerate() {
            if ph.barrier {
                push(c, format_args!("    _plc_barrier(); /* phase {k} */\n"));
                if !started[w] {
                    started[w] = true;
                    push(c, format_args!("    _plc_state *self = _plc_par_self;\n    _plc_ctx *ctx = _plc_begin({w});\n    (void)self; (void)ctx;\n"));
                }
            }
        }
        while id < list.len() && list[id].0 == k {
            let w = list[id].1;
            push(&mut code[w], format_args!("    _plc_pc{id}(self, ctx);\n"));
            id += 1;
        }
    }
    if s.plan.end_barrier {
        for c in &mut code {
            c.push_str("    _plc_barrier(); /* end of the scan */\n");
        }
    }
    code
}

/// `_plc_task_of_rung`: the task of each main-program rung (`UINT32_MAX`: none), by which the
/// faults are put back in the sequential order.
fn task_of_rung(p: &Program, plan: &ScanPlan) -> String {
    let main = p.main().rungs.clone();
    let mut s = format!(
        "#define _PLC_MAIN_RUNGS {}u\nstatic const uint32_t _plc_task_of_rung[] = {{\n",
        main.end
    );
    let mut line = String::from("   ");
    for r in 0..main.end {
        let t = plan
            .task_of_rung
            .get(r as usize)
            .copied()
            .flatten()
            .filter(|_| main.contains(&r));
        match t {
            Some(t) => push(&mut line, format_args!(" {},", t.raw())),
            None => line.push_str(" UINT32_MAX,"),
        }
        if line.len() > 90 {
            s.push_str(&line);
            s.push('\n');
            line = String::from("   ");
        }
    }
    if main.end == 0 {
        line.push_str(" 0");
    }
    s.push_str(&line);
    s.push_str("\n};\n\n");
    s
}

/// The plan in words for the header comment of `plc_parallel.c`.
fn describe(p: &Program, sh: &Shared, s: &Split) -> String {
    let workers = s.plan.workers;
    let mut h = String::new();
    let levels = s.phases.last().map_or(0, |_| {
        s.plan
            .phases
            .iter()
            .map(|ph| ph.levels.end)
            .max()
            .unwrap_or(0)
    });
    let barriers =
        s.phases.iter().filter(|ph| ph.barrier).count() + usize::from(s.plan.end_barrier);
    push(
        &mut h,
        format_args!(
            " * Plan: {} phases over {levels} levels of the schedule, {barriers} barriers per scan.\n",
            s.phases.len()
        ),
    );
    for (k, ph) in s.phases.iter().enumerate() {
        let lv = &s.plan.phases[k].levels;
        let rungs: Vec<String> = ph
            .workers
            .iter()
            .map(|ts| {
                let n: usize = ts
                    .iter()
                    .map(|&t| s.plan.task_rungs[t as usize].len())
                    .sum();
                format!("{} tasks/{n} rungs", ts.len())
            })
            .collect();
        push(
            &mut h,
            format_args!(
                " *   phase {k} (levels {}..{}, {}): {}\n",
                lv.start,
                lv.end,
                if ph.parallel {
                    "parallel"
                } else {
                    "worker 0 alone"
                },
                if ph.parallel {
                    rungs.join(", ")
                } else {
                    rungs[0].clone()
                }
            ),
        );
        if h.len() > 4000 && k + 1 < s.phases.len() {
            push(
                &mut h,
                format_args!(" *   … {} more phases\n", s.phases.len() - k - 1),
            );
            break;
        }
    }
    let (cross, unplaced) = crossing_lines(p, sh, s);
    push(
        &mut h,
        format_args!(
            " * Cache lines that move between workers per scan (a model: a 64-byte line of the\n \
             * state read or written by a worker after another one wrote it): {cross} of the BOOL,\n \
             * INT, counter and timer members{}.\n * Workers: {workers} (worker 0 is the caller's thread).\n",
            if unplaced > 0 {
                format!(" ({unplaced} other variables, laid out by the C compiler, not counted)")
            } else {
                String::new()
            }
        ),
    );
    h
}

/// The lines that cross workers in the second of two scans (module doc of `describe`), and the
/// number of variables whose offsets the generator does not know.
fn crossing_lines(p: &Program, sh: &Shared, s: &Split) -> (usize, usize) {
    let acc = plc_analysis::accesses(p);
    let size = |v: usize| {
        super::CLASSES
            .iter()
            .find(|c| (c.is)(p.vars()[v].ty))
            .map_or(1, |c| c.size)
    };
    let lines = |v: plc_model::VarId| {
        let at = sh.at[v.index()]?;
        Some(at / 64..=(at + size(v.index()) - 1) / 64)
    };
    let nlines = sh.at.iter().flatten().max().map_or(0, |m| m / 64 + 2) as usize;
    let mut last_writer = vec![u32::MAX; nlines];
    let mut seen = vec![0u64; nlines];
    let mut cross = 0usize;
    let mut access = |w: usize, v: plc_model::VarId, write: bool, count: bool| {
        let Some(ls) = lines(v) else { return };
        let bit = 1u64 << (w % 64);
        for l in ls {
            let l = l as usize;
            let o = last_writer[l];
            if o != u32::MAX && o != w as u32 && seen[l] & bit == 0 {
                cross += usize::from(count);
                seen[l] |= bit;
            }
            if write {
                last_writer[l] = w as u32;
                seen[l] = bit;
            }
        }
    };
    let inputs: Vec<_> = (p.vars().iter_enumerated())
        .filter(|(_, v)| v.class == VarClass::Input)
        .map(|(i, _)| i)
        .collect();
    for scan in 0..2 {
        let count = scan == 1;
        for &v in &inputs {
            access(0, v, true, count);
        }
        for ph in &s.phases {
            for (w, tasks) in ph.workers.iter().enumerate() {
                for &t in tasks {
                    for &r in &s.plan.task_rungs[t as usize] {
                        for &v in acc.ins(r) {
                            access(w, v, false, count);
                        }
                        for &v in acc.outs(r) {
                            access(w, v, true, count);
                        }
                    }
                }
            }
        }
    }
    let unplaced = (0..p.vars().len())
        .filter(|&i| sh.at[i].is_none() && !sh.local_only[i])
        .count();
    (cross, unplaced)
}

/// Declarations of `plc_parallel.h` before the chunk functions'.
const WORKER_DECLS: &str =
    "/* A fault a worker raised, with the task it ran (faults are replayed in task order). */
typedef struct { uint32_t rung; int kind; uint32_t task; } _plc_par_fault;
/* A worker's context (its first member: the fault hook finds the rest from it), on lines of
   its own. */
typedef struct {
    _Alignas(64) _plc_ctx ctx;
    uint32_t task;
    size_t nfaults, cap;
    _plc_par_fault *faults;
} _plc_worker_data;
/* The task that the next call runs for (a fault in a callee names the callee's rung). */
static inline void _plc_par_task(_plc_ctx *ctx, uint32_t task) {
    ((_plc_worker_data *)(void *)ctx)->task = task;
}

";

/// `plc_api.h`: the API for runtimes (docs/c.md).
pub(crate) const API_H: &str = "/* plc_api.h: the program for a runtime (generated by plc-deps c --threads; docs/c.md).
   plc_init() once: the state to its initial value, the worker threads started (they live as long
   as the process). Then per cycle: write the inputs into plc_state, call one scan, read the
   outputs. The three scans compute the same state; plc_scan_adaptive measures the other two on
   its first scans, keeps the faster, and measures again when the scan time changes. */
#ifndef PLC_API_H
#define PLC_API_H
#include \"plc_program.h\"

extern _plc_state plc_state;
/* Faults of the scans (NULL: ignored): scan index, rung id (JSON text), kind (_PLC_DIV_BY_ZERO…). */
extern void (*plc_fault_hook)(uint64_t scan, const char *rung, int kind);
void plc_init(void);
void plc_scan(int64_t now_ms);
void plc_scan_parallel(int64_t now_ms);
void plc_scan_adaptive(int64_t now_ms);
/* What plc_scan_adaptive runs: \"measuring\", \"sequential\" or \"parallel\". */
const char *plc_choice(void);

/* For the harness (plc_main.h): the scans on any state, and starting the workers. */
int _plc_par_start(void);
void _plc_scan_parallel_desc(void *self, _plc_ctx *ctx);
void _plc_scan_adaptive_desc(void *self, _plc_ctx *ctx);
const char *_plc_adaptive_choice(void);
#endif
";

/// `plc_parallel.c`.
fn parallel_source(
    sh: &Shared,
    split: Option<&Split>,
    header: &str,
    worker_code: &[String],
    task_table: &str,
    threads: usize,
) -> String {
    let mut s = format!(
        "/* plc_parallel.c: the parallel scan and the runtime API, generated by plc-deps c --threads {threads}.\n\
         {header} */\n#define _POSIX_C_SOURCE 200809L\n#include \"plc_parallel.h\"\n#include \"plc_api.h\"\n\
         #include <pthread.h>\n#include <sched.h>\n#include <stdatomic.h>\n#include <stdint.h>\n#include <time.h>\n\n"
    );
    s.push_str(RUNTIME_C);
    match split {
        None => {
            s.push_str(
                "static int _plc_par_ok;\n\
                 int _plc_par_start(void) { return 0; }\n\
                 static void _plc_scan_par(_plc_state *self, _plc_ctx *ctx) { _plc_scan(self, ctx); }\n",
            );
        }
        Some(_) => {
            s.push_str(task_table);
            s.push_str(WORKERS_C);
            let ctr = if sh.counters.iter().any(Option::is_some) {
                "    memset(self->_ctr, 0, sizeof self->_ctr);\n"
            } else {
                ""
            };
            push(
                &mut s,
                format_args!(
                    "static void _plc_worker_0(_plc_state *self, _plc_ctx *outer) {{\n    _plc_par_self = self;\n    \
                     _plc_par_now = outer->now;\n    _plc_par_scan_no = outer->scan;\n    _plc_par_cap = outer->loop_cap;\n{ctr}    \
                     _plc_ctx *ctx = _plc_begin(0);\n    (void)ctx;\n{}}}\n\n",
                    worker_code[0]
                ),
            );
            for (w, code) in worker_code.iter().enumerate().skip(1) {
                push(
                    &mut s,
                    format_args!("static void _plc_worker_{w}(void) {{\n{code}}}\n\n"),
                );
            }
            s.push_str("static void *_plc_thread(void *arg) {\n    unsigned w = (unsigned)(uintptr_t)arg;\n    for (;;) {\n        switch (w) {\n");
            for w in 1..worker_code.len() {
                push(
                    &mut s,
                    format_args!("        case {w}: _plc_worker_{w}(); break;\n"),
                );
            }
            s.push_str("        default: return NULL;\n        }\n    }\n}\n\n");
            s.push_str(START_C);
        }
    }
    s.push_str(ADAPTIVE_C);
    s
}

/// The barrier and its wait (spin, then yield, then sleep on a condition variable).
const RUNTIME_C: &str =
    "/* Waiting: spin with a pause up to _PLC_SPINS times (about 1-4 ms: a level's work is
   microseconds, and with 2,000 spins the sleep below was reached often enough to halve the
   speed of gen 20k), yield up to _PLC_YIELDS times, then sleep on a condition variable until
   woken: never an unbounded busy wait. */
#ifndef _PLC_SPINS
#define _PLC_SPINS 100000
#endif
#ifndef _PLC_YIELDS
#define _PLC_YIELDS 100
#endif
static inline void _plc_pause(void) {
#if defined(__x86_64__) || defined(__i386__)
    __builtin_ia32_pause();
#elif defined(__aarch64__)
    __asm__ __volatile__(\"yield\");
#endif
}

";

/// The workers' shared data, the barrier, the fault merge and the parallel scan.
const WORKERS_C: &str = "static _plc_worker_data _plc_w[PLC_THREADS];
/* The barrier: arrivals and the generation, each on its own line. */
static struct {
    _Alignas(64) atomic_uint count;
    _Alignas(64) atomic_uint gen;
    atomic_uint sleepers;
} _plc_bar;
static pthread_mutex_t _plc_bar_m = PTHREAD_MUTEX_INITIALIZER;
static pthread_cond_t _plc_bar_c = PTHREAD_COND_INITIALIZER;
/* The scan in progress: written by worker 0 before the scan's first barrier, read after it. */
static _plc_state *_plc_par_self;
static int64_t _plc_par_now;
static uint64_t _plc_par_scan_no, _plc_par_cap;
static int _plc_par_ok;

static void _plc_barrier(void) {
    unsigned g = atomic_load_explicit(&_plc_bar.gen, memory_order_acquire);
    if (atomic_fetch_add_explicit(&_plc_bar.count, 1, memory_order_acq_rel) + 1 == PLC_THREADS) {
        atomic_store_explicit(&_plc_bar.count, 0, memory_order_relaxed);
        atomic_store(&_plc_bar.gen, g + 1);
        if (atomic_load(&_plc_bar.sleepers)) {
            pthread_mutex_lock(&_plc_bar_m);
            pthread_cond_broadcast(&_plc_bar_c);
            pthread_mutex_unlock(&_plc_bar_m);
        }
        return;
    }
    for (int i = 0; i < _PLC_SPINS; i++) {
        if (atomic_load_explicit(&_plc_bar.gen, memory_order_acquire) != g) return;
        _plc_pause();
    }
    for (int i = 0; i < _PLC_YIELDS; i++) {
        if (atomic_load_explicit(&_plc_bar.gen, memory_order_acquire) != g) return;
        sched_yield();
    }
    pthread_mutex_lock(&_plc_bar_m);
    atomic_fetch_add(&_plc_bar.sleepers, 1);
    while (atomic_load(&_plc_bar.gen) == g) pthread_cond_wait(&_plc_bar_c, &_plc_bar_m);
    atomic_fetch_sub(&_plc_bar.sleepers, 1);
    pthread_mutex_unlock(&_plc_bar_m);
}

static void _plc_on_fault(_plc_ctx *ctx, uint32_t rung, int kind) {
    _plc_worker_data *d = (_plc_worker_data *)(void *)ctx;
    if (d->nfaults == d->cap) {
        size_t cap = d->cap ? d->cap * 2 : 16;
        _plc_par_fault *f = realloc(d->faults, cap * sizeof *f);
        if (!f) return;
        d->faults = f;
        d->cap = cap;
    }
    uint32_t task = rung < _PLC_MAIN_RUNGS && _plc_task_of_rung[rung] != UINT32_MAX
                        ? _plc_task_of_rung[rung] : d->task;
    d->faults[d->nfaults++] = (_plc_par_fault){rung, kind, task};
}

/* Worker w's context for the scan in progress. */
static _plc_ctx *_plc_begin(unsigned w) {
    _plc_worker_data *d = &_plc_w[w];
    d->ctx.now = _plc_par_now;
    d->ctx.scan = _plc_par_scan_no;
    d->ctx.loop_cap = _plc_par_cap;
    d->ctx.fault = _plc_on_fault;
    d->ctx.user = NULL;
    d->ctx.budget_task = 0;
    d->ctx.budget_rungs = 0;
    d->task = 0;
    d->nfaults = 0;
    return &d->ctx;
}

/* The faults of every worker, replayed into `outer` in task order (the sequential order: a
   task runs on one worker, which keeps its faults in order). */
typedef struct { uint32_t task; uint32_t worker; size_t at; } _plc_fault_key;
static int _plc_fault_cmp(const void *a, const void *b) {
    const _plc_fault_key *x = a, *y = b;
    if (x->task != y->task) return x->task < y->task ? -1 : 1;
    if (x->worker != y->worker) return x->worker < y->worker ? -1 : 1;
    return x->at < y->at ? -1 : x->at > y->at;
}
static void _plc_merge_faults(_plc_ctx *outer, size_t n) {
    _plc_fault_key *keys = malloc(n * sizeof *keys);
    if (!keys) return;
    size_t k = 0;
    for (uint32_t w = 0; w < PLC_THREADS; w++)
        for (size_t i = 0; i < _plc_w[w].nfaults; i++)
            keys[k++] = (_plc_fault_key){_plc_w[w].faults[i].task, w, i};
    qsort(keys, n, sizeof *keys, _plc_fault_cmp);
    for (size_t i = 0; i < n; i++) {
        const _plc_par_fault *f = &_plc_w[keys[i].worker].faults[keys[i].at];
        _plc_fault(outer, f->rung, f->kind);
    }
    free(keys);
}

";

/// Starting the workers and the parallel scan's entry.
const START_C: &str = "int _plc_par_start(void) {
    static int tried;
    if (tried) return _plc_par_ok;
    tried = 1;
    for (uintptr_t w = 1; w < PLC_THREADS; w++) {
        pthread_t t;
        if (pthread_create(&t, NULL, _plc_thread, (void *)w)) return 0;
        pthread_detach(t);
    }
    _plc_par_ok = 1;
    return 1;
}

static void _plc_scan_par(_plc_state *self, _plc_ctx *ctx) {
    if (!_plc_par_ok) { _plc_scan(self, ctx); return; }
    _plc_worker_0(self, ctx);
    size_t n = 0;
    for (int w = 0; w < PLC_THREADS; w++) n += _plc_w[w].nfaults;
    if (n) _plc_merge_faults(ctx, n);
}

";

/// The adaptive choice and the API.
const ADAPTIVE_C: &str = "/* The adaptive scan: _PLC_PROBES scans of each entry point, alternating (the first pair not
   counted), then the one of the smaller median; every 8th scan of the chosen one is timed, and
   a moving average that leaves [ref / 1.5, ref * 1.5] (ref: its median when chosen) after at
   least 1,024 scans, or 65,536 scans, starts the measuring again. */
#ifndef _PLC_PROBES
#define _PLC_PROBES 7
#endif
static struct {
    int choice; /* 0 measuring, 1 sequential, 2 parallel */
    unsigned k;
    double t[2][_PLC_PROBES];
    double ref, avg;
    uint64_t since;
} _plc_ad;

static double _plc_ns(void) {
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec * 1e9 + (double)ts.tv_nsec;
}

static double _plc_median(double *v) {
    for (int i = 1; i < _PLC_PROBES; i++)
        for (int j = i; j > 0 && v[j - 1] > v[j]; j--) { double x = v[j]; v[j] = v[j - 1]; v[j - 1] = x; }
    return v[_PLC_PROBES / 2];
}

static void _plc_scan_adaptive(_plc_state *self, _plc_ctx *ctx) {
    if (!_plc_par_ok) { _plc_scan(self, ctx); _plc_ad.choice = 1; return; }
    if (_plc_ad.choice == 0) {
        unsigned k = _plc_ad.k++;
        int par = k & 1;
        double t0 = _plc_ns();
        if (par) _plc_scan_par(self, ctx); else _plc_scan(self, ctx);
        double t = _plc_ns() - t0;
        if (k >= 2) _plc_ad.t[par][(k - 2) / 2] = t;
        if (k + 1 == 2 + 2 * _PLC_PROBES) {
            double s = _plc_median(_plc_ad.t[0]), p = _plc_median(_plc_ad.t[1]);
            _plc_ad.choice = p < s ? 2 : 1;
            _plc_ad.ref = _plc_ad.avg = p < s ? p : s;
            _plc_ad.since = 0;
        }
        return;
    }
    int timed = (_plc_ad.since++ & 7) == 0;
    double t0 = timed ? _plc_ns() : 0;
    if (_plc_ad.choice == 2) _plc_scan_par(self, ctx); else _plc_scan(self, ctx);
    if (!timed) return;
    _plc_ad.avg = _plc_ad.avg * 0.875 + (_plc_ns() - t0) * 0.125;
    if (_plc_ad.since >= 65536 || (_plc_ad.since >= 1024 && (_plc_ad.avg > _plc_ad.ref * 1.5 ||
                                                             _plc_ad.avg * 1.5 < _plc_ad.ref))) {
        _plc_ad.choice = 0;
        _plc_ad.k = 0;
    }
}

const char *_plc_adaptive_choice(void) {
    static const char *const names[] = {\"measuring\", \"sequential\", \"parallel\"};
    return names[_plc_ad.choice];
}

void _plc_scan_parallel_desc(void *self, _plc_ctx *ctx) { _plc_scan_par(self, ctx); }
void _plc_scan_adaptive_desc(void *self, _plc_ctx *ctx) { _plc_scan_adaptive(self, ctx); }

/* The API (plc_api.h). */
_plc_state plc_state;
void (*plc_fault_hook)(uint64_t scan, const char *rung, int kind);
static _plc_ctx _plc_api_ctx;

static void _plc_api_fault(_plc_ctx *ctx, uint32_t rung, int kind) {
    if (plc_fault_hook) plc_fault_hook(ctx->scan, _plc_rung_ids[rung], kind);
}

void plc_init(void) {
    plc_state = _plc_initial;
    _plc_api_ctx = (_plc_ctx){0, 0, _plc_program_desc.loop_cap, _plc_api_fault, NULL, 0, 0};
    _plc_ad.choice = 0;
    _plc_ad.k = 0;
    _plc_par_start();
}

static _plc_ctx *_plc_api_next(int64_t now_ms) {
    _plc_api_ctx.now = now_ms;
    return &_plc_api_ctx;
}

void plc_scan(int64_t now_ms) { _plc_scan(&plc_state, _plc_api_next(now_ms)); _plc_api_ctx.scan++; }
void plc_scan_parallel(int64_t now_ms) { _plc_scan_par(&plc_state, _plc_api_next(now_ms)); _plc_api_ctx.scan++; }
void plc_scan_adaptive(int64_t now_ms) { _plc_scan_adaptive(&plc_state, _plc_api_next(now_ms)); _plc_api_ctx.scan++; }
const char *plc_choice(void) { return _plc_adaptive_choice(); }
";
