//! A program file's text as the commands read it: in memory, or, for a large regular file,
//! mapped from the page cache.
//!
//! Reading a file copies it into memory the kernel must first zero: at a million rungs that is
//! 223 MB, a tenth of `plc-deps report`'s whole run time (profiled with `perf record`: the page
//! faults of the read buffer). A mapping reads the page cache's own pages instead, so files from
//! [`MAP_FROM`] bytes on are mapped (read-only, private); smaller files, standard input and
//! anything that cannot be mapped are read. The mapping is populated when it is made
//! (`MAP_POPULATE` on Linux): one system call maps every page, instead of one page fault per
//! 4 KiB page as the reader first touches it (at a million rungs, half the process's page
//! faults: 23,273 against 11,044 with it, `perf stat -e page-faults`).
//!
//! Invariant: the text is UTF-8 (validated here when it is made, whatever the caller's check
//! said) and starts after any byte-order mark. Caveat, as for every program that maps its input (ripgrep's `--mmap`): the text is the
//! file as it is while the command runs; a file truncated by another process meanwhile ends the
//! process with `SIGBUS`, and one rewritten meanwhile gives unspecified text.
//!
//! Not here: the checks that name the file in errors (size, folder, UTF-8: `super::io`).

use std::fs::File;
use std::ops::Deref;

/// Files from this size on are mapped rather than read (16 MiB: below it the copy costs less
/// than setting up the mapping).
pub const MAP_FROM: u64 = 16 << 20;

/// A file's text (see the module's comment).
pub struct SourceText {
    repr: Repr,
}

enum Repr {
    Owned(String),
    /// `map[start..]` is valid UTF-8.
    Mapped {
        map: memmap2::Mmap,
        start: usize,
    },
}

impl SourceText {
    /// Text already in memory.
    pub fn owned(text: String) -> SourceText {
        SourceText {
            repr: Repr::Owned(text),
        }
    }

    /// The mapped contents of `file`, when it can be mapped, checked by `check`, which returns
    /// where the text starts (after a byte-order mark) or why the bytes are not text. Whatever
    /// `check` says, the bytes from there on are validated as UTF-8 here (`std::str::from_utf8`,
    /// a few milliseconds for 50 MB), so no `check` can make an invalid `str`: a start past the
    /// end or inside a character, or bytes that are not UTF-8, is an error.
    pub fn mapped(
        file: &File,
        check: impl Fn(&[u8]) -> Result<usize, String>,
    ) -> Option<Result<SourceText, String>> {
        // SAFETY: the mapping is read-only and private, and this process never writes the file.
        // What another process does to the file while it is mapped is the caveat of the
        // module's comment; memmap2 documents the same.
        let map = unsafe { memmap2::MmapOptions::new().populate().map(file) }.ok()?;
        let start = match check(&map) {
            Ok(start) => start,
            Err(e) => return Some(Err(e)),
        };
        let text = match map.get(start..) {
            Some(text) => text,
            None => {
                return Some(Err(format!(
                    "the text starts at byte {start}, past the end"
                )))
            }
        };
        if let Err(e) = std::str::from_utf8(text) {
            return Some(Err(e.to_string()));
        }
        Some(Ok(SourceText {
            repr: Repr::Mapped { map, start },
        }))
    }
}

impl Deref for SourceText {
    type Target = str;
    fn deref(&self) -> &str {
        match &self.repr {
            Repr::Owned(s) => s,
            // SAFETY: `mapped` validated `map[start..]` as UTF-8 with `std::str::from_utf8` when
            // it made this, whatever its `check` said, and the mapping is read-only: nothing in
            // this process changes it since.
            Repr::Mapped { map, start } => unsafe { std::str::from_utf8_unchecked(&map[*start..]) },
        }
    }
}

impl AsRef<str> for SourceText {
    fn as_ref(&self) -> &str {
        self
    }
}

impl std::fmt::Debug for SourceText {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let how = match self.repr {
            Repr::Owned(_) => "read",
            Repr::Mapped { .. } => "mapped",
        };
        write!(f, "SourceText({how}, {} bytes)", self.len())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::io::Write;

    fn file_of(bytes: &[u8]) -> File {
        let path = std::env::temp_dir().join(format!(
            "plc-deps-source-test-{}-{}",
            std::process::id(),
            bytes.len()
        ));
        std::fs::File::create(&path)
            .and_then(|mut f| f.write_all(bytes))
            .expect("writes the scratch file");
        let file = File::open(&path).expect("opens the scratch file");
        let _ = std::fs::remove_file(&path);
        file
    }

    /// A check that accepts anything cannot make an invalid `str`: the bytes are validated
    /// after it, and a start inside a character or past the end is refused.
    #[test]
    fn a_check_that_accepts_anything_makes_no_invalid_text() {
        let f = file_of(b"ok \xff\xfe not UTF-8");
        let err = SourceText::mapped(&f, |_| Ok(0))
            .expect("maps")
            .unwrap_err();
        assert_eq!(err, "invalid utf-8 sequence of 1 bytes from index 3");
        let f = file_of("é and more".as_bytes());
        let err = SourceText::mapped(&f, |_| Ok(1))
            .expect("maps")
            .unwrap_err();
        assert_eq!(err, "invalid utf-8 sequence of 1 bytes from index 0");
        let err = SourceText::mapped(&f, |b| Ok(b.len() + 1))
            .expect("maps")
            .unwrap_err();
        assert_eq!(err, "the text starts at byte 12, past the end");
        let text = SourceText::mapped(&f, |_| Ok(3))
            .expect("maps")
            .expect("UTF-8");
        assert_eq!(&*text, "and more");
        assert_eq!(format!("{text:?}"), "SourceText(mapped, 8 bytes)");
        let err = SourceText::mapped(&f, |_| Err("refused".into())).expect("maps");
        assert_eq!(err.unwrap_err(), "refused");
    }
}
