//! Random ladder programs for property tests: every element kind, jumps (forward and backward),
//! FOR/NEXT loops, calls, timers, counters, the bistables, edge detectors and up-down counter,
//! set/reset and edges. Programs are built as JSON text
//! from a seed, so a failing case is reproducible and printable.
#![allow(dead_code)]

pub(crate) mod c;
pub(crate) mod cli;
pub(crate) mod fbd;

use plc_deps::exec::parallel::ScanDriver;
use plc_deps::exec::{Fault, Machine};
use plc_deps::model::{Value as PlcValue, VarId};
use serde_json::{json, Value};
use std::time::Duration;

/// A scan driver for differential tests: writes each scan's inputs from a table and records the
/// full state and the faults after every scan.
pub(crate) struct Recorder<'a> {
    pub inputs: &'a [Vec<(VarId, PlcValue)>],
    pub states: Vec<Vec<u8>>,
    pub faults: Vec<Vec<Fault>>,
}

impl ScanDriver for Recorder<'_> {
    fn before_scan(&mut self, m: &Machine, scan: u64, slots: &mut [u8]) {
        m.set_inputs_in(slots, &self.inputs[scan as usize]);
    }
    fn after_scan(&mut self, _: &Machine, _: u64, slots: &[u8], faults: &[Fault], _: Duration) {
        self.states.push(slots.to_vec());
        self.faults.push(faults.to_vec());
    }
}

/// A small deterministic PRNG (splitmix64).
pub(crate) struct Rng(u64);

impl Rng {
    pub(crate) fn new(seed: u64) -> Rng {
        Rng(seed ^ 0x9E37_79B9_7F4A_7C15)
    }
    pub(crate) fn next(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }
    pub(crate) fn below(&mut self, n: u64) -> u64 {
        self.next() % n.max(1)
    }
    pub(crate) fn chance(&mut self, percent: u64) -> bool {
        self.below(100) < percent
    }
    pub(crate) fn pick<'a, T>(&mut self, items: &'a [T]) -> &'a T {
        &items[self.below(items.len() as u64) as usize]
    }
}

pub(crate) const BOOLS: &[&str] = &["b0", "b1", "b2", "b3", "b4", "b5"];
pub(crate) const INPUTS: &[&str] = &["i0", "i1", "i2"];
pub(crate) const INTS: &[&str] = &["n0", "n1", "n2"];

fn vars() -> Vec<Value> {
    let mut v = Vec::new();
    for i in INPUTS {
        v.push(json!({"name": i, "type": "BOOL", "class": "input"}));
    }
    v.push(json!({"name": "k", "type": "INT", "class": "input"}));
    v.push(json!({"name": "kl", "type": "LINT", "class": "input"}));
    for b in BOOLS {
        v.push(json!({"name": b, "type": "BOOL"}));
    }
    for (i, n) in INTS.iter().enumerate() {
        v.push(json!({"name": n, "type": "INT", "init": i as i64 * 3}));
    }
    v.push(json!({"name": "q", "type": "BOOL", "class": "output"}));
    v.push(json!({"name": "r", "type": "REAL"}));
    v.push(json!({"name": "d", "type": "DINT"}));
    v.push(json!({"name": "tm", "type": "TIME"}));
    v.push(json!({"name": "t0", "type": "TON"}));
    v.push(json!({"name": "t1", "type": "TOF"}));
    v.push(json!({"name": "t2", "type": "TP"}));
    v.push(json!({"name": "c0", "type": "CTU"}));
    v.push(json!({"name": "c1", "type": "CTD"}));
    v.push(json!({"name": "li", "type": "INT"}));
    v.push(json!({"name": "s0", "type": "SR"}));
    v.push(json!({"name": "s1", "type": "RS"}));
    v.push(json!({"name": "e0", "type": "R_TRIG"}));
    v.push(json!({"name": "e1", "type": "F_TRIG"}));
    v.push(json!({"name": "u0", "type": "CTUD"}));
    for (i, (name, ty, consts)) in typed().into_iter().enumerate() {
        // Every other one starts at an extreme value, so that the first steps overflow.
        let init = if i % 2 == 0 {
            consts[0].clone()
        } else {
            json!(0)
        };
        v.push(json!({"name": name, "type": ty, "init": init}));
    }
    v
}

/// One variable of each elementary type besides BOOL, INT, DINT, REAL and TIME, with the
/// constants its operations use: the type's extremes first, then small values.
pub(crate) fn typed() -> Vec<(&'static str, &'static str, Vec<Value>)> {
    vec![
        (
            "xs",
            "SINT",
            vec![json!(127), json!(-128), json!(-1), json!(3)],
        ),
        (
            "xus",
            "USINT",
            vec![json!(255), json!(0), json!(1), json!(7)],
        ),
        (
            "xui",
            "UINT",
            vec![json!(65535), json!(1), json!(300), json!("UINT#2")],
        ),
        (
            "xud",
            "UDINT",
            vec![json!(4294967295u64), json!(1), json!(70000)],
        ),
        (
            "xl",
            "LINT",
            vec![
                json!(i64::MIN),
                json!(i64::MAX),
                json!(-1),
                json!(5),
                json!("kl"),
            ],
        ),
        (
            "xul",
            "ULINT",
            vec![json!(u64::MAX), json!(1), json!(1u64 << 40), json!(3)],
        ),
        (
            "xr",
            "LREAL",
            vec![json!(1e300), json!(-0.25), json!(0.1), json!(3)],
        ),
        (
            "xb",
            "BYTE",
            vec![json!("16#FF"), json!(0), json!("2#1010")],
        ),
        ("xw", "WORD", vec![json!("16#FFFF"), json!(0), json!(7)]),
        (
            "xd",
            "DWORD",
            vec![json!("DWORD#16#FFFFFFFF"), json!(0), json!(9)],
        ),
        (
            "xlw",
            "LWORD",
            vec![json!("16#FFFF_FFFF_FFFF_FFFF"), json!(0), json!(1)],
        ),
    ]
}

/// A move, or an arithmetic box the type accepts (none for the bit strings), on one of
/// [`typed`]'s variables.
fn typed_action(rng: &mut Rng) -> Value {
    let all = typed();
    let (v, ty, consts) = rng.pick(&all);
    let ops: &[&str] = match *ty {
        "BYTE" | "WORD" | "DWORD" | "LWORD" => &[],
        "LREAL" => &["ADD", "SUB", "MUL", "DIV"],
        _ => &["ADD", "SUB", "MUL", "DIV", "MOD"],
    };
    let operand = |rng: &mut Rng| {
        if rng.chance(40) {
            json!(v)
        } else {
            rng.pick(consts).clone()
        }
    };
    if rng.chance(35) {
        return typed_function(rng, v, ty);
    }
    if ops.is_empty() || rng.chance(20) {
        return json!({"move": operand(rng), "to": v});
    }
    json!({"op": rng.pick(ops), "in": [operand(rng), operand(rng)], "out": v})
}

/// A standard function on [`typed`]'s variable `v` of type `ty`: a conversion to another of
/// them, a shift or rotation of its bit pattern, AND/OR/XOR/NOT of it, ABS, or (LREAL) a real
/// function.
fn typed_function(rng: &mut Rng, v: &str, ty: &str) -> Value {
    let all = typed();
    if rng.chance(50) {
        let (w, wty, _) = rng.pick(&all);
        return json!({"op": format!("{ty}_TO_{wty}"), "in": [v], "out": w});
    }
    match ty {
        "LREAL" => {
            let f = *rng.pick(&["SQRT", "LN", "LOG", "EXP", "SIN", "ATAN", "ABS"]);
            if rng.chance(20) {
                json!({"op": "EXPT", "in": [v, *rng.pick(&[2, -1, 3])], "out": v})
            } else {
                json!({"op": f, "in": [v], "out": v})
            }
        }
        "SINT" | "LINT" if rng.chance(30) => json!({"op": "ABS", "in": [v], "out": v}),
        _ if rng.chance(40) => {
            // Bit by bit: AND, OR, XOR of two or three inputs, or NOT.
            let consts = &all
                .iter()
                .find(|(w, ..)| *w == v)
                .expect("a typed variable")
                .2;
            match *rng.pick(&["AND", "OR", "XOR", "NOT"]) {
                "NOT" => json!({"op": "NOT", "in": [v], "out": v}),
                f if rng.chance(50) => {
                    json!({"op": f, "in": [v, rng.pick(consts).clone()], "out": v})
                }
                f => {
                    json!({"op": f, "in": [rng.pick(consts).clone(), v, rng.pick(consts).clone()], "out": v})
                }
            }
        }
        _ => {
            let f = *rng.pick(&["SHL", "SHR", "ROL", "ROR"]);
            let n = *rng.pick(&[0, 1, 3, 7, 8, 15, 16, 31, 33, 63, 64, -1]);
            json!({"op": f, "in": [v, n], "out": v})
        }
    }
}

/// A comparison of one of [`typed`]'s variables with a constant of its type or itself.
fn typed_compare(rng: &mut Rng) -> Value {
    let all = typed();
    let (v, _, consts) = rng.pick(&all);
    let b = if rng.chance(20) {
        json!(v)
    } else {
        rng.pick(consts).clone()
    };
    json!({"compare": rng.pick(&["EQ", "NE", "LT", "LE", "GT", "GE"]), "a": v, "b": b})
}

fn bool_read(rng: &mut Rng) -> &'static str {
    match rng.below(10) {
        0..=3 => rng.pick::<&str>(BOOLS),
        4..=6 => rng.pick::<&str>(INPUTS),
        7 => "t0.Q",
        8 => "c0.Q",
        _ => rng.pick::<&str>(&[
            "t1.Q", "t2.Q", "c1.Q", "q", "s0.Q1", "s1.Q1", "e0.Q", "e1.Q", "u0.QU", "u0.QD",
        ]),
    }
}

fn int_operand(rng: &mut Rng) -> Value {
    match rng.below(5) {
        0 => json!(rng.below(7) as i64 - 2),
        1 => json!("k"),
        2 => json!(rng.pick(&["c0.CV", "u0.CV"])),
        _ => json!(rng.pick(INTS)),
    }
}

fn condition(rng: &mut Rng, depth: u32) -> Value {
    match rng.below(if depth > 1 { 9 } else { 11 }) {
        8 => typed_compare(rng),
        0..=3 => json!({"contact": bool_read(rng)}),
        4 => json!({"contact": bool_read(rng), "negated": true}),
        5 => {
            json!({"contact": bool_read(rng), "edge": if rng.chance(50) { "rising" } else { "falling" }})
        }
        6 | 7 => {
            json!({"compare": rng.pick(&["EQ", "NE", "LT", "LE", "GT", "GE"]), "a": int_operand(rng), "b": int_operand(rng)})
        }
        _ => {
            let n = 2 + rng.below(2);
            let branches: Vec<Value> = (0..n)
                .map(|_| {
                    Value::Array(
                        (0..1 + rng.below(2))
                            .map(|_| condition(rng, depth + 1))
                            .collect(),
                    )
                })
                .collect();
            json!({"or": branches})
        }
    }
}

/// A standard function box over the REAL `r`, the INTs, the DINT `d` and the TIME `tm`.
fn function(rng: &mut Rng) -> Value {
    let i = |rng: &mut Rng| int_operand(rng);
    let n = *rng.pick(INTS);
    let (op, args, out): (&str, Vec<Value>, &str) = match rng.below(8) {
        0 => {
            let f = *rng.pick(&[
                "SQRT", "LN", "LOG", "EXP", "SIN", "COS", "TAN", "ASIN", "ACOS", "ATAN", "ABS",
            ]);
            (f, vec![json!("r")], "r")
        }
        1 => ("EXPT", vec![json!("r"), i(rng)], "r"),
        2 => (
            *rng.pick(&["ABS", "SHL", "SHR", "ROL", "ROR"]),
            vec![i(rng), i(rng)],
            n,
        ),
        3 => {
            let k = 3 + rng.below(3) as usize;
            ("MUX", (0..k).map(|_| int_operand(rng)).collect(), n)
        }
        4 => (*rng.pick(&["REAL_TO_INT", "TRUNC"]), vec![json!("r")], n),
        5 => (
            *rng.pick(&["INT_TO_REAL", "INT_TO_DINT"]),
            vec![i(rng)],
            if rng.chance(50) { "r" } else { "d" },
        ),
        6 => (
            *rng.pick(&[
                "DINT_TO_INT",
                "DINT_TO_REAL",
                "DINT_TO_TIME",
                "DINT_TO_BOOL",
            ]),
            vec![json!("d")],
            n,
        ),
        _ => (
            *rng.pick(&[
                "REAL_TO_DINT",
                "REAL_TO_TIME",
                "TIME_TO_REAL",
                "BOOL_TO_INT",
            ]),
            vec![json!("r")],
            n,
        ),
    };
    // Fix the pairs the table above leaves loose: ABS takes one input; a conversion's output is
    // its TO type, its input its FROM type.
    let (args, out) = match op {
        "ABS" if out != "r" => (vec![args[0].clone()], out),
        "INT_TO_REAL" => (args, "r"),
        "INT_TO_DINT" => (args, "d"),
        "DINT_TO_REAL" => (args, "r"),
        "DINT_TO_TIME" => (args, "tm"),
        "DINT_TO_BOOL" => (args, *rng.pick(BOOLS)),
        "REAL_TO_DINT" => (args, "d"),
        "REAL_TO_TIME" => (args, "tm"),
        "TIME_TO_REAL" => (vec![json!("tm")], "r"),
        "BOOL_TO_INT" => (vec![json!(bool_read(rng))], out),
        _ => (args, out),
    };
    json!({"op": op, "in": args, "out": out})
}

/// An output, box or control element; `labels` are the jump targets available in this POU.
fn action(rng: &mut Rng, labels: &[String], subs: &[String], depth: u32) -> Value {
    let w = *rng.pick(BOOLS);
    match rng.below(if depth > 0 { 23 } else { 25 }) {
        21 | 22 => typed_action(rng),
        0..=2 => json!({"coil": w}),
        3 => json!({"coil": w, "negated": true}),
        4 => json!({"set": w}),
        5 => json!({"reset": w}),
        6 => json!({"ton": "t0", "pt": *rng.pick(&["T#20ms", "T#30ms", "T#0ms"])}),
        7 => json!({"tof": "t1", "pt": "T#20ms"}),
        8 => json!({"tp": "t2", "pt": "T#30ms"}),
        9 => json!({"ctu": "c0", "pv": 3, "reset": bool_read(rng)}),
        10 => json!({"ctd": "c1", "pv": 2, "load": bool_read(rng)}),
        11 => json!({"move": int_operand(rng), "to": rng.pick(INTS)}),
        12 => {
            json!({"op": rng.pick(&["ADD", "SUB", "MUL", "DIV", "MOD"]), "in": [int_operand(rng), int_operand(rng)], "out": rng.pick(INTS)})
        }
        13 if rng.chance(50) => function(rng),
        13 => json!({"op": rng.pick(&["ADD", "MUL", "DIV"]), "in": ["r", 1.5], "out": "r"}),
        14 if !labels.is_empty() => json!({"jmp": rng.pick(labels)}),
        14 | 15 if !subs.is_empty() => json!({"call": rng.pick(subs)}),
        14 | 15 => json!({"coil": "q"}),
        16 => json!({"sr": "s0", "reset": bool_read(rng)}),
        17 => json!({"rs": "s1", "reset": bool_read(rng)}),
        18 => json!({"r_trig": "e0"}),
        19 => json!({"f_trig": "e1"}),
        20 => {
            json!({"ctud": "u0", "cd": bool_read(rng), "reset": bool_read(rng), "load": bool_read(rng), "pv": int_operand(rng)})
        }
        _ => {
            let n = 2 + rng.below(2);
            let branches: Vec<Value> = (0..n)
                .map(|_| {
                    let mut s: Vec<Value> = (0..rng.below(2)).map(|_| condition(rng, 1)).collect();
                    s.push(action(rng, labels, subs, depth + 1));
                    Value::Array(s)
                })
                .collect();
            json!({"branch": branches})
        }
    }
}

/// Rungs of one POU: `prefix` names them, `subs` are callable subroutines.
fn rungs(
    rng: &mut Rng,
    prefix: &str,
    count: usize,
    subs: &[String],
    main: bool,
    loops: bool,
) -> Vec<Value> {
    let labels: Vec<String> = (0..count)
        .filter(|i| i % 3 == 1)
        .map(|i| format!("{prefix}L{i}"))
        .collect();
    let mut out = Vec::new();
    let mut i = 0;
    while i < count {
        let id = format!("{prefix}{i}");
        let label = if i % 3 == 1 {
            Some(format!("{prefix}L{i}"))
        } else {
            None
        };
        let mut series: Vec<Value> = (0..rng.below(3)).map(|_| condition(rng, 0)).collect();
        // A FOR/NEXT block of 1–2 body rungs with a constant bound.
        if loops && main && rng.chance(8) && i + 3 < count && label.is_none() {
            series.push(json!({"for": {"var": "li", "from": 0, "to": rng.below(3) as i64}}));
            out.push(json!({"id": id, "ld": series}));
            let body = 1 + rng.below(2) as usize;
            for b in 0..body {
                let s = vec![condition(rng, 0), action(rng, &[], subs, 0)];
                out.push(json!({"id": format!("{prefix}{}", i + 1 + b), "ld": s}));
            }
            out.push(json!({"id": format!("{prefix}{}", i + 1 + body), "ld": [{"next": true}]}));
            i += body + 2;
            continue;
        }
        let n = 1 + rng.below(2);
        for _ in 0..n {
            series.push(action(rng, &labels, subs, 0));
        }
        if rng.chance(4) {
            series.push(if main && rng.chance(50) {
                json!({"end": true})
            } else {
                json!({"ret": true})
            });
        }
        let mut r = json!({"id": id, "ld": series});
        if let Some(l) = label {
            r["label"] = json!(l);
        }
        out.push(r);
        i += 1;
    }
    out
}

/// A random program; it may be rejected by the loader (a jump into a FOR body), so callers
/// skip those.
pub(crate) fn random_program(seed: u64, max_rungs: usize) -> String {
    let mut rng = Rng::new(seed);
    let nsubs = rng.below(3) as usize;
    let mut subroutines = serde_json::Map::new();
    let mut names: Vec<String> = Vec::new();
    // S1 may call S0; S0 calls nothing: no recursion.
    for s in 0..nsubs {
        let name = format!("S{s}");
        let count = 1 + rng.below(3) as usize;
        let body = rungs(&mut rng, &format!("{name}_"), count, &names, false, false);
        subroutines.insert(name.clone(), json!({"rungs": body}));
        names.push(name);
    }
    let count = 1 + rng.below(max_rungs as u64) as usize;
    let main = rungs(&mut rng, "R", count, &names, true, true);
    json!({"program": "random", "vars": vars(), "rungs": main, "subroutines": subroutines})
        .to_string()
}

/// The JSON report of the worked example `analyses/NAME`, parsed.
pub(crate) fn example_report(name: &str) -> serde_json::Value {
    use plc_deps::cmd::report::{render_report, ReportFormat};
    let path = format!(
        "{}/analyses/{name}/program.json",
        env!("CARGO_MANIFEST_DIR")
    );
    let text = std::fs::read_to_string(path).unwrap();
    let (p, fbd) = plc_deps::load::program_and_fbd_from_json(&text).unwrap();
    let json = render_report(&p, &fbd, ReportFormat::Json, plc_deps::report::View::All);
    serde_json::from_str(&json).unwrap()
}

/// A random value for an input of type `ty`: BOOL, small integers (often 0: DIV/MOD faults),
/// for LINT now and then an extreme, REAL halves, TIME milliseconds.
pub(crate) fn random_input(ty: plc_deps::model::Type, rng: &mut Rng) -> PlcValue {
    use plc_deps::model::{Type, Wide};
    match ty {
        Type::Bool => PlcValue::Bool(rng.chance(50)),
        Type::Int => PlcValue::Int(rng.below(9) as i16 - 3),
        Type::Dint => PlcValue::Dint(rng.below(9) as i32 - 3),
        Type::Real => PlcValue::Real(rng.below(9) as f32 * 0.5),
        Type::Lint if rng.chance(20) => {
            PlcValue::Lint(Wide::new(*rng.pick(&[i64::MIN, i64::MAX]) as u64))
        }
        Type::Lint => PlcValue::Lint(Wide::new((rng.below(9) as i64 - 3) as u64)),
        _ => PlcValue::Time(rng.below(100) as i32),
    }
}
