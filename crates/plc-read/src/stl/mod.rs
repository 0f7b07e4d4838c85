//! S7-200 Statement List (STL, "AWL"), as STEP 7-Micro/WIN exports it and `plc-deps il` writes
//! it → the surface syntax ([`plc_syntax`]), so that resolution, analysis, `run`, `order` and
//! `c` are the JSON format's.
//!
//! A file is declaration sections (`VAR_INPUT`, `VAR_OUTPUT`, `VAR` … `END_VAR`: `name : TYPE
//! [:= value];`) and blocks: `ORGANIZATION_BLOCK name[:OB1]` (the main program),
//! `SUBROUTINE_BLOCK name[:SBRn]` (a subroutine, with its own `VAR` sections), `INTERRUPT_BLOCK`
//! (read as a subroutine nothing calls, with a warning) … `END_…`, each holding `NETWORK n`
//! (with an optional `// title` or `TITLE=` line) and one instruction per line; `//` starts a
//! comment. Operands are symbolic names (`#x` a subroutine local) or absolute addresses:
//! `I0.0`, `Q0.0`, `M0.0`, `V10.1` bits (variables `I0_0` …, class input, output, memory; the
//! format's names have no dots), `VW`/`MW` words (INT), `VD`/`MD` double words (DINT, REAL for
//! the R instructions), `T37`/`C5` timers and counters (typed by their instruction, the PT in the
//! timer's resolution), `SM0.0` always on, `SM0.1` on in the first scan only; `S M0.0, N` / `R M0.0, N` act on N
//! consecutive bits. [`net`] executes
//! the 9-level logic stack of each network at read time and rebuilds it as one rung.
//!
//! Invariants: every error carries the file's line and column; a program loads whole or not at
//! all; an instruction the reader does not know is an error, never skipped. The format and the
//! instruction set: docs/il.md; the stack shapes follow Zhou & Zhang 2015 and the S7-200 system
//! manual.

mod decode;
mod flat;
mod net;
mod operand;
mod tree;

use plc_diag::{LoadError, Origin};
use plc_syntax::{self as syntax, Body, Located, RoutineKind, Subroutine, Var, VarClass};
use std::borrow::Cow;

pub use crate::plcopen::Note;

/// True when the text reads as STL: its first line that is neither blank nor a comment starts
/// a declaration section or a block.
pub fn looks_like_stl(text: &str) -> bool {
    let first = text
        .lines()
        .map(|l| l.split("//").next().unwrap_or("").trim())
        .find(|l| !l.is_empty());
    first.is_some_and(|l| {
        let w = l
            .split_whitespace()
            .next()
            .unwrap_or("")
            .to_ascii_uppercase();
        matches!(
            w.as_str(),
            "ORGANIZATION_BLOCK"
                | "SUBROUTINE_BLOCK"
                | "INTERRUPT_BLOCK"
                | "VAR"
                | "VAR_INPUT"
                | "VAR_OUTPUT"
                | "VAR_GLOBAL"
                | "NETWORK"
        )
    })
}

/// A syntax error at byte `at` of `text`.
pub(crate) fn error(text: &str, at: usize, message: impl Into<String>) -> LoadError {
    let (line, column) = Origin::at(at).line_column(text).unwrap_or((1, 1));
    LoadError::Syntax {
        line: line as usize,
        column: column as usize,
        message: message.into(),
    }
}

/// One token of a line: its text and byte offset.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Tok<'a> {
    pub text: &'a str,
    pub at: usize,
}

/// One instruction line: the mnemonic (upper case) and its operands.
#[derive(Clone, Debug)]
pub(crate) struct Ins<'a> {
    pub op: String,
    pub at: usize,
    pub args: Vec<Tok<'a>>,
}

/// A block as read.
pub(crate) struct Block<'a> {
    pub kind: String,
    pub name: String,
    pub at: usize,
    pub name_at: usize,
    pub nets: Vec<RawNet<'a>>,
    pub vars: Vec<Var<'static>>,
}

/// A network as read: number, title, instructions.
pub(crate) struct RawNet<'a> {
    pub number: Tok<'a>,
    pub title: Option<&'a str>,
    pub code: Vec<Ins<'a>>,
}

/// The lines of `text` without comments: (offset of the line's first non-blank byte, the
/// trimmed text, the comment after `//`).
fn lines(text: &str) -> Vec<(usize, &str, Option<&str>)> {
    let mut out = Vec::new();
    let mut start = 0;
    for line in text.split_inclusive('\n') {
        let (code, comment) = match line.find("//") {
            Some(i) => (&line[..i], Some(line[i + 2..].trim())),
            None => (line, None),
        };
        let lead = code.len() - code.trim_start().len();
        let t = code.trim();
        if !t.is_empty() || comment.is_some() {
            out.push((start + lead, t, comment));
        }
        start += line.len();
    }
    out
}

fn words(s: &str) -> (&str, &str) {
    match s.find(char::is_whitespace) {
        Some(i) => (&s[..i], s[i..].trim_start()),
        None => (s, ""),
    }
}

/// Splits the operands of an instruction (`a, b, c`), with their offsets.
fn operands(rest: &str, at: usize) -> Vec<Tok<'_>> {
    let mut out = Vec::new();
    let mut off = 0;
    for part in rest.split(',') {
        let lead = part.len() - part.trim_start().len();
        let t = part.trim();
        if !t.is_empty() {
            out.push(Tok {
                text: t,
                at: at + off + lead,
            });
        }
        off += part.len() + 1;
    }
    out
}

/// Reads an STL file into the surface syntax.
pub fn parse(text: &str) -> Result<syntax::Program<'static>, LoadError> {
    let ls = lines(text);
    let mut cx = operand::Context::new(text);
    let mut program = syntax::Program {
        origin: Origin::at(ls.first().map_or(0, |l| l.0)),
        ..Default::default()
    };
    let mut i = 0;
    let mut blocks: Vec<Block> = Vec::new();
    while i < ls.len() {
        let (at, t, _) = ls[i];
        if t.is_empty() {
            i += 1;
            continue;
        }
        let (w, rest) = words(t);
        let w = w.to_ascii_uppercase();
        if w.starts_with("VAR") {
            let (vars, next) = declarations(text, &ls, i)?;
            program.vars.extend(vars);
            i = next;
            continue;
        }
        let kind = match w.as_str() {
            "ORGANIZATION_BLOCK" | "SUBROUTINE_BLOCK" | "INTERRUPT_BLOCK" => w.clone(),
            _ => return Err(error(text, at, format!("expected a declaration section or a block (ORGANIZATION_BLOCK, SUBROUTINE_BLOCK, INTERRUPT_BLOCK), found `{t}`"))),
        };
        let name = rest.split(':').next().unwrap_or("").trim();
        if name.is_empty() {
            return Err(error(text, at, format!("{kind} needs a name")));
        }
        let (nets, vars, next) = block(text, &ls, i + 1, &kind)?;
        blocks.push(Block {
            kind,
            name: name.to_string(),
            at,
            name_at: at + t.len() - rest.len(),
            nets,
            vars,
        });
        i = next;
    }
    let mut main_seen = false;
    cx.declare(&program.vars, &blocks);
    for b in blocks {
        let Block {
            kind,
            name,
            at,
            name_at,
            nets,
            vars,
        } = b;
        let (kind, name) = (kind.as_str(), name.as_str());
        cx.locals = vars
            .iter()
            .map(|v| (v.name.value.to_string(), v.ty.value.to_string()))
            .collect();
        let prefix = if kind == "ORGANIZATION_BLOCK" {
            String::new()
        } else {
            format!("{name}_")
        };
        let rungs = net::rungs(&mut cx, &nets, &prefix)?;
        match kind {
            "ORGANIZATION_BLOCK" => {
                if main_seen {
                    return Err(error(
                        text,
                        at,
                        "a second ORGANIZATION_BLOCK (the S7-200 has one main program)",
                    ));
                }
                main_seen = true;
                program.name = Cow::Owned(name.to_string());
                program.name_origin = Origin::at(name_at);
                program.body = Some(Body::Rungs(rungs));
            }
            _ => {
                let kind = if kind == "INTERRUPT_BLOCK" {
                    RoutineKind::Interrupt
                } else {
                    RoutineKind::Subroutine
                };
                program.subroutines.push(Subroutine {
                    origin: Origin::at(name_at),
                    kind,
                    name: Cow::Owned(name.to_string()),
                    vars,
                    body: Some(Body::Rungs(rungs)),
                });
            }
        }
    }
    if !main_seen {
        return Err(error(
            text,
            text.len(),
            "no ORGANIZATION_BLOCK (the main program)",
        ));
    }
    cx.finish(&mut program);
    Ok(program)
}

/// A block's optional `TITLE=` and `VAR` sections, `BEGIN`, networks, up to `END_<kind>`.
#[allow(clippy::type_complexity)]
fn block<'a>(
    text: &'a str,
    ls: &[(usize, &'a str, Option<&'a str>)],
    mut i: usize,
    kind: &str,
) -> Result<(Vec<RawNet<'a>>, Vec<Var<'static>>, usize), LoadError> {
    let end = format!("END_{kind}");
    let mut nets: Vec<RawNet<'a>> = Vec::new();
    let mut vars = Vec::new();
    while i < ls.len() {
        let (at, t, comment) = ls[i];
        let (w, rest) = words(t);
        let upper = w.to_ascii_uppercase();
        if t.is_empty() {
            i += 1;
            continue;
        }
        if upper == end {
            return Ok((nets, vars, i + 1));
        }
        if upper.starts_with("TITLE=") || upper == "BEGIN" {
            if upper.starts_with("TITLE=") && !nets.is_empty() {
                let n = nets.last_mut().expect("checked");
                if n.code.is_empty() {
                    n.title = Some(t[6..].trim());
                }
            }
            i += 1;
            continue;
        }
        if upper.starts_with("VAR") && nets.is_empty() {
            let (v, next) = declarations(text, ls, i)?;
            vars.extend(v);
            i = next;
            continue;
        }
        if upper == "NETWORK" {
            let number = operands(rest, at + t.len() - rest.len());
            let Some(&number) = number.first() else {
                return Err(error(text, at, "NETWORK needs its number"));
            };
            // `NETWORK 4` (its title, if any, is the `//` comment): anything else after the
            // keyword would become the rung's id.
            if number.text.is_empty() || !number.text.bytes().all(|b| b.is_ascii_digit()) {
                return Err(error(
                    text,
                    number.at,
                    format!(
                        "NETWORK needs its number, not `{}` (a title goes after `//`)",
                        number.text
                    ),
                ));
            }
            nets.push(RawNet {
                number,
                title: comment.filter(|c| !c.is_empty()),
                code: Vec::new(),
            });
            i += 1;
            continue;
        }
        let Some(n) = nets.last_mut() else {
            return Err(error(
                text,
                at,
                format!("`{t}` before the first NETWORK of the block"),
            ));
        };
        n.code.push(Ins {
            op: upper,
            at,
            args: operands(rest, at + t.len() - rest.len()),
        });
        i += 1;
    }
    Err(error(
        text,
        text.len(),
        format!("{kind} is not closed by {end}"),
    ))
}

/// A declaration section starting at line `i`: `name : TYPE [:= value];` lines up to END_VAR.
fn declarations(
    text: &str,
    ls: &[(usize, &str, Option<&str>)],
    mut i: usize,
) -> Result<(Vec<Var<'static>>, usize), LoadError> {
    let (at0, head, _) = ls[i];
    let class = match head.to_ascii_uppercase().as_str() {
        "VAR_INPUT" => VarClass::Input,
        "VAR_OUTPUT" => VarClass::Output,
        "VAR" | "VAR_GLOBAL" => VarClass::Memory,
        _ => {
            return Err(error(
                text,
                at0,
                format!("unknown declaration section `{head}` (VAR_INPUT, VAR_OUTPUT, VAR)"),
            ))
        }
    };
    let mut vars = Vec::new();
    i += 1;
    while i < ls.len() {
        let (at, t, _) = ls[i];
        i += 1;
        if t.is_empty() {
            continue;
        }
        if t.eq_ignore_ascii_case("END_VAR") {
            return Ok((vars, i));
        }
        let body = t.strip_suffix(';').unwrap_or(t);
        let Some((name, rest)) = body.split_once(':') else {
            return Err(error(
                text,
                at,
                format!("expected `name : TYPE;`, found `{t}`"),
            ));
        };
        let (ty, init) = match rest.split_once(":=") {
            Some((ty, init)) => (ty.trim(), Some(init.trim())),
            None => (rest.trim(), None),
        };
        let ty_at = at + t.find(ty).unwrap_or(0);
        let own = |s: &str, o: usize| Located {
            value: Cow::Owned(s.to_string()),
            origin: Origin::at(o),
        };
        vars.push(Var {
            origin: Origin::at(at),
            name: own(name.trim(), at),
            ty: own(&ty.to_ascii_uppercase(), ty_at),
            class: Located {
                value: class,
                origin: Origin::at(at0),
            },
            init: init.map(|s| {
                let o = at + t.find(s).unwrap_or(0);
                Box::new(Located {
                    value: operand::scalar(s),
                    origin: Origin::at(o),
                })
            }),
            problem: None,
        });
    }
    Err(error(
        text,
        at0,
        "declaration section not closed by END_VAR",
    ))
}
