//! The generated C, compiled with `cc -std=c11 -Wall -Wextra -Werror -O2` and run, gives after
//! every scan the same state (as the JSON line of `plc-deps run --format json`'s `state`) and the
//! same faults as the sequential interpreter: on every `analyses/` example and on thousands of
//! random ladder and FBD programs (with nested function block types) and generated programs,
//! compiled many to a binary (`common::c::Batch`). Example C's C has the shape the FBD
//! text-generation paper prints.

use crate::common;

use common::c::{compile, fresh_dir, random_csv, run_with_input, Batch};
use common::Rng;
use plc_deps::codegen::c::{generate, CConfig};
use std::path::PathBuf;

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

/// Binaries per batch: compiled in parallel on the two cores.
const PARTS: usize = 2;

#[test]
fn every_example_matches_the_interpreter_after_every_scan() {
    let mut batch = Batch::default();
    for e in std::fs::read_dir(root().join("analyses")).unwrap() {
        let dir = e.unwrap().path();
        // `analyses/plcopen/` holds the PLCopen exports, checked by their own test.
        let Ok(text) = std::fs::read_to_string(dir.join("program.json")) else {
            continue;
        };
        let csv = std::fs::read_to_string(dir.join("inputs.csv")).unwrap_or_default();
        // The committed runs use a 1 s cycle (their timers run out within the scenario); the
        // KASKAD examples run 700 scans of 10 ms (their toggles are at 100, 201, …).
        let (cycle_ms, scans) = if csv.is_empty() {
            (10, 700)
        } else {
            (1000, 60)
        };
        let cfg = CConfig {
            cycle_ms,
            ..CConfig::default()
        };
        let name = dir.file_name().unwrap().to_string_lossy().into_owned();
        batch.add(text, csv, scans, cfg, name);
    }
    assert!(batch.len() >= 11, "{} examples", batch.len());
    batch.check(PARTS, "examples");
}

/// Compares the programs `make(seed)` gives for `seeds` (those that load), each with random
/// inputs and a random cycle and loop cap; at least `min` must load.
fn random_programs(
    tag: &str,
    seeds: std::ops::Range<u64>,
    min: usize,
    make: impl Fn(u64) -> String,
    chunk_rungs: impl Fn(&mut Rng) -> usize,
) {
    let mut batch = Batch::default();
    for seed in seeds {
        let text = make(seed);
        let Ok(p) = plc_deps::load::program_from_json(&text) else {
            continue;
        };
        let mut rng = Rng::new(seed + 1000);
        let csv = random_csv(&p, &mut rng, 30);
        let cfg = CConfig {
            cycle_ms: 1 + rng.below(50) as u32,
            loop_cap: 1 + rng.below(200) as u32,
            chunk_rungs: chunk_rungs(&mut rng),
            // Every other program with its rungs of contacts and coils as table rows.
            rows: seed % 2 == 1,
            // Budgets that the random loops and calls reach now and then (scan-budget faults).
            scan_budget: 10 + rng.below(300),
            ..CConfig::default()
        };
        batch.add(text, csv, 40, cfg, format!("{tag}-{seed}"));
    }
    assert!(
        batch.len() >= min,
        "only {} {tag} programs loaded",
        batch.len()
    );
    batch.check(PARTS, tag);
}

#[test]
fn random_ladder_programs_match_the_interpreter() {
    random_programs(
        "ladder",
        0..700,
        350,
        |seed| common::random_program(seed, 24),
        |rng| 1 + rng.below(8) as usize,
    );
}

#[test]
fn generated_programs_with_every_feature_match_the_interpreter() {
    random_programs(
        "gen",
        0..6,
        6,
        |seed| {
            let gc = plc_deps::synth::GenConfig::all_features(400, 20, seed);
            plc_deps::synth::generate_string(&gc)
        },
        |_| 64,
    );
}

#[test]
fn random_fbd_programs_match_the_interpreter() {
    random_programs("fbd", 0..500, 200, common::fbd::random_fbd_program, |_| {
        CConfig::default().chunk_rungs
    });
}

#[test]
fn random_fbd_programs_with_nested_fb_types_match_the_interpreter() {
    // One function per type: FB1, FB2 (nested in FB1 and at the top), FB3 (ladder).
    for seed in 0..40u64 {
        let text = common::fbd::random_nested_fbd_program(seed);
        let Ok((p, fbd)) = plc_deps::load::program_and_fbd_from_json(&text) else {
            continue;
        };
        let files = generate(&p, &fbd, &CConfig::default());
        let fns: usize = files
            .iter()
            .filter(|f| f.name.starts_with("fb_"))
            .map(|f| f.text.matches("_body(_fb_").count())
            .sum();
        assert_eq!(fns, 3, "fbd-nested-{seed}: functions of the 3 types");
    }
    random_programs(
        "fbd-nested",
        0..500,
        150,
        common::fbd::random_nested_fbd_program,
        |_| CConfig::default().chunk_rungs,
    );
}

/// Example C of the FBD text-generation paper: compute 3 and 4; `if (3) {flag = 1; 8}`;
/// `if (4) {flag = 1; 10; 27; if (27) {24}}`; `if (flag) {15; 17}` — checked on the text's
/// structure (its lines without the comments), its behaviour by the example test above.
#[test]
fn example_c_has_the_shape_the_paper_prints() {
    let text = std::fs::read_to_string(root().join("analyses/example-c/program.json")).unwrap();
    let (p, fbd) = plc_deps::load::program_and_fbd_from_json(&text).unwrap();
    let files = generate(&p, &fbd, &CConfig::default());
    let body = &files
        .iter()
        .find(|f| f.name == "pou_block1.c")
        .unwrap()
        .text;
    let code: Vec<&str> = body
        .lines()
        .map(str::trim)
        .filter(|l| !l.starts_with("/*") && !l.is_empty())
        .collect();
    let start = code
        .iter()
        .position(|l| l.starts_with("_run0_3 = 0"))
        .unwrap();
    assert_eq!(
        code[start..].to_vec(),
        vec![
            "_run0_3 = 0;",
            "_3_0 = (self->_v_Var1 == 1);",
            "_4_0 = (self->_v_Var1 == 2);",
            "if (_3_0) {",
            "_run0_3 = 1;",
            "self->_v_LVar = _plc_add_i16(self->_v_Var2, 10);",
            "}",
            "if (_4_0) {",
            "_run0_3 = 1;",
            "_10_0 = _plc_mul_i16(self->_v_Var2, 3);",
            "self->_v_LVar = _10_0;",
            "_27_0 = (_10_0 > 0);",
            "if (_27_0) {",
            "self->_v_Var3 = _plc_mul_i16(self->_v_Var3, _10_0);",
            "}",
            "}",
            "if (_run0_3) {",
            "_15_0 = _plc_sub_i16(self->_v_LVar, 1);",
            "self->_v_WriteValue_17._v_IVal = _15_0;",
            // The call charges the block's two rungs to its task's scan budget (docs/scan.md).
            "if (_plc_charge(ctx, 19, 2, PLC_SCAN_BUDGET, 14)) _fb_WriteValue_body(&self->_v_WriteValue_17, self, ctx);",
            "self->_v_Written = self->_v_WriteValue_17._v_OVal;",
            "}",
            "}",
        ]
    );
    // One local per data arc (3, 4, 10, 15, 27) and the run flag; nothing stored twice.
    for local in ["_3_0", "_4_0", "_10_0", "_15_0", "_27_0", "_run0_3"] {
        assert!(
            code.iter().any(|l| l.contains(&format!(" {local} = 0;"))),
            "{local}"
        );
    }
}

/// n-input blocks are one statement into their destination (no store per step), and run as
/// the interpreter runs them: INT wrap-around, a REAL chain's rounding, a destination that is
/// also an input (the lowering's temporary), MAX/MIN/LIMIT.
#[test]
fn n_input_blocks_are_one_statement() {
    let doc = serde_json::json!({"program": "nin", "vars": [
        {"name": "a", "type": "INT", "class": "input"}, {"name": "b", "type": "INT", "class": "input"},
        {"name": "c", "type": "INT", "class": "input"}, {"name": "x", "type": "REAL", "class": "input"},
        {"name": "s", "type": "INT"}, {"name": "m", "type": "INT"}, {"name": "l", "type": "INT"},
        {"name": "r", "type": "REAL"}, {"name": "acc", "type": "INT", "init": 1}],
     "fbd": {"networks": [{"id": "N1", "blocks": [
        {"id": 1, "op": "ADD", "in": ["a", "b", "c"], "out": "s"},
        {"id": 2, "op": "MAX", "in": ["a", "b", "c"], "out": "m"},
        {"id": 3, "op": "LIMIT", "in": [-5, "a", 10], "out": "l"},
        {"id": 4, "op": "MUL", "in": ["x", 0.1, "x", 3.0], "out": "r"},
        {"id": 5, "op": "MUL", "in": ["acc", "a", "acc"], "out": "acc"}
     ]}]}})
    .to_string();
    let (p, fbd) = plc_deps::load::program_and_fbd_from_json(&doc).unwrap();
    let files = generate(&p, &fbd, &CConfig::default());
    let body = &files.iter().find(|f| f.name == "pou_nin.c").unwrap().text;
    for line in [
        "self->_v_s = _plc_add_i16(_plc_add_i16(self->_v_a, self->_v_b), self->_v_c);",
        "self->_v_m = _plc_max_i16(_plc_max_i16(self->_v_a, self->_v_b), self->_v_c);",
        "self->_v_l = _plc_min_i16(_plc_max_i16(self->_v_a, -5), 10);",
        "self->_v_r = ((self->_v_x * 0.1f) * self->_v_x) * 3.0f;",
    ] {
        assert!(body.lines().any(|l| l.trim() == line), "{line}\n{body}");
    }
    let mut rng = Rng::new(11);
    let mut csv = String::from("a,b,c,x\n");
    for _ in 0..60 {
        let int = |rng: &mut Rng| match rng.below(4) {
            0 => 32767i64,
            1 => -32768,
            _ => rng.below(201) as i64 - 100,
        };
        let (a, b, c) = (int(&mut rng), int(&mut rng), int(&mut rng));
        let x = (rng.below(20001) as f64 - 10000.0) / 7.0;
        csv.push_str(&format!("{a},{b},{c},{x}\n"));
    }
    let mut batch = Batch::default();
    batch.add(doc, csv, 60, CConfig::default(), "nin".into());
    batch.check(1, "nin");
}

/// `_plc_put_real` prints every float as `run --format json` does (shortest decimal, ties up,
/// serde_json's exponent form), on random bit patterns and on values near powers of ten.
#[test]
fn reals_print_as_the_run_report_prints_them() {
    use plc_deps::exec::VarValue;
    use plc_deps::model::Value;
    let dir = fresh_dir("reals");
    std::fs::write(dir.join("plc_runtime.h"), plc_deps::codegen::c::RUNTIME_H).unwrap();
    std::fs::write(
        dir.join("reals.c"),
        "#include \"plc_runtime.h\"\nint main(void) { unsigned b; while (scanf(\"%u\", &b) == 1) \
         { _plc_put_real(stdout, _plc_f32(b)); putchar('\\n'); } return 0; }\n",
    )
    .unwrap();
    compile(&dir, "reals", &["reals.c".to_string()]);
    let mut rng = Rng::new(5);
    let mut bits: Vec<u32> = (0..20_000).map(|_| rng.next() as u32).collect();
    for e in -12..=20 {
        // 9.999_999 is written as users write it (it rounds to a nearby f32); 46.757_812_5
        // is exact. Both are the point of the test: what C and Rust print for them.
        #[allow(clippy::excessive_precision)]
        for d in [1.0f32, 1.5, 9.999_999, 46.757_812_5, 0.1, 0.3] {
            bits.push((d * 10f32.powi(e)).to_bits());
        }
    }
    bits.extend([0, 0x8000_0000, 1, 0x7f7f_ffff, 0x7f80_0000, 0x7fc0_0000]);
    let input: String = bits.iter().map(|b| format!("{b}\n")).collect();
    let out = run_with_input(&dir.join("reals"), &[], input.as_bytes());
    let lines: Vec<&str> = std::str::from_utf8(&out.stdout).unwrap().lines().collect();
    assert_eq!(lines.len(), bits.len());
    for (b, line) in bits.iter().zip(&lines) {
        let want = VarValue::Scalar(Value::Real(f32::from_bits(*b)))
            .to_json()
            .to_string();
        assert_eq!(*line, want, "bits {b:#010x}");
    }
    let _ = std::fs::remove_dir_all(dir);
}

/// A ladder POU of more chunk functions than 8 part files of 16 hold is cut into 8 part files
/// that grow instead (the build stays linear: every part file parses the whole state), and the
/// C still matches the interpreter.
#[test]
fn a_large_pou_is_cut_into_at_most_eight_part_files_and_stays_exact() {
    let gc = plc_deps::synth::GenConfig {
        rungs: 600,
        width: 30,
        seed: 3,
        timers: true,
        ..Default::default()
    };
    let text = plc_deps::synth::generate_string(&gc);
    let (p, fbd) = plc_deps::load::program_and_fbd_from_json(&text).unwrap();
    // One rung per function: 600 functions, 75 per file (600 / 8), so 8 files
    // (the rungs as statements: with rows, a run of rows of one kernel is one unit).
    let cfg = CConfig {
        chunk_rungs: 1,
        rows: false,
        ..CConfig::default()
    };
    let files = generate(&p, &fbd, &cfg);
    let per_file: Vec<usize> = (0..)
        .map_while(|n| {
            let name = format!("_part{n}.c");
            let f = files.iter().find(|f| f.name.ends_with(&name))?;
            Some(f.text.matches("(void *_self, _plc_ctx *ctx) {").count())
        })
        .collect();
    assert_eq!(per_file, vec![75; 8]);
    let mut rng = Rng::new(3);
    let csv = random_csv(&p, &mut rng, 30);
    let mut batch = Batch::default();
    batch.add(text, csv, 40, cfg, "parts".into());
    batch.check(1, "parts");
}

/// The rows' data files (`plc_table*.c`) and kernels (`plc_rows*.c`) of `files`.
fn rows_text(files: &[plc_deps::codegen::c::CFile]) -> (String, String) {
    let pick = |f: &dyn Fn(&str) -> bool| -> String {
        files
            .iter()
            .filter(|x| f(&x.name))
            .map(|x| x.text.as_str())
            .collect()
    };
    (
        pick(&|n| n.starts_with("plc_table")),
        pick(&|n| n.starts_with("plc_rows")),
    )
}

/// The kinds of row none of `kernels` (and none of the rows `ids` of `p`) is: contacts (their
/// negations in the pattern word), ORs, edges, INT compares, INT moves, arithmetic, DIV/MOD,
/// timer and counter boxes, two outputs, and (data, not code) coil, negated coil, set, reset,
/// rising and falling edges (also inside an OR), each compare operator, ADD, SUB, MUL, DIV and
/// MOD (also by zero), TON, TOF, TP, CTU and CTD, and reads of a timer's or counter's Q and a
/// counter's CV.
fn missing_kinds(
    kernels: &str,
    p: &plc_deps::model::Program,
    ids: &std::collections::HashSet<String>,
) -> Vec<&'static str> {
    use plc_deps::model::{walk_elements, ArithOp, ContactKind, Element, Field, Operand, Value};
    let mut seen = std::collections::HashSet::new();
    for r in p.rungs().iter().filter(|r| ids.contains(&r.id)) {
        for e in &r.series {
            if let Element::Or(bs) = e {
                let mut edge = false;
                walk_elements(&bs.concat(), &mut |e| {
                    edge |= matches!(
                        e,
                        Element::Contact {
                            kind: ContactKind::Rising { .. } | ContactKind::Falling { .. },
                            ..
                        }
                    )
                });
                if edge {
                    seen.insert("an edge inside an OR");
                }
            }
        }
        walk_elements(&r.series, &mut |e| {
            let kind = match e {
                Element::Coil { negated: false, .. } => "a coil",
                Element::Coil { negated: true, .. } => "a negated coil",
                Element::Set(_) => "a set",
                Element::Reset(_) => "a reset",
                Element::Contact { var, kind } => {
                    match (var.field, kind) {
                        (Some(Field::Q), _) => seen.insert("a read of a Q"),
                        (_, ContactKind::Rising { .. }) => seen.insert("a rising edge"),
                        (_, ContactKind::Falling { .. }) => seen.insert("a falling edge"),
                        _ => false,
                    };
                    return;
                }
                Element::Compare { op, a, b } => {
                    for o in [a, b] {
                        if matches!(o, Operand::Var(v) if v.field == Some(Field::Cv)) {
                            seen.insert("a read of a CV");
                        }
                    }
                    seen.insert(op.name());
                    return;
                }
                Element::Arith { op, b, .. } => {
                    if matches!(op, ArithOp::Div | ArithOp::Mod)
                        && matches!(b, Operand::Const(Value::Int(0)))
                    {
                        seen.insert("a division by zero");
                    }
                    op.name()
                }
                Element::Timer { kind, .. } => kind.name(),
                Element::Ctu { .. } => "CTU",
                Element::Ctd { .. } => "CTD",
                _ => return,
            };
            seen.insert(kind);
        });
    }
    let code = [
        ("contacts", kernels.contains("(((q ^ t[")),
        (
            "an OR",
            // In the power's expression, whatever its branches start with.
            kernels
                .lines()
                .any(|l| l.trim_start().starts_with("unsigned p =") && l.contains(" | ")),
        ),
        ("an edge", kernels.contains("unsigned e")),
        ("a compare", kernels.contains("_plc_cmp_row_i16(t[")),
        (
            "a move",
            kernels.contains("= p ? *(int16_t *)") || kernels.contains("= p ? (int16_t)"),
        ),
        ("arithmetic", kernels.contains("= p ? _plc_ring_row_i16(")),
        ("DIV/MOD", kernels.contains("= p ? _plc_divmod_row_i16(")),
        ("a timer", kernels.contains("p = _plc_timer_row(")),
        ("a counter", kernels.contains("p = _plc_counter_row(")),
        ("two outputs", kernels.contains("s[t[2]] = _pou__bit[")),
    ];
    let data = [
        "a coil",
        "a negated coil",
        "a set",
        "a reset",
        "a rising edge",
        "a falling edge",
        "an edge inside an OR",
        "EQ",
        "NE",
        "LT",
        "LE",
        "GT",
        "GE",
        "ADD",
        "SUB",
        "MUL",
        "DIV",
        "MOD",
        "a division by zero",
        "ton",
        "tof",
        "tp",
        "CTU",
        "CTD",
        "a read of a Q",
        "a read of a CV",
    ];
    code.into_iter()
        .filter(|k| !k.1)
        .map(|k| k.0)
        .chain(data.into_iter().filter(|k| !seen.contains(k)))
        .collect()
}

/// The rung ids of the rows of a data file, in table order (`    12, 5, 3, /* R1 */`).
fn row_ids(tables: &str) -> Vec<String> {
    tables
        .lines()
        .filter_map(|l| Some(l.split("/* ").nth(1)?.strip_suffix(" */")?.to_string()))
        .filter(|id| !id.starts_with("Rows of"))
        .collect()
}

/// Whether some row comes before a row of an earlier rung (`p`'s rung order).
fn reordered(p: &plc_deps::model::Program, ids: &[String]) -> bool {
    let at: std::collections::HashMap<&str, usize> = p
        .rungs()
        .iter()
        .enumerate()
        .map(|(i, r)| (r.id.as_str(), i))
        .collect();
    ids.windows(2)
        .any(|w| at[w[0].as_str()] > at[w[1].as_str()])
}

/// By default the rungs of contacts and coils of a generated program (ORs, edges, set/reset,
/// negated coils, two-coil outputs) become rows of kernels specialised by shape, reordered
/// within their dependence levels so that rows of one kernel run together, and the C still
/// matches the interpreter; `rows: false` writes every rung as statements.
#[test]
fn rows_carry_the_contact_and_coil_rungs_and_stay_exact() {
    let gc = plc_deps::synth::GenConfig {
        rungs: 3000,
        width: 100,
        seed: 5,
        ..Default::default()
    };
    let text = plc_deps::synth::generate_string(&gc);
    let (p, fbd) = plc_deps::load::program_and_fbd_from_json(&text).unwrap();
    let cfg = CConfig::default();
    assert!(cfg.rows, "rows are the default");
    let files = generate(&p, &fbd, &cfg);
    let (tables, kernels) = rows_text(&files);
    let ids = row_ids(&tables);
    assert!(
        ids.len() * 100 >= p.rungs().len() * 95,
        "{} rows of {} rungs",
        ids.len(),
        p.rungs().len()
    );
    assert!(reordered(&p, &ids), "rows in program order");
    let set = ids.iter().cloned().collect();
    // The kinds a program of contacts, coils and INT boxes has (no timers, counters, DIV/MOD).
    let basic = [
        "contacts",
        "an OR",
        "an edge",
        "a compare",
        "a move",
        "arithmetic",
        "two outputs",
        "a coil",
        "a negated coil",
        "a set",
        "a reset",
        "a rising edge",
        "a falling edge",
    ];
    let missing = missing_kinds(&kernels, &p, &set);
    assert!(
        !missing.iter().any(|k| basic.contains(k)),
        "missing {missing:?}"
    );
    // Without rows there is none.
    let stmts = CConfig {
        rows: false,
        ..CConfig::default()
    };
    let plain = generate(&p, &fbd, &stmts);
    assert_eq!(rows_text(&plain), (String::new(), String::new()));
    let mut rng = Rng::new(5);
    let csv = random_csv(&p, &mut rng, 30);
    let mut batch = Batch::default();
    batch.add(text.clone(), csv.clone(), 40, cfg, "rows".into());
    batch.add(text, csv, 40, stmts, "statements".into());
    batch.check(1, "rows");
}

/// The random ladder programs the differential test compiles with rows have rows of every
/// kind (so that test exercises them), and rows are reordered in some of them and in every
/// generated program that test compiles with rows.
#[test]
fn random_ladder_programs_have_rows_of_every_kind() {
    let (mut kernels, mut count) = (String::new(), 0);
    let mut missing: Option<Vec<&str>> = None;
    for seed in (1..700).step_by(2) {
        let Ok((p, fbd)) =
            plc_deps::load::program_and_fbd_from_json(&common::random_program(seed, 24))
        else {
            continue;
        };
        let (t, k) = rows_text(&generate(&p, &fbd, &CConfig::default()));
        let ids = row_ids(&t);
        count += usize::from(reordered(&p, &ids));
        kernels.push_str(&k);
        // A kind counts when some program has it (the outputs: in its rows).
        let m = missing_kinds(&kernels, &p, &ids.iter().cloned().collect());
        missing = Some(match missing {
            None => m,
            Some(old) => old.into_iter().filter(|k| m.contains(k)).collect(),
        });
    }
    assert_eq!(missing.unwrap_or_default(), Vec::<&str>::new());
    assert!(count >= 1, "{count} programs with reordered rows");
    // The generated programs the differential test compiles with rows (the odd seeds) all
    // have reordered rows.
    for seed in (1..6).step_by(2) {
        let gc = plc_deps::synth::GenConfig::all_features(400, 20, seed);
        let text = plc_deps::synth::generate_string(&gc);
        let (p, fbd) = plc_deps::load::program_and_fbd_from_json(&text).unwrap();
        let (t, _) = rows_text(&generate(&p, &fbd, &CConfig::default()));
        assert!(
            reordered(&p, &row_ids(&t)),
            "gen-{seed}: rows in program order"
        );
    }
}
