//! Flow, anti and output data dependences between units in sequential order (seed 004, §2,
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
use crate::model::VarId;

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
                .map(|l| l.iter().map(|&v| VarId(v)).collect::<Vec<_>>()),
        )
    }

    /// Example A of seed 004: R2 δo R3, R2 δf R4, R3 δf R4; levels {R1,R2,R5} {R3} {R4}.
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
