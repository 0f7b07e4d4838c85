//! Where the resolver is in the syntax tree, as a chain of path segments on the stack: rendered
//! into a JSON path string (`rungs[2].ld[1].or[0][0]`) only when an error names it.

use std::fmt;

/// One step of a path: the base (rung `index` of the POU whose rung array is at `pou`), an array
/// index or an object key.
#[derive(Copy, Clone)]
enum Seg<'p> {
    Rung { pou: &'p str, index: usize },
    Index(usize),
    Key(&'p str),
}

/// A position in the tree: a segment and the position it is in.
#[derive(Copy, Clone)]
pub(crate) struct At<'p> {
    parent: Option<&'p At<'p>>,
    seg: Seg<'p>,
}

impl<'p> At<'p> {
    /// Rung `index` of the POU whose rung array is at `pou` (`""`: the top-level `rungs`).
    pub(crate) fn rung(pou: &'p str, index: usize) -> At<'p> {
        At {
            parent: None,
            seg: Seg::Rung { pou, index },
        }
    }
    pub(crate) fn index(&'p self, i: usize) -> At<'p> {
        At {
            parent: Some(self),
            seg: Seg::Index(i),
        }
    }
    pub(crate) fn key(&'p self, k: &'p str) -> At<'p> {
        At {
            parent: Some(self),
            seg: Seg::Key(k),
        }
    }
    /// The path with a suffix (`.contact`, `[1]`, or "").
    pub(crate) fn with(&self, suffix: &str) -> String {
        format!("{self}{suffix}")
    }
}

impl fmt::Display for At<'_> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        if let Some(p) = self.parent {
            write!(f, "{p}")?;
        }
        match self.seg {
            Seg::Rung { pou: "", index } => write!(f, "rungs[{index}]"),
            Seg::Rung { pou, index } => write!(f, "{pou}[{index}]"),
            Seg::Index(i) => write!(f, "[{i}]"),
            Seg::Key(k) => write!(f, ".{k}"),
        }
    }
}
