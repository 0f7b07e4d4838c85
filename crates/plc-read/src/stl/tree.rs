//! Small constructors of the surface syntax's tree for the STL reader: a name at a byte
//! offset, an element at a byte offset, a plain contact. Every node they make is owned
//! (`'static`) and carries the origin of the STL text it comes from. Nothing here reads
//! instructions or operands (`decode`, `operand`).

use plc_diag::Origin;
use plc_syntax::{self as syntax, Element, ElementKind, Located};
use std::borrow::Cow;

pub(super) type E = Element<'static>;

pub(super) fn name(s: &str, at: usize) -> syntax::Name<'static> {
    Located {
        value: Cow::Owned(s.to_string()),
        origin: Origin::at(at),
    }
}

pub(super) fn el(kind: ElementKind<'static>, at: usize) -> E {
    Element {
        origin: Origin::at(at),
        kind,
    }
}

pub(super) fn contact(var: &str, negated: bool, at: usize) -> E {
    el(
        ElementKind::Contact {
            var: name(var, at),
            negated,
            edge: None,
        },
        at,
    )
}
