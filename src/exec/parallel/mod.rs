//! The parallel scan: the combined schedule (`analysis::schedule`) run level by level on several
//! threads, with a result identical — every slot and every fault, every scan — to
//! [`Machine::run_scan`].
//!
//! # Shape
//! Granularity decides everything: a rung of 6 contacts and a coil costs about 3.5 ns, a level
//! of a thousand of them a few µs, so the executor must not pay a thread wake-up per level. The
//! workers are therefore entered **once per run** (one [`rayon::ThreadPool::in_place_scope`]
//! around all scans: the calling thread is worker 0, the pool supplies the others) and meet at a
//! spinning barrier ([`SpinBarrier`]) between the *phases* of every scan:
//!
//! - a **parallel phase** is one level of the schedule, cut statically into one *slice* per
//!   worker, balanced on the cost model (`Analysis::rung_costs`): contiguous runs of tasks
//!   (best for many small rungs: a slice of consecutive rungs is one call into the interpreter)
//!   or LPT (best for a few large tasks), whichever the model says finishes first;
//! - a **sequential phase** is a run of consecutive levels that cannot pay for a barrier, merged
//!   and run by worker 0 alone, in task order;
//! - when nothing pays, the whole program runs as the sequential scan ([`Plan::sequential`]).
//!
//! The choice is a small dynamic programme over the levels (each level parallel or sequential,
//! a barrier at every change and between parallel levels; sequential levels next to each other
//! share their barriers): it minimises the modelled scan time `Σ parallel makespans + Σ
//! sequential costs + barriers × barrier_cost`, and the plan is used only if it beats the plain
//! sequential scan by more than one barrier. `plc-deps run --explain` prints the decisions.
//!
//! Per scan: worker 0 writes the inputs and zeroes the loop counters; barrier; every phase (a
//! barrier before a parallel phase and after it); worker 0 then merges the faults (into the
//! sequential order: by task index), hands the state to the caller, and starts the next scan.
//!
//! # Why it is exact
//! - Tasks of one level never touch a variable that another task of the level writes (the
//!   schedule's guarantee), and the loop counters of main-program loops belong to one task
//!   each; a level whose tasks may share a subroutine's loop counters is run sequentially.
//!   [`ParallelMachine::verify`] checks, slot by slot, that no slot written by a worker in a
//!   parallel phase is read or written by another worker of that phase (debug builds check it at
//!   construction).
//! - Control: after a task runs, the slot of its *decision* records where control left (the rung
//!   it went to, or STOP); a task that does not run records NOT_RUN. A task runs iff its guard is
//!   empty or one of its disjuncts holds (`decision(controller)` leads to `successor`); a loop
//!   task with several entries is entered at the rung its predecessor's decision names (the
//!   schedule places it after all its predecessors). Decisions are read only in later phases.
//! - A *run* of tasks `t, t+1, …, u` (consecutive in task order, same slice) is executed as one
//!   walk of the interpreter over their rungs when each of `t..u` has the next one as its only
//!   successor in the condensed CFG and `t+1..=u` are unguarded with a single entry: the walk
//!   then visits exactly these tasks in this order, as the sequential scan does.
//! - The iteration cap refuses a loop-back locally (see the [module semantics](super)); a refused
//!   backward jump continues in its rung as an unpowered jump, which the CFG already contains
//!   when the jump is conditional. For an unconditional backward jump of the main program the
//!   plan checks that every way on after a refusal is an edge the schedule already knows, and
//!   otherwise runs the program sequentially.
//!
//! # Memory
//! The state is one slot array shared by all workers without locks ([`SharedSlots`]: a raw
//! pointer; disjointness is the schedule's guarantee above, ordering comes from the barrier's
//! release/acquire). Its layout ([`Layout::from_groups`], 8-slot = 64-byte lines) groups the
//! variables by the set of (phase, worker) pairs that write them, so two workers never write the
//! same cache line in one phase; loop counters have a line each; decisions and fault buffers are
//! padded per worker.

mod barrier;
mod calls;
mod config;
mod explain;
mod plan;
mod shared;
mod tasks;

pub use barrier::SpinBarrier;
pub use config::{PlanConfig, Slicing, Strategy};
pub use plan::{LevelPlan, Plan};
pub use shared::SharedSlots;

use calls::{call_closure, rung_callees};
use plan::{Item, Region, FOR_TEST, NONE, NOT_RUN, STOP};
use shared::{FaultBuffer, Padded, Shared};

use super::{ExecConfig, Exit, Fault, Layout, LowerError, Machine, State};
use crate::analysis::Analysis;
use crate::model::{PouId, Program, RungId, VarId};
use std::cell::UnsafeCell;
use std::collections::HashMap;
use std::ops::Range;
use std::sync::atomic::{AtomicU32, Ordering};
use std::time::{Duration, Instant};

/// A program lowered for the parallel scan: a [`Machine`] on the plan's padded layout, and the
/// [`Plan`]. Immutable and `Sync`.
#[derive(Debug)]
pub struct ParallelMachine {
    machine: Machine,
    plan: Plan,
}

/// What a caller of [`ParallelMachine::run`] (or [`run_sequential`]) does around each scan. Both
/// methods are called on the calling thread, with exclusive access to the state.
pub trait ScanDriver {
    /// Before scan `scan`: write its inputs (`Machine::set_inputs_in`).
    fn before_scan(&mut self, machine: &Machine, scan: u64, slots: &mut [u64]);
    /// After scan `scan`: the state, the scan's faults in sequential order, and the time the
    /// scan took (inputs and this call excluded).
    fn after_scan(
        &mut self,
        machine: &Machine,
        scan: u64,
        slots: &[u64],
        faults: &[Fault],
        elapsed: Duration,
    );
    /// Whether the driver wants each scan timed (two clock reads per scan); `elapsed` is zero
    /// otherwise.
    fn wants_time(&self) -> bool {
        true
    }
}

/// Runs scans `scans` of the sequential interpreter on `state`, timing each one.
pub fn run_sequential<D: ScanDriver + ?Sized>(
    machine: &Machine,
    state: &mut State,
    scans: Range<u64>,
    driver: &mut D,
) {
    let mut faults = Vec::new();
    let timed = driver.wants_time();
    for scan in scans {
        driver.before_scan(machine, scan, &mut state.slots);
        faults.clear();
        let t0 = timed.then(Instant::now);
        machine.run_scan(state, scan, &mut faults);
        let elapsed = t0.map(|t| t.elapsed()).unwrap_or_default();
        driver.after_scan(machine, scan, &state.slots, &faults, elapsed);
    }
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
        let layout = if plan.sequential.is_some() {
            Layout::dense(program)
        } else {
            Layout::from_groups(program, &plan.groups, 8).expect("groups hold each variable once")
        };
        let machine = Machine::new(program, layout, exec)?;
        let pm = ParallelMachine { machine, plan };
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
        // Per slot: (phase stamp, writer task, writer worker); readers checked against it.
        let mut stamp = vec![u32::MAX; n_slots];
        let mut writer = vec![(0u32, 0u32); n_slots];
        let task_slots = |t: u32| -> (Vec<u32>, Vec<u32>) {
            let (mut reads, mut writes) = (Vec::new(), Vec::new());
            for &r in &sched.tasks[t as usize].rungs {
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
        let name = |t: u32| {
            p.rung(sched.head(crate::analysis::schedule::TaskId(t)))
                .id
                .clone()
        };
        for (pi, ph) in self.plan.phases.iter().enumerate() {
            if !ph.parallel {
                continue;
            }
            let mut per_task: Vec<(u32, u32, Vec<u32>, Vec<u32>)> = Vec::new();
            for (w, slice) in ph.slices.iter().enumerate() {
                for it in slice {
                    for t in it.first..=it.last {
                        let (r, wr) = task_slots(t);
                        per_task.push((t, w as u32, r, wr));
                    }
                }
            }
            for (t, w, _, writes) in &per_task {
                for &s in writes {
                    let s = s as usize;
                    if stamp[s] == pi as u32 && writer[s].0 != *t {
                        let (t2, w2) = writer[s];
                        return Err(format!("phase {pi}: slot {s} written by tasks {} (worker {w2}) and {} (worker {w})", name(t2), name(*t)));
                    }
                    stamp[s] = pi as u32;
                    writer[s] = (*t, *w);
                }
            }
            for (t, w, reads, _) in &per_task {
                for &s in reads {
                    let s = s as usize;
                    if stamp[s] == pi as u32 && writer[s].0 != *t {
                        let (t2, w2) = writer[s];
                        return Err(format!("phase {pi}: slot {s} written by task {} (worker {w2}) and read by {} (worker {w})", name(t2), name(*t)));
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
        let decisions: Vec<AtomicU32> = (0..self.plan.decision_slots)
            .map(|_| AtomicU32::new(NOT_RUN))
            .collect();
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
                    let items: &[Item] = if ph.parallel {
                        &ph.slices[w]
                    } else if w == 0 {
                        &ph.slices[0]
                    } else {
                        &[]
                    };
                    for it in items {
                        self.run_item(it, &mut store, &mut ctx, sh);
                        if !ctx.faults.is_empty() {
                            // SAFETY: only worker `w` touches its fault buffer during a scan;
                            // worker 0 reads it after the scan's last barrier.
                            let buf = unsafe { &mut *sh.faults[w].0.get() };
                            buf.extend(ctx.faults.drain(..).map(|f| (it.first, f)));
                        }
                    }
                }
                if self.plan.end_barrier && !sh.barrier.wait(w, &mut epoch) {
                    return;
                }
                if let Some(d) = driver.as_deref_mut() {
                    let elapsed = t0.map(|t| t.elapsed()).unwrap_or_default();
                    // SAFETY: every other worker has passed the scan's last barrier and waits at
                    // the next scan's first one: worker 0 has the buffers and slots to itself.
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

    #[inline]
    fn decision_of(&self, sh: &Shared<'_>, slot: u32) -> u32 {
        // Relaxed: written in an earlier phase, ordered by the barrier in between.
        sh.decisions[slot as usize].load(Ordering::Relaxed)
    }

    /// The successor (task or STOP) a decision leads to; NOT_RUN stays NOT_RUN.
    #[inline]
    fn successor_of(&self, d: u32) -> u32 {
        match d {
            NOT_RUN | STOP => d,
            _ => self.plan.task_of_rung[(d & !FOR_TEST) as usize],
        }
    }

    #[inline]
    fn run_item(
        &self,
        it: &Item,
        store: &mut SharedSlots,
        ctx: &mut super::ScanCtx<'_>,
        sh: &Shared<'_>,
    ) {
        let plan = &self.plan;
        if !it.guard.is_empty() {
            let holds = plan.guards[it.guard.start as usize..it.guard.end as usize]
                .iter()
                .any(|&(slot, succ)| self.successor_of(self.decision_of(sh, slot)) == succ);
            if !holds {
                if it.decision != NONE {
                    sh.decisions[it.decision as usize].store(NOT_RUN, Ordering::Relaxed);
                }
                return;
            }
        }
        let at = if it.entries.is_empty() {
            Exit::Rung(RungId(it.start))
        } else {
            let mut at = None;
            for &slot in &plan.entry_slots[it.entries.start as usize..it.entries.end as usize] {
                let d = self.decision_of(sh, slot);
                if d != NOT_RUN && d != STOP && self.successor_of(d) == it.first {
                    debug_assert!(at.is_none(), "task {} entered twice", it.first);
                    at = Some(if d & FOR_TEST != 0 {
                        Exit::ForTest(RungId(d & !FOR_TEST))
                    } else {
                        Exit::Rung(RungId(d))
                    });
                }
            }
            match at {
                Some(at) => at,
                None => {
                    // No predecessor led here: the sequential scan does not run it either.
                    if it.decision != NONE {
                        sh.decisions[it.decision as usize].store(NOT_RUN, Ordering::Relaxed);
                    }
                    return;
                }
            }
        };
        let exit = match it.region {
            Region::Rungs(lo, hi) => self
                .machine
                .resume(store, ctx, at, |r| lo <= r.0 && r.0 < hi),
            Region::Tasks(lo, hi) => {
                let task_of = &plan.task_of_rung;
                self.machine.resume(store, ctx, at, |r| {
                    let t = task_of[r.index()];
                    lo <= t && t <= hi
                })
            }
        };
        if it.decision != NONE {
            let d = match exit {
                Exit::Stop => STOP,
                Exit::Rung(r) => r.0,
                Exit::ForTest(h) => h.0 | FOR_TEST,
            };
            sh.decisions[it.decision as usize].store(d, Ordering::Relaxed);
        }
    }
}
