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
//! listings do) is built *flat* instead ([`flat`]): every output gets its own path whose
//! conditions are the whole stack value, valid only when re-reading those conditions reads what
//! the S7-200 read (no edge read twice, no variable re-read after the network wrote it; else an
//! error). Zhou & Zhang 2015 give the stack shapes; S7-200 system manual, chapter 6.

use super::operand::Context;
use super::{error, Ins, RawNet};
use crate::diag::{LoadError, Origin};
use crate::model::{ArithOp, CmpOp, TimerKind};
use crate::syntax::{self, Element, ElementKind, Located, Rung, Series};
use std::borrow::Cow;

type E = Element<'static>;

const LEVELS: usize = 9;

fn name(s: &str, at: usize) -> syntax::Name<'static> {
    Located {
        value: Cow::Owned(s.to_string()),
        origin: Origin::at(at),
    }
}

fn el(kind: ElementKind<'static>, at: usize) -> E {
    Element {
        origin: Origin::at(at),
        kind,
    }
}

fn contact(var: &str, negated: bool, at: usize) -> E {
    el(
        ElementKind::Contact {
            var: name(var, at),
            negated,
            edge: None,
        },
        at,
    )
}

/// The first rung of a main program that reads SM0.1: SM0.1 is on until the first scan ends.
pub(super) fn first_scan_rung(at: usize) -> Rung<'static> {
    let seen = "SM0_1_seen";
    let body = vec![el(
        ElementKind::Branch(vec![
            vec![
                contact(seen, true, at),
                el(
                    ElementKind::Coil {
                        var: name("SM0_1", at),
                        negated: false,
                    },
                    at,
                ),
            ],
            vec![el(ElementKind::Set(name(seen, at)), at)],
        ]),
        at,
    )];
    Rung {
        origin: Origin::at(at),
        id: name("SM0_1", at),
        label: None,
        comment: Some(Cow::Borrowed("SM0.1: on in the first scan only")),
        ld: body,
        ld_origin: Origin::at(at),
        problem: None,
        problem_in_rung: false,
    }
}

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
            label = Some(Box::new(name(l.text, l.at)));
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
        _ if cmp("A") || cmp("O") => (1, 0, 0),
        _ if op.len() == 2 && "+-*/".contains(&op[..1]) && "IDR".contains(&op[1..]) => (1, 0, 0),
        "ALD" | "OLD" | "CTU" | "CTD" => (2, 1, 0),
        "LPP" => (1, 1, 0),
        "CRET" | "RET" | "MEND" | "NEXT" | "LBL" => (0, 0, 0),
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
                    "no LPS is open".to_string()
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

/// The kinds of instruction the builders share.
enum Op {
    /// A condition: loaded (`LD` …) or ANDed (`A` …) or ORed (`O` …) into the top.
    Cond(char, E),
    /// An element that acts on the top's power and passes it on unchanged.
    Out(E),
    /// A timer (its Q is not the power on): kept apart in its own branch.
    Boxed(E),
    Counter {
        down: bool,
        instance: String,
        pv: syntax::Operand<'static>,
        at: usize,
    },
    Stack(&'static str),
    /// RET, MEND, NEXT with nothing loaded: unconditional.
    Alone(E),
}

fn cmp_op(s: &str) -> CmpOp {
    match s {
        "=" => CmpOp::Eq,
        "<>" => CmpOp::Ne,
        "<" => CmpOp::Lt,
        "<=" => CmpOp::Le,
        ">" => CmpOp::Gt,
        _ => CmpOp::Ge,
    }
}

fn arg<'a>(cx: &Context, ins: &'a Ins, k: usize, n: usize) -> Result<super::Tok<'a>, LoadError> {
    if ins.args.len() != n {
        return Err(error(
            cx.text,
            ins.at,
            format!("{} takes {n} operand(s), found {}", ins.op, ins.args.len()),
        ));
    }
    Ok(ins.args[k])
}

/// Decodes one instruction (the stack check has accepted its mnemonic).
fn decode(cx: &mut Context, ins: &Ins, empty: bool) -> Result<Op, LoadError> {
    let at = ins.at;
    let op = ins.op.as_str();
    let kind = |k| el(k, at);
    Ok(match op {
        "LD" | "LDN" | "A" | "AN" | "O" | "ON" => {
            let t = arg(cx, ins, 0, 1)?;
            let mode = op.chars().next().unwrap_or('L');
            if op == "LD" && t.text.eq_ignore_ascii_case("SM0.0") {
                return Ok(Op::Stack("TRUE"));
            }
            let v = cx.bit(t)?;
            Op::Cond(mode, contact(&v, op.ends_with('N'), t.at))
        }
        "ALD" | "OLD" | "LPS" | "LRD" | "LPP" | "NOT" | "EU" | "ED" => Op::Stack(match op {
            "ALD" => "ALD",
            "OLD" => "OLD",
            "LPS" => "LPS",
            "LRD" => "LRD",
            "LPP" => "LPP",
            "NOT" => "NOT",
            "EU" => "EU",
            _ => "ED",
        }),
        "=" | "S" | "R" => {
            let n = if op == "=" { 1 } else { 2 };
            let t = arg(cx, ins, 0, n)?;
            if n == 2 && ins.args[1].text != "1" {
                return Err(error(
                    cx.text,
                    ins.args[1].at,
                    format!(
                        "{op} of {} bits is not read yet (only `{op} x, 1`)",
                        ins.args[1].text
                    ),
                ));
            }
            let v = name(&cx.bit(t)?, t.at);
            Op::Out(kind(match op {
                "=" => ElementKind::Coil {
                    var: v,
                    negated: false,
                },
                "S" => ElementKind::Set(v),
                _ => ElementKind::Reset(v),
            }))
        }
        "TON" | "TOF" => {
            let (t, p) = (arg(cx, ins, 0, 2)?, arg(cx, ins, 1, 2)?);
            let ty = if op == "TON" { "TON" } else { "TOF" };
            let instance = name(&cx.instance(t, ty)?, t.at);
            let pt = cx.pt(t, p)?;
            let kind2 = if op == "TON" {
                TimerKind::Ton
            } else {
                TimerKind::Tof
            };
            Op::Boxed(kind(ElementKind::Timer(Box::new(syntax::Timer {
                kind: kind2,
                instance,
                pt,
            }))))
        }
        "CTU" | "CTD" => {
            let (c, p) = (arg(cx, ins, 0, 2)?, arg(cx, ins, 1, 2)?);
            let instance = cx.instance(c, if op == "CTU" { "CTU" } else { "CTD" })?;
            Op::Counter {
                down: op == "CTD",
                instance,
                pv: cx.word(p, 'W')?,
                at,
            }
        }
        "MOVW" | "MOVD" | "MOVR" => {
            let fam = op.chars().nth(3).unwrap_or('W');
            let (a, b) = (arg(cx, ins, 0, 2)?, arg(cx, ins, 1, 2)?);
            let from = cx.word(a, fam)?;
            let to = cx.word(b, fam)?;
            let to = name(to.value.as_str().unwrap_or(b.text), b.at);
            Op::Out(kind(ElementKind::Move(Box::new(syntax::Move { from, to }))))
        }
        "JMP" => Op::Out(kind(ElementKind::Jmp(name(arg(cx, ins, 0, 1)?.text, at)))),
        "CALL" => Op::Out(kind(ElementKind::Call(name(arg(cx, ins, 0, 1)?.text, at)))),
        "END" => Op::Out(kind(ElementKind::End)),
        "MEND" if empty => Op::Alone(kind(ElementKind::End)),
        "MEND" => Op::Out(kind(ElementKind::End)),
        "CRET" | "RET" if empty => Op::Alone(kind(ElementKind::Ret)),
        "CRET" | "RET" => Op::Out(kind(ElementKind::Ret)),
        "NEXT" => Op::Alone(kind(ElementKind::Next)),
        "FOR" => {
            let v = arg(cx, ins, 0, 3)?;
            let var = name(v.text.strip_prefix('#').unwrap_or(v.text), v.at);
            let from = cx.word(ins.args[1], 'W')?;
            let to = cx.word(ins.args[2], 'W')?;
            Op::Out(kind(ElementKind::For(Box::new(syntax::For {
                var,
                from,
                to,
            }))))
        }
        _ if op.len() == 2 => {
            let fam = match &op[1..] {
                "I" => 'W',
                "D" => 'D',
                _ => 'R',
            };
            let (a, b) = (arg(cx, ins, 0, 2)?, arg(cx, ins, 1, 2)?);
            let inb = cx.word(a, fam)?;
            let out = cx.word(b, fam)?;
            let op2 = match &op[..1] {
                "+" => ArithOp::Add,
                "-" => ArithOp::Sub,
                "*" => ArithOp::Mul,
                _ => ArithOp::Div,
            };
            let outn = name(out.value.as_str().unwrap_or(b.text), b.at);
            Op::Out(kind(ElementKind::Arith(Box::new(syntax::Arith {
                op: op2,
                a: out,
                b: inb,
                out: outn,
            }))))
        }
        _ => {
            // A compare: LDW>= a, b and the A/O, D/R forms.
            let (mode, rest) = (
                op.chars().next().unwrap_or('L'),
                op.trim_start_matches("LD"),
            );
            let rest = if mode == 'L' { rest } else { &op[1..] };
            let fam = rest.chars().next().unwrap_or('W');
            let (a, b) = (arg(cx, ins, 0, 2)?, arg(cx, ins, 1, 2)?);
            let c = syntax::Compare {
                op: cmp_op(&rest[1..]),
                a: cx.word(a, fam)?,
                b: cx.word(b, fam)?,
            };
            Op::Cond(mode, kind(ElementKind::Compare(Box::new(c))))
        }
    })
}

/// The negation of a pure condition series (De Morgan), if it has one in the format.
fn negate(s: &[E]) -> Option<Series<'static>> {
    let one = |e: &E| -> Option<Series<'static>> {
        match &e.kind {
            ElementKind::Contact {
                var,
                negated,
                edge: None,
            } => Some(vec![contact(
                var.as_str(),
                !negated,
                e.origin.offset().unwrap_or(0),
            )]),
            ElementKind::Compare(c) => {
                let op = match c.op {
                    CmpOp::Eq => CmpOp::Ne,
                    CmpOp::Ne => CmpOp::Eq,
                    CmpOp::Lt => CmpOp::Ge,
                    CmpOp::Ge => CmpOp::Lt,
                    CmpOp::Gt => CmpOp::Le,
                    CmpOp::Le => CmpOp::Gt,
                };
                Some(vec![Element {
                    origin: e.origin,
                    kind: ElementKind::Compare(Box::new(syntax::Compare {
                        op,
                        a: c.a.clone(),
                        b: c.b.clone(),
                    })),
                }])
            }
            ElementKind::Or(bs) => {
                let mut out = Vec::new();
                for b in bs {
                    out.extend(negate(b)?);
                }
                Some(out)
            }
            _ => None,
        }
    };
    match s {
        [] => None,
        [e] => one(e),
        _ => {
            let bs: Option<Vec<Series>> = s.iter().map(one).collect();
            Some(vec![el(
                ElementKind::Or(bs?),
                s[0].origin.offset().unwrap_or(0),
            )])
        }
    }
}

/// The OR of two pure series (TRUE, the empty series, absorbs).
fn or(a: Series<'static>, b: Series<'static>) -> Series<'static> {
    if a.is_empty() || b.is_empty() {
        return Vec::new();
    }
    let at = a[0].origin.offset().unwrap_or(0);
    let branches = |s: Series<'static>| match <[E; 1]>::try_from(s) {
        Ok(
            [Element {
                kind: ElementKind::Or(bs),
                ..
            }],
        ) => bs,
        Ok([e]) => vec![vec![e]],
        Err(s) => vec![s],
    };
    let mut bs = branches(a);
    bs.extend(branches(b));
    vec![el(ElementKind::Or(bs), at)]
}

fn is_pure(s: &[E]) -> bool {
    s.iter().all(|e| e.kind.is_condition())
}

/// An edge on the single contact just loaded.
fn edge(text: &str, s: &mut [E], rising: bool, at: usize) -> Result<(), LoadError> {
    match s {
        [Element {
            kind:
                ElementKind::Contact {
                    negated: false,
                    edge: e @ None,
                    ..
                },
            ..
        }] => {
            *e = Some(if rising {
                syntax::Edge::Rising
            } else {
                syntax::Edge::Falling
            });
            Ok(())
        }
        _ => Err(error(
            text,
            at,
            "EU/ED is read only right after `LD bit` (an edge of a compound condition is not yet)",
        )),
    }
}

/// The reset (CTU) or load (CTD) input of a counter: one bit, or SM0.0 (TRUE) negated or not.
fn counter_aux(
    text: &str,
    s: Series<'static>,
    at: usize,
) -> Result<syntax::Operand<'static>, LoadError> {
    let value = match &s[..] {
        [] => syntax::Scalar::Bool(true),
        [Element {
            kind:
                ElementKind::Contact {
                    var,
                    negated,
                    edge: None,
                },
            ..
        }] if var.as_str() == "SM0_0" => syntax::Scalar::Bool(!negated),
        [Element {
            kind:
                ElementKind::Contact {
                    var,
                    negated: false,
                    edge: None,
                },
            ..
        }] => syntax::Scalar::Str(Cow::Owned(var.as_str().to_string())),
        _ => {
            return Err(error(
                text,
                at,
                "the reset/load input of a counter must be one bit (not yet: a condition)",
            ))
        }
    };
    Ok(Located {
        value,
        origin: Origin::at(at),
    })
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

/// The bases of the variables a condition element reads.
fn reads(e: &E, out: &mut Vec<String>) {
    let base = |s: &str| s.split('.').next().unwrap_or(s).to_string();
    match &e.kind {
        ElementKind::Contact { var, .. } => out.push(base(var.as_str())),
        ElementKind::Compare(c) => {
            for o in [&c.a, &c.b] {
                if let Some(s) = o.value.as_str() {
                    out.push(base(s));
                }
            }
        }
        ElementKind::Or(bs) => bs.iter().flatten().for_each(|x| reads(x, out)),
        _ => {}
    }
}

/// The variable an output element writes (`None`: it writes nothing; `*` anything, a call).
fn writes(e: &E) -> Option<String> {
    Some(match &e.kind {
        ElementKind::Coil { var, .. } | ElementKind::Set(var) | ElementKind::Reset(var) => {
            var.as_str().to_string()
        }
        ElementKind::Move(m) => m.to.as_str().to_string(),
        ElementKind::Arith(a) => a.out.as_str().to_string(),
        ElementKind::Timer(t) => t.instance.as_str().to_string(),
        ElementKind::Counter(c) => c.instance.as_str().to_string(),
        ElementKind::For(f) => f.var.as_str().to_string(),
        ElementKind::Call(_) => "*".into(),
        _ => return None,
    })
}

/// A condition with the number of writes done when the S7-200 evaluated it.
type Timed = (E, usize);

/// The flat build: exact stack semantics on pure conditions, one path per run of outputs.
fn flat(cx: &mut Context, code: &[Ins]) -> Result<Series<'static>, LoadError> {
    let mut st: Vec<(Vec<Timed>, u32)> = Vec::new();
    let mut paths: Vec<(Series<'static>, u32, bool)> = Vec::new();
    let mut written: Vec<String> = Vec::new();
    let mut version = 0u32;
    let mut edges_used = 0usize;
    let mut i = 0;
    while i < code.len() {
        let ins = &code[i];
        let at = ins.at;
        let clock = written.len();
        let mut fresh = |v: &mut u32| {
            version += 1;
            *v = version;
        };
        let mut out: Option<(E, bool)> = None;
        match decode(cx, ins, st.is_empty())? {
            Op::Stack("TRUE") => st.push((Vec::new(), 0)),
            Op::Cond('L', e) => {
                st.push((vec![(e, clock)], 0));
                fresh(&mut st.last_mut().expect("pushed").1);
            }
            Op::Cond(m, e) => {
                let t = st.last_mut().expect("checked");
                if m == 'A' {
                    t.0.push((e, clock));
                } else {
                    let s: Series<'static> = t.0.drain(..).map(|x| x.0).collect();
                    t.0 = or(s, vec![e]).into_iter().map(|x| (x, clock)).collect();
                }
                fresh(&mut t.1);
            }
            Op::Stack(s @ ("ALD" | "OLD")) => {
                let (b, _) = st.pop().expect("checked");
                let t = st.last_mut().expect("checked");
                if s == "ALD" {
                    t.0.extend(b);
                } else {
                    let a: Series<'static> = t.0.drain(..).map(|x| x.0).collect();
                    let b: Series<'static> = b.into_iter().map(|x| x.0).collect();
                    t.0 = or(a, b).into_iter().map(|x| (x, clock)).collect();
                }
                fresh(&mut t.1);
            }
            Op::Stack("NOT") => {
                let t = st.last_mut().expect("checked");
                let s: Series<'static> = t.0.iter().map(|x| x.0.clone()).collect();
                let Some(n) = negate(&s) else {
                    return Err(error(
                        cx.text,
                        at,
                        "NOT of this value has no rung form (an edge, or always on; not yet)",
                    ));
                };
                t.0 = n.into_iter().map(|x| (x, clock)).collect();
                fresh(&mut t.1);
            }
            Op::Stack(e @ ("EU" | "ED")) => {
                let t = st.last_mut().expect("checked");
                let mut s: Series<'static> = t.0.iter().map(|x| x.0.clone()).collect();
                edge(cx.text, &mut s, e == "EU", at)?;
                t.0 = s.into_iter().map(|x| (x, clock)).collect();
                fresh(&mut t.1);
            }
            Op::Stack("LPS") => {
                let t = st.last().expect("checked").clone();
                st.push(t);
            }
            Op::Stack("LRD") => {
                let t = st[st.len() - 2].clone();
                *st.last_mut().expect("checked") = t;
            }
            Op::Stack(_) => {
                st.pop();
            }
            Op::Out(e) => out = Some((e, true)),
            Op::Boxed(e) => out = Some((e, false)),
            Op::Counter {
                down,
                instance,
                pv,
                at,
            } => {
                let (r, _) = st.pop().expect("checked");
                let aux = counter_aux(cx.text, r.into_iter().map(|x| x.0).collect(), at)?;
                let c = syntax::Counter {
                    down,
                    instance: name(&instance, at),
                    pv,
                    aux,
                };
                out = Some((el(ElementKind::Counter(Box::new(c)), at), false));
            }
            Op::Alone(e) => paths.push((vec![e], 0, false)),
        }
        if let Some((e, keeps)) = out {
            let (cond, v) = st.last().expect("checked").clone();
            let w = writes(&e);
            match paths.last_mut() {
                Some((p, pv, true)) if *pv == v && v != 0 => {
                    p.push(e);
                    paths.last_mut().expect("some").2 = keeps;
                }
                _ => {
                    for (c, t) in &cond {
                        let mut r = Vec::new();
                        reads(c, &mut r);
                        if let Some(x) = r
                            .iter()
                            .find(|x| written[*t..].iter().any(|w| w == *x || w == "*"))
                        {
                            return Err(error(cx.text, at, format!("this network re-reads `{x}` after writing it: no rung has its shape (not yet)")));
                        }
                        if matches!(c.kind, ElementKind::Contact { edge: Some(_), .. }) {
                            edges_used += 1;
                        }
                    }
                    let mut p: Series<'static> = cond.into_iter().map(|x| x.0).collect();
                    p.push(e);
                    paths.push((p, v, keeps));
                }
            }
            if edges_used > 1 {
                return Err(error(cx.text, at, "an edge (EU/ED) would be evaluated twice: no rung has this network's shape (not yet)"));
            }
            written.extend(w);
        }
        i += 1;
    }
    let mut paths: Vec<Series<'static>> = paths.into_iter().map(|p| p.0).collect();
    Ok(match paths.len() {
        0 => Vec::new(),
        1 => paths.pop().expect("one"),
        _ => vec![el(ElementKind::Branch(paths), code[0].at)],
    })
}
