//! Flow, anti and output data dependences between units in sequential order (Zhao & Yan, 2012, §2,
//! Definition 1), and their ASAP levels.
//!
//! For units S before T and a variable x:
//! - flow   S δf T: x ∈ OUT(S) ∧ x ∈ IN(T)   (read after write)
//! - anti   S δa T: x ∈ IN(S)  ∧ x ∈ OUT(T)  (write after read)
//! - output S δo T: x ∈ OUT(S) ∧ x ∈ OUT(T)  (write after write)
//!
//! [`data_dependences`] lists every such pair, exactly as the paper defines them, in
//! O(accesses + pairs) (plus a binary search per access): it indexes, per variable, the units
//! that read it and those that write it, in order, and pairs each access only with the earlier
//! accesses it conflicts with; no two units are ever compared blindly. [`data_levels`] levels the units in O(accesses) without
//! looking at pairs at all: per variable it keeps the level of the last writer and the highest
//! level of the readers since then, which is all that ASAP levelling needs (a later writer must
//! follow those readers and that writer; a reader must follow that writer).
//! [`data_dependences_pairwise`] is the O(units²) definition itself, kept as the reference that
//! the property tests and the speed benchmark compare against.
//!
//! Units are abstract (rungs, or tasks of the combined schedule): unit `i` is the `i`-th in
//! sequential order, and its IN/OUT are `reads.list(i)` / `writes.list(i)`.

use super::accesses::VarSets;
use plc_model::VarId;

/// The kind of a dependence.
#[derive(Copy, Clone, Debug, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub enum DepKind {
    Flow,
    Anti,
    Output,
    Control,
}

impl DepKind {
    pub fn name(self) -> &'static str {
        match self {
            DepKind::Flow => "flow",
            DepKind::Anti => "anti",
            DepKind::Output => "output",
            DepKind::Control => "control",
        }
    }
}

/// One data dependence `from δ to` caused by `var` (`from` < `to`, unit indices).
#[derive(Copy, Clone, Debug, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub struct DataDependence {
    pub from: u32,
    pub to: u32,
    pub kind: DepKind,
    pub var: VarId,
}

fn var_count(reads: &VarSets, writes: &VarSets) -> usize {
    let max = |s: &VarSets| {
        (0..s.len())
            .flat_map(|i| s.list(i).iter())
            .map(|v| v.index() + 1)
            .max()
            .unwrap_or(0)
    };
    max(reads).max(max(writes))
}

/// For each variable, the units that access it (through `sets`), in unit order, as one flat
/// array: `units[start[x]..start[x + 1]]`.
struct ByVar {
    start: Vec<u32>,
    units: Vec<u32>,
}

impl ByVar {
    fn new(sets: &VarSets, vars: usize) -> ByVar {
        let mut start = vec![0u32; vars + 1];
        for i in 0..sets.len() {
            for x in sets.list(i) {
                start[x.index() + 1] += 1;
            }
        }
        for x in 0..vars {
            start[x + 1] += start[x];
        }
        let mut fill = start.clone();
        let mut units = vec![0u32; sets.total()];
        for i in 0..sets.len() {
            for x in sets.list(i) {
                units[fill[x.index()] as usize] = i as u32;
                fill[x.index()] += 1;
            }
        }
        ByVar { start, units }
    }
    /// The units accessing `x` before unit `t`.
    fn before(&self, x: VarId, t: u32) -> &[u32] {
        let all = &self.units[self.start[x.index()] as usize..self.start[x.index() + 1] as usize];
        &all[..all.partition_point(|&u| u < t)]
    }
}

/// Every flow, anti and output dependence, sorted by (to, from, kind, var).
pub fn data_dependences(reads: &VarSets, writes: &VarSets) -> Vec<DataDependence> {
    let n = reads.len();
    let vars = var_count(reads, writes);
    let readers = ByVar::new(reads, vars);
    let writers = ByVar::new(writes, vars);
    let mut out = Vec::new();
    for t in 0..n {
        let start = out.len();
        let tu = t as u32;
        for &x in reads.list(t) {
            for &s in writers.before(x, tu) {
                out.push(DataDependence {
                    from: s,
                    to: tu,
                    kind: DepKind::Flow,
                    var: x,
                });
            }
        }
        for &x in writes.list(t) {
            for &s in readers.before(x, tu) {
                out.push(DataDependence {
                    from: s,
                    to: tu,
                    kind: DepKind::Anti,
                    var: x,
                });
            }
            for &s in writers.before(x, tu) {
                out.push(DataDependence {
                    from: s,
                    to: tu,
                    kind: DepKind::Output,
                    var: x,
                });
            }
        }
        out[start..].sort_unstable();
    }
    out
}

/// How many pairs of each data kind the every-pair definition gives, in total and per variable.
///
/// Computed without listing a single pair, in O(accesses · log accesses): for each access, the
/// number of earlier conflicting accesses of its variable is a binary search in the per-variable
/// index. A hot variable written by k rungs has k(k−1)/2 output pairs, so these counts are what a
/// report can always afford even when the pairs themselves are too many to list.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct DependenceCounts {
    pub flow: u64,
    pub anti: u64,
    pub output: u64,
    /// Per variable with at least one pair: (variable, flow, anti, output), by variable id.
    pub by_var: Vec<(VarId, u64, u64, u64)>,
}

impl DependenceCounts {
    /// All data pairs together.
    pub fn total(&self) -> u64 {
        self.flow + self.anti + self.output
    }
}

/// Counts the pairs [`data_dependences`] would list, per kind and per variable.
pub fn dependence_counts(reads: &VarSets, writes: &VarSets) -> DependenceCounts {
    let vars = var_count(reads, writes);
    let readers = ByVar::new(reads, vars);
    let writers = ByVar::new(writes, vars);
    // Per variable: its id (once a task writes it: every pair has a writer) and its counts.
    let mut per: Vec<(Option<VarId>, u64, u64, u64)> = vec![(None, 0, 0, 0); vars];
    for t in 0..reads.len() {
        let tu = t as u32;
        for &x in reads.list(t) {
            per[x.index()].1 += writers.before(x, tu).len() as u64;
        }
        for &x in writes.list(t) {
            let e = &mut per[x.index()];
            e.0 = Some(x);
            e.2 += readers.before(x, tu).len() as u64;
            e.3 += writers.before(x, tu).len() as u64;
        }
    }
    let mut c = DependenceCounts::default();
    for &(x, f, a, o) in &per {
        c.flow += f;
        c.anti += a;
        c.output += o;
        if let (Some(x), true) = (x, f + a + o > 0) {
            c.by_var.push((x, f, a, o));
        }
    }
    c
}

/// The *direct* data dependences: per variable, last writer → reader (flow), each reader since
/// the last write → the next writer (anti), writer → next writer (output). Sorted like
/// [`data_dependences`], and a subset of it.
///
/// Every pair of the full definition is implied by a path of direct pairs (a writer reaches a
/// later writer through the chain of output pairs between them, and a later reader through that
/// chain and the last writer's flow pair; a reader reaches a later writer through its anti pair
/// and the output chain), so any schedule that respects the direct pairs respects them all, and
/// ASAP levels over the direct pairs equal [`data_levels`]. Their number is at most the number
/// of accesses, O(accesses) to compute, where the full list can be quadratic in the writers of a
/// hot variable.
pub fn direct_dependences(reads: &VarSets, writes: &VarSets) -> Vec<DataDependence> {
    let vars = var_count(reads, writes);
    let mut last_writer: Vec<Option<u32>> = vec![None; vars];
    // Readers since the last write of each variable, as linked lists through `reader_links`.
    let mut readers_head: Vec<Option<u32>> = vec![None; vars];
    // Sized once, from the bounds below: at 1M rungs these vectors are hundreds of megabytes,
    // and growing them by doubling copies each into fresh memory the kernel must zero first.
    // Capacity never written is never touched, so the bound costs no memory.
    let mut reader_links: Vec<(u32, Option<u32>)> = Vec::with_capacity(reads.total());
    // At most one flow pair per read, one anti pair per reader link, one output pair per write.
    let mut out = Vec::with_capacity(2 * reads.total() + writes.total());
    for t in 0..reads.len() {
        let start = out.len();
        let tu = t as u32;
        for &x in reads.list(t) {
            if let Some(s) = last_writer[x.index()] {
                out.push(DataDependence {
                    from: s,
                    to: tu,
                    kind: DepKind::Flow,
                    var: x,
                });
            }
        }
        for &x in writes.list(t) {
            let mut node = readers_head[x.index()].take();
            while let Some(i) = node {
                let (s, next) = reader_links[i as usize];
                out.push(DataDependence {
                    from: s,
                    to: tu,
                    kind: DepKind::Anti,
                    var: x,
                });
                node = next;
            }
            if let Some(s) = last_writer[x.index()] {
                out.push(DataDependence {
                    from: s,
                    to: tu,
                    kind: DepKind::Output,
                    var: x,
                });
            }
            last_writer[x.index()] = Some(tu);
        }
        for &x in reads.list(t) {
            if writes.list(t).binary_search(&x).is_err() {
                reader_links.push((tu, readers_head[x.index()]));
                readers_head[x.index()] = Some(reader_links.len() as u32 - 1);
            }
        }
        out[start..].sort_unstable();
    }
    out
}

/// The definition applied literally: every ordered pair of units, every variable. O(n² · |vars|).
pub fn data_dependences_pairwise(reads: &VarSets, writes: &VarSets) -> Vec<DataDependence> {
    let n = reads.len();
    let mut out = Vec::new();
    for t in 0..n {
        for s in 0..t {
            let mut add = |kind, a: &[VarId], b: &[VarId]| {
                for &x in a {
                    if b.contains(&x) {
                        out.push(DataDependence {
                            from: s as u32,
                            to: t as u32,
                            kind,
                            var: x,
                        });
                    }
                }
            };
            add(DepKind::Flow, writes.list(s), reads.list(t));
            add(DepKind::Anti, reads.list(s), writes.list(t));
            add(DepKind::Output, writes.list(s), writes.list(t));
        }
    }
    out.sort_unstable_by_key(|d| (d.to, d.from, d.kind, d.var));
    out
}

/// Per-variable state of the incremental levelling.
#[derive(Copy, Clone, Default)]
struct VarState {
    /// 1 + level of the last writer (0: none yet).
    after_writer: u32,
    /// 1 + highest level of a reader since the last write (0: none).
    after_readers: u32,
}

/// Incremental ASAP levelling over units in sequential order, with extra per-unit lower bounds.
///
/// Levels are 0-based here; `floor(i)` is a lower bound for unit `i` that other constraints
/// impose (control dependences in the combined schedule), called after earlier units are levelled.
pub struct Leveller {
    vars: Vec<VarState>,
}

impl Leveller {
    pub fn new(var_count: usize) -> Leveller {
        Leveller {
            vars: vec![VarState::default(); var_count],
        }
    }

    /// Levels the next unit with IN `reads`, OUT `writes` and lower bound `floor`.
    pub fn place(&mut self, reads: &[VarId], writes: &[VarId], floor: u32) -> u32 {
        let mut level = floor;
        for x in reads {
            level = level.max(self.vars[x.index()].after_writer);
        }
        for x in writes {
            let s = self.vars[x.index()];
            level = level.max(s.after_writer).max(s.after_readers);
        }
        for x in reads {
            let s = &mut self.vars[x.index()];
            s.after_readers = s.after_readers.max(level + 1);
        }
        for x in writes {
            let s = &mut self.vars[x.index()];
            s.after_writer = level + 1;
            s.after_readers = 0;
        }
        level
    }
}

/// ASAP levels (0-based) of the data dependences alone, in O(accesses).
pub fn data_levels(reads: &VarSets, writes: &VarSets) -> Vec<u32> {
    let mut l = Leveller::new(var_count(reads, writes));
    (0..reads.len())
        .map(|i| l.place(reads.list(i), writes.list(i), 0))
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sets(lists: &[&[u32]]) -> VarSets {
        VarSets::from_lists(
            lists
                .iter()
                .map(|l| l.iter().map(|&v| VarId::from_raw(v)).collect::<Vec<_>>()),
        )
    }

    /// Zhao & Yan's Example A: R2 δo R3, R2 δf R4, R3 δf R4; levels {R1,R2,R5} {R3} {R4}.
    #[test]
    fn example_a() {
        // vars: 0 I0, 1 Q1, 2 A, 3 X, 4 B, 5 Y, 6 C, 7 Z
        let reads = sets(&[&[0], &[2], &[4], &[3], &[6]]);
        let writes = sets(&[&[1], &[3], &[3], &[5], &[7]]);
        let deps = data_dependences(&reads, &writes);
        let pairs: Vec<_> = deps.iter().map(|d| (d.from, d.to, d.kind)).collect();
        assert_eq!(
            pairs,
            vec![
                (1, 2, DepKind::Output),
                (1, 3, DepKind::Flow),
                (2, 3, DepKind::Flow)
            ]
        );
        assert_eq!(data_levels(&reads, &writes), vec![0, 0, 1, 2, 0]);
        assert_eq!(deps, data_dependences_pairwise(&reads, &writes));
    }

    #[test]
    fn reader_before_rewrite_orders_the_rewrite() {
        // 0 writes x; 1 reads x; 2 writes x; 3 reads x.
        let reads = sets(&[&[], &[0], &[], &[0]]);
        let writes = sets(&[&[0], &[], &[0], &[]]);
        assert_eq!(data_levels(&reads, &writes), vec![0, 1, 2, 3]);
    }
}
