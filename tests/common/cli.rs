//! Running the `plc-deps` binary from tests: the checkout root, a run, a scratch file, and the
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
