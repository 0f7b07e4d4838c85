//! User data types (TC6 `types/dataTypes/dataType`, IEC 61131-3 6.4.4, "derived data types")
//! and the data types of Beremiz's SVGHMI library, as the model's elementary types.
//!
//! The model has only BOOL, INT, DINT, REAL, TIME and function block instances, so a derived
//! type is read as what it stands on:
//!
//! - an alias (`TYPE T : INT; END_TYPE`) and a subrange (`INT (0..1000)`) as its base type
//!   (then, like any elementary type, mapped by [`super::interface`]); the subrange's bounds are
//!   kept for the note and not enforced;
//! - an enumeration as INT, its values numbered 0, 1, … in declaration order (as Beremiz's
//!   compiler matiec numbers them); a value's name is a constant wherever a literal is read
//!   (an initial value, an ST expression);
//! - a structure as its members ([`super::structure`]): a variable of it is flattened into one
//!   variable per elementary leaf field (`Motor.Speed`), nested structures recursively;
//! - an array as one whole variable: a read or write of any element is a read or write of the
//!   variable. It has no value (it stands in as a DINT 0, like a string), so it may appear only
//!   in bodies `run` does not execute.
//!
//! Beremiz's SVGHMI extension declares HMI_BOOL, HMI_INT, HMI_REAL, HMI_STRING and HMI_NODE
//! (and, in older versions, HMI_CLASS and HMI_LABEL) in its own library (`svghmi/pous.xml`),
//! which an exported project does not contain: they are aliases of BOOL, INT, REAL, STRING and
//! BOOL, and read as such unless the project declares a type of the same name.
//!
//! Invariants: every type of the file resolves to a [`Base`] or is an error at its
//! `dataType` (an unknown base, a cycle of aliases, a malformed range or enumeration); names are
//! IEC identifiers.
//!
//! Deliberately not here: range checks, element-wise arrays, pointers and references (errors).

use super::xml::{attr, error, identifier, origin, Tc6, R};
use plc_diag::Origin;
use roxmltree::Node;
use std::collections::HashMap;

/// What a data type stands on.
#[derive(Clone, Debug, PartialEq)]
pub enum Base {
    /// An elementary type as TC6 writes it (`INT`, `UINT`, `string`).
    Elementary(String),
    /// An enumeration: its value names; value `k` (0-based) is the integer `k`.
    Enum(Vec<String>),
    /// An array, analysed as one whole variable (a structure is always [`Base::Struct`]).
    Whole(Aggregate),
    /// A structure: its members in declaration order.
    Struct(Vec<Member>),
}

/// A member of a structure (IEC 61131-3 6.4.4.3): its type and its initial value (the
/// member's own `initialValue`, or one a structured initial value gave it).
#[derive(Clone, Debug, PartialEq)]
pub struct Member {
    pub name: String,
    pub ty: DataType,
    pub init: Option<(String, Origin)>,
    /// The member's type is an elementary type as written (not a data type).
    pub elementary: bool,
}

/// The aggregate kinds of IEC 61131-3 6.4.4 read as one whole variable.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Aggregate {
    Array,
}

impl Aggregate {
    pub fn word(self) -> &'static str {
        match self {
            Aggregate::Array => "an array",
        }
    }
}

/// A data type as read.
#[derive(Clone, Debug, PartialEq)]
pub struct DataType {
    pub name: String,
    pub base: Base,
    /// The bounds of a subrange on the way to the base (not enforced).
    pub range: Option<(i64, i64)>,
    /// The type's initial value (`simpleValue@value`), the default of its variables.
    pub init: Option<(String, Origin)>,
    /// The library that declares it when the file does not (Beremiz SVGHMI).
    pub library: Option<&'static str>,
}

impl DataType {
    /// How the note describes what the type was read as.
    pub fn describe(&self) -> String {
        let mut d = match &self.base {
            Base::Elementary(t) => format!("an alias of {}", t.to_ascii_uppercase()),
            Base::Enum(v) => {
                let vals: Vec<String> = v
                    .iter()
                    .enumerate()
                    .map(|(i, n)| format!("{n} = {i}"))
                    .collect();
                format!("an enumeration, read as INT with {}", vals.join(", "))
            }
            Base::Whole(a) => format!("{}, read as one whole variable without a value", a.word()),
            Base::Struct(m) => format!(
                "a structure, read as one variable per field: {}",
                super::structure::leaves(m)
                    .iter()
                    .map(|(path, t)| format!("{path} {t}"))
                    .collect::<Vec<_>>()
                    .join(", ")
            ),
        };
        if let Some((lo, hi)) = self.range {
            d.push_str(&format!(", subrange {lo}..{hi} not enforced"));
        }
        if let Some(l) = self.library {
            d.push_str(&format!(", from the {l} library"));
        }
        d
    }
}

/// The SVGHMI types of Beremiz (`svghmi/pous.xml`) and their base types.
const SVGHMI: &[(&str, &str)] = &[
    ("HMI_BOOL", "BOOL"),
    ("HMI_INT", "INT"),
    ("HMI_REAL", "REAL"),
    ("HMI_STRING", "string"),
    ("HMI_NODE", "BOOL"),
    ("HMI_CLASS", "BOOL"),
    ("HMI_LABEL", "BOOL"),
];

/// The project's data types by name.
#[derive(Default)]
pub struct DataTypes {
    types: HashMap<String, DataType>,
}

impl DataTypes {
    /// Reads `types/dataTypes` (none: only the library types).
    pub fn read(tc6: Tc6, data_types: Option<Node>) -> R<Self> {
        let place = "types/dataTypes";
        let mut raw: HashMap<String, Node> = HashMap::new();
        let mut order = Vec::new();
        for dt in data_types
            .into_iter()
            .flat_map(|d| tc6.children(d, "dataType"))
        {
            let name = identifier(attr(dt, "name", place)?, "data type", dt, place)?;
            order.push(name.clone());
            if raw.insert(name.clone(), dt).is_some() {
                return Err(error(
                    origin(dt),
                    place,
                    format!("data type `{name}` is declared twice"),
                ));
            }
        }
        let mut out = DataTypes::default();
        // In file order, so that the error of a cycle is the same every time.
        for name in order {
            let t = resolve(tc6, &raw, &name, raw[&name], 0)?;
            out.types.insert(name, t);
        }
        Ok(out)
    }

    /// The type named `name`: the project's, else a library type.
    pub fn get(&self, name: &str) -> Option<DataType> {
        if let Some(t) = self.types.get(name) {
            return Some(t.clone());
        }
        let &(n, b) = SVGHMI.iter().find(|(n, _)| *n == name)?;
        Some(DataType {
            name: n.to_owned(),
            base: Base::Elementary(b.to_owned()),
            range: None,
            init: None,
            library: Some("Beremiz SVGHMI"),
        })
    }

    /// Every enumeration value of the project and its integer.
    pub fn enum_values(&self) -> Vec<(String, i64)> {
        let mut out = Vec::new();
        for t in self.types.values() {
            if let Base::Enum(v) = &t.base {
                out.extend(v.iter().cloned().zip(0..));
            }
        }
        out
    }

    /// The integer of value `text` (`CLOSED` or `MYTYPE2#CLOSED`) of enumeration `t`.
    pub fn enum_value(t: &DataType, text: &str) -> Option<i64> {
        let Base::Enum(v) = &t.base else { return None };
        let text = text.trim();
        let name = match text.split_once('#') {
            Some((ty, n)) if ty == t.name => n,
            Some(_) => return None,
            None => text,
        };
        v.iter()
            .position(|x| x.eq_ignore_ascii_case(name))
            .map(|i| i as i64)
    }
}

/// Type `name` (its `dataType` element `dt`), resolved to its base; `depth` counts the aliases
/// followed (more than there are types is a cycle).
pub(super) fn resolve(
    tc6: Tc6,
    raw: &HashMap<String, Node>,
    name: &str,
    dt: Node,
    depth: usize,
) -> R<DataType> {
    let place = format!("types/dataTypes, dataType {name}");
    if depth > raw.len() {
        return Err(error(
            origin(dt),
            &place,
            format!("data type `{name}` is defined through itself (a cycle of derived types)"),
        ));
    }
    let iv = tc6.child(dt, "initialValue");
    let init = match iv {
        Some(iv) => match tc6.child(iv, "simpleValue") {
            Some(s) => Some((attr(s, "value", &place)?.to_owned(), origin(s))),
            // An array value initialises a variable that has no value anyway; a structure's is
            // given to its members below.
            None => None,
        },
        None => None,
    };
    let bt = tc6
        .child(dt, "baseType")
        .and_then(|b| tc6.elements(b).next())
        .ok_or_else(|| {
            error(
                origin(dt),
                &place,
                format!("data type `{name}` has no base type"),
            )
        })?;
    let mut t = base(tc6, raw, name, bt, depth, &place)?;
    if init.is_some() {
        t.init = init;
    }
    if let (Some(sv), Base::Struct(members)) =
        (iv.and_then(|iv| tc6.child(iv, "structValue")), &mut t.base)
    {
        super::structure::apply_value(tc6, members, sv, name, &place)?;
    }
    Ok(t)
}

/// The base type element `bt` of type `name`.
pub(super) fn base(
    tc6: Tc6,
    raw: &HashMap<String, Node>,
    name: &str,
    bt: Node,
    depth: usize,
    place: &str,
) -> R<DataType> {
    let plain = |base: Base| DataType {
        name: name.to_owned(),
        base,
        range: None,
        init: None,
        library: None,
    };
    let tag = bt.tag_name().name();
    if super::elementary::is_elementary_tag(tag) {
        return Ok(plain(Base::Elementary(tag.to_owned())));
    }
    match tag {
        "derived" => {
            let of = identifier(attr(bt, "name", place)?, "type", bt, place)?;
            if let Some(next) = raw.get(&of) {
                let mut t = resolve(tc6, raw, &of, *next, depth + 1)?;
                t.name = name.to_owned();
                return Ok(t);
            }
            if let Some(&(_, b)) = SVGHMI.iter().find(|(n, _)| *n == of) {
                return Ok(plain(Base::Elementary(b.to_owned())));
            }
            Err(error(
                origin(bt),
                place,
                format!("data type `{name}` derives from `{of}`, which is neither an elementary type nor a data type of the project"),
            ))
        }
        "subrangeSigned" | "subrangeUnsigned" => {
            let r = tc6.child(bt, "range").ok_or_else(|| {
                error(origin(bt), place, format!("subrange `{name}` has no range"))
            })?;
            let bound = |a: &str| -> R<i64> {
                let v = attr(r, a, place)?;
                v.trim().parse().map_err(|_| {
                    error(
                        origin(r),
                        place,
                        format!("bound `{v}` of subrange `{name}` is not a whole number"),
                    )
                })
            };
            let (lo, hi) = (bound("lower")?, bound("upper")?);
            let inner = tc6
                .child(bt, "baseType")
                .and_then(|b| tc6.elements(b).next())
                .ok_or_else(|| {
                    error(
                        origin(bt),
                        place,
                        format!("subrange `{name}` has no base type"),
                    )
                })?;
            let mut t = base(tc6, raw, name, inner, depth, place)?;
            t.range = Some((lo, hi));
            Ok(t)
        }
        "enum" => {
            let mut vals = Vec::new();
            for v in tc6
                .child(bt, "values")
                .into_iter()
                .flat_map(|vs| tc6.children(vs, "value"))
            {
                vals.push(identifier(
                    attr(v, "name", place)?,
                    "enumeration value",
                    v,
                    place,
                )?);
            }
            if vals.is_empty() {
                return Err(error(
                    origin(bt),
                    place,
                    format!("enumeration `{name}` has no values"),
                ));
            }
            Ok(plain(Base::Enum(vals)))
        }
        "array" => Ok(plain(Base::Whole(Aggregate::Array))),
        "struct" => Ok(plain(Base::Struct(super::structure::members(
            tc6, raw, None, name, bt, depth, place,
        )?))),
        other => Err(error(
            origin(bt),
            place,
            format!("data type `{name}` is a {other}, which is not supported yet (supported: aliases of elementary types, subranges, enumerations, arrays and structures)"),
        )),
    }
}
