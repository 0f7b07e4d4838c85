//! Bounded, deterministic fuzzing of every reader, run by the normal test command.
//!
//! Each case takes a committed seed file of one reader — the JSON program format
//! (`analyses/*/program.json`), PLCopen TC6 XML with its ST/LD/FBD bodies (`tests/plcopen/*.xml`,
//! `tests/plcopen_structs/*.xml`), S7-200 STL (`analyses/*/program.stl`, `tests/stl/*.stl`) and
//! the `run --inputs` CSV and JSON files (`analyses/*/inputs.csv`, and the same rows as JSON) —
//! applies one to four mutations chosen by a seeded PRNG (byte flips, inserts and deletes,
//! spliced and duplicated lines, XML elements and attributes duplicated or dropped, numbers
//! swapped for extremes, deep nesting, non-ASCII and control characters, CR-only line ends), and
//! drives the library in-process: load → analyse → the report in every format (text, JSON, DOT,
//! HTML) → three scans of `run`, both modes, compared → C and IL generation (not compiled) →
//! `convert` (whose output must load again). What a case must do: never panic, never hang, never
//! crash the process; any error is located (every diagnostic has a line and column inside the
//! file, an inputs error starts `FILE:LINE:COLUMN: `).
//!
//! Isolation: a stack overflow aborts a process and a hang cannot be stopped from inside one, so
//! the test re-runs its own binary as a worker (`PLC_DEPS_FUZZ_WORKER` names the worker's
//! folder). The worker runs the cases on a thread with the CLI's main-thread stack (8 MiB), each
//! under `catch_unwind`, and writes one line per case; a watchdog ends the worker when a case
//! outlives [`HANG_SECONDS`]. The parent restarts a worker that died after the case it died in,
//! so one crash never hides the cases after it.
//!
//! Budget: [`CASES`] cases (counted, not timed; `PLC_DEPS_FUZZ_CASES=N` for a longer campaign,
//! `PLC_DEPS_FUZZ_SEED=S` for other cases; docs/fuzzing.md). The counts per reader and outcome are
//! printed. Any failure fails the test with the case's number, seed, mutations and the saved
//! input (an input worth keeping goes to `tests/fuzz-regressions/`, run by `fuzz_regressions`).
//!
//! It does not compile the generated C, and does not judge whether a loaded mutant means what
//! its author wanted: only that the tool stays well behaved.

use crate::common::Rng;
use plc_deps::cmd::report::{render_report, ReportFormat};
use plc_deps::cmd::run::{parse_inputs_csv, parse_inputs_json, run_report, RunConfig, RunMode};
use plc_deps::cmd::CliError;
use plc_deps::diag::Shown;
use plc_deps::exec::parallel::PlanKind;
use plc_deps::read::LoadError;
use plc_deps::report::View;
use std::collections::BTreeMap;
use std::io::Write;
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::sync::atomic::{AtomicU64, AtomicU8, Ordering};
use std::sync::Mutex;
use std::time::{Duration, Instant};

/// Cases of one CI run: 1,000 executions of the whole pipeline (each reader gets a fifth).
const CASES: u64 = 1000;
/// The base seed of CI's cases.
const SEED: u64 = 0x5EED_F022;
/// A case still running after this long is a hang (generous: a busy 2-core machine, debug build).
const HANG_SECONDS: u64 = 20;
/// Set in a worker process: the folder it writes its results to.
const WORKER_ENV: &str = "PLC_DEPS_FUZZ_WORKER";

/// The five readers fuzzed.
#[derive(Copy, Clone, Debug, PartialEq, Eq, PartialOrd, Ord)]
enum Reader {
    Json,
    PlcOpen,
    Stl,
    InputsCsv,
    InputsJson,
}

const READERS: [Reader; 5] = [
    Reader::Json,
    Reader::PlcOpen,
    Reader::Stl,
    Reader::InputsCsv,
    Reader::InputsJson,
];

impl Reader {
    fn name(self) -> &'static str {
        match self {
            Reader::Json => "json",
            Reader::PlcOpen => "plcopen",
            Reader::Stl => "stl",
            Reader::InputsCsv => "inputs-csv",
            Reader::InputsJson => "inputs-json",
        }
    }
    /// The extension a saved input gets (what the CLI picks the reader by).
    fn extension(self) -> &'static str {
        match self {
            Reader::Json | Reader::InputsJson => "json",
            Reader::PlcOpen => "xml",
            Reader::Stl => "stl",
            Reader::InputsCsv => "csv",
        }
    }
}

/// One seed file: its reader, where it is, its text and, for an inputs file, the program it is for.
struct Seed {
    reader: Reader,
    name: String,
    text: String,
    program: Option<PathBuf>,
}

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

/// The files in `dir` (relative to the crate) whose names end with `suffix`, sorted.
fn files(dir: &str, suffix: &str) -> Vec<PathBuf> {
    let mut out: Vec<PathBuf> = std::fs::read_dir(root().join(dir))
        .unwrap_or_else(|e| panic!("{dir}: {e}"))
        .filter_map(|e| Some(e.ok()?.path()))
        .filter(|p| p.to_string_lossy().ends_with(suffix))
        .collect();
    out.sort();
    out
}

/// The inputs CSV `csv` as the JSON inputs format (one object per row; empty cells left out).
fn csv_as_json(csv: &str) -> String {
    let mut lines = csv.lines().filter(|l| !l.trim().is_empty());
    let header: Vec<&str> = lines.next().unwrap_or("").split(',').collect();
    let rows: Vec<String> = lines
        .map(|l| {
            let cells: Vec<String> = header
                .iter()
                .zip(l.split(','))
                .filter(|(_, v)| !v.is_empty())
                .map(|(k, v)| {
                    let v = match v {
                        "true" | "false" => v.to_string(),
                        _ if v.parse::<f64>().is_ok() => v.to_string(),
                        _ => format!("{v:?}"),
                    };
                    format!("{k:?}: {v}")
                })
                .collect();
            format!("{{{}}}", cells.join(", "))
        })
        .collect();
    format!("[\n{}\n]\n", rows.join(",\n"))
}

fn seeds() -> Vec<Seed> {
    let mut out = Vec::new();
    let read = |p: &Path| std::fs::read_to_string(p).unwrap_or_else(|e| panic!("{p:?}: {e}"));
    let named = |p: &Path| p.strip_prefix(root()).unwrap_or(p).display().to_string();
    for dir in files("analyses", "") {
        let program = dir.join("program.json");
        if program.exists() {
            out.push(Seed {
                reader: Reader::Json,
                name: named(&program),
                text: read(&program),
                program: None,
            });
        }
        let stl = dir.join("program.stl");
        if stl.exists() {
            out.push(Seed {
                reader: Reader::Stl,
                name: named(&stl),
                text: read(&stl),
                program: None,
            });
        }
        let csv = dir.join("inputs.csv");
        if csv.exists() && program.exists() {
            let text = read(&csv);
            out.push(Seed {
                reader: Reader::InputsJson,
                name: named(&csv).replace(".csv", ".json (from the CSV)"),
                text: csv_as_json(&text),
                program: Some(program.clone()),
            });
            out.push(Seed {
                reader: Reader::InputsCsv,
                name: named(&csv),
                text,
                program: Some(program.clone()),
            });
        }
    }
    for p in files("tests/plcopen", ".xml")
        .into_iter()
        .chain(files("tests/plcopen_structs", ".xml"))
    {
        out.push(Seed {
            reader: Reader::PlcOpen,
            name: named(&p),
            text: read(&p),
            program: None,
        });
    }
    for p in files("tests/stl", ".stl") {
        out.push(Seed {
            reader: Reader::Stl,
            name: named(&p),
            text: read(&p),
            program: None,
        });
    }
    for r in READERS {
        assert!(
            out.iter().filter(|s| s.reader == r).count() >= 3,
            "{r:?}: the seed files are there"
        );
    }
    out
}

// ---------------------------------------------------------------------------------------------
// Mutations
// ---------------------------------------------------------------------------------------------

/// Text a mutant may gain, per reader: structure, references, keywords. PLCopen's are
/// [`crate::plcopen_mutation::SNIPPETS`] (XML) and [`ST_SNIPPETS`].
fn snippets(reader: Reader) -> Vec<&'static str> {
    match reader {
        Reader::Json => vec![
            "{",
            "}",
            "[",
            "]",
            ",",
            ":",
            "\"",
            "null",
            "true",
            "\"ld\": [",
            "{\"contact\": \"x\"}",
            "{\"coil\": \"y\"}",
            "{\"or\": [[",
            "]]}",
            "\"type\": \"INT\"",
            "\"class\": \"input\"",
            "\"rungs\": []",
            "\"id\": \"R1\"",
            "\"jmp\": \"L\"",
            "\"label\": \"L\"",
            "\"call\": \"S\"",
            "\\u0000",
            "\\ud800",
            "1e999",
            "-0",
            "\"fbd\": {",
            "\"op\": \"ADD\"",
        ],
        Reader::PlcOpen => crate::plcopen_mutation::SNIPPETS
            .iter()
            .chain(ST_SNIPPETS)
            .copied()
            .collect(),
        Reader::Stl => vec![
            "NETWORK",
            "NETWORK 1",
            "LD I0.0",
            "A M0.0",
            "O Q0.0",
            "= Q0.1",
            "LPS",
            "LRD",
            "LPP",
            "ALD",
            "OLD",
            "TON T37, +10",
            "CTU C0, 5",
            "MOVW +1, VW0",
            "+I VW0, VW2",
            "CALL SBR_0",
            "SBR 0",
            "INT 0",
            "END_SUBROUTINE_BLOCK",
            "ORGANIZATION_BLOCK",
            "VAR_INPUT",
            "END_VAR",
            "//",
            "(*",
            "I",
            ".",
            ",",
            "#",
            "LDN",
            "JMP 0",
            "LBL 0",
            "S Q0.0, 300",
        ],
        Reader::InputsCsv => vec![
            ",", "\"", "\"\"", "true", "false", "16#FF", "2#1010", "8#17", "T#1.5s", "1_000", "-",
            "NaN", "inf", "1e40", "T#", "16#", "\n", "\r\n", ",,,,",
        ],
        Reader::InputsJson => vec![
            "[",
            "]",
            "{",
            "}",
            ",",
            ":",
            "\"",
            "null",
            "true",
            "\"T#1s\"",
            "\"16#FF\"",
            "{\"x\": 1}",
            "1e999",
            "-0",
            "[[",
            "\"\\ud800\"",
        ],
    }
}

/// ST and more PLCopen markup a PLCopen mutant may gain.
const ST_SNIPPETS: &[&str] = &[
    "<ST><xhtml:p><![CDATA[x := (1 + ;]]></xhtml:p></ST>",
    "IF x THEN",
    "END_IF;",
    "WHILE TRUE DO",
    "END_WHILE;",
    ":=",
    "(*",
    "*)",
    "FOR i := 0 TO 32767 DO",
    "executionOrderId=\"0\"",
    "<contact localId=\"7\">",
    "<coil localId=\"8\">",
];

/// Numbers a number of the seed may become.
const EXTREMES: &[&str] = &[
    "0",
    "-1",
    "1",
    "255",
    "32768",
    "-32769",
    "65536",
    "2147483647",
    "2147483648",
    "-2147483649",
    "4294967295",
    "4294967296",
    "9223372036854775807",
    "9223372036854775808",
    "18446744073709551616",
    "99999999999999999999999999999999999999",
    "1e309",
    "-1e309",
    "1.5",
    "0.0000000001",
    "00000000000000000000000000000000007",
];

/// Characters a mutant may gain: non-ASCII, combining, direction, BOM, controls.
const ODD_CHARS: &[&str] = &[
    "é", "ẞ", "Ω", "😀", "\u{0301}", "\u{202e}", "\u{feff}", "\u{00a0}", "\u{2028}", "\t", "\r",
    "\u{1}", "\u{1b}", "\u{7f}", "\u{85}",
];

/// Openers repeated to nest deeply, per reader.
fn openers(reader: Reader) -> &'static [&'static str] {
    match reader {
        Reader::Json => &["[", "{\"or\": [[", "{\"and\": [", "{\"a\": "],
        Reader::PlcOpen => &["(", "NOT(", "<a>", "IF x THEN ", "x + (", "-"],
        Reader::Stl => &["LPS\n", "(", "LD I0.0\n"],
        Reader::InputsCsv => &["\"", "(", ","],
        Reader::InputsJson => &["[", "{\"a\": "],
    }
}

/// One mutation; `at`, `from` etc. are fractions of the text in millionths, so that an edit
/// reads the same whatever the text's length.
#[derive(Clone, Debug)]
enum Mutation {
    FlipBit {
        at: u32,
        bit: u8,
    },
    InsertByte {
        at: u32,
        byte: u8,
    },
    Delete {
        at: u32,
        len: u32,
    },
    Duplicate {
        from: u32,
        len: u32,
        at: u32,
    },
    Truncate {
        at: u32,
    },
    /// A line of another seed of the same reader, inserted before line `at`.
    SpliceLine {
        seed: u32,
        line: u32,
        at: u32,
    },
    DuplicateLine {
        line: u32,
    },
    DeleteLine {
        line: u32,
    },
    Snippet {
        at: u32,
        snippet: u32,
    },
    Number {
        at: u32,
        with: u32,
    },
    XmlElement {
        at: u32,
        delete: bool,
    },
    XmlAttribute {
        at: u32,
        how: u8,
    },
    Nest {
        at: u32,
        opener: u32,
        depth: u32,
    },
    OddChar {
        at: u32,
        which: u32,
    },
    CrOnly,
    CrLf,
}

fn mutation(rng: &mut Rng, reader: Reader) -> Mutation {
    let mut at = || rng.below(1_000_001) as u32;
    let (a, b, c) = (at(), at(), at());
    let xml = reader == Reader::PlcOpen;
    match rng.below(if xml { 18 } else { 16 }) {
        0 => Mutation::FlipBit {
            at: a,
            bit: rng.below(8) as u8,
        },
        1 => Mutation::InsertByte {
            at: a,
            byte: *rng.pick(&[
                0u8, b'\n', b'\r', b'"', b'<', b'>', b'&', b'{', b',', 0xFF, 0xC3, b' ',
            ]),
        },
        2 => Mutation::Delete {
            at: a,
            len: 1 + rng.below(64) as u32,
        },
        3 => Mutation::Duplicate {
            from: a,
            len: 1 + rng.below(200) as u32,
            at: b,
        },
        4 if rng.chance(30) => Mutation::Truncate { at: a },
        4 | 5 => Mutation::SpliceLine {
            seed: rng.next() as u32,
            line: b,
            at: c,
        },
        6 => Mutation::DuplicateLine { line: a },
        7 => Mutation::DeleteLine { line: a },
        8 | 9 => Mutation::Snippet {
            at: a,
            snippet: rng.next() as u32,
        },
        10 | 11 => Mutation::Number {
            at: a,
            with: rng.below(EXTREMES.len() as u64) as u32,
        },
        12 if rng.chance(25) => Mutation::Nest {
            at: a,
            opener: rng.next() as u32,
            depth: *rng.pick(&[50, 300, 3000, 30_000]),
        },
        12 | 13 => Mutation::OddChar {
            at: a,
            which: rng.next() as u32,
        },
        14 if rng.chance(15) => Mutation::CrOnly,
        14 => Mutation::CrLf,
        15 => Mutation::Snippet {
            at: a,
            snippet: rng.next() as u32,
        },
        16 => Mutation::XmlElement {
            at: a,
            delete: rng.chance(50),
        },
        _ => Mutation::XmlAttribute {
            at: a,
            how: rng.below(4) as u8,
        },
    }
}

/// The byte `at` millionths into `len` bytes.
fn place(len: usize, at: u32) -> usize {
    (len as u64 * at as u64 / 1_000_000) as usize
}

/// The starts of the lines of `text` (the first at 0).
fn line_starts(text: &[u8]) -> Vec<usize> {
    std::iter::once(0)
        .chain(
            text.iter()
                .enumerate()
                .filter(|(_, &b)| b == b'\n')
                .map(|(i, _)| i + 1),
        )
        .collect()
}

/// Line `k` (by fraction `at`) of `text`, with its end of line: its byte range.
fn line_range(text: &[u8], at: u32) -> std::ops::Range<usize> {
    let starts = line_starts(text);
    let k = place(starts.len(), at).min(starts.len() - 1);
    let end = starts.get(k + 1).copied().unwrap_or(text.len());
    starts[k]..end
}

fn apply(text: &mut Vec<u8>, m: &Mutation, reader: Reader, others: &[&str]) {
    let len = text.len();
    match *m {
        Mutation::FlipBit { at, bit } => {
            if len > 0 {
                let i = place(len, at).min(len - 1);
                text[i] ^= 1 << bit;
            }
        }
        Mutation::InsertByte { at, byte } => text.insert(place(len, at), byte),
        Mutation::Delete { at, len: n } => {
            let a = place(len, at);
            let b = (a + n as usize).min(len);
            text.drain(a..b);
        }
        Mutation::Duplicate { from, len: n, at } => {
            let a = place(len, from);
            let piece = text[a..(a + n as usize).min(len)].to_vec();
            let to = place(len, at);
            text.splice(to..to, piece);
        }
        Mutation::Truncate { at } => text.truncate(place(len, at)),
        Mutation::SpliceLine { seed, line, at } => {
            let other = others[seed as usize % others.len()].as_bytes();
            let mut piece = other[line_range(other, line)].to_vec();
            if !piece.ends_with(b"\n") {
                piece.push(b'\n');
            }
            let to = line_range(text, at).start;
            text.splice(to..to, piece);
        }
        Mutation::DuplicateLine { line } => {
            let r = line_range(text, line);
            let piece = text[r.clone()].to_vec();
            text.splice(r.start..r.start, piece);
        }
        Mutation::DeleteLine { line } => {
            let r = line_range(text, line);
            text.drain(r);
        }
        Mutation::Snippet { at, snippet } => {
            let s = snippets(reader);
            let s = s[snippet as usize % s.len()].as_bytes();
            let to = place(len, at);
            text.splice(to..to, s.iter().copied());
        }
        Mutation::Number { at, with } => {
            let a = place(len, at);
            if let Some(start) = text[a..].iter().position(u8::is_ascii_digit).map(|i| a + i) {
                let end = text[start..]
                    .iter()
                    .position(|b| !b.is_ascii_digit())
                    .map_or(len, |i| start + i);
                text.splice(start..end, EXTREMES[with as usize].bytes());
            }
        }
        Mutation::XmlElement { at, delete } => {
            if let Some(r) = xml_element(text, place(len, at)) {
                if delete {
                    text.drain(r);
                } else {
                    let piece = text[r.clone()].to_vec();
                    text.splice(r.end..r.end, piece);
                }
            }
        }
        Mutation::XmlAttribute { at, how } => {
            if let Some((whole, value)) = xml_attribute(text, place(len, at)) {
                match how {
                    0 => {
                        text.drain(whole);
                    }
                    1 => {
                        let piece = text[whole.clone()].to_vec();
                        text.splice(whole.end..whole.end, piece);
                    }
                    2 => {
                        text.drain(value);
                    }
                    _ => {
                        text.splice(value, "é\u{1}99999999999".bytes());
                    }
                }
            }
        }
        Mutation::Nest { at, opener, depth } => {
            let o = openers(reader);
            let o = o[opener as usize % o.len()];
            let to = place(len, at);
            text.splice(to..to, o.repeat(depth as usize).into_bytes());
        }
        Mutation::OddChar { at, which } => {
            let to = place(len, at);
            let c = ODD_CHARS[which as usize % ODD_CHARS.len()];
            text.splice(to..to, c.bytes());
        }
        Mutation::CrOnly => {
            let s = String::from_utf8_lossy(text)
                .replace("\r\n", "\n")
                .replace('\n', "\r");
            *text = s.into_bytes();
        }
        Mutation::CrLf => {
            let s = String::from_utf8_lossy(text)
                .replace("\r\n", "\n")
                .replace('\n', "\r\n");
            *text = s.into_bytes();
        }
    }
}

/// The element whose start tag opens at or after `from`: its byte range (to the first matching
/// close tag of that name, or its `/>`).
fn xml_element(text: &[u8], from: usize) -> Option<std::ops::Range<usize>> {
    let start = (from..text.len().saturating_sub(1))
        .find(|&i| text[i] == b'<' && text[i + 1].is_ascii_alphabetic())?;
    let name_end = (start + 1..text.len())
        .find(|&i| !(text[i].is_ascii_alphanumeric() || text[i] == b':' || text[i] == b'_'))?;
    let name = &text[start + 1..name_end];
    let tag_end = (name_end..text.len()).find(|&i| text[i] == b'>')?;
    if text[tag_end - 1] == b'/' {
        return Some(start..tag_end + 1);
    }
    let mut close = b"</".to_vec();
    close.extend_from_slice(name);
    close.push(b'>');
    let end = text[tag_end..]
        .windows(close.len())
        .position(|w| w == close.as_slice())
        .map(|i| tag_end + i + close.len())?;
    Some(start..end)
}

/// The attribute `name="value"` at or after `from`: its whole range (with the space before it)
/// and the range of its value.
fn xml_attribute(
    text: &[u8],
    from: usize,
) -> Option<(std::ops::Range<usize>, std::ops::Range<usize>)> {
    let eq =
        (from..text.len().saturating_sub(1)).find(|&i| text[i] == b'=' && text[i + 1] == b'"')?;
    let name_start = (0..eq).rev().find(|&i| text[i] == b' ')?;
    let value_end = (eq + 2..text.len()).find(|&i| text[i] == b'"')?;
    Some((name_start..value_end + 1, eq + 2..value_end))
}

// ---------------------------------------------------------------------------------------------
// One case
// ---------------------------------------------------------------------------------------------

/// The stage a case is in (for the watchdog and the report of a crash).
#[derive(Copy, Clone, Debug, PartialEq, Eq)]
#[repr(u8)]
enum Stage {
    Load = 1,
    Report,
    Scan,
    C,
    Il,
    Convert,
    Inputs,
}

const STAGES: [Stage; 7] = [
    Stage::Load,
    Stage::Report,
    Stage::Scan,
    Stage::C,
    Stage::Il,
    Stage::Convert,
    Stage::Inputs,
];

static STAGE: AtomicU8 = AtomicU8::new(0);

fn stage(s: Stage) {
    STAGE.store(s as u8, Ordering::SeqCst);
}

fn current_stage() -> Option<Stage> {
    let s = STAGE.load(Ordering::SeqCst);
    STAGES.into_iter().find(|&x| x as u8 == s)
}

/// How a case that behaved ended.
#[derive(Copy, Clone, Debug, PartialEq, Eq, PartialOrd, Ord)]
enum Outcome {
    /// Loaded (and went through the whole pipeline).
    Loaded,
    /// Refused with located errors.
    Refused,
}

/// Lines of `text` as error positions count them (`\n` ends a line).
fn line_count(text: &str) -> u32 {
    text.split('\n').count() as u32
}

/// Lines of an inputs file as its errors count them (LF, CRLF and CR each end a line).
fn input_line_count(text: &str) -> u32 {
    text.replace("\r\n", "\n").split(['\n', '\r']).count() as u32
}

/// A load error must be located: every diagnostic with a line and column inside the text, and
/// the command line's rendering of it (with its excerpt) must not panic.
pub(crate) fn check_load_error(file: &str, text: &str, e: &LoadError) -> Result<(), String> {
    let shown = Shown::load_error(file, text, e);
    if shown.is_empty() {
        return Err(format!("an error with no diagnostic: {e}"));
    }
    let lines = line_count(text);
    for s in &shown {
        let rendered = s.text(false);
        let _ = s.json();
        if s.message.trim().is_empty() {
            return Err(format!("an empty message: {rendered}"));
        }
        match s.position {
            None => return Err(format!("an error without line and column: {rendered}")),
            Some((line, column)) if line < 1 || line > lines || column < 1 => {
                return Err(format!(
                    "{line}:{column} is outside the file ({lines} lines): {rendered}"
                ))
            }
            Some(_) => {}
        }
    }
    Ok(())
}

/// An inputs error must be `FILE:LINE:COLUMN: message` with the line inside the file.
fn check_inputs_error(file: &str, text: &str, e: &CliError) -> Result<(), String> {
    let shown = e.to_string();
    let CliError::Usage(message) = e else {
        return Err(format!("not an inputs error: {shown}"));
    };
    let rest = message
        .strip_prefix(file)
        .and_then(|r| r.strip_prefix(':'))
        .ok_or_else(|| format!("does not name {file}: {shown}"))?;
    let mut parts = rest.splitn(3, ':');
    let line = parts.next().and_then(|l| l.parse::<u32>().ok());
    let column = parts.next().and_then(|c| c.parse::<u32>().ok());
    match (line, column, parts.next()) {
        (Some(l), Some(c), Some(m))
            if l >= 1 && l <= input_line_count(text) && c >= 1 && !m.trim().is_empty() =>
        {
            Ok(())
        }
        _ => Err(format!("not located inside the file: {shown}")),
    }
}

/// A run's error: a load error must be located as [`check_load_error`] says; a usage error (a
/// lowering limit, a plan) is accepted as it is.
fn check_run_error(text: &str, e: &CliError) -> Result<(), String> {
    match e {
        CliError::Load { file, error, .. } => check_load_error(file, text, error),
        CliError::Run(m) => Err(format!("a run failure: {m}")),
        _ => Ok(()),
    }
}

/// The case's folder in the worker (a program or an inputs file written for `run`).
fn case_file(dir: &Path, name: &str) -> PathBuf {
    dir.join(name)
}

/// Runs one case: the whole pipeline of its reader on `text`.
fn run_case(
    reader: Reader,
    seed: &Seed,
    text: &str,
    plan: PlanKind,
    dir: &Path,
) -> Result<Outcome, String> {
    match reader {
        Reader::InputsCsv | Reader::InputsJson => {
            stage(Stage::Inputs);
            let program_path = seed
                .program
                .as_ref()
                .expect("an inputs seed has its program");
            let program =
                plc_deps::cmd::io::load_program(program_path).map_err(|e| e.to_string())?;
            let file = format!("inputs.{}", reader.extension());
            let parsed = match reader {
                Reader::InputsCsv => parse_inputs_csv(&program, text, &file),
                _ => parse_inputs_json(&program, text, &file),
            };
            match parsed {
                Err(e) => {
                    check_inputs_error(&file, text, &e)?;
                    Ok(Outcome::Refused)
                }
                Ok(table) => {
                    stage(Stage::Scan);
                    let path = case_file(dir, &file);
                    std::fs::write(&path, text).map_err(|e| e.to_string())?;
                    let mut c = run_config(program_path, plan);
                    c.inputs = Some(path);
                    c.scans = Some((table.rows.len() as u64).clamp(1, 4));
                    match run_report(&c) {
                        Ok(r) if r.identical == Some(false) => {
                            Err(format!("seq and par differ: {:?}", r.first_difference))
                        }
                        Ok(_) => Ok(Outcome::Loaded),
                        Err(e) => Err(format!("inputs that parse are refused by run: {e}")),
                    }
                }
            }
        }
        Reader::Json | Reader::PlcOpen | Reader::Stl => {
            stage(Stage::Load);
            let loaded = match reader {
                Reader::Json => plc_deps::load::program_and_fbd_from_json(text),
                Reader::PlcOpen => plc_deps::load::plcopen(text).map(|(p, f, _)| (p, f)),
                _ => plc_deps::load::stl(text),
            };
            let file = format!("program.{}", reader.extension());
            let (p, fbd) = match loaded {
                Err(e) => {
                    check_load_error(&file, text, &e)?;
                    return Ok(Outcome::Refused);
                }
                Ok(x) => x,
            };
            stage(Stage::Report);
            for format in [
                ReportFormat::Text,
                ReportFormat::Json,
                ReportFormat::Dot,
                ReportFormat::Html,
            ] {
                let out = render_report(&p, &fbd, format, View::All);
                if out.is_empty() {
                    return Err(format!("an empty {format:?} report"));
                }
            }
            stage(Stage::Scan);
            let path = case_file(dir, &file);
            std::fs::write(&path, text).map_err(|e| e.to_string())?;
            let mut c = run_config(&path, plan);
            c.scans = Some(3);
            match run_report(&c) {
                Ok(r) if r.identical == Some(false) => {
                    return Err(format!("seq and par differ: {:?}", r.first_difference))
                }
                Ok(_) => {}
                Err(e) => check_run_error(text, &e)?,
            }
            stage(Stage::C);
            let files = plc_deps::codegen::c::generate(&p, &fbd, &Default::default());
            if files.is_empty() {
                return Err("no C files".into());
            }
            stage(Stage::Il);
            let _ = plc_deps::codegen::il::generate(&p, &fbd);
            stage(Stage::Convert);
            let mut out = Vec::new();
            let written = match reader {
                Reader::Json => plc_deps::read::json::parse(text)
                    .map_err(|e| format!("loads but does not parse again: {e}"))
                    .map(|s| plc_deps::write::json::program(&s, &mut out)),
                Reader::PlcOpen => {
                    plc_deps::load::plcopen_syntax(text, plc_deps::load::Pick::default(), true)
                        .map_err(|e| format!("loads but does not parse again: {e}"))
                        .map(|s| plc_deps::write::json::program(&s, &mut out))
                }
                // `plc-deps convert` reads no STL (it takes an STL file for JSON).
                _ => return Ok(Outcome::Loaded),
            }?;
            if written.is_ok() {
                let json = String::from_utf8(out).map_err(|_| "convert wrote non-UTF-8")?;
                plc_deps::load::program_and_fbd_from_json(&json).map_err(|e| {
                    format!(
                        "convert's output does not load: {}",
                        e.locate(&json).in_file("converted.json")
                    )
                })?;
            }
            Ok(Outcome::Loaded)
        }
    }
}

fn run_config(program: &Path, plan: PlanKind) -> RunConfig {
    let mut c = RunConfig::new(program);
    c.mode = RunMode::Both;
    c.threads = 2;
    c.plan = plan;
    c.calibrate = false;
    c.progress = false;
    c.alternate = Some(1);
    c
}

/// Case `i` of the run with base seed `base`: its reader, seed file, mutations, text and plan.
struct Case<'s> {
    seed: &'s Seed,
    mutations: Vec<Mutation>,
    text: String,
    plan: PlanKind,
}

fn make_case<'s>(seeds: &'s [Seed], base: u64, i: u64) -> Case<'s> {
    let mut rng = Rng::new(base ^ i.wrapping_mul(0xA24B_AED4_963E_E407));
    let reader = READERS[(i % READERS.len() as u64) as usize];
    let mine: Vec<&Seed> = seeds.iter().filter(|s| s.reader == reader).collect();
    let seed = *rng.pick(&mine);
    let others: Vec<&str> = mine.iter().map(|s| s.text.as_str()).collect();
    let n = 1 + rng.below(4) as usize;
    let mutations: Vec<Mutation> = (0..n).map(|_| mutation(&mut rng, reader)).collect();
    let mut bytes = seed.text.clone().into_bytes();
    for m in &mutations {
        apply(&mut bytes, m, reader, &others);
    }
    // The CLI refuses text that is not UTF-8 before any reader sees it (`cmd::io::read_text`):
    // the readers get its lossy form, which is still a mutant of the seed.
    let text = match String::from_utf8(bytes) {
        Ok(t) => t,
        Err(e) => String::from_utf8_lossy(e.as_bytes()).into_owned(),
    };
    let plan = *rng.pick(&[
        PlanKind::Par,
        PlanKind::Deps,
        PlanKind::Exchange,
        PlanKind::Seq,
    ]);
    Case {
        seed,
        mutations,
        text,
        plan,
    }
}

// ---------------------------------------------------------------------------------------------
// The worker process
// ---------------------------------------------------------------------------------------------

/// The message and place of the last panic (set by the worker's panic hook).
static LAST_PANIC: Mutex<String> = Mutex::new(String::new());
/// The case running, and when it started (ms since the worker started; 0: none running).
static RUNNING: AtomicU64 = AtomicU64::new(0);
static STARTED_MS: AtomicU64 = AtomicU64::new(0);

fn append(path: &Path, line: &str) {
    let mut f = std::fs::OpenOptions::new()
        .create(true)
        .append(true)
        .open(path)
        .expect("the results file opens");
    writeln!(f, "{}", line.replace('\n', "\\n")).expect("the results file is written");
}

/// The worker: runs cases `from..to` of base seed `base`, writing one line per case to
/// `dir/results` (`case I READER OUTCOME [message]`), the case about to run to `dir/current`.
fn worker(dir: &Path) {
    let plan = std::fs::read_to_string(dir.join("plan")).expect("the worker's plan");
    let nums: Vec<u64> = plan
        .split_whitespace()
        .map(|n| n.parse().expect("a number"))
        .collect();
    let (base, from, to) = (nums[0], nums[1], nums[2]);
    std::panic::set_hook(Box::new(|info| {
        let place = info
            .location()
            .map(|l| format!("{}:{}", l.file(), l.line()))
            .unwrap_or_default();
        let payload = info
            .payload()
            .downcast_ref::<&str>()
            .map(|s| s.to_string())
            .or_else(|| info.payload().downcast_ref::<String>().cloned())
            .unwrap_or_default();
        *LAST_PANIC.lock().unwrap_or_else(|e| e.into_inner()) =
            format!("panicked at {place}: {payload}");
    }));
    let start = Instant::now();
    let work_dir = dir.to_path_buf();
    let handle = std::thread::Builder::new()
        .name("fuzz-case".into())
        // The CLI runs on the main thread, whose stack is 8 MiB.
        .stack_size(8 << 20)
        .spawn(move || {
            let dir = work_dir;
            let seeds = seeds();
            let results = dir.join("results");
            for i in from..to {
                let case = make_case(&seeds, base, i);
                let reader = case.seed.reader;
                std::fs::write(dir.join("current"), format!("{i}\n")).expect("current");
                std::fs::write(
                    dir.join(format!("current.{}", reader.extension())),
                    &case.text,
                )
                .expect("current input");
                STAGE.store(0, Ordering::SeqCst);
                STARTED_MS.store(start.elapsed().as_millis() as u64 + 1, Ordering::SeqCst);
                RUNNING.store(i, Ordering::SeqCst);
                let outcome = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
                    run_case(reader, case.seed, &case.text, case.plan, &dir)
                }));
                STARTED_MS.store(0, Ordering::SeqCst);
                let line = match outcome {
                    Ok(Ok(o)) => format!("case {i} {} {o:?}", reader.name()),
                    Ok(Err(why)) => format!(
                        "case {i} {} fail {:?}: {why}",
                        reader.name(),
                        current_stage()
                    ),
                    Err(_) => format!(
                        "case {i} {} panic {:?}: {}",
                        reader.name(),
                        current_stage(),
                        LAST_PANIC.lock().unwrap_or_else(|e| e.into_inner())
                    ),
                };
                append(&results, &line);
            }
        })
        .expect("the case thread starts");
    // The watchdog: a case past HANG_SECONDS ends the process (the parent records it).
    while !handle.is_finished() {
        std::thread::sleep(Duration::from_millis(50));
        let started = STARTED_MS.load(Ordering::SeqCst);
        if started > 0 && start.elapsed().as_millis() as u64 + 1 - started > HANG_SECONDS * 1000 {
            let i = RUNNING.load(Ordering::SeqCst);
            append(
                &dir.join("results"),
                &format!(
                    "hang {i} {:?}: still running after {HANG_SECONDS} s",
                    current_stage()
                ),
            );
            std::process::exit(3);
        }
    }
    handle.join().expect("the case thread ends");
}

// ---------------------------------------------------------------------------------------------
// The parent
// ---------------------------------------------------------------------------------------------

/// A case that misbehaved.
#[derive(Debug)]
struct Failure {
    case: u64,
    reader: String,
    kind: String,
    message: String,
    saved: PathBuf,
}

/// Runs cases `0..cases` of base seed `base` in worker processes (restarted after a case that
/// ends one), and returns the results' lines and the failures whose process died.
fn run_workers(base: u64, cases: u64, dir: &Path) -> (Vec<String>, Vec<Failure>) {
    let exe = std::env::current_exe().expect("the test binary");
    let results = dir.join("results");
    let mut died = Vec::new();
    let mut from = 0;
    while from < cases {
        std::fs::write(dir.join("plan"), format!("{base} {from} {cases}")).unwrap();
        let _ = std::fs::remove_file(dir.join("current"));
        let mut child = Command::new(&exe)
            .args([
                "fuzz_readers::every_reader_survives_mutated_files",
                "--exact",
                "--nocapture",
                "--test-threads",
                "1",
            ])
            .env(WORKER_ENV, dir)
            .stdout(Stdio::null())
            .stderr(Stdio::piped())
            .spawn()
            .expect("the worker starts");
        // The worker ends itself on a hang; this is the backstop should even that not happen.
        let mut stderr = child.stderr.take().expect("piped");
        let reader = std::thread::spawn(move || {
            let mut s = String::new();
            let _ = std::io::Read::read_to_string(&mut stderr, &mut s);
            s
        });
        let mut last_len = 0;
        let mut quiet = Instant::now();
        let status = loop {
            if let Some(s) = child.try_wait().expect("wait") {
                break s;
            }
            std::thread::sleep(Duration::from_millis(50));
            let len = std::fs::metadata(&results).map_or(0, |m| m.len());
            if len != last_len {
                (last_len, quiet) = (len, Instant::now());
            } else if quiet.elapsed() > Duration::from_secs(HANG_SECONDS * 3 + 60) {
                let _ = child.kill();
                break child.wait().expect("wait");
            }
        };
        let stderr = reader.join().unwrap_or_default();
        let done: Vec<String> = std::fs::read_to_string(&results)
            .unwrap_or_default()
            .lines()
            .map(str::to_owned)
            .collect();
        if status.success() {
            break;
        }
        // The case it died in: the one it was running.
        let current: u64 = std::fs::read_to_string(dir.join("current"))
            .ok()
            .and_then(|s| s.trim().parse().ok())
            .unwrap_or(from);
        let hung = done
            .iter()
            .any(|l| l.starts_with(&format!("hang {current} ")));
        if !hung {
            let tail: String = stderr
                .lines()
                .filter(|l| !l.starts_with("warning") && !l.trim().is_empty())
                .rev()
                .take(6)
                .collect::<Vec<_>>()
                .into_iter()
                .rev()
                .collect::<Vec<_>>()
                .join(" | ");
            died.push(Failure {
                case: current,
                reader: String::new(),
                kind: "crash".into(),
                message: format!("the worker died ({status}): {tail}"),
                saved: PathBuf::new(),
            });
        }
        from = current + 1;
    }
    let lines = std::fs::read_to_string(&results)
        .unwrap_or_default()
        .lines()
        .map(str::to_owned)
        .collect();
    (lines, died)
}

fn env_u64(name: &str) -> Option<u64> {
    let v = std::env::var(name).ok()?;
    let v = v.trim();
    Some(match v.strip_prefix("0x") {
        Some(hex) => u64::from_str_radix(hex, 16).unwrap_or_else(|_| panic!("{name}={v}")),
        None => v.parse().unwrap_or_else(|_| panic!("{name}={v}")),
    })
}

/// Every reader, fed mutants of its seed files, either loads them (and the whole pipeline runs)
/// or refuses them with located errors; never a panic, hang or crash. In a worker process (see
/// the module comment) this test is the worker.
#[test]
fn every_reader_survives_mutated_files() {
    if let Some(dir) = std::env::var_os(WORKER_ENV) {
        worker(Path::new(&dir));
        return;
    }
    let cases = env_u64("PLC_DEPS_FUZZ_CASES").unwrap_or(CASES);
    let base = env_u64("PLC_DEPS_FUZZ_SEED").unwrap_or(SEED);
    let dir = std::env::temp_dir().join(format!("plc-deps-fuzz-{}-{base:x}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    let (lines, died) = run_workers(base, cases, &dir);

    let seeds = seeds();
    let mut counts: BTreeMap<(String, String), u64> = BTreeMap::new();
    let mut failures = died;
    for l in &lines {
        let mut parts = l.splitn(4, ' ');
        let (kind, case, reader) = (parts.next(), parts.next(), parts.next());
        let case: u64 = case.and_then(|c| c.parse().ok()).unwrap_or(u64::MAX);
        match kind {
            Some("case") => {
                let rest = parts.next().unwrap_or("");
                let outcome = rest.split_whitespace().next().unwrap_or("").to_string();
                *counts
                    .entry((reader.unwrap_or("").to_string(), outcome.clone()))
                    .or_default() += 1;
                if outcome == "fail" || outcome == "panic" {
                    failures.push(Failure {
                        case,
                        reader: reader.unwrap_or("").into(),
                        kind: outcome.clone(),
                        message: rest[outcome.len()..].trim().to_string(),
                        saved: PathBuf::new(),
                    });
                }
            }
            Some("hang") => failures.push(Failure {
                case,
                reader: String::new(),
                kind: "hang".into(),
                message: l.splitn(3, ' ').nth(2).unwrap_or("").to_string(),
                saved: PathBuf::new(),
            }),
            _ => {}
        }
    }
    let mut new = Vec::new();
    for mut f in failures {
        let case = make_case(&seeds, base, f.case);
        f.reader = case.seed.reader.name().into();
        let saved = dir.join(format!("case-{}.{}", f.case, case.seed.reader.extension()));
        std::fs::write(&saved, &case.text).unwrap();
        f.saved = saved;
        new.push((f, case.seed.name.clone(), case.mutations));
    }
    let executed: u64 = counts.values().sum::<u64>() + new.len() as u64
        - counts
            .iter()
            .filter(|((_, o), _)| o == "fail" || o == "panic")
            .map(|(_, n)| n)
            .sum::<u64>();
    println!(
        "fuzz_readers: {executed} executions of {cases} cases (seed {base:#x}): {:?}",
        counts
    );
    let report: Vec<String> = new
        .iter()
        .map(|(f, seed, mutations)| {
            format!(
                "case {} (PLC_DEPS_FUZZ_SEED={base:#x}), {} seed {seed}, mutations {mutations:?}: {} {}\n  input saved as {}",
                f.case,
                f.reader,
                f.kind,
                f.message,
                f.saved.display()
            )
        })
        .collect();
    assert!(
        report.is_empty(),
        "{} new failures:\n{}",
        report.len(),
        report.join("\n")
    );
    assert!(
        counts.keys().any(|(_, o)| o == "Loaded") && counts.keys().any(|(_, o)| o == "Refused"),
        "mutants both load and are refused: {counts:?}"
    );
    let _ = std::fs::remove_dir_all(&dir);
}
