//! POU interfaces and global variable lists (`interface/inputVars` …, `globalVars`) → the
//! syntax's variable declarations, with their types and initial values (IEC 61131-3 6.5; TC6
//! `varList`, `variable`, `type`, `initialValue`).
//!
//! Invariants: every declaration that is read becomes a [`Var`] or an error naming it and its
//! line; an external declaration (`externalVars`) is a reference to a global of that name and
//! declares nothing (names resolve to the program's variables). Located variables take their
//! class from the address: `%I…` is an input, `%Q…` an output (written by the scan / read by it).
//!
//! Every elementary type of IEC 61131-3 Table 10 but the strings, LTIME and the dates and
//! times of day is the model's own (BOOL, SINT … LINT, USINT … ULINT, REAL, LREAL, BYTE …
//! LWORD, TIME). Those it lacks are read as one it has ([`super::elementary::MAPPED`]), and each such variable is
//! recorded ([`Mapped`]) for the POU's note.
//!
//! A user data type (or a library one, [`super::data_types`]) is read as its base: an alias or
//! subrange as its elementary type, an enumeration as INT, an array (named or declared in
//! place) of an elementary type as one variable per element (`a[3]`, its initial values from an
//! `arrayValue`), any other array as a whole variable without a value; each such variable is
//! recorded too, with the type's description. A structure (named or declared in place) is flattened into one variable
//! per elementary field, `Motor.Speed` ([`super::data_types`]), each read as above.
//!
//! `VAR_IN_OUT` (`inOutVars`) is read as an input of the POU: a POU no call passes an argument
//! to (a program, which the configuration calls without arguments; a function block whose calls
//! leave the in-out unconnected) uses its own variable, as matiec's reference then points at
//! nothing else; a call that wires an in-out is refused by name ([`super::wiring`]), since
//! passing by reference is not modelled.
//!
//! Deliberately not here: structured initial values of elementary variables and `VAR_ACCESS`
//! — each an error naming the variable, until the model has them.

use super::data_types::{Base, DataType, DataTypes};
use super::elementary::{is_elementary_tag, model_type_of, MAPPED, MODEL_ELEMENTARY};
use super::xml::{error, identifier, origin, Tc6, R};
use plc_syntax::{Located, Name, Operand, Scalar, Var, VarClass};
use roxmltree::Node;
use std::borrow::Cow;

/// The names of the project's own data types, function blocks and functions, for messages.
pub(super) struct Known {
    pub data_types: DataTypes,
}

/// The lists of an interface, in the order the standard's keywords name them.
#[derive(Default)]
pub(super) struct Interface {
    pub inputs: Vec<Var<'static>>,
    pub outputs: Vec<Var<'static>>,
    pub locals: Vec<Var<'static>>,
    pub globals: Vec<Var<'static>>,
    /// The names of `externalVars` (references to globals).
    pub externals: Vec<String>,
    /// The variables whose elementary type was mapped onto one of the model's.
    pub mapped: Vec<Mapped>,
    /// Where the `returnType` of a function is.
    pub returns: Option<plc_diag::Origin>,
    /// The model type of a function's result, when it has one the model can read.
    pub return_ty: Option<String>,
    /// The declarations of the `externalVars`, and those of them whose type was mapped.
    pub external_decls: Vec<Var<'static>>,
    pub external_mapped: Vec<Mapped>,
    /// The initial values of function block instances (`T0 : TON := (PT := T#1s)`).
    pub fb_inits: Vec<FbInit>,
}

/// The initial value of a function block instance (IEC 61131-3 6.5.1.4 Table 14, TC6
/// `initialValue/structValue`): a value for each member it names, in file order. A graphical
/// call of the instance that leaves an input unconnected reads it (`super::fbd`,
/// `super::ld_block`); [`super::project`] makes `run` refuse a POU where one cannot apply.
#[derive(Clone, Debug)]
pub(super) struct FbInit {
    pub instance: String,
    /// The instance's function block type.
    pub fb: String,
    pub origin: plc_diag::Origin,
    pub members: Vec<(String, Operand<'static>)>,
}

/// A variable whose IEC 61131-3 elementary type the model lacks, read as one it has.
#[derive(Clone, Debug)]
pub(super) struct Mapped {
    pub var: String,
    pub origin: plc_diag::Origin,
    pub from: String,
    pub to: &'static str,
    /// A string or an array: the model has no value for it (the variable stands in as a DINT
    /// 0).
    pub text: bool,
    /// The data type's description when `from` is a derived type ([`DataType::describe`]).
    pub via: Option<String>,
}

/// Reads the interface of POU `pou` (its `interface` element; none is an empty interface).
pub(super) fn interface(tc6: Tc6, node: Option<Node>, pou: &str, known: &Known) -> R<Interface> {
    let mut out = Interface::default();
    let Some(node) = node else { return Ok(out) };
    for list in tc6.elements(node) {
        let kind = list.tag_name().name();
        let place = format!("pou {pou}, {kind}");
        match kind {
            // A function's result type (whether the POU may have one is the project's check).
            "returnType" => {
                out.returns = Some(origin(list));
                out.return_ty = match type_name(tc6, list, "result", &place, known)? {
                    Ty::Elementary(t) => model_type_of(&t).map(str::to_owned),
                    Ty::Data(d) => model_type_of(&data_base(&d)).map(str::to_owned),
                    Ty::Fb(_) => None,
                };
            }
            "inputVars" | "inOutVars" | "outputVars" | "localVars" | "tempVars" | "globalVars" => {
                let class = match kind {
                    "inputVars" | "inOutVars" => VarClass::Input,
                    "outputVars" => VarClass::Output,
                    _ => VarClass::Default,
                };
                let (m, f) = (&mut out.mapped, &mut out.fb_inits);
                let vars = var_list(tc6, list, class, &place, known, m, f)?;
                match kind {
                    "inputVars" | "inOutVars" => out.inputs.extend(vars),
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
                // Their declarations, for a global the file does not declare (an editor
                // extension's); one that cannot be read is left to the global's.
                let mut mapped = Vec::new();
                let mut inits = Vec::new();
                let class = VarClass::Default;
                if let Ok(vars) = var_list(tc6, list, class, &place, known, &mut mapped, &mut inits)
                {
                    out.external_decls.extend(vars);
                    out.external_mapped.extend(mapped);
                }
            }
            "accessVars" => {
                return Err(error(
                    origin(list),
                    &place,
                    format!("{kind} (VAR_ACCESS) of POU `{pou}` are not supported yet"),
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
pub(super) fn var_list(
    tc6: Tc6,
    list: Node,
    class: VarClass,
    place: &str,
    known: &Known,
    mapped: &mut Vec<Mapped>,
    fb_inits: &mut Vec<FbInit>,
) -> R<Vec<Var<'static>>> {
    let mut out = Vec::new();
    for v in tc6.children(list, "variable") {
        out.extend(variable(tc6, v, class, place, known, mapped, fb_inits)?);
    }
    Ok(out)
}

/// The variables one declaration `v` makes: itself, or, for a structure, one per leaf field
/// ([`super::data_types`]).
fn variable(
    tc6: Tc6,
    v: Node,
    class: VarClass,
    place: &str,
    known: &Known,
    mapped: &mut Vec<Mapped>,
    fb_inits: &mut Vec<FbInit>,
) -> R<Vec<Var<'static>>> {
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
    let ty = type_name(tc6, ty_node, &name, &place, known)?;
    let decl = Decl {
        v,
        class,
        ty_node,
        place: &place,
    };
    let Ty::Data(d) = &ty else {
        let iv = tc6.child(v, "initialValue");
        let simple = iv
            .and_then(|iv| tc6.child(iv, "simpleValue"))
            .and_then(|s| s.attribute("value"));
        if let (Ty::Fb(fb), Some(value)) = (&ty, simple) {
            // A function block instance has no simple initial value (IEC 61131-3 6.5.1.4): the
            // type is one the file names and does not define, a library's enumeration most
            // often (`LEVEL : LOGLEVEL := DEBUG`, Beremiz's LOGLEVEL). It is read as the type
            // nobody defines (a black box, [`super::project`]), its initial value not read.
            mapped.push(Mapped {
                var: name.clone(),
                origin: origin(v),
                from: fb.clone(),
                to: "DINT",
                text: true,
                via: Some(format!("a type the file does not define, given the simple initial value `{}`, which is not read: not a function block instance, whose initial value would be structured", value.trim())),
            });
            return Ok(vec![one(tc6, &decl, name, ty, None, None, mapped)?]);
        }
        if let (Ty::Fb(fb), Some(iv)) = (&ty, iv) {
            fb_inits.push(fb_init(tc6, iv, &name, fb, &place)?);
            return Ok(vec![one(tc6, &decl, name, ty, None, None, mapped)?]);
        }
        return Ok(vec![one(tc6, &decl, name, ty, iv, None, mapped)?]);
    };
    if let Base::Array(a) = &d.base {
        let mut a = (**a).clone();
        if let Some(iv) = tc6.child(v, "initialValue") {
            let av = tc6.child(iv, "arrayValue").ok_or_else(|| {
                error(
                    origin(iv),
                    &place,
                    format!(
                        "the initial value of array `{name}` is not an array value (`[1, 2, 3]`)"
                    ),
                )
            })?;
            a.init = super::data_types::array_value(tc6, av, a.len(), &name, &place)?;
        }
        mapped.push(Mapped {
            var: name.clone(),
            origin: origin(v),
            from: d.name.clone(),
            to: "its elements",
            text: false,
            via: Some(d.describe()),
        });
        let mut out = Vec::new();
        for el in super::data_types::elements(&name, &a) {
            let ty = if el.elementary {
                Ty::Elementary(data_base(&el.ty))
            } else {
                Ty::Data(el.ty)
            };
            out.push(one(tc6, &decl, el.path, ty, None, el.init, mapped)?);
        }
        return Ok(out);
    }
    let Base::Struct(members) = &d.base else {
        let iv = tc6.child(v, "initialValue");
        return Ok(vec![one(tc6, &decl, name, ty, iv, None, mapped)?]);
    };
    let mut members = members.clone();
    if let Some(iv) = tc6.child(v, "initialValue") {
        let sv = tc6.child(iv, "structValue").ok_or_else(|| {
            error(
                origin(iv),
                &place,
                format!("the initial value of structure `{name}` is not a structured value"),
            )
        })?;
        super::data_types::apply_value(tc6, &mut members, sv, &name, &place)?;
    }
    mapped.push(Mapped {
        var: name.clone(),
        origin: origin(v),
        from: d.name.clone(),
        to: "its fields",
        text: false,
        via: Some(d.describe()),
    });
    let mut out = Vec::new();
    for leaf in super::data_types::flatten(&name, &members) {
        let ty = if leaf.elementary {
            Ty::Elementary(data_base(&leaf.ty))
        } else {
            Ty::Data(leaf.ty)
        };
        out.push(one(tc6, &decl, leaf.path, ty, None, leaf.init, mapped)?);
    }
    Ok(out)
}

/// Where a declaration is, for the variables it makes.
struct Decl<'d, 'a, 'i> {
    v: Node<'a, 'i>,
    class: VarClass,
    ty_node: Node<'a, 'i>,
    place: &'d str,
}

/// One model variable `name` of type `ty` of declaration `d`, with its initial value: the
/// declaration's `iv`, else a structure field's `field_init`, else its data type's.
fn one(
    tc6: Tc6,
    d: &Decl,
    name: String,
    ty: Ty,
    iv: Option<Node>,
    field_init: Option<(String, plc_diag::Origin)>,
    mapped: &mut Vec<Mapped>,
) -> R<Var<'static>> {
    let (v, class, ty_node, place) = (d.v, d.class, d.ty_node, d.place);
    let (mut ty, is_fb, mut data) = match ty {
        Ty::Elementary(t) => (t, false, None),
        Ty::Fb(t) => (t, true, None),
        Ty::Data(d) => (data_base(&d), false, Some(d)),
    };
    // A field's own initial value comes before its type's.
    let mut field_init = field_init;
    if let (Some(i), Some(d)) = (&field_init, &mut data) {
        d.init = Some(i.clone());
        field_init = None;
    }
    let mut text = data
        .as_ref()
        .is_some_and(|d| matches!(d.base, Base::Whole(_)));
    if let Some(&(from, to)) = MAPPED.iter().find(|(f, _)| *f == ty) {
        // A WSTRING has no value in the model (a STRING has: `string` reads as STRING).
        text |= from.eq_ignore_ascii_case("wstring");
        ty = to.to_owned();
        if data.is_none() && to != "STRING" {
            mapped.push(Mapped {
                var: name.clone(),
                origin: origin(v),
                from: from.to_ascii_uppercase(),
                to,
                text,
                via: None,
            });
        }
    }
    if let Some(d) = &data {
        mapped.push(Mapped {
            var: name.clone(),
            origin: origin(v),
            from: d.name.clone(),
            to: if text { "DINT" } else { model_type(&ty) },
            text,
            via: Some(d.describe()),
        });
    }
    let init = match (iv, &data) {
        // A string's or array's initial value has no value in the model (the stand-in starts
        // at 0).
        (Some(_), _) if text => None,
        (Some(iv), _) if is_fb => {
            return Err(error(
                origin(iv),
                place,
                format!("function block instance `{name}` has an initial value"),
            ))
        }
        (Some(iv), Some(d)) if matches!(d.base, Base::Enum(_)) => {
            Some(Box::new(enum_initial(tc6, iv, d, &name, place)?))
        }
        (Some(iv), _) if ty == "STRING" => Some(Box::new(string_initial(tc6, iv, &name, place)?)),
        (Some(iv), _) => Some(Box::new(initial_value(tc6, iv, &name, place)?)),
        (None, Some(d)) if !text => type_initial(d, &name, place)?.map(Box::new),
        (None, None) if !text => match field_init {
            Some((text, at)) => Some(Box::new(literal_operand(&text, at, &name, place)?)),
            None => None,
        },
        (None, _) => None,
    };
    // `0` / `1` for a BOOL are FALSE / TRUE (IEC 61131-3 6.3.2: the BOOL literals 0 and 1).
    let init = init.map(|mut i| {
        if ty == "BOOL" {
            if let Scalar::Number(n) = &i.value {
                match n.as_u64() {
                    Some(0) => i.value = Scalar::Bool(false),
                    Some(1) => i.value = Scalar::Bool(true),
                    _ => {}
                }
            }
        }
        i
    });
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

/// A variable's declared type.
enum Ty {
    /// An elementary type as TC6 writes it.
    Elementary(String),
    /// A function block type (the project's or a standard one).
    Fb(String),
    /// A data type of the project or a library, or an array or structure declared in place.
    Data(DataType),
}

/// The TC6 name of the elementary type a data type is read as (an enumeration as INT; an array
/// or structure as `string`, the stand-in without a value: a structure's variables are its
/// fields, this is only for a function's result).
fn data_base(d: &DataType) -> String {
    match &d.base {
        Base::Elementary(t) => t.clone(),
        Base::Enum(_) => "INT".to_owned(),
        // An array (or a structure not flattened) has no value: the DINT stand-in.
        Base::Whole(_) | Base::Struct(_) | Base::Array(_) => "DINT".to_owned(),
    }
}

/// The model's type name as a static string.
fn model_type(ty: &str) -> &'static str {
    MODEL_ELEMENTARY
        .iter()
        .find(|t| **t == ty)
        .copied()
        .unwrap_or("DINT")
}

fn type_name(tc6: Tc6, ty: Node, var: &str, place: &str, known: &Known) -> R<Ty> {
    let Some(t) = tc6.elements(ty).next() else {
        return Err(error(
            origin(ty),
            place,
            format!("variable `{var}` has an empty type"),
        ));
    };
    let tag = t.tag_name().name();
    if is_elementary_tag(tag) {
        return Ok(Ty::Elementary(tag.to_owned()));
    }
    match tag {
        "array" => {
            return Ok(Ty::Data(super::data_types::array(
                tc6,
                &std::collections::HashMap::new(),
                Some(&known.data_types),
                "ARRAY",
                t,
                0,
                place,
            )?))
        }
        // A subrange or enumeration declared in place (`x : INT (0..10)`, `c : (RED, GREEN)`).
        "subrangeSigned" | "subrangeUnsigned" | "enum" => {
            let shown = if tag == "enum" { "ENUM" } else { "SUBRANGE" };
            let d = super::data_types::base(
                tc6,
                &std::collections::HashMap::new(),
                shown,
                t,
                0,
                place,
            )?;
            return Ok(Ty::Data(d));
        }
        "struct" => {
            let members = super::data_types::members(
                tc6,
                &std::collections::HashMap::new(),
                Some(&known.data_types),
                "STRUCT",
                t,
                0,
                place,
            )?;
            return Ok(Ty::Data(DataType {
                name: "STRUCT".to_owned(),
                base: Base::Struct(members),
                range: None,
                init: None,
                library: None,
            }));
        }
        "derived" => {}
        // CODESYS's POINTER TO and REFERENCE TO: an address, which plc-deps does not follow: a
        // type nobody defines (the black box of `super::project`), named after what it points to.
        "pointer" | "reference" => {
            let to = tc6
                .elements(t)
                .find(|c| c.tag_name().name() == "baseType")
                .and_then(|b| tc6.elements(b).next())
                .map(|b| match b.tag_name().name() {
                    "derived" => b.attribute("name").unwrap_or("ANY").to_owned(),
                    other => other.to_owned(),
                })
                .unwrap_or_else(|| "ANY".to_owned());
            let kind = if tag == "pointer" { "POINTER" } else { "REFERENCE" };
            return Ok(Ty::Fb(format!(
                "{kind}_TO_{}",
                to.replace(|c: char| !c.is_ascii_alphanumeric(), "_")
            )));
        }
        _ => return Err(error(
            origin(t),
            place,
            format!("type {tag} of variable `{var}` is not supported yet (supported: {}, the other elementary types of IEC 61131-3, data types, arrays, structures and function block types)", MODEL_ELEMENTARY.join(", ")),
        )),
    }
    let name = super::xml::attr(t, "name", place)?;
    let name =
        super::xml::type_reference(name, &|ty| known.data_types.get(ty).is_some(), t, place)?;
    if let Some(d) = known.data_types.get(&name) {
        return Ok(Ty::Data(d));
    }
    Ok(Ty::Fb(name))
}

/// The initial value `iv` of function block instance `var` of type `fb`: a structured value
/// whose members are simple values (`(PT := T#1s, PV := 3)`).
fn fb_init(tc6: Tc6, iv: Node, var: &str, fb: &str, place: &str) -> R<FbInit> {
    let sv = tc6.child(iv, "structValue").ok_or_else(|| {
        error(
            origin(iv),
            place,
            format!("the initial value of function block instance `{var}` is not a structured value (`(PT := T#1s)`)"),
        )
    })?;
    let mut members = Vec::new();
    for m in tc6.children(sv, "value") {
        let member = super::xml::attr(m, "member", place)?.trim().to_owned();
        let simple = tc6.child(m, "simpleValue").ok_or_else(|| {
            error(
                origin(m),
                place,
                format!("the initial value of `{var}.{member}` is not a simple value (nested structured and array values of an instance are not supported yet)"),
            )
        })?;
        let text = super::xml::attr(simple, "value", place)?;
        let shown = format!("{var}.{member}");
        // A STRING member's literal (`FriendlyName := 'Button 1'`) as STRING variables have it.
        let t = text.trim();
        let value = if t.len() >= 2 && t.starts_with('\'') && t.ends_with('\'') {
            Located {
                value: Scalar::Str(Cow::Owned(text.trim().to_owned())),
                origin: origin(simple),
            }
        } else if let Some((ty, v)) = text
            .trim()
            .split_once(['.', '#'])
            .filter(|(t, v)| super::xml::is_identifier(t) && super::xml::is_identifier(v))
        {
            // An enumeration value (`E_MODE.Auto`, CODESYS; `E_MODE#Auto`, IEC 61131-3).
            Located {
                value: Scalar::Str(Cow::Owned(format!("{ty}#{v}"))),
                origin: origin(simple),
            }
        } else {
            literal_operand(text, origin(simple), &shown, place)?
        };
        members.push((member, value));
    }
    Ok(FbInit {
        instance: var.to_owned(),
        fb: fb.to_owned(),
        origin: origin(iv),
        members,
    })
}

/// The initial value of enumeration variable `var`: one of its type's values.
fn enum_initial(tc6: Tc6, iv: Node, d: &DataType, var: &str, place: &str) -> R<Operand<'static>> {
    let simple = tc6.child(iv, "simpleValue").ok_or_else(|| {
        error(
            origin(iv),
            place,
            format!("the initial value of `{var}` is not a simple value"),
        )
    })?;
    let text = super::xml::attr(simple, "value", place)?;
    enum_operand(d, text, origin(simple), var, place)
}

fn enum_operand(
    d: &DataType,
    text: &str,
    at: plc_diag::Origin,
    var: &str,
    place: &str,
) -> R<Operand<'static>> {
    let i = DataTypes::enum_value(d, text).ok_or_else(|| {
        error(
            at,
            place,
            format!(
                "initial value `{text}` of `{var}` is not a value of enumeration `{}`",
                d.name
            ),
        )
    })?;
    Ok(Located {
        value: Scalar::Number(i.into()),
        origin: at,
    })
}

/// The initial value a variable of data type `d` gets from its type (IEC 61131-3 6.4.4), if any.
fn type_initial(d: &DataType, var: &str, place: &str) -> R<Option<Operand<'static>>> {
    let Some((text, at)) = &d.init else {
        // An enumeration without an initial value starts at its first value (IEC 61131-3
        // 6.4.4.2), which named values may make other than 0.
        if let Base::Enum(v) = &d.base {
            if let Some(&(_, first)) = v.first().filter(|f| f.1 != 0) {
                return Ok(Some(Located {
                    value: Scalar::Number(first.into()),
                    origin: plc_diag::Origin::default(),
                }));
            }
        }
        return Ok(None);
    };
    if matches!(d.base, Base::Enum(_)) {
        return enum_operand(d, text, *at, var, place).map(Some);
    }
    let value = literal(text).ok_or_else(|| {
        error(
            *at,
            place,
            format!("initial value `{text}` of data type `{}` is not a boolean, a number, a TIME or a date and time literal", d.name),
        )
    })?;
    Ok(Some(Located { value, origin: *at }))
}

/// Initial value `text` (at `at`) of `var` as an operand (a boolean in any case, a number, a
/// TIME literal): a variable's own or one a structure gives its elementary field.
fn literal_operand(
    text: &str,
    at: plc_diag::Origin,
    var: &str,
    place: &str,
) -> R<Operand<'static>> {
    let value = literal(text).ok_or_else(|| {
        error(
            at,
            place,
            format!(
                "initial value `{text}` of `{var}` is not a boolean, a number, a TIME or a date and time literal"
            ),
        )
    })?;
    Ok(Located { value, origin: at })
}

/// `initialValue/simpleValue@value` as an operand ([`literal_operand`]).
/// The initial value of STRING variable `var`: a literal `'…'`, or (as Beremiz's editor saves
/// what was typed without quotes, `blup`) the text itself.
fn string_initial(tc6: Tc6, iv: Node, var: &str, place: &str) -> R<Operand<'static>> {
    let simple = tc6.child(iv, "simpleValue").ok_or_else(|| {
        error(
            origin(iv),
            place,
            format!("the initial value of `{var}` is not a simple value"),
        )
    })?;
    let text = super::xml::attr(simple, "value", place)?.trim();
    let lit = if text.starts_with('\'') {
        text.to_owned()
    } else {
        plc_model::string_literal(text.as_bytes())
    };
    let at = origin(simple);
    Ok(Located {
        value: Scalar::Str(Cow::Owned(lit)),
        origin: at,
    })
}

fn initial_value(tc6: Tc6, iv: Node, var: &str, place: &str) -> R<Operand<'static>> {
    let simple = tc6.child(iv, "simpleValue").ok_or_else(|| {
        error(
            origin(iv),
            place,
            format!("the initial value of `{var}` is not a simple value (array and structure values are not supported yet)"),
        )
    })?;
    let text = super::xml::attr(simple, "value", place)?;
    literal_operand(text, origin(simple), var, place)
}

/// A literal as IEC 61131-3 writes it (TRUE/FALSE in any case, integers and reals with `_`
/// separators, based integers `16#FF`, typed literals `INT#5`, `T#…`/`TIME#…`), or `None`.
pub(super) fn literal(text: &str) -> Option<Scalar<'static>> {
    let t = text.trim();
    if t.eq_ignore_ascii_case("true") {
        return Some(Scalar::Bool(true));
    }
    if t.eq_ignore_ascii_case("false") {
        return Some(Scalar::Bool(false));
    }
    if plc_syntax::is_time_literal(t) {
        return Some(Scalar::Str(Cow::Owned(t.to_owned())));
    }
    // A date, time of day or date and time: the integer the model holds for it (seconds since
    // 1970 for DATE and DT, ms since midnight for TOD; [`plc_model::parse_date_literal`]).
    if let Some((_, v)) = plc_model::parse_date_literal(t) {
        return Some(Scalar::Number(v.into()));
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
        return u64::from_str_radix(&digits, radix)
            .ok()
            .map(|i| Scalar::Number(i.into()));
    }
    let digits: String = t.chars().filter(|c| *c != '_').collect();
    if !digits.starts_with(|c: char| c.is_ascii_digit() || c == '-' || c == '+') {
        return None;
    }
    // Exact up to the 64-bit types' ranges (ULINT up to 2^64 - 1).
    if let Ok(i) = digits.parse::<i64>() {
        return Some(Scalar::Number(i.into()));
    }
    if let Ok(u) = digits.parse::<u64>() {
        return Some(Scalar::Number(u.into()));
    }
    let f: f64 = digits.parse().ok()?;
    serde_json::Number::from_f64(f).map(Scalar::Number)
}

/// A name made from the file (owned), at `origin`.
pub(super) fn name(s: impl Into<String>, at: plc_diag::Origin) -> Name<'static> {
    Located {
        value: Cow::Owned(s.into()),
        origin: at,
    }
}

/// The notes of a file whose variables' types were mapped (`mapped`: with the POU, or `None`
/// for a global): one for the elementary types, one for the data types.
pub(super) fn mapped_notes(mapped: &[(Option<String>, Mapped)]) -> Vec<super::xml::Note> {
    let (derived, elementary): (Vec<_>, Vec<_>) =
        mapped.iter().cloned().partition(|(_, m)| m.via.is_some());
    mapped_note(&elementary)
        .into_iter()
        .chain(derived_note(&derived))
        .collect()
}

fn qualified(pou: &Option<String>, m: &Mapped) -> String {
    pou.as_ref()
        .map_or(m.var.clone(), |p| format!("{p}.{}", m.var))
}

/// The one note of the variables whose type is a data type.
fn derived_note(mapped: &[(Option<String>, Mapped)]) -> Option<super::xml::Note> {
    let first = mapped.first()?;
    // By type, in the order of their first variable.
    let mut groups: Vec<(&Mapped, Vec<String>)> = Vec::new();
    for (pou, m) in mapped {
        match groups
            .iter_mut()
            .find(|(g, _)| g.from == m.from && g.via == m.via)
        {
            Some((_, vars)) => vars.push(qualified(pou, m)),
            None => groups.push((m, vec![qualified(pou, m)])),
        }
    }
    let list: Vec<String> = groups
        .iter()
        .map(|(m, vars)| {
            format!(
                "{} → {} ({}): {}",
                m.from,
                m.to,
                m.via.as_deref().unwrap_or(""),
                vars.join(", ")
            )
        })
        .collect();
    Some(super::xml::Note {
        origin: first.1.origin,
        message: format!("data types are read as the model's types (IEC 61131-3 6.4.4): {}; `run` does not check subranges, an array of an elementary type is one variable per element (`a[i]`) and any other array one whole variable (a read or write of any element reads or writes it) with no value, and a structure is one variable per elementary field (`s.f`)", list.join("; ")),
    })
}

/// The one note of the variables whose elementary type was mapped.
fn mapped_note(mapped: &[(Option<String>, Mapped)]) -> Option<super::xml::Note> {
    let first = mapped.first()?;
    let list: Vec<String> = mapped
        .iter()
        .map(|(pou, m)| format!("{} {} → {}", qualified(pou, m), m.from, m.to))
        .collect();
    Some(super::xml::Note {
        origin: first.1.origin,
        message: format!("elementary types the model lacks are read as one it has: {}; `run` computes them as that type (dates and times of day as DINT, LTIME as 32-bit ms TIME), so it differs from a PLC where a value leaves that type's range, and a string has no value (it stands in as a DINT 0)", list.join(", ")),
    })
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
        // Dates as seconds since 1970, times of day as ms since midnight (IEC 61131-3 6.3.4).
        assert_eq!(literal("D#1970-01-02"), Some(Scalar::Number(86_400.into())));
        assert_eq!(literal("TOD#00:00:01.5"), Some(Scalar::Number(1500.into())));
        assert_eq!(
            literal("DT#1970-01-01-01:00:00"),
            Some(Scalar::Number(3600.into()))
        );
        assert_eq!(
            literal("LTIME#2s"),
            Some(Scalar::Str(Cow::Borrowed("LTIME#2s")))
        );
    }
}
