//! Slot encoding of values, and the values a caller reads back.
//!
//! Encoding of one slot: BOOL 0 or 1; INT, DINT and TIME (ms) sign-extended to 64 bits; REAL the
//! `f32` bit pattern in the low 32 bits. Integers of every width therefore compare as `i64`.

use crate::model::{FbKind, Type, Value};
use serde::{Serialize, Serializer};
use serde_json::{json, Value as Json};

/// The slot bits of a scalar value.
#[inline]
pub fn encode(v: Value) -> u64 {
    match v {
        Value::Bool(b) => b as u64,
        Value::Int(i) => i as i64 as u64,
        Value::Dint(i) | Value::Time(i) => i as i64 as u64,
        Value::Real(f) => f.to_bits() as u64,
    }
}

/// The scalar value of type `ty` held in slot bits `bits`. Instance types have no scalar value:
/// for them this returns the slot read as TIME (use [`Machine::value`](super::Machine::value)).
#[inline]
pub fn decode(ty: Type, bits: u64) -> Value {
    match ty {
        Type::Bool => Value::Bool(bits != 0),
        Type::Int => Value::Int(bits as i16),
        Type::Dint => Value::Dint(bits as i32),
        Type::Real => Value::Real(f32::from_bits(bits as u32)),
        Type::Time | Type::Fb(_) => Value::Time(bits as i32),
    }
}

/// The value of a variable as a caller sees it: a scalar, or the readable fields of an instance.
#[derive(Copy, Clone, Debug, PartialEq)]
pub enum VarValue {
    /// A BOOL, INT, DINT, REAL or TIME variable.
    Scalar(Value),
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
}

impl VarValue {
    /// Decodes the slots of a variable of type `ty` (`slots` starts at its first slot).
    pub(crate) fn from_slots(ty: Type, slots: &[u64]) -> VarValue {
        match ty {
            Type::Fb(FbKind::Ton | FbKind::Tof | FbKind::Tp) => VarValue::Timer {
                q: slots[super::layout::Q as usize] != 0,
                et: slots[super::layout::ET as usize] as i32,
                pt: slots[super::layout::PT as usize] as i32,
            },
            Type::Fb(FbKind::Ctu | FbKind::Ctd) => VarValue::Counter {
                q: slots[super::layout::Q as usize] != 0,
                cv: slots[super::layout::ET as usize] as i16,
                pv: slots[super::layout::PT as usize] as i16,
            },
            scalar => VarValue::Scalar(decode(scalar, slots[0])),
        }
    }

    /// The scalar value, if this is one.
    pub fn scalar(&self) -> Option<Value> {
        match self {
            VarValue::Scalar(v) => Some(*v),
            _ => None,
        }
    }

    /// The BOOL value, or the Q of an instance.
    pub fn as_bool(&self) -> Option<bool> {
        match self {
            VarValue::Scalar(Value::Bool(b)) => Some(*b),
            VarValue::Timer { q, .. } | VarValue::Counter { q, .. } => Some(*q),
            _ => None,
        }
    }

    /// JSON form: BOOL `true`/`false`; INT, DINT numbers; REAL a number (its shortest decimal
    /// form; `null` for NaN and infinities, which JSON cannot hold); TIME milliseconds; a timer
    /// `{"Q", "ET", "PT"}` and a counter `{"Q", "CV", "PV"}`.
    pub fn to_json(&self) -> Json {
        match *self {
            VarValue::Scalar(v) => scalar_json(v),
            VarValue::Timer { q, et, pt } => json!({"Q": q, "ET": et, "PT": pt}),
            VarValue::Counter { q, cv, pv } => json!({"Q": q, "CV": cv, "PV": pv}),
        }
    }
}

fn scalar_json(v: Value) -> Json {
    match v {
        Value::Bool(b) => Json::Bool(b),
        Value::Int(i) => Json::from(i),
        Value::Dint(i) | Value::Time(i) => Json::from(i),
        Value::Real(f) => {
            // The shortest decimal that reads back as this f32 (0.1, not 0.10000000149…).
            let shortest: f64 = format!("{f}").parse().unwrap_or(f64::NAN);
            serde_json::Number::from_f64(shortest)
                .map(Json::Number)
                .unwrap_or(Json::Null)
        }
    }
}

/// Serializes as [`VarValue::to_json`].
impl Serialize for VarValue {
    fn serialize<S: Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
        self.to_json().serialize(serializer)
    }
}
