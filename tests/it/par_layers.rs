//! The parallel scan's modules and `run`'s modules keep a one-way order: every module uses only
//! the modules below it in the order its `mod.rs` documents (`exec/parallel`: the basics, then
//! planning, the measured choice, the running machine, the explanation; `cmd/run`: config,
//! trace, inputs, compare, engine, output). Read from the sources: every `super::…` and
//! `crate::parallel::…` (in the executor crate) / `crate::cmd::run::…` path outside comments and test modules is
//! resolved to the module it names, and must name one that comes earlier in the order.
//!
//! One exception, named here: `machine::items`, `machine::exchange`, `machine::claimed` and
//! `machine::workers` are the second half of `ParallelMachine`'s implementation (one plan item;
//! the levelled plan on private states; the levelled plan's units; the workers' loops), so they
//! use their parent's types as the parent uses their functions.

use std::path::Path;

/// A module path inside the tree (`["planning", "plan"]`), bottom to top.
type Order = &'static [&'static [&'static str]];

const PARALLEL: Order = &[
    &["ids"],
    &["config"],
    &["pad"],
    &["planning", "calibrate"],
    &["planning", "rung_cost"],
    &["planning", "calls"],
    &["planning", "tasks"],
    &["planning", "partition"],
    &["planning", "movement"],
    &["planning", "slicing"],
    &["planning", "one_way"],
    &["planning", "ready"],
    &["planning", "phase"],
    &["planning", "plan"],
    &["planning", "deps_plan"],
    &["planning", "candidates"],
    &["planning", "order_check"],
    &["planning", "check"],
    &["planning", "early"],
    &["planning", "exchange"],
    &["planning", "remote"],
    &["planning"],
    &["static_plan"],
    &["choice"],
    &["machine", "run_log"],
    &["machine", "backoff"],
    &["machine", "barrier"],
    &["machine", "flags"],
    &["machine", "units"],
    &["machine", "xlines"],
    &["machine", "shared"],
    &["machine", "driver"],
    &["machine", "relayout"],
    &["machine", "items"],
    &["machine", "exchange"],
    &["machine", "claimed"],
    &["machine", "workers"],
    &["machine"],
    &["explain"],
    &[],
];

const RUN: Order = &[
    &["config"],
    &["trace"],
    &["inputs"],
    &["compare"],
    &["bookkeeping"],
    &["engine"],
    &["output"],
    &[],
];

/// Where a module's source is.
fn file_of(root: &Path, m: &[&str]) -> std::path::PathBuf {
    let dir = root.join(m.join("/"));
    if m.is_empty() || dir.join("mod.rs").exists() {
        dir.join("mod.rs")
    } else {
        root.join(format!("{}.rs", m.join("/")))
    }
}

/// The code of a file: comment lines and the test module (from `#[cfg(test)]` on) removed.
fn code(text: &str) -> String {
    let body = text.split("#[cfg(test)]").next().unwrap_or("");
    body.lines()
        .filter(|l| !l.trim_start().starts_with("//"))
        .collect::<Vec<_>>()
        .join("\n")
}

/// Every path the code names through `super` or `absolute`, as a list of segments from the
/// tree's root, for a file whose module is `m` (`super` of a `mod.rs` is its parent's parent).
fn named_paths(code: &str, m: &[&str], absolute: &str) -> Vec<Vec<String>> {
    let ident = |s: &str| -> Vec<String> {
        let mut segs = Vec::new();
        let mut rest = s;
        loop {
            let end = rest
                .find(|c: char| !(c.is_alphanumeric() || c == '_'))
                .unwrap_or(rest.len());
            if end == 0 {
                // `{a, b}` after `::`: every first segment inside the braces.
                if let Some(inner) = rest.strip_prefix('{') {
                    let close = inner.find('}').unwrap_or(inner.len());
                    return inner[..close]
                        .split(',')
                        .map(|p| p.trim().split("::").next().unwrap_or("").to_string())
                        .filter(|p| !p.is_empty())
                        .map(|p| {
                            let mut v = segs.clone();
                            v.push(p);
                            v.join("::")
                        })
                        .collect();
                }
                break;
            }
            segs.push(rest[..end].to_string());
            match rest[end..].strip_prefix("::") {
                Some(r) => rest = r,
                None => break,
            }
        }
        vec![segs.join("::")]
    };
    let mut out = Vec::new();
    for (at, _) in code.match_indices("super::") {
        if at >= 7 && &code[at - 7..at] == "super::" {
            continue; // counted from the first `super`
        }
        let mut base: Vec<String> = m.iter().map(|s| s.to_string()).collect();
        let mut rest = &code[at..];
        while let Some(r) = rest.strip_prefix("super::") {
            base.pop();
            rest = r;
        }
        for p in ident(rest) {
            let mut v = base.clone();
            v.extend(p.split("::").filter(|s| !s.is_empty()).map(str::to_string));
            out.push(v);
        }
    }
    for (at, _) in code.match_indices(absolute) {
        for p in ident(&code[at + absolute.len()..]) {
            out.push(
                p.split("::")
                    .filter(|s| !s.is_empty())
                    .map(str::to_string)
                    .collect(),
            );
        }
    }
    out
}

/// The position in `order` of the longest module that `path` starts with.
fn module_of(order: Order, path: &[String]) -> usize {
    (0..order.len())
        .filter(|&i| order[i].len() <= path.len() && order[i].iter().zip(path).all(|(a, b)| a == b))
        .max_by_key(|&i| order[i].len())
        .expect("the root matches every path")
}

/// Every use that goes up the order (or to its own parent), as "user -> used".
fn upward_uses(root: &Path, order: Order, absolute: &str) -> Vec<String> {
    let mut bad = Vec::new();
    for (pos, m) in order.iter().enumerate() {
        let file = file_of(root, m);
        let text = std::fs::read_to_string(&file).unwrap_or_else(|e| panic!("{file:?}: {e}"));
        // `super` inside a `mod.rs` names the parent of its directory.
        let mut me: Vec<&str> = m.to_vec();
        if file.ends_with("mod.rs") {
            me.push("mod");
        }
        for path in named_paths(&code(&text), &me, absolute) {
            let used = module_of(order, &path);
            let own_parent = m.len() == order[used].len() + 1 && m.starts_with(order[used]);
            let exception = (*m == ["machine", "claimed"]
                || *m == ["machine", "items"]
                || *m == ["machine", "exchange"]
                || *m == ["machine", "workers"])
                && order[used] == ["machine"];
            if used == pos || exception {
                continue;
            }
            if used > pos || own_parent {
                bad.push(format!("{} -> {}", m.join("::"), path.join("::")));
            }
        }
    }
    bad.sort();
    bad.dedup();
    bad
}

/// Every module file of the tree is in the order (a new module must be placed in it), but for
/// test modules in a file of their own (`tests.rs`, `*_tests.rs`), which are left out as an inline
/// `#[cfg(test)]` module is (`code`).
fn unlisted(root: &Path, order: Order) -> Vec<String> {
    let mut found = Vec::new();
    let mut stack = vec![root.to_path_buf()];
    while let Some(dir) = stack.pop() {
        for e in std::fs::read_dir(&dir).expect("readable") {
            let p = e.expect("an entry").path();
            if p.is_dir() {
                stack.push(p);
            } else if p.extension().is_some_and(|x| x == "rs")
                && p.file_name()
                    .is_some_and(|n| n != "tests.rs" && !n.to_string_lossy().ends_with("_tests.rs"))
            {
                found.push(p);
            }
        }
    }
    found
        .into_iter()
        .filter(|p| !order.iter().any(|m| file_of(root, m) == *p))
        .map(|p| p.display().to_string())
        .collect()
}

#[test]
fn the_parallel_scan_s_modules_use_only_the_ones_below_them() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("crates/plc-exec/src/parallel");
    assert_eq!(unlisted(&root, PARALLEL), Vec::<String>::new());
    assert_eq!(
        upward_uses(&root, PARALLEL, "crate::parallel::"),
        Vec::<String>::new()
    );
}

#[test]
fn run_s_modules_use_only_the_ones_below_them() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("src/cmd/run");
    assert_eq!(unlisted(&root, RUN), Vec::<String>::new());
    assert_eq!(
        upward_uses(&root, RUN, "crate::cmd::run::"),
        Vec::<String>::new()
    );
}

/// The check finds an upward use: a file that names a module above it is reported.
#[test]
fn an_upward_use_is_found() {
    let paths = named_paths(
        "use super::{plan::Plan, ready};\nlet x = super::super::choice::Chooser::new();",
        &["planning", "tasks"],
        "crate::parallel::",
    );
    let used: Vec<usize> = paths.iter().map(|p| module_of(PARALLEL, p)).collect();
    let names: Vec<&[&str]> = used.iter().map(|&i| PARALLEL[i]).collect();
    assert_eq!(
        names,
        vec![
            &["planning", "plan"][..],
            &["planning", "ready"][..],
            &["choice"][..]
        ]
    );
    let tasks = PARALLEL
        .iter()
        .position(|m| *m == ["planning", "tasks"])
        .unwrap();
    assert!(used.iter().all(|&u| u > tasks));
}
