//! The function blocks of matiec's library beyond the standard ones the model has (the typed
//! counters CTU_DINT … CTUD_ULINT of `lib/counter.txt`, and INTEGRAL, DERIVATIVE, PID, RAMP,
//! HYSTERESIS and SEMA of `lib/*_st.txt` and `lib/sema.txt`, which IEC 61131-3 2nd ed. Annex F
//! gives as examples and Beremiz and OpenPLC Editor offer in their block library), as POUs
//! written in IEC ST: a project that uses one of them (a variable declared of its type or a
//! block of its type) and does not define a POU of that name gets the library's POU added to
//! its own, read by the same code as the project's POUs ([`super::project`]: its interface,
//! its ST body lowered for `run` and `c` by [`super::st_lower`]). So the report analyses them
//! like any user function block, and `run`, its parallel machine and the C execute them.
//!
//! The ST texts (`matiec_lib/*.xml`, each a TC6 `pou` element) are written for plc-deps from
//! the blocks' behaviour (matiec's files are LGPL; each body's comment names the file whose
//! behaviour it follows): the same inputs, outputs, initial values and results, call by call.
//! The counters' texts are one template per kind with `{T}` for DINT, LINT, UDINT or ULINT.
//!
//! Invariants: a project's own POU of a library name wins (compared in any case), and so is
//! used by the library's POUs that call it (PID calls INTEGRAL and DERIVATIVE, which are added
//! with it). A library POU's variables are its own (an instance's fields), so they cannot clash
//! with the project's. The library POUs are parsed from one text that starts with as many
//! spaces as the project's file has bytes, so their byte offsets lie past the file's end: a
//! diagnostic about them has no line and column in the user's file (rather than a wrong one);
//! the notes the reader would make about their bodies are left out, one note naming the blocks
//! added instead ([`Added::note`]).
//!
//! Only for projects of matiec's dialect (the caller asks): CODESYS's and TwinCAT's libraries have
//! blocks of these names with other pins (CODESYS's Util PID).
//!
//! Deliberately not here: RTC (it reads the PLC's wall clock: a black box of
//! [`super::library`]), and the typed counters' names in other cases than upper case (Beremiz
//! writes them so).

use super::xml::{Note, Tc6};
use plc_diag::Origin;
use roxmltree::Node;

/// A block of the library: its POU's text and the library blocks its body calls.
struct Entry {
    name: &'static str,
    xml: &'static str,
    needs: &'static [&'static str],
    source: &'static str,
}

const FIXED: &[Entry] = &[
    Entry {
        name: "INTEGRAL",
        xml: include_str!("matiec_lib/integral.xml"),
        needs: &[],
        source: "lib/integral_st.txt",
    },
    Entry {
        name: "DERIVATIVE",
        xml: include_str!("matiec_lib/derivative.xml"),
        needs: &[],
        source: "lib/derivative_st.txt",
    },
    Entry {
        name: "PID",
        xml: include_str!("matiec_lib/pid.xml"),
        needs: &["INTEGRAL", "DERIVATIVE"],
        source: "lib/pid_st.txt",
    },
    Entry {
        name: "RAMP",
        xml: include_str!("matiec_lib/ramp.xml"),
        needs: &[],
        source: "lib/ramp_st.txt",
    },
    Entry {
        name: "HYSTERESIS",
        xml: include_str!("matiec_lib/hysteresis.xml"),
        needs: &[],
        source: "lib/hysteresis_st.txt",
    },
    Entry {
        name: "SEMA",
        xml: include_str!("matiec_lib/sema.xml"),
        needs: &[],
        source: "lib/sema.txt",
    },
];

/// The counters' templates by name prefix, and the types matiec instantiates them for.
const COUNTERS: &[(&str, &str)] = &[
    ("CTUD_", include_str!("matiec_lib/ctud.xml")),
    ("CTU_", include_str!("matiec_lib/ctu.xml")),
    ("CTD_", include_str!("matiec_lib/ctd.xml")),
];
const COUNTER_TYPES: &[&str] = &["DINT", "LINT", "UDINT", "ULINT"];

/// The POU text of library block `name`, the blocks it calls and its source file.
fn pou(name: &str) -> Option<(String, &'static [&'static str], &'static str)> {
    if let Some(e) = FIXED.iter().find(|e| e.name == name) {
        return Some((e.xml.to_owned(), e.needs, e.source));
    }
    COUNTERS.iter().find_map(|(prefix, xml)| {
        let t = name.strip_prefix(prefix)?;
        COUNTER_TYPES
            .contains(&t)
            .then(|| (xml.replace("{T}", t), &[][..], "lib/counter.txt"))
    })
}

/// The library POUs a project needs, as one text to parse.
pub(super) struct Added {
    /// `<pous xmlns="…">` with the POUs, after as many spaces as the project's file has bytes.
    pub text: String,
    /// The offset past which every origin is in [`Added::text`]'s POUs.
    pub start: usize,
    /// The note naming the blocks added, at the first use.
    pub note: Note,
}

/// The library POUs the project whose root is `root` (its file `len` bytes long) uses and does
/// not define (`own`: the names of its POUs), with those they call; `None` when there are none.
pub(super) fn added(tc6: Tc6, root: Node, own: &[&str], len: usize) -> Option<Added> {
    let defined = |n: &str| own.iter().any(|o| o.eq_ignore_ascii_case(n));
    let mut names: Vec<String> = Vec::new();
    let mut first = None;
    for n in root.descendants() {
        let used = if tc6.is(n, "derived") {
            n.attribute("name")
        } else if tc6.is(n, "block") {
            n.attribute("typeName")
        } else {
            None
        };
        let Some(u) = used.map(str::trim) else {
            continue;
        };
        if pou(u).is_some() && !defined(u) && !names.iter().any(|x| x == u) {
            first.get_or_insert(super::xml::origin(n));
            names.push(u.to_owned());
        }
    }
    let at = first?;
    let mut texts = Vec::new();
    let mut shown = Vec::new();
    let mut k = 0;
    while k < names.len() {
        let (xml, needs, source) = pou(&names[k]).expect("only library names are queued");
        texts.push(xml);
        shown.push(format!("{} ({source})", names[k]));
        for n in needs {
            if !defined(n) && !names.iter().any(|x| x == n) {
                names.push((*n).to_owned());
            }
        }
        k += 1;
    }
    let mut text = " ".repeat(len);
    text.push_str(&format!("<pous xmlns=\"{}\">\n", tc6.ns));
    for t in &texts {
        text.push_str(t);
    }
    text.push_str("</pous>\n");
    Some(Added {
        text,
        start: len,
        note: Note {
            origin: at,
            message: format!(
                "function blocks of matiec's library that the project uses and does not define, added as POUs written in ST with matiec's interfaces and behaviour and executed like the project's own (docs/plcopen.md, matiec's library blocks): {}",
                shown.join(", ")
            ),
        },
    })
}

/// True when a note's origin is in the library's text (past the project's file, `start`).
pub(super) fn in_library(o: Origin, start: usize) -> bool {
    o.offset().is_some_and(|off| off >= start)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_library_pou_is_well_formed_xml_naming_itself() {
        let mut names: Vec<String> = FIXED.iter().map(|e| e.name.to_owned()).collect();
        for (p, _) in COUNTERS {
            for t in COUNTER_TYPES {
                names.push(format!("{p}{t}"));
            }
        }
        for n in names {
            let (xml, _, _) = pou(&n).unwrap();
            let wrapped =
                format!("<pous xmlns=\"http://www.plcopen.org/xml/tc6_0201\">{xml}</pous>");
            let doc = roxmltree::Document::parse(&wrapped).unwrap();
            let p = doc.root_element().first_element_child().unwrap();
            assert_eq!(p.attribute("name"), Some(n.as_str()));
            assert!(!xml.contains("{T}"), "{n}");
        }
        assert!(pou("CTU_INT").is_none() && pou("CTU").is_none() && pou("PIDX").is_none());
    }
}
