//! Property tests of `plc_deps::graph` against petgraph's reference
//! implementations, plus a few hand-written cases (including a
//! 1,000,000-node chain, which must not overflow the stack).

use petgraph::algo::{dominators::simple_fast, tarjan_scc};
use petgraph::graph::{DiGraph, NodeIndex};
use plc_deps::graph::{dominators, strongly_connected_components, Csr, DominatorTree, Sccs};
use proptest::prelude::*;

// ---------------------------------------------------------------- helpers

fn petgraph_of(n: usize, edges: &[(u32, u32)]) -> DiGraph<(), ()> {
    let mut g = DiGraph::with_capacity(n, edges.len());
    for _ in 0..n {
        g.add_node(());
    }
    for &(s, t) in edges {
        g.add_edge(NodeIndex::new(s as usize), NodeIndex::new(t as usize), ());
    }
    g
}

/// Checks `dom` against petgraph's `simple_fast` and against its own idom
/// chains: idom, reachability, depth, `dominates` for every pair, children.
fn check_dominators(n: usize, edges: &[(u32, u32)], root: u32) {
    let g = Csr::from_edges(n, edges);
    let dom = dominators(&g, root);
    let reference = simple_fast(&petgraph_of(n, edges), NodeIndex::new(root as usize));
    assert_eq!(dom.root(), root);

    for v in 0..n as u32 {
        let expected = reference
            .immediate_dominator(NodeIndex::new(v as usize))
            .map(|d| d.index() as u32);
        assert_eq!(dom.immediate_dominator(v), expected, "idom of {v}");
        let reachable = v == root || expected.is_some();
        assert_eq!(dom.is_reachable(v), reachable, "reachability of {v}");
    }
    check_tree_consistency(&dom, n);
}

/// `dominates`, `depth` and `children` agree with the idom chains.
fn check_tree_consistency(dom: &DominatorTree, n: usize) {
    let mut on_chain = vec![false; n];
    let mut chain = Vec::new();
    for b in 0..n as u32 {
        chain.clear();
        if dom.is_reachable(b) {
            let mut x = Some(b);
            while let Some(y) = x {
                chain.push(y);
                x = dom.immediate_dominator(y);
            }
            assert_eq!(*chain.last().unwrap(), dom.root());
            assert_eq!(dom.depth(b) as usize, chain.len() - 1, "depth of {b}");
        } else {
            assert_eq!(dom.depth(b), 0);
            assert!(dom.children(b).is_empty());
        }
        for &y in &chain {
            on_chain[y as usize] = true;
        }
        for a in 0..n as u32 {
            assert_eq!(
                dom.dominates(a, b),
                on_chain[a as usize],
                "dominates({a}, {b})"
            );
        }
        for &y in &chain {
            on_chain[y as usize] = false;
        }
        // children(b) = { v : idom(v) == b }, ascending.
        let expected: Vec<u32> = (0..n as u32)
            .filter(|&v| dom.immediate_dominator(v) == Some(b))
            .collect();
        assert_eq!(dom.children(b), &expected[..], "children of {b}");
    }
}

/// Checks `sccs` against petgraph's `tarjan_scc` and the topological numbering.
fn check_sccs(n: usize, edges: &[(u32, u32)]) {
    let g = Csr::from_edges(n, edges);
    let sccs = strongly_connected_components(&g);
    let mut expected: Vec<Vec<u32>> = tarjan_scc(&petgraph_of(n, edges))
        .into_iter()
        .map(|c| {
            let mut c: Vec<u32> = c.into_iter().map(|x| x.index() as u32).collect();
            c.sort_unstable();
            c
        })
        .collect();
    expected.sort();
    check_scc_structure(&sccs, &g);
    let mut ours: Vec<Vec<u32>> = (0..sccs.len() as u32)
        .map(|c| sccs.members(c).to_vec())
        .collect();
    ours.sort();
    assert_eq!(ours, expected);
}

/// Members ascending and consistent with `component_of`, topological
/// numbering on every edge, `is_cyclic` as defined.
fn check_scc_structure(sccs: &Sccs, g: &Csr) {
    let n = g.node_count();
    let mut total = 0;
    for c in 0..sccs.len() as u32 {
        let m = sccs.members(c);
        assert!(!m.is_empty());
        assert!(
            m.windows(2).all(|w| w[0] < w[1]),
            "members of {c} not ascending"
        );
        for &v in m {
            assert_eq!(sccs.component_of(v), c);
        }
        total += m.len();
        let cyclic = m.len() > 1 || g.successors(m[0]).contains(&m[0]);
        assert_eq!(sccs.is_cyclic(c, g), cyclic, "is_cyclic({c})");
    }
    assert_eq!(total, n);
    for u in 0..n as u32 {
        for &v in g.successors(u) {
            let (cu, cv) = (sccs.component_of(u), sccs.component_of(v));
            assert!(
                cu <= cv,
                "edge {u}->{v} goes from component {cu} back to {cv}"
            );
        }
    }
}

// ---------------------------------------------------------------- strategies

/// Arbitrary multigraphs: self loops, duplicate edges, unreachable nodes.
fn random_graph() -> impl Strategy<Value = (usize, Vec<(u32, u32)>, u32)> {
    (1usize..80).prop_flat_map(|n| {
        let edge = (0..n as u32, 0..n as u32);
        (Just(n), prop::collection::vec(edge, 0..=3 * n), 0..n as u32)
    })
}

/// Control-flow-like graphs: a chain 0 -> 1 -> ... -> n-1 plus random
/// forward and backward edges; deep DFS trees exercise path compression and
/// the NCA jump pointers.
fn chain_graph() -> impl Strategy<Value = (usize, Vec<(u32, u32)>, u32)> {
    (2usize..400).prop_flat_map(|n| {
        let edge = (0..n as u32, 0..n as u32);
        (
            Just(n),
            prop::collection::vec(edge, 0..n / 4 + 1),
            prop::bool::ANY,
        )
            .prop_map(|(n, extra, from_end)| {
                let mut edges: Vec<(u32, u32)> = (1..n as u32).map(|i| (i - 1, i)).collect();
                edges.extend(extra);
                if from_end {
                    // Post-dominator shape: reverse everything, root at the end.
                    for e in &mut edges {
                        *e = (e.1, e.0);
                    }
                    (n, edges, n as u32 - 1)
                } else {
                    (n, edges, 0)
                }
            })
    })
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(2000))]

    #[test]
    fn dominators_match_petgraph((n, edges, root) in random_graph()) {
        check_dominators(n, &edges, root);
    }

    #[test]
    fn sccs_match_petgraph((n, edges, _root) in random_graph()) {
        check_sccs(n, &edges);
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(500))]

    #[test]
    fn dominators_match_petgraph_on_chains((n, edges, root) in chain_graph()) {
        check_dominators(n, &edges, root);
    }

    #[test]
    fn sccs_match_petgraph_on_chains((n, edges, _root) in chain_graph()) {
        check_sccs(n, &edges);
    }
}

// ---------------------------------------------------------------- hand-written

#[test]
fn diamond() {
    //   0
    //  / \
    // 1   2
    //  \ /
    //   3
    let edges = [(0, 1), (0, 2), (1, 3), (2, 3)];
    let g = Csr::from_edges(4, &edges);
    let d = dominators(&g, 0);
    assert_eq!(d.immediate_dominator(3), Some(0));
    assert_eq!(d.children(0), &[1, 2, 3]);
    assert!(!d.dominates(1, 3) && !d.dominates(2, 3) && d.dominates(0, 3) && d.dominates(3, 3));
    let pd = dominators(&g.reversed(), 3);
    assert_eq!(pd.immediate_dominator(0), Some(3));
    assert_eq!(pd.immediate_dominator(1), Some(3));
    let s = strongly_connected_components(&g);
    assert_eq!(s.len(), 4);
    assert!((0..4).all(|c| !s.is_cyclic(c, &g)));
    check_dominators(4, &edges, 0);
    check_sccs(4, &edges);
}

#[test]
fn simple_loop() {
    // 0 -> 1 -> 2 -> 3 -> 4, 3 -> 1 (back edge), 2 -> 2 (self loop)
    let edges = [(0, 1), (1, 2), (2, 3), (3, 4), (3, 1), (2, 2)];
    let g = Csr::from_edges(5, &edges);
    let d = dominators(&g, 0);
    assert_eq!(
        (1..5)
            .map(|v| d.immediate_dominator(v).unwrap())
            .collect::<Vec<_>>(),
        vec![0, 1, 2, 3]
    );
    let s = strongly_connected_components(&g);
    assert_eq!(s.len(), 3);
    let body = s.component_of(1);
    assert_eq!(s.members(body), &[1, 2, 3]);
    assert!(s.is_cyclic(body, &g));
    assert!(s.component_of(0) < body && body < s.component_of(4));
    // A single node with a self loop is cyclic.
    let g2 = Csr::from_edges(2, &[(0, 1), (1, 1)]);
    let s2 = strongly_connected_components(&g2);
    assert!(s2.is_cyclic(s2.component_of(1), &g2));
    assert!(!s2.is_cyclic(s2.component_of(0), &g2));
    check_dominators(5, &edges, 0);
    check_sccs(5, &edges);
}

#[test]
fn unreachable_and_root_in_the_middle() {
    let edges = [(0, 1), (1, 2), (2, 0), (3, 1)];
    let g = Csr::from_edges(5, &edges);
    let d = dominators(&g, 1);
    assert_eq!(d.immediate_dominator(1), None);
    assert_eq!(d.immediate_dominator(2), Some(1));
    assert_eq!(d.immediate_dominator(0), Some(2));
    assert!(!d.is_reachable(3) && !d.is_reachable(4));
    assert!(!d.dominates(3, 3) && !d.dominates(1, 3));
    check_dominators(5, &edges, 1);
}

const BIG: u32 = 1_000_000;

#[test]
fn million_node_chain_dominators() {
    let edges: Vec<(u32, u32)> = (1..BIG).map(|i| (i - 1, i)).collect();
    let g = Csr::from_edges(BIG as usize, &edges);

    let d = dominators(&g, 0);
    for v in 1..BIG {
        assert_eq!(d.immediate_dominator(v), Some(v - 1));
    }
    assert_eq!(d.depth(BIG - 1), BIG - 1);
    assert!(d.dominates(0, BIG - 1) && d.dominates(BIG / 2, BIG - 1));
    assert!(!d.dominates(BIG - 1, 0));
    assert_eq!(d.children(BIG - 2), &[BIG - 1]);

    // Post-dominators: the same chain, reversed, rooted at the end.
    let pd = dominators(&g.reversed(), BIG - 1);
    for v in 0..BIG - 1 {
        assert_eq!(pd.immediate_dominator(v), Some(v + 1));
    }
    assert_eq!(pd.depth(0), BIG - 1);
    assert!(pd.dominates(BIG - 1, 0));
}

#[test]
fn million_node_chain_sccs() {
    // A chain: a million singleton components, in chain order.
    let mut edges: Vec<(u32, u32)> = (1..BIG).map(|i| (i - 1, i)).collect();
    let g = Csr::from_edges(BIG as usize, &edges);
    let s = strongly_connected_components(&g);
    assert_eq!(s.len(), BIG as usize);
    for v in 0..BIG {
        assert_eq!(s.component_of(v), v);
    }

    // Close it into a cycle: one million-node component, found 1M frames deep.
    edges.push((BIG - 1, 0));
    let g = Csr::from_edges(BIG as usize, &edges);
    let s = strongly_connected_components(&g);
    assert_eq!(s.len(), 1);
    assert_eq!(s.members(0).len(), BIG as usize);
    assert!(s.is_cyclic(0, &g));
}

#[test]
fn million_node_cycle_dominators() {
    // Cycle 0 -> 1 -> ... -> n-1 -> 0 rooted in the middle: the DFS wraps
    // around, and the post-dominators of the reversed graph do too.
    let mut edges: Vec<(u32, u32)> = (1..BIG).map(|i| (i - 1, i)).collect();
    edges.push((BIG - 1, 0));
    let g = Csr::from_edges(BIG as usize, &edges);
    let root = BIG / 2;
    let d = dominators(&g, root);
    for v in 0..BIG {
        let expected = if v == root {
            None
        } else {
            Some((v + BIG - 1) % BIG)
        };
        assert_eq!(d.immediate_dominator(v), expected);
    }
    assert_eq!(d.depth(root - 1), BIG - 1);
}

#[test]
fn many_shallow_semidominators_below_a_deep_chain() {
    // 0 -> 1 -> ... -> M, then M -> x for L nodes x, and 0 -> x for each x.
    // The DFS reaches every x from M (deep), but sdom(x) = idom(x) = 0.
    // Textbook Semi-NCA walks M idom links per x (M * L = 1e10 steps here);
    // with jump pointers it is O(log M) per x, so this finishes instantly.
    const M: u32 = 100_000;
    const L: u32 = 100_000;
    let n = (M + 1 + L) as usize;
    let mut edges: Vec<(u32, u32)> = (1..=M).map(|i| (i - 1, i)).collect();
    edges.extend((M + 1..M + 1 + L).map(|x| (M, x)));
    edges.extend((M + 1..M + 1 + L).map(|x| (0, x)));
    let g = Csr::from_edges(n, &edges);
    let start = std::time::Instant::now();
    let d = dominators(&g, 0);
    let elapsed = start.elapsed();
    for x in M + 1..M + 1 + L {
        assert_eq!(d.immediate_dominator(x), Some(0));
        assert_eq!(d.depth(x), 1);
    }
    assert_eq!(d.depth(M), M);
    assert!(
        elapsed < std::time::Duration::from_secs(5),
        "took {elapsed:?}"
    );
}
