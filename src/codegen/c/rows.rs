//! Rungs of contacts and coils as data: each such rung is a row of plain numbers (byte offsets,
//! a pattern word, output kinds, INT constants) in a table, run by a small loop generated for
//! its *shape* (a kernel), instead of C statements per rung.
//!
//! Why: `cc -O2` spends about a millisecond of CPU on each rung written as statements (spread
//! over all its passes), so 100,000 rungs as statements take minutes to build however they are
//! written. A row costs only the parsing of a few integers, and a kernel is a loop of a few
//! lines, compiled once for every rung of its shape. Because the kernel is specialised (its
//! contact count, ORs, edges, compares and boxes are C code) a row runs about as fast as the
//! statements (docs/c.md).
//!
//! A rung is a row when its series is a condition of Normal, Negated, Rising and Falling
//! contacts on BOOL variables of the state and compares of INTs (variables of the state or
//! INT constants), with ORs of series of those (no edge inside an OR, no empty branch), then
//! optionally INT moves and ADD/SUB/MUL boxes, then one output or an output branch of single
//! outputs or INT boxes: coil, negated coil, set or reset of BOOL variables of the state.
//! Its shape is that tree in a canonical form: the top-level Normal and Negated contacts are a
//! count, padded to 4, 6 or 8 (which are negated is the row's pattern word, and padded slots
//! are masked out by its care bits); the other items of every AND are sorted, the branches of
//! every OR too — exact since contacts and compares have no side effects, and an edge contact's
//! only effect is on its own hidden memory, which no other contact reads; so rungs that differ
//! only in the order or the negations of their contacts share one kernel. A BOOL output's kind
//! (coil, negated coil, set, reset) is data too: the new value is looked up in a table of 16
//! bytes by kind, power and old value. The row's slots are the outputs' (the BOOL and its kind;
//! a box's target and operands), then the contacts' offsets and the pattern word, then the
//! other items' (an edge contact: its BOOL, then its memory; a compare: its two operands).
//!
//! The kernel evaluates as the interpreter does (docs/scan.md): every edge contact computes its
//! pulse (rising `v & !m`, falling `!v & m`) and its memory takes `v`, and every contact and
//! compare is read, before the first output is written; the outputs and boxes are written in
//! order (coil `p`, negated coil `!p`, set `old | p`, reset `old & !p`; a box only when
//! powered). BOOLs are the bytes 0 and 1 of C `bool`s, read and written through `uint8_t`,
//! which may alias anything; INTs are read and written as `int16_t`. Offsets are the
//! generator's own (`mod::member_offsets`: the BOOLs, then the INTs, first in `_plc_state`,
//! checked by `_Static_assert`s), so table files need no struct and no `offsetof`: they are
//! data only.
//!
//! Consecutive rows of one kernel in a function make one run, one call
//! `_pou__kK((uint8_t *)self, _pou__tF + first, count)`; any other line of C (a rung that is no
//! row, a label, the function's end) ends the run first, so rows run in the order they are
//! emitted. Only ladder functions of POUs use rows (not FBD bodies or function block types,
//! whose variables may be locals or another struct's members). The emission order itself (rungs
//! of one dependence level grouped by kernel) is `order`'s.
//!
//! Not here: the C of the rungs that are no row (`ladder`), the order of the rungs (`order`),
//! the files (`mod`).

use super::ladder::{push, Shared};
use crate::model::{
    ArithOp, ContactKind, Element, Operand, RungId, Series, Type, Value, VarId, VarRef,
};
use std::collections::{BTreeSet, HashMap};

/// A condition item of a shape, in its canonical order (derived `Ord`: positive contacts,
/// negated contacts, rising edges, falling edges, ORs).
#[derive(Clone, Debug, PartialEq, Eq, PartialOrd, Ord, Hash)]
enum Item {
    /// A Normal (false) or Negated (true) contact.
    Lit(bool),
    /// An edge contact: falling (true) or rising (false).
    Edge(bool),
    /// A comparison of two INTs (`==`, `<` …), each a variable or a constant (true).
    Cmp(&'static str, bool, bool),
    /// An OR of ANDs (each with at least one item).
    Or(Vec<Vec<Item>>),
}

/// An output of a shape, or a box before or beside the outputs (which passes power on).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
enum Out {
    /// A coil, negated coil, set or reset of a BOOL: which one is data (slots: the BOOL, the
    /// kind 0–3, looked up in `_pou__bit` with the power and the old value).
    Bit,
    /// An INT move from a variable or a constant (true).
    Move(bool),
    /// INT `+`, `-` or `*` (wrapping, `_plc_add_i16` …) of variables or constants (true).
    Arith(&'static str, bool, bool),
}

impl Out {
    /// Its slots: the target, then the operands.
    fn slots(self) -> usize {
        match self {
            Out::Bit | Out::Move(_) => 2,
            Out::Arith(..) => 3,
        }
    }
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
                    Item::Edge(_) | Item::Cmp(..) => 2,
                    Item::Or(bs) => bs.iter().map(|b| count(b)).sum(),
                })
                .sum()
        }
        self.out_slots() + self.lits + usize::from(self.lits > 0) + count(&self.cond)
    }

    fn out_slots(&self) -> usize {
        self.outs.iter().map(|o| o.slots()).sum()
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
    /// Some slot of some row is 65,536 or more: the tables hold `uint32_t`, not `uint16_t`.
    wide: bool,
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
        self.wide |= slots.iter().any(|&v| v > u32::from(u16::MAX));
        Some(Row { kernel, slots })
    }

    /// The C type of the tables' entries: 16 bits when every slot fits (half the bytes a
    /// scan reads from the tables), else 32.
    pub fn entry_type(&self) -> &'static str {
        if self.wide {
            "uint32_t"
        } else {
            "uint16_t"
        }
    }

    pub fn is_empty(&self) -> bool {
        self.shapes.is_empty()
    }

    /// `plc_rows.c`: every kernel's function.
    pub fn source(&self) -> String {
        let mut s = String::from(
            "/* plc_rows.c: the loops that run the rows of the tables, one per rung shape \
             (docs/c.md). */\n#include \"plc_runtime.h\"\n\n\
             /* A BOOL output's new value: _pou__bit[kind | power << 2 | old << 3], kind 0 coil, \
             1 negated coil, 2 set, 3 reset. */\n\
             static const uint8_t _pou__bit[16] = {0, 1, 0, 0, 1, 0, 1, 0, 0, 1, 1, 1, 1, 0, 1, 0};\n\n",
        );
        for (k, shape) in self.shapes.iter().enumerate() {
            s.push_str(&kernel(k, shape, self.entry_type()));
        }
        s
    }
}

/// The declaration of kernel `k` over tables of `ty`.
fn kernel_decl(k: u32, ty: &str) -> String {
    format!("void _pou__k{k}(uint8_t *s, const {ty} *t, size_t n)")
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
    for o in &shape.outs {
        let int = |k: usize| format!("*(int16_t *)(s + t[{k}])");
        let stmt = match *o {
            Out::Bit => format!(
                "s[t[{i}]] = _pou__bit[t[{}] | p << 2 | (unsigned)s[t[{i}]] << 3];",
                i + 1
            ),
            Out::Move(c) => format!("{0} = p ? {1} : {0};", int(i), int_operand(i + 1, c)),
            Out::Arith(f, ca, cb) => format!(
                "{0} = p ? _plc_{f}_i16({1}, {2}) : {0};",
                int(i),
                int_operand(i + 1, ca),
                int_operand(i + 2, cb)
            ),
        };
        i += o.slots();
        push(&mut body, format_args!("        {stmt}\n"));
    }
    format!(
        "_PLC_KERNEL {} {{\n    for (; n; n--, t += {}) {{\n{body}    }}\n}}\n\n",
        kernel_decl(k as u32, ty).trim_start_matches("void "),
        shape.slots()
    )
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
                    format_args!(
                        "        unsigned e{v} = {pulse};\n        s[t[{m}]] = s[t[{v}]];\n"
                    ),
                );
                format!("e{v}")
            }
            Item::Cmp(op, ca, cb) => {
                *next += 2;
                let (a, b) = (int_operand(*next - 2, *ca), int_operand(*next - 1, *cb));
                format!("({a} {op} {b})")
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
    let (out, rest) = series.split_last()?;
    // The boxes directly before the output run, when powered, before it.
    let n = rest
        .iter()
        .rposition(|e| int_box(sh, e).is_none())
        .map_or(0, |i| i + 1);
    let (cond, boxes) = rest.split_at(n);
    let mut outs: Vec<(Out, Vec<u32>)> = Vec::new();
    for e in boxes {
        outs.push(int_box(sh, e)?);
    }
    match out {
        Element::Branch(paths) => {
            for path in paths {
                match path.as_slice() {
                    [e] => outs.push(output(sh, e).or_else(|| int_box(sh, e))?),
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
    let out_slots = outs.iter().map(|o| o.1.len()).sum::<usize>();
    let mut slots: Vec<u32> = outs.iter().flat_map(|o| o.1.clone()).collect();
    let (mut cond, mut rest) = (Vec::new(), Vec::new());
    let mut pattern = 0u32;
    for (item, s) in items {
        match item {
            Item::Lit(neg) => {
                if slots.len() - out_slots == 8 {
                    return None; // more contacts than the pattern word has bits
                }
                pattern |= u32::from(!neg) << (slots.len() - out_slots);
                slots.extend(s);
            }
            item => {
                cond.push(item);
                rest.extend(s);
            }
        }
    }
    let real = slots.len() - out_slots;
    // Padded to a class of 4, 6 or 8 contacts (fewer kernels, longer runs): a padded contact
    // reads the first output's byte and is masked out of the comparison.
    let lits = match real {
        0 => 0,
        1..=4 => 4,
        5 | 6 => 6,
        _ => 8,
    };
    let care = (1u32 << real) - 1;
    slots.resize(out_slots + lits, slots[0]);
    if lits > 0 {
        slots.push(pattern | care << 8);
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
                    let m = bool_at(sh, *memory)?;
                    let falling = matches!(kind, ContactKind::Falling { .. });
                    Some((Item::Edge(falling), vec![v, m]))
                }
                _ => None,
            }
        }
        Element::Compare { op, a, b } => {
            let (a, b) = (int_slot(sh, a)?, int_slot(sh, b)?);
            let sym = super::spelling::cmp_symbol(*op);
            Some((Item::Cmp(sym, a.1, b.1), vec![a.0, b.0]))
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

/// An INT move or `+`, `-`, `*` box as a row output (its slots: target, operands).
fn int_box(sh: &Shared, e: &Element) -> Option<(Out, Vec<u32>)> {
    let target = |v: VarId| (sh.p.var(v).ty == Type::Int).then(|| sh.at[v.index()])?;
    match e {
        Element::Move { from, to } => {
            let (f, c) = int_slot(sh, from)?;
            Some((Out::Move(c), vec![target(*to)?, f]))
        }
        Element::Arith { op, a, b, out } => {
            let f = match op {
                ArithOp::Add => "add",
                ArithOp::Sub => "sub",
                ArithOp::Mul => "mul",
                ArithOp::Div | ArithOp::Mod => return None, // they may record a fault
            };
            let ((a, ca), (b, cb)) = (int_slot(sh, a)?, int_slot(sh, b)?);
            Some((Out::Arith(f, ca, cb), vec![target(*out)?, a, b]))
        }
        _ => None,
    }
}

/// An INT operand's slot: a variable's offset (false) or a constant's bits (true).
fn int_slot(sh: &Shared, o: &Operand) -> Option<(u32, bool)> {
    match *o {
        Operand::Const(Value::Int(v)) => Some((u32::from(v as u16), true)),
        Operand::Var(VarRef { var, field: None }) if sh.p.var(var).ty == Type::Int => {
            Some((sh.at[var.index()]?, false))
        }
        _ => None,
    }
}

/// An output element as a row output.
fn output(sh: &Shared, e: &Element) -> Option<(Out, Vec<u32>)> {
    let (var, kind) = match *e {
        Element::Coil {
            var,
            negated: false,
        } => (var, 0),
        Element::Coil { var, negated: true } => (var, 1),
        Element::Set(var) => (var, 2),
        Element::Reset(var) => (var, 3),
        _ => return None,
    };
    Some((Out::Bit, vec![bool_at(sh, var)?, kind]))
}

/// The offset of a BOOL variable of the state.
fn bool_at(sh: &Shared, v: VarId) -> Option<u32> {
    (sh.p.var(v).ty == Type::Bool).then_some(())?;
    sh.at[v.index()]
}

/// The offset of a contact's BOOL (a whole BOOL variable of the state; fields of instances
/// are no rows).
fn contact(sh: &Shared, r: VarRef) -> Option<u32> {
    match r.field {
        None => bool_at(sh, r.var),
        Some(_) => None,
    }
}

/// The rows of the functions of one source file: one table (data file `plc_table{file}.c`)
/// that holds them in the order they run, whatever their kernels, so a scan reads it front to
/// back (with a table per kernel, every short run started on a cache line of its own); the
/// kernels used, and the run not yet called (its kernel, first entry, rows).
pub(crate) struct Tables {
    file: usize,
    /// The C type of the entries (`Kernels::entry_type`).
    ty: &'static str,
    text: String,
    entries: usize,
    used: BTreeSet<u32>,
    run: Option<(u32, usize, usize)>,
}

impl Tables {
    pub fn new(file: usize, ty: &'static str) -> Tables {
        Tables {
            file,
            ty,
            text: String::new(),
            entries: 0,
            used: BTreeSet::new(),
            run: None,
        }
    }

    /// Adds `row` (rung `id`); the call of the run it ends, if it starts another.
    pub fn push(&mut self, row: &Row, id: &str) -> Option<String> {
        let call = match self.run {
            Some((k, _, _)) if k != row.kernel => self.take_call(),
            _ => None,
        };
        match &mut self.run {
            Some((_, _, n)) => *n += 1,
            None => self.run = Some((row.kernel, self.entries, 1)),
        }
        self.used.insert(row.kernel);
        let nums: Vec<String> = row.slots.iter().map(u32::to_string).collect();
        push(
            &mut self.text,
            format_args!("    {}, /* {id} */\n", nums.join(", ")),
        );
        self.entries += row.slots.len();
        call
    }

    /// The call of the run of rows pushed since the last call, if any.
    pub fn take_call(&mut self) -> Option<String> {
        let (k, first, n) = self.run.take()?;
        Some(format!(
            "_pou__k{k}((uint8_t *)self, _pou__t{} + {first}, {n});",
            self.file
        ))
    }

    /// The declarations the functions' C needs (empty: no rows).
    pub fn declarations(&self) -> String {
        if self.entries == 0 {
            return String::new();
        }
        let mut s = format!("extern const {} _pou__t{}[];\n", self.ty, self.file);
        for &k in &self.used {
            push(&mut s, format_args!("{};\n", kernel_decl(k, self.ty)));
        }
        s
    }

    /// The data file (name stem, text), if there are rows.
    pub fn data_file(&self) -> Option<(String, String)> {
        if self.entries == 0 {
            return None;
        }
        Some((
            format!("plc_table{}", self.file),
            format!(
                "/* Rows of contacts and coils: byte offsets (docs/c.md). */\n#include <stdint.h>\n\n\
                 const {} _pou__t{}[{}] = {{\n{}}};\n",
                self.ty, self.file, self.entries, self.text
            ),
        ))
    }
}
