//! The pipeline every cargo-fuzz target drives (docs/fuzzing.md), in-process and quiet.
//!
//! A program text goes through its reader, then — when it loads — the analysis, the report in
//! every format, three sequential scans, C and IL generation and `convert` (whose output must load
//! again). An inputs text goes through the `run --inputs` reader for one of the shipped programs,
//! then, when it parses, through scans with those inputs. Anything wrong panics, which is what
//! libFuzzer reports: a panic anywhere, an error without a line and column inside the text, an
//! inputs error not starting `FILE:LINE:COLUMN: `, a convert output that does not load.
//!
//! It does not run the parallel executor (a thread pool per input is too slow to fuzz; the CI
//! harness tests/it/fuzz_readers.rs runs both modes), and it does not compile the C.

use plc_deps::cmd::report::{render_report, ReportFormat};
use plc_deps::cmd::run::{parse_inputs_csv, parse_inputs_json};
use plc_deps::cmd::CliError;
use plc_deps::diag::Shown;
use plc_deps::exec::{ExecConfig, Layout, Machine};
use plc_deps::fbd::Fbd;
use plc_deps::model::Program;
use plc_deps::read::LoadError;
use plc_deps::report::View;

/// The program readers.
#[derive(Copy, Clone, Debug)]
pub enum Format {
    Json,
    PlcOpen,
    Stl,
}

/// The `run --inputs` formats.
#[derive(Copy, Clone, Debug)]
pub enum Inputs {
    Csv,
    Json,
}

/// The programs an inputs file may be for (each with inputs of several types).
const PROGRAMS: &[&str] = &[
    include_str!("../../analyses/example-a/program.json"),
    include_str!("../../analyses/analog-scaling/program.json"),
    include_str!("../../analyses/mixing-station/program.json"),
    include_str!("../../analyses/packaging-line/program.json"),
    include_str!("../../analyses/conveyor/program.json"),
];

/// Panics unless every diagnostic of `e` has a line and column inside `text`, and renders them
/// as the command line does.
fn located(text: &str, e: &LoadError) {
    let shown = Shown::load_error("input", text, e);
    assert!(!shown.is_empty(), "an error without a diagnostic: {e}");
    let lines = text.split('\n').count() as u32;
    for s in shown {
        let rendered = s.text(false);
        let _ = s.json();
        let (line, column) = s
            .position
            .unwrap_or_else(|| panic!("an error without line and column: {rendered}"));
        assert!(
            (1..=lines).contains(&line) && column >= 1,
            "{line}:{column} outside the text ({lines} lines): {rendered}"
        );
    }
}

/// Three sequential scans of `p` with `inputs` written before each.
fn scans(p: &Program, inputs: &[Vec<(plc_deps::model::VarId, plc_deps::model::Value)>]) {
    let Ok(m) = Machine::new(p, Layout::dense(p), &ExecConfig::default()) else {
        return;
    };
    let mut state = m.initial_state();
    let mut faults = Vec::new();
    for scan in 0..3u64 {
        if let Some(row) = inputs.get(scan as usize) {
            m.set_inputs(&mut state, row);
        }
        m.run_scan(&mut state, scan, &mut faults);
    }
}

/// Everything after loading.
fn pipeline(p: &Program, fbd: &Fbd) {
    for format in [
        ReportFormat::Text,
        ReportFormat::Json,
        ReportFormat::Dot,
        ReportFormat::Html,
    ] {
        assert!(!render_report(p, fbd, format, View::All).is_empty());
    }
    scans(p, &[]);
    let _ = plc_deps::codegen::c::generate(p, fbd, &Default::default());
    let _ = plc_deps::codegen::il::generate(p, fbd);
}

/// A program text through its reader and, when it loads, the whole pipeline.
pub fn program(format: Format, text: &str) {
    let loaded = match format {
        Format::Json => plc_deps::load::program_and_fbd_from_json(text),
        Format::PlcOpen => plc_deps::load::plcopen(text).map(|(p, f, _)| (p, f)),
        Format::Stl => plc_deps::load::stl(text),
    };
    let (p, fbd) = match loaded {
        Ok(x) => x,
        Err(e) => return located(text, &e),
    };
    pipeline(&p, &fbd);
    // `convert`: the syntax written as JSON loads again.
    let mut out = Vec::new();
    let written =
        match format {
            Format::Json => plc_deps::read::json::parse(text)
                .map(|s| plc_deps::write::json::program(&s, &mut out)),
            Format::PlcOpen => plc_deps::read::plcopen::parse(text)
                .map(|(s, _)| plc_deps::write::json::program(&s, &mut out)),
            Format::Stl => plc_deps::read::stl::parse(text)
                .map(|s| plc_deps::write::json::program(&s, &mut out)),
        }
        .expect("a text that loads parses again");
    if written.is_ok() {
        let json = String::from_utf8(out).expect("convert writes UTF-8");
        if let Err(e) = plc_deps::load::program_and_fbd_from_json(&json) {
            panic!(
                "convert's output does not load: {}",
                e.locate(&json).in_file("converted")
            );
        }
    }
}

/// An inputs text for program `pick` (modulo the shipped ones) through its reader and, when it
/// parses, three scans with it.
pub fn inputs(format: Inputs, pick: u8, text: &str) {
    let program = PROGRAMS[pick as usize % PROGRAMS.len()];
    let p = plc_deps::load::program_from_json(program).expect("a shipped program loads");
    let file = "inputs";
    let parsed = match format {
        Inputs::Csv => parse_inputs_csv(&p, text, file),
        Inputs::Json => parse_inputs_json(&p, text, file),
    };
    match parsed {
        Ok(table) => scans(&p, &table.rows),
        Err(CliError::Usage(m)) => {
            let mut parts = m
                .strip_prefix("inputs:")
                .unwrap_or_else(|| panic!("does not name the file: {m}"))
                .splitn(3, ':');
            let line: u32 = parts.next().and_then(|l| l.parse().ok()).unwrap_or(0);
            let column: u32 = parts.next().and_then(|c| c.parse().ok()).unwrap_or(0);
            assert!(
                line >= 1 && line <= text.split('\n').count() as u32 && column >= 1,
                "not located inside the text: {m}"
            );
        }
        Err(e) => panic!("not an inputs error: {e}"),
    }
}
