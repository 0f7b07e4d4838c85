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
//! - an array as one whole variable: a read or write of any element is a read or write of the
//!   variable. It has no value (it stands in as a DINT 0, like a string), so it may appear only
//!   in bodies `run` does not execute.
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
//! Deliberately not here: range checks, element-wise arrays, pointers and references (errors).
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
//! variable, and dependences are per field. A member that is an array stays one whole
//! variable (the array's stand-in, above); an array of structures is an array.
//!
//! A leaf's initial value is, first found: the variable's own structured initial value for that
//! field, the member's `initialValue` in the structure's declaration (or a structured initial
//! value of the structure type, which overrides it), the initial value of the member's type.
//!
//! Invariants: member names are IEC identifiers, unique in their structure; a structure has at
//! least one member and at most [`MAX_LEAVES`] leaf fields (so a chain of structures nesting
//! each other several times cannot blow up); a `structValue` names only members that exist.
//!
//! Deliberately not here: element-wise arrays; whole-structure assignment in graphical bodies
//! (a structure read or written as a whole is its fields in ST, [`super::st_body`]).

use super::xml::{attr, error, identifier, origin, Tc6, R};
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
    /// An array, analysed as one whole variable (a structure is always [`Base::Struct`]).
    Whole(Aggregate),
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

    /// The integer of value `text` (`CLOSED` or `MYTYPE2#CLOSED`) of enumeration `t`.
    pub(super) fn enum_value(t: &DataType, text: &str) -> Option<i64> {
        let Base::Enum(v) = &t.base else { return None };
        let text = text.trim();
        let name = match text.split_once('#') {
            Some((ty, n)) if ty == t.name => n,
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
        "array" => Ok(plain(Base::Whole(Aggregate::Array))),
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
                let of = identifier(attr(te, "name", place)?, "type", te, place)?;
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
            "array" => base(tc6, raw, "ARRAY", te, depth + 1, place)?,
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
            ("simpleValue", Base::Struct(_) | Base::Whole(_)) => return Err(mismatch()),
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

/// The leaf fields of a structure relative to it (`Speed`, `Motor.Speed`) with their types as
/// the notes show them (`INT`, `MYTYPE`, an array as `ARRAY`).
pub(super) fn leaves(members: &[Member]) -> Vec<(String, String)> {
    flatten("", members)
        .into_iter()
        .map(|l| {
            let t = match &l.ty.base {
                Base::Whole(_) => "ARRAY".to_owned(),
                Base::Elementary(t) if l.elementary => t.to_ascii_uppercase(),
                _ => l.ty.name.clone(),
            };
            (l.path[1..].to_owned(), t)
        })
        .collect()
}
