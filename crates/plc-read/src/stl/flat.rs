//! The flat build of a network whose shape no rung's LAD shape holds (an O or OLD on a value
//! that already fed outputs, as Zhou & Zhang 2015 print): the S7-200 logic stack executed
//! exactly on pure conditions, one rung path per run of outputs on the same stack value, each
//! path's conditions the whole value. Valid only when re-reading those conditions reads what
//! the S7-200 read: a condition re-read after the network wrote its variable, or an edge read
//! twice, is an error (not yet), never a silently different rung.

use super::decode::{counter_aux, decode, edge, negate, or, Op};
use super::operand::Context;
use super::tree::{el, name, E};
use super::{error, Ins};
use plc_diag::LoadError;
use plc_syntax::{self as syntax, ElementKind, Series};

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
        ElementKind::Function(f) => f.out.as_str().to_string(),
        ElementKind::Timer(t) => t.instance.as_str().to_string(),
        ElementKind::Counter(c) => c.instance.as_str().to_string(),
        ElementKind::For(f) => f.var.as_str().to_string(),
        ElementKind::Call(_) => "*".into(),
        _ => return None,
    })
}

/// A condition with the number of writes done when the S7-200 evaluated it.
type Timed = (E, usize);

/// When the earliest of `s` was evaluated (a combination is as old as its oldest part).
fn earliest(s: &[Timed], now: usize) -> usize {
    s.iter().map(|x| x.1).min().unwrap_or(now)
}

/// The flat build: exact stack semantics on pure conditions, one path per run of outputs.
pub(super) fn flat(cx: &mut Context, code: &[Ins]) -> Result<Series<'static>, LoadError> {
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
                    let c = earliest(&t.0, clock);
                    let s: Series<'static> = t.0.drain(..).map(|x| x.0).collect();
                    t.0 = or(s, vec![e]).into_iter().map(|x| (x, c)).collect();
                }
                fresh(&mut t.1);
            }
            Op::Stack(s @ ("ALD" | "OLD")) => {
                let (b, _) = st.pop().expect("checked");
                let t = st.last_mut().expect("checked");
                if s == "ALD" {
                    t.0.extend(b);
                } else {
                    let c = earliest(&t.0, clock).min(earliest(&b, clock));
                    let a: Series<'static> = t.0.drain(..).map(|x| x.0).collect();
                    let b: Series<'static> = b.into_iter().map(|x| x.0).collect();
                    t.0 = or(a, b).into_iter().map(|x| (x, c)).collect();
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
                let c = earliest(&t.0, clock);
                t.0 = n.into_iter().map(|x| (x, c)).collect();
                fresh(&mut t.1);
            }
            Op::Stack(e @ ("EU" | "ED")) => {
                let t = st.last_mut().expect("checked");
                let mut s: Series<'static> = t.0.iter().map(|x| x.0.clone()).collect();
                edge(cx.text, &mut s, e == "EU", at)?;
                let c = earliest(&t.0, clock);
                t.0 = s.into_iter().map(|x| (x, c)).collect();
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
