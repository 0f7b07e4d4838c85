//! Rungs of contacts and coils as data: each such rung is a row of plain byte offsets in a
//! table, run by a small loop generated for its exact *shape* (a kernel), instead of C
//! statements per rung.
//!
//! Why: `cc -O2` spends about a millisecond of CPU on each rung written as statements (spread
//! over all its passes), so 100,000 rungs as statements take minutes to build however they are
//! written. A row costs only the parsing of a few integers, and a kernel is a loop of a few
//! lines, compiled once for every rung of its shape. Because the kernel is specialised — its
//! contacts, negations, ORs, edge and outputs are C code, only the offsets are data — a row runs
//! about as fast as the statements (docs/c.md).
//!
//! A rung is a row when its series is a condition of Normal, Negated, Rising and Falling
//! contacts on BOOL variables of the state (ORs of series of Normal and Negated contacts, no
//! empty branch; edge contacts only outside the ORs) followed by one output, or an output
//! branch of single outputs: coil, negated coil, set or reset of BOOL variables of the state.
//! Its shape is that tree in a canonical form: the items of every AND sorted (positive
//! contacts, negated contacts, edge contacts, ORs), the branches of every OR too — exact since
//! contacts have no side effects, and an edge contact's only effect is on its own hidden memory,
//! which no other contact reads; so rungs that differ only in the order of their contacts share
//! one kernel. The row's slots are the outputs' offsets, then the contacts' offsets in the
//! canonical order (an edge contact: its BOOL, then its memory).
//!
//! The kernel evaluates as the interpreter does (docs/scan.md): every edge contact computes its
//! pulse (rising `v & !m`, falling `!v & m`) and its memory takes `v` before the outputs are
//! written, all contacts are read before the first output is written, and the outputs are
//! written in order: coil `p`, negated coil `!p`, set `old | p`, reset `old & !p`. BOOLs are the
//! bytes 0 and 1 of C `bool`s, read and written through `uint8_t`, which may alias anything; a
//! BOOL's offset is its index among the state's BOOL members, which `_plc_state` lists first
//! (`mod`, checked by `_Static_assert`s in `plc_program.c`), so table files need no struct and
//! no `offsetof`: they are data only.
//!
//! Consecutive rows of one kernel in a function make one run, one call
//! `_pou__kK((uint8_t *)self, _pou__tF_K + first, count)`; any other line of C (a rung that is no
//! row, a label, the function's end) ends the run first, so rows run in the order they are
//! emitted. Only ladder functions of POUs use rows (not FBD bodies or function block types,
//! whose variables may be locals or another struct's members). The emission order itself (rungs
//! of one dependence level grouped by kernel) is `order`'s.
//!
//! Not here: the C of the rungs that are no row (`ladder`), the order of the rungs (`order`),
//! the files (`mod`).

use super::ladder::{push, Shared};
use crate::model::{ContactKind, Element, RungId, Series, Type, VarId, VarRef};
use std::collections::{BTreeMap, HashMap};

/// A condition item of a shape, in its canonical order (derived `Ord`: positive contacts,
/// negated contacts, rising edges, falling edges, ORs).
#[derive(Clone, Debug, PartialEq, Eq, PartialOrd, Ord, Hash)]
enum Item {
    /// A Normal (false) or Negated (true) contact.
    Lit(bool),
    /// An edge contact: falling (true) or rising (false).
    Edge(bool),
    /// An OR of ANDs (each with at least one item).
    Or(Vec<Vec<Item>>),
}

/// An output of a shape.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
enum Out {
    Coil,
    NegCoil,
    Set,
    Reset,
}

/// The shape of a row: what its kernel computes.
#[derive(Clone, Debug, PartialEq, Eq, Hash)]
struct Shape {
    /// The contacts of the top-level AND (Normal or Negated: which ones is data, the row's
    /// pattern word).
    lits: usize,
    /// The other items of the top-level AND, sorted.
    cond: Vec<Item>,
    outs: Vec<Out>,
}

impl Shape {
    fn slots(&self) -> usize {
        fn count(items: &[Item]) -> usize {
            items
                .iter()
                .map(|i| match i {
                    Item::Lit(_) => 1,
                    Item::Edge(_) => 2,
                    Item::Or(bs) => bs.iter().map(|b| count(b)).sum(),
                })
                .sum()
        }
        self.outs.len() + self.lits + usize::from(self.lits > 0) + count(&self.cond)
    }
}

/// A rung as a row: its kernel and its slots (the offsets of its BOOLs).
#[derive(Clone, Debug)]
pub(crate) struct Row {
    pub kernel: u32,
    slots: Vec<u32>,
}

/// The kernels of a program: one per shape used.
#[derive(Default)]
pub(crate) struct Kernels {
    ids: HashMap<Shape, u32>,
    shapes: Vec<Shape>,
}

impl Kernels {
    /// Rung `r` as a row (its shape's kernel registered), if it has a row's form.
    pub fn row(&mut self, sh: &Shared, r: RungId) -> Option<Row> {
        let (shape, slots) = shape(sh, &sh.p.rung(r).series)?;
        let next = self.shapes.len() as u32;
        let kernel = *self.ids.entry(shape.clone()).or_insert_with(|| next);
        if kernel == next {
            self.shapes.push(shape);
        }
        Some(Row { kernel, slots })
    }

    pub fn is_empty(&self) -> bool {
        self.shapes.is_empty()
    }

    /// `plc_rows.c`: every kernel's function.
    pub fn source(&self) -> String {
        let mut s = String::from(
            "/* plc_rows.c: the loops that run the rows of the tables, one per rung shape \
             (docs/c.md). */\n#include \"plc_runtime.h\"\n\n",
        );
        for (k, shape) in self.shapes.iter().enumerate() {
            s.push_str(&kernel(k, shape));
        }
        s
    }
}

/// The declaration of kernel `k`.
fn kernel_decl(k: u32) -> String {
    format!("void _pou__k{k}(uint8_t *s, const uint32_t *t, size_t n)")
}

/// The C of kernel `k`: one loop over `n` rows of `shape`.
fn kernel(k: usize, shape: &Shape) -> String {
    let mut pre = String::new();
    let mut next = shape.outs.len() + shape.lits + usize::from(shape.lits > 0);
    let mut cond = and_expr(&shape.cond, &mut next, &mut pre);
    if shape.lits > 0 {
        // The contacts' bytes as the bits of a word, compared with the pattern the row's
        // contacts pass on (bit i set: contact i is Normal).
        let o = shape.outs.len();
        let bits: Vec<String> = (0..shape.lits)
            .map(|i| match i {
                0 => format!("(unsigned)s[t[{o}]]"),
                _ => format!("(unsigned)s[t[{}]] << {i}", o + i),
            })
            .collect();
        push(&mut pre, format_args!("        unsigned q = {};\n", bits.join(" | ")));
        let eq = format!("(q == t[{}])", o + shape.lits);
        cond = if shape.cond.is_empty() { eq } else { format!("{eq} & {cond}") };
    }
    let mut body = pre;
    push(&mut body, format_args!("        unsigned p = {cond};\n"));
    for (i, o) in shape.outs.iter().enumerate() {
        let stmt = match o {
            Out::Coil => format!("s[t[{i}]] = p;"),
            Out::NegCoil => format!("s[t[{i}]] = p ^ 1;"),
            Out::Set => format!("s[t[{i}]] |= p;"),
            Out::Reset => format!("s[t[{i}]] &= p ^ 1;"),
        };
        push(&mut body, format_args!("        {stmt}\n"));
    }
    format!(
        "_PLC_KERNEL {} {{\n    for (; n; n--, t += {}) {{\n{body}    }}\n}}\n\n",
        kernel_decl(k as u32).trim_start_matches("void "),
        shape.slots()
    )
}

/// The C expression of an AND of items whose slots start at `*next`; edge pulses are computed
/// into locals by statements appended to `pre`.
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
            Item::Edge(falling) => {
                let (v, m) = (*next, *next + 1);
                *next += 2;
                let pulse = if *falling {
                    format!("(s[t[{v}]] ^ 1) & s[t[{m}]]")
                } else {
                    format!("s[t[{v}]] & (s[t[{m}]] ^ 1)")
                };
                push(
                    pre,
                    format_args!("        unsigned e{v} = {pulse};\n        s[t[{m}]] = s[t[{v}]];\n"),
                );
                format!("e{v}")
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

/// The shape of `series` and its slots, if it is a row.
fn shape(sh: &Shared, series: &Series) -> Option<(Shape, Vec<u32>)> {
    let (out, cond) = series.split_last()?;
    let mut outs = Vec::new();
    match out {
        Element::Branch(paths) => {
            for path in paths {
                match path.as_slice() {
                    [e] => outs.push(output(sh, e)?),
                    _ => return None,
                }
            }
        }
        e => outs.push(output(sh, e)?),
    }
    if outs.is_empty() {
        return None;
    }
    let items = and_items(sh, cond, true)?;
    let mut slots: Vec<u32> = outs.iter().map(|o| o.1).collect();
    let (mut cond, mut rest) = (Vec::new(), Vec::new());
    let mut pattern = 0u32;
    for (item, s) in items {
        match item {
            Item::Lit(neg) => {
                if slots.len() - outs.len() == 32 {
                    return None; // more contacts than the pattern word has bits
                }
                pattern |= u32::from(!neg) << (slots.len() - outs.len());
                slots.extend(s);
            }
            item => {
                cond.push(item);
                rest.extend(s);
            }
        }
    }
    let lits = slots.len() - outs.len();
    if lits > 0 {
        slots.push(pattern);
    }
    slots.extend(rest);
    let outs = outs.into_iter().map(|o| o.0).collect();
    Some((Shape { lits, cond, outs }, slots))
}

/// The items of an AND (sorted, each with its slots); `top`: edge contacts are allowed.
fn and_items(sh: &Shared, series: &[Element], top: bool) -> Option<Vec<(Item, Vec<u32>)>> {
    let mut items = Vec::with_capacity(series.len());
    for e in series {
        items.push(item(sh, e, top)?);
    }
    // Stable: equal items keep their order (their slots then differ only by variable).
    items.sort_by(|a, b| a.0.cmp(&b.0));
    Some(items)
}

fn item(sh: &Shared, e: &Element, top: bool) -> Option<(Item, Vec<u32>)> {
    match e {
        Element::Contact { var, kind } => {
            let v = contact(sh, *var)?;
            match kind {
                ContactKind::Normal => Some((Item::Lit(false), vec![v])),
                ContactKind::Negated => Some((Item::Lit(true), vec![v])),
                ContactKind::Rising { memory } | ContactKind::Falling { memory } if top => {
                    let m = sh.bool_at[memory.index()]?;
                    let falling = matches!(kind, ContactKind::Falling { .. });
                    Some((Item::Edge(falling), vec![v, m]))
                }
                _ => None,
            }
        }
        Element::Or(branches) if !branches.is_empty() => {
            let mut bs = Vec::with_capacity(branches.len());
            for b in branches {
                let items = and_items(sh, b, false)?;
                if items.is_empty() {
                    return None; // an empty branch passes power: left to the statements
                }
                bs.push(items);
            }
            bs.sort_by(|a, b| {
                let ka = a.iter().map(|x| &x.0);
                ka.cmp(b.iter().map(|x| &x.0))
            });
            let shape = bs
                .iter()
                .map(|b| b.iter().map(|x| x.0.clone()).collect())
                .collect();
            let slots = bs.into_iter().flatten().flat_map(|x| x.1).collect();
            Some((Item::Or(shape), slots))
        }
        _ => None,
    }
}

/// An output element as a row output.
fn output(sh: &Shared, e: &Element) -> Option<(Out, u32)> {
    let (var, out) = match *e {
        Element::Coil {
            var,
            negated: false,
        } => (var, Out::Coil),
        Element::Coil { var, negated: true } => (var, Out::NegCoil),
        Element::Set(var) => (var, Out::Set),
        Element::Reset(var) => (var, Out::Reset),
        _ => return None,
    };
    Some((out, bool_at(sh, var)?))
}

/// The offset of a BOOL variable of the state.
fn bool_at(sh: &Shared, v: VarId) -> Option<u32> {
    (sh.p.var(v).ty == Type::Bool).then_some(())?;
    sh.bool_at[v.index()]
}

/// The offset of a contact's BOOL (a whole BOOL variable of the state; fields of instances
/// are no rows).
fn contact(sh: &Shared, r: VarRef) -> Option<u32> {
    match r.field {
        None => bool_at(sh, r.var),
        Some(_) => None,
    }
}

/// The rows of the functions of one source file: a table per kernel (data file
/// `plc_table{file}.c`), and the run not yet called (its kernel and first row).
pub(crate) struct Tables {
    file: usize,
    tables: BTreeMap<u32, Table>,
    run: Option<(u32, usize)>,
}

/// One table: the initializer text of its rows, how many, the slots per row.
struct Table {
    text: String,
    count: usize,
    stride: usize,
}

impl Tables {
    pub fn new(file: usize) -> Tables {
        Tables {
            file,
            tables: BTreeMap::new(),
            run: None,
        }
    }

    /// Adds `row` (rung `id`); the call of the run it ends, if it starts another.
    pub fn push(&mut self, row: &Row, id: &str) -> Option<String> {
        let call = match self.run {
            Some((k, _)) if k != row.kernel => self.take_call(),
            _ => None,
        };
        let t = self.tables.entry(row.kernel).or_insert_with(|| Table {
            text: String::new(),
            count: 0,
            stride: row.slots.len(),
        });
        if self.run.is_none() {
            self.run = Some((row.kernel, t.count));
        }
        let nums: Vec<String> = row.slots.iter().map(u32::to_string).collect();
        push(
            &mut t.text,
            format_args!("    {}, /* {id} */\n", nums.join(", ")),
        );
        t.count += 1;
        call
    }

    /// The call of the run of rows pushed since the last call, if any.
    pub fn take_call(&mut self) -> Option<String> {
        let (k, first) = self.run.take()?;
        let t = &self.tables[&k];
        Some(format!(
            "_pou__k{k}((uint8_t *)self, _pou__t{}_{k} + {}, {});",
            self.file,
            first * t.stride,
            t.count - first
        ))
    }

    /// The declarations the functions' C needs (empty: no rows).
    pub fn declarations(&self) -> String {
        let mut s = String::new();
        for &k in self.tables.keys() {
            push(
                &mut s,
                format_args!(
                    "extern const uint32_t _pou__t{}_{k}[];\n{};\n",
                    self.file,
                    kernel_decl(k)
                ),
            );
        }
        s
    }

    /// The data file (name stem, text), if there are rows.
    pub fn data_file(&self) -> Option<(String, String)> {
        if self.tables.is_empty() {
            return None;
        }
        let mut s = String::from("/* Rows of contacts and coils: byte offsets (docs/c.md). */\n#include <stdint.h>\n\n");
        for (k, t) in &self.tables {
            push(
                &mut s,
                format_args!(
                    "const uint32_t _pou__t{}_{k}[{}] = {{\n{}}};\n",
                    self.file,
                    t.count * t.stride,
                    t.text
                ),
            );
        }
        Some((format!("plc_table{}", self.file), s))
    }
}
