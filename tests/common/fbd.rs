//! Random FBD programs for property tests (the differential test of the parallel executor and
//! the C generator's test): every op — compares, arithmetic, logic, MOVE, SEL, MAX/MIN/LIMIT,
//! timers, counters, JMP forward and backward, RET, TSTART/TSTOP, calls of a user function block
//! with two instances; data arcs in any id order, conditional arcs, one-source and compound
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
    instances: Vec<&'static str>,
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
                    b.insert("op".into(), json!("FB1"));
                    b.insert("instance".into(), json!(rng.pick(&s.instances)));
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

/// A random FBD program (main body and a user function block FB1 with two instances).
pub fn random_fbd_program(seed: u64) -> String {
    let mut rng = Rng::new(seed ^ 0x5EED_F00D);
    let main = Scope {
        bools_read: vec![
            "i0", "i1", "b0", "b1", "q", "t0.Q", "c0.Q", "f0.Q", "sr0.Q1", "ud0.QD",
        ],
        bools_write: vec!["b0", "b1", "q"],
        ints_read: vec!["k", "n0", "n1", "c0.CV", "f1.OUT", "ud0.CV"],
        ints_write: vec!["n0", "n1", "n2"],
        time_var: "tv",
        ton: Some("t0"),
        tof: Some("t1"),
        ctu: Some("c0"),
        ctd: Some("c1"),
        instances: vec!["f0", "f1"],
    };
    let fb = Scope {
        bools_read: vec!["EN", "Q", "L0"],
        bools_write: vec!["Q", "L0"],
        ints_read: vec!["IN1", "ACC", "OUT"],
        ints_write: vec!["ACC", "OUT"],
        time_var: "TV",
        ton: Some("T"),
        tof: Some("TF"),
        ctu: None,
        ctd: None,
        instances: vec![],
    };
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
        "function_blocks": {"FB1": {
            "inputs": [{"name": "IN1", "type": "INT"}, {"name": "EN", "type": "BOOL"}],
            "outputs": [{"name": "OUT", "type": "INT"}, {"name": "Q", "type": "BOOL"}],
            "vars": [{"name": "ACC", "type": "INT"}, {"name": "L0", "type": "BOOL"}, {"name": "T", "type": "TON"}, {"name": "TF", "type": "TOF"}, {"name": "TV", "type": "TIME"}],
            "fbd": fb_body
        }},
        "fbd": main_body
    })
    .to_string()
}
