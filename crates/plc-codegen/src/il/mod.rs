//! S7-200 Instruction List (STL) from ladder and boolean FBD programs, as STEP 7-Micro/WIN
//! shows it: one block per POU (`ORGANIZATION_BLOCK` for the main program, `SUBROUTINE_BLOCK`
//! for each subroutine), `NETWORK n` per rung or FBD network, one instruction per line, operands
//! as the program's variable names (a variable named like an absolute address, `I0_0` of class
//! input, is written `I0.0`).
//!
//! Ladder rungs are walked as their series/parallel element trees ([`ladder`]); boolean FBD
//! networks become N-ary trees (first child / next sibling), simplified by lifting the children
//! of a node of its parent's type, split under virtual roots where one result feeds several
//! outputs, and emitted by a post-order walk with LPS/LRD/LPP ([`tree`]): Zhou & Zhang 2015,
//! "Conversion of PLC function block diagrams to instruction list based on N-ary trees".
//!
//! Invariants: every emitted network needs at most [`STACK_LEVELS`] levels of the logic stack
//! (counted from the network's start; a network that would need more is an error naming it),
//! every LPS is closed by an LPP in the same network, and the reader `plc_read::stl` reads
//! the text back into a program with the same scan behaviour (tests/it/il_roundtrip.rs).
//!
//! Deliberately not here: what has no S7-200 instruction (TP timers, `b := a MOD b`, XOR blocks,
//! FBD networks with non-boolean blocks, conditional arcs, function block types) is one error
//! naming the rung or block ([`IlError`]) — never an approximation. MOD and `out := a - out`
//! are written through a scratch word the STL declares (`IL_TMP_INT`). The format: docs/il.md.

mod ladder;
mod tree;

use plc_fbd::{Fbd, FbdPouKind};
use plc_model::{
    walk_elements, ArithOp, Element, Field, Operand, PouId, PouKind, Program, Type, Value,
    VarClass, VarId, VarRef,
};
use std::fmt::Write as _;

/// Levels of the S7-200 logic stack.
pub const STACK_LEVELS: u32 = 9;

/// Why a program has no S7-200 form: the rung (`rung R3`) or block (`network N1 block 4`) and
/// what (`TP has no S7-200 instruction …`).
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
#[error("{place}: {message}")]
pub struct IlError {
    pub place: String,
    pub message: String,
}

/// One instruction: its mnemonic and operands as written.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Instr {
    pub op: String,
    pub args: Vec<String>,
}

/// The instructions of one network with the logic stack depth they reach.
#[derive(Default)]
pub(crate) struct Net {
    pub code: Vec<Instr>,
    pub depth: u32,
    pub max: u32,
    /// Depths at which an LPS is open (innermost last).
    pub forks: Vec<u32>,
}

impl Net {
    /// Emits `op args` changing the stack depth by `delta`.
    pub(crate) fn emit(&mut self, op: &str, args: &[&str], delta: i32) {
        self.code.push(Instr {
            op: op.to_string(),
            args: args.iter().map(|s| s.to_string()).collect(),
        });
        self.depth = (self.depth as i32 + delta).max(0) as u32;
        self.max = self.max.max(self.depth);
    }
    pub(crate) fn lps(&mut self) {
        self.emit("LPS", &[], 1);
        self.forks.push(self.depth);
    }
    pub(crate) fn lrd(&mut self) {
        self.emit("LRD", &[], 0);
    }
    pub(crate) fn lpp(&mut self) {
        self.emit("LPP", &[], -1);
        self.forks.pop();
    }
}

/// The STL of `p` (with its FBD bodies `fbd`), or the first construct that has none.
pub fn generate(p: &Program, fbd: &Fbd) -> Result<String, IlError> {
    // STRINGs have no S7-200 STL form here: refused by name, never written as numbers.
    if let Some(v) = p.vars().iter().find(|v| v.ty == Type::String) {
        return Err(IlError {
            place: format!("variable {}", v.name),
            message: "STRING has no S7-200 STL form in plc-deps il (not yet)".into(),
        });
    }
    let mut textual = None;
    for r in p.rungs().iter() {
        plc_model::walk_elements(&r.series, &mut |e| {
            if let Element::Function { func, .. } = e {
                if func.is_textual() && textual.is_none() {
                    textual = Some((r.id.clone(), func.static_name()));
                }
            }
        });
    }
    if let Some((rung, f)) = textual {
        return Err(IlError {
            place: format!("rung {rung}"),
            message: format!(
                "{f} works on STRINGs, which have no S7-200 STL form in plc-deps il (not yet)"
            ),
        });
    }
    let names = Names::new(p);
    let mut out = String::new();
    let mut headers = Vec::new();
    let _ = writeln!(out, "// {}: S7-200 STL written by plc-deps il", p.name());
    declarations(&mut out, p, &names, None);
    let (mut subroutines, mut interrupts) = (0, 0);
    for (id, pou) in p.pous().iter_enumerated() {
        if fbd.instances.iter().any(|inst| inst.pou == id) {
            return Err(IlError {
                place: format!("function block instance {}", pou.name),
                message: "user function block types have no S7-200 form (not yet: write the logic as a subroutine)".into(),
            });
        }
        let (kind, tag) = match pou.kind {
            PouKind::Main => ("ORGANIZATION_BLOCK", "OB1".to_string()),
            PouKind::Subroutine => {
                subroutines += 1;
                ("SUBROUTINE_BLOCK", format!("SBR{}", subroutines - 1))
            }
            PouKind::Interrupt => {
                interrupts += 1;
                ("INTERRUPT_BLOCK", format!("INT{}", interrupts - 1))
            }
        };
        let _ = writeln!(out, "{kind} {}:{tag}", pou.name);
        if pou.kind != PouKind::Main {
            declarations(&mut out, p, &names, Some(id));
        }
        out.push_str("BEGIN\n");
        let (nets, what) = match fbd.pous.iter().find(|f| {
            f.kind != FbdPouKind::FunctionBlock && f.copies.first().map(|c| c.pou) == Some(id)
        }) {
            Some(f) => (tree::pou(p, &names, id, f)?, "network"),
            None => (ladder::pou(p, &names, id)?, "rung"),
        };
        for (n, (title, net)) in nets.iter().enumerate() {
            headers.push((out.len(), format!("{what} {title}")));
            let _ = writeln!(out, "NETWORK {} // {title}", n + 1);
            for ins in &net.code {
                if ins.args.is_empty() {
                    let _ = writeln!(out, "{}", ins.op);
                } else {
                    let _ = writeln!(out, "{:<6} {}", ins.op, ins.args.join(", "));
                }
            }
        }
        let _ = writeln!(out, "END_{kind}");
    }
    reads_back(&out, &headers)?;
    Ok(out)
}

/// What `il` writes, the STL reader reads: a network the reader cannot rebuild as one rung
/// (a flat network that would re-read a variable after writing it) is an error naming it.
fn reads_back(out: &str, headers: &[(usize, String)]) -> Result<(), IlError> {
    let Err(e) = plc_read::stl::parse(out) else {
        return Ok(());
    };
    let line = match &e {
        plc_diag::LoadError::Syntax { line, .. } => *line,
        _ => 0,
    };
    let offset: usize = out
        .split_inclusive('\n')
        .take(line.saturating_sub(1))
        .map(str::len)
        .sum();
    let place = headers
        .iter()
        .rev()
        .find(|(at, _)| *at <= offset)
        .map_or("the program".to_string(), |h| h.1.clone());
    let message = match &e {
        plc_diag::LoadError::Syntax { message, .. } => message.clone(),
        other => other.to_string(),
    };
    Err(IlError {
        place,
        message: format!("its STL has no rung shape for the STL reader: {message}"),
    })
}

/// Checks a finished network: the stack depth it needs and that every LPS was popped.
pub(crate) fn check(place: &str, net: &Net) -> Result<(), IlError> {
    if net.max > STACK_LEVELS {
        return Err(IlError {
            place: place.to_string(),
            message: format!(
                "needs {} levels of the logic stack; the S7-200 has {STACK_LEVELS} (split the rung)",
                net.max
            ),
        });
    }
    debug_assert!(net.forks.is_empty());
    Ok(())
}

/// How variables are written in the STL.
pub(crate) struct Names<'a> {
    pub p: &'a Program,
    /// Per variable: its STL operand.
    pub text: Vec<String>,
    /// Per variable: written in absolute form (so not declared).
    pub absolute: Vec<bool>,
    /// The scratch words the arithmetic needs, one per type (`IL_TMP_INT : INT`): a MOD, and
    /// `out := a - out` / `out := a / out`, have no S7-200 form without one.
    pub scratch: Vec<(Type, String)>,
}

/// Whether `out := a op b` needs a scratch word of out's type in the STL (ladder::arith).
fn needs_scratch(op: ArithOp, b: &Operand, out: VarId) -> bool {
    let b_is_out = matches!(b, Operand::Var(r) if r.var == out && r.field.is_none());
    op == ArithOp::Mod || (b_is_out && matches!(op, ArithOp::Sub | ArithOp::Div))
}

/// INT_TO_REAL, which S7-200 does in two steps through a DINT (`I_DI`, then `DI_R`).
pub(crate) const INT_TO_REAL: plc_model::Function = plc_model::Function::Convert {
    from: Type::Int,
    to: Type::Real,
};

/// The scratch words `p`'s arithmetic and INT_TO_REAL need: one per type, named `IL_TMP_<TYPE>` (a number
/// added while that names a variable of the program).
fn scratch_words(p: &Program) -> Vec<(Type, String)> {
    let mut types: Vec<Type> = Vec::new();
    for r in p.rungs().iter() {
        walk_elements(&r.series, &mut |e| {
            let ty = match e {
                Element::Arith { op, b, out, .. } if needs_scratch(*op, b, *out) => p.var(*out).ty,
                Element::Function { func, .. } if *func == INT_TO_REAL => Type::Dint,
                _ => return,
            };
            if !types.contains(&ty) {
                types.push(ty);
            }
        });
    }
    let taken = |n: &str| p.vars().iter().any(|v| v.name.eq_ignore_ascii_case(n));
    types
        .into_iter()
        .map(|ty| {
            let stem = format!("IL_TMP_{ty}");
            let name = std::iter::once(stem.clone())
                .chain((2..).map(|k| format!("{stem}_{k}")))
                .find(|n| !taken(n))
                .expect("an unused name");
            (ty, name)
        })
        .collect()
}

/// The absolute address a variable name stands for (`I0_0` → `I0.0`, `SM0_1` → `SM0.1`), when
/// it has that shape: area I, Q, M, V or SM, a byte number, `_`, a bit 0–7.
pub fn absolute_form(name: &str) -> Option<String> {
    let (area, rest) = ["SM", "I", "Q", "M", "V"]
        .iter()
        .find_map(|a| name.strip_prefix(a).map(|r| (*a, r)))?;
    let (byte, bit) = rest.split_once('_')?;
    let digits = |s: &str| !s.is_empty() && s.len() <= 5 && s.bytes().all(|b| b.is_ascii_digit());
    if !digits(byte) || bit.len() != 1 || !(b'0'..=b'7').contains(&bit.as_bytes()[0]) {
        return None;
    }
    Some(format!("{area}{byte}.{bit}"))
}

/// The class an absolute bit address gets when the STL reader meets it undeclared.
pub fn absolute_class(address: &str) -> VarClass {
    match address.as_bytes()[0] {
        b'I' => VarClass::Input,
        b'Q' => VarClass::Output,
        _ => VarClass::Memory,
    }
}

impl<'a> Names<'a> {
    fn new(p: &'a Program) -> Names<'a> {
        let mut text = Vec::with_capacity(p.vars().len());
        let mut absolute = Vec::with_capacity(p.vars().len());
        for v in p.vars().iter() {
            let short = match v.scope {
                Some(_) => format!("#{}", v.name.split_once(':').map_or(&*v.name, |x| x.1)),
                None => v.name.clone(),
            };
            let abs = absolute_form(&v.name).filter(|a| {
                v.scope.is_none()
                    && v.ty == Type::Bool
                    && v.init == Value::Bool(false)
                    && v.class == absolute_class(a)
                    && !a.starts_with("SM")
            });
            absolute.push(abs.is_some());
            text.push(abs.unwrap_or(short));
        }
        Names {
            p,
            text,
            absolute,
            scratch: scratch_words(p),
        }
    }

    /// The scratch word of type `ty` (one [`scratch_words`] found a use for).
    pub(crate) fn scratch(&self, ty: Type) -> &str {
        let found = self.scratch.iter().find(|(t, _)| *t == ty);
        &found.expect("a scratch word of this type was declared").1
    }

    pub(crate) fn var(&self, v: VarId) -> &str {
        &self.text[v.index()]
    }

    /// A BOOL read as a contact operand: a timer or counter's Q is the instance's own name.
    pub(crate) fn bit(&self, r: VarRef) -> String {
        match r.field {
            None | Some(Field::Q) => self.var(r.var).to_string(),
            Some(f) => format!("{}.{}", self.var(r.var), f.name()),
        }
    }

    /// A word operand: a variable, a field, or a constant. A counter's current value is the
    /// counter itself, as the S7-200 reads `C5` in a word instruction.
    pub(crate) fn operand(&self, o: &plc_model::Operand) -> String {
        let counter = |v: VarId| {
            matches!(
                self.p.var(v).ty,
                Type::Fb(plc_model::FbKind::Ctu | plc_model::FbKind::Ctd)
            )
        };
        match o {
            plc_model::Operand::Var(r) => match r.field {
                None => self.var(r.var).to_string(),
                Some(Field::Cv) if counter(r.var) => self.var(r.var).to_string(),
                Some(f) => format!("{}.{}", self.var(r.var), f.name()),
            },
            plc_model::Operand::Const(v) => constant(*v),
        }
    }

    /// A name as an FBD body writes it (`T1.Q`, `x`), in the scope of `pou`.
    pub(crate) fn named(&self, text: &str, pou: PouId) -> String {
        let (base, field) = match text.split_once('.') {
            Some((b, f)) => (b, Some(f)),
            None => (text, None),
        };
        let base = self
            .position(base, pou)
            .map_or(base.to_string(), |i| self.text[i].clone());
        match field {
            None | Some("Q") => base,
            Some(f) => format!("{base}.{f}"),
        }
    }

    /// The variable `base` of POU `pou` (its own, else a global), as an index into `p.vars`.
    fn position(&self, base: &str, pou: PouId) -> Option<usize> {
        let scoped = format!("{}:{base}", self.p.pou(pou).name);
        let vars = &self.p.vars();
        vars.iter()
            .position(|v| !v.hidden && v.scope == Some(pou) && v.name == scoped)
            .or_else(|| {
                vars.iter()
                    .position(|v| !v.hidden && v.scope.is_none() && v.name == base)
            })
    }

    /// False when `text` (a variable or `instance.FIELD` of `pou`, as an FBD network names it)
    /// is known not to be a BOOL: a variable of another type, or a timer's or counter's
    /// ET, PT, CV or PV.
    pub(crate) fn may_be_bool(&self, text: &str, pou: PouId) -> bool {
        match text.split_once('.') {
            Some((_, f)) => !matches!(f, "ET" | "PT" | "CV" | "PV"),
            None => self
                .position(text, pou)
                .is_none_or(|i| self.p.vars()[i].ty == plc_model::Type::Bool),
        }
    }
}

/// A constant as an operand: numbers as written (integers and bit strings in decimal), REAL and
/// LREAL with a point, TIME as `T#…ms` (the model's `Display`).
pub(crate) fn constant(v: Value) -> String {
    v.to_string()
}

/// The declaration sections of the program's variables (`scope` None) or of one subroutine's.
fn declarations(out: &mut String, p: &Program, names: &Names, scope: Option<PouId>) {
    for (section, class) in [
        ("VAR_INPUT", VarClass::Input),
        ("VAR_OUTPUT", VarClass::Output),
        ("VAR", VarClass::Memory),
    ] {
        let mut lines: Vec<String> = (0..p.vars().len())
            .filter(|&i| {
                let v = &p.vars()[i];
                !v.hidden && v.scope == scope && v.class == class && !names.absolute[i]
            })
            .map(|i| {
                let v = &p.vars()[i];
                let name = names.text[i].trim_start_matches('#');
                let init = match v.ty {
                    Type::Fb(_) => String::new(),
                    ty if v.init == ty.zero() => String::new(),
                    _ => format!(" := {}", constant(v.init)),
                };
                format!("    {name} : {}{init};", v.ty)
            })
            .collect();
        if scope.is_none() && class == VarClass::Memory {
            for (ty, name) in &names.scratch {
                lines.push(format!(
                    "    {name} : {ty}; // scratch word of the arithmetic"
                ));
            }
        }
        if lines.is_empty() {
            continue;
        }
        let _ = writeln!(out, "{section}");
        for l in lines {
            let _ = writeln!(out, "{l}");
        }
        let _ = writeln!(out, "END_VAR");
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn absolute_forms_of_variable_names() {
        assert_eq!(absolute_form("I0_0").as_deref(), Some("I0.0"));
        assert_eq!(absolute_form("Q12_7").as_deref(), Some("Q12.7"));
        assert_eq!(absolute_form("SM0_1").as_deref(), Some("SM0.1"));
        assert_eq!(absolute_form("V100_3").as_deref(), Some("V100.3"));
        assert_eq!(absolute_form("I0_8"), None, "bits are 0-7");
        assert_eq!(absolute_form("Input_1"), None);
        assert_eq!(absolute_form("I0"), None);
        assert_eq!(absolute_class("I0.0"), VarClass::Input);
        assert_eq!(absolute_class("Q0.0"), VarClass::Output);
        assert_eq!(absolute_class("M0.0"), VarClass::Memory);
    }
}
