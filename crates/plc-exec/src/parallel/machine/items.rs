//! One item of a levelled or dependence-driven plan on the shared state: whether it runs this
//! scan (its guard: the decisions of the tasks that control it), where it starts (the decision
//! that led to it), running its rungs with [`Machine::resume`](crate::Machine::resume),
//! and recording where it left; and the faults of a scan merged back into sequential order.
//! The second half of [`ParallelMachine`]'s implementation, with `claimed`: the scans of
//! `mod` and `claimed` call these, these call nothing above them.
//!
//! Invariant relied on: an item's guard and entries read decisions only of items of earlier
//! phases (the plan check), so they are final when the item runs.

use super::shared::{faults_of, ItemStore, Shared};
use super::{Buffers, ParallelMachine, SharedSlots};
use crate::parallel::ids::{Decision, Next};
use crate::parallel::planning::{Item, Plan, Region};
use crate::{Exit, Fault, Machine, ScanCtx};
use plc_model::RungId;

impl ParallelMachine {
    /// The faults of every worker's buffer in sequential order (by task; a task's faults keep
    /// their order), the buffers emptied. Worker 0, when every item of the scan is done (every
    /// unit done, or every worker past the scan's last barrier or hand-over): then the buffers
    /// hold every fault of the scan and no other.
    pub(super) fn merged_faults<'b>(&self, sh: &Shared<'_>, b: &'b mut Buffers) -> &'b [Fault] {
        b.merged.clear();
        for f in sh.faults.iter() {
            b.merged.append(&mut faults_of(f));
        }
        b.merged.sort_by_key(|&(t, _)| t);
        b.out.clear();
        b.out.extend(b.merged.iter().map(|&(_, f)| f));
        &b.out
    }

    /// Where a decision leads: the task holding the rung control went to, or the end of the
    /// scan; `None` if the task did not run.
    #[inline]
    fn successor_of(plan: &Plan, d: Decision) -> Option<Next> {
        match d {
            Decision::NotRun => None,
            Decision::Stop => Some(Next::Stop),
            Decision::Rung(r) | Decision::ForTest(r) => {
                plan.task_of_rung[r.index()].map(Next::Task)
            }
        }
    }

    /// Where item `it` starts this scan; `None` if the sequential scan would not run it.
    #[inline]
    fn entry(plan: &Plan, it: &Item, sh: &Shared<'_>) -> Option<Exit> {
        if !it.guard.is_empty() {
            let holds = plan.guards[it.guard.start as usize..it.guard.end as usize]
                .iter()
                .any(|&(slot, succ)| {
                    Self::successor_of(plan, sh.decisions.get(slot)) == Some(succ)
                });
            if !holds {
                return None;
            }
        }
        if it.entries.is_empty() {
            return Some(Exit::Rung(it.start));
        }
        let mut at = None;
        for &slot in &plan.entry_slots[it.entries.start as usize..it.entries.end as usize] {
            let d = sh.decisions.get(slot);
            if Self::successor_of(plan, d) == Some(Next::Task(it.first)) {
                debug_assert!(at.is_none(), "task {} entered twice", it.first.raw());
                at = match d {
                    Decision::ForTest(h) => Some(Exit::ForTest(h)),
                    Decision::Rung(r) => Some(Exit::Rung(r)),
                    Decision::Stop | Decision::NotRun => at,
                };
            }
        }
        // None: no predecessor led here, so the sequential scan does not run it either.
        at
    }

    /// Runs item `it` of `plan` on `store` with `m`'s lowered code (the common layout's machine,
    /// or a `par-exchange` plan's own), and records where it left.
    ///
    /// # Safety
    /// `plan` passed its check against `m`'s code (`planning::check_plan`), `store` is a state of
    /// `m` (the shared state, or this worker's private one), and `it` is an item of the phase
    /// the calling worker runs now that the plan gives it (its slice, or a unit it claimed),
    /// every earlier phase of the scan handed over (Release/Acquire) before it started.
    #[inline]
    pub(super) unsafe fn run_item(
        &self,
        m: &Machine,
        plan: &Plan,
        it: &Item,
        store: &mut SharedSlots,
        ctx: &mut ScanCtx<'_>,
        sh: &Shared<'_>,
    ) {
        let Some(at) = Self::entry(plan, it, sh) else {
            if let Some(slot) = it.decision {
                sh.decisions.set(slot, Decision::NotRun);
            }
            return;
        };
        // SAFETY: the store goes only to `m.resume` and is dropped when it returns; the item's
        // accesses are this worker's in this phase under the checked plan (this function's
        // contract), which is `ItemStore::new`'s.
        let mut st = unsafe { ItemStore::new(*store, m) };
        let exit = match it.region {
            Region::Rungs(lo, hi) => m.resume(&mut st, ctx, at, |r| lo <= r.raw() && r.raw() < hi),
            Region::Tasks(lo, hi) => {
                let task_of = &plan.task_of_rung;
                m.resume(&mut st, ctx, at, |r: RungId| {
                    task_of[r.index()].is_some_and(|t| lo <= t && t <= hi)
                })
            }
        };
        if let Some(slot) = it.decision {
            let d = match exit {
                Exit::Stop => Decision::Stop,
                Exit::Rung(r) => Decision::Rung(r),
                Exit::ForTest(h) => Decision::ForTest(h),
            };
            sh.decisions.set(slot, d);
        }
    }
}
