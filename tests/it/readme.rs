//! Every command the README gives still works: each line of a ```sh block that runs `plc-deps`
//! (or `cargo run --release --`) runs, in README order, in one scratch folder that holds the
//! repository's `analyses/`, and must succeed; a ```text block right after a ```sh block lists
//! lines that its last command must print (on standard output or standard error).

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

/// The arguments of a README command line that runs plc-deps, without its comment.
fn plc_deps_args(line: &str) -> Option<Vec<String>> {
    let command = line.split(" #").next().unwrap_or("").trim();
    let rest = command
        .strip_prefix("plc-deps ")
        .or_else(|| command.strip_prefix("cargo run --release -- "))?;
    Some(rest.split_whitespace().map(str::to_owned).collect())
}

#[test]
fn every_readme_command_runs_and_prints_what_the_readme_shows() {
    let root = common::cli::root();
    let readme = std::fs::read_to_string(root.join("README.md")).unwrap();
    let scratch = common::cli::tmp("readme");
    let _ = std::fs::remove_dir_all(&scratch);
    std::fs::create_dir_all(&scratch).unwrap();
    std::os::unix::fs::symlink(root.join("analyses"), scratch.join("analyses")).unwrap();
    let blocks = blocks(&readme);
    let (mut commands, mut checked) = (0, 0);
    let mut last_output: Option<(String, String)> = None;
    for b in &blocks {
        match b.lang.as_str() {
            "sh" => {
                last_output = None;
                for line in &b.lines {
                    let Some(args) = plc_deps_args(line) else {
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
                    assert!(out.status.success(), "README: `{line}` failed:\n{text}");
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
                        "README: `{command}` no longer prints\n{want}\nIt printed:\n{text}"
                    );
                    checked += 1;
                }
            }
            _ => last_output = None,
        }
    }
    // The set-up command and the tour: a README that lost them would pass trivially.
    assert!(commands >= 10, "{commands} README commands found");
    assert!(checked >= 8, "{checked} README output lines checked");
    assert!(Path::new(&scratch.join("example-b.html")).is_file());
    assert!(scratch.join("example-c/Makefile").is_file());
}
