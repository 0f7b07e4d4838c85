//! The place in a JSON text that a JSON path names, for errors found after reading.
//!
//! The resolver and the FBD lowering work on the program model, which keeps the JSON path of
//! every node it reports on (`fbd.networks[0].blocks[1].in[1]`) but not always its byte offset:
//! their errors carry the offset of the innermost node that still had one, a network, say.
//! [`path_offset`] walks the text along the path once the load has failed, so every error points
//! at the value it names. It skips what is off the path without building anything.
//!
//! Invariants: the walk never reads past the text, never recurses (depth is a loop, skipping
//! nested values is a counter), and answers `None` rather than guessing when the text does not
//! have the path's first node. It assumes a text that the reader accepted as JSON; on anything
//! else it stops where it is lost and returns the deepest node reached.

/// Where the value at `path` in `text` is (keys separated by `.`, array indices in `[i]`), or the
/// deepest value on the way to it that the text has: the offset its member starts at (its key,
/// for a member of an object) and the offset of the value. `None` when not even the first step
/// is there (or the path is empty).
pub fn path_offset(text: &str, path: &str) -> Option<(usize, usize)> {
    let b = text.as_bytes();
    let mut at = skip_ws(b, 0);
    if b.get(at) == Some(&0xef) {
        // A byte-order mark.
        at = skip_ws(b, at + 3);
    }
    let mut deepest = None;
    for step in steps(path) {
        let next = match step {
            Step::Key(k) => member(b, at, k),
            Step::Index(i) => element(b, at, i).map(|v| (v, v)),
        };
        match next {
            Some((start, v)) => {
                at = v;
                deepest = Some((start, v));
            }
            None => break,
        }
    }
    deepest
}

#[derive(Debug, PartialEq)]
enum Step<'p> {
    Key(&'p str),
    Index(usize),
}

/// The steps of a path: `a.b[2][0].c` → `a`, `b`, `2`, `0`, `c`.
fn steps(path: &str) -> impl Iterator<Item = Step<'_>> {
    path.split('.').filter(|s| !s.is_empty()).flat_map(|seg| {
        let (key, rest) = seg.split_at(seg.find('[').unwrap_or(seg.len()));
        let key = (!key.is_empty()).then_some(Step::Key(key));
        let indices = rest
            .split('[')
            .filter_map(|s| s.strip_suffix(']'))
            .map(|s| s.parse().map_or(Step::Index(usize::MAX), Step::Index));
        key.into_iter().chain(indices)
    })
}

fn skip_ws(b: &[u8], mut at: usize) -> usize {
    while matches!(b.get(at), Some(b' ' | b'\t' | b'\n' | b'\r')) {
        at += 1;
    }
    at
}

/// One past the end of the string that starts at `at` (a `"`).
fn skip_string(b: &[u8], mut at: usize) -> usize {
    at += 1;
    while let Some(&c) = b.get(at) {
        at += 1;
        match c {
            b'"' => return at,
            b'\\' => at += 1,
            _ => {}
        }
    }
    at
}

/// One past the end of the value that starts at `at`.
fn skip_value(b: &[u8], at: usize) -> usize {
    let mut depth = 0usize;
    let mut i = at;
    while let Some(&c) = b.get(i) {
        match c {
            b'"' => {
                i = skip_string(b, i);
                if depth == 0 {
                    return i;
                }
                continue;
            }
            b'{' | b'[' => depth += 1,
            b'}' | b']' => {
                if depth <= 1 {
                    return i + usize::from(depth == 1);
                }
                depth -= 1;
            }
            b',' | b':' if depth == 0 => return i,
            _ => {}
        }
        i += 1;
    }
    i
}

/// The offsets of member `key` of the object at `at` and of its value.
fn member(b: &[u8], at: usize, key: &str) -> Option<(usize, usize)> {
    if b.get(at) != Some(&b'{') {
        return None;
    }
    let mut i = skip_ws(b, at + 1);
    while b.get(i) == Some(&b'"') {
        let start = i;
        let end = skip_string(b, i);
        let name = b.get(i + 1..end.saturating_sub(1))?;
        i = skip_ws(b, end);
        if b.get(i) != Some(&b':') {
            return None;
        }
        i = skip_ws(b, i + 1);
        if name == key.as_bytes() {
            return Some((start, i));
        }
        i = skip_ws(b, skip_value(b, i));
        if b.get(i) != Some(&b',') {
            return None;
        }
        i = skip_ws(b, i + 1);
    }
    None
}

/// The offset of element `index` of the array at `at`.
fn element(b: &[u8], at: usize, index: usize) -> Option<usize> {
    if b.get(at) != Some(&b'[') {
        return None;
    }
    let mut i = skip_ws(b, at + 1);
    for _ in 0..index {
        if matches!(b.get(i), None | Some(b']')) {
            return None;
        }
        i = skip_ws(b, skip_value(b, i));
        if b.get(i) != Some(&b',') {
            return None;
        }
        i = skip_ws(b, i + 1);
    }
    (!matches!(b.get(i), None | Some(b']'))).then_some(i)
}

#[cfg(test)]
mod tests {
    use super::*;

    const DOC: &str = r#"{"program": "p", "fbd": {"networks": [{"id": "N1", "blocks": [
   {"id": 1, "op": "GT", "in": ["X", 5]},
   {"id": 2, "op": "ADD", "in": ["X", {"from": 1}], "out": "X"}
 ]}]}, "s": "a \" } ] , b"}"#;

    fn at(path: &str) -> Option<&'static str> {
        path_offset(DOC, path).map(|(_, o)| &DOC[o..])
    }

    #[test]
    fn finds_the_value_a_path_names() {
        assert!(at("").is_none());
        assert!(at("program").unwrap().starts_with("\"p\""));
        assert!(at("fbd.networks[0].blocks[1].in[1]")
            .unwrap()
            .starts_with("{\"from\": 1}"));
        assert!(at("fbd.networks[0].blocks[1].in[1].from")
            .unwrap()
            .starts_with("1}"));
        assert!(at("fbd.networks[0].blocks[1].out")
            .unwrap()
            .starts_with("\"X\""));
        assert!(at("s").unwrap().starts_with("\"a \\\""));
        let (key, value) = path_offset(DOC, "fbd.networks[0].blocks[1].out").unwrap();
        assert_eq!(
            (&DOC[key..key + 5], &DOC[value..value + 3]),
            ("\"out\"", "\"X\"")
        );
    }

    #[test]
    fn stops_at_the_deepest_node_the_text_has() {
        assert!(at("fbd.networks[0].blocks[1].label")
            .unwrap()
            .starts_with("{\"id\": 2"));
        assert!(at("fbd.networks[0].blocks[7]").unwrap().starts_with("[\n"));
        assert_eq!(at("nothing.here"), None);
    }

    #[test]
    fn splits_paths_into_steps() {
        let s: Vec<Step> = steps("rungs[1].ld[0].or[1][0].contact").collect();
        assert_eq!(
            s,
            [
                Step::Key("rungs"),
                Step::Index(1),
                Step::Key("ld"),
                Step::Index(0),
                Step::Key("or"),
                Step::Index(1),
                Step::Index(0),
                Step::Key("contact"),
            ]
        );
    }

    #[test]
    fn never_reads_past_a_cut_text() {
        for cut in 0..DOC.len() {
            if DOC.is_char_boundary(cut) {
                let _ = path_offset(&DOC[..cut], "fbd.networks[0].blocks[1].in[1].from");
            }
        }
    }
}
