//! The measured choice among candidate plans, in the manner of FFTW's planner in "measure"
//! mode (Frigo & Johnson): the first scans of a run time each candidate — real scans of the
//! run, their results kept — and the fastest runs; cheap re-measurements every N scans (N
//! doubling while the choice holds, up to a cap) or as soon as the scan time jumps keep the
//! choice right when the machine gets busy or calms down.
//!
//! A pure state machine over nanoseconds: [`Chooser::next`] says which candidate runs the next
//! window of scans, [`Chooser::record`] takes the times of a window's scans. It neither runs nor
//! times anything (the machine does) and knows nothing of plans beyond their number, so it is
//! tested here on made-up timings. Invariant: every window has at least one scan, and the
//! candidate of a window is one of `0..candidates`.

use super::config::Measure;

/// A change of the running candidate.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Switch {
    /// The first scan run on the new candidate.
    pub scan: u64,
    /// Candidate indices.
    pub from: usize,
    /// Candidate indices.
    pub to: usize,
    /// Why, in words (the timings that decided).
    pub why: String,
}

/// The next scans to run.
#[derive(Copy, Clone, Debug, PartialEq, Eq)]
pub struct Window {
    /// Which candidate.
    pub candidate: usize,
    /// How many scans (at least 1).
    pub scans: u64,
    /// Time every scan of the window (otherwise every `sample_every`-th).
    pub timed: bool,
}

#[derive(Clone, Debug)]
enum Stage {
    /// Timing candidate `order[at]`, one scan per window.
    Probe {
        order: Vec<usize>,
        at: usize,
        samples: Vec<u64>,
    },
    /// Running the chosen candidate; `left` scans to the next re-measurement.
    Exploit { left: u64 },
}

/// The measured choice of one run.
#[derive(Clone, Debug)]
pub struct Chooser {
    measure: Measure,
    n: usize,
    current: usize,
    /// Median ns per scan of each candidate at its last measurement.
    estimate: Vec<Option<u64>>,
    /// Recent samples of the current candidate.
    recent: Vec<u64>,
    interval: u64,
    stage: Stage,
    /// The first scan of the next window.
    scan: u64,
    switches: Vec<Switch>,
    scans_on: Vec<u64>,
    rounds: u64,
}

/// The median of `v` (sorts it); 0 when empty.
fn median(v: &mut [u64]) -> u64 {
    if v.is_empty() {
        return 0;
    }
    v.sort_unstable();
    v[v.len() / 2]
}

impl Chooser {
    /// A choice among `candidates` (at least 1) starting at scan `first`; candidate 0 is
    /// the default (the first to run, and the one kept on ties).
    pub fn new(candidates: usize, measure: Measure, first: u64) -> Chooser {
        let n = candidates.max(1);
        let stage = if n == 1 {
            Stage::Exploit { left: u64::MAX }
        } else {
            Stage::Probe {
                order: (0..n).collect(),
                at: 0,
                samples: Vec::new(),
            }
        };
        Chooser {
            measure,
            n,
            current: 0,
            estimate: vec![None; n],
            recent: Vec::new(),
            interval: measure.min_interval.max(1),
            stage,
            scan: first,
            switches: Vec::new(),
            scans_on: vec![0; n],
            rounds: 0,
        }
    }

    /// The window to run next.
    pub fn next(&self) -> Window {
        match &self.stage {
            Stage::Probe { order, at, .. } => Window {
                candidate: order[*at],
                scans: 1,
                timed: true,
            },
            Stage::Exploit { left } => Window {
                candidate: self.current,
                scans: (*left).clamp(1, self.measure.chunk.max(1)),
                timed: false,
            },
        }
    }

    /// The window `w` ran; `times` are the ns of its timed scans (any number, maybe none).
    pub fn record(&mut self, w: Window, times: &[u64]) {
        self.scans_on[w.candidate] += w.scans;
        self.scan += w.scans;
        match &mut self.stage {
            Stage::Probe { order, at, samples } => {
                samples.extend_from_slice(times);
                let best_other = (0..self.n)
                    .filter(|&c| c != order[*at])
                    .filter_map(|c| self.estimate[c])
                    .min();
                let last = samples.last().copied().unwrap_or(0);
                let hopeless = best_other.is_some_and(|b| last > b.saturating_mul(4));
                if samples.len() as u64 >= self.measure.probe_scans.max(1) || hopeless {
                    // The first scan on a candidate warms its caches: not counted if others are.
                    let mut s = if samples.len() > 1 {
                        samples[1..].to_vec()
                    } else {
                        samples.clone()
                    };
                    self.estimate[order[*at]] = Some(median(&mut s));
                    samples.clear();
                    *at += 1;
                    if *at == order.len() {
                        self.decide();
                    }
                }
            }
            Stage::Exploit { left } => {
                *left = left.saturating_sub(w.scans);
                self.recent.extend_from_slice(times);
                let keep = 16;
                if self.recent.len() > keep {
                    self.recent.drain(..self.recent.len() - keep);
                }
                let est = self.estimate[self.current];
                if self.n > 1 && !times.is_empty() && self.recent.len() >= 3 {
                    let mut r = self.recent.clone();
                    let now = median(&mut r);
                    if let Some(e) = est {
                        if now > e.saturating_mul(3) / 2 + 1000 {
                            let why = format!("scan time rose from {e} ns to {now} ns");
                            return self.remeasure(Some(why));
                        }
                    }
                }
                if *left == 0 {
                    self.remeasure(None);
                }
            }
        }
    }

    /// Starts a re-measurement of every other candidate (the current one's estimate comes
    /// from its recent scans).
    fn remeasure(&mut self, jump: Option<String>) {
        if !self.recent.is_empty() {
            let mut r = self.recent.clone();
            self.estimate[self.current] = Some(median(&mut r));
        }
        self.recent.clear();
        if jump.is_some() {
            self.interval = self.measure.min_interval.max(1);
        }
        let order: Vec<usize> = (0..self.n).filter(|&c| c != self.current).collect();
        self.stage = Stage::Probe {
            order,
            at: 0,
            samples: Vec::new(),
        };
    }

    /// All candidates measured: run the fastest (ties: the current, then the lowest index).
    fn decide(&mut self) {
        self.rounds += 1;
        let est = |c: usize| self.estimate[c].unwrap_or(u64::MAX);
        let mut best = self.current;
        for c in 0..self.n {
            // Switch only for a clear gain (3 %): noise must not flip the choice back and forth.
            if est(c).saturating_mul(100) < est(best).saturating_mul(97) {
                best = c;
            }
        }
        if best != self.current {
            let why = format!(
                "measured {} ns per scan against {} ns",
                est(best),
                est(self.current)
            );
            self.switches.push(Switch {
                scan: self.scan,
                from: self.current,
                to: best,
                why,
            });
            self.current = best;
            self.interval = self.measure.min_interval.max(1);
        } else if self.rounds > 1 {
            self.interval = (self.interval * 2).min(self.measure.max_interval.max(1));
        }
        self.stage = Stage::Exploit {
            left: self.interval,
        };
    }

    /// The candidate running now (or last).
    pub fn current(&self) -> usize {
        self.current
    }

    /// Every switch so far.
    pub fn switches(&self) -> &[Switch] {
        &self.switches
    }

    /// The last measured ns per scan of each candidate.
    pub fn estimates(&self) -> &[Option<u64>] {
        &self.estimate
    }

    /// Scans run on each candidate.
    pub fn scans_on(&self) -> &[u64] {
        &self.scans_on
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn measure() -> Measure {
        Measure::default()
    }

    /// Runs windows until `stop` says so, timing candidate `c`'s scans with `ns(c, scan)`.
    fn drive(ch: &mut Chooser, scans: u64, ns: impl Fn(usize, u64) -> u64) -> Vec<usize> {
        let mut ran = Vec::new();
        let mut scan = 0;
        while scan < scans {
            let w = ch.next();
            assert!(w.scans >= 1 && w.candidate < 2);
            let times: Vec<u64> = (scan..scan + w.scans).map(|s| ns(w.candidate, s)).collect();
            ran.extend(std::iter::repeat_n(w.candidate, w.scans as usize));
            ch.record(w, &times);
            scan += w.scans;
        }
        ran
    }

    #[test]
    fn the_first_scans_time_each_candidate_and_the_fastest_runs() {
        let mut ch = Chooser::new(2, measure(), 0);
        let ran = drive(&mut ch, 8, |c, _| if c == 0 { 100_000 } else { 60_000 });
        assert_eq!(ran, [0, 0, 0, 0, 1, 1, 1, 1]);
        assert_eq!(ch.current(), 1);
        assert_eq!(ch.estimates(), &[Some(100_000), Some(60_000)]);
        assert_eq!(ch.switches().len(), 1);
        assert_eq!(ch.switches()[0].scan, 8);
        assert_eq!(
            ch.switches()[0].why,
            "measured 60000 ns per scan against 100000 ns"
        );
        assert_eq!(
            ch.next(),
            Window {
                candidate: 1,
                scans: 32,
                timed: false
            }
        );
    }

    #[test]
    fn a_hopeless_candidate_is_dropped_after_one_scan_and_the_default_kept() {
        let mut ch = Chooser::new(2, measure(), 0);
        let ran = drive(&mut ch, 5, |c, _| if c == 0 { 100_000 } else { 1_000_000 });
        assert_eq!(ran, [0, 0, 0, 0, 1]);
        assert_eq!(ch.current(), 0);
        assert!(ch.switches().is_empty());
        // A gain under 3 % does not switch either.
        let mut ch = Chooser::new(2, measure(), 0);
        drive(&mut ch, 8, |c, _| if c == 0 { 100_000 } else { 98_000 });
        assert_eq!(ch.current(), 0);
    }

    #[test]
    fn a_busy_machine_switches_to_sequential_and_back_when_it_calms_down() {
        let mut ch = Chooser::new(2, measure(), 0);
        // Quiet until scan 200, busy (parallel 5x slower) until 1000, quiet again.
        let ns = |c: usize, s: u64| match (c, (200..1000).contains(&s)) {
            (0, _) => 100_000,
            (_, false) => 60_000,
            (_, true) => 300_000,
        };
        let ran = drive(&mut ch, 4000, ns);
        let sw = ch.switches();
        assert!(sw.len() >= 3, "{sw:?}");
        assert_eq!((sw[0].from, sw[0].to), (0, 1));
        assert_eq!((sw[1].from, sw[1].to), (1, 0));
        assert!(
            sw[1].scan >= 200 && sw[1].scan < 300,
            "reacts within a window: {sw:?}"
        );
        assert!(sw[2].scan > 1000 && sw[2].scan < 1000 + 2048 + 16, "{sw:?}");
        assert_eq!(ch.current(), 1);
        // While busy, the parallel candidate ran only its probes.
        let busy_par = ran[300..1000].iter().filter(|&&c| c == 1).count();
        assert!(busy_par < 40, "{busy_par} busy scans on the parallel plan");
    }

    #[test]
    fn the_interval_doubles_while_the_choice_holds() {
        let mut ch = Chooser::new(2, measure(), 0);
        let ran = drive(&mut ch, 2000, |c, _| if c == 0 { 100_000 } else { 60_000 });
        // Probes of the sequential walk after 128, 256, 512 and 1024 scans on the parallel one.
        let probes = ran.windows(2).filter(|w| w[0] == 1 && w[1] == 0).count();
        assert_eq!(probes, 4, "re-measurements in 2000 scans");
        assert_eq!(ch.switches().len(), 1);
    }

    #[test]
    fn one_candidate_never_measures() {
        let ch = Chooser::new(1, measure(), 5);
        assert_eq!(
            ch.next(),
            Window {
                candidate: 0,
                scans: 32,
                timed: false
            }
        );
    }
}
