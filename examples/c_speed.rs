//! Generated C against the sequential interpreter, as a user runs both: for each program shape
//! and size, `plc-deps gen`, `plc-deps c`, one `make -j2` of the C (`cc -std=c11 -Wall -Wextra
//! -Werror -O2`, wall time, CPU time and peak memory from `/usr/bin/time -v`), then `runs`
//! interleaved runs each of the compiled program (`./plc_program SCANS --time`) and of the
//! interpreter (`plc-deps run FILE --mode seq --inputs CSV --format json`: `modes.seq
//! .ns_per_scan`) on one inputs CSV whose inputs change every scan (a fixed xorshift stream of
//! 0/1), and a check that both end in the same state. Prints one markdown row per program: the
//! medians with the spread (min–max) in ns per rung per scan.
//!
//! ```text
//! cargo build --release
//! cargo run --release --example c_speed -- [--sizes 1000,20000,100000] [--runs 3]
//!     [--shapes wide,levels20,levels20-random] [--dir /tmp/c_speed]
//! ```
//!
//! Shapes (docs/gen.md): `wide` is `gen --rungs N` (100 rungs per stage, local reads),
//! `levels20` is `gen --rungs N --levels 20` (local reads), `levels20-random` adds
//! `--reads random`; a shape with `+statements` (`wide+statements`) is the same program (the
//! same JSON and inputs) generated with `plc-deps c --statements` (every rung as C statements,
//! not the default rows). It uses the `plc-deps` binary beside this example's folder
//! (`target/release/plc-deps`; `PLC_DEPS=path` to choose another) and `make`, `cc` and
//! `/usr/bin/time` from the PATH. It times things: run it on a quiet machine.

use serde_json::Value;
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};

fn main() {
    let opts = Options::parse();
    let bin = plc_deps_binary();
    std::fs::create_dir_all(&opts.dir).expect("create the work folder");
    println!(
        "| rungs | shape | cc wall (make -j2) | cc CPU | cc peak RSS | C ns/rung | interpreter ns/rung | interp / C |"
    );
    println!("|---|---|---|---|---|---|---|---|");
    for &rungs in &opts.sizes {
        for shape in &opts.shapes {
            let row = measure(&bin, &opts, rungs, shape);
            println!("{row}");
        }
    }
}

struct Options {
    sizes: Vec<usize>,
    shapes: Vec<String>,
    runs: usize,
    dir: PathBuf,
}

impl Options {
    fn parse() -> Options {
        let mut o = Options {
            sizes: vec![1_000, 20_000, 100_000],
            shapes: vec!["wide".into(), "levels20".into(), "levels20-random".into()],
            runs: 3,
            dir: std::env::temp_dir().join("c_speed"),
        };
        let mut args = std::env::args().skip(1);
        while let Some(a) = args.next() {
            let mut value = || {
                args.next()
                    .unwrap_or_else(|| usage(&format!("{a} needs a value")))
            };
            match a.as_str() {
                "--sizes" => {
                    o.sizes = value()
                        .split(',')
                        .map(|s| s.parse().unwrap_or_else(|_| usage("--sizes: numbers")))
                        .collect()
                }
                "--shapes" => o.shapes = value().split(',').map(str::to_string).collect(),
                "--runs" => {
                    o.runs = value()
                        .parse()
                        .unwrap_or_else(|_| usage("--runs: a number"))
                }
                "--dir" => o.dir = PathBuf::from(value()),
                _ => usage(&format!("unknown argument {a}")),
            }
        }
        for s in &o.shapes {
            if shape_args(s).is_none() {
                usage(&format!("unknown shape {s}"));
            }
        }
        o
    }
}

fn usage(why: &str) -> ! {
    eprintln!("c_speed: {why}\nusage: c_speed [--sizes N,N] [--shapes wide,levels20,levels20-random,wide+statements,…] [--runs R] [--dir DIR]");
    std::process::exit(2);
}

/// The `gen` arguments of a shape.
fn shape_args(shape: &str) -> Option<&'static [&'static str]> {
    match shape.strip_suffix("+statements").unwrap_or(shape) {
        "wide" => Some(&[]),
        "levels20" => Some(&["--levels", "20"]),
        "levels20-random" => Some(&["--levels", "20", "--reads", "random"]),
        _ => None,
    }
}

fn plc_deps_binary() -> PathBuf {
    if let Some(p) = std::env::var_os("PLC_DEPS") {
        return PathBuf::from(p);
    }
    let exe = std::env::current_exe().expect("this example's path");
    let bin = exe
        .parent()
        .and_then(Path::parent)
        .map(|d| d.join("plc-deps"))
        .expect("the target folder");
    if !bin.exists() {
        usage(&format!(
            "{} is missing: run `cargo build --release` first",
            bin.display()
        ));
    }
    bin
}

/// Scans per timed run: about 20 M rung evaluations, at least 200 scans.
fn scans_for(rungs: usize) -> usize {
    (20_000_000 / rungs).clamp(200, 20_000)
}

fn run(cmd: &mut Command) -> std::process::Output {
    let out = cmd.output().unwrap_or_else(|e| panic!("{cmd:?}: {e}"));
    if !out.status.success() {
        panic!(
            "{cmd:?} failed: {}\n{}",
            out.status,
            String::from_utf8_lossy(&out.stderr)
        );
    }
    out
}

fn measure(bin: &Path, o: &Options, rungs: usize, shape: &str) -> String {
    let stem = o.dir.join(format!("{shape}-{rungs}"));
    let csv = stem.with_extension("csv");
    let cdir = o.dir.join(format!("{shape}-{rungs}-c"));
    let rungs_s = rungs.to_string();
    let json = o.dir.join(format!(
        "{}-{rungs}.json",
        shape.strip_suffix("+statements").unwrap_or(shape)
    ));
    let mut gen = Command::new(bin);
    gen.args(["gen", "--rungs", &rungs_s])
        .args(shape_args(shape).expect("checked"))
        .arg("-o")
        .arg(&json);
    run(&mut gen);
    run(Command::new(bin)
        .arg("c")
        .arg(&json)
        .arg("-o")
        .arg(&cdir)
        .arg("--force")
        .args(shape.ends_with("+statements").then_some("--statements")));
    let scans = scans_for(rungs);
    write_inputs(&json, &csv, scans);
    eprintln!("{shape} {rungs}: building");
    let build = run(Command::new("/usr/bin/time")
        .args(["-v", "make", "-s", "-j2", "-C"])
        .arg(&cdir)
        .stdout(Stdio::null()));
    let b = BuildCost::parse(&String::from_utf8_lossy(&build.stderr));
    let (mut c_ns, mut i_ns) = (Vec::new(), Vec::new());
    let (mut c_state, mut i_state) = (Value::Null, Value::Null);
    for k in 0..o.runs {
        eprintln!("{shape} {rungs}: run {}/{}", k + 1, o.runs);
        let input = std::fs::File::open(&csv).expect("the inputs CSV");
        let out = run(Command::new(cdir.join("plc_program"))
            .args([&scans.to_string(), "--time"])
            .stdin(input));
        let err = String::from_utf8_lossy(&out.stderr);
        let line = err.lines().last().expect("the --time line");
        let t: Value = serde_json::from_str(line).expect("{\"ns_per_scan\": T}");
        c_ns.push(t["ns_per_scan"].as_f64().expect("ns_per_scan") / rungs as f64);
        c_state = serde_json::from_slice(&out.stdout).expect("the last state line");
        let out = run(Command::new(bin)
            .arg("run")
            .arg(&json)
            .args(["--mode", "seq", "--format", "json", "--inputs"])
            .arg(&csv));
        let r: Value = serde_json::from_slice(&out.stdout).expect("run's JSON");
        i_ns.push(r["modes"]["seq"]["ns_per_scan"].as_f64().expect("seq time") / rungs as f64);
        i_state = r["state"].clone();
    }
    assert_eq!(
        c_state, i_state,
        "{shape} {rungs}: the C and the interpreter end in different states"
    );
    let (c, i) = (Spread::of(&mut c_ns), Spread::of(&mut i_ns));
    format!(
        "| {rungs} | {shape} | {:.1} s | {:.1} s | {:.0} MB | {c} | {i} | {:.1}× |",
        b.wall_s,
        b.cpu_s,
        b.peak_kb as f64 / 1024.0,
        i.median / c.median
    )
}

/// The inputs CSV: every input of the program, a fresh random 0/1 in every scan.
fn write_inputs(json: &Path, csv: &Path, scans: usize) {
    let text = std::fs::read_to_string(json).expect("the program");
    let doc: Value = serde_json::from_str(&text).expect("the program's JSON");
    let names: Vec<&str> = doc["vars"]
        .as_array()
        .expect("vars")
        .iter()
        .filter(|v| v["class"] == "input" && v["type"] == "BOOL")
        .map(|v| v["name"].as_str().expect("a name"))
        .collect();
    let mut x = 0x9E37_79B9_7F4A_7C15u64;
    let mut s = names.join(",");
    s.push('\n');
    for _ in 0..scans {
        for k in 0..names.len() {
            x ^= x << 13;
            x ^= x >> 7;
            x ^= x << 17;
            if k > 0 {
                s.push(',');
            }
            s.push(if x >> 63 == 1 { '1' } else { '0' });
        }
        s.push('\n');
    }
    std::fs::write(csv, s).expect("write the inputs CSV");
}

/// What `/usr/bin/time -v` says of the build.
struct BuildCost {
    wall_s: f64,
    cpu_s: f64,
    peak_kb: u64,
}

impl BuildCost {
    fn parse(text: &str) -> BuildCost {
        let field = |key: &str| {
            text.lines()
                .find_map(|l| l.trim().strip_prefix(key))
                .map(|v| v.trim().to_string())
                .unwrap_or_else(|| panic!("/usr/bin/time -v printed no `{key}`"))
        };
        let secs = |k: &str| field(k).parse::<f64>().expect("seconds");
        let wall = field("Elapsed (wall clock) time (h:mm:ss or m:ss):");
        let wall_s = wall.split(':').fold(0.0, |acc, part| {
            acc * 60.0 + part.parse::<f64>().expect("h:mm:ss")
        });
        BuildCost {
            wall_s,
            cpu_s: secs("User time (seconds):") + secs("System time (seconds):"),
            peak_kb: field("Maximum resident set size (kbytes):")
                .parse()
                .expect("kbytes"),
        }
    }
}

/// A median with its range.
struct Spread {
    median: f64,
    min: f64,
    max: f64,
}

impl Spread {
    fn of(v: &mut [f64]) -> Spread {
        v.sort_by(f64::total_cmp);
        Spread {
            median: v[v.len() / 2],
            min: v[0],
            max: v[v.len() - 1],
        }
    }
}

impl std::fmt::Display for Spread {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{:.2} ({:.2}–{:.2})", self.median, self.min, self.max)
    }
}
