//! `plc-deps run`: runs a program's scans on virtual time, sequentially, in parallel or both, and
//! reports the outputs of the last scan, the faults, the speed of each mode and (with both) whether
//! every scan's full state was identical. The format of the inputs, the trace and the JSON report
//! is documented in docs/scan.md.
//!
//! Everything is validated before the first scan (program, inputs, trace variables, arguments);
//! a problem is one [`CliError`] naming the file, line and column (exit code 2), and no output
//! file is written.
//!
//! With `--mode both` the sequential run and the parallel run are timed separately, one after the
//! other, each with nothing else in its timed region (inputs, tracing, checking and progress are
//! outside it). Every scan's full state (all slots in a layout-independent order: every variable,
//! instance internals, edge memories and loop counters) and its faults are condensed into a
//! 128-bit digest; the parallel run's digest of each scan is compared with the sequential one's.
//! On the first mismatch both runs are replayed in lockstep, exactly, up to that scan to name the
//! first difference (variable and both values).

use crate::analysis::analyse;
use crate::app::{load_program, write_output, write_output_with, CliError};
use crate::exec::parallel::{run_sequential, ParallelMachine, PlanConfig, ScanDriver};
use crate::exec::{ExecConfig, Fault, FaultKind, Layout, Machine, VarValue};
use crate::model::{parse_time_literal, Field, Program, Type, Value, VarClass, VarId, VarRef};
use serde_json::{json, Map, Value as Json};
use std::fmt::Write as _;
use std::io::{IsTerminal, Write};
use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

/// Which executors `run` uses.
#[derive(Copy, Clone, Debug, PartialEq, Eq)]
pub enum RunMode {
    /// The sequential interpreter only.
    Seq,
    /// The parallel executor only.
    Par,
    /// Both, timed separately, every scan checked seq == par.
    Both,
}

/// Output format of `run`.
#[derive(Copy, Clone, Debug, PartialEq, Eq)]
pub enum RunFormat {
    Text,
    Json,
}

/// A validated `plc-deps run` invocation.
#[derive(Clone, Debug)]
pub struct RunConfig {
    /// The program file.
    pub input: PathBuf,
    /// Number of scans; `None`: the number of input rows (at least 1), or 1000 without inputs.
    pub scans: Option<u64>,
    /// Input values per scan (CSV or JSON, by extension: `.json` is JSON, anything else CSV).
    pub inputs: Option<PathBuf>,
    /// Virtual scan period, ms (at least 1).
    pub cycle_ms: u32,
    /// Workers of the parallel executor (at least 1).
    pub threads: usize,
    pub mode: RunMode,
    /// Write the chosen variables after every scan to this CSV file.
    pub trace: Option<PathBuf>,
    /// The traced variables (names or instance fields `T1.Q`); `None`: every variable.
    pub trace_vars: Option<Vec<String>>,
    pub format: RunFormat,
    /// Describe the parallel plan.
    pub explain: bool,
    /// Loop-backs per loop-back rung and scan.
    pub loop_cap: u32,
    /// Write the report here instead of standard output.
    pub output: Option<PathBuf>,
    /// Show a progress bar on standard error (when it is a terminal and the run takes > 1 s).
    pub progress: bool,
}

impl RunConfig {
    /// Defaults for a program file: all scans of the inputs (or 1000), 10 ms, one worker per
    /// core, both modes, text, progress on a terminal.
    pub fn new(input: impl Into<PathBuf>) -> RunConfig {
        RunConfig {
            input: input.into(),
            scans: None,
            inputs: None,
            cycle_ms: 10,
            threads: std::thread::available_parallelism().map_or(1, |n| n.get()),
            mode: RunMode::Both,
            trace: None,
            trace_vars: None,
            format: RunFormat::Text,
            explain: false,
            loop_cap: ExecConfig::default().loop_cap,
            output: None,
            progress: std::io::stderr().is_terminal(),
        }
    }
}

/// Parses `--cycle`: a TIME literal with or without its `T#` prefix (`10ms`, `T#1s`, `1.5s`),
/// positive and at most 24 days (32-bit milliseconds).
pub fn parse_cycle(s: &str) -> Result<u32, CliError> {
    let t = s.trim();
    let literal = if t.to_ascii_uppercase().starts_with("T#")
        || t.to_ascii_uppercase().starts_with("TIME#")
    {
        t.to_string()
    } else {
        format!("T#{t}")
    };
    match parse_time_literal(&literal) {
        Some(ms) if ms >= 1 && ms <= i32::MAX as i64 => Ok(ms as u32),
        Some(_) => Err(CliError::Usage(format!(
            "--cycle {s}: the cycle must be a positive TIME of at most T#24d (e.g. 10ms, T#1s)"
        ))),
        None => Err(CliError::Usage(format!(
            "--cycle {s}: not a TIME (e.g. 10ms, T#250ms, 1s)"
        ))),
    }
}

// ---------------------------------------------------------------- inputs

/// Input values per scan: `rows[k]` holds the values that change at scan `k`; an input not in a
/// row (and every input after the last row) keeps its value.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct InputTable {
    pub rows: Vec<Vec<(VarId, Value)>>,
}

impl InputTable {
    /// The values written before scan `scan`.
    pub fn at(&self, scan: u64) -> &[(VarId, Value)] {
        self.rows.get(scan as usize).map_or(&[], |r| r.as_slice())
    }
}

/// The input variables by name.
fn input_var(p: &Program, name: &str) -> Result<VarId, String> {
    match p.vars.iter().position(|v| v.name == name && !v.hidden) {
        Some(i) if p.vars[i].class == VarClass::Input => Ok(VarId(i as u32)),
        Some(i) => Err(format!(
            "`{name}` is not an input variable (it is {})",
            match p.vars[i].class {
                VarClass::Output => "an output",
                _ => "a memory variable",
            }
        )),
        None => {
            let inputs: Vec<&str> = p
                .vars
                .iter()
                .filter(|v| v.class == VarClass::Input)
                .map(|v| v.name.as_str())
                .collect();
            Err(format!(
                "unknown input variable `{name}` (inputs: {})",
                if inputs.is_empty() {
                    "none".to_string()
                } else {
                    inputs.join(", ")
                }
            ))
        }
    }
}

/// Parses a cell or JSON string for an input of type `ty`.
fn parse_value(ty: Type, s: &str) -> Result<Value, String> {
    let t = s.trim();
    let bad = || format!("`{t}` is not a valid {ty}");
    Ok(match ty {
        Type::Bool => match t.to_ascii_lowercase().as_str() {
            "true" | "1" => Value::Bool(true),
            "false" | "0" => Value::Bool(false),
            _ => return Err(format!("`{t}` is not a BOOL (true, false, 1 or 0)")),
        },
        Type::Int => Value::Int(
            t.parse()
                .map_err(|_| format!("`{t}` is not an INT (-32768..32767)"))?,
        ),
        Type::Dint => Value::Dint(
            t.parse()
                .map_err(|_| format!("`{t}` is not a DINT (32-bit integer)"))?,
        ),
        Type::Real => Value::Real(t.parse().map_err(|_| bad())?),
        Type::Time => {
            let ms = if let Ok(ms) = t.parse::<i64>() {
                Some(ms)
            } else {
                parse_time_literal(t)
            };
            match ms {
                Some(ms) if ms >= i32::MIN as i64 && ms <= i32::MAX as i64 => {
                    Value::Time(ms as i32)
                }
                _ => {
                    return Err(format!(
                        "`{t}` is not a TIME (milliseconds or a literal like T#1s)"
                    ))
                }
            }
        }
        Type::Fb(_) => return Err(bad()),
    })
}

/// Splits a CSV line into (1-based start column, field) pairs; `"…"` quotes with `""` escapes.
fn csv_fields(line: &str) -> Result<Vec<(usize, String)>, (usize, String)> {
    let chars: Vec<char> = line.chars().collect();
    let mut out = Vec::new();
    let mut i = 0;
    loop {
        let start = i + 1;
        let mut field = String::new();
        if i < chars.len() && chars[i] == '"' {
            i += 1;
            loop {
                match chars.get(i) {
                    None => return Err((start, "unterminated quoted field".into())),
                    Some('"') if chars.get(i + 1) == Some(&'"') => {
                        field.push('"');
                        i += 2;
                    }
                    Some('"') => {
                        i += 1;
                        break;
                    }
                    Some(&c) => {
                        field.push(c);
                        i += 1;
                    }
                }
            }
            while i < chars.len() && chars[i] != ',' {
                if !chars[i].is_whitespace() {
                    return Err((i + 1, "unexpected text after a quoted field".into()));
                }
                i += 1;
            }
        } else {
            while i < chars.len() && chars[i] != ',' {
                field.push(chars[i]);
                i += 1;
            }
        }
        out.push((start, field.trim().to_string()));
        if i >= chars.len() {
            return Ok(out);
        }
        i += 1; // the comma
    }
}

/// Parses inputs in CSV: a header row of input variable names, then one row per scan (row k is
/// scan k); an empty cell or a missing trailing cell keeps the input's value; blank lines are
/// ignored. `file` names the file in errors (`file:line:column: message`).
pub fn parse_inputs_csv(p: &Program, text: &str, file: &str) -> Result<InputTable, CliError> {
    let err = |line: usize, col: usize, msg: String| {
        CliError::Usage(format!("{file}:{line}:{col}: {msg}"))
    };
    let text = text.strip_prefix('\u{feff}').unwrap_or(text);
    let mut lines = text
        .lines()
        .enumerate()
        .map(|(i, l)| (i + 1, l.strip_suffix('\r').unwrap_or(l)))
        .filter(|(_, l)| !l.trim().is_empty());
    let Some((hline, header)) = lines.next() else {
        return Ok(InputTable::default());
    };
    let mut columns: Vec<(VarId, String)> = Vec::new();
    for (col, name) in csv_fields(header).map_err(|(c, m)| err(hline, c, m))? {
        if name.is_empty() {
            return Err(err(hline, col, "empty column name in the header".into()));
        }
        let v = input_var(p, &name).map_err(|m| err(hline, col, m))?;
        if columns.iter().any(|(w, _)| *w == v) {
            return Err(err(hline, col, format!("input `{name}` has two columns")));
        }
        columns.push((v, name));
    }
    let mut rows = Vec::new();
    for (line, l) in lines {
        let fields = csv_fields(l).map_err(|(c, m)| err(line, c, m))?;
        if fields.len() > columns.len() {
            return Err(err(
                line,
                fields[columns.len()].0,
                format!(
                    "{} values in a row, the header has {} columns",
                    fields.len(),
                    columns.len()
                ),
            ));
        }
        let mut row = Vec::new();
        for ((col, cell), (v, name)) in fields.iter().zip(&columns) {
            if cell.is_empty() {
                continue;
            }
            let value = parse_value(p.var(*v).ty, cell).map_err(|m| {
                err(
                    line,
                    *col,
                    format!("scan {}, column `{name}`: {m}", rows.len()),
                )
            })?;
            row.push((*v, value));
        }
        rows.push(row);
    }
    Ok(InputTable { rows })
}

/// Parses inputs in JSON: an array with one object per scan (element k is scan k) mapping input
/// names to values — BOOL `true`/`false`, numbers, TIME as milliseconds or a `"T#…"` string;
/// a missing key or `null` keeps the input's value. Errors carry the line and column.
pub fn parse_inputs_json(p: &Program, text: &str, file: &str) -> Result<InputTable, CliError> {
    use serde::de::{DeserializeSeed, Error as _, MapAccess, SeqAccess, Visitor};
    use std::fmt;
    struct Rows<'a>(&'a Program);
    struct Row<'a>(&'a Program, usize);
    impl<'de> DeserializeSeed<'de> for Rows<'_> {
        type Value = Vec<Vec<(VarId, Value)>>;
        fn deserialize<D: serde::Deserializer<'de>>(self, d: D) -> Result<Self::Value, D::Error> {
            d.deserialize_seq(self)
        }
    }
    impl<'de> Visitor<'de> for Rows<'_> {
        type Value = Vec<Vec<(VarId, Value)>>;
        fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
            f.write_str("an array with one object of input values per scan")
        }
        fn visit_seq<A: SeqAccess<'de>>(self, mut seq: A) -> Result<Self::Value, A::Error> {
            let mut rows = Vec::new();
            while let Some(row) = seq.next_element_seed(Row(self.0, rows.len()))? {
                rows.push(row);
            }
            Ok(rows)
        }
    }
    impl<'de> DeserializeSeed<'de> for Row<'_> {
        type Value = Vec<(VarId, Value)>;
        fn deserialize<D: serde::Deserializer<'de>>(self, d: D) -> Result<Self::Value, D::Error> {
            d.deserialize_map(self)
        }
    }
    impl<'de> Visitor<'de> for Row<'_> {
        type Value = Vec<(VarId, Value)>;
        fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
            write!(f, "an object of input values for scan {}", self.1)
        }
        fn visit_map<A: MapAccess<'de>>(self, mut map: A) -> Result<Self::Value, A::Error> {
            let mut row: Vec<(VarId, Value)> = Vec::new();
            while let Some(name) = map.next_key::<String>()? {
                let v = input_var(self.0, &name)
                    .map_err(|m| A::Error::custom(format!("scan {}: {m}", self.1)))?;
                if row.iter().any(|(w, _)| *w == v) {
                    return Err(A::Error::custom(format!(
                        "scan {}: input `{name}` given twice",
                        self.1
                    )));
                }
                let raw: Json = map.next_value()?;
                let ty = self.0.var(v).ty;
                let value = match (&raw, ty) {
                    (Json::Null, _) => continue,
                    (Json::Bool(b), Type::Bool) => Ok(Value::Bool(*b)),
                    (Json::Number(n), Type::Real) => {
                        Ok(Value::Real(n.as_f64().unwrap_or(f64::NAN) as f32))
                    }
                    (Json::Number(n), Type::Int | Type::Dint | Type::Time) if n.is_i64() => {
                        parse_value(ty, &n.to_string())
                    }
                    (Json::String(s), Type::Time) if s.contains('#') => parse_value(ty, s),
                    _ => Err(format!(
                        "{} is not {} {ty}",
                        describe_json(&raw),
                        if matches!(ty, Type::Int) { "an" } else { "a" }
                    )),
                };
                let value = value.map_err(|m| {
                    A::Error::custom(format!("scan {}, input `{name}`: {m}", self.1))
                })?;
                row.push((v, value));
            }
            Ok(row)
        }
    }
    let mut de = serde_json::Deserializer::from_str(text);
    let rows = Rows(p)
        .deserialize(&mut de)
        .and_then(|rows| de.end().map(|_| rows))
        .map_err(|e| {
            let msg = e.to_string();
            let msg = msg
                .rfind(" at line ")
                .map_or(msg.as_str(), |i| &msg[..i])
                .to_string();
            CliError::Usage(format!("{file}:{}:{}: {msg}", e.line(), e.column()))
        })?;
    Ok(InputTable { rows })
}

fn describe_json(v: &Json) -> String {
    match v {
        Json::Null => "null".into(),
        Json::Bool(b) => format!("{b}"),
        Json::Number(n) => format!("{n}"),
        Json::String(s) => format!("\"{s}\""),
        Json::Array(_) => "an array".into(),
        Json::Object(_) => "an object".into(),
    }
}

/// Reads an inputs file (JSON if it ends in `.json`, CSV otherwise).
pub fn load_inputs(p: &Program, path: &Path) -> Result<InputTable, CliError> {
    let text = std::fs::read_to_string(path).map_err(|e| CliError::Io {
        path: path.display().to_string(),
        message: e.to_string(),
    })?;
    let file = path.display().to_string();
    if path
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("json"))
    {
        parse_inputs_json(p, &text, &file)
    } else {
        parse_inputs_csv(p, &text, &file)
    }
}

// ---------------------------------------------------------------- values

/// JSON of a scalar value as `state` shows it (BOOL true/false, numbers, TIME ms).
fn value_json(v: VarValue) -> Json {
    v.to_json()
}

/// Text of a value (BOOL TRUE/FALSE, TIME T#…ms, instances as their fields).
fn value_text(v: VarValue) -> String {
    match v {
        VarValue::Scalar(Value::Real(f)) => format!("{f}"),
        VarValue::Scalar(x) => x.to_string(),
        VarValue::Timer { q, et, pt } => format!(
            "Q={} ET=T#{et}ms PT=T#{pt}ms",
            if q { "TRUE" } else { "FALSE" }
        ),
        VarValue::Counter { q, cv, pv } => {
            format!("Q={} CV={cv} PV={pv}", if q { "TRUE" } else { "FALSE" })
        }
    }
}

/// The CSV cell of one traced slot: BOOL 1/0, integers and TIME (ms) as numbers, REAL shortest.
fn cell(ty: Type, bits: u64) -> String {
    match crate::exec::decode(ty, bits) {
        Value::Bool(b) => (if b { "1" } else { "0" }).to_string(),
        Value::Int(i) => i.to_string(),
        Value::Dint(i) | Value::Time(i) => i.to_string(),
        Value::Real(f) => format!("{f}"),
    }
}

/// Slot order independent of the layout: every variable's slots in declaration order, then the
/// loop counters in rung order.
fn canonical_slots(m: &Machine) -> Vec<u32> {
    let l = m.layout();
    let mut out: Vec<u32> = (0..l.var_count() as u32)
        .flat_map(|v| l.slots_of(VarId(v)))
        .collect();
    out.extend(m.loop_counters().map(|(_, s)| s));
    out
}

/// 128-bit digest of a scan's state (in canonical slot order) and faults.
fn digest(slots: &[u64], canon: &[u32], faults: &[Fault]) -> u128 {
    #[inline(always)]
    fn mix(mut z: u64) -> u64 {
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }
    let (mut a, mut b) = (0x243F_6A88_85A3_08D3u64, 0x1319_8A2E_0370_7344u64);
    let mut feed = |i: u64, v: u64| {
        let x = mix(v ^ i.wrapping_mul(0x9E37_79B9_7F4A_7C15));
        a = (a ^ x).wrapping_mul(0xFF51_AFD7_ED55_8CCD).rotate_left(23);
        b = b
            .wrapping_add(mix(x ^ 0xA076_1D64_78BD_642F))
            .rotate_left(41);
    };
    for (i, &s) in canon.iter().enumerate() {
        feed(i as u64, slots[s as usize]);
    }
    for (i, f) in faults.iter().enumerate() {
        let kind = match f.kind {
            FaultKind::DivByZero => 1,
            FaultKind::LoopCap => 2,
        };
        feed(u64::MAX - i as u64, (f.rung.0 as u64) << 8 | kind);
    }
    ((mix(a ^ b) as u128) << 64) | mix(b.wrapping_add(a)) as u128
}

// ---------------------------------------------------------------- the run

/// Faults kept in the report (the count covers all).
const FAULTS_KEPT: usize = 1000;

/// What a run found.
#[derive(Clone, Debug)]
pub struct RunReport {
    pub program: String,
    pub scans: u64,
    pub cycle_ms: u32,
    pub threads: usize,
    /// Main-program rungs (for the rung-execution rate).
    pub rungs: usize,
    /// Output variables after the last scan.
    pub outputs: Vec<(String, VarValue)>,
    /// Every variable but the hidden edge memories, after the last scan.
    pub state: Vec<(String, VarValue)>,
    /// The first faults (at most 1000) and the total.
    pub faults: Vec<(u64, String, FaultKind)>,
    pub fault_count: u64,
    /// Per mode: (name, total scan time).
    pub modes: Vec<(&'static str, Duration)>,
    /// `Some` when both modes ran.
    pub identical: Option<bool>,
    pub first_difference: Option<Json>,
    /// The parallel plan (text, JSON) when asked for.
    pub explain: Option<(String, Json)>,
}

/// Per-scan bookkeeping shared by both modes.
struct Driver<'a> {
    inputs: &'a InputTable,
    canon: Vec<u32>,
    /// Digests of the reference run (filled), or to check against.
    digests: Vec<u128>,
    check: bool,
    first_mismatch: Option<u64>,
    total: Duration,
    faults: Vec<(u64, u32, FaultKind)>,
    fault_count: u64,
    trace: Option<Trace<'a>>,
    progress: &'a mut Progress,
}

impl<'a> Driver<'a> {
    fn new(
        inputs: &'a InputTable,
        m: &Machine,
        digests: Vec<u128>,
        check: bool,
        trace: Option<Trace<'a>>,
        progress: &'a mut Progress,
    ) -> Driver<'a> {
        Driver {
            inputs,
            canon: canonical_slots(m),
            digests,
            check,
            first_mismatch: None,
            total: Duration::ZERO,
            faults: Vec::new(),
            fault_count: 0,
            trace,
            progress,
        }
    }
}

struct Trace<'a> {
    out: &'a mut dyn Write,
    cols: Vec<(u32, Type)>,
    line: String,
    error: Option<std::io::Error>,
}

impl ScanDriver for Driver<'_> {
    fn before_scan(&mut self, m: &Machine, scan: u64, slots: &mut [u64]) {
        m.set_inputs_in(slots, self.inputs.at(scan));
    }

    fn after_scan(
        &mut self,
        m: &Machine,
        scan: u64,
        slots: &[u64],
        faults: &[Fault],
        elapsed: Duration,
    ) {
        self.total += elapsed;
        let d = digest(slots, &self.canon, faults);
        if self.check {
            if self.first_mismatch.is_none() && self.digests.get(scan as usize) != Some(&d) {
                self.first_mismatch = Some(scan);
            }
        } else {
            self.digests.push(d);
        }
        self.fault_count += faults.len() as u64;
        for f in faults {
            if self.faults.len() < FAULTS_KEPT {
                self.faults.push((f.scan, f.rung.0, f.kind));
            }
        }
        if let Some(t) = &mut self.trace {
            if t.error.is_none() {
                t.line.clear();
                let _ = write!(
                    t.line,
                    "{scan},{}",
                    (scan as i64).wrapping_mul(m.config().cycle_ms as i64)
                );
                for &(slot, ty) in &t.cols {
                    t.line.push(',');
                    t.line.push_str(&cell(ty, slots[slot as usize]));
                }
                t.line.push('\n');
                if let Err(e) = t.out.write_all(t.line.as_bytes()) {
                    t.error = Some(e);
                }
            }
        }
        self.progress.tick();
    }
}

/// A progress bar on standard error, drawn once a run has taken more than a second.
pub struct Progress {
    enabled: bool,
    start: Instant,
    last_draw: Option<Instant>,
    done: u64,
    total: u64,
    label: &'static str,
    checks: u32,
}

impl Progress {
    fn new(enabled: bool, total: u64) -> Progress {
        Progress {
            enabled,
            start: Instant::now(),
            last_draw: None,
            done: 0,
            total,
            label: "",
            checks: 0,
        }
    }

    fn tick(&mut self) {
        self.done += 1;
        if !self.enabled {
            return;
        }
        self.checks += 1;
        if self.checks < 64 && self.done < self.total {
            return; // look at the clock every 64 scans
        }
        self.checks = 0;
        let now = Instant::now();
        if now.duration_since(self.start) < Duration::from_secs(1)
            || self
                .last_draw
                .is_some_and(|t| now.duration_since(t) < Duration::from_millis(100))
        {
            return;
        }
        self.last_draw = Some(now);
        let width = 30;
        let filled = (self.done * width / self.total.max(1)) as usize;
        let mut err = std::io::stderr().lock();
        let _ = write!(
            err,
            "\r[{}{}] {:>3}% {} scans {}/{}",
            "#".repeat(filled),
            " ".repeat(width as usize - filled.min(width as usize)),
            self.done * 100 / self.total.max(1),
            self.label,
            self.done,
            self.total
        );
        let _ = err.flush();
    }

    fn finish(&mut self) {
        if self.last_draw.is_some() {
            let mut err = std::io::stderr().lock();
            let _ = write!(err, "\r{}\r", " ".repeat(72));
            let _ = err.flush();
        }
    }
}

/// Resolves `--trace-vars` (names, or instance fields `T1.Q`) to (header, variable, type)
/// columns; `None`: every variable but the hidden edge memories, instances as their Q/ET/PT or
/// Q/CV/PV fields.
fn trace_columns(
    p: &Program,
    vars: Option<&[String]>,
) -> Result<Vec<(String, VarRef, Type)>, CliError> {
    let fields_of = |v: VarId| -> Vec<(Field, Type)> {
        match p.var(v).ty {
            Type::Fb(crate::model::FbKind::Ctu | crate::model::FbKind::Ctd) => vec![
                (Field::Q, Type::Bool),
                (Field::Cv, Type::Int),
                (Field::Pv, Type::Int),
            ],
            Type::Fb(_) => vec![
                (Field::Q, Type::Bool),
                (Field::Et, Type::Time),
                (Field::Pt, Type::Time),
            ],
            _ => vec![],
        }
    };
    let mut cols = Vec::new();
    let mut add = |v: VarId, field: Option<(Field, Type)>| {
        let name = &p.var(v).name;
        match field {
            Some((f, ty)) => cols.push((
                format!("{name}.{}", f.name()),
                VarRef {
                    var: v,
                    field: Some(f),
                },
                ty,
            )),
            None => cols.push((
                name.clone(),
                VarRef {
                    var: v,
                    field: None,
                },
                p.var(v).ty,
            )),
        }
    };
    match vars {
        None => {
            for v in (0..p.vars.len() as u32)
                .map(VarId)
                .filter(|&v| !p.var(v).hidden)
            {
                let fields = fields_of(v);
                if fields.is_empty() {
                    add(v, None);
                } else {
                    for f in fields {
                        add(v, Some(f));
                    }
                }
            }
        }
        Some(names) => {
            for raw in names {
                let name = raw.trim();
                let (base, field) = match name.split_once('.') {
                    Some((b, f)) => (b, Some(f)),
                    None => (name, None),
                };
                let Some(v) = p
                    .vars
                    .iter()
                    .position(|x| x.name == base)
                    .map(|i| VarId(i as u32))
                else {
                    return Err(CliError::Usage(format!(
                        "--trace-vars: unknown variable `{name}`"
                    )));
                };
                let fields = fields_of(v);
                match field {
                    None if fields.is_empty() => add(v, None),
                    None => {
                        for f in fields {
                            add(v, Some(f));
                        }
                    }
                    Some(f) => match fields
                        .iter()
                        .find(|(x, _)| x.name().eq_ignore_ascii_case(f))
                    {
                        Some(&ft) => add(v, Some(ft)),
                        None => {
                            return Err(CliError::Usage(format!(
                                "--trace-vars: `{name}`: {base} has no field {f}"
                            )))
                        }
                    },
                }
            }
        }
    }
    Ok(cols)
}

impl<'a> Trace<'a> {
    fn new(m: &Machine, cols: &[(String, VarRef, Type)], out: &'a mut dyn Write) -> Trace<'a> {
        let mut line = String::from("scan,time_ms");
        for (name, _, _) in cols {
            line.push(',');
            line.push_str(name);
        }
        line.push('\n');
        let error = out.write_all(line.as_bytes()).err();
        Trace {
            out,
            cols: cols.iter().map(|&(_, r, t)| (m.slot_of(r), t)).collect(),
            line,
            error,
        }
    }
}

/// Names the first difference between the two runs by replaying both exactly up to `scan`.
#[allow(clippy::too_many_arguments)]
fn first_difference(
    p: &Program,
    seq: &Machine,
    par: &ParallelMachine,
    pool: Option<&rayon::ThreadPool>,
    inputs: &InputTable,
    until: u64,
) -> Json {
    let (cs, cp) = (canonical_slots(seq), canonical_slots(par.machine()));
    let (mut a, mut b) = (seq.initial_state(), par.initial_state());
    let n_var_slots: usize = (0..p.vars.len() as u32)
        .map(|v| seq.layout().slots_of(VarId(v)).len())
        .sum();
    for scan in 0..=until {
        let (mut fa, mut fb) = (Vec::new(), Vec::new());
        seq.scan(&mut a, scan, inputs.at(scan), &mut fa);
        par.scan(pool, &mut b, scan, inputs.at(scan), &mut fb);
        if let Some(i) = cs
            .iter()
            .zip(&cp)
            .position(|(&x, &y)| a.slots[x as usize] != b.slots[y as usize])
        {
            if i < n_var_slots {
                // Which variable holds canonical slot i.
                let mut k = 0;
                for v in (0..p.vars.len() as u32).map(VarId) {
                    let w = seq.layout().slots_of(v).len();
                    if i < k + w {
                        let (va, vb) = (seq.value(&a, v), par.machine().value(&b, v));
                        let mut d = json!({"scan": scan, "variable": p.var(v).name, "seq": value_json(va), "par": value_json(vb)});
                        if va == vb {
                            d["detail"] = json!(format!("internal slot {} of the instance", i - k));
                        }
                        return d;
                    }
                    k += w;
                }
            }
            let (rung, _) = seq
                .loop_counters()
                .nth(i - n_var_slots)
                .expect("a loop counter");
            return json!({"scan": scan, "variable": format!("loop counter of rung {}", p.rung(rung).id),
                "seq": a.slots[cs[i] as usize], "par": b.slots[cp[i] as usize]});
        }
        if fa != fb {
            let list = |fs: &[Fault]| {
                fs.iter().map(|f| json!({"scan": f.scan, "rung": p.rung(f.rung).id, "kind": f.kind.name()})).collect::<Vec<_>>()
            };
            return json!({"scan": scan, "variable": null, "faults": {"seq": list(&fa), "par": list(&fb)}});
        }
    }
    json!({"scan": until, "variable": null, "detail": "the digests differed but an exact replay found no difference"})
}

/// Untimed warm-up scans before each timed pass.
const WARM_UP: u64 = 16;

/// A driver that only writes the inputs (warm-up).
struct Inputs<'a>(&'a InputTable);

impl ScanDriver for Inputs<'_> {
    fn before_scan(&mut self, m: &Machine, scan: u64, slots: &mut [u64]) {
        m.set_inputs_in(slots, self.0.at(scan));
    }
    fn after_scan(&mut self, _: &Machine, _: u64, _: &[u64], _: &[Fault], _: Duration) {}
    fn wants_time(&self) -> bool {
        false
    }
}

/// Everything a run needs, checked: nothing after this fails but writing the trace.
struct Prepared {
    p: Program,
    inputs: InputTable,
    scans: u64,
    seq: Option<Machine>,
    par: Option<ParallelMachine>,
    pool: Option<rayon::ThreadPool>,
    trace_cols: Option<Vec<(String, VarRef, Type)>>,
}

fn prepare(c: &RunConfig) -> Result<Prepared, CliError> {
    if c.threads == 0 {
        return Err(CliError::Usage("--threads must be at least 1".into()));
    }
    if c.cycle_ms == 0 {
        return Err(CliError::Usage("--cycle must be positive".into()));
    }
    if c.scans == Some(0) {
        return Err(CliError::Usage("--scans must be at least 1".into()));
    }
    let p = load_program(&c.input)?;
    let inputs = match &c.inputs {
        Some(path) => load_inputs(&p, path)?,
        None => InputTable::default(),
    };
    let scans = c.scans.unwrap_or(if c.inputs.is_some() {
        inputs.rows.len().max(1) as u64
    } else {
        1000
    });
    let trace_cols = match &c.trace {
        Some(_) => Some(trace_columns(&p, c.trace_vars.as_deref())?),
        None => None,
    };
    let exec = ExecConfig {
        cycle_ms: c.cycle_ms,
        loop_cap: c.loop_cap,
    };
    let lower_error =
        |e: crate::exec::LowerError| CliError::Usage(format!("{}: {e}", c.input.display()));
    let seq = if c.mode != RunMode::Par {
        Some(Machine::new(&p, Layout::dense(&p), &exec).map_err(lower_error)?)
    } else {
        None
    };
    let par = if c.mode != RunMode::Seq || c.explain {
        let a = analyse(&p);
        Some(
            ParallelMachine::new(&p, &a, &exec, &PlanConfig::new(c.threads))
                .map_err(lower_error)?,
        )
    } else {
        None
    };
    let pool = match &par {
        Some(pm) if c.mode != RunMode::Seq && pm.plan().sequential().is_none() && c.threads > 1 => {
            Some(
                rayon::ThreadPoolBuilder::new()
                    .num_threads(c.threads - 1)
                    .thread_name(|i| format!("plc-worker-{}", i + 1))
                    .build()
                    .map_err(|e| CliError::Io {
                        path: "thread pool".into(),
                        message: e.to_string(),
                    })?,
            )
        }
        _ => None,
    };
    Ok(Prepared {
        p,
        inputs,
        scans,
        seq,
        par,
        pool,
        trace_cols,
    })
}

/// Runs the prepared scans; `trace` receives the trace CSV (from the sequential run, or from the
/// parallel one when it runs alone).
fn execute(
    pr: &Prepared,
    c: &RunConfig,
    trace: Option<&mut dyn Write>,
) -> (RunReport, Option<std::io::Error>) {
    let (p, inputs, scans) = (&pr.p, &pr.inputs, pr.scans);
    // The parallel machine may exist only for --explain.
    let run_par = if c.mode == RunMode::Seq {
        None
    } else {
        pr.par.as_ref()
    };
    let passes = pr.seq.is_some() as u64 + run_par.is_some() as u64;
    let mut progress = Progress::new(c.progress, scans * passes);
    let mut trace = trace;
    let mut modes = Vec::new();
    let mut digests = Vec::new();
    let mut report_state: Option<(Vec<u64>, bool)> = None; // (slots, of the parallel machine)
    let (mut faults, mut fault_count, mut first_mismatch, mut trace_error) =
        (Vec::new(), 0, None, None);
    // Untimed warm-up scans on a throwaway state before each timed pass, so that neither mode
    // pays for cold caches and branch predictors (or for the other mode's warm ones).
    let warm = scans.min(WARM_UP);
    if let Some(m) = &pr.seq {
        let mut st = m.initial_state();
        run_sequential(m, &mut st, 0..warm, &mut Inputs(inputs));
        progress.label = "seq";
        let progress = &mut progress;
        let t = match (&pr.trace_cols, trace.take()) {
            (Some(cols), Some(out)) => Some(Trace::new(m, cols, out)),
            _ => None,
        };
        let mut d = Driver::new(inputs, m, Vec::new(), false, t, progress);
        let mut st = m.initial_state();
        run_sequential(m, &mut st, 0..scans, &mut d);
        modes.push(("seq", d.total));
        digests = std::mem::take(&mut d.digests);
        faults = std::mem::take(&mut d.faults);
        fault_count = d.fault_count;
        trace_error = d.trace.and_then(|t| t.error);
        report_state = Some((st.slots, false));
    }
    if let Some(pm) = run_par {
        let mut st = pm.initial_state();
        pm.run(pr.pool.as_ref(), &mut st, 0..warm, &mut Inputs(inputs));
        progress.label = "par";
        let progress = &mut progress;
        let m = pm.machine();
        let t = match (&pr.trace_cols, trace.take()) {
            (Some(cols), Some(out)) => Some(Trace::new(m, cols, out)),
            _ => None,
        };
        let check = pr.seq.is_some();
        let mut d = Driver::new(inputs, m, std::mem::take(&mut digests), check, t, progress);
        let mut st = pm.initial_state();
        pm.run(pr.pool.as_ref(), &mut st, 0..scans, &mut d);
        modes.push(("par", d.total));
        first_mismatch = d.first_mismatch;
        if !check {
            faults = std::mem::take(&mut d.faults);
            fault_count = d.fault_count;
            trace_error = d.trace.and_then(|t| t.error);
            report_state = Some((st.slots, true));
        }
    }
    progress.finish();
    let (identical, first_difference) = match (&pr.seq, run_par) {
        (Some(s), Some(pm)) => match first_mismatch {
            None => (Some(true), None),
            Some(k) => (
                Some(false),
                Some(self::first_difference(
                    p,
                    s,
                    pm,
                    pr.pool.as_ref(),
                    inputs,
                    k,
                )),
            ),
        },
        _ => (None, None),
    };
    let (slots, on_par) = report_state.expect("one mode ran");
    let m: &Machine = if on_par {
        pr.par.as_ref().expect("par").machine()
    } else {
        pr.seq.as_ref().expect("seq")
    };
    let visible: Vec<VarId> = (0..p.vars.len() as u32)
        .map(VarId)
        .filter(|&v| !p.var(v).hidden)
        .collect();
    let state: Vec<(String, VarValue)> = visible
        .iter()
        .map(|&v| (p.var(v).name.clone(), m.value_in(&slots, v)))
        .collect();
    let outputs = visible
        .iter()
        .filter(|&&v| p.var(v).class == VarClass::Output)
        .map(|&v| (p.var(v).name.clone(), m.value_in(&slots, v)))
        .collect();
    let explain = if c.explain {
        pr.par.as_ref().map(|pm| (pm.explain(p), pm.explain_json()))
    } else {
        None
    };
    let report = RunReport {
        program: p.name.clone(),
        scans,
        cycle_ms: c.cycle_ms,
        threads: c.threads,
        rungs: p.main().rungs.len(),
        outputs,
        state,
        faults: faults
            .into_iter()
            .map(|(s, r, k)| (s, p.rungs[r as usize].id.clone(), k))
            .collect(),
        fault_count,
        modes,
        identical,
        first_difference,
        explain,
    };
    (report, trace_error)
}

/// Checks and loads everything a run needs, runs it, and returns the report (the trace file, if
/// any, is written whole, or not at all).
pub fn run_report(c: &RunConfig) -> Result<RunReport, CliError> {
    let pr = prepare(c)?;
    match &c.trace {
        Some(path) => {
            let mut result = None;
            write_output_with(Some(path), |w| {
                let (r, err) = execute(&pr, c, Some(w));
                result = Some(r);
                err.map_or(Ok(()), Err)
            })?;
            Ok(result.expect("the run finished"))
        }
        None => Ok(execute(&pr, c, None).0),
    }
}

/// The JSON report (normative keys: docs/scan.md). `deterministic` zeroes the timing fields, so
/// that the same run always gives the same bytes (the committed `analyses/*/run.json`).
pub fn render_json(r: &RunReport, deterministic: bool) -> String {
    let mut doc = Map::new();
    doc.insert("program".into(), json!(r.program));
    doc.insert("scans".into(), json!(r.scans));
    doc.insert("cycle_ms".into(), json!(r.cycle_ms));
    doc.insert("threads".into(), json!(r.threads));
    doc.insert(
        "outputs".into(),
        Json::Object(
            r.outputs
                .iter()
                .map(|(n, v)| (n.clone(), value_json(*v)))
                .collect(),
        ),
    );
    doc.insert(
        "state".into(),
        Json::Object(
            r.state
                .iter()
                .map(|(n, v)| (n.clone(), value_json(*v)))
                .collect(),
        ),
    );
    doc.insert(
        "faults".into(),
        json!(r
            .faults
            .iter()
            .map(|(s, rung, k)| json!({"scan": s, "rung": rung, "kind": k.name()}))
            .collect::<Vec<_>>()),
    );
    doc.insert("fault_count".into(), json!(r.fault_count));
    let mut modes = Map::new();
    for &(name, total) in &r.modes {
        let (ns, per_s, rungs_per_s) = if deterministic || total.is_zero() {
            (json!(0), json!(0), json!(0))
        } else {
            let ns = total.as_nanos() as f64 / r.scans as f64;
            let per_s = 1e9 / ns;
            (
                json!((ns * 10.0).round() / 10.0),
                json!(per_s.round()),
                json!((per_s * r.rungs as f64).round()),
            )
        };
        modes.insert(
            name.into(),
            json!({"scans_per_s": per_s, "ns_per_scan": ns, "rungs_per_s": rungs_per_s}),
        );
    }
    doc.insert("modes".into(), Json::Object(modes));
    let speedup = match (
        r.modes.iter().find(|m| m.0 == "seq"),
        r.modes.iter().find(|m| m.0 == "par"),
    ) {
        (Some(s), Some(p)) if !deterministic && !p.1.is_zero() => {
            json!((s.1.as_secs_f64() / p.1.as_secs_f64() * 1000.0).round() / 1000.0)
        }
        (Some(_), Some(_)) => json!(0),
        _ => Json::Null,
    };
    doc.insert("speedup".into(), speedup);
    doc.insert("identical".into(), json!(r.identical));
    doc.insert(
        "first_difference".into(),
        r.first_difference.clone().unwrap_or(Json::Null),
    );
    if let Some((_, plan)) = &r.explain {
        doc.insert("plan".into(), plan.clone());
    }
    let mut s = serde_json::to_string_pretty(&Json::Object(doc)).expect("JSON");
    s.push('\n');
    s
}

fn time_text(ns: f64) -> String {
    if ns >= 1e9 {
        format!("{:.2} s", ns / 1e9)
    } else if ns >= 1e6 {
        format!("{:.2} ms", ns / 1e6)
    } else if ns >= 1e3 {
        format!("{:.2} µs", ns / 1e3)
    } else {
        format!("{ns:.0} ns")
    }
}

/// The text report.
pub fn render_text(r: &RunReport) -> String {
    let mut s = String::new();
    let _ = writeln!(
        s,
        "program {}: {} scans, cycle {} ms, {} thread(s)",
        r.program, r.scans, r.cycle_ms, r.threads
    );
    if let Some((text, _)) = &r.explain {
        s.push('\n');
        s.push_str(text);
        s.push('\n');
    }
    let _ = writeln!(s, "outputs after scan {}:", r.scans - 1);
    if r.outputs.is_empty() {
        let _ = writeln!(s, "  (no output variables)");
    }
    let width = r.outputs.iter().map(|(n, _)| n.len()).max().unwrap_or(0);
    for (n, v) in &r.outputs {
        let _ = writeln!(s, "  {n:<width$}  {}", value_text(*v));
    }
    if r.fault_count == 0 {
        let _ = writeln!(s, "faults: none");
    } else {
        let count = |k: FaultKind| r.faults.iter().filter(|f| f.2 == k).count();
        let _ = writeln!(
            s,
            "faults: {}{} (listed: {} div-by-zero, {} loop-cap)",
            r.fault_count,
            if r.fault_count as usize > r.faults.len() {
                format!(", the first {} listed", r.faults.len())
            } else {
                String::new()
            },
            count(FaultKind::DivByZero),
            count(FaultKind::LoopCap)
        );
        for (scan, rung, kind) in r.faults.iter().take(20) {
            let _ = writeln!(s, "  scan {scan}: rung {rung}: {}", kind.name());
        }
        if r.faults.len() > 20 {
            let _ = writeln!(s, "  ... ({} more in --format json)", r.fault_count - 20);
        }
    }
    let _ = writeln!(s, "speed:");
    let seq_total = r.modes.iter().find(|m| m.0 == "seq").map(|m| m.1);
    for &(name, total) in &r.modes {
        let ns = total.as_nanos() as f64 / r.scans as f64;
        let per_s = if ns > 0.0 { 1e9 / ns } else { 0.0 };
        let _ = write!(
            s,
            "  {name}  {:>12.0} scans/s  {:>10}/scan  {:>8.1} M rungs/s",
            per_s,
            time_text(ns),
            per_s * r.rungs as f64 / 1e6
        );
        if let (Some(st), "par") = (seq_total, name) {
            if !total.is_zero() {
                let _ = write!(s, "  ({:.2}x seq)", st.as_secs_f64() / total.as_secs_f64());
            }
        }
        s.push('\n');
    }
    match (r.identical, &r.first_difference) {
        (Some(true), _) => {
            let _ = writeln!(
                s,
                "identical: yes, seq == par after every scan (full state and faults)"
            );
        }
        (Some(false), Some(d)) => {
            let _ = writeln!(s, "identical: NO, first difference: {d}");
        }
        _ => {}
    }
    s
}

/// `plc-deps run`.
pub fn run(c: &RunConfig) -> Result<(), CliError> {
    let r = run_report(c)?;
    let out = match c.format {
        RunFormat::Text => render_text(&r),
        RunFormat::Json => render_json(&r, false),
    };
    write_output(c.output.as_deref(), &out)
}

/// The deterministic JSON of a run (timing fields zero): what `analyses/*/run.json` holds.
pub fn run_json_deterministic(c: &RunConfig) -> Result<String, CliError> {
    let c = RunConfig {
        progress: false,
        trace: None,
        ..c.clone()
    };
    Ok(render_json(&run_report(&c)?, true))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn cycles() {
        assert_eq!(parse_cycle("10ms").unwrap(), 10);
        assert_eq!(parse_cycle("T#1.5s").unwrap(), 1500);
        assert_eq!(parse_cycle("time#1m").unwrap(), 60_000);
        assert!(parse_cycle("10").is_err());
        assert!(parse_cycle("0ms").is_err());
        assert!(parse_cycle("-5ms").is_err());
        assert!(parse_cycle("T#25d").is_err());
    }

    #[test]
    fn csv_splitting() {
        let f = |l: &str| {
            csv_fields(l)
                .unwrap()
                .into_iter()
                .map(|(c, s)| format!("{c}:{s}"))
                .collect::<Vec<_>>()
        };
        assert_eq!(f("a, b ,,c"), ["1:a", "3:b", "7:", "8:c"]);
        assert_eq!(
            f(r#""x,y","say ""hi""" ,z"#),
            ["1:x,y", "7:say \"hi\"", "21:z"]
        );
        assert!(csv_fields(r#""open"#).is_err());
        assert!(csv_fields(r#""a"b"#).is_err());
    }

    #[test]
    fn first_difference_names_the_variable_and_both_values() {
        // The same program on two clocks: the timer's ET differs from scan 1 on.
        let p = crate::read::program_from_json(
            r#"{"program": "t", "vars": [{"name": "go", "type": "BOOL", "class": "input", "init": true},
                {"name": "T1", "type": "TON"}], "rungs": [{"id": "R1", "ld": [{"contact": "go"}, {"ton": "T1", "pt": "T#1s"}]}]}"#,
        )
        .unwrap();
        let a = analyse(&p);
        let seq = Machine::new(
            &p,
            Layout::dense(&p),
            &ExecConfig {
                cycle_ms: 10,
                loop_cap: 10,
            },
        )
        .unwrap();
        let par = ParallelMachine::new(
            &p,
            &a,
            &ExecConfig {
                cycle_ms: 20,
                loop_cap: 10,
            },
            &PlanConfig::new(1),
        )
        .unwrap();
        let d = first_difference(&p, &seq, &par, None, &InputTable::default(), 5);
        assert_eq!(
            d,
            json!({"scan": 1, "variable": "T1", "seq": {"Q": false, "ET": 10, "PT": 1000}, "par": {"Q": false, "ET": 20, "PT": 1000}})
        );
        let d = first_difference(&p, &seq, &par, None, &InputTable::default(), 0);
        assert_eq!(d["variable"], Json::Null, "no difference in scan 0: {d}");
    }

    #[test]
    fn digests_see_every_slot_and_the_faults() {
        let canon = [0u32, 1, 2];
        let base = digest(&[1, 2, 3], &canon, &[]);
        assert_ne!(base, digest(&[1, 2, 4], &canon, &[]));
        assert_ne!(base, digest(&[2, 1, 3], &canon, &[]));
        let f = Fault {
            scan: 0,
            rung: crate::model::RungId(0),
            kind: FaultKind::DivByZero,
        };
        assert_ne!(base, digest(&[1, 2, 3], &canon, &[f]));
        assert_eq!(
            base,
            digest(&[9, 1, 2, 3], &[1, 2, 3], &[]),
            "the layout does not matter"
        );
    }
}
