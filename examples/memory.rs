//! Live and peak heap bytes after loading and after each analysis step, to see what a big
//! program's memory is made of: `cargo run --release --example memory FILE.json`.
//!
//! A counting wrapper around the allocator the binary uses (mimalloc); the mapped or read input
//! text is not counted (the binary maps files of 16 MiB and more).

use plc_deps::analysis::*;
use plc_deps::cmd::report::ReportFormat;
use std::alloc::{GlobalAlloc, Layout};
use std::sync::atomic::{AtomicUsize, Ordering::Relaxed};

struct Counting;
static LIVE: AtomicUsize = AtomicUsize::new(0);
static PEAK: AtomicUsize = AtomicUsize::new(0);
static INNER: mimalloc::MiMalloc = mimalloc::MiMalloc;

// SAFETY: every call is forwarded unchanged to mimalloc, which upholds `GlobalAlloc`'s
// contract; the counters only observe sizes.
unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, l: Layout) -> *mut u8 {
        let live = LIVE.fetch_add(l.size(), Relaxed) + l.size();
        PEAK.fetch_max(live, Relaxed);
        // SAFETY: forwarded with the caller's layout.
        unsafe { INNER.alloc(l) }
    }
    unsafe fn dealloc(&self, p: *mut u8, l: Layout) {
        LIVE.fetch_sub(l.size(), Relaxed);
        // SAFETY: `p` came from `INNER.alloc` with this layout.
        unsafe { INNER.dealloc(p, l) }
    }
    unsafe fn realloc(&self, p: *mut u8, l: Layout, new: usize) -> *mut u8 {
        if new >= l.size() {
            let live = LIVE.fetch_add(new - l.size(), Relaxed) + new - l.size();
            PEAK.fetch_max(live, Relaxed);
        } else {
            LIVE.fetch_sub(l.size() - new, Relaxed);
        }
        // SAFETY: forwarded with the caller's pointer, layout and size.
        unsafe { INNER.realloc(p, l, new) }
    }
}

#[global_allocator]
static GLOBAL: Counting = Counting;

fn mb(b: usize) -> f64 {
    b as f64 / 1e6
}

fn step<T>(name: &str, f: impl FnOnce() -> T) -> T {
    let before = LIVE.load(Relaxed);
    PEAK.store(before, Relaxed);
    let t = f();
    let after = LIVE.load(Relaxed);
    eprintln!(
        "{name:<24} kept {:>8.1} MB   transient peak {:>8.1} MB   live {:>8.1} MB",
        mb(after.saturating_sub(before)),
        mb(PEAK.load(Relaxed).saturating_sub(before)),
        mb(after)
    );
    t
}

fn main() {
    let path = std::env::args().nth(1).expect("usage: memory FILE.json");
    let text = std::fs::read_to_string(&path).expect("read");
    let base = LIVE.load(Relaxed);
    eprintln!("input text {:.1} MB (not counted below)", mb(base));
    let p = step("load", || {
        plc_deps::load::program_from_json(&text).expect("load")
    });
    let acc = step("accesses", || accesses(&p));
    let cfg = step("control flow graph", || control_flow_graph(&p));
    let counts = step("dependence counts", || {
        dependence_counts(&acc.reads, &acc.writes)
    });
    let _levels = step("data levels", || data_levels(&acc.reads, &acc.writes));
    let _sched = step("combined schedule", || combined_schedule(&p, &cfg, &acc));
    drop((acc, cfg, counts, _levels, _sched));
    let a = step("whole analysis", || analyse(&p));
    let mut out = std::io::sink();
    step("text report", || {
        let text = plc_deps::report::TextOptions::default();
        plc_deps::cmd::report::write_report(&p, &a, None, ReportFormat::Text, &text, None, &mut out)
    })
    .ok();
}
