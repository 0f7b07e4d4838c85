//! The parallel scan in generated C against the sequential C and the interpreter (issue 41):
//! for each program, `plc-deps gen`, `plc-deps c --threads 2` and `make -j2` (both timed, wall
//! clock), then `runs` runs of `./plc_program SCANS --time` (the sequential, the parallel and the
//! adaptive scan of one binary, one after another: `sequential_ns_per_scan`,
//! `parallel_ns_per_scan`, `adaptive_choice`) taking turns with `plc-deps run FILE --threads 2
//! --mode both --format json --scans SCANS` (the interpreter's `seq` and `par`). Prints one
//! markdown row per program: medians in ns per rung per scan, and the ratios; the load average
//! before and after.
//!
//! ```text
//! cargo build --release
//! cargo run --release --example c_parallel_bench -- [--runs 3] [--scans 1000] [--dir /tmp/c_parallel_bench]
//! ```
//!
//! The programs: `gen --rungs 20000 --width 1000`, `gen --rungs 20000 --levels 20 --reads
//! random`, `gen --rungs 100000 --width 5000` (a third of the scans) and the 50-rung chain `gen
//! --rungs 50 --width 1` (a hundred times the scans). Every input keeps its initial value (no
//! inputs file), for the C and the interpreter alike. It uses the `plc-deps` binary beside this
//! example (`target/release/plc-deps`; `PLC_DEPS=path` for another), `make` and `cc`; it times
//! things: read the load average it prints. Nothing here is used by the tool.

use std::path::{Path, PathBuf};
use std::process::Command;
use std::time::Instant;

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
    if n == 0 {
        return 0.0;
    }
    if n % 2 == 1 {
        v[n / 2]
    } else {
        (v[n / 2 - 1] + v[n / 2]) / 2.0
    }
}

fn ok(out: &std::process::Output, what: &str) {
    assert!(
        out.status.success(),
        "{what}: {}",
        String::from_utf8_lossy(&out.stderr)
    );
}

fn main() {
    let mut runs = 3usize;
    let mut scans = 1000u64;
    let mut dir = std::env::temp_dir().join("c_parallel_bench");
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
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).expect("the scratch folder");
    let bin = binary();
    let rows: [(&str, &[&str], u64, u64); 4] = [
        (
            "gen 20k (`--width 1000`)",
            &["--rungs", "20000", "--width", "1000"],
            20_000,
            scans,
        ),
        (
            "random reads 20k (`--levels 20 --reads random`)",
            &["--rungs", "20000", "--levels", "20", "--reads", "random"],
            20_000,
            scans,
        ),
        (
            "gen 100k (`--width 5000`)",
            &["--rungs", "100000", "--width", "5000"],
            100_000,
            (scans / 3).max(1),
        ),
        (
            "50-rung chain (`--width 1`)",
            &["--rungs", "50", "--width", "1"],
            50,
            scans * 100,
        ),
    ];
    println!("load average before: {}", load_average());
    println!();
    println!(
        "| program | c --threads 2 + make -j2 | seq C | par C | interp seq | interp par | \
         par C / seq C | seq C / interp seq | par C / interp par | adaptive chose |"
    );
    println!("|---|---|---|---|---|---|---|---|---|---|");
    for (k, (name, gen, rungs, scans)) in rows.iter().enumerate() {
        let file = dir.join(format!("gen{k}.json"));
        let out = Command::new(&bin)
            .arg("gen")
            .args(*gen)
            .arg("-o")
            .arg(&file)
            .output()
            .expect("plc-deps gen runs");
        ok(&out, "gen");
        let cdir = dir.join(format!("c{k}"));
        let t0 = Instant::now();
        let out = Command::new(&bin)
            .arg("c")
            .arg(&file)
            .arg("-o")
            .arg(&cdir)
            .args(["--threads", "2"])
            .output()
            .expect("plc-deps c runs");
        ok(&out, "c");
        let out = Command::new("make")
            .args(["-s", "-j2"])
            .current_dir(&cdir)
            .output()
            .expect("make runs");
        ok(&out, "make");
        let build = t0.elapsed().as_secs_f64();
        let plan = std::fs::read_to_string(cdir.join("plc_parallel.c")).unwrap_or_default();
        let sequential_plan = plan.contains("Plan: sequential");
        let per = |ns: f64| ns / *rungs as f64;
        let (mut sc, mut pc, mut si, mut pi) = (Vec::new(), Vec::new(), Vec::new(), Vec::new());
        let mut choice = Vec::new();
        for _ in 0..runs {
            let out = Command::new(cdir.join("plc_program"))
                .args([scans.to_string(), "--time".into()])
                .stdin(std::process::Stdio::null())
                .output()
                .expect("the C runs");
            ok(&out, "plc_program");
            let j: serde_json::Value =
                serde_json::from_str(String::from_utf8_lossy(&out.stderr).trim())
                    .expect("the timing line");
            sc.push(per(j["sequential_ns_per_scan"].as_f64().unwrap()));
            pc.push(per(j["parallel_ns_per_scan"].as_f64().unwrap()));
            choice.push(j["adaptive_choice"].as_str().unwrap_or("?").to_string());
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
                .arg(scans.to_string())
                .output()
                .expect("plc-deps run runs");
            ok(&out, "run");
            let j: serde_json::Value = serde_json::from_slice(&out.stdout).expect("run's JSON");
            si.push(per(j["modes"]["seq"]["ns_per_scan"]
                .as_f64()
                .unwrap_or(0.0)));
            pi.push(per(j["modes"]["par"]["ns_per_scan"]
                .as_f64()
                .unwrap_or(0.0)));
        }
        let (sc, pc, si, pi) = (
            median(&mut sc),
            median(&mut pc),
            median(&mut si),
            median(&mut pi),
        );
        choice.sort();
        println!(
            "| {name}{} | {build:.1} s | {sc:.2} | {pc:.2} | {si:.2} | {pi:.2} | {:.2}× | {:.2}× | {:.2}× | {} |",
            if sequential_plan { " (plan: sequential)" } else { "" },
            sc / pc,
            si / sc,
            pi / pc,
            choice.join(", ")
        );
    }
    println!();
    println!("(ns per rung per scan, medians of {runs} runs)");
    println!("load average after: {}", load_average());
}
