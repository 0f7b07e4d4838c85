//! The running machine: a [`ParallelMachine`] (a [`Machine`] on the plan's padded layout and the
//! [`Plan`]) and its scans: the workers entered once per run, meeting at the barrier between
//! phases, each running its slice's items through the interpreter on the shared slot array.
//!
//! Invariants: worker 0 is the calling thread and alone talks to the driver, between barriers;
//! the results are those of [`Machine::run_scan`], slot for slot and fault for fault. It does
//! not plan (see `plan`) and takes the plan's safety from `verify` at construction.

use super::barrier::SpinBarrier;
use super::calls::{call_closure, rung_callees};
use super::config::PlanConfig;
use super::driver::{run_sequential, ScanDriver};
use super::ids::{Decision, Next, TaskId};
use super::pad::Padded;
use super::plan::{layout_groups, Plan};
use super::shared::{Decisions, FaultBuffer, Shared, SharedSlots};
use super::tasks::{Item, Region};
use crate::analysis::Analysis;
use crate::exec::{ExecConfig, Exit, Fault, Layout, LowerError, Machine, ScanCtx, State};
use crate::model::{PouId, Program, RungId, VarId};
use std::cell::UnsafeCell;
use std::collections::HashMap;
use std::ops::Range;
use std::time::{Duration, Instant};

/// A program lowered for the parallel scan: a [`Machine`] on the plan's padded layout, and the
/// [`Plan`]. Immutable and `Sync`.
#[derive(Debug)]
pub struct ParallelMachine {
    pub(super) machine: Machine,
    pub(super) plan: Plan,
    /// Padding groups of the layout (for `--explain`).
    pub(super) layout_groups: usize,
}

impl ParallelMachine {
    /// Plans `program` (analysed as `analysis`) for `config.threads` workers and lowers it on the
    /// plan's layout. In debug builds, also [`verify`](Self::verify)s the plan.
    pub fn new(
        program: &Program,
        analysis: &Analysis,
        exec: &ExecConfig,
        config: &PlanConfig,
    ) -> Result<ParallelMachine, LowerError> {
        let plan = Plan::build(program, analysis, config);
        let (layout, groups) = if plan.sequential.is_some() {
            (Layout::dense(program), 0)
        } else {
            let groups = layout_groups(&[&plan], program.vars.len());
            let layout =
                Layout::from_groups(program, &groups, 8).expect("groups hold each variable once");
            (layout, groups.len())
        };
        let machine = Machine::new(program, layout, exec)?;
        let pm = ParallelMachine {
            machine,
            plan,
            layout_groups: groups,
        };
        #[cfg(debug_assertions)]
        if let Err(e) = pm.verify(program, analysis) {
            panic!("parallel plan of {} is unsafe: {e}", program.name);
        }
        Ok(pm)
    }

    /// The machine (on the plan's layout).
    pub fn machine(&self) -> &Machine {
        &self.machine
    }

    /// The plan.
    pub fn plan(&self) -> &Plan {
        &self.plan
    }

    /// The state at load.
    pub fn initial_state(&self) -> State {
        self.machine.initial_state()
    }

    /// Checks, slot by slot, that in every parallel phase no slot written by one worker is read
    /// or written by another (variables through the rungs' IN/OUT sets, calls included; loop
    /// counters of the task's own and called loop-back rungs), and that no two tasks of a
    /// parallel phase write a variable the other reads or writes (the schedule's guarantee).
    pub fn verify(&self, p: &Program, a: &Analysis) -> Result<(), String> {
        let sched = &a.schedule;
        let layout = self.machine.layout();
        let closure = call_closure(p);
        let counter: HashMap<u32, u32> = self
            .machine
            .loop_counters()
            .map(|(r, s)| (r.0, s))
            .collect();
        let n_slots = self.machine.slot_count() as usize;
        // Per slot: the phase and (task, worker) that wrote it last.
        let mut writer: Vec<Option<(usize, TaskId, usize)>> = vec![None; n_slots];
        let task_slots = |t: TaskId| -> (Vec<u32>, Vec<u32>) {
            let (mut reads, mut writes) = (Vec::new(), Vec::new());
            for &r in &sched.tasks[t.index()].rungs {
                for &v in a.accesses.ins(r) {
                    reads.extend(layout.slots_of(v));
                }
                for &v in a.accesses.outs(r) {
                    writes.extend(layout.slots_of(v));
                }
                let mut rungs = vec![r];
                for c in rung_callees(p, &closure, r) {
                    rungs.extend(p.pou_rungs(PouId(c)));
                }
                for x in rungs {
                    if let Some(&s) = counter.get(&x.0) {
                        writes.push(s);
                    }
                }
            }
            (reads, writes)
        };
        let name = |t: TaskId| p.rung(sched.head(t.0)).id.clone();
        for (pi, ph) in self.plan.phases.iter().enumerate() {
            if !ph.is_parallel() {
                continue;
            }
            let mut per_task: Vec<(TaskId, usize, Vec<u32>, Vec<u32>)> = Vec::new();
            for (w, it) in ph.all_items() {
                for t in it.tasks() {
                    let (r, wr) = task_slots(t);
                    per_task.push((t, w, r, wr));
                }
            }
            for (t, w, _, writes) in &per_task {
                for &s in writes {
                    let s = s as usize;
                    if let Some((ph2, t2, w2)) = writer[s] {
                        if ph2 == pi && t2 != *t {
                            return Err(format!("phase {pi}: slot {s} written by tasks {} (worker {w2}) and {} (worker {w})", name(t2), name(*t)));
                        }
                    }
                    writer[s] = Some((pi, *t, *w));
                }
            }
            for (t, w, reads, _) in &per_task {
                for &s in reads {
                    if let Some((ph2, t2, w2)) = writer[s as usize] {
                        if ph2 == pi && t2 != *t {
                            return Err(format!("phase {pi}: slot {s} written by task {} (worker {w2}) and read by {} (worker {w})", name(t2), name(*t)));
                        }
                    }
                }
            }
        }
        Ok(())
    }

    /// One scan (enters the workers for this scan only; use [`run`](Self::run) for many).
    pub fn scan(
        &self,
        pool: Option<&rayon::ThreadPool>,
        state: &mut State,
        scan: u64,
        inputs: &[(VarId, crate::model::Value)],
        faults: &mut Vec<Fault>,
    ) {
        struct One<'a> {
            inputs: &'a [(VarId, crate::model::Value)],
            faults: &'a mut Vec<Fault>,
        }
        impl ScanDriver for One<'_> {
            fn before_scan(&mut self, m: &Machine, _: u64, slots: &mut [u64]) {
                m.set_inputs_in(slots, self.inputs);
            }
            fn after_scan(
                &mut self,
                _: &Machine,
                _: u64,
                _: &[u64],
                faults: &[Fault],
                _: Duration,
            ) {
                self.faults.extend_from_slice(faults);
            }
        }
        self.run(pool, state, scan..scan + 1, &mut One { inputs, faults });
    }

    /// Runs scans `scans` on `state`. The workers are entered once for all of them: the calling
    /// thread is worker 0 and `pool` supplies the others (it needs at least `threads − 1` threads,
    /// and may be `None` for one thread or a sequential plan).
    ///
    /// # Panics
    /// If the pool is too small, if called from one of the pool's threads, or if `state` is not
    /// a state of this machine.
    pub fn run<D: ScanDriver + ?Sized>(
        &self,
        pool: Option<&rayon::ThreadPool>,
        state: &mut State,
        scans: Range<u64>,
        driver: &mut D,
    ) {
        assert_eq!(
            state.slots.len(),
            self.machine.slot_count() as usize,
            "state of another machine"
        );
        if self.plan.sequential.is_some() {
            return run_sequential(&self.machine, state, scans, driver);
        }
        let threads = self.plan.threads;
        let decisions = Decisions::new(self.plan.decision_slots);
        let faults: Vec<FaultBuffer> = (0..threads)
            .map(|_| Padded(UnsafeCell::new(Vec::new())))
            .collect();
        let shared = Shared {
            slots: SharedSlots {
                ptr: state.slots.as_mut_ptr(),
                len: state.slots.len(),
            },
            decisions: &decisions,
            faults: &faults,
            barrier: SpinBarrier::new(threads),
        };
        let shared = &shared;
        if threads == 1 {
            return self.worker(0, shared, scans, Some(driver));
        }
        let pool = pool.expect("a thread pool for more than one worker");
        assert!(
            pool.current_thread_index().is_none(),
            "run the parallel executor from outside its pool (worker 0 is the calling thread)"
        );
        assert!(
            pool.current_num_threads() >= threads - 1,
            "the pool has {} threads, {} workers need {}",
            pool.current_num_threads(),
            threads,
            threads - 1
        );
        pool.in_place_scope(|s| {
            for w in 1..threads {
                let scans = scans.clone();
                s.spawn(move |_| self.worker(w, shared, scans, None::<&mut D>));
            }
            self.worker(0, shared, scans, Some(driver));
        });
    }

    /// One worker's whole run. Worker 0 also runs the sequential phases and talks to the driver.
    fn worker<D: ScanDriver + ?Sized>(
        &self,
        w: usize,
        sh: &Shared<'_>,
        scans: Range<u64>,
        mut driver: Option<&mut D>,
    ) {
        let body = std::panic::AssertUnwindSafe(|| {
            sh.barrier.register(w);
            let mut store = sh.slots;
            let mut epoch = 0u64;
            let mut scratch: Vec<Fault> = Vec::new();
            let mut merged: Vec<(u32, Fault)> = Vec::new();
            let mut out: Vec<Fault> = Vec::new();
            for scan in scans {
                let mut t0 = None;
                if let Some(d) = driver.as_deref_mut() {
                    // SAFETY: the other workers wait at the next barrier (or have not started):
                    // worker 0 has the slots to itself until it reaches that barrier.
                    let slots =
                        unsafe { std::slice::from_raw_parts_mut(sh.slots.ptr, sh.slots.len) };
                    d.before_scan(&self.machine, scan, slots);
                    t0 = d.wants_time().then(Instant::now);
                    self.machine.begin_scan(&mut store);
                }
                let mut ctx = self.machine.context(scan, &mut scratch);
                for ph in &self.plan.phases {
                    if ph.barrier_before && !sh.barrier.wait(w, &mut epoch) {
                        return;
                    }
                    for it in ph.items_of(w) {
                        self.run_item(it, &mut store, &mut ctx, sh);
                        if !ctx.faults.is_empty() {
                            // SAFETY: only worker `w` touches its fault buffer during a scan;
                            // worker 0 reads it after the scan's last barrier.
                            let buf = unsafe { &mut *sh.faults[w].0.get() };
                            buf.extend(ctx.faults.drain(..).map(|f| (it.first.0, f)));
                        }
                    }
                }
                if self.plan.end_barrier && !sh.barrier.wait(w, &mut epoch) {
                    return;
                }
                if let Some(d) = driver.as_deref_mut() {
                    let elapsed = t0.map(|t| t.elapsed()).unwrap_or_default();
                    // Every other worker has passed the scan's last barrier and waits at the
                    // next scan's first one: worker 0 has the buffers and slots to itself.
                    merged.clear();
                    for f in sh.faults.iter() {
                        // SAFETY: as above; no other reference to the buffer exists now.
                        let buf = unsafe { &mut *f.0.get() };
                        merged.append(buf);
                    }
                    merged.sort_by_key(|&(t, _)| t); // stable: a task's faults keep their order
                    out.clear();
                    out.extend(merged.iter().map(|&(_, f)| f));
                    // SAFETY: as above: nobody writes the slots until worker 0 reaches the next
                    // barrier, after the driver returned.
                    let slots = unsafe { std::slice::from_raw_parts(sh.slots.ptr, sh.slots.len) };
                    d.after_scan(&self.machine, scan, slots, &out, elapsed);
                }
            }
        });
        if let Err(panic) = std::panic::catch_unwind(body) {
            sh.barrier.poison();
            std::panic::resume_unwind(panic);
        }
    }

    /// Where a decision leads: the task holding the rung control went to, or the end of the
    /// scan; `None` if the task did not run.
    #[inline]
    fn successor_of(&self, d: Decision) -> Option<Next> {
        match d {
            Decision::NotRun => None,
            Decision::Stop => Some(Next::Stop),
            Decision::Rung(r) | Decision::ForTest(r) => {
                self.plan.task_of_rung[r.index()].map(Next::Task)
            }
        }
    }

    /// Where item `it` starts this scan; `None` if the sequential scan would not run it.
    #[inline]
    fn entry(&self, it: &Item, sh: &Shared<'_>) -> Option<Exit> {
        let plan = &self.plan;
        if !it.guard.is_empty() {
            let holds = plan.guards[it.guard.start as usize..it.guard.end as usize]
                .iter()
                .any(|&(slot, succ)| self.successor_of(sh.decisions.get(slot)) == Some(succ));
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
            if d.rung().is_some() && self.successor_of(d) == Some(Next::Task(it.first)) {
                debug_assert!(at.is_none(), "task {} entered twice", it.first.0);
                at = Some(match d {
                    Decision::ForTest(h) => Exit::ForTest(h),
                    _ => Exit::Rung(d.rung().expect("checked above")),
                });
            }
        }
        // None: no predecessor led here, so the sequential scan does not run it either.
        at
    }

    #[inline]
    fn run_item(&self, it: &Item, store: &mut SharedSlots, ctx: &mut ScanCtx<'_>, sh: &Shared<'_>) {
        let Some(at) = self.entry(it, sh) else {
            if let Some(slot) = it.decision {
                sh.decisions.set(slot, Decision::NotRun);
            }
            return;
        };
        let exit = match it.region {
            Region::Rungs(lo, hi) => self
                .machine
                .resume(store, ctx, at, |r| lo <= r.0 && r.0 < hi),
            Region::Tasks(lo, hi) => {
                let task_of = &self.plan.task_of_rung;
                self.machine.resume(store, ctx, at, |r: RungId| {
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
