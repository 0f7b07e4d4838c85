//! The C of the rows' kernels (`rows`): one function per row shape, a loop over `n` rows of a
//! table, and the files that hold them.
//!
//! A kernel evaluates a row as the interpreter evaluates its rung (docs/scan.md): every edge
//! contact computes its pulse (`(v ^ falling) & (m ^ falling ^ 1)`) and its memory takes `v`,
//! and every contact and compare is read, before the first output; then the outputs and boxes
//! in order (a BOOL output through the 16-byte `_pou__bit` table, an INT box writing only when
//! powered, `x = p ? v : x`, so a DIV or MOD by zero records its fault only when powered, as
//! the statements' `if`; a timer or counter box makes its Q the power on). What a box does by
//! kind (TON/TOF/TP, CTU/CTD, ADD/SUB/MUL, DIV/MOD) and a compare's operator are data, the
//! runtime's `_plc_timer_row` … `_plc_cmp_row_i16`, so rungs differing only in those share a
//! kernel. BOOLs are the bytes 0 and 1 of C `bool`s, read and written through `uint8_t`; INTs
//! are read and written as `int16_t`, instances through pointers to their runtime structs, all
//! at the offsets of the row.
//!
//! Files: at most [`PER_FILE`] kernels per file, so `make -j` compiles them in parallel.
//!
//! Not here: which rungs are rows and their slots (`rows`); the shapes as data (`shape`).

use super::shape::{Item, Out, Shape};
use super::text::push;

/// Kernels per source file.
pub(super) const PER_FILE: usize = 64;

/// The declaration of kernel `k` over tables of `ty`.
pub(super) fn decl(k: u32, ty: &str) -> String {
    format!("void _pou__k{k}(uint8_t *s, const {ty} *t, size_t n, _plc_ctx *ctx)")
}

/// The kernels' source files (name stem, text): `plc_rows`, or `plc_rows0`, `plc_rows1` …
/// of at most [`PER_FILE`] kernels each.
pub(super) fn sources(shapes: &[Shape], ty: &str) -> Vec<(String, String)> {
    let files = shapes.len().div_ceil(PER_FILE);
    (0..files)
        .map(|f| {
            let stem = match files {
                1 => "plc_rows".to_string(),
                _ => format!("plc_rows{f}"),
            };
            let range = f * PER_FILE..shapes.len().min((f + 1) * PER_FILE);
            let mut s = format!(
                "/* {stem}.c: loops that run the rows of the tables, one per rung shape \
                 (docs/c.md). */\n#include \"plc_runtime.h\"\n\n"
            );
            if shapes[range.clone()]
                .iter()
                .any(|sh| sh.outs.contains(&Out::Bit))
            {
                s.push_str(
                    "/* A BOOL output's new value: _pou__bit[kind | power << 2 | old << 3], kind 0 \
                     coil, 1 negated coil, 2 set, 3 reset. */\n\
                     static const uint8_t _pou__bit[16] = {0, 1, 0, 0, 1, 0, 1, 0, 0, 1, 1, 1, 1, 0, 1, 0};\n\n",
                );
            }
            for k in range {
                s.push_str(&kernel(k, &shapes[k], ty));
            }
            (stem, s)
        })
        .collect()
}

/// The C of kernel `k`: one loop over `n` rows of `shape`.
fn kernel(k: usize, shape: &Shape, ty: &str) -> String {
    let mut pre = String::new();
    let mut next = shape.out_slots() + shape.lits + usize::from(shape.lits > 0);
    let mut cond = and_expr(&shape.cond, &mut next, &mut pre);
    if shape.lits > 0 {
        // The contacts' bytes as the bits of a word, compared with the pattern the row's
        // contacts pass on (entry bit i set: contact i is Normal) where they count (bit 8 + i
        // set: contact i is one of the rung's, not padding).
        let o = shape.out_slots();
        let bits: Vec<String> = (0..shape.lits)
            .map(|i| match i {
                0 => format!("(unsigned)s[t[{o}]]"),
                _ => format!("(unsigned)s[t[{}]] << {i}", o + i),
            })
            .collect();
        push(
            &mut pre,
            format_args!("        unsigned q = {};\n", bits.join(" | ")),
        );
        let e = format!("t[{}]", o + shape.lits);
        let eq = format!("(((q ^ {e}) & ({e} >> 8)) == 0)");
        cond = if shape.cond.is_empty() {
            eq
        } else {
            format!("{eq} & {cond}")
        };
    }
    let mut body = pre;
    push(&mut body, format_args!("        unsigned p = {cond};\n"));
    let mut i = 0;
    for &o in &shape.outs {
        push(&mut body, format_args!("        {}\n", output(o, i)));
        i += o.slots();
    }
    format!(
        "_PLC_KERNEL {} {{\n    (void)ctx;\n    for (; n; n--, t += {}) {{\n{body}    }}\n}}\n\n",
        decl(k as u32, ty).trim_start_matches("void "),
        shape.slots()
    )
}

/// The statement of output `o` whose slots start at `i`.
fn output(o: Out, i: usize) -> String {
    let int = |k: usize| format!("*(int16_t *)(s + t[{k}])");
    match o {
        Out::Bit => format!(
            "s[t[{i}]] = _pou__bit[t[{}] | p << 2 | (unsigned)s[t[{i}]] << 3];",
            i + 1
        ),
        Out::Move(c) => format!("{0} = p ? {1} : {0};", int(i), int_operand(i + 1, c)),
        Out::Arith(ca, cb) => format!(
            "{0} = p ? _plc_ring_row_i16(t[{1}], {2}, {3}) : {0};",
            int(i),
            i + 1,
            int_operand(i + 2, ca),
            int_operand(i + 3, cb)
        ),
        Out::DivMod(ca, cb) => format!(
            "{0} = p ? _plc_divmod_row_i16(t[{1}], {2}, {3}, ctx, t[{4}]) : {0};",
            int(i),
            i + 1,
            int_operand(i + 2, ca),
            int_operand(i + 3, cb),
            i + 4
        ),
        Out::Timer => format!(
            "p = _plc_timer_row((_plc_timer *)(void *)(s + t[{i}]), ctx->now, t[{}], (int32_t)t[{}], p);",
            i + 1,
            i + 2
        ),
        Out::Counter(cp, cr) => {
            let r = if cr {
                format!("t[{}] != 0", i + 3)
            } else {
                format!("s[t[{}]]", i + 3)
            };
            format!(
                "p = _plc_counter_row((_plc_counter *)(void *)(s + t[{i}]), t[{}], {}, p, {r});",
                i + 1,
                int_operand(i + 2, cp)
            )
        }
    }
}

/// The INT in slot `k`: a constant (`c`, its bits) or a variable's offset.
fn int_operand(k: usize, c: bool) -> String {
    if c {
        format!("(int16_t)(uint16_t)t[{k}]")
    } else {
        format!("*(int16_t *)(s + t[{k}])")
    }
}

/// The C expression of an AND of items whose slots start at `*next`; edge pulses are computed
/// into locals by statements appended to `pre` (in slot order, so in the rung's canonical
/// order: an edge's memory is read by nothing else in the rung).
fn and_expr(items: &[Item], next: &mut usize, pre: &mut String) -> String {
    if items.is_empty() {
        return "1u".into();
    }
    let parts: Vec<String> = items
        .iter()
        .map(|item| match item {
            Item::Lit(false) => {
                *next += 1;
                format!("s[t[{}]]", *next - 1)
            }
            Item::Lit(true) => {
                *next += 1;
                format!("(s[t[{}]] ^ 1)", *next - 1)
            }
            Item::Contact => {
                *next += 2;
                format!("(s[t[{}]] ^ t[{}])", *next - 2, *next - 1)
            }
            Item::Edge => {
                let (v, m, f) = (*next, *next + 1, *next + 2);
                *next += 3;
                push(
                    pre,
                    format_args!(
                        "        unsigned e{v} = (s[t[{v}]] ^ t[{f}]) & (s[t[{m}]] ^ t[{f}] ^ 1u);\n        s[t[{m}]] = s[t[{v}]];\n"
                    ),
                );
                format!("e{v}")
            }
            Item::Cmp(ca, cb) => {
                *next += 3;
                let (a, b) = (int_operand(*next - 3, *ca), int_operand(*next - 2, *cb));
                format!("_plc_cmp_row_i16(t[{}], {a}, {b})", *next - 1)
            }
            Item::Or(branches) => {
                let bs: Vec<String> = branches
                    .iter()
                    .map(|b| match b.len() {
                        1 => and_expr(b, next, pre),
                        _ => format!("({})", and_expr(b, next, pre)),
                    })
                    .collect();
                format!("({})", bs.join(" | "))
            }
        })
        .collect();
    parts.join(" & ")
}
