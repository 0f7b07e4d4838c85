//! The harness: `plc_program.c` (initial state, the scan, input and output tables, and the
//! program's descriptor `_plc_program_desc` that points at them), `plc_main.h` (the driver
//! `_plc_main`, the same for every program: it runs a program through its descriptor), `main.c`
//! (calls the driver; it reads the CSV of `plc-deps run --inputs` on standard input, runs one scan per row on
//! virtual time, prints after each scan one JSON line with the keys and value forms of the
//! `state` object of `plc-deps run --format json`, and each fault as a JSON line
//! `{"scan","rung","kind"}` on standard error) and the `Makefile`.
//!
//! Not here: the POUs' code (`ladder`, `fbd`).

use super::ladder::Shared;
use super::names::{c_string, json_string};
use super::spelling::c_init;
use super::text::push;
use super::CConfig;
use plc_model::{FbKind, Program, Type, Value, VarClass};

/// Declarations of the tables `plc_program.c` defines, for `plc_program.h`.
pub(crate) const HEADER_DECLS: &str = "extern const char *const _plc_input_names[];\n\
    int _plc_set_input(_plc_state *self, unsigned input, const char *text);\n\
    void _plc_print_state(const _plc_state *self, FILE *out);\n\
    extern const char *const _plc_rung_ids[];\n\
    extern const _plc_program _plc_program_desc;\n";

/// `extra`: initializers of the instances' bases (`    .G1._rung0 = 12,\n`).
pub(crate) fn program_source(p: &Program, sh: &Shared, extra: &[String], cfg: &CConfig) -> String {
    let mut s = String::from(
        "/* plc_program.c: state, scan and harness tables. */\n#include \"plc_program.h\"\n\n",
    );
    // The initial state: declared init values (zero is the default of a static object).
    let inits: Vec<String> = p
        .vars()
        .iter()
        .enumerate()
        .filter(|(i, v)| !matches!(v.ty, Type::Fb(_)) && !is_zero(v.init) && !sh.local_only[*i])
        .map(|(i, v)| format!("    .{} = {},\n", field(sh, i), c_init(v.init)))
        .chain(extra.iter().cloned())
        .collect();
    if inits.is_empty() {
        s.push_str("const _plc_state _plc_initial;\n\n");
    } else {
        s.push_str("const _plc_state _plc_initial = {\n");
        s.extend(inits);
        s.push_str("};\n\n");
    }
    // The BOOLs, the INTs, the counters and the timers are the struct's first members (the
    // rows' tables hold their offsets): the last of each class where the generator put it.
    for c in super::CLASSES {
        let last = (0..p.vars().len())
            .filter(|&i| (c.is)(p.vars()[i].ty))
            .filter_map(|i| Some((i, sh.at[i]?)))
            .next_back();
        if let Some((i, at)) = last {
            push(
                &mut s,
                format_args!(
                    "_Static_assert(offsetof(_plc_state, {}) == {at}, \"the rows' offsets\");\n",
                    field(sh, i)
                ),
            );
        }
    }
    s.push_str("void _plc_scan(_plc_state *self, _plc_ctx *ctx) {\n");
    s.push_str("    ctx->budget_task = 0;\n    ctx->budget_rungs = 0;\n");
    if sh.counters.iter().any(Option::is_some) {
        s.push_str("    memset(self->_ctr, 0, sizeof self->_ctr);\n");
    }
    push(
        &mut s,
        format_args!("    {}(self, ctx);\n}}\n\n", sh.pou_fns[0]),
    );
    inputs(p, sh, &mut s);
    restore_inputs(p, sh, &mut s);
    print_state(p, sh, &mut s);
    s.push_str("const char *const _plc_rung_ids[] = {\n");
    for r in p.rungs().iter() {
        push(
            &mut s,
            format_args!("    {},\n", c_string(&json_string(&r.id))),
        );
    }
    s.push_str("    NULL\n};\n");
    s.push_str(
        &DESCRIPTOR
            .replace("@CYCLE@", &cfg.cycle_ms.to_string())
            .replace("@LOOP_CAP@", &cfg.loop_cap.to_string()),
    );
    s
}

/// The program's descriptor: what the driver (`plc_main.h`) runs it through.
const DESCRIPTOR: &str = "
static void _plc_desc_scan(void *self, _plc_ctx *ctx) { _plc_scan(self, ctx); }
static int _plc_desc_set_input(void *self, unsigned input, const char *text) {
    return _plc_set_input(self, input, text);
}
static void _plc_desc_print(const void *self, FILE *out) { _plc_print_state(self, out); }
static void _plc_desc_restore(void *self, const void *image) { _plc_restore_inputs(self, image); }

const _plc_program _plc_program_desc = {
    sizeof(_plc_state), &_plc_initial, _plc_desc_scan, _plc_desc_set_input, _plc_desc_print,
    _plc_input_names, _plc_input_types, _plc_output_names, _plc_memory_names, _plc_rung_ids,
    @CYCLE@, @LOOP_CAP@, _plc_desc_restore
};
";

fn is_zero(v: Value) -> bool {
    v.to_bits() == 0
}

fn field(sh: &Shared, i: usize) -> String {
    sh.vars[i].trim_start_matches("self->").to_string()
}

/// The harness's slot kind of a type (`_PLC_K_…` of `plc_runtime.h`).
fn slot_kind(ty: Type) -> &'static str {
    match ty {
        Type::Bool => "_PLC_K_BOOL",
        Type::Int => "_PLC_K_INT",
        Type::Dint => "_PLC_K_DINT",
        Type::Time => "_PLC_K_TIME",
        Type::Real => "_PLC_K_REAL",
        Type::Sint => "_PLC_K_SINT",
        Type::Lint => "_PLC_K_LINT",
        Type::Usint | Type::Byte => "_PLC_K_USINT",
        Type::Uint | Type::Word => "_PLC_K_UINT",
        Type::Udint | Type::Dword => "_PLC_K_UDINT",
        Type::Ulint | Type::Lword => "_PLC_K_ULINT",
        Type::Lreal => "_PLC_K_LREAL",
        Type::String => "_PLC_K_STRING",
        Type::Fb(FbKind::Ton | FbKind::Tof | FbKind::Tp) => "_PLC_K_TIMER",
        Type::Fb(FbKind::Ctu | FbKind::Ctd) => "_PLC_K_COUNTER",
        Type::Fb(FbKind::Sr | FbKind::Rs) => "_PLC_K_BISTABLE",
        Type::Fb(FbKind::RTrig | FbKind::FTrig) => "_PLC_K_TRIGGER",
        Type::Fb(FbKind::Ctud) => "_PLC_K_UPDOWN",
    }
}

/// A static table `name` of `_plc_slot`s, one per variable of `vars` with its JSON key
/// (`"x":`); returns the number of entries (C has no empty arrays: an empty table gets one
/// unused entry).
fn slot_table(p: &Program, sh: &Shared, s: &mut String, name: &str, vars: &[usize]) -> usize {
    push(s, format_args!("static const _plc_slot {name}[] = {{\n"));
    for &i in vars {
        let key = format!("{}:", json_string(&p.vars()[i].name));
        // The offsets the generator computed (asserted below) as numbers: `cc` spent about a
        // quarter of this file's time on the `offsetof`s (1.2 of 4.6 s at 100,000 rungs).
        let at = match sh.at[i] {
            Some(at) => at.to_string(),
            None => format!("offsetof(_plc_state, {})", field(sh, i)),
        };
        push(
            s,
            format_args!(
                "    {{{}, {at}, {}}},\n",
                c_string(&key),
                slot_kind(p.vars()[i].ty)
            ),
        );
    }
    if vars.is_empty() {
        s.push_str("    {\"\", 0, _PLC_K_BOOL}\n");
    }
    s.push_str("};\n\n");
    vars.len()
}

/// The input names and `_plc_set_input`, through a table of the inputs.
fn inputs(p: &Program, sh: &Shared, s: &mut String) {
    let ins: Vec<usize> = (0..p.vars().len())
        .filter(|&i| p.vars()[i].class == VarClass::Input && !p.vars()[i].hidden)
        .collect();
    s.push_str("const char *const _plc_input_names[] = {\n");
    for &i in &ins {
        push(s, format_args!("    {},\n", c_string(&p.vars()[i].name)));
    }
    s.push_str("    NULL\n};\n\n");
    // What the driver needs to read the inputs CSV as `plc-deps run` does: each input's type
    // as its messages name it, and the other variables' names (a column naming one is refused
    // as "not an input variable").
    s.push_str("static const char *const _plc_input_types[] = {\n");
    for &i in &ins {
        push(
            s,
            format_args!("    {},\n", c_string(&cell_type(p.vars()[i].ty))),
        );
    }
    s.push_str("    NULL\n};\n\n");
    for (table, class) in [
        ("_plc_output_names", Some(VarClass::Output)),
        ("_plc_memory_names", None),
    ] {
        push(s, format_args!("static const char *const {table}[] = {{\n"));
        for v in p.vars().iter() {
            let other = v.class != VarClass::Input && v.class != VarClass::Output;
            if !v.hidden && (Some(v.class) == class || (class.is_none() && other)) {
                push(s, format_args!("    {},\n", c_string(&v.name)));
            }
        }
        s.push_str("    NULL\n};\n\n");
    }
    let n = slot_table(p, sh, s, "_plc_input_slots", &ins);
    s.push_str("int _plc_set_input(_plc_state *self, unsigned input, const char *text) {\n");
    if n == 0 {
        // `input < 0u` would be a warning: no input is ever set.
        s.push_str("    (void)self; (void)input; (void)text; (void)_plc_input_slots;\n    return 0;\n}\n\n");
    } else {
        push(
            s,
            format_args!(
                "    return input < {n}u ? _plc_set_slot(self, &_plc_input_slots[input], text) : 0;\n}}\n\n"
            ),
        );
    }
}

/// `_plc_restore_inputs`: copies the input image (`image`, a state the driver sets every cell of
/// the inputs into) into each input the program writes (`Program::written_inputs`, warning
/// W0208) before every scan, as `plc-deps run` does (`InputTable::with_image`) and as the
/// Beremiz/OpenPLC runtime copies its input image into the located `%I` variables.
fn restore_inputs(p: &Program, sh: &Shared, s: &mut String) {
    let written = p.written_inputs();
    s.push_str("static void _plc_restore_inputs(_plc_state *self, const _plc_state *image) {\n");
    if written.is_empty() {
        s.push_str("    (void)self; (void)image;\n");
    }
    for &v in written {
        let lhs = &sh.vars[v.index()];
        let rhs = lhs.replacen("self->", "image->", 1);
        push(
            s,
            format_args!("    memcpy(&{lhs}, &{rhs}, sizeof {lhs});\n"),
        );
    }
    s.push_str("}\n\n");
}

/// An input's entry of `_plc_input_types`: `BOOL`, `REAL`, `LREAL`, `TIME`, or for an integer
/// or bit string what its cells must be (`an INT (-32768..32767)`), as `plc-deps run` says it.
fn cell_type(ty: Type) -> String {
    match ty {
        Type::Bool | Type::Real | Type::Lreal | Type::Time | Type::String => ty.to_string(),
        ty => plc_model::integer_cell(ty),
    }
}

/// `_plc_print_state`, through a table of the visible variables.
fn print_state(p: &Program, sh: &Shared, s: &mut String) {
    let vis: Vec<usize> = (0..p.vars().len())
        .filter(|&i| !p.vars()[i].hidden)
        .collect();
    let n = slot_table(p, sh, s, "_plc_state_slots", &vis);
    push(
        s,
        format_args!(
            "void _plc_print_state(const _plc_state *self, FILE *o) {{\n    \
             _plc_put_slots(o, self, _plc_state_slots, {n});\n}}\n\n"
        ),
    );
}

/// `main.c`: runs the program through the driver.
pub(crate) const MAIN_C: &str =
    "/* main.c: runs the generated program scan by scan on virtual time (docs/c.md). */
#include \"plc_program.h\"
#include \"plc_main.h\"

int main(int argc, char **argv) { return _plc_main(&_plc_program_desc, argc, argv); }
";

/// `main.c` of a `--threads` build: starts the workers, then the driver (`par_main_h`).
pub(crate) const PAR_MAIN_C: &str =
    "/* main.c: runs the generated program scan by scan on virtual time, on the parallel scan's
   worker threads (docs/c.md). */
#include \"plc_program.h\"
#include \"plc_api.h\"
#include \"plc_main.h\"

int main(int argc, char **argv) {
    _plc_par_start();
    return _plc_main(&_plc_program_desc, argc, argv);
}
";

/// The `Makefile` of a `--threads` build: `-pthread` with the C standard (kept when a user
/// sets `CFLAGS`).
pub(crate) fn par_makefile(seq: &str) -> String {
    let old = "CSTD = -std=c11\n";
    assert!(seq.contains(old), "the Makefile sets CSTD");
    seq.replacen(old, "CSTD = -std=c11 -pthread\n", 1).replacen(
        "plc_main.h\n",
        "plc_main.h plc_api.h plc_parallel.h\n",
        1,
    )
}

/// The scan loop of the driver, which a `--threads` build replaces (`par_main_h`).
const SCAN_LOOP: &str = r#"    double spent = 0;
    _plc_ctx ctx = {0, 0, prog->loop_cap, on_fault, (void *)prog, 0, 0};
    for (unsigned long long k = 0; k < scans; k++) {
        if (k < nrows)
            for (size_t v = rows[k].first; v < rows[k].first + rows[k].count; v++) {
                _plc_set_cell(prog, &f, state, value_input[v], &values[v], (size_t)k);
                _plc_set_cell(prog, &f, image, value_input[v], &values[v], (size_t)k);
            }
        prog->restore_inputs(state, image);
        ctx.scan = k;
        ctx.now = (int64_t)k * prog->cycle_ms;
        double t0 = timing ? seconds() : 0;
        prog->scan(state, &ctx);
        if (timing) spent += seconds() - t0;
        else prog->print(state, stdout);
    }
    if (timing) {
        prog->print(state, stdout);
        fprintf(stderr, "{\"ns_per_scan\": %.1f}\n", scans ? spent * 1e9 / (double)scans : 0.0);
    }
"#;

/// The driver's scan loop in a `--threads` build: argv[2] `--sequential`, `--parallel` (the
/// default) or `--adaptive` picks the scan; `--time` runs the three, each from the initial
/// state, and reports them side by side with the adaptive scan's choice.
const PAR_SCAN_LOOP: &str = r#"    /* --threads build: argv[2] --sequential, --parallel (the default) or --adaptive picks the
       scan; --time runs the three from the initial state, one after another, and prints
       {"ns_per_scan": adaptive, "sequential_ns_per_scan", "parallel_ns_per_scan",
       "parallel_speedup": sequential / parallel, "threads", "adaptive_choice"} on stderr. */
    void (*const scan_of[3])(void *, _plc_ctx *) = {prog->scan, _plc_scan_parallel_desc,
                                                    _plc_scan_adaptive_desc};
    int mode = argc > 2 && !strcmp(argv[2], "--sequential") ? 0
               : argc > 2 && !strcmp(argv[2], "--adaptive") ? 2 : 1;
    double spent_in[3] = {0, 0, 0};
    for (int m = timing ? 0 : mode; m < (timing ? 3 : mode + 1); m++) {
        double spent = 0;
        memcpy(state, prog->initial, prog->size);
        memcpy(image, prog->initial, prog->size);
        _plc_ctx ctx = {0, 0, prog->loop_cap, on_fault, (void *)prog, 0, 0};
        for (unsigned long long k = 0; k < scans; k++) {
            if (k < nrows)
                for (size_t v = rows[k].first; v < rows[k].first + rows[k].count; v++) {
                    _plc_set_cell(prog, &f, state, value_input[v], &values[v], (size_t)k);
                    _plc_set_cell(prog, &f, image, value_input[v], &values[v], (size_t)k);
                }
            prog->restore_inputs(state, image);
            ctx.scan = k;
            ctx.now = (int64_t)k * prog->cycle_ms;
            double t0 = timing ? seconds() : 0;
            scan_of[m](state, &ctx);
            if (timing) spent += seconds() - t0;
            else prog->print(state, stdout);
        }
        spent_in[m] = spent;
    }
    if (timing) {
        prog->print(state, stdout);
        double n = scans ? (double)scans : 1.0;
        fprintf(stderr, "{\"ns_per_scan\": %.1f, \"sequential_ns_per_scan\": %.1f, "
                "\"parallel_ns_per_scan\": %.1f, \"parallel_speedup\": %.3f, \"threads\": %d, "
                "\"adaptive_choice\": \"%s\"}\n",
                spent_in[2] * 1e9 / n, spent_in[0] * 1e9 / n, spent_in[1] * 1e9 / n,
                spent_in[1] > 0 ? spent_in[0] / spent_in[1] : 0.0, PLC_THREADS,
                _plc_adaptive_choice());
    }
"#;

/// `plc_main.h` of a `--threads` build: the driver with [`PAR_SCAN_LOOP`].
pub(crate) fn par_main_h() -> String {
    assert!(PLC_MAIN_H.contains(SCAN_LOOP), "the driver's scan loop");
    PLC_MAIN_H.replacen(SCAN_LOOP, PAR_SCAN_LOOP, 1).replacen(
        "   argv[2] = --time: only the last state,",
        "   argv[2] = --sequential, --parallel (the default) or --adaptive: the scan run (a
            plc-deps c --threads build); = --time: only the last state,",
        1,
    )
}

/// The `Makefile`: every object `stems` with `CSTD` (the C standard, not replaced by a user's
/// `CFLAGS`) and `CFLAGS`, the part files `parts` with `PARTFLAGS` too.
pub(crate) fn makefile(stems: &[String], parts: &[String]) -> String {
    let objs: Vec<String> = stems.iter().map(|s| format!("{s}.o")).collect();
    let parts: Vec<String> = parts.iter().map(|s| format!("{s}.o")).collect();
    format!(
        "# Generated by plc-deps c. `make` builds ./plc_program; it reads the CSV of\n\
         # `plc-deps run --inputs` on standard input and prints one JSON state per scan.\n\
         # The rows of contacts and coils are data (plc_table*.c) run by the loops of plc_rows*.c.\n\
         # PARTFLAGS: extra flags for the part files of large ladder POUs (PARTS), the rungs\n\
         # written as statements: with `plc-deps c --statements`, `make PARTFLAGS=-O1` builds in\n\
         # about two thirds of the CPU time, and the rungs run about a fifth slower (docs/c.md).\n\
         # CSTD: the C standard, kept apart from CFLAGS so that `make CFLAGS=-O1` keeps it.\n\
         CC ?= cc\nCSTD = -std=c11\nCFLAGS ?= -Wall -Wextra -Werror -O2\nPARTFLAGS ?=\n\
         OBJS = main.o plc_program.o {}\nPARTS = {}\n\n\
         plc_program: $(OBJS)\n\t$(CC) $(CSTD) $(CFLAGS) -o $@ $(OBJS) -lm\n\n\
         $(PARTS): EXTRA = $(PARTFLAGS)\n\n\
         %.o: %.c plc_program.h plc_runtime.h plc_main.h\n\t$(CC) $(CSTD) $(CFLAGS) $(EXTRA) -c -o $@ $<\n\n\
         clean:\n\trm -f plc_program $(OBJS)\n\n.PHONY: clean\n",
        objs.join(" "),
        parts.join(" ")
    )
}

/// `plc_main.h`: the driver, the same for every program. Its reader of the inputs CSV accepts
/// exactly the files `plc-deps run --inputs` accepts (`src/cmd/run/inputs.rs`, docs/scan.md,
/// *Inputs*) and refuses the others with the same message at the same line and column; the
/// `csv_inputs` integration test runs one table of files through both.
pub(crate) const PLC_MAIN_H: &str = r#"/* plc_main.h: runs a generated program scan by scan on virtual time (docs/c.md).
   stdin: the CSV of `plc-deps run --inputs` (a header row of input names, one row per scan),
   read as `plc-deps run` reads it (docs/scan.md, Inputs): a bad file is one error line
   `error: <stdin>:LINE:COLUMN: message` (the message of `plc-deps run`), exit code 2, no state.
   argv[1]: the number of scans (default: the rows, at least 1).
   stdout: after each scan the state as one JSON line; stderr: each fault as a JSON line.
   argv[2] = --time: only the last state, and {"ns_per_scan": T} on stderr (the time of the
   scans alone: inputs and printing excluded). */
#ifndef PLC_MAIN_H
#define PLC_MAIN_H
#include "plc_runtime.h"
#include <stdarg.h>
#include <time.h>

static double seconds(void) {
    struct timespec ts;
    timespec_get(&ts, TIME_UTC);
    return (double)ts.tv_sec + (double)ts.tv_nsec * 1e-9;
}

static void on_fault(_plc_ctx *ctx, uint32_t rung, int kind) {
    const _plc_program *prog = ctx->user;
    const char *name = kind == _PLC_DIV_BY_ZERO ? "div-by-zero"
                       : kind == _PLC_LOOP_CAP ? "loop-cap"
                       : kind == _PLC_SCAN_BUDGET ? "scan-budget" : "index-range";
    fprintf(stderr, "{\"scan\":%llu,\"rung\":%s,\"kind\":\"%s\"}\n", (unsigned long long)ctx->scan,
            prog->rung_ids[rung], name);
}

/* The inputs text: bytes without the byte-order mark, and `out`, where each cell's value is
   written at the cell's own offset (a value is never longer than its cell plus separator). */
typedef struct { const unsigned char *b; size_t n; char *out; } _plc_csv;
/* A cell: the offset of its first character and its value (unquoted, trimmed). */
typedef struct { size_t at; const char *text; } _plc_cell;

/* `error: <stdin>:LINE:COLUMN: ` and the message; lines end with LF, CRLF or CR, columns count
   characters (UTF-8 sequences). */
static void _plc_csv_error(const _plc_csv *f, size_t at, const char *fmt, ...) {
    size_t line = 1, col = 1;
    for (size_t i = 0; i < at; i++) {
        unsigned char c = f->b[i];
        if (c == '\n' || (c == '\r' && (i + 1 >= f->n || f->b[i + 1] != '\n'))) { line++; col = 1; }
        else if ((c & 0xC0) != 0x80) col++;
    }
    fprintf(stderr, "error: <stdin>:%zu:%zu: ", line, col);
    va_list ap;
    va_start(ap, fmt);
    vfprintf(stderr, fmt, ap);
    va_end(ap);
    fputc('\n', stderr);
}

/* Where the first byte is that is not UTF-8 (as Rust's `str::from_utf8` finds it), or n. */
static size_t _plc_utf8_bad(const unsigned char *b, size_t n) {
    size_t i = 0;
    while (i < n) {
        unsigned char c = b[i];
        size_t len; unsigned char lo = 0x80, hi = 0xBF;
        if (c < 0x80) { i++; continue; }
        else if (c >= 0xC2 && c <= 0xDF) len = 2;
        else if (c >= 0xE0 && c <= 0xEF) { len = 3; if (c == 0xE0) lo = 0xA0; if (c == 0xED) hi = 0x9F; }
        else if (c >= 0xF0 && c <= 0xF4) { len = 4; if (c == 0xF0) lo = 0x90; if (c == 0xF4) hi = 0x8F; }
        else return i;
        if (i + 1 >= n || b[i + 1] < lo || b[i + 1] > hi) return i;
        for (size_t k = 2; k < len; k++)
            if (i + k >= n || (b[i + k] & 0xC0) != 0x80) return i;
        i += len;
    }
    return n;
}

static int _plc_csv_eol(const _plc_csv *f, size_t i) {
    return i == f->n || f->b[i] == '\n' || f->b[i] == '\r';
}

/* The next record from *pos (empty and blank lines skipped): 1 with its cells in *cells (grown
   as needed), 0 at the end, -1 after printing the error. A quote opens a cell only as its first
   character and must close, followed by nothing but spaces and tabs; `""` is a quote in it. */
static int _plc_csv_record(_plc_csv *f, size_t *pos, _plc_cell **cells, size_t *cap, size_t *count) {
    const unsigned char *b = f->b;
    size_t n = f->n, i = *pos;
    for (;;) {
        while (i < n && (b[i] == '\n' || b[i] == '\r')) i++;
        if (i == n) { *pos = i; return 0; }
        size_t j = i;
        while (j < n && (b[j] == ' ' || b[j] == '\t')) j++;
        if (!_plc_csv_eol(f, j)) break;
        i = j;
    }
    size_t nc = 0;
    for (;;) {
        if (nc == *cap) {
            *cap = *cap ? *cap * 2 : 16;
            *cells = realloc(*cells, *cap * sizeof **cells);
            if (!*cells) { fputs("error: out of memory\n", stderr); return -1; }
        }
        size_t start = i;
        char *w = f->out + start;
        if (i < n && b[i] == '"') {
            size_t open = i++;
            for (;;) {
                if (i == n) { _plc_csv_error(f, open, "a quoted cell is not closed"); return -1; }
                if (b[i] == '"') {
                    if (i + 1 < n && b[i + 1] == '"') { *w++ = '"'; i += 2; continue; }
                    break;
                }
                *w++ = (char)b[i++];
            }
            i++;
            while (i < n && (b[i] == ' ' || b[i] == '\t')) i++;
            if (!(_plc_csv_eol(f, i) || b[i] == ',')) {
                _plc_csv_error(f, i, "text after the closing quote of a cell");
                return -1;
            }
        } else {
            while (!(_plc_csv_eol(f, i) || b[i] == ',')) {
                if (b[i] == '"') {
                    _plc_csv_error(f, i, "a quote inside a cell that does not start with one "
                                         "(quote the whole cell and double the quote)");
                    return -1;
                }
                *w++ = (char)b[i++];
            }
        }
        *w = 0;
        char *t = f->out + start;
        while (*t == ' ' || *t == '\t') t++;
        while (w > t && (w[-1] == ' ' || w[-1] == '\t')) *--w = 0;
        (*cells)[nc].at = start;
        (*cells)[nc].text = t;
        nc++;
        if (i < n && b[i] == ',') { i++; continue; }
        *pos = i;
        *count = nc;
        return 1;
    }
}

/* What a TIME cell is (src/cmd/run/inputs.rs, parse_time_cell): milliseconds `[+-]digits`, or
   a literal T#/t#/TIME#/time#, `-`, numbers (at most one `.`, `_` anywhere) each with a unit
   d h m s ms in any case. The value is kept exactly as W ms + S 10^-12 ms. */
enum { _PLC_TIME_OK, _PLC_TIME_RANGE, _PLC_TIME_FRACTION, _PLC_TIME_NOT };
static int _plc_time_cell(const char *t, int32_t *out) {
    const uint64_t unit = 1000000000000ull, cap = (uint64_t)1 << 62;
    if (!strchr(t, '#')) {
        int neg = 0;
        const char *s = t;
        if (*s == '-' || *s == '+') { neg = *s == '-'; s++; }
        size_t len = strlen(s);
        if (!len || s[0] == '_' || s[len - 1] == '_' || strstr(s, "__")) return _PLC_TIME_NOT;
        uint64_t v = 0;
        for (; *s; s++) {
            if (*s == '_') continue;
            if (*s < '0' || *s > '9') return _PLC_TIME_NOT;
            v = v > cap / 10 ? cap : v * 10 + (uint64_t)(*s - '0');
        }
        if (v > (neg ? 2147483648ull : 2147483647ull)) return _PLC_TIME_RANGE;
        *out = (int32_t)(neg ? -(int64_t)v : (int64_t)v);
        return _PLC_TIME_OK;
    }
    const char *p;
    if (!strncmp(t, "T#", 2) || !strncmp(t, "t#", 2)) p = t + 2;
    else if (!strncmp(t, "TIME#", 5) || !strncmp(t, "time#", 5)) p = t + 5;
    else return _PLC_TIME_NOT;
    int neg = 0;
    if (*p == '-') { neg = 1; p++; }
    if (!*p) return _PLC_TIME_NOT;
    uint64_t ms = 0, sub = 0;
    int too_precise = 0;
    while (*p) {
        uint64_t whole = 0, frac = 0;
        int dots = 0, digits = 0, k = 0, last_nonzero = 0;
        for (; (*p >= '0' && *p <= '9') || *p == '.' || *p == '_'; p++) {
            if (*p == '.') { dots++; continue; }
            if (*p == '_') continue;
            unsigned d = (unsigned)(*p - '0');
            digits++;
            if (!dots) { if (whole <= 10000000000ull) whole = whole * 10 + d; continue; }
            k++;
            if (d) last_nonzero = k;
            if (k <= 12) frac = frac * 10 + d;
        }
        if (dots > 1 || !digits) return _PLC_TIME_NOT;
        if (last_nonzero > 12) too_precise = 1;
        for (; k < 12; k++) frac *= 10;
        const char *u = p;
        while (*p && !((*p >= '0' && *p <= '9') || *p == '.')) p++;
        size_t ul = (size_t)(p - u);
        char a = ul ? (char)(u[0] | 0x20) : 0, b = ul > 1 ? (char)(u[1] | 0x20) : 0;
        uint64_t f;
        if (ul == 1 && a == 'd') f = 86400000;
        else if (ul == 1 && a == 'h') f = 3600000;
        else if (ul == 1 && a == 'm') f = 60000;
        else if (ul == 1 && a == 's') f = 1000;
        else if (ul == 2 && a == 'm' && b == 's') f = 1;
        else return _PLC_TIME_NOT;
        if (too_precise) continue;
        /* whole * f < 2^64 (whole < 10^11, f < 10^8); frac * f in two halves. */
        uint64_t hi = frac / 1000000 * f, add = whole * f + hi / 1000000;
        sub += hi % 1000000 * 1000000 + frac % 1000000 * f;
        add += sub / unit;
        sub %= unit;
        ms = ms > cap - (add > cap ? cap : add) ? cap : ms + add;
    }
    if (too_precise) return _PLC_TIME_FRACTION;
    uint64_t limit = neg ? 2147483648ull : 2147483647ull;
    if (ms > limit || (ms == limit && sub)) return _PLC_TIME_RANGE;
    if (sub) return _PLC_TIME_FRACTION;
    *out = (int32_t)(neg ? -(int64_t)ms : (int64_t)ms);
    return _PLC_TIME_OK;
}

static int _plc_eq_word(const char *s, const char *w) {
    for (; *s && *w; s++, w++)
        if ((*s | 0x20) != *w) return 0;
    return !*s && !*w;
}

/* A REAL or LREAL cell (src/cmd/run/inputs.rs, is_real_text): a decimal number with an optional
   exponent, or inf, infinity, nan in any case, with an optional sign; strtof/strtod read it. */
static int _plc_real_text(const char *t) {
    if (*t == '+' || *t == '-') t++;
    if (_plc_eq_word(t, "inf") || _plc_eq_word(t, "infinity") || _plc_eq_word(t, "nan")) return 1;
    int n = 0;
    while (*t >= '0' && *t <= '9') { t++; n++; }
    if (*t == '.') { t++; while (*t >= '0' && *t <= '9') { t++; n++; } }
    if (!n) return 0;
    if (*t == 'e' || *t == 'E') {
        t++;
        if (*t == '+' || *t == '-') t++;
        int e = 0;
        while (*t >= '0' && *t <= '9') { t++; e++; }
        if (!e) return 0;
    }
    return !*t;
}

/* Sets input `input` (of type `type`: its entry of `input_types`) from a cell in `state`;
   0 after printing why the cell is not a value of it. */
static int _plc_set_cell(const _plc_program *prog, const _plc_csv *f, void *state, unsigned input,
                         const _plc_cell *cell, size_t scan) {
    const char *type = prog->input_types[input], *t = cell->text, *name = prog->input_names[input];
    char ms[16];
    int32_t v = 0;
    if (!strcmp(type, "TIME")) {
        switch (_plc_time_cell(t, &v)) {
        case _PLC_TIME_RANGE:
            _plc_csv_error(f, cell->at, "scan %zu, column `%s`: `%s` is out of the range of TIME (32-bit ms)", scan, name, t);
            return 0;
        case _PLC_TIME_FRACTION:
            _plc_csv_error(f, cell->at, "scan %zu, column `%s`: `%s` is not a whole number of milliseconds (TIME counts milliseconds)", scan, name, t);
            return 0;
        case _PLC_TIME_NOT:
            _plc_csv_error(f, cell->at, "scan %zu, column `%s`: `%s` is not a TIME%s", scan, name, t,
                           strchr(t, '#') ? "" : " (milliseconds or a literal like T#1s)");
            return 0;
        default:
            snprintf(ms, sizeof ms, "%ld", (long)v);
            t = ms;
        }
    } else if ((!strcmp(type, "REAL") || !strcmp(type, "LREAL")) && !_plc_real_text(t)) {
        _plc_csv_error(f, cell->at, "scan %zu, column `%s`: `%s` is not a valid %s", scan, name, t, type);
        return 0;
    }
    if (prog->set_input(state, input, t)) return 1;
    if (!strcmp(type, "BOOL"))
        _plc_csv_error(f, cell->at, "scan %zu, column `%s`: `%s` is not a BOOL (true, false, 1 or 0)", scan, name, t);
    else
        _plc_csv_error(f, cell->at, "scan %zu, column `%s`: `%s` is not %s", scan, name, t, type);
    return 0;
}

static int _plc_in(const char *const *names, const char *name) {
    for (; *names; names++) if (!strcmp(*names, name)) return 1;
    return 0;
}

/* The header's cell `c`: the input it names, or -1 after printing why it names none. */
static int _plc_column(const _plc_program *prog, const _plc_csv *f, const _plc_cell *c,
                       const int *taken, size_t ncols) {
    if (!*c->text) { _plc_csv_error(f, c->at, "empty column name in the header"); return -1; }
    for (int i = 0; prog->input_names[i]; i++) {
        if (strcmp(prog->input_names[i], c->text)) continue;
        for (size_t k = 0; k < ncols; k++)
            if (taken[k] == i) { _plc_csv_error(f, c->at, "input `%s` has two columns", c->text); return -1; }
        return i;
    }
    if (_plc_in(prog->output_names, c->text) || _plc_in(prog->memory_names, c->text)) {
        _plc_csv_error(f, c->at, "`%s` is not an input variable (it is %s)", c->text,
                       _plc_in(prog->output_names, c->text) ? "an output" : "a memory variable");
        return -1;
    }
    size_t size = 5;
    for (int i = 0; prog->input_names[i]; i++) size += strlen(prog->input_names[i]) + 2;
    char *list = malloc(size);
    if (!list) return -1;
    char *w = list;
    for (int i = 0; prog->input_names[i]; i++)
        w += sprintf(w, "%s%s", i ? ", " : "", prog->input_names[i]);
    if (w == list) strcpy(list, "none");
    _plc_csv_error(f, c->at, "unknown input variable `%s` (inputs: %s)", c->text, list);
    free(list);
    return -1;
}

/* One row's values: (input, cell) pairs, checked against a scratch state. */
typedef struct { size_t first, count; } _plc_row;

/* The harness of `prog`: argv[1] the number of scans, argv[2] `--time`; 0, or 2 on bad input. */
static int _plc_main(const _plc_program *prog, int argc, char **argv) {
    size_t cap = 1 << 16, len = 0;
    char *text = malloc(cap);
    if (!text) return 2;
    for (size_t got; (got = fread(text + len, 1, cap - len - 1, stdin)) > 0;) {
        len += got;
        if (cap - len < 2) { cap *= 2; text = realloc(text, cap); if (!text) return 2; }
    }
    text[len] = 0;
    const unsigned char *bytes = (const unsigned char *)text;
    size_t bad = _plc_utf8_bad(bytes, len), nul = len;
    for (size_t i = 0; i < len; i++) if (!bytes[i]) { nul = i; break; }
    if (bad < len && nul >= bad) {
        fprintf(stderr, "error: cannot read <stdin>: not UTF-8 text (byte 0x%02x at offset %zu is not valid UTF-8)\n", bytes[bad], bad);
        return 2;
    }
    if (nul < len) {
        fprintf(stderr, "error: cannot read <stdin>: binary data, not text (a NUL byte at offset %zu)\n", nul);
        return 2;
    }
    size_t skip = len >= 3 && !memcmp(text, "\xEF\xBB\xBF", 3) ? 3 : 0;
    _plc_csv f = {bytes + skip, len - skip, malloc(len - skip + 1)};
    void *state = malloc(prog->size), *scratch = malloc(prog->size), *image = malloc(prog->size);
    if (!f.out || !state || !scratch || !image) return 2;
    memcpy(state, prog->initial, prog->size);
    memcpy(scratch, prog->initial, prog->size);
    /* The input image: every cell is set into it too, and the inputs the program writes are
       copied from it before each scan (docs/scan.md, Inputs). */
    memcpy(image, prog->initial, prog->size);
    _plc_cell *cells = NULL;
    size_t cells_cap = 0, ncells = 0, pos = 0, ncols = 0;
    int *column_input = NULL;
    /* The header, then every row checked before the first scan (as `plc-deps run` does). */
    int got = _plc_csv_record(&f, &pos, &cells, &cells_cap, &ncells);
    if (got < 0) return 2;
    if (got > 0) {
        ncols = ncells;
        column_input = malloc(ncols * sizeof *column_input);
        if (!column_input) return 2;
        for (size_t c = 0; c < ncols; c++) {
            int i = _plc_column(prog, &f, &cells[c], column_input, c);
            if (i < 0) return 2;
            column_input[c] = i;
        }
    }
    _plc_row *rows = NULL;
    _plc_cell *values = NULL;
    unsigned *value_input = NULL;
    size_t nrows = 0, rows_cap = 0, nvalues = 0, values_cap = 0;
    while (got > 0 && (got = _plc_csv_record(&f, &pos, &cells, &cells_cap, &ncells)) > 0) {
        if (ncells > ncols) {
            _plc_csv_error(&f, cells[ncols].at, "%zu value%s in a row, the header has %zu column%s",
                           ncells, ncells == 1 ? "" : "s", ncols, ncols == 1 ? "" : "s");
            return 2;
        }
        if (nrows == rows_cap) {
            rows_cap = rows_cap ? rows_cap * 2 : 64;
            rows = realloc(rows, rows_cap * sizeof *rows);
            if (!rows) return 2;
        }
        rows[nrows].first = nvalues;
        for (size_t c = 0; c < ncells; c++) {
            if (!*cells[c].text) continue;
            if (!_plc_set_cell(prog, &f, scratch, (unsigned)column_input[c], &cells[c], nrows)) return 2;
            if (nvalues == values_cap) {
                values_cap = values_cap ? values_cap * 2 : 256;
                values = realloc(values, values_cap * sizeof *values);
                value_input = realloc(value_input, values_cap * sizeof *value_input);
                if (!values || !value_input) return 2;
            }
            values[nvalues] = cells[c];
            value_input[nvalues++] = (unsigned)column_input[c];
        }
        rows[nrows].count = nvalues - rows[nrows].first;
        nrows++;
    }
    if (got < 0) return 2;
    unsigned long long scans = nrows > 0 ? nrows : 1;
    if (argc > 1) scans = strtoull(argv[1], NULL, 10);
    int timing = argc > 2 && !strcmp(argv[2], "--time");
    double spent = 0;
    _plc_ctx ctx = {0, 0, prog->loop_cap, on_fault, (void *)prog, 0, 0};
    for (unsigned long long k = 0; k < scans; k++) {
        if (k < nrows)
            for (size_t v = rows[k].first; v < rows[k].first + rows[k].count; v++) {
                _plc_set_cell(prog, &f, state, value_input[v], &values[v], (size_t)k);
                _plc_set_cell(prog, &f, image, value_input[v], &values[v], (size_t)k);
            }
        prog->restore_inputs(state, image);
        ctx.scan = k;
        ctx.now = (int64_t)k * prog->cycle_ms;
        double t0 = timing ? seconds() : 0;
        prog->scan(state, &ctx);
        if (timing) spent += seconds() - t0;
        else prog->print(state, stdout);
    }
    if (timing) {
        prog->print(state, stdout);
        fprintf(stderr, "{\"ns_per_scan\": %.1f}\n", scans ? spent * 1e9 / (double)scans : 0.0);
    }
    free(state);
    free(scratch);
    free(image);
    free(rows);
    free(values);
    free(value_input);
    free(cells);
    free(column_input);
    free(f.out);
    free(text);
    return 0;
}
#endif
"#;
