//! Data-driven worked examples: every `analyses/*/program.json` has its committed reports
//! (`report.txt`, `report.json`) beside it. This test regenerates them all and fails on any
//! difference; `UPDATE_EXPECT=1 cargo test --release --test it analyses::` re-blesses them. Examples written in
//! FBD also have `order.txt` and `order.json` (`plc-deps order`).
//!
//! Every example also has its committed `run.json`: the JSON of `plc-deps run program.json
//! --inputs inputs.csv --cycle 1s --threads 2 --mode both --format json` (or, for a program
//! without `inputs.csv`, `--scans 450 --cycle 10ms`) with the timing fields zeroed
//! (`runcmd::run_json_deterministic`).

use plc_deps::cmd::report::{render_report, ReportFormat};
use plc_deps::report::View;
use std::path::{Path, PathBuf};

fn examples() -> Vec<PathBuf> {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("analyses");
    let mut dirs: Vec<PathBuf> = std::fs::read_dir(&root)
        .expect("analyses/ exists")
        .map(|e| e.expect("readable entry").path())
        .filter(|p| p.join("program.json").is_file())
        .collect();
    dirs.sort();
    dirs
}

/// Compares `actual` with the committed file, or writes it when re-blessing.
fn check(path: &Path, actual: &str, failures: &mut Vec<String>) {
    if std::env::var_os("UPDATE_EXPECT").is_some() {
        std::fs::write(path, actual).expect("write expectation");
        return;
    }
    let expected = std::fs::read_to_string(path).unwrap_or_default();
    if expected != actual {
        let line = expected
            .lines()
            .zip(actual.lines())
            .position(|(a, b)| a != b)
            .unwrap_or_else(|| expected.lines().count().min(actual.lines().count()));
        failures.push(format!(
            "{} differs at line {}:\n  committed: {:?}\n  now:       {:?}",
            path.display(),
            line + 1,
            expected.lines().nth(line).unwrap_or("<end>"),
            actual.lines().nth(line).unwrap_or("<end>")
        ));
    }
}

#[test]
fn every_worked_example_matches_its_committed_reports() {
    let dirs = examples();
    assert!(
        dirs.len() >= 5,
        "expected the worked examples in analyses/, found {}",
        dirs.len()
    );
    let mut failures = Vec::new();
    let mut runs = 0;
    for dir in dirs {
        let text = std::fs::read_to_string(dir.join("program.json")).expect("read program");
        let (program, fbd) = plc_deps::load::program_and_fbd_from_json(&text)
            .unwrap_or_else(|e| panic!("{}: {e}", dir.display()));
        check(
            &dir.join("report.txt"),
            &render_report(&program, &fbd, ReportFormat::Text, View::All),
            &mut failures,
        );
        check(
            &dir.join("report.json"),
            &render_report(&program, &fbd, ReportFormat::Json, View::All),
            &mut failures,
        );
        if !fbd.pous.is_empty() {
            // FBD examples also commit `plc-deps order` (text and JSON).
            check(
                &dir.join("order.txt"),
                &plc_deps::cmd::order::render_order(
                    &program,
                    &fbd,
                    plc_deps::cmd::order::OrderFormat::Text,
                ),
                &mut failures,
            );
            check(
                &dir.join("order.json"),
                &plc_deps::cmd::order::render_order(
                    &program,
                    &fbd,
                    plc_deps::cmd::order::OrderFormat::Json,
                ),
                &mut failures,
            );
        }
        {
            runs += 1;
            let mut c = plc_deps::cmd::run::RunConfig::new(dir.join("program.json"));
            if dir.join("inputs.csv").is_file() {
                c.inputs = Some(dir.join("inputs.csv"));
                c.cycle_ms = 1000;
            } else {
                // Programs without inputs (KASKAD 2-5) run 450 scans of 10 ms: long enough for
                // the 1 s and 2 s generators of KASKAD 4 and 5 to toggle.
                c.scans = Some(450);
                c.cycle_ms = 10;
            }
            c.threads = 2;
            c.mode = plc_deps::cmd::run::RunMode::Both;
            let run = plc_deps::cmd::run::run_json_deterministic(&c)
                .unwrap_or_else(|e| panic!("{}: {e}", dir.display()));
            let doc: serde_json::Value = serde_json::from_str(&run).expect("run JSON");
            assert_eq!(
                doc["identical"],
                true,
                "{}: {}",
                dir.display(),
                doc["first_difference"]
            );
            check(&dir.join("run.json"), &run, &mut failures);
        }
    }
    assert!(
        runs >= 11,
        "expected every worked example to run, found {runs}"
    );
    assert!(
        failures.is_empty(),
        "{}\n(re-bless with UPDATE_EXPECT=1 if the change is intended)",
        failures.join("\n")
    );
}

/// The real PLCopen exports of `analyses/plcopen/*/program.xml` (as editors wrote them; where
/// each came from is in `tests/plcopen/MANIFEST.md`): the reader's warnings (`notes.txt`: what
/// it read only through an interface, what it ignored), and the reports and a 100-scan run of
/// each file that loads, or the error of each file that does not (`error.txt`); for a file that
/// loads but that `run` refuses (a string in an LD or FBD body), `run-refused.txt` has the reason.
#[test]
fn every_plcopen_export_matches_its_committed_outputs() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("analyses/plcopen");
    let mut dirs: Vec<PathBuf> = std::fs::read_dir(&root)
        .expect("analyses/plcopen/ exists")
        .map(|e| e.expect("readable entry").path())
        .filter(|p| p.join("program.xml").is_file())
        .collect();
    dirs.sort();
    assert!(dirs.len() >= 12, "found {}", dirs.len());
    let mut failures = Vec::new();
    for dir in dirs {
        let text = std::fs::read_to_string(dir.join("program.xml")).expect("read program");
        let stale = |name: &str| {
            let p = dir.join(name);
            if std::env::var_os("UPDATE_EXPECT").is_some() && p.exists() {
                std::fs::remove_file(p).expect("remove a stale expectation");
            }
        };
        match plc_deps::load::plcopen(&text) {
            Err(e) => {
                let shown = format!("error: {}\n", e.locate(&text).in_file("program.xml"));
                check(&dir.join("error.txt"), &shown, &mut failures);
                for name in [
                    "notes.txt",
                    "report.txt",
                    "report.json",
                    "run.json",
                    "run-refused.txt",
                ] {
                    stale(name);
                }
            }
            Ok((program, fbd, notes)) => {
                stale("error.txt");
                let notes: String = notes
                    .iter()
                    .map(|n| {
                        let note = plc_deps::read::plcopen::note_text("program.xml", &text, n);
                        format!("warning: {note}\n")
                    })
                    .collect();
                check(&dir.join("notes.txt"), &notes, &mut failures);
                check(
                    &dir.join("report.txt"),
                    &render_report(&program, &fbd, ReportFormat::Text, View::All),
                    &mut failures,
                );
                check(
                    &dir.join("report.json"),
                    &render_report(&program, &fbd, ReportFormat::Json, View::All),
                    &mut failures,
                );
                // A project `run` cannot execute (a string in an LD or FBD body): its reason.
                if let Err(e) = plc_deps::load::plcopen_for_run(&text) {
                    stale("run.json");
                    let shown = format!("error: {}\n", e.in_file("program.xml"));
                    check(&dir.join("run-refused.txt"), &shown, &mut failures);
                    continue;
                }
                stale("run-refused.txt");
                let mut c = plc_deps::cmd::run::RunConfig::new(dir.join("program.xml"));
                c.scans = Some(100);
                c.cycle_ms = 10;
                c.threads = 2;
                c.mode = plc_deps::cmd::run::RunMode::Both;
                // ST, IL and SFC bodies run as their stand-in rungs (the JSON lists them).
                c.allow_skipped = true;
                let run = plc_deps::cmd::run::run_json_deterministic(&c)
                    .unwrap_or_else(|e| panic!("{}: {e}", dir.display()));
                let doc: serde_json::Value = serde_json::from_str(&run).expect("run JSON");
                assert_eq!(doc["identical"], true, "{}", dir.display());
                check(&dir.join("run.json"), &run, &mut failures);
            }
        }
    }
    assert!(
        failures.is_empty(),
        "{}\n(re-bless with UPDATE_EXPECT=1 if the change is intended)",
        failures.join("\n")
    );
}
