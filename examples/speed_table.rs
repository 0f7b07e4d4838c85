//! The README's speed table, as a user measures it: the parallel scan against the sequential
//! interpreter on the worked examples and on generated programs of every shape, each from one
//! `plc-deps run FILE --threads 2 --mode both --format json` (the two passes take turns, so a
//! change of the host's speed hits both alike), repeated, with the medians and the range of
//! the ratio. Prints one markdown table and the load average before and after.
//!
//! ```text
//! cargo build --release
//! cargo run --release --example speed_table -- [--runs 3] [--scans 1000] [--dir /tmp/speed_table]
//! ```
//!
//! The programs: `analyses/{example-a,conveyor,packaging-line}` (100,000 scans each: a pass of
//! 1,000 scans of them lasts about 100 µs, under the timer's resolution for a ratio), a 50-rung
//! chain (`gen --rungs 50 --width 1`), `gen --rungs 1000 --width 50`, `gen --rungs 20000
//! --width 1000`, `gen --rungs 20000 --levels 20 --reads random` and `gen --rungs 100000 --width
//! 5000` (300 scans). The plan column is what `--plan auto` ran last (`plan_run.last`), or
//! "fallback" when the model already called the program sequential. It uses the `plc-deps`
//! binary beside this example (`target/release/plc-deps`; `PLC_DEPS=path` for another) and
//! times things: run it on a quiet machine, and read the load average it prints.
//!
//! Nothing here is used by the tool.

use std::path::{Path, PathBuf};
use std::process::Command;

/// One program of the table: its row name, how to get its file, and the scans per run.
struct Row {
    name: &'static str,
    source: Source,
    scans: u64,
}

enum Source {
    /// A worked example's program under `analyses/`.
    Example(&'static str),
    /// `plc-deps gen` with these arguments.
    Gen(&'static [&'static str]),
}

fn binary() -> PathBuf {
    std::env::var_os("PLC_DEPS").map_or_else(
        || {
            let exe = std::env::current_exe().expect("the example's path");
            exe.parent()
                .and_then(Path::parent)
                .expect("target/release/examples")
                .join("plc-deps")
        },
        PathBuf::from,
    )
}

fn load_average() -> String {
    std::fs::read_to_string("/proc/loadavg")
        .map(|l| l.split_whitespace().take(3).collect::<Vec<_>>().join(" "))
        .unwrap_or_else(|_| "unknown".into())
}

fn median(v: &mut [f64]) -> f64 {
    v.sort_by(f64::total_cmp);
    let n = v.len();
    if n % 2 == 1 {
        v[n / 2]
    } else {
        (v[n / 2 - 1] + v[n / 2]) / 2.0
    }
}

fn main() {
    let mut runs = 3usize;
    let mut scans = 1000u64;
    let mut dir = std::env::temp_dir().join("speed_table");
    let mut args = std::env::args().skip(1);
    while let Some(a) = args.next() {
        let value = args.next().unwrap_or_else(|| panic!("{a} needs a value"));
        match a.as_str() {
            "--runs" => runs = value.parse().expect("--runs N"),
            "--scans" => scans = value.parse().expect("--scans N"),
            "--dir" => dir = PathBuf::from(value),
            _ => panic!("unknown argument {a}"),
        }
    }
    std::fs::create_dir_all(&dir).expect("the scratch folder");
    let bin = binary();
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let rows = [
        Row {
            name: "example-a",
            source: Source::Example("example-a"),
            scans: 100_000,
        },
        Row {
            name: "conveyor",
            source: Source::Example("conveyor"),
            scans: 100_000,
        },
        Row {
            name: "packaging-line",
            source: Source::Example("packaging-line"),
            scans: 100_000,
        },
        Row {
            name: "50-rung chain (`gen --rungs 50 --width 1`)",
            source: Source::Gen(&["--rungs", "50", "--width", "1"]),
            scans: 100_000,
        },
        Row {
            name: "gen 1k (`--width 50`)",
            source: Source::Gen(&["--rungs", "1000", "--width", "50"]),
            scans,
        },
        Row {
            name: "gen 20k (`--width 1000`, 20 levels)",
            source: Source::Gen(&["--rungs", "20000", "--width", "1000"]),
            scans,
        },
        Row {
            name: "random reads 20k (`--levels 20 --reads random`)",
            source: Source::Gen(&["--rungs", "20000", "--levels", "20", "--reads", "random"]),
            scans,
        },
        Row {
            name: "gen 100k (`--width 5000`)",
            source: Source::Gen(&["--rungs", "100000", "--width", "5000"]),
            scans: 300,
        },
    ];
    println!("load average before: {}", load_average());
    println!();
    println!("| program | rungs | seq µs/scan | par µs/scan | par / seq | plan |");
    println!("|---|---|---|---|---|---|");
    for (k, row) in rows.iter().enumerate() {
        let file = match &row.source {
            Source::Example(name) => root.join("analyses").join(name).join("program.json"),
            Source::Gen(gen) => {
                let file = dir.join(format!("gen{k}.json"));
                let out = Command::new(&bin)
                    .arg("gen")
                    .args(*gen)
                    .arg("-o")
                    .arg(&file)
                    .output()
                    .expect("plc-deps gen runs");
                assert!(
                    out.status.success(),
                    "gen: {}",
                    String::from_utf8_lossy(&out.stderr)
                );
                file
            }
        };
        let report = Command::new(&bin)
            .arg("report")
            .arg(&file)
            .args(["--format", "json"])
            .output()
            .expect("plc-deps report runs");
        let report: serde_json::Value =
            serde_json::from_slice(&report.stdout).expect("report's JSON");
        let rungs = report["rungs"].as_array().map_or(0, Vec::len);
        let (mut seq, mut par, mut ratio) = (Vec::new(), Vec::new(), Vec::new());
        let mut plan = String::new();
        for _ in 0..runs {
            let out = Command::new(&bin)
                .arg("run")
                .arg(&file)
                .args([
                    "--threads",
                    "2",
                    "--mode",
                    "both",
                    "--format",
                    "json",
                    "--scans",
                ])
                .arg(row.scans.to_string())
                .output()
                .expect("plc-deps run runs");
            assert!(
                out.status.success(),
                "run: {}",
                String::from_utf8_lossy(&out.stderr)
            );
            let j: serde_json::Value = serde_json::from_slice(&out.stdout).expect("run's JSON");
            assert_eq!(j["identical"], true, "{}: seq != par", row.name);
            let s = j["modes"]["seq"]["ns_per_scan"].as_f64().unwrap_or(0.0);
            let p = j["modes"]["par"]["ns_per_scan"].as_f64().unwrap_or(0.0);
            seq.push(s / 1000.0);
            par.push(p / 1000.0);
            ratio.push(if p > 0.0 { s / p } else { 0.0 });
            plan = if j["sequential_fallback"].is_string() {
                "fallback".into()
            } else {
                j["plan_run"]["last"].as_str().unwrap_or("?").to_string()
            };
        }
        let (lo, hi) = ratio
            .iter()
            .fold((f64::INFINITY, 0.0_f64), |(l, h), &r| (l.min(r), h.max(r)));
        println!(
            "| {} | {} | {:.3} | {:.3} | {:.2} ({:.2}–{:.2}) | {} |",
            row.name,
            rungs,
            median(&mut seq),
            median(&mut par),
            median(&mut ratio),
            lo,
            hi,
            plan
        );
    }
    println!();
    println!(
        "load average after: {} ({runs} runs each; medians, the ratio's range in brackets)",
        load_average()
    );
}
