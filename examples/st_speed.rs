//! Structured Text against ladder: the same logic written as an ST program of N statements (a
//! PLCopen export of Beremiz's shape) and as a ladder program of N rungs (the JSON format), run
//! by the same interpreter. Prints ns per statement and per rung (medians of the rounds, with
//! their range, and the per-round ratio), checks that both end every run in the same state, and
//! that the ST program's parallel scan ends in the sequential scan's state.
//!
//! `cargo run --release --example st_speed [statements] [scans] [rounds]` (default 10,000 × 200
//! × 5).
//!
//! The statements, drawn with a fixed seed, are of two kinds, each with its rung:
//! - `cK := iA AND NOT iB AND iC AND iD AND NOT iE AND iF;` (two of three): six contacts and a
//!   coil, as `examples/exec_speed.rs`; an operand is sometimes an earlier such statement's `cJ`;
//! - `IF iA AND NOT iB THEN nK := nJ + 1; END_IF;` (one of three; `nJ` an earlier one's): two contacts and an ADD box
//!   (DINT, which matiec's C computes as it is written: no widening).
//!
//! Nothing here is used by the tool.

use plc_deps::analysis::analyse;
use plc_deps::exec::parallel::{ParallelMachine, PlanConfig, PlanKind, ScanDriver};
use plc_deps::exec::{ExecConfig, Fault, Layout, Machine};
use plc_deps::model::{Program, Value, VarId};
use serde_json::json;
use std::fmt::Write as _;
use std::time::{Duration, Instant};

const INPUTS: usize = 64;

enum Stmt {
    Logic {
        out: usize,
        ops: Vec<(String, bool)>,
    },
    Count {
        out: usize,
        a: usize,
        b: usize,
        from: usize,
    },
}

fn statements(n: usize) -> Vec<Stmt> {
    let mut x = 0x9E37_79B9_7F4A_7C15u64;
    let mut rand = move || {
        x ^= x << 13;
        x ^= x >> 7;
        x ^= x << 17;
        x
    };
    let (mut counts, mut logic): (Vec<usize>, Vec<usize>) = (Vec::new(), Vec::new());
    (0..n)
        .map(|k| {
            if rand() % 3 == 2 {
                // An earlier counting statement's `n`, or its own.
                let from = match counts.len() {
                    0 => k,
                    c => counts[rand() as usize % c],
                };
                counts.push(k);
                Stmt::Count {
                    out: k,
                    a: rand() as usize % INPUTS,
                    b: rand() as usize % INPUTS,
                    from,
                }
            } else {
                let ops = (0..6)
                    .map(|_| {
                        let r = rand();
                        let name = if !logic.is_empty() && r % 4 == 0 {
                            format!("c{}", logic[(r >> 8) as usize % logic.len()])
                        } else {
                            format!("i{}", (r >> 8) as usize % INPUTS)
                        };
                        (name, (r >> 40) % 3 == 0)
                    })
                    .collect();
                logic.push(k);
                Stmt::Logic { out: k, ops }
            }
        })
        .collect()
}

fn st_program(stmts: &[Stmt]) -> String {
    let mut vars = String::new();
    for i in 0..INPUTS {
        let _ = writeln!(
            vars,
            r#"<variable name="i{i}" address="%IX{}.{}"><type><BOOL/></type></variable>"#,
            i / 8,
            i % 8
        );
    }
    let mut locals = String::new();
    let mut body = String::new();
    for s in stmts {
        match s {
            Stmt::Logic { out, ops } => {
                let _ = writeln!(
                    locals,
                    r#"<variable name="c{out}"><type><BOOL/></type></variable>"#
                );
                let terms: Vec<String> = ops
                    .iter()
                    .map(|(n, neg)| if *neg { format!("NOT {n}") } else { n.clone() })
                    .collect();
                let _ = writeln!(body, "c{out} := {};", terms.join(" AND "));
            }
            Stmt::Count { out, a, b, from } => {
                let _ = writeln!(
                    locals,
                    r#"<variable name="n{out}"><type><DINT/></type></variable>"#
                );
                let _ = writeln!(
                    body,
                    "IF i{a} AND NOT i{b} THEN n{out} := n{from} + 1; END_IF;"
                );
            }
        }
    }
    format!(
        r#"<?xml version="1.0" encoding="utf-8"?>
<project xmlns="http://www.plcopen.org/xml/tc6_0201">
<fileHeader companyName="plc-deps" productName="Beremiz" productVersion="1" creationDateTime="2026-12-07T00:00:00"/>
<contentHeader name="st_speed"><coordinateInfo><fbd><scaling x="1" y="1"/></fbd><ld><scaling x="1" y="1"/></ld><sfc><scaling x="1" y="1"/></sfc></coordinateInfo></contentHeader>
<types><dataTypes/><pous><pou name="main" pouType="program"><interface>
<localVars>
{vars}{locals}</localVars></interface>
<body><ST><xhtml:p xmlns:xhtml="http://www.w3.org/1999/xhtml"><![CDATA[
{body}]]></xhtml:p></ST></body></pou></pous></types>
<instances><configurations/></instances></project>
"#
    )
}

fn ladder_program(stmts: &[Stmt]) -> serde_json::Value {
    let mut vars: Vec<serde_json::Value> = (0..INPUTS)
        .map(|i| json!({"name": format!("i{i}"), "type": "BOOL", "class": "input"}))
        .collect();
    let mut rungs = Vec::new();
    for s in stmts {
        match s {
            Stmt::Logic { out, ops } => {
                vars.push(json!({"name": format!("c{out}"), "type": "BOOL"}));
                let mut ld: Vec<serde_json::Value> = ops
                    .iter()
                    .map(|(n, neg)| json!({"contact": n, "negated": neg}))
                    .collect();
                ld.push(json!({"coil": format!("c{out}")}));
                rungs.push(json!({"id": format!("R{out}"), "ld": ld}));
            }
            Stmt::Count { out, a, b, from } => {
                vars.push(json!({"name": format!("n{out}"), "type": "DINT"}));
                let ld = json!([
                    {"contact": format!("i{a}")},
                    {"contact": format!("i{b}"), "negated": true},
                    {"op": "ADD", "in": [format!("n{from}"), 1], "out": format!("n{out}")}
                ]);
                rungs.push(json!({"id": format!("R{out}"), "ld": ld}));
            }
        }
    }
    json!({"program": "ladder", "vars": vars, "rungs": rungs})
}

/// The variable of each name the benchmark compares, in the program.
fn ids(p: &Program, names: &[String]) -> Vec<VarId> {
    names
        .iter()
        .map(|n| {
            let i = p
                .vars()
                .iter()
                .position(|v| v.name == *n || v.name.ends_with(&format!(".{n}")))
                .unwrap_or_else(|| panic!("no variable {n}"));
            p.vars().id(i)
        })
        .collect()
}

fn med(v: &[f64]) -> (f64, f64, f64) {
    let mut v = v.to_vec();
    v.sort_by(f64::total_cmp);
    (v[v.len() / 2], v[0], v[v.len() - 1])
}

/// Sets the inputs of pattern `scan % 16` before each scan.
struct Feed<'a> {
    patterns: &'a [Vec<(VarId, Value)>],
}

impl ScanDriver for Feed<'_> {
    fn before_scan(&mut self, m: &Machine, scan: u64, slots: &mut [u8]) {
        m.set_inputs_in(slots, &self.patterns[scan as usize % 16]);
    }
    fn after_scan(&mut self, _: &Machine, _: u64, _: &[u8], _: &[Fault], _: Duration) {}
}

fn main() {
    let mut args = std::env::args().skip(1);
    let n: usize = args
        .next()
        .map_or(10_000, |a| a.parse().expect("statements"));
    let scans: u64 = args.next().map_or(200, |a| a.parse().expect("scans"));
    let rounds: usize = args.next().map_or(5, |a| a.parse().expect("rounds"));
    let stmts = statements(n);
    let t = Instant::now();
    let xml = st_program(&stmts);
    let (st, _, _) = plc_deps::load::plcopen_for_run(&xml).expect("the ST program loads");
    let st_load = t.elapsed();
    let ld = plc_deps::load::program_from_value(&ladder_program(&stmts)).expect("ladder loads");
    let st_m = Machine::new(&st, Layout::dense(&st), &ExecConfig::default()).expect("lowers");
    let ld_m = Machine::new(&ld, Layout::dense(&ld), &ExecConfig::default()).expect("lowers");
    let names: Vec<String> = (0..INPUTS).map(|i| format!("i{i}")).collect();
    let outs: Vec<String> = stmts
        .iter()
        .map(|s| match s {
            Stmt::Logic { out, .. } => format!("c{out}"),
            Stmt::Count { out, .. } => format!("n{out}"),
        })
        .collect();
    let (st_in, ld_in) = (ids(&st, &names), ids(&ld, &names));
    let (st_out, ld_out) = (ids(&st, &outs), ids(&ld, &outs));
    let mut x = 0x2545_F491_4F6C_DD1Du64;
    let mut bits = move || {
        x ^= x << 13;
        x ^= x >> 7;
        x ^= x << 17;
        x.is_multiple_of(2)
    };
    let raw: Vec<Vec<bool>> = (0..16)
        .map(|_| (0..INPUTS).map(|_| bits()).collect())
        .collect();
    let pattern = |ins: &[VarId]| -> Vec<Vec<(VarId, Value)>> {
        raw.iter()
            .map(|r| {
                ins.iter()
                    .zip(r)
                    .map(|(&v, &b)| (v, Value::Bool(b)))
                    .collect()
            })
            .collect()
    };
    let (st_pat, ld_pat) = (pattern(&st_in), pattern(&ld_in));
    let mut faults = Vec::new();
    let (mut st_ns, mut ld_ns, mut ratio) = (Vec::new(), Vec::new(), Vec::new());
    for _ in 0..rounds {
        let mut per = [0.0f64; 2];
        for (k, (m, pat)) in [(&st_m, &st_pat), (&ld_m, &ld_pat)].into_iter().enumerate() {
            let mut state = m.initial_state();
            for s in 0..16 {
                m.set_inputs(&mut state, &pat[s as usize % 16]);
                m.run_scan(&mut state, s, &mut faults);
            }
            let t = Instant::now();
            for s in 16..16 + scans {
                m.set_inputs(&mut state, &pat[s as usize % 16]);
                m.run_scan(&mut state, s, &mut faults);
            }
            per[k] = t.elapsed().as_nanos() as f64 / (scans as f64 * n as f64);
            std::hint::black_box(&state);
        }
        st_ns.push(per[0]);
        ld_ns.push(per[1]);
        ratio.push(per[0] / per[1]);
    }
    assert!(faults.is_empty(), "no faults: {faults:?}");
    // The same end state: 16 + scans scans of the same inputs on each.
    let end = |m: &Machine, pat: &[Vec<(VarId, Value)>]| {
        let mut state = m.initial_state();
        let mut f = Vec::new();
        for s in 0..16 + scans {
            m.set_inputs(&mut state, &pat[s as usize % 16]);
            m.run_scan(&mut state, s, &mut f);
        }
        state
    };
    let (st_end, ld_end) = (end(&st_m, &st_pat), end(&ld_m, &ld_pat));
    for (k, (&a, &b)) in st_out.iter().zip(&ld_out).enumerate() {
        assert_eq!(
            format!("{:?}", st_m.value(&st_end, a)),
            format!("{:?}", ld_m.value(&ld_end, b)),
            "statement {k} and rung {k} differ"
        );
    }
    // seq == par on the ST program: the parallel machine's end state is the sequential one's.
    let analysis = analyse(&st);
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .build()
        .expect("a pool");
    let config = PlanConfig {
        kind: PlanKind::Par,
        ..PlanConfig::new(2)
    };
    let pm = ParallelMachine::new(&st, &analysis, &ExecConfig::default(), &config)
        .expect("the parallel machine lowers");
    let mut par = pm.initial_state();
    pm.run(
        Some(&pool),
        &mut par,
        0..16 + scans,
        &mut Feed { patterns: &st_pat },
    );
    let seq = end(pm.machine(), &st_pat);
    assert!(
        par.bytes() == seq.bytes(),
        "the parallel scan ends in a state other than the sequential scan's"
    );
    let par_note = match pm.sequential_reason() {
        Some(why) => format!("the parallel machine ran sequentially: {why}"),
        None => format!("{} levels on 2 threads", pm.plan().levels().len()),
    };
    let (s, slo, shi) = med(&st_ns);
    let (l, llo, lhi) = med(&ld_ns);
    let (r, rlo, rhi) = med(&ratio);
    println!(
        "{n} statements / rungs, {scans} scans × {rounds} rounds; ST loaded and lowered in {:.0} ms \
         ({} instructions, ladder {})",
        st_load.as_secs_f64() * 1e3,
        st_m.instruction_count(),
        ld_m.instruction_count()
    );
    println!("  ST     {s:6.2} ns/statement ({slo:.2}–{shi:.2})");
    println!("  ladder {l:6.2} ns/rung      ({llo:.2}–{lhi:.2})");
    println!("  ST / ladder, per round: {r:.2} ({rlo:.2}–{rhi:.2}); end states equal");
    println!("  ST seq == par after {} scans ({par_note})", 16 + scans);
}
