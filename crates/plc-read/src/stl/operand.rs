//! STL operands → the names and constants of the surface syntax: symbolic names (a subroutine
//! local `#x` is `x`), absolute addresses (declared implicitly, typed by their area and by the
//! instructions that use them), numbers (`+100`), TIME literals, TRUE/FALSE.
//!
//! Absolute bits `I0.0` become variables `I0_0` (the program format's names have no dots);
//! `T37`/`C5` become timers and counters of the type of their box (TON, TOF, CTU, CTD), read as
//! bits through their Q; `SM0.0` is always on, `SM0.1` on in the first scan only (a memory
//! bit that a first rung of the main program clears after the first scan, through `SM0_1_seen`).
//! Not here: byte operands (`VB`, `MB`), accumulators, indirect addressing (`*VD`): errors.

use super::tree::{contact, el, name};
use super::{error, Block, Tok};
use plc_diag::{LoadError, Origin};
use plc_syntax::{self as syntax, ElementKind, Located, Rung, Scalar, Var, VarClass};
use std::borrow::Cow;
use std::collections::{BTreeMap, HashMap};

/// A variable the reader declares because the file uses its address.
struct Implicit {
    ty: &'static str,
    class: VarClass,
    init: Option<bool>,
    at: usize,
}

/// What operands resolve against: the declared types and the implicit variables so far.
pub(crate) struct Context<'t> {
    pub text: &'t str,
    /// The current block's local variables: name → type.
    pub locals: HashMap<String, String>,
    globals: HashMap<String, String>,
    implicit: BTreeMap<String, Implicit>,
    /// `T37` → TON, `C5` → CTD: the boxes that use them.
    boxes: HashMap<String, &'static str>,
}

/// A leaf as the file wrote it: TRUE/FALSE, a number, else the text (a name or a TIME literal).
pub(crate) fn scalar(s: &str) -> Scalar<'static> {
    if s.eq_ignore_ascii_case("TRUE") {
        return Scalar::Bool(true);
    }
    if s.eq_ignore_ascii_case("FALSE") {
        return Scalar::Bool(false);
    }
    let t = s.strip_prefix('+').unwrap_or(s);
    if let Ok(i) = t.parse::<i64>() {
        return Scalar::Number(i.into());
    }
    // Up to ULINT's and LWORD's 2^64 - 1, exactly.
    if let Ok(u) = t.parse::<u64>() {
        return Scalar::Number(u.into());
    }
    if t.bytes()
        .next()
        .is_some_and(|b| b.is_ascii_digit() || b == b'-')
    {
        if let Some(n) = t.parse::<f64>().ok().and_then(serde_json::Number::from_f64) {
            return Scalar::Number(n);
        }
    }
    Scalar::Str(Cow::Owned(s.to_string()))
}

/// `I0.0` → (`I`, byte, bit) for the bit areas I, Q, M, V, SM.
fn bit_address(s: &str) -> Option<(&'static str, &str, &str)> {
    let up = s.to_ascii_uppercase();
    let area = ["SM", "I", "Q", "M", "V"]
        .into_iter()
        .find(|a| up.starts_with(a))?;
    let (byte, bit) = s[area.len()..].split_once('.')?;
    let ok = !byte.is_empty() && byte.bytes().all(|b| b.is_ascii_digit());
    (ok && bit.len() == 1 && (b'0'..=b'7').contains(&bit.as_bytes()[0]))
        .then_some((area, byte, bit))
}

/// `T37` → ("T", 37), `C5` → ("C", 5).
fn box_address(s: &str) -> Option<(char, u32)> {
    let mut c = s.chars();
    let area = c.next()?.to_ascii_uppercase();
    let n: u32 = c.as_str().parse().ok()?;
    (matches!(area, 'T' | 'C') && n <= 255 && !c.as_str().starts_with('+')).then_some((area, n))
}

/// The resolution of S7-200 timer `n` of a TON/TOF, in ms (None: a TONR number).
fn resolution(n: u32) -> Option<i64> {
    match n {
        32 | 96 => Some(1),
        33..=36 | 97..=100 => Some(10),
        37..=63 | 101..=255 => Some(100),
        _ => None,
    }
}

impl<'t> Context<'t> {
    pub(super) fn new(text: &'t str) -> Context<'t> {
        Context {
            text,
            locals: HashMap::new(),
            globals: HashMap::new(),
            implicit: BTreeMap::new(),
            boxes: HashMap::new(),
        }
    }

    /// Records the declared globals and the type of every absolute timer and counter.
    pub(super) fn declare(&mut self, vars: &[Var], blocks: &[Block]) {
        for v in vars {
            self.globals
                .insert(v.name.value.to_string(), v.ty.value.to_string());
        }
        for b in blocks {
            for n in &b.nets {
                for ins in &n.code {
                    if let ("TON" | "TOF" | "CTU" | "CTD", Some(a)) =
                        (ins.op.as_str(), ins.args.first())
                    {
                        let ty = match ins.op.as_str() {
                            "TON" => "TON",
                            "TOF" => "TOF",
                            "CTU" => "CTU",
                            _ => "CTD",
                        };
                        self.boxes.entry(a.text.to_ascii_uppercase()).or_insert(ty);
                    }
                }
            }
        }
    }

    fn declared(&self, name: &str) -> Option<&str> {
        self.locals
            .get(name)
            .or_else(|| self.globals.get(name))
            .map(|s| s.as_str())
    }

    fn implicit(&mut self, name: String, ty: &'static str, class: VarClass, at: usize) -> String {
        if self.declared(&name).is_none() {
            let init = (name == "SM0_0").then_some(true);
            self.implicit.entry(name.clone()).or_insert(Implicit {
                ty,
                class,
                init,
                at,
            });
        }
        name
    }

    /// A bit operand (contact, coil, set, reset): the variable's name, `T1.Q` for an instance.
    pub(super) fn bit(&mut self, t: Tok) -> Result<String, LoadError> {
        if let Some((area, byte, bit)) = bit_address(t.text) {
            let class = match area {
                "I" => VarClass::Input,
                "Q" => VarClass::Output,
                _ => VarClass::Memory,
            };
            return Ok(self.implicit(format!("{area}{byte}_{bit}"), "BOOL", class, t.at));
        }
        if let Some((area, _)) = box_address(t.text).filter(|_| self.declared(t.text).is_none()) {
            let up = t.text.to_ascii_uppercase();
            let Some(&ty) = self.boxes.get(&up) else {
                return Err(error(
                    self.text,
                    t.at,
                    format!(
                        "{up} is used as a bit but no TON, TOF, CTU or CTD box gives it a type"
                    ),
                ));
            };
            let _ = area;
            self.implicit(up.clone(), ty, VarClass::Memory, t.at);
            return Ok(format!("{up}.Q"));
        }
        let name = t.text.strip_prefix('#').unwrap_or(t.text).to_string();
        self.check_name(t, &name)?;
        match self.declared(&name) {
            Some("TON" | "TOF" | "TP" | "CTU" | "CTD") => Ok(format!("{name}.Q")),
            _ => Ok(name),
        }
    }

    fn check_name(&self, t: Tok, name: &str) -> Result<(), LoadError> {
        let ok = name
            .bytes()
            .next()
            .is_some_and(|b| b.is_ascii_alphabetic() || b == b'_')
            && name
                .bytes()
                .all(|b| b.is_ascii_alphanumeric() || b == b'_' || b == b'.');
        if ok {
            Ok(())
        } else {
            Err(error(self.text, t.at, format!("`{}` is not an operand plc-deps reads (a name, I0.0, VW0, VD0, T37, C0, a number or T#…)", t.text)))
        }
    }

    /// A word operand of an instruction of `family` (`W` INT, `D` DINT, `R` REAL).
    pub(super) fn word(
        &mut self,
        t: Tok,
        family: char,
    ) -> Result<syntax::Operand<'static>, LoadError> {
        let s = scalar(t.text);
        let value = match s {
            Scalar::Str(ref text) if !syntax::is_time_literal(text) => {
                let up = text.to_ascii_uppercase();
                let area = ["VW", "MW", "VD", "MD"]
                    .into_iter()
                    .find(|a| up.starts_with(a));
                match area {
                    Some(a) if up[2..].bytes().all(|b| b.is_ascii_digit()) && up.len() > 2 => {
                        let ty = match (a.as_bytes()[1], family) {
                            (b'W', _) => "INT",
                            (_, 'R') => "REAL",
                            _ => "DINT",
                        };
                        Scalar::Str(Cow::Owned(self.implicit(up, ty, VarClass::Memory, t.at)))
                    }
                    _ if box_address(text).is_some() && self.declared(text).is_none() => {
                        // A counter as a word is its current value (S7-200: the INT count);
                        // a timer's is counted in its resolution, which ET in ms is not.
                        match self.boxes.get(&up) {
                            Some(&ty @ ("CTU" | "CTD")) => {
                                self.implicit(up.clone(), ty, VarClass::Memory, t.at);
                                Scalar::Str(Cow::Owned(format!("{up}.CV")))
                            }
                            _ => return Err(error(self.text, t.at, format!("{up} as a word (its current value) is not read yet: use a symbolic timer and its .ET"))),
                        }
                    }
                    _ => {
                        let name = text.strip_prefix('#').unwrap_or(text).to_string();
                        self.check_name(t, &name)?;
                        // A declared counter as a word: its current value, as above.
                        let counter = matches!(self.declared(&name), Some("CTU" | "CTD"));
                        Scalar::Str(Cow::Owned(if counter {
                            format!("{name}.CV")
                        } else {
                            name
                        }))
                    }
                }
            }
            other => other,
        };
        Ok(Located {
            value,
            origin: Origin::at(t.at),
        })
    }

    /// The instance operand of a TON/TOF/CTU/CTD.
    pub(super) fn instance(&mut self, t: Tok, ty: &'static str) -> Result<String, LoadError> {
        if box_address(t.text).is_some() && self.declared(t.text).is_none() {
            let up = t.text.to_ascii_uppercase();
            if up.starts_with('T') && resolution(up[1..].parse().unwrap_or(0)).is_none() {
                return Err(error(
                    self.text,
                    t.at,
                    format!(
                        "{up} is a TONR timer on the S7-200 (TON and TOF use T32–T63 and T96–T255)"
                    ),
                ));
            }
            return Ok(self.implicit(up, ty, VarClass::Memory, t.at));
        }
        let name = t.text.strip_prefix('#').unwrap_or(t.text).to_string();
        self.check_name(t, &name)?;
        Ok(name)
    }

    /// The PT of timer `timer`: counted in the timer's resolution for `T37`, ms (or a TIME
    /// literal, or a TIME variable) for a symbolic timer.
    pub(super) fn pt(&mut self, timer: Tok, t: Tok) -> Result<syntax::Operand<'static>, LoadError> {
        let absolute = box_address(timer.text).filter(|_| self.declared(timer.text).is_none());
        let value = match (absolute, scalar(t.text)) {
            (Some((_, n)), Scalar::Number(v)) => {
                let ms = v.as_i64().unwrap_or(0) * resolution(n).unwrap_or(1);
                Scalar::Str(Cow::Owned(format!("T#{ms}ms")))
            }
            (Some(_), _) => {
                return Err(error(
                    self.text,
                    t.at,
                    "the PT of an absolute timer must be a number (not yet: a word)",
                ));
            }
            (None, Scalar::Number(v)) => Scalar::Str(Cow::Owned(format!("T#{v}ms"))),
            (None, _) => return self.word(t, 'D'),
        };
        Ok(Located {
            value,
            origin: Origin::at(t.at),
        })
    }

    /// Declares the implicit variables (and the first-scan rung when SM0.1 is read).
    pub(super) fn finish(self, program: &mut syntax::Program<'static>) {
        let own = |s: &str, at: usize| Located {
            value: Cow::Owned(s.to_string()),
            origin: Origin::at(at),
        };
        let first_scan = self.implicit.get("SM0_1").map(|i| i.at);
        let mut implicit = self.implicit;
        if let Some(at) = first_scan {
            implicit.insert(
                "SM0_1_seen".into(),
                Implicit {
                    ty: "BOOL",
                    class: VarClass::Memory,
                    init: None,
                    at,
                },
            );
        }
        for (name, i) in implicit {
            program.vars.push(Var {
                origin: Origin::at(i.at),
                name: own(&name, i.at),
                ty: own(i.ty, i.at),
                class: Located {
                    value: i.class,
                    origin: Origin::NONE,
                },
                init: i.init.map(|b| {
                    Box::new(Located {
                        value: Scalar::Bool(b),
                        origin: Origin::NONE,
                    })
                }),
                problem: None,
            });
        }
        if let (Some(at), Some(syntax::Body::Rungs(rungs))) = (first_scan, program.body.as_mut()) {
            rungs.insert(0, first_scan_rung(at));
        }
    }
}

/// The first rung of a main program that reads SM0.1: SM0.1 is on until the first scan ends.
fn first_scan_rung(at: usize) -> Rung<'static> {
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
