//! Generic graph algorithms on dense `u32`-indexed graphs.
//!
//! Nodes are the integers `0..n`; graphs are stored in compressed sparse row
//! form ([`Csr`]). Every algorithm here is iterative (no recursion, so a
//! million-node chain cannot overflow the stack), works on dense `Vec`s
//! rather than hash maps, and is linear or near-linear:
//!
//! * [`csr`]: the adjacency structure, built by counting sort, and its reverse.
//! * [`scc`]: strongly connected components (iterative Tarjan/Pearce),
//!   numbered in topological order of the condensation.
//! * [`dominators`](mod@dominators): dominator trees (Semi-NCA); post-dominators
//!   are the dominators of [`Csr::reversed`] rooted at the exit node.
#![forbid(unsafe_code)]

pub mod csr;
pub mod dominators;
pub mod scc;

pub use csr::{reachable, Csr};
pub use dominators::{dominators, DominatorTree};
pub use scc::{strongly_connected_components, Sccs};
