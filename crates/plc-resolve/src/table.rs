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
//! Invariants: at most 3/4 of the slots are full (probes stay short: two slots share a cache
//! line, and a million names take 64 MB rather than 128); a slot is `None` or holds
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
        let want = ((self.len + more) * 4 / 3 + 1).next_power_of_two().max(8);
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

    /// Starts loading the slot where `name`'s search begins into the cache, so that looking up
    /// several names of one rung overlaps their cache misses instead of taking them one after
    /// another (a hint: nothing observable changes).
    #[inline]
    pub(crate) fn prefetch(&self, name: &str) {
        if self.slots.is_empty() {
            return;
        }
        let i = hash(name).0 as usize & (self.slots.len() - 1);
        plc_hint::prefetch_read(self.slots.as_ptr().wrapping_add(i).cast());
    }

    pub(crate) fn contains_key(&self, name: &str) -> bool {
        self.get(name).is_some()
    }

    /// Adds `name` (or gives it a new value); the old value, if it was there.
    pub(crate) fn insert(&mut self, name: &str, value: V) -> Option<V> {
        if (self.len + 1) * 4 > self.slots.len() * 3 {
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

/// A set of names kept elsewhere (the rung ids of the streamed main program, in the rungs they
/// name): 8-byte slots of a hash tag and an index; the name of index `i` is `text(i)`, read
/// only when a tag matches. The tag also places the slot, so growing reads no name. Same
/// invariants as [`NameTable`], at most 3/4 full.
#[derive(Default)]
pub(crate) struct IndexSet {
    slots: Vec<Option<(NonZeroU32, u32)>>,
    len: usize,
}

impl IndexSet {
    /// Room for `n` names in all.
    pub(crate) fn with_capacity(n: usize) -> IndexSet {
        IndexSet {
            slots: vec![None; (n * 4 / 3 + 1).next_power_of_two().max(8)],
            len: 0,
        }
    }

    /// The index of `name`: `Ok` if present, else `Err` with the slot it would take.
    fn find<'t>(&self, name: &str, text: impl Fn(u32) -> &'t str) -> Result<u32, usize> {
        let tag = hash(name).1;
        let mask = self.slots.len() - 1;
        let mut i = Self::home(tag, mask);
        loop {
            match self.slots[i] {
                None => return Err(i),
                Some((t, idx)) if t == tag && text(idx) == name => return Ok(idx),
                Some(_) => i = (i + 1) & mask,
            }
        }
    }

    /// Starts loading the slot where `name`'s search begins into the cache (a hint, as
    /// [`NameTable::prefetch`]).
    #[inline]
    pub(crate) fn prefetch(&self, name: &str) {
        if !self.slots.is_empty() {
            let i = Self::home(hash(name).1, self.slots.len() - 1);
            plc_hint::prefetch_read(self.slots.as_ptr().wrapping_add(i).cast());
        }
    }

    /// The first slot a name with hash tag `tag` may take.
    fn home(tag: NonZeroU32, mask: usize) -> usize {
        (tag.get() >> 1) as usize & mask
    }

    pub(crate) fn get<'t>(&self, name: &str, text: impl Fn(u32) -> &'t str) -> Option<u32> {
        if self.slots.is_empty() {
            return None;
        }
        self.find(name, text).ok()
    }

    /// Adds `name` as index `idx`; false (and nothing changed) if it was there.
    pub(crate) fn insert<'t>(
        &mut self,
        name: &str,
        idx: u32,
        text: impl Fn(u32) -> &'t str,
    ) -> bool {
        if (self.len + 1) * 4 > self.slots.len() * 3 {
            let old = std::mem::replace(self, IndexSet::with_capacity(2 * self.len.max(4)));
            for (t, i) in old.slots.into_iter().flatten() {
                let mask = self.slots.len() - 1;
                let mut at = Self::home(t, mask);
                while self.slots[at].is_some() {
                    at = (at + 1) & mask;
                }
                self.slots[at] = Some((t, i));
                self.len += 1;
            }
        }
        match self.find(name, &text) {
            Ok(_) => false,
            Err(at) => {
                self.slots[at] = Some((hash(name).1, idx));
                self.len += 1;
                true
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

    #[test]
    fn an_index_set_finds_names_by_their_index_through_growth() {
        let names: Vec<String> = (0..1000).map(|i| format!("R{i}")).collect();
        let text = |i: u32| names[i as usize].as_str();
        let mut s = IndexSet::default();
        assert_eq!(s.get("R1", text), None);
        for i in 0..1000u32 {
            assert!(s.insert(&names[i as usize], i, text));
        }
        assert!(!s.insert("R5", 7, text));
        assert_eq!(s.get("R5", text), Some(5));
        assert_eq!(s.get("R999", text), Some(999));
        assert_eq!(s.get("R1000", text), None);
        assert_eq!(s.len, 1000);
    }
}
