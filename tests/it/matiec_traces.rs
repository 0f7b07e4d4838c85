//! plc-deps against the reference toolchain, without the toolchain: `corpus/against-matiec` ran
//! each program of `tests/matiec/outcomes.txt` through Beremiz's generator and matiec with a
//! harness that sets the inputs and `__CURRENT_TIME` per scan, and recorded matiec's state
//! after every scan (`tests/matiec/NAME.matiec.csv`, columns `NAME:TYPE` in matiec's upper
//! case) and the inputs it used (`NAME.inputs.csv`). This test runs today's plc-deps on the
//! same program, inputs and cycle (10 ms) and compares every variable both traces have, by the
//! script's rule (REAL as 32-bit floats; a random program's FOR control variables `fN` are
//! left out: their value after the loop is implementation-dependent, docs/matiec.md). The
//! outcome must be the recorded one: `same`, or the first difference, each explained in
//! docs/matiec.md. A change either way fails until re-blessed with
//! `UPDATE_EXPECT=1 cargo test --release --test it matiec_traces`, which rewrites the outcomes
//! of the lines with a matiec trace (the others, where Beremiz or matiec refused the file, are
//! kept as the script wrote them).

use crate::common::cli::{root, run, tmp};
use std::fs;

const OUTCOMES: &str = "tests/matiec/outcomes.txt";

/// The rows of a CSV file; a field in double quotes may hold commas (matiec's trace names a
/// transition of a simultaneous divergence or convergence `"F1,E2->G"`, as Python's csv writes it).
fn csv_rows(text: &str) -> Vec<Vec<String>> {
    text.lines().map(csv_fields).collect()
}

fn csv_fields(line: &str) -> Vec<String> {
    let (mut fields, mut field, mut quoted) = (Vec::new(), String::new(), false);
    let mut chars = line.chars().peekable();
    while let Some(c) = chars.next() {
        match c {
            '"' if quoted && chars.peek() == Some(&'"') => {
                chars.next();
                field.push('"');
            }
            '"' => quoted = !quoted,
            ',' if !quoted => fields.push(std::mem::take(&mut field)),
            _ => field.push(c),
        }
    }
    fields.push(field);
    fields
}

fn same(a: &str, b: &str, typ: &str) -> bool {
    if a == b {
        return true;
    }
    match typ {
        "REAL" => match (a.parse::<f32>(), b.parse::<f32>()) {
            (Ok(x), Ok(y)) => x == y,
            _ => false,
        },
        "LREAL" => match (a.parse::<f64>(), b.parse::<f64>()) {
            (Ok(x), Ok(y)) => x == y,
            _ => false,
        },
        _ => false,
    }
}

/// The script's `compare_traces`.
fn compare(matiec: &[Vec<String>], plc: &[Vec<String>], random_program: bool) -> String {
    let pos = |name: &str| plc[0].iter().position(|c| c.to_uppercase() == name);
    let mut cols = Vec::new();
    for (j, c) in matiec[0].iter().enumerate().skip(2) {
        let (name, typ) = c.split_once(':').unwrap_or((c, ""));
        let loop_var = name.len() > 1
            && name.starts_with('F')
            && name[1..].bytes().all(|b| b.is_ascii_digit());
        if random_program && loop_var {
            continue;
        }
        if let Some(i) = pos(name) {
            cols.push((j, i, plc[0][i].clone(), typ.to_string()));
        }
    }
    for (k, (m, p)) in matiec[1..].iter().zip(&plc[1..]).enumerate() {
        for (j, i, col, typ) in &cols {
            if !same(&m[*j], &p[*i], typ) {
                return format!(
                    "compared={} vars | differs: {col} at scan {k} (matiec {}, plc-deps {})",
                    cols.len(),
                    m[*j],
                    p[*i]
                );
            }
        }
    }
    if matiec.len() != plc.len() {
        return format!(
            "compared={} vars | differs: {} scans against {}",
            cols.len(),
            matiec.len() - 1,
            plc.len() - 1
        );
    }
    format!("compared={} vars | same", cols.len())
}

/// Today's outcome of one program with a recorded matiec trace.
fn outcome(source: &str) -> String {
    let name = source.rsplit('/').next().unwrap().trim_end_matches(".xml");
    let dir = root().join("tests/matiec");
    let matiec = csv_rows(&fs::read_to_string(dir.join(format!("{name}.matiec.csv"))).unwrap());
    let inputs = dir.join(format!("{name}.inputs.csv"));
    let scans = (matiec.len() - 1).to_string();
    let trace = tmp(&format!("matiec-{name}.csv"));
    let mut args = vec![
        "run",
        source,
        "--mode",
        "seq",
        "--scans",
        &scans,
        "--cycle",
        "10ms",
        "--trace",
        trace.to_str().unwrap(),
    ];
    let has_inputs = fs::metadata(&inputs).map(|m| m.len() > 0).unwrap_or(false);
    if has_inputs {
        args.extend(["--inputs", inputs.to_str().unwrap()]);
    }
    let out = run(&args);
    if !out.status.success() {
        let stderr = String::from_utf8_lossy(&out.stderr);
        let first = stderr
            .lines()
            .find(|l| l.starts_with("error"))
            .unwrap_or("error");
        let code = match first.strip_prefix("error[") {
            Some(rest) => rest.split(']').next().unwrap().to_string(),
            None if first.contains("not executed") => "body-not-executed".into(),
            None => "uncoded".into(),
        };
        return format!("matiec=ok | plc-deps=refuses({code})");
    }
    let plc = csv_rows(&fs::read_to_string(&trace).unwrap());
    let _ = fs::remove_file(&trace);
    format!(
        "matiec=ok | {}",
        compare(&matiec, &plc, name.starts_with("random-st-"))
    )
}

#[test]
fn every_program_compares_with_matiec_as_recorded() {
    let path = root().join(OUTCOMES);
    let text = fs::read_to_string(&path).unwrap();
    let update = std::env::var_os("UPDATE_EXPECT").is_some();
    let mut written = String::new();
    let mut wrong = Vec::new();
    let mut traced = 0;
    for line in text.lines() {
        let Some((source, recorded)) = line.split_once(" | ") else {
            written.push_str(line);
            written.push('\n');
            continue;
        };
        if line.starts_with('#') || !recorded.starts_with("matiec=ok") {
            written.push_str(line);
            written.push('\n');
            continue;
        }
        traced += 1;
        let now = outcome(source);
        if now != recorded {
            wrong.push(format!(
                "{source}\n  recorded: {recorded}\n  now:      {now}"
            ));
        }
        written.push_str(&format!("{source} | {now}\n"));
    }
    assert!(traced >= 20, "only {traced} programs with a matiec trace");
    if update {
        fs::write(&path, written).unwrap();
    } else {
        assert!(
            wrong.is_empty(),
            "against matiec (re-bless with UPDATE_EXPECT=1 if better, and explain each \
             difference in docs/matiec.md):\n{}",
            wrong.join("\n")
        );
    }
}
