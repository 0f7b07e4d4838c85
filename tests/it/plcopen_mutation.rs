//! Mutated PLCopen files: whatever an editor, a transfer or a person does to a file, reading it
//! never panics or hangs. Every committed PLCopen file (the real exports and the hand-written
//! cases) is cut, spliced, truncated and given stray markup at random; each mutant either
//! loads (and then is analysed and scanned without a panic) or fails with one error that has a
//! line and a column inside the file. A few mutants also go through `plc-deps report`: exit 0
//! with an output file, or exit 2 with located error lines and no output file.

use crate::common;

use proptest::prelude::*;
use std::path::PathBuf;

/// Every XML file under `tests/plcopen/`, with its text.
fn fixtures() -> Vec<(String, String)> {
    let dir = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("tests/plcopen");
    let mut out: Vec<(String, String)> = std::fs::read_dir(&dir)
        .expect("tests/plcopen exists")
        .filter_map(|e| {
            let path = e.ok()?.path();
            (path.extension()? == "xml").then_some(path)
        })
        .map(|path| {
            let text = std::fs::read_to_string(&path).expect("fixtures are UTF-8");
            (
                path.file_name().unwrap().to_string_lossy().into_owned(),
                text,
            )
        })
        .collect();
    out.sort();
    assert!(out.len() >= 12, "the real exports are all there");
    out
}

/// Stray markup a mutant may gain: structure, references, entities, numbers.
pub(crate) const SNIPPETS: &[&str] = &[
    "<",
    ">",
    "\"",
    "/>",
    "</block>",
    "<block localId=\"1\" typeName=\"TON\">",
    "<connection refLocalId=\"99999\"/>",
    "refLocalId=\"1\"",
    "localId=\"1\"",
    "&amp;",
    "&bogus;",
    "<!DOCTYPE x [<!ENTITY a \"aaaaaaaaaa\">]>",
    "<![CDATA[",
    "]]>",
    "<?xml version=\"1.0\"?>",
    "formalParameter=\"IN\"",
    "negated=\"true\"",
    "<variable formalParameter=\"Q\">",
    "typeName=\"\"",
    "name=\"../x\"",
    "<pou name=\"P\" pouType=\"program\">",
    "0",
    "-1",
    "4294967296",
    "\u{0}",
    "é",
];

/// One edit of a text.
#[derive(Clone, Debug)]
enum Edit {
    /// Removes `len` bytes at `at` (both as fractions of the text, in thousandths).
    Delete { at: u32, len: u32 },
    /// Inserts a snippet at `at`.
    Insert { at: u32, snippet: usize },
    /// Copies `len` bytes from `from` to `at`.
    Duplicate { from: u32, len: u32, at: u32 },
    /// Cuts the text at `at`.
    Truncate { at: u32 },
    /// Swaps the digits of the number that starts at or after `at` for `with`.
    Number { at: u32, with: u32 },
}

fn edit() -> impl Strategy<Value = Edit> {
    let at = 0u32..1000;
    prop_oneof![
        (at.clone(), 1u32..40).prop_map(|(at, len)| Edit::Delete { at, len }),
        (at.clone(), 0..SNIPPETS.len()).prop_map(|(at, snippet)| Edit::Insert { at, snippet }),
        (at.clone(), 1u32..60, at.clone()).prop_map(|(from, len, at)| Edit::Duplicate {
            from,
            len,
            at
        }),
        at.clone().prop_map(|at| Edit::Truncate { at }),
        (at, 0u32..200).prop_map(|(at, with)| Edit::Number { at, with }),
    ]
}

/// The byte `at` thousandths into `text`, moved back to a character boundary.
fn place(text: &str, at: u32) -> usize {
    let mut i = (text.len() as u64 * at as u64 / 1000) as usize;
    while !text.is_char_boundary(i) {
        i -= 1;
    }
    i
}

fn apply(text: &mut String, e: &Edit) {
    match *e {
        Edit::Delete { at, len } => {
            let a = place(text, at);
            let mut b = (a + len as usize).min(text.len());
            while !text.is_char_boundary(b) {
                b += 1;
            }
            text.replace_range(a..b, "");
        }
        Edit::Insert { at, snippet } => {
            let a = place(text, at);
            text.insert_str(a, SNIPPETS[snippet]);
        }
        Edit::Duplicate { from, len, at } => {
            let a = place(text, from);
            let mut b = (a + len as usize).min(text.len());
            while !text.is_char_boundary(b) {
                b += 1;
            }
            let piece = text[a..b].to_owned();
            let to = place(text, at);
            text.insert_str(to, &piece);
        }
        Edit::Truncate { at } => {
            let a = place(text, at);
            text.truncate(a);
        }
        Edit::Number { at, with } => {
            let a = place(text, at);
            if let Some(start) = text[a..].find(|c: char| c.is_ascii_digit()).map(|i| a + i) {
                let end = text[start..]
                    .find(|c: char| !c.is_ascii_digit())
                    .map_or(text.len(), |i| start + i);
                text.replace_range(start..end, &with.to_string());
            }
        }
    }
}

/// Loads a mutant: a loaded one is analysed and scanned; a refused one has a place in the text.
fn check(name: &str, text: &str) -> Result<(), TestCaseError> {
    match plc_deps::load::plcopen(text) {
        Ok((program, _fbd, _notes)) => {
            let _ = plc_deps::analysis::analyse(&program);
            use plc_deps::exec::{ExecConfig, Layout, Machine};
            if let Ok(m) = Machine::new(&program, Layout::dense(&program), &ExecConfig::default()) {
                let mut state = m.initial_state();
                let mut faults = Vec::new();
                for scan in 0..3 {
                    m.run_scan(&mut state, scan, &mut faults);
                }
            }
        }
        // Located as every reader's errors are (the fuzz harness's check).
        Err(e) => {
            let located = crate::fuzz_readers::check_load_error(name, text, &e);
            prop_assert!(located.is_ok(), "{name}: {}", located.unwrap_err());
        }
    }
    Ok(())
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 768, ..ProptestConfig::default() })]

    #[test]
    fn a_mutated_file_loads_or_fails_with_one_located_error(
        file in any::<prop::sample::Index>(),
        edits in prop::collection::vec(edit(), 1..4),
    ) {
        let fixtures = fixtures_once();
        let (name, text) = &fixtures[file.index(fixtures.len())];
        let mut text = text.clone();
        for e in &edits {
            apply(&mut text, e);
        }
        check(name, &text)?;
    }
}

fn fixtures_once() -> &'static [(String, String)] {
    static FIXTURES: std::sync::OnceLock<Vec<(String, String)>> = std::sync::OnceLock::new();
    FIXTURES.get_or_init(fixtures)
}

/// Mutants found by the random test that crashed the process: an LD wire renumbered so that the
/// power into a contact comes from its own output through contacts and coils only (an endless
/// recursion), and an extensible block's pin renumbered past 4 billion (an allocation of that
/// many pins). Each is now one located error.
#[test]
fn mutants_that_crashed_the_reader_are_located_errors() {
    let fixtures = fixtures_once();
    let cases: [(&str, &[Edit]); 3] = [
        (
            "assemblyarea__plc.xml",
            &[Edit::Number { at: 411, with: 39 }],
        ),
        // `IN1` of an XOR renumbered `IN42949672961`: a gap in its inputs, not 43 billion pins.
        (
            "sail-plant-automation__plc.xml",
            &[
                Edit::Insert {
                    at: 593,
                    snippet: 23,
                },
                Edit::Number { at: 114, with: 92 },
            ],
        ),
        (
            "mixer-with-lld__plc.xml",
            &[
                Edit::Number { at: 381, with: 173 },
                Edit::Number { at: 919, with: 27 },
            ],
        ),
    ];
    for (file, edits) in cases {
        let (name, text) = fixtures
            .iter()
            .find(|(n, _)| n == file)
            .expect("the fixture is there");
        let mut text = text.clone();
        for e in edits {
            apply(&mut text, e);
        }
        assert!(
            plc_deps::load::plcopen(&text).is_err(),
            "{name}: the mutant loads"
        );
        check(name, &text).unwrap_or_else(|e| panic!("{name}: {e}"));
    }
}

/// Through the command line: exit 0 and an output file, or exit 2, errors with a line and a
/// column, and no output file.
#[test]
fn the_command_line_exits_cleanly_on_mutants() {
    let fixtures = fixtures_once();
    let edits = [
        Edit::Truncate { at: 500 },
        Edit::Delete { at: 300, len: 30 },
        Edit::Insert {
            at: 400,
            snippet: 11,
        },
        Edit::Insert {
            at: 600,
            snippet: 6,
        },
        Edit::Number { at: 700, with: 0 },
    ];
    for (i, e) in edits.iter().enumerate() {
        let (name, text) = &fixtures[(i * 5) % fixtures.len()];
        let mut text = text.clone();
        apply(&mut text, e);
        let input = common::cli::tmp(&format!("mutant{i}.xml"));
        std::fs::write(&input, &text).unwrap();
        let out = common::cli::tmp(&format!("mutant{i}.txt"));
        let _ = std::fs::remove_file(&out);
        let r = common::cli::run(&[
            "report",
            input.to_str().unwrap(),
            "-o",
            out.to_str().unwrap(),
        ]);
        let stderr = String::from_utf8_lossy(&r.stderr);
        match r.status.code() {
            Some(0) => assert!(out.exists(), "{name} {e:?}: exit 0 without the report"),
            Some(2) => {
                assert!(!out.exists(), "{name} {e:?}: a refused file left an output");
                assert!(!stderr.contains("panicked"), "{stderr}");
                for line in common::cli::one_line(&stderr)
                    .lines()
                    .filter(|l| l.starts_with("error"))
                {
                    let file = input.to_string_lossy();
                    let rest = line.split_once(&*file).map(|(_, r)| r).unwrap_or("");
                    let mut parts = rest.trim_start_matches(':').split(':');
                    let located = parts.next().is_some_and(|l| l.parse::<u32>().is_ok())
                        && parts.next().is_some_and(|c| c.parse::<u32>().is_ok());
                    assert!(located, "{name} {e:?}: no line:column in {line:?}");
                }
            }
            other => panic!("{name} {e:?}: exit {other:?}: {stderr}"),
        }
    }
}

/// The mutants above are not all refused at the first byte: small edits of real files give both
/// programs that still load and every kind of error.
#[test]
fn mutants_both_load_and_fail() {
    let (mut loaded, mut refused) = (0, 0);
    for (_, text) in fixtures_once() {
        for at in (0..1000).step_by(97) {
            for e in [
                Edit::Number { at, with: 7 },
                Edit::Delete { at, len: 3 },
                Edit::Insert { at, snippet: 21 },
            ] {
                let mut t = text.clone();
                apply(&mut t, &e);
                match plc_deps::load::plcopen(&t) {
                    Ok(_) => loaded += 1,
                    Err(_) => refused += 1,
                }
            }
        }
    }
    assert!(
        loaded > 10 && refused > 100,
        "{loaded} loaded, {refused} refused"
    );
}
