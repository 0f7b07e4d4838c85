//! A phase of a levelled plan's scan: the items each worker runs between two barriers (a
//! parallel phase: one slice per worker) or the items worker 0 runs alone (a sequential phase),
//! and the levels of the schedule it covers. Plain data below the planner (`plan`) and
//! the machine that runs it; it decides nothing.

use super::tasks::Item;
use std::ops::Range;

/// Whether a phase runs on all workers or on worker 0 alone.
#[derive(Clone, Debug, PartialEq, Eq)]
pub(in crate::parallel) enum PhaseKind {
    /// One slice of items per worker.
    Parallel(Vec<Vec<Item>>),
    /// Worker 0 runs these items, in task order.
    Sequential(Vec<Item>),
}

/// The state's lines a worker's slice of a parallel phase finds in another core's cache
/// (`remote`): line numbers (byte address / 64), ascending. Only a hint to the machine, which
/// prefetches them when the slice starts.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub(in crate::parallel) struct RemoteLines {
    /// Lines the slice reads whose latest value another worker wrote.
    pub(in crate::parallel) reads: Vec<u32>,
    /// Lines the slice writes that another worker has read or written since this worker last
    /// wrote them (a copy of them is in another core's cache).
    pub(in crate::parallel) writes: Vec<u32>,
}

/// One phase of a scan.
#[derive(Clone, Debug, PartialEq, Eq)]
pub(in crate::parallel) struct Phase {
    pub(in crate::parallel) kind: PhaseKind,
    /// The levels it runs.
    pub(in crate::parallel) levels: Range<usize>,
    /// Meet at the barrier before running it.
    pub(in crate::parallel) barrier_before: bool,
}

impl Phase {
    /// The items worker `w` runs in this phase.
    #[inline]
    pub(in crate::parallel) fn items_of(&self, w: usize) -> &[Item] {
        match &self.kind {
            PhaseKind::Parallel(slices) => slices.get(w).map_or(&[], |s| s.as_slice()),
            PhaseKind::Sequential(items) if w == 0 => items,
            PhaseKind::Sequential(_) => &[],
        }
    }

    pub(in crate::parallel) fn is_parallel(&self) -> bool {
        matches!(self.kind, PhaseKind::Parallel(_))
    }

    /// Every (worker, slice of items) of the phase.
    pub(in crate::parallel) fn slices(&self) -> Vec<(usize, &[Item])> {
        match &self.kind {
            PhaseKind::Parallel(s) => s.iter().map(|v| v.as_slice()).enumerate().collect(),
            PhaseKind::Sequential(items) => vec![(0, items.as_slice())],
        }
    }

    /// Every (worker, item) of the phase.
    pub(in crate::parallel) fn all_items(&self) -> impl Iterator<Item = (usize, &Item)> {
        self.slices()
            .into_iter()
            .flat_map(|(w, items)| items.iter().map(move |it| (w, it)))
    }
}
