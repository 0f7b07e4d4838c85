//! Post-dominators and control dependences (Zhao & Yan, 2012, §2; Ferrante, Ottenstein & Warren 1987,
//! "The program dependence graph and its use in optimization").
//!
//! Definitions, for a graph with exit node STOP: Y post-dominates X if every path from X to STOP
//! passes through Y (reflexive); the immediate post-dominator ipdom(X) is the strict
//! post-dominator closest to X; the post-dominator tree links each node to its ipdom and is rooted
//! at STOP. Y is control dependent on X if X has a successor from which every path to STOP passes
//! Y while X itself is not strictly post-dominated by Y: X decides whether Y runs.
//!
//! Post-dominators are dominators of the reversed graph rooted at STOP, computed with the
//! Semi-NCA algorithm of [`plc_graph::dominators`] in near-linear time. Nodes that cannot
//! reach STOP (an endless jump loop) have no post-dominator in the true sense; for each such
//! region (a sink strongly connected part of the nodes that cannot reach STOP) we add one virtual
//! edge from its last node to STOP, report the region as a warning, and compute the tree on the
//! augmented graph, as compilers do for infinite loops. Virtual edges never cause dependences.
//!
//! Control dependences by the FOW walk: for each edge A→B where B does not post-dominate A, every
//! node on the tree path from B up to ipdom(A) (exclusive) is control dependent on A; when that
//! path meets A itself (a loop), A is included; a self loop A→A makes A depend on itself. Each dependence keeps the edge that causes it.
//! Cost: O(E + |CD|).

use plc_graph::{dominators, reachable, strongly_connected_components, Csr, DominatorTree};

/// The post-dominator tree of a graph.
#[derive(Clone, Debug)]
pub struct PostDominators {
    tree: DominatorTree,
    /// Virtual edges added from nodes of endless loops to STOP.
    pub virtual_edges: Vec<(u32, u32)>,
    /// Regions (sorted node lists) that cannot reach STOP.
    pub endless: Vec<Vec<u32>>,
}

impl PostDominators {
    /// ipdom(n); `None` for STOP itself.
    pub fn immediate(&self, n: u32) -> Option<u32> {
        self.tree.immediate_dominator(n)
    }
    /// True if `a` post-dominates `b` (reflexive).
    pub fn post_dominates(&self, a: u32, b: u32) -> bool {
        self.tree.dominates(a, b)
    }
    /// Children of `n` in the post-dominator tree.
    pub fn children(&self, n: u32) -> &[u32] {
        self.tree.children(n)
    }
    pub fn stop(&self) -> u32 {
        self.tree.root()
    }
}

/// Post-dominators of the graph given by `edges` over `node_count` nodes, with exit `stop`.
pub fn post_dominators(node_count: usize, edges: &[(u32, u32)], stop: u32) -> PostDominators {
    let forward = Csr::from_edges(node_count, edges);
    let mut reverse = forward.reversed();
    // Which nodes reach STOP?
    let reaches = reachable(&reverse, stop);
    let mut virtual_edges = Vec::new();
    let mut endless = Vec::new();
    if reaches.iter().any(|r| !r) {
        // Sink components of the subgraph of nodes that cannot reach STOP.
        let sub: Vec<(u32, u32)> = edges
            .iter()
            .copied()
            .filter(|&(a, b)| !reaches[a as usize] && !reaches[b as usize])
            .collect();
        let g = Csr::from_edges(node_count, &sub);
        let sccs = strongly_connected_components(&g);
        let mut has_exit = vec![false; sccs.len()];
        for &(a, b) in &sub {
            if sccs.component_of(a) != sccs.component_of(b) {
                has_exit[sccs.component_of(a) as usize] = true;
            }
        }
        for c in 0..sccs.len() as u32 {
            let members = sccs.members(c);
            if has_exit[c as usize] || reaches[members[0] as usize] {
                continue;
            }
            let last = *members.iter().max().expect("components are non-empty");
            virtual_edges.push((last, stop));
            endless.push(members.to_vec());
        }
        let mut all = edges.to_vec();
        all.extend_from_slice(&virtual_edges);
        reverse = Csr::from_edges(node_count, &all).reversed();
        debug_assert!(reachable(&reverse, stop).iter().all(|&r| r));
    }
    PostDominators {
        tree: dominators(&reverse, stop),
        virtual_edges,
        endless,
    }
}

/// `dependent` is control dependent on `controller` because of CFG edge `edge`.
#[derive(Copy, Clone, Debug, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub struct ControlDependence {
    pub controller: u32,
    pub dependent: u32,
    /// Index of the causing edge in the edge list given to [`control_dependences`].
    pub edge: u32,
}

/// Control dependences by the Ferrante–Ottenstein–Warren walk, for the edges whose source
/// `include(source)` accepts. Sorted by (controller, dependent, edge).
pub fn control_dependences(
    edges: &[(u32, u32)],
    pdom: &PostDominators,
    include: impl Fn(u32) -> bool,
) -> Vec<ControlDependence> {
    let mut out = Vec::new();
    for (i, &(a, b)) in edges.iter().enumerate() {
        if !include(a) {
            continue;
        }
        if a == b {
            // A self loop: the rung decides whether it runs again (the walk below would stop at
            // once, since every node post-dominates itself).
            out.push(ControlDependence {
                controller: a,
                dependent: a,
                edge: i as u32,
            });
            continue;
        }
        if pdom.post_dominates(b, a) {
            continue;
        }
        let stop_at = pdom.immediate(a);
        let mut x = Some(b);
        while let Some(n) = x {
            if Some(n) == stop_at {
                break;
            }
            out.push(ControlDependence {
                controller: a,
                dependent: n,
                edge: i as u32,
            });
            x = pdom.immediate(n);
        }
    }
    out.sort_unstable();
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Zhao & Yan's Example B as a bare graph (nodes 0..=11 are R1..R12, 12 START, 13 STOP).
    fn example_b() -> Vec<(u32, u32)> {
        vec![
            (12, 0),
            (0, 8),
            (0, 1),
            (1, 2),
            (2, 4),
            (2, 3),
            (4, 5),
            (5, 6),
            (6, 7),
            (7, 2),
            (3, 8),
            (8, 9),
            (9, 10),
            (9, 11),
            (10, 9),
            (11, 9),
            (9, 13),
        ]
    }

    #[test]
    fn example_b_ipdoms_and_cdg() {
        let edges = example_b();
        let pd = post_dominators(14, &edges, 13);
        let ipdom: Vec<Option<u32>> = (0..14).map(|n| pd.immediate(n)).collect();
        // START→R1, R1→R9, R2→R3, R3→R4, R4→R9, R5→R6, R6→R7, R7→R8, R8→R3, R9→R10, R10→STOP, R11→R10, R12→R10
        assert_eq!(
            ipdom,
            vec![
                Some(8),
                Some(2),
                Some(3),
                Some(8),
                Some(5),
                Some(6),
                Some(7),
                Some(2),
                Some(9),
                Some(13),
                Some(9),
                Some(9),
                Some(0),
                None
            ]
        );
        let cd = control_dependences(&edges, &pd, |_| true);
        let pairs: std::collections::BTreeSet<(u32, u32)> =
            cd.iter().map(|d| (d.controller, d.dependent)).collect();
        let want: std::collections::BTreeSet<(u32, u32)> = [
            (0, 1),
            (0, 2),
            (0, 3),
            (2, 4),
            (2, 5),
            (2, 6),
            (2, 7),
            (2, 2),
            (9, 10),
            (9, 11),
            (9, 9),
        ]
        .into_iter()
        .collect();
        assert_eq!(pairs, want);
    }

    #[test]
    fn endless_loop_gets_a_virtual_exit() {
        // 0 START → 1 → 2 → 1 (no way out); 3 STOP.
        let edges = vec![(0, 1), (1, 2), (2, 1)];
        let pd = post_dominators(4, &edges, 3);
        assert_eq!(pd.endless, vec![vec![1, 2]]);
        assert_eq!(pd.virtual_edges, vec![(2, 3)]);
        assert_eq!(pd.immediate(1), Some(2));
        assert_eq!(pd.immediate(0), Some(1));
    }
}
