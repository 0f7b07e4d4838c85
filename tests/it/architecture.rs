//! The workspace's layers, as docs/design/architecture.md draws them: every crate depends
//! (normally or for its tests) only on crates below it, every crate is on the map, and only the
//! crates that need `unsafe` are allowed it.
//!
//! Cargo itself refuses a dependency that closes a cycle; this test refuses any dependency
//! against the order, cycle or not (`plc-read` on `plc-analysis` would not be a cycle today).

use std::path::Path;

/// The crates from the bottom up: a crate may depend only on crates earlier in the list.
const LAYERS: &[&str] = &[
    "plc-diag",
    "plc-graph",
    "plc-hint",
    "plc-synth",
    "plc-model",
    "plc-fbd",
    "plc-syntax",
    "plc-read",
    "plc-write",
    "plc-resolve",
    "plc-load",
    "plc-analysis",
    "plc-report",
    "plc-exec",
    "plc-codegen",
];

/// The crates whose code needs `unsafe` (cache hints; the executor's shared state); every
/// other crate says `#![forbid(unsafe_code)]`.
const MAY_USE_UNSAFE: &[&str] = &["plc-hint", "plc-exec"];

fn root() -> &'static Path {
    Path::new(env!("CARGO_MANIFEST_DIR"))
}

/// The `plc-*` path dependencies of a manifest, in every dependency table.
fn path_dependencies(manifest: &str) -> Vec<String> {
    manifest
        .lines()
        .filter(|l| l.contains("path = \"../plc-") || l.contains("path = \"crates/plc-"))
        .map(|l| l.split_whitespace().next().expect("a key").to_string())
        .collect()
}

fn crate_dirs() -> Vec<String> {
    let mut names: Vec<String> = std::fs::read_dir(root().join("crates"))
        .expect("crates/")
        .map(|e| {
            e.expect("an entry")
                .file_name()
                .to_string_lossy()
                .into_owned()
        })
        .collect();
    names.sort();
    names
}

#[test]
fn every_crate_is_a_layer_and_depends_only_on_the_layers_below_it() {
    let mut on_map: Vec<String> = LAYERS.iter().map(|s| s.to_string()).collect();
    on_map.sort();
    assert_eq!(crate_dirs(), on_map, "crates/ and the layer list differ");
    let mut upward = Vec::new();
    for (level, name) in LAYERS.iter().enumerate() {
        let manifest = std::fs::read_to_string(root().join("crates").join(name).join("Cargo.toml"))
            .expect("a manifest");
        for dep in path_dependencies(&manifest) {
            let at = LAYERS.iter().position(|l| *l == dep);
            match at {
                Some(at) if at < level => {}
                _ => upward.push(format!("{name} -> {dep}")),
            }
        }
    }
    assert_eq!(
        upward,
        Vec::<String>::new(),
        "dependencies against the layer order"
    );
    // The root (CLI and facade) sits on top of every layer.
    let root_deps = path_dependencies(&std::fs::read_to_string(root().join("Cargo.toml")).unwrap());
    let mut sorted = root_deps.clone();
    sorted.sort();
    assert_eq!(sorted, on_map, "the facade re-exports every layer");
}

#[test]
fn the_architecture_map_names_every_crate() {
    let map = std::fs::read_to_string(root().join("docs/design/architecture.md")).expect("the map");
    let missing: Vec<&&str> = LAYERS
        .iter()
        .filter(|c| !map.contains(&format!("`{c}`")))
        .collect();
    assert_eq!(missing, Vec::<&&str>::new());
}

#[test]
fn only_the_crates_that_need_unsafe_allow_it() {
    for name in LAYERS {
        let lib = std::fs::read_to_string(root().join("crates").join(name).join("src/lib.rs"))
            .expect("lib.rs");
        let forbids = lib.contains("#![forbid(unsafe_code)]");
        assert_eq!(
            forbids,
            !MAY_USE_UNSAFE.contains(name),
            "{name}: forbid(unsafe_code) is {forbids}"
        );
    }
    // The executor allows it only in the modules and functions that say so by name.
    let exec = std::fs::read_to_string(root().join("crates/plc-exec/src/lib.rs")).unwrap();
    assert!(exec.contains("#![deny(unsafe_code)]"));
    let lib = std::fs::read_to_string(root().join("src/lib.rs")).unwrap();
    assert!(lib.contains("#![deny(unsafe_code)]"));
    let main = std::fs::read_to_string(root().join("src/main.rs")).unwrap();
    assert!(main.contains("#![forbid(unsafe_code)]"));
}
