//! The boolean functions AND, OR, XOR and NOT (IEC 61131-3 2.5.1.5.2, Table 28) as blocks in LD
//! rungs, with BOOL pins fed by power (`IN1` … `INn`, `IN` of NOT) and their `OUT` as the power
//! out: rewritten into the contacts, compares and `or`s of the series-parallel rung, so that no
//! new element kind is needed.
//!
//! The inputs' series from the rail share a prefix (kept once, as for a wired OR); after it,
//! every input's rest must be conditions only. Then OR is the `or` of the rests (the wired OR of
//! [`super::ld_power`]), AND their series one after another, XOR of two inputs
//! `(a AND NOT b) OR (NOT a AND b)`, and NOT the negation of the input's whole series (De Morgan:
//! a series becomes an `or` of its negated elements, an `or` a series of its negated branches, a
//! contact toggles `negated`, a compare takes the complementary operator).
//!
//! Deliberately not here (errors naming the block and its localId): EN/ENO on these blocks,
//! inputs fed through an output or a box (a timer's Q, a coil), negating an edge contact, XOR
//! of more than two inputs, NOT of the rail (always FALSE).

use super::ld_power::{Item, Key, Path, Power};
use super::wiring::{ElemId, Source};
use super::xml::{error, origin, R};
use plc_syntax::{Element, ElementKind, Series};

/// True for the boolean functions this module rewrites.
pub(super) fn is_logic(ty: &str) -> bool {
    matches!(ty, "AND" | "OR" | "XOR" | "NOT")
}

/// The power out of boolean block `e` of type `ty`.
pub(super) fn power_out(p: &mut Power, e: ElemId, ty: &str) -> R<Path> {
    let el = p.g.get(e);
    let here = p.at(e);
    let fail = |why: String| {
        error(
            origin(el.node),
            &here,
            format!("{ty} (localId {}) {why}", el.local_id),
        )
    };
    let mut sources: Vec<Source> = Vec::new();
    for pin in &el.inputs {
        let name = pin.name.unwrap_or("");
        let ok = if ty == "NOT" {
            name == "IN"
        } else {
            name.starts_with("IN")
        };
        if !ok {
            return Err(fail(format!(
                "has the input `{name}`, which plc-deps does not support in LD (inputs: {})",
                if ty == "NOT" { "IN" } else { "IN1, IN2, …" }
            )));
        }
        match pin.sources.as_slice() {
            [s] => sources.push(s.clone()),
            [] => return Err(fail(format!("has its input {name} unconnected"))),
            _ if ty == "OR" => sources.extend(pin.sources.iter().cloned()),
            _ => {
                return Err(fail(format!(
                    "has several wires into {name}: put an OR before it"
                )))
            }
        }
    }
    for &(_, _, out_pin) in &p.g.consumers[e.0 as usize] {
        if out_pin.is_some_and(|x| x != "OUT") {
            return Err(fail(format!(
                "has its output `{}` wired: only OUT can be in LD",
                out_pin.unwrap_or("")
            )));
        }
    }
    let mut paths = Vec::with_capacity(sources.len());
    for s in &sources {
        paths.push(p.out(s.elem, s.pin)?);
    }
    if ty == "NOT" {
        let [path] = paths.as_slice() else {
            return Err(fail("needs exactly one input IN".into()));
        };
        let series = conditions(path, 0).ok_or_else(|| fail("negates a series that holds an output or a box (only contacts, compares and ORs can be negated)".into()))?;
        if series.is_empty() {
            return Err(fail(
                "negates the rail: its output would always be FALSE".into(),
            ));
        }
        let negated = negate_series(&series)
            .ok_or_else(|| fail("negates an edge contact, which has no negation in LD".into()))?;
        return Ok(negated.into_iter().map(|x| item(e, x)).collect());
    }
    if paths.len() < 2 {
        return Err(fail("needs at least two inputs".into()));
    }
    let common = (0..)
        .take_while(|&i| {
            paths
                .iter()
                .all(|q| q.get(i).map(|x| &x.key) == paths[0].get(i).map(|x| &x.key))
        })
        .count();
    let mut rests: Vec<Series<'static>> = Vec::with_capacity(paths.len());
    for q in &paths {
        rests.push(conditions(q, common).ok_or_else(|| fail("has an input fed through an output or a box (a timer's Q, a coil), which plc-deps cannot combine in a rung".into()))?);
    }
    let mut out: Path = paths[0][..common].to_vec();
    match ty {
        "AND" => {
            for (q, _) in paths.iter().zip(&rests) {
                out.extend(q[common..].iter().cloned());
            }
        }
        "OR" => {
            if rests.iter().any(Vec::is_empty) {
                return Err(fail("has an input that is the same power as the others, so its OR would always be TRUE there".into()));
            }
            out.push(item(
                e,
                Element {
                    origin: origin(el.node),
                    kind: ElementKind::Or(rests),
                },
            ));
        }
        _ => {
            let [a, b] = rests.as_slice() else {
                return Err(fail(
                    "has more than two inputs; plc-deps reads XOR of two".into(),
                ));
            };
            let neg = |s: &Series<'static>| {
                negate_series(s).ok_or_else(|| {
                    fail("has an edge contact in an input, which has no negation in LD".into())
                })
            };
            // After the common prefix an empty rest is TRUE: XOR(TRUE, b) = NOT b.
            let xor = match (a.is_empty(), b.is_empty()) {
                (true, true) => {
                    return Err(fail(
                        "has two inputs of the same power: its output would always be FALSE".into(),
                    ))
                }
                (true, false) => neg(b)?,
                (false, true) => neg(a)?,
                (false, false) => {
                    let branch = |x: &Series<'static>, y: Series<'static>| -> Series<'static> {
                        x.iter().cloned().chain(y).collect()
                    };
                    vec![Element {
                        origin: origin(el.node),
                        kind: ElementKind::Or(vec![
                            branch(a, neg(b)?),
                            branch(&neg(a)?, b.clone()),
                        ]),
                    }]
                }
            };
            out.extend(xor.into_iter().map(|x| item(e, x)));
        }
    }
    Ok(out)
}

fn item(e: ElemId, element: Element<'static>) -> Item {
    Item {
        key: Key::Elem(e),
        element,
    }
}

/// The elements of `path` from `from` on, when they are all conditions.
fn conditions(path: &Path, from: usize) -> Option<Series<'static>> {
    let rest = path.get(from..)?;
    rest.iter()
        .all(|x| x.element.kind.is_condition())
        .then(|| rest.iter().map(|x| x.element.clone()).collect())
}

/// NOT of a series of conditions: the negated element, or an `or` of the negated elements;
/// `None` when it holds an edge contact.
fn negate_series(s: &[Element<'static>]) -> Option<Series<'static>> {
    if let [one] = s {
        return negate(one);
    }
    let branches = s.iter().map(negate).collect::<Option<Vec<_>>>()?;
    Some(vec![Element {
        origin: s.first()?.origin,
        kind: ElementKind::Or(branches),
    }])
}

/// NOT of one condition, as a series.
fn negate(x: &Element<'static>) -> Option<Series<'static>> {
    let kind = match &x.kind {
        ElementKind::Contact {
            var,
            negated,
            edge: None,
        } => ElementKind::Contact {
            var: var.clone(),
            negated: !negated,
            edge: None,
        },
        ElementKind::Compare(c) => {
            let mut c = c.clone();
            c.op = c.op.negated();
            ElementKind::Compare(c)
        }
        // NOT (b1 OR b2 …) = NOT b1 AND NOT b2 …: the negated branches in series.
        ElementKind::Or(branches) => {
            let mut series = Vec::new();
            for b in branches {
                series.extend(negate_series(b)?);
            }
            return Some(series);
        }
        _ => return None,
    };
    Some(vec![Element {
        origin: x.origin,
        kind,
    }])
}
