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
//! contacts on BOOLs of the state (variables, or the Q of a timer or counter instance of the
//! state) and compares of INTs (variables of the state, a counter's CV or PV, or INT
//! constants), with ORs of series of those (no empty branch), then outputs and boxes in series:
//! coil, negated coil, set or reset of a BOOL variable of the state; INT moves and INT ADD,
//! SUB, MUL, DIV and MOD boxes; TON, TOF and TP with a constant preset of 0 to 65,535 ms, and
//! CTU and CTD whose PV is an INT and whose reset or load a BOOL of the state or a constant
//! (their Q is the power after them); the last may be an output branch whose paths are one
//! output or INT box each. Jumps, FOR/NEXT, calls, returns, SR/RS, R_TRIG/F_TRIG, CTUD,
//! variable presets, standard functions and arithmetic on other types stay statements.
//! Its shape is that tree in a canonical form: the top-level Normal and Negated contacts are a
//! count, padded to 4, 6 or 8 (which are negated is the row's pattern word, and padded slots
//! are masked out by its care bits); the other items of every AND are sorted, the branches of
//! every OR too — exact since contacts and compares have no side effects, and an edge contact's
//! only effect is on its own hidden memory, which no other contact reads; so rungs that differ
//! only in the order or the negations of their contacts share one kernel. What is data, not
//! shape: a BOOL output's kind (coil, negated coil, set, reset: the new value is looked up in a
//! table of 16 bytes by kind, power and old value), an edge's direction, a compare's operator,
//! the operator of an arithmetic or DIV/MOD box and the kind of a timer or counter. The row's
//! slots are the outputs' (the BOOL and its kind; a box's target, kind and operands; a DIV or
//! MOD's rung), then the contacts' offsets and the pattern word, then the other items' (an edge
//! contact: its BOOL, its memory, its direction; a compare: its two operands and operator).
//!
//! The kernels (`kernel`) evaluate as the interpreter does. Offsets are the generator's own
//! (`mod::member_offsets`: the BOOLs, the INTs, the counters, then the timers, first in
//! `_plc_state`, checked by `_Static_assert`s), so table files need no struct and no
//! `offsetof`: they are data only.
//!
//! Consecutive rows of one kernel in a function make one run, one call
//! `_pou__kK((uint8_t *)self, _pou__tF + first, count, ctx)`; any other line of C (a rung that is no
//! row, a label, the function's end) ends the run first, so rows run in the order they are
//! emitted. Only ladder functions of POUs use rows (not FBD bodies or function block types,
//! whose variables may be locals or another struct's members). The emission order itself (rungs
//! of one dependence level grouped by kernel) is `order`'s.
//!
//! Not here: the C of the rungs that are no row (`ladder`), the order of the rungs (`order`),
//! the files (`mod`); the shape and row types (`shape`), the tables and their runs (`table`).

use super::kernel;
use super::ladder::Shared;
use super::shape::{Item, Out, Row, Shape};
use plc_model::{
    ArithOp, CmpOp, ContactKind, Element, FbKind, Field, Operand, RungId, TimerKind, Type, Value,
    VarId, VarRef,
};
use std::collections::HashMap;

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
    pub(super) fn row(&mut self, sh: &Shared, r: RungId) -> Option<Row> {
        let (shape, slots) = shape(sh, r)?;
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
    pub(super) fn entry_type(&self) -> &'static str {
        if self.wide {
            "uint32_t"
        } else {
            "uint16_t"
        }
    }

    /// The kernels' source files (name stem, text): `plc_rows.c`, or with more than
    /// [`kernel::PER_FILE`] kernels `plc_rows0.c`, `plc_rows1.c` … (`make -j` compiles them in
    /// parallel).
    pub(super) fn sources(&self) -> Vec<(String, String)> {
        kernel::sources(&self.shapes, self.entry_type())
    }
}

/// The mask of a compare's operator over `(a < b) | (a == b) << 1` (bit 0: a > b, bit 1:
/// a < b, bit 2: a == b).
fn cmp_mask(op: CmpOp) -> u32 {
    match op {
        CmpOp::Eq => 0b100,
        CmpOp::Ne => 0b011,
        CmpOp::Lt => 0b010,
        CmpOp::Le => 0b110,
        CmpOp::Gt => 0b001,
        CmpOp::Ge => 0b101,
    }
}

/// Rung `r`'s shape and its slots, if it is a row: a condition (contacts, compares, ORs),
/// then outputs and boxes in series, the last of which may be an output branch whose paths are
/// one output or INT box each.
fn shape(sh: &Shared, r: RungId) -> Option<(Shape, Vec<u32>)> {
    let series = &sh.p.rung(r).series;
    let n = series
        .iter()
        .position(|e| {
            !matches!(
                e,
                Element::Contact { .. } | Element::Compare { .. } | Element::Or(_)
            )
        })
        .unwrap_or(series.len());
    let (cond, acts) = series.split_at(n);
    let mut outs: Vec<(Out, Vec<u32>)> = Vec::new();
    for (i, e) in acts.iter().enumerate() {
        match e {
            Element::Branch(paths) if i + 1 == acts.len() => {
                for path in paths {
                    match path.as_slice() {
                        [e] => outs.push(action(sh, r, e).filter(|o| !o.0.takes_q())?),
                        _ => return None,
                    }
                }
            }
            e => outs.push(action(sh, r, e)?),
        }
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

/// The items of an AND (sorted, each with its slots); `top`: the rung's top-level AND.
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
                ContactKind::Normal if top => Some((Item::Lit(false), vec![v])),
                ContactKind::Negated if top => Some((Item::Lit(true), vec![v])),
                ContactKind::Normal => Some((Item::Contact, vec![v, 0])),
                ContactKind::Negated => Some((Item::Contact, vec![v, 1])),
                ContactKind::Rising { memory } | ContactKind::Falling { memory } => {
                    let m = bool_at(sh, *memory)?;
                    let falling = matches!(kind, ContactKind::Falling { .. });
                    Some((Item::Edge, vec![v, m, u32::from(falling)]))
                }
            }
        }
        Element::Compare { op, a, b } => {
            let (a, b) = (int_slot(sh, a)?, int_slot(sh, b)?);
            let mask = cmp_mask(*op);
            if a.1 && !b.1 {
                // A constant before a variable: the mirrored compare (`<` for `>`), so that
                // both orders share a kernel.
                let mirrored = (mask & 0b100) | (mask & 1) << 1 | (mask & 2) >> 1;
                return Some((Item::Cmp(false, true), vec![b.0, a.0, mirrored]));
            }
            Some((Item::Cmp(a.1, b.1), vec![a.0, b.0, mask]))
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

/// An output or a box of rung `r` as a row output (its slots: target, then the rest).
fn action(sh: &Shared, r: RungId, e: &Element) -> Option<(Out, Vec<u32>)> {
    let target = |v: VarId| (sh.p.var(v).ty == Type::Int).then(|| sh.at[v.index()])?;
    let bit = |var: VarId, kind: u32| Some((Out::Bit, vec![bool_at(sh, var)?, kind]));
    match *e {
        Element::Coil {
            var,
            negated: false,
        } => bit(var, 0),
        Element::Coil { var, negated: true } => bit(var, 1),
        Element::Set(var) => bit(var, 2),
        Element::Reset(var) => bit(var, 3),
        Element::Move { from, to } => {
            let (f, c) = int_slot(sh, &from)?;
            Some((Out::Move(c), vec![target(to)?, f]))
        }
        Element::Arith { op, a, b, out } => {
            let ((a, ca), (b, cb)) = (int_slot(sh, &a)?, int_slot(sh, &b)?);
            let to = target(out)?;
            Some(match op {
                ArithOp::Add => (Out::Arith(ca, cb), vec![to, 0, a, b]),
                ArithOp::Sub => (Out::Arith(ca, cb), vec![to, 1, a, b]),
                ArithOp::Mul => (Out::Arith(ca, cb), vec![to, 2, a, b]),
                ArithOp::Div => (Out::DivMod(ca, cb), vec![to, 0, a, b, r.raw()]),
                ArithOp::Mod => (Out::DivMod(ca, cb), vec![to, 1, a, b, r.raw()]),
            })
        }
        Element::Timer { kind, instance, pt } => {
            let Operand::Const(Value::Time(ms)) = pt else {
                return None; // a variable preset: left to the statements
            };
            let ms = u16::try_from(ms).ok()?;
            let kind = match kind {
                TimerKind::Ton => 0,
                TimerKind::Tof => 1,
                TimerKind::Tp => 2,
            } | u32::from(sh.p.dialect().timer_compares_after_edge()) << 2;
            let at = fb_at(sh, instance, &[FbKind::Ton, FbKind::Tof, FbKind::Tp])?;
            Some((Out::Timer, vec![at, kind, u32::from(ms)]))
        }
        Element::Ctu {
            instance,
            pv,
            reset: r,
        }
        | Element::Ctd {
            instance,
            pv,
            load: r,
        } => {
            let kind = u32::from(matches!(e, Element::Ctd { .. }))
                | u32::from(sh.p.dialect().counters_stop_at_preset()) << 1;
            let at = fb_at(sh, instance, &[FbKind::Ctu, FbKind::Ctd])?;
            let ((pv, cp), (r, cr)) = (int_slot(sh, &pv)?, bool_slot(sh, &r)?);
            Some((Out::Counter(cp, cr), vec![at, kind, pv, r]))
        }
        _ => None,
    }
}

/// The offset of an instance of one of the kinds `kinds` in the state.
fn fb_at(sh: &Shared, v: VarId, kinds: &[FbKind]) -> Option<u32> {
    match sh.p.var(v).ty {
        Type::Fb(k) if kinds.contains(&k) => sh.at[v.index()],
        _ => None,
    }
}

/// An INT operand's slot: a variable's offset (false) or a constant's bits (true). A counter's
/// CV and PV are INTs of the state too (at 2 and 4 in `_plc_counter`).
fn int_slot(sh: &Shared, o: &Operand) -> Option<(u32, bool)> {
    match *o {
        Operand::Const(Value::Int(v)) => Some((u32::from(v as u16), true)),
        Operand::Var(VarRef { var, field: None }) if sh.p.var(var).ty == Type::Int => {
            Some((sh.at[var.index()]?, false))
        }
        Operand::Var(VarRef {
            var,
            field: Some(f @ (Field::Cv | Field::Pv)),
        }) => {
            let at = fb_at(sh, var, &[FbKind::Ctu, FbKind::Ctd])?;
            Some((at + if f == Field::Cv { 2 } else { 4 }, false))
        }
        _ => None,
    }
}

/// A BOOL operand's slot: a BOOL's offset (false) or a constant 0 or 1 (true).
fn bool_slot(sh: &Shared, o: &Operand) -> Option<(u32, bool)> {
    match *o {
        Operand::Const(Value::Bool(b)) => Some((u32::from(b), true)),
        Operand::Var(r) => Some((contact(sh, r)?, false)),
        Operand::Const(_) => None,
    }
}

/// The offset of a BOOL variable of the state.
fn bool_at(sh: &Shared, v: VarId) -> Option<u32> {
    (sh.p.var(v).ty == Type::Bool).then_some(())?;
    sh.at[v.index()]
}

/// The offset of a contact's BOOL: a BOOL variable of the state, or the Q of a timer or
/// counter of the state (at 0 in `_plc_timer` and `_plc_counter`).
fn contact(sh: &Shared, r: VarRef) -> Option<u32> {
    match r.field {
        None => bool_at(sh, r.var),
        Some(Field::Q) => fb_at(
            sh,
            r.var,
            &[
                FbKind::Ton,
                FbKind::Tof,
                FbKind::Tp,
                FbKind::Ctu,
                FbKind::Ctd,
            ],
        ),
        Some(_) => None,
    }
}
