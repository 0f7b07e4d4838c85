//! Progress on standard error for the commands (`run` uses it; `report` can too), on top of
//! `indicatif`.
//!
//! A [`Progress`] is either shown (standard error is a terminal) or hidden (piped, or asked to
//! be quiet), decided once. Every phase of a command is one of two guards:
//!
//! - [`Progress::phase`]`(name)`: work of unknown length (reading a file, analysing). A spinner
//!   `⠋ name… 1.2s` appears once the phase has taken half a second and disappears when the guard
//!   is dropped, so fast phases show nothing.
//! - [`Progress::bar`]`(name, len, unit)`: `len` steps (scans). A bar with the count, the rate
//!   (`scans/s`) and the time left, also after half a second; call [`Bar::inc`] once per step
//!   (cheap: it looks at the clock once per batch of steps, the batch sized to about 50 ms, and
//!   only then updates the shared bar) and drop or [`Bar::finish`] it at the end.
//!
//! ```no_run
//! use plc_deps::cmd::progress::Progress;
//! let progress = Progress::stderr(); // hidden unless standard error is a terminal
//! let text = {
//!     let _phase = progress.phase("reading prog.json");
//!     std::fs::read_to_string("prog.json")
//! }; // the spinner (if it appeared) is gone here
//! let mut bar = progress.bar("analysing", 1000, "rungs");
//! for _ in 0..1000 {
//!     bar.inc();
//! }
//! bar.finish();
//! ```
//!
//! Invariants: nothing is ever drawn when hidden (no thread is started either); a shown phase is
//! cleared from the screen when its guard drops, so output printed afterwards (warnings, the
//! report on a terminal) starts on a clean line; print on standard error only between guards.
//! It does not decide what a phase is, nor time anything for reports.

use indicatif::{ProgressBar, ProgressDrawTarget, ProgressState, ProgressStyle};
use std::io::IsTerminal;
use std::sync::mpsc;
use std::time::Duration;

/// How long a phase runs before it is shown.
const SHOW_AFTER: Duration = Duration::from_millis(500);
/// How often a shown phase is redrawn (spinner, elapsed time, rate) even without progress.
const REDRAW: Duration = Duration::from_millis(100);
/// Steps of a [`Bar`] between updates of the shared bar: at most this many, fewer when steps
/// are slow, so that the shared bar moves about every [`FLUSH_EVERY`].
const MAX_BATCH: u64 = 1024;
const FLUSH_EVERY: Duration = Duration::from_millis(50);

/// Progress on standard error, shown or hidden for the whole command.
#[derive(Copy, Clone, Debug)]
pub struct Progress {
    shown: bool,
}

impl Progress {
    /// Shown when standard error is a terminal, hidden otherwise.
    pub fn stderr() -> Progress {
        Progress::new(std::io::stderr().is_terminal())
    }

    /// Shown (on standard error) or hidden.
    pub fn new(shown: bool) -> Progress {
        Progress { shown }
    }

    /// Whether anything may be drawn.
    pub fn is_shown(&self) -> bool {
        self.shown
    }

    /// A phase of unknown length: a spinner with `name` and the elapsed time, from half a
    /// second on, until the guard is dropped.
    pub fn phase(&self, name: &str) -> Phase {
        let style = ProgressStyle::with_template("{spinner} {msg}… {elapsed}")
            .expect("template")
            .tick_chars("⠋⠙⠹⠸⠼⠴⠦⠧⠇⠏ ");
        Phase(Delayed::start(self.shown, None, style, name))
    }

    /// A phase of `len` steps of `unit` (plural, e.g. `scans`): a bar with the count, the rate
    /// and the time left, from half a second on, until finished or dropped.
    pub fn bar(&self, name: &str, len: u64, unit: &'static str) -> Bar {
        let style = ProgressStyle::with_template(
            "{msg} [{bar:30}] {pos}/{len} {unit} ({rate}, {eta} left)",
        )
        .expect("template")
        .progress_chars("#>-")
        .with_key(
            "unit",
            move |_: &ProgressState, w: &mut dyn std::fmt::Write| {
                let _ = w.write_str(unit);
            },
        )
        .with_key(
            "rate",
            move |s: &ProgressState, w: &mut dyn std::fmt::Write| {
                let _ = write!(w, "{:.0} {unit}/s", s.per_sec());
            },
        );
        Bar {
            shared: Delayed::start(self.shown, Some(len), style, name),
            done: 0,
            flushed: 0,
            batch: 1,
            last_flush: std::time::Instant::now(),
            len,
            shown: self.shown,
        }
    }
}

/// A progress bar that is drawn only after [`SHOW_AFTER`]: a helper thread waits that long
/// (or until the guard drops), then points the bar at standard error and redraws it steadily.
struct Delayed {
    bar: ProgressBar,
    stop: Option<mpsc::Sender<()>>,
    helper: Option<std::thread::JoinHandle<()>>,
}

impl Delayed {
    fn start(shown: bool, len: Option<u64>, style: ProgressStyle, name: &str) -> Delayed {
        let bar = ProgressBar::with_draw_target(len, ProgressDrawTarget::hidden())
            .with_style(style)
            .with_message(name.to_string());
        if !shown {
            return Delayed {
                bar,
                stop: None,
                helper: None,
            };
        }
        let (stop, stopped) = mpsc::channel::<()>();
        let shared = bar.clone();
        let helper = std::thread::spawn(move || {
            if stopped.recv_timeout(SHOW_AFTER) == Err(mpsc::RecvTimeoutError::Timeout) {
                shared.set_draw_target(ProgressDrawTarget::stderr());
                shared.enable_steady_tick(REDRAW);
            }
        });
        Delayed {
            bar,
            stop: Some(stop),
            helper: Some(helper),
        }
    }
}

impl Drop for Delayed {
    fn drop(&mut self) {
        drop(self.stop.take()); // wakes the helper if it still waits
        if let Some(h) = self.helper.take() {
            let _ = h.join();
        }
        self.bar.finish_and_clear();
    }
}

/// The guard of a [`Progress::phase`]: the spinner disappears when it is dropped.
pub struct Phase(#[allow(dead_code)] Delayed);

/// The guard of a [`Progress::bar`]: count steps with [`Bar::inc`]; the bar disappears when it
/// is finished or dropped.
pub struct Bar {
    shared: Delayed,
    done: u64,
    flushed: u64,
    /// Steps between looks at the clock (1 ..= MAX_BATCH).
    batch: u64,
    last_flush: std::time::Instant,
    len: u64,
    shown: bool,
}

impl Bar {
    /// One more step done.
    #[inline]
    pub fn inc(&mut self) {
        self.done += 1;
        if self.shown && (self.done - self.flushed >= self.batch || self.done == self.len) {
            self.flush();
        }
    }

    #[cold]
    fn flush(&mut self) {
        let now = std::time::Instant::now();
        let took = now.duration_since(self.last_flush);
        if took < FLUSH_EVERY / 2 {
            self.batch = (self.batch * 2).min(MAX_BATCH);
        } else if took > FLUSH_EVERY * 2 {
            self.batch = (self.batch / 2).max(1);
        }
        self.last_flush = now;
        self.flushed = self.done;
        self.shared.bar.set_position(self.done);
    }

    /// Steps done so far.
    pub fn done(&self) -> u64 {
        self.done
    }

    /// Ends the phase (the same as dropping the guard).
    pub fn finish(self) {}
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn hidden_progress_starts_no_thread_and_still_counts() {
        let p = Progress::new(false);
        assert!(!p.is_shown());
        let phase = p.phase("reading");
        assert!(phase.0.helper.is_none());
        drop(phase);
        let mut bar = p.bar("seq", 10, "scans");
        assert!(bar.shared.helper.is_none());
        for _ in 0..10 {
            bar.inc();
        }
        assert_eq!(bar.done(), 10);
        bar.finish();
    }

    #[test]
    fn a_short_phase_is_never_drawn() {
        // Shown, but over before SHOW_AFTER: the helper thread ends without drawing.
        let p = Progress::new(true);
        let phase = p.phase("quick");
        assert!(phase.0.bar.is_hidden());
        drop(phase);
        let mut bar = p.bar("seq", 3, "scans");
        bar.inc();
        assert!(bar.shared.bar.is_hidden());
        bar.inc();
        bar.inc();
        assert_eq!(
            bar.shared.bar.position(),
            3,
            "the last step is always flushed"
        );
    }
}
