//! What a caller does around each scan ([`ScanDriver`]), and the plain sequential loop over
//! scans ([`run_sequential`]) every plan falls back to. Depends only on the interpreter; the
//! bottom of the running side of the parallel module.

use crate::{Fault, Machine, State};
use std::ops::Range;
use std::time::{Duration, Instant};

/// What a caller of [`ParallelMachine::run`](super::ParallelMachine::run) (or [`run_sequential`]) does around each scan. Both
/// methods are called on the calling thread, with exclusive access to the state.
pub trait ScanDriver {
    /// Before scan `scan`: write its inputs (`Machine::set_inputs_in`) into the state's bytes.
    fn before_scan(&mut self, machine: &Machine, scan: u64, slots: &mut [u8]);
    /// After scan `scan`: the state, the scan's faults in sequential order, and the time the
    /// scan took (inputs and this call excluded).
    fn after_scan(
        &mut self,
        machine: &Machine,
        scan: u64,
        slots: &[u8],
        faults: &[Fault],
        elapsed: Duration,
    );
    /// Whether the driver wants each scan timed (two clock reads per scan); `elapsed` is zero
    /// otherwise.
    fn wants_time(&self) -> bool {
        true
    }
    /// Whether `after_scan` reads the state. When false, the parallel executor may leave the
    /// caller's state behind while a plan runs on a layout of its own (`slots` is then the
    /// state as it was before those scans), and brings it up to date between windows and at
    /// the end of the run.
    fn wants_state(&self) -> bool {
        true
    }
    /// Whether the driver reads and writes the state only through the [`Machine`] it is given
    /// (its layout: `set_inputs_in`, `canonical_values`, `addr_of`), whichever machine that is.
    /// The parallel executor then hands it a plan's own layout's machine and state directly,
    /// instead of moving the state into the caller's layout around every scan.
    fn reads_any_layout(&self) -> bool {
        false
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
        driver.before_scan(machine, scan, state.bytes_mut());
        faults.clear();
        let t0 = timed.then(Instant::now);
        machine.run_scan(state, scan, &mut faults);
        let elapsed = t0.map(|t| t.elapsed()).unwrap_or_default();
        driver.after_scan(machine, scan, state.bytes(), &faults, elapsed);
    }
}
