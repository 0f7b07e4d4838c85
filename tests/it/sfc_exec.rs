//! PLCopen SFC bodies executed (crates/plc-read/src/plcopen/sfc.rs, sfc_lower.rs): the charts
//! of tests/sfc/ run scan by scan to the values worked out by hand below from matiec's
//! generated code (stage4/generate_c/generate_c_sfc.cc: elapsed time, steps' `prev` and `T`,
//! actions' flags and remaining times, transition tests in priority order, steps reset and set,
//! associations, action states, actions executed; docs/plcopen.md, SFC bodies) on `run`'s
//! virtual clock (docs/scan.md: scan k at k × 10 ms, so the first scan's elapsed time is 0),
//! sequential and parallel equal after every scan (`--mode both`), and the C that `plc-deps c`
//! writes equal to the interpreter after every scan. What is not executed (a macro step, an
//! unknown qualifier) is refused by `run` with its name and place.

use crate::common::cli::run;
use crate::st_exec::{c_equals_run, run_json};
use serde_json::{json, Value};

/// Runs `file` for 1..=rows.len() scans and checks the named variables after each.
fn scan_by_scan(file: &str, names: &[&str], rows: &[&[i64]]) {
    for (k, row) in rows.iter().enumerate() {
        let v = run_json(file, k as u32 + 1, None);
        for (n, want) in names.iter().zip(row.iter()) {
            let got = &v["state"][*n];
            let got = match got {
                Value::Bool(b) => *b as i64,
                Value::Number(x) => x.as_i64().unwrap(),
                other => panic!("{file}: {n} = {other}"),
            };
            assert_eq!(got, *want, "{file}: `{n}` after scan {} (k = {k})", k + 1);
        }
    }
}

#[test]
fn a_sequence_with_a_jump_runs_its_steps_actions_and_step_times_scan_by_scan() {
    // Start (initial, action Count N: cnt := cnt + 1) --[cnt >= 2]--> Run (out1 N, an inline
    // action copying Run.X and Run.T) --[Run.T >= T#20ms]--> jump to Start. Scan 0: Start
    // active, cnt 1; scan 1: Start.T 10 ms, cnt 2; scan 2: the transition sees cnt = 2 and
    // fires: Run active with T = 0, Start's N action ends (deactivated), out1 and x1 TRUE;
    // scan 3: Run.T 10; scan 4: Run.T 20 fires the jump: Start again (T 0, cnt 3), out1 reset
    // by N's deactivation, the inline action does not run (t1 keeps 10); scan 5: cnt = 3 fires
    // at once: Run again, t1 0.
    let names = [
        "cnt", "out1", "x1", "t1", "Start.X", "Run.X", "Start.T", "Run.T",
    ];
    scan_by_scan(
        "tests/sfc/sequence.xml",
        &names,
        &[
            &[1, 0, 0, 0, 1, 0, 0, 0],
            &[2, 0, 0, 0, 1, 0, 10, 0],
            &[2, 1, 1, 0, 0, 1, 20, 0],
            &[2, 1, 1, 10, 0, 1, 20, 10],
            &[3, 0, 1, 10, 1, 0, 0, 20],
            &[3, 1, 1, 0, 0, 1, 10, 0],
            &[3, 1, 1, 10, 0, 1, 10, 10],
        ],
    );
    c_equals_run("tests/sfc/sequence.xml", 8, None);
}

#[test]
fn divergences_fire_by_priority_or_all_at_once_and_a_convergence_waits_for_every_branch() {
    // Chart 1: both branches' conditions TRUE; PRIORITY 0 (B) is tested before PRIORITY 1 (A)
    // and resets Init1 at once, so only B. Chart 2: no priorities: matiec tests both with
    // Init1's flag from before the resets, so C and D both become active. Chart 3: Init3 →
    // (E1 ∥ E2); E1 → F1 when E1.T >= 10 ms (scan 1); (F1 ∥ E2) → G at scan 2.
    let names = [
        "Init1.X", "A.X", "B.X", "Init2.X", "C.X", "D.X", "Init3.X", "E1.X", "E2.X", "F1.X", "G.X",
    ];
    scan_by_scan(
        "tests/sfc/divergence.xml",
        &names,
        &[
            &[0, 0, 1, 0, 1, 1, 0, 1, 1, 0, 0],
            &[0, 0, 1, 0, 1, 1, 0, 0, 1, 1, 0],
            &[0, 0, 1, 0, 1, 1, 0, 0, 0, 0, 1],
        ],
    );
    c_equals_run("tests/sfc/divergence.xml", 4, None);
}

#[test]
fn every_action_qualifier_follows_matiecs_rules_and_times() {
    // S0 (initial) active in scans 0–2 (S0.T 0, 10, 20; T#30ms fires at scan 3), S1 in scans
    // 3–6 (S1.T 0…30; T#40ms fires at scan 7), S2 from scan 7.
    // N vN: TRUE while S0 is active, FALSE when it is deactivated (scan 3).
    // L T#20ms vL: TRUE while S0.T < 20 ms (scans 0, 1), then FALSE.
    // D T#20ms vD: TRUE once S0.T >= 20 ms (scan 2), FALSE at the deactivation.
    // P vP and P1 CountP1: only at S1's activation (scan 3); (P on an initial step never fires
    // on the first scan in matiec: its prev flag is already TRUE.) P0 vP0: at S1's
    // deactivation (scan 7) only.
    // S vS on S0, R vS on S2: TRUE until scan 7. S Inc on S1, R Inc on S2: Inc's body runs in
    // scans 3–6 (stored), not in 7 (the reset clears stored before the state is computed).
    // SD T#20ms vSD: set at S1's activation (scan 3) → remaining 20, 10 (scan 4), 0 (scan 5):
    // TRUE from scan 5. DS T#30ms vDS: TRUE at scan 6, S1 still active. DS T#50ms vDS2: the
    // deactivation (scan 7, remaining 10 ms) cancels it: never TRUE. SL T#20ms vSL: TRUE at
    // activation (scan 3), reset 20 ms later (scan 5).
    let names = [
        "vN", "vL", "vD", "vP", "nP1", "vP0", "vS", "nS", "vSD", "vDS", "vDS2", "vSL", "S1.X",
        "S2.X",
    ];
    scan_by_scan(
        "tests/sfc/qualifiers.xml",
        &names,
        &[
            &[1, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 0, 0, 0],
            &[1, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 0, 0, 0],
            &[1, 0, 1, 0, 0, 0, 1, 0, 0, 0, 0, 0, 0, 0],
            &[0, 0, 0, 1, 1, 0, 1, 1, 0, 0, 0, 1, 1, 0],
            &[0, 0, 0, 0, 1, 0, 1, 2, 0, 0, 0, 1, 1, 0],
            &[0, 0, 0, 0, 1, 0, 1, 3, 1, 0, 0, 0, 1, 0],
            &[0, 0, 0, 0, 1, 0, 1, 4, 1, 1, 0, 0, 1, 0],
            &[0, 0, 0, 0, 1, 1, 0, 4, 1, 1, 0, 0, 0, 1],
            &[0, 0, 0, 0, 1, 0, 0, 4, 1, 1, 0, 0, 0, 1],
        ],
    );
    c_equals_run("tests/sfc/qualifiers.xml", 10, None);
}

#[test]
fn the_report_shows_an_sfc_body_as_its_steps_transitions_and_actions() {
    let out = run(&["report", "tests/sfc/sequence.xml", "--format", "json"]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let v: Value = serde_json::from_slice(&out.stdout).unwrap();
    let ids: Vec<&str> = v["rungs"]
        .as_array()
        .unwrap()
        .iter()
        .map(|r| r["id"].as_str().unwrap())
        .collect();
    for want in [
        "P.step.Start.1",
        "P.tr.T3.2",
        "P.tr.T6.set.1",
        "P.step.Run.assoc.1",
        "P.act.Count.run.1",
        "P.act.out1.run.1",
    ] {
        assert!(ids.contains(&want), "{want} not in {ids:?}");
    }
    // The transition's test reads the step flag the ST condition's rungs need.
    let t3 = v["rungs"]
        .as_array()
        .unwrap()
        .iter()
        .find(|r| r["id"] == json!("P.tr.T3.2"))
        .unwrap();
    assert!(
        t3["in"].as_array().unwrap().contains(&json!("Start.X")),
        "{t3}"
    );
}

#[test]
fn what_is_not_executed_is_refused_by_name_and_place() {
    let out = run(&["run", "tests/sfc/macro_step.xml"]);
    assert_eq!(out.status.code(), Some(2));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains("its SFC body is not executed: a macro step (`macroStep`) at 14:11"),
        "{err}"
    );
    let text = std::fs::read_to_string("tests/sfc/qualifiers.xml")
        .unwrap()
        .replace("qualifier=\"P0\"", "qualifier=\"XY\"");
    let dir = crate::common::cli::tmp("sfc-refused");
    std::fs::create_dir_all(&dir).unwrap();
    let f = dir.join("q.xml");
    std::fs::write(&f, text).unwrap();
    let out = run(&[
        "c",
        f.to_str().unwrap(),
        "-o",
        dir.join("c").to_str().unwrap(),
    ]);
    assert_eq!(out.status.code(), Some(2));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("the action qualifier `XY` at 45:13"), "{err}");
}
