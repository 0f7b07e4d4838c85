//! Random FBD programs for property tests (the differential test of the parallel executor and
//! the C generator's test): every op — compares, arithmetic, logic, MOVE, SEL, MAX/MIN/LIMIT,
//! timers, counters, JMP forward and backward, RET, TSTART/TSTOP, calls of a user function block
//! with two instances (and, in [`random_nested_fbd_program`], FB types nested in it, one with a
//! ladder body); data arcs in any id order, conditional arcs, one-source and compound
//! control arcs. Some break a rule of the reader; callers skip those.

use super::Rng;
use serde_json::{json, Value as Json};

#[derive(Copy, Clone, PartialEq)]
enum Ty {
    Bool,
    Int,
    Time,
}

/// Names a generated body may use.
struct Scope {
    bools_read: Vec<&'static str>,
    bools_write: Vec<&'static str>,
    ints_read: Vec<&'static str>,
    ints_write: Vec<&'static str>,
    time_var: &'static str,
    ton: Option<&'static str>,
    tof: Option<&'static str>,
    ctu: Option<&'static str>,
    ctd: Option<&'static str>,
    /// User function block instances with their types (each type has the pins IN1, EN → OUT, Q).
    instances: Vec<(&'static str, &'static str)>,
}

/// A random FBD body of `networks` networks.
fn body(rng: &mut Rng, s: &Scope, networks: usize) -> Json {
    let mut ids: Vec<u32> = (1..=400).collect();
    for i in (1..ids.len()).rev() {
        ids.swap(i, rng.below(i as u64 + 1) as usize);
    }
    let mut ids = ids.into_iter();
    let labels: Vec<Option<String>> = (0..networks)
        .map(|i| {
            if i == 0 || rng.chance(60) {
                Some(format!("L{i}"))
            } else {
                None
            }
        })
        .collect();
    let targets: Vec<&str> = labels.iter().flatten().map(String::as_str).collect();
    let mut nets = Vec::new();
    for (ni, label) in labels.iter().enumerate() {
        let mut blocks: Vec<Json> = Vec::new();
        // Outputs available to arcs in this network: (block id, pin, type).
        let mut avail: Vec<(u32, &'static str, Ty)> = Vec::new();
        let mut earlier: Vec<u32> = Vec::new();
        let mut conditional: Vec<u32> = Vec::new();
        let n = 2 + rng.below(8);
        for _ in 0..n {
            let id = ids.next().expect("enough ids");
            let arc = |rng: &mut Rng, ty: Ty, avail: &[(u32, &'static str, Ty)]| -> Option<Json> {
                let c: Vec<_> = avail.iter().filter(|a| a.2 == ty).collect();
                if c.is_empty() || !rng.chance(45) {
                    return None;
                }
                let (b, pin, _) = **rng.pick(&c);
                Some(if pin == "OUT" && rng.chance(50) {
                    json!({"from": b})
                } else {
                    json!({"from": b, "pin": pin})
                })
            };
            let int_in = |rng: &mut Rng| -> Json {
                if let Some(a) = arc(rng, Ty::Int, &avail) {
                    return a;
                }
                match rng.below(4) {
                    0 => json!(rng.below(7) as i64 - 2),
                    _ => json!(rng.pick(&s.ints_read)),
                }
            };
            let bool_in = |rng: &mut Rng| -> Json {
                if let Some(a) = arc(rng, Ty::Bool, &avail) {
                    return a;
                }
                if rng.chance(10) {
                    return json!(rng.chance(50));
                }
                json!(rng.pick(&s.bools_read))
            };
            let mut b = serde_json::Map::new();
            b.insert("id".into(), json!(id));
            let mut outs: Vec<(&'static str, Ty)> = Vec::new();
            match rng.below(22) {
                0..=3 => {
                    b.insert(
                        "op".into(),
                        json!(rng.pick(&["EQ", "NE", "LT", "LE", "GT", "GE"])),
                    );
                    b.insert("in".into(), json!([int_in(rng), int_in(rng)]));
                    outs.push(("OUT", Ty::Bool));
                }
                4..=6 => {
                    let op = *rng.pick(&["ADD", "SUB", "MUL", "ADD", "DIV", "MOD"]);
                    let k = if matches!(op, "ADD" | "MUL") && rng.chance(30) {
                        3
                    } else {
                        2
                    };
                    b.insert("op".into(), json!(op));
                    b.insert(
                        "in".into(),
                        Json::Array((0..k).map(|_| int_in(rng)).collect()),
                    );
                    outs.push(("OUT", Ty::Int));
                }
                7..=8 => {
                    let op = *rng.pick(&["AND", "OR", "XOR", "NOT"]);
                    let k = if op == "NOT" { 1 } else { 2 + rng.below(2) };
                    b.insert("op".into(), json!(op));
                    b.insert(
                        "in".into(),
                        Json::Array((0..k).map(|_| bool_in(rng)).collect()),
                    );
                    outs.push(("OUT", Ty::Bool));
                }
                9 => {
                    b.insert("op".into(), json!("MOVE"));
                    if rng.chance(50) {
                        b.insert("in".into(), json!([int_in(rng)]));
                        outs.push(("OUT", Ty::Int));
                    } else {
                        b.insert("in".into(), json!([bool_in(rng)]));
                        outs.push(("OUT", Ty::Bool));
                    }
                }
                10 => {
                    b.insert("op".into(), json!("SEL"));
                    b.insert(
                        "in".into(),
                        json!({"G": bool_in(rng), "IN0": int_in(rng), "IN1": int_in(rng)}),
                    );
                    outs.push(("OUT", Ty::Int));
                }
                11 => {
                    let op = *rng.pick(&["MAX", "MIN", "LIMIT"]);
                    let k = if op == "LIMIT" { 3 } else { 2 + rng.below(2) };
                    b.insert("op".into(), json!(op));
                    b.insert(
                        "in".into(),
                        Json::Array((0..k).map(|_| int_in(rng)).collect()),
                    );
                    outs.push(("OUT", Ty::Int));
                }
                12..=13 if s.ton.is_some() => {
                    let (op, inst) = if rng.chance(60) {
                        ("TON", s.ton.unwrap())
                    } else {
                        ("TOF", s.tof.unwrap())
                    };
                    b.insert("op".into(), json!(op));
                    b.insert("instance".into(), json!(inst));
                    b.insert(
                        "in".into(),
                        json!([bool_in(rng), *rng.pick(&["T#20ms", "T#50ms", "T#0ms"])]),
                    );
                    outs.push(("Q", Ty::Bool));
                    outs.push(("ET", Ty::Time));
                }
                14 if s.ctu.is_some() => {
                    if rng.chance(50) {
                        b.insert("op".into(), json!("CTU"));
                        b.insert("instance".into(), json!(s.ctu.unwrap()));
                        b.insert(
                            "in".into(),
                            json!({"CU": bool_in(rng), "R": bool_in(rng), "PV": 3}),
                        );
                    } else {
                        b.insert("op".into(), json!("CTD"));
                        b.insert("instance".into(), json!(s.ctd.unwrap()));
                        b.insert(
                            "in".into(),
                            json!({"CD": bool_in(rng), "LD": bool_in(rng), "PV": 2}),
                        );
                    }
                    outs.push(("Q", Ty::Bool));
                    outs.push(("CV", Ty::Int));
                }
                15 => {
                    b.insert("op".into(), json!("JMP"));
                    b.insert("label".into(), json!(rng.pick(&targets)));
                    if rng.chance(85) {
                        b.insert("cond".into(), bool_in(rng));
                    }
                }
                16 if rng.chance(30) => {
                    b.insert("op".into(), json!("RET"));
                    b.insert("cond".into(), bool_in(rng));
                }
                17 => {
                    b.insert(
                        "op".into(),
                        json!(if rng.chance(60) { "TSTART" } else { "TSTOP" }),
                    );
                    b.insert("in".into(), json!([s.time_var]));
                }
                18..=19 if !s.instances.is_empty() => {
                    let (inst, ty) = *rng.pick(&s.instances);
                    b.insert("op".into(), json!(ty));
                    b.insert("instance".into(), json!(inst));
                    let mut ins = serde_json::Map::new();
                    if rng.chance(80) {
                        ins.insert("IN1".into(), int_in(rng));
                    }
                    if rng.chance(80) {
                        ins.insert("EN".into(), bool_in(rng));
                    }
                    b.insert("in".into(), Json::Object(ins));
                    outs.push(("OUT", Ty::Int));
                    outs.push(("Q", Ty::Bool));
                }
                20 if s.ctu.is_some() => {
                    // The standard function blocks of the main program's instances.
                    let (op, inst) = *rng.pick(&[
                        ("SR", "sr0"),
                        ("RS", "rs0"),
                        ("R_TRIG", "rt0"),
                        ("F_TRIG", "ft0"),
                        ("CTUD", "ud0"),
                    ]);
                    b.insert("op".into(), json!(op));
                    b.insert("instance".into(), json!(inst));
                    let ins = match op {
                        "SR" => json!({"S1": bool_in(rng), "R": bool_in(rng)}),
                        "RS" => json!({"S": bool_in(rng), "R1": bool_in(rng)}),
                        "CTUD" => json!({"CU": bool_in(rng), "CD": bool_in(rng),
                            "R": bool_in(rng), "LD": bool_in(rng), "PV": int_in(rng)}),
                        _ => json!({"CLK": bool_in(rng)}),
                    };
                    b.insert("in".into(), ins);
                    match op {
                        "SR" | "RS" => outs.push(("Q1", Ty::Bool)),
                        "CTUD" => {
                            outs.push(("QU", Ty::Bool));
                            outs.push(("QD", Ty::Bool));
                            outs.push(("CV", Ty::Int));
                        }
                        _ => outs.push(("Q", Ty::Bool)),
                    }
                }
                _ => {
                    b.insert("op".into(), json!("ADD"));
                    b.insert("in".into(), json!([int_in(rng), 1]));
                    outs.push(("OUT", Ty::Int));
                }
            }
            // Variables the outputs go to.
            if let Some(&(pin, ty)) = outs.first() {
                if rng.chance(55) {
                    let var = match ty {
                        Ty::Bool => *rng.pick(&s.bools_write),
                        Ty::Int => *rng.pick(&s.ints_write),
                        Ty::Time => s.time_var,
                    };
                    b.insert(
                        "out".into(),
                        if pin == "OUT" && rng.chance(50) {
                            json!(var)
                        } else {
                            json!({pin: var})
                        },
                    );
                }
            }
            let is_jump = matches!(b.get("op").and_then(Json::as_str), Some("JMP" | "RET"));
            if !is_jump && rng.chance(35) {
                if let Some(c) = arc(rng, Ty::Bool, &avail) {
                    b.insert("cond".into(), c);
                } else if rng.chance(30) {
                    b.insert("cond".into(), json!(rng.pick(&s.bools_read)));
                }
            }
            if !earlier.is_empty() && rng.chance(15) && !b.contains_key("cond") {
                let k = 1 + rng.below(2);
                let after: Vec<u32> = (0..k).map(|_| *rng.pick(&earlier)).collect();
                b.insert("after".into(), json!(after));
            } else if conditional.len() >= 2 && rng.chance(40) && !b.contains_key("cond") {
                // A compound control arc from two conditional blocks.
                let (x, y) = (*rng.pick(&conditional), *rng.pick(&conditional));
                b.insert("after".into(), json!([x, y]));
            }
            if b.contains_key("cond") && !is_jump {
                conditional.push(id);
            }
            for (pin, ty) in outs {
                avail.push((id, pin, ty));
            }
            earlier.push(id);
            blocks.push(Json::Object(b));
        }
        let mut net = json!({"id": format!("N{ni}"), "blocks": blocks});
        if let Some(l) = label {
            net["label"] = json!(l);
        }
        nets.push(net);
    }
    json!({ "networks": nets })
}

/// The names the main program's body may use: these reads and instances, and its variables.
fn main_scope(
    bools_read: Vec<&'static str>,
    ints_read: Vec<&'static str>,
    instances: Vec<(&'static str, &'static str)>,
) -> Scope {
    Scope {
        bools_read,
        bools_write: vec!["b0", "b1", "q"],
        ints_read,
        ints_write: vec!["n0", "n1", "n2"],
        time_var: "tv",
        ton: Some("t0"),
        tof: Some("t1"),
        ctu: Some("c0"),
        ctd: Some("c1"),
        instances,
    }
}

/// The names a function block type's body may use (its pins, own variables, nested instances).
fn fb_scope(instances: Vec<(&'static str, &'static str)>) -> Scope {
    let mut ints_read = vec!["IN1", "ACC", "OUT"];
    let mut bools_read = vec!["EN", "Q", "L0"];
    for &(inst, _) in &instances {
        let (int, b) = match inst {
            "g0" => ("g0.OUT", "g0.Q"),
            "g1" => ("g1.OUT", "g1.Q"),
            _ => ("h0.OUT", "h0.Q"),
        };
        ints_read.push(int);
        bools_read.push(b);
    }
    Scope {
        bools_read,
        bools_write: vec!["Q", "L0"],
        ints_read,
        ints_write: vec!["ACC", "OUT"],
        time_var: "TV",
        ton: Some("T"),
        tof: Some("TF"),
        ctu: None,
        ctd: None,
        instances,
    }
}

/// The interface of the test's function block types: IN1, EN → OUT, Q and own variables.
fn fb_type(extra_vars: &[(&str, &str)], body: (&str, Json)) -> Json {
    let mut vars = vec![
        json!({"name": "ACC", "type": "INT"}),
        json!({"name": "L0", "type": "BOOL"}),
        json!({"name": "T", "type": "TON"}),
        json!({"name": "TF", "type": "TOF"}),
        json!({"name": "TV", "type": "TIME"}),
    ];
    for (n, t) in extra_vars {
        vars.push(json!({"name": n, "type": t}));
    }
    let mut t = json!({
        "inputs": [{"name": "IN1", "type": "INT"}, {"name": "EN", "type": "BOOL"}],
        "outputs": [{"name": "OUT", "type": "INT"}, {"name": "Q", "type": "BOOL"}],
        "vars": vars,
    });
    t[body.0] = body.1;
    t
}

/// A random ladder body over the function block interface of [`fb_type`] (plus a counter
/// `C`): edge contacts (hidden memories per instance), compares, a counter, arithmetic with
/// DIV (faults), a backward jump (the loop cap), RET.
fn fb_ladder(rng: &mut Rng) -> Json {
    let n = 2 + rng.below(4) as usize;
    let mut rungs = Vec::new();
    for i in 0..n {
        let cond = match rng.below(5) {
            0 => json!({"contact": "EN", "edge": "rising"}),
            1 => json!({"contact": *rng.pick(&["EN", "Q", "L0", "C.Q"]), "negated": true}),
            2 => {
                json!({"compare": *rng.pick(&["LT", "GE", "NE"]), "a": *rng.pick(&["IN1", "ACC", "OUT"]), "b": rng.below(5) as i64})
            }
            3 => json!({"contact": "EN", "edge": "falling"}),
            _ => json!({"contact": *rng.pick(&["EN", "L0", "T.Q"])}),
        };
        let act = match rng.below(8) {
            0 => json!({"coil": *rng.pick(&["Q", "L0"])}),
            1 => json!({"ctu": "C", "pv": 3, "reset": "L0"}),
            2 => {
                json!({"op": *rng.pick(&["ADD", "SUB", "DIV", "MOD"]), "in": [*rng.pick(&["IN1", "ACC", "OUT"]), *rng.pick(&["IN1", "ACC", "C.CV"])], "out": *rng.pick(&["ACC", "OUT"])})
            }
            3 => json!({"ton": "T", "pt": "T#20ms"}),
            4 if i > 0 => json!({"jmp": "B0"}),
            5 => json!({"ret": true}),
            6 => json!({"set": "L0"}),
            _ => json!({"move": *rng.pick(&["IN1", "ACC"]), "to": "OUT"}),
        };
        let mut r = json!({"id": format!("R{i}"), "ld": [cond, act]});
        if i == 0 {
            r["label"] = json!("B0");
        }
        rungs.push(r);
    }
    Json::Array(rungs)
}

/// A random FBD program whose function block FB1 holds two instances of FB2 (FBD) and one of
/// FB3 (ladder); the main program has two instances of FB1 and one of FB2 (a type instantiated
/// both at the top and nested).
pub(crate) fn random_nested_fbd_program(seed: u64) -> String {
    let mut rng = Rng::new(seed ^ 0x0FB5_7E57);
    let mut v: Json = serde_json::from_str(&random_fbd_program(seed)).unwrap();
    let main_scope = main_scope(
        vec!["i0", "i1", "b0", "q", "t0.Q", "f0.Q", "f2.Q", "ud0.QD"],
        vec!["k", "n0", "n1", "f1.OUT", "f2.OUT"],
        vec![("f0", "FB1"), ("f1", "FB1"), ("f2", "FB2")],
    );
    let main_nets = 1 + rng.below(3) as usize;
    v["fbd"] = body(&mut rng, &main_scope, main_nets);
    v["vars"]
        .as_array_mut()
        .unwrap()
        .push(json!({"name": "f2", "type": "FB2"}));
    let fb1 = fb_scope(vec![("g0", "FB2"), ("g1", "FB2"), ("h0", "FB3")]);
    let fb1_nets = 1 + rng.below(3) as usize;
    let fb1_body = body(&mut rng, &fb1, fb1_nets);
    let fb2_nets = 1 + rng.below(2) as usize;
    let fb2_body = body(&mut rng, &fb_scope(vec![]), fb2_nets);
    let fb3_body = fb_ladder(&mut rng);
    v["function_blocks"] = json!({
        "FB1": fb_type(&[("g0", "FB2"), ("g1", "FB2"), ("h0", "FB3")], ("fbd", fb1_body)),
        "FB2": fb_type(&[], ("fbd", fb2_body)),
        "FB3": fb_type(&[("C", "CTU")], ("rungs", fb3_body)),
    });
    v.to_string()
}

/// A random FBD program (main body and a user function block FB1 with two instances).
pub(crate) fn random_fbd_program(seed: u64) -> String {
    let mut rng = Rng::new(seed ^ 0x5EED_F00D);
    let main = main_scope(
        vec![
            "i0", "i1", "b0", "b1", "q", "t0.Q", "c0.Q", "f0.Q", "sr0.Q1", "ud0.QD",
        ],
        vec!["k", "n0", "n1", "c0.CV", "f1.OUT", "ud0.CV"],
        vec![("f0", "FB1"), ("f1", "FB1")],
    );
    let fb = fb_scope(vec![]);
    let networks = 1 + rng.below(4) as usize;
    let main_body = body(&mut rng, &main, networks);
    let fb_networks = 1 + rng.below(2) as usize;
    let fb_body = body(&mut rng, &fb, fb_networks);
    json!({
        "program": format!("fbd{seed}"),
        "vars": [
            {"name": "i0", "type": "BOOL", "class": "input"},
            {"name": "i1", "type": "BOOL", "class": "input"},
            {"name": "k", "type": "INT", "class": "input"},
            {"name": "b0", "type": "BOOL"}, {"name": "b1", "type": "BOOL"},
            {"name": "q", "type": "BOOL", "class": "output"},
            {"name": "n0", "type": "INT", "init": 3}, {"name": "n1", "type": "INT"}, {"name": "n2", "type": "INT", "class": "output"},
            {"name": "tv", "type": "TIME"},
            {"name": "t0", "type": "TON"}, {"name": "t1", "type": "TOF"},
            {"name": "c0", "type": "CTU"}, {"name": "c1", "type": "CTD"},
            {"name": "sr0", "type": "SR"}, {"name": "rs0", "type": "RS"},
            {"name": "rt0", "type": "R_TRIG"}, {"name": "ft0", "type": "F_TRIG"},
            {"name": "ud0", "type": "CTUD"},
            {"name": "f0", "type": "FB1"}, {"name": "f1", "type": "FB1"}
        ],
        "function_blocks": {"FB1": fb_type(&[], ("fbd", fb_body))},
        "fbd": main_body
    })
    .to_string()
}
