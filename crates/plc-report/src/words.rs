//! Numbers in words, the same in every renderer: `12,345` (thousands separated by commas) and
//! `1 rung` / `2 rungs`. Below the document and every renderer, so that the configuration's
//! sentences and the text, DOT and HTML renderers share them without importing one another.

/// `12345` → `12,345`.
pub fn thousands(n: usize) -> String {
    let s = n.to_string();
    let mut out = String::new();
    for (i, c) in s.chars().enumerate() {
        if i > 0 && (s.len() - i).is_multiple_of(3) {
            out.push(',');
        }
        out.push(c);
    }
    out
}

/// `1 rung`, `2 rungs`.
pub(crate) fn plural(n: usize, one: &str, many: &str) -> String {
    format!("{} {}", thousands(n), if n == 1 { one } else { many })
}
