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
//! - a structure as its members (below, *Structures*): a variable of it is flattened into one
//!   variable per elementary leaf field (`Motor.Speed`), nested structures recursively;
//! - an array of an elementary type (or of an alias, subrange or enumeration of one) with
//!   integer bounds, at most [`MAX_ELEMENTS`] elements, SCALARISED ([`ArrayOf`]): one variable
//!   per element named `a[3]`, `m[1,-2]` (IEC 61131-3 6.4.4.5), in element order (the last
//!   subscript fastest), its initial values from an `arrayValue` (`[1, 2]`, `[3(0)]`; the rest the
//!   element type's default); the ST lowering ([`super::st_lower`]) selects among them;
//! - any other array as one whole variable: a read or write of any element is a read or write
//!   of the variable. It has no value (it stands in as a DINT 0, like a string), so it may
//!   appear only in bodies `run` does not execute.
//!
//! Beremiz's SVGHMI extension declares HMI_BOOL, HMI_INT, HMI_REAL, HMI_STRING and HMI_NODE
//! (and, in older versions, HMI_CLASS and HMI_LABEL) in its own library (`svghmi/pous.xml`),
//! which an exported project does not contain: they are aliases of BOOL, INT, REAL, STRING and
//! BOOL, and read as such unless the project declares a type of the same name.
//!
//! A type derived from a type that nobody defines (a CODESYS library type such as `JSONVAR`)
//! is a black box: one whole variable without a value, like an array.
//!
//! Invariants: every type of the file resolves to a [`Base`] or is an error at its
//! `dataType` (a cycle of aliases, a malformed range or enumeration); names are IEC
//! identifiers.
//!
//! Deliberately not here: range checks, arrays of structures or instances (whole variables),
//! pointers and references (errors).
//!
//! # Structures
//!
//! Structures (IEC 61131-3 6.4.4.3, TC6 `struct`): their members, their structured initial
//! values (`structValue`), and the flattening of a structure into its elementary leaf fields.
//! They share this module with the data types because reading them recurses both ways: a
//! member has a data type ([`resolve`], [`base`]), and a data type may be a structure
//! ([`members`]).
//!
//! The model has no structured types, so a variable `Motor` of a structure type with members
//! `Speed : INT` and `On : BOOL` is read as the variables `Motor.Speed` (INT) and `Motor.On`
//! (BOOL), named as a function block instance's members are (`G1.IN`); a nested structure
//! recurses (`Plant.Motor.Speed`). So a field read or written in any body is exactly that
//! variable, and dependences are per field. A member that is an array of an elementary type is
//! one variable per element (`Motor.Hist[0]`); another array stays one whole variable (the
//! array's stand-in, above); an array of structures is such an array.
//!
//! A leaf's initial value is, first found: the variable's own structured initial value for that
//! field, the member's `initialValue` in the structure's declaration (or a structured initial
//! value of the structure type, which overrides it), the initial value of the member's type.
//!
//! Invariants: member names are IEC identifiers, unique in their structure; a structure has at
//! least one member and at most [`MAX_LEAVES`] leaf fields (so a chain of structures nesting
//! each other several times cannot blow up); a `structValue` names only members that exist.
//!
//! Deliberately not here: arrays of structures; whole-structure assignment in graphical bodies
//! (a structure read or written as a whole is its fields in ST, [`super::st_body`]).

use super::xml::{attr, error, identifier, origin, type_reference, Tc6, R};
use plc_diag::Origin;
use roxmltree::Node;
use std::collections::HashMap;

/// What a data type stands on.
#[derive(Clone, Debug, PartialEq)]
pub(super) enum Base {
    /// An elementary type as TC6 writes it (`INT`, `UINT`, `string`).
    Elementary(String),
    /// An enumeration: its value names and integers, in declaration order: a value's own
    /// (`value` attribute, IEC 61131-3 6.4.4.2 named values), else one more than the previous
    /// one's (the first 0), as CODESYS and matiec number them.
    Enum(Vec<(String, i64)>),
    /// An array whose elements are not scalarised (of structures, instances, strings, arrays,
    /// or with bounds that are not integers), or a type nobody defines: one whole variable.
    Whole(Aggregate),
    /// An array of an elementary type (or an alias, subrange or enumeration of one),
    /// scalarised into one variable per element ([`ArrayOf`]).
    Array(Box<ArrayOf>),
    /// A structure: its members in declaration order.
    Struct(Vec<Member>),
}

/// A member of a structure (IEC 61131-3 6.4.4.3): its type and its initial value (the
/// member's own `initialValue`, or one a structured initial value gave it).
#[derive(Clone, Debug, PartialEq)]
pub(super) struct Member {
    pub name: String,
    pub ty: DataType,
    pub init: Option<(String, Origin)>,
    /// The member's type is an elementary type as written (not a data type).
    pub elementary: bool,
}

/// An array type scalarised (IEC 61131-3 6.4.4.5; TC6 `array`: `dimension@lower/@upper` and a
/// `baseType`): its dimensions, its element type and its elements' initial values.
#[derive(Clone, Debug, PartialEq)]
pub(super) struct ArrayOf {
    /// The bounds of each dimension, `lower..=upper`.
    pub dims: Vec<(i64, i64)>,
    /// The element type: an elementary type as written (`elementary`), else a data type.
    pub elem: DataType,
    pub elementary: bool,
    /// The elements' initial values in element order (the last index varying fastest), from an
    /// `arrayValue`; `None` where it gives none (the element type's default applies).
    pub init: Vec<Option<(String, Origin)>>,
}

impl ArrayOf {
    /// How many elements the array has.
    pub(super) fn len(&self) -> usize {
        self.dims
            .iter()
            .map(|&(lo, hi)| (hi - lo + 1) as usize)
            .product()
    }

    /// The subscripts of every element, in element order (the last index varying fastest, as
    /// IEC 61131-3 6.4.4.5 orders an array's initial values).
    pub(super) fn subscripts(&self) -> Vec<Vec<i64>> {
        let mut out: Vec<Vec<i64>> = vec![Vec::new()];
        for &(lo, hi) in &self.dims {
            out = out
                .into_iter()
                .flat_map(|p| {
                    (lo..=hi).map(move |k| {
                        let mut q = p.clone();
                        q.push(k);
                        q
                    })
                })
                .collect();
        }
        out
    }

    /// The variable of the element with subscripts `k` of array variable `name`: `a[3]`,
    /// `m[1,2]`.
    pub(super) fn element_name(name: &str, k: &[i64]) -> String {
        let ks: Vec<String> = k.iter().map(|i| i.to_string()).collect();
        format!("{name}[{}]", ks.join(","))
    }

    /// `ARRAY[1..10, 0..3] OF INT`, for the notes.
    fn describe(&self) -> String {
        let dims: Vec<String> = self.dims.iter().map(|(l, h)| format!("{l}..{h}")).collect();
        let of = if self.elementary {
            self.elem.name.to_ascii_uppercase()
        } else {
            self.elem.name.clone()
        };
        format!("ARRAY[{}] OF {of}", dims.join(", "))
    }
}

/// The most elements an array may have to be scalarised (a larger one is one whole variable).
pub(super) const MAX_ELEMENTS: usize = 65_536;

/// The aggregate kinds of IEC 61131-3 6.4.4 read as one whole variable.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) enum Aggregate {
    Array,
    /// A type the file names and nobody defines (a CODESYS library type such as `JSONVAR`):
    /// a black box, read as one whole variable.
    Undefined,
}

impl Aggregate {
    pub(super) fn word(self) -> &'static str {
        match self {
            Aggregate::Array => "an array",
            Aggregate::Undefined => {
                "a type that neither the file nor plc-deps defines (a library type: a black box)"
            }
        }
    }
}

/// A data type as read.
#[derive(Clone, Debug, PartialEq)]
pub(super) struct DataType {
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
    pub(super) fn describe(&self) -> String {
        let mut d = match &self.base {
            Base::Elementary(t) => format!("an alias of {}", t.to_ascii_uppercase()),
            Base::Enum(v) => {
                let vals: Vec<String> = v.iter().map(|(n, i)| format!("{n} = {i}")).collect();
                format!("an enumeration, read as INT with {}", vals.join(", "))
            }
            Base::Whole(a) => format!("{}, read as one whole variable without a value", a.word()),
            Base::Array(a) => format!(
                "{}, read as one variable per element (`a[i]`)",
                a.describe()
            ),
            Base::Struct(m) => format!(
                "a structure, read as one variable per field: {}",
                leaves(m)
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
pub(super) struct DataTypes {
    types: HashMap<String, DataType>,
}

impl DataTypes {
    /// Reads `types/dataTypes` (none: only the library types).
    pub(super) fn read(tc6: Tc6, data_types: Option<Node>) -> R<Self> {
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
    pub(super) fn get(&self, name: &str) -> Option<DataType> {
        if let Some(t) = self.types.get(name) {
            return Some(t.clone());
        }
        if name == "LOGLEVEL" {
            // Beremiz's NativeLib.xml: `TYPE LOGLEVEL : (CRITICAL, WARNING, INFO, DEBUG) :=
            // INFO; END_TYPE`, the type of its LOGGER's LEVEL ([`super::library`]).
            let vals = ["CRITICAL", "WARNING", "INFO", "DEBUG"];
            return Some(DataType {
                name: name.to_owned(),
                base: Base::Enum(vals.iter().map(|v| v.to_string()).zip(0..).collect()),
                range: None,
                init: Some(("INFO".to_owned(), Origin::default())),
                library: Some("Beremiz NativeLib"),
            });
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

    /// Every enumeration value of the project: its type's name, its name and its integer.
    pub(super) fn enum_values(&self) -> Vec<(String, String, i64)> {
        let mut out = Vec::new();
        for t in self.types.values() {
            if let Base::Enum(v) = &t.base {
                out.extend(v.iter().map(|(n, i)| (t.name.clone(), n.clone(), *i)));
            }
        }
        out
    }

    /// The integer of value `text` (`CLOSED`, `MYTYPE2#CLOSED`, or CODESYS's `MYTYPE2.CLOSED`)
    /// of enumeration `t`.
    pub(super) fn enum_value(t: &DataType, text: &str) -> Option<i64> {
        let Base::Enum(v) = &t.base else { return None };
        let text = text.trim();
        let name = match text.split_once('#').or_else(|| text.split_once('.')) {
            Some((ty, n)) if ty.eq_ignore_ascii_case(&t.name) => n,
            Some(_) => return None,
            None => text,
        };
        v.iter()
            .find(|(x, _)| x.eq_ignore_ascii_case(name))
            .map(|&(_, i)| i)
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
        apply_value(tc6, members, sv, name, &place)?;
    }
    if let (Some(av), Base::Array(a)) = (iv.and_then(|iv| tc6.child(iv, "arrayValue")), &mut t.base)
    {
        a.init = array_value(tc6, av, a.len(), name, &place)?;
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
            let of = type_reference(attr(bt, "name", place)?, &|t| raw.contains_key(t), bt, place)?;
            if let Some(next) = raw.get(&of) {
                let mut t = resolve(tc6, raw, &of, *next, depth + 1)?;
                t.name = name.to_owned();
                return Ok(t);
            }
            if let Some(&(_, b)) = SVGHMI.iter().find(|(n, _)| *n == of) {
                return Ok(plain(Base::Elementary(b.to_owned())));
            }
            // A library type the file does not define (CODESYS's `JSONVAR`): a black box, one
            // whole variable without a value, named after the type (the data type's note says
            // so, and `run` refuses the bodies that use it, [`super::interface::Mapped`]).
            Ok(DataType {
                name: of,
                ..plain(Base::Whole(Aggregate::Undefined))
            })
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
            let mut vals: Vec<(String, i64)> = Vec::new();
            for v in tc6
                .child(bt, "values")
                .into_iter()
                .flat_map(|vs| tc6.children(vs, "value"))
            {
                let n = identifier(attr(v, "name", place)?, "enumeration value", v, place)?;
                let i = match v.attribute("value") {
                    // `5`, `-1`, `16#1F`, `INT#5`: an integer literal (IEC 61131-3 6.3.2).
                    Some(text) => {
                        let t = text.trim();
                        let t = plc_model::split_typed_literal(t).map_or(t, |(_, r)| r);
                        plc_model::parse_int_literal(t)
                            .and_then(|i| i64::try_from(i).ok())
                            .ok_or_else(|| {
                                error(
                                    origin(v),
                                    place,
                                    format!("value `{text}` of enumeration value `{n}` of `{name}` is not an integer literal"),
                                )
                            })?
                    }
                    None => vals.last().map_or(0, |&(_, p)| p.saturating_add(1)),
                };
                vals.push((n, i));
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
        "array" => array(tc6, raw, None, name, bt, depth, place),
        "struct" => Ok(plain(Base::Struct(members(
            tc6, raw, None, name, bt, depth, place,
        )?))),
        other => Err(error(
            origin(bt),
            place,
            format!("data type `{name}` is a {other}, which is not supported yet (supported: aliases of elementary types, subranges, enumerations, arrays and structures)"),
        )),
    }
}

/// The most leaf fields a structure may flatten into.
pub(super) const MAX_LEAVES: usize = 65_536;

/// The members of `struct` element `st` of data type `name`: named types are looked up in
/// `raw` (the data types being resolved), else in `resolved` (a structure declared in place in
/// a variable's type, once the data types are read).
pub(super) fn members(
    tc6: Tc6,
    raw: &HashMap<String, Node>,
    resolved: Option<&DataTypes>,
    name: &str,
    st: Node,
    depth: usize,
    place: &str,
) -> R<Vec<Member>> {
    let mut out: Vec<Member> = Vec::new();
    for v in tc6.children(st, "variable") {
        let m = identifier(attr(v, "name", place)?, "structure member", v, place)?;
        if out.iter().any(|o| o.name.eq_ignore_ascii_case(&m)) {
            return Err(error(
                origin(v),
                place,
                format!("structure `{name}` declares member `{m}` twice"),
            ));
        }
        let te = tc6
            .child(v, "type")
            .and_then(|t| tc6.elements(t).next())
            .ok_or_else(|| {
                error(
                    origin(v),
                    place,
                    format!("member `{m}` of structure `{name}` has no type"),
                )
            })?;
        let inner = format!("{name}.{m}");
        let ty = match te.tag_name().name() {
            // A named data type keeps its name (for the notes and the enumeration values).
            "derived" => {
                let of = type_reference(
                    attr(te, "name", place)?,
                    &|t| raw.contains_key(t),
                    te,
                    place,
                )?;
                match (raw.get(&of), resolved.and_then(|r| r.get(&of))) {
                    (Some(dt), _) => resolve(tc6, raw, &of, *dt, depth + 1)?,
                    (None, Some(d)) => d,
                    (None, None) => base(tc6, raw, &inner, te, depth + 1, place)?,
                }
            }
            "struct" => DataType {
                name: inner.clone(),
                base: Base::Struct(members(tc6, raw, resolved, &inner, te, depth + 1, place)?),
                range: None,
                init: None,
                library: None,
            },
            // An array declared in place is named as a variable's is (`ARRAY`).
            "array" => array(tc6, raw, resolved, "ARRAY", te, depth + 1, place)?,
            _ => base(tc6, raw, &inner, te, depth + 1, place)?,
        };
        let elementary = super::elementary::is_elementary_tag(te.tag_name().name());
        let mut init = None;
        if let Some(iv) = tc6.child(v, "initialValue") {
            init = simple(tc6, iv, place)?;
        }
        let mut member = Member {
            name: m,
            ty,
            init,
            elementary,
        };
        if let (Some(sv), Base::Struct(inner_members)) = (
            tc6.child(v, "initialValue")
                .and_then(|iv| tc6.child(iv, "structValue")),
            &mut member.ty.base,
        ) {
            apply_value(tc6, inner_members, sv, &inner, place)?;
        }
        out.push(member);
    }
    if out.is_empty() {
        return Err(error(
            origin(st),
            place,
            format!("structure `{name}` has no members"),
        ));
    }
    let n = count(&out);
    if n > MAX_LEAVES {
        return Err(error(
            origin(st),
            place,
            format!("structure `{name}` has {n} elementary fields, more than the {MAX_LEAVES} plc-deps reads"),
        ));
    }
    Ok(out)
}

/// The `simpleValue` of initial value `iv` (`None`: it is an array or structure value).
fn simple(tc6: Tc6, iv: Node, place: &str) -> R<Option<(String, Origin)>> {
    match tc6.child(iv, "simpleValue") {
        Some(s) => Ok(Some((attr(s, "value", place)?.to_owned(), origin(s)))),
        None => Ok(None),
    }
}

/// How many leaf fields `members` flatten into.
fn count(members: &[Member]) -> usize {
    members
        .iter()
        .map(|m| match &m.ty.base {
            Base::Struct(inner) => count(inner),
            Base::Array(a) => a.len(),
            _ => 1,
        })
        .sum()
}

/// Gives the members of a structure the values of structured value `sv` (TC6 `structValue`:
/// `value@member` elements holding a `simpleValue`, a nested `structValue`, or an
/// `arrayValue`, which an array member ignores since it has no value). `what` names the
/// structure or variable for messages.
pub(super) fn apply_value(
    tc6: Tc6,
    members: &mut [Member],
    sv: Node,
    what: &str,
    place: &str,
) -> R<()> {
    for v in tc6.children(sv, "value") {
        let m = attr(v, "member", place)?;
        let Some(member) = members
            .iter_mut()
            .find(|x| x.name.eq_ignore_ascii_case(m.trim()))
        else {
            let names: Vec<&str> = members.iter().map(|x| x.name.as_str()).collect();
            return Err(error(
                origin(v),
                place,
                format!(
                    "the initial value of `{what}` gives member `{m}`, which the structure does not have (its members: {})",
                    names.join(", ")
                ),
            ));
        };
        let inner = format!("{what}.{}", member.name);
        let Some(content) = tc6.elements(v).next() else {
            return Err(error(
                origin(v),
                place,
                format!("the initial value of `{inner}` is empty"),
            ));
        };
        let tag = content.tag_name().name();
        let mismatch = || {
            error(
                origin(content),
                place,
                format!("the initial value of `{inner}` is a {tag}, which does not fit its type"),
            )
        };
        match (tag, &mut member.ty.base) {
            ("simpleValue", Base::Struct(_) | Base::Whole(_) | Base::Array(_)) => {
                return Err(mismatch())
            }
            ("arrayValue", Base::Array(a)) => {
                a.init = array_value(tc6, content, a.len(), &inner, place)?
            }
            ("simpleValue", _) => member.init = simple(tc6, v, place)?,
            ("structValue", Base::Struct(inner_members)) => {
                apply_value(tc6, inner_members, content, &inner, place)?
            }
            // An array has no value in the model.
            ("arrayValue", Base::Whole(_)) => {}
            ("structValue" | "arrayValue", _) => return Err(mismatch()),
            (other, _) => {
                return Err(error(
                    origin(content),
                    place,
                    format!(
                    "the initial value of `{inner}` is a `{other}`, which plc-deps does not read"
                ),
                ))
            }
        }
    }
    Ok(())
}

/// One elementary field of a flattened structure.
#[derive(Clone, Debug)]
pub(super) struct Leaf {
    /// `Motor.Speed`, `Plant.Motor.Speed`.
    pub path: String,
    /// Its type: an elementary type as written (`elementary`), else a data type.
    pub ty: DataType,
    pub elementary: bool,
    /// Its initial value (the member's, else its type's).
    pub init: Option<(String, Origin)>,
}

/// The leaf fields of a variable `name` of structure `members`, in declaration order.
pub(super) fn flatten(name: &str, members: &[Member]) -> Vec<Leaf> {
    let mut out = Vec::new();
    for m in members {
        let path = format!("{name}.{}", m.name);
        match &m.ty.base {
            Base::Struct(inner) => out.extend(flatten(&path, inner)),
            Base::Array(a) => out.extend(elements(&path, a)),
            _ => out.push(Leaf {
                path,
                ty: m.ty.clone(),
                elementary: m.elementary,
                init: m.init.clone().or_else(|| m.ty.init.clone()),
            }),
        }
    }
    out
}

/// The elements of array variable `name` of type `a` as leaves (`a[1]`, `m[0,2]`), in element
/// order, each with its initial value (the array value's, else the element type's).
pub(super) fn elements(name: &str, a: &ArrayOf) -> Vec<Leaf> {
    a.subscripts()
        .into_iter()
        .enumerate()
        .map(|(i, k)| Leaf {
            path: ArrayOf::element_name(name, &k),
            ty: a.elem.clone(),
            elementary: a.elementary,
            init: a
                .init
                .get(i)
                .cloned()
                .flatten()
                .or_else(|| a.elem.init.clone()),
        })
        .collect()
}

/// Array type element `arr` (TC6 `array`) of type `name`: scalarised ([`Base::Array`]) when its
/// bounds are integers and its elements of an elementary type, an alias, a subrange or an
/// enumeration, and it has at most [`MAX_ELEMENTS`] elements; else one whole variable
/// ([`Base::Whole`]), which `run` refuses by name.
pub(super) fn array(
    tc6: Tc6,
    raw: &HashMap<String, Node>,
    resolved: Option<&DataTypes>,
    name: &str,
    arr: Node,
    depth: usize,
    place: &str,
) -> R<DataType> {
    let whole = DataType {
        name: name.to_owned(),
        base: Base::Whole(Aggregate::Array),
        range: None,
        init: None,
        library: None,
    };
    let mut dims = Vec::new();
    for d in tc6.children(arr, "dimension") {
        let bound = |a: &str| {
            d.attribute(a)
                .and_then(|v| plc_model::parse_int_literal(v.trim()))
                .and_then(|v| i64::try_from(v).ok())
                .or_else(|| {
                    let v = d.attribute(a)?.trim();
                    let v = v.strip_prefix('-')?;
                    plc_model::parse_int_literal(v)
                        .and_then(|v| i64::try_from(v).ok())
                        .map(|v| -v)
                })
        };
        let (Some(lo), Some(hi)) = (bound("lower"), bound("upper")) else {
            return Ok(whole);
        };
        if hi < lo {
            return Err(error(
                origin(d),
                place,
                format!("array `{name}` has a dimension {lo}..{hi} whose upper bound is below its lower bound"),
            ));
        }
        dims.push((lo, hi));
    }
    let Some(bt) = tc6
        .child(arr, "baseType")
        .and_then(|b| tc6.elements(b).next())
    else {
        return Err(error(
            origin(arr),
            place,
            format!("array `{name}` has no element type"),
        ));
    };
    let total = dims.iter().try_fold(1usize, |n, &(lo, hi)| {
        usize::try_from(hi - lo + 1)
            .ok()
            .and_then(|k| n.checked_mul(k))
    });
    if dims.is_empty() || total.is_none_or(|n| n > MAX_ELEMENTS) {
        return Ok(whole);
    }
    let tag = bt.tag_name().name();
    let elementary = super::elementary::is_elementary_tag(tag);
    let elem = match tag {
        _ if elementary => DataType {
            name: tag.to_owned(),
            base: Base::Elementary(tag.to_owned()),
            range: None,
            init: None,
            library: None,
        },
        "derived" => {
            let of = type_reference(
                attr(bt, "name", place)?,
                &|t| raw.contains_key(t),
                bt,
                place,
            )?;
            match (raw.get(&of), resolved.and_then(|r| r.get(&of))) {
                (Some(dt), _) => resolve(tc6, raw, &of, *dt, depth + 1)?,
                (None, Some(d)) => d,
                (None, None) => base(tc6, raw, &of, bt, depth + 1, place)?,
            }
        }
        "subrangeSigned" | "subrangeUnsigned" | "enum" => {
            base(tc6, raw, name, bt, depth + 1, place)?
        }
        _ => return Ok(whole),
    };
    let scalar = match &elem.base {
        Base::Elementary(t) => !matches!(t.to_ascii_lowercase().as_str(), "string" | "wstring"),
        Base::Enum(_) => true,
        _ => false,
    };
    if !scalar {
        return Ok(whole);
    }
    Ok(DataType {
        name: name.to_owned(),
        base: Base::Array(Box::new(ArrayOf {
            dims,
            elem,
            elementary,
            init: Vec::new(),
        })),
        range: None,
        init: None,
        library: None,
    })
}

/// The initial values of the `len` elements of array `what` from array value `av` (TC6
/// `arrayValue`: `value` elements, each a `simpleValue` (or a nested `arrayValue`, read in
/// order) and an optional `repetitionValue`, IEC 61131-3 6.4.4.5's `[3(0), 2(1)]`): in element
/// order, `None` for the elements after the last value given. More values than elements is an
/// error, as in matiec.
pub(super) fn array_value(
    tc6: Tc6,
    av: Node,
    len: usize,
    what: &str,
    place: &str,
) -> R<Vec<Option<(String, Origin)>>> {
    let mut out = Vec::new();
    fn walk(
        tc6: Tc6,
        av: Node,
        len: usize,
        what: &str,
        place: &str,
        out: &mut Vec<Option<(String, Origin)>>,
    ) -> R<()> {
        for v in tc6.children(av, "value") {
            let times = match v.attribute("repetitionValue") {
                None => 1,
                Some(r) => r.trim().parse::<usize>().map_err(|_| {
                    error(
                        origin(v),
                        place,
                        format!("repetition `{r}` in the initial value of `{what}` is not a whole number"),
                    )
                })?,
            };
            let Some(content) = tc6.elements(v).next() else {
                return Err(error(
                    origin(v),
                    place,
                    format!("a value in the initial value of `{what}` is empty"),
                ));
            };
            match content.tag_name().name() {
                "simpleValue" => {
                    let text = attr(content, "value", place)?.to_owned();
                    if out.len().saturating_add(times) > len {
                        return Err(error(
                            origin(v),
                            place,
                            format!("the initial value of `{what}` gives more values than its {len} elements"),
                        ));
                    }
                    for _ in 0..times {
                        out.push(Some((text.clone(), origin(content))));
                    }
                }
                "arrayValue" => {
                    for _ in 0..times {
                        walk(tc6, content, len, what, place, out)?;
                    }
                }
                other => {
                    return Err(error(
                        origin(content),
                        place,
                        format!("the initial value of `{what}` holds a `{other}`, which an array of an elementary type cannot take"),
                    ))
                }
            }
        }
        Ok(())
    }
    walk(tc6, av, len, what, place, &mut out)?;
    Ok(out)
}

/// The leaf fields of a structure relative to it (`Speed`, `Motor.Speed`) with their types as
/// the notes show them (`INT`, `MYTYPE`, an array as `ARRAY`).
pub(super) fn leaves(members: &[Member]) -> Vec<(String, String)> {
    flatten("", members)
        .into_iter()
        .map(|l| {
            let t = match &l.ty.base {
                Base::Whole(_) | Base::Array(_) => "ARRAY".to_owned(),
                Base::Elementary(t) if l.elementary => t.to_ascii_uppercase(),
                _ => l.ty.name.clone(),
            };
            (l.path[1..].to_owned(), t)
        })
        .collect()
}
