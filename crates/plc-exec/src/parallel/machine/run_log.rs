//! The candidates of a run ([`Candidate`]: the sequential walk, a plan on the shared state, a
//! levelled plan on private states) and what a run did with them ([`RunLog`]): plain data,
//! filled by the machine and read by `explain` and `plc-deps run`.

use crate::parallel::choice::{Switch, WindowRecord};

/// One way to run a scan.
#[derive(Copy, Clone, Debug, PartialEq, Eq)]
pub enum Candidate {
    /// The sequential walk ([`Machine::run_scan`]) on worker 0.
    Sequential,
    /// The plan `plans[i]` on all workers: a levelled plan, or the dependence-driven one
    /// (named `par-deps`).
    Levelled(usize),
    /// The levelled plan `plans[i]` with each worker on a private state, handing over what it
    /// wrote after each phase (named `par-exchange`; `exchange`).
    Exchange(usize),
}

/// What a run did: which candidates ran how many scans, their last measured times, and every
/// switch between them.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct RunLog {
    /// Candidate names (`seq`, `par`, `par-deps`, `par-exchange`), by candidate index.
    pub candidates: Vec<String>,
    /// Scans run on each candidate.
    pub scans_on: Vec<u64>,
    /// The last measured ns per scan of each candidate (`None`: never measured).
    pub estimates: Vec<Option<u64>>,
    /// Every change of the running candidate.
    pub switches: Vec<Switch>,
    /// The candidate that ran last.
    pub last: usize,
    /// Runs of scans on one candidate: (first scan, candidate), ascending.
    pub segments: Vec<(u64, usize)>,
    /// Per candidate: the waits per scan of a dependence-driven plan (`None` for the others).
    pub waits: Vec<Option<u64>>,
    /// The windows of scans as they ran, with their times: the first 64, then those of every
    /// measurement that ended in a switch (bounded: `choice`).
    pub windows: Vec<WindowRecord>,
    /// Windows run but not in `windows`.
    pub windows_unlogged: u64,
}

impl RunLog {
    /// The candidate that ran scan `scan` (the first if the log does not cover it).
    pub fn candidate_at(&self, scan: u64) -> usize {
        match self.segments.partition_point(|&(s, _)| s <= scan) {
            0 => 0,
            i => self.segments[i - 1].1,
        }
    }

    pub(super) fn push_segment(&mut self, first: u64, candidate: usize) {
        if self.segments.last().map(|s| s.1) != Some(candidate) {
            self.segments.push((first, candidate));
        }
    }
}
