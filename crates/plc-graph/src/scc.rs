//! Strongly connected components of a [`Csr`] graph.
//!
//! # Definitions
//!
//! Two nodes **u** and **v** are *strongly connected* iff there is a path
//! from **u** to **v** and a path from **v** to **u** (every node is strongly
//! connected to itself through the empty path). The equivalence classes of
//! this relation are the *strongly connected components* (SCCs). Contracting
//! every SCC to a single node yields the *condensation*, which is acyclic.
//!
//! A component is *cyclic* iff it contains a cycle: it has more than one
//! member, or its single member has a self loop. In a control-flow graph the
//! cyclic components are exactly the loops (including loops nested in one
//! another, which end up in the same component).
//!
//! # Algorithm
//!
//! Tarjan's algorithm (R. E. Tarjan, *Depth-first search and linear graph
//! algorithms*, SIAM J. Computing 1(2), 1972) in the space-efficient variant
//! of D. J. Pearce (*A space-efficient algorithm for finding strongly
//! connected components*, Information Processing Letters 116(1), 2016 —
//! the same variant as petgraph's `TarjanScc`): a single `rindex` array
//! serves as DFS index, low-link and, once a node is finished, component id,
//! so no separate `lowlink`/`on_stack` arrays are needed.
//!
//! The depth-first search is iterative, with an explicit stack of frames
//! `(node, next edge, is_root)`: a 1,000,000-node chain is 1,000,000 frames
//! on the heap, not on the thread's stack.
//!
//! Tarjan's algorithm completes components in *reverse* topological order of
//! the condensation (a component is completed only after every component it
//! can reach). Pearce's variant hands out component ids counting down, so
//! after a final shift the ids are a topological order: for every edge
//! `u -> v` with `component_of(u) != component_of(v)`,
//! `component_of(u) < component_of(v)`.
//!
//! The member lists are then built by a counting sort of the nodes by
//! component, which leaves every list in ascending node order.
//!
//! # Complexity
//!
//! * Time: **O(V + E)**.
//! * Space: the result is `2V + C + 1` `u32`s (`C` components); the search
//!   needs at most `V` frames of 12 bytes and a `V`-element node stack.
//!
//! # What it does not do
//!
//! It does not find the loop *structure* inside a component (headers, nesting
//! of natural loops, irreducibility); use dominators for that. Components are
//! not ordered by size or by smallest member, only topologically.

use super::csr::{prefix_sum, shift_right, Csr};

/// The strongly connected components of a graph, numbered `0..len()` in a
/// topological order of the condensation.
///
/// Built by [`strongly_connected_components`].
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Sccs {
    /// Component of every node.
    component: Vec<u32>,
    /// `members[offsets[c]..offsets[c + 1]]` are the nodes of component `c`.
    offsets: Vec<u32>,
    /// Nodes grouped by component, ascending within each component.
    members: Vec<u32>,
}

impl Sccs {
    /// Number of components.
    #[inline]
    pub fn len(&self) -> usize {
        self.offsets.len() - 1
    }

    /// `true` iff there are no components, i.e. the graph has no nodes.
    #[inline]
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// The component containing `n`.
    ///
    /// Components are numbered topologically: for every edge `u -> v` between
    /// different components, `component_of(u) < component_of(v)`.
    ///
    /// # Panics
    ///
    /// If `n` is not a node of the graph.
    #[inline]
    pub fn component_of(&self, n: u32) -> u32 {
        self.component[n as usize]
    }

    /// The nodes of component `c`, in ascending order. Never empty.
    ///
    /// # Panics
    ///
    /// If `c >= len()`.
    #[inline]
    pub fn members(&self, c: u32) -> &[u32] {
        let c = c as usize;
        &self.members[self.offsets[c] as usize..self.offsets[c + 1] as usize]
    }

    /// `true` iff component `c` contains a cycle: it has more than one member,
    /// or its only member has a self loop in `g`.
    ///
    /// `g` must be the graph the components were computed from.
    ///
    /// # Panics
    ///
    /// If `c >= len()`.
    pub fn is_cyclic(&self, c: u32, g: &Csr) -> bool {
        match self.members(c) {
            [n] => g.successors(*n).contains(n),
            _ => true,
        }
    }
}

/// One DFS frame of the iterative search.
struct Frame {
    node: u32,
    /// Index into `g.targets` of the next successor to look at.
    next: u32,
    /// No successor reached a node with a smaller `rindex` (yet): `node` is
    /// the root of its component.
    root: bool,
}

/// Computes the strongly connected components of `g`, numbered in a
/// topological order of the condensation.
///
/// Iterative Tarjan/Pearce, **O(V + E)**, no recursion. See the
/// [module documentation](self).
pub fn strongly_connected_components(g: &Csr) -> Sccs {
    let n = g.node_count();
    // rindex[v]:
    //   0               unvisited;
    //   1..=live        DFS index / low-link of a node still being searched
    //                   (on the call stack or on `stack`);
    //   next_comp+1..=n component value of a finished node.
    // Live indices are recycled (`index` is decremented as nodes finish), so
    // the live range stays strictly below every component value handed out
    // so far; hence "rindex[w] < rindex[v]" is never true for a finished `w`.
    let mut rindex = vec![0u32; n];
    let mut index: u32 = 1;
    let mut next_comp: u32 = n as u32;
    let mut calls: Vec<Frame> = Vec::new();
    let mut stack: Vec<u32> = Vec::new();

    for start in 0..n as u32 {
        if rindex[start as usize] != 0 {
            continue;
        }
        rindex[start as usize] = index;
        index += 1;
        calls.push(Frame {
            node: start,
            next: g.edge_range(start).0,
            root: true,
        });

        while let Some(frame) = calls.last_mut() {
            let v = frame.node;
            let end = g.offsets[v as usize + 1];
            if frame.next < end {
                let w = g.targets[frame.next as usize];
                frame.next += 1;
                if rindex[w as usize] == 0 {
                    rindex[w as usize] = index;
                    index += 1;
                    calls.push(Frame {
                        node: w,
                        next: g.edge_range(w).0,
                        root: true,
                    });
                } else if rindex[w as usize] < rindex[v as usize] {
                    rindex[v as usize] = rindex[w as usize];
                    frame.root = false;
                }
                continue;
            }

            // All successors of `v` done: finish it.
            let root = frame.root;
            calls.pop();
            if root {
                let low = rindex[v as usize];
                index -= 1;
                while let Some(&top) = stack.last() {
                    if rindex[top as usize] < low {
                        break;
                    }
                    stack.pop();
                    rindex[top as usize] = next_comp;
                    index -= 1;
                }
                rindex[v as usize] = next_comp;
                next_comp -= 1;
            } else {
                stack.push(v);
            }
            // Propagate the low-link to the parent, as the recursive version
            // does after the recursive call returns.
            if let Some(parent) = calls.last_mut() {
                let p = parent.node as usize;
                if rindex[v as usize] < rindex[p] {
                    rindex[p] = rindex[v as usize];
                    parent.root = false;
                }
            }
        }
    }
    debug_assert!(stack.is_empty());

    // Component values are next_comp+1..=n, handed out in reverse topological
    // order (sinks first, with the highest values): subtracting next_comp + 1
    // gives ids 0..count in topological order.
    let count = n - next_comp as usize;
    let base = next_comp + 1;
    let mut component = rindex;
    let mut offsets = vec![0u32; count + 1];
    for c in component.iter_mut() {
        *c -= base;
        offsets[*c as usize + 1] += 1;
    }
    prefix_sum(&mut offsets);
    let mut members = vec![0u32; n];
    for (v, &c) in component.iter().enumerate() {
        let slot = &mut offsets[c as usize];
        members[*slot as usize] = v as u32;
        *slot += 1;
    }
    shift_right(&mut offsets);
    Sccs {
        component,
        offsets,
        members,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn two_loops_and_a_bridge() {
        // 0 -> 1 <-> 2 -> 3 <-> 4, 4 -> 4
        let g = Csr::from_edges(5, &[(0, 1), (1, 2), (2, 1), (2, 3), (3, 4), (4, 3), (4, 4)]);
        let s = strongly_connected_components(&g);
        assert_eq!(s.len(), 3);
        assert_eq!(s.members(s.component_of(0)), &[0]);
        assert_eq!(s.members(s.component_of(1)), &[1, 2]);
        assert_eq!(s.members(s.component_of(3)), &[3, 4]);
        assert!(s.component_of(0) < s.component_of(1));
        assert!(s.component_of(1) < s.component_of(3));
        assert!(!s.is_cyclic(s.component_of(0), &g));
        assert!(s.is_cyclic(s.component_of(1), &g));
    }

    #[test]
    fn empty() {
        let s = strongly_connected_components(&Csr::from_edges(0, &[]));
        assert!(s.is_empty());
    }
}
