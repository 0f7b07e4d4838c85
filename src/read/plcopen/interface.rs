//! POU interfaces and global variable lists (`interface/inputVars` …, `globalVars`) → the
//! syntax's variable declarations, with their types and initial values (IEC 61131-3 6.5; TC6
//! `varList`, `variable`, `type`, `initialValue`).
//!
//! Invariants: every declaration that is read becomes a [`Var`] or an error naming it and its
//! line; an external declaration (`externalVars`) is a reference to a global of that name and
//! declares nothing (names resolve to the program's variables). Located variables take their
//! class from the address: `%I…` is an input, `%Q…` an output (written by the scan / read by it).
//!
//! The elementary types the model lacks (SINT, WORD, LREAL, STRING …) are read as one it has
//! ([`MAPPED`]), and each such variable is recorded ([`Mapped`]) for the POU's note.
//!
//! Deliberately not here: user data types, arrays, structured initial values and `VAR_IN_OUT`
//! — each an error naming the variable, until the model has them.

use super::xml::{error, identifier, origin, Tc6, R};
use crate::syntax::{Located, Name, Operand, Scalar, Var, VarClass};
use roxmltree::Node;
use std::borrow::Cow;
use std::collections::HashSet;

/// The names of the project's own data types, function blocks and functions, for messages.
pub struct Known<'d> {
    pub data_types: HashSet<&'d str>,
}

/// The lists of an interface, in the order the standard's keywords name them.
#[derive(Default)]
pub struct Interface {
    pub inputs: Vec<Var<'static>>,
    pub outputs: Vec<Var<'static>>,
    pub locals: Vec<Var<'static>>,
    pub globals: Vec<Var<'static>>,
    /// The names of `externalVars` (references to globals).
    pub externals: Vec<String>,
    /// The variables whose elementary type was mapped onto one of the model's.
    pub mapped: Vec<Mapped>,
}

/// A variable whose IEC 61131-3 elementary type the model lacks, read as one it has.
#[derive(Clone, Debug)]
pub struct Mapped {
    pub var: String,
    pub origin: crate::diag::Origin,
    pub from: String,
    pub to: &'static str,
    /// A string type: the model has no value for it (the variable stands in as a DINT 0).
    pub text: bool,
}

/// The elementary types of IEC 61131-3 (6.4.2, Table 10) the model lacks, and the model's type
/// each is read as: the narrower and unsigned integers and the bit strings as INT when every
/// value fits INT, else DINT; the 64-bit ones as DINT; LREAL as REAL; dates and times of day as
/// DINT, LTIME as TIME; strings as DINT (a stand-in: analysis only). docs/plcopen.md says what
/// `run` computes differently.
const MAPPED: &[(&str, &str)] = &[
    ("SINT", "INT"),
    ("USINT", "INT"),
    ("BYTE", "INT"),
    ("UINT", "DINT"),
    ("WORD", "DINT"),
    ("UDINT", "DINT"),
    ("DWORD", "DINT"),
    ("LINT", "DINT"),
    ("ULINT", "DINT"),
    ("LWORD", "DINT"),
    ("LREAL", "REAL"),
    ("LTIME", "TIME"),
    ("DATE", "DINT"),
    ("TOD", "DINT"),
    ("TIME_OF_DAY", "DINT"),
    ("DT", "DINT"),
    ("DATE_AND_TIME", "DINT"),
    ("string", "DINT"),
    ("wstring", "DINT"),
    ("STRING", "DINT"),
    ("WSTRING", "DINT"),
];

/// Standard function blocks the model has.
const MODEL_FBS: &[&str] = &[
    "TON", "TOF", "TP", "CTU", "CTD", "SR", "RS", "R_TRIG", "F_TRIG", "CTUD",
];
/// Standard function blocks of IEC 61131-3 the model does not have yet.
const OTHER_STD_FBS: &[&str] = &[
    "CTU_DINT",
    "CTD_DINT",
    "CTUD_DINT",
    "CTU_LINT",
    "CTU_UDINT",
    "CTU_ULINT",
    "RTC",
];
const MODEL_ELEMENTARY: &[&str] = &["BOOL", "INT", "DINT", "REAL", "TIME"];

/// True when a declared type (as the reader writes it into the syntax) is elementary, not a
/// function block type.
pub fn is_elementary(ty: &str) -> bool {
    MODEL_ELEMENTARY.contains(&ty)
}

/// Reads the interface of POU `pou` (its `interface` element; none is an empty interface).
pub fn interface(tc6: Tc6, node: Option<Node>, pou: &str, known: &Known) -> R<Interface> {
    let mut out = Interface::default();
    let Some(node) = node else { return Ok(out) };
    for list in tc6.elements(node) {
        let kind = list.tag_name().name();
        let place = format!("pou {pou}, {kind}");
        match kind {
            "returnType" => {
                return Err(error(
                    origin(list),
                    &place,
                    format!("POU `{pou}` is a function (it has a return type): functions are not supported yet"),
                ))
            }
            "inputVars" | "outputVars" | "localVars" | "tempVars" | "globalVars" => {
                let class = match kind {
                    "inputVars" => VarClass::Input,
                    "outputVars" => VarClass::Output,
                    _ => VarClass::Default,
                };
                let vars = var_list(tc6, list, class, &place, known, &mut out.mapped)?;
                match kind {
                    "inputVars" => out.inputs.extend(vars),
                    "outputVars" => out.outputs.extend(vars),
                    "globalVars" => out.globals.extend(vars),
                    _ => out.locals.extend(vars),
                }
            }
            "externalVars" => {
                for v in tc6.children(list, "variable") {
                    let name = super::xml::attr(v, "name", &place)?;
                    out.externals.push(identifier(name, "variable", v, &place)?);
                }
            }
            "inOutVars" | "accessVars" => {
                return Err(error(
                    origin(list),
                    &place,
                    format!("{kind} (VAR_IN_OUT, VAR_ACCESS) of POU `{pou}` are not supported yet"),
                ))
            }
            "documentation" | "addData" => {}
            other => {
                return Err(error(
                    origin(list),
                    &place,
                    format!("unknown element `{other}` in the interface of POU `{pou}`"),
                ))
            }
        }
    }
    Ok(out)
}

/// The variables of one `varList` (`class` for all of them; an address may override it).
pub fn var_list(
    tc6: Tc6,
    list: Node,
    class: VarClass,
    place: &str,
    known: &Known,
    mapped: &mut Vec<Mapped>,
) -> R<Vec<Var<'static>>> {
    let mut out = Vec::new();
    for v in tc6.children(list, "variable") {
        out.push(variable(tc6, v, class, place, known, mapped)?);
    }
    Ok(out)
}

fn variable(
    tc6: Tc6,
    v: Node,
    class: VarClass,
    place: &str,
    known: &Known,
    mapped: &mut Vec<Mapped>,
) -> R<Var<'static>> {
    let raw = super::xml::attr(v, "name", place)?;
    let name = identifier(raw, "variable", v, place)?;
    let place = format!("{place}, variable {name}");
    let class = match v.attribute("address").map(str::trim) {
        Some(a) if a.starts_with("%I") => VarClass::Input,
        Some(a) if a.starts_with("%Q") => VarClass::Output,
        _ => class,
    };
    let ty_node = tc6
        .child(v, "type")
        .ok_or_else(|| error(origin(v), &place, format!("variable `{name}` has no type")))?;
    let (mut ty, is_fb) = type_name(tc6, ty_node, &name, &place, known)?;
    let mut text = false;
    if let Some(&(from, to)) = MAPPED.iter().find(|(f, _)| *f == ty) {
        text = from.eq_ignore_ascii_case("string") || from.eq_ignore_ascii_case("wstring");
        mapped.push(Mapped {
            var: name.clone(),
            origin: origin(v),
            from: from.to_ascii_uppercase(),
            to,
            text,
        });
        ty = to.to_owned();
    }
    let init = match tc6.child(v, "initialValue") {
        // A string's initial value has no value in the model (the stand-in starts at 0).
        Some(_) if text => None,
        Some(iv) if is_fb => {
            return Err(error(
                origin(iv),
                &place,
                format!("function block instance `{name}` has an initial value"),
            ))
        }
        Some(iv) => Some(Box::new(initial_value(tc6, iv, &name, &place)?)),
        None => None,
    };
    let at = origin(v);
    Ok(Var {
        origin: at,
        name: Located {
            value: Cow::Owned(name),
            origin: at,
        },
        ty: Located {
            value: Cow::Owned(ty),
            origin: origin(ty_node),
        },
        class: Located {
            value: class,
            origin: at,
        },
        init,
        problem: None,
    })
}

/// The type's name and whether it is (or may be) a function block type.
fn type_name(tc6: Tc6, ty: Node, var: &str, place: &str, known: &Known) -> R<(String, bool)> {
    let Some(t) = tc6.elements(ty).next() else {
        return Err(error(
            origin(ty),
            place,
            format!("variable `{var}` has an empty type"),
        ));
    };
    let tag = t.tag_name().name();
    if MODEL_ELEMENTARY.contains(&tag) || MAPPED.iter().any(|(f, _)| *f == tag) {
        return Ok((tag.to_owned(), false));
    }
    if tag != "derived" {
        return Err(error(
            origin(t),
            place,
            format!("type {tag} of variable `{var}` is not supported yet (supported: {}, the other elementary types of IEC 61131-3, and function block types)", MODEL_ELEMENTARY.join(", ")),
        ));
    }
    let name = super::xml::attr(t, "name", place)?;
    let name = identifier(name, "type", t, place)?;
    if known.data_types.contains(name.as_str()) {
        return Err(error(
            origin(t),
            place,
            format!("variable `{var}` has the user data type `{name}`: data types (types/dataTypes) are not supported yet"),
        ));
    }
    if OTHER_STD_FBS.contains(&name.as_str()) {
        return Err(error(
            origin(t),
            place,
            format!("variable `{var}` is an instance of the standard function block {name}, which is not supported yet (supported: {})", MODEL_FBS.join(", ")),
        ));
    }
    Ok((name, true))
}

/// `initialValue/simpleValue@value` as an operand (a boolean in any case, a number, a TIME
/// literal).
fn initial_value(tc6: Tc6, iv: Node, var: &str, place: &str) -> R<Operand<'static>> {
    let simple = tc6.child(iv, "simpleValue").ok_or_else(|| {
        error(
            origin(iv),
            place,
            format!("the initial value of `{var}` is not a simple value (array and structure values are not supported yet)"),
        )
    })?;
    let text = super::xml::attr(simple, "value", place)?;
    let value = literal(text).ok_or_else(|| {
        error(
            origin(simple),
            place,
            format!(
                "initial value `{text}` of `{var}` is not a boolean, a number or a TIME literal"
            ),
        )
    })?;
    Ok(Located {
        value,
        origin: origin(simple),
    })
}

/// A literal as IEC 61131-3 writes it (TRUE/FALSE in any case, integers and reals with `_`
/// separators, based integers `16#FF`, typed literals `INT#5`, `T#…`/`TIME#…`), or `None`.
pub fn literal(text: &str) -> Option<Scalar<'static>> {
    let t = text.trim();
    if t.eq_ignore_ascii_case("true") {
        return Some(Scalar::Bool(true));
    }
    if t.eq_ignore_ascii_case("false") {
        return Some(Scalar::Bool(false));
    }
    if crate::syntax::is_time_literal(t) {
        return Some(Scalar::Str(Cow::Owned(t.to_owned())));
    }
    if let Some((prefix, rest)) = t.split_once('#') {
        let p = prefix.to_ascii_uppercase();
        // A typed literal (`INT#5`, `BOOL#TRUE`, IEC 61131-3 6.3.2): the value without its type.
        if MODEL_ELEMENTARY.contains(&p.as_str())
            || MAPPED.iter().any(|(f, _)| f.eq_ignore_ascii_case(&p))
        {
            return literal(rest);
        }
        // A based integer (`16#FF`, `8#17`, `2#1010`).
        let radix = match p.as_str() {
            "2" => 2,
            "8" => 8,
            "16" => 16,
            _ => return None,
        };
        let digits: String = rest.chars().filter(|c| *c != '_').collect();
        return i64::from_str_radix(&digits, radix)
            .ok()
            .map(|i| Scalar::Number(i.into()));
    }
    let digits: String = t.chars().filter(|c| *c != '_').collect();
    if !digits.starts_with(|c: char| c.is_ascii_digit() || c == '-' || c == '+') {
        return None;
    }
    if let Ok(i) = digits.parse::<i64>() {
        return Some(Scalar::Number(i.into()));
    }
    let f: f64 = digits.parse().ok()?;
    serde_json::Number::from_f64(f).map(Scalar::Number)
}

/// A name made from the file (owned), at `origin`.
pub fn name(s: impl Into<String>, at: crate::diag::Origin) -> Name<'static> {
    Located {
        value: Cow::Owned(s.into()),
        origin: at,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn literals_read_as_iec_writes_them() {
        assert_eq!(literal("True"), Some(Scalar::Bool(true)));
        assert_eq!(literal(" FALSE "), Some(Scalar::Bool(false)));
        assert_eq!(literal("1_000"), Some(Scalar::Number(1000.into())));
        assert_eq!(literal("-3"), Some(Scalar::Number((-3).into())));
        assert_eq!(
            literal("2.5"),
            Some(Scalar::Number(serde_json::Number::from_f64(2.5).unwrap()))
        );
        assert_eq!(literal("T#1s"), Some(Scalar::Str(Cow::Borrowed("T#1s"))));
        assert_eq!(literal("blup"), None);
        assert_eq!(literal("INT#5"), Some(Scalar::Number(5.into())));
        assert_eq!(literal("BOOL#TRUE"), Some(Scalar::Bool(true)));
        assert_eq!(literal("16#FF"), Some(Scalar::Number(255.into())));
        assert_eq!(literal("UINT#2#1010"), Some(Scalar::Number(10.into())));
        assert_eq!(
            literal("TIME#2s"),
            Some(Scalar::Str(Cow::Borrowed("TIME#2s")))
        );
        assert_eq!(literal("FOO#5"), None);
    }
}

/// The one note of a file whose variables' types were mapped (`mapped`: with the POU, or
/// `None` for a global), or none.
pub fn mapped_note(mapped: &[(Option<String>, Mapped)]) -> Option<super::xml::Note> {
    let first = mapped.first()?;
    let list: Vec<String> = mapped
        .iter()
        .map(|(pou, m)| {
            let name = pou
                .as_ref()
                .map_or(m.var.clone(), |p| format!("{p}.{}", m.var));
            format!("{name} {} → {}", m.from, m.to)
        })
        .collect();
    Some(super::xml::Note {
        origin: first.1.origin,
        message: format!("elementary types the model lacks are read as one it has: {}; `run` computes them at the model's width (INT 16-bit, DINT 32-bit, signed; REAL 32-bit), so it differs from a PLC where a value leaves the declared type's range or needs LREAL precision, and a string has no value (it stands in as a DINT 0)", list.join(", ")),
    })
}
