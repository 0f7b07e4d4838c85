//! The generated C in tests: writing and compiling it with the exact flags (`cc -std=c11 -Wall
//! -Wextra -Werror -O2`), running its harness, running the sequential interpreter on the same
//! inputs, and comparing the two after every scan (state lines and faults).
//!
//! [`Batch`] compiles many programs into one binary: each program's files are included into
//! one translation unit with every symbol it defines renamed by a prefix (`#define _plc_scan
//! _p7_plc_scan`, the same for its POU and function block functions and its descriptor), the
//! harness's driver (`plc_main.h`) once, and one `main` runs every program through the driver
//! in turn, its inputs CSV on standard input, a marker line before each program's output. So
//! thousands of programs need a few `cc` runs, and each runs through the harness `plc-deps c`
//! writes.

use super::Rng;
use plc_deps::codegen::c::{generate, CConfig};
use plc_deps::exec::{ExecConfig, Layout, Machine};
use plc_deps::model::{Program, Type, VarClass};
use serde_json::{json, Map};
use std::path::{Path, PathBuf};
use std::process::{Command, Output, Stdio};
use std::sync::atomic::{AtomicU32, Ordering};

/// The flags every test compiles the generated C with.
pub(crate) const CFLAGS: &[&str] = &["-std=c11", "-Wall", "-Wextra", "-Werror", "-O2"];

/// A fresh empty folder under the temporary directory.
pub(crate) fn fresh_dir(tag: &str) -> PathBuf {
    static N: AtomicU32 = AtomicU32::new(0);
    let d = std::env::temp_dir().join(format!(
        "plc-c-{}-{tag}-{}",
        std::process::id(),
        N.fetch_add(1, Ordering::Relaxed)
    ));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// Asserts that a child process succeeded, showing its standard error if not.
pub(crate) fn assert_ok(out: &Output, what: &str) {
    assert!(
        out.status.success(),
        "{what}:\n{}",
        String::from_utf8_lossy(&out.stderr)
    );
}

/// `cc CFLAGS -o exe sources… -lm` in `dir`.
pub(crate) fn compile(dir: &Path, exe: &str, sources: &[String]) {
    let out = Command::new("cc")
        .args(CFLAGS)
        .args(["-I.", "-o", exe])
        .args(sources)
        .arg("-lm")
        .current_dir(dir)
        .output()
        .expect("cc runs");
    assert_ok(&out, &format!("cc failed in {}", dir.display()));
}

/// Writes the C of `text` into `dir` (without the runtime header when `runtime` is false); the
/// names of its C sources.
fn write(text: &str, cfg: &CConfig, dir: &Path, runtime: bool) -> Vec<String> {
    let (p, fbd) = plc_deps::load::program_and_fbd_from_json(text).expect("program loads");
    let mut sources = Vec::new();
    for f in generate(&p, &fbd, cfg) {
        if (f.name == "plc_runtime.h" || f.name == "plc_main.h") && !runtime {
            continue;
        }
        if f.name.ends_with(".c") {
            sources.push(f.name.clone());
        }
        std::fs::write(dir.join(&f.name), f.text).unwrap();
    }
    sources
}

/// Writes the C of `text` into a fresh folder and compiles it into `prog` there.
pub(crate) fn build(text: &str, cfg: &CConfig, tag: &str) -> PathBuf {
    let dir = fresh_dir(tag);
    let sources = write(text, cfg, &dir, true);
    compile(&dir, "prog", &sources);
    dir
}

fn lines(b: &[u8]) -> Vec<String> {
    String::from_utf8_lossy(b)
        .lines()
        .map(String::from)
        .collect()
}

/// Runs `exe` with `args`, `input` on standard input: its output, asserted successful.
pub(crate) fn run_with_input(exe: &Path, args: &[String], input: &[u8]) -> Output {
    use std::io::Write;
    let mut child = Command::new(exe)
        .args(args)
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    // Written from a thread: the program may answer before it has read everything.
    let mut stdin = child.stdin.take().unwrap();
    let input = input.to_vec();
    let writer = std::thread::spawn(move || stdin.write_all(&input).unwrap());
    let out = child.wait_with_output().unwrap();
    writer.join().unwrap();
    assert_ok(&out, &exe.display().to_string());
    out
}

/// Runs the built program: its state lines and fault lines.
pub(crate) fn run_c(dir: &Path, csv: &str, scans: u64) -> (Vec<String>, Vec<String>) {
    let out = run_with_input(&dir.join("prog"), &[scans.to_string()], csv.as_bytes());
    (lines(&out.stdout), lines(&out.stderr))
}

/// What the interpreter gives for the same inputs: the state line after every scan, the faults.
pub(crate) fn run_interpreter(
    text: &str,
    csv: &str,
    scans: u64,
    cfg: &CConfig,
) -> (Vec<String>, Vec<String>) {
    let p = plc_deps::load::program_from_json(text).unwrap();
    let exec = ExecConfig {
        cycle_ms: cfg.cycle_ms,
        loop_cap: cfg.loop_cap,
        scan_budget: cfg.scan_budget,
    };
    let m = Machine::new(&p, Layout::dense(&p), &exec).unwrap();
    let table = plc_deps::cmd::run::parse_inputs_csv(&p, csv, "inputs.csv").unwrap();
    let mut st = m.initial_state();
    let (mut lines, mut faults) = (Vec::new(), Vec::new());
    for k in 0..scans {
        let mut f = Vec::new();
        m.set_inputs(&mut st, table.at(k));
        m.run_scan(&mut st, k, &mut f);
        lines.push(state_line(&p, &m, &st));
        for x in f {
            let rung = &p.rung(x.rung).id;
            faults.push(json!({"scan": x.scan, "rung": rung, "kind": x.kind.name()}).to_string());
        }
    }
    (lines, faults)
}

/// The `state` object of `plc-deps run --format json`, as one line.
pub(crate) fn state_line(p: &Program, m: &Machine, st: &plc_deps::exec::State) -> String {
    let mut map = Map::new();
    for (i, v) in p.vars().iter().enumerate() {
        if !v.hidden {
            let value = m.value(st, plc_deps::model::VarId::from_raw(i as u32));
            map.insert(v.name.clone(), value.to_json());
        }
    }
    serde_json::Value::Object(map).to_string()
}

/// Compares the C's state lines and faults with the interpreter's.
fn compare(c: (Vec<String>, Vec<String>), i: (Vec<String>, Vec<String>), tag: &str, at: &Path) {
    assert_eq!(c.0.len(), i.0.len(), "{tag}: scans ({})", at.display());
    for (k, (c, i)) in c.0.iter().zip(&i.0).enumerate() {
        assert_eq!(c, i, "{tag}: state after scan {k} ({})", at.display());
    }
    assert_eq!(c.1, i.1, "{tag}: faults ({})", at.display());
}

/// A CSV of random values for the program's inputs, `rows` rows (some cells empty).
pub(crate) fn random_csv(p: &Program, rng: &mut Rng, rows: usize) -> String {
    let ins: Vec<_> = p
        .vars()
        .iter()
        // A STRING input is not set from an inputs file (neither `run` nor the harness reads
        // one): it keeps its initial value.
        .filter(|v| v.class == VarClass::Input && !v.hidden && v.ty != Type::String)
        .collect();
    if ins.is_empty() {
        return String::new();
    }
    let names: Vec<&str> = ins.iter().map(|v| v.name.as_str()).collect();
    let mut s = names.join(",");
    s.push('\n');
    for _ in 0..rows {
        let cells: Vec<String> = ins
            .iter()
            .map(|v| {
                if rng.chance(20) {
                    return String::new();
                }
                match v.ty {
                    Type::Bool => (if rng.chance(50) { "true" } else { "0" }).to_string(),
                    Type::Int => (rng.below(200) as i64 - 100).to_string(),
                    Type::Dint => (rng.below(2_000_000) as i64 - 1_000_000).to_string(),
                    Type::Real => format!("{}", (rng.below(4000) as f64 - 2000.0) / 8.0),
                    Type::Time => (rng.below(5000)).to_string(),
                    // The other integers: small values, extremes, and now and then the
                    // based form (`16#…`) the harness and `run` both read.
                    ty => {
                        let v = super::random_input(ty, rng);
                        let i = v.as_i128().expect("an integer input");
                        match i {
                            0..=255 if rng.chance(20) => format!("16#{i:X}"),
                            i => i.to_string(),
                        }
                    }
                }
            })
            .collect();
        s.push_str(&cells.join(","));
        s.push('\n');
    }
    s
}

/// One program of a batch.
struct Job {
    text: String,
    csv: String,
    scans: u64,
    cfg: CConfig,
    tag: String,
}

/// Programs compiled together into one binary per part and compared with the interpreter.
#[derive(Default)]
pub(crate) struct Batch {
    jobs: Vec<Job>,
}

/// Symbols of the harness that every program defines (its POU and function block functions
/// are found in its text: `_pou_…`, `_fb_…`).
const HARNESS_SYMBOLS: &[&str] = &[
    "_plc_state",
    "_plc_initial",
    "_plc_scan",
    "_plc_input_names",
    "_plc_input_slots",
    "_plc_input_types",
    "_plc_output_names",
    "_plc_memory_names",
    "_plc_set_input",
    "_plc_state_slots",
    "_plc_print_state",
    "_plc_rung_ids",
    "_plc_program_desc",
    "_plc_desc_scan",
    "_plc_desc_set_input",
    "_plc_desc_print",
    "_plc_restore_inputs",
    "_plc_desc_restore",
];

/// Macros a program's files define (undefined before the next program's).
const HARNESS_MACROS: &[&str] = &["PLC_PROGRAM_H", "PLC_SCAN_BUDGET"];

/// Every identifier in `text` that a program defines and others would too.
fn program_symbols(text: &str, out: &mut std::collections::BTreeSet<String>) {
    for id in text.split(|c: char| !(c.is_ascii_alphanumeric() || c == '_')) {
        if id.starts_with("_pou_") || id.starts_with("_fb_") {
            out.insert(id.to_string());
        }
    }
}

impl Batch {
    /// Adds a program to compare after every one of `scans` scans of `csv`.
    pub(crate) fn add(&mut self, text: String, csv: String, scans: u64, cfg: CConfig, tag: String) {
        self.jobs.push(Job {
            text,
            csv,
            scans,
            cfg,
            tag,
        });
    }

    pub(crate) fn len(&self) -> usize {
        self.jobs.len()
    }

    /// Compiles the programs into `parts` binaries (compiled in parallel), runs them and
    /// compares every program with the interpreter.
    pub(crate) fn check(self, parts: usize, tag: &str) {
        let per = self.jobs.len().div_ceil(parts.max(1)).max(1);
        std::thread::scope(|s| {
            let handles: Vec<_> = self
                .jobs
                .chunks(per)
                .enumerate()
                .map(|(k, jobs)| s.spawn(move || check_part(jobs, &format!("{tag}-{k}"))))
                .collect();
            for h in handles {
                if let Err(e) = h.join() {
                    std::panic::resume_unwind(e);
                }
            }
        });
    }
}

/// One binary of a batch: writes, compiles, runs, compares (the folder is kept on failure).
fn check_part(jobs: &[Job], tag: &str) {
    let dir = fresh_dir(tag);
    let mut unit = String::from("#include \"plc_main.h\"\n");
    let mut calls = String::new();
    for (j, job) in jobs.iter().enumerate() {
        let sub = format!("p{j}");
        std::fs::create_dir_all(dir.join(&sub)).unwrap();
        std::fs::write(dir.join(&sub).join("in.csv"), &job.csv).unwrap();
        let sources = write(&job.text, &job.cfg, &dir.join(&sub), j == 0);
        if j == 0 {
            // The runtime and the driver, once, beside the programs' folders.
            for h in ["plc_runtime.h", "plc_main.h"] {
                std::fs::rename(dir.join(&sub).join(h), dir.join(h)).unwrap();
            }
        }
        let mut symbols: std::collections::BTreeSet<String> =
            HARNESS_SYMBOLS.iter().map(|s| s.to_string()).collect();
        for f in std::fs::read_dir(dir.join(&sub)).unwrap() {
            program_symbols(
                &std::fs::read_to_string(f.unwrap().path()).unwrap(),
                &mut symbols,
            );
        }
        for s in symbols
            .iter()
            .map(String::as_str)
            .chain(HARNESS_MACROS.iter().copied())
        {
            unit.push_str(&format!("#undef {s}\n"));
        }
        for s in &symbols {
            unit.push_str(&format!("#define {s} _{sub}{s}\n"));
        }
        for src in sources.iter().filter(|s| *s != "main.c") {
            unit.push_str(&format!("#include \"{sub}/{src}\"\n"));
        }
        calls.push_str(&format!(
            "    if (!rc) rc = run(&_{sub}_plc_program_desc, {:?}, \"{}\", {j});\n",
            dir.join(&sub).join("in.csv").to_str().unwrap(),
            job.scans
        ));
    }
    unit.push_str(BATCH_MAIN_HEAD);
    unit.push_str(&calls);
    unit.push_str("    return rc;\n}\n");
    std::fs::write(dir.join("batch.c"), unit).unwrap();
    let t0 = std::time::Instant::now();
    compile(&dir, "batch", &["batch.c".to_string()]);
    let t1 = std::time::Instant::now();
    let out = run_with_input(&dir.join("batch"), &[], b"");
    let cc = t1 - t0;
    eprintln!(
        "{tag}: {} programs, cc {cc:.1?}, run {:.1?}",
        jobs.len(),
        t1.elapsed()
    );
    let (stdout, stderr) = (split_marked(&out.stdout), split_marked(&out.stderr));
    assert_eq!(stdout.len(), jobs.len(), "{tag}: programs run");
    for (j, job) in jobs.iter().enumerate() {
        let c = (
            stdout[j].clone(),
            stderr.get(j).cloned().unwrap_or_default(),
        );
        let i = run_interpreter(&job.text, &job.csv, job.scans, &job.cfg);
        compare(c, i, &job.tag, &dir.join(format!("p{j}")));
    }
    if std::env::var_os("PLC_C_KEEP").is_none() {
        let _ = std::fs::remove_dir_all(dir);
    }
}

/// Lines per program: each program's output follows a line `\x1e<index>`.
fn split_marked(b: &[u8]) -> Vec<Vec<String>> {
    let mut out: Vec<Vec<String>> = Vec::new();
    for l in lines(b) {
        match l.strip_prefix('\u{1e}') {
            Some(_) => out.push(Vec::new()),
            None => out.last_mut().expect("a marker first").push(l),
        }
    }
    out
}

const BATCH_MAIN_HEAD: &str = r#"
static int run(const _plc_program *prog, const char *csv, const char *scans, int j) {
    printf("\036%d\n", j);
    fflush(stdout);
    fprintf(stderr, "\036%d\n", j);
    if (!freopen(csv, "r", stdin)) return 3;
    char a0[] = "prog", a1[32];
    snprintf(a1, sizeof a1, "%s", scans);
    char *av[] = {a0, a1, NULL};
    int rc = _plc_main(prog, 2, av);
    fflush(stdout);
    fflush(stderr);
    return rc;
}

int main(void) {
    int rc = 0;
"#;

/// Builds, runs and compares one program scan by scan (through a batch of one).
pub(crate) fn check(text: &str, csv: &str, scans: u64, cfg: &CConfig, tag: &str) {
    let mut b = Batch::default();
    b.add(text.into(), csv.into(), scans, cfg.clone(), tag.into());
    b.check(1, tag);
}
