//! Running the `plc-deps` binary from tests: the checkout root, a run (with or without standard
//! input), the one-line form of a failure's diagnostics, scratch files (a generated program among
//! them) and leftover temporary files, and the Graphviz check that DOT output renders without
//! warnings.

use std::path::PathBuf;
use std::process::{Command, Output, Stdio};

/// A program written by `plc-deps gen ARGS` into the scratch folder as `name`.
pub(crate) fn generated(name: &str, args: &[&str]) -> PathBuf {
    let path = tmp(name);
    let mut all = vec!["gen"];
    all.extend_from_slice(args);
    all.extend_from_slice(&["-o", path.to_str().unwrap()]);
    let out = run(&all);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    path
}

/// The checkout (the directory of Cargo.toml).
pub(crate) fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

/// Runs `plc-deps ARGS` in the checkout.
pub(crate) fn run(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_plc-deps"))
        .current_dir(root())
        .args(args)
        .output()
        .expect("run plc-deps")
}

/// Runs `plc-deps ARGS` in the checkout with `stdin` as its standard input.
pub(crate) fn run_stdin(args: &[&str], stdin: &[u8]) -> Output {
    use std::io::Write;
    let mut child = Command::new(env!("CARGO_BIN_EXE_plc-deps"))
        .current_dir(root())
        .args(args)
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("run plc-deps");
    let mut input = child.stdin.take().unwrap();
    // A command that fails early may close its standard input before reading it all.
    let _ = input.write_all(stdin);
    drop(input);
    child.wait_with_output().expect("run plc-deps")
}

/// The error of a failed command with exit code 2 and nothing on stdout, as one line: the
/// one diagnostic on stderr in its one-line form ([`one_line`]).
pub(crate) fn error_line(out: &Output, what: &str) -> String {
    let stderr = String::from_utf8_lossy(&out.stderr).into_owned();
    assert_eq!(out.status.code(), Some(2), "{what}: {stderr}");
    assert!(out.stdout.is_empty(), "{what}: nothing on stdout");
    let line = one_line(&stderr);
    assert_eq!(line.lines().count(), 1, "{what}: one diagnostic: {stderr}");
    assert!(line.starts_with("error: "), "{what}: {stderr}");
    line.trim_end().to_string()
}

/// The diagnostics of a command's stderr, rendered in the style of rustc, each as one line
/// `SEVERITY: FILE:LINE:COLUMN: LOCATION: message` (the form `LoadError::in_file` writes),
/// reassembled from the header (`error[E0204]: message`), the `-->` line and the label after
/// the carets, or from the keys of a JSON diagnostic (`--format json`); lines that are not
/// part of a diagnostic (`error: cannot read …`) are kept as they are. The rendering itself is
/// compared whole in tests/errors/*.err.
pub(crate) fn one_line(stderr: &str) -> String {
    let mut out = Vec::new();
    let mut lines = stderr.lines().peekable();
    while let Some(line) = lines.next() {
        if let Ok(d) = serde_json::from_str::<serde_json::Value>(line) {
            out.push(json_one_line(&d));
            continue;
        }
        let header = ["error[", "warning["]
            .iter()
            .find(|p| line.starts_with(**p))
            .and_then(|_| line.split_once("]: "));
        let Some((severity, message)) = header else {
            if !line.trim().is_empty() {
                out.push(line.to_string());
            }
            continue;
        };
        let severity = severity.split('[').next().unwrap();
        let (mut place, mut label) = (None, None);
        while let Some(next) = lines.peek() {
            if next.starts_with("error") || next.starts_with("warning") {
                break;
            }
            let next = lines.next().unwrap().trim();
            if let Some(p) = next.strip_prefix("--> ") {
                place = Some(p.to_string());
            } else if let Some(n) = next.strip_prefix("= note: in ") {
                place = Some(n.to_string());
            } else if let Some(rest) = next.strip_prefix('|') {
                let rest = rest.trim_start();
                if rest.starts_with('^') {
                    let l = rest.trim_start_matches('^').trim();
                    label = (!l.is_empty()).then(|| l.to_string());
                }
            }
        }
        out.push(match (place, label) {
            (Some(p), Some(l)) => format!("{severity}: {p}: {l}: {message}"),
            (Some(p), None) => format!("{severity}: {p}: {message}"),
            _ => format!("{severity}: {message}"),
        });
    }
    out.join("\n")
}

/// A JSON diagnostic as one line (see [`one_line`]).
fn json_one_line(d: &serde_json::Value) -> String {
    let mut s = format!("{}: ", d["severity"].as_str().unwrap());
    if let Some(f) = d["file"].as_str() {
        s += f;
        if let (Some(l), Some(c)) = (d["line"].as_u64(), d["column"].as_u64()) {
            s += &format!(":{l}:{c}");
        }
        s += ": ";
    }
    if let Some(l) = d["location"].as_str() {
        s += &format!("{l}: ");
    }
    s + d["message"].as_str().unwrap()
}

/// The files of a folder whose name contains `.tmp-` (leftover temporary files).
pub(crate) fn temp_files_in(dir: &std::path::Path) -> Vec<String> {
    files_in(dir, |n| n.contains(".tmp-"))
}

/// The names of the entries of a folder that `keep` keeps (none if it cannot be read).
pub(crate) fn files_in(dir: &std::path::Path, keep: impl Fn(&str) -> bool) -> Vec<String> {
    std::fs::read_dir(dir)
        .map(|d| {
            d.filter_map(|e| e.ok())
                .map(|e| e.file_name().to_string_lossy().into_owned())
                .filter(|n| keep(n))
                .collect()
        })
        .unwrap_or_default()
}

/// A path for a scratch file of this test process.
pub(crate) fn tmp(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("plc-deps-test-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    dir.join(name)
}

/// Renders `dot` text with Graphviz and fails on an error or any warning.
pub(crate) fn graphviz(dot: &[u8], what: &str) {
    let child = Command::new("dot")
        .arg("-Tsvg")
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("Graphviz `dot` is installed (.ci/run installs it)");
    use std::io::Write;
    child.stdin.as_ref().unwrap().write_all(dot).unwrap();
    let res = child.wait_with_output().unwrap();
    assert!(res.status.success(), "{what}: dot failed");
    assert!(
        res.stderr.is_empty(),
        "{what}: dot warned: {}",
        String::from_utf8_lossy(&res.stderr)
    );
    assert!(String::from_utf8_lossy(&res.stdout).contains("<svg"));
}
