//! The progress bar of `plc-deps run` on standard error.

use std::io::Write;
use std::time::{Duration, Instant};

/// A progress bar on standard error, drawn once a run has taken more than a second.
pub struct Progress {
    enabled: bool,
    start: Instant,
    last_draw: Option<Instant>,
    done: u64,
    total: u64,
    pub(super) label: &'static str,
    checks: u32,
}

impl Progress {
    pub(super) fn new(enabled: bool, total: u64) -> Progress {
        Progress {
            enabled,
            start: Instant::now(),
            last_draw: None,
            done: 0,
            total,
            label: "",
            checks: 0,
        }
    }

    pub(super) fn tick(&mut self) {
        self.done += 1;
        if !self.enabled {
            return;
        }
        self.checks += 1;
        if self.checks < 64 && self.done < self.total {
            return; // look at the clock every 64 scans
        }
        self.checks = 0;
        let now = Instant::now();
        if now.duration_since(self.start) < Duration::from_secs(1)
            || self
                .last_draw
                .is_some_and(|t| now.duration_since(t) < Duration::from_millis(100))
        {
            return;
        }
        self.last_draw = Some(now);
        let width = 30;
        let filled = (self.done * width / self.total.max(1)) as usize;
        let mut err = std::io::stderr().lock();
        let _ = write!(
            err,
            "\r[{}{}] {:>3}% {} scans {}/{}",
            "#".repeat(filled),
            " ".repeat(width as usize - filled.min(width as usize)),
            self.done * 100 / self.total.max(1),
            self.label,
            self.done,
            self.total
        );
        let _ = err.flush();
    }

    pub(super) fn finish(&mut self) {
        if self.last_draw.is_some() {
            let mut err = std::io::stderr().lock();
            let _ = write!(err, "\r{}\r", " ".repeat(72));
            let _ = err.flush();
        }
    }
}
