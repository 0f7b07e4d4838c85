//! One STL network → one rung: the S7-200 logic stack (9 levels) executed at read time on
//! rung fragments instead of bits.
//!
//! First the stack is checked alone ([`depth`]): every instruction finds the values it needs,
//! no network needs more than 9 levels, every LRD/LPP has its LPS directly below the top, every
//! LPS is popped by the network's end (each an error at its line and column). Then the network
//! is built *nested* ([`Nested`]): a stack entry is the series that gives its power (a rung's
//! LAD shape: LD/A/O/ALD/OLD build conditions, LPS/LRD/LPP build output branches, outputs append
//! to the top), the rung is the entries left at the end, each a path from the rail. A network
//! the LAD shape cannot hold (an O or OLD on a value that already fed outputs, as the paper's
//! listings do) is built *flat* instead (`super::flat`): every output gets its own path whose
//! conditions are the whole stack value, valid only when re-reading those conditions reads what
//! the S7-200 read (no edge read twice, no variable re-read after the network wrote it; else an
//! error). Zhou & Zhang 2015 give the stack shapes; S7-200 system manual, chapter 6.

use super::decode::{
    counter_aux, decode, edge, is_pure, label as label_operand, negate, or, Op, LEVELS,
};
use super::flat::flat;
use super::operand::Context;
use super::tree::{el, name};
use super::{error, Ins, RawNet};
use plc_diag::{LoadError, Origin};
use plc_syntax::{self as syntax, Element, ElementKind, Rung, Series};
use std::borrow::Cow;

/// The rungs of a block's networks; ids are the network titles (else `N<n>`, prefixed).
pub(super) fn rungs(
    cx: &mut Context,
    nets: &[RawNet],
    prefix: &str,
) -> Result<Vec<Rung<'static>>, LoadError> {
    let mut out = Vec::new();
    for n in nets {
        depth(cx.text, n)?;
        let mut code = &n.code[..];
        let mut label = None;
        if let Some(first) = code.first().filter(|i| i.op == "LBL") {
            let Some(l) = first.args.first() else {
                return Err(error(cx.text, first.at, "LBL needs a label"));
            };
            label = Some(Box::new(label_operand(cx.text, *l)?));
            code = &code[1..];
        }
        if let Some(l) = code.iter().find(|i| i.op == "LBL") {
            return Err(error(
                cx.text,
                l.at,
                "LBL must be the first instruction of its network",
            ));
        }
        let ld = match Nested::build(cx, code)? {
            Some(s) => s,
            None => flat(cx, code)?,
        };
        let id = match n.title.filter(|t| !t.contains(char::is_whitespace)) {
            Some(t) => t.to_string(),
            None => format!("{prefix}N{}", n.number.text),
        };
        out.push(Rung {
            origin: Origin::at(n.number.at),
            id: name(&id, n.number.at),
            label,
            comment: n
                .title
                .filter(|t| t.contains(char::is_whitespace))
                .map(|t| Cow::Owned(t.to_string())),
            ld,
            ld_origin: Origin::at(n.number.at),
            problem: None,
            problem_in_rung: false,
        });
    }
    Ok(out)
}

/// What an instruction does to the stack: values it needs, pops, pushes.
fn effect(op: &str) -> Option<(usize, usize, usize)> {
    let cmp = |p: &str| {
        op.strip_prefix(p).is_some_and(|r| {
            let r = r.strip_prefix(['W', 'D', 'R']).unwrap_or("x");
            matches!(r, "=" | "<>" | "<" | "<=" | ">" | ">=")
        })
    };
    Some(match op {
        "LD" | "LDN" | "LPS" => (0, 0, 1),
        _ if cmp("LD") => (0, 0, 1),
        "A" | "AN" | "O" | "ON" | "NOT" | "EU" | "ED" | "LRD" | "=" | "S" | "R" | "TON" | "TOF"
        | "MOVW" | "MOVD" | "MOVR" | "JMP" | "CALL" | "FOR" | "END" => (1, 0, 0),
        "SQRT" | "LN" | "EXP" | "SIN" | "COS" | "TAN" | "I_DI" | "DI_R" | "ROUND" | "TRUNC"
        | "SLW" | "SRW" | "RLW" | "RRW" | "SLD" | "SRD" | "RLD" | "RRD" => (1, 0, 0),
        "ANDW" | "ORW" | "XORW" | "INVW" | "ANDD" | "ORD" | "XORD" | "INVD" => (1, 0, 0),
        _ if cmp("A") || cmp("O") => (1, 0, 0),
        _ if matches!(
            op.as_bytes(),
            [b'+' | b'-' | b'*' | b'/', b'I' | b'D' | b'R']
        ) =>
        {
            (1, 0, 0)
        }
        "ALD" | "OLD" | "CTU" | "CTD" => (2, 1, 0),
        "LPP" => (1, 1, 0),
        "CRET" | "RET" | "CRETI" | "RETI" | "MEND" | "NEXT" | "LBL" => (0, 0, 0),
        _ => return None,
    })
}

/// Checks the network's stack alone: needs, overflow, LPS/LRD/LPP balance.
fn depth(text: &str, n: &RawNet) -> Result<(), LoadError> {
    let mut d = 0usize;
    let mut forks: Vec<usize> = Vec::new();
    let net = n.number.text;
    for ins in &n.code {
        let Some((need, pop, push)) = effect(&ins.op) else {
            return Err(error(text, ins.at, format!("unknown instruction `{}` (not an S7-200 instruction plc-deps reads; docs/il.md lists them)", ins.op)));
        };
        let floor = forks.last().copied().unwrap_or(0);
        if matches!(ins.op.as_str(), "LRD" | "LPP") {
            if forks.last() != Some(&d) {
                let why = if forks.is_empty() {
                    "no LPS open".to_string()
                } else {
                    format!("{} value(s) above its LPS", d - floor)
                };
                return Err(error(
                    text,
                    ins.at,
                    format!(
                        "network {net}: unbalanced logic stack: {} with {why}",
                        ins.op
                    ),
                ));
            }
        } else if d < need || (pop > 0 && d - pop < floor) {
            let have = if pop > 0 { d + 1 - floor.max(1) } else { d };
            return Err(error(text, ins.at, format!("network {net}: unbalanced logic stack: {} needs {need} value(s), the network has {have} here", ins.op)));
        }
        d = d - pop + push;
        if d > LEVELS {
            return Err(error(text, ins.at, format!("network {net}: logic stack overflow: {} needs a 10th level (the S7-200 logic stack has 9)", ins.op)));
        }
        match ins.op.as_str() {
            "LPS" => forks.push(d),
            "LPP" => {
                forks.pop();
            }
            _ => {}
        }
    }
    if !forks.is_empty() {
        return Err(error(text, n.code.last().map_or(n.number.at, |i| i.at), format!("network {net}: unbalanced logic stack: {} LPS not popped by LPP at the end of the network", forks.len())));
    }
    Ok(())
}

/// A stack entry of the nested build: the series that gives its power; `rel`: it starts at
/// the fork below (an output branch), not at the rail.
enum Item {
    Power {
        s: Series<'static>,
        rel: bool,
    },
    Fork {
        base: Series<'static>,
        rel: bool,
        branches: Vec<Series<'static>>,
    },
}

struct Nested;

impl Nested {
    /// The rung of a network in the LAD shape, or `None` if it has another shape.
    fn build(cx: &mut Context, code: &[Ins]) -> Result<Option<Series<'static>>, LoadError> {
        let mut st: Vec<Item> = Vec::new();
        let mut i = 0;
        while i < code.len() {
            let ins = &code[i];
            let op = decode(cx, ins, st.is_empty())?;
            // `NOT`, `= x`, `NOT`: a negated coil.
            if ins.op == "NOT"
                && code.get(i + 2).is_some_and(|n| n.op == "NOT")
                && code.get(i + 1).is_some_and(|n| n.op == "=")
            {
                if let Op::Out(Element {
                    kind: ElementKind::Coil { var, .. },
                    origin,
                }) = decode(cx, &code[i + 1], false)?
                {
                    let Some(Item::Power { s, .. }) = st.last_mut() else {
                        return Ok(None);
                    };
                    s.push(Element {
                        origin,
                        kind: ElementKind::Coil { var, negated: true },
                    });
                    i += 3;
                    continue;
                }
            }
            if !Self::step(cx, &mut st, op, ins.at)? {
                return Ok(None);
            }
            i += 1;
        }
        let mut paths: Vec<Series<'static>> = Vec::new();
        for it in st {
            if let Item::Power { s, .. } = it {
                if !s.is_empty() {
                    paths.push(unwrap_tail(s));
                }
            }
        }
        Ok(Some(match paths.len() {
            0 => Vec::new(),
            1 => paths.pop().expect("one"),
            _ => vec![el(ElementKind::Branch(paths), code[0].at)],
        }))
    }

    /// One instruction; false: the network has no LAD shape.
    fn step(cx: &mut Context, st: &mut Vec<Item>, op: Op, at: usize) -> Result<bool, LoadError> {
        let top_pure =
            |st: &Vec<Item>| matches!(st.last(), Some(Item::Power { s, rel: false }) if is_pure(s));
        match op {
            Op::Stack("TRUE") => st.push(Item::Power {
                s: Vec::new(),
                rel: false,
            }),
            Op::Cond('L', e) => st.push(Item::Power {
                s: vec![e],
                rel: false,
            }),
            Op::Cond('A', e) => top(st).push(e),
            Op::Cond(_, e) => {
                if !top_pure(st) {
                    return Ok(false);
                }
                let s = std::mem::take(top(st));
                *top(st) = or(s, vec![e]);
            }
            Op::Stack("ALD") => {
                if !top_pure(st) {
                    return Ok(false);
                }
                let Some(Item::Power { s, .. }) = st.pop() else {
                    unreachable!()
                };
                top(st).extend(s);
            }
            Op::Stack("OLD") => {
                if !top_pure(st)
                    || !matches!(&st[st.len() - 2], Item::Power { s, rel: false } if is_pure(s))
                {
                    return Ok(false);
                }
                let Some(Item::Power { s: b, .. }) = st.pop() else {
                    unreachable!()
                };
                let a = std::mem::take(top(st));
                *top(st) = or(a, b);
            }
            Op::Stack("NOT") => {
                if !top_pure(st) {
                    return Ok(false);
                }
                match negate(top(st)) {
                    Some(n) => *top(st) = n,
                    None => {
                        return Err(error(
                            cx.text,
                            at,
                            "NOT of this value has no rung form (an edge, or always on; not yet)",
                        ))
                    }
                }
            }
            Op::Stack(e @ ("EU" | "ED")) => edge(cx.text, top(st), e == "EU", at)?,
            Op::Stack("LPS") => {
                let Some(Item::Power { s, rel }) = st.pop() else {
                    unreachable!()
                };
                st.push(Item::Fork {
                    base: s,
                    rel,
                    branches: Vec::new(),
                });
                st.push(Item::Power {
                    s: Vec::new(),
                    rel: true,
                });
            }
            Op::Stack(lrd_lpp) => {
                let Some(Item::Power { s, .. }) = st.pop() else {
                    unreachable!()
                };
                let Some(Item::Fork { branches, .. }) = st.last_mut() else {
                    unreachable!()
                };
                if !s.is_empty() {
                    branches.push(s);
                }
                if lrd_lpp == "LRD" {
                    st.push(Item::Power {
                        s: Vec::new(),
                        rel: true,
                    });
                } else {
                    let Some(Item::Fork {
                        mut base,
                        rel,
                        branches,
                    }) = st.pop()
                    else {
                        unreachable!()
                    };
                    if !branches.is_empty() {
                        base.push(el(ElementKind::Branch(branches), at));
                    }
                    st.push(Item::Power { s: base, rel });
                }
            }
            Op::Out(e) => top(st).push(e),
            Op::Boxed(e) => top(st).push(el(ElementKind::Branch(vec![vec![e]]), at)),
            Op::Counter {
                down,
                instance,
                pv,
                at,
            } => {
                let Some(Item::Power { s, rel: false }) = st.pop() else {
                    return Ok(false);
                };
                let aux = counter_aux(cx.text, s, at)?;
                let c = syntax::Counter {
                    down,
                    instance: name(&instance, at),
                    pv,
                    aux,
                };
                top(st).push(el(
                    ElementKind::Branch(vec![vec![el(ElementKind::Counter(Box::new(c)), at)]]),
                    at,
                ));
            }
            Op::Alone(e) => st.push(Item::Power {
                s: vec![e],
                rel: false,
            }),
        }
        Ok(true)
    }
}

fn top(st: &mut [Item]) -> &mut Series<'static> {
    match st.last_mut() {
        Some(Item::Power { s, .. }) => s,
        _ => unreachable!("the stack check puts a value on top"),
    }
}

/// A path ending in a one-branch Branch (a timer kept apart) ends with its content instead.
fn unwrap_tail(mut s: Series<'static>) -> Series<'static> {
    if let Some(Element {
        kind: ElementKind::Branch(bs),
        ..
    }) = s.last()
    {
        if bs.len() == 1 {
            let Some(Element {
                kind: ElementKind::Branch(mut bs),
                ..
            }) = s.pop()
            else {
                unreachable!()
            };
            s.append(&mut bs[0]);
        }
    }
    s
}
