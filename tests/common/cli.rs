//! Running the `plc-deps` binary from tests: the checkout root, a run (with or without standard
//! input), the one-line error of a failure, scratch files and leftover temporary files, and the
//! Graphviz check that DOT output renders without warnings.

use std::path::PathBuf;
use std::process::{Command, Output, Stdio};

/// The checkout (the directory of Cargo.toml).
pub fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

/// Runs `plc-deps ARGS` in the checkout.
pub fn run(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_plc-deps"))
        .current_dir(root())
        .args(args)
        .output()
        .expect("run plc-deps")
}

/// Runs `plc-deps ARGS` in the checkout with `stdin` as its standard input.
pub fn run_stdin(args: &[&str], stdin: &[u8]) -> Output {
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

/// The single `error: ` line of a failed command with exit code 2 and nothing on stdout.
pub fn error_line(out: &Output, what: &str) -> String {
    let stderr = String::from_utf8_lossy(&out.stderr).into_owned();
    assert_eq!(out.status.code(), Some(2), "{what}: {stderr}");
    assert!(out.stdout.is_empty(), "{what}: nothing on stdout");
    assert_eq!(stderr.lines().count(), 1, "{what}: one line: {stderr}");
    assert!(stderr.starts_with("error: "), "{what}: {stderr}");
    stderr.trim_end().to_string()
}

/// The files of a folder whose name contains `.tmp-` (leftover temporary files).
pub fn temp_files_in(dir: &std::path::Path) -> Vec<String> {
    files_in(dir, |n| n.contains(".tmp-"))
}

/// The names of the entries of a folder that `keep` keeps (none if it cannot be read).
pub fn files_in(dir: &std::path::Path, keep: impl Fn(&str) -> bool) -> Vec<String> {
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
pub fn tmp(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("plc-deps-test-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    dir.join(name)
}

/// Renders `dot` text with Graphviz and fails on an error or any warning.
pub fn graphviz(dot: &[u8], what: &str) {
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
