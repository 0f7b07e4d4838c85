//! The fused instructions against the general ones: the same program lowered with and without
//! fusion (`Machine::new_unfused`) must leave byte-identical states (same layout, so loop
//! counters, instance internals and constants included) and the same faults after every scan,
//! on generated programs with every feature and on a program of hand-picked rung shapes.

use super::{ExecConfig, Fault, Layout, Machine};
use plc_model::{Program, Type, Value, VarClass, VarId};
use plc_synth::{generate_string, GenConfig, Reads};

/// Runs `scans` scans of `p` on both machines with the same pseudo-random inputs (every BOOL input a
/// fresh 0/1 per scan) and asserts equal states and faults after each; returns how many rungs
/// the fused machine fused (whole or head), to show the test exercised them.
fn compare(p: &Program, scans: u64, seed: u64) -> usize {
    let cfg = ExecConfig {
        cycle_ms: 10,
        loop_cap: 50,
        scan_budget: crate::DEFAULT_SCAN_BUDGET,
    };
    let fused = Machine::new(p, Layout::dense(p), &cfg).expect("lowers");
    let plain = Machine::new_unfused(p, Layout::dense(p), &cfg).expect("lowers");
    let inputs: Vec<VarId> = p
        .vars()
        .ids()
        .filter(|v| p.var(*v).class == VarClass::Input && p.var(*v).ty == Type::Bool)
        .collect();
    let (mut a, mut b) = (fused.initial_state(), plain.initial_state());
    let (mut fa, mut fb): (Vec<Fault>, Vec<Fault>) = (Vec::new(), Vec::new());
    let mut rng = fastrand::Rng::with_seed(seed);
    for scan in 0..scans {
        let row: Vec<(VarId, Value)> = inputs
            .iter()
            .map(|&v| (v, Value::Bool(rng.bool())))
            .collect();
        fused.scan(&mut a, scan, &row, &mut fa);
        plain.scan(&mut b, scan, &row, &mut fb);
        assert_eq!(a, b, "state after scan {scan} (seed {seed})");
        assert_eq!(fa, fb, "faults after scan {scan} (seed {seed})");
    }
    fused.code.fused.len()
}

#[test]
fn fused_rungs_match_the_general_instructions_on_generated_programs() {
    let mut fused = 0;
    for seed in 0..12u64 {
        let mut g = GenConfig::all_features(300, 12, seed);
        g.reads = if seed % 2 == 0 {
            Reads::Local
        } else {
            Reads::Random
        };
        let p = plc_load::program_from_json(&generate_string(&g)).expect("loads");
        fused += compare(&p, 40, seed);
    }
    assert!(fused > 12 * 200, "only {fused} fused rungs");
}

#[test]
fn fused_rungs_match_the_general_instructions_on_every_fusable_shape() {
    // Outputs of all four kinds; ors nested and first or last; exactly 8 contacts and 9 (not
    // fused whole: a head of 8); no contact; an instance's Q as a contact; a rung whose output
    // is also one of its contacts; heads before a compare, a MOVE and a branch of outputs; and
    // shapes that must not fuse (edge contact, an `or` holding a compare).
    let p = plc_load::program_from_json(
        r#"{"program": "p", "vars": [
            {"name": "a", "type": "BOOL", "class": "input"},
            {"name": "b", "type": "BOOL", "class": "input"},
            {"name": "c", "type": "BOOL", "class": "input"},
            {"name": "d", "type": "BOOL", "class": "input"},
            {"name": "e", "type": "BOOL", "class": "input"},
            {"name": "q", "type": "BOOL", "class": "output"},
            {"name": "r", "type": "BOOL", "class": "output"},
            {"name": "s", "type": "BOOL", "class": "output"},
            {"name": "u", "type": "BOOL", "class": "output"},
            {"name": "n", "type": "INT"},
            {"name": "m", "type": "BOOL"},
            {"name": "t", "type": "TON"}],
          "rungs": [
            {"id": "R1", "ld": [{"contact": "a"}, {"contact": "b", "negated": true}, {"coil": "q"}]},
            {"id": "R2", "ld": [{"or": [[{"contact": "a"}, {"contact": "c"}], [{"contact": "d", "negated": true}]]},
                                {"contact": "e"}, {"coil": "r", "negated": true}]},
            {"id": "R3", "ld": [{"contact": "c"}, {"or": [[{"contact": "q"}], [{"or": [[{"contact": "a"}], [{"contact": "b"}]]}, {"contact": "e"}]]},
                                {"set": "s"}]},
            {"id": "R4", "ld": [{"contact": "d"}, {"contact": "s"}, {"reset": "s"}]},
            {"id": "R5", "ld": [{"contact": "a"}, {"contact": "b"}, {"contact": "c"}, {"contact": "d"},
                                {"contact": "e", "negated": true}, {"contact": "q"}, {"contact": "r"}, {"contact": "s", "negated": true},
                                {"coil": "u"}]},
            {"id": "R6", "ld": [{"contact": "a", "negated": true}, {"contact": "b"}, {"contact": "c"}, {"contact": "d"},
                                {"contact": "e"}, {"contact": "q"}, {"contact": "r"}, {"contact": "s"}, {"contact": "u", "negated": true},
                                {"coil": "u"}]},
            {"id": "R7", "ld": [{"coil": "m"}]},
            {"id": "R8", "ld": [{"contact": "m", "negated": true}, {"contact": "u"}, {"coil": "m"}]},
            {"id": "R9", "ld": [{"contact": "a"}, {"ton": "t", "pt": "T#20ms"}, {"coil": "r"}]},
            {"id": "R10", "ld": [{"contact": "t.Q"}, {"or": [[{"contact": "b"}], [{"contact": "c"}]]}, {"reset": "q"}]},
            {"id": "R11", "ld": [{"contact": "a"}, {"contact": "b"}, {"compare": "GT", "a": "n", "b": 3}, {"coil": "s"}]},
            {"id": "R12", "ld": [{"or": [[{"contact": "c"}], [{"contact": "d"}]]}, {"move": 7, "to": "n"}, {"coil": "u"}]},
            {"id": "R13", "ld": [{"contact": "e"}, {"branch": [[{"coil": "q"}], [{"op": "ADD", "in": ["n", 1], "out": "n"}]]}]},
            {"id": "R14", "ld": [{"contact": "a", "edge": "rising"}, {"contact": "b"}, {"coil": "m"}]},
            {"id": "R15", "ld": [{"or": [[{"contact": "c"}], [{"compare": "LT", "a": "n", "b": 5}]]}, {"set": "q"}]}]}"#,
    )
    .expect("the shapes load");
    let fused = compare(&p, 200, 7);
    assert_eq!(
        fused, 13,
        "R1–R5, R7, R8 and R10 whole; R6, R9 and R11–R13 heads"
    );
}
