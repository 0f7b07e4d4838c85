//! The resolver's name tables (variables and instances of a scope): names → ids, built once
//! per scope and looked up for every operand of every element.
//!
//! A program of a million rungs has a million variables and looks names up five million times,
//! in an order a hash spreads over the whole table: each lookup is a cache miss. A general hash
//! map costs three (its control bytes, its bucket, the key's heap text); this table costs one:
//! open addressing with linear probing over 32-byte slots that hold the hash tag, the value and
//! — for names of up to 22 bytes, which is nearly all of them — the name itself. Longer names
//! are kept aside and compared there.
//!
//! Invariants: at most half the slots are full (probes stay short); a slot is `None` or holds
//! one name; names are unique (an insert of a present name replaces its value). Deliberately no
//! removal (scopes only grow) and no iteration order.

use super::util::FxHasher;
use std::hash::Hasher;
use std::num::NonZeroU32;

/// Longest name kept in its slot.
const INLINE: usize = 22;

#[derive(Clone, Copy)]
enum Key {
    Inline {
        len: u8,
        bytes: [u8; INLINE],
    },
    /// Index into [`NameTable::long`].
    Long(u32),
}

#[derive(Clone, Copy)]
struct Slot<V> {
    /// High bits of the name's hash (never zero, so that an empty slot costs no tag).
    tag: NonZeroU32,
    value: V,
    key: Key,
}

/// Names → `V`.
#[derive(Clone)]
pub(crate) struct NameTable<V> {
    slots: Vec<Option<Slot<V>>>,
    len: usize,
    long: Vec<Box<str>>,
}

impl<V> Default for NameTable<V> {
    fn default() -> Self {
        NameTable {
            slots: Vec::new(),
            len: 0,
            long: Vec::new(),
        }
    }
}

fn hash(name: &str) -> (u64, NonZeroU32) {
    let mut h = FxHasher::default();
    h.write(name.as_bytes());
    let h = h.finish();
    let tag = NonZeroU32::new((h >> 32) as u32 | 1).unwrap_or(NonZeroU32::MIN);
    (h, tag)
}

impl<V: Copy> NameTable<V> {
    /// Room for `more` names without growing.
    pub(crate) fn reserve(&mut self, more: usize) {
        let want = ((self.len + more) * 2).next_power_of_two().max(8);
        if want > self.slots.len() {
            self.rebuild(want);
        }
    }

    fn rebuild(&mut self, size: usize) {
        let old = std::mem::replace(&mut self.slots, vec![None; size]);
        let mask = size - 1;
        for slot in old.into_iter().flatten() {
            let name = self.key_text(&slot.key);
            let mut i = hash(name).0 as usize & mask;
            while self.slots[i].is_some() {
                i = (i + 1) & mask;
            }
            self.slots[i] = Some(slot);
        }
    }

    fn key_text<'k>(&'k self, key: &'k Key) -> &'k str {
        match key {
            // Inline keys are copied from a `&str`, so they are UTF-8.
            Key::Inline { len, bytes } => {
                std::str::from_utf8(&bytes[..*len as usize]).unwrap_or_default()
            }
            Key::Long(i) => &self.long[*i as usize],
        }
    }

    fn matches(&self, key: &Key, name: &str) -> bool {
        match key {
            Key::Inline { len, bytes } => {
                *len as usize == name.len() && &bytes[..name.len()] == name.as_bytes()
            }
            Key::Long(i) => &*self.long[*i as usize] == name,
        }
    }

    /// The slot of `name`: `Ok` where it is, `Err` where it would go.
    #[inline]
    fn find(&self, name: &str) -> Result<usize, usize> {
        let (h, tag) = hash(name);
        let mask = self.slots.len() - 1;
        let mut i = h as usize & mask;
        loop {
            match &self.slots[i] {
                None => return Err(i),
                Some(s) if s.tag == tag && self.matches(&s.key, name) => return Ok(i),
                Some(_) => i = (i + 1) & mask,
            }
        }
    }

    #[inline]
    pub(crate) fn get(&self, name: &str) -> Option<&V> {
        if self.len == 0 {
            return None;
        }
        let i = self.find(name).ok()?;
        self.slots[i].as_ref().map(|s| &s.value)
    }

    pub(crate) fn contains_key(&self, name: &str) -> bool {
        self.get(name).is_some()
    }

    /// Adds `name` (or gives it a new value); the old value, if it was there.
    pub(crate) fn insert(&mut self, name: &str, value: V) -> Option<V> {
        if (self.len + 1) * 2 > self.slots.len() {
            self.reserve(1.max(self.len));
        }
        match self.find(name) {
            Ok(i) => self.slots[i]
                .as_mut()
                .map(|s| std::mem::replace(&mut s.value, value)),
            Err(i) => {
                let key = if name.len() <= INLINE {
                    let mut bytes = [0u8; INLINE];
                    bytes[..name.len()].copy_from_slice(name.as_bytes());
                    Key::Inline {
                        len: name.len() as u8,
                        bytes,
                    }
                } else {
                    self.long.push(name.into());
                    Key::Long((self.long.len() - 1) as u32)
                };
                let tag = hash(name).1;
                self.slots[i] = Some(Slot { tag, value, key });
                self.len += 1;
                None
            }
        }
    }
}

// One cache line holds two slots of a variable table.
const _: () = assert!(std::mem::size_of::<Option<Slot<u32>>>() == 32);

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn finds_what_was_inserted_short_and_long_through_growth() {
        let mut t: NameTable<u32> = NameTable::default();
        assert_eq!(t.get("A"), None);
        let long = "A_VERY_LONG_VARIABLE_NAME_INDEED";
        for i in 0..1000u32 {
            assert_eq!(t.insert(&format!("M{i}"), i), None);
        }
        assert_eq!(t.insert(long, 7), None);
        assert_eq!(t.insert("M5", 55), Some(5));
        assert_eq!(t.get("M5"), Some(&55));
        assert_eq!(t.get("M999"), Some(&999));
        assert_eq!(t.get(long), Some(&7));
        assert_eq!(t.get("M1000"), None);
        assert_eq!(t.get(&long[..30]), None);
        assert!(t.contains_key("M0") && !t.contains_key(""));
        assert_eq!(t.len, 1001);
    }
}
