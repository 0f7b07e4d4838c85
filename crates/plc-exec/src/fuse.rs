//! Whole-rung superinstructions: a rung that is only plain contacts (in series and in `or`s of
//! series, at most [`MAX_CONTACTS`] in all) followed by one output (coil, negated coil, set or
//! reset) is lowered to one `Op::Fused` (`lower`) instruction instead of a rung marker,
//! contact instructions, `or` brackets and an output. Any other rung that starts with such
//! contacts gets one `Op::FusedHead` (`lower`) for its marker and those contacts (the
//! power they give, from the same kind of table), then the general instructions of the rest.
//!
//! At run time such a rung loads its contacts' bytes (always [`MAX_CONTACTS`] loads: slots past
//! the rung's contacts repeat a byte the rung reads anyway), packs them into an 8-bit index, xors
//! in the negation bits, adds the output's old value as bit 8 and reads the output's new value
//! from the rung's table (512 bits, 64 bytes): one uniform, branch-free instruction per
//! rung, whatever the mix of series and `or`s, the kind of output and the values. Tables are
//! shared: most rungs of a program have one of a few shapes (`n` contacts in series, one `or` of
//! two contacts then a series...) and one of four outputs, so the tables stay few and in the
//! first-level cache.
//!
//! Why this is exact: plain contacts have no side effects and an `or` of such series evaluates
//! every branch from the same power in (`exec` module docs), so the rung's power before its
//! output is a pure boolean function of its contacts' values, and the output's new value a
//! function of that power and its old value (a set or reset without power keeps it: the old
//! value is written back), which is what the table holds (computed once per distinct shape and
//! output). The power after the output is not kept: the next instruction starts a rung or ends
//! the POU. Rungs with an `or` of no branch (power passes unchanged) or anything else (edge
//! contacts, compares, boxes, jumps, several outputs) are not fused whole: they keep the general
//! instructions, after a head when they start with plain contacts.
//!
//! This is the superinstruction of fast interpreters (Ertl and Gregg 2003: fewer, larger
//! dispatches for the most frequent instruction sequences). Not here: the general instructions
//! (`lower`, `run`).

use super::output_mode::{OUT_COIL, OUT_NCOIL, OUT_RESET, OUT_SET};
use super::store::Addr;
use plc_model::{index_type, ContactKind, Element, VarId, VarRef};
use std::collections::HashMap;

/// Contacts a fused rung may have: one byte of truth-table index.
pub(crate) const MAX_CONTACTS: usize = 8;

index_type!(
    /// A fused rung's operands: index into the machine's `fused`.
    FusedId
);

/// The operands of a fused rung: its contacts' bytes (padded) and its output's byte.
#[derive(Copy, Clone, Debug)]
pub(crate) struct FusedRung {
    /// Contact `k`'s byte; slots past the rung's contacts repeat slot 0 (or the output's byte
    /// when the rung has no contact). The table ignores them.
    pub at: [Addr; MAX_CONTACTS],
    /// The output's byte (a head's: slot 0, never written).
    pub out: Addr,
}

/// A rung's table over a 9-bit index: bit `i` is the output's new value for index `i`, whose
/// bit `k < 8` says contact `k` passes (its byte xor its negation) and bit 8 is the output's old
/// value.
pub(crate) type Table = [u64; 8];

/// Bit `index` of `table` (only the index's low 9 bits count).
#[inline(always)]
pub(crate) fn lookup(table: &Table, index: usize) -> u8 {
    ((table[(index >> 6) & 7] >> (index & 63)) & 1) as u8
}

/// The new value of an output of kind `mode` (`OUT_COIL`...) given the power and its old value
/// (the `exec` module's coil semantics).
fn output(mode: u8, power: bool, old: bool) -> bool {
    match mode {
        OUT_COIL => power,
        OUT_NCOIL => !power,
        OUT_SET => power || old,
        OUT_RESET => !power && old,
        _ => unreachable!("an output mode"),
    }
}

/// The boolean structure of a rung's conditions over its contacts (numbered in order).
#[derive(Clone, Debug, PartialEq, Eq, Hash)]
enum Cond {
    /// Contact `k` passes.
    Lit(u8),
    /// A series: all pass (an empty series passes).
    All(Vec<Cond>),
    /// An `or` (at least one branch): one passes.
    Any(Vec<Cond>),
}

impl Cond {
    fn eval(&self, index: usize) -> bool {
        match self {
            Cond::Lit(k) => (index >> k) & 1 == 1,
            Cond::All(v) => v.iter().all(|c| c.eval(index)),
            Cond::Any(v) => v.iter().any(|c| c.eval(index)),
        }
    }

    fn table(&self, mode: u8) -> Table {
        let mut t = [0u64; 8];
        for i in 0..512usize {
            if output(mode, self.eval(i & 255), i >> 8 == 1) {
                t[i >> 6] |= 1 << (i & 63);
            }
        }
        t
    }
}

/// A rung's conditions that can be fused: the contacts in evaluation order (variable, negated)
/// and the structure over them.
struct Shape {
    contacts: Vec<(VarRef, bool)>,
    cond: Cond,
}

/// How many leading elements of `series` a head can take: plain contacts and `or`s of them,
/// with at most [`MAX_CONTACTS`] contacts in all.
fn prefix_len(series: &[Element]) -> usize {
    let mut contacts = 0;
    series
        .iter()
        .take_while(|e| {
            let mut probe = Vec::new();
            let fits = series_cond(std::slice::from_ref(*e), &mut probe).is_some();
            contacts += probe.len();
            fits && contacts <= MAX_CONTACTS
        })
        .count()
}

/// The conditions `series` (everything before the rung's output) as a [`Shape`], or `None` if
/// they hold anything but plain contacts and non-empty `or`s, or more than [`MAX_CONTACTS`]
/// contacts.
fn shape(series: &[Element]) -> Option<Shape> {
    let mut contacts = Vec::new();
    let cond = series_cond(series, &mut contacts)?;
    Some(Shape { contacts, cond })
}

fn series_cond(series: &[Element], contacts: &mut Vec<(VarRef, bool)>) -> Option<Cond> {
    let mut all = Vec::with_capacity(series.len());
    for e in series {
        match e {
            Element::Contact { var, kind } => {
                let neg = match kind {
                    ContactKind::Normal => false,
                    ContactKind::Negated => true,
                    _ => return None,
                };
                if contacts.len() == MAX_CONTACTS {
                    return None;
                }
                all.push(Cond::Lit(contacts.len() as u8));
                contacts.push((*var, neg));
            }
            Element::Or(bs) if !bs.is_empty() => {
                let any = bs
                    .iter()
                    .map(|b| series_cond(b, contacts))
                    .collect::<Option<Vec<_>>>()?;
                all.push(Cond::Any(any));
            }
            _ => return None,
        }
    }
    Some(Cond::All(all))
}

/// A fused start of a rung: its instruction's operands.
pub(crate) struct Start {
    /// Whether it is the whole rung (`Op::Fused`) or a head (`Op::FusedHead`).
    pub whole: bool,
    /// How many of the rung's elements it takes.
    pub taken: usize,
    pub operands: FusedRung,
    pub table: u16,
    pub neg: u8,
}

/// How the rung `series` starts fused, if its shape allows: the whole rung (plain contacts,
/// then one output), else a head of its leading plain contacts (at least one), else `None`
/// (also when the tables are full). `addr` gives a contact's byte, `start` an output's.
pub(crate) fn start(
    series: &[Element],
    tables: &mut Tables,
    addr: impl Fn(VarRef) -> Addr,
    start: impl Fn(VarId) -> Addr,
) -> Option<Start> {
    let output = |e: &Element| match *e {
        Element::Coil { var, negated } => Some((var, if negated { OUT_NCOIL } else { OUT_COIL })),
        Element::Set(var) => Some((var, OUT_SET)),
        Element::Reset(var) => Some((var, OUT_RESET)),
        _ => None,
    };
    if let Some((last, conds)) = series.split_last() {
        if let (Some((var, mode)), Some(s)) = (output(last), shape(conds)) {
            if let Some(table) = tables.index(&s, mode) {
                let (operands, neg) = operands(&s, &addr, Some(start(var)));
                let (whole, taken) = (true, series.len());
                return Some(Start {
                    whole,
                    taken,
                    operands,
                    table,
                    neg,
                });
            }
        }
    }
    let taken = prefix_len(series);
    let s = shape(&series[..taken]).filter(|s| !s.contacts.is_empty())?;
    let table = tables.index(&s, OUT_COIL)?;
    let (operands, neg) = operands(&s, &addr, None);
    Some(Start {
        whole: false,
        taken,
        operands,
        table,
        neg,
    })
}

/// The operands of `shape` (output `out`, or none for a head) and its negation bits.
fn operands(shape: &Shape, addr: impl Fn(VarRef) -> Addr, out: Option<Addr>) -> (FusedRung, u8) {
    let mut at = [Addr(0); MAX_CONTACTS];
    let mut neg = 0u8;
    for (k, &(v, n)) in shape.contacts.iter().enumerate() {
        at[k] = addr(v);
        neg |= (n as u8) << k;
    }
    // Padding repeats a byte the rung reads anyway (a head always has a contact).
    let pad = match (shape.contacts.is_empty(), out) {
        (true, Some(out)) => out,
        _ => at[0],
    };
    for slot in at.iter_mut().skip(shape.contacts.len()) {
        *slot = pad;
    }
    let out = out.unwrap_or(at[0]);
    (FusedRung { at, out }, neg)
}

/// The machine's rung tables, one per distinct shape and output mode.
#[derive(Default)]
pub(crate) struct Tables {
    pub tables: Vec<Table>,
    of: HashMap<(Cond, u8), u16>,
}

impl Tables {
    /// The index of the table of `shape` with an output of kind `mode` (`OUT_COIL`...), added if
    /// new; `None` past 2^16 distinct tables.
    fn index(&mut self, shape: &Shape, mode: u8) -> Option<u16> {
        let key = (shape.cond.clone(), mode);
        if let Some(&i) = self.of.get(&key) {
            return Some(i);
        }
        let i = u16::try_from(self.tables.len()).ok()?;
        self.tables.push(shape.cond.table(mode));
        self.of.insert(key, i);
        Some(i)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn lit(k: u8) -> Cond {
        Cond::Lit(k)
    }

    #[test]
    fn a_series_passes_only_when_every_contact_does() {
        let t = Cond::All(vec![lit(0), lit(1), lit(2)]).table(OUT_COIL);
        for i in 0..512 {
            assert_eq!(lookup(&t, i), (i & 7 == 7) as u8, "index {i}");
        }
    }

    #[test]
    fn outputs_follow_the_coil_semantics() {
        let c = Cond::All(vec![lit(0)]);
        // (index, coil, negated coil, set, reset): bit 0 the power, bit 8 the old value.
        for (i, coil, ncoil, set, reset) in [
            (0, 0, 1, 0, 0),
            (1, 1, 0, 1, 0),
            (256, 0, 1, 1, 1),
            (257, 1, 0, 1, 0),
        ] {
            assert_eq!(lookup(&c.table(OUT_COIL), i), coil, "coil {i}");
            assert_eq!(lookup(&c.table(OUT_NCOIL), i), ncoil, "negated coil {i}");
            assert_eq!(lookup(&c.table(OUT_SET), i), set, "set {i}");
            assert_eq!(lookup(&c.table(OUT_RESET), i), reset, "reset {i}");
        }
    }

    #[test]
    fn an_or_then_a_series() {
        // (c0 c1 | c2) c3
        let c = Cond::All(vec![
            Cond::Any(vec![
                Cond::All(vec![lit(0), lit(1)]),
                Cond::All(vec![lit(2)]),
            ]),
            lit(3),
        ]);
        let t = c.table(OUT_COIL);
        for i in 0..512usize {
            let b = |k: usize| (i >> k) & 1 == 1;
            let want = ((b(0) && b(1)) || b(2)) && b(3);
            assert_eq!(lookup(&t, i), want as u8, "index {i}");
        }
    }

    #[test]
    fn an_empty_series_passes_and_bits_past_the_contacts_are_ignored() {
        let t = Cond::All(vec![]).table(OUT_COIL);
        assert!((0..512).all(|i| lookup(&t, i) == 1));
        let t = Cond::All(vec![lit(0)]).table(OUT_COIL);
        assert!((0..512).all(|i| lookup(&t, i) == (i & 1) as u8));
    }
}
