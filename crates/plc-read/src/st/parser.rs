//! A recursive-descent parser of Structured Text statement lists (IEC 61131-3, 3rd edition,
//! 7.3.3: assignments, calls, IF / CASE / FOR / WHILE / REPEAT, EXIT, CONTINUE, RETURN) with
//! precedence climbing for expressions (7.3.2, Table 71).
//!
//! Keywords are case-insensitive. A statement ends with `;`; a missing `;` before a keyword that
//! closes its block (`END_IF`, `ELSE`, …) or after a compound statement's `END_…` is accepted,
//! as editors do. The first error stops the
//! parse, at the offset of the token that was not expected.
//!
//! Invariant: no tree it returns nests deeper than [`MAX_NESTING`] levels, so that the parser
//! and every later walk over the tree (accesses, lowering, dropping it) recurse a bounded depth
//! whatever the text (10,000 parentheses or a chain of 10,000 `+` are an error at the token that
//! goes past the limit, not a stack overflow).
//!
//! Deliberately not here: declarations (`VAR … END_VAR`: a PLCopen file declares them in the
//! POU's interface), types, and whether a name exists (the caller's).

use super::ast::*;
use super::lexer::{tokens, LexError, Tok, Token};

/// The deepest nesting an ST body or expression may have. Each statement list inside a
/// compound statement, each parenthesised expression, argument list or subscript, each unary
/// operator and each binary operator above its operands (`a + b + c` is two levels) counts one
/// level; going past it is an error at the token that does (docs/plcopen.md, "ST bodies").
/// 128 as the JSON format's reader allows (serde_json's recursion limit); it keeps a debug
/// build's parse within a 2 MiB thread stack (about 12 KiB a level there).
pub const MAX_NESTING: usize = 128;

/// Parses an ST body into its statements.
pub fn statements(text: &str) -> Result<Vec<Statement>, LexError> {
    let toks = tokens(text)?;
    let mut p = Parser {
        toks,
        i: 0,
        end: text.len(),
        depth: 0,
    };
    let body = p.list(false)?;
    match p.peek() {
        None => Ok(body),
        Some(t) => Err(p.unexpected(t.at, "a statement")),
    }
}

/// Parses one ST expression (an FBD in variable's, say): the whole text must be it.
pub fn expression(text: &str) -> Result<Expr, LexError> {
    let toks = tokens(text)?;
    let mut p = Parser {
        toks,
        i: 0,
        end: text.len(),
        depth: 0,
    };
    let e = p.expr()?;
    match p.peek() {
        None => Ok(e),
        Some(t) => Err(p.unexpected(t.at, "the end of the expression")),
    }
}

struct Parser<'a> {
    toks: Vec<Token<'a>>,
    i: usize,
    end: usize,
    /// Nesting levels open at the current token (statement lists, expressions, unary
    /// operators), at most [`MAX_NESTING`].
    depth: usize,
}

/// The error of a text nested past [`MAX_NESTING`] levels, at byte `at`.
fn too_deep(at: usize) -> LexError {
    LexError {
        at,
        message: format!("nested more than {MAX_NESTING} levels deep (parentheses, operators, calls and compound statements each count one; docs/plcopen.md)"),
    }
}

/// The height of `e` in levels as [`MAX_NESTING`] counts them (a name or literal is 1). The
/// parser calls it only on trees it has already bounded, so its recursion is bounded too.
fn height(e: &Expr) -> usize {
    let place = |p: &Place| {
        p.selectors
            .iter()
            .filter_map(|s| match s {
                Selector::Index(ix) => ix.iter().map(height).max(),
                _ => None,
            })
            .max()
            .map_or(1, |h| h + 1)
    };
    match e {
        Expr::Literal(_) => 1,
        Expr::Var(p) => place(p),
        Expr::Unary(_, x) => height(x) + 1,
        Expr::Binary(_, l, r) => height(l).max(height(r)) + 1,
        Expr::Call { callee, args } => {
            args.iter()
                .map(|a| match a {
                    Arg::Input { value, .. } => height(value),
                    Arg::Output { target, .. } => place(target),
                })
                .max()
                .unwrap_or(0)
                .max(place(callee))
                + 1
        }
    }
}

type P<T> = Result<T, LexError>;

/// Keywords that close a statement list.
const CLOSERS: &[&str] = &[
    "END_IF",
    "ELSIF",
    "ELSE",
    "END_CASE",
    "END_FOR",
    "END_WHILE",
    "UNTIL",
    "END_REPEAT",
];

impl<'a> Parser<'a> {
    fn peek(&self) -> Option<&Token<'a>> {
        self.toks.get(self.i)
    }

    fn peek_at(&self, k: usize) -> Option<&Tok<'a>> {
        self.toks.get(self.i + k).map(|t| &t.kind)
    }

    fn at(&self) -> usize {
        self.peek().map_or(self.end, |t| t.at)
    }

    fn unexpected(&self, at: usize, wanted: &str) -> LexError {
        let found = match self.toks.iter().find(|t| t.at == at).map(|t| &t.kind) {
            Some(Tok::Ident(s) | Tok::Literal(s) | Tok::Direct(s) | Tok::Sym(s)) => {
                format!("`{s}`")
            }
            Some(Tok::Pragma(_)) => {
                "a pragma `{…}` (one may stand only where a statement may)".to_owned()
            }
            None => "the end of the body".to_owned(),
        };
        LexError {
            at,
            message: format!("expected {wanted}, found {found}"),
        }
    }

    fn is_kw(&self, kw: &str) -> bool {
        matches!(self.peek_at(0), Some(Tok::Ident(s)) if s.eq_ignore_ascii_case(kw))
    }

    fn is_sym(&self, sym: &str) -> bool {
        matches!(self.peek_at(0), Some(Tok::Sym(s)) if *s == sym)
    }

    fn eat_kw(&mut self, kw: &str) -> bool {
        let yes = self.is_kw(kw);
        self.i += usize::from(yes);
        yes
    }

    fn eat_sym(&mut self, sym: &str) -> bool {
        let yes = self.is_sym(sym);
        self.i += usize::from(yes);
        yes
    }

    fn expect_kw(&mut self, kw: &str) -> P<()> {
        if self.eat_kw(kw) {
            Ok(())
        } else {
            Err(self.unexpected(self.at(), &format!("`{kw}`")))
        }
    }

    fn expect_sym(&mut self, sym: &str) -> P<()> {
        if self.eat_sym(sym) {
            Ok(())
        } else {
            Err(self.unexpected(self.at(), &format!("`{sym}`")))
        }
    }

    /// True at a keyword that closes a statement list (or at a CASE label, in a CASE).
    fn at_close(&self, in_case: bool) -> bool {
        match self.peek_at(0) {
            None => true,
            Some(Tok::Ident(s)) if CLOSERS.iter().any(|k| s.eq_ignore_ascii_case(k)) => true,
            _ => in_case && self.at_case_label(),
        }
    }

    /// A CASE label starts here: a constant or name, then `,`, `..` or `:`.
    fn at_case_label(&self) -> bool {
        let first = match self.peek_at(0) {
            Some(Tok::Sym("-")) => 1,
            _ => 0,
        };
        matches!(self.peek_at(first), Some(Tok::Literal(_) | Tok::Ident(_)))
            && matches!(self.peek_at(first + 1), Some(Tok::Sym(":" | "," | "..")))
    }

    /// Opens one nesting level at the current token (an error past [`MAX_NESTING`]).
    fn enter(&mut self) -> P<()> {
        self.depth += 1;
        if self.depth > MAX_NESTING {
            return Err(too_deep(self.at()));
        }
        Ok(())
    }

    fn list(&mut self, in_case: bool) -> P<Vec<Statement>> {
        self.enter()?;
        let mut out = Vec::new();
        while !self.at_close(in_case) {
            out.push(self.statement()?);
        }
        self.depth -= 1;
        Ok(out)
    }

    /// The `;` after a statement (optional before a closing keyword).
    fn end_of_statement(&mut self) -> P<()> {
        if self.eat_sym(";") || self.at_close(false) {
            Ok(())
        } else {
            Err(self.unexpected(self.at(), "`;`"))
        }
    }

    fn statement(&mut self) -> P<Statement> {
        let at = self.at();
        if let Some(Tok::Pragma(p)) = self.peek_at(0) {
            // matiec takes a pragma as a statement of the list, without a `;`.
            let text = p.to_string();
            self.i += 1;
            return Ok(Statement {
                at,
                kind: Stmt::Pragma { text },
            });
        }
        let kind = if self.eat_sym(";") {
            return Ok(Statement {
                at,
                kind: Stmt::Empty,
            });
        } else if self.eat_kw("IF") {
            self.if_statement()?
        } else if self.eat_kw("CASE") {
            self.case_statement()?
        } else if self.eat_kw("FOR") {
            self.for_statement()?
        } else if self.eat_kw("WHILE") {
            let cond = self.expr()?;
            self.expect_kw("DO")?;
            let body = self.list(false)?;
            self.expect_kw("END_WHILE")?;
            Stmt::While { cond, body }
        } else if self.eat_kw("REPEAT") {
            let body = self.list(false)?;
            self.expect_kw("UNTIL")?;
            let until = self.expr()?;
            self.expect_kw("END_REPEAT")?;
            Stmt::Repeat { body, until }
        } else if self.eat_kw("EXIT") {
            Stmt::Exit
        } else if self.eat_kw("CONTINUE") {
            Stmt::Continue
        } else if self.eat_kw("RETURN") {
            Stmt::Return
        } else {
            let target = self.place()?;
            if self.eat_sym(":=") {
                Stmt::Assign {
                    target,
                    value: self.expr()?,
                }
            } else if self.eat_sym("(") {
                Stmt::Call {
                    callee: target,
                    args: self.args()?,
                }
            } else {
                return Err(self.unexpected(self.at(), "`:=` or a call"));
            }
        };
        let compound = matches!(
            kind,
            Stmt::If { .. }
                | Stmt::Case { .. }
                | Stmt::For { .. }
                | Stmt::While { .. }
                | Stmt::Repeat { .. }
        );
        if compound {
            // `END_IF;` is the standard; editors also write `END_IF` alone before the next one.
            self.eat_sym(";");
        } else {
            self.end_of_statement()?;
        }
        Ok(Statement { at, kind })
    }

    fn if_statement(&mut self) -> P<Stmt> {
        let mut arms = Vec::new();
        loop {
            let cond = self.expr()?;
            self.expect_kw("THEN")?;
            arms.push((cond, self.list(false)?));
            if !self.eat_kw("ELSIF") {
                break;
            }
        }
        let otherwise = if self.eat_kw("ELSE") {
            self.list(false)?
        } else {
            Vec::new()
        };
        self.expect_kw("END_IF")?;
        Ok(Stmt::If { arms, otherwise })
    }

    fn case_statement(&mut self) -> P<Stmt> {
        let selector = self.expr()?;
        self.expect_kw("OF")?;
        let mut arms = Vec::new();
        while self.at_case_label() {
            let mut labels = Vec::new();
            loop {
                let a = self.expr()?;
                labels.push(if self.eat_sym("..") {
                    CaseLabel::Range(a, self.expr()?)
                } else {
                    CaseLabel::One(a)
                });
                if !self.eat_sym(",") {
                    break;
                }
            }
            self.expect_sym(":")?;
            arms.push((labels, self.list(true)?));
        }
        let otherwise = if self.eat_kw("ELSE") {
            self.list(false)?
        } else {
            Vec::new()
        };
        self.expect_kw("END_CASE")?;
        Ok(Stmt::Case {
            selector,
            arms,
            otherwise,
        })
    }

    fn for_statement(&mut self) -> P<Stmt> {
        let var = self.place()?;
        self.expect_sym(":=")?;
        let from = self.expr()?;
        self.expect_kw("TO")?;
        let to = self.expr()?;
        let by = if self.eat_kw("BY") {
            Some(self.expr()?)
        } else {
            None
        };
        self.expect_kw("DO")?;
        let body = self.list(false)?;
        self.expect_kw("END_FOR")?;
        Ok(Stmt::For {
            var,
            from,
            to,
            by,
            body,
        })
    }

    /// A variable: a name or direct address, then fields, subscripts and dereferences.
    fn place(&mut self) -> P<Place> {
        let at = self.at();
        let base = match self.peek_at(0) {
            Some(Tok::Ident(s) | Tok::Direct(s)) => s.to_string(),
            _ => return Err(self.unexpected(at, "a variable")),
        };
        self.i += 1;
        let mut selectors = Vec::new();
        loop {
            if self.is_sym(".") && matches!(self.peek_at(1), Some(Tok::Ident(_))) {
                if let Some(Tok::Ident(f)) = self.peek_at(1) {
                    selectors.push(Selector::Field(f.to_string()));
                }
                self.i += 2;
            } else if self.is_sym(".") && matches!(self.peek_at(1), Some(Tok::Literal(_))) {
                // A bit of a variable: `w.3`.
                if let Some(Tok::Literal(f)) = self.peek_at(1) {
                    selectors.push(Selector::Field(f.to_string()));
                }
                self.i += 2;
            } else if self.eat_sym("[") {
                let mut index = vec![self.expr()?];
                while self.eat_sym(",") {
                    index.push(self.expr()?);
                }
                self.expect_sym("]")?;
                selectors.push(Selector::Index(index));
            } else if self.eat_sym("^") {
                selectors.push(Selector::Deref);
            } else {
                break;
            }
        }
        Ok(Place {
            base,
            base_at: at,
            selectors,
        })
    }

    /// The arguments of a call, after `(`, up to and with `)`.
    fn args(&mut self) -> P<Vec<Arg>> {
        let mut args = Vec::new();
        if self.eat_sym(")") {
            return Ok(args);
        }
        loop {
            let named = matches!(self.peek_at(0), Some(Tok::Ident(_)))
                && matches!(self.peek_at(1), Some(Tok::Sym(":=" | "=>")));
            let not_out = self.is_kw("NOT")
                && matches!(self.peek_at(1), Some(Tok::Ident(_)))
                && matches!(self.peek_at(2), Some(Tok::Sym("=>")));
            if named || not_out {
                self.i += usize::from(not_out);
                let name = match self.peek_at(0) {
                    Some(Tok::Ident(s)) => s.to_string(),
                    _ => unreachable!("checked above"),
                };
                self.i += 1;
                if self.eat_sym("=>") {
                    args.push(Arg::Output {
                        name,
                        target: self.place()?,
                    });
                } else {
                    self.expect_sym(":=")?;
                    args.push(Arg::Input {
                        name: Some(name),
                        value: self.expr()?,
                    });
                }
            } else {
                args.push(Arg::Input {
                    name: None,
                    value: self.expr()?,
                });
            }
            if !self.eat_sym(",") {
                break;
            }
        }
        self.expect_sym(")")?;
        Ok(args)
    }

    fn expr(&mut self) -> P<Expr> {
        self.enter()?;
        let e = self.binary(0)?;
        self.depth -= 1;
        Ok(e)
    }

    /// Operators of precedence `min` and up. A chain of them builds a tree as tall as the chain
    /// is long (`a + b + c` is `(a + b) + c`), which the recursion does not see: its height is
    /// counted and bounded here.
    fn binary(&mut self, min: u8) -> P<Expr> {
        let mut left = self.unary()?;
        let mut tall: Option<usize> = None;
        while let Some(op) = self.binary_op() {
            if op.precedence() < min {
                break;
            }
            let at = self.at();
            self.i += 1;
            let right = self.binary(op.precedence() + 1)?;
            let h = tall.unwrap_or_else(|| height(&left)).max(height(&right)) + 1;
            if self.depth + h > MAX_NESTING {
                return Err(too_deep(at));
            }
            tall = Some(h);
            left = Expr::Binary(op, Box::new(left), Box::new(right));
        }
        Ok(left)
    }

    fn binary_op(&self) -> Option<BinaryOp> {
        use BinaryOp::*;
        Some(match self.peek_at(0)? {
            Tok::Sym(s) => match *s {
                "**" => Power,
                "*" => Mul,
                "/" => Div,
                "+" => Add,
                "-" => Sub,
                "<" => Lt,
                ">" => Gt,
                "<=" => Le,
                ">=" => Ge,
                "=" => Eq,
                "<>" => Ne,
                "&" => And,
                _ => return None,
            },
            Tok::Ident(s) => match s.to_ascii_uppercase().as_str() {
                "MOD" => Mod,
                "AND" => And,
                "XOR" => Xor,
                "OR" => Or,
                _ => return None,
            },
            _ => return None,
        })
    }

    fn unary(&mut self) -> P<Expr> {
        let op = if self.is_kw("NOT") {
            UnaryOp::Not
        } else if self.is_sym("-") {
            UnaryOp::Neg
        } else if self.is_sym("+") {
            UnaryOp::Plus
        } else {
            return self.primary();
        };
        self.enter()?;
        self.i += 1;
        let x = self.unary()?;
        self.depth -= 1;
        Ok(Expr::Unary(op, Box::new(x)))
    }

    fn primary(&mut self) -> P<Expr> {
        let at = self.at();
        match self.peek_at(0) {
            Some(Tok::Literal(s)) => {
                let s = s.to_string();
                self.i += 1;
                Ok(Expr::Literal(s))
            }
            Some(Tok::Sym("(")) => {
                self.i += 1;
                let e = self.expr()?;
                self.expect_sym(")")?;
                Ok(e)
            }
            Some(Tok::Ident(s))
                if s.eq_ignore_ascii_case("TRUE") || s.eq_ignore_ascii_case("FALSE") =>
            {
                let s = s.to_string();
                self.i += 1;
                Ok(Expr::Literal(s))
            }
            Some(Tok::Ident(_) | Tok::Direct(_)) => {
                let place = self.place()?;
                if self.eat_sym("(") {
                    Ok(Expr::Call {
                        callee: place,
                        args: self.args()?,
                    })
                } else {
                    Ok(Expr::Var(place))
                }
            }
            _ => Err(self.unexpected(at, "an expression")),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn var(name: &str, at: usize) -> Expr {
        Expr::Var(Place {
            base: name.into(),
            base_at: at,
            selectors: vec![],
        })
    }

    #[test]
    fn precedence_follows_the_standard() {
        // a OR b AND NOT c = d  is  a OR (b AND ((NOT c) = d)).
        let s = statements("x := a OR b AND NOT c = d;").unwrap();
        let Stmt::Assign { value, .. } = &s[0].kind else {
            panic!("{s:?}")
        };
        use BinaryOp::*;
        let expected = Expr::Binary(
            Or,
            Box::new(var("a", 5)),
            Box::new(Expr::Binary(
                And,
                Box::new(var("b", 10)),
                Box::new(Expr::Binary(
                    Eq,
                    Box::new(Expr::Unary(UnaryOp::Not, Box::new(var("c", 20)))),
                    Box::new(var("d", 24)),
                )),
            )),
        );
        assert_eq!(value, &expected);
    }

    #[test]
    fn every_statement_kind() {
        let text = "
            IF a THEN x := 1; ELSIF b THEN x := 2 ELSE x := 3; END_IF;
            CASE n OF 1, 2: y := 1; 3..5: y := 2; -1: ; ELSE y := 0; END_CASE
            FOR i := 1 TO 10 BY 2 DO arr[i] := i * 2; IF i > 5 THEN EXIT; END_IF; END_FOR;
            WHILE w DO w := FALSE; CONTINUE; END_WHILE;
            REPEAT k := k + 1; UNTIL k >= 3 END_REPEAT;
            T1(IN := start, PT := T#5s, Q => done, NOT ET => t);
            out := MAX(a := 1, 2) + p^.f.g[1, 2];
            RETURN;";
        let s = statements(text).unwrap();
        let kinds: Vec<&str> = s
            .iter()
            .map(|s| match &s.kind {
                Stmt::If { .. } => "if",
                Stmt::Case { arms, .. } if arms.len() == 3 => "case",
                Stmt::For { body, .. } if body.len() == 2 => "for",
                Stmt::While { body, .. } if body.len() == 2 => "while",
                Stmt::Repeat { .. } => "repeat",
                Stmt::Call { args, .. } if args.len() == 4 => "call",
                Stmt::Assign { .. } => "assign",
                Stmt::Return => "return",
                _ => "other",
            })
            .collect();
        assert_eq!(
            kinds,
            ["if", "case", "for", "while", "repeat", "call", "assign", "return"]
        );
        assert_eq!(&text[s[1].at..s[1].at + 4], "CASE");
    }

    #[test]
    fn nesting_past_the_limit_is_an_error_at_the_token_that_goes_past_it() {
        let at_limit = |open: &str, close: &str, n: usize| {
            format!("x := {}a{};", open.repeat(n), close.repeat(n))
        };
        // `x := (…(a)…);`: the statement list and the assignment's expression are two levels.
        assert!(statements(&at_limit("(", ")", MAX_NESTING - 2)).is_ok());
        let e = statements(&at_limit("(", ")", 10_000)).unwrap_err();
        assert_eq!(e.at, 5 + MAX_NESTING - 1);
        assert!(
            e.message.starts_with("nested more than 128 levels deep"),
            "{}",
            e.message
        );
        assert!(statements(&at_limit("-", "", MAX_NESTING - 2)).is_ok());
        let e = statements(&at_limit("-", "", 20_000)).unwrap_err();
        assert_eq!(e.at, 5 + MAX_NESTING - 2);
        assert!(statements(&at_limit("NOT ", "", 20_000)).is_err());
        // A chain of binary operators is as tall as it is long.
        let chain = |n: usize| format!("x := a{};", " + a".repeat(n));
        assert!(statements(&chain(MAX_NESTING - 3)).is_ok());
        let e = statements(&chain(20_000)).unwrap_err();
        assert_eq!(e.at, 5 + 1 + 4 * (MAX_NESTING - 3) + 1);
        // Compound statements count one level each.
        let ifs = |n: usize| format!("{}x := 1;{}", "IF c THEN ".repeat(n), " END_IF;".repeat(n));
        assert!(statements(&ifs(MAX_NESTING - 2)).is_ok());
        let e = statements(&ifs(5_000)).unwrap_err();
        assert_eq!(e.at, 10 * (MAX_NESTING - 1) + 3);
        assert!(expression(&"(".repeat(10_000)).is_err());
    }

    #[test]
    fn errors_name_what_was_expected_and_where() {
        let e = statements("IF a THEN x := 1;").unwrap_err();
        assert_eq!(e.message, "expected `END_IF`, found the end of the body");
        let e = statements("x := (a + ;").unwrap_err();
        assert_eq!(
            (e.at, e.message.as_str()),
            (10, "expected an expression, found `;`")
        );
        let e = statements("x 1;").unwrap_err();
        assert_eq!(
            (e.at, e.message.as_str()),
            (2, "expected `:=` or a call, found `1`")
        );
    }
}
