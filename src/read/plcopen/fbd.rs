//! FBD bodies (TC6 `FBD`) → the syntax's FBD body.

use super::xml::{error, origin, Note, Tc6, R};
use crate::syntax::FbdBody;
use roxmltree::Node;

/// Reads FBD body `node` of POU `pou`.
pub fn body(_tc6: Tc6, node: Node, pou: &str, _notes: &mut Vec<Note>) -> R<FbdBody<'static>> {
    Err(error(
        origin(node),
        &format!("pou {pou}, FBD"),
        "FBD bodies are not read yet",
    ))
}
