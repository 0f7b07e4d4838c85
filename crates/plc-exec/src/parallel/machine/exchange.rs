//! A levelled plan's scans on private states (`par-exchange`): worker 0 runs its slices on the
//! shared state (the driver's, or its own layout's copy of it: `relayout`), every other worker
//! on a copy of its own, and after each phase each worker packs what it wrote (the plan's
//! [`Exchange`] key: BOOLs as bits) into its lines of an exchange buffer; before the next
//! phase every worker waits for the others' lines of the phase and unpacks them into its state.
//! Worker 0 hands over the driver's inputs the same way before each scan, and unpacks the last
//! phase's keys after it, so the state the driver sees is whole. Only the exchanged lines move
//! between the cores; no line of any state is shared.
//!
//! The lines (`xlines`) carry the data and its readiness together; waiting for all the others'
//! lines of a phase is the phase's barrier. Two sets of lines alternate by scan parity, so a
//! writer one scan ahead never overwrites lines a late reader has not read (it cannot get two
//! scans ahead: each scan starts with worker 0's inputs, which it hands over only after it has
//! read every worker's last phase of the scan before).
//!
//! The results are the sequential walk's for the reason `planning::exchange` gives; faults and
//! decisions travel as in the other plans (per-worker buffers, shared decision slots), ordered
//! by the same Release/Acquire pairs. It does not steal slices (a worker's private state holds
//! only what it was handed), so its windows are short, as a dependence-driven plan's.

use super::relayout::Relayout;
use super::shared::{faults_of, Shared, SharedSlots};
use super::xlines::XBuffer;
use super::{Buffers, ParallelMachine, ScanDriver, Timing};
use crate::parallel::planning::{Exchange, Item, Plan};
use crate::{Machine, ScanCtx};
use std::time::Instant;

/// What a `par-exchange` window runs: the plan's exchange, its lines, and the machine whose
/// layout its states have (its own, or the common one).
pub(super) type XRun<'s> = (&'s Exchange, &'s XBuffer, &'s Machine);

/// Worker 0's side of a `par-exchange` window: the driver, which scans it times, and, when the
/// plan runs on its own layout and the driver reads only the caller's layout, the caller's state
/// and the moves between them (a driver that reads any layout is given the own layout's machine
/// and state).
pub(super) struct Lead<'d, D: ScanDriver + ?Sized> {
    pub(super) driver: &'d mut D,
    pub(super) timing: Timing,
    pub(super) times: &'d mut Vec<u64>,
    pub(super) home: Option<(&'d Relayout, SharedSlots)>,
}

impl ParallelMachine {
    /// Waits for and unpacks every other worker's key of `phase` into `state`.
    fn take_phase(
        &self,
        w: usize,
        (x, buf, _): XRun<'_>,
        phase: usize,
        state: SharedSlots,
        seq: u64,
        sh: &Shared<'_>,
    ) -> bool {
        for o in (0..x.threads).filter(|&o| o != w) {
            let key = x.key(phase, o);
            if !buf.wait(key, seq, &sh.barrier) {
                return false;
            }
            // SAFETY: `state` is worker `w`'s own for the window (the shared slots for worker
            // 0, whose followers touch only their private states; a private state for the
            // others); no other reference to its bytes is alive here.
            buf.unpack(key, unsafe { state.bytes_mut() }, seq);
        }
        true
    }

    /// Runs item `it` of worker `w` and keeps its faults in the worker's buffer.
    #[inline]
    #[allow(clippy::too_many_arguments)]
    fn run_exchange_item(
        &self,
        m: &Machine,
        w: usize,
        plan: &Plan,
        it: &Item,
        store: &mut SharedSlots,
        ctx: &mut ScanCtx<'_>,
        sh: &Shared<'_>,
    ) {
        // SAFETY: `plan` is a checked `par-exchange` plan of `m` (the caller's), `store` is
        // worker `w`'s own state of `m` for the window, and `it` is an item of `w`'s slice of the
        // current phase (`exchange_scans`); what other workers wrote before reaches this state
        // only through `take_phase`, on this thread.
        unsafe { self.run_item(m, plan, it, store, ctx, sh) };
        if !ctx.faults.is_empty() {
            faults_of(&sh.faults[w]).extend(ctx.faults.drain(..).map(|f| (it.first.raw(), f)));
        }
    }

    /// Worker `w`'s part of `scans` on `plan` with exchange `xr`, on `store` (worker 0: the
    /// shared slots or its own layout's home, and the driver); false if a worker panicked.
    #[allow(clippy::too_many_arguments)]
    pub(super) fn exchange_scans<D: ScanDriver + ?Sized>(
        &self,
        w: usize,
        plan: &Plan,
        xr: XRun<'_>,
        sh: &Shared<'_>,
        scans: std::ops::Range<u64>,
        mut store: SharedSlots,
        mut lead: Option<Lead<'_, D>>,
        b: &mut Buffers,
    ) -> bool {
        let (x, buf, m) = xr;
        let last = plan.phases.len() - 1;
        let wants_state = lead.as_ref().is_some_and(|l| l.driver.wants_state());
        for scan in scans {
            let seq = scan + 1;
            let mut t0 = None;
            if let Some(l) = lead.as_mut() {
                // SAFETY: worker 0's states (the caller's and its own layout's); the others read
                // only the exchange lines.
                let slots = unsafe { store.bytes_mut() };
                match l.home {
                    Some((r, home)) => {
                        // SAFETY: the caller's state, worker 0's alone during the window (the
                        // others copied from the own layout's state, not this one).
                        let common = unsafe { home.bytes_mut() };
                        l.driver.before_scan(&self.machine, scan, common);
                        r.inputs_to_own(common, slots);
                    }
                    None => l.driver.before_scan(m, scan, slots),
                }
                t0 = l.timing.wants(scan).then(Instant::now);
                buf.pack(&x.inputs, slots, seq);
            } else {
                if !buf.wait(&x.inputs, seq, &sh.barrier) {
                    return false;
                }
                // SAFETY: as in `take_phase`.
                buf.unpack(&x.inputs, unsafe { store.bytes_mut() }, seq);
            }
            // SAFETY: as in `take_phase`: `store` is this worker's own state for the window.
            m.begin_scan(unsafe { store.bytes_mut() });
            let mut ctx = m.context(scan, &mut b.scratch);
            for pi in 0..plan.phases.len() {
                let split = x.split(pi, w);
                buf.prefetch_write(x.key(pi, w), seq);
                let (early, late) = split.items.split_at(split.early as usize);
                for (i, it) in early.iter().enumerate() {
                    self.run_exchange_item(m, w, plan, it, &mut store, &mut ctx, sh);
                    if split.prefetch_after == Some(i as u32 + 1) {
                        for o in (0..x.threads).filter(|&o| o != w) {
                            buf.prefetch_read(x.key(pi - 1, o), seq);
                        }
                    }
                }
                if pi > 0 && !self.take_phase(w, xr, pi - 1, store, seq, sh) {
                    return false;
                }
                for it in late {
                    self.run_exchange_item(m, w, plan, it, &mut store, &mut ctx, sh);
                }
                // SAFETY: as in `take_phase`.
                buf.pack(x.key(pi, w), unsafe { store.bytes_mut() }, seq);
            }
            if !self.take_phase(w, xr, last, store, seq, sh) {
                return false;
            }
            if let Some(l) = lead.as_mut() {
                let elapsed = t0.map(|t| t.elapsed()).unwrap_or_default();
                if t0.is_some() {
                    l.times.push(elapsed.as_nanos() as u64);
                }
                // Worker 0 has taken every other worker's last phase of the scan (`take_phase`
                // above): their items of the scan are done, and their faults in their buffers.
                let faults = self.merged_faults(sh, b);
                // SAFETY: worker 0's states, as above.
                let slots: &[u8] = unsafe { store.bytes() };
                let (m, slots) = match l.home {
                    Some((r, home)) => {
                        // SAFETY: as before the scan.
                        let common = unsafe { home.bytes_mut() };
                        if wants_state {
                            r.to_common(slots, common);
                        }
                        (&self.machine, &*common)
                    }
                    None => (m, slots),
                };
                l.driver.after_scan(m, scan, slots, faults, elapsed);
            }
        }
        true
    }

    /// Moves the state of plan `k`'s own layout back into the caller's (worker 0, between
    /// windows).
    pub(super) fn home_from_own(&self, k: usize, sh: &Shared<'_>) {
        if let (Some(o), Some(home)) = (&self.own[k], sh.xhomes[k]) {
            // SAFETY: between windows: the other workers wait for the bell and touch neither
            // state; worker 0 holds no other reference to them.
            let (from, to) = unsafe { (home.bytes(), sh.slots.bytes_mut()) };
            o.relayout.to_common(from, to);
        }
    }
}
