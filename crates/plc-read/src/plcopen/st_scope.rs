//! The names an ST body sees ([`Scope`]): its POU's variables and the globals it declares
//! external, by lower-case name, each an elementary variable, an instance of a function block
//! type, an enumeration value, a structure flattened into its fields or an array scalarised
//! into its elements ([`Decl`]; an element `a[3]` is an elementary variable too). Shared by
//! the analysis's stand-ins ([`super::st_body`]) and the lowering ([`super::st_lower`]).
//!
//! Invariant: IEC names are case-insensitive; a name found here carries its declared spelling.
//! Deliberately not here: what a statement reads or writes (the callers').

use super::textual::Read;
use std::collections::HashMap;
/// What a name of an ST body is: an elementary variable (with its type) or an instance (with
/// the BOOL-or-not field a read of it stands for, when it has one).
#[derive(Clone, Debug)]
pub(super) enum Decl {
    Elementary {
        name: String,
        ty: String,
    },
    Instance {
        name: String,
        /// The function block type's name.
        ty: String,
        read: Option<Read>,
    },
    /// A value of an enumeration data type (a constant: reading it reads no variable), with
    /// its integer (`None` when values of two enumerations have its name and different
    /// integers: then only `TYPE#VALUE` says which).
    Constant(Option<i64>),
    /// A structure (or a structure inside one) flattened into its fields: its leaf fields'
    /// names and types. Reading or writing it whole reads or writes every one.
    Structure {
        leaves: Vec<(String, String)>,
    },
    /// An array scalarised into its elements ([`super::data_types::ArrayOf`]): each element's
    /// variable (`a[3]`, its own [`Decl::Elementary`] too), subscripts and type, in declaration
    /// order. Reading or writing it whole (or through a subscript that is not constant) reads
    /// or writes every one.
    Array {
        /// The array's name as declared (`a`, `s.a`).
        name: String,
        elements: Vec<Element>,
    },
}

/// An element of a scalarised array: its variable, subscripts and type.
#[derive(Clone, Debug)]
pub(super) struct Element {
    pub name: String,
    pub index: Vec<i64>,
    pub ty: String,
}

impl Decl {
    /// The elementary variables a structure or an array stands for, with their types (`None`
    /// for any other declaration).
    pub(super) fn leaves(&self) -> Option<Vec<(String, String)>> {
        match self {
            Decl::Structure { leaves } => Some(leaves.clone()),
            Decl::Array { elements, .. } => Some(
                elements
                    .iter()
                    .map(|e| (e.name.clone(), e.ty.clone()))
                    .collect(),
            ),
            _ => None,
        }
    }
}

/// The array and subscripts of an element variable's name (`m[1,-2]` → `m`, `[1, -2]`).
pub(super) fn split_element(name: &str) -> Option<(&str, Vec<i64>)> {
    let inner = name.strip_suffix(']')?;
    let open = inner.rfind('[')?;
    let index: Option<Vec<i64>> = inner[open + 1..]
        .split(',')
        .map(|k| k.trim().parse().ok())
        .collect();
    Some((&name[..open], index?))
}

/// The declarations an ST body sees, by lower-case name.
#[derive(Clone, Default)]
pub(super) struct Scope {
    pub names: HashMap<String, Decl>,
    /// The lower-case names of the variables of class input (declared inputs, `%I` locations):
    /// the scan writes them, the program only reads them.
    pub inputs: std::collections::HashSet<String>,
    /// The enumeration values as `type#value` (lower case), with their integers.
    pub typed: HashMap<String, i64>,
    /// The project's function block types by lower-case name.
    pub fbs: HashMap<String, FbPins>,
    /// Arithmetic of types narrower than DINT is computed in DINT and cut where it is stored
    /// or passed, as matiec's C computes it in `int` (the file's editor is Beremiz or OpenPLC:
    /// [`plc_model::Dialect::int_arithmetic_in_dint`]).
    pub int_arithmetic_in_dint: bool,
    /// The project's functions by lower-case name ([`super::user_functions`]).
    pub funcs: HashMap<String, super::user_functions::FnSig>,
}

/// A function block type of the project: its inputs and outputs (name as declared, model
/// type as the reader maps it; a structure's fields flattened, `st.On`).
#[derive(Clone, Debug)]
pub(super) struct FbPins {
    pub name: String,
    pub inputs: Vec<(String, String)>,
    pub outputs: Vec<(String, String)>,
    /// Its actions called from ST (`Inst.A()`, [`super::fb_actions`]), in file order: action
    /// `k` (0-based) runs when its selector input holds `k + 1`.
    pub actions: Vec<String>,
}

impl Scope {
    /// Declares `name` of type `ty` (elementary or a function block type).
    pub(super) fn declare(&mut self, name: &str, ty: &str) {
        let decl = if super::elementary::is_elementary(ty) {
            Decl::Elementary {
                name: name.to_owned(),
                ty: ty.to_owned(),
            }
        } else {
            Decl::Instance {
                name: name.to_owned(),
                ty: ty.to_owned(),
                read: first_output(ty).map(|(f, b)| Read {
                    name: format!("{name}.{f}"),
                    bool: b,
                }),
            }
        };
        self.names.insert(name.to_ascii_lowercase(), decl);
        // An array's element (`a[3]`) makes its array known as the set of its elements.
        if let Some((array, index)) = split_element(name) {
            let entry = self
                .names
                .entry(array.to_ascii_lowercase())
                .or_insert_with(|| Decl::Array {
                    name: array.to_owned(),
                    elements: Vec::new(),
                });
            if let Decl::Array { elements, .. } = entry {
                elements.push(Element {
                    name: name.to_owned(),
                    index,
                    ty: ty.to_owned(),
                });
            }
        }
        // A structure's field (`Plant.Motor.Speed`) makes its structures (`Plant`,
        // `Plant.Motor`) known as the sets of their fields.
        let mut at = name.len();
        while let Some(dot) = name[..at].rfind('.') {
            at = dot;
            let entry = self
                .names
                .entry(name[..at].to_ascii_lowercase())
                .or_insert(Decl::Structure { leaves: Vec::new() });
            if let Decl::Structure { leaves } = entry {
                leaves.push((name.to_owned(), ty.to_owned()));
            }
        }
    }

    /// Declares value `name` (integer `value`) of enumeration `ty` (a constant), unless a
    /// variable has its name.
    pub(super) fn constant(&mut self, ty: &str, name: &str, value: i64) {
        self.typed
            .insert(format!("{ty}#{name}").to_ascii_lowercase(), value);
        let e = self
            .names
            .entry(name.to_ascii_lowercase())
            .or_insert(Decl::Constant(Some(value)));
        if let Decl::Constant(Some(v)) = e {
            if *v != value {
                *e = Decl::Constant(None);
            }
        }
    }

    /// The integer of enumeration literal `text` (`COLOR#RED`), if it is one.
    pub(super) fn enum_literal(&self, text: &str) -> Option<i64> {
        self.typed.get(&text.to_ascii_lowercase()).copied()
    }

    /// `name` as it is, or, when it is a structure, the names of its fields.
    pub(super) fn fields_of(&self, name: &str) -> Vec<String> {
        match self.get(name).and_then(Decl::leaves) {
            Some(leaves) => leaves.into_iter().map(|(n, _)| n).collect(),
            None => vec![name.to_owned()],
        }
    }

    /// The pins of the project's function block type `ty`, if it is one.
    pub(super) fn fb(&self, ty: &str) -> Option<&FbPins> {
        self.fbs.get(&ty.to_ascii_lowercase())
    }

    /// The project's function `name`, if it is one (and no variable hides it).
    pub(super) fn func(&self, name: &str) -> Option<&super::user_functions::FnSig> {
        if self.get(name).is_some() {
            return None;
        }
        self.funcs.get(&name.to_ascii_lowercase())
    }

    pub(super) fn get(&self, name: &str) -> Option<&Decl> {
        self.names.get(&name.to_ascii_lowercase())
    }

    /// What access path `path` (`s`, `s.f`, `T1.Q`) names: the declaration of the path, else
    /// of its longest declared prefix, with `true` when that is the whole path. A field of a
    /// structure that has no such field is `Err` with the message.
    pub(super) fn find(&self, path: &str) -> Result<Option<(&Decl, bool)>, String> {
        let mut at = path.len();
        loop {
            if let Some(d) = self.get(&path[..at]) {
                if let (Decl::Structure { leaves }, false) = (d, at == path.len()) {
                    let fields: Vec<&str> = leaves.iter().map(|(n, _)| &n[at + 1..]).collect();
                    return Err(format!(
                        "`{path}`: structure `{}` has no field `{}` (its fields: {})",
                        &path[..at],
                        &path[at + 1..],
                        fields.join(", ")
                    ));
                }
                return Ok(Some((d, at == path.len())));
            }
            match path[..at].rfind('.') {
                Some(dot) => at = dot,
                None => return Ok(None),
            }
        }
    }
}

/// The first output of a standard function block (IEC 61131-3 2.5.2.3), and whether it is BOOL.
fn first_output(ty: &str) -> Option<(&'static str, bool)> {
    Some(match ty {
        "TON" | "TOF" | "TP" | "CTU" | "CTD" | "R_TRIG" | "F_TRIG" => ("Q", true),
        "SR" | "RS" => ("Q1", true),
        "CTUD" => ("QU", true),
        _ => return None,
    })
}
