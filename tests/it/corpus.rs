//! Real editor exports through the built binary, file by file. In CI these are the exports
//! that are in the repository, `tests/plcopen/` (the files its MANIFEST.md lists); the corpus
//! of 121 more (`corpus/MANIFEST.md`, docs/corpus.md) is not in the repository (not ours to
//! redistribute) and is checked the same way by `corpus/fetch-and-check`, outside CI, into
//! `corpus/outcomes.txt`. For each file here:
//!
//! - `report FILE` loads it (exit 0) or refuses it with exit 2 and a located error (a `-->`
//!   line or `FILE:LINE:COLUMN:`); any other exit (a panic's 101, a signal), or an error
//!   without a place, fails the test;
//! - a file that loads: `run FILE --mode both --scans 20` says `identical: yes`, or refuses;
//! - a file that runs: `c FILE -o DIR` writes C, and its program (converted to the JSON format
//!   by `convert`) is built with the tests' flags (`cc -std=c11 -Wall -Wextra -Werror -O2`,
//!   the [`common::c::Batch`] of c_build.rs) and run on 20 scans of random inputs, its state
//!   compared with the interpreter's after every scan. A program whose JSON is over
//!   [`C_SIZE_BOUND`] bytes is not built (`c=skipped(size)`), to keep the test within its time.
//!
//! The outcomes are `tests/corpus/outcomes.txt`, one line per file, compared exactly, so a file
//! that loaded and no longer does, or ran identical and no longer does, fails; an improvement
//! fails too until re-blessed with `UPDATE_EXPECT=1 cargo test --release --test it corpus::`,
//! which also rewrites the README's table (counted from this file's outcomes and, by editor,
//! from `corpus/outcomes.txt`, which the test checks has one line per manifest file). It does
//! not fetch the corpus, nor judge whether a refusal is right: docs/corpus.md lists every
//! refusal by reason, and the test checks each reason there is one of the outcomes' (of both
//! files) and each outcome's is there.

use crate::common;

use common::c::Batch;
use common::cli::{root, run, tmp};
use common::Rng;
use plc_deps::codegen::c::CConfig;
use std::collections::BTreeMap;
use std::path::Path;

/// Scans of `run` and of the C comparison.
const SCANS: u64 = 20;

/// A converted program (JSON) larger than this is not built as C (none is today: the largest
/// that runs is a few kB; the limit keeps a large future addition from costing minutes of cc).
const C_SIZE_BOUND: usize = 200_000;

/// Where the outcomes are kept.
const OUTCOMES: &str = "tests/corpus/outcomes.txt";

const HEADER: &str = "\
# Outcomes of the real exports in the repository (tests/plcopen/, its MANIFEST.md's files)
# through plc-deps: tests/it/corpus.rs. The corpus's are corpus/outcomes.txt (not in CI).
# file | load=ok or refused(CODE) | run=identical, differs or refused(CODE) | c=equal, differs (or does not build),
# refused(CODE) or skipped(size); `-` where the step before did not pass. CODE is the error's
# code, or a word for an error without one; `,unlocated` marks an error without a place.
# Re-bless with UPDATE_EXPECT=1 cargo test --release --test it corpus::
";

/// The corpus's outcomes, measured by corpus/fetch-and-check.
const CORPUS_OUTCOMES: &str = "corpus/outcomes.txt";

/// One corpus manifest line's fields that the test uses.
struct Entry {
    file: String,
    editor: String,
}

/// The corpus manifest's lines (file | repository | path | commit | editor | languages |
/// licence | sha256 | bytes).
fn manifest() -> Vec<Entry> {
    let text = std::fs::read_to_string(root().join("corpus/MANIFEST.md")).unwrap();
    text.lines()
        .filter_map(|l| l.strip_prefix("- "))
        .map(|l| {
            let f: Vec<&str> = l.split(" | ").collect();
            assert_eq!(f.len(), 9, "a manifest line has 9 fields: {l}");
            assert!(
                f[7].len() == 64 && f[7].bytes().all(|b| b.is_ascii_hexdigit()),
                "{}: a sha256",
                f[0]
            );
            Entry {
                file: f[0].to_string(),
                editor: f[4].to_string(),
            }
        })
        .collect()
}

/// The files tests/plcopen/MANIFEST.md lists (`- FILE | …`).
fn plcopen_exports() -> Vec<String> {
    let text = std::fs::read_to_string(root().join("tests/plcopen/MANIFEST.md")).unwrap();
    let mut files: Vec<String> = text
        .lines()
        .filter_map(|l| l.strip_prefix("- "))
        .map(|l| l.split(" | ").next().unwrap().to_string())
        .collect();
    files.sort();
    files
}

/// An outcomes file's lines (`FILE | load=… | run=… | c=…`), `#` lines skipped.
fn parse_outcomes(text: &str) -> BTreeMap<String, [String; 3]> {
    text.lines()
        .filter(|l| !l.starts_with('#') && !l.is_empty())
        .map(|l| {
            let f: Vec<&str> = l.split(" | ").collect();
            assert_eq!(f.len(), 4, "an outcome line has 4 fields: {l}");
            let field = |i: usize, key: &str| {
                f[i].strip_prefix(key)
                    .unwrap_or_else(|| panic!("{l}: field {i} starts with {key}"))
                    .to_string()
            };
            (
                f[0].to_string(),
                [field(1, "load="), field(2, "run="), field(3, "c=")],
            )
        })
        .collect()
}

/// The code of the first error on `stderr` (`error[E0501]: …`), or a word for an error without
/// one; `,unlocated` when the error names no place.
fn refusal(stderr: &str) -> String {
    let first = stderr
        .lines()
        .find(|l| l.starts_with("error"))
        .unwrap_or("error: (none)");
    let mut code = match first.strip_prefix("error[") {
        Some(rest) => rest.split(']').next().unwrap().to_string(),
        None if first.contains("body is not executed") => "body-not-executed".to_string(),
        None => "uncoded".to_string(),
    };
    // A located error: rustc style (`  --> FILE:LINE:COLUMN`) or the one-line form
    // (`error: FILE:LINE:COLUMN: …`).
    let one_line_place = first
        .strip_prefix("error: ")
        .and_then(|r| r.split(": ").next())
        .is_some_and(|p| {
            p.rsplitn(3, ':').count() == 3 && p.ends_with(|c: char| c.is_ascii_digit())
        });
    if !(stderr.contains("--> ") || one_line_place) {
        code.push_str(",unlocated");
    }
    code
}

/// What one file gave: the outcome line's three fields and, for a program to build as C, its
/// JSON.
struct Outcome {
    load: String,
    run: String,
    c: String,
    json: Option<String>,
}

/// Fails on an exit that is neither success nor a refusal (a panic, a signal).
fn exit_of(out: &std::process::Output, what: &str) -> i32 {
    match out.status.code() {
        Some(code @ (0 | 2)) => code,
        other => panic!(
            "{what}: exit {other:?} (a panic or a signal, never a refusal):\n{}",
            String::from_utf8_lossy(&out.stderr)
        ),
    }
}

fn check_file(path: &Path) -> Outcome {
    let p = path.to_str().unwrap();
    let name = path.file_name().unwrap().to_str().unwrap();
    let dash = || "-".to_string();
    let report = run(&["report", p]);
    if exit_of(&report, &format!("{name}: report")) == 2 {
        return Outcome {
            load: format!(
                "refused({})",
                refusal(&String::from_utf8_lossy(&report.stderr))
            ),
            run: dash(),
            c: dash(),
            json: None,
        };
    }
    let scans = SCANS.to_string();
    let ran = run(&["run", p, "--mode", "both", "--scans", &scans]);
    if exit_of(&ran, &format!("{name}: run")) == 2 {
        return Outcome {
            load: "ok".into(),
            run: format!(
                "refused({})",
                refusal(&String::from_utf8_lossy(&ran.stderr))
            ),
            c: dash(),
            json: None,
        };
    }
    let stdout = String::from_utf8_lossy(&ran.stdout);
    if !stdout
        .lines()
        .any(|l| l.trim_start().starts_with("identical: yes"))
    {
        return Outcome {
            load: "ok".into(),
            run: "differs".into(),
            c: dash(),
            json: None,
        };
    }
    let dir = tmp(&format!("corpus-c-{name}"));
    let _ = std::fs::remove_dir_all(&dir);
    let c = run(&["c", p, "-o", dir.to_str().unwrap()]);
    let _ = std::fs::remove_dir_all(&dir);
    if exit_of(&c, &format!("{name}: c")) == 2 {
        return Outcome {
            load: "ok".into(),
            run: "identical".into(),
            c: format!("refused({})", refusal(&String::from_utf8_lossy(&c.stderr))),
            json: None,
        };
    }
    let conv = run(&["convert", p]);
    assert_eq!(
        exit_of(&conv, &format!("{name}: convert")),
        0,
        "{name}: a program that runs converts: {}",
        String::from_utf8_lossy(&conv.stderr)
    );
    let json = String::from_utf8(conv.stdout).unwrap();
    if json.len() > C_SIZE_BOUND {
        return Outcome {
            load: "ok".into(),
            run: "identical".into(),
            c: "skipped(size)".into(),
            json: None,
        };
    }
    Outcome {
        load: "ok".into(),
        run: "identical".into(),
        c: String::new(),
        json: Some(json),
    }
}

/// A batch of the programs `jobs` (name, JSON), each on 20 rows of random inputs (seeded by its
/// index, so a failure repeats).
fn batch_of(jobs: &[(String, String)]) -> Batch {
    let mut b = Batch::default();
    for (k, (name, json)) in jobs.iter().enumerate() {
        let p = plc_deps::load::program_from_json(json).expect("a converted program loads");
        let csv = common::c::random_csv(&p, &mut Rng::new(0xC0_8905 + k as u64), SCANS as usize);
        b.add(json.clone(), csv, SCANS, CConfig::default(), name.clone());
    }
    b
}

/// Builds and compares the programs as C: all in one batch and, if that fails, each alone to
/// tell which differ (or do not build). Each name's `c=` field.
fn c_outcomes(jobs: &[(String, String)]) -> BTreeMap<String, String> {
    let quiet = |f: &dyn Fn()| std::panic::catch_unwind(std::panic::AssertUnwindSafe(f)).is_ok();
    if jobs.is_empty() {
        return BTreeMap::new();
    }
    if quiet(&|| batch_of(jobs).check(2, "corpus")) {
        return jobs
            .iter()
            .map(|(n, _)| (n.clone(), "equal".to_string()))
            .collect();
    }
    jobs.iter()
        .map(|job| {
            let ok = quiet(&|| batch_of(std::slice::from_ref(job)).check(1, "corpus-one"));
            (
                job.0.clone(),
                if ok { "equal" } else { "differs" }.to_string(),
            )
        })
        .collect()
}

/// The README's table: files, loads, runs identical and C equal, by editor for the corpus (from
/// `corpus`, measured on `date`), their total, then the in-repository exports' (`plcopen`).
fn readme_table(
    entries: &[Entry],
    corpus: &BTreeMap<String, [String; 3]>,
    date: &str,
    plcopen: &BTreeMap<String, [String; 3]>,
) -> String {
    let count = |row: &mut [usize; 4], o: &[String; 3]| {
        row[0] += 1;
        row[1] += usize::from(o[0] == "ok");
        row[2] += usize::from(o[1] == "identical");
        row[3] += usize::from(o[2] == "equal");
    };
    let mut by: BTreeMap<String, [usize; 4]> = BTreeMap::new();
    let (mut total, mut in_repo) = ([0; 4], [0; 4]);
    for e in entries {
        count(
            by.entry(format!("corpus: {}", e.editor)).or_default(),
            &corpus[&e.file],
        );
        count(&mut total, &corpus[&e.file]);
    }
    for o in plcopen.values() {
        count(&mut in_repo, o);
    }
    let measured = format!("measured by corpus/fetch-and-check on {date}, not in CI");
    let mut s = String::from(
        "| exports | how | files | load | run (seq = par) | C = interpreter |\n|---|---|---:|---:|---:|---:|\n",
    );
    let rows = by
        .iter()
        .map(|(e, r)| (e.as_str(), measured.as_str(), r))
        .chain([
            ("corpus: all", measured.as_str(), &total),
            (
                "tests/plcopen/ (in the repository)",
                "checked by `cargo test`",
                &in_repo,
            ),
        ]);
    for (what, how, r) in rows {
        s.push_str(&format!(
            "| {what} | {how} | {} | {} | {} | {} |\n",
            r[0], r[1], r[2], r[3]
        ));
    }
    s
}

const TABLE_BEGIN: &str = "<!-- corpus table: tests/it/corpus.rs -->\n";
const TABLE_END: &str = "<!-- end of corpus table -->";

#[test]
fn every_real_export_loads_runs_and_builds_as_recorded() {
    let t0 = std::time::Instant::now();
    let dir = root().join("tests/plcopen");
    let files = plcopen_exports();
    assert_eq!(
        files.len(),
        12,
        "tests/plcopen/MANIFEST.md lists 12 exports"
    );
    for f in &files {
        assert!(
            dir.join(f).is_file(),
            "tests/plcopen/{f} is in the repository"
        );
    }

    // Each file through the binary, three at a time (each step is a process).
    let next = std::sync::atomic::AtomicUsize::new(0);
    let results = std::sync::Mutex::new(BTreeMap::new());
    std::thread::scope(|s| {
        for _ in 0..3 {
            s.spawn(|| loop {
                let i = next.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
                let Some(f) = files.get(i) else { break };
                let o = check_file(&dir.join(f));
                results.lock().unwrap().insert(f.clone(), o);
            });
        }
    });
    let mut results = results.into_inner().unwrap();
    let jobs: Vec<(String, String)> = results
        .iter_mut()
        .filter_map(|(n, o)| o.json.take().map(|j| (n.clone(), j)))
        .collect();
    for (name, c) in c_outcomes(&jobs) {
        results.get_mut(&name).unwrap().c = c;
    }
    let outcomes: BTreeMap<String, [String; 3]> = results
        .into_iter()
        .map(|(n, o)| (n, [o.load, o.run, o.c]))
        .collect();
    let mut text = String::from(HEADER);
    for (n, [l, r, c]) in &outcomes {
        text.push_str(&format!("{n} | load={l} | run={r} | c={c}\n"));
    }

    // The corpus's outcomes are corpus/fetch-and-check's: one line for each manifest file, and
    // the date they were measured on.
    let entries = manifest();
    assert!(
        entries.len() >= 60,
        "at least 60 corpus files: {}",
        entries.len()
    );
    let corpus_text = std::fs::read_to_string(root().join(CORPUS_OUTCOMES)).unwrap();
    let corpus = parse_outcomes(&corpus_text);
    let date = corpus_text
        .lines()
        .find_map(|l| l.strip_prefix("# Measured on "))
        .and_then(|l| l.strip_suffix('.'))
        .expect("corpus/outcomes.txt says `# Measured on DATE.`");
    assert!(
        corpus.keys().eq({
            let mut m: Vec<&String> = entries.iter().map(|e| &e.file).collect();
            m.sort();
            m
        }),
        "{CORPUS_OUTCOMES} has one line for each file of corpus/MANIFEST.md"
    );
    // A refusal names its place (the project rule: one clear error naming the place, exit 2).
    let unlocated: Vec<&String> = outcomes
        .iter()
        .chain(&corpus)
        .filter(|(_, o)| o.iter().any(|f| f.contains("unlocated")))
        .map(|(n, _)| n)
        .collect();
    assert!(
        unlocated.is_empty(),
        "refused without a place: {unlocated:?}"
    );

    // The README's table, between its markers.
    let readme_path = root().join("README.md");
    let readme = std::fs::read_to_string(&readme_path).unwrap();
    let table = readme_table(&entries, &corpus, date, &outcomes);
    let (before, rest) = readme
        .split_once(TABLE_BEGIN)
        .expect("README.md has the corpus table's begin marker");
    let (old_table, after) = rest
        .split_once(TABLE_END)
        .expect("README.md has the corpus table's end marker");

    let path = root().join(OUTCOMES);
    if std::env::var_os("UPDATE_EXPECT").is_some() {
        std::fs::create_dir_all(path.parent().unwrap()).unwrap();
        std::fs::write(&path, &text).unwrap();
        std::fs::write(
            &readme_path,
            format!("{before}{TABLE_BEGIN}{table}{TABLE_END}{after}"),
        )
        .unwrap();
    } else {
        let expected = std::fs::read_to_string(&path).unwrap_or_default();
        assert!(
            expected == text,
            "the outcomes changed (re-bless with UPDATE_EXPECT=1 if it is intended):\n{}",
            diff(&expected, &text)
        );
        assert_eq!(
            old_table, table,
            "README.md's corpus table is not the outcomes' (UPDATE_EXPECT=1 rewrites it)"
        );
    }

    // Every refusal reason of the outcomes is in docs/corpus.md's table, and every reason there
    // is one of the outcomes'.
    let docs = std::fs::read_to_string(root().join("docs/corpus.md")).unwrap();
    let mut reasons: std::collections::BTreeSet<String> = Default::default();
    for [l, r, c] in outcomes.values().chain(corpus.values()) {
        for f in [l, r, c] {
            if let Some(code) = f.strip_prefix("refused(").and_then(|x| x.strip_suffix(')')) {
                reasons.insert(code.split(',').next().unwrap().to_string());
            }
        }
    }
    let documented: std::collections::BTreeSet<String> = docs
        .lines()
        .filter_map(|l| l.strip_prefix("| `"))
        .filter_map(|l| l.split('`').next())
        .map(str::to_string)
        .collect();
    assert_eq!(
        reasons, documented,
        "the refusals of the outcomes and docs/corpus.md's table (its rows start with | `CODE`)"
    );
    eprintln!("corpus: {} files in {:.1?}", files.len(), t0.elapsed());
}

/// The lines of `a` and `b` that differ, marked `-` and `+`.
fn diff(a: &str, b: &str) -> String {
    let (la, lb): (Vec<&str>, Vec<&str>) = (a.lines().collect(), b.lines().collect());
    let mut out = String::new();
    for l in &la {
        if !lb.contains(l) {
            out.push_str(&format!("- {l}\n"));
        }
    }
    for l in &lb {
        if !la.contains(l) {
            out.push_str(&format!("+ {l}\n"));
        }
    }
    out
}
