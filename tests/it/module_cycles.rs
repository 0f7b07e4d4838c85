//! No import cycle between sibling modules of any crate of the repository: if `a` refers to its
//! sibling `b` (`use crate::b::…`, `crate::b::…`, `super::b::…` in `a` or any module below it),
//! `b` must not refer back to `a`. The lower module of two must not know the higher one.
//!
//! The scan is plain text, on purpose (no parser dependency): crates are found by their
//! `Cargo.toml` under the repository root (not under `target/`, `fuzz/` or hidden folders), and
//! each crate root (`src/lib.rs`, `src/main.rs`, `src/bin/*.rs`) is followed through its
//! `mod name;` declarations to every module file. Comments, string and character literals are
//! blanked first; test code is left out: `#[cfg(test)]` items (`mod tests;` files, `use`s,
//! functions), `mod tests { … }` blocks, and files named `tests.rs` or `*_tests.rs`. Every
//! reference that starts with `crate::`, `super::` or `self::` is made absolute and cut to the
//! longest prefix that is a module file; a reference from module `p::a::…` to `p::b::…` is an
//! edge `a → b` among the children of `p`. Sibling graphs are checked for the top-level modules
//! of a crate and for the children of each top-level module (deeper levels are not checked).
//!
//! A reference to a module's re-export is followed to where the item comes from
//! (`crate::analysis::Cfg`, re-exported from `analysis::cfg`, is a reference to `analysis::cfg`):
//! a `pub use` by name or rename, or a glob over a module that declares the name (`fn`,
//! `struct`, … or the last argument of a macro call such as `index_type!(… Name);`). What a text
//! scan cannot see: items made by other macros, paths written inside macros other than as plain
//! paths, and inline non-test `mod x { … }` blocks (their text counts as their file's).
//! Another crate of the workspace is reached by its crate name, never by `crate::`, so links
//! between crates are not edges here (Cargo already refuses cycles between crates).

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};

/// A module of a crate: its path from the crate root (empty for the root) and its file.
struct Module {
    path: Vec<String>,
    file: PathBuf,
    /// The file's text with comments, literals and test code blanked (lines kept).
    text: String,
    /// Whether its own child modules live in its folder (`mod.rs`, `lib.rs`, `main.rs`) rather
    /// than in a folder named after it.
    owns_folder: bool,
}

/// A reference of one module to another: the place that shows it.
#[derive(Clone, Debug)]
struct Evidence {
    file: PathBuf,
    line: usize,
}

/// A cycle among the children of `parent`: `members[0] → members[1] → … → members[0]`, each
/// step with the place of one reference.
#[derive(Debug)]
struct Cycle {
    parent: Vec<String>,
    members: Vec<String>,
    evidence: Vec<Evidence>,
}

impl Cycle {
    /// `a::b → a::c → a::b` with the references' places.
    fn describe(&self, root: &Path) -> String {
        let name = |m: &str| {
            let mut p = self.parent.clone();
            p.push(m.to_string());
            p.join("::")
        };
        let mut s = name(&self.members[0]);
        for (i, e) in self.evidence.iter().enumerate() {
            let next = &self.members[(i + 1) % self.members.len()];
            let file = e.file.strip_prefix(root).unwrap_or(&e.file);
            s += &format!(" → {} ({}:{})", name(next), file.display(), e.line);
        }
        s
    }
}

/// The repository root: the outermost folder with a `Cargo.toml` above this package, not
/// leaving the git checkout (the folder with `.git`).
fn repo_root() -> PathBuf {
    let here = PathBuf::from(env!("CARGO_MANIFEST_DIR"));
    let mut root = here.clone();
    for dir in here.ancestors() {
        if dir.join("Cargo.toml").is_file() {
            root = dir.to_path_buf();
        }
        if dir.join(".git").exists() {
            break;
        }
    }
    root
}

/// The folders holding a `Cargo.toml` under `root` (itself included), sorted; `target`,
/// `fuzz` and hidden folders are not searched.
fn crate_dirs(root: &Path) -> Vec<PathBuf> {
    let mut out = Vec::new();
    let mut todo = vec![root.to_path_buf()];
    while let Some(dir) = todo.pop() {
        if dir.join("Cargo.toml").is_file() {
            out.push(dir.clone());
        }
        let Ok(entries) = std::fs::read_dir(&dir) else {
            continue;
        };
        for e in entries.flatten() {
            let name = e.file_name().to_string_lossy().into_owned();
            let skip = name.starts_with('.') || name == "target" || name == "fuzz";
            if !skip && e.file_type().is_ok_and(|t| t.is_dir()) {
                todo.push(e.path());
            }
        }
    }
    out.sort();
    out
}

/// The crate root files of the package in `dir`: its library, its binary, `src/bin/*.rs`, and
/// any other `path = "…"` of its manifest's `[lib]` and `[[bin]]` sections.
fn crate_roots(dir: &Path) -> Vec<PathBuf> {
    let src = dir.join("src");
    let mut roots: Vec<PathBuf> = ["lib.rs", "main.rs"]
        .iter()
        .map(|f| src.join(f))
        .filter(|p| p.is_file())
        .collect();
    if let Ok(entries) = std::fs::read_dir(src.join("bin")) {
        let mut bins: Vec<PathBuf> = entries
            .flatten()
            .map(|e| e.path())
            .filter(|p| p.extension().is_some_and(|x| x == "rs"))
            .collect();
        bins.sort();
        roots.extend(bins);
    }
    let manifest = std::fs::read_to_string(dir.join("Cargo.toml")).unwrap_or_default();
    let mut section = "";
    for line in manifest.lines().map(str::trim) {
        if line.starts_with('[') {
            section = line;
        } else if section == "[lib]" || section == "[[bin]]" {
            let value = line
                .strip_prefix("path")
                .and_then(|v| v.trim_start().strip_prefix('='))
                .map(|v| v.trim().trim_matches('"'));
            if let Some(path) = value.map(|v| dir.join(v)) {
                if path.is_file()
                    && !roots
                        .iter()
                        .any(|r| r.ends_with(path.strip_prefix(dir).unwrap()))
                {
                    roots.push(path);
                }
            }
        }
    }
    roots
}

fn is_ident(c: char) -> bool {
    c.is_alphanumeric() || c == '_'
}

/// `text` with comments (nested block comments too), string literals (raw and byte ones too)
/// and character literals replaced by spaces; line breaks are kept, so lines still count.
fn blank_comments_and_literals(text: &str) -> String {
    let c: Vec<char> = text.chars().collect();
    let mut out = String::with_capacity(text.len());
    let blank = |out: &mut String, ch: char| out.push(if ch == '\n' { '\n' } else { ' ' });
    let mut i = 0;
    while i < c.len() {
        let prev_ident = i > 0 && is_ident(c[i - 1]);
        if c[i] == '/' && c.get(i + 1) == Some(&'/') {
            while i < c.len() && c[i] != '\n' {
                i += 1;
            }
        } else if c[i] == '/' && c.get(i + 1) == Some(&'*') {
            let mut depth = 0;
            while i < c.len() {
                if c[i] == '/' && c.get(i + 1) == Some(&'*') {
                    depth += 1;
                    out.push_str("  ");
                    i += 2;
                } else if c[i] == '*' && c.get(i + 1) == Some(&'/') {
                    depth -= 1;
                    out.push_str("  ");
                    i += 2;
                    if depth == 0 {
                        break;
                    }
                } else {
                    blank(&mut out, c[i]);
                    i += 1;
                }
            }
        } else if !prev_ident && (c[i] == 'r' || (c[i] == 'b' && c.get(i + 1) == Some(&'r'))) && {
            let mut j = i + if c[i] == 'b' { 2 } else { 1 };
            while c.get(j) == Some(&'#') {
                j += 1;
            }
            c.get(j) == Some(&'"')
        } {
            // A raw string: r"…", r#"…"#, br"…".
            let mut j = i + if c[i] == 'b' { 2 } else { 1 };
            let mut hashes = 0;
            while c[j] == '#' {
                hashes += 1;
                j += 1;
            }
            j += 1;
            while j < c.len() {
                if c[j] == '"' && (1..=hashes).all(|k| c.get(j + k) == Some(&'#')) {
                    j += 1 + hashes;
                    break;
                }
                j += 1;
            }
            for &ch in &c[i..j.min(c.len())] {
                blank(&mut out, ch);
            }
            i = j;
        } else if c[i] == '"' {
            let mut j = i + 1;
            while j < c.len() && c[j] != '"' {
                j += if c[j] == '\\' { 2 } else { 1 };
            }
            for &ch in &c[i..(j + 1).min(c.len())] {
                blank(&mut out, ch);
            }
            i = j + 1;
        } else if c[i] == '\'' {
            // A character literal ('x', '\n', '\u{…}') or a lifetime ('a): only the first ends
            // in a quote right after its character or escape.
            let end = if c.get(i + 1) == Some(&'\\') {
                (i + 3..c.len()).find(|&j| c[j] == '\'')
            } else if c.get(i + 2) == Some(&'\'') {
                Some(i + 2)
            } else {
                None
            };
            match end {
                Some(j) => {
                    for &ch in &c[i..=j] {
                        blank(&mut out, ch);
                    }
                    i = j + 1;
                }
                None => {
                    out.push('\'');
                    i += 1;
                }
            }
        } else {
            out.push(c[i]);
            i += 1;
        }
    }
    out
}

/// The index just past the item that starts at `from` in cleaned text `c`: at the first `;` or
/// at the `}` closing its first block, outside brackets.
fn item_end(c: &[char], from: usize) -> usize {
    let mut depth = 0i32;
    let mut i = from;
    while i < c.len() {
        match c[i] {
            '(' | '[' | '{' => depth += 1,
            ')' | ']' => depth -= 1,
            '}' => {
                depth -= 1;
                if depth == 0 {
                    return i + 1;
                }
            }
            ';' if depth == 0 => return i + 1,
            _ => {}
        }
        i += 1;
    }
    c.len()
}

/// The index just past the attribute `#[…]` that starts at `from`.
fn attribute_end(c: &[char], from: usize) -> usize {
    let mut depth = 0i32;
    for (i, &ch) in c.iter().enumerate().skip(from) {
        match ch {
            '[' => depth += 1,
            ']' => {
                depth -= 1;
                if depth == 0 {
                    return i + 1;
                }
            }
            _ => {}
        }
    }
    c.len()
}

/// Whether the cleaned text `c` has the word `word` at `i` (not inside a longer identifier).
fn word_at(c: &[char], i: usize, word: &str) -> bool {
    let n = word.len(); // the words looked for are ASCII
    c.get(i..i + n)
        .is_some_and(|s| s.iter().copied().eq(word.chars()))
        && (i == 0 || !is_ident(c[i - 1]))
        && c.get(i + n).is_none_or(|&ch| !is_ident(ch))
}

/// Skips spaces from `i`.
fn skip_space(c: &[char], mut i: usize) -> usize {
    while i < c.len() && c[i].is_whitespace() {
        i += 1;
    }
    i
}

/// Cleaned text with test code blanked: every item after `#[cfg(test)]` and every
/// `mod tests { … }` block.
fn blank_tests(text: &str) -> String {
    let mut c: Vec<char> = text.chars().collect();
    let attr: Vec<char> = "#[cfg(test)]".chars().collect();
    let mut i = 0;
    while i < c.len() {
        let start = i;
        let end = if c[i..].starts_with(&attr) {
            // The attribute, any further attributes, then the item.
            let mut j = skip_space(&c, i + attr.len());
            while c.get(j) == Some(&'#') {
                j = skip_space(&c, attribute_end(&c, j));
            }
            Some(item_end(&c, j))
        } else if word_at(&c, i, "mod") {
            let j = skip_space(&c, i + 3);
            let k = skip_space(&c, j + 5);
            (word_at(&c, j, "tests") && c.get(k) == Some(&'{')).then(|| item_end(&c, i))
        } else {
            None
        };
        match end {
            Some(end) => {
                for ch in &mut c[start..end] {
                    if *ch != '\n' {
                        *ch = ' ';
                    }
                }
                i = end;
            }
            None => i += 1,
        }
    }
    c.into_iter().collect()
}

/// The file's text as the scan reads it (comments, literals and test code blanked).
fn scan_text(file: &Path) -> String {
    let raw = std::fs::read_to_string(file).unwrap_or_else(|e| panic!("{}: {e}", file.display()));
    blank_tests(&blank_comments_and_literals(&raw))
}

/// The `mod name;` declarations of a cleaned text, outside any block.
fn declared_modules(text: &str) -> Vec<String> {
    let c: Vec<char> = text.chars().collect();
    let mut out = Vec::new();
    let mut depth = 0i32;
    let mut i = 0;
    while i < c.len() {
        match c[i] {
            '{' => depth += 1,
            '}' => depth -= 1,
            _ if depth == 0 && word_at(&c, i, "mod") => {
                let j = skip_space(&c, i + 3);
                let k = (j..c.len()).find(|&k| !is_ident(c[k])).unwrap_or(c.len());
                if k > j && c.get(skip_space(&c, k)) == Some(&';') {
                    out.push(c[j..k].iter().collect());
                }
            }
            _ => {}
        }
        i += 1;
    }
    out
}

/// Every module of the crate rooted at `root_file`, through its `mod` declarations; test files
/// (`tests.rs`, `*_tests.rs`) are left out.
fn crate_modules(root_file: &Path) -> Vec<Module> {
    let mut out = Vec::new();
    let mut todo = vec![Module {
        path: Vec::new(),
        file: root_file.to_path_buf(),
        text: scan_text(root_file),
        owns_folder: true,
    }];
    while let Some(m) = todo.pop() {
        let dir = if m.owns_folder {
            m.file.parent().unwrap().to_path_buf()
        } else {
            m.file.with_extension("")
        };
        for name in declared_modules(&m.text) {
            if name == "tests" || name.ends_with("_tests") {
                continue;
            }
            let flat = dir.join(format!("{name}.rs"));
            let nested = dir.join(&name).join("mod.rs");
            let (file, owns_folder) = if flat.is_file() {
                (flat, false)
            } else if nested.is_file() {
                (nested, true)
            } else {
                continue;
            };
            let mut path = m.path.clone();
            path.push(name);
            todo.push(Module {
                path,
                text: scan_text(&file),
                file,
                owns_folder,
            });
        }
        out.push(m);
    }
    out.sort_by(|a, b| a.path.cmp(&b.path));
    out
}

/// A path of a `use` tree and the name it brings in when renamed (`as name`).
type UsePath = (Vec<String>, Option<String>);

/// The paths of a `use` tree (`a::{b, c::{d, e}}` → `a::b`, `a::c::d`, `a::c::e`), as
/// segments; `self` inside braces names the prefix itself.
fn use_tree_paths(tree: &str) -> Vec<UsePath> {
    fn walk(c: &[char], i: &mut usize, prefix: &[String], out: &mut Vec<UsePath>) {
        let mut path = prefix.to_vec();
        loop {
            *i = skip_space(c, *i);
            match c.get(*i) {
                Some('{') => {
                    *i += 1;
                    loop {
                        walk(c, i, &path, out);
                        *i = skip_space(c, *i);
                        match c.get(*i) {
                            Some(',') => *i += 1,
                            Some('}') => {
                                *i += 1;
                                return;
                            }
                            _ => return,
                        }
                        if c.get(skip_space(c, *i)) == Some(&'}') {
                            *i = skip_space(c, *i) + 1;
                            return;
                        }
                    }
                }
                Some(ch) if is_ident(*ch) || *ch == '*' || *ch == '$' => {
                    let j = (*i + 1..c.len())
                        .find(|&k| !is_ident(c[k]))
                        .unwrap_or(c.len());
                    let seg: String = c[*i..j].iter().collect();
                    *i = skip_space(c, j);
                    if seg == "as" {
                        // `x as y`: the rename ends the path.
                        let k = (*i..c.len()).find(|&k| !is_ident(c[k])).unwrap_or(c.len());
                        let alias: String = c[*i..k].iter().collect();
                        *i = k;
                        out.push((path, Some(alias)));
                        return;
                    }
                    if seg != "self" || path.is_empty() {
                        path.push(seg);
                    }
                    if c.get(*i) == Some(&':') && c.get(*i + 1) == Some(&':') {
                        *i += 2;
                        continue;
                    }
                    // `x as y` after the last segment.
                    if word_at(c, *i, "as") {
                        continue;
                    }
                    out.push((path, None));
                    return;
                }
                _ => {
                    if !path.is_empty() {
                        out.push((path, None));
                    }
                    return;
                }
            }
        }
    }
    let c: Vec<char> = tree.chars().collect();
    let mut out = Vec::new();
    let mut i = 0;
    walk(&c, &mut i, &[], &mut out);
    out
}

/// The paths that a cleaned text refers to, each with its line: the trees of `use` items and
/// every path in code that starts with `crate`, `$crate`, `super` or `self` followed by `::`.
fn referenced_paths(text: &str) -> Vec<(Vec<String>, usize)> {
    let c: Vec<char> = text.chars().collect();
    // Line of each character, 1-based.
    let mut lines = Vec::with_capacity(c.len());
    let mut line = 1;
    for &ch in &c {
        lines.push(line);
        line += usize::from(ch == '\n');
    }
    let line_at = |i: usize| lines[i];
    let mut out = Vec::new();
    let mut i = 0;
    while i < c.len() {
        if word_at(&c, i, "use") {
            let end = item_end(&c, i);
            let tree: String = c[i + 3..end].iter().filter(|&&ch| ch != ';').collect();
            for (p, _) in use_tree_paths(&tree) {
                out.push((p, line_at(i)));
            }
            i = end;
            continue;
        }
        let starts = ["crate", "super", "self"].iter().any(|w| word_at(&c, i, w))
            && (i == 0 || c[i - 1] != ':');
        if starts {
            let line = line_at(i);
            let mut path = Vec::new();
            let mut j = i;
            loop {
                let k = (j..c.len()).find(|&k| !is_ident(c[k])).unwrap_or(c.len());
                if k == j {
                    break;
                }
                path.push(c[j..k].iter().collect::<String>());
                let after = skip_space(&c, k);
                if c.get(after) == Some(&':') && c.get(after + 1) == Some(&':') {
                    j = skip_space(&c, after + 2);
                } else {
                    j = k;
                    break;
                }
            }
            if path.len() > 1 {
                out.push((path, line));
            }
            i = j.max(i + 1);
            continue;
        }
        i += 1;
    }
    out
}

/// Whether the `use` at `i` of cleaned text `c` is a re-export: `pub`, `pub(crate)`,
/// `pub(super)` or `pub(in …)` before it.
fn is_reexport(c: &[char], i: usize) -> bool {
    let mut j = i;
    while j > 0 && c[j - 1].is_whitespace() {
        j -= 1;
    }
    if j > 0 && c[j - 1] == ')' {
        while j > 0 && c[j - 1] != '(' {
            j -= 1;
        }
        j = j.saturating_sub(1);
        while j > 0 && c[j - 1].is_whitespace() {
            j -= 1;
        }
    }
    j >= 3 && word_at(c, j - 3, "pub")
}

/// The re-exports of a cleaned text: each path as written and the name it is known by here
/// (its rename, or its last segment; `*` for a glob).
fn reexports(text: &str) -> Vec<(Vec<String>, String)> {
    let c: Vec<char> = text.chars().collect();
    let mut out = Vec::new();
    let mut i = 0;
    while i < c.len() {
        if word_at(&c, i, "use") && is_reexport(&c, i) {
            let end = item_end(&c, i);
            let tree: String = c[i + 3..end].iter().filter(|&&ch| ch != ';').collect();
            for (path, alias) in use_tree_paths(&tree) {
                let name = alias.unwrap_or_else(|| path.last().cloned().unwrap_or_default());
                out.push((path, name));
            }
            i = end;
        } else {
            i += 1;
        }
    }
    out
}

/// Whether cleaned text declares an item `name` itself: `fn`, `struct`, `enum`, `const`,
/// `static`, `type`, `trait`, `union`, `mod` or `macro_rules!` with that name, or a macro call
/// whose last argument it is (`index_type!(… Name);`, the way the crate declares its ids).
fn declares(text: &str, name: &str) -> bool {
    let c: Vec<char> = text.chars().collect();
    let keywords = [
        "fn",
        "struct",
        "enum",
        "const",
        "static",
        "type",
        "trait",
        "union",
        "mod",
        "macro_rules!",
    ];
    (0..c.len()).any(|i| {
        if !word_at(&c, i, name) {
            return false;
        }
        let mut j = i;
        while j > 0 && c[j - 1].is_whitespace() {
            j -= 1;
        }
        let before: String = c[j.saturating_sub(12)..j].iter().collect();
        let declared = keywords.iter().any(|k| {
            before.ends_with(k) && {
                let at = j - k.chars().count();
                at == 0 || !is_ident(c[at - 1])
            }
        });
        let after = skip_space(&c, i + name.chars().count());
        declared || (c.get(after) == Some(&')') && c.get(skip_space(&c, after + 1)) == Some(&';'))
    })
}

/// The absolute module path (segments from the crate root) of `path` written in module
/// `here`; `None` for a path into another crate (or one this scan does not follow).
fn absolute(here: &[String], path: &[String]) -> Option<Vec<String>> {
    let mut segs = path.iter().map(String::as_str).peekable();
    let mut base: Vec<String> = match segs.peek().copied() {
        Some("crate") | Some("$crate") => {
            segs.next();
            Vec::new()
        }
        Some("self") => {
            segs.next();
            here.to_vec()
        }
        Some("super") => here.to_vec(),
        _ => return None,
    };
    while segs.peek() == Some(&"super") {
        segs.next();
        base.pop()?;
    }
    base.extend(segs.map(String::from));
    Some(base)
}

/// The sibling cycles of one crate: per parent module (the root and each top-level module), the
/// strongly connected groups of its children under "refers to", each as one cycle through them.
fn crate_cycles(root_file: &Path) -> Vec<Cycle> {
    let modules = crate_modules(root_file);
    let known: BTreeSet<&[String]> = modules.iter().map(|m| &m.path[..]).collect();
    let text_of: BTreeMap<&[String], &str> = modules
        .iter()
        .map(|m| (&m.path[..], m.text.as_str()))
        .collect();
    // Per module, its re-exports as (absolute path, name): a bare first segment is a child.
    let exports: BTreeMap<&[String], Vec<(Vec<String>, String)>> = modules
        .iter()
        .map(|m| {
            let list = reexports(&m.text)
                .into_iter()
                .filter_map(|(path, name)| {
                    let child = [&m.path[..], &path[..1]].concat();
                    let target = match absolute(&m.path, &path) {
                        Some(t) => t,
                        None if known.contains(&child[..]) => [&m.path[..], &path[..]].concat(),
                        None => return None,
                    };
                    Some((target, name))
                })
                .collect();
            (&m.path[..], list)
        })
        .collect();
    let module_part = |t: &[String]| {
        let mut k = t.len();
        while k > 0 && !known.contains(&t[..k]) {
            k -= 1;
        }
        k
    };
    // Follows re-exports: `a::Name` re-exported by `a` from `a::b` (by name or by a glob over
    // a module that declares it) is `a::b::Name`. Gives the module the path ends in.
    let resolve = |mut t: Vec<String>| -> Vec<String> {
        for _ in 0..8 {
            let k = module_part(&t);
            if k == t.len() {
                break;
            }
            let (module, name) = (&t[..k], &t[k]);
            if declares(text_of[module], name) {
                break;
            }
            let named = exports[module].iter().find(|(_, n)| n == name);
            let next = if let Some((target, _)) = named {
                Some([&target[..], &t[k + 1..]].concat())
            } else {
                exports[module]
                    .iter()
                    .filter(|(_, n)| n == "*")
                    .map(|(target, _)| &target[..module_part(target)])
                    .find(|q| {
                        *q != module
                            && (declares(text_of[q], name)
                                || exports[q].iter().any(|(_, n)| n == name))
                    })
                    .map(|q| [q, &t[k..]].concat())
            };
            match next {
                Some(next) if next != t => t = next,
                _ => break,
            }
        }
        let k = module_part(&t);
        t.truncate(k);
        t
    };
    // parent → (from child, to child) → first evidence.
    let mut graphs: BTreeMap<Vec<String>, BTreeMap<(String, String), Evidence>> = BTreeMap::new();
    for m in &modules {
        for (path, line) in referenced_paths(&m.text) {
            let Some(target) = absolute(&m.path, &path) else {
                continue;
            };
            let target = resolve(target);
            let common = m
                .path
                .iter()
                .zip(&target)
                .take_while(|(a, b)| a == b)
                .count();
            if common >= 2 || common >= m.path.len() || common >= target.len() {
                continue;
            }
            graphs
                .entry(m.path[..common].to_vec())
                .or_default()
                .entry((m.path[common].clone(), target[common].clone()))
                .or_insert(Evidence {
                    file: m.file.clone(),
                    line,
                });
        }
    }
    let mut cycles = Vec::new();
    for (parent, edges) in graphs {
        for group in strongly_connected(&edges) {
            for members in cycles_in(&group, &edges) {
                let evidence = (0..members.len())
                    .map(|i| {
                        let key = (members[i].clone(), members[(i + 1) % members.len()].clone());
                        edges[&key].clone()
                    })
                    .collect();
                cycles.push(Cycle {
                    parent: parent.clone(),
                    members,
                    evidence,
                });
            }
        }
    }
    cycles
}

/// The groups of two or more nodes that reach one another (sorted), by petgraph's Tarjan.
fn strongly_connected(edges: &BTreeMap<(String, String), Evidence>) -> Vec<Vec<String>> {
    let mut g = petgraph::graph::DiGraph::<String, ()>::new();
    let mut index = BTreeMap::new();
    for (a, b) in edges.keys() {
        for n in [a, b] {
            if !index.contains_key(n) {
                index.insert(n.clone(), g.add_node(n.clone()));
            }
        }
        g.add_edge(index[a], index[b], ());
    }
    let mut groups: Vec<Vec<String>> = petgraph::algo::tarjan_scc(&g)
        .into_iter()
        .filter(|c| c.len() > 1)
        .map(|c| {
            let mut names: Vec<String> = c.iter().map(|&n| g[n].clone()).collect();
            names.sort();
            names
        })
        .collect();
    groups.sort();
    groups
}

/// The cycles of a strongly connected `group` that name every reference in it: for each edge
/// `a → b` inside the group, `a` then the shortest way from `b` back to `a` (breadth first,
/// inside the group); each cycle once, starting at its smallest member.
fn cycles_in(group: &[String], edges: &BTreeMap<(String, String), Evidence>) -> Vec<Vec<String>> {
    let inside = |n: &String| group.contains(n);
    let mut out: BTreeSet<Vec<String>> = BTreeSet::new();
    for (a, b) in edges.keys().filter(|(a, b)| inside(a) && inside(b)) {
        // Breadth first from `b` to `a`.
        let mut came_from: BTreeMap<&String, &String> = BTreeMap::new();
        let mut queue = std::collections::VecDeque::from([b]);
        while let Some(n) = queue.pop_front() {
            if n == a {
                break;
            }
            for (x, y) in edges.keys() {
                if x == n && inside(y) && y != b && !came_from.contains_key(y) {
                    came_from.insert(y, n);
                    queue.push_back(y);
                }
            }
        }
        // a, b, …, (back to a).
        let mut back = Vec::new();
        let mut at = a;
        while at != b {
            at = came_from[at];
            back.push(at.clone());
        }
        back.reverse();
        let mut cycle = vec![a.clone()];
        cycle.extend(back);
        let first = (0..cycle.len()).min_by_key(|&i| &cycle[i]).unwrap();
        cycle.rotate_left(first);
        out.insert(cycle);
    }
    out.into_iter().collect()
}

/// Every sibling cycle of every crate under `root`, described.
fn repository_cycles(root: &Path) -> Vec<String> {
    let mut out = Vec::new();
    for dir in crate_dirs(root) {
        for root_file in crate_roots(&dir) {
            for cycle in crate_cycles(&root_file) {
                let crate_name = root_file.strip_prefix(root).unwrap_or(&root_file);
                out.push(format!(
                    "{}: {}",
                    crate_name.display(),
                    cycle.describe(root)
                ));
            }
        }
    }
    out
}

#[test]
fn no_import_cycle_between_sibling_modules() {
    let root = repo_root();
    let crates: usize = crate_dirs(&root).iter().map(|d| crate_roots(d).len()).sum();
    assert!(crates >= 1, "no crate found under {}", root.display());
    let cycles = repository_cycles(&root);
    assert!(
        cycles.is_empty(),
        "{} import cycle(s) between sibling modules (the lower module must not refer to the \
         higher one; move what they share down):\n{}",
        cycles.len(),
        cycles.join("\n")
    );
}

/// A scratch crate: `files` as (path under the folder, text).
fn scratch_crate(tag: &str, files: &[(&str, &str)]) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("plc-module-cycles-{}-{tag}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    for (path, text) in files {
        let file = dir.join(path);
        std::fs::create_dir_all(file.parent().unwrap()).unwrap();
        std::fs::write(file, text).unwrap();
    }
    dir
}

#[test]
fn the_scan_finds_cycles_by_use_path_and_super_and_names_them() {
    let dir = scratch_crate(
        "found",
        &[
            ("Cargo.toml", "[package]\nname = \"x\"\n"),
            ("src/lib.rs", "pub mod a;\npub mod b;\nmod c;\n"),
            ("src/a.rs", "use crate::{b::Thing, c};\npub fn f() {}\n"),
            (
                "src/b.rs",
                "pub struct Thing;\nfn g() {\n    super::a::f()\n}\n",
            ),
            ("src/c/mod.rs", "mod x;\nmod y;\npub use x::X;\n"),
            (
                "src/c/x.rs",
                "pub struct X;\nfn h() -> super::y::Y { todo!() }\n",
            ),
            (
                "src/c/y.rs",
                "pub struct Y;\nconst S: &str = \"super::x::X\";\n\
                 fn k() -> crate::c::x::X { todo!() }\n",
            ),
        ],
    );
    let cycles: Vec<String> = crate_cycles(&dir.join("src/lib.rs"))
        .iter()
        .map(|c| c.describe(&dir))
        .collect();
    assert_eq!(
        cycles,
        vec![
            "a → b (src/a.rs:1) → a (src/b.rs:3)".to_string(),
            "c::x → c::y (src/c/x.rs:2) → c::x (src/c/y.rs:3)".to_string(),
        ]
    );
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn the_scan_follows_reexports_of_the_parent() {
    let dir = scratch_crate(
        "reexports",
        &[
            ("Cargo.toml", "[package]\nname = \"x\"\n"),
            ("src/lib.rs", "mod p;\n"),
            (
                "src/p/mod.rs",
                "mod x;\nmod y;\nmod z;\npub use x::Thing as Renamed;\npub(crate) use y::*;\n\
                 pub fn own() {}\n",
            ),
            // x reaches y through the parent's glob, y reaches x through the parent's rename.
            (
                "src/p/x.rs",
                "pub struct Thing;\nfn f(_: super::Other) {}\n",
            ),
            (
                "src/p/y.rs",
                "pub struct Other;\nuse super::{own, Renamed};\nfn g() { own() }\n",
            ),
            // Only what the parent declares itself: no edge.
            ("src/p/z.rs", "fn h() { super::own() }\n"),
        ],
    );
    let cycles: Vec<String> = crate_cycles(&dir.join("src/lib.rs"))
        .iter()
        .map(|c| c.describe(&dir))
        .collect();
    assert_eq!(
        cycles,
        vec!["p::x → p::y (src/p/x.rs:2) → p::x (src/p/y.rs:2)"]
    );
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn the_scan_ignores_comments_strings_and_test_code() {
    let dir = scratch_crate(
        "ignored",
        &[
            ("Cargo.toml", "[package]\nname = \"x\"\n"),
            ("src/lib.rs", "pub mod a;\npub mod b;\n"),
            ("src/a.rs", "use crate::b::Thing;\n#[cfg(test)]\nmod tests;\n"),
            // The way back is only in tests, comments, strings and a `*_tests.rs` file.
            (
                "src/b.rs",
                "pub struct Thing;\n// use crate::a;\n/* super::a::f() /* nested */ */\n\
                 const S: &str = r#\"crate::a\"#;\nconst C: char = '\\'';\n\
                 fn l<'a>(x: &'a str) -> &'a str { x }\n\
                 #[cfg(test)]\nuse crate::a::f;\n#[cfg(test)]\n#[allow(unused)]\nfn t() { super::a::f() }\n\
                 mod tests {\n    use super::super::a;\n}\n#[cfg(test)]\nmod b_tests;\n",
            ),
            ("src/a/tests.rs", "use crate::b::Thing;\n"),
            ("src/b/b_tests.rs", "use crate::a::f;\n"),
        ],
    );
    let cycles: Vec<String> = crate_cycles(&dir.join("src/lib.rs"))
        .iter()
        .map(|c| c.describe(&dir))
        .collect();
    assert_eq!(cycles, Vec::<String>::new());
    // And a reference outside test code is found.
    std::fs::write(
        dir.join("src/b.rs"),
        "pub struct Thing;\nuse crate::a as up;\n",
    )
    .unwrap();
    let cycles: Vec<String> = crate_cycles(&dir.join("src/lib.rs"))
        .iter()
        .map(|c| c.describe(&dir))
        .collect();
    assert_eq!(cycles, vec!["a → b (src/a.rs:1) → a (src/b.rs:2)"]);
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn crates_are_found_by_manifest_outside_target_and_fuzz() {
    let dir = scratch_crate(
        "workspace",
        &[
            ("Cargo.toml", "[workspace]\n"),
            ("crates/one/Cargo.toml", "[package]\nname = \"one\"\n"),
            ("crates/one/src/lib.rs", "mod a;\n"),
            ("crates/one/src/a.rs", ""),
            (
                "crates/two/Cargo.toml",
                "[package]\nname = \"two\"\n[[bin]]\nname = \"t\"\npath = \"src/main.rs\"\n\
                 [lib]\npath = \"lib/two.rs\"\n[[bench]]\nname = \"b\"\npath = \"benches/b.rs\"\n",
            ),
            ("crates/two/src/main.rs", "fn main() {}\n"),
            ("crates/two/lib/two.rs", ""),
            ("crates/two/benches/b.rs", ""),
            ("fuzz/Cargo.toml", "[package]\nname = \"fuzz\"\n"),
            ("target/x/Cargo.toml", "[package]\nname = \"built\"\n"),
        ],
    );
    let found: Vec<PathBuf> = crate_dirs(&dir)
        .iter()
        .flat_map(|d| crate_roots(d))
        .map(|p| p.strip_prefix(&dir).unwrap().to_path_buf())
        .collect();
    assert_eq!(
        found,
        vec![
            PathBuf::from("crates/one/src/lib.rs"),
            PathBuf::from("crates/two/src/main.rs"),
            PathBuf::from("crates/two/lib/two.rs")
        ]
    );
    let _ = std::fs::remove_dir_all(&dir);
}
