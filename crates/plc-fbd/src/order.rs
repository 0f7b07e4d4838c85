//! Execution order of a network: depth-first topological sort (the FBD text-generation paper), O(V + E).
//!
//! The search runs on the *predecessor* graph (a block's inputs first), so a block is placed
//! when the processing of all blocks it depends on has ended — the seed's "no element runs before
//! all its inputs are computed". Ties are broken by block id: the search starts from the blocks
//! in increasing id and visits a block's predecessors in increasing id; the order is the
//! post-order. So blocks with no arc between them keep the order of their ids (the execution
//! numbers of an FBD editor), and a block's inputs are placed just before it when nothing
//! placed them earlier. Every arc counts: data arcs, conditional arcs and control arcs (`after`).
//!
//! A network may name its *roots* (PLCopen: Beremiz's statement order): the search starts from
//! them in that order, then from the other blocks by id; so a root runs after what it depends on
//! and before the roots after it, each block just before its first consumer (Beremiz pulls a
//! block when a statement first reads it).
//!
//! A grey block met again closes a cycle (a back edge of the search); the blocks on it are
//! returned in data-flow order, starting from the smallest id.

use super::model::{BlockId, Network};

/// The topological order of `net`, or the blocks of a cycle (`a → b → … → a`, `a` the smallest).
pub fn topological_order(net: &Network) -> Result<Vec<BlockId>, Vec<BlockId>> {
    let n = net.blocks.len();
    // Predecessor lists in CSR form, each sorted by block id.
    let mut offsets = Vec::with_capacity(n + 1);
    let mut preds = Vec::new();
    offsets.push(0u32);
    for b in 0..n {
        preds.extend(net.predecessors(BlockId::new(b as u32)));
        offsets.push(preds.len() as u32);
    }
    #[derive(Copy, Clone, PartialEq)]
    enum Colour {
        White,
        Grey,
        Black,
    }
    let mut colour = vec![Colour::White; n];
    let mut order = Vec::with_capacity(n);
    // (block, next predecessor index)
    let mut stack: Vec<(u32, u32)> = Vec::new();
    let roots = net.roots.iter().map(|b| b.raw()).chain(0..n as u32);
    for root in roots {
        if colour[root as usize] != Colour::White {
            continue;
        }
        colour[root as usize] = Colour::Grey;
        stack.push((root, offsets[root as usize]));
        while let Some(top) = stack.last_mut() {
            let (v, i) = *top;
            if i < offsets[v as usize + 1] {
                top.1 += 1;
                let p = preds[i as usize];
                match colour[p.index()] {
                    Colour::White => {
                        colour[p.index()] = Colour::Grey;
                        stack.push((p.raw(), offsets[p.index()]));
                    }
                    Colour::Grey => {
                        // p feeds v; each stack entry is fed by the entry above it.
                        let at = stack
                            .iter()
                            .position(|&(b, _)| b == p.raw())
                            .expect("grey blocks are on the stack");
                        let mut cycle: Vec<BlockId> = std::iter::once(p)
                            .chain(stack[at + 1..].iter().rev().map(|&(b, _)| BlockId::new(b)))
                            .collect();
                        let min = cycle
                            .iter()
                            .enumerate()
                            .min_by_key(|(_, b)| net.block(**b).id)
                            .map(|(i, _)| i)
                            .unwrap_or(0);
                        cycle.rotate_left(min);
                        return Err(cycle);
                    }
                    Colour::Black => {}
                }
            } else {
                colour[v as usize] = Colour::Black;
                order.push(BlockId::new(v));
                stack.pop();
            }
        }
    }
    Ok(order)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::*;

    fn net(edges: &[(u32, u32)], ids: &[u32]) -> Network {
        let index = |id: u32| BlockId::new(ids.iter().position(|&x| x == id).unwrap() as u32);
        let blocks = ids
            .iter()
            .map(|&id| Block {
                id,
                op: Op::Move,
                path: String::new(),
                origin: plc_diag::Origin::NONE,
                inputs: edges
                    .iter()
                    .filter(|e| e.1 == id)
                    .map(|e| InputPin {
                        name: "IN".into(),
                        input: Some(Input::Arc {
                            from: index(e.0),
                            pin: 0,
                        }),
                        path: String::new(),
                    })
                    .collect(),
                outputs: vec![OutputPin {
                    name: "OUT".into(),
                    vars: vec![],
                }],
                cond: None,
                en: false,
                after: vec![],
                comment: None,
            })
            .collect();
        Network {
            id: "N".into(),
            label: None,
            comment: None,
            path: String::new(),
            origin: plc_diag::Origin::NONE,
            blocks,
            roots: vec![],
        }
    }

    fn ids(n: &Network, order: &[BlockId]) -> Vec<u32> {
        order.iter().map(|b| n.block(*b).id).collect()
    }

    #[test]
    fn independent_blocks_keep_id_order_and_inputs_come_first() {
        let n = net(&[(9, 1)], &[1, 5, 9]);
        assert_eq!(ids(&n, &topological_order(&n).unwrap()), vec![9, 1, 5]);
        let n = net(&[], &[2, 4, 7]);
        assert_eq!(ids(&n, &topological_order(&n).unwrap()), vec![2, 4, 7]);
    }

    #[test]
    fn a_cycle_is_reported_in_flow_order_from_its_smallest_block() {
        let n = net(&[(5, 6), (6, 7), (7, 5), (1, 5)], &[1, 5, 6, 7]);
        assert_eq!(ids(&n, &topological_order(&n).unwrap_err()), vec![5, 6, 7]);
        let n = net(&[(3, 3)], &[3]);
        assert_eq!(ids(&n, &topological_order(&n).unwrap_err()), vec![3]);
    }
}
