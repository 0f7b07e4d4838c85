//! Every JSON example in `docs/*.md` is checked, so the documentation cannot drift from the
//! reader.
//!
//! The rule, by the info string of a fenced block:
//! * ```` ```json ```` — a **whole program**: one JSON object with a `"program"` key, loaded with
//!   `plc_deps::load::program_from_json` (FBD bodies included); it must load.
//! * ```` ```json fragment ```` — a **fragment** (an element, a declaration, a list of inputs):
//!   not loaded, but it must be a sequence of one or more valid JSON values (one per line, say).
//! * any other info string starting with `json` is an error (so no block is skipped silently);
//!   blocks in other languages (```` ```text ```` for grammar sketches with placeholders such as
//!   `VAR, ...`, `sh`, `csv`, none) are not JSON and not checked.
//!
//! Failures name the doc file and the line of the block's opening fence. This test does not
//! check that a program means what the surrounding prose says.

use std::fs;
use std::path::{Path, PathBuf};

/// A fenced block: its file, the line of its opening fence (1-based), its info string and text.
struct Block {
    file: PathBuf,
    line: usize,
    info: String,
    text: String,
}

fn blocks(file: &Path) -> Vec<Block> {
    let doc = fs::read_to_string(file).unwrap_or_else(|e| panic!("{}: {e}", file.display()));
    let mut out = Vec::new();
    let mut open: Option<Block> = None;
    for (i, line) in doc.lines().enumerate() {
        let fence = line.trim_start().strip_prefix("```");
        match (&mut open, fence) {
            (None, Some(info)) => {
                open = Some(Block {
                    file: file.to_owned(),
                    line: i + 1,
                    info: info.trim().to_owned(),
                    text: String::new(),
                })
            }
            (Some(_), Some(_)) => out.extend(open.take()),
            (Some(b), None) => {
                b.text.push_str(line);
                b.text.push('\n');
            }
            (None, None) => {}
        }
    }
    if let Some(b) = open {
        panic!("{}:{}: fenced block not closed", b.file.display(), b.line);
    }
    out
}

/// Checks one block; `Ok(true)` when it is a whole program that loaded.
fn check(b: &Block) -> Result<bool, String> {
    match b.info.as_str() {
        "json" => {
            let v: serde_json::Value = serde_json::from_str(&b.text)
                .map_err(|e| format!("not JSON ({e}); a sketch with placeholders is ```text"))?;
            if v.get("program").is_none() {
                return Err(
                    "not a whole program (no \"program\" key): mark it ```json fragment".into(),
                );
            }
            plc_deps::load::program_from_json(&b.text)
                .map(|_| true)
                .map_err(|e| format!("the program does not load: {e}"))
        }
        "json fragment" => {
            let mut values = 0;
            for v in serde_json::Deserializer::from_str(&b.text).into_iter::<serde_json::Value>() {
                v.map_err(|e| format!("fragment is not a sequence of JSON values: {e}"))?;
                values += 1;
            }
            if values == 0 {
                return Err("empty fragment".into());
            }
            Ok(false)
        }
        other if other.starts_with("json") => Err(format!(
            "unknown info string {other:?}: use ```json (a whole program) or ```json fragment"
        )),
        _ => Ok(false),
    }
}

#[test]
fn every_json_example_in_the_docs_loads() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("docs");
    let mut files: Vec<PathBuf> = fs::read_dir(&dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|x| x == "md"))
        .collect();
    files.sort();
    let (mut programs, mut fragments, mut errors) = (0, 0, Vec::new());
    for f in &files {
        for b in blocks(f) {
            match check(&b) {
                Ok(true) => programs += 1,
                Ok(false) => fragments += usize::from(b.info.starts_with("json")),
                Err(e) => {
                    let file = b
                        .file
                        .strip_prefix(env!("CARGO_MANIFEST_DIR"))
                        .unwrap_or(&b.file);
                    errors.push(format!("{}:{}: {e}", file.display(), b.line))
                }
            }
        }
    }
    assert!(errors.is_empty(), "{}", errors.join("\n"));
    println!("{programs} whole programs loaded, {fragments} fragments parsed");
    assert!(programs >= 1, "no whole program found in {}", dir.display());
}
