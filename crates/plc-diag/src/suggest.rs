//! "Did you mean …?": the declared name nearest to a misspelt one.
//!
//! The distance is the optimal string alignment distance (`strsim::osa_distance`; Levenshtein
//! 1966: insertions, deletions and substitutions; Damerau 1964: a transposition of two
//! neighbours, the commonest slip of typing; each 1), computed without regard to case (IEC
//! 61131-3 §6.1.2: identifiers are not case sensitive, so `count` for `Count` is distance 0 and
//! worth saying). A candidate is offered
//! only when it is close: at most a third of the name's length (at least 1; 0 for a name of
//! one character, where any other letter would be as near). Ties go to the
//! first candidate in the order given. It does not look names up: the caller passes the names
//! in scope.

/// `did you mean `X`?` for the candidate nearest to `name`, if one is close enough.
pub fn did_you_mean<'a>(
    name: &str,
    candidates: impl IntoIterator<Item = &'a str>,
) -> Option<String> {
    let name_l = name.to_lowercase();
    let len = name_l.chars().count();
    let limit = match len {
        0 | 1 => 0,
        n => (n / 3).max(1),
    };
    let mut best: Option<(usize, &str)> = None;
    for c in candidates {
        if c == name {
            continue;
        }
        let c_l = c.to_lowercase();
        if c_l.chars().count().abs_diff(len) > limit {
            continue;
        }
        let d = strsim::osa_distance(&name_l, &c_l);
        if d <= limit && best.is_none_or(|(b, _)| d < b) {
            best = Some((d, c));
        }
    }
    best.map(|(_, c)| format!("did you mean `{c}`?"))
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
        // A transposition of neighbours is one slip.
        assert_eq!(
            did_you_mean("Satrt", names),
            Some("did you mean `Start`?".into())
        );
        // Two edits are too far for a five-letter name (limit 1).
        assert_eq!(did_you_mean("Stxry", names), None);
    }

    /// Candidates at the same distance: the first in the order given wins, whatever its case.
    #[test]
    fn ties_go_to_the_first_candidate() {
        // "Countr" is one edit from both.
        assert_eq!(
            did_you_mean("Countr", ["Counter", "Count"]),
            Some("did you mean `Counter`?".into())
        );
        assert_eq!(
            did_you_mean("Countr", ["Count", "Counter"]),
            Some("did you mean `Count`?".into())
        );
        // Case does not count: `motr` is one edit from both; a candidate is skipped only when
        // it is the name itself.
        assert_eq!(
            did_you_mean("motr", ["MOTOR", "Motor"]),
            Some("did you mean `MOTOR`?".into())
        );
        assert_eq!(
            did_you_mean("Q1", ["Q1", "Q2"]),
            Some("did you mean `Q2`?".into())
        );
    }
}
