//! Small helpers of the resolver: names, paths, type expectations.

use super::Result;
use plc_diag::{Invalid, LoadError};
use plc_model::Type;

/// `path.key`, or `key` at the top level.
pub(super) fn join(path: &str, key: &str) -> String {
    if path.is_empty() {
        key.to_owned()
    } else {
        format!("{path}.{key}")
    }
}

pub(super) fn rung_path(pou_path: &str, i: usize) -> String {
    if pou_path.is_empty() {
        format!("rungs[{i}]")
    } else {
        format!("{pou_path}[{i}]")
    }
}

pub(super) fn expect_type(
    found: Type,
    expected: Type,
    what: &'static str,
    name: &str,
) -> std::result::Result<(), Invalid> {
    if found == expected {
        Ok(())
    } else {
        Err(Invalid::Type {
            what,
            expected: expected.to_string(),
            operand: name.to_owned(),
            found: found.to_string(),
        })
    }
}

/// A valid name, or the error at the path `path` renders (only then).
pub(super) fn check_name(
    name: &str,
    path: impl FnOnce() -> String,
    rung: Option<&str>,
) -> Result<()> {
    let mut chars = name.chars();
    let ok = matches!(chars.next(), Some(c) if c.is_ascii_alphabetic() || c == '_')
        && chars.all(|c| c.is_ascii_alphanumeric() || c == '_');
    if ok {
        Ok(())
    } else {
        Err(LoadError::invalid(
            rung,
            &path(),
            Invalid::BadName { name: name.into() },
        ))
    }
}

/// Printable text for a free-form name or id (`what`: `"rung id"`, `"program name"`): no
/// control character (C0, DEL, C1), which would break the DOT, STL and C written from it and
/// drive a terminal; else the error at the path `path` renders.
pub(super) fn check_printable(
    what: &'static str,
    text: &str,
    path: impl FnOnce() -> String,
    rung: Option<&str>,
) -> Result<()> {
    match Invalid::control_char(what, text) {
        None => Ok(()),
        Some(kind) => Err(LoadError::invalid(rung, &path(), kind)),
    }
}

/// A valid rung label: a name, or a number as S7-200 Micro/WIN numbers its labels (`LBL 4`);
/// else the error at the path `path` renders (only then).
pub(super) fn check_label(
    label: &str,
    path: impl FnOnce() -> String,
    rung: Option<&str>,
) -> Result<()> {
    if !label.is_empty() && label.bytes().all(|b| b.is_ascii_digit()) {
        return Ok(());
    }
    check_name(label, path, rung)
}

/// A valid variable name: an identifier, or identifiers joined by `.` (a structure's field
/// flattened into its own variable, `Motor.Speed`), each optionally followed by one subscript
/// of integers (an array's element scalarised into its own variable by the PLCopen reader,
/// `a[3]`, `m[1,-2]`, `s.a[0]`); else the error at the path `path` renders.
pub(super) fn check_var_name(name: &str, path: impl FnOnce() -> String) -> Result<()> {
    if !name.contains(['.', '[']) {
        return check_name(name, path, None);
    }
    let part_ok = |part: &str| {
        let (id, sub) = match part.split_once('[') {
            Some((id, rest)) => (id, Some(rest)),
            None => (part, None),
        };
        check_name(id, String::new, None).is_ok()
            && sub.is_none_or(|s| {
                s.strip_suffix(']').is_some_and(|inner| {
                    inner.split(',').all(|k| {
                        let k = k.strip_prefix('-').unwrap_or(k);
                        !k.is_empty() && k.bytes().all(|b| b.is_ascii_digit())
                    })
                })
            })
    };
    if name.split('.').all(part_ok) {
        Ok(())
    } else {
        Err(LoadError::invalid(
            None,
            &path(),
            Invalid::BadName { name: name.into() },
        ))
    }
}

/// A fast, non-cryptographic hasher for the resolver's name tables (the multiply-rotate hash of
/// Firefox and rustc): names come from one trusted file, and SipHash's resistance to chosen
/// collisions is not worth its cost on millions of lookups.
#[derive(Default, Clone, Copy)]
pub(crate) struct FxHasher {
    hash: u64,
}

impl FxHasher {
    #[inline]
    fn add(&mut self, word: u64) {
        self.hash = (self.hash.rotate_left(5) ^ word).wrapping_mul(0x51_7c_c1_b7_27_22_0a_95);
    }
}

impl std::hash::Hasher for FxHasher {
    #[inline]
    fn write(&mut self, bytes: &[u8]) {
        let mut chunks = bytes.chunks_exact(8);
        for c in &mut chunks {
            let mut w = [0u8; 8];
            w.copy_from_slice(c);
            self.add(u64::from_le_bytes(w));
        }
        let rest = chunks.remainder();
        if !rest.is_empty() {
            let mut w = [0u8; 8];
            w[..rest.len()].copy_from_slice(rest);
            self.add(u64::from_le_bytes(w));
        }
    }
    #[inline]
    fn write_u8(&mut self, i: u8) {
        self.add(i as u64);
    }
    #[inline]
    fn write_u32(&mut self, i: u32) {
        self.add(i as u64);
    }
    #[inline]
    fn write_u64(&mut self, i: u64) {
        self.add(i);
    }
    #[inline]
    fn write_usize(&mut self, i: usize) {
        self.add(i as u64);
    }
    /// With a final mix (MurmurHash3's): the multiply leaves the low bits, which pick the
    /// bucket, poorly mixed, and ids like `R1`…`R1000000` would collide.
    #[inline]
    fn finish(&self) -> u64 {
        let mut h = self.hash;
        h ^= h >> 33;
        h = h.wrapping_mul(0xff51_afd7_ed55_8ccd);
        h ^ (h >> 33)
    }
}

/// A `HashMap` with [`FxHasher`].
pub(crate) type FastMap<K, V> =
    std::collections::HashMap<K, V, std::hash::BuildHasherDefault<FxHasher>>;
/// A `HashSet` with [`FxHasher`].
pub(crate) type FastSet<K> = std::collections::HashSet<K, std::hash::BuildHasherDefault<FxHasher>>;
