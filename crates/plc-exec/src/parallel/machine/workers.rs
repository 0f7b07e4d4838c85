//! The workers' loops of a run: worker 0 (the calling thread) asks the measured choice which
//! candidate runs the next window of scans, runs sequential windows alone and parallel windows
//! with the others (announced on the window bell), and moves the state between the common
//! layout and `par-exchange`'s own one around its windows; workers 1.. wait for a window and
//! run their part of it, until the run is over. The top of the running side: it uses `items`,
//! `exchange` and `claimed` for the scans themselves, and `mod` uses it for `run`.

use super::claimed;
use super::exchange::{Lead, XRun};
use super::shared::{faults_of, Shared, SharedSlots};
use super::units::WindowNote;
use super::{Buffers, Candidate, NoDriver, ParallelMachine, RunLog, ScanDriver, Timing};
use crate::parallel::choice::{Chooser, Window};
use crate::parallel::planning::Plan;
use crate::State;
use std::ops::Range;
use std::time::Instant;

/// Scans at most per window of a dependence-driven plan.
const DEPS_WINDOW: u64 = 4;

/// One window of scans as worker 0 runs it: which scans, the driver that feeds and reads them,
/// and which of them are timed.
struct WindowRun<'d, D: ?Sized> {
    scans: Range<u64>,
    driver: &'d mut D,
    timing: Timing,
}

impl<D: ?Sized> WindowRun<'_, D> {
    /// How many scans the window has.
    fn len(&self) -> u64 {
        self.scans.end - self.scans.start
    }

    /// The bell's note announcing this window of plan `plan`, whose units are numbered from
    /// `base`; `exchange` as `WindowNote` has it.
    fn note(&self, plan: usize, base: u64, exchange: Option<bool>) -> WindowNote {
        WindowNote {
            plan,
            first: self.scans.start,
            scans: self.len(),
            base,
            exchange,
        }
    }
}

/// What worker 0 carries from one window to the next.
#[derive(Default)]
struct LeaderState {
    /// Barriers worker 0 has passed.
    epoch: u64,
    /// Units issued before the next window.
    base: u64,
    /// The timed scans of the window in progress, ns.
    times: Vec<u64>,
    bufs: Buffers,
    /// Whether the last levelled window ran most of the other workers' slices itself (they
    /// were not on a core): a dependence-driven plan, which must wait for them, is then not
    /// worth measuring.
    others_away: bool,
    /// The `par-exchange` plan whose private states are current (its window was last).
    private_current: Option<usize>,
    /// The `par-exchange` plan on its own layout whose state the caller's lags behind.
    home_behind: Option<usize>,
}

impl ParallelMachine {
    /// Worker 0: chooses, runs sequential windows alone and parallel windows with the others
    /// (announced on the bell: a levelled plan's scans as claimed units, a dependence-driven
    /// plan's behind the barrier), then tells them the run is over.
    pub(super) fn leader<D: ScanDriver + ?Sized>(
        &self,
        sh: &Shared<'_>,
        scans: Range<u64>,
        driver: &mut D,
        chooser: &mut Chooser,
        allowed: &[usize],
        log: &mut RunLog,
    ) {
        let body = std::panic::AssertUnwindSafe(|| {
            sh.barrier.register(0);
            let mut ls = LeaderState::default();
            let mut scan = scans.start;
            while scan < scans.end {
                let mut win = chooser.next();
                while ls.others_away
                    && chooser.measuring_other()
                    && self.waits_for_all(allowed[win.candidate])
                {
                    chooser.skip();
                    win = chooser.next();
                }
                let c = allowed[win.candidate];
                if let Some(k) = ls
                    .home_behind
                    .filter(|&k| self.candidates[c] != Candidate::Exchange(k))
                {
                    self.home_from_own(k, sh);
                    ls.home_behind = None;
                }
                let deps = self.waits_for_all(c);
                // A dependence-driven or exchange window is short and timed whole: its waits
                // cost a time slice each when another worker loses its core, so the chooser must
                // see that within a few scans (it cannot take the other worker's items, as
                // units can).
                let cap = if deps { DEPS_WINDOW } else { u64::MAX };
                let n = win.scans.min(scans.end - scan).min(cap);
                log.scans_on[c] += n;
                log.push_segment(scan, c);
                ls.times.clear();
                let timing = Timing {
                    all: win.timed || deps || driver.wants_time(),
                    every: self.measure.sample_every.max(1),
                };
                let run = WindowRun {
                    scans: scan..scan + n,
                    driver: &mut *driver,
                    timing,
                };
                // Private states stay current only while one plan's exchange windows follow
                // each other.
                let was_current = ls.private_current.take();
                let ok = match self.candidates[c] {
                    Candidate::Sequential => {
                        self.sequential_window(sh, run, &mut ls.times);
                        true
                    }
                    Candidate::Exchange(i) => {
                        let copy = was_current != Some(i);
                        self.exchange_window(i, copy, sh, run, &mut ls)
                    }
                    Candidate::Levelled(i) => self.levelled_window(i, sh, run, &mut ls),
                };
                if !ok {
                    return;
                }
                chooser.record(Window { scans: n, ..win }, &ls.times);
                scan += n;
            }
            if let Some(k) = ls.home_behind {
                self.home_from_own(k, sh);
            }
            sh.bell.ring(WindowNote {
                plan: 0,
                first: scan,
                scans: 0,
                base: ls.base,
                exchange: None,
            });
        });
        if let Err(panic) = std::panic::catch_unwind(body) {
            sh.barrier.poison();
            std::panic::resume_unwind(panic);
        }
    }

    /// Worker 0's window `run` on `par-exchange` plan `i`: moves the state into the plan's
    /// private states when `copy` (another candidate ran since its last window), announces the
    /// window, and runs its part. False if a worker panicked.
    fn exchange_window<D: ScanDriver + ?Sized>(
        &self,
        i: usize,
        copy: bool,
        sh: &Shared<'_>,
        run: WindowRun<'_, D>,
        ls: &mut LeaderState,
    ) -> bool {
        let own = self.own[i].as_ref().zip(sh.xhomes[i]);
        if let Some((o, home)) = own.filter(|_| copy) {
            // SAFETY: the other workers wait for the bell (rung below): worker 0 alone touches
            // the two states.
            let (from, to) = unsafe { (sh.slots.bytes(), home.bytes_mut()) };
            o.relayout.to_own(from, to);
        }
        sh.bell.ring(run.note(i, ls.base, Some(copy)));
        // The followers copy the shared state between the two barriers.
        for _ in 0..1 + copy as usize {
            if !sh.barrier.wait(0, &mut ls.epoch) {
                return false;
            }
        }
        // A driver that reads any layout sees the own one; otherwise the caller's state is kept
        // up to date after every scan if the driver reads it.
        let direct = run.driver.reads_any_layout();
        if own.is_some() && (direct || !run.driver.wants_state()) {
            ls.home_behind = Some(i);
        }
        let lead = Lead {
            driver: run.driver,
            timing: run.timing,
            times: &mut ls.times,
            home: own
                .filter(|_| !direct)
                .map(|(o, _)| (&o.relayout, sh.slots)),
        };
        let x = self.exchange_of(i, sh);
        let store = own.map_or(sh.slots, |(_, home)| home);
        let (plan, b) = (&self.plans[i], &mut ls.bufs);
        if !self.exchange_scans(0, plan, x, sh, run.scans, store, Some(lead), b) {
            return false;
        }
        ls.private_current = Some(i);
        true
    }

    /// Worker 0's window `run` on levelled plan `i`: announces it and runs its part, behind
    /// the barrier for a dependence-driven plan, as claimed units otherwise (noting whether the
    /// other workers were away). False if a worker panicked.
    fn levelled_window<D: ScanDriver + ?Sized>(
        &self,
        i: usize,
        sh: &Shared<'_>,
        run: WindowRun<'_, D>,
        ls: &mut LeaderState,
    ) -> bool {
        let plan = &self.plans[i];
        let n = run.len();
        sh.bell.ring(run.note(i, ls.base, None));
        let b = &mut ls.bufs;
        if plan.ready.is_some() {
            if !sh.barrier.wait(0, &mut ls.epoch) {
                return false;
            }
            let d = Some((run.driver, run.timing, &mut ls.times));
            return self.plan_scans(0, plan, sh, run.scans, &mut ls.epoch, d, b);
        }
        let Some(taken) = self.leader_units(
            plan,
            sh,
            ls.base,
            run.scans,
            run.driver,
            run.timing,
            &mut ls.times,
            b,
        ) else {
            return false;
        };
        let others = n * (plan.threads as u64 - 1) * plan.parallel_phases() as u64;
        ls.others_away = others > 0 && taken * 2 > others;
        ls.base += n * claimed::unit_layout(plan).1 as u64;
        true
    }

    /// Whether candidate `c` needs every worker on a core at every phase: a dependence-driven
    /// plan, or a levelled plan on private states (neither can give a late worker's items to
    /// another).
    fn waits_for_all(&self, c: usize) -> bool {
        match self.candidates[c] {
            Candidate::Levelled(i) => self.plans[i].ready.is_some(),
            Candidate::Exchange(_) => true,
            Candidate::Sequential => false,
        }
    }

    /// Plan `i`'s exchange, its lines in this run, and the machine of its states' layout.
    fn exchange_of<'s>(&'s self, i: usize, sh: &'s Shared<'_>) -> XRun<'s> {
        let m = self.own[i].as_ref().map_or(&self.machine, |o| &o.machine);
        match (&self.exchanges[i], &sh.xbufs[i]) {
            (Some(x), Some(b)) => (x, b, m),
            _ => unreachable!("a par-exchange candidate has an exchange and its lines"),
        }
    }

    /// Workers 1..: wait for a window, run their part of it, until the run is over.
    pub(super) fn follower(&self, w: usize, sh: &Shared<'_>) {
        let body = std::panic::AssertUnwindSafe(|| {
            sh.barrier.register(w);
            sh.bell.register(w);
            let mut epoch = 0u64;
            let mut bufs = Buffers::default();
            // This worker's state in `par-exchange` windows.
            let mut private: Option<State> = None;
            let mut k = 1;
            loop {
                let Some((got, note)) = sh.bell.wait(w, k, &sh.barrier) else {
                    return;
                };
                k = got + 1;
                if note.scans == 0 {
                    return;
                }
                let plan = &self.plans[note.plan];
                let scans = note.first..note.first + note.scans;
                let ok = if let Some(copy) = note.exchange {
                    let x = self.exchange_of(note.plan, sh);
                    let m = x.2;
                    let mut ok = sh.barrier.wait(w, &mut epoch);
                    let size = m.state_size() as usize;
                    let state = match &mut private {
                        Some(s) if s.bytes().len() == size => s,
                        p => p.insert(m.initial_state()),
                    };
                    if ok && copy {
                        let from = sh.xhomes[note.plan].unwrap_or(sh.slots);
                        // SAFETY: worker 0 waits at the barrier below and the other workers
                        // only read: nobody writes worker 0's state meanwhile.
                        state.bytes_mut().copy_from_slice(unsafe { from.bytes() });
                        ok = sh.barrier.wait(w, &mut epoch);
                    }
                    let store = SharedSlots::new(state.bytes_mut(), m);
                    ok && self
                        .exchange_scans::<NoDriver>(w, plan, x, sh, scans, store, None, &mut bufs)
                } else if plan.ready.is_some() {
                    sh.barrier.wait(w, &mut epoch)
                        && self
                            .plan_scans::<NoDriver>(w, plan, sh, scans, &mut epoch, None, &mut bufs)
                } else {
                    self.follower_units(w, plan, sh, got, note, &mut bufs)
                };
                if !ok {
                    return;
                }
            }
        });
        if let Err(panic) = std::panic::catch_unwind(body) {
            sh.barrier.poison();
            std::panic::resume_unwind(panic);
        }
    }

    /// Worker 0 alone runs the window `run` as the sequential walk on the shared slots.
    fn sequential_window<D: ScanDriver + ?Sized>(
        &self,
        sh: &Shared<'_>,
        run: WindowRun<'_, D>,
        times: &mut Vec<u64>,
    ) {
        let WindowRun {
            scans,
            driver,
            timing,
        } = run;
        // SAFETY: the other workers wait at the window barrier (or have not started) and touch
        // no slot until worker 0 reaches it: worker 0 has the slots to itself for this window.
        let slots = unsafe { sh.slots.bytes_mut() };
        let mut faults = Vec::new();
        for scan in scans {
            driver.before_scan(&self.machine, scan, slots);
            faults.clear();
            let t0 = timing.wants(scan).then(Instant::now);
            self.machine.run_scan_in(slots, scan, &mut faults);
            let elapsed = t0.map(|t| t.elapsed()).unwrap_or_default();
            if t0.is_some() {
                times.push(elapsed.as_nanos() as u64);
            }
            driver.after_scan(&self.machine, scan, slots, &faults, elapsed);
        }
    }

    /// Worker `w`'s part of `scans` on `plan`; worker 0 also talks to the driver. False if a
    /// worker panicked.
    #[allow(clippy::too_many_arguments)]
    fn plan_scans<D: ScanDriver + ?Sized>(
        &self,
        w: usize,
        plan: &Plan,
        sh: &Shared<'_>,
        scans: Range<u64>,
        epoch: &mut u64,
        mut driver: Option<(&mut D, Timing, &mut Vec<u64>)>,
        b: &mut Buffers,
    ) -> bool {
        let mut store = sh.slots;
        for scan in scans {
            let mut t0 = None;
            if let Some((d, timing, _)) = driver.as_mut() {
                // SAFETY: the other workers wait at the next barrier (or have not started):
                // worker 0 has the slots to itself until it reaches that barrier.
                let slots = unsafe { sh.slots.bytes_mut() };
                d.before_scan(&self.machine, scan, slots);
                t0 = timing.wants(scan).then(Instant::now);
                self.machine.begin_scan(slots);
            }
            let mut ctx = self.machine.context(scan, &mut b.scratch);
            for ph in &plan.phases {
                if ph.barrier_before && !sh.barrier.wait(w, epoch) {
                    return false;
                }
                let ahead = plan.item_remote.get(w).map_or(&[][..], Vec::as_slice);
                if let Some(lines) = ahead.first() {
                    store.prefetch(lines);
                }
                for (i, it) in ph.items_of(w).iter().enumerate() {
                    if let Some(lines) = ahead.get(i + 1) {
                        store.prefetch(lines);
                    }
                    for x in &plan.waits[it.waits.start as usize..it.waits.end as usize] {
                        if !sh
                            .ready
                            .wait(x.worker as usize, *epoch, x.done, &sh.barrier)
                        {
                            return false;
                        }
                    }
                    // SAFETY: `plan` is one of the machine's checked plans on the shared state
                    // of `self.machine`, `it` is in worker `w`'s slice of the current phase,
                    // and every item of another worker it depends on has published its ready
                    // flag (the waits above, Acquire of their Release).
                    unsafe { self.run_item(&self.machine, plan, it, &mut store, &mut ctx, sh) };
                    if it.publish {
                        sh.ready.publish(w, *epoch, i as u32 + 1);
                    }
                    if !ctx.faults.is_empty() {
                        faults_of(&sh.faults[w])
                            .extend(ctx.faults.drain(..).map(|f| (it.first.raw(), f)));
                    }
                }
            }
            if plan.end_barrier && !sh.barrier.wait(w, epoch) {
                return false;
            }
            if let Some((d, _, times)) = driver.as_mut() {
                let elapsed = t0.map(|t| t.elapsed()).unwrap_or_default();
                if t0.is_some() {
                    times.push(elapsed.as_nanos() as u64);
                }
                // Every other worker has passed the scan's last barrier and waits at the next
                // one: worker 0 has the buffers and slots to itself.
                let faults = self.merged_faults(sh, b);
                // SAFETY: as above: nobody writes the slots until worker 0 reaches the next
                // barrier, after the driver returned.
                let slots: &[u8] = unsafe { sh.slots.bytes_mut() };
                d.after_scan(&self.machine, scan, slots, faults, elapsed);
            }
        }
        true
    }
}
