//! Rungs of contacts and coils as data: a row of a table that a loop of the runtime
//! (`_plc_rows`, `_plc_rows2` in `plc_runtime.h`) runs, instead of C statements per rung.
//!
//! Why: `cc -O2` spends about a millisecond of CPU on each rung statement (spread over its
//! passes: value numbering, dead store elimination, the register allocator, the scheduler …),
//! so 100,000 rungs as statements take minutes to build however they are written; a table row
//! costs only the parser. The price is run time: a row loads each contact's offset and
//! negation besides its byte, and keeps no value in a register from one rung to the next, so
//! rows run 1.5–3 times slower than the statements (docs/c.md): an option (`--rows`).
//!
//! Two kinds of rows, each a table of fixed-size entries and a loop without branches:
//! - `_plc_row`: a series of 1 to [`CLAUSES`] Normal or Negated contacts on BOOLs of the state
//!   (whole variables or fields) and one coil, negated coil, set or reset of a BOOL of the state;
//! - `_plc_row2`: a condition that is an AND of at most [`CLAUSES`] ORs of at most two such
//!   contacts (an OR of series of contacts is brought to that form by distribution:
//!   `(a & b) | c` is `(a | c) & (b | c)`, exact since contacts have no side effects), with at
//!   most one rising or falling edge contact outside the ORs, and one or two outputs (the
//!   second the path of an output branch: `[[coil M], [coil Q]]`).
//!
//! A row holds byte offsets in `_plc_state` (a shorter condition repeats its first contact,
//! `x & x` being `x`), negations (XORed in), and each output's kind as four masks of
//! `new = ((old & keep) | ((p ^ inv) & put)) & ~(p & clr)`: coil `p`, negated coil `!p`, set
//! `old | p`, reset `old & !p` — the interpreter's rules (docs/scan.md), with no branch (a row of
//! one output writes it twice: every kind is idempotent). An edge contact's pulse is
//! `(v ^ ef) & (m ^ er)` (rising `v & !m`, falling `!v & m`), its memory then takes `v`, before
//! the outputs are written, as the interpreter evaluates contacts before the coil; without an
//! edge the pulse is forced to 1 and the "memory" is the first contact, written with its own
//! value. Values are the bytes of C `bool`s (0 or 1), read and written through `uint8_t`, which
//! may alias anything.
//!
//! Consecutive rows of one kind make one run, one call `_plc_rows(state, table + first, count)`
//! (or `_plc_rows2`); any other line of C (a rung that is no row, a label a jump targets, the
//! function's end) ends the run first, so rungs still run in program order. Only the ladder
//! functions of POUs use rows (not FBD bodies or function block types, whose variables may be
//! locals or another struct's).
//!
//! Not here: the C of the rungs that are no row (`ladder`), the tables' place in the files
//! (`mod`), the loops themselves (`runtime`).

use super::ladder::Body;
use crate::model::{ContactKind, Element, Field, RungId, Series, Type, VarId, VarRef};

/// The most clauses (contacts, or ORs of two) of a row.
pub(crate) const CLAUSES: usize = 6;

/// One table of a function: its name, the initializer text of its rows, how many.
struct Table {
    name: String,
    text: String,
    count: usize,
}

/// The rows of one function, in its two tables, and the run not yet called (its kind, first
/// row).
pub(crate) struct Rows {
    tables: [Table; 2],
    run: Option<(usize, usize)>,
}

impl Rows {
    /// The rows of a function whose tables are `names` (`_pou_…` names: the test batches rename
    /// every such symbol per program).
    pub fn new(names: [String; 2]) -> Rows {
        let [a, b] = names;
        let table = |name| Table {
            name,
            text: String::new(),
            count: 0,
        };
        Rows {
            tables: [table(a), table(b)],
            run: None,
        }
    }

    /// Adds a row of `kind`; the call of the run it ends, if it starts another.
    fn push(&mut self, kind: usize, row: &str) -> Option<String> {
        let call = match self.run {
            Some((k, _)) if k != kind => self.take_call(),
            _ => None,
        };
        let t = &mut self.tables[kind];
        if self.run.is_none() {
            self.run = Some((kind, t.count));
        }
        t.text.push_str(row);
        t.count += 1;
        call
    }

    /// The call of the run of rows pushed since the last call, if any.
    pub fn take_call(&mut self) -> Option<String> {
        let (kind, first) = self.run.take()?;
        let t = &self.tables[kind];
        let f = ["_plc_rows", "_plc_rows2"][kind];
        Some(format!(
            "{f}((uint8_t *)self, {} + {first}, {});",
            t.name,
            t.count - first
        ))
    }

    /// The tables' definitions, to write before the function (empty: no rows).
    pub fn definitions(&self) -> String {
        let mut out = String::new();
        for (t, ty) in self.tables.iter().zip(["_plc_row", "_plc_row2"]) {
            if t.count > 0 {
                out.push_str(&format!(
                    "static const {ty} {}[{}] = {{\n{}}};\n",
                    t.name, t.count, t.text
                ));
            }
        }
        out
    }
}

/// A contact of a row: the member designator of its BOOL (`G1.Q`), and whether negated.
type Lit = (String, u8);

/// What a rung is, as a row.
struct Shape {
    clauses: Vec<Vec<Lit>>,
    /// An edge contact: its BOOL, its memory, rising.
    edge: Option<(String, String, bool)>,
    /// The outputs: the member and the masks `[keep, inv, put, clr]`.
    outputs: Vec<(String, [u8; 4])>,
}

/// Rung `r` as a row of `b`'s tables (pushed, after the call of a run of the other kind), if
/// it has a row's shape; false: write it as C.
pub(crate) fn push_rung(b: &mut Body, r: RungId) -> bool {
    if b.rows.is_none() || b.inst.is_some() || !b.locals.is_empty() {
        return false;
    }
    let Some(shape) = shape(b, &b.sh.p.rung(r).series) else {
        return false;
    };
    let id = super::names::comment(&b.sh.p.rung(r).id);
    let plain = shape.edge.is_none()
        && shape.outputs.len() == 1
        && shape.clauses.iter().all(|c| c.len() == 1);
    let (kind, row) = if plain {
        (0, row1(&shape, &id))
    } else {
        (1, row2(&shape, &id))
    };
    if let Some(call) = b.rows.as_mut().expect("checked").push(kind, &row) {
        b.line_before_rows(&call);
    }
    true
}

fn at(m: &str) -> String {
    format!("_PLC_AT({m})")
}

fn list<T: ToString>(xs: impl IntoIterator<Item = T>) -> String {
    let v: Vec<String> = xs.into_iter().map(|x| x.to_string()).collect();
    format!("{{{}}}", v.join(", "))
}

/// The clauses padded to [`CLAUSES`] with the first.
fn padded(clauses: &[Vec<Lit>]) -> Vec<Vec<Lit>> {
    let mut c = clauses.to_vec();
    while c.len() < CLAUSES {
        c.push(c[0].clone());
    }
    c
}

fn row1(s: &Shape, id: &str) -> String {
    let c = padded(&s.clauses);
    let (coil, m) = &s.outputs[0];
    format!(
        "    {{{}, {}, {}, {}}}, /* {id} */\n",
        list(c.iter().map(|l| at(&l[0].0))),
        at(coil),
        list(c.iter().map(|l| l[0].1)),
        list(m),
    )
}

fn row2(s: &Shape, id: &str) -> String {
    let c: Vec<Vec<Lit>> = padded(&s.clauses)
        .into_iter()
        .map(|mut l| {
            if l.len() == 1 {
                l.push(l[0].clone());
            }
            l
        })
        .collect();
    let (ev, em, ef, er, none) = match &s.edge {
        Some((v, m, true)) => (v.clone(), m.clone(), 0, 1, 0),
        Some((v, m, false)) => (v.clone(), m.clone(), 1, 0, 0),
        None => (c[0][0].0.clone(), c[0][0].0.clone(), 0, 0, 1),
    };
    let out2 = s.outputs.get(1).unwrap_or(&s.outputs[0]);
    format!(
        "    {{{}, {}, {}, {}, {}, {ef}, {er}, {none}, {}}}, /* {id} */\n",
        list(c.iter().map(|l| list(l.iter().map(|x| at(&x.0))))),
        list([at(&s.outputs[0].0), at(&out2.0)]),
        at(&ev),
        at(&em),
        list(c.iter().map(|l| list(l.iter().map(|x| x.1)))),
        list([s.outputs[0].1, out2.1].map(list)),
    )
}

/// The row shape of `series`, if it has one.
fn shape(b: &Body, series: &Series) -> Option<Shape> {
    let (out, cond) = series.split_last()?;
    let mut outputs = vec![output(b, out)?];
    if outputs[0].0.is_empty() {
        // An output branch of two single outputs.
        let Element::Branch(paths) = out else {
            return None;
        };
        outputs = match paths.as_slice() {
            [a, c] if a.len() == 1 && c.len() == 1 => {
                vec![output(b, &a[0])?, output(b, &c[0])?]
            }
            _ => return None,
        };
        if outputs.iter().any(|o| o.0.is_empty()) {
            return None;
        }
    }
    let mut clauses = Vec::new();
    let mut edge = None;
    for e in cond {
        match e {
            Element::Contact {
                var,
                kind: kind @ (ContactKind::Rising { memory } | ContactKind::Falling { memory }),
            } if edge.is_none() => {
                let rising = matches!(kind, ContactKind::Rising { .. });
                edge = Some((contact(b, *var)?, state_member(b, *memory)?, rising));
            }
            _ => clauses.extend(cnf(b, e)?),
        }
        if clauses.len() > CLAUSES {
            return None;
        }
    }
    if clauses.is_empty() {
        return None; // no contact to pad the clauses with: the rung stays C
    }
    Some(Shape {
        clauses,
        edge,
        outputs,
    })
}

/// An output element as a row output; `("", _)` for an output branch (looked into by the
/// caller); None: no row.
fn output(b: &Body, e: &Element) -> Option<(String, [u8; 4])> {
    let (var, masks) = match *e {
        Element::Coil { var, negated } => (var, if negated { [0, 1, 1, 0] } else { [0, 0, 1, 0] }),
        Element::Set(var) => (var, [1, 0, 1, 0]),
        Element::Reset(var) => (var, [1, 0, 0, 1]),
        Element::Branch(_) => return Some((String::new(), [0; 4])),
        _ => return None,
    };
    (b.sh.p.var(var).ty == Type::Bool).then_some(())?;
    Some((state_member(b, var)?, masks))
}

/// The member designator of a variable of the state (not a local).
fn state_member(b: &Body, v: VarId) -> Option<String> {
    if b.locals.contains_key(&v) {
        return None;
    }
    b.var(v).strip_prefix("self->").map(String::from)
}

/// The member designator of a contact's BOOL (a BOOL variable or a BOOL field).
fn contact(b: &Body, r: VarRef) -> Option<String> {
    let p = b.sh.p;
    let is_bool = match (p.var(r.var).ty, r.field) {
        (Type::Bool, None) => true,
        (Type::Fb(fb), Some(f)) => {
            Field::lookup(fb, f.name()).is_some_and(|(_, t)| t == Type::Bool)
        }
        _ => false,
    };
    if !is_bool || b.locals.contains_key(&r.var) {
        return None;
    }
    b.var_ref_text(r).strip_prefix("self->").map(String::from)
}

/// A condition element as clauses of at most two contacts (None: it has no such form).
fn cnf(b: &Body, e: &Element) -> Option<Vec<Vec<Lit>>> {
    match e {
        Element::Contact { var, kind } => {
            let neg = match kind {
                ContactKind::Normal => 0,
                ContactKind::Negated => 1,
                _ => return None,
            };
            Some(vec![vec![(contact(b, *var)?, neg)]])
        }
        Element::Or(branches) if !branches.is_empty() => {
            // OR of the branches' ANDs: the clauses of every choice of one clause per branch.
            let mut acc: Vec<Vec<Lit>> = vec![vec![]];
            for br in branches {
                let mut cl = Vec::new();
                for e in br {
                    cl.extend(cnf(b, e)?);
                }
                if cl.is_empty() {
                    return None; // an empty branch passes power: leave it to the C
                }
                let mut next = Vec::new();
                for a in &acc {
                    for c in &cl {
                        let mut l = a.clone();
                        for x in c {
                            if !l.contains(x) {
                                l.push(x.clone());
                            }
                        }
                        if l.len() > 2 {
                            return None;
                        }
                        next.push(l);
                    }
                }
                if next.len() > CLAUSES {
                    return None;
                }
                acc = next;
            }
            Some(acc)
        }
        _ => None,
    }
}
