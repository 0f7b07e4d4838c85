//! Behaviour of the scan interpreter (`plc_deps::exec`) on small programs whose expected values
//! are computed by hand from the scan semantics documented in `crates/plc-exec/src/lib.rs`.

use plc_deps::exec::{ExecConfig, Exit, Fault, FaultKind, Layout, Machine, State, VarValue};
use plc_deps::model::{Program, RungId, Value, VarId};

// ---------------------------------------------------------------- harness

/// A loaded program with its machine, state, scan counter and faults.
struct Sim {
    p: Program,
    m: Machine,
    st: State,
    scan: u64,
    faults: Vec<Fault>,
}

impl Sim {
    fn new(json: &str) -> Sim {
        Sim::with(json, ExecConfig::default())
    }

    fn with(json: &str, config: ExecConfig) -> Sim {
        let p = plc_deps::load::program_from_json(json).expect("test program loads");
        let m = Machine::new(&p, Layout::dense(&p), &config).expect("test program lowers");
        let st = m.initial_state();
        Sim {
            p,
            m,
            st,
            scan: 0,
            faults: Vec::new(),
        }
    }

    fn id(&self, name: &str) -> VarId {
        VarId::from_raw(
            self.p
                .vars()
                .iter()
                .position(|v| v.name == name)
                .unwrap_or_else(|| panic!("no variable {name}")) as u32,
        )
    }

    fn rung(&self, id: &str) -> RungId {
        RungId::from_raw(
            self.p
                .rungs()
                .iter()
                .position(|r| r.id == id)
                .unwrap_or_else(|| panic!("no rung {id}")) as u32,
        )
    }

    /// One scan with these BOOL inputs.
    fn step(&mut self, inputs: &[(&str, bool)]) {
        let vals: Vec<(VarId, Value)> = inputs
            .iter()
            .map(|&(n, b)| (self.id(n), Value::Bool(b)))
            .collect();
        self.step_values(&vals);
    }

    fn step_values(&mut self, inputs: &[(VarId, Value)]) {
        self.m
            .scan(&mut self.st, self.scan, inputs, &mut self.faults);
        self.scan += 1;
    }

    fn get(&self, name: &str) -> VarValue {
        self.m.value(&self.st, self.id(name))
    }

    fn bool(&self, name: &str) -> bool {
        match self.get(name) {
            VarValue::Scalar(Value::Bool(b)) => b,
            other => panic!("{name} is not a BOOL: {other:?}"),
        }
    }

    /// INT, DINT or TIME as i64.
    fn int(&self, name: &str) -> i64 {
        match self.get(name) {
            VarValue::Scalar(Value::Int(i)) => i as i64,
            VarValue::Scalar(Value::Dint(i)) | VarValue::Scalar(Value::Time(i)) => i as i64,
            other => panic!("{name} is not an integer: {other:?}"),
        }
    }

    fn real(&self, name: &str) -> f32 {
        match self.get(name) {
            VarValue::Scalar(Value::Real(f)) => f,
            other => panic!("{name} is not a REAL: {other:?}"),
        }
    }

    fn fault(&self, scan: u64, rung: &str, kind: FaultKind) -> Fault {
        Fault {
            scan,
            rung: self.rung(rung),
            kind,
        }
    }
}

// ---------------------------------------------------------------- KASKAD (the KASKAD-SAU manual)

/// Example 2 with FOR/NEXT: the loop body adds 1 to Count ten times; after the loop idx holds
/// the first value that failed the test (10), copied to `after`; then idx := 0.
const KASKAD_FOR: &str = r#"{
  "program": "kaskad_for",
  "vars": [
    {"name": "Count", "type": "INT", "class": "output"},
    {"name": "idx", "type": "INT"},
    {"name": "after", "type": "INT"}
  ],
  "rungs": [
    {"id": "R1", "ld": [{"for": {"var": "idx", "from": 0, "to": 9}}]},
    {"id": "R2", "ld": [{"op": "ADD", "in": ["Count", 1], "out": "Count"}]},
    {"id": "R3", "ld": [{"next": true}]},
    {"id": "R4", "ld": [{"move": "idx", "to": "after"}]},
    {"id": "R5", "ld": [{"move": 0, "to": "idx"}]}
  ]
}"#;

/// Example 2 as written by KASKAD: loop with post-check, a backward jump.
const KASKAD_POST: &str = r#"{
  "program": "kaskad_post",
  "vars": [
    {"name": "Count", "type": "INT", "class": "output"},
    {"name": "idx", "type": "INT"}
  ],
  "rungs": [
    {"id": "R1", "label": "L2", "ld": [{"op": "ADD", "in": ["Count", 1], "out": "Count"}]},
    {"id": "R2", "ld": [{"op": "ADD", "in": ["idx", 1], "out": "idx"}]},
    {"id": "R3", "ld": [{"compare": "LT", "a": "idx", "b": 10}, {"jmp": "L2"}]},
    {"id": "R4", "ld": [{"move": 0, "to": "idx"}]}
  ]
}"#;

/// Example 3: loop with pre-check, a forward jump out and a backward jump to the test.
const KASKAD_PRE: &str = r#"{
  "program": "kaskad_pre",
  "vars": [
    {"name": "Count", "type": "INT", "class": "output"},
    {"name": "idx", "type": "INT"}
  ],
  "rungs": [
    {"id": "R1", "label": "L2", "ld": [{"compare": "GE", "a": "idx", "b": 10}, {"jmp": "L29"}]},
    {"id": "R2", "ld": [{"op": "ADD", "in": ["Count", 1], "out": "Count"}]},
    {"id": "R3", "ld": [{"op": "ADD", "in": ["idx", 1], "out": "idx"}]},
    {"id": "R4", "ld": [{"jmp": "L2"}]},
    {"id": "R5", "label": "L29", "ld": [{"move": 0, "to": "idx"}]}
  ]
}"#;

fn check_kaskad_loop(json: &str) -> Sim {
    let mut s = Sim::new(json);
    for (scans, count) in [(1, 10), (2, 20), (5, 50)] {
        while s.scan < scans {
            s.step(&[]);
        }
        assert_eq!(s.int("Count"), count, "Count after {scans} scans");
        assert_eq!(s.int("idx"), 0, "idx after {scans} scans");
    }
    assert!(s.faults.is_empty(), "{:?}", s.faults);
    s
}

#[test]
fn kaskad_loop_with_for_next() {
    let s = check_kaskad_loop(KASKAD_FOR);
    assert_eq!(s.int("after"), 10);
}

#[test]
fn kaskad_loop_with_post_check_backward_jump() {
    check_kaskad_loop(KASKAD_POST);
}

#[test]
fn kaskad_loop_with_pre_check_two_jumps() {
    check_kaskad_loop(KASKAD_PRE);
}

#[test]
fn kaskad_average_of_three_real() {
    let mut s = Sim::new(
        r#"{
      "program": "kaskad_avg",
      "vars": [
        {"name": "glVar1", "type": "REAL", "class": "input"},
        {"name": "glVar2", "type": "REAL", "class": "input"},
        {"name": "glVar3", "type": "REAL", "class": "input"},
        {"name": "sum", "type": "REAL"},
        {"name": "Result", "type": "REAL", "class": "output"}
      ],
      "rungs": [
        {"id": "R1", "ld": [{"op": "ADD", "in": ["glVar1", "glVar2"], "out": "sum"}]},
        {"id": "R2", "ld": [{"op": "ADD", "in": ["sum", "glVar3"], "out": "sum"}]},
        {"id": "R3", "ld": [{"op": "DIV", "in": ["sum", 3], "out": "Result"}]}
      ]
    }"#,
    );
    let (a, b, c) = (s.id("glVar1"), s.id("glVar2"), s.id("glVar3"));
    s.step_values(&[
        (a, Value::Real(1.0)),
        (b, Value::Real(2.0)),
        (c, Value::Real(4.5)),
    ]);
    assert_eq!(s.real("Result"), 2.5);
    s.step_values(&[
        (a, Value::Real(-3.0)),
        (b, Value::Real(0.0)),
        (c, Value::Real(0.0)),
    ]);
    assert_eq!(s.real("Result"), -1.0);
}

// ---------------------------------------------------------------- timers

/// Scan, IN, then (Q, ET) of the TON, the TOF and the TP.
type TimerRow = (u64, bool, (bool, i32), (bool, i32), (bool, i32));
/// (CU, R), CTU (CV, Q), (CD, LD), CTD (CV, Q).
type CounterRow = ((bool, bool), (i16, bool), (bool, bool), (i16, bool));

#[test]
fn ton_tof_tp_timing_table() {
    let mut s = Sim::new(
        r#"{
      "program": "timers",
      "vars": [
        {"name": "in", "type": "BOOL", "class": "input"},
        {"name": "T1", "type": "TON"},
        {"name": "T2", "type": "TOF"},
        {"name": "T3", "type": "TP"},
        {"name": "q1", "type": "BOOL", "class": "output"},
        {"name": "q2", "type": "BOOL", "class": "output"},
        {"name": "q3", "type": "BOOL", "class": "output"},
        {"name": "lamp", "type": "BOOL", "class": "output"},
        {"name": "late", "type": "BOOL", "class": "output"}
      ],
      "rungs": [
        {"id": "R1", "ld": [{"contact": "in"}, {"ton": "T1", "pt": "T#30ms"}, {"coil": "q1"}]},
        {"id": "R2", "ld": [{"contact": "in"}, {"tof": "T2", "pt": "T#30ms"}, {"coil": "q2"}]},
        {"id": "R3", "ld": [{"contact": "in"}, {"tp": "T3", "pt": "T#30ms"}, {"coil": "q3"}]},
        {"id": "R4", "ld": [{"contact": "T1.Q"}, {"coil": "lamp"}]},
        {"id": "R5", "ld": [{"compare": "GE", "a": "T3.ET", "b": "T#20ms"}, {"coil": "late"}]}
      ]
    }"#,
    );
    // Cycle 10 ms: scan k runs at now = 10 k.
    // k, IN, TON (Q, ET), TOF (Q, ET), TP (Q, ET)
    #[rustfmt::skip]
    let table: [TimerRow; 16] = [
        (0,  false, (false, 0),  (false, 0),  (false, 0)),
        (1,  true,  (false, 0),  (true, 0),   (true, 0)),   // TON starts at 10; TP pulse starts at 10
        (2,  true,  (false, 10), (true, 0),   (true, 10)),
        (3,  true,  (false, 20), (true, 0),   (true, 20)),
        (4,  true,  (true, 30),  (true, 0),   (false, 30)), // TON done; TP pulse over, IN still true: ET stays PT
        (5,  true,  (true, 30),  (true, 0),   (false, 30)),
        (6,  false, (false, 0),  (true, 0),   (false, 0)),  // TOF starts at 60
        (7,  true,  (false, 0),  (true, 0),   (true, 0)),   // TOF cancelled; TP pulse starts at 70
        (8,  false, (false, 0),  (true, 0),   (true, 10)),  // TOF starts at 80; TP ignores IN while pulsing
        (9,  true,  (false, 0),  (true, 0),   (true, 20)),  // TOF cancelled; rising IN during a pulse: ignored
        (10, false, (false, 0),  (true, 0),   (false, 0)),  // TOF starts at 100; TP over with IN false: ET 0 at once
        (11, false, (false, 0),  (true, 10),  (false, 0)),
        (12, false, (false, 0),  (true, 20),  (false, 0)),
        (13, false, (false, 0),  (false, 30), (false, 0)),  // TOF done
        (14, true,  (false, 0),  (true, 0),   (true, 0)),   // TON starts at 140; TP pulse at 140
        (15, false, (false, 0),  (true, 0),   (true, 10)),  // TON reset; TOF starts at 150
    ];
    for (k, input, ton, tof, tp) in table {
        assert_eq!(s.scan, k);
        s.step(&[("in", input)]);
        assert_eq!(
            s.get("T1"),
            VarValue::Timer {
                q: ton.0,
                et: ton.1,
                pt: 30
            },
            "TON at scan {k}"
        );
        assert_eq!(
            s.get("T2"),
            VarValue::Timer {
                q: tof.0,
                et: tof.1,
                pt: 30
            },
            "TOF at scan {k}"
        );
        assert_eq!(
            s.get("T3"),
            VarValue::Timer {
                q: tp.0,
                et: tp.1,
                pt: 30
            },
            "TP at scan {k}"
        );
        // Box power out is Q; fields are readable by later rungs.
        assert_eq!(
            (s.bool("q1"), s.bool("q2"), s.bool("q3")),
            (ton.0, tof.0, tp.0),
            "box outputs at scan {k}"
        );
        assert_eq!(s.bool("lamp"), ton.0, "T1.Q contact at scan {k}");
        assert_eq!(s.bool("late"), tp.1 >= 20, "T3.ET compare at scan {k}");
    }
}

#[test]
fn timer_in_skipped_rung_is_not_evaluated() {
    // R2's TON is evaluated only when R1 does not jump over it.
    let mut s = Sim::new(
        r#"{
      "program": "skip_timer",
      "vars": [
        {"name": "skip", "type": "BOOL", "class": "input"},
        {"name": "T1", "type": "TON"}
      ],
      "rungs": [
        {"id": "R1", "ld": [{"contact": "skip"}, {"jmp": "L"}]},
        {"id": "R2", "ld": [{"ton": "T1", "pt": "T#50ms"}]},
        {"id": "R3", "label": "L", "ld": []}
      ]
    }"#,
    );
    s.step(&[("skip", true)]); // scan 0: not evaluated, PT not even recorded
    assert_eq!(
        s.get("T1"),
        VarValue::Timer {
            q: false,
            et: 0,
            pt: 0
        }
    );
    s.step(&[("skip", false)]); // scan 1 (10 ms): IN rises, start = 10
    assert_eq!(
        s.get("T1"),
        VarValue::Timer {
            q: false,
            et: 0,
            pt: 50
        }
    );
    s.step(&[("skip", true)]); // scan 2: skipped, fields frozen
    s.step(&[("skip", true)]); // scan 3
    assert_eq!(
        s.get("T1"),
        VarValue::Timer {
            q: false,
            et: 0,
            pt: 50
        }
    );
    s.step(&[("skip", false)]); // scan 4 (40 ms): still timing since 10
    assert_eq!(
        s.get("T1"),
        VarValue::Timer {
            q: false,
            et: 30,
            pt: 50
        }
    );
    s.step(&[("skip", false)]); // scan 5 (50 ms)
    s.step(&[("skip", false)]); // scan 6 (60 ms): 50 ≥ PT
    assert_eq!(
        s.get("T1"),
        VarValue::Timer {
            q: true,
            et: 50,
            pt: 50
        }
    );
}

// ---------------------------------------------------------------- counters

#[test]
fn ctu_ctd_count_reset_and_load() {
    let mut s = Sim::new(
        r#"{
      "program": "counters",
      "vars": [
        {"name": "cu", "type": "BOOL", "class": "input"},
        {"name": "r", "type": "BOOL", "class": "input"},
        {"name": "cd", "type": "BOOL", "class": "input"},
        {"name": "ld", "type": "BOOL", "class": "input"},
        {"name": "C1", "type": "CTU"},
        {"name": "C2", "type": "CTD"},
        {"name": "up_q", "type": "BOOL", "class": "output"},
        {"name": "dn_q", "type": "BOOL", "class": "output"}
      ],
      "rungs": [
        {"id": "R1", "ld": [{"contact": "cu"}, {"ctu": "C1", "pv": 3, "reset": "r"}, {"coil": "up_q"}]},
        {"id": "R2", "ld": [{"contact": "cd"}, {"ctd": "C2", "pv": 2, "load": "ld"}, {"coil": "dn_q"}]}
      ]
    }"#,
    );
    // (cu, r) → CTU (CV, Q); (cd, ld) → CTD (CV, Q)
    #[rustfmt::skip]
    let table: [CounterRow; 13] = [
        ((false, false), (0, false), (false, true),  (2, false)),  // k0: CTD loads PV
        ((true, false),  (1, false), (true, false),  (1, false)),  // k1: both count
        ((true, false),  (1, false), (false, false), (1, false)),  // k2: CU held: no edge
        ((false, false), (1, false), (true, false),  (0, true)),   // k3: CTD reaches 0
        ((true, false),  (2, false), (false, false), (0, true)),
        ((false, false), (2, false), (true, false),  (-1, true)),  // k5: CTD goes below 0
        ((true, false),  (3, true),  (true, true),   (2, false)),  // k6: CTU reaches PV; CTD loads (CD held)
        ((false, false), (3, true),  (false, false), (2, false)),
        ((true, false),  (4, true),  (true, false),  (1, false)),  // k8: CTU counts past PV
        ((true, true),   (0, false), (true, false),  (1, false)),  // k9: reset; CD held
        ((true, false),  (0, false), (false, false), (1, false)),  // k10: CU was recorded during reset: no edge
        ((false, false), (0, false), (true, false),  (0, true)),
        ((true, false),  (1, false), (false, false), (0, true)),
    ];
    for (k, ((cu, r), ctu, (cd, ld), ctd)) in table.into_iter().enumerate() {
        s.step(&[("cu", cu), ("r", r), ("cd", cd), ("ld", ld)]);
        assert_eq!(
            s.get("C1"),
            VarValue::Counter {
                q: ctu.1,
                cv: ctu.0,
                pv: 3
            },
            "CTU at scan {k}"
        );
        assert_eq!(
            s.get("C2"),
            VarValue::Counter {
                q: ctd.1,
                cv: ctd.0,
                pv: 2
            },
            "CTD at scan {k}"
        );
        assert_eq!(
            (s.bool("up_q"), s.bool("dn_q")),
            (ctu.1, ctd.1),
            "box outputs at scan {k}"
        );
    }
}

#[test]
fn ctu_saturates_at_32767() {
    // t toggles every scan (TRUE at even scans), so C counts once per two scans.
    let mut s = Sim::new(
        r#"{
      "program": "ctu_sat",
      "vars": [{"name": "t", "type": "BOOL"}, {"name": "C", "type": "CTU"}],
      "rungs": [
        {"id": "R1", "ld": [{"contact": "t", "negated": true}, {"coil": "t"}]},
        {"id": "R2", "ld": [{"contact": "t"}, {"ctu": "C", "pv": 100, "reset": false}]}
      ]
    }"#,
    );
    for _ in 0..2 * 32_765 {
        s.step(&[]);
    }
    assert_eq!(
        s.get("C"),
        VarValue::Counter {
            q: true,
            cv: 32_765,
            pv: 100
        }
    );
    for _ in 0..20 {
        s.step(&[]);
    }
    assert_eq!(
        s.get("C"),
        VarValue::Counter {
            q: true,
            cv: 32_767,
            pv: 100
        }
    );
}

#[test]
fn counter_in_skipped_rung_keeps_its_previous_cu() {
    let mut s = Sim::new(
        r#"{
      "program": "skip_counter",
      "vars": [
        {"name": "skip", "type": "BOOL", "class": "input"},
        {"name": "cu", "type": "BOOL", "class": "input"},
        {"name": "C", "type": "CTU"}
      ],
      "rungs": [
        {"id": "R1", "ld": [{"contact": "skip"}, {"jmp": "L"}]},
        {"id": "R2", "ld": [{"contact": "cu"}, {"ctu": "C", "pv": 10, "reset": false}]},
        {"id": "R3", "label": "L", "ld": []}
      ]
    }"#,
    );
    s.step(&[("skip", true), ("cu", true)]); // not evaluated: previous CU stays FALSE
    assert_eq!(
        s.get("C"),
        VarValue::Counter {
            q: false,
            cv: 0,
            pv: 0
        }
    );
    s.step(&[("skip", false), ("cu", true)]); // CU TRUE vs previous FALSE: counts
    assert_eq!(
        s.get("C"),
        VarValue::Counter {
            q: false,
            cv: 1,
            pv: 10
        }
    );
}

// ---------------------------------------------------------------- coils, latches, edges

#[test]
fn set_reset_latch_and_seal_in() {
    let mut s = Sim::new(
        r#"{
      "program": "latch",
      "vars": [
        {"name": "start", "type": "BOOL", "class": "input"},
        {"name": "stop", "type": "BOOL", "class": "input"},
        {"name": "motor", "type": "BOOL", "class": "output"},
        {"name": "m2", "type": "BOOL", "class": "output"}
      ],
      "rungs": [
        {"id": "R1", "ld": [{"contact": "start"}, {"set": "motor"}]},
        {"id": "R2", "ld": [{"contact": "stop"}, {"reset": "motor"}]},
        {"id": "R3", "ld": [{"or": [[{"contact": "start"}], [{"contact": "m2"}]]}, {"contact": "stop", "negated": true}, {"coil": "m2"}]}
      ]
    }"#,
    );
    // (start, stop) → motor (= m2: reset and stop win over start)
    let table = [
        ((false, false), false),
        ((true, false), true),
        ((false, false), true),
        ((false, true), false),
        ((false, false), false),
        ((true, true), false),
        ((true, false), true),
        ((false, false), true),
    ];
    for (k, ((start, stop), on)) in table.into_iter().enumerate() {
        s.step(&[("start", start), ("stop", stop)]);
        assert_eq!(s.bool("motor"), on, "set/reset latch at scan {k}");
        assert_eq!(s.bool("m2"), on, "seal-in latch at scan {k}");
    }
}

#[test]
fn long_series_of_contacts_with_negations() {
    // 1 to 8 contacts in a row (fused into 2-, 3- and 4–6-contact instructions), every third one
    // negated: the coil is the AND of them all, for every input combination.
    for n in 1..=8usize {
        let vars: Vec<String> = (0..n)
            .map(|i| format!(r#"{{"name": "x{i}", "type": "BOOL", "class": "input"}}"#))
            .chain([r#"{"name": "y", "type": "BOOL", "class": "output"}"#.to_string()])
            .collect();
        let ld: Vec<String> = (0..n)
            .map(|i| {
                format!(
                    r#"{{"contact": "x{i}"{}}}"#,
                    if i % 3 == 2 {
                        r#", "negated": true"#
                    } else {
                        ""
                    }
                )
            })
            .chain([r#"{"coil": "y"}"#.to_string()])
            .collect();
        let json = format!(
            r#"{{"program": "series", "vars": [{}], "rungs": [{{"id": "R1", "ld": [{}]}}]}}"#,
            vars.join(","),
            ld.join(",")
        );
        let mut s = Sim::new(&json);
        for bits in 0..1u32 << n {
            let inputs: Vec<(VarId, Value)> = (0..n)
                .map(|i| (VarId::from_raw(i as u32), Value::Bool(bits >> i & 1 != 0)))
                .collect();
            s.step_values(&inputs);
            let expected = (0..n).all(|i| (bits >> i & 1 != 0) != (i % 3 == 2));
            assert_eq!(s.bool("y"), expected, "{n} contacts, inputs {bits:b}");
        }
    }
}

#[test]
fn or_and_branch_power_flow() {
    let mut s = Sim::new(
        r#"{
      "program": "flow",
      "vars": [
        {"name": "a", "type": "BOOL", "class": "input"},
        {"name": "b", "type": "BOOL", "class": "input"},
        {"name": "c", "type": "BOOL", "class": "input"},
        {"name": "d", "type": "BOOL", "class": "input"},
        {"name": "q1", "type": "BOOL"}, {"name": "q2", "type": "BOOL"},
        {"name": "q3", "type": "BOOL"}, {"name": "q4", "type": "BOOL"},
        {"name": "q5", "type": "BOOL"}
      ],
      "rungs": [
        {"id": "R1", "ld": [
          {"or": [[{"contact": "a"}], [{"contact": "b"}, {"contact": "c"}]]},
          {"branch": [[{"coil": "q1"}], [{"contact": "d"}, {"coil": "q2"}], [{"coil": "q3", "negated": true}]]},
          {"coil": "q4"}
        ]},
        {"id": "R2", "ld": [
          {"or": [[{"or": [[{"contact": "a", "negated": true}], [{"contact": "b"}]]}, {"contact": "c"}], [{"contact": "d"}]]},
          {"coil": "q5"}
        ]}
      ]
    }"#,
    );
    for bits in 0..16u32 {
        let (a, b, c, d) = (bits & 1 != 0, bits & 2 != 0, bits & 4 != 0, bits & 8 != 0);
        s.step(&[("a", a), ("b", b), ("c", c), ("d", d)]);
        let q1 = a || (b && c);
        assert_eq!(s.bool("q1"), q1, "{bits:04b}");
        assert_eq!(s.bool("q2"), q1 && d, "{bits:04b}");
        assert_eq!(s.bool("q3"), !q1, "{bits:04b}");
        assert_eq!(s.bool("q4"), q1, "branch passes its power in, {bits:04b}");
        assert_eq!(s.bool("q5"), ((!a || b) && c) || d, "{bits:04b}");
    }
}

#[test]
fn rising_and_falling_edge_contacts() {
    let mut s = Sim::new(
        r#"{
      "program": "edges",
      "vars": [
        {"name": "x", "type": "BOOL", "class": "input"},
        {"name": "en", "type": "BOOL", "class": "input"},
        {"name": "up", "type": "BOOL", "class": "output"},
        {"name": "down", "type": "BOOL", "class": "output"},
        {"name": "up2", "type": "BOOL", "class": "output"}
      ],
      "rungs": [
        {"id": "R1", "ld": [{"contact": "x", "edge": "rising"}, {"coil": "up"}]},
        {"id": "R2", "ld": [{"contact": "x", "edge": "falling"}, {"coil": "down"}]},
        {"id": "R3", "ld": [{"contact": "en"}, {"contact": "x", "edge": "rising"}, {"coil": "up2"}]}
      ]
    }"#,
    );
    // (x, en) → (up, down, up2). R3's memory follows x even while en is FALSE (scan 1), so
    // the edge it would have seen is gone by scan 2.
    let table = [
        ((false, true), (false, false, false)),
        ((true, false), (true, false, false)),
        ((true, true), (false, false, false)),
        ((false, true), (false, true, false)),
        ((false, true), (false, false, false)),
        ((true, true), (true, false, true)),
        ((false, false), (false, true, false)),
    ];
    for (k, ((x, en), (up, down, up2))) in table.into_iter().enumerate() {
        s.step(&[("x", x), ("en", en)]);
        assert_eq!(
            (s.bool("up"), s.bool("down"), s.bool("up2")),
            (up, down, up2),
            "scan {k}"
        );
    }
    // The hidden memory is an ordinary variable.
    assert!(!s.bool("R1:edge1"));
}

// ---------------------------------------------------------------- subroutines

#[test]
fn subroutine_call_with_local_and_conditional_ret() {
    let mut s = Sim::new(
        r#"{
      "program": "calls",
      "vars": [
        {"name": "go", "type": "BOOL", "class": "input"},
        {"name": "skip", "type": "BOOL", "class": "input"},
        {"name": "called", "type": "BOOL", "class": "output"},
        {"name": "last", "type": "INT", "class": "output"}
      ],
      "rungs": [
        {"id": "R1", "ld": [{"contact": "go"}, {"call": "SUB"}, {"coil": "called"}]}
      ],
      "subroutines": {
        "SUB": {
          "vars": [{"name": "n", "type": "INT"}],
          "rungs": [
            {"id": "S1", "ld": [{"op": "ADD", "in": ["n", 1], "out": "n"}]},
            {"id": "S2", "ld": [{"contact": "skip"}, {"ret": true}]},
            {"id": "S3", "ld": [{"move": "n", "to": "last"}]}
          ]
        }
      }
    }"#,
    );
    // (go, skip) → (n, last, called)
    let table = [
        ((true, false), (1, 1, true)),
        ((false, false), (1, 1, false)), // not called: the local keeps its value
        ((true, true), (2, 1, true)),    // ret before S3; the calling rung continues: called
        ((true, false), (3, 3, true)),
    ];
    for (k, ((go, skip), (n, last, called))) in table.into_iter().enumerate() {
        s.step(&[("go", go), ("skip", skip)]);
        assert_eq!(
            (s.int("SUB:n"), s.int("last"), s.bool("called")),
            (n, last, called),
            "scan {k}"
        );
    }
}

#[test]
fn main_ret_and_end_stop_the_scan() {
    let mut s = Sim::new(
        r#"{
      "program": "stops",
      "vars": [
        {"name": "r", "type": "BOOL", "class": "input"},
        {"name": "e", "type": "BOOL", "class": "input"},
        {"name": "q1", "type": "BOOL"}, {"name": "q2", "type": "BOOL"}, {"name": "q3", "type": "BOOL"}
      ],
      "rungs": [
        {"id": "R1", "ld": [{"coil": "q1"}, {"contact": "r"}, {"ret": true}]},
        {"id": "R2", "ld": [{"branch": [[{"coil": "q2"}], [{"contact": "e"}, {"end": true}], [{"coil": "q3"}]]}]}
      ]
    }"#,
    );
    s.step(&[("r", true), ("e", false)]);
    assert_eq!(
        (s.bool("q1"), s.bool("q2"), s.bool("q3")),
        (true, false, false)
    );
    s.step(&[("r", false), ("e", true)]); // END inside a branch: q3 (after it) not written
    assert_eq!(
        (s.bool("q1"), s.bool("q2"), s.bool("q3")),
        (true, true, false)
    );
    s.step(&[("r", false), ("e", false)]);
    assert_eq!(
        (s.bool("q1"), s.bool("q2"), s.bool("q3")),
        (true, true, true)
    );
}

// ---------------------------------------------------------------- arithmetic and faults

#[test]
fn division_by_zero_gives_zero_and_a_fault() {
    let mut s = Sim::new(
        r#"{
      "program": "div",
      "vars": [
        {"name": "a", "type": "INT", "class": "input"},
        {"name": "b", "type": "INT", "class": "input"},
        {"name": "x", "type": "REAL", "class": "input"},
        {"name": "y", "type": "REAL", "class": "input"},
        {"name": "q", "type": "INT", "init": 5},
        {"name": "m", "type": "INT", "init": 5},
        {"name": "z", "type": "REAL"}
      ],
      "rungs": [
        {"id": "R1", "ld": [{"op": "DIV", "in": ["a", "b"], "out": "q"}]},
        {"id": "R2", "ld": [{"op": "MOD", "in": ["a", "b"], "out": "m"}]},
        {"id": "R3", "ld": [{"op": "DIV", "in": ["x", "y"], "out": "z"}]}
      ]
    }"#,
    );
    let ids = [s.id("a"), s.id("b"), s.id("x"), s.id("y")];
    let step = |s: &mut Sim, a: i16, b: i16, x: f32, y: f32| {
        let vals = [Value::Int(a), Value::Int(b), Value::Real(x), Value::Real(y)];
        let inputs: Vec<(VarId, Value)> = ids.iter().copied().zip(vals).collect();
        s.step_values(&inputs);
    };
    step(&mut s, 7, 0, 1.0, 0.0);
    assert_eq!((s.int("q"), s.int("m")), (0, 0));
    assert_eq!(s.real("z"), f32::INFINITY); // REAL: IEEE, no fault
    assert_eq!(
        s.faults,
        vec![
            s.fault(0, "R1", FaultKind::DivByZero),
            s.fault(0, "R2", FaultKind::DivByZero)
        ]
    );
    step(&mut s, -7, 2, 0.0, 0.0);
    assert_eq!((s.int("q"), s.int("m")), (-3, -1)); // truncation; MOD has the dividend's sign
    assert!(s.real("z").is_nan());
    assert_eq!(s.faults.len(), 2);
    step(&mut s, -32768, -1, 1.0, 4.0);
    assert_eq!((s.int("q"), s.int("m")), (-32768, 0)); // -32768 / -1 wraps
    assert_eq!(s.real("z"), 0.25);
    assert_eq!(s.faults.len(), 2);
    step(&mut s, 1, 0, 1.0, 1.0);
    assert_eq!(
        s.faults[2..],
        [
            s.fault(3, "R1", FaultKind::DivByZero),
            s.fault(3, "R2", FaultKind::DivByZero)
        ]
    );
}

#[test]
fn integer_wrap_around() {
    let mut s = Sim::new(
        r#"{
      "program": "wrap",
      "vars": [
        {"name": "i", "type": "INT", "init": 32767},
        {"name": "j", "type": "INT", "init": -32768},
        {"name": "d", "type": "DINT", "init": 2147483647},
        {"name": "m", "type": "INT"},
        {"name": "t", "type": "TIME", "init": "T#2147483647ms"}
      ],
      "rungs": [
        {"id": "R1", "ld": [{"op": "ADD", "in": ["i", 1], "out": "i"}]},
        {"id": "R2", "ld": [{"op": "SUB", "in": ["j", 1], "out": "j"}]},
        {"id": "R3", "ld": [{"op": "ADD", "in": ["d", 1], "out": "d"}]},
        {"id": "R4", "ld": [{"op": "MUL", "in": [200, 200], "out": "m"}]},
        {"id": "R5", "ld": [{"op": "ADD", "in": ["t", "T#1ms"], "out": "t"}]}
      ]
    }"#,
    );
    s.step(&[]);
    assert_eq!(s.int("i"), -32768); // 32767 + 1
    assert_eq!(s.int("j"), 32767); // -32768 - 1
    assert_eq!(s.int("d"), -2_147_483_648);
    assert_eq!(s.int("m"), 40_000 - 65_536);
    assert_eq!(s.int("t"), -2_147_483_648);
    s.step(&[]);
    assert_eq!((s.int("i"), s.int("j")), (-32767, 32766));
    assert!(s.faults.is_empty());
}

// ---------------------------------------------------------------- loop cap

const ENDLESS_JUMP: &str = r#"{
  "program": "endless",
  "vars": [{"name": "n", "type": "DINT"}, {"name": "after", "type": "BOOL"}],
  "rungs": [
    {"id": "R1", "label": "L", "ld": [{"op": "ADD", "in": ["n", 1], "out": "n"}]},
    {"id": "R2", "ld": [{"jmp": "L"}]},
    {"id": "R3", "ld": [{"coil": "after"}]}
  ]
}"#;

#[test]
fn loop_cap_ends_an_endless_backward_jump() {
    let mut s = Sim::with(
        ENDLESS_JUMP,
        ExecConfig {
            cycle_ms: 10,
            loop_cap: 1000,
            scan_budget: plc_deps::exec::DEFAULT_SCAN_BUDGET,
        },
    );
    s.step(&[]);
    // R1 runs once, then once more after each of the 1000 allowed jumps; jump 1001 is refused
    // (a fault) and the scan goes on after R2, as if the loop had ended.
    assert_eq!(s.int("n"), 1001);
    assert!(s.bool("after"));
    assert_eq!(s.faults, vec![s.fault(0, "R2", FaultKind::LoopCap)]);
    assert_eq!(s.m.loop_count(&s.st, s.rung("R2")), Some(1001));
    assert_eq!(s.m.loop_count(&s.st, s.rung("R1")), None);
    s.step(&[]); // the cap is per scan
    assert_eq!(s.int("n"), 2002);
    assert_eq!(s.faults[1], s.fault(1, "R2", FaultKind::LoopCap));
}

#[test]
fn loop_cap_default_is_100_000() {
    let mut s = Sim::new(ENDLESS_JUMP);
    s.step(&[]);
    assert_eq!(s.int("n"), 100_001);
    assert!(s.bool("after"));
    assert_eq!(s.faults, vec![s.fault(0, "R2", FaultKind::LoopCap)]);
}

#[test]
fn loop_cap_is_per_rung_and_faults_once_per_rung_and_scan() {
    // Two loop-back rungs in one loop: when R2 is refused, control falls to R3, which loops back
    // on its own budget; R2 is then refused again (silently) until R3 is refused too. A refused
    // jump acts as an unpowered one: the coil after it in R3 gets no power (`tail` FALSE).
    let mut s = Sim::with(
        r#"{
      "program": "two_backs",
      "vars": [{"name": "n", "type": "DINT"}, {"name": "m", "type": "DINT"},
               {"name": "tail", "type": "BOOL", "init": true}, {"name": "after", "type": "BOOL"}],
      "rungs": [
        {"id": "R1", "label": "L", "ld": [{"op": "ADD", "in": ["n", 1], "out": "n"}]},
        {"id": "R2", "ld": [{"jmp": "L"}]},
        {"id": "R3", "ld": [{"op": "ADD", "in": ["m", 1], "out": "m"}, {"jmp": "L"}, {"coil": "tail"}]},
        {"id": "R4", "ld": [{"coil": "after"}]}
      ]
    }"#,
        ExecConfig {
            cycle_ms: 10,
            loop_cap: 10,
            scan_budget: plc_deps::exec::DEFAULT_SCAN_BUDGET,
        },
    );
    s.step(&[]);
    // R1 runs 1 + 10 (R2's loop-backs) + 10 (R3's) times; R3 runs 11 times.
    assert_eq!((s.int("n"), s.int("m")), (21, 11));
    assert!(!s.bool("tail") && s.bool("after"));
    assert_eq!(
        s.faults,
        vec![
            s.fault(0, "R2", FaultKind::LoopCap),
            s.fault(0, "R3", FaultKind::LoopCap)
        ]
    );
    assert_eq!(s.m.loop_count(&s.st, s.rung("R2")), Some(21));
    assert_eq!(s.m.loop_count(&s.st, s.rung("R3")), Some(11));
}

#[test]
fn loop_cap_of_a_subroutine_counts_over_all_its_calls() {
    let mut s = Sim::with(
        r#"{
      "program": "sub_loop",
      "vars": [{"name": "k", "type": "DINT"}, {"name": "after", "type": "BOOL"}],
      "rungs": [
        {"id": "R1", "ld": [{"call": "S"}]},
        {"id": "R2", "ld": [{"call": "S"}]},
        {"id": "R3", "ld": [{"coil": "after"}]}
      ],
      "subroutines": {"S": {"rungs": [
        {"id": "S1", "label": "L", "ld": [{"op": "ADD", "in": ["k", 1], "out": "k"}]},
        {"id": "S2", "ld": [{"compare": "LT", "a": "k", "b": 1000}, {"jmp": "L"}]}
      ]}}
    }"#,
        ExecConfig {
            cycle_ms: 10,
            loop_cap: 5,
            scan_budget: plc_deps::exec::DEFAULT_SCAN_BUDGET,
        },
    );
    s.step(&[]);
    // First call: S1 runs 6 times (5 loop-backs, the 6th refused). Second call: S1 runs once,
    // S2's budget is spent: refused again, silently.
    assert_eq!(s.int("k"), 7);
    assert!(s.bool("after"));
    assert_eq!(s.faults, vec![s.fault(0, "S2", FaultKind::LoopCap)]);
    s.step(&[]);
    assert_eq!(s.int("k"), 14);
    assert_eq!(s.faults.len(), 2);
}

#[test]
fn loop_cap_ends_an_endless_for_loop() {
    // FOR i := 0 TO 32767 on an INT never ends (i wraps to -32768).
    let mut s = Sim::with(
        r#"{
      "program": "endless_for",
      "vars": [{"name": "i", "type": "INT"}, {"name": "k", "type": "DINT"}],
      "rungs": [
        {"id": "R1", "ld": [{"for": {"var": "i", "from": 0, "to": 32767}}]},
        {"id": "R2", "ld": [{"op": "ADD", "in": ["k", 1], "out": "k"}]},
        {"id": "R3", "ld": [{"next": true}]}
      ]
    }"#,
        ExecConfig {
            cycle_ms: 10,
            loop_cap: 1000,
            scan_budget: plc_deps::exec::DEFAULT_SCAN_BUDGET,
        },
    );
    s.step(&[]);
    // 1000 NEXTs loop back; the 1001st is refused: no increment, on past the NEXT.
    assert_eq!((s.int("k"), s.int("i")), (1001, 1000));
    assert_eq!(s.faults, vec![s.fault(0, "R3", FaultKind::LoopCap)]);
}

#[test]
fn for_loop_not_entered_and_empty_range() {
    let mut s = Sim::new(
        r#"{
      "program": "for_guard",
      "vars": [
        {"name": "go", "type": "BOOL", "class": "input"},
        {"name": "top", "type": "DINT", "class": "input"},
        {"name": "i", "type": "DINT", "init": 77},
        {"name": "k", "type": "DINT"}
      ],
      "rungs": [
        {"id": "R1", "ld": [{"contact": "go"}, {"for": {"var": "i", "from": 1, "to": "top"}}]},
        {"id": "R2", "ld": [{"op": "ADD", "in": ["k", "i"], "out": "k"}]},
        {"id": "R3", "ld": [{"next": true}]}
      ]
    }"#,
    );
    let (go, top) = (s.id("go"), s.id("top"));
    s.step_values(&[(go, Value::Bool(false)), (top, Value::Dint(4))]);
    assert_eq!((s.int("i"), s.int("k")), (77, 0)); // head unpowered: i untouched, body skipped
    s.step_values(&[(go, Value::Bool(true)), (top, Value::Dint(4))]);
    assert_eq!((s.int("i"), s.int("k")), (5, 10)); // 1 + 2 + 3 + 4
    s.step_values(&[(go, Value::Bool(true)), (top, Value::Dint(0))]);
    assert_eq!((s.int("i"), s.int("k")), (1, 10)); // 1 > 0: body never runs
}

// ---------------------------------------------------------------- regions, layouts, values

#[test]
fn run_from_reports_where_control_leaves_a_region() {
    let s = Sim::new(
        r#"{
      "program": "regions",
      "vars": [
        {"name": "idx", "type": "INT"}, {"name": "done", "type": "BOOL"},
        {"name": "i", "type": "INT"}, {"name": "k", "type": "INT"}
      ],
      "rungs": [
        {"id": "R0", "ld": [{"move": 0, "to": "idx"}]},
        {"id": "R1", "label": "L", "ld": [{"op": "ADD", "in": ["idx", 1], "out": "idx"}]},
        {"id": "R2", "ld": [{"compare": "LT", "a": "idx", "b": 3}, {"jmp": "L"}]},
        {"id": "R3", "ld": [{"coil": "done"}]},
        {"id": "R4", "ld": [{"for": {"var": "i", "from": 1, "to": 2}}]},
        {"id": "R5", "ld": [{"op": "ADD", "in": ["k", 1], "out": "k"}]},
        {"id": "R6", "ld": [{"next": true}]},
        {"id": "R7", "ld": []}
      ]
    }"#,
    );
    let (m, mut st) = (&s.m, s.st.clone());
    let mut faults = Vec::new();
    let mut ctx = m.context(0, &mut faults);
    let r = RungId::from_raw;
    let store = st.bytes_mut();
    m.begin_scan(store);
    assert_eq!(
        m.run_from(store, &mut ctx, r(0), |x| x == r(0)),
        Exit::Rung(r(1))
    );
    // The backward-jump loop as one region: leaves to R3 with idx = 3.
    assert_eq!(
        m.run_from(store, &mut ctx, r(1), |x| x == r(1) || x == r(2)),
        Exit::Rung(r(3))
    );
    assert_eq!(
        m.run_from(store, &mut ctx, r(3), |x| x == r(3)),
        Exit::Rung(r(4))
    );
    // The FOR head alone: enters the body, which is outside.
    assert_eq!(
        m.run_from(store, &mut ctx, r(4), |x| x == r(4)),
        Exit::Rung(r(5))
    );
    // The body and NEXT without the head: NEXT goes back to the head's test, outside.
    assert_eq!(
        m.run_from(store, &mut ctx, r(5), |x| x == r(5) || x == r(6)),
        Exit::ForTest(r(4))
    );
    // Resuming at the test (i = 2 ≤ 2) enters the body again; then the test fails: exit R7.
    assert_eq!(
        m.resume(store, &mut ctx, Exit::ForTest(r(4)), |x| (4..=6)
            .contains(&x.raw())),
        Exit::Rung(r(7))
    );
    assert_eq!(m.run_from(store, &mut ctx, r(7), |_| true), Exit::Stop);
    assert_eq!(m.resume(store, &mut ctx, Exit::Stop, |_| true), Exit::Stop);
    assert!(faults.is_empty());
    // R2 jumped back twice, the NEXT looped back twice.
    assert_eq!(
        (m.loop_count(&st, r(2)), m.loop_count(&st, r(6))),
        (Some(2), Some(2))
    );
    let v = |n: &str| m.value(&st, s.id(n));
    assert_eq!(v("idx"), VarValue::Scalar(Value::Int(3)));
    assert_eq!(v("done"), VarValue::Scalar(Value::Bool(true)));
    assert_eq!(
        (v("i"), v("k")),
        (
            VarValue::Scalar(Value::Int(3)),
            VarValue::Scalar(Value::Int(2))
        )
    );
    // Same end state as one whole scan.
    let mut whole = s.m.initial_state();
    s.m.run_scan(&mut whole, 0, &mut Vec::new());
    assert_eq!(whole, st);
}

/// Zhao & Yan's Example B (as in analyses/example-b.json): a conditional jump, a backward-jump
/// loop holding a timer, and two calls.
const EXAMPLE_B: &str = r#"{
  "program": "example_b",
  "vars": [
    {"name": "x1", "type": "BOOL", "class": "input"},
    {"name": "x2", "type": "BOOL", "class": "input"},
    {"name": "x3", "type": "BOOL", "class": "input"},
    {"name": "x4", "type": "BOOL", "class": "input"},
    {"name": "x5", "type": "BOOL", "class": "input"},
    {"name": "c1", "type": "BOOL", "class": "input"},
    {"name": "c2", "type": "BOOL", "class": "input"},
    {"name": "idx", "type": "INT"},
    {"name": "done", "type": "BOOL", "class": "output"},
    {"name": "lamp", "type": "BOOL", "class": "output"},
    {"name": "q9", "type": "BOOL", "class": "output"},
    {"name": "qa", "type": "BOOL", "class": "output"},
    {"name": "qb", "type": "BOOL", "class": "output"},
    {"name": "T1", "type": "TON"}
  ],
  "rungs": [
    {"id": "R1", "ld": [{"contact": "x1"}, {"contact": "x2"}, {"jmp": "L9"}]},
    {"id": "R2", "ld": [{"contact": "x3"}, {"move": 0, "to": "idx"}]},
    {"id": "R3", "label": "L3", "ld": [{"compare": "LT", "a": "idx", "b": 5}, {"jmp": "L5"}]},
    {"id": "R4", "ld": [{"branch": [[{"coil": "done"}], [{"jmp": "L9"}]]}]},
    {"id": "R5", "label": "L5", "ld": [{"op": "ADD", "in": ["idx", 1], "out": "idx"}]},
    {"id": "R6", "ld": [{"contact": "x4"}, {"ton": "T1", "pt": "T#500ms"}]},
    {"id": "R7", "ld": [{"contact": "T1.Q"}, {"coil": "lamp"}]},
    {"id": "R8", "ld": [{"jmp": "L3"}]},
    {"id": "R9", "label": "L9", "ld": [{"contact": "x5"}, {"coil": "q9"}]},
    {"id": "R10", "ld": [{"branch": [[{"contact": "c1"}, {"call": "SBR_A"}], [{"contact": "c2"}, {"call": "SBR_B"}]]}]}
  ],
  "subroutines": {
    "SBR_A": {"rungs": [{"id": "R11", "ld": [{"contact": "x1"}, {"coil": "qa"}]}]},
    "SBR_B": {"rungs": [{"id": "R12", "ld": [{"contact": "x2"}, {"coil": "qb"}]}]}
  }
}"#;

/// Runs one scan task by task, the way a parallel executor would: levels in order, each task
/// iff its guard holds, entered where its predecessor's exit points. Returns the faults.
fn scan_by_schedule(
    m: &Machine,
    p: &Program,
    sched: &plc_deps::analysis::schedule::Schedule,
    st: &mut State,
    scan: u64,
) -> Vec<Fault> {
    use plc_deps::analysis::schedule::Successor;
    let mut faults = Vec::new();
    m.begin_scan(st.bytes_mut());
    let mut ctx = m.context(scan, &mut faults);
    let n = sched.tasks.len();
    let mut exit: Vec<Option<Exit>> = vec![None; n];
    let successor = |e: Exit| match e {
        Exit::Stop => Successor::Stop,
        Exit::Rung(r) | Exit::ForTest(r) => {
            Successor::Task(sched.task_of[r.index()].expect("exit to a live rung"))
        }
    };
    for level in &sched.levels {
        for &t in level {
            let task = sched.task(t);
            let runs = task.guard.is_empty()
                || task
                    .guard
                    .iter()
                    .any(|g| exit[g.controller.index()].map(successor) == Some(g.successor));
            if !runs {
                continue;
            }
            // One entry: there. Several: the schedule placed every predecessor at an earlier
            // level, so exactly one task that ran this scan left towards this one.
            let at = match task.entries.as_slice() {
                [entry] => Exit::Rung(*entry),
                _ => {
                    let entered: Vec<Exit> = exit
                        .iter()
                        .flatten()
                        .copied()
                        .filter(|&e| successor(e) == Successor::Task(t))
                        .collect();
                    match entered.as_slice() {
                        [e] => *e,
                        other => panic!("{}: task {t:?} entered from {other:?}", p.name()),
                    }
                }
            };
            let inside = |r: RungId| sched.task_of[r.index()] == Some(t);
            exit[t.index()] = Some(m.resume(st.bytes_mut(), &mut ctx, at, inside));
        }
    }
    faults
}

/// Also when the iteration cap refuses loop-backs (caps 1–3 cut Example B's loop short: a refusal
/// at R8 goes on to R9 and skips R4, which the schedule must know).
#[test]
fn schedule_driven_scan_equals_sequential_scan() {
    for (json, loop_cap) in [EXAMPLE_B, KASKAD_FOR, KASKAD_POST, KASKAD_PRE]
        .into_iter()
        .flat_map(|j| [100_000, 1, 2, 3].map(|c| (j, c)))
    {
        let p = plc_deps::load::program_from_json(json).unwrap();
        let sched = plc_deps::analysis::analyse(&p).schedule;
        let config = ExecConfig {
            loop_cap,
            ..ExecConfig::default()
        };
        let m = Machine::new(&p, Layout::dense(&p), &config).unwrap();
        let (mut a, mut b) = (m.initial_state(), m.initial_state());
        let inputs: Vec<VarId> = (0..p.vars().len() as u32)
            .map(VarId::from_raw)
            .filter(|&v| p.var(v).class == plc_deps::model::VarClass::Input)
            .collect();
        let mut x = 0x2545_F491_4F6C_DD1Du64;
        for scan in 0..200 {
            x ^= x << 13;
            x ^= x >> 7;
            x ^= x << 17;
            let vals: Vec<(VarId, Value)> = inputs
                .iter()
                .enumerate()
                .map(|(i, &v)| (v, Value::Bool(x >> i & 1 != 0)))
                .collect();
            let mut fa = Vec::new();
            m.scan(&mut a, scan, &vals, &mut fa);
            m.set_inputs(&mut b, &vals);
            let fb = scan_by_schedule(&m, &p, &sched, &mut b, scan);
            assert_eq!(
                a,
                b,
                "{} (cap {loop_cap}): states differ after scan {scan}",
                p.name()
            );
            assert_eq!(fa, fb);
        }
    }
}

#[test]
fn padded_permuted_layout_gives_the_same_values() {
    let p = plc_deps::load::program_from_json(EXAMPLE_B).unwrap();
    let dense = Machine::new(&p, Layout::dense(&p), &ExecConfig::default()).unwrap();
    // Reverse order, one variable per 64-byte line.
    let n = p.vars().len() as u32;
    let groups: Vec<Vec<VarId>> = (0..n).rev().map(|v| vec![VarId::from_raw(v)]).collect();
    let layout = Layout::from_groups(&p, &groups, 64).unwrap();
    assert_eq!(layout.size(), 64 * n);
    assert_eq!(
        layout.bytes_of(VarId::from_raw(0)),
        64 * (n - 1)..64 * (n - 1) + 1
    );
    let (idx, t1) = (VarId::from_raw(7), VarId::from_raw(13));
    assert_eq!(layout.bytes_of(idx).len(), 2, "an INT is 2 bytes");
    assert_eq!(
        layout.bytes_of(t1).len(),
        plc_deps::exec::TIMER_BYTES as usize
    );
    let padded = Machine::new(&p, layout.clone(), &ExecConfig::default()).unwrap();
    // The same layout through explicit starts.
    let starts: Vec<u32> = (0..n).map(|v| layout.start(VarId::from_raw(v)).0).collect();
    assert_eq!(
        Layout::from_starts(&p, starts, layout.size()).unwrap(),
        layout
    );
    // Dense: the 12 BOOLs packed first (in declaration order), then the INT, then the timer
    // on its 8-byte alignment.
    let dense_layout = dense.layout();
    assert_eq!(dense_layout.bytes_of(VarId::from_raw(0)), 0..1);
    assert_eq!(
        dense_layout.bytes_of(VarId::from_raw(8)),
        7..8,
        "done follows the seven inputs"
    );
    assert_eq!(dense_layout.bytes_of(idx), 12..14);
    assert_eq!(dense_layout.bytes_of(t1), 16..40);
    assert_eq!(dense_layout.size(), 40);
    let (mut a, mut b) = (dense.initial_state(), padded.initial_state());
    for scan in 0..100u64 {
        let vals: Vec<(VarId, Value)> = (0..7)
            .map(|i| {
                (
                    VarId::from_raw(i),
                    Value::Bool(!(scan * 7 + i as u64).is_multiple_of(3)),
                )
            })
            .collect();
        dense.scan(&mut a, scan, &vals, &mut Vec::new());
        padded.scan(&mut b, scan, &vals, &mut Vec::new());
        for v in 0..p.vars().len() as u32 {
            assert_eq!(
                dense.value(&a, VarId::from_raw(v)),
                padded.value(&b, VarId::from_raw(v)),
                "{} at scan {scan}",
                p.vars()[v as usize].name
            );
        }
    }
}

#[test]
fn bad_layouts_are_refused() {
    use plc_deps::exec::LayoutError;
    let p = plc_deps::load::program_from_json(KASKAD_POST).unwrap(); // Count, idx: 2 INTs
    assert_eq!(
        Layout::from_starts(&p, vec![0], 4),
        Err(LayoutError::WrongLength {
            expected: 2,
            found: 1
        })
    );
    assert_eq!(
        Layout::from_starts(&p, vec![0, 0], 4),
        Err(LayoutError::Overlap { a: 0, b: 1 })
    );
    assert_eq!(
        Layout::from_starts(&p, vec![0, 1], 4),
        Err(LayoutError::Misaligned {
            var: 1,
            start: 1,
            align: 2
        })
    );
    assert!(matches!(
        Layout::from_starts(&p, vec![0, 4], 4),
        Err(LayoutError::OutOfRange { var: 1, .. })
    ));
    assert!(Layout::from_starts(&p, vec![6, 0], 8).is_ok());
    assert_eq!(
        Layout::from_groups(
            &p,
            &[vec![VarId::from_raw(1)], vec![VarId::from_raw(1)]],
            64
        ),
        Err(LayoutError::BadVar { var: 1 })
    );
    assert_eq!(Layout::from_groups(&p, &[], 48), Err(LayoutError::BadAlign));
    let other = plc_deps::load::program_from_json(EXAMPLE_B).unwrap();
    assert!(Machine::new(&p, Layout::dense(&other), &ExecConfig::default()).is_err());
}

#[test]
fn values_as_json() {
    let mut s = Sim::new(
        r#"{
      "program": "json",
      "vars": [
        {"name": "b", "type": "BOOL", "init": true},
        {"name": "i", "type": "INT", "init": -3},
        {"name": "d", "type": "DINT", "init": 100000},
        {"name": "r", "type": "REAL", "init": 0.1},
        {"name": "t", "type": "TIME", "init": "T#1.5s"},
        {"name": "T1", "type": "TON"},
        {"name": "C1", "type": "CTU"}
      ],
      "rungs": [
        {"id": "R1", "ld": [{"ton": "T1", "pt": "T#1s"}]},
        {"id": "R2", "ld": [{"ctu": "C1", "pv": 2, "reset": false}]}
      ]
    }"#,
    );
    s.step(&[]);
    s.step(&[]);
    let j = |n: &str| s.get(n).to_json().to_string();
    assert_eq!(j("b"), "true");
    assert_eq!(j("i"), "-3");
    assert_eq!(j("d"), "100000");
    assert_eq!(j("r"), "0.1");
    assert_eq!(j("t"), "1500");
    assert_eq!(j("T1"), r#"{"Q":false,"ET":10,"PT":1000}"#);
    assert_eq!(j("C1"), r#"{"Q":false,"CV":1,"PV":2}"#);
    assert_eq!(serde_json::to_string(&s.get("C1")).unwrap(), j("C1"));
    let outputs = s.m.outputs(&s.st);
    assert!(outputs.is_empty());
}

#[test]
fn machine_is_shareable_between_threads() {
    fn shareable<T: Send + Sync>() {}
    shareable::<Machine>();
    shareable::<Layout>();
}
