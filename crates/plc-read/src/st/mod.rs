//! Structured Text (IEC 61131-3, 3rd edition, 7.3): the statements of an ST body, parsed for
//! real ([`parser`]: expressions, assignments, IF / CASE / FOR / WHILE / REPEAT / EXIT /
//! RETURN, function block and function calls with formal and informal arguments), and what
//! each top-level statement reads and writes ([`accesses`]), so that a POU written in ST is
//! analysed with its statements as units — an ST statement plays the part of a rung.
//!
//! Accesses name the variable and the fields selected in it up to the first subscript or
//! dereference (its access path: `a.b[i].c := x` writes `a.b` and reads `a.b`, `i` and `x`;
//! a partial write reads what it keeps), so that a caller that flattens structures into their
//! fields can resolve a field exactly and one that does not can take the first part;
//! a compound statement (IF, CASE, a loop) is one unit that reads and writes what any of its
//! parts may (its conditions and bounds read, its loop variable written). A call of a function
//! block instance `T1(IN := x, Q => y)` reads `x` and `T1` (its state), writes `T1` and `y`;
//! a function call reads its arguments. Names are reported as written (the caller resolves
//! them against the POU's declarations, case-insensitively as IEC names are).
//!
//! Deliberately not here: executing ST (the PLCopen reader lowers a body to rungs,
//! `crate::plcopen::st_lower`),
//! declarations (a PLCopen file declares variables in the POU's interface), and IL.

pub mod ast;
pub mod lexer;
pub mod parser;

pub use lexer::LexError;
pub use parser::statements;

use ast::*;

/// What a statement reads and writes, and the names it calls, each in order of first mention.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Accesses {
    pub reads: Vec<String>,
    pub writes: Vec<String>,
    /// Functions and function block instances called (an instance is also read and written).
    pub calls: Vec<String>,
    /// The reads that only stand for the rest of a variable a field write keeps
    /// (`s.f := 1` reads `s.f` as a part of `s`): where `s.f` is a variable of its own (a
    /// flattened structure's field), the write is whole and this read is not one.
    pub kept: Vec<String>,
    /// The statement holds a pragma (C code that may read and write anything of the POU).
    pub pragma: bool,
}

impl Accesses {
    fn read(&mut self, name: &str) {
        push_once(&mut self.reads, name);
        self.kept.retain(|k| !k.eq_ignore_ascii_case(name));
    }
    /// A read of what a write of part of `name` keeps.
    fn read_kept(&mut self, name: &str) {
        if !self.reads.iter().any(|n| n.eq_ignore_ascii_case(name)) {
            self.reads.push(name.to_owned());
            push_once(&mut self.kept, name);
        }
    }
    fn write(&mut self, name: &str) {
        push_once(&mut self.writes, name);
    }
}

fn push_once(v: &mut Vec<String>, name: &str) {
    if !v.iter().any(|n| n.eq_ignore_ascii_case(name)) {
        v.push(name.to_owned());
    }
}

/// What `s` (and every statement inside it) reads and writes.
pub fn accesses(s: &Statement) -> Accesses {
    let mut a = Accesses::default();
    statement(s, &mut a);
    a
}

fn statement(s: &Statement, a: &mut Accesses) {
    match &s.kind {
        Stmt::Assign { target, value } => {
            expr(value, a);
            write_place(target, a);
        }
        Stmt::Call { callee, args } => call(callee, args, a, true),
        Stmt::If { arms, otherwise } => {
            for (cond, body) in arms {
                expr(cond, a);
                body.iter().for_each(|s| statement(s, a));
            }
            otherwise.iter().for_each(|s| statement(s, a));
        }
        Stmt::Case {
            selector,
            arms,
            otherwise,
        } => {
            expr(selector, a);
            for (labels, body) in arms {
                for l in labels {
                    match l {
                        CaseLabel::One(e) => expr(e, a),
                        CaseLabel::Range(x, y) => {
                            expr(x, a);
                            expr(y, a);
                        }
                    }
                }
                body.iter().for_each(|s| statement(s, a));
            }
            otherwise.iter().for_each(|s| statement(s, a));
        }
        Stmt::For {
            var,
            from,
            to,
            by,
            body,
        } => {
            expr(from, a);
            expr(to, a);
            if let Some(by) = by {
                expr(by, a);
            }
            write_place(var, a);
            read_place(var, a);
            body.iter().for_each(|s| statement(s, a));
        }
        Stmt::While { cond, body } => {
            expr(cond, a);
            body.iter().for_each(|s| statement(s, a));
        }
        Stmt::Repeat { body, until } => {
            body.iter().for_each(|s| statement(s, a));
            expr(until, a);
        }
        Stmt::Exit | Stmt::Continue | Stmt::Return | Stmt::Empty => {}
        Stmt::Pragma { .. } => a.pragma = true,
    }
}

/// A call: the arguments' reads, the outputs' writes; a statement call of an instance also reads
/// and writes the instance (its state).
fn call(callee: &Place, args: &[Arg], a: &mut Accesses, statement: bool) {
    push_once(&mut a.calls, &callee.base);
    for arg in args {
        match arg {
            Arg::Input { value, .. } => expr(value, a),
            Arg::Output { target, .. } => write_place(target, a),
        }
    }
    if statement {
        a.read(&callee.base);
        a.write(&callee.base);
    }
}

fn indices(p: &Place, a: &mut Accesses) {
    for s in &p.selectors {
        if let Selector::Index(es) = s {
            es.iter().for_each(|e| expr(e, a));
        }
    }
}

/// `p`'s access path: its base and the fields selected before any dereference or subscript
/// that is not constant; a constant subscript (integer literals and `+ - *` of them, IEC
/// 61131-3 6.4.4.5) is kept as the element's name (`a[3]`, `m[1,-2]`, a variable of its own
/// where the reader scalarises the array), and ends the path.
fn path(p: &Place) -> String {
    let mut out = p.base.clone();
    for s in &p.selectors {
        match s {
            Selector::Field(f) => {
                out.push('.');
                out.push_str(f);
            }
            Selector::Index(es) => {
                if let Some(k) = es.iter().map(constant).collect::<Option<Vec<i64>>>() {
                    let k: Vec<String> = k.iter().map(|i| i.to_string()).collect();
                    out.push('[');
                    out.push_str(&k.join(","));
                    out.push(']');
                }
                break;
            }
            Selector::Deref => break,
        }
    }
    out
}

/// Whether `p` is a whole path: fields and constant subscripts only (a write of it writes that
/// variable whole).
fn exact(p: &Place) -> bool {
    p.selectors.iter().enumerate().all(|(i, s)| match s {
        Selector::Field(_) => true,
        Selector::Index(es) => {
            i + 1 == p.selectors.len() && es.iter().all(|e| constant(e).is_some())
        }
        Selector::Deref => false,
    })
}

/// The value of constant integer expression `e` (integer literals, unary `-` and `+`, `+ - *`
/// of them), `None` when it is not one.
pub fn constant(e: &Expr) -> Option<i64> {
    match e {
        Expr::Literal(s) => {
            let t = s.replace('_', "");
            let t = [
                "INT#", "DINT#", "SINT#", "LINT#", "UINT#", "UDINT#", "USINT#", "ULINT#",
            ]
            .iter()
            .find_map(|p| {
                t.get(..p.len())
                    .filter(|h| h.eq_ignore_ascii_case(p))
                    .map(|_| t[p.len()..].to_owned())
            })
            .unwrap_or(t);
            if let Some((radix, digits)) = t.split_once('#') {
                let r = match radix {
                    "2" => 2,
                    "8" => 8,
                    "16" => 16,
                    _ => return None,
                };
                return i64::from_str_radix(digits, r).ok();
            }
            t.parse().ok()
        }
        Expr::Unary(UnaryOp::Neg, x) => constant(x)?.checked_neg(),
        Expr::Unary(UnaryOp::Plus, x) => constant(x),
        Expr::Binary(op, a, b) => {
            let (a, b) = (constant(a)?, constant(b)?);
            match op {
                BinaryOp::Add => a.checked_add(b),
                BinaryOp::Sub => a.checked_sub(b),
                BinaryOp::Mul => a.checked_mul(b),
                _ => None,
            }
        }
        _ => None,
    }
}

fn read_place(p: &Place, a: &mut Accesses) {
    indices(p, a);
    a.read(&path(p));
}

fn write_place(p: &Place, a: &mut Accesses) {
    indices(p, a);
    // Writing through a pointer reads the pointer; writing a part of a variable keeps the rest
    // (a field path names the part when the selectors are fields only).
    let whole = path(p);
    if !exact(p) {
        a.read(&whole);
    } else if !p.selectors.is_empty() {
        a.read_kept(&whole);
    }
    a.write(&whole);
}

fn expr(e: &Expr, a: &mut Accesses) {
    match e {
        Expr::Literal(_) => {}
        Expr::Var(p) => read_place(p, a),
        Expr::Unary(_, x) => expr(x, a),
        Expr::Binary(_, x, y) => {
            expr(x, a);
            expr(y, a);
        }
        Expr::Call { callee, args } => call(callee, args, a, false),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn of(text: &str) -> Vec<Accesses> {
        statements(text).unwrap().iter().map(accesses).collect()
    }

    fn names(v: &[&str]) -> Vec<String> {
        v.iter().map(|s| s.to_string()).collect()
    }

    #[test]
    fn each_statement_reads_and_writes_exactly_its_variables() {
        let a = of("
            x := a + b * c;
            IF start AND NOT stop THEN run := TRUE; ELSIF reset THEN count := 0; END_IF;
            T1(IN := run, PT := T#5s, Q => done);
            FOR i := lo TO hi DO arr[i] := arr[i] + 1; END_FOR;
            y := MAX(a, LIMIT(0, z, 10));
            cfg.speed := 3;");
        assert_eq!(a[0].reads, names(&["a", "b", "c"]));
        assert_eq!(a[0].writes, names(&["x"]));
        assert_eq!(a[1].reads, names(&["start", "stop", "reset"]));
        assert_eq!(a[1].writes, names(&["run", "count"]));
        assert_eq!(a[2].reads, names(&["run", "T1"]));
        assert_eq!(a[2].writes, names(&["done", "T1"]));
        assert_eq!(a[2].calls, names(&["T1"]));
        assert_eq!(a[3].reads, names(&["lo", "hi", "i", "arr"]));
        assert_eq!(a[3].writes, names(&["i", "arr"]));
        assert_eq!(a[4].reads, names(&["a", "z"]));
        assert_eq!(a[4].writes, names(&["y"]));
        assert_eq!(a[4].calls, names(&["MAX", "LIMIT"]));
        assert_eq!(a[5].reads, names(&["cfg.speed"]));
        assert_eq!(a[5].writes, names(&["cfg.speed"]));
        assert_eq!(a[5].kept, names(&["cfg.speed"]));
    }

    #[test]
    fn names_are_reported_once_whatever_their_case() {
        let a = of("X := x + X;");
        assert_eq!(a[0].reads, names(&["x"]));
        assert_eq!(a[0].writes, names(&["X"]));
    }
}
