//! ASAP levelling of a dependence graph (Zhao & Yan, 2012, §3: "rungs with no dependence are level L1; a
//! rung depending on rungs at levels Li, Lj is at level max(i, j) + 1").
//!
//! [`asap_levels`] works on any edge list, in any order, with cycles: the nodes of a strongly
//! connected part share one level (the paper's control view has such parts when a loop's rungs
//! control one another). Self edges are ignored, as the paper does. O(V + E).
//! Levels are 0-based in the library and printed 1-based.

use plc_graph::{strongly_connected_components, Csr};

/// ASAP levels of `n` nodes under `edges` (from must come at a lower level than to).
pub fn asap_levels(n: usize, edges: &[(u32, u32)]) -> Vec<u32> {
    let g = Csr::from_edges(n, edges);
    let sccs = strongly_connected_components(&g);
    // Components are numbered in topological order: relax in that order.
    let mut level = vec![0u32; sccs.len()];
    for c in 0..sccs.len() as u32 {
        let here = level[c as usize];
        for &m in sccs.members(c) {
            for &s in g.successors(m) {
                let d = sccs.component_of(s);
                if d != c {
                    let l = &mut level[d as usize];
                    *l = (*l).max(here + 1);
                }
            }
        }
    }
    (0..n as u32)
        .map(|v| level[sccs.component_of(v) as usize])
        .collect()
}

/// Groups node indices by level: `groups[l]` lists the nodes at level `l`, ascending.
pub fn group_by_level(levels: &[u32]) -> Vec<Vec<u32>> {
    let count = levels.iter().map(|&l| l as usize + 1).max().unwrap_or(0);
    let mut groups = vec![Vec::new(); count];
    for (i, &l) in levels.iter().enumerate() {
        groups[l as usize].push(i as u32);
    }
    groups
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn chain_diamond_cycle() {
        assert_eq!(asap_levels(3, &[(0, 1), (1, 2)]), vec![0, 1, 2]);
        assert_eq!(
            asap_levels(4, &[(0, 1), (0, 2), (1, 3), (2, 3)]),
            vec![0, 1, 1, 2]
        );
        // 1 and 2 form a cycle; 3 after them; self edge on 0 ignored.
        assert_eq!(
            asap_levels(4, &[(0, 0), (0, 1), (1, 2), (2, 1), (2, 3)]),
            vec![0, 1, 1, 2]
        );
        assert_eq!(
            group_by_level(&[0, 1, 1, 2]),
            vec![vec![0], vec![1, 2], vec![3]]
        );
    }
}
