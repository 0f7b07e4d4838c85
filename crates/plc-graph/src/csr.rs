//! Compressed sparse row (CSR) adjacency for dense `u32`-indexed graphs.
//!
//! # Representation
//!
//! A directed multigraph on the nodes `0..n` is stored as two flat vectors:
//!
//! * `offsets`, of length `n + 1`, non-decreasing, with `offsets[0] == 0` and
//!   `offsets[n] == edge_count`;
//! * `targets`, of length `edge_count`: the successors of node `v` are
//!   `targets[offsets[v]..offsets[v + 1]]`.
//!
//! This is the layout every algorithm in [`crate`] walks: one
//! contiguous slice per node, no per-node allocation, no hashing, and
//! 4 bytes per edge plus 4 bytes per node.
//!
//! # Construction
//!
//! [`Csr::from_edges`] is a stable counting sort of the edge list by source
//! node: **O(V + E)** time, two allocations (the two vectors above) and no
//! temporary buffer (the offsets array doubles as the fill cursor). The
//! successors of each node keep the order in which their edges were given,
//! and duplicate edges and self loops are kept as they are. [`Csr::reversed`]
//! builds the predecessor graph the same way; the predecessors of each node
//! come out in ascending source order.
//!
//! # Invariants and limits
//!
//! * `node_count < u32::MAX`: `u32::MAX` is reserved as a "no node" sentinel
//!   by the algorithms of this module tree.
//! * `edge_count <= u32::MAX`, since offsets are `u32`.
//! * Every target is `< node_count`; this is checked at construction, so the
//!   algorithms can index without further checks.
//!
//! # What it does not do
//!
//! The structure is immutable once built: there is no edge insertion or
//! removal (rebuild instead), no edge weights or ids, and no deduplication.

/// A directed multigraph on the nodes `0..node_count`, in compressed sparse
/// row form.
///
/// See the [module documentation](self) for the layout and its invariants.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Csr {
    /// `offsets[v]..offsets[v + 1]` is the range of `targets` holding the
    /// successors of `v`. Length `node_count + 1`.
    pub(crate) offsets: Vec<u32>,
    /// Concatenated successor lists. Length `edge_count`.
    pub(crate) targets: Vec<u32>,
}

impl Csr {
    /// Builds the graph on the nodes `0..node_count` with the given edges
    /// `(source, target)`.
    ///
    /// The successors of each node keep the order in which their edges
    /// appear in `edges`; duplicate edges and self loops are kept.
    ///
    /// Runs in **O(V + E)** time with no temporary allocation.
    ///
    /// # Panics
    ///
    /// If an endpoint is `>= node_count`, if `node_count >= u32::MAX`, or if
    /// there are more than `u32::MAX` edges.
    pub fn from_edges(node_count: usize, edges: &[(u32, u32)]) -> Csr {
        assert!(
            node_count < u32::MAX as usize,
            "Csr: node_count {node_count} must be below u32::MAX"
        );
        assert!(
            edges.len() <= u32::MAX as usize,
            "Csr: at most u32::MAX edges are supported, got {}",
            edges.len()
        );
        let mut offsets = vec![0u32; node_count + 1];
        for &(s, t) in edges {
            assert!(
                (s as usize) < node_count && (t as usize) < node_count,
                "Csr: edge ({s}, {t}) out of range for {node_count} nodes"
            );
            offsets[s as usize + 1] += 1;
        }
        prefix_sum(&mut offsets);
        let mut targets = vec![0u32; edges.len()];
        // `offsets[s]` is used as the fill cursor of `s`; afterwards it holds
        // the end of `s`'s range, i.e. the start of `s + 1`'s.
        for &(s, t) in edges {
            let slot = &mut offsets[s as usize];
            targets[*slot as usize] = t;
            *slot += 1;
        }
        shift_right(&mut offsets);
        Csr { offsets, targets }
    }

    /// Number of nodes; the nodes are `0..node_count()`.
    #[inline]
    pub fn node_count(&self) -> usize {
        self.offsets.len() - 1
    }

    /// Number of edges, duplicates and self loops included.
    #[inline]
    pub fn edge_count(&self) -> usize {
        self.targets.len()
    }

    /// The successors of `n`, in the order their edges were given.
    ///
    /// # Panics
    ///
    /// If `n >= node_count()`.
    #[inline]
    pub fn successors(&self, n: u32) -> &[u32] {
        let n = n as usize;
        &self.targets[self.offsets[n] as usize..self.offsets[n + 1] as usize]
    }

    /// The predecessor graph: an edge `v -> u` for every edge `u -> v`.
    ///
    /// The successors of each node in the result (its predecessors here) are
    /// in ascending order, with duplicates kept. **O(V + E)**.
    pub fn reversed(&self) -> Csr {
        let n = self.node_count();
        let mut offsets = vec![0u32; n + 1];
        for &t in &self.targets {
            offsets[t as usize + 1] += 1;
        }
        prefix_sum(&mut offsets);
        let mut targets = vec![0u32; self.targets.len()];
        for s in 0..n {
            let (lo, hi) = (self.offsets[s] as usize, self.offsets[s + 1] as usize);
            for &t in &self.targets[lo..hi] {
                let slot = &mut offsets[t as usize];
                targets[*slot as usize] = s as u32;
                *slot += 1;
            }
        }
        shift_right(&mut offsets);
        Csr { offsets, targets }
    }

    /// The range of `targets` holding the successors of `n`.
    #[inline]
    pub(crate) fn edge_range(&self, n: u32) -> (u32, u32) {
        (self.offsets[n as usize], self.offsets[n as usize + 1])
    }
}

/// In-place inclusive prefix sum.
pub(crate) fn prefix_sum(v: &mut [u32]) {
    let mut acc = 0u32;
    for x in v.iter_mut() {
        acc += *x;
        *x = acc;
    }
}

/// After a counting-sort fill, `offsets[v]` holds the end of `v`'s range for
/// `v < n`; shifting right by one turns ends into starts.
pub(crate) fn shift_right(offsets: &mut [u32]) {
    let n = offsets.len() - 1;
    for i in (1..=n).rev() {
        offsets[i] = offsets[i - 1];
    }
    offsets[0] = 0;
}

/// The nodes reachable from `from` (itself included), by an iterative depth-first search.
/// O(V + E).
pub fn reachable(g: &Csr, from: u32) -> Vec<bool> {
    let mut seen = vec![false; g.node_count()];
    let mut stack = vec![from];
    seen[from as usize] = true;
    while let Some(n) = stack.pop() {
        for &s in g.successors(n) {
            if !seen[s as usize] {
                seen[s as usize] = true;
                stack.push(s);
            }
        }
    }
    seen
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn order_and_duplicates_are_kept() {
        let g = Csr::from_edges(4, &[(2, 1), (0, 3), (2, 0), (0, 1), (2, 1), (3, 3)]);
        assert_eq!(g.node_count(), 4);
        assert_eq!(g.edge_count(), 6);
        assert_eq!(g.successors(0), &[3, 1]);
        assert_eq!(g.successors(1), &[] as &[u32]);
        assert_eq!(g.successors(2), &[1, 0, 1]);
        assert_eq!(g.successors(3), &[3]);
        let r = g.reversed();
        assert_eq!(r.edge_count(), 6);
        assert_eq!(r.successors(0), &[2]);
        assert_eq!(r.successors(1), &[0, 2, 2]);
        assert_eq!(r.successors(2), &[] as &[u32]);
        assert_eq!(r.successors(3), &[0, 3]);
    }

    #[test]
    fn empty_graph() {
        let g = Csr::from_edges(0, &[]);
        assert_eq!(g.node_count(), 0);
        assert_eq!(g.edge_count(), 0);
        assert_eq!(g.reversed(), g);
    }

    #[test]
    #[should_panic]
    fn out_of_range_edge_panics() {
        let _ = Csr::from_edges(2, &[(0, 2)]);
    }
}
