//! The workspace's layers, as docs/design/architecture.md draws them: every crate depends
//! (normally or for its tests) only on crates below it, every crate is on the map, only the
//! crates that need `unsafe` are allowed it, and in the executor every raw memory access is in
//! its one `raw` module.
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

/// The executor's modules that allow `unsafe` (paths under crates/plc-exec/src): `raw`, which
/// holds every raw memory access, and the callers of its `unsafe fn`s, each arguing the
/// callee's precondition in its file (the interpreter; the parallel machine's item runner and
/// the three scan loops that run items and hand the state to worker 0).
const EXEC_UNSAFE_MODULES: &[&str] = &[
    "parallel/machine/claimed.rs",
    "parallel/machine/exchange.rs",
    "parallel/machine/items.rs",
    "parallel/machine/workers.rs",
    "raw.rs",
    "run.rs",
];

/// What only the executor's `raw` module may write (outside comments): raw pointer reads and
/// writes, unchecked indexing, interior mutability by hand, `Send`/`Sync` promises, SIMD
/// intrinsics.
const RAW_ONLY: &[&str] = &[
    "from_raw_parts",
    "get_unchecked",
    "unsafe impl",
    "UnsafeCell",
    "std::arch",
    "transmute",
    "ptr::read",
    "ptr::write",
    "read_unaligned",
    "write_unaligned",
];

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

/// The `.rs` files under `dir`, as paths relative to `base` with `/` separators.
fn rust_files(base: &Path, dir: &Path, out: &mut Vec<String>) {
    for e in std::fs::read_dir(dir).expect("a source directory") {
        let path = e.expect("an entry").path();
        if path.is_dir() {
            rust_files(base, &path, out);
        } else if path.extension().is_some_and(|x| x == "rs") {
            let rel = path.strip_prefix(base).expect("under the base");
            out.push(rel.to_string_lossy().replace('\\', "/"));
        }
    }
}

#[test]
fn the_executor_s_raw_accesses_are_in_one_module() {
    let src = root().join("crates/plc-exec/src");
    let mut files = Vec::new();
    rust_files(&src, &src, &mut files);
    files.sort();
    assert!(files.iter().any(|f| f == "raw.rs"), "{files:?}");
    let mut allowed = Vec::new();
    for file in &files {
        let text = std::fs::read_to_string(src.join(file)).expect("a source file");
        let code: Vec<&str> = text
            .lines()
            .filter(|l| !l.trim_start().starts_with("//"))
            .collect();
        if file != "raw.rs" {
            for l in &code {
                for word in RAW_ONLY {
                    assert!(!l.contains(word), "{file}: `{word}` outside raw.rs: {l}");
                }
            }
        }
        // `allow(unsafe_code)` only on module declarations, never on a function or block.
        for (i, l) in code.iter().enumerate() {
            if !l.contains("allow(unsafe_code)") {
                continue;
            }
            let next = code[i + 1..]
                .iter()
                .map(|l| l.trim())
                .find(|l| !l.starts_with("#["))
                .expect("an item after the attribute");
            let name = next
                .strip_prefix("mod ")
                .and_then(|n| n.strip_suffix(';'))
                .unwrap_or_else(|| panic!("{file}: allow(unsafe_code) on `{next}`, not a module"));
            // A module declared in `a/mod.rs` or `lib.rs` lives in `a/`, in `a/b.rs` in `a/b/`.
            let dir = match file.rsplit_once('/') {
                Some((d, "mod.rs")) => format!("{d}/"),
                None if file == "lib.rs" => String::new(),
                _ => format!("{}/", file.strip_suffix(".rs").expect(".rs")),
            };
            let flat = format!("{dir}{name}.rs");
            let nested = format!("{dir}{name}/mod.rs");
            allowed.push(if files.contains(&flat) { flat } else { nested });
        }
    }
    allowed.sort();
    assert_eq!(allowed, EXEC_UNSAFE_MODULES);
}
