//! Values in state memory, and the values a caller reads back.
//!
//! A scalar is stored in its type's representation ([`Repr`]): BOOL a byte 0 or 1, the
//! integers and bit strings in their width (SINT an `i8`, WORD a `u16`, …), TIME (ms) an `i32`,
//! REAL an `f32`, LREAL an `f64`, native byte order, at an address aligned to its width. This module converts between those bytes and [`Value`]s; it does not place
//! variables (`layout`).

use super::layout::{Repr, CV, ET, PT, PV, Q, QD};
use super::store::{Addr, Store};
use super::strings::{load_str, of_value, store_str, StrBuf};
use plc_model::{FbKind, Type, Value};
use serde::{Serialize, Serializer};
use serde_json::{json, Value as Json};

/// Writes the scalar `v` at `at` in its type's representation.
#[inline]
pub fn store_value<S: Store + ?Sized>(st: &mut S, at: Addr, v: Value) {
    if let Value::Str(_) = v {
        return store_str(st, at, &of_value(v));
    }
    // Every representation is its value's bits in native order: store the low bytes.
    let bits = v.to_bits();
    match Repr::of(v.ty()).map_or(1, Repr::width) {
        1 => st.store(at, bits as u8),
        2 => st.store(at, bits as u16),
        4 => st.store(at, bits as u32),
        _ => st.store(at, bits),
    }
}

/// The scalar of type `ty` stored at `at`. Instance types have no scalar value: for them this
/// reads the instance's Q (use [`Machine::value`](super::Machine::value)); nor has a STRING
/// (its value is no constant): for it this gives the empty string (use [`VarValue::load`]).
#[inline]
pub fn load_value<S: Store + ?Sized>(st: &S, at: Addr, ty: Type) -> Value {
    let Some(repr) = Repr::of(ty) else {
        return Value::Bool(st.load::<u8>(at) != 0);
    };
    let bits = match repr.width() {
        1 => st.load::<u8>(at) as u64,
        2 => st.load::<u16>(at) as u64,
        4 => st.load::<u32>(at) as u64,
        _ => st.load::<u64>(at),
    };
    Value::from_bits(ty, bits)
}

/// The value of a variable as a caller sees it: a scalar, or the readable fields of an instance.
#[derive(Copy, Clone, Debug, PartialEq)]
pub enum VarValue {
    /// A variable of an elementary type.
    Scalar(Value),
    /// A STRING variable.
    Text(StrBuf),
    /// A TON, TOF or TP instance.
    Timer {
        /// Output.
        q: bool,
        /// Elapsed time, ms.
        et: i32,
        /// The preset time of its last evaluation, ms.
        pt: i32,
    },
    /// A CTU or CTD instance.
    Counter {
        /// Output.
        q: bool,
        /// Current value.
        cv: i16,
        /// The preset value of its last evaluation.
        pv: i16,
    },
    /// An SR or RS instance.
    Bistable {
        /// Output.
        q1: bool,
    },
    /// An R_TRIG or F_TRIG instance.
    Trigger {
        /// Output.
        q: bool,
    },
    /// A CTUD instance.
    UpDown {
        /// Up output (`CV >= PV`).
        qu: bool,
        /// Down output (`CV <= 0`).
        qd: bool,
        /// Current value.
        cv: i16,
        /// The preset value of its last evaluation.
        pv: i16,
    },
}

impl VarValue {
    /// Reads the variable of type `ty` stored at `at` in `mem`.
    pub(crate) fn load(ty: Type, mem: &[u8], at: Addr) -> VarValue {
        let q = mem.load::<u8>(at.offset(Q)) != 0;
        match ty {
            Type::Fb(FbKind::Ton | FbKind::Tof | FbKind::Tp) => VarValue::Timer {
                q,
                et: mem.load(at.offset(ET)),
                pt: mem.load(at.offset(PT)),
            },
            Type::Fb(FbKind::Ctu | FbKind::Ctd) => VarValue::Counter {
                q,
                cv: mem.load(at.offset(CV)),
                pv: mem.load(at.offset(PV)),
            },
            Type::Fb(FbKind::Sr | FbKind::Rs) => VarValue::Bistable { q1: q },
            Type::Fb(FbKind::RTrig | FbKind::FTrig) => VarValue::Trigger { q },
            Type::Fb(FbKind::Ctud) => VarValue::UpDown {
                qu: q,
                qd: mem.load::<u8>(at.offset(QD)) != 0,
                cv: mem.load(at.offset(CV)),
                pv: mem.load(at.offset(PV)),
            },
            Type::String => VarValue::Text(load_str(mem, at)),
            scalar => VarValue::Scalar(load_value(mem, at, scalar)),
        }
    }

    /// The scalar value, if this is one.
    pub fn scalar(&self) -> Option<Value> {
        match self {
            VarValue::Scalar(v) => Some(*v),
            _ => None,
        }
    }

    /// The BOOL value, or the Q of an instance (Q1 of a bistable, QU of a CTUD).
    pub fn as_bool(&self) -> Option<bool> {
        match self {
            VarValue::Scalar(Value::Bool(b)) => Some(*b),
            VarValue::Timer { q, .. }
            | VarValue::Counter { q, .. }
            | VarValue::Bistable { q1: q }
            | VarValue::Trigger { q }
            | VarValue::UpDown { qu: q, .. } => Some(*q),
            _ => None,
        }
    }

    /// JSON form: BOOL `true`/`false`; the integers and bit strings exact JSON integers (a
    /// ULINT above 2^53 too: readers that parse JSON numbers as doubles round it); REAL and
    /// LREAL a number (the shortest decimal that reads back as the value; `null` for NaN and
    /// infinities, which JSON cannot hold); TIME milliseconds; a timer
    /// `{"Q", "ET", "PT"}`, a counter `{"Q", "CV", "PV"}`, a bistable `{"Q1"}`, an edge detector
    /// `{"Q"}` and an up-down counter `{"QU", "QD", "CV", "PV"}`; a STRING a JSON string, each
    /// byte one character (Latin-1: ASCII as itself).
    pub fn to_json(&self) -> Json {
        match *self {
            VarValue::Scalar(v) => scalar_json(v),
            VarValue::Text(s) => Json::String(s.text()),
            VarValue::Timer { q, et, pt } => json!({"Q": q, "ET": et, "PT": pt}),
            VarValue::Counter { q, cv, pv } => json!({"Q": q, "CV": cv, "PV": pv}),
            VarValue::Bistable { q1 } => json!({ "Q1": q1 }),
            VarValue::Trigger { q } => json!({ "Q": q }),
            VarValue::UpDown { qu, qd, cv, pv } => {
                json!({"QU": qu, "QD": qd, "CV": cv, "PV": pv})
            }
        }
    }
}

fn scalar_json(v: Value) -> Json {
    match v {
        Value::Bool(b) => Json::Bool(b),
        Value::Real(f) => {
            // The shortest decimal that reads back as this f32 (0.1, not 0.10000000149…).
            let shortest: f64 = format!("{f}").parse().unwrap_or(f64::NAN);
            serde_json::Number::from_f64(shortest)
                .map(Json::Number)
                .unwrap_or(Json::Null)
        }
        Value::Lreal(_) => v
            .as_f64()
            .and_then(serde_json::Number::from_f64)
            .map_or(Json::Null, Json::Number),
        v => match v.as_i128().unwrap_or(0) {
            i if i < 0 => Json::from(i as i64),
            i => Json::from(i as u64),
        },
    }
}

/// Serializes as [`VarValue::to_json`].
impl Serialize for VarValue {
    fn serialize<S: Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
        self.to_json().serialize(serializer)
    }
}
