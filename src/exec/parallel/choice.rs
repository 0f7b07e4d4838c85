//! The measured choice among candidate plans, in the manner of FFTW's planner in "measure"
//! mode (Frigo & Johnson): the first scans of a run time the candidates — real scans of the
//! run, their results kept — and the fastest runs; cheap re-measurements every N scans (N
//! doubling while the choice holds, quadrupling when every other candidate took twice its time
//! or more, up to a cap) or as soon as the scan time jumps keep the
//! choice right when the machine gets busy or calms down.
//!
//! A measurement is made of *rounds*; a round *visits* each measured candidate once (the order
//! rotating from round to round), and a visit runs a few untimed-for-the-choice warm-up scans
//! (the first scans after a switch pay for moving the state and code between the cores) and then
//! a few timed ones, whose median is the visit's time. Interleaving the candidates in rounds
//! makes a change of the machine's load hit them alike, and the choice compares each candidate
//! with the current one *round by round* ([`choose`]): it replaces the current one only if it
//! was faster in more than half the rounds, by at least 3 % at the median of the per-round
//! ratios. The measurement stops once it has its minimum of rounds and the choice after the
//! last round is the choice after the round before (successive choices agree), or when a
//! candidate is at least twice as fast in every round, or at its maximum of rounds.
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

/// One window as it ran, for the run's log ([`Chooser::windows`]): its candidate, its scans and
/// what its timed scans took.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct WindowRecord {
    /// The window's first scan.
    pub scan: u64,
    /// Candidate index.
    pub candidate: usize,
    /// Scans run.
    pub scans: u64,
    /// Whether it was part of a measurement (a visit's scan) rather than a run of the chosen
    /// candidate.
    pub measuring: bool,
    /// Timed scans (every scan of a measurement; every `sample_every`-th otherwise).
    pub timed: usize,
    /// Lower median and minimum of the timed scans, ns (`None` when none was timed).
    pub median_ns: Option<u64>,
    /// See `median_ns`.
    pub min_ns: Option<u64>,
}

/// The log keeps the first this many windows of a run whole ...
const LOG_FIRST: usize = 64;
/// ... then the windows of each measurement that ends in a switch (at most this many of each)
/// ...
const LOG_PER_SWITCH: usize = 48;
/// ... and never more than this many in all (the rest are counted, not kept).
const LOG_MAX: usize = 512;

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

/// What a measurement concluded ([`choose`]).
#[derive(Copy, Clone, Debug, PartialEq, Eq)]
pub struct Verdict {
    /// The candidate to run (an index of the table: 0 is the current one).
    pub pick: usize,
    /// The median over the rounds of its time per scan over the current one's, per mille
    /// (1000 when the pick is the current one).
    pub ratio_permille: u64,
    /// Rounds in which it was faster than the current one, of `rounds` measured with both.
    pub wins: usize,
    /// Rounds measured with both.
    pub rounds: usize,
    /// Whether it was at most half the current one's time in every such round.
    pub decisive: bool,
}

/// The candidate a measurement picks: `table[i][r]` is candidate `i`'s time per scan in round
/// `r` (`None`: not measured in that round), candidate 0 the one running now. Another candidate
/// replaces it only if it was faster in more than half the rounds both were measured in and its
/// median per-round ratio to the current one is at most 0.97; among several, the lowest median
/// ratio (ties: the lower index). Noise must not flip the choice back and forth, and a plan
/// slower than the current one never replaces it.
pub fn choose(table: &[Vec<Option<u64>>]) -> Verdict {
    let mut best = Verdict {
        pick: 0,
        ratio_permille: 1000,
        wins: 0,
        rounds: 0,
        decisive: false,
    };
    let Some(current) = table.first() else {
        return best;
    };
    for (i, row) in table.iter().enumerate().skip(1) {
        let pairs: Vec<(u64, u64)> = row
            .iter()
            .zip(current)
            .filter_map(|(&t, &c)| Some((t?, c?.max(1))))
            .collect();
        if pairs.is_empty() {
            continue;
        }
        let mut ratios: Vec<u64> = pairs.iter().map(|&(t, c)| t * 1000 / c).collect();
        let wins = pairs.iter().filter(|&&(t, c)| t < c).count();
        let decisive = ratios.iter().all(|&r| r <= 500);
        let ratio = lower_median(&mut ratios);
        if ratio <= 970 && wins * 2 > pairs.len() && ratio < best.ratio_permille {
            best = Verdict {
                pick: i,
                ratio_permille: ratio,
                wins,
                rounds: pairs.len(),
                decisive,
            };
        }
    }
    best
}

/// The lower median of `v` (sorts it); 0 when empty.
fn lower_median(v: &mut [u64]) -> u64 {
    if v.is_empty() {
        return 0;
    }
    v.sort_unstable();
    v[(v.len() - 1) / 2]
}

/// A measurement in progress.
#[derive(Clone, Debug)]
struct Measurement {
    /// The candidates measured, the current one first.
    who: Vec<usize>,
    /// Rounds completed.
    round: usize,
    /// Position in this round's order.
    at: usize,
    /// Scans and timed scans of the visit in progress (its warm-up included).
    visit_scans: u64,
    visit: Vec<u64>,
    /// Per `who` index, per round: the visit's median ns per scan.
    table: Vec<Vec<Option<u64>>>,
    /// Left out of the later rounds (hopeless: 4× the best visit of a round after one scan).
    dropped: Vec<bool>,
    /// The choice after the previous round.
    last: Option<usize>,
    /// Why the measurement started early (a jump in scan time), if it did.
    why: Option<String>,
}

impl Measurement {
    fn new(who: Vec<usize>, why: Option<String>) -> Measurement {
        let n = who.len();
        Measurement {
            who,
            round: 0,
            at: 0,
            visit_scans: 0,
            visit: Vec::new(),
            table: vec![Vec::new(); n],
            dropped: vec![false; n],
            last: None,
            why,
        }
    }

    /// This round's visiting order (indices of `who`): rotated by the round, the dropped left
    /// out.
    fn order(&self) -> Vec<usize> {
        let n = self.who.len();
        (0..n)
            .map(|k| (k + self.round) % n)
            .filter(|&i| !self.dropped[i])
            .collect()
    }

    /// The best visit time of the current round so far.
    fn best_this_round(&self) -> Option<u64> {
        self.table
            .iter()
            .filter_map(|row| row.get(self.round).copied().flatten())
            .min()
    }
}

#[derive(Clone, Debug)]
enum Stage {
    Measure(Box<Measurement>),
    /// Running the chosen candidate; `left` scans to the next re-measurement.
    Exploit {
        left: u64,
    },
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
    measurements: u64,
    /// The windows logged (the first ones, then those of measurements that switched).
    log: Vec<WindowRecord>,
    /// The windows of the measurement in progress, once past the first ones.
    pending: Vec<WindowRecord>,
    /// Windows run but not logged.
    unlogged: u64,
}

impl Chooser {
    /// A choice among `candidates` (at least 1) starting at scan `first`; candidate 0 is
    /// the default (the first to run, and the one kept unless another is clearly faster).
    pub fn new(candidates: usize, measure: Measure, first: u64) -> Chooser {
        let n = candidates.max(1);
        let stage = if n == 1 {
            Stage::Exploit { left: u64::MAX }
        } else {
            Stage::Measure(Box::new(Measurement::new((0..n).collect(), None)))
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
            measurements: 0,
            log: Vec::new(),
            pending: Vec::new(),
            unlogged: 0,
        }
    }

    /// The window to run next.
    pub fn next(&self) -> Window {
        match &self.stage {
            Stage::Measure(m) => Window {
                candidate: m.who[m.order()[m.at]],
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
        self.log_window(w, times);
        self.scans_on[w.candidate] += w.scans;
        self.scan += w.scans;
        match &mut self.stage {
            Stage::Measure(m) => {
                m.visit_scans += w.scans;
                m.visit.extend_from_slice(times);
                if self.visit_over() {
                    self.end_visit();
                }
            }
            Stage::Exploit { left } => {
                *left = left.saturating_sub(w.scans);
                let left = *left;
                self.recent.extend_from_slice(times);
                let keep = 16;
                if self.recent.len() > keep {
                    self.recent.drain(..self.recent.len() - keep);
                }
                let est = self.estimate[self.current];
                if self.n > 1 && !times.is_empty() && self.recent.len() >= 3 {
                    let now = lower_median(&mut self.recent.clone());
                    if let Some(e) = est {
                        if now > e.saturating_mul(3) / 2 + 1000 {
                            let why = format!("scan time rose from {e} ns to {now} ns");
                            return self.remeasure(Some(why));
                        }
                    }
                }
                if left == 0 {
                    self.remeasure(None);
                }
            }
        }
    }

    /// Logs window `w` (bounded: the first [`LOG_FIRST`] whole, then a measurement's windows
    /// when it ends in a switch, see [`decide`](Self::decide)).
    fn log_window(&mut self, w: Window, times: &[u64]) {
        let measuring = matches!(self.stage, Stage::Measure(_));
        let mut sorted = times.to_vec();
        let rec = WindowRecord {
            scan: self.scan,
            candidate: w.candidate,
            scans: w.scans,
            measuring,
            timed: times.len(),
            median_ns: (!sorted.is_empty()).then(|| lower_median(&mut sorted)),
            min_ns: times.iter().copied().min(),
        };
        if self.log.len() < LOG_FIRST {
            self.log.push(rec);
        } else if measuring && self.pending.len() < LOG_PER_SWITCH {
            self.pending.push(rec);
        } else {
            self.unlogged += 1;
        }
    }

    /// Whether the visit in progress has its scans, or is hopeless (a candidate other than the
    /// current one taking 4× the best visit of the round, after one scan).
    fn visit_over(&self) -> bool {
        let Stage::Measure(m) = &self.stage else {
            return false;
        };
        let warm = self.measure.warm_scans;
        if m.visit_scans >= warm + self.measure.probe_scans.max(1) {
            return true;
        }
        let last = m.visit.last().copied().unwrap_or(0);
        let best = m.best_this_round().or(self.estimate[self.current]);
        best.is_some_and(|b| last > b.saturating_mul(4))
    }

    /// Closes the visit in progress: its median into the table; the round and the measurement
    /// end when it was the last.
    fn end_visit(&mut self) {
        let Stage::Measure(m) = &mut self.stage else {
            return;
        };
        let warm = self.measure.warm_scans as usize;
        let complete = m.visit_scans >= self.measure.warm_scans + self.measure.probe_scans.max(1);
        let mut timed: Vec<u64> = if m.visit.len() > warm {
            m.visit[warm..].to_vec()
        } else {
            m.visit.clone()
        };
        let i = m.order()[m.at];
        let median = (!timed.is_empty()).then(|| lower_median(&mut timed));
        m.table[i].resize(m.round + 1, None);
        m.table[i][m.round] = median;
        if !complete && i != 0 {
            m.dropped[i] = true;
        }
        m.visit.clear();
        m.visit_scans = 0;
        m.at += 1;
        if m.at < m.order().len() {
            return;
        }
        m.round += 1;
        m.at = 0;
        for row in m.table.iter_mut() {
            row.resize(m.round, None);
        }
        let verdict = choose(&m.table);
        let others_left = m.dropped.iter().skip(1).any(|&d| !d);
        let stable =
            m.round >= self.measure.min_rounds.max(1) as usize && m.last == Some(verdict.pick);
        let clear = m.round >= 2 && verdict.decisive;
        if stable || clear || !others_left || m.round >= self.measure.max_rounds.max(1) as usize {
            let m = std::mem::replace(m, Box::new(Measurement::new(Vec::new(), None)));
            self.decide(&m, verdict);
        } else {
            m.last = Some(verdict.pick);
        }
    }

    /// Starts a re-measurement: of every candidate after a jump in scan time (`jump`), else of
    /// the current one, the default (candidate 0: the sequential walk of a run, the one a run
    /// must never be slower than) and the best of the others at their last measurement.
    fn remeasure(&mut self, jump: Option<String>) {
        if !self.recent.is_empty() {
            self.estimate[self.current] = Some(lower_median(&mut self.recent.clone()));
        }
        self.recent.clear();
        let others = (0..self.n).filter(|&c| c != self.current);
        let runner_up = others
            .clone()
            .filter(|&c| self.estimate[c].is_some())
            .min_by_key(|&c| self.estimate[c]);
        let mut who = vec![self.current];
        match (&jump, runner_up) {
            (None, Some(r)) => {
                if self.current != 0 && r != 0 {
                    who.push(0);
                }
                who.push(r);
            }
            _ => who.extend(others),
        }
        if jump.is_some() {
            self.interval = self.measure.min_interval.max(1);
        }
        self.stage = Stage::Measure(Box::new(Measurement::new(who, jump)));
    }

    /// A measurement is over: run what `verdict` picked.
    fn decide(&mut self, m: &Measurement, verdict: Verdict) {
        self.measurements += 1;
        for (i, row) in m.table.iter().enumerate() {
            let mut v: Vec<u64> = row.iter().flatten().copied().collect();
            if !v.is_empty() {
                self.estimate[m.who[i]] = Some(lower_median(&mut v));
            }
        }
        let best = m.who[verdict.pick];
        let pending = std::mem::take(&mut self.pending);
        if best != self.current && self.log.len() + pending.len() <= LOG_MAX {
            self.log.extend(pending);
        } else {
            self.unlogged += pending.len() as u64;
        }
        if best != self.current {
            let est = |c: usize| self.estimate[c].unwrap_or(0);
            let mut why = format!(
                "measured {} ns per scan against {} ns (faster in {} of {} rounds)",
                est(best),
                est(self.current),
                verdict.wins,
                verdict.rounds
            );
            if let Some(jump) = &m.why {
                why = format!("{jump}; {why}");
            }
            self.switches.push(Switch {
                scan: self.scan,
                from: self.current,
                to: best,
                why,
            });
            self.current = best;
            self.interval = self.measure.min_interval.max(1);
        } else {
            // The choice holds: wait longer before the next look, four times longer when every
            // other candidate measured took at least twice the current one's time (a plan that
            // far behind costs most to visit and is least likely to have caught up).
            let far_behind = |c: usize| {
                let (e, cur) = (self.estimate[c], self.estimate[self.current]);
                e.zip(cur)
                    .is_some_and(|(e, cur)| e >= cur.saturating_mul(2))
            };
            let all_far = m.who.iter().all(|&c| c == self.current || far_behind(c));
            let factor = match (all_far, self.measurements > 1) {
                (true, _) => 4,
                (false, true) => 2,
                (false, false) => 1,
            };
            self.interval = (self.interval * factor).min(self.measure.max_interval.max(1));
        }
        self.stage = Stage::Exploit {
            left: self.interval,
        };
    }

    /// Whether the next window is a measurement's visit of a candidate other than the current
    /// one (one [`skip`](Self::skip) may leave out).
    pub fn measuring_other(&self) -> bool {
        matches!(&self.stage, Stage::Measure(m) if m.order()[m.at] != 0)
    }

    /// Leaves the next visit's candidate out of this measurement without running it, as if it
    /// were hopeless (the machine knows it cannot gain now: its workers are not on a core).
    /// Nothing when [`measuring_other`](Self::measuring_other) is false.
    pub fn skip(&mut self) {
        if self.measuring_other() {
            self.end_visit();
        }
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

    /// The windows logged: the first 64 of the run, then the windows of every measurement
    /// that ended in a switch (at most 48 each, 512 in all), in order.
    pub fn windows(&self) -> &[WindowRecord] {
        &self.log
    }

    /// Windows run but not in [`windows`](Self::windows) (the measurement in progress at the
    /// end of the run included).
    pub fn windows_unlogged(&self) -> u64 {
        self.unlogged + self.pending.len() as u64
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn measure() -> Measure {
        Measure::default()
    }

    /// Runs `scans` scans through the chooser's windows, timing candidate `c`'s scan `s` with
    /// `ns(c, s, cold)`, `cold` for the first scan after a change of candidate (every scan of a
    /// timed window, else every 8th, as the machine does). Returns the candidate of every scan.
    fn drive(
        ch: &mut Chooser,
        candidates: usize,
        scans: u64,
        ns: impl Fn(usize, u64, bool) -> u64,
    ) -> Vec<usize> {
        let mut ran: Vec<usize> = Vec::new();
        let mut scan = 0;
        while scan < scans {
            let w = ch.next();
            assert!(w.scans >= 1 && w.candidate < candidates);
            let times: Vec<u64> = (scan..scan + w.scans)
                .map(|s| {
                    let before = if s == scan {
                        ran.last()
                    } else {
                        Some(&w.candidate)
                    };
                    ns(w.candidate, s, before != Some(&w.candidate))
                })
                .zip(scan..)
                .filter(|&(_, s)| w.timed || s % 8 == 0)
                .map(|(t, _)| t)
                .collect();
            ran.extend(std::iter::repeat_n(w.candidate, w.scans as usize));
            ch.record(w, &times);
            scan += w.scans;
        }
        ran
    }

    fn table(rows: &[&[u64]]) -> Vec<Vec<Option<u64>>> {
        rows.iter()
            .map(|r| r.iter().map(|&t| (t > 0).then_some(t)).collect())
            .collect()
    }

    #[test]
    fn choose_needs_a_majority_of_rounds_and_a_three_percent_gain() {
        // Faster in 2 of 3 rounds by 10 %: switch; the outlier round does not matter.
        let v = choose(&table(&[&[100, 100, 100], &[90, 300, 90]]));
        assert_eq!(
            v,
            Verdict {
                pick: 1,
                ratio_permille: 900,
                wins: 2,
                rounds: 3,
                decisive: false
            }
        );
        // Faster in only 1 of 3 rounds (one lucky round): no switch.
        assert_eq!(choose(&table(&[&[100, 100, 100], &[50, 120, 110]])).pick, 0);
        // 2 % faster in every round: noise, no switch.
        assert_eq!(choose(&table(&[&[100, 100, 100], &[98, 98, 98]])).pick, 0);
        // The lowest median ratio wins among several; rounds a candidate missed are not paired.
        let v = choose(&table(&[
            &[100, 200, 100],
            &[80, 160, 80],
            &[50, 0, 0],
            &[60, 110, 60],
        ]));
        assert_eq!(
            (v.pick, v.ratio_permille, v.rounds, v.decisive),
            (2, 500, 1, true)
        );
        // The current one when nothing else was measured.
        assert_eq!(choose(&table(&[&[100], &[0]])).pick, 0);
    }

    #[test]
    fn a_cold_first_scan_does_not_make_the_sequential_walk_lose() {
        // The sequential walk takes 1.03 ms once warm but 1.62 ms on its first scan after the
        // parallel plan ran (its state and code come back from the other core); the parallel
        // plan takes 1.25 ms warm. Timing the cold scan would keep the slower plan.
        let ns = |c: usize, _: u64, cold: bool| match (c, cold) {
            (0, true) => 1_620_000,
            (0, false) => 1_030_000,
            (_, true) => 1_400_000,
            (_, false) => 1_250_000,
        };
        let mut ch = Chooser::new(2, measure(), 0);
        let ran = drive(&mut ch, 2, 1000, ns);
        assert_eq!(ch.current(), 0);
        assert!(ch.switches().is_empty());
        assert_eq!(ch.estimates(), &[Some(1_030_000), Some(1_250_000)]);
        // Three rounds of two visits of 3 scans, then the sequential walk until the first
        // re-measurement.
        assert_eq!(
            ran[..18],
            [0, 0, 0, 1, 1, 1, 1, 1, 1, 0, 0, 0, 0, 0, 0, 1, 1, 1]
        );
        assert!(ran[18..18 + 128].iter().all(|&c| c == 0));
        let on_par = ran.iter().filter(|&&c| c == 1).count();
        assert!(on_par <= 40, "{on_par} of 1000 scans on the slower plan");
    }

    #[test]
    fn the_first_rounds_time_each_candidate_and_the_fastest_runs() {
        let mut ch = Chooser::new(3, measure(), 0);
        let ns = |c: usize, _: u64, _: bool| [100_000, 60_000, 70_000][c];
        let ran = drive(&mut ch, 3, 27, ns);
        // Round 0: 0, 1, 2; round 1: 1, 2, 0; round 2: 2, 0, 1 (3 scans a visit).
        let visits: Vec<usize> = ran.chunks(3).map(|v| v[0]).collect();
        assert_eq!(visits, [0, 1, 2, 1, 2, 0, 2, 0, 1]);
        assert_eq!(ch.current(), 1);
        assert_eq!(ch.estimates(), &[Some(100_000), Some(60_000), Some(70_000)]);
        assert_eq!(ch.switches().len(), 1);
        assert_eq!(ch.switches()[0].scan, 27);
        assert_eq!(
            ch.switches()[0].why,
            "measured 60000 ns per scan against 100000 ns (faster in 3 of 3 rounds)"
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
    fn a_measurement_runs_until_successive_choices_agree() {
        // Rounds alternate which of the two looks faster, 20 % apart: the choice never settles,
        // so the measurement runs its 8 rounds and keeps the default (won 4 of 8: no majority).
        let mut ch = Chooser::new(2, measure(), 0);
        let ns = |c: usize, s: u64, _: bool| {
            let round = s / 6;
            if (c == 1) == (round.is_multiple_of(2)) {
                80_000
            } else {
                100_000
            }
        };
        let ran = drive(&mut ch, 2, 48 + 10, ns);
        assert!(ran[48..].iter().all(|&c| c == 0), "{:?}", &ran[40..]);
        assert!(ch.switches().is_empty());
    }

    #[test]
    fn a_skipped_candidate_never_runs_in_that_measurement_and_the_others_decide() {
        let mut ch = Chooser::new(3, measure(), 0);
        let mut ran = Vec::new();
        while ran.len() < 40 {
            if ch.next().candidate == 2 {
                assert!(ch.measuring_other());
                ch.skip();
                continue;
            }
            let w = ch.next();
            let t = [100_000, 50_000, 10_000][w.candidate];
            ran.extend(std::iter::repeat_n(w.candidate, w.scans as usize));
            ch.record(w, &vec![t; w.scans as usize]);
        }
        assert!(!ran.contains(&2), "{ran:?}");
        assert_eq!(ch.current(), 1, "the faster of the two measured");
        assert_eq!(ch.estimates()[2], None);
        // Not measuring another candidate: skip does nothing.
        assert!(!ch.measuring_other());
        let before = ch.next();
        ch.skip();
        assert_eq!(ch.next(), before);
    }

    #[test]
    fn a_hopeless_candidate_is_dropped_after_one_scan_and_the_default_kept() {
        let mut ch = Chooser::new(3, measure(), 0);
        let ns = |c: usize, _: u64, _: bool| [100_000, 1_000_000, 101_000][c];
        let ran = drive(&mut ch, 3, 30, ns);
        assert_eq!(ran.iter().filter(|&&c| c == 1).count(), 1, "{ran:?}");
        assert_eq!(ch.current(), 0);
        assert!(ch.switches().is_empty());
    }

    #[test]
    fn a_busy_machine_switches_to_sequential_and_back_when_it_calms_down() {
        let mut ch = Chooser::new(2, measure(), 0);
        // Quiet until scan 200, busy (parallel 5x slower) until 1000, quiet again.
        let ns = |c: usize, s: u64, _: bool| match (c, (200..1000).contains(&s)) {
            (0, _) => 100_000,
            (_, false) => 60_000,
            (_, true) => 300_000,
        };
        let ran = drive(&mut ch, 2, 4000, ns);
        let sw = ch.switches();
        assert!(sw.len() >= 3, "{sw:?}");
        assert_eq!((sw[0].from, sw[0].to), (0, 1));
        assert_eq!((sw[1].from, sw[1].to), (1, 0));
        assert!(
            sw[1].scan >= 200 && sw[1].scan < 300,
            "reacts within a window: {sw:?}"
        );
        assert!(sw[1]
            .why
            .starts_with("scan time rose from 60000 ns to 300000 ns; measured 100000"));
        assert!(sw[2].scan > 1000 && sw[2].scan < 1000 + 2048 + 32, "{sw:?}");
        assert_eq!(ch.current(), 1);
        // While busy, the parallel candidate ran only its probes.
        let busy_par = ran[300..1000].iter().filter(|&&c| c == 1).count();
        assert!(busy_par < 40, "{busy_par} busy scans on the parallel plan");
    }

    #[test]
    fn re_measurements_compare_with_the_default_and_the_runner_up_and_the_interval_doubles() {
        let mut ch = Chooser::new(4, measure(), 0);
        let ns = |c: usize, _: u64, _: bool| [100_000, 60_000, 70_000, 90_000][c];
        let ran = drive(&mut ch, 4, 4000, ns);
        // After the first measurement, the default (candidate 0) and the runner-up (2) are
        // timed again, after 128, 256, 512 and 1024 scans on candidate 1; candidate 3 is not.
        let after: Vec<usize> = ran[36..].to_vec();
        assert!(
            !after.contains(&3),
            "a slower candidate is not measured again"
        );
        for c in [0, 2] {
            let probes = after.iter().filter(|&&x| x == c).count();
            assert_eq!(
                probes,
                4 * 3 * 3,
                "three visits in each of four re-measurements"
            );
        }
        let gaps: Vec<usize> = after
            .split(|&c| c != 1)
            .map(<[usize]>::len)
            .filter(|&n| n > 100)
            .collect();
        // Scans on candidate 1 between two re-measurements (the interval, and the visit of
        // candidate 1 that opens the re-measurement).
        assert_eq!(gaps.len(), 5, "{gaps:?}");
        assert_eq!(gaps[..4], [128 + 3, 256 + 3, 512 + 3, 1024 + 3]);
        assert_eq!(ch.switches().len(), 1);
    }

    #[test]
    fn a_candidate_twice_as_slow_is_looked_at_four_times_less_often() {
        // The sequential walk 3.7 µs, the parallel plan 10.4 µs (gen 1k on 2 vCPUs): the
        // intervals grow 4x from the first measurement (512, then the cap), not 128, 256 …
        let mut ch = Chooser::new(2, measure(), 0);
        let ns = |c: usize, _: u64, _: bool| [3_700, 10_400][c];
        let ran = drive(&mut ch, 2, 5000, ns);
        assert!(ch.switches().is_empty());
        let gaps: Vec<usize> = ran
            .split(|&c| c != 0)
            .map(<[usize]>::len)
            .filter(|&n| n > 100)
            .collect();
        assert_eq!(gaps[..2], [512 + 3, 2048 + 3], "{gaps:?}");
        // The parallel plan ran only in measurements (three visits of 3 scans each): the first
        // and three looks in 5,000 scans, where doubling intervals would have taken five.
        let visits = ran.iter().filter(|&&c| c == 1).count();
        assert_eq!(visits, 4 * 9, "scans on the slow plan");
    }

    #[test]
    fn the_log_keeps_the_first_windows_and_the_measurements_that_switch() {
        // Parallel faster until scan 2000, then 5x slower: one switch to it at the start, one
        // back after the jump.
        let mut ch = Chooser::new(2, measure(), 0);
        let ns = |c: usize, s: u64, _: bool| match (c, s < 2000) {
            (0, _) => 100_000,
            (_, true) => 60_000,
            (_, false) => 300_000,
        };
        drive(&mut ch, 2, 4000, ns);
        let log = ch.windows();
        assert_eq!(ch.switches().len(), 2, "{:?}", ch.switches());
        // The first measurement: 3 rounds of two visits of 3 one-scan windows, each timed.
        assert!(log[..18]
            .iter()
            .all(|w| w.measuring && w.scans == 1 && w.timed == 1));
        assert_eq!(
            (
                log[0].candidate,
                log[0].median_ns,
                log[3].candidate,
                log[3].median_ns
            ),
            (0, Some(100_000), 1, Some(60_000))
        );
        // Then runs of 32 scans on the parallel plan, every 8th timed.
        assert_eq!(
            (
                log[18].scan,
                log[18].candidate,
                log[18].scans,
                log[18].measuring
            ),
            (18, 1, 32, false)
        );
        assert_eq!((log[18].timed, log[18].median_ns), (4, Some(60_000)));
        // The windows of every scan are accounted for; the log is contiguous up to the first
        // 64 and then holds the measurement that switched back (it began on the quiet machine
        // and saw the 300 µs visits).
        let logged: u64 = log.len() as u64;
        assert!(logged + ch.windows_unlogged() > 64);
        assert!(
            log[64..].iter().all(|w| w.measuring && w.scan > 1900),
            "{:?}",
            &log[64..]
        );
        assert!(log[64..].iter().any(|w| w.median_ns == Some(300_000)));
        assert!(log.windows(2).all(|p| p[0].scan < p[1].scan));
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
