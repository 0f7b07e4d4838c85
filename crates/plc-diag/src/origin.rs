//! Where a node starts in a program's text: a byte offset, 4 bytes, and its line and column
//! computed only on demand.
//!
//! Invariant: an [`Origin`] is either none (a node a reader or the resolver made up) or the byte
//! offset of the first byte of the node in the text it was read from. Line and column are
//! 1-based, the column counted in characters (as the syntax errors of `serde_json` count them).
//! Deliberately no file name and no text: the offsets are resolved against the text by
//! [`line_columns`], once for all the errors of a load.

use std::num::NonZeroU32;

/// A byte offset into the program text, or none; 4 bytes (offset + 1, so `None` is the niche).
#[derive(Copy, Clone, Debug, Default, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub struct Origin(Option<NonZeroU32>);

impl Origin {
    pub const NONE: Origin = Origin(None);

    /// The node at byte `offset` (none if the offset does not fit 32 bits: texts over 4 GiB
    /// cannot be loaded anyway).
    #[inline]
    pub fn at(offset: usize) -> Origin {
        Origin(
            u32::try_from(offset)
                .ok()
                .and_then(|o| o.checked_add(1))
                .and_then(NonZeroU32::new),
        )
    }

    /// The byte offset, if known.
    #[inline]
    pub fn offset(self) -> Option<usize> {
        self.0.map(|o| o.get() as usize - 1)
    }

    /// This origin, or `other` when this one is none.
    #[inline]
    pub fn or(self, other: Origin) -> Origin {
        if self.0.is_some() {
            self
        } else {
            other
        }
    }

    pub fn is_none(self) -> bool {
        self.0.is_none()
    }

    /// 1-based line and column of the node in `text` (one scan up to the offset).
    pub fn line_column(self, text: &str) -> Option<(u32, u32)> {
        line_columns(text, &[self])[0]
    }
}

/// Line and column of each origin in `text`, in one forward pass over the text up to the
/// furthest one (the origins may come in any order).
pub(crate) fn line_columns(text: &str, origins: &[Origin]) -> Vec<Option<(u32, u32)>> {
    let mut order: Vec<(usize, usize)> = origins
        .iter()
        .enumerate()
        .filter_map(|(i, o)| Some((o.offset()?, i)))
        .filter(|&(off, _)| text.is_char_boundary(off) && off <= text.len())
        .collect();
    order.sort_unstable();
    let mut out = vec![None; origins.len()];
    let (mut line, mut line_start, mut pos) = (1u32, 0usize, 0usize);
    for (offset, i) in order {
        let bytes = &text.as_bytes()[pos..offset];
        for (k, &b) in bytes.iter().enumerate() {
            if b == b'\n' {
                line += 1;
                line_start = pos + k + 1;
            }
        }
        pos = offset;
        let column = text[line_start..offset].chars().count() as u32 + 1;
        out[i] = Some((line, column));
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn lines_and_columns_count_from_one_in_characters() {
        let text = "ab\nçd\n\nx";
        let at = |o| Origin::at(o);
        let got = line_columns(text, &[at(8), at(0), at(5), Origin::NONE, at(3), at(7)]);
        assert_eq!(
            got,
            [
                Some((4, 1)),
                Some((1, 1)),
                Some((2, 2)),
                None,
                Some((2, 1)),
                Some((3, 1))
            ]
        );
        assert_eq!(std::mem::size_of::<Origin>(), 4);
        assert_eq!(at(7).offset(), Some(7));
        assert_eq!(Origin::NONE.or(at(2)), at(2));
    }
}
