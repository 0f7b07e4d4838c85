//! The per-scan bookkeeping of a run: the driver that writes each scan's inputs and, after it,
//! folds the state's digest (seq == par is checked by comparing two passes' digests chunk by
//! chunk), counts and keeps the faults, writes the trace line and moves the progress bar; and
//! the warm-up's driver, which only writes inputs. The passes themselves, and what they add
//! up to, are `engine`'s. Nothing here prints.

use super::compare::{canonical_slots, digest};
use super::inputs::InputTable;
use super::trace::{cell, Trace};
use crate::cmd::progress::Bar;
use plc_exec::parallel::ScanDriver;
use plc_exec::{load_value, Addr, Fault, FaultKind, Machine};
use std::collections::HashMap;
use std::fmt::Write as _;
use std::time::Duration;

/// Faults kept in the report (the count covers all).
const FAULTS_KEPT: usize = 1000;

/// Counts every fault by (rung, kind), in the order of first occurrence.
#[derive(Default)]
pub(super) struct FaultTally {
    pub(super) index: HashMap<(u32, FaultKind), usize>,
    /// (rung, kind, count, first scan, last scan)
    pub(super) rows: Vec<(u32, FaultKind, u64, u64, u64)>,
}

impl FaultTally {
    pub(super) fn add(&mut self, f: &Fault) {
        let rows = &mut self.rows;
        let i = *self.index.entry((f.rung.raw(), f.kind)).or_insert_with(|| {
            rows.push((f.rung.raw(), f.kind, 0, f.scan, f.scan));
            rows.len() - 1
        });
        let row = &mut self.rows[i];
        row.2 += 1;
        row.4 = f.scan;
    }
}

/// What a pass does with the per-scan digests of the state (the hash of every value and fault
/// that checks seq == par): a pass that no other pass is compared with computes none (`run
/// --mode seq` or `--mode par` spend no time on them between the scans).
pub(super) enum Digests {
    /// No other pass to compare with.
    Skip,
    /// Record them for the pass that follows (one turn's).
    Record(TurnDigests),
    /// Check them against the pass before's (the same turn's).
    Check(TurnDigests),
}

/// The most digests a turn keeps: a turn of more scans folds consecutive scans' digests into
/// one per chunk of `ceil(turn / DIGESTS_KEPT)` scans, so the memory of a run does not grow
/// with its scans or its turns (16 bytes × 4096 at most).
pub(super) const DIGESTS_KEPT: u64 = 4096;

/// One turn's digests, folded by chunks of `per` consecutive scans (one scan per chunk when the
/// turn has at most [`DIGESTS_KEPT`] scans: every scan's digest, as before). The sequential pass
/// records them; the parallel pass, which runs the same turn next, folds its own the same way
/// and compares chunk by chunk. A chunk that differs gives its last scan as the mismatch: the
/// replay (`first_difference`) then finds the first scan that differs, which is no later.
#[derive(Default)]
pub(super) struct TurnDigests {
    /// Scans per chunk in this turn.
    pub(super) per: u64,
    /// The fold of the current chunk's digests, and how many it holds.
    pub(super) acc: u128,
    pub(super) in_acc: u64,
    /// Recorded chunks (recording), or the other pass's chunks (checking).
    pub(super) chunks: Vec<u128>,
    /// Checking: the next chunk to compare.
    pub(super) next: usize,
}

impl TurnDigests {
    /// Starts a turn of `scans` scans (the recorded chunks of the last turn are dropped).
    pub(super) fn start_turn(&mut self, scans: u64) {
        self.per = scans.div_ceil(DIGESTS_KEPT).max(1);
        self.acc = 0;
        self.in_acc = 0;
        self.chunks.clear();
        self.next = 0;
    }

    /// Folds one scan's digest in; the chunk's fold when it is complete.
    pub(super) fn fold(&mut self, d: u128) -> Option<u128> {
        // Order-sensitive: an odd multiplier, then the next digest (a chunk of one is `d`).
        self.acc = self
            .acc
            .wrapping_mul(0x9e37_79b9_7f4a_7c15_f39c_c060_5ced_c835)
            ^ d;
        self.in_acc += 1;
        (self.in_acc == self.per).then(|| self.take())
    }

    /// The fold of the (partial) chunk so far, which starts a new chunk.
    pub(super) fn take(&mut self) -> u128 {
        let acc = self.acc;
        (self.acc, self.in_acc) = (0, 0);
        acc
    }

    /// Checking: whether `chunk` equals the other pass's next chunk.
    pub(super) fn matches(&mut self, chunk: u128) -> bool {
        let ok = self.chunks.get(self.next) == Some(&chunk);
        self.next += 1;
        ok
    }
}

/// Per-scan bookkeeping shared by both modes.
pub(super) struct Driver<'a> {
    pub(super) inputs: &'a InputTable,
    /// The canonical values' addresses in the layout of the machine last seen (its address), and
    /// in the other one seen (a parallel plan on a layout of its own): computed once each.
    pub(super) canon: Vec<(Addr, u32)>,
    pub(super) canon_of: usize,
    pub(super) canon_other: Option<(usize, Vec<(Addr, u32)>)>,
    pub(super) digests: Digests,
    pub(super) first_mismatch: Option<u64>,
    pub(super) total: Duration,
    /// The scan time of each full window of `window_scans` scans, in run order (the spread of
    /// the measurement; a last partial window is left out).
    pub(super) windows: Vec<Duration>,
    pub(super) window_scans: u64,
    window_at: (u64, Duration),
    pub(super) faults: Vec<(u64, u32, FaultKind)>,
    pub(super) fault_count: u64,
    pub(super) tally: FaultTally,
    pub(super) trace: Option<Trace<'a>>,
    pub(super) bar: Bar,
}

impl<'a> Driver<'a> {
    pub(super) fn new(
        inputs: &'a InputTable,
        m: &Machine,
        digests: Digests,
        trace: Option<Trace<'a>>,
        bar: Bar,
        window_scans: u64,
    ) -> Driver<'a> {
        Driver {
            inputs,
            canon: match digests {
                Digests::Skip => Vec::new(),
                _ => canonical_slots(m),
            },
            canon_of: std::ptr::from_ref(m) as usize,
            canon_other: None,
            digests,
            first_mismatch: None,
            total: Duration::ZERO,
            windows: Vec::new(),
            window_scans: window_scans.max(1),
            window_at: (0, Duration::ZERO),
            faults: Vec::new(),
            fault_count: 0,
            tally: FaultTally::default(),
            trace,
            bar,
        }
    }
}

impl ScanDriver for Driver<'_> {
    fn before_scan(&mut self, m: &Machine, scan: u64, slots: &mut [u8]) {
        m.set_inputs_in(slots, self.inputs.at(scan));
    }

    fn after_scan(
        &mut self,
        m: &Machine,
        scan: u64,
        slots: &[u8],
        faults: &[Fault],
        elapsed: Duration,
    ) {
        self.total += elapsed;
        self.window_at.0 += 1;
        self.window_at.1 += elapsed;
        if self.window_at.0 == self.window_scans {
            self.windows.push(self.window_at.1);
            self.window_at = (0, Duration::ZERO);
        }
        let of = std::ptr::from_ref(m) as usize;
        if of != self.canon_of && !matches!(self.digests, Digests::Skip) {
            let other = match self.canon_other.take() {
                Some((o, c)) if o == of => c,
                _ => canonical_slots(m),
            };
            let last = std::mem::replace(&mut self.canon, other);
            self.canon_other = Some((self.canon_of, last));
            self.canon_of = of;
        }
        match &mut self.digests {
            Digests::Skip => {}
            Digests::Record(ds) => {
                if let Some(chunk) = ds.fold(digest(slots, &self.canon, faults)) {
                    ds.chunks.push(chunk);
                }
            }
            Digests::Check(ds) => {
                if let Some(chunk) = ds.fold(digest(slots, &self.canon, faults)) {
                    if !ds.matches(chunk) && self.first_mismatch.is_none() {
                        self.first_mismatch = Some(scan);
                    }
                }
            }
        }
        self.fault_count += faults.len() as u64;
        for f in faults {
            if self.faults.len() < FAULTS_KEPT {
                self.faults.push((f.scan, f.rung.raw(), f.kind));
            }
            self.tally.add(f);
        }
        if let Some(t) = &mut self.trace {
            if t.error.is_none() {
                t.line.clear();
                let _ = write!(
                    t.line,
                    "{scan},{}",
                    (scan as i64).wrapping_mul(m.config().cycle_ms as i64)
                );
                for &(at, ty) in &t.cols {
                    t.line.push(',');
                    if ty == plc_model::Type::String {
                        let s = plc_exec::strings::load_str(slots, at);
                        t.line.push_str(&super::trace::text_cell(&s.text()));
                    } else {
                        t.line.push_str(&cell(load_value(slots, at, ty)));
                    }
                }
                t.line.push('\n');
                if let Err(e) = t.out.write_all(t.line.as_bytes()) {
                    t.error = Some(e);
                }
            }
        }
        self.bar.inc();
    }

    fn wants_state(&self) -> bool {
        !matches!(self.digests, Digests::Skip) || self.trace.is_some()
    }

    /// The digests read the state through the machine's canonical values (any layout); the
    /// trace's columns are addresses of the first machine's layout.
    fn reads_any_layout(&self) -> bool {
        self.trace.is_none()
    }
}

/// A driver that only writes the inputs (warm-up).
pub(super) struct Inputs<'a>(pub(super) &'a InputTable);

impl ScanDriver for Inputs<'_> {
    fn before_scan(&mut self, m: &Machine, scan: u64, slots: &mut [u8]) {
        m.set_inputs_in(slots, self.0.at(scan));
    }
    fn after_scan(&mut self, _: &Machine, _: u64, _: &[u8], _: &[Fault], _: Duration) {}
    fn wants_time(&self) -> bool {
        false
    }
    fn wants_state(&self) -> bool {
        false
    }
    fn reads_any_layout(&self) -> bool {
        true
    }
}
