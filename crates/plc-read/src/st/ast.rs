//! The syntax tree of Structured Text statements and expressions (IEC 61131-3, 3rd edition,
//! 7.3.2 expressions, 7.3.3 statements), as written: names are the text of the file, every
//! statement keeps the offset where it starts.

/// A statement and where it starts (a byte offset in the ST text).
#[derive(Clone, Debug, PartialEq)]
pub struct Statement {
    pub at: usize,
    pub kind: Stmt,
}

#[derive(Clone, Debug, PartialEq)]
pub enum Stmt {
    /// `target := value`.
    Assign {
        target: Place,
        value: Expr,
    },
    /// A function block or function call as a statement: `T1(IN := x, Q => y);`.
    Call {
        callee: Place,
        args: Vec<Arg>,
    },
    If {
        /// `IF c THEN …`, then each `ELSIF c THEN …`.
        arms: Vec<(Expr, Vec<Statement>)>,
        otherwise: Vec<Statement>,
    },
    Case {
        selector: Expr,
        arms: Vec<(Vec<CaseLabel>, Vec<Statement>)>,
        otherwise: Vec<Statement>,
    },
    For {
        var: Place,
        from: Expr,
        to: Expr,
        by: Option<Expr>,
        body: Vec<Statement>,
    },
    While {
        cond: Expr,
        body: Vec<Statement>,
    },
    Repeat {
        body: Vec<Statement>,
        until: Expr,
    },
    Exit,
    Continue,
    Return,
    /// `;` alone.
    Empty,
    /// A pragma where a statement may stand (`{ … }`, Beremiz's C code `{{ … }}`), as written:
    /// matiec copies its text into the C it generates, so it may read and write anything.
    Pragma {
        text: String,
    },
}

/// A variable as written: `a`, `a.b[i, j].c`, `%IX0.1`, `p^`.
#[derive(Clone, Debug, PartialEq)]
pub struct Place {
    /// The first name (or the direct address).
    pub base: String,
    pub base_at: usize,
    /// What follows: fields, subscripts (whose expressions are read), dereferences.
    pub selectors: Vec<Selector>,
}

#[derive(Clone, Debug, PartialEq)]
pub enum Selector {
    Field(String),
    Index(Vec<Expr>),
    Deref,
}

/// A call argument: `IN := x` (input), `Q => y` (output, written), `NOT Q => y`, or `x`
/// (positional, an input).
#[derive(Clone, Debug, PartialEq)]
pub enum Arg {
    Input { name: Option<String>, value: Expr },
    Output { name: String, target: Place },
}

#[derive(Clone, Debug, PartialEq)]
pub enum CaseLabel {
    One(Expr),
    Range(Expr, Expr),
}

#[derive(Clone, Debug, PartialEq)]
pub enum Expr {
    /// A literal as written (`5`, `T#1s`, `'text'`, `TRUE`).
    Literal(String),
    Var(Place),
    Unary(UnaryOp, Box<Expr>),
    Binary(BinaryOp, Box<Expr>, Box<Expr>),
    /// A function call (or a function block's output read by calling it, which IEC forbids
    /// but some editors accept): `MAX(a, b)`, `ADD(IN1 := a, IN2 := b)`.
    Call {
        callee: Place,
        args: Vec<Arg>,
    },
}

#[derive(Copy, Clone, Debug, PartialEq, Eq)]
pub enum UnaryOp {
    Not,
    Neg,
    Plus,
}

/// The binary operators, by precedence (7.3.2, Table 71): `**`; `*` `/` `MOD`; `+` `-`;
/// comparisons; `=` `<>`; `AND` `&`; `XOR`; `OR`.
#[derive(Copy, Clone, Debug, PartialEq, Eq)]
pub enum BinaryOp {
    Power,
    Mul,
    Div,
    Mod,
    Add,
    Sub,
    Lt,
    Gt,
    Le,
    Ge,
    Eq,
    Ne,
    And,
    Xor,
    Or,
}

impl BinaryOp {
    /// Binding strength: higher binds tighter.
    pub fn precedence(self) -> u8 {
        use BinaryOp::*;
        match self {
            Power => 7,
            Mul | Div | Mod => 6,
            Add | Sub => 5,
            Lt | Gt | Le | Ge => 4,
            Eq | Ne => 3,
            And => 2,
            Xor => 1,
            Or => 0,
        }
    }
}
