//! Every command the README and `docs/*.md` give still works: each line of a ```sh block that
//! runs `plc-deps` (or `cargo run --release --`) runs, in document order, in one scratch folder
//! per document that holds the repository's `analyses/` and `tests/`, and must succeed (or exit
//! with the code its comment names: `# exits 2`); a line ending in `\` continues on the next. A
//! ```text block right after a ```sh block lists lines that its last command must print (on
//! standard output or standard error), exactly. A ```sh benchmark block is a recipe that takes
//! minutes (the benchmark examples run it); it is not run here, and is the only kind skipped.

use crate::common;

use std::path::Path;
use std::process::Command;

/// A fenced block: its language and its lines.
struct Block {
    lang: String,
    lines: Vec<String>,
}

fn blocks(markdown: &str) -> Vec<Block> {
    let mut out = Vec::new();
    let mut open: Option<Block> = None;
    for line in markdown.lines() {
        match (line.strip_prefix("```"), open.take()) {
            (Some(_), Some(b)) => out.push(b),
            (Some(lang), None) => {
                open = Some(Block {
                    lang: lang.trim().to_owned(),
                    lines: Vec::new(),
                })
            }
            (None, Some(mut b)) => {
                b.lines.push(line.to_owned());
                open = Some(b);
            }
            (None, None) => {}
        }
    }
    out
}

/// The arguments of a document's command line that runs plc-deps, without its comment, and the
/// exit code the comment promises (`# exits N`; 0 when none).
fn plc_deps_args(line: &str) -> Option<(Vec<String>, i32)> {
    let mut parts = line.splitn(2, " #");
    let command = parts.next().unwrap_or("").trim();
    let comment = parts.next().unwrap_or("");
    let rest = command
        .strip_prefix("plc-deps ")
        .or_else(|| command.strip_prefix("cargo run --release -- "))?;
    let code = comment
        .split("exits ")
        .nth(1)
        .and_then(|c| c.split_whitespace().next())
        .and_then(|c| c.parse().ok())
        .unwrap_or(0);
    Some((rest.split_whitespace().map(str::to_owned).collect(), code))
}

/// The lines of a ```sh block with `\` continuations joined.
fn joined(lines: &[String]) -> Vec<String> {
    let mut out: Vec<String> = Vec::new();
    let mut open = false;
    for line in lines {
        let (text, more) = match line.trim_end().strip_suffix('\\') {
            Some(t) => (t.to_owned(), true),
            None => (line.clone(), false),
        };
        match out.last_mut() {
            Some(last) if open => {
                last.push(' ');
                last.push_str(text.trim());
            }
            _ => out.push(text),
        }
        open = more;
    }
    out
}

/// Runs the commands of the document `doc` in a fresh scratch folder and checks what they print;
/// returns the number of commands run and of output lines checked.
fn check_document(doc: &Path, scratch_name: &str) -> (usize, usize) {
    let root = common::cli::root();
    let markdown = std::fs::read_to_string(doc).unwrap();
    let name = doc.strip_prefix(&root).unwrap_or(doc).display().to_string();
    let scratch = common::cli::tmp(scratch_name);
    let _ = std::fs::remove_dir_all(&scratch);
    std::fs::create_dir_all(&scratch).unwrap();
    for dir in ["analyses", "tests"] {
        std::os::unix::fs::symlink(root.join(dir), scratch.join(dir)).unwrap();
    }
    let (mut commands, mut checked) = (0, 0);
    let mut last_output: Option<(String, String)> = None;
    for b in &blocks(&markdown) {
        match b.lang.as_str() {
            "sh" => {
                last_output = None;
                for line in joined(&b.lines) {
                    let Some((args, code)) = plc_deps_args(&line) else {
                        continue;
                    };
                    let out = Command::new(env!("CARGO_BIN_EXE_plc-deps"))
                        .current_dir(&scratch)
                        .args(&args)
                        .output()
                        .unwrap();
                    let text = format!(
                        "{}{}",
                        String::from_utf8_lossy(&out.stdout),
                        String::from_utf8_lossy(&out.stderr)
                    );
                    assert_eq!(
                        out.status.code(),
                        Some(code),
                        "{name}: `{line}` should exit {code}:\n{text}"
                    );
                    commands += 1;
                    last_output = Some((line.clone(), text));
                }
            }
            "text" => {
                let Some((command, text)) = last_output.take() else {
                    continue;
                };
                let printed: Vec<&str> = text.lines().collect();
                for want in &b.lines {
                    assert!(
                        printed.contains(&want.as_str()),
                        "{name}: `{command}` no longer prints\n{want}\nIt printed:\n{text}"
                    );
                    checked += 1;
                }
            }
            _ => last_output = None,
        }
    }
    (commands, checked)
}

#[test]
fn every_readme_command_runs_and_prints_what_the_readme_shows() {
    let root = common::cli::root();
    let (commands, checked) = check_document(&root.join("README.md"), "readme");
    // The set-up command and the tour: a README that lost them would pass trivially.
    assert!(commands >= 10, "{commands} README commands found");
    assert!(checked >= 8, "{checked} README output lines checked");
    let scratch = common::cli::tmp("readme");
    assert!(Path::new(&scratch.join("example-b.html")).is_file());
    assert!(scratch.join("example-c/Makefile").is_file());
}

#[test]
fn every_command_in_the_docs_runs_and_prints_what_the_docs_show() {
    let root = common::cli::root();
    let mut docs: Vec<_> = std::fs::read_dir(root.join("docs"))
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "md"))
        .collect();
    docs.sort();
    let (mut commands, mut checked) = (0, 0);
    for (i, doc) in docs.iter().enumerate() {
        let (c, k) = check_document(doc, &format!("docs-{i}"));
        commands += c;
        checked += k;
    }
    // The error example of docs/format.md, the il output of docs/il.md, and the others.
    assert!(commands >= 8, "{commands} docs commands found");
    assert!(checked >= 20, "{checked} docs output lines checked");
}
