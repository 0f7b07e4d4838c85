//! The XML layer of the PLCopen reader: parsing with limits, the namespace of the project,
//! children by local name, attributes, and the errors and notes every other part reports.
//!
//! Invariants: every error and note carries the [`Origin`] (byte offset) of the XML node it is
//! about, so the command line prints it as `FILE:LINE:COLUMN`. Elements of the project are
//! matched by local name *and* the project's namespace (one of [`NAMESPACES`]); elements of
//! other namespaces (XHTML text, vendor data) are only looked at where the format puts them.
//! Names from the file are checked as IEC 61131-3 identifiers (6.1.2) before they reach the
//! syntax tree.
//!
//! Deliberately not here: anything about POUs, wiring or bodies (the sibling modules).

use plc_diag::{Invalid, LoadError, Origin};
use roxmltree::{Document, Node};

/// The TC6 namespaces read: 2.01, 2.00 (CODESYS, e!COCKPIT) and the pre-2.0 one.
pub const NAMESPACES: &[&str] = &[
    "http://www.plcopen.org/xml/tc6_0201",
    "http://www.plcopen.org/xml/tc6_0200",
    "http://www.plcopen.org/xml/tc6.xsd",
];

/// Largest XML text read: 512 MiB (the parsed tree takes several times the text).
pub const MAX_XML_BYTES: usize = 512 << 20;
/// Deepest element nesting accepted (a TC6 project nests about 15 deep).
pub(super) const MAX_DEPTH: usize = 256;

/// A PLCopen error (one, located at an XML node).
pub(super) type R<T> = Result<T, LoadError>;

/// A located error: `where` names the element (`pou Main, LD, contact localId 5`).
pub(super) fn error(origin: Origin, place: &str, message: impl Into<String>) -> LoadError {
    LoadError::invalid(
        None,
        place,
        Invalid::PlcOpen {
            message: message.into(),
        },
    )
    .at(origin)
}

/// Where a node starts.
pub(super) fn origin(n: Node) -> Origin {
    Origin::at(n.range().start)
}

/// Something the reader did that the user should know about (printed as a warning).
#[derive(Clone, Debug, PartialEq)]
pub struct Note {
    pub origin: Origin,
    pub message: String,
}

/// The executionOrderIds of an FBD body, to compare with the order plc-deps gives it.
#[derive(Clone, Debug)]
pub struct ExecOrder {
    /// The ids of the body's networks.
    pub networks: Vec<String>,
    pub origin: Origin,
    /// (executionOrderId, localId) of the elements that have one above 0, sorted.
    pub ids: Vec<(u32, u32)>,
}

/// What the reader has to say: notes, and the execution orders to check after resolution.
#[derive(Default)]
pub struct Notes {
    pub list: Vec<Note>,
    pub exec_orders: Vec<ExecOrder>,
    /// Variables an LD body needs that the file does not declare, with their POU: the BOOL
    /// that holds a contact network feeding a block's data pin (`SR0__R`, a name no file can
    /// declare: IEC 61131-3 identifiers have no double `_`).
    pub ld_vars: Vec<(String, plc_syntax::Var<'static>)>,
    /// The stand-in function block types of the blocks the model lacks
    /// ([`super::black_box`]).
    pub black_boxes: Vec<super::block_types::BlackBox>,
    /// Why `run` cannot execute a POU's body (a string in a body it would execute): the POU's
    /// name and the reason, in file order; `run` refuses the project for the first one whose POU
    /// it runs.
    pub no_run: Vec<(String, Note)>,
    /// The bodies read only as stand-in rungs (ST, IL, SFC), moved into the syntax tree.
    pub skipped: Vec<plc_syntax::SkippedBody>,
    /// Read for execution (`run`, `c`): an ST body that lowers to rungs is those rungs
    /// ([`super::st_lower`]); otherwise (the analyses) a stand-in rung per statement.
    pub exec: bool,
    /// Functions whose calls are not executed but read as black boxes (lower-case name, why):
    /// those whose body the reader took but the resolver refused (`plc_load` reads again).
    pub refuse_functions: Vec<(String, String)>,
    /// The project has several configurations and no [`super::Pick::configuration`] chose
    /// one: the first in file order is read, and this note names the others (W0502).
    pub configurations: Option<Note>,
}

impl Notes {
    pub fn push(&mut self, n: Note) {
        self.list.push(n);
    }

    /// The variables an LD body of POU `pou` added ([`Notes::ld_vars`]).
    pub fn take_ld_vars(&mut self, pou: &str) -> Vec<plc_syntax::Var<'static>> {
        let (mine, rest) = std::mem::take(&mut self.ld_vars)
            .into_iter()
            .partition(|(p, _)| p == pou);
        self.ld_vars = rest;
        mine.into_iter().map(|(_, v)| v).collect()
    }
}

/// Parses the text as XML: no DTD (so no entity expansion), at most [`MAX_XML_BYTES`], at most
/// [`MAX_DEPTH`] levels. Errors are syntax errors with line and column.
pub(super) fn parse(text: &str) -> R<Document<'_>> {
    if text.len() > MAX_XML_BYTES {
        return Err(syntax(
            1,
            1,
            format!(
                "the XML file is larger than the limit of {} MiB ({} bytes)",
                MAX_XML_BYTES >> 20,
                text.len()
            ),
        ));
    }
    let opt = roxmltree::ParsingOptions {
        allow_dtd: false,
        nodes_limit: u32::MAX,
    };
    let doc = Document::parse_with_options(text, opt).map_err(|e| {
        if let roxmltree::Error::DtdDetected = e {
            let at = text.find("<!DOCTYPE").unwrap_or(0);
            let (l, c) = Origin::at(at).line_column(text).unwrap_or((1, 1));
            return syntax(
                l as usize,
                c as usize,
                "a DTD (<!DOCTYPE …>) is not allowed in a PLCopen file (its entities could expand without bound)".into(),
            );
        }
        let pos = e.pos();
        syntax(pos.row as usize, pos.col as usize, strip_position(&e.to_string()))
    })?;
    check_depth(&doc, text)?;
    Ok(doc)
}

fn syntax(line: usize, column: usize, message: String) -> LoadError {
    LoadError::Syntax {
        line,
        column,
        message,
    }
}

/// roxmltree's message without its ` at L:C` (the error carries them).
fn strip_position(m: &str) -> String {
    let mut out = String::with_capacity(m.len());
    let mut rest = m;
    while let Some(i) = rest.find(" at ") {
        let tail = &rest[i + 4..];
        let len = tail
            .find(|c: char| !(c.is_ascii_digit() || c == ':'))
            .unwrap_or(tail.len());
        out.push_str(&rest[..i]);
        if len == 0 || !tail[..len].contains(':') {
            out.push_str(" at ");
        }
        rest = &tail[len..];
    }
    out.push_str(rest);
    format!("malformed XML: {out}")
}

/// Refuses nesting deeper than [`MAX_DEPTH`], naming where it gets too deep.
fn check_depth(doc: &Document, text: &str) -> R<()> {
    let mut depth = vec![0u16; doc.descendants().count() + 1];
    for n in doc.descendants() {
        let d = n.parent().map_or(0, |p| depth[p.id().get_usize()]) + 1;
        depth[n.id().get_usize()] = d;
        if d as usize > MAX_DEPTH {
            let (l, c) = origin(n).line_column(text).unwrap_or((1, 1));
            return Err(syntax(
                l as usize,
                c as usize,
                format!("elements nest deeper than {MAX_DEPTH} levels"),
            ));
        }
    }
    Ok(())
}

/// The project's namespace: the root must be `project` in one of [`NAMESPACES`].
pub(super) fn project_namespace(doc: &Document) -> R<&'static str> {
    let root = doc.root_element();
    let tag = root.tag_name();
    let ns = tag.namespace().unwrap_or("");
    if tag.name() != "project" {
        return Err(error(
            origin(root),
            "top level",
            format!(
                "not a PLCopen TC6 project: the root element is `{}`, not `project`",
                tag.name()
            ),
        ));
    }
    NAMESPACES
        .iter()
        .find(|n| **n == ns)
        .copied()
        .ok_or_else(|| {
            error(
                origin(root),
                "top level",
                format!(
                    "unknown namespace `{ns}` of the PLCopen project (expected one of {})",
                    NAMESPACES.join(", ")
                ),
            )
        })
}

/// The project's XML with its namespace: children by local name.
#[derive(Copy, Clone)]
pub(super) struct Tc6 {
    pub ns: &'static str,
}

impl Tc6 {
    /// True when `n` is the element `name` of the project's namespace.
    pub(super) fn is(&self, n: Node, name: &str) -> bool {
        n.is_element() && n.tag_name().name() == name && n.tag_name().namespace() == Some(self.ns)
    }

    /// The first child element `name`.
    pub(super) fn child<'a, 'i>(&self, n: Node<'a, 'i>, name: &str) -> Option<Node<'a, 'i>> {
        n.children().find(|c| self.is(*c, name))
    }

    /// Every child element `name`, in file order.
    pub(super) fn children<'a, 'i: 'a>(
        &self,
        n: Node<'a, 'i>,
        name: &'a str,
    ) -> impl Iterator<Item = Node<'a, 'i>> + 'a {
        let me = *self;
        n.children().filter(move |c| me.is(*c, name))
    }

    /// The element children of the project's namespace.
    pub(super) fn elements<'a, 'i: 'a>(
        &self,
        n: Node<'a, 'i>,
    ) -> impl Iterator<Item = Node<'a, 'i>> + 'a {
        let ns = self.ns;
        n.children()
            .filter(move |c| c.is_element() && c.tag_name().namespace() == Some(ns))
    }
}

/// A required attribute.
pub(super) fn attr<'a>(n: Node<'a, '_>, name: &str, place: &str) -> R<&'a str> {
    n.attribute(name).ok_or_else(|| {
        error(
            origin(n),
            place,
            format!("`{}` has no attribute `{name}`", n.tag_name().name()),
        )
    })
}

/// A boolean attribute (`true`/`false`/`1`/`0`; default false).
pub(super) fn flag(n: Node, name: &str, place: &str) -> R<bool> {
    match n.attribute(name) {
        None | Some("false") | Some("0") => Ok(false),
        Some("true") | Some("1") => Ok(true),
        Some(other) => Err(error(
            origin(n),
            place,
            format!("attribute `{name}` is `{other}`, not true or false"),
        )),
    }
}

/// True for an IEC 61131-3 identifier (6.1.2): letters, digits and `_`, not starting with a
/// digit, no two `_` in a row.
pub(super) fn is_identifier(s: &str) -> bool {
    let b = s.as_bytes();
    !b.is_empty()
        && !b[0].is_ascii_digit()
        && b.iter().all(|c| c.is_ascii_alphanumeric() || *c == b'_')
        && !s.contains("__")
}

/// Type name `s` as written where a type is named (`derived`): an identifier, or a CODESYS
/// name qualified by its library's namespace (`Standard.R_TRIG`, `MQTT.QoS`), which is the type
/// itself when `defined` says the file defines it or the standard does (`R_TRIG`), else the
/// type `MQTT_QoS` that nobody defines (a black box, [`super::project`]).
pub(super) fn type_reference(
    s: &str,
    defined: &dyn Fn(&str) -> bool,
    n: Node,
    place: &str,
) -> R<String> {
    if is_identifier(s) {
        return Ok(s.to_owned());
    }
    if let Some((ns, ty)) = s.trim().rsplit_once('.') {
        if ns.split('.').all(is_identifier) && is_identifier(ty) {
            let standard = matches!(
                plc_model::Type::parse(&ty.to_ascii_uppercase()),
                Some(plc_model::Type::Fb(_))
            );
            if defined(ty) || standard {
                return Ok(ty.to_owned());
            }
            return Ok(format!("{}_{ty}", ns.replace('.', "_")));
        }
    }
    identifier(s, "type", n, place)
}

/// `s` checked as an identifier (`what` names it in the message: "variable", "POU").
pub(super) fn identifier(s: &str, what: &str, n: Node, place: &str) -> R<String> {
    if is_identifier(s) {
        Ok(s.to_owned())
    } else {
        Err(error(
            origin(n),
            place,
            format!("{what} name `{s}` is not an IEC 61131-3 identifier (letters, digits and single `_`, not starting with a digit)"),
        ))
    }
}

/// A variable reference as an LD/FBD element names it: an identifier or a field of one
/// (`T1.Q`, `G1.RESULT`), trimmed; or an element of constant subscripts of a scalarised array,
/// as its variable's name (`a[ 1 + 2 ]` as `a[3]`, [`super::data_types`]).
pub(super) fn variable_ref(s: &str, n: Node, place: &str) -> R<String> {
    let t = s.trim();
    if !t.is_empty() && t.split('.').all(is_identifier) {
        Ok(t.to_owned())
    } else if let Some(e) = t
        .contains('[')
        .then(|| crate::st::parser::expression(t).ok())
        .flatten()
        .and_then(|e| match e {
            crate::st::ast::Expr::Var(p) => element_name(&p),
            _ => None,
        })
    {
        Ok(e)
    } else {
        Err(error(
            origin(n),
            place,
            format!("`{t}` is not a variable or a field of one (`X`, `T1.Q`): array elements, direct addresses and expressions are not supported here yet"),
        ))
    }
}

/// The variable of array element `p` when its subscripts are constant and last (`a[3]`,
/// `s.m[1, -2]` as `s.m[1,-2]`), the name a scalarised array's element has.
pub(super) fn element_name(p: &crate::st::ast::Place) -> Option<String> {
    let (last, fields) = p.selectors.split_last()?;
    let crate::st::ast::Selector::Index(ix) = last else {
        return None;
    };
    let mut name = p.base.clone();
    for f in fields {
        let crate::st::ast::Selector::Field(f) = f else {
            return None;
        };
        name.push('.');
        name.push_str(f);
    }
    let ks: Option<Vec<String>> = ix
        .iter()
        .map(|e| crate::st::constant(e).map(|k| k.to_string()))
        .collect();
    Some(format!("{name}[{}]", ks?.join(",")))
}

/// The `addData` children of `n` as one note (their `data@name`s), if any. A `data` holding a
/// TC6 `pou` or `resource` is not ignored (the project reader reads them) and is left out.
pub(super) fn add_data_note(tc6: Tc6, n: Node, notes: &mut Notes) {
    for a in tc6.children(n, "addData") {
        let names: Vec<&str> = tc6
            .children(a, "data")
            .filter(|d| tc6.child(*d, "pou").is_none() && tc6.child(*d, "resource").is_none())
            .filter_map(|d| d.attribute("name"))
            .collect();
        if !names.is_empty() {
            notes.push(Note {
                origin: origin(a),
                message: format!("vendor data (addData) ignored: {}", names.join(", ")),
            });
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn identifiers_follow_iec_61131_3() {
        for ok in ["A", "_x1", "TON0", "a_b"] {
            assert!(is_identifier(ok), "{ok}");
        }
        for bad in ["", "1a", "../x", "a\"; b", "a__b", "a b", "é"] {
            assert!(!is_identifier(bad), "{bad}");
        }
    }

    #[test]
    fn positions_leave_the_message() {
        assert_eq!(
            strip_position("expected 'a' tag, not 'b' at 3:4"),
            "malformed XML: expected 'a' tag, not 'b'"
        );
    }
}
