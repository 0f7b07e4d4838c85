//! Classifying one element object: which kind (by the key it has, in the format's order —
//! `ctu`/`ctd`/`ctud`/`sr`/`rs` before `reset`, since these boxes have a `reset` operand), which keys it may have, and
//! the shape of each field. Names and operands are left to the resolver. The element's keys are
//! the top of the reader's scratch stack (from `mark` on); they are taken from there.

use plc_diag::Invalid;
use plc_model::{ArithOp, BistableKind, CmpOp, TimerKind, TriggerKind};
use plc_syntax::{
    self as syntax, Edge, ElementKind, Located, Name, Operand, Origin, Problem, Scalar, Series,
    Text,
};

/// The keys of a `for` object in file order: (key, its origin, the value).
pub(super) type ForSlots<'a> = Vec<(Text<'a>, Origin, Operand<'a>)>;

/// The value of one key of an element object.
pub(super) enum Slot<'a> {
    Scalar(Operand<'a>),
    /// `for`: the object's keys in file order, or the leaf found instead of an object.
    For(Result<ForSlots<'a>, Scalar<'a>>),
    Branches(Result<Vec<Series<'a>>, Box<Problem>>),
    /// `in` of an arithmetic box: the operands, or what was found instead of an array.
    List(Result<Vec<Operand<'a>>, Scalar<'a>>),
}

/// One key of an element object: the key and its origin, the value's origin and the value.
pub(super) struct SlotEntry<'a> {
    pub(super) key: Text<'a>,
    pub(super) key_origin: Origin,
    pub(super) origin: Origin,
    pub(super) slot: Slot<'a>,
}

/// Element kind keys, in the order they are recognised, with the keys each kind allows.
const ELEMENT_KINDS: &[(&str, &[&str])] = &[
    ("ctu", &["ctu", "pv", "reset"]),
    ("ctd", &["ctd", "pv", "load"]),
    ("ctud", &["ctud", "cd", "reset", "load", "pv"]),
    ("sr", &["sr", "reset"]),
    ("rs", &["rs", "reset"]),
    ("r_trig", &["r_trig"]),
    ("f_trig", &["f_trig"]),
    ("contact", &["contact", "negated", "edge"]),
    ("compare", &["compare", "a", "b"]),
    ("or", &["or"]),
    ("coil", &["coil", "negated"]),
    ("set", &["set"]),
    ("reset", &["reset"]),
    ("branch", &["branch"]),
    ("ton", &["ton", "pt"]),
    ("tof", &["tof", "pt"]),
    ("tp", &["tp", "pt"]),
    ("move", &["move", "to"]),
    ("op", &["op", "in", "out"]),
    ("jmp", &["jmp"]),
    ("ret", &["ret"]),
    ("end", &["end"]),
    ("call", &["call"]),
    ("for", &["for"]),
    ("next", &["next"]),
    ("range_fault", &["range_fault"]),
];

fn element_what(key: &str) -> &'static str {
    match key {
        "contact" => "a contact",
        "compare" => "a compare contact",
        "or" => "an or",
        "coil" => "a coil",
        "set" => "a set coil",
        "reset" => "a reset coil",
        "branch" => "a branch",
        "ton" => "a TON box",
        "tof" => "a TOF box",
        "tp" => "a TP box",
        "ctu" => "a CTU box",
        "ctd" => "a CTD box",
        "ctud" => "a CTUD box",
        "sr" => "an SR box",
        "rs" => "an RS box",
        "r_trig" => "an R_TRIG box",
        "f_trig" => "an F_TRIG box",
        "move" => "a move box",
        "op" => "an arithmetic box",
        "jmp" => "a jump",
        "ret" => "a return",
        "end" => "an end",
        "call" => "a call",
        "for" => "a FOR",
        "range_fault" => "a range fault",
        _ => "a NEXT",
    }
}

type R<T> = Result<T, Box<Problem>>;

fn shape(
    at: impl Into<String>,
    origin: Origin,
    expected: &'static str,
    found: &Scalar,
) -> Box<Problem> {
    Problem::new(
        at,
        origin,
        Invalid::Shape {
            expected,
            found: found.kind(),
        },
    )
}

/// The fields of one element object (`slots[mark..]`), taken out by key.
struct Fields<'s, 'a> {
    slots: &'s mut Vec<SlotEntry<'a>>,
    mark: usize,
    what: &'static str,
    /// The element's origin.
    origin: Origin,
}

impl<'a> Fields<'_, 'a> {
    /// The value of `key` and its origin.
    fn take(&mut self, key: &'static str) -> Option<(Slot<'a>, Origin)> {
        let i = self.slots[self.mark..].iter().position(|s| s.key == key)?;
        let e = self.slots.swap_remove(self.mark + i);
        Some((e.slot, e.origin))
    }
    fn required(&mut self, key: &'static str) -> R<(Slot<'a>, Origin)> {
        let (what, origin) = (self.what, self.origin);
        self.take(key)
            .ok_or_else(|| Problem::new("", origin, Invalid::MissingField { field: key, what }))
    }
    /// A required leaf (operand).
    fn operand(&mut self, key: &'static str) -> R<Operand<'a>> {
        match self.required(key)? {
            (Slot::Scalar(s), _) => Ok(s),
            (_, origin) => Ok(Located {
                value: Scalar::Array,
                origin,
            }),
        }
    }
    /// A required string.
    fn string(&mut self, key: &'static str) -> R<Name<'a>> {
        let o = self.operand(key)?;
        match o.value {
            Scalar::Str(s) => Ok(Located {
                value: s,
                origin: o.origin,
            }),
            other => Err(shape(format!(".{key}"), o.origin, "a string", &other)),
        }
    }
    /// An optional `true`/`false`.
    fn boolean(&mut self, key: &'static str) -> R<bool> {
        let expected = "true or false";
        match self.take(key) {
            None => Ok(false),
            Some((
                Slot::Scalar(Located {
                    value: Scalar::Bool(b),
                    ..
                }),
                _,
            )) => Ok(b),
            Some((Slot::Scalar(o), _)) => {
                Err(shape(format!(".{key}"), o.origin, expected, &o.value))
            }
            Some((_, origin)) => Err(shape(format!(".{key}"), origin, expected, &Scalar::Array)),
        }
    }
    /// A marker such as `"ret": true`.
    fn flag(&mut self, key: &'static str) -> R<()> {
        let o = self.operand(key)?;
        match o.value {
            Scalar::Bool(true) => Ok(()),
            other => Err(shape(format!(".{key}"), o.origin, "true", &other)),
        }
    }
    fn branches(&mut self, key: &'static str) -> R<Vec<Series<'a>>> {
        match self.required(key)? {
            (Slot::Branches(Ok(b)), origin) if b.is_empty() => Err(Problem::new(
                format!(".{key}"),
                origin,
                Invalid::Shape {
                    expected: "at least one branch",
                    found: "an empty array".into(),
                },
            )),
            (Slot::Branches(Ok(b)), _) => Ok(b),
            (Slot::Branches(Err(mut p)), _) => {
                p.at = format!(".{key}{}", p.at);
                Err(p)
            }
            (_, origin) => Err(shape(
                format!(".{key}"),
                origin,
                "an array",
                &Scalar::Object,
            )),
        }
    }
}

/// Which element the object whose keys are `slots[mark..]` is (at `origin`), with its fields
/// checked for shape. The slots it does not take are left for the caller to drop.
pub(super) fn classify<'a>(
    slots: &mut Vec<SlotEntry<'a>>,
    mark: usize,
    origin: Origin,
) -> R<ElementKind<'a>> {
    let own = &slots[mark..];
    let Some(&(key, allowed)) = ELEMENT_KINDS
        .iter()
        .find(|(k, _)| own.iter().any(|s| s.key == *k))
    else {
        let keys = own
            .iter()
            .map(|s| format!("\"{}\": …", s.key))
            .collect::<Vec<_>>()
            .join(", ");
        return Err(Problem::new("", origin, Invalid::UnknownElement { keys }));
    };
    let what = element_what(key);
    if let Some(s) = own.iter().find(|s| !allowed.contains(&s.key.as_ref())) {
        return Err(Problem::new(
            format!(".{}", s.key),
            s.key_origin,
            Invalid::UnknownField {
                field: s.key.to_string(),
                what,
                allowed: allowed.join(", "),
            },
        ));
    }
    let mut f = Fields {
        slots,
        mark,
        what,
        origin,
    };
    Ok(match key {
        "contact" => contact(&mut f)?,
        "compare" => {
            let op = f.string("compare")?;
            let op = cmp_op(&op.value).ok_or_else(|| {
                Problem::new(
                    ".compare",
                    op.origin,
                    Invalid::Shape {
                        expected: "EQ, NE, LT, LE, GT or GE",
                        found: format!("\"{}\"", op.value),
                    },
                )
            })?;
            let a = f.operand("a")?;
            let b = f.operand("b")?;
            ElementKind::Compare(Box::new(syntax::Compare { op, a, b }))
        }
        "or" => ElementKind::Or(f.branches("or")?),
        "branch" => ElementKind::Branch(f.branches("branch")?),
        "coil" => {
            let var = f.string("coil")?;
            let negated = f.boolean("negated")?;
            ElementKind::Coil { var, negated }
        }
        "set" => ElementKind::Set(f.string("set")?),
        "reset" => ElementKind::Reset(f.string("reset")?),
        "ton" | "tof" | "tp" => {
            let instance = f.string(key)?;
            let pt = f.operand("pt")?;
            ElementKind::Timer(Box::new(syntax::Timer {
                kind: timer_kind(key).unwrap_or(plc_model::TimerKind::Ton),
                instance,
                pt,
            }))
        }
        "ctu" | "ctd" => {
            let down = key == "ctd";
            let instance = f.string(key)?;
            let pv = f.operand("pv")?;
            let aux = f.operand(if down { "load" } else { "reset" })?;
            ElementKind::Counter(Box::new(syntax::Counter {
                down,
                instance,
                pv,
                aux,
            }))
        }
        "ctud" => {
            let instance = f.string(key)?;
            let cd = f.operand("cd")?;
            let reset = f.operand("reset")?;
            let load = f.operand("load")?;
            let pv = f.operand("pv")?;
            ElementKind::Ctud(Box::new(syntax::Ctud {
                instance,
                cd,
                reset,
                load,
                pv,
            }))
        }
        "sr" | "rs" => {
            let instance = f.string(key)?;
            let reset = f.operand("reset")?;
            ElementKind::Bistable(Box::new(syntax::Bistable {
                kind: if key == "sr" {
                    BistableKind::SetDominant
                } else {
                    BistableKind::ResetDominant
                },
                instance,
                reset,
            }))
        }
        "r_trig" | "f_trig" => ElementKind::Trigger {
            kind: if key == "r_trig" {
                TriggerKind::Rising
            } else {
                TriggerKind::Falling
            },
            instance: f.string(key)?,
        },
        "move" => {
            let to = f.string("to")?;
            let from = f.operand("move")?;
            ElementKind::Move(Box::new(syntax::Move { from, to }))
        }
        "op" => arith(&mut f)?,
        "jmp" => ElementKind::Jmp(f.string("jmp")?),
        "ret" => {
            f.flag("ret")?;
            ElementKind::Ret
        }
        "end" => {
            f.flag("end")?;
            ElementKind::End
        }
        "next" => {
            f.flag("next")?;
            ElementKind::Next
        }
        "range_fault" => {
            f.flag("range_fault")?;
            ElementKind::RangeFault
        }
        "call" => ElementKind::Call(f.string("call")?),
        _ => for_loop(&mut f)?,
    })
}

fn contact<'a>(f: &mut Fields<'_, 'a>) -> R<ElementKind<'a>> {
    let var = f.string("contact")?;
    let negated = f.boolean("negated")?;
    let edge = match f.take("edge") {
        None => None,
        Some((_, origin)) if negated => {
            return Err(Problem::new(
                ".edge",
                origin,
                Invalid::Misplaced {
                    what: "`edge`",
                    place: "together with `negated`",
                },
            ))
        }
        Some((
            Slot::Scalar(Located {
                value: Scalar::Str(s),
                origin,
            }),
            _,
        )) => Some(edge(&s).ok_or_else(|| {
            Problem::new(
                ".edge",
                origin,
                Invalid::Shape {
                    expected: "\"rising\" or \"falling\"",
                    found: format!("\"{s}\""),
                },
            )
        })?),
        Some((Slot::Scalar(o), _)) => return Err(shape(".edge", o.origin, "a string", &o.value)),
        Some((_, origin)) => return Err(shape(".edge", origin, "a string", &Scalar::Array)),
    };
    Ok(ElementKind::Contact { var, negated, edge })
}

fn arith<'a>(f: &mut Fields<'_, 'a>) -> R<ElementKind<'a>> {
    let name = f.string("op")?;
    let func = plc_model::Function::parse(&name.value);
    let op = arith_op(&name.value);
    if op.is_none() && func.is_none() {
        return Err(Problem::new(
            ".op",
            name.origin,
            Invalid::Shape {
                expected: "ADD, SUB, MUL, DIV, MOD or a standard function (ABS, SQRT, SHL, MUX, INT_TO_REAL, … docs/format.md)",
                found: format!("\"{}\"", name.value),
            },
        ));
    }
    let out = f.string("out")?;
    let (inputs, origin) = match f.required("in")? {
        (Slot::List(Ok(list)), origin) => (list, origin),
        (Slot::List(Err(found)), origin) => return Err(shape(".in", origin, "an array", &found)),
        (_, origin) => return Err(shape(".in", origin, "an array", &Scalar::Object)),
    };
    let Some(op) = op else {
        let func = func.expect("checked above");
        if !func.arity_ok(inputs.len()) {
            let pins = func.input_names(inputs.len());
            return Err(Problem::new(
                ".in",
                origin,
                Invalid::Shape {
                    expected: if func.extensible() {
                        "K and two or more inputs"
                    } else if pins.len() == 1 {
                        "one operand"
                    } else {
                        "two operands"
                    },
                    found: format!("{} operands", inputs.len()),
                },
            ));
        }
        return Ok(ElementKind::Function(Box::new(syntax::FunctionCall {
            func,
            args: inputs,
            out,
        })));
    };
    let [a, b]: [Operand; 2] = inputs.try_into().map_err(|v: Vec<Operand>| {
        Problem::new(
            ".in",
            origin,
            Invalid::Shape {
                expected: "two operands",
                found: format!("{} operands", v.len()),
            },
        )
    })?;
    Ok(ElementKind::Arith(Box::new(syntax::Arith {
        op,
        a,
        b,
        out,
    })))
}

fn for_loop<'a>(f: &mut Fields<'_, 'a>) -> R<ElementKind<'a>> {
    let (mut slots, origin) = match f.required("for")? {
        (Slot::For(Ok(slots)), origin) => (slots, origin),
        (Slot::For(Err(found)), origin) => return Err(shape(".for", origin, "an object", &found)),
        (_, origin) => return Err(shape(".for", origin, "an object", &Scalar::Array)),
    };
    if let Some((k, key_origin, _)) = slots
        .iter()
        .find(|(k, _, _)| !["var", "from", "to"].contains(&k.as_ref()))
    {
        return Err(Problem::new(
            format!(".for.{k}"),
            *key_origin,
            Invalid::UnknownField {
                field: k.to_string(),
                what: "a FOR",
                allowed: "var, from, to".into(),
            },
        ));
    }
    let mut get = |key: &'static str| -> R<Operand<'a>> {
        let i = slots.iter().position(|(k, _, _)| k == key).ok_or_else(|| {
            Problem::new(
                ".for",
                origin,
                Invalid::MissingField {
                    field: key,
                    what: "a FOR",
                },
            )
        })?;
        Ok(slots.swap_remove(i).2)
    };
    let var = get("var")?;
    let var = match var.value {
        Scalar::Str(s) => Located {
            value: s,
            origin: var.origin,
        },
        other => return Err(shape(".for.var", var.origin, "a string", &other)),
    };
    let from = get("from")?;
    let to = get("to")?;
    Ok(ElementKind::For(Box::new(syntax::For { var, from, to })))
}

/// Kinds of elements by name (for the classifier).
fn timer_kind(key: &str) -> Option<TimerKind> {
    match key {
        "ton" => Some(TimerKind::Ton),
        "tof" => Some(TimerKind::Tof),
        "tp" => Some(TimerKind::Tp),
        _ => None,
    }
}

fn edge(s: &str) -> Option<Edge> {
    match s {
        "rising" => Some(Edge::Rising),
        "falling" => Some(Edge::Falling),
        _ => None,
    }
}

fn cmp_op(s: &str) -> Option<CmpOp> {
    CmpOp::parse(s)
}

fn arith_op(s: &str) -> Option<ArithOp> {
    ArithOp::parse(s)
}
