//! IEC 61131-3 Instruction List text (3rd edition, 7.2; 2nd edition, 3.2) → a list of labels
//! and instructions ([`Item`]), each with the byte offset where it starts in the IL text.
//!
//! The instructions, by IEC's tables (3rd ed. Tables 67 and 68; 2nd ed. Tables 51 and 52):
//! `LD LDN ST STN S R NOT`, the expression operators `AND ANDN & &N OR ORN XOR XORN ADD SUB
//! MUL DIV MOD GT GE EQ NE LE LT` with an operand or a deferred operand `OP( [operand] … )`
//! (an instruction list of its own, ended by `)`), `JMP JMPC JMPCN label`, `RET RETC RETCN`,
//! `CAL CALC CALCN instance[(arguments)]` (formal `IN := x`, `Q => y`, or informal), the
//! function block input operators `S1 R1 CLK CU CD PV IN PT instance` (an implicit call),
//! and any other name as a function called with the current result as its first argument and
//! the operands that follow (`LIMIT 0, 100`, matiec's `il_function_call`), or called formally
//! `F( IN1 := x, OUT => y )` (its arguments as `CAL`'s, one a line or not). Labels `L1:` stand
//! before an instruction or alone on a line. Comments are the ST lexer's (`(* … *)`, nesting,
//! and `// …`); an instruction ends at the end of its line (an argument list or a deferred
//! operand's list in parentheses may span lines).
//!
//! Operands (7.2.1): literals (numeric, typed, time, string, `TRUE`/`FALSE`, `-5`), variables
//! with fields and subscripts (`T1.Q`, `a[i]`), direct addresses (`%IX0.1`).
//!
//! Invariant: a syntax error is one [`LexError`] at the offset of the token that is wrong.
//! Deliberately not here: types and meaning (`super::il_body` translates the list to ST and
//! refuses what it cannot execute).

use crate::st::ast::{Arg, BinaryOp, Expr, Place, Selector};
use crate::st::lexer::{tokens, Tok, Token};
use crate::st::LexError;

/// A condition of a jump, call or return: always, when the current result is TRUE (`C`), when
/// it is FALSE (`CN`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum Cond {
    Always,
    IfTrue,
    IfFalse,
}

/// An instruction's operator and what it takes.
#[derive(Clone, Debug, PartialEq)]
pub(super) enum Op {
    /// `LD` (`neg`: `LDN`).
    Ld {
        neg: bool,
    },
    /// `ST` (`neg`: `STN`).
    St {
        neg: bool,
    },
    /// `S` and `R`: set or reset a BOOL when the current result is TRUE, or an implicit call
    /// of an instance's input `S` or `R`.
    Set,
    Reset,
    Not,
    /// An expression operator (`AND`, `ADD`, `GT`, …; `neg`: the operand negated, `ANDN`).
    Binary {
        op: BinaryOp,
        neg: bool,
    },
    /// A function block input operator (`CLK R1`): the instance called with that input set to
    /// the current result (matiec's `XXX_CAL_operator`).
    FbInput(String),
    Jmp(Cond, String),
    Ret(Cond),
    Cal {
        cond: Cond,
        fb: Place,
        args: Vec<Arg>,
    },
    /// A function called with the current result first, then `args`.
    Function {
        name: String,
        args: Vec<Expr>,
    },
    /// A formal function call `F( IN1 := x, OUT => y )`: the current result is not an input,
    /// the result becomes the current result.
    FormalCall {
        name: String,
        args: Vec<Arg>,
    },
}

/// An instruction: its operator, its operand (for operators that take one) and, for a
/// deferred operand `OP( … )`, the instructions in the parentheses.
#[derive(Clone, Debug, PartialEq)]
pub(super) struct Instr {
    pub at: usize,
    /// The operator as written.
    pub name: String,
    pub op: Op,
    pub operand: Option<Expr>,
    pub nested: Option<Vec<Item>>,
}

#[derive(Clone, Debug, PartialEq)]
pub(super) enum Item {
    /// A label (upper case, as IEC names are case-insensitive) and where it is.
    Label(String, usize),
    Instr(Instr),
}

/// The labels and instructions of IL text `text`.
pub(super) fn parse(text: &str) -> Result<Vec<Item>, LexError> {
    let toks = tokens(text)?;
    // Whether a line ends between token i-1 and token i.
    let mut fresh = Vec::with_capacity(toks.len());
    let mut prev_end = 0;
    for t in &toks {
        fresh.push(text[prev_end..t.at].contains('\n') || prev_end == 0);
        prev_end = t.at + tok_text(&t.kind).len();
    }
    let mut p = P {
        toks,
        fresh,
        i: 0,
        end: text.len(),
        depth: 0,
    };
    p.list(false)
}

fn tok_text<'a>(t: &Tok<'a>) -> &'a str {
    match t {
        Tok::Ident(s) | Tok::Literal(s) | Tok::Direct(s) | Tok::Sym(s) | Tok::Pragma(s) => s,
    }
}

struct P<'a> {
    toks: Vec<Token<'a>>,
    fresh: Vec<bool>,
    i: usize,
    end: usize,
    depth: usize,
}

type R<T> = Result<T, LexError>;

const FB_INPUTS: &[&str] = &["S1", "R1", "CLK", "CU", "CD", "PV", "IN", "PT"];

fn binary(name: &str) -> Option<(BinaryOp, bool)> {
    use BinaryOp::*;
    Some(match name {
        "AND" | "&" => (And, false),
        "ANDN" | "&N" => (And, true),
        "OR" => (Or, false),
        "ORN" => (Or, true),
        "XOR" => (Xor, false),
        "XORN" => (Xor, true),
        "ADD" => (Add, false),
        "SUB" => (Sub, false),
        "MUL" => (Mul, false),
        "DIV" => (Div, false),
        "MOD" => (Mod, false),
        "GT" => (Gt, false),
        "GE" => (Ge, false),
        "EQ" => (Eq, false),
        "NE" => (Ne, false),
        "LE" => (Le, false),
        "LT" => (Lt, false),
        _ => return None,
    })
}

fn cond(name: &str, base: &str) -> Option<Cond> {
    Some(match name.strip_prefix(base)? {
        "" => Cond::Always,
        "C" => Cond::IfTrue,
        "CN" => Cond::IfFalse,
        _ => return None,
    })
}

impl<'a> P<'a> {
    fn peek(&self) -> Option<&Token<'a>> {
        self.toks.get(self.i)
    }
    fn at(&self) -> usize {
        self.peek().map_or(self.end, |t| t.at)
    }
    /// Whether the current token starts a new line (or there is none).
    fn at_eol(&self) -> bool {
        self.peek().is_none() || self.fresh[self.i]
    }
    fn is_sym(&self, s: &str) -> bool {
        matches!(self.peek(), Some(Token { kind: Tok::Sym(x), .. }) if *x == s)
    }
    fn eat_sym(&mut self, s: &str) -> bool {
        let yes = self.is_sym(s);
        if yes {
            self.i += 1;
        }
        yes
    }
    fn err<T>(&self, at: usize, m: impl Into<String>) -> R<T> {
        Err(LexError {
            at,
            message: m.into(),
        })
    }
    fn unexpected<T>(&self, wanted: &str) -> R<T> {
        match self.peek() {
            Some(t) => self.err(
                t.at,
                format!("`{}` where {wanted} was expected", tok_text(&t.kind)),
            ),
            None => self.err(
                self.end,
                format!("the end of the text where {wanted} was expected"),
            ),
        }
    }
    /// Whether the instruction's line ends here (`nested`: or its list's `)` comes).
    fn line_ends(&self, nested: bool) -> bool {
        self.at_eol() || (nested && self.is_sym(")"))
    }
    fn end_of_instruction(&self, in_parens: bool) -> R<()> {
        if self.at_eol() || (in_parens && self.is_sym(")")) {
            Ok(())
        } else {
            self.unexpected("the end of the line")
        }
    }

    /// Items up to the end (or, `nested`, up to and including the `)` that closes them).
    fn list(&mut self, nested: bool) -> R<Vec<Item>> {
        let mut out = Vec::new();
        loop {
            let Some(t) = self.peek().cloned() else {
                if nested {
                    return self.unexpected("`)` closing the deferred operand");
                }
                return Ok(out);
            };
            if nested && self.is_sym(")") {
                self.i += 1;
                return Ok(out);
            }
            // A label: `name:` (not `name :=`).
            if let Tok::Ident(n) = t.kind {
                if matches!(
                    self.toks.get(self.i + 1),
                    Some(Token {
                        kind: Tok::Sym(":"),
                        ..
                    })
                ) {
                    if nested {
                        return self.err(
                            t.at,
                            format!("the label `{n}` inside a deferred operand's parentheses"),
                        );
                    }
                    self.i += 2;
                    out.push(Item::Label(n.to_ascii_uppercase(), t.at));
                    continue;
                }
            }
            out.push(Item::Instr(self.instruction(nested)?));
        }
    }

    fn instruction(&mut self, nested: bool) -> R<Instr> {
        let Some(t) = self.peek().cloned() else {
            return self.unexpected("an instruction");
        };
        let at = t.at;
        let name = match t.kind {
            Tok::Ident(n) => n.to_ascii_uppercase(),
            Tok::Sym("&") => "&".to_owned(),
            _ => return self.unexpected("an IL operator"),
        };
        self.i += 1;
        // `&N`: the lexer reads `&` and `N` apart.
        let name = if name == "&"
            && matches!(self.peek(), Some(Token { kind: Tok::Ident(n), at: a }) if n.eq_ignore_ascii_case("N") && *a == at + 1)
        {
            self.i += 1;
            "&N".to_owned()
        } else {
            name
        };
        let mut instr = Instr {
            at,
            name: name.clone(),
            op: Op::Not,
            operand: None,
            nested: None,
        };
        let n = name.as_str();
        instr.op = match n {
            "LD" | "LDN" => Op::Ld { neg: n == "LDN" },
            "ST" | "STN" => Op::St { neg: n == "STN" },
            "S" => Op::Set,
            "R" => Op::Reset,
            "NOT" => Op::Not,
            _ if FB_INPUTS.contains(&n) => Op::FbInput(name.clone()),
            _ => {
                if let Some((op, neg)) = binary(n) {
                    Op::Binary { op, neg }
                } else if let Some(c) = cond(n, "JMP") {
                    let label = match self.peek() {
                        Some(Token {
                            kind: Tok::Ident(l),
                            ..
                        }) if !self.at_eol() => l.to_ascii_uppercase(),
                        _ => return self.unexpected(&format!("the label {n} jumps to")),
                    };
                    self.i += 1;
                    Op::Jmp(c, label)
                } else if let Some(c) = cond(n, "RET") {
                    Op::Ret(c)
                } else if let Some(c) = cond(n, "CAL") {
                    if self.at_eol() {
                        return self.unexpected(&format!("the instance {n} calls"));
                    }
                    let fb = self.place()?;
                    let args = if self.is_sym("(") && !self.at_eol() {
                        self.i += 1;
                        self.call_args()?
                    } else {
                        Vec::new()
                    };
                    Op::Cal { cond: c, fb, args }
                } else if self.is_sym("(") && !self.at_eol() {
                    // A formal function call `F( IN1 := …, OUT => … )`.
                    let Tok::Ident(orig) = t.kind else {
                        return self.err(at, format!("`{name}` is not an IL operator"));
                    };
                    self.i += 1;
                    Op::FormalCall {
                        name: orig.to_owned(),
                        args: self.call_args()?,
                    }
                } else if let Tok::Ident(orig) = t.kind {
                    let mut args = Vec::new();
                    if !self.line_ends(nested) {
                        args.push(self.operand()?);
                        while self.eat_sym(",") {
                            args.push(self.operand()?);
                        }
                    }
                    self.end_of_instruction(nested)?;
                    return Ok(Instr {
                        op: Op::Function {
                            name: orig.to_owned(),
                            args,
                        },
                        ..instr
                    });
                } else {
                    return self.err(at, format!("`{name}` is not an IL operator"));
                }
            }
        };
        match &instr.op {
            Op::Ld { .. } | Op::St { .. } | Op::Set | Op::Reset | Op::FbInput(_) => {
                if self.at_eol() {
                    return self.unexpected(&format!("the operand of {n}"));
                }
                instr.operand = Some(self.operand()?);
            }
            Op::Binary { .. } => {
                if self.is_sym("(") && !self.at_eol() {
                    self.i += 1;
                    self.depth += 1;
                    if self.depth > crate::st::parser::MAX_NESTING {
                        return self.err(at, "deferred operands nested too deep");
                    }
                    if !self.at_eol() {
                        instr.operand = Some(self.operand()?);
                    }
                    instr.nested = Some(self.list(true)?);
                    self.depth -= 1;
                } else {
                    if self.at_eol() {
                        return self.unexpected(&format!("the operand of {n}"));
                    }
                    instr.operand = Some(self.operand()?);
                }
            }
            Op::Not if !self.line_ends(nested) => {
                return self.err(
                    self.at(),
                    "an operand after NOT (IEC gives it no meaning; matiec refuses it)",
                )
            }
            _ => {}
        }
        self.end_of_instruction(nested)?;
        Ok(instr)
    }

    /// `( [IN := x, Q => y | x, y] )` after `CAL inst`, the `(` eaten.
    fn call_args(&mut self) -> R<Vec<Arg>> {
        let mut args = Vec::new();
        if self.eat_sym(")") {
            return Ok(args);
        }
        loop {
            let formal = matches!(
                (self.peek(), self.toks.get(self.i + 1)),
                (
                    Some(Token {
                        kind: Tok::Ident(_),
                        ..
                    }),
                    Some(Token {
                        kind: Tok::Sym(":=" | "=>"),
                        ..
                    })
                )
            );
            let negated_out = matches!(
                (self.peek(), self.toks.get(self.i + 2)),
                (Some(Token { kind: Tok::Ident(n), .. }), Some(Token { kind: Tok::Sym("=>"), .. })) if n.eq_ignore_ascii_case("NOT")
            );
            if negated_out {
                return self.err(self.at(), "a negated output `NOT Q => y` in a call");
            }
            if formal {
                let Some(Token {
                    kind: Tok::Ident(name),
                    ..
                }) = self.peek().cloned()
                else {
                    return self.unexpected("an argument");
                };
                self.i += 1;
                if self.eat_sym(":=") {
                    if self.is_sym("(") {
                        return self.err(self.at(), "an instruction list as an argument");
                    }
                    args.push(Arg::Input {
                        name: Some(name.to_owned()),
                        value: self.operand()?,
                    });
                } else {
                    self.i += 1; // =>
                    args.push(Arg::Output {
                        name: name.to_owned(),
                        target: self.place()?,
                    });
                }
            } else {
                args.push(Arg::Input {
                    name: None,
                    value: self.operand()?,
                });
            }
            if self.eat_sym(")") {
                return Ok(args);
            }
            if !self.eat_sym(",") {
                return self.unexpected("`,` or `)` in the argument list");
            }
        }
    }

    /// A literal, a variable or a direct address.
    fn operand(&mut self) -> R<Expr> {
        let Some(t) = self.peek().cloned() else {
            return self.unexpected("an operand");
        };
        match t.kind {
            Tok::Literal(l) => {
                self.i += 1;
                Ok(Expr::Literal(l.to_owned()))
            }
            Tok::Sym("-" | "+") => {
                let sign = if self.is_sym("-") { "-" } else { "" };
                self.i += 1;
                match self.peek() {
                    Some(Token {
                        kind: Tok::Literal(l),
                        ..
                    }) => {
                        let l = format!("{sign}{l}");
                        self.i += 1;
                        Ok(Expr::Literal(l))
                    }
                    _ => self.unexpected("a number after the sign"),
                }
            }
            Tok::Ident(n) if n.eq_ignore_ascii_case("TRUE") || n.eq_ignore_ascii_case("FALSE") => {
                self.i += 1;
                Ok(Expr::Literal(n.to_owned()))
            }
            Tok::Ident(_) | Tok::Direct(_) => Ok(Expr::Var(self.place()?)),
            _ => self.unexpected("an operand"),
        }
    }

    /// `a`, `a.b`, `a[i, 2].c`, `%IX0.1`.
    fn place(&mut self) -> R<Place> {
        let Some(t) = self.peek().cloned() else {
            return self.unexpected("a variable");
        };
        let base = match t.kind {
            Tok::Ident(n) | Tok::Direct(n) => n.to_owned(),
            _ => return self.unexpected("a variable"),
        };
        self.i += 1;
        let mut selectors = Vec::new();
        loop {
            if self.is_sym(".") && !self.at_eol() {
                self.i += 1;
                match self.peek().cloned() {
                    Some(Token {
                        kind: Tok::Ident(f),
                        ..
                    }) => {
                        self.i += 1;
                        selectors.push(Selector::Field(f.to_owned()));
                    }
                    // `T1.Q` lexes as `T1`, `.`, `Q`; a bit `x.3` as a literal.
                    _ => return self.unexpected("a field name"),
                }
            } else if self.is_sym("[") && !self.at_eol() {
                self.i += 1;
                let mut ix = vec![self.operand()?];
                while self.eat_sym(",") {
                    ix.push(self.operand()?);
                }
                if !self.eat_sym("]") {
                    return self.unexpected("`]`");
                }
                selectors.push(Selector::Index(ix));
            } else {
                break;
            }
        }
        Ok(Place {
            base,
            base_at: t.at,
            selectors,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn ops(text: &str) -> Vec<String> {
        parse(text)
            .unwrap()
            .iter()
            .map(|i| match i {
                Item::Label(l, _) => format!("{l}:"),
                Item::Instr(x) => x.name.clone(),
            })
            .collect()
    }

    #[test]
    fn lines_labels_and_operators() {
        assert_eq!(
            ops("LD a (* c *)\nL1: ANDN b\nJMPC L1\nL2:\n  CAL T1(IN := x,\n PT := T#1s)\nRETCN\nLIMIT 0, 100\n&N c"),
            ["LD", "L1:", "ANDN", "JMPC", "L2:", "CAL", "RETCN", "LIMIT", "&N"]
        );
        let items = parse("AND( b\n OR c\n)\nST d").unwrap();
        let Item::Instr(i) = &items[0] else { panic!() };
        assert_eq!(
            i.op,
            Op::Binary {
                op: BinaryOp::And,
                neg: false
            }
        );
        assert_eq!(
            i.operand,
            Some(Expr::Var(Place {
                base: "b".into(),
                base_at: 5,
                selectors: vec![]
            }))
        );
        assert_eq!(i.nested.as_ref().map(|n| n.len()), Some(1));
        let Item::Instr(f) = &parse("LIMIT 0, -5").unwrap()[0] else {
            panic!()
        };
        assert_eq!(
            f.op,
            Op::Function {
                name: "LIMIT".into(),
                args: vec![Expr::Literal("0".into()), Expr::Literal("-5".into())]
            }
        );
        let items = parse("F(\n  EN := go,\n  a := 1,\n  ENO => ok\n)\nST y").unwrap();
        let Item::Instr(f) = &items[0] else { panic!() };
        let Op::FormalCall { name, args } = &f.op else {
            panic!("{:?}", f.op)
        };
        assert_eq!(name, "F");
        let names: Vec<&str> = args
            .iter()
            .map(|a| match a {
                Arg::Input { name, .. } => name.as_deref().unwrap_or("?"),
                Arg::Output { name, .. } => name,
            })
            .collect();
        assert_eq!(names, ["EN", "a", "ENO"]);
        assert_eq!(items.len(), 2);
    }

    #[test]
    fn errors_are_at_the_token() {
        let e = parse("LD a b").unwrap_err();
        assert_eq!(
            (e.at, e.message.as_str()),
            (5, "`b` where the end of the line was expected")
        );
        let e = parse("LD\nST x").unwrap_err();
        assert_eq!(e.at, 3);
        assert!(parse("AND( a\nOR b").unwrap_err().message.contains("`)`"));
        assert_eq!(parse("JMP\n").unwrap_err().at, 4);
    }
}
