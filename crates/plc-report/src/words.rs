//! Numbers in words, the same in every renderer: `12,345` (thousands separated by commas),
//! `1 rung` / `2 rungs`, and the share of scan cycles a schedule saves (`99.8 %`). Below the document and every renderer, so that the configuration's
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

/// The share of `before` scan cycles that a schedule of `after` cycles saves, rounded to a
/// whole percent, except that a saving short of all of them is never shown as `100 %` (6 cycles
/// out of 3,019 is `99.8 %`); `0 %` when there is nothing to save.
pub(crate) fn saved_percent(before: usize, after: usize) -> String {
    if before == 0 {
        return "0 %".to_string();
    }
    let saved = (before - after.min(before)) as f64 / before as f64 * 100.0;
    if saved.round() >= 100.0 && after > 0 {
        format!("{:.1} %", (saved * 10.0).floor() / 10.0)
    } else {
        format!("{saved:.0} %")
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_saving_short_of_all_is_never_100_percent() {
        assert_eq!(saved_percent(3019, 6), "99.8 %");
        assert_eq!(saved_percent(5000, 20), "99.6 %");
        assert_eq!(saved_percent(100_000, 1), "99.9 %");
        assert_eq!(saved_percent(10, 0), "100 %");
        assert_eq!(saved_percent(10, 5), "50 %");
        assert_eq!(saved_percent(3, 2), "33 %");
        assert_eq!(saved_percent(0, 0), "0 %");
    }
}
