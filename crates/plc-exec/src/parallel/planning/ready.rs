//! The data of a dependence-driven plan: the waits before items ([`Wait`]: "worker `w` has
//! finished its first `done` items of this scan") and what `--explain` shows of the plan
//! ([`Ready`]). Plain data between the task facts and the planner: `deps_plan` fills it,
//! `order_check` proves it, the machine runs it (`flags`).
//!
//! Invariant: a wait before item `i` of worker `w` names another worker and a count of at
//! least 1; the waited-for item publishes its worker's flag. Nothing here plans or runs.

use crate::parallel::config::DepsPartition;

/// Before an item: wait until worker `worker` has finished its first `done` items (its ready
/// flag reads at least `done` in this scan).
#[derive(Copy, Clone, Debug, PartialEq, Eq)]
pub(in crate::parallel) struct Wait {
    pub(in crate::parallel) worker: u32,
    pub(in crate::parallel) done: u32,
}

/// What the dependence-driven plan is, besides its items (for `--explain` and the JSON).
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Ready {
    /// Per worker: the waits before its items, per scan.
    pub waits_per_worker: Vec<u64>,
    /// Per worker: its items per scan, and how many publish its ready flag.
    pub items_per_worker: Vec<u64>,
    /// Per worker: items that publish its flag.
    pub publishing_per_worker: Vec<u64>,
    /// Cross-worker dependences before the reduction to the latest producer per worker.
    pub cross_dependences: u64,
    /// The modelled critical path over the task graph with this assignment and the per-wait
    /// cost (steps; the scan's two barriers not included).
    pub critical_path: u64,
    /// Which partition the plan uses ([`DepsPartition::Levels`] or [`DepsPartition::OneWay`]).
    pub partition: DepsPartition,
}

impl Ready {
    /// Waits per scan, all workers.
    pub fn waits(&self) -> u64 {
        self.waits_per_worker.iter().sum()
    }
}

/// The items of every worker in one order that respects both each worker's order and every
/// wait (an item comes after the items its waits name): (worker, item index) pairs. `Err`
/// names a worker whose next item can never run (the waits form a cycle, or name an item that
/// does not exist): the plan would deadlock.
pub(in crate::parallel) fn item_order(
    items_per_worker: &[usize],
    waits_of: impl Fn(usize, usize) -> Vec<Wait>,
) -> Result<Vec<(usize, usize)>, String> {
    let p = items_per_worker.len();
    let total: usize = items_per_worker.iter().sum();
    let mut next = vec![0usize; p];
    let mut out = Vec::with_capacity(total);
    while out.len() < total {
        let before = out.len();
        for w in 0..p {
            while next[w] < items_per_worker[w] {
                let ready = waits_of(w, next[w]).iter().all(|x| {
                    let o = x.worker as usize;
                    o != w && o < p && x.done >= 1 && next[o] >= x.done as usize
                });
                if !ready {
                    break;
                }
                out.push((w, next[w]));
                next[w] += 1;
            }
        }
        if out.len() == before {
            let w = (0..p)
                .find(|&w| next[w] < items_per_worker[w])
                .expect("items left");
            return Err(format!(
                "worker {w} item {} waits for items that can never finish (a cycle of waits)",
                next[w]
            ));
        }
    }
    Ok(out)
}
