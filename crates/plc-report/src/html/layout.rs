//! A layered graph layout for the HTML report's CFG and post-dominator tree: a simple Sugiyama
//! scheme (Sugiyama, Tagawa & Toda 1981). Cycles are broken by reversing the back edges of a
//! depth-first search, nodes are layered by longest path from the sources, edges that span
//! several layers pass through dummy nodes, and each layer is ordered by repeated barycentre
//! sweeps (down, then up), keeping the order with the fewest crossings seen.
//!
//! Invariants: the layout is a pure function of the node widths and the edge list (same input,
//! same coordinates); every edge `u → v` with `u != v` gets a polyline from `u` to `v` (a
//! reversed back edge is reversed back, so it still runs from `u` to `v`); a self loop gets an
//! empty polyline (the caller draws it). O((V + E') · sweeps · log) with E' the edges after
//! dummies, plus the crossing counts (quadratic in the edges between two layers).
//!
//! Deliberately not here: coordinate assignment beyond centring each layer (no
//! Brandes–Köpf), edge routing around nodes, and drawing (`graphs`).

/// Node height and spacing.
pub(super) const NODE_H: f64 = 22.0;
const LAYER_GAP: f64 = 34.0;
const NODE_GAP: f64 = 14.0;
const DUMMY_W: f64 = 8.0;
const SWEEPS: usize = 8;

/// A computed layout.
#[derive(Clone, Debug, PartialEq)]
pub(super) struct Layered {
    /// Top-left corner of each real node.
    pub pos: Vec<(f64, f64)>,
    /// Layer of each real node.
    pub layer: Vec<u32>,
    /// Per input edge: its polyline from the source's bottom to the target's top.
    pub edges: Vec<Vec<(f64, f64)>>,
    /// Per input edge: true if it was reversed to break a cycle (drawn as a back edge).
    pub back: Vec<bool>,
    pub width: f64,
    pub height: f64,
    /// Crossings between adjacent layers in the final order.
    pub crossings: usize,
}

/// The back edges of a depth-first search from the nodes without predecessors (in index
/// order), then from any node not yet visited.
fn back_edges(n: usize, edges: &[(usize, usize)]) -> Vec<bool> {
    let mut out_edges: Vec<Vec<usize>> = vec![Vec::new(); n];
    let mut has_pred = vec![false; n];
    for (i, &(u, v)) in edges.iter().enumerate() {
        out_edges[u].push(i);
        if u != v {
            has_pred[v] = true;
        }
    }
    #[derive(Copy, Clone, PartialEq)]
    enum Mark {
        New,
        Open,
        Done,
    }
    let mut mark = vec![Mark::New; n];
    let mut back = vec![false; edges.len()];
    let roots = (0..n).filter(|&v| !has_pred[v]).chain(0..n);
    for root in roots {
        if mark[root] != Mark::New {
            continue;
        }
        let mut stack: Vec<(usize, usize)> = vec![(root, 0)];
        mark[root] = Mark::Open;
        while let Some(&mut (v, ref mut next)) = stack.last_mut() {
            if let Some(&e) = out_edges[v].get(*next) {
                *next += 1;
                let w = edges[e].1;
                match mark[w] {
                    Mark::New => {
                        mark[w] = Mark::Open;
                        stack.push((w, 0));
                    }
                    Mark::Open => back[e] = true,
                    Mark::Done => {}
                }
            } else {
                mark[v] = Mark::Done;
                stack.pop();
            }
        }
    }
    back
}

/// Longest-path layers of a DAG given as `(from, to)` pairs.
fn longest_path_layers(n: usize, dag: &[(usize, usize)]) -> Vec<u32> {
    let mut indeg = vec![0usize; n];
    let mut succ: Vec<Vec<usize>> = vec![Vec::new(); n];
    for &(u, v) in dag {
        succ[u].push(v);
        indeg[v] += 1;
    }
    let mut layer = vec![0u32; n];
    let mut ready: Vec<usize> = (0..n).rev().filter(|&v| indeg[v] == 0).collect();
    while let Some(u) = ready.pop() {
        for &v in &succ[u] {
            layer[v] = layer[v].max(layer[u] + 1);
            indeg[v] -= 1;
            if indeg[v] == 0 {
                ready.push(v);
            }
        }
    }
    layer
}

/// Crossings between layer `l` and `l + 1` for the segments `segs` (upper node, lower node).
fn crossings_between(pos: &[usize], segs: &[(usize, usize)]) -> usize {
    let mut c = 0;
    for (i, &(a, b)) in segs.iter().enumerate() {
        for &(x, y) in &segs[i + 1..] {
            let (pa, pb, px, py) = (pos[a], pos[b], pos[x], pos[y]);
            if (pa < px && pb > py) || (pa > px && pb < py) {
                c += 1;
            }
        }
    }
    c
}

/// The order of every layer after barycentre sweeps, and its crossing count.
fn order_layers(
    layers: &mut [Vec<usize>],
    segs_below: &[Vec<(usize, usize)>],
    total: usize,
) -> usize {
    let mut pos = vec![0usize; total];
    let place = |layers: &[Vec<usize>], pos: &mut Vec<usize>| {
        for l in layers {
            for (i, &v) in l.iter().enumerate() {
                pos[v] = i;
            }
        }
    };
    let count =
        |pos: &[usize]| -> usize { segs_below.iter().map(|s| crossings_between(pos, s)).sum() };
    place(layers, &mut pos);
    let mut best = (count(&pos), layers.to_vec());
    let mut up: Vec<Vec<usize>> = vec![Vec::new(); total];
    let mut down: Vec<Vec<usize>> = vec![Vec::new(); total];
    for s in segs_below {
        for &(a, b) in s {
            down[a].push(b);
            up[b].push(a);
        }
    }
    for sweep in 0..SWEEPS {
        let downward = sweep % 2 == 0;
        let range: Vec<usize> = if downward {
            (1..layers.len()).collect()
        } else {
            (0..layers.len().saturating_sub(1)).rev().collect()
        };
        for l in range {
            let neighbours = if downward { &up } else { &down };
            let mut keyed: Vec<(f64, usize, usize)> = layers[l]
                .iter()
                .enumerate()
                .map(|(i, &v)| {
                    let ns = &neighbours[v];
                    let bary = if ns.is_empty() {
                        i as f64
                    } else {
                        ns.iter().map(|&u| pos[u] as f64).sum::<f64>() / ns.len() as f64
                    };
                    (bary, i, v)
                })
                .collect();
            keyed.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
            layers[l] = keyed.into_iter().map(|k| k.2).collect();
            for (i, &v) in layers[l].iter().enumerate() {
                pos[v] = i;
            }
        }
        let c = count(&pos);
        if c < best.0 {
            best = (c, layers.to_vec());
        }
    }
    layers.clone_from_slice(&best.1);
    best.0
}

/// Lays out `n` nodes of widths `widths` with the edges `edges` (`from`, `to`), top to bottom.
pub(super) fn layered(widths: &[f64], edges: &[(usize, usize)]) -> Layered {
    let n = widths.len();
    let back = back_edges(n, edges);
    let dag: Vec<(usize, usize)> = edges
        .iter()
        .zip(&back)
        .filter(|((u, v), _)| u != v)
        .map(|(&(u, v), &b)| if b { (v, u) } else { (u, v) })
        .collect();
    let layer = longest_path_layers(n, &dag);
    let depth = layer.iter().copied().max().map_or(0, |m| m as usize + 1);
    // Real nodes, then dummies; chains[e] = the nodes edge e passes, top to bottom.
    let mut node_layer: Vec<u32> = layer.clone();
    let mut chains: Vec<Vec<usize>> = Vec::with_capacity(edges.len());
    for (&(u, v), &b) in edges.iter().zip(&back) {
        if u == v {
            chains.push(Vec::new());
            continue;
        }
        let (top, bottom) = if b { (v, u) } else { (u, v) };
        let mut chain = vec![top];
        for l in layer[top] + 1..layer[bottom] {
            node_layer.push(l);
            chain.push(node_layer.len() - 1);
        }
        chain.push(bottom);
        chains.push(chain);
    }
    let total = node_layer.len();
    let mut layers: Vec<Vec<usize>> = vec![Vec::new(); depth];
    for (v, &l) in node_layer.iter().enumerate() {
        layers[l as usize].push(v);
    }
    let mut segs_below: Vec<Vec<(usize, usize)>> = vec![Vec::new(); depth.saturating_sub(1)];
    for c in &chains {
        for w in c.windows(2) {
            segs_below[node_layer[w[0]] as usize].push((w[0], w[1]));
        }
    }
    let crossings = order_layers(&mut layers, &segs_below, total);
    let width_of = |v: usize| if v < n { widths[v] } else { DUMMY_W };
    let layer_w = |l: &Vec<usize>| {
        l.iter().map(|&v| width_of(v)).sum::<f64>() + NODE_GAP * l.len().saturating_sub(1) as f64
    };
    let width = layers.iter().map(layer_w).fold(0.0, f64::max);
    let mut xy = vec![(0.0, 0.0); total];
    for (li, l) in layers.iter().enumerate() {
        let mut x = (width - layer_w(l)) / 2.0;
        for &v in l {
            xy[v] = (x, li as f64 * (NODE_H + LAYER_GAP));
            x += width_of(v) + NODE_GAP;
        }
    }
    let centre = |v: usize, bottom: bool| {
        let (x, y) = xy[v];
        let y = if v >= n {
            y + NODE_H / 2.0
        } else if bottom {
            y + NODE_H
        } else {
            y
        };
        (x + width_of(v) / 2.0, y)
    };
    let polylines = chains
        .iter()
        .zip(&back)
        .map(|(c, &b)| {
            let k = c.len();
            let mut pts: Vec<(f64, f64)> = c
                .iter()
                .enumerate()
                .map(|(i, &v)| centre(v, i + 1 < k))
                .collect();
            if b {
                pts.reverse();
            }
            pts
        })
        .collect();
    Layered {
        pos: xy[..n].to_vec(),
        layer,
        edges: polylines,
        back,
        width,
        height: if depth == 0 {
            0.0
        } else {
            depth as f64 * (NODE_H + LAYER_GAP) - LAYER_GAP
        },
        crossings,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_chain_is_one_column_of_layers() {
        let l = layered(&[10.0; 4], &[(0, 1), (1, 2), (2, 3)]);
        assert_eq!(l.layer, vec![0, 1, 2, 3]);
        assert_eq!(l.crossings, 0);
        assert_eq!(l.back, vec![false; 3]);
        assert!(l.pos.iter().all(|p| p.0 == 0.0));
    }

    #[test]
    fn a_back_edge_is_reversed_and_still_drawn_from_its_source() {
        // 0 → 1 → 2 → 1: the loop-back 2 → 1 is the back edge.
        let l = layered(&[10.0; 3], &[(0, 1), (1, 2), (2, 1)]);
        assert_eq!(l.layer, vec![0, 1, 2]);
        assert_eq!(l.back, vec![false, false, true]);
        let e = &l.edges[2];
        assert_eq!(
            e.first().unwrap().1,
            l.pos[2].1,
            "starts at node 2 (its top)"
        );
        assert_eq!(
            e.last().unwrap().1,
            l.pos[1].1 + NODE_H,
            "ends at node 1 (its bottom)"
        );
    }

    #[test]
    fn long_edges_pass_dummies_and_barycentres_remove_crossings() {
        // 0 → {1, 2}; 1 → 4, 2 → 3 (crossing in the initial order 3, 4), and 0 → 4 long.
        let edges = [(0, 1), (0, 2), (1, 4), (2, 3), (0, 4)];
        let l = layered(&[10.0; 5], &edges);
        assert_eq!(l.layer, vec![0, 1, 1, 2, 2]);
        assert_eq!(l.edges[4].len(), 3, "one dummy on layer 1");
        assert_eq!(l.crossings, 0);
        // Same side: 1's child 4 is on 1's side of 2's child 3.
        assert_eq!(l.pos[1].0 < l.pos[2].0, l.pos[4].0 < l.pos[3].0);
    }

    #[test]
    fn a_self_loop_has_no_polyline() {
        let l = layered(&[10.0; 2], &[(0, 0), (0, 1)]);
        assert!(l.edges[0].is_empty());
        assert_eq!(l.layer, vec![0, 1]);
    }
}
