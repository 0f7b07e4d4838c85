//! Structures (IEC 61131-3 6.4.4.3, TC6 `struct`): their members, their structured initial
//! values (`structValue`), and the flattening of a structure into its elementary leaf fields.
//!
//! The model has no structured types, so a variable `Motor` of a structure type with members
//! `Speed : INT` and `On : BOOL` is read as the variables `Motor.Speed` (INT) and `Motor.On`
//! (BOOL), named as a function block instance's members are (`G1.IN`); a nested structure
//! recurses (`Plant.Motor.Speed`). So a field read or written in any body is exactly that
//! variable, and dependences are per field. A member that is an array stays one whole
//! variable (the array's stand-in, [`super::data_types`]); an array of structures is an array.
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

use super::data_types::{base, resolve, Base, DataType, DataTypes, Member};
use super::xml::{attr, error, identifier, origin, Tc6, R};
use plc_diag::Origin;
use roxmltree::Node;
use std::collections::HashMap;

/// The most leaf fields a structure may flatten into.
pub const MAX_LEAVES: usize = 65_536;

/// The members of `struct` element `st` of data type `name`: named types are looked up in
/// `raw` (the data types being resolved), else in `resolved` (a structure declared in place in
/// a variable's type, once the data types are read).
pub fn members(
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
pub fn apply_value(tc6: Tc6, members: &mut [Member], sv: Node, what: &str, place: &str) -> R<()> {
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
pub struct Leaf {
    /// `Motor.Speed`, `Plant.Motor.Speed`.
    pub path: String,
    /// Its type: an elementary type as written (`elementary`), else a data type.
    pub ty: DataType,
    pub elementary: bool,
    /// Its initial value (the member's, else its type's).
    pub init: Option<(String, Origin)>,
}

/// The leaf fields of a variable `name` of structure `members`, in declaration order.
pub fn flatten(name: &str, members: &[Member]) -> Vec<Leaf> {
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
pub fn leaves(members: &[Member]) -> Vec<(String, String)> {
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
