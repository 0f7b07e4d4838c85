//! "Did you mean …?": the declared name nearest to a misspelt one.
//!
//! The distance is the optimal string alignment distance (Levenshtein 1966: insertions,
//! deletions and substitutions; Damerau 1964: a transposition of two neighbours, the commonest
//! slip of typing; each 1), computed without regard to case (IEC 61131-3 §6.1.2: identifiers are not case
//! sensitive, so `count` for `Count` is distance 0 and worth saying). A candidate is offered
//! only when it is close: at most a third of the name's length (at least 1; 0 for a name of
//! one character, where any other letter would be as near). Ties go to the
//! first candidate in the order given. It does not look names up: the caller passes the names
//! in scope.

/// `did you mean `X`?` for the candidate nearest to `name`, if one is close enough.
pub fn did_you_mean<'a>(
    name: &str,
    candidates: impl IntoIterator<Item = &'a str>,
) -> Option<String> {
    let name_l: Vec<char> = name.to_lowercase().chars().collect();
    let limit = match name_l.len() {
        0 | 1 => 0,
        n => (n / 3).max(1),
    };
    let mut best: Option<(usize, &str)> = None;
    for c in candidates {
        if c == name {
            continue;
        }
        let c_l: Vec<char> = c.to_lowercase().chars().collect();
        if c_l.len().abs_diff(name_l.len()) > limit {
            continue;
        }
        let d = distance(&name_l, &c_l);
        if d <= limit && best.is_none_or(|(b, _)| d < b) {
            best = Some((d, c));
        }
    }
    best.map(|(_, c)| format!("did you mean `{c}`?"))
}

/// Optimal string alignment distance of two character sequences (the full table: names are
/// short).
fn distance(a: &[char], b: &[char]) -> usize {
    let w = b.len() + 1;
    let mut d = vec![0usize; (a.len() + 1) * w];
    for i in 0..=a.len() {
        for j in 0..=b.len() {
            d[i * w + j] = match (i, j) {
                (0, j) => j,
                (i, 0) => i,
                (i, j) => {
                    let cost = usize::from(a[i - 1] != b[j - 1]);
                    let mut v = (d[(i - 1) * w + j - 1] + cost)
                        .min(d[(i - 1) * w + j] + 1)
                        .min(d[i * w + j - 1] + 1);
                    if i > 1 && j > 1 && a[i - 1] == b[j - 2] && a[i - 2] == b[j - 1] {
                        v = v.min(d[(i - 2) * w + j - 2] + 1);
                    }
                    v
                }
            };
        }
    }
    d[a.len() * w + b.len()]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_nearest_close_name_is_offered() {
        let names = ["Start", "Count", "Counter", "Q"];
        assert_eq!(
            did_you_mean("Cuont", names),
            Some("did you mean `Count`?".into())
        );
        assert_eq!(
            did_you_mean("count", names),
            Some("did you mean `Count`?".into())
        );
        assert_eq!(
            did_you_mean("Countr", names),
            Some("did you mean `Count`?".into())
        );
        assert_eq!(did_you_mean("Stop", names), None);
        assert_eq!(did_you_mean("X", names), None);
        assert_eq!(did_you_mean("Qx", names), Some("did you mean `Q`?".into()));
        assert_eq!(distance(&['a', 'b', 'c'], &['y', 'a', 'b']), 2);
        assert_eq!(distance(&['a', 'b', 'c'], &['b', 'a', 'c']), 1);
    }
}
