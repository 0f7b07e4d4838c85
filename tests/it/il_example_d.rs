//! Example D of Zhou & Zhang 2015 (FBD to IL through N-ary trees, Fig. 3 and Fig. 9): the
//! network in FBD (`analyses/example-d/program.json`) gives an STL of at most the paper's 33
//! instructions, and that STL read back, the paper's own listing (`paper.stl`, its first Q0.3
//! taken as Q0.1) and the verbatim listing (both Q0.3: the second write wins) all compute the
//! paper's formulas for all 65,536 input combinations.

use plc_deps::exec::{ExecConfig, Layout, Machine};
use plc_deps::model::{Program, Value, VarId};
use std::path::Path;

fn analyses(file: &str) -> String {
    let p = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("analyses/example-d")
        .join(file);
    std::fs::read_to_string(p).unwrap()
}

const INPUTS: [&str; 16] = [
    "I0_0", "I0_1", "I0_2", "I0_3", "I0_4", "I0_5", "I1_0", "I1_1", "I1_2", "I1_3", "I1_4", "I1_5",
    "I2_0", "I2_1", "I2_2", "I2_3",
];

/// The paper's outputs for input bits `i` (bit k is INPUTS[k]): Q0.0, Q0.1, Q0.2, Q0.3, Q0.4,
/// Q1.0, Q1.1 (the digest's X, Y, Z; Q0.1 is the listing's first Q0.3).
fn formulas(i: u32) -> [bool; 7] {
    let b = |k: usize| i >> k & 1 == 1;
    let x = (b(0) && b(1)) || (b(2) && b(3));
    let y = (x && b(6)) || (b(7) && b(8));
    let z = x && b(11);
    [
        (x && b(4)) || b(5),
        y && b(9),
        x,
        z,
        y || b(10),
        (z && b(12)) || b(13) || b(14),
        z || b(15),
    ]
}

/// Runs one scan per input combination; returns the outputs named in `outs` for each.
fn truth_table(p: &Program, outs: &[&str]) -> Vec<Vec<bool>> {
    let m = Machine::new(
        p,
        Layout::dense(p),
        &ExecConfig {
            cycle_ms: 10,
            loop_cap: 10,
            scan_budget: plc_deps::exec::DEFAULT_SCAN_BUDGET,
        },
    )
    .unwrap();
    let id = |n: &str| {
        VarId::from_raw(
            p.vars()
                .iter()
                .position(|v| v.name == n)
                .unwrap_or_else(|| panic!("{n}")) as u32,
        )
    };
    let ins: Vec<VarId> = INPUTS.iter().map(|n| id(n)).collect();
    let outs: Vec<VarId> = outs.iter().map(|n| id(n)).collect();
    let mut st = m.initial_state();
    (0..1u32 << 16)
        .map(|i| {
            let set: Vec<_> = ins
                .iter()
                .enumerate()
                .map(|(k, v)| (*v, Value::Bool(i >> k & 1 == 1)))
                .collect();
            m.set_inputs(&mut st, &set);
            m.run_scan(&mut st, i as u64, &mut Vec::new());
            outs.iter()
                .map(|o| m.value(&st, *o).to_json() == serde_json::json!(true))
                .collect()
        })
        .collect()
}

const OUTS: [&str; 7] = ["Q0_0", "Q0_1", "Q0_2", "Q0_3", "Q0_4", "Q1_0", "Q1_1"];

fn expected() -> Vec<Vec<bool>> {
    (0..1u32 << 16).map(|i| formulas(i).to_vec()).collect()
}

/// The instruction lines of an STL text (not headers, declarations, comments).
fn instructions(stl: &str) -> usize {
    let mut inside = false;
    stl.lines()
        .map(|l| l.split("//").next().unwrap().trim())
        .filter(|l| {
            let w = l.split_whitespace().next().unwrap_or("");
            if w == "BEGIN" {
                inside = true;
            }
            if w.starts_with("END_") {
                inside = false;
            }
            inside && !l.is_empty() && w != "BEGIN" && w != "NETWORK"
        })
        .count()
}

#[test]
fn the_generated_stl_is_at_most_the_papers_33_instructions_and_computes_its_formulas() {
    let (p, fbd) = plc_deps::load::program_and_fbd_from_json(&analyses("program.json")).unwrap();
    let stl = plc_deps::codegen::il::generate(&p, &fbd).unwrap();
    assert_eq!(instructions(&stl), 32, "{stl}");
    assert_eq!(instructions(&analyses("paper.stl")), 33);
    let want = expected();
    assert_eq!(truth_table(&p, &OUTS), want, "the FBD program itself");
    let (back, _) = plc_deps::load::stl(&stl).unwrap();
    assert_eq!(
        truth_table(&back, &OUTS),
        want,
        "the generated STL read back"
    );
}

#[test]
fn the_papers_own_listing_computes_the_same_truth_table() {
    let (p, _) = plc_deps::load::stl(&analyses("paper.stl")).unwrap();
    assert_eq!(truth_table(&p, &OUTS), expected());
}

#[test]
fn the_verbatim_listing_writes_q0_3_twice_and_the_second_write_wins() {
    let text = std::fs::read_to_string(
        Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/stl/example-d-verbatim.stl"),
    )
    .unwrap();
    let (p, _) = plc_deps::load::stl(&text).unwrap();
    assert!(p.vars().iter().all(|v| v.name != "Q0_1"));
    let outs = ["Q0_0", "Q0_2", "Q0_3", "Q0_4", "Q1_0", "Q1_1"];
    let want: Vec<Vec<bool>> = expected()
        .into_iter()
        .map(|f| vec![f[0], f[2], f[3], f[4], f[5], f[6]])
        .collect();
    assert_eq!(truth_table(&p, &outs), want);
}
