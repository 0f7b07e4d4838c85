//! The IEC 61131-3 standard functions the model calls as one element (`Element::Function`):
//! their names, pins and typing rules (IEC 61131-3 2nd ed., 2.5.1.5: numeric functions of
//! Table 23, EXPT of Table 24, bit shifts of Table 25, MUX of Table 27, type conversions of
//! 2.5.1.5.1 and TRUNC).
//!
//! A function's pins are typed by [`Pin`]: `Generic` pins share the one type `T` of the call
//! (which is also the output's type when the output is `Generic`), `Own` pins have a type of
//! their own (the shift count N, MUX's selector K, EXPT's exponent, a conversion's input). The
//! resolvers (ladder and FBD) give each argument its type with [`Function::types`], so the
//! rule is written once.
//!
//! Not here: what a function computes (`plc_exec::functions`, shared by the interpreter and
//! the C generator's differential tests), nor how a block or box is drawn.

use super::Type;

/// A standard function.
#[derive(Copy, Clone, Debug, PartialEq, Eq, Hash)]
pub enum Function {
    Abs,
    Sqrt,
    Ln,
    Log,
    Exp,
    Sin,
    Cos,
    Tan,
    Asin,
    Acos,
    Atan,
    /// EXPT(IN1, IN2): IN1 ** IN2.
    Expt,
    Shl,
    Shr,
    Rol,
    Ror,
    /// MUX(K, IN0, …, INn): INk (extensible).
    Mux,
    /// AND(IN1, …, INn) of bit strings, bit by bit (extensible; on BOOLs AND is contacts).
    And,
    /// OR(IN1, …, INn) of bit strings, bit by bit (extensible).
    Or,
    /// XOR(IN1, …, INn) of bit strings, bit by bit (extensible).
    Xor,
    /// NOT(IN) of a bit string: every bit inverted.
    Not,
    /// `FROM_TO_TO` (IEC 61131-3 2.5.1.5.1).
    Convert {
        from: Type,
        to: Type,
    },
    /// TRUNC: a REAL to an integer, toward zero.
    Trunc,
    /// CONCAT(IN1, …, INn) of STRINGs (extensible; IEC 61131-3 2.5.1.5.6 Table 29).
    Concat,
    /// LEN(IN): the length of a STRING, as an integer.
    Len,
    /// LEFT(IN, L): the first L characters.
    Left,
    /// RIGHT(IN, L): the last L characters.
    Right,
    /// MID(IN, L, P): L characters from position P (1-based).
    Mid,
    /// INSERT(IN1, IN2, P): IN2 inserted after position P of IN1.
    Insert,
    /// DELETE(IN, L, P): L characters deleted from position P.
    Delete,
    /// REPLACE(IN1, IN2, L, P): L characters of IN1 from position P replaced by IN2.
    Replace,
    /// FIND(IN1, IN2): the position of the first IN2 in IN1 (0: none).
    Find,
}

/// A set of types a pin accepts (the generic types of IEC 61131-3 2.3.2 the model has).
#[derive(Copy, Clone, Debug, PartialEq, Eq)]
pub enum Class {
    /// ANY_NUM: INT, DINT, REAL.
    Num,
    /// ANY_REAL: REAL.
    Real,
    /// ANY_INT: INT, DINT.
    Int,
    /// ANY_BIT as bit patterns: the integer types by their width ([`bit_width`]).
    Bit,
    /// Any elementary type (BOOL, INT, DINT, REAL, TIME).
    Elementary,
    /// Exactly this type.
    Exact(Type),
}

impl Class {
    pub fn accepts(self, t: Type) -> bool {
        match self {
            Class::Num => t.is_int() || t.is_real(),
            Class::Real => t.is_real(),
            Class::Int => t.is_int(),
            Class::Bit => bit_width(t).is_some(),
            Class::Elementary => !matches!(t, Type::Fb(_) | Type::String),
            Class::Exact(x) => t == x,
        }
    }
    /// How messages name the class.
    pub fn text(self) -> String {
        match self {
            Class::Num => "an integer or real type (ANY_NUM)".into(),
            Class::Real => "REAL or LREAL".into(),
            Class::Int => "an integer type (ANY_INT)".into(),
            Class::Bit => "an integer or bit-string type".into(),
            Class::Elementary => "an elementary type".into(),
            Class::Exact(t) => t.to_string(),
        }
    }
    /// The type an untyped number constant takes on such a pin when nothing else fixes it.
    pub fn default_for(self, real_literal: bool) -> Type {
        match self {
            Class::Real => Type::Real,
            Class::Exact(t) => t,
            Class::Num | Class::Elementary if real_literal => Type::Real,
            _ => Type::Dint,
        }
    }
}

/// How a pin is typed.
#[derive(Copy, Clone, Debug, PartialEq, Eq)]
pub enum Pin {
    /// The call's one type `T`, which must be in the class.
    Generic(Class),
    /// A type of its own in the class.
    Own(Class),
}

/// The width of a type read as a bit pattern by SHL, SHR, ROL and ROR: one arm per type.
pub fn bit_width(t: Type) -> Option<u32> {
    (t.is_int() || t.is_bits()).then(|| t.bits())
}

/// Why a call's types do not fit its function: the argument (`None`: the output) and the
/// class it needed.
#[derive(Clone, Debug, PartialEq)]
pub struct Mismatch {
    pub arg: Option<usize>,
    pub expected: String,
    pub found: Type,
}

/// The types of a resolved call.
#[derive(Clone, Debug, PartialEq)]
pub struct Typing {
    pub args: Vec<Type>,
    pub out: Type,
}

impl Function {
    /// The function called `name` (upper case), with the model's type names for conversions.
    pub fn parse(name: &str) -> Option<Function> {
        use Function::*;
        Some(match name {
            "ABS" => Abs,
            "SQRT" => Sqrt,
            "LN" => Ln,
            "LOG" => Log,
            "EXP" => Exp,
            "SIN" => Sin,
            "COS" => Cos,
            "TAN" => Tan,
            "ASIN" => Asin,
            "ACOS" => Acos,
            "ATAN" => Atan,
            "EXPT" => Expt,
            "SHL" => Shl,
            "SHR" => Shr,
            "ROL" => Rol,
            "ROR" => Ror,
            "MUX" => Mux,
            "AND" => And,
            "OR" => Or,
            "XOR" => Xor,
            "NOT" => Not,
            "TRUNC" => Trunc,
            "CONCAT" => Concat,
            "LEN" => Len,
            "LEFT" => Left,
            "RIGHT" => Right,
            "MID" => Mid,
            "INSERT" => Insert,
            "DELETE" => Delete,
            "REPLACE" => Replace,
            "FIND" => Find,
            _ => {
                let (a, b) = name.split_once("_TO_")?;
                let (from, to) = (Type::parse(a)?, Type::parse(b)?);
                if matches!(from, Type::Fb(_)) || matches!(to, Type::Fb(_)) {
                    return None;
                }
                // A STRING converts to and from BOOL, the integers and the bit strings (matiec's
                // `__bool_to_string`, `__sint_to_string`, `__bit_to_string`, `__string_to_sint`
                // …); REAL and TIME texts are not modelled.
                let textual = |t: Type| t == Type::Bool || t.is_int() || t.is_bits();
                if (from == Type::String && !textual(to)) || (to == Type::String && !textual(from))
                {
                    return None;
                }
                Convert { from, to }
            }
        })
    }

    /// The function's name as IEC 61131-3 writes it (`SQRT`, `INT_TO_REAL`).
    pub fn name(self) -> String {
        self.static_name().to_owned()
    }

    /// The name as a `&'static str`.
    pub fn static_name(self) -> &'static str {
        use Function::*;
        match self {
            Abs => "ABS",
            Sqrt => "SQRT",
            Ln => "LN",
            Log => "LOG",
            Exp => "EXP",
            Sin => "SIN",
            Cos => "COS",
            Tan => "TAN",
            Asin => "ASIN",
            Acos => "ACOS",
            Atan => "ATAN",
            Expt => "EXPT",
            Shl => "SHL",
            Shr => "SHR",
            Rol => "ROL",
            Ror => "ROR",
            Mux => "MUX",
            And => "AND",
            Or => "OR",
            Xor => "XOR",
            Not => "NOT",
            Trunc => "TRUNC",
            Concat => "CONCAT",
            Len => "LEN",
            Left => "LEFT",
            Right => "RIGHT",
            Mid => "MID",
            Insert => "INSERT",
            Delete => "DELETE",
            Replace => "REPLACE",
            Find => "FIND",
            Convert { from, to } => conversion_name(from, to),
        }
    }

    /// True for MUX, AND, OR and XOR, whose last input pin repeats (`IN0`, `IN1`, … for MUX;
    /// `IN1`, `IN2`, … for the others).
    pub fn extensible(self) -> bool {
        matches!(
            self,
            Function::Mux | Function::And | Function::Or | Function::Xor | Function::Concat
        )
    }

    /// True when the function reads or writes a STRING (the string functions and the
    /// conversions to and from STRING).
    pub fn is_textual(self) -> bool {
        use Function::*;
        match self {
            Concat | Len | Left | Right | Mid | Insert | Delete | Replace | Find => true,
            Convert { from, to } => from == Type::String || to == Type::String,
            _ => false,
        }
    }

    /// The fixed input pins: names and typing (MUX: K and the first of its repeated inputs).
    pub fn pins(self) -> &'static [(&'static str, Pin)] {
        use Function::*;
        const NUM: &[(&str, Pin)] = &[("IN", Pin::Generic(Class::Num))];
        const REAL: &[(&str, Pin)] = &[("IN", Pin::Generic(Class::Real))];
        const STR: Pin = Pin::Own(Class::Exact(Type::String));
        const INT: Pin = Pin::Own(Class::Int);
        match self {
            Abs => NUM,
            Sqrt | Ln | Log | Exp | Sin | Cos | Tan | Asin | Acos | Atan => REAL,
            Expt => &[
                ("IN1", Pin::Generic(Class::Real)),
                ("IN2", Pin::Own(Class::Num)),
            ],
            Shl | Shr | Rol | Ror => &[
                ("IN", Pin::Generic(Class::Bit)),
                ("N", Pin::Own(Class::Int)),
            ],
            Mux => &[
                ("K", Pin::Own(Class::Int)),
                ("IN0", Pin::Generic(Class::Elementary)),
            ],
            And | Or | Xor => &[
                ("IN1", Pin::Generic(Class::Bit)),
                ("IN2", Pin::Generic(Class::Bit)),
            ],
            Not => &[("IN", Pin::Generic(Class::Bit))],
            Trunc => &[("IN", Pin::Own(Class::Real))],
            // Its `from` is checked by `types` (a pin table is static).
            Convert { .. } => &[("IN", Pin::Own(Class::Elementary))],
            Concat => &[("IN1", STR), ("IN2", STR)],
            Len => &[("IN", STR)],
            Left | Right => &[("IN", STR), ("L", INT)],
            Mid => &[("IN", STR), ("L", INT), ("P", INT)],
            Insert => &[("IN1", STR), ("IN2", STR), ("P", INT)],
            Delete => &[("IN", STR), ("L", INT), ("P", INT)],
            Replace => &[("IN1", STR), ("IN2", STR), ("L", INT), ("P", INT)],
            Find => &[("IN1", STR), ("IN2", STR)],
        }
    }

    /// The input pin names for `n` inputs (MUX: `K, IN0 … IN(n-2)`; AND, OR, XOR:
    /// `IN1 … INn`; the others: their pins).
    pub fn input_names(self, n: usize) -> Vec<String> {
        if self == Function::Mux {
            let k = n.max(3);
            return std::iter::once("K".to_owned())
                .chain((0..k - 1).map(|i| format!("IN{i}")))
                .collect();
        }
        if self.extensible() {
            return (1..=n.max(2)).map(|i| format!("IN{i}")).collect();
        }
        self.pins().iter().map(|(n, _)| n.to_string()).collect()
    }

    /// The number of inputs a call may have.
    pub fn arity_ok(self, n: usize) -> bool {
        match self {
            Function::Mux => n >= 3,
            f if f.extensible() => n >= 2,
            f => n == f.pins().len(),
        }
    }

    /// How the output is typed.
    pub fn out_pin(self) -> Pin {
        match self {
            Function::Trunc => Pin::Own(Class::Int),
            Function::Convert { to, .. } => Pin::Own(Class::Exact(to)),
            Function::Len | Function::Find => Pin::Own(Class::Int),
            f if f.is_textual() => Pin::Own(Class::Exact(Type::String)),
            other => other
                .pins()
                .iter()
                .find_map(|(_, p)| match p {
                    Pin::Generic(_) => Some(*p),
                    Pin::Own(_) => None,
                })
                .unwrap_or(Pin::Own(Class::Elementary)),
        }
    }

    /// The typing of argument `i`.
    pub fn pin(self, i: usize) -> Pin {
        let pins = self.pins();
        match self {
            Function::Convert { from, .. } => Pin::Own(Class::Exact(from)),
            _ => pins[i.min(pins.len() - 1)].1,
        }
    }

    /// The types of a call: `args` gives each argument's own type (`None` for a number
    /// constant, with whether it is a REAL literal), `out` the output variable's type when
    /// there is one. `T` is the first generic argument's type, else the output's (when it is
    /// generic), else the constants' default; an own pin takes its argument's type, else its
    /// class's default; an own output takes `out`, else its class's default.
    pub fn types(
        self,
        args: &[(Option<Type>, bool)],
        out: Option<Type>,
    ) -> Result<Typing, Mismatch> {
        let out_pin = self.out_pin();
        let generic_class = (0..args.len()).find_map(|i| match self.pin(i) {
            Pin::Generic(c) => Some(c),
            Pin::Own(_) => None,
        });
        let t = generic_class.map(|c| {
            (0..args.len())
                .filter(|&i| matches!(self.pin(i), Pin::Generic(_)))
                .find_map(|i| args[i].0)
                .or(match out_pin {
                    Pin::Generic(_) => out,
                    Pin::Own(_) => None,
                })
                .unwrap_or_else(|| {
                    let real = (0..args.len()).any(|i| {
                        matches!(self.pin(i), Pin::Generic(_)) && args[i].1 && args[i].0.is_none()
                    });
                    c.default_for(real)
                })
        });
        let mut types = Vec::with_capacity(args.len());
        for (i, &(own, real)) in args.iter().enumerate() {
            let (ty, class) = match self.pin(i) {
                Pin::Generic(c) => (t.unwrap_or(Type::Dint), c),
                Pin::Own(c) => (own.unwrap_or_else(|| c.default_for(real)), c),
            };
            if !class.accepts(ty) {
                return Err(Mismatch {
                    arg: Some(i),
                    expected: class.text(),
                    found: ty,
                });
            }
            types.push(ty);
        }
        let out_ty = match out_pin {
            Pin::Generic(_) => t.unwrap_or(Type::Dint),
            Pin::Own(c) => out.unwrap_or_else(|| c.default_for(false)),
        };
        let out_class = match out_pin {
            Pin::Generic(c) | Pin::Own(c) => c,
        };
        if !out_class.accepts(out_ty) || out.is_some_and(|o| o != out_ty) {
            return Err(Mismatch {
                arg: None,
                expected: if out_pin == Pin::Own(out_class) {
                    out_class.text()
                } else {
                    out_ty.to_string()
                },
                found: out.unwrap_or(out_ty),
            });
        }
        Ok(Typing {
            args: types,
            out: out_ty,
        })
    }
}

/// `FROM_TO_TO` as a `&'static str`: the names of the conversions among the elementary types,
/// made once (at most 16 × 16 short strings).
fn conversion_name(from: Type, to: Type) -> &'static str {
    use std::collections::HashMap;
    use std::sync::OnceLock;
    static NAMES: OnceLock<HashMap<(Type, Type), &'static str>> = OnceLock::new();
    let names = NAMES.get_or_init(|| {
        let types = || {
            super::ELEMENTARY
                .iter()
                .map(|&(_, t)| t)
                .chain([Type::Time, Type::String])
        };
        types()
            .flat_map(|a| types().map(move |b| (a, b)))
            .map(|(a, b)| {
                let name: &'static str = Box::leak(format!("{a}_TO_{b}").into_boxed_str());
                ((a, b), name)
            })
            .collect()
    });
    names.get(&(from, to)).copied().unwrap_or("TYPE_CONVERSION")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_read_back() {
        for name in [
            "ABS",
            "SQRT",
            "EXPT",
            "SHL",
            "ROR",
            "MUX",
            "TRUNC",
            "INT_TO_REAL",
            "REAL_TO_TIME",
        ] {
            assert_eq!(Function::parse(name).unwrap().name(), name);
        }
        assert_eq!(Function::parse("TON_TO_INT"), None);
        assert_eq!(Function::parse("STRING_TO_REAL"), None);
        assert_eq!(
            Function::parse("STRING_TO_INT").unwrap().name(),
            "STRING_TO_INT"
        );
        assert_eq!(Function::parse("CONCAT").unwrap().name(), "CONCAT");
        // Every elementary type converts to every other, by its IEC name.
        let sint = Function::parse("SINT_TO_ULINT").unwrap();
        assert_eq!(
            sint,
            Function::Convert {
                from: Type::Sint,
                to: Type::Ulint
            }
        );
        assert_eq!(sint.static_name(), "SINT_TO_ULINT");
    }

    #[test]
    fn typing_rules() {
        let r = |f: &str, a: &[(Option<Type>, bool)], o| Function::parse(f).unwrap().types(a, o);
        // SQRT of an INT is refused, naming the argument.
        let e = r("SQRT", &[(Some(Type::Int), false)], Some(Type::Real)).unwrap_err();
        assert_eq!((e.arg, e.expected.as_str()), (Some(0), "REAL or LREAL"));
        // ABS of a constant takes the output's type.
        let t = r("ABS", &[(None, false)], Some(Type::Int)).unwrap();
        assert_eq!((t.args, t.out), (vec![Type::Int], Type::Int));
        // EXPT: REAL base, an INT exponent of its own.
        let t = r(
            "EXPT",
            &[(Some(Type::Real), false), (Some(Type::Int), false)],
            None,
        )
        .unwrap();
        assert_eq!((t.args, t.out), (vec![Type::Real, Type::Int], Type::Real));
        // SHL: the output is IN's type; N a DINT constant.
        let t = r(
            "SHL",
            &[(Some(Type::Int), false), (None, false)],
            Some(Type::Int),
        )
        .unwrap();
        assert_eq!(t.args, vec![Type::Int, Type::Dint]);
        let e = r(
            "SHL",
            &[(Some(Type::Int), false), (None, false)],
            Some(Type::Dint),
        )
        .unwrap_err();
        assert_eq!(e.arg, None);
        // MUX: K of its own, the inputs and the output one type.
        let t = r(
            "MUX",
            &[(None, false), (Some(Type::Time), false), (None, false)],
            None,
        )
        .unwrap();
        assert_eq!(
            (t.args, t.out),
            (vec![Type::Dint, Type::Time, Type::Time], Type::Time)
        );
        // Conversions: the input is exactly FROM, the output exactly TO.
        let e = r("INT_TO_REAL", &[(Some(Type::Dint), false)], None).unwrap_err();
        assert_eq!((e.arg, e.found), (Some(0), Type::Dint));
        let t = r("TRUNC", &[(None, true)], Some(Type::Int)).unwrap();
        assert_eq!((t.args, t.out), (vec![Type::Real], Type::Int));
        let e = r("TRUNC", &[(None, true)], Some(Type::Real)).unwrap_err();
        assert_eq!(
            (e.arg, e.expected.as_str()),
            (None, "an integer type (ANY_INT)")
        );
    }
}
