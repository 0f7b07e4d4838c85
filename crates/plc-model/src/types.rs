//! Elementary IEC 61131-3 types, values and operands of the program model.
//!
//! The elementary types of IEC 61131-3 (2.3.1, table 10) at their declared widths: the signed
//! integers SINT, INT, DINT, LINT (8 to 64 bits), the unsigned USINT, UINT, UDINT, ULINT, the
//! reals REAL and LREAL (IEEE 754 single and double), the bit strings BYTE, WORD, DWORD, LWORD
//! and BOOL. TIME values are held as signed 32-bit milliseconds (CODESYS and S7 `TIME` are 32-bit
//! ms). Which operations accept which types follows the generic types of 2.3.2 ([`Type::is_int`]
//! for ANY_INT, [`Type::is_real`] for ANY_REAL, [`Type::is_bits`] for ANY_BIT): arithmetic on
//! ANY_NUM (ADD and SUB also on TIME, MOD only on ANY_INT), comparisons on every elementary type
//! but BOOL, MOVE on any. A 64-bit constant is held as two 32-bit halves ([`Wide`]) so that a
//! [`Value`] stays 4-byte aligned and 12 bytes, and a model element 32 bytes.
//! Function block types (TON, TOF, TP, CTU, CTD, and the bistables SR, RS, the edge detectors
//! R_TRIG, F_TRIG and the up-down counter CTUD of IEC 61131-3 2.5.2.3) are instance types: a
//! variable of such a type is an instance, and its readable fields are listed by [`Field`].

use super::VarId;
use std::fmt;

/// The IEC type of a variable or operand.
#[derive(Copy, Clone, Debug, PartialEq, Eq, Hash)]
pub enum Type {
    Bool,
    /// 8-bit signed integer.
    Sint,
    /// 16-bit signed integer.
    Int,
    /// 32-bit signed integer.
    Dint,
    /// 64-bit signed integer.
    Lint,
    /// 8-bit unsigned integer.
    Usint,
    /// 16-bit unsigned integer.
    Uint,
    /// 32-bit unsigned integer.
    Udint,
    /// 64-bit unsigned integer.
    Ulint,
    /// 32-bit IEEE 754 float.
    Real,
    /// 64-bit IEEE 754 float.
    Lreal,
    /// 8-bit bit string.
    Byte,
    /// 16-bit bit string.
    Word,
    /// 32-bit bit string.
    Dword,
    /// 64-bit bit string.
    Lword,
    /// Milliseconds, 32-bit signed.
    Time,
    /// A character string of at most [`STR_MAX_LEN`](super::STR_MAX_LEN) bytes (IEC 61131-3
    /// 2.3.1 STRING; matiec's length byte and 126-byte body).
    String,
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
        if let Some(t) = Type::elementary(s) {
            return Some(t);
        }
        Some(match s {
            "TIME" => Type::Time,
            "STRING" => Type::String,
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
    /// The elementary types but TIME, by name: the table [`ELEMENTARY`].
    fn elementary(s: &str) -> Option<Type> {
        ELEMENTARY.iter().find(|(n, _)| *n == s).map(|&(_, t)| t)
    }
    /// The name of an elementary type but TIME.
    fn elementary_name(self) -> Option<&'static str> {
        ELEMENTARY.iter().find(|(_, t)| *t == self).map(|&(n, _)| n)
    }
    /// ANY_SIGNED: SINT, INT, DINT, LINT.
    pub fn is_signed(self) -> bool {
        matches!(self, Type::Sint | Type::Int | Type::Dint | Type::Lint)
    }
    /// ANY_UNSIGNED: USINT, UINT, UDINT, ULINT.
    pub fn is_unsigned(self) -> bool {
        matches!(self, Type::Usint | Type::Uint | Type::Udint | Type::Ulint)
    }
    /// ANY_INT: the signed and unsigned integers.
    pub fn is_int(self) -> bool {
        self.is_signed() || self.is_unsigned()
    }
    /// ANY_REAL: REAL, LREAL.
    pub fn is_real(self) -> bool {
        matches!(self, Type::Real | Type::Lreal)
    }
    /// ANY_BIT but BOOL: BYTE, WORD, DWORD, LWORD.
    pub fn is_bits(self) -> bool {
        matches!(self, Type::Byte | Type::Word | Type::Dword | Type::Lword)
    }
    /// ANY_NUM (the integers and reals) and TIME: the types ADD and SUB accept.
    pub fn is_numeric(self) -> bool {
        self.is_int() || self.is_real() || self == Type::Time
    }
    /// The types a comparison accepts: every elementary type but BOOL (numbers, TIME and the
    /// bit strings, IEC 61131-3 2.5.1.5.4 `ANY_ELEMENTARY`).
    pub fn is_comparable(self) -> bool {
        self.is_numeric() || self.is_bits() || self == Type::String
    }
    /// The width in bits of an integer, real or bit-string type (TIME 32; BOOL 1).
    pub fn bits(self) -> u32 {
        match self {
            Type::Bool => 1,
            Type::Sint | Type::Usint | Type::Byte => 8,
            Type::Int | Type::Uint | Type::Word => 16,
            Type::Dint | Type::Udint | Type::Dword | Type::Real | Type::Time => 32,
            Type::Lint | Type::Ulint | Type::Lword | Type::Lreal => 64,
            Type::String | Type::Fb(_) => 0,
        }
    }
    /// The zero value (FALSE, 0, 0.0, T#0ms); instances have no scalar value.
    pub fn zero(self) -> Value {
        Value::from_bits(self, 0)
    }
}

/// The types [`Type::is_comparable`] accepts, for messages.
pub const COMPARABLE: &str = "a number, TIME, bit string or STRING (not BOOL)";

/// The elementary types but TIME, with their IEC names.
pub const ELEMENTARY: [(&str, Type); 15] = [
    ("BOOL", Type::Bool),
    ("SINT", Type::Sint),
    ("INT", Type::Int),
    ("DINT", Type::Dint),
    ("LINT", Type::Lint),
    ("USINT", Type::Usint),
    ("UINT", Type::Uint),
    ("UDINT", Type::Udint),
    ("ULINT", Type::Ulint),
    ("REAL", Type::Real),
    ("LREAL", Type::Lreal),
    ("BYTE", Type::Byte),
    ("WORD", Type::Word),
    ("DWORD", Type::Dword),
    ("LWORD", Type::Lword),
];

impl fmt::Display for Type {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        if let Some(name) = self.elementary_name() {
            return f.write_str(name);
        }
        f.write_str(match self {
            Type::Time => "TIME",
            Type::String => "STRING",
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
            _ => unreachable!("elementary types are named by ELEMENTARY"),
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

/// 64 bits held as two 32-bit halves (low first), so that a [`Value`] holding one is 4-byte
/// aligned: a `u64` would make every model element 8 bytes larger.
#[derive(Copy, Clone, Debug, PartialEq, Eq, Hash)]
pub struct Wide([u32; 2]);

impl Wide {
    pub fn new(bits: u64) -> Wide {
        Wide([bits as u32, (bits >> 32) as u32])
    }
    pub fn bits(self) -> u64 {
        self.0[0] as u64 | (self.0[1] as u64) << 32
    }
}

/// A constant value.
#[derive(Copy, Clone, Debug, PartialEq)]
pub enum Value {
    Bool(bool),
    Sint(i8),
    Int(i16),
    Dint(i32),
    /// LINT, as its two's complement bits.
    Lint(Wide),
    Usint(u8),
    Uint(u16),
    Udint(u32),
    Ulint(Wide),
    Real(f32),
    /// LREAL, as its IEEE 754 bits.
    Lreal(Wide),
    Byte(u8),
    Word(u16),
    Dword(u32),
    Lword(Wide),
    /// Milliseconds.
    Time(i32),
    /// A STRING constant, interned ([`intern`](super::intern)).
    Str(super::StrId),
}

impl Value {
    pub fn ty(self) -> Type {
        match self {
            Value::Bool(_) => Type::Bool,
            Value::Sint(_) => Type::Sint,
            Value::Int(_) => Type::Int,
            Value::Dint(_) => Type::Dint,
            Value::Lint(_) => Type::Lint,
            Value::Usint(_) => Type::Usint,
            Value::Uint(_) => Type::Uint,
            Value::Udint(_) => Type::Udint,
            Value::Ulint(_) => Type::Ulint,
            Value::Real(_) => Type::Real,
            Value::Lreal(_) => Type::Lreal,
            Value::Byte(_) => Type::Byte,
            Value::Word(_) => Type::Word,
            Value::Dword(_) => Type::Dword,
            Value::Lword(_) => Type::Lword,
            Value::Time(_) => Type::Time,
            Value::Str(_) => Type::String,
        }
    }

    /// The stored bits, zero-extended to 64 (a signed value's two's complement bits of its
    /// width; a real's IEEE bits).
    pub fn to_bits(self) -> u64 {
        match self {
            Value::Bool(b) => b as u64,
            Value::Sint(v) => v as u8 as u64,
            Value::Int(v) => v as u16 as u64,
            Value::Dint(v) | Value::Time(v) => v as u32 as u64,
            Value::Usint(v) | Value::Byte(v) => v as u64,
            Value::Uint(v) | Value::Word(v) => v as u64,
            Value::Udint(v) | Value::Dword(v) => v as u64,
            Value::Real(v) => v.to_bits() as u64,
            Value::Lint(w) | Value::Ulint(w) | Value::Lreal(w) | Value::Lword(w) => w.bits(),
            // The interned id: equal strings have equal ids, the empty string 0.
            Value::Str(id) => id.0 as u64,
        }
    }

    /// The value of type `ty` whose stored bits are the low bits of `bits` (the inverse of
    /// [`to_bits`](Self::to_bits)); an instance type gives `Time(0)`.
    pub fn from_bits(ty: Type, bits: u64) -> Value {
        match ty {
            Type::Bool => Value::Bool(bits & 1 != 0),
            Type::Sint => Value::Sint(bits as i8),
            Type::Int => Value::Int(bits as i16),
            Type::Dint => Value::Dint(bits as i32),
            Type::Lint => Value::Lint(Wide::new(bits)),
            Type::Usint => Value::Usint(bits as u8),
            Type::Uint => Value::Uint(bits as u16),
            Type::Udint => Value::Udint(bits as u32),
            Type::Ulint => Value::Ulint(Wide::new(bits)),
            Type::Real => Value::Real(f32::from_bits(bits as u32)),
            Type::Lreal => Value::Lreal(Wide::new(bits)),
            Type::Byte => Value::Byte(bits as u8),
            Type::Word => Value::Word(bits as u16),
            Type::Dword => Value::Dword(bits as u32),
            Type::Lword => Value::Lword(Wide::new(bits)),
            Type::Time => Value::Time(bits as i32),
            Type::String => Value::Str(super::StrId(bits as u32)),
            Type::Fb(_) => Value::Time(0),
        }
    }

    /// An integer value (signed, unsigned, bit string, TIME ms) widened exactly; `None` for
    /// BOOL and the reals.
    pub fn as_i128(self) -> Option<i128> {
        let bits = self.to_bits();
        let ty = self.ty();
        match ty {
            Type::Bool | Type::Real | Type::Lreal | Type::String | Type::Fb(_) => None,
            t if t.is_signed() || t == Type::Time => {
                let shift = 64 - t.bits();
                Some((((bits << shift) as i64) >> shift) as i128)
            }
            _ => Some(bits as i128),
        }
    }

    /// A real value as `f64` (REAL widened exactly); `None` for other types.
    pub fn as_f64(self) -> Option<f64> {
        match self {
            Value::Real(v) => Some(v as f64),
            Value::Lreal(w) => Some(f64::from_bits(w.bits())),
            _ => None,
        }
    }

    /// The integer `v` as a value of the integer, bit-string or TIME type `ty`, if it is in
    /// that type's range.
    pub fn int_of(ty: Type, v: i128) -> Option<Value> {
        let is_int = ty.is_int() || ty.is_bits() || ty == Type::Time;
        let (lo, hi) = int_range(ty);
        (is_int && (lo..=hi).contains(&v)).then(|| Value::from_bits(ty, v as u64))
    }
}

impl fmt::Display for Value {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Value::Bool(b) => write!(f, "{}", if *b { "TRUE" } else { "FALSE" }),
            Value::Real(v) => write!(f, "{v:?}"),
            Value::Lreal(w) => write!(f, "{:?}", f64::from_bits(w.bits())),
            Value::Time(ms) => write!(f, "T#{ms}ms"),
            Value::Str(id) => f.write_str(&super::string_literal(super::str_bytes(*id))),
            v => write!(f, "{}", v.as_i128().unwrap_or(0)),
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
    /// Whether the operation takes operands of type `ty` (IEC 61131-3 2.5.1.5.2): ADD and SUB
    /// ANY_NUM and TIME, MUL and DIV ANY_NUM, MOD ANY_INT. Never the bit strings (ANY_BIT).
    pub fn accepts(self, ty: Type) -> bool {
        match self {
            ArithOp::Add | ArithOp::Sub => ty.is_numeric(),
            ArithOp::Mul | ArithOp::Div => ty.is_int() || ty.is_real(),
            ArithOp::Mod => ty.is_int(),
        }
    }
    /// The types [`accepts`](Self::accepts) takes, for messages.
    pub fn expected(self) -> &'static str {
        match self {
            ArithOp::Add | ArithOp::Sub => "a number or TIME",
            ArithOp::Mul | ArithOp::Div => "a number (an integer or a real)",
            ArithOp::Mod => "an integer",
        }
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

/// "an" or "a" before a type's name, as the names are spoken ("an INT", "a UINT").
fn article(ty: Type) -> &'static str {
    if matches!(ty, Type::Int | Type::Lint | Type::Lword) {
        "an"
    } else {
        "a"
    }
}

/// What a cell of an integer or bit string type must be, as errors say it: `an INT
/// (-32768..32767)`, `a BYTE (0..255)` (the C harness prints the same, generated from this).
pub fn integer_cell(ty: Type) -> String {
    let (lo, hi) = int_range(ty);
    format!("{} {ty} ({lo}..{hi})", article(ty))
}

/// The range of an integer, bit-string or TIME type (two's complement for the signed types and
/// TIME, `0..2^n - 1` for the others); `(0, 0)` for other types.
pub fn int_range(ty: Type) -> (i128, i128) {
    let n = ty.bits();
    if ty.is_signed() || ty == Type::Time {
        (-(1i128 << (n - 1)), (1i128 << (n - 1)) - 1)
    } else if ty.is_unsigned() || ty.is_bits() {
        (0, (1i128 << n) - 1)
    } else {
        (0, 0)
    }
}

/// Parses an IEC integer literal (IEC 61131-3 2.2.1): decimal with an optional sign (`-5`,
/// `1_000`), or based, unsigned (`2#1010`, `8#17`, `16#FF`); `_` separates digits. `None` when
/// the text is not one or its value is beyond ±2^100 (no IEC type holds it anyway).
pub fn parse_int_literal(s: &str) -> Option<i128> {
    let (neg, body) = match s.as_bytes().first()? {
        b'-' => (true, &s[1..]),
        b'+' => (false, &s[1..]),
        _ => (false, s),
    };
    let (radix, digits) = match body.split_once('#') {
        Some(("2", d)) if !neg => (2, d),
        Some(("8", d)) if !neg => (8, d),
        Some(("16", d)) if !neg => (16, d),
        Some(_) => return None,
        None => (10, body),
    };
    if digits.is_empty()
        || digits.starts_with('_')
        || digits.ends_with('_')
        || digits.contains("__")
    {
        return None;
    }
    let mut v: i128 = 0;
    for c in digits.chars().filter(|&c| c != '_') {
        v = v.checked_mul(radix)? + c.to_digit(radix as u32)? as i128;
        if v > 1 << 100 {
            return None;
        }
    }
    Some(if neg { -v } else { v })
}

/// Splits a typed literal `TYPE#rest` (`UINT#5`, `WORD#16#FF`, `LREAL#1.5`) into its
/// elementary type and the rest; `None` when the text does not start with an elementary type
/// name (other than TIME, whose literals are [`parse_time_literal`]'s) and `#`.
pub fn split_typed_literal(s: &str) -> Option<(Type, &str)> {
    let (name, rest) = s.split_once('#')?;
    let ty = Type::elementary(&name.to_ascii_uppercase())?;
    Some((ty, rest))
}

/// Strips the first of `prefixes` (each ending in `#`) that `s` starts with, in any case
/// (IEC 61131-3 keywords are case-insensitive: `T#`, `t#`, `Time#`).
fn strip_prefix_ci<'s>(s: &'s str, prefixes: &[&str]) -> Option<&'s str> {
    prefixes.iter().find_map(|p| {
        let head = s.get(..p.len())?;
        head.eq_ignore_ascii_case(p).then(|| &s[p.len()..])
    })
}

/// True when an operand string is a TIME literal (`T#…`, `TIME#…`, LTIME's `LT#…`, `LTIME#…`,
/// any case) rather than a name,
/// as the operand syntax of docs/format.md tells them apart.
pub fn is_time_literal(s: &str) -> bool {
    let b = s.as_bytes();
    let starts = |p: &[u8]| b.len() >= p.len() && b[..p.len()].eq_ignore_ascii_case(p);
    starts(b"T#") || starts(b"TIME#") || starts(b"LT#") || starts(b"LTIME#")
}

/// Parses an IEC TIME literal (`T#1s`, `T#250ms`, `TIME#1m30s`, `T#1.5s`, `T#1h_30m`,
/// `LTIME#5s`) into milliseconds.
///
/// The grammar is IEC 61131-3 6.3.3 Table 8 (as matiec's `iec_flex.ll` reads it): a prefix
/// `T#`, `TIME#`, `LT#` or `LTIME#` in any case, an optional sign, then one or more
/// `number unit` parts, each unit `d`, `h`, `m`, `s`, `ms`, `us` or `ns` (any case), the number
/// decimal with `_` between digits and an optional fraction; one `_` may separate a unit from
/// the next part (`T#0D_0H_0M_0S_1MS`). LTIME is read as TIME (docs/plcopen.md).
///
/// `None` for exactly two reasons: the text is not a TIME literal, or its value is not a whole
/// number of milliseconds (`T#0.5ms`, `T#1.0005s`, `T#1us`): TIME counts milliseconds, and a
/// fraction would be lost silently. (IEC 61131-3 allows finer literals; this executor does
/// not.) The arithmetic is exact (decimal digits, not floating point); a value beyond the `i64`
/// range saturates, so callers check the range they need.
pub fn parse_time_literal(s: &str) -> Option<i64> {
    let rest = strip_prefix_ci(s, &["T#", "TIME#", "LT#", "LTIME#"])?;
    let (neg, mut rest) = match rest.as_bytes().first() {
        Some(b'-') => (true, &rest[1..]),
        Some(b'+') => (false, &rest[1..]),
        _ => (false, rest),
    };
    if rest.is_empty() {
        return None;
    }
    // The value in units of 10^-FRAC ns; more fractional digits than FRAC can never add up to
    // whole milliseconds (a unit is at most 2^10 · 3^3 · 5^5 ms), so they are refused.
    const FRAC: u32 = 12;
    let mut total: i128 = 0;
    let mut saturated = false;
    while !rest.is_empty() {
        let num_len = rest
            .find(|c: char| !(c.is_ascii_digit() || c == '.' || c == '_'))
            .unwrap_or(rest.len());
        let raw = &rest[..num_len];
        if raw.starts_with('_') || raw.ends_with('_') || raw.contains("__") {
            return None;
        }
        let number = raw.replace('_', "");
        rest = &rest[num_len..];
        if number.matches('.').count() > 1 || !number.bytes().any(|b| b.is_ascii_digit()) {
            return None;
        }
        let (int, frac) = number.split_once('.').unwrap_or((&number, ""));
        let frac = frac.trim_end_matches('0');
        let unit_len = rest
            .find(|c: char| !c.is_ascii_alphabetic())
            .unwrap_or(rest.len());
        let factor: i128 = match rest[..unit_len].to_ascii_lowercase().as_str() {
            "d" => 86_400_000_000_000,
            "h" => 3_600_000_000_000,
            "m" => 60_000_000_000,
            "s" => 1_000_000_000,
            "ms" => 1_000_000,
            "us" => 1000,
            "ns" => 1,
            _ => return None,
        };
        rest = &rest[unit_len..];
        // One `_` between a unit and the next part (IEC 61131-3 Table 8, `T#25h_15m`).
        if let Some(r) = rest.strip_prefix('_') {
            if r.is_empty() {
                return None;
            }
            rest = r;
        }
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
    let unit = 10i128.pow(FRAC) * 1_000_000;
    if saturated {
        return Some(if neg { i64::MIN } else { i64::MAX });
    }
    if total % unit != 0 {
        return None;
    }
    let ms = i64::try_from(total / unit).unwrap_or(i64::MAX);
    Some(if neg { -ms } else { ms })
}

/// The kinds of the IEC 61131-3 date and time-of-day literals (6.3.4, Table 9).
#[derive(Copy, Clone, Debug, PartialEq, Eq)]
pub enum DateKind {
    /// `D#`, `DATE#` (and `LD#`, `LDATE#`): seconds since 1970-01-01.
    Date,
    /// `TOD#`, `TIME_OF_DAY#` (and `LTOD#`, `LTIME_OF_DAY#`): milliseconds since midnight.
    TimeOfDay,
    /// `DT#`, `DATE_AND_TIME#` (and `LDT#`, `LDATE_AND_TIME#`): seconds since 1970-01-01.
    DateAndTime,
}

/// Days from 1970-01-01 to the proleptic Gregorian date `y-m-d` (H. Hinnant's
/// `days_from_civil`); `None` when the month or day does not exist.
fn days_from_civil(y: i64, m: i64, d: i64) -> Option<i64> {
    let leap = (y % 4 == 0 && y % 100 != 0) || y % 400 == 0;
    let len = [
        31,
        if leap { 29 } else { 28 },
        31,
        30,
        31,
        30,
        31,
        31,
        30,
        31,
        30,
        31,
    ];
    if !(1..=12).contains(&m) || d < 1 || d > len[(m - 1) as usize] {
        return None;
    }
    let y = if m <= 2 { y - 1 } else { y };
    let era = y.div_euclid(400);
    let yoe = y - era * 400;
    let mp = (m + 9) % 12;
    let doy = (153 * mp + 2) / 5 + d - 1;
    let doe = yoe * 365 + yoe / 4 - yoe / 100 + doy;
    Some(era * 146_097 + doe - 719_468)
}

/// `yyyy-mm-dd` as days since 1970-01-01.
fn date_days(s: &str) -> Option<i64> {
    let mut it = s.split('-');
    let num = |p: Option<&str>| -> Option<i64> {
        let p = p?.replace('_', "");
        (!p.is_empty() && p.bytes().all(|b| b.is_ascii_digit())).then_some(())?;
        p.parse().ok()
    };
    let (y, m, d) = (num(it.next())?, num(it.next())?, num(it.next())?);
    if it.next().is_some() {
        return None;
    }
    days_from_civil(y, m, d)
}

/// `hh:mm:ss[.fff]` as milliseconds since midnight; `None` unless a whole number of ms.
fn daytime_ms(s: &str) -> Option<i64> {
    let mut it = s.split(':');
    let (h, m, sec) = (it.next()?, it.next()?, it.next()?);
    if it.next().is_some() {
        return None;
    }
    let int = |p: &str| -> Option<i64> {
        (!p.is_empty() && p.bytes().all(|b| b.is_ascii_digit())).then_some(())?;
        p.parse().ok()
    };
    let (h, m) = (int(h)?, int(m)?);
    let (si, sf) = sec.split_once('.').unwrap_or((sec, ""));
    let si = int(si)?;
    let sf = sf.trim_end_matches('0');
    if sf.len() > 3 || !sf.bytes().all(|b| b.is_ascii_digit()) {
        return None;
    }
    let frac_ms: i64 = format!("{sf:0<3}").parse().ok()?;
    if h > 23 || m > 59 || si > 59 {
        return None;
    }
    Some(((h * 60 + m) * 60 + si) * 1000 + frac_ms)
}

/// Parses an IEC date, time-of-day or date-and-time literal (IEC 61131-3 6.3.4, Table 9:
/// `D#2024-01-31`, `TOD#12:30:15.5`, `DT#2024-01-31-12:30:00`, any prefix in any case) into
/// the integer the model holds for it: seconds since 1970-01-01 for a DATE (matiec's
/// `__date_to_timespec` `tv_sec`) and a DATE_AND_TIME (its `__dt_to_timespec` `tv_sec`),
/// milliseconds since midnight for a TIME_OF_DAY (CODESYS's TOD). `None` when the text is not
/// one, names a day or time that does not exist, or (DT, TOD) has a fraction finer than its
/// unit: it would be lost silently.
pub fn parse_date_literal(s: &str) -> Option<(DateKind, i64)> {
    if let Some(r) = strip_prefix_ci(s, &["DATE_AND_TIME#", "DT#", "LDATE_AND_TIME#", "LDT#"]) {
        // The date's three parts, then the daytime.
        let mut cut = 0;
        for _ in 0..3 {
            cut += r[cut..].find('-')? + 1;
        }
        let (date, time) = (&r[..cut - 1], &r[cut..]);
        let ms = daytime_ms(time)?;
        if ms % 1000 != 0 {
            return None;
        }
        return Some((DateKind::DateAndTime, date_days(date)? * 86_400 + ms / 1000));
    }
    if let Some(r) = strip_prefix_ci(s, &["TIME_OF_DAY#", "TOD#", "LTIME_OF_DAY#", "LTOD#"]) {
        return Some((DateKind::TimeOfDay, daytime_ms(r)?));
    }
    if let Some(r) = strip_prefix_ci(s, &["DATE#", "D#", "LDATE#", "LD#"]) {
        return Some((DateKind::Date, date_days(r)? * 86_400));
    }
    None
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
        // `_` between units, any case, LTIME, finer units (IEC 61131-3 Table 8, matiec's lexer).
        assert_eq!(parse_time_literal("T#1h_30m"), Some(5_400_000));
        assert_eq!(parse_time_literal("T#0D_0H_0M_0S_1MS"), Some(1));
        assert_eq!(parse_time_literal("Time#1s"), Some(1000));
        assert_eq!(parse_time_literal("LTIME#1d_2h"), Some(93_600_000));
        assert_eq!(parse_time_literal("lt#+3s"), Some(3000));
        assert_eq!(parse_time_literal("T#1500us"), None, "1.5 ms");
        assert_eq!(parse_time_literal("T#2000us_3000000ns"), Some(5));
        assert_eq!(parse_time_literal("T#100ms_"), None);
        assert_eq!(parse_time_literal("T#1h__30m"), None);
        assert_eq!(parse_time_literal("T#1h_"), None);
    }

    #[test]
    fn date_literals() {
        use DateKind::*;
        // 2024-01-31 is 19753 days after 1970-01-01.
        assert_eq!(
            parse_date_literal("D#2024-01-31"),
            Some((Date, 19_753 * 86_400))
        );
        assert_eq!(parse_date_literal("DATE#1970-01-02"), Some((Date, 86_400)));
        assert_eq!(
            parse_date_literal("date#2000-03-01"),
            Some((Date, 11_017 * 86_400))
        );
        assert_eq!(parse_date_literal("D#2023-02-29"), None);
        assert_eq!(
            parse_date_literal("D#2024-02-29"),
            Some((Date, 19_782 * 86_400))
        );
        assert_eq!(
            parse_date_literal("TOD#12:30:15.5"),
            Some((TimeOfDay, 45_015_500))
        );
        assert_eq!(
            parse_date_literal("TIME_OF_DAY#00:00:00"),
            Some((TimeOfDay, 0))
        );
        assert_eq!(parse_date_literal("TOD#24:00:00"), None);
        assert_eq!(parse_date_literal("TOD#1:2:3.0001"), None);
        assert_eq!(
            parse_date_literal("DT#1970-01-01-00:01:00"),
            Some((DateAndTime, 60))
        );
        assert_eq!(
            parse_date_literal("DATE_AND_TIME#2024-01-31-12:00:00"),
            Some((DateAndTime, 19_753 * 86_400 + 43_200))
        );
        assert_eq!(parse_date_literal("DT#1970-01-01-00:00:00.5"), None);
        assert_eq!(parse_date_literal("DT#1970-01-01"), None);
        assert_eq!(parse_date_literal("D#1970-13-01"), None);
        assert_eq!(parse_date_literal("T#1s"), None);
    }
}
