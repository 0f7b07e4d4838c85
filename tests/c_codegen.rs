//! The generated C, compiled with `cc -std=c11 -Wall -Wextra -Werror -O2` and run, gives after
//! every scan the same state (as the JSON line of `plc-deps run --format json`'s `state`) and the
//! same faults as the sequential interpreter: on every `analyses/` example and on random ladder
//! and generated programs. Example C's C has the shape the FBD text-generation paper prints.

mod common;

use common::Rng;
use plc_deps::codegen::c::{generate, CConfig};
use plc_deps::exec::{ExecConfig, Layout, Machine};
use plc_deps::model::{Program, Type, VarClass};
use serde_json::{json, Map};
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::sync::atomic::{AtomicU32, Ordering};

fn fresh_dir(tag: &str) -> PathBuf {
    static N: AtomicU32 = AtomicU32::new(0);
    let d = std::env::temp_dir().join(format!(
        "plc-c-{}-{tag}-{}",
        std::process::id(),
        N.fetch_add(1, Ordering::Relaxed)
    ));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// Writes the C of `text` into a fresh folder and compiles it with the exact flags.
fn build(text: &str, cfg: &CConfig, tag: &str) -> PathBuf {
    let (p, fbd) = plc_deps::read::program_and_fbd_from_json(text).expect("program loads");
    let dir = fresh_dir(tag);
    let mut sources = Vec::new();
    for f in generate(&p, &fbd, cfg) {
        if f.name.ends_with(".c") {
            sources.push(f.name.clone());
        }
        std::fs::write(dir.join(&f.name), f.text).unwrap();
    }
    let out = Command::new("cc")
        .args([
            "-std=c11", "-Wall", "-Wextra", "-Werror", "-O2", "-o", "prog",
        ])
        .args(&sources)
        .arg("-lm")
        .current_dir(&dir)
        .output()
        .expect("cc runs");
    assert!(
        out.status.success(),
        "cc failed in {}:\n{}",
        dir.display(),
        String::from_utf8_lossy(&out.stderr)
    );
    dir
}

/// Runs the built program: its state lines and fault lines.
fn run_c(dir: &Path, csv: &str, scans: u64) -> (Vec<String>, Vec<String>) {
    let mut child = Command::new(dir.join("prog"))
        .arg(scans.to_string())
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    use std::io::Write;
    child
        .stdin
        .take()
        .unwrap()
        .write_all(csv.as_bytes())
        .unwrap();
    let out = child.wait_with_output().unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let lines = |b: &[u8]| {
        String::from_utf8_lossy(b)
            .lines()
            .map(String::from)
            .collect()
    };
    (lines(&out.stdout), lines(&out.stderr))
}

/// What the interpreter gives for the same inputs: the state line after every scan, the faults.
fn run_interpreter(text: &str, csv: &str, scans: u64, cfg: &CConfig) -> (Vec<String>, Vec<String>) {
    let p = plc_deps::read::program_from_json(text).unwrap();
    let exec = ExecConfig {
        cycle_ms: cfg.cycle_ms,
        loop_cap: cfg.loop_cap,
    };
    let m = Machine::new(&p, Layout::dense(&p), &exec).unwrap();
    let table = plc_deps::cmd::run::parse_inputs_csv(&p, csv, "inputs.csv").unwrap();
    let mut st = m.initial_state();
    let (mut lines, mut faults) = (Vec::new(), Vec::new());
    for k in 0..scans {
        let mut f = Vec::new();
        m.set_inputs(&mut st, table.at(k));
        m.run_scan(&mut st, k, &mut f);
        lines.push(state_line(&p, &m, &st));
        for x in f {
            let rung = &p.rung(x.rung).id;
            faults.push(json!({"scan": x.scan, "rung": rung, "kind": x.kind.name()}).to_string());
        }
    }
    (lines, faults)
}

fn state_line(p: &Program, m: &Machine, st: &plc_deps::exec::State) -> String {
    let mut map = Map::new();
    for (i, v) in p.vars.iter().enumerate() {
        if !v.hidden {
            let value = m.value(st, plc_deps::model::VarId(i as u32));
            map.insert(v.name.clone(), value.to_json());
        }
    }
    serde_json::Value::Object(map).to_string()
}

/// Builds, runs and compares scan by scan.
fn check(text: &str, csv: &str, scans: u64, cfg: &CConfig, tag: &str) {
    let dir = build(text, cfg, tag);
    let (c_lines, c_faults) = run_c(&dir, csv, scans);
    let (i_lines, i_faults) = run_interpreter(text, csv, scans, cfg);
    assert_eq!(c_lines.len(), i_lines.len(), "{tag}: scans");
    for (k, (c, i)) in c_lines.iter().zip(&i_lines).enumerate() {
        assert_eq!(c, i, "{tag}: state after scan {k} ({})", dir.display());
    }
    assert_eq!(c_faults, i_faults, "{tag}: faults");
    let _ = std::fs::remove_dir_all(dir);
}

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

#[test]
fn every_example_matches_the_interpreter_after_every_scan() {
    let mut seen = 0;
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
        check(&text, &csv, scans, &cfg, &name);
        seen += 1;
    }
    assert!(seen >= 11, "{seen} examples");
}

/// A CSV of random values for the program's inputs, `rows` rows (some cells empty).
fn random_csv(p: &Program, rng: &mut Rng, rows: usize) -> String {
    let ins: Vec<_> = p
        .vars
        .iter()
        .filter(|v| v.class == VarClass::Input && !v.hidden)
        .collect();
    if ins.is_empty() {
        return String::new();
    }
    let mut s = ins
        .iter()
        .map(|v| v.name.as_str())
        .collect::<Vec<_>>()
        .join(",");
    s.push('\n');
    for _ in 0..rows {
        let cells: Vec<String> = ins
            .iter()
            .map(|v| {
                if rng.chance(20) {
                    return String::new();
                }
                match v.ty {
                    Type::Bool => (if rng.chance(50) { "true" } else { "0" }).to_string(),
                    Type::Int => (rng.below(200) as i64 - 100).to_string(),
                    Type::Dint => (rng.below(2_000_000) as i64 - 1_000_000).to_string(),
                    Type::Real => format!("{}", (rng.below(4000) as f64 - 2000.0) / 8.0),
                    _ => (rng.below(5000)).to_string(),
                }
            })
            .collect();
        s.push_str(&cells.join(","));
        s.push('\n');
    }
    s
}

#[test]
fn random_ladder_programs_match_the_interpreter() {
    let mut checked = 0;
    for seed in 0..60u64 {
        let text = common::random_program(seed, 24);
        let Ok(p) = plc_deps::read::program_from_json(&text) else {
            continue;
        };
        let mut rng = Rng::new(seed + 1000);
        let csv = random_csv(&p, &mut rng, 40);
        let cfg = CConfig {
            cycle_ms: 1 + rng.below(50) as u32,
            loop_cap: 1 + rng.below(200) as u32,
            chunk_rungs: 1 + rng.below(8) as usize,
        };
        check(&text, &csv, 50, &cfg, &format!("random-{seed}"));
        checked += 1;
    }
    assert!(checked >= 30, "only {checked} random programs loaded");
}

#[test]
fn generated_programs_with_every_feature_match_the_interpreter() {
    for seed in 0..6u64 {
        let gc = plc_deps::synth::GenConfig::all_features(400, 20, seed);
        let text = plc_deps::synth::generate_string(&gc);
        let p = plc_deps::read::program_from_json(&text).unwrap();
        let mut rng = Rng::new(seed);
        let csv = random_csv(&p, &mut rng, 30);
        let cfg = CConfig {
            chunk_rungs: 64,
            ..CConfig::default()
        };
        check(&text, &csv, 40, &cfg, &format!("gen-{seed}"));
    }
}

#[test]
fn random_fbd_programs_match_the_interpreter() {
    let mut checked = 0;
    for seed in 0..50u64 {
        let text = common::fbd::random_fbd_program(seed);
        let Ok(p) = plc_deps::read::program_from_json(&text) else {
            continue;
        };
        let mut rng = Rng::new(seed + 77);
        let csv = random_csv(&p, &mut rng, 30);
        let cfg = CConfig {
            cycle_ms: 1 + rng.below(40) as u32,
            loop_cap: 1 + rng.below(50) as u32,
            ..CConfig::default()
        };
        check(&text, &csv, 40, &cfg, &format!("fbd-{seed}"));
        checked += 1;
    }
    assert!(checked >= 20, "only {checked} random FBD programs loaded");
}

#[test]
fn random_fbd_programs_with_nested_fb_types_match_the_interpreter() {
    let mut checked = 0;
    for seed in 0..40u64 {
        let text = common::fbd::random_nested_fbd_program(seed);
        let Ok((p, fbd)) = plc_deps::read::program_and_fbd_from_json(&text) else {
            continue;
        };
        // One function per type: FB1, FB2 (nested in FB1 and at the top), FB3 (ladder).
        let files = generate(&p, &fbd, &CConfig::default());
        let fns: usize = files
            .iter()
            .filter(|f| f.name.starts_with("fb_"))
            .map(|f| f.text.matches("_body(_fb_").count())
            .sum();
        assert_eq!(fns, 3, "fbd-nested-{seed}: functions of the 3 types");
        let mut rng = Rng::new(seed + 91);
        let csv = random_csv(&p, &mut rng, 30);
        let cfg = CConfig {
            cycle_ms: 1 + rng.below(40) as u32,
            loop_cap: 1 + rng.below(50) as u32,
            ..CConfig::default()
        };
        check(&text, &csv, 40, &cfg, &format!("fbd-nested-{seed}"));
        checked += 1;
    }
    assert!(
        checked >= 15,
        "only {checked} random nested FBD programs loaded"
    );
}

/// Example C of the FBD text-generation paper: compute 3 and 4; `if (3) {flag = 1; 8}`;
/// `if (4) {flag = 1; 10; 27; if (27) {24}}`; `if (flag) {15; 17}` — checked on the text's
/// structure (its lines without the comments), its behaviour by the example test above.
#[test]
fn example_c_has_the_shape_the_paper_prints() {
    let text = std::fs::read_to_string(root().join("analyses/example-c/program.json")).unwrap();
    let (p, fbd) = plc_deps::read::program_and_fbd_from_json(&text).unwrap();
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
            "_3_0 = (self->Var1 == 1);",
            "_4_0 = (self->Var1 == 2);",
            "if (_3_0) {",
            "_run0_3 = 1;",
            "self->LVar = _plc_add_i16(self->Var2, 10);",
            "}",
            "if (_4_0) {",
            "_run0_3 = 1;",
            "_10_0 = _plc_mul_i16(self->Var2, 3);",
            "self->LVar = _10_0;",
            "_27_0 = (_10_0 > 0);",
            "if (_27_0) {",
            "self->Var3 = _plc_mul_i16(self->Var3, _10_0);",
            "}",
            "}",
            "if (_run0_3) {",
            "_15_0 = _plc_sub_i16(self->LVar, 1);",
            "self->WriteValue_17.IVal = _15_0;",
            "_fb_WriteValue_body(&self->WriteValue_17, self, ctx);",
            "self->Written = self->WriteValue_17.OVal;",
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
    let out = Command::new("cc")
        .args([
            "-std=c11", "-Wall", "-Wextra", "-Werror", "-O2", "-o", "reals", "reals.c", "-lm",
        ])
        .current_dir(&dir)
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let mut rng = Rng::new(5);
    let mut bits: Vec<u32> = (0..20_000).map(|_| rng.next() as u32).collect();
    for e in -12..=20 {
        for d in [1.0f32, 1.5, 9.999_999, 46.757_812_5, 0.1, 0.3] {
            bits.push((d * 10f32.powi(e)).to_bits());
        }
    }
    bits.extend([0, 0x8000_0000, 1, 0x7f7f_ffff, 0x7f80_0000, 0x7fc0_0000]);
    let input: String = bits.iter().map(|b| format!("{b}\n")).collect();
    let (lines, _) = {
        let mut child = Command::new(dir.join("reals"))
            .stdin(Stdio::piped())
            .stdout(Stdio::piped())
            .spawn()
            .unwrap();
        use std::io::Write;
        // Written from a thread: the program answers line by line, and both pipes are finite.
        let mut stdin = child.stdin.take().unwrap();
        let writer = std::thread::spawn(move || stdin.write_all(input.as_bytes()).unwrap());
        let out = child.wait_with_output().unwrap();
        writer.join().unwrap();
        let l: Vec<String> = String::from_utf8(out.stdout)
            .unwrap()
            .lines()
            .map(String::from)
            .collect();
        (l, ())
    };
    assert_eq!(lines.len(), bits.len());
    for (b, line) in bits.iter().zip(&lines) {
        let want = VarValue::Scalar(Value::Real(f32::from_bits(*b)))
            .to_json()
            .to_string();
        assert_eq!(line, &want, "bits {b:#010x}");
    }
    let _ = std::fs::remove_dir_all(dir);
}
