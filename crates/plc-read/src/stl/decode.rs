//! STL instructions → the element kinds of the surface syntax, and the small rewrites both
//! network builders share: De Morgan for NOT, OR of two conditions, an edge on one contact, a
//! counter's reset/load bit. The mnemonics are the S7-200 system manual's (chapter 6).

use super::operand::Context;
use super::tree::{contact, el, name, E};
use super::{error, Ins};
use plc_diag::{LoadError, Origin};
use plc_model::{ArithOp, CmpOp, Function, TimerKind, Type};
use plc_syntax::{self as syntax, Element, ElementKind, Located, Series};
use std::borrow::Cow;

pub(super) const LEVELS: usize = 9;

/// The largest label number Micro/WIN gives (`LBL 0` … `LBL 255`).
pub(super) const MAX_LABEL: u32 = 255;

/// The label operand of an LBL or JMP: a number `0..=MAX_LABEL`, as Micro/WIN writes labels,
/// or a name (as `plc-deps il` writes the labels of other formats).
pub(super) fn label(text: &str, t: super::Tok) -> Result<syntax::Name<'static>, LoadError> {
    if t.text.bytes().all(|b| b.is_ascii_digit())
        && t.text.parse::<u32>().map_or(true, |n| n > MAX_LABEL)
    {
        return Err(error(
            text,
            t.at,
            format!(
                "label {} is out of range (S7-200 labels are numbered 0 to {MAX_LABEL})",
                t.text
            ),
        ));
    }
    Ok(name(t.text, t.at))
}

/// The kinds of instruction the builders share.
pub(super) enum Op {
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

pub(super) fn cmp_op(s: &str) -> CmpOp {
    match s {
        "=" => CmpOp::Eq,
        "<>" => CmpOp::Ne,
        "<" => CmpOp::Lt,
        "<=" => CmpOp::Le,
        ">" => CmpOp::Gt,
        _ => CmpOp::Ge,
    }
}

pub(super) fn arg<'a>(
    cx: &Context,
    ins: &'a Ins,
    k: usize,
    n: usize,
) -> Result<super::Tok<'a>, LoadError> {
    if ins.args.len() != n {
        return Err(error(
            cx.text,
            ins.at,
            format!("{} takes {n} operand(s), found {}", ins.op, ins.args.len()),
        ));
    }
    Ok(ins.args[k])
}

/// The N of `S bit, N` / `R bit, N`: 1 to 255 bits.
fn bit_count(cx: &Context, t: super::Tok) -> Result<u32, LoadError> {
    match t.text.strip_prefix('+').unwrap_or(t.text).parse::<u32>() {
        Ok(n @ 1..=255) => Ok(n),
        _ => Err(error(
            cx.text,
            t.at,
            format!("the number of bits must be 1 to 255, found `{}`", t.text),
        )),
    }
}

/// The bit `k` places after absolute bit `start` (`M0.7` + 1 is `M1.0`).
fn next_bit(start: &str, k: u32) -> Option<String> {
    let up = start.to_ascii_uppercase();
    let area = ["I", "Q", "M", "V"]
        .into_iter()
        .find(|a| up.starts_with(a) && !up.starts_with("SM"))?;
    let (byte, bit) = up[1..].split_once('.')?;
    let at = byte.parse::<u32>().ok()? * 8 + bit.parse::<u32>().ok().filter(|b| *b < 8)? + k;
    Some(format!("{area}{}.{}", at / 8, at % 8))
}

/// Decodes one instruction (the stack check has accepted its mnemonic).
pub(super) fn decode(cx: &mut Context, ins: &Ins, empty: bool) -> Result<Op, LoadError> {
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
            let count = if n == 2 {
                bit_count(cx, ins.args[1])?
            } else {
                1
            };
            let mut outs = Vec::new();
            for k in 0..count {
                let bit = match k {
                    0 => t.text.to_string(),
                    _ => next_bit(t.text, k).ok_or_else(|| {
                        error(cx.text, t.at, format!("{op} of {count} bits needs an absolute bit address (I, Q, M, V) to count from"))
                    })?,
                };
                let v = name(
                    &cx.bit(super::Tok {
                        text: &bit,
                        at: t.at,
                    })?,
                    t.at,
                );
                outs.push(kind(match op {
                    "=" => ElementKind::Coil {
                        var: v,
                        negated: false,
                    },
                    "S" => ElementKind::Set(v),
                    _ => ElementKind::Reset(v),
                }));
            }
            match outs.len() {
                1 => Op::Out(outs.pop().expect("one")),
                _ => Op::Out(kind(ElementKind::Branch(vec![outs]))),
            }
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
        "SQRT" | "LN" | "EXP" | "SIN" | "COS" | "TAN" | "I_DI" | "DI_R" | "ROUND" | "TRUNC" => {
            // IN, OUT: the standard function (the conversions: INT_TO_DINT, DINT_TO_REAL,
            // REAL_TO_DINT, TRUNC to a DINT).
            let (func, fi, fo) = match op {
                "I_DI" => (
                    Function::Convert {
                        from: Type::Int,
                        to: Type::Dint,
                    },
                    'W',
                    'D',
                ),
                "DI_R" => (
                    Function::Convert {
                        from: Type::Dint,
                        to: Type::Real,
                    },
                    'D',
                    'R',
                ),
                "ROUND" => (
                    Function::Convert {
                        from: Type::Real,
                        to: Type::Dint,
                    },
                    'R',
                    'D',
                ),
                "TRUNC" => (Function::Trunc, 'R', 'D'),
                _ => (Function::parse(op).unwrap_or(Function::Sqrt), 'R', 'R'),
            };
            let (a, b) = (arg(cx, ins, 0, 2)?, arg(cx, ins, 1, 2)?);
            let inp = cx.word(a, fi)?;
            let out = cx.word(b, fo)?;
            let out = name(out.value.as_str().unwrap_or(b.text), b.at);
            Op::Out(kind(ElementKind::Function(Box::new(
                syntax::FunctionCall {
                    func,
                    args: vec![inp],
                    out,
                },
            ))))
        }
        "SLW" | "SRW" | "RLW" | "RRW" | "SLD" | "SRD" | "RLD" | "RRD" => {
            // OUT, N: OUT := SHL/SHR/ROL/ROR(OUT, N).
            let func = match &op[..2] {
                "SL" => Function::Shl,
                "SR" => Function::Shr,
                "RL" => Function::Rol,
                _ => Function::Ror,
            };
            let fam = if op.ends_with('W') { 'W' } else { 'D' };
            let (a, b) = (arg(cx, ins, 0, 2)?, arg(cx, ins, 1, 2)?);
            let cur = cx.word(a, fam)?;
            let n = cx.word(b, 'W')?;
            let out = name(cur.value.as_str().unwrap_or(a.text), a.at);
            Op::Out(kind(ElementKind::Function(Box::new(
                syntax::FunctionCall {
                    func,
                    args: vec![cur, n],
                    out,
                },
            ))))
        }
        "ANDW" | "ORW" | "XORW" | "ANDD" | "ORD" | "XORD" => {
            // IN1, OUT: OUT := AND/OR/XOR(IN1, OUT), bit by bit.
            let func = match &op[..op.len() - 1] {
                "AND" => Function::And,
                "OR" => Function::Or,
                _ => Function::Xor,
            };
            let fam = if op.ends_with('W') { 'W' } else { 'D' };
            let (a, b) = (arg(cx, ins, 0, 2)?, arg(cx, ins, 1, 2)?);
            let inp = cx.word(a, fam)?;
            let cur = cx.word(b, fam)?;
            let out = name(cur.value.as_str().unwrap_or(b.text), b.at);
            Op::Out(kind(ElementKind::Function(Box::new(
                syntax::FunctionCall {
                    func,
                    args: vec![inp, cur],
                    out,
                },
            ))))
        }
        "INVW" | "INVD" => {
            // OUT: OUT := NOT(OUT), every bit inverted.
            let fam = if op.ends_with('W') { 'W' } else { 'D' };
            let a = arg(cx, ins, 0, 1)?;
            let cur = cx.word(a, fam)?;
            let out = name(cur.value.as_str().unwrap_or(a.text), a.at);
            Op::Out(kind(ElementKind::Function(Box::new(
                syntax::FunctionCall {
                    func: Function::Not,
                    args: vec![cur],
                    out,
                },
            ))))
        }
        "JMP" => {
            let l = label(cx.text, arg(cx, ins, 0, 1)?)?;
            Op::Out(kind(ElementKind::Jmp(name(&l.value, at))))
        }
        "CALL" => Op::Out(kind(ElementKind::Call(name(arg(cx, ins, 0, 1)?.text, at)))),
        "END" => Op::Out(kind(ElementKind::End)),
        "MEND" if empty => Op::Alone(kind(ElementKind::End)),
        "MEND" => Op::Out(kind(ElementKind::End)),
        "CRET" | "RET" | "CRETI" | "RETI" if empty => Op::Alone(kind(ElementKind::Ret)),
        "CRET" | "RET" | "CRETI" | "RETI" => Op::Out(kind(ElementKind::Ret)),
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
pub(super) fn negate(s: &[E]) -> Option<Series<'static>> {
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
                let op = c.op.negated();
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
pub(super) fn or(a: Series<'static>, b: Series<'static>) -> Series<'static> {
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

pub(super) fn is_pure(s: &[E]) -> bool {
    s.iter().all(|e| e.kind.is_condition())
}

/// An edge on the single contact just loaded.
pub(super) fn edge(text: &str, s: &mut [E], rising: bool, at: usize) -> Result<(), LoadError> {
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
pub(super) fn counter_aux(
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
