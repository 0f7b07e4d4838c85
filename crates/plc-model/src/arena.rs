//! Dense typed indices and the arenas that hand them out.
//!
//! An id declared with [`index_type!`](crate::index_type) is an opaque `u32`: its number can be
//! read ([`Idx::index`], `raw()`), but outside the crate that declares it an id is only ever made
//! by the [`Arena`] that owns the values it indexes: [`Arena::push`] returns the new value's id,
//! [`Arena::ids`] and [`Arena::iter_enumerated`] walk them, and [`Arena::id`] turns a position
//! into an id after checking that the arena holds it. So a `VarId` in the hands of an analysis
//! was made by the program that holds the variable, never computed from an integer.
//!
//! Inside the declaring crate `Id::new(raw)` is available (`pub(crate)`), for ids that index
//! something other than an arena (a CFG's START and STOP nodes, an instruction counter).
//! `Id::from_raw` decodes an id packed with `raw()` (a decision word shared between workers);
//! it is the one way to make an id from a number outside its crate, and is named so that a
//! review finds every use (`grep from_raw`).
//!
//! Outside the declaring crate, neither the number nor a constructor is reachable:
//!
//! ```compile_fail
//! let v = plc_model::VarId(3); // the field is private
//! ```
//! ```compile_fail
//! let v = plc_model::VarId::new(3); // `new` is the declaring crate's own
//! ```
//! ```compile_fail
//! let n = plc_model::VarId::from_raw(3).0; // read the number with `raw()`
//! ```
//! ```
//! use plc_model::{Arena, VarId};
//! let mut names: Arena<VarId, &str> = Arena::new();
//! let a = names.push("A");
//! let b = names.push("B");
//! assert_eq!(names[b], "B");
//! assert_eq!(names.ids().collect::<Vec<_>>(), [a, b]);
//! assert_eq!(names.get_id(2), None);
//! ```
//!
//! It deliberately does not tag an id with the arena it came from (as rustc's `IndexVec` does
//! not): an id of one program used with another is a logic error that bounds checks catch.
//! The shape follows rust-analyzer's `la_arena` and rustc's `IndexVec`.

use std::fmt;
use std::marker::PhantomData;
use std::ops::{Deref, DerefMut, Index, IndexMut};

/// Proof that an id is being made by an [`Arena`]: only this module can make one, so
/// [`Idx::from_arena`] cannot be called from outside it.
#[derive(Copy, Clone)]
pub struct ArenaMade(());

/// A typed dense index (implemented by [`index_type!`](crate::index_type)).
pub trait Idx: Copy + Eq + Ord + std::hash::Hash + fmt::Debug {
    /// The id at position `raw`; callable only with the arena's proof.
    fn from_arena(raw: u32, made: ArenaMade) -> Self;
    /// The position in the owning arena.
    fn index(self) -> usize;
}

/// Values indexed by the ids it hands out. Dereferences to a slice, so positional reads
/// (`arena[i]` with a `usize`, `iter()`, `len()`) work as on a `Vec`; what it adds is that an id
/// comes from it.
#[derive(Clone, PartialEq)]
pub struct Arena<I, T> {
    items: Vec<T>,
    id: PhantomData<fn(I) -> I>,
}

impl<I: Idx, T> Arena<I, T> {
    pub fn new() -> Self {
        Arena {
            items: Vec::new(),
            id: PhantomData,
        }
    }

    pub fn with_capacity(n: usize) -> Self {
        Arena {
            items: Vec::with_capacity(n),
            id: PhantomData,
        }
    }

    /// Adds `value` and returns its id.
    pub fn push(&mut self, value: T) -> I {
        let id = self.next_id();
        self.items.push(value);
        id
    }

    /// The id the next [`push`](Arena::push) will return.
    pub fn next_id(&self) -> I {
        let raw = u32::try_from(self.items.len()).expect("an arena holds at most 2^32 - 1 values");
        I::from_arena(raw, ArenaMade(()))
    }

    /// The id of the value at `index`.
    ///
    /// # Panics
    /// If the arena holds no value there.
    #[inline]
    #[track_caller]
    pub fn id(&self, index: usize) -> I {
        if index >= self.items.len() {
            no_value_at(index, self.items.len())
        }
        I::from_arena(index as u32, ArenaMade(()))
    }

    /// The id of the value at `index`, if the arena holds one.
    pub fn get_id(&self, index: usize) -> Option<I> {
        (index < self.items.len()).then(|| I::from_arena(index as u32, ArenaMade(())))
    }

    /// Every id, in order.
    pub fn ids(&self) -> impl DoubleEndedIterator<Item = I> + ExactSizeIterator + 'static {
        (0..self.items.len() as u32).map(|i| I::from_arena(i, ArenaMade(())))
    }

    /// Every value with its id, in order.
    pub fn iter_enumerated(&self) -> impl DoubleEndedIterator<Item = (I, &T)> + ExactSizeIterator {
        self.items
            .iter()
            .enumerate()
            .map(|(i, v)| (I::from_arena(i as u32, ArenaMade(())), v))
    }

    /// The values, as a `Vec` (for a consumer that takes ownership).
    pub fn into_vec(self) -> Vec<T> {
        self.items
    }

    pub fn reserve(&mut self, n: usize) {
        self.items.reserve(n);
    }

    /// Removes the last value; its id is no longer valid.
    pub fn pop(&mut self) -> Option<T> {
        self.items.pop()
    }

    /// Removes and returns the values from `at` on; their ids are no longer valid.
    pub fn split_off(&mut self, at: usize) -> Vec<T> {
        self.items.split_off(at)
    }

    /// Removes every value from `len` on; the ids from `len` on are no longer valid.
    pub fn truncate(&mut self, len: usize) {
        self.items.truncate(len);
    }
}

#[cold]
#[inline(never)]
#[track_caller]
fn no_value_at(index: usize, len: usize) -> ! {
    panic!("no value at {index} in an arena of {len}")
}

impl<I: Idx, T> Default for Arena<I, T> {
    fn default() -> Self {
        Arena::new()
    }
}

impl<I: Idx, T> From<Vec<T>> for Arena<I, T> {
    fn from(items: Vec<T>) -> Self {
        assert!(
            u32::try_from(items.len()).is_ok(),
            "an arena holds at most 2^32 - 1 values"
        );
        Arena {
            items,
            id: PhantomData,
        }
    }
}

impl<I: Idx, T> FromIterator<T> for Arena<I, T> {
    fn from_iter<It: IntoIterator<Item = T>>(iter: It) -> Self {
        Arena::from(iter.into_iter().collect::<Vec<T>>())
    }
}

impl<I: Idx, T> Extend<T> for Arena<I, T> {
    fn extend<It: IntoIterator<Item = T>>(&mut self, iter: It) {
        self.items.extend(iter);
        assert!(
            u32::try_from(self.items.len()).is_ok(),
            "an arena holds at most 2^32 - 1 values"
        );
    }
}

impl<I, T> Deref for Arena<I, T> {
    type Target = [T];
    fn deref(&self) -> &[T] {
        &self.items
    }
}

impl<I, T> DerefMut for Arena<I, T> {
    fn deref_mut(&mut self) -> &mut [T] {
        &mut self.items
    }
}

impl<I: Idx, T> Index<I> for Arena<I, T> {
    type Output = T;
    #[inline]
    fn index(&self, id: I) -> &T {
        &self.items[id.index()]
    }
}

impl<I: Idx, T> IndexMut<I> for Arena<I, T> {
    #[inline]
    fn index_mut(&mut self, id: I) -> &mut T {
        &mut self.items[id.index()]
    }
}

impl<I: Idx, T> Index<usize> for Arena<I, T> {
    type Output = T;
    #[inline]
    fn index(&self, i: usize) -> &T {
        &self.items[i]
    }
}

impl<I: Idx, T> IndexMut<usize> for Arena<I, T> {
    #[inline]
    fn index_mut(&mut self, i: usize) -> &mut T {
        &mut self.items[i]
    }
}

impl<I: Idx, T> Index<std::ops::Range<usize>> for Arena<I, T> {
    type Output = [T];
    #[inline]
    fn index(&self, r: std::ops::Range<usize>) -> &[T] {
        &self.items[r]
    }
}

impl<'a, I, T> IntoIterator for &'a Arena<I, T> {
    type Item = &'a T;
    type IntoIter = std::slice::Iter<'a, T>;
    fn into_iter(self) -> Self::IntoIter {
        self.items.iter()
    }
}

impl<I, T> IntoIterator for Arena<I, T> {
    type Item = T;
    type IntoIter = std::vec::IntoIter<T>;
    fn into_iter(self) -> Self::IntoIter {
        self.items.into_iter()
    }
}

impl<I, T: fmt::Debug> fmt::Debug for Arena<I, T> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        self.items.fmt(f)
    }
}

/// Ids numbered in order before their values exist: a resolver numbers every rung before it
/// resolves any, so that a jump has its target's id when the target comes later. The values are
/// then pushed in the same order; [`Program::new`](crate::Program::new) checks that every id the
/// program names is one it holds.
#[derive(Clone, Debug)]
pub struct Numbering<I> {
    next: u32,
    id: PhantomData<fn(I) -> I>,
}

impl<I: Idx> Numbering<I> {
    /// Numbers from the first id.
    pub fn new() -> Self {
        Numbering {
            next: 0,
            id: PhantomData,
        }
    }
    /// Numbers on from `first`.
    pub fn starting_at(first: I) -> Self {
        Numbering {
            next: first.index() as u32,
            id: PhantomData,
        }
    }
    /// Numbers on from the ids `arena` has handed out.
    pub fn following<T>(arena: &Arena<I, T>) -> Self {
        Numbering {
            next: arena.next_id().index() as u32,
            id: PhantomData,
        }
    }
    /// The next id.
    pub fn next_id(&mut self) -> I {
        let id = I::from_arena(self.next, ArenaMade(()));
        self.next = self.next.checked_add(1).expect("at most 2^32 - 1 ids");
        id
    }
    /// Numbers `n` ids that another part has already given out (in order).
    pub fn skip(&mut self, n: usize) {
        self.next = u32::try_from(self.next as usize + n).expect("at most 2^32 - 1 ids");
    }
    /// How many ids have been numbered (including those before [`following`](Numbering::following)'s arena's end).
    pub fn count(&self) -> usize {
        self.next as usize
    }
}

impl<I: Idx> Default for Numbering<I> {
    fn default() -> Self {
        Numbering::new()
    }
}

/// Declares a typed dense index: an opaque `u32` that its [`Arena`] hands out (module docs).
#[macro_export]
macro_rules! index_type {
    ($(#[$m:meta])* $name:ident) => {
        $(#[$m])*
        #[derive(Copy, Clone, Debug, PartialEq, Eq, PartialOrd, Ord, Hash)]
        pub struct $name(u32);
        impl $name {
            /// The position in the owning arena.
            #[inline]
            pub fn index(self) -> usize {
                self.0 as usize
            }
            /// The id's number, for packing into a wider word or a graph library's node index;
            /// only the owning arena turns a number back into an id.
            #[inline]
            pub fn raw(self) -> u32 {
                self.0
            }
            /// The id whose [`raw`](Self::raw) number is `raw`: only to decode an id that was
            /// packed with `raw()` (a bit-packed atomic word, a range of consecutive ids one
            /// plan holds); a new id comes from its arena.
            #[inline]
            pub fn from_raw(raw: u32) -> Self {
                $name(raw)
            }
            /// The id numbered `raw`, for the declaring crate's own ids that index no arena.
            #[allow(dead_code)]
            #[inline]
            pub(crate) const fn new(raw: u32) -> Self {
                $name(raw)
            }
        }
        impl $crate::arena::Idx for $name {
            #[inline]
            fn from_arena(raw: u32, _: $crate::arena::ArenaMade) -> Self {
                $name(raw)
            }
            #[inline]
            fn index(self) -> usize {
                self.0 as usize
            }
        }
    };
}
