//! Where the resolver is in the syntax tree, as a chain of path segments on the stack: rendered
//! into a JSON path string (`rungs[2].ld[1].or[0][0]`) only when an error names it.

use std::fmt;

/// One step of a path: the base (a rung's path), an array index or an object key.
#[derive(Copy, Clone)]
enum Seg<'p> {
    Base(&'p str),
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
    pub(crate) fn base(path: &'p str) -> At<'p> {
        At {
            parent: None,
            seg: Seg::Base(path),
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
            Seg::Base(s) => f.write_str(s),
            Seg::Index(i) => write!(f, "[{i}]"),
            Seg::Key(k) => write!(f, ".{k}"),
        }
    }
}
