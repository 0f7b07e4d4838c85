//! Post-dominators and SCCs of ladder-program-shaped control-flow graphs.
//!
//! The CFG is a chain `0 -> 1 -> ... -> n-1` (START, the rungs, STOP) plus,
//! every ~50 nodes, a forward jump over 1–5 rungs and, every ~500 nodes, a
//! back edge of 2–5 rungs (a loop). Post-dominators are the dominators of the
//! reversed graph rooted at STOP (`n - 1`).
//!
//! Run with `cargo bench --bench dominators`.

use std::hint::black_box;

use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion};
use petgraph::algo::dominators::simple_fast;
use petgraph::graph::{DiGraph, NodeIndex};
use petgraph::visit::Reversed;
use plc_deps::graph::{dominators, strongly_connected_components, Csr};

/// Deterministic xorshift64*, so every run benchmarks the same graph.
struct Rng(u64);

impl Rng {
    fn next(&mut self) -> u64 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        self.0.wrapping_mul(0x2545_F491_4F6C_DD1D)
    }

    /// Uniform in `lo..=hi`.
    fn range(&mut self, lo: u32, hi: u32) -> u32 {
        lo + (self.next() % u64::from(hi - lo + 1)) as u32
    }
}

/// Edges of a ladder-shaped CFG with `n` nodes.
fn ladder_cfg(n: u32) -> Vec<(u32, u32)> {
    let mut rng = Rng(0x9E37_79B9_7F4A_7C15);
    let mut edges: Vec<(u32, u32)> = Vec::with_capacity(n as usize + n as usize / 40);
    let mut next_jump = rng.range(25, 75);
    let mut next_back = rng.range(250, 750);
    for i in 0..n - 1 {
        edges.push((i, i + 1));
        if i == next_jump {
            let target = i + 1 + rng.range(1, 5);
            if target < n {
                edges.push((i, target));
            }
            next_jump = i + rng.range(25, 75);
        }
        if i == next_back {
            let span = rng.range(2, 5);
            if i > span {
                edges.push((i, i - span));
            }
            next_back = i + rng.range(250, 750);
        }
    }
    edges
}

/// The same graph for petgraph (the chain makes node `n - 1` exist).
fn petgraph_of(edges: &[(u32, u32)]) -> DiGraph<(), ()> {
    DiGraph::from_edges(edges.iter().copied())
}

fn bench(c: &mut Criterion) {
    let mut group = c.benchmark_group("cfg");
    group.sample_size(10);

    for n in [100_000u32, 1_000_000] {
        let edges = ladder_cfg(n);
        let g = Csr::from_edges(n as usize, &edges);
        let rev = g.reversed();
        let stop = n - 1;

        group.bench_with_input(BenchmarkId::new("csr_from_edges", n), &edges, |b, e| {
            b.iter(|| Csr::from_edges(n as usize, black_box(e)))
        });
        group.bench_with_input(BenchmarkId::new("reverse+postdominators", n), &g, |b, g| {
            b.iter(|| dominators(&black_box(g).reversed(), stop))
        });
        group.bench_with_input(BenchmarkId::new("postdominators", n), &rev, |b, rev| {
            b.iter(|| dominators(black_box(rev), stop))
        });
        group.bench_with_input(BenchmarkId::new("scc", n), &g, |b, g| {
            b.iter(|| strongly_connected_components(black_box(g)))
        });
    }

    // petgraph's Cooper–Harvey–Kennedy on the same shape, for comparison.
    let n = 100_000u32;
    let edges = ladder_cfg(n);
    let pg = petgraph_of(&edges);
    // Sanity check: both agree on every immediate post-dominator.
    let ours = dominators(&Csr::from_edges(n as usize, &edges).reversed(), n - 1);
    let theirs = simple_fast(Reversed(&pg), NodeIndex::new(n as usize - 1));
    for v in 0..n {
        let expected = theirs
            .immediate_dominator(NodeIndex::new(v as usize))
            .map(|d| d.index() as u32);
        assert_eq!(ours.immediate_dominator(v), expected, "node {v}");
    }
    group.bench_function(
        BenchmarkId::new("petgraph_simple_fast_postdominators", n),
        |b| b.iter(|| simple_fast(Reversed(black_box(&pg)), NodeIndex::new(n as usize - 1))),
    );

    group.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
