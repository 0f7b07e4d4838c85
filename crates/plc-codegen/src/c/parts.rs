//! A ladder POU's C files: its function and, for a large POU, chunk functions of about
//! [`CConfig::chunk_rungs`] units each (a rung written as statements is one unit, a run of rows
//! of one kernel one), cut at boundaries no jump and no FOR loop crosses, in part files whose
//! number is bounded, so the C compiler's time grows linearly with the program; and the data
//! file of each source file's rows (`rows`).
//!
//! The rungs are emitted in the order of the POU's plan (`order`): program order, or with rows
//! grouped by level and kernel inside straight-line regions. A region holds no jump, label or
//! FOR, so whether a boundary is crossed by a jump or a loop is the same for every boundary
//! inside it, and the cut points computed from the program's jump and loop spans stay valid
//! in the plan's order.
//!
//! Not here: the rungs' C (`ladder`), the rows and their kernels (`rows`), the order (`order`).

use super::ladder::{Body, Shared};
use super::order::Plan;
use super::table::Tables;
use super::text;
use super::{names, CConfig};
use plc_model::{walk_elements, Element, Program};

/// Cut points of a ladder POU's plan: ranges of positions of about `chunk` units of weight
/// that no jump or FOR crosses.
pub(crate) fn chunks(
    p: &Program,
    pou: usize,
    plan: &Plan,
    chunk: usize,
) -> Vec<std::ops::Range<usize>> {
    let range = p.pous()[pou].rungs.clone();
    let n = (range.end - range.start) as usize;
    // blocked[i]: the boundary before position i is crossed by a jump or a loop.
    let mut diff = vec![0i32; n + 1];
    let mut span = |a: u32, b: u32| {
        let (lo, hi) = (a.min(b) - range.start, a.max(b) - range.start);
        if lo < hi {
            diff[lo as usize + 1] += 1;
            diff[hi as usize + 1] -= 1;
        }
    };
    for r in range.clone() {
        walk_elements(&p.rungs()[r as usize].series, &mut |e| match e {
            Element::Jmp { target, .. } => span(r, target.raw()),
            Element::For { next, .. } => span(r, next.raw()),
            _ => {}
        });
    }
    let mut out = Vec::new();
    let (mut start, mut depth, mut units) =
        (0usize, 0i32, plan.weight.first().copied().unwrap_or(0));
    for (i, d) in diff.iter().enumerate().take(n).skip(1) {
        depth += d;
        if depth == 0 && units >= chunk {
            out.push(start..i);
            start = i;
            units = 0;
        }
        units += plan.weight[i];
    }
    out.push(start..n);
    out
}

/// Chunk functions per part file (`pou_X_partN.c`) of the large ladder POUs: at least
/// [`MIN_CHUNKS_PER_FILE`], more when the program has more than [`MAX_PART_FILES`] files' worth,
/// so that the parts stay few. Every translation unit parses the whole state struct (about
/// 0.3 s of `cc` at 100,000 rungs, and the struct's members cost again in the optimiser), so
/// parts of a fixed size would make the build quadratic in the program; a bounded number of
/// parts keeps it linear, and still enough of them for `make -j` to use every core. With most
/// rungs as rows a part file is mostly kernel calls and the struct's parsing is half of its
/// `cc` time, so 8 files rather than 16 (100,000 rungs with timers, loops, jumps and calls:
/// 12.8 s of `make -j2` wall time against 15.7 s; 4 files: 11.9 s). With every rung as
/// statements 8 files cost about the same: `gen --rungs 100000 --width 5000 --statements`,
/// 45.4 s of wall time, 85 s of CPU and 344 MB for the largest `cc` against 46.6 s, 87 s and
/// 328 MB with 16.
pub(crate) fn chunks_per_file(p: &Program, plans: &[Option<Plan>], chunk: usize) -> usize {
    let total: usize = plans
        .iter()
        .enumerate()
        .filter_map(|(i, plan)| Some(chunks(p, i, plan.as_ref()?, chunk.max(1)).len()))
        .filter(|&n| n > 1)
        .sum();
    MIN_CHUNKS_PER_FILE.max(total.div_ceil(MAX_PART_FILES))
}

/// The fewest chunk functions in a part file (1,024 rungs of 64).
const MIN_CHUNKS_PER_FILE: usize = 16;
/// The most part files of a program before they grow instead of multiplying.
const MAX_PART_FILES: usize = 8;

/// The data files of the rows (`(stem, text)`) and the C type of their entries.
pub(crate) struct DataFiles {
    pub entry: &'static str,
    pub files: Vec<(String, String)>,
}

/// The C of a ladder POU: its function and, for a large POU, the part files of its chunks
/// (`(file suffix, text)`; the first has no suffix), and the declarations for its header. The
/// data files of the rows are appended to `data`.
pub(crate) fn ladder_files(
    p: &Program,
    sh: &Shared,
    pou: usize,
    cfg: &CConfig,
    per_file: usize,
    plan: &Plan,
    data: &mut DataFiles,
) -> (Vec<(String, String)>, String) {
    let f = &sh.pou_fns[pou];
    let groups = chunks(p, pou, plan, cfg.chunk_rungs.max(1));
    let name = names::comment(&p.pous()[pou].name);
    let head = "#include \"plc_program.h\"\n\n";
    // A new source file's rows, in the data file numbered after those written so far.
    let tables = |data: &DataFiles| cfg.rows.then(|| Tables::new(data.files.len(), data.entry));
    // The rows' declarations, and their data file into `data`.
    let close = |t: Option<Tables>, data: &mut DataFiles| {
        let t = t?;
        data.files.extend(t.data_file());
        Some(t.declarations())
    };
    // Generated names made from the function's (`_pou_` + the POU's encoded name, which starts
    // with a letter or `_u`): `_pou__c3_X` (chunk 3), `_pou__k3` (kernel 3), `_pou__t2_3`
    // (table 3 of data file 2) meet no POU's function.
    let enc = f.trim_start_matches("_pou_");
    if groups.len() == 1 {
        let mut b = Body::new(sh, "return;", 1);
        b.rows = tables(data);
        b.line("(void)self; (void)ctx;");
        for &r in &plan.order {
            b.rung(r);
        }
        b.flush_rows();
        let decls = close(b.rows.take(), data).unwrap_or_default();
        let text = format!(
            "{head}{decls}/* ladder POU {name} */\nvoid {f}(_plc_state *self, _plc_ctx *ctx) {{\n{}}}\n",
            b.finish()
        );
        return (vec![(String::new(), text)], String::new());
    }
    // A chunk function takes the state as `void *`: with `_plc_state *`, GCC's interprocedural
    // passes spent time per function that grew with the whole struct (a 64-rung function of
    // the 100,000-rung program took 0.12 s of `cc -O2` with rows, 0.02 s with `void *`).
    let mut files = Vec::new();
    let mut decls = String::new();
    for (n, part) in groups.chunks(per_file).enumerate() {
        let mut s = String::new();
        let mut t = tables(data);
        for (j, g) in part.iter().enumerate() {
            let k = n * per_file + j;
            let mut b = Body::new(sh, "return 1;", 1);
            b.rows = t.take();
            b.line("(void)self; (void)ctx;");
            for &r in &plan.order[g.clone()] {
                b.rung(r);
            }
            b.line("return 0;");
            t = b.rows.take();
            text::push(
                &mut s,
                format_args!(
                    "bool _pou__c{k}_{enc}(void *_self, _plc_ctx *ctx) {{\n    _plc_state *self = _self;\n{}}}\n\n",
                    b.finish()
                ),
            );
            text::push(
                &mut decls,
                format_args!("bool _pou__c{k}_{enc}(void *_self, _plc_ctx *ctx);\n"),
            );
        }
        let rows = close(t, data).unwrap_or_default();
        files.push((
            format!("_part{n}"),
            format!("{head}{rows}/* ladder POU {name}, part {n} */\n{s}"),
        ));
    }
    let mut s = format!(
        "{head}/* ladder POU {name}, in {} functions */\n",
        groups.len()
    );
    text::push(
        &mut s,
        format_args!("void {f}(_plc_state *self, _plc_ctx *ctx) {{\n"),
    );
    for k in 0..groups.len() {
        text::push(
            &mut s,
            format_args!("    if (_pou__c{k}_{enc}(self, ctx)) return;\n"),
        );
    }
    s.push_str("}\n");
    files.insert(0, (String::new(), s));
    (files, decls)
}
