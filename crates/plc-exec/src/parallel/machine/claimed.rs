//! A levelled plan's scans run as claimed units (`units`): worker 0 starts each scan (the
//! driver's inputs, the loop counters) and finishes it (the faults merged, the driver's look at
//! the state); in between, every worker runs its own slice of each parallel phase and then any
//! slice of the phase nobody has claimed yet, and worker 0 runs the sequential phases. A worker
//! that is late (descheduled, or busy with the driver) loses its slices to the others instead of
//! holding them at a barrier. The results are those of the sequential scan for the reasons the
//! parallel module gives (a slice runs whole, on one worker, after the previous phase is done);
//! who runs a slice changes nothing but the cache the lines are in.
//!
//! It does not choose (the leader in `machine` does) and does not run dependence-driven plans
//! (their ready flags name the worker that runs an item: they keep the barrier).

use super::shared::{faults_of, Shared};
use super::units::WindowNote;
use super::{Buffers, ParallelMachine, ScanDriver, Timing};
use crate::parallel::planning::{Phase, Plan};
use std::ops::Range;
use std::time::Instant;

/// A phase of a scan as units: the phase, its index, its first unit's position in the scan and
/// that unit's id.
#[derive(Copy, Clone)]
struct PhaseUnits<'p> {
    ph: &'p Phase,
    pi: usize,
    at: usize,
    first: u64,
}

/// Where each phase's units start in a scan of `plan` (position 0 is the scan's start), and
/// the units per scan.
pub(super) fn unit_layout(plan: &Plan) -> (Vec<usize>, usize) {
    let mut at = 1;
    let starts = plan
        .phases
        .iter()
        .map(|ph| {
            let s = at;
            at += units_of(plan, ph);
            s
        })
        .collect();
    (starts, at)
}

fn units_of(plan: &Plan, ph: &Phase) -> usize {
    if ph.is_parallel() {
        plan.threads
    } else {
        1
    }
}

impl ParallelMachine {
    /// Worker 0's scans `scans` of `plan` as units numbered from `base`: the number of units it
    /// ran that were another worker's slices, or `None` if a worker panicked.
    #[allow(clippy::too_many_arguments)]
    pub(super) fn leader_units<D: ScanDriver + ?Sized>(
        &self,
        plan: &Plan,
        sh: &Shared<'_>,
        base: u64,
        scans: Range<u64>,
        driver: &mut D,
        timing: Timing,
        times: &mut Vec<u64>,
        b: &mut Buffers,
    ) -> Option<u64> {
        let (starts, per_scan) = unit_layout(plan);
        let (mut store, units) = (sh.slots, sh.units);
        let mut taken = 0;
        for (i, scan) in scans.enumerate() {
            let s0 = base + (i * per_scan) as u64;
            // SAFETY: every unit of the previous scan is done (waited for below, or before the
            // window) and no unit of this scan can be claimed before its start is counted:
            // worker 0 has the slots to itself.
            let slots = unsafe { sh.slots.bytes_mut() };
            driver.before_scan(&self.machine, scan, slots);
            let t0 = timing.wants(scan).then(Instant::now);
            self.machine.begin_scan(slots);
            units.done();
            let mut ctx = self.machine.context(scan, &mut b.scratch);
            for (pi, (ph, &at)) in plan.phases.iter().zip(&starts).enumerate() {
                let first = s0 + at as u64;
                if !units.wait(first, &sh.barrier, || false) {
                    return None;
                }
                let unit = PhaseUnits { ph, pi, at, first };
                taken += self.take_units(0, plan, unit, &mut store, &mut ctx, sh);
            }
            if !units.wait(s0 + per_scan as u64, &sh.barrier, || false) {
                return None;
            }
            let elapsed = t0.map(|t| t.elapsed()).unwrap_or_default();
            if t0.is_some() {
                times.push(elapsed.as_nanos() as u64);
            }
            // Every unit of the scan is done and none of the next can start before worker 0
            // counts its start: the buffers and slots are worker 0's.
            let faults = self.merged_faults(sh, b);
            // SAFETY: as above.
            let slots: &[u8] = unsafe { sh.slots.bytes_mut() };
            driver.after_scan(&self.machine, scan, slots, faults, elapsed);
        }
        Some(taken)
    }

    /// Worker `w`'s (w ≥ 1) part of window `k` (`note`): its slices and any unclaimed one, until
    /// the window is over or a later one is announced. False if a worker panicked.
    pub(super) fn follower_units(
        &self,
        w: usize,
        plan: &Plan,
        sh: &Shared<'_>,
        k: u64,
        note: WindowNote,
        b: &mut Buffers,
    ) -> bool {
        let (starts, per_scan) = unit_layout(plan);
        let mut store = sh.slots;
        let units = sh.units;
        let moved_on = || sh.bell.announced() > k;
        for i in 0..note.scans {
            let s0 = note.base + i * per_scan as u64;
            let mut ctx = self.machine.context(note.first + i, &mut b.scratch);
            for (pi, (ph, &at)) in plan.phases.iter().zip(&starts).enumerate() {
                let first = s0 + at as u64;
                if !ph.is_parallel() {
                    continue;
                }
                if !units.wait(first, &sh.barrier, moved_on) {
                    return !sh.barrier.is_poisoned();
                }
                if units.completed() >= first + plan.threads as u64 {
                    continue;
                }
                let unit = PhaseUnits { ph, pi, at, first };
                self.take_units(w, plan, unit, &mut store, &mut ctx, sh);
            }
        }
        true
    }

    /// Runs the units of phase `ph` (at position `at`, first unit id above `first`) that worker
    /// `w` claims: its own slice first, then the others in turn (a sequential phase: worker 0
    /// only). The number it ran that were not its own.
    fn take_units(
        &self,
        w: usize,
        plan: &Plan,
        u: PhaseUnits<'_>,
        store: &mut super::shared::SharedSlots,
        ctx: &mut crate::ScanCtx<'_>,
        sh: &Shared<'_>,
    ) -> u64 {
        let PhaseUnits { ph, pi, at, first } = u;
        let (n, units) = (units_of(plan, ph), sh.units);
        let mut taken = 0;
        for j in 0..n {
            let slice = (w + j) % n;
            if !units.claim(at + slice, first + slice as u64 + 1) {
                continue;
            }
            if let Some(lines) = plan.remote.get(pi).and_then(|r| r.get(slice)) {
                store.prefetch(lines);
            }
            for it in ph.items_of(slice) {
                // SAFETY: `plan` is one of the machine's checked plans on the shared state of
                // `self.machine`, and `it` is an item of unit `slice` of the current phase,
                // which this worker claimed (no other worker runs it); the phase started after
                // every unit of the phases before it was done (`units.wait`: Acquire of their
                // Release `done`).
                unsafe { self.run_item(&self.machine, plan, it, store, ctx, sh) };
                if !ctx.faults.is_empty() {
                    faults_of(&sh.faults[w])
                        .extend(ctx.faults.drain(..).map(|f| (it.first.raw(), f)));
                }
            }
            units.done();
            taken += (slice != w) as u64;
        }
        taken
    }
}
