//! Elementary IEC 61131-3 types, values and operands of the program model.
//!
//! TIME values are held as signed 32-bit milliseconds (CODESYS and S7 `TIME` are 32-bit ms).
//! Function block types (TON, TOF, TP, CTU, CTD, and the bistables SR, RS, the edge detectors
//! R_TRIG, F_TRIG and the up-down counter CTUD of IEC 61131-3 2.5.2.3) are instance types: a
//! variable of such a type is an instance, and its readable fields are listed by [`Field`].

use super::VarId;
use std::fmt;

/// The IEC type of a variable or operand.
#[derive(Copy, Clone, Debug, PartialEq, Eq, Hash)]
pub enum Type {
    Bool,
    /// 16-bit signed integer.
    Int,
    /// 32-bit signed integer.
    Dint,
    /// 32-bit IEEE 754 float.
    Real,
    /// Milliseconds, 32-bit signed.
    Time,
    /// A function block instance.
    Fb(FbKind),
}

/// Standard function block types that can be instantiated.
#[derive(Copy, Clone, Debug, PartialEq, Eq, Hash)]
pub enum FbKind {
    Ton,
    Tof,
    Tp,
    Ctu,
    Ctd,
    /// Set-dominant bistable (S1, R → Q1).
    Sr,
    /// Reset-dominant bistable (S, R1 → Q1).
    Rs,
    /// Rising edge detector (CLK → Q).
    RTrig,
    /// Falling edge detector (CLK → Q).
    FTrig,
    /// Up-down counter (CU, CD, R, LD, PV → QU, QD, CV).
    Ctud,
}

/// The two IEC bistables: which input dominates when both are TRUE.
#[derive(Copy, Clone, Debug, PartialEq, Eq, Hash)]
pub enum BistableKind {
    /// SR: `Q1 := S1 OR (NOT R AND Q1)`.
    SetDominant,
    /// RS: `Q1 := NOT R1 AND (S OR Q1)`.
    ResetDominant,
}

impl BistableKind {
    pub fn fb(self) -> FbKind {
        match self {
            BistableKind::SetDominant => FbKind::Sr,
            BistableKind::ResetDominant => FbKind::Rs,
        }
    }
}

/// The two IEC edge detectors.
#[derive(Copy, Clone, Debug, PartialEq, Eq, Hash)]
pub enum TriggerKind {
    /// R_TRIG: `Q := CLK AND NOT M; M := CLK`.
    Rising,
    /// F_TRIG: `Q := NOT CLK AND NOT M; M := NOT CLK`.
    Falling,
}

impl TriggerKind {
    pub fn fb(self) -> FbKind {
        match self {
            TriggerKind::Rising => FbKind::RTrig,
            TriggerKind::Falling => FbKind::FTrig,
        }
    }
}

/// The three IEC timers.
#[derive(Copy, Clone, Debug, PartialEq, Eq, Hash)]
pub enum TimerKind {
    Ton,
    Tof,
    Tp,
}

impl TimerKind {
    pub fn fb(self) -> FbKind {
        match self {
            TimerKind::Ton => FbKind::Ton,
            TimerKind::Tof => FbKind::Tof,
            TimerKind::Tp => FbKind::Tp,
        }
    }
    pub fn name(self) -> &'static str {
        match self {
            TimerKind::Ton => "ton",
            TimerKind::Tof => "tof",
            TimerKind::Tp => "tp",
        }
    }
}

impl Type {
    /// Parses a type name of the program format.
    pub fn parse(s: &str) -> Option<Type> {
        Some(match s {
            "BOOL" => Type::Bool,
            "INT" => Type::Int,
            "DINT" => Type::Dint,
            "REAL" => Type::Real,
            "TIME" => Type::Time,
            "TON" => Type::Fb(FbKind::Ton),
            "TOF" => Type::Fb(FbKind::Tof),
            "TP" => Type::Fb(FbKind::Tp),
            "CTU" => Type::Fb(FbKind::Ctu),
            "CTD" => Type::Fb(FbKind::Ctd),
            "SR" => Type::Fb(FbKind::Sr),
            "RS" => Type::Fb(FbKind::Rs),
            "R_TRIG" => Type::Fb(FbKind::RTrig),
            "F_TRIG" => Type::Fb(FbKind::FTrig),
            "CTUD" => Type::Fb(FbKind::Ctud),
            _ => return None,
        })
    }
    /// True for INT, DINT, REAL and TIME (the types compare and arithmetic accept).
    pub fn is_numeric(self) -> bool {
        matches!(self, Type::Int | Type::Dint | Type::Real | Type::Time)
    }
    /// The zero value (FALSE, 0, 0.0, T#0ms); instances have no scalar value.
    pub fn zero(self) -> Value {
        match self {
            Type::Bool => Value::Bool(false),
            Type::Int => Value::Int(0),
            Type::Dint => Value::Dint(0),
            Type::Real => Value::Real(0.0),
            Type::Time | Type::Fb(_) => Value::Time(0),
        }
    }
}

impl fmt::Display for Type {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            Type::Bool => "BOOL",
            Type::Int => "INT",
            Type::Dint => "DINT",
            Type::Real => "REAL",
            Type::Time => "TIME",
            Type::Fb(FbKind::Ton) => "TON",
            Type::Fb(FbKind::Tof) => "TOF",
            Type::Fb(FbKind::Tp) => "TP",
            Type::Fb(FbKind::Ctu) => "CTU",
            Type::Fb(FbKind::Ctd) => "CTD",
            Type::Fb(FbKind::Sr) => "SR",
            Type::Fb(FbKind::Rs) => "RS",
            Type::Fb(FbKind::RTrig) => "R_TRIG",
            Type::Fb(FbKind::FTrig) => "F_TRIG",
            Type::Fb(FbKind::Ctud) => "CTUD",
        })
    }
}

/// A readable field of a function block instance.
#[derive(Copy, Clone, Debug, PartialEq, Eq, Hash)]
pub enum Field {
    /// Output (timers, CTU, CTD, R_TRIG, F_TRIG), BOOL.
    Q,
    /// Output of SR and RS, BOOL.
    Q1,
    /// Up output of CTUD (`CV >= PV`), BOOL.
    Qu,
    /// Down output of CTUD (`CV <= 0`), BOOL.
    Qd,
    /// Elapsed time (timers), TIME.
    Et,
    /// Preset time (timers), TIME.
    Pt,
    /// Current value (counters, CTUD), INT.
    Cv,
    /// Preset value (counters, CTUD), INT.
    Pv,
}

impl Field {
    /// The field of `fb` called `name`, with its type.
    pub fn lookup(fb: FbKind, name: &str) -> Option<(Field, Type)> {
        use FbKind::*;
        Some(match (fb, name) {
            (Ton | Tof | Tp | Ctu | Ctd | RTrig | FTrig, "Q") => (Field::Q, Type::Bool),
            (Ton | Tof | Tp, "ET") => (Field::Et, Type::Time),
            (Ton | Tof | Tp, "PT") => (Field::Pt, Type::Time),
            (Ctu | Ctd | Ctud, "CV") => (Field::Cv, Type::Int),
            (Ctu | Ctd | Ctud, "PV") => (Field::Pv, Type::Int),
            (Sr | Rs, "Q1") => (Field::Q1, Type::Bool),
            (Ctud, "QU") => (Field::Qu, Type::Bool),
            (Ctud, "QD") => (Field::Qd, Type::Bool),
            _ => return None,
        })
    }
    pub fn name(self) -> &'static str {
        match self {
            Field::Q => "Q",
            Field::Q1 => "Q1",
            Field::Qu => "QU",
            Field::Qd => "QD",
            Field::Et => "ET",
            Field::Pt => "PT",
            Field::Cv => "CV",
            Field::Pv => "PV",
        }
    }
    /// The readable fields of `fb`, in the order the state shows them.
    pub fn all(fb: FbKind) -> &'static [Field] {
        match fb {
            FbKind::Ton | FbKind::Tof | FbKind::Tp => &[Field::Q, Field::Et, Field::Pt],
            FbKind::Ctu | FbKind::Ctd => &[Field::Q, Field::Cv, Field::Pv],
            FbKind::Sr | FbKind::Rs => &[Field::Q1],
            FbKind::RTrig | FbKind::FTrig => &[Field::Q],
            FbKind::Ctud => &[Field::Qu, Field::Qd, Field::Cv, Field::Pv],
        }
    }
    /// The names of the fields of `fb`, for error messages.
    pub fn names(fb: FbKind) -> &'static str {
        match fb {
            FbKind::Ton | FbKind::Tof | FbKind::Tp => "Q, ET, PT",
            FbKind::Ctu | FbKind::Ctd => "Q, CV, PV",
            FbKind::Sr | FbKind::Rs => "Q1",
            FbKind::RTrig | FbKind::FTrig => "Q",
            FbKind::Ctud => "QU, QD, CV, PV",
        }
    }
}

/// A reference to a variable or to a field of an instance.
#[derive(Copy, Clone, Debug, PartialEq, Eq, Hash)]
pub struct VarRef {
    pub var: VarId,
    pub field: Option<Field>,
}

/// A constant value.
#[derive(Copy, Clone, Debug, PartialEq)]
pub enum Value {
    Bool(bool),
    Int(i16),
    Dint(i32),
    Real(f32),
    /// Milliseconds.
    Time(i32),
}

impl Value {
    pub fn ty(self) -> Type {
        match self {
            Value::Bool(_) => Type::Bool,
            Value::Int(_) => Type::Int,
            Value::Dint(_) => Type::Dint,
            Value::Real(_) => Type::Real,
            Value::Time(_) => Type::Time,
        }
    }
}

impl fmt::Display for Value {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Value::Bool(b) => write!(f, "{}", if *b { "TRUE" } else { "FALSE" }),
            Value::Int(v) => write!(f, "{v}"),
            Value::Dint(v) => write!(f, "{v}"),
            Value::Real(v) => write!(f, "{v:?}"),
            Value::Time(ms) => write!(f, "T#{ms}ms"),
        }
    }
}

/// An operand: a variable (or field) read, or a constant.
#[derive(Copy, Clone, Debug, PartialEq)]
pub enum Operand {
    Var(VarRef),
    Const(Value),
}

impl Operand {
    /// The variable the operand reads, if any.
    pub fn var(&self) -> Option<VarId> {
        match self {
            Operand::Var(r) => Some(r.var),
            Operand::Const(_) => None,
        }
    }
}

/// Comparison operators of the compare contact.
#[derive(Copy, Clone, Debug, PartialEq, Eq, Hash)]
pub enum CmpOp {
    Eq,
    Ne,
    Lt,
    Le,
    Gt,
    Ge,
}

impl CmpOp {
    pub fn parse(s: &str) -> Option<CmpOp> {
        Some(match s {
            "EQ" => CmpOp::Eq,
            "NE" => CmpOp::Ne,
            "LT" => CmpOp::Lt,
            "LE" => CmpOp::Le,
            "GT" => CmpOp::Gt,
            "GE" => CmpOp::Ge,
            _ => return None,
        })
    }
    pub fn name(self) -> &'static str {
        match self {
            CmpOp::Eq => "EQ",
            CmpOp::Ne => "NE",
            CmpOp::Lt => "LT",
            CmpOp::Le => "LE",
            CmpOp::Gt => "GT",
            CmpOp::Ge => "GE",
        }
    }

    /// The operator as IEC 61131-3 writes it in ST and IL (`=`, `<>`, `<`, `<=`, `>`, `>=`).
    pub fn symbol(self) -> &'static str {
        match self {
            CmpOp::Eq => "=",
            CmpOp::Ne => "<>",
            CmpOp::Lt => "<",
            CmpOp::Le => "<=",
            CmpOp::Gt => ">",
            CmpOp::Ge => ">=",
        }
    }

    /// The comparison that is true exactly when this one is false (`<` for `>=`).
    pub fn negated(self) -> CmpOp {
        match self {
            CmpOp::Eq => CmpOp::Ne,
            CmpOp::Ne => CmpOp::Eq,
            CmpOp::Lt => CmpOp::Ge,
            CmpOp::Ge => CmpOp::Lt,
            CmpOp::Gt => CmpOp::Le,
            CmpOp::Le => CmpOp::Gt,
        }
    }
}

/// Arithmetic box operators.
#[derive(Copy, Clone, Debug, PartialEq, Eq, Hash)]
pub enum ArithOp {
    Add,
    Sub,
    Mul,
    Div,
    Mod,
}

impl ArithOp {
    pub fn parse(s: &str) -> Option<ArithOp> {
        Some(match s {
            "ADD" => ArithOp::Add,
            "SUB" => ArithOp::Sub,
            "MUL" => ArithOp::Mul,
            "DIV" => ArithOp::Div,
            "MOD" => ArithOp::Mod,
            _ => return None,
        })
    }
    pub fn name(self) -> &'static str {
        match self {
            ArithOp::Add => "ADD",
            ArithOp::Sub => "SUB",
            ArithOp::Mul => "MUL",
            ArithOp::Div => "DIV",
            ArithOp::Mod => "MOD",
        }
    }
}

/// Parses an IEC TIME literal (`T#1s`, `T#250ms`, `TIME#1m30s`, `T#1.5s`) into milliseconds.
///
/// `None` for exactly two reasons: the text is not a TIME literal, or its value is not a whole
/// number of milliseconds (`T#0.5ms`, `T#1.0005s`): TIME counts milliseconds, and a fraction
/// would be lost silently. (IEC 61131-3 allows finer literals; this executor does not.) The
/// arithmetic is exact (decimal digits, not floating point); a value beyond the `i64` range
/// saturates, so callers check the range they need.
pub fn parse_time_literal(s: &str) -> Option<i64> {
    let rest = s
        .strip_prefix("T#")
        .or_else(|| s.strip_prefix("t#"))
        .or_else(|| s.strip_prefix("TIME#"))
        .or_else(|| s.strip_prefix("time#"))?;
    let (neg, mut rest) = match rest.strip_prefix('-') {
        Some(r) => (true, r),
        None => (false, rest),
    };
    if rest.is_empty() {
        return None;
    }
    // The value in units of 10^-FRAC ms; more fractional digits than FRAC can never add up to
    // whole milliseconds (a unit is at most 2^10 · 3^3 · 5^5 ms), so they are refused.
    const FRAC: u32 = 12;
    let mut total: i128 = 0;
    let mut saturated = false;
    while !rest.is_empty() {
        let num_len = rest
            .find(|c: char| !(c.is_ascii_digit() || c == '.' || c == '_'))
            .unwrap_or(rest.len());
        let number = rest[..num_len].replace('_', "");
        rest = &rest[num_len..];
        if number.matches('.').count() > 1 || !number.bytes().any(|b| b.is_ascii_digit()) {
            return None;
        }
        let (int, frac) = number.split_once('.').unwrap_or((&number, ""));
        let frac = frac.trim_end_matches('0');
        let unit_len = rest
            .find(|c: char| c.is_ascii_digit() || c == '.')
            .unwrap_or(rest.len());
        let factor: i128 = match rest[..unit_len].to_ascii_lowercase().as_str() {
            "d" => 86_400_000,
            "h" => 3_600_000,
            "m" => 60_000,
            "s" => 1000,
            "ms" => 1,
            _ => return None,
        };
        rest = &rest[unit_len..];
        if frac.len() > FRAC as usize {
            return None;
        }
        let digits = format!("{int}{frac}{}", "0".repeat(FRAC as usize - frac.len()));
        let part = digits
            .parse::<i128>()
            .ok()
            .and_then(|d| d.checked_mul(factor));
        match part.and_then(|p| total.checked_add(p)) {
            Some(t) => total = t,
            None => saturated = true,
        }
    }
    let unit = 10i128.pow(FRAC);
    if saturated {
        return Some(if neg { i64::MIN } else { i64::MAX });
    }
    if total % unit != 0 {
        return None;
    }
    let ms = i64::try_from(total / unit).unwrap_or(i64::MAX);
    Some(if neg { -ms } else { ms })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn time_literals() {
        assert_eq!(parse_time_literal("T#1s"), Some(1000));
        assert_eq!(parse_time_literal("T#250ms"), Some(250));
        assert_eq!(parse_time_literal("TIME#1m30s"), Some(90_000));
        assert_eq!(parse_time_literal("T#1.5s"), Some(1500));
        assert_eq!(parse_time_literal("T#-2s"), Some(-2000));
        assert_eq!(parse_time_literal("T#"), None);
        assert_eq!(parse_time_literal("T#5x"), None);
        assert_eq!(parse_time_literal("5s"), None);
        assert_eq!(parse_time_literal("T#0.001s"), Some(1));
        assert_eq!(parse_time_literal("T#1.250_0s"), Some(1250));
        assert_eq!(parse_time_literal("T#0.1s0.2s"), Some(300));
        assert_eq!(parse_time_literal("T#1_000ms"), Some(1000));
        assert_eq!(parse_time_literal("T#.5s"), Some(500));
        assert_eq!(parse_time_literal("T#2.ms"), Some(2));
        assert_eq!(parse_time_literal("T#0.00001d"), Some(864));
        assert_eq!(parse_time_literal("T#0.000001d"), None, "86.4 ms");
        // Not a whole number of milliseconds: refused, never rounded.
        assert_eq!(parse_time_literal("T#0.4ms"), None);
        assert_eq!(parse_time_literal("T#0.5ms"), None);
        assert_eq!(parse_time_literal("T#1.0005s"), None);
        assert_eq!(parse_time_literal("T#0.0000000000001s"), None);
        assert_eq!(parse_time_literal("T#1.2.3s"), None);
        assert_eq!(parse_time_literal("T#.s"), None);
        assert_eq!(parse_time_literal("T#_s"), None);
        assert_eq!(
            parse_time_literal("T#99999999999999999999999999999999999999999d"),
            Some(i64::MAX)
        );
    }
}
