//! Values in state memory, and the values a caller reads back.
//!
//! A scalar is stored in its type's representation ([`Repr`]): BOOL a byte 0 or 1, INT an
//! `i16`, DINT and TIME (ms) an `i32`, REAL an `f32`, native byte order, at an address aligned
//! to its width. This module converts between those bytes and [`Value`]s; it does not place
//! variables (`layout`).

use super::layout::{Repr, CV, ET, PT, PV, Q, QD};
use super::store::{Addr, Store};
use crate::model::{FbKind, Type, Value};
use serde::{Serialize, Serializer};
use serde_json::{json, Value as Json};

/// Writes the scalar `v` at `at` in its type's representation.
#[inline]
pub fn store_value<S: Store + ?Sized>(st: &mut S, at: Addr, v: Value) {
    match v {
        Value::Bool(b) => st.store(at, b as u8),
        Value::Int(i) => st.store(at, i),
        Value::Dint(i) | Value::Time(i) => st.store(at, i),
        Value::Real(f) => st.store(at, f),
    }
}

/// The scalar of type `ty` stored at `at`. Instance types have no scalar value: for them this
/// reads the instance's Q (use [`Machine::value`](super::Machine::value)).
#[inline]
pub fn load_value<S: Store + ?Sized>(st: &S, at: Addr, ty: Type) -> Value {
    match Repr::of(ty) {
        Some(Repr::Bool) | None => Value::Bool(st.load::<u8>(at) != 0),
        Some(Repr::I16) => Value::Int(st.load(at)),
        Some(Repr::I32) if ty == Type::Time => Value::Time(st.load(at)),
        Some(Repr::I32) => Value::Dint(st.load(at)),
        Some(Repr::F32) => Value::Real(st.load(at)),
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

    /// JSON form: BOOL `true`/`false`; INT, DINT numbers; REAL a number (its shortest decimal
    /// form; `null` for NaN and infinities, which JSON cannot hold); TIME milliseconds; a timer
    /// `{"Q", "ET", "PT"}`, a counter `{"Q", "CV", "PV"}`, a bistable `{"Q1"}`, an edge detector
    /// `{"Q"}` and an up-down counter `{"QU", "QD", "CV", "PV"}`.
    pub fn to_json(&self) -> Json {
        match *self {
            VarValue::Scalar(v) => scalar_json(v),
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
