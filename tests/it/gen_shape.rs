//! Shape and validity of the synthetic program generator (`plc_deps::synth`), checked on the JSON
//! text alone (serde_json), independently of the crate's reader.

use plc_deps::synth::{generate_string, phase, write_program, GenConfig, Reads};
use proptest::prelude::*;
use serde_json::{Map, Value};
use std::collections::{BTreeMap, HashMap, HashSet};
use std::io::{self, Write};
use std::time::Instant;

// ---------------------------------------------------------------------------------------------
// Independent validator

#[derive(Clone, Debug)]
struct Decl {
    ty: String,
    class: String,
}

/// What one validated program contained.
#[derive(Default, Debug)]
struct Stats {
    main_rungs: usize,
    sub_rungs: BTreeMap<String, usize>,
    /// Element kind (with variants such as `contact.negated`) → count.
    kinds: BTreeMap<String, usize>,
}

struct Checker<'a> {
    globals: &'a HashMap<String, Decl>,
    locals: HashMap<String, Decl>,
    subs: &'a HashSet<String>,
    pou: String,
    is_main: bool,
    rung: String,
    kinds: &'a mut BTreeMap<String, usize>,
    calls: &'a mut Vec<(String, String)>,
    jumps: Vec<String>,
}

fn fail<T>(msg: String) -> Result<T, String> {
    Err(msg)
}

fn field_type(fb: &str, field: &str) -> Option<&'static str> {
    match (fb, field) {
        ("TON" | "TOF" | "TP", "Q" | "IN") => Some("BOOL"),
        ("TON" | "TOF" | "TP", "ET" | "PT") => Some("TIME"),
        ("CTU" | "CTD", "Q" | "CU" | "CD" | "R" | "LD") => Some("BOOL"),
        ("CTU" | "CTD", "CV" | "PV") => Some("INT"),
        _ => None,
    }
}

const NUMERIC: [&str; 4] = ["INT", "DINT", "REAL", "TIME"];

impl Checker<'_> {
    fn count(&mut self, k: &str) {
        *self.kinds.entry(k.to_owned()).or_default() += 1;
    }

    fn decl(&self, name: &str) -> Result<&Decl, String> {
        self.locals
            .get(name)
            .or_else(|| self.globals.get(name))
            .ok_or_else(|| {
                format!(
                    "{}: undeclared variable {name:?} in {}",
                    self.rung, self.pou
                )
            })
    }

    /// Type of an operand; `"NUM"` for a plain number literal.
    fn operand(&self, v: &Value) -> Result<String, String> {
        match v {
            Value::Bool(_) => Ok("BOOL".into()),
            Value::Number(_) => Ok("NUM".into()),
            Value::String(s) if s.starts_with("T#") => {
                let body = &s[2..];
                let ok = ["ms", "s", "m", "h"].iter().any(|u| {
                    body.strip_suffix(u)
                        .is_some_and(|d| !d.is_empty() && d.chars().all(|c| c.is_ascii_digit()))
                });
                if ok {
                    Ok("TIME".into())
                } else {
                    fail(format!("{}: bad TIME literal {s:?}", self.rung))
                }
            }
            Value::String(s) => match s.split_once('.') {
                None => Ok(self.decl(s)?.ty.clone()),
                Some((var, field)) => {
                    let fb = &self.decl(var)?.ty;
                    field_type(fb, field)
                        .map(str::to_owned)
                        .ok_or_else(|| format!("{}: no field {field} on {var}: {fb}", self.rung))
                }
            },
            other => fail(format!("{}: bad operand {other}", self.rung)),
        }
    }

    fn expect(&self, v: &Value, ty: &str, what: &str) -> Result<(), String> {
        let t = self.operand(v)?;
        let ok = t == ty || (t == "NUM" && matches!(ty, "INT" | "DINT" | "REAL"));
        if !ok {
            return fail(format!(
                "{}: {what} {v} has type {t}, expected {ty}",
                self.rung
            ));
        }
        if let (Some(x), "INT") = (v.as_i64(), ty) {
            if i16::try_from(x).is_err() {
                return fail(format!("{}: {what} {x} out of INT range", self.rung));
            }
        }
        Ok(())
    }

    fn writable(&self, v: &Value, ty: Option<&str>, what: &str) -> Result<String, String> {
        let name = v
            .as_str()
            .ok_or_else(|| format!("{}: {what} target not a string", self.rung))?;
        let d = self.decl(name)?;
        if d.class == "input" {
            return fail(format!("{}: {what} writes input {name}", self.rung));
        }
        if let Some(ty) = ty {
            if d.ty != ty {
                return fail(format!(
                    "{}: {what} on {name}: {}, expected {ty}",
                    self.rung, d.ty
                ));
            }
        }
        Ok(d.ty.clone())
    }

    fn flag(&self, o: &Map<String, Value>, key: &str) -> Result<(), String> {
        if o.get(key) != Some(&Value::Bool(true)) {
            return fail(format!("{}: `{key}` must be true", self.rung));
        }
        Ok(())
    }

    /// `place`: "top", "branch" or "or".
    fn series(&mut self, v: &Value, place: &str) -> Result<(), String> {
        let items = v
            .as_array()
            .ok_or_else(|| format!("{}: series is not an array", self.rung))?;
        for (i, e) in items.iter().enumerate() {
            let o = e
                .as_object()
                .ok_or_else(|| format!("{}: element is not an object", self.rung))?;
            // Boxes first: a `ctu` box has a `reset` operand, which is not a reset coil.
            let key = [
                "ctu", "ctd", "ton", "tof", "tp", "move", "op", "compare", "contact", "or", "coil",
                "set", "reset", "branch", "jmp", "ret", "end", "call", "for", "next",
            ]
            .into_iter()
            .find(|k| o.contains_key(*k))
            .ok_or_else(|| format!("{}: unknown element {e}", self.rung))?;
            if place == "or" && !matches!(key, "contact" | "compare" | "or") {
                return fail(format!("{}: {key} inside or", self.rung));
            }
            self.count(key);
            match key {
                "contact" => {
                    self.expect(&o["contact"], "BOOL", "contact")?;
                    let neg = o.get("negated") == Some(&Value::Bool(true));
                    if neg {
                        self.count("contact.negated");
                    }
                    if let Some(edge) = o.get("edge") {
                        if neg || !matches!(edge.as_str(), Some("rising" | "falling")) {
                            return fail(format!("{}: bad edge contact {e}", self.rung));
                        }
                        self.count("contact.edge");
                    }
                }
                "compare" => {
                    let op = o["compare"].as_str().unwrap_or("");
                    if !["EQ", "NE", "LT", "LE", "GT", "GE"].contains(&op) {
                        return fail(format!("{}: bad compare {op}", self.rung));
                    }
                    let (a, b) = (self.operand(&o["a"])?, self.operand(&o["b"])?);
                    let ty = if a == "NUM" { &b } else { &a };
                    if !NUMERIC.contains(&ty.as_str()) && ty != "NUM" {
                        return fail(format!("{}: compare on {ty}", self.rung));
                    }
                    self.expect(&o["a"], ty, "compare a")?;
                    self.expect(&o["b"], ty, "compare b")?;
                }
                "or" | "branch" => {
                    let branches = o[key]
                        .as_array()
                        .ok_or_else(|| format!("{}: {key} not an array", self.rung))?;
                    if branches.len() < 2 {
                        return fail(format!("{}: {key} with fewer than 2 branches", self.rung));
                    }
                    for b in branches {
                        self.series(b, key)?;
                    }
                }
                "coil" | "set" | "reset" => {
                    self.writable(&o[key], Some("BOOL"), key)?;
                    if o.get("negated") == Some(&Value::Bool(true)) {
                        self.count("coil.negated");
                    }
                }
                "ton" | "tof" | "tp" => {
                    self.writable(&o[key], Some(&key.to_ascii_uppercase()), key)?;
                    self.expect(&o["pt"], "TIME", "pt")?;
                }
                "ctu" | "ctd" => {
                    self.writable(&o[key], Some(&key.to_ascii_uppercase()), key)?;
                    self.expect(&o["pv"], "INT", "pv")?;
                    let ctl = if key == "ctu" { "reset" } else { "load" };
                    self.expect(&o[ctl], "BOOL", ctl)?;
                }
                "move" => {
                    let ty = self.writable(&o["to"], None, "move")?;
                    self.expect(&o["move"], &ty, "move source")?;
                }
                "op" => {
                    let op = o["op"].as_str().unwrap_or("");
                    if !["ADD", "SUB", "MUL", "DIV", "MOD"].contains(&op) {
                        return fail(format!("{}: bad op {op}", self.rung));
                    }
                    let ty = self.writable(&o["out"], None, "op")?;
                    if !["INT", "DINT"].contains(&ty.as_str()) {
                        return fail(format!("{}: op on {ty}", self.rung));
                    }
                    let ins = o["in"]
                        .as_array()
                        .filter(|a| a.len() == 2)
                        .ok_or_else(|| format!("{}: op needs 2 inputs", self.rung))?;
                    for x in ins {
                        self.expect(x, &ty, "op input")?;
                    }
                    if matches!(op, "DIV" | "MOD") && ins[1].as_i64() == Some(0) {
                        return fail(format!("{}: division by constant 0", self.rung));
                    }
                }
                "jmp" => {
                    let l = o["jmp"]
                        .as_str()
                        .ok_or_else(|| format!("{}: jmp label not a string", self.rung))?;
                    self.jumps.push(l.to_owned());
                }
                "ret" => self.flag(o, "ret")?,
                "end" => {
                    self.flag(o, "end")?;
                    if !self.is_main {
                        return fail(format!("{}: end in a subroutine", self.rung));
                    }
                }
                "call" => {
                    let callee = o["call"].as_str().unwrap_or("");
                    if !self.subs.contains(callee) {
                        return fail(format!("{}: call to unknown {callee:?}", self.rung));
                    }
                    self.calls.push((self.pou.clone(), callee.to_owned()));
                }
                "for" => {
                    if place != "top" || i + 1 != items.len() {
                        return fail(format!("{}: for not last in its rung", self.rung));
                    }
                    let f = o["for"]
                        .as_object()
                        .ok_or_else(|| format!("{}: bad for", self.rung))?;
                    self.writable(&f["var"], Some("INT"), "for index")?;
                    self.expect(&f["from"], "INT", "for from")?;
                    self.expect(&f["to"], "INT", "for to")?;
                }
                "next" => {
                    self.flag(o, "next")?;
                    if place != "top" || items.len() != 1 {
                        return fail(format!("{}: next not alone in its rung", self.rung));
                    }
                }
                _ => unreachable!(),
            }
        }
        Ok(())
    }
}

fn declare(
    vars: &Value,
    into: &mut HashMap<String, Decl>,
    all: &mut HashSet<String>,
) -> Result<(), String> {
    for v in vars.as_array().ok_or("vars is not an array")? {
        let name = v["name"].as_str().ok_or("var without name")?.to_owned();
        let ty = v["type"].as_str().ok_or("var without type")?.to_owned();
        let class = v
            .get("class")
            .and_then(Value::as_str)
            .unwrap_or("memory")
            .to_owned();
        if ![
            "BOOL", "INT", "DINT", "REAL", "TIME", "TON", "TOF", "TP", "CTU", "CTD",
        ]
        .contains(&ty.as_str())
        {
            return fail(format!("{name}: unknown type {ty}"));
        }
        if !["input", "output", "memory"].contains(&class.as_str()) {
            return fail(format!("{name}: unknown class {class}"));
        }
        if let Some(init) = v.get("init") {
            let ok = match ty.as_str() {
                "BOOL" => init.is_boolean(),
                "INT" => init.as_i64().is_some_and(|x| i16::try_from(x).is_ok()),
                _ => false,
            };
            if !ok {
                return fail(format!("{name}: bad init {init} for {ty}"));
            }
        }
        // The generator keeps names unique program-wide (locals included).
        if !all.insert(name.clone()) {
            return fail(format!("duplicate variable {name}"));
        }
        into.insert(name, Decl { ty, class });
    }
    Ok(())
}

/// Checks everything the brief asks of a generated program; returns what it found.
fn validate(text: &str) -> Result<Stats, String> {
    let v: Value = serde_json::from_str(text).map_err(|e| format!("not JSON: {e}"))?;
    let top = v.as_object().ok_or("top level is not an object")?;
    for k in top.keys() {
        if !["program", "vars", "rungs", "subroutines"].contains(&k.as_str()) {
            return fail(format!("unknown top-level key {k}"));
        }
    }
    top.get("program")
        .and_then(Value::as_str)
        .ok_or("program name missing")?;
    let mut all = HashSet::new();
    let mut globals = HashMap::new();
    declare(&v["vars"], &mut globals, &mut all)?;
    let empty = Map::new();
    let subs_obj = top
        .get("subroutines")
        .map(|s| s.as_object().ok_or("subroutines is not an object"))
        .transpose()?
        .unwrap_or(&empty);
    let subs: HashSet<String> = subs_obj.keys().cloned().collect();

    let mut pous: Vec<(String, &Value, HashMap<String, Decl>)> =
        vec![("main".into(), &v["rungs"], HashMap::new())];
    for (name, body) in subs_obj {
        let mut locals = HashMap::new();
        declare(&body["vars"], &mut locals, &mut all)?;
        pous.push((name.clone(), &body["rungs"], locals));
    }

    let mut stats = Stats::default();
    let mut calls = Vec::new();
    let mut ids = Vec::new();
    for (pi, (pou, rungs, locals)) in pous.into_iter().enumerate() {
        let rungs = rungs
            .as_array()
            .ok_or_else(|| format!("{pou}: rungs is not an array"))?;
        if pi == 0 {
            stats.main_rungs = rungs.len();
        } else {
            stats.sub_rungs.insert(pou.clone(), rungs.len());
        }
        let mut labels: HashMap<String, usize> = HashMap::new();
        let mut jumps: Vec<(usize, String)> = Vec::new();
        // Enclosing FOR heads of each rung (a NEXT rung is in its own block's body).
        let mut enclosing: Vec<Vec<usize>> = Vec::with_capacity(rungs.len());
        let mut stack: Vec<usize> = Vec::new();
        let mut checker = Checker {
            globals: &globals,
            locals,
            subs: &subs,
            pou: pou.clone(),
            is_main: pi == 0,
            rung: String::new(),
            kinds: &mut stats.kinds,
            calls: &mut calls,
            jumps: Vec::new(),
        };
        for (ri, r) in rungs.iter().enumerate() {
            let o = r
                .as_object()
                .ok_or_else(|| format!("{pou}: rung {ri} is not an object"))?;
            for k in o.keys() {
                if !["id", "label", "comment", "ld"].contains(&k.as_str()) {
                    return fail(format!("{pou}: rung {ri}: unknown key {k}"));
                }
            }
            let id = o
                .get("id")
                .and_then(Value::as_str)
                .ok_or_else(|| format!("{pou}: rung {ri} without id"))?;
            ids.push(id.to_owned());
            if let Some(c) = o.get("comment") {
                c.as_str()
                    .ok_or_else(|| format!("{id}: comment not a string"))?;
            }
            if let Some(l) = o.get("label") {
                let l = l
                    .as_str()
                    .ok_or_else(|| format!("{id}: label not a string"))?;
                if labels.insert(l.to_owned(), ri).is_some() {
                    return fail(format!("{pou}: duplicate label {l}"));
                }
            }
            checker.rung = id.to_owned();
            checker.series(&o["ld"], "top")?;
            for l in checker.jumps.drain(..) {
                jumps.push((ri, l));
            }
            let ld = o["ld"]
                .as_array()
                .ok_or_else(|| format!("{id}: ld not an array"))?;
            let last = ld.last().and_then(Value::as_object);
            enclosing.push(stack.clone());
            if last.is_some_and(|e| e.contains_key("for")) {
                stack.push(ri);
            } else if last.is_some_and(|e| e.contains_key("next")) && stack.pop().is_none() {
                return fail(format!("{id}: next without for"));
            }
        }
        if !stack.is_empty() {
            return fail(format!("{pou}: {} for without next", stack.len()));
        }
        for (src, l) in jumps {
            let &t = labels
                .get(&l)
                .ok_or_else(|| format!("{pou}: jmp to missing label {l}"))?;
            if t <= src {
                return fail(format!(
                    "{pou}: jmp {l} from rung {src} goes backwards to {t}"
                ));
            }
            if enclosing[t] != enclosing[src] {
                return fail(format!(
                    "{pou}: jmp {l} from rung {src} enters or leaves a FOR body"
                ));
            }
        }
    }

    // Ids: unique and R1..Rn in program order (main first).
    let unique: HashSet<&String> = ids.iter().collect();
    if unique.len() != ids.len() {
        return fail("duplicate rung ids".into());
    }
    for (i, id) in ids.iter().enumerate() {
        if *id != format!("R{}", i + 1) {
            return fail(format!("rung {i} has id {id}, expected R{}", i + 1));
        }
    }

    // No recursion: the call graph among subroutines is acyclic.
    let mut edges: HashMap<&str, Vec<&str>> = HashMap::new();
    for (a, b) in &calls {
        edges.entry(a.as_str()).or_default().push(b.as_str());
    }
    fn visit<'s>(
        n: &'s str,
        edges: &HashMap<&'s str, Vec<&'s str>>,
        path: &mut Vec<&'s str>,
        done: &mut HashSet<&'s str>,
    ) -> Result<(), String> {
        if path.contains(&n) {
            return fail(format!("recursive call chain {path:?} → {n}"));
        }
        if done.contains(n) {
            return Ok(());
        }
        path.push(n);
        for &m in edges.get(n).map(Vec::as_slice).unwrap_or(&[]) {
            visit(m, edges, path, done)?;
        }
        path.pop();
        done.insert(n);
        Ok(())
    }
    let mut done = HashSet::new();
    visit("main", &edges, &mut Vec::new(), &mut done)?;
    for s in &subs {
        visit(s, &edges, &mut Vec::new(), &mut done)?;
    }
    Ok(stats)
}

fn cfg(rungs: usize, width: usize, seed: u64, on: bool) -> GenConfig {
    GenConfig {
        rungs,
        width,
        seed,
        timers: on,
        loops: on,
        jumps: on,
        calls: on,
        for_body: None,
        hot_fraction: None,
        reads: Reads::Local,
    }
}

fn check(c: &GenConfig) -> Stats {
    let text = generate_string(c);
    let stats = validate(&text).unwrap_or_else(|e| panic!("{c:?}: {e}"));
    assert_eq!(stats.main_rungs, c.rungs, "{c:?}: main rung count");
    stats
}

// ---------------------------------------------------------------------------------------------
// Tests

#[test]
fn valid_and_exact_counts_over_many_shapes() {
    for &rungs in &[1usize, 2, 3, 5, 17, 100, 1000, 3000] {
        for &width in &[0usize, 1, 3, 5, 16, 33, 200, 5000] {
            let seeds = if rungs >= 1000 { 1 } else { 3 };
            for seed in 0..seeds {
                for mask in [0u8, 1, 2, 4, 8, 15] {
                    let c = GenConfig {
                        rungs,
                        width,
                        seed,
                        timers: mask & 1 != 0,
                        loops: mask & 2 != 0,
                        jumps: mask & 4 != 0,
                        calls: mask & 8 != 0,
                        for_body: None,
                        hot_fraction: None,
                        reads: if seed % 2 == 1 {
                            Reads::Random
                        } else {
                            Reads::Local
                        },
                    };
                    let stats = check(&c);
                    if c.calls {
                        let n = stats.sub_rungs.len();
                        assert!((2..=4).contains(&n), "{c:?}: {n} subroutines");
                        assert!(
                            stats.sub_rungs.values().all(|r| (3..=10).contains(r)),
                            "{c:?}: {:?}",
                            stats.sub_rungs
                        );
                    } else {
                        assert!(stats.sub_rungs.is_empty());
                    }
                }
            }
        }
    }
}

#[test]
fn knobs_off_means_no_structure() {
    let s = check(&cfg(5000, 40, 9, false));
    for k in [
        "ton", "tof", "tp", "ctu", "ctd", "for", "next", "jmp", "ret", "end", "call",
    ] {
        assert!(
            !s.kinds.contains_key(k),
            "{k} present with knobs off: {:?}",
            s.kinds
        );
    }
    for k in [
        "contact",
        "contact.negated",
        "contact.edge",
        "compare",
        "or",
        "coil",
        "coil.negated",
        "set",
        "reset",
        "branch",
        "move",
        "op",
    ] {
        assert!(s.kinds.contains_key(k), "{k} missing: {:?}", s.kinds);
    }
}

#[test]
fn all_element_kinds_appear_with_all_knobs() {
    let s = check(&GenConfig::all_features(5000, 32, 7));
    println!("element counts: {:?}", s.kinds);
    let all = [
        "contact",
        "contact.negated",
        "contact.edge",
        "compare",
        "or",
        "coil",
        "coil.negated",
        "set",
        "reset",
        "branch",
        "ton",
        "tof",
        "tp",
        "ctu",
        "ctd",
        "move",
        "op",
        "jmp",
        "ret",
        "end",
        "call",
        "for",
        "next",
    ];
    for k in all {
        assert!(s.kinds.contains_key(k), "{k} missing: {:?}", s.kinds);
    }
    // Rates roughly as documented (per 5000 main rungs).
    let n = |k: &str| s.kinds.get(k).copied().unwrap_or(0);
    assert!((10..=50).contains(&n("for")), "for: {}", n("for"));
    assert!((20..=100).contains(&n("jmp")), "jmp: {}", n("jmp"));
    assert!(
        (120..=400).contains(&(n("ton") + n("tof") + n("tp"))),
        "timers: {:?}",
        s.kinds
    );
}

#[test]
fn deterministic_and_seed_sensitive() {
    for on in [false, true] {
        let a = generate_string(&cfg(2000, 24, 42, on));
        let b = generate_string(&cfg(2000, 24, 42, on));
        assert_eq!(a, b, "same config must give the same bytes");
        let c = generate_string(&cfg(2000, 24, 43, on));
        assert_ne!(a, c, "different seeds must differ");
        // write_program and generate_string agree.
        let mut buf = Vec::new();
        write_program(&cfg(2000, 24, 42, on), &mut buf).unwrap();
        assert_eq!(buf, a.as_bytes());
    }
}

/// `--reads random`: normal rung (s, j) still writes `M{j}_{phase(s)}`, and reads 3–6 distinct
/// `M{l}_{phase(s-1)}` of any lanes, far ones included.
#[test]
fn random_reads_layout() {
    let (n, w) = (4000usize, 50usize);
    let c = GenConfig {
        reads: Reads::Random,
        ..cfg(n, w, 3, false)
    };
    let v: Value = serde_json::from_str(&generate_string(&c)).unwrap();
    let mut far = 0;
    let mut counts = [0usize; 7];
    for (r, rung) in v["rungs"].as_array().unwrap().iter().enumerate() {
        let (s, j) = (r / w, r % w);
        let (mut reads, mut writes) = (Vec::new(), Vec::new());
        collect(&rung["ld"], &mut reads, &mut writes);
        let ms: Vec<&String> = writes.iter().filter(|x| x.starts_with('M')).collect();
        assert_eq!(
            ms,
            vec![&format!("M{j}_{}", phase(s))],
            "rung {r} writes {writes:?}"
        );
        let mut lanes = HashSet::new();
        for x in reads.iter().filter(|x| x.starts_with('M')) {
            assert!(s > 0, "stage 0 rung {r} reads {x}");
            let (lane, ph) = x[1..].split_once('_').unwrap();
            let (lane, ph): (usize, usize) = (lane.parse().unwrap(), ph.parse().unwrap());
            assert_eq!(ph, phase(s - 1), "rung {r} (stage {s}) reads {x}");
            let d = (lane + w - j) % w;
            far += (d > 2 && d < w - 2) as usize;
            assert!(lanes.insert(lane), "rung {r} reads lane {lane} twice");
        }
        if s > 0 {
            assert!((3..=6).contains(&lanes.len()), "rung {r} reads {reads:?}");
            counts[lanes.len()] += 1;
        }
    }
    assert!(far > n, "most reads are far: {far}");
    assert!(counts[3] > 0 && counts[6] > 0, "3 to 6 reads: {counts:?}");
}

/// The documented stage/lane layout: normal rung (s, j) writes `M{j}_{phase(s)}` and reads only
/// inputs (stage 0) or `M{l}_{phase(s-1)}` with `l` within 2 lanes of `j` (mod W).
#[test]
fn stage_lane_layout() {
    let (n, w) = (4000usize, 50usize);
    let v: Value = serde_json::from_str(&generate_string(&cfg(n, w, 3, false))).unwrap();
    let rungs = v["rungs"].as_array().unwrap();
    let mut memory_vars = 0;
    for var in v["vars"].as_array().unwrap() {
        let name = var["name"].as_str().unwrap();
        if name.starts_with('M') {
            memory_vars += 1;
        }
    }
    let phases = (0..n.div_ceil(w)).map(|s| phase(s) + 1).max().unwrap();
    assert_eq!(memory_vars, phases * w);
    let inputs = v["vars"]
        .as_array()
        .unwrap()
        .iter()
        .filter(|x| x["class"] == "input")
        .count();
    assert_eq!(inputs, 8.max(w / 8));
    let mut q_written = HashSet::new();
    for (r, rung) in rungs.iter().enumerate() {
        let (s, j) = (r / w, r % w);
        let mut reads = Vec::new();
        let mut writes = Vec::new();
        collect(&rung["ld"], &mut reads, &mut writes);
        let own = format!("M{j}_{}", phase(s));
        let ms: Vec<&String> = writes.iter().filter(|x| x.starts_with('M')).collect();
        assert_eq!(ms, vec![&own], "rung {r} writes {writes:?}");
        q_written.extend(writes.iter().filter(|x| x.starts_with('Q')).cloned());
        for x in &reads {
            // Inputs, and the lane's own INT (an `op` at stage 0 may accumulate into it).
            if x.starts_with('I') || *x == format!("N{j}_{}", phase(s)) {
                continue;
            }
            if s == 0 {
                panic!("stage 0 rung {r} reads {x}");
            }
            let (lane, ph) = x[1..].split_once('_').unwrap();
            let (lane, ph): (usize, usize) = (lane.parse().unwrap(), ph.parse().unwrap());
            let d = (lane + w - j) % w;
            assert!(d <= 2 || d >= w - 2, "rung {r} (lane {j}) reads {x}");
            assert_eq!(ph, phase(s - 1), "rung {r} (stage {s}) reads {x}");
        }
        assert!(reads.len() >= 4, "rung {r} reads only {reads:?}");
    }
    assert_eq!(
        q_written.len(),
        w.div_ceil(16),
        "outputs written: {q_written:?}"
    );
}

/// Variable names read (contacts, compare and box operands) and written (coils, box outputs).
fn collect(series: &Value, reads: &mut Vec<String>, writes: &mut Vec<String>) {
    let name = |v: &Value| {
        v.as_str()
            .map(|s| s.split('.').next().unwrap_or(s).to_owned())
    };
    for e in series.as_array().unwrap() {
        let o = e.as_object().unwrap();
        for k in ["or", "branch"] {
            if let Some(bs) = o.get(k) {
                for b in bs.as_array().unwrap() {
                    collect(b, reads, writes);
                }
            }
        }
        for k in ["contact", "a", "b", "move"] {
            reads.extend(o.get(k).and_then(name));
        }
        if let Some(ins) = o.get("in") {
            reads.extend(ins.as_array().unwrap().iter().filter_map(name));
        }
        for k in ["coil", "set", "reset", "to", "out"] {
            writes.extend(o.get(k).and_then(name));
        }
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(64))]
    #[test]
    fn random_configs_are_valid(rungs in 1usize..400, width in 0usize..70, seed in any::<u64>(), mask in 0u8..16) {
        let c = GenConfig { rungs, width, seed, timers: mask & 1 != 0, loops: mask & 2 != 0, jumps: mask & 4 != 0, calls: mask & 8 != 0, for_body: None, hot_fraction: None, reads: Default::default() };
        let text = generate_string(&c);
        let stats = validate(&text).map_err(|e| TestCaseError::fail(format!("{c:?}: {e}")))?;
        prop_assert_eq!(stats.main_rungs, rungs);
    }
}

/// Counts bytes and rung lines (`{"id":"R` at the start of a line) without keeping the text.
struct Counter {
    bytes: usize,
    rungs: usize,
    /// How much of `PAT` the text seen so far ends with.
    matched: usize,
}

const PAT: &[u8] = b"\n{\"id\":\"R";

impl Write for Counter {
    fn write(&mut self, buf: &[u8]) -> io::Result<usize> {
        self.bytes += buf.len();
        for &b in buf {
            // PAT's first byte does not recur in it, so a mismatch restarts at 0 or 1.
            self.matched = if b == PAT[self.matched] {
                self.matched + 1
            } else if b == PAT[0] {
                1
            } else {
                0
            };
            if self.matched == PAT.len() {
                self.rungs += 1;
                self.matched = 0;
            }
        }
        Ok(buf.len())
    }
    fn flush(&mut self) -> io::Result<()> {
        Ok(())
    }
}

/// One million rungs (100,000 in debug builds), streamed to a counting sink; prints the time.
#[test]
fn million_rungs_stream() {
    let n = if cfg!(debug_assertions) {
        100_000
    } else {
        1_000_000
    };
    for (width, on) in [(1000usize, false), (1000, true), (64, true)] {
        let c = cfg(n, width, 1, on);
        let mut sink = Counter {
            bytes: 0,
            rungs: 0,
            matched: 0,
        };
        let t = Instant::now();
        write_program(&c, &mut sink).unwrap();
        let dt = t.elapsed();
        let subs = if on { sink.rungs - n } else { 0 };
        assert!(
            sink.rungs >= n && subs <= 40,
            "{} rung lines for {n}",
            sink.rungs
        );
        println!(
            "gen {n} rungs, width {width}, knobs {}: {:.3} s, {:.1} MB ({:.0} B/rung, {subs} subroutine rungs)",
            if on { "on" } else { "off" },
            dt.as_secs_f64(),
            sink.bytes as f64 / 1e6,
            sink.bytes as f64 / sink.rungs as f64,
        );
    }
}

// ---------------------------------------------------------------------------------------------
// Hot variable and fixed FOR bodies

/// Main rungs (index, rung) that write / read `name`.
fn rungs_touching(v: &Value, name: &str) -> (Vec<usize>, Vec<usize>) {
    let (mut writers, mut readers) = (Vec::new(), Vec::new());
    for (i, rung) in v["rungs"].as_array().unwrap().iter().enumerate() {
        let (mut reads, mut writes) = (Vec::new(), Vec::new());
        collect(&rung["ld"], &mut reads, &mut writes);
        if writes.iter().any(|x| x == name) {
            writers.push(i);
        }
        if reads.iter().any(|x| x == name) {
            readers.push(i);
        }
    }
    (writers, readers)
}

/// Body lengths of the main program's FOR blocks (header and NEXT excluded).
fn for_bodies(v: &Value) -> Vec<usize> {
    let (mut open, mut bodies) = (Vec::new(), Vec::new());
    for (i, rung) in v["rungs"].as_array().unwrap().iter().enumerate() {
        let last = rung["ld"].as_array().unwrap().last().unwrap();
        if last.get("for").is_some() {
            open.push(i);
        } else if last.get("next").is_some() {
            bodies.push(i - open.pop().unwrap() - 1);
        }
    }
    bodies
}

fn loads(text: &str, c: &GenConfig) {
    if let Err(e) = plc_deps::load::program_from_json(text) {
        panic!("{c:?}: the reader refuses the program: {e}");
    }
}

/// 100,000 rungs with `hot_fraction` 0.05: exactly 5,000 rungs set `FAULT` (always through
/// `set`), 500 read it, evenly spread; every other rung is the rung of the program without it.
#[test]
fn hot_variable_has_the_asked_number_of_writers() {
    let n = 100_000;
    let off = GenConfig {
        seed: 5,
        ..cfg(n, 100, 5, false)
    };
    let hot = GenConfig {
        hot_fraction: Some(0.05),
        ..off.clone()
    };
    let text = generate_string(&hot);
    let stats = validate(&text).unwrap_or_else(|e| panic!("{hot:?}: {e}"));
    assert_eq!(stats.main_rungs, n);
    loads(&text, &hot);
    let v: Value = serde_json::from_str(&text).unwrap();
    let fault: Vec<&Value> = v["vars"]
        .as_array()
        .unwrap()
        .iter()
        .filter(|d| d["name"] == "FAULT")
        .collect();
    assert_eq!(fault.len(), 1);
    assert_eq!(fault[0]["type"], "BOOL");
    let (writers, readers) = rungs_touching(&v, "FAULT");
    assert_eq!(writers.len(), 5_000);
    assert_eq!(readers.len(), 500);
    assert_eq!(text.matches(r#"{"set":"FAULT"}"#).count(), 5_000);
    // Evenly spread: consecutive writers 20 rungs apart (readers 200).
    assert!(writers.windows(2).all(|w| w[1] - w[0] == 20), "{writers:?}");
    assert!(readers.windows(2).all(|w| w[1] - w[0] == 200));
    // The hot variable changes nothing else.
    let plain: Value = serde_json::from_str(&generate_string(&off)).unwrap();
    let (a, b) = (
        v["rungs"].as_array().unwrap(),
        plain["rungs"].as_array().unwrap(),
    );
    for i in 0..n {
        if writers.binary_search(&i).is_err() && readers.binary_search(&i).is_err() {
            assert_eq!(a[i], b[i], "rung {i}");
        }
    }
}

#[test]
fn hot_variable_with_every_knob() {
    for (n, f, seed) in [(20_000usize, 0.05, 1u64), (3_000, 0.5, 2), (500, 0.001, 3)] {
        let c = GenConfig {
            hot_fraction: Some(f),
            ..GenConfig::all_features(n, 64, seed)
        };
        let text = generate_string(&c);
        validate(&text).unwrap_or_else(|e| panic!("{c:?}: {e}"));
        loads(&text, &c);
        let v: Value = serde_json::from_str(&text).unwrap();
        let (writers, readers) = rungs_touching(&v, "FAULT");
        let want = ((f * n as f64).round() as usize).clamp(1, n);
        // Slots on header/NEXT/jump/call rungs are owed to the next normal rungs; only slots
        // still owed after the last normal rung (a NEXT, the end rung) are lost.
        assert!(
            (want.saturating_sub(2)..=want).contains(&writers.len()),
            "{c:?}: {} writers, want {want}",
            writers.len()
        );
        assert!(!readers.is_empty());
        assert_eq!(text, generate_string(&c), "deterministic");
    }
}

/// A 4,000-rung FOR body; the blocks are otherwise as without `for_body`.
#[test]
fn fixed_for_body_length() {
    let c = GenConfig {
        loops: true,
        for_body: Some(4_000),
        ..cfg(10_000, 100, 11, false)
    };
    let text = generate_string(&c);
    validate(&text).unwrap_or_else(|e| panic!("{c:?}: {e}"));
    loads(&text, &c);
    let v: Value = serde_json::from_str(&text).unwrap();
    let bodies = for_bodies(&v);
    assert!(!bodies.is_empty(), "no FOR block");
    assert!(bodies.iter().all(|&b| b == 4_000), "{bodies:?}");
    // The first block starts at rung 0 (the first place it fits).
    assert!(v["rungs"][0]["ld"].as_array().unwrap().last().unwrap()["for"].is_object());
    // Every knob on, small bodies and too-long ones (no block fits: none is made).
    for (n, body) in [(5_000usize, 1usize), (5_000, 37), (2_000, 1_990), (50, 60)] {
        let c = GenConfig {
            for_body: Some(body),
            hot_fraction: Some(0.1),
            ..GenConfig::all_features(n, 40, 3)
        };
        let text = generate_string(&c);
        validate(&text).unwrap_or_else(|e| panic!("{c:?}: {e}"));
        loads(&text, &c);
        let bodies = for_bodies(&serde_json::from_str(&text).unwrap());
        assert!(bodies.iter().all(|&b| b == body), "{c:?}: {bodies:?}");
        assert_eq!(bodies.is_empty(), body + 3 > n, "{c:?}: {bodies:?}");
    }
}

#[test]
fn invalid_configs_are_refused() {
    let bad = [
        cfg(0, 10, 1, false),
        GenConfig {
            for_body: Some(0),
            ..cfg(10, 10, 1, true)
        },
        GenConfig {
            hot_fraction: Some(0.0),
            ..cfg(10, 10, 1, false)
        },
        GenConfig {
            hot_fraction: Some(1.5),
            ..cfg(10, 10, 1, false)
        },
        GenConfig {
            hot_fraction: Some(f64::NAN),
            ..cfg(10, 10, 1, false)
        },
    ];
    for c in bad {
        assert!(c.validate().is_err(), "{c:?}");
        let mut buf = Vec::new();
        let e = write_program(&c, &mut buf).unwrap_err();
        assert_eq!(e.kind(), io::ErrorKind::InvalidInput, "{c:?}");
        assert!(buf.is_empty(), "{c:?}: wrote {} bytes", buf.len());
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(48))]
    #[test]
    fn random_hot_and_for_body_configs_are_valid(
        rungs in 1usize..400,
        width in 0usize..70,
        seed in any::<u64>(),
        mask in 0u8..16,
        body in proptest::option::of(1usize..40),
        hot in proptest::option::of(0.0001f64..=1.0),
    ) {
        let c = GenConfig {
            rungs, width, seed,
            timers: mask & 1 != 0, loops: mask & 2 != 0 || body.is_some(), jumps: mask & 4 != 0, calls: mask & 8 != 0,
            for_body: body,
            hot_fraction: hot,
            reads: if seed % 3 == 0 { Reads::Random } else { Reads::Local },
        };
        let text = generate_string(&c);
        let stats = validate(&text).map_err(|e| TestCaseError::fail(format!("{c:?}: {e}")))?;
        prop_assert_eq!(stats.main_rungs, rungs);
        let v: Value = serde_json::from_str(&text).unwrap();
        if let Some(b) = body {
            prop_assert!(for_bodies(&v).iter().all(|&x| x == b));
        }
        if let Some(f) = hot {
            let want = ((f * rungs as f64).round() as usize).clamp(1, rungs);
            let (writers, _) = rungs_touching(&v, "FAULT");
            // Only slots owed by rungs that cannot carry one (header, NEXT, jump, call, end)
            // can be lost.
            let structural = v["rungs"].as_array().unwrap().iter().filter(|r| {
                let last = r["ld"].as_array().unwrap().last().unwrap();
                ["for", "next", "jmp", "call", "end"].iter().any(|k| last.get(*k).is_some())
            }).count();
            prop_assert!(writers.len() <= want && writers.len() + structural >= want, "{:?}: {} writers, want {}", c, writers.len(), want);
        }
    }
}
