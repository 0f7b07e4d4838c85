//! The harness: `plc_program.c` (initial state, the scan, input and output tables, and the
//! program's descriptor `_plc_program_desc` that points at them), `plc_main.h` (the driver
//! `_plc_main`, the same for every program: it runs a program through its descriptor), `main.c`
//! (calls the driver; it reads the CSV of `plc-deps run --inputs` on standard input, runs one scan per row on
//! virtual time, prints after each scan one JSON line with the keys and value forms of the
//! `state` object of `plc-deps run --format json`, and each fault as a JSON line
//! `{"scan","rung","kind"}` on standard error) and the `Makefile`.
//!
//! Not here: the POUs' code (`ladder`, `fbd`).

use super::ladder::{c_const, push, Shared};
use super::names::{c_string, json_string};
use super::CConfig;
use crate::model::{FbKind, Program, Type, Value, VarClass};

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
        .vars
        .iter()
        .enumerate()
        .filter(|(i, v)| !matches!(v.ty, Type::Fb(_)) && !is_zero(v.init) && !sh.local_only[*i])
        .map(|(i, v)| format!("    .{} = {},\n", field(sh, i), c_const(v.init)))
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
        let last = (0..p.vars.len())
            .filter(|&i| (c.is)(p.vars[i].ty))
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
    print_state(p, sh, &mut s);
    s.push_str("const char *const _plc_rung_ids[] = {\n");
    for r in &p.rungs {
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

const _plc_program _plc_program_desc = {
    sizeof(_plc_state), &_plc_initial, _plc_desc_scan, _plc_desc_set_input, _plc_desc_print,
    _plc_input_names, _plc_rung_ids, @CYCLE@, @LOOP_CAP@
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
        let key = format!("{}:", json_string(&p.vars[i].name));
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
                slot_kind(p.vars[i].ty)
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
    let ins: Vec<usize> = (0..p.vars.len())
        .filter(|&i| p.vars[i].class == VarClass::Input && !p.vars[i].hidden)
        .collect();
    s.push_str("const char *const _plc_input_names[] = {\n");
    for &i in &ins {
        push(s, format_args!("    {},\n", c_string(&p.vars[i].name)));
    }
    s.push_str("    NULL\n};\n\n");
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

/// `_plc_print_state`, through a table of the visible variables.
fn print_state(p: &Program, sh: &Shared, s: &mut String) {
    let vis: Vec<usize> = (0..p.vars.len()).filter(|&i| !p.vars[i].hidden).collect();
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

/// The `Makefile`: every object `stems` with `CFLAGS`, the part files `parts` with `PARTFLAGS` too.
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
         CC ?= cc\nCFLAGS ?= -std=c11 -Wall -Wextra -Werror -O2\nPARTFLAGS ?=\n\
         OBJS = main.o plc_program.o {}\nPARTS = {}\n\n\
         plc_program: $(OBJS)\n\t$(CC) $(CFLAGS) -o $@ $(OBJS) -lm\n\n\
         $(PARTS): EXTRA = $(PARTFLAGS)\n\n\
         %.o: %.c plc_program.h plc_runtime.h plc_main.h\n\t$(CC) $(CFLAGS) $(EXTRA) -c -o $@ $<\n\n\
         clean:\n\trm -f plc_program $(OBJS)\n\n.PHONY: clean\n",
        objs.join(" "),
        parts.join(" ")
    )
}

/// `plc_main.h`: the driver, the same for every program.
pub(crate) const PLC_MAIN_H: &str = r#"/* plc_main.h: runs a generated program scan by scan on virtual time (docs/c.md).
   stdin: the CSV of `plc-deps run --inputs` (a header row of input names, one row per scan).
   argv[1]: the number of scans (default: the rows, at least 1).
   stdout: after each scan the state as one JSON line; stderr: each fault as a JSON line.
   argv[2] = --time: only the last state, and {"ns_per_scan": T} on stderr (the time of the
   scans alone: inputs and printing excluded). */
#ifndef PLC_MAIN_H
#define PLC_MAIN_H
#include "plc_runtime.h"
#include <time.h>

static double seconds(void) {
    struct timespec ts;
    timespec_get(&ts, TIME_UTC);
    return (double)ts.tv_sec + (double)ts.tv_nsec * 1e-9;
}

static void on_fault(_plc_ctx *ctx, uint32_t rung, int kind) {
    const _plc_program *prog = ctx->user;
    const char *name = kind == _PLC_DIV_BY_ZERO ? "div-by-zero"
                       : kind == _PLC_LOOP_CAP ? "loop-cap" : "scan-budget";
    fprintf(stderr, "{\"scan\":%llu,\"rung\":%s,\"kind\":\"%s\"}\n", (unsigned long long)ctx->scan,
            prog->rung_ids[rung], name);
}

/* Splits one CSV line into cells (double quotes as in RFC 4180); returns the count. */
static int split(char *line, char **cells, int max) {
    int n = 0;
    char *r = line, *w = line;
    while (n < max) {
        cells[n++] = w;
        if (*r == '"') {
            r++;
            for (;;) {
                if (!*r) break;
                if (*r == '"' && r[1] == '"') { *w++ = '"'; r += 2; continue; }
                if (*r == '"') { r++; break; }
                *w++ = *r++;
            }
            while (*r && *r != ',') r++;
        } else {
            while (*r && *r != ',') *w++ = *r++;
        }
        int more = *r == ',';
        if (more) r++;
        *w++ = 0;
        if (!more) break;
    }
    return n;
}

static char *trim(char *s) {
    while (*s == ' ' || *s == '\t') s++;
    size_t n = strlen(s);
    while (n && (s[n - 1] == ' ' || s[n - 1] == '\t' || s[n - 1] == '\r')) s[--n] = 0;
    return s;
}

static int blank(const char *s) {
    for (; *s; s++) if (*s != ' ' && *s != '\t' && *s != '\r') return 0;
    return 1;
}

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
    /* Lines, without blank ones. */
    size_t nlines = 0, lcap = 64;
    char **lines = malloc(lcap * sizeof *lines);
    for (char *s = text; s && *s;) {
        char *nl = strchr(s, '\n');
        if (nl) *nl = 0;
        if (!blank(s)) {
            if (nlines == lcap) { lcap *= 2; lines = realloc(lines, lcap * sizeof *lines); }
            lines[nlines++] = s;
        }
        s = nl ? nl + 1 : NULL;
    }
    enum { MAX_COLS = 4096 };
    static char *cells[MAX_COLS];
    static int column_input[MAX_COLS];
    int ncols = 0;
    if (nlines > 0) {
        ncols = split(lines[0], cells, MAX_COLS);
        for (int c = 0; c < ncols; c++) {
            char *name = trim(cells[c]);
            column_input[c] = -1;
            for (int i = 0; prog->input_names[i]; i++)
                if (!strcmp(prog->input_names[i], name)) column_input[c] = i;
            if (column_input[c] < 0) {
                fprintf(stderr, "error: <stdin>:1: unknown input variable `%s`\n", name);
                return 2;
            }
        }
    }
    size_t rows = nlines > 0 ? nlines - 1 : 0;
    unsigned long long scans = rows > 0 ? rows : 1;
    if (argc > 1) scans = strtoull(argv[1], NULL, 10);
    int timing = argc > 2 && !strcmp(argv[2], "--time");
    double spent = 0;
    void *state = malloc(prog->size);
    if (!state) return 2;
    memcpy(state, prog->initial, prog->size);
    _plc_ctx ctx = {0, 0, prog->loop_cap, on_fault, (void *)prog, 0, 0};
    for (unsigned long long k = 0; k < scans; k++) {
        if (k < rows) {
            int n = split(lines[k + 1], cells, MAX_COLS);
            for (int c = 0; c < n && c < ncols; c++) {
                char *cell = trim(cells[c]);
                if (!*cell) continue;
                if (!prog->set_input(state, (unsigned)column_input[c], cell)) {
                    fprintf(stderr, "error: <stdin>: scan %llu, column `%s`: `%s` is not a value of that input\n",
                            k, prog->input_names[column_input[c]], cell);
                    return 2;
                }
            }
        }
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
    free(lines);
    free(text);
    return 0;
}
#endif
"#;
