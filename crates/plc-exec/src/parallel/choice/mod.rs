//! The measured choice among candidate plans, in the manner of FFTW's planner in "measure"
//! mode (Frigo & Johnson): the first scans of a run time the candidates — real scans of the
//! run, their results kept — and the fastest runs; cheap re-measurements every N scans (N
//! doubling while the choice holds, quadrupling when every other candidate took twice its time
//! or more, up to a cap, and never so small that the next re-measurement's visits of slower
//! candidates would cost more than a budget, 1.5 % by default, of the scans between) or as soon
//! as the scan time jumps keep the choice right when the machine gets busy or calms down. A
//! routine re-measurement visits the default (the sequential walk) only while it is within
//! reach: while the running plan takes more than 2/3 of the walk's last time.
//!
//! A measurement is made of *rounds*; a round *visits* each measured candidate once (the order
//! rotating from round to round), and a visit runs a few untimed-for-the-choice warm-up scans
//! (the first scans after a switch pay for moving the state and code between the cores) and then
//! a few timed ones, whose median is the visit's time. Interleaving the candidates in rounds
//! makes a change of the machine's load hit them alike, and the choice compares each candidate
//! with the current one *round by round* ([`choose`]): it replaces the current one only if it
//! was faster in more than half the rounds, by at least 3 % at the median of the per-round
//! ratios. A candidate other than the current one that took more than 1.5× the best time of a
//! round sits out the later rounds (4× the best after one scan: the rest of its visit too);
//! one the machine skips (its workers are away from their cores) misses that round only, and a
//! candidate without a time yet is visited again at the next routine re-measurement.
//! The measurement stops once it has its minimum of rounds and the choice after the last round
//! is the choice after the round before (successive choices agree), or when a candidate is at
//! least twice as fast in every round, or when every other candidate sits out, or at its
//! maximum of rounds.
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
pub(super) struct Verdict {
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
pub(super) fn choose(table: &[Vec<Option<u64>>]) -> Verdict {
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

/// Whether a candidate that took `ns` per scan is hopeless against one that took `best`: more
/// than 4× its time (a visit of it ends after one scan).
fn hopeless(ns: u64, best: u64) -> bool {
    ns > best.saturating_mul(4)
}

/// Whether a candidate that took `ns` per scan in a round is out of the race against the
/// round's best, `best`: more than 1.5× its time. Noise between rounds is a few per cent; a
/// candidate this far behind would need to gain a third to be picked, so it is left out of the
/// measurement's later rounds (each visit of it costs half a scan or more per scan).
fn outpaced(ns: u64, best: u64) -> bool {
    ns.saturating_mul(2) > best.saturating_mul(3)
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
        best.is_some_and(|b| hopeless(last, b))
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
        if !complete && m.visit_scans > 0 && i != 0 {
            // Hopeless after a scan: out of the measurement, and so out of the order (`at`
            // already points at the next visit). A skipped visit (no scan) is not.
            m.dropped[i] = true;
        } else {
            m.at += 1;
        }
        m.visit.clear();
        m.visit_scans = 0;
        if m.at < m.order().len() {
            return;
        }
        m.round += 1;
        m.at = 0;
        for row in m.table.iter_mut() {
            row.resize(m.round, None);
        }
        // Candidates other than the current one that were outpaced in this round sit out the
        // later ones (the current one is what the others are compared with).
        let r = m.round - 1;
        if let Some(best) = m.table.iter().filter_map(|row| row[r]).min() {
            for i in 1..m.who.len() {
                if m.table[i][r].is_some_and(|t| outpaced(t, best)) {
                    m.dropped[i] = true;
                }
            }
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
        let mut who = vec![self.current];
        match (&jump, self.runner_up()) {
            (None, Some(_)) => who.extend(self.routine_visits()),
            _ => who.extend((0..self.n).filter(|&c| c != self.current)),
        }
        if jump.is_some() {
            self.interval = self.measure.min_interval.max(1);
        }
        if who.len() == 1 {
            // Nothing worth a visit: look again after twice as long.
            self.interval = (self.interval * 2).min(self.measure.max_interval.max(1));
            self.stage = Stage::Exploit {
                left: self.interval,
            };
            return;
        }
        self.stage = Stage::Measure(Box::new(Measurement::new(who, jump)));
    }

    /// Whether a routine re-measurement leaves the default (candidate 0, the sequential walk)
    /// out: the current candidate is another and takes at most 2/3 of the default's last time
    /// (its own time just refreshed from its recent scans). The walk would have to have become
    /// 1.5× faster against it, which a change of the machine's load does not do: a busier
    /// machine slows the parallel plan, and a rise of its time by half re-measures every
    /// candidate at once; a smaller rise brings the walk back into reach at the next routine
    /// look. Visiting the walk costs a run most (on gen 20k, about 2 % of 1,000 scans).
    fn default_out_of_reach(&self) -> bool {
        self.current != 0
            && matches!(
                (self.estimate[self.current], self.estimate[0]),
                (Some(c), Some(d)) if c.saturating_mul(3) <= d.saturating_mul(2)
            )
    }

    /// The fastest candidate other than the current one at their last measurements.
    fn runner_up(&self) -> Option<usize> {
        (0..self.n)
            .filter(|&c| c != self.current && self.estimate[c].is_some())
            .min_by_key(|&c| self.estimate[c])
    }

    /// The candidates besides the current one that a routine re-measurement visits: the
    /// default (candidate 0) unless it is out of reach, the runner-up (unless it is the default
    /// out of reach), and any not measured yet (skipped in every round so far while the other
    /// workers were away).
    fn routine_visits(&self) -> Vec<usize> {
        let mut who = Vec::new();
        let far = self.default_out_of_reach();
        if let Some(r) = self.runner_up() {
            if self.current != 0 && r != 0 && !far {
                who.push(0);
            }
            if r != 0 || !far {
                who.push(r);
            }
        }
        let unmeasured = (0..self.n).filter(|&c| c != self.current && self.estimate[c].is_none());
        for c in unmeasured {
            if !who.contains(&c) {
                who.push(c);
            }
        }
        who
    }

    /// The fewest scans between re-measurements that keeps the next routine one within the
    /// budget: its expected extra time (each visited candidate's last time per scan above the
    /// current one's, times its scans: all rounds' visits, or one scan when it will be found
    /// hopeless) over `budget_permille` of the current candidate's time per scan. 0 when
    /// nothing is known or there is no budget.
    fn budget_interval(&self) -> u64 {
        let m = self.measure;
        let Some(cur) = self.estimate[self.current].filter(|&c| c > 0) else {
            return 0;
        };
        if m.budget_permille == 0 {
            return 0;
        }
        let visit = m.warm_scans + m.probe_scans.max(1);
        let extra: u64 = self
            .routine_visits()
            .into_iter()
            .filter_map(|c| self.estimate[c])
            .map(|e| {
                let scans = if hopeless(e, cur) {
                    1
                } else if outpaced(e, cur) {
                    visit
                } else {
                    visit * m.min_rounds.max(1)
                };
                e.saturating_sub(cur).saturating_mul(scans)
            })
            .sum();
        extra.saturating_mul(1000) / m.budget_permille.saturating_mul(cur)
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
        let floor = self.budget_interval();
        self.interval = self
            .interval
            .max(floor)
            .min(self.measure.max_interval.max(1));
        self.stage = Stage::Exploit {
            left: self.interval,
        };
    }

    /// Whether the next window is a measurement's visit of a candidate other than the current
    /// one (one [`skip`](Self::skip) may leave out).
    pub fn measuring_other(&self) -> bool {
        matches!(&self.stage, Stage::Measure(m) if m.order()[m.at] != 0)
    }

    /// Leaves the next visit's candidate out of this round of the measurement without running it
    /// (the machine knows it cannot gain now: its workers are not on a core); the measurement's
    /// later rounds visit it again. Nothing when [`measuring_other`](Self::measuring_other) is
    /// false.
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
mod tests;
