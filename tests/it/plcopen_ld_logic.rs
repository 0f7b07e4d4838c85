//! The boolean functions AND, OR, XOR and NOT as blocks in hand-written PLCopen TC6 LD rungs:
//! rewritten into contacts and ORs, they give the truth tables of IEC 61131-3 (2.5.1.5.2), and
//! what cannot be rewritten is one located error.

use crate::common;
use crate::plcopen_common as px;

use common::cli::run_stdin;
use px::{block, coil, contact, io, project, rail, report, rung, trace, Source};

fn on(op: &str, id: u32, ins: &[u32]) -> String {
    let pins: Vec<String> = (1..=ins.len()).map(|k| format!("IN{k}")).collect();
    let wires: Vec<Source> = ins.iter().map(|&i| (i, None)).collect();
    let inputs: Vec<(&str, &[Source])> = if op == "NOT" {
        vec![("IN", &wires[..1])]
    } else {
        pins.iter()
            .zip(&wires)
            .map(|(p, w)| (p.as_str(), std::slice::from_ref(w)))
            .collect()
    };
    block(id, op, None, &inputs, &["OUT"])
}

/// a, b → AND → x, OR → y, XOR → z; NOT a → n.
fn gates() -> String {
    let ld = [
        rail(1),
        contact(2, "a", &[1], ""),
        contact(3, "b", &[1], ""),
        on("AND", 4, &[2, 3]),
        coil(5, "x", &[4], ""),
        on("OR", 6, &[2, 3]),
        coil(7, "y", &[6], ""),
        on("XOR", 8, &[2, 3]),
        coil(9, "z", &[8], ""),
        on("NOT", 10, &[2]),
        coil(11, "n", &[10], ""),
    ]
    .concat();
    let mut vars = vec![("inputVars", "a", "BOOL"), ("inputVars", "b", "BOOL")];
    for o in ["x", "y", "z", "n"] {
        vars.push(("outputVars", o, "BOOL"));
    }
    project(&vars, &ld)
}

#[test]
fn and_or_xor_and_not_blocks_give_their_truth_tables() {
    let got = trace(
        "gates",
        &gates(),
        "a,b\n0,0\n0,1\n1,0\n1,1\n",
        &["x", "y", "z", "n"],
    );
    assert_eq!(got[0], ["0", "0", "0", "1"], "AND");
    assert_eq!(got[1], ["0", "1", "1", "1"], "OR");
    assert_eq!(got[2], ["0", "1", "1", "0"], "XOR");
    assert_eq!(got[3], ["1", "1", "0", "0"], "NOT");
    assert_eq!(
        io(&report(&gates())),
        vec![rung("P.R1", &["a", "b"], &["x", "y", "z", "n"])]
    );
}

#[test]
fn a_not_of_a_timer_output_is_read_as_data_flow() {
    let ld = [
        rail(1),
        contact(2, "a", &[1], ""),
        px::in_var(3, "T#1s"),
        block(
            4,
            "TON",
            Some("T0"),
            &[("IN", &[(2, None)]), ("PT", &[(3, None)])],
            &["Q"],
        ),
        on("NOT", 5, &[4]),
        coil(6, "n", &[5], ""),
    ]
    .concat();
    let xml = project(
        &[
            ("inputVars", "a", "BOOL"),
            ("outputVars", "n", "BOOL"),
            ("localVars", "T0", "TON"),
        ],
        &ld,
    );
    // No rung can negate a box's output; as Beremiz generates it, n := NOT T0.Q. With `a`
    // held TRUE the timer (1 s) has not fired in 3 scans of 10 ms: n stays TRUE.
    let got = trace("not-q", &xml, "a\n1\n1\n0\n", &["n"]);
    assert_eq!(got[0], ["1", "1", "1"]);
    let out = run_stdin(&["report", "-"], xml.as_bytes());
    let warnings = String::from_utf8_lossy(&out.stderr);
    assert!(
        warnings.contains("NOT (localId 5) negates a series that holds an output or a box"),
        "{warnings}"
    );
}
