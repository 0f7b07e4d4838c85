//! Rendering a run's report: the text report, the JSON report (normative keys: docs/scan.md)
//! and its deterministic form for `analyses/*/run.json`, and the HTML page (the program's report
//! page with the run's figures, drawn by `report::html`; this module only hands it the figures).

use super::config::{count, RunWarning};
use super::engine::RunReport;
use plc_analysis::Analysis;
use plc_exec::parallel::run_log_json;
use plc_exec::VarValue;
use plc_fbd::Fbd;
use plc_model::{Program, Value};
use plc_report::configuration::{run_entry, run_label};
use plc_report::{
    document_with, fbd_parts, render_run_html, FaultRow, HtmlInput, ModeFigures, PlanFigures,
    RunFigures,
};
use serde_json::{json, Map, Value as Json};
use std::fmt::Write as _;

/// Text of a value (BOOL TRUE/FALSE, TIME T#…ms, instances as their fields).
fn value_text(v: VarValue) -> String {
    match v {
        VarValue::Scalar(Value::Real(f)) => format!("{f}"),
        VarValue::Scalar(x) => x.to_string(),
        // A STRING as its IEC literal (`'a$'b'`, `$hh` for a byte not printable ASCII).
        VarValue::Text(s) => plc_model::string_literal(s.bytes()),
        VarValue::Timer { q, et, pt } => format!(
            "Q={} ET=T#{et}ms PT=T#{pt}ms",
            if q { "TRUE" } else { "FALSE" }
        ),
        VarValue::Counter { q, cv, pv } => {
            format!("Q={} CV={cv} PV={pv}", if q { "TRUE" } else { "FALSE" })
        }
        VarValue::Bistable { q1 } => format!("Q1={}", if q1 { "TRUE" } else { "FALSE" }),
        VarValue::Trigger { q } => format!("Q={}", if q { "TRUE" } else { "FALSE" }),
        VarValue::UpDown { qu, qd, cv, pv } => {
            let b = |x: bool| if x { "TRUE" } else { "FALSE" };
            format!("QU={} QD={} CV={cv} PV={pv}", b(qu), b(qd))
        }
    }
}

/// The JSON report (normative keys: docs/scan.md). `deterministic` zeroes the timing fields, so
/// that the same run always gives the same bytes (the committed `analyses/*/run.json`).
pub fn render_json(r: &RunReport, deterministic: bool) -> String {
    let mut doc = Map::new();
    doc.insert("program".into(), json!(r.program));
    if !r.instances.is_empty() {
        let runs: Vec<_> = r.instances.iter().map(run_entry).collect();
        doc.insert("programs".into(), json!(runs));
    }
    if !r.skipped.is_empty() {
        let skipped: Vec<Json> = r.skipped.iter().map(|s| s.json()).collect();
        doc.insert("skipped_pous".into(), Json::Array(skipped));
    }
    doc.insert("scans".into(), json!(r.scans));
    doc.insert("cycle_ms".into(), json!(r.cycle_ms));
    doc.insert("threads".into(), json!(r.threads));
    doc.insert("workers".into(), json!(r.workers));
    doc.insert(
        "outputs".into(),
        Json::Object(
            r.outputs
                .iter()
                .map(|(n, v)| (n.clone(), VarValue::to_json(v)))
                .collect(),
        ),
    );
    doc.insert(
        "state".into(),
        Json::Object(
            r.state
                .iter()
                .map(|(n, v)| (n.clone(), VarValue::to_json(v)))
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
    doc.insert(
        "fault_summary".into(),
        json!(r
            .fault_summary
            .iter()
            .map(
                |f| json!({"rung": f.rung, "kind": f.kind.name(), "count": f.count,
                "first_scan": f.first_scan, "last_scan": f.last_scan})
            )
            .collect::<Vec<_>>()),
    );
    let mut modes = Map::new();
    for (k, &(name, total)) in r.modes.iter().enumerate() {
        let windows = r.windows.get(k).map_or(&[][..], Vec::as_slice);
        let (lo, hi) = spread(windows).unwrap_or((0.0, 0.0));
        let (lo, hi, n) = if deterministic {
            (json!(0), json!(0), json!(0))
        } else {
            (
                json!((lo * 10.0).round() / 10.0),
                json!((hi * 10.0).round() / 10.0),
                json!(windows.len()),
            )
        };
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
            json!({"scans_per_s": per_s, "ns_per_scan": ns, "rungs_per_s": rungs_per_s,
                   "ns_per_scan_min": lo, "ns_per_scan_max": hi, "timing_windows": n}),
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
    let both = r.modes.len() == 2;
    doc.insert(
        "speedup_scans".into(),
        if both { json!(r.scans) } else { Json::Null },
    );
    // The turns follow the sequential walk's measured speed: zeroed with the other timings.
    let block = r.block_scans.map(|b| if deterministic { 0 } else { b });
    doc.insert("speedup_block_scans".into(), json!(block));
    doc.insert("plan_kind".into(), json!(r.plan_kind.name()));
    doc.insert("sequential_fallback".into(), json!(r.sequential_fallback));
    doc.insert(
        "plan_run".into(),
        r.plan_run
            .as_ref()
            .map_or(Json::Null, |log| run_log_json(log, deterministic)),
    );
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

/// How the two passes took turns, when they did more than once: `; seq and par alternated
/// every 84 scans`.
fn turns_text(r: &RunReport) -> String {
    match r.block_scans {
        Some(b) if b < r.scans => format!(
            "; seq and par alternated every {}",
            count(b, "scan", "scans")
        ),
        _ => String::new(),
    }
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

/// Distinct faults listed in the text report (all of them are in the JSON).
const DISTINCT_FAULTS_SHOWN: usize = 50;

/// The faults of the text report: the total, then one line per distinct fault (rung and kind)
/// with its count and its first and last scan.
fn write_faults(s: &mut String, r: &RunReport) {
    if r.fault_count == 0 {
        let _ = writeln!(s, "faults: none");
        return;
    }
    let distinct = r.fault_summary.len() as u64;
    let _ = writeln!(
        s,
        "faults: {} ({})",
        r.fault_count,
        count(distinct, "distinct fault", "distinct faults")
    );
    for f in r.fault_summary.iter().take(DISTINCT_FAULTS_SHOWN) {
        let when = if f.count == 1 {
            format!("once, in scan {}", f.first_scan)
        } else {
            format!(
                "{} times, scans {} to {}",
                f.count, f.first_scan, f.last_scan
            )
        };
        let _ = writeln!(s, "  rung {}: {}, {when}", f.rung, f.kind.name());
    }
    if r.fault_summary.len() > DISTINCT_FAULTS_SHOWN {
        let more = (r.fault_summary.len() - DISTINCT_FAULTS_SHOWN) as u64;
        let _ = writeln!(
            s,
            "  ... and {} more (fault_summary in --format json)",
            count(more, "distinct fault", "distinct faults")
        );
    }
}

/// `; 40 of them sequential, 2 switches` when the parallel pass mixed candidates.
fn mix_text(r: &RunReport) -> String {
    let Some(log) = &r.plan_run else {
        return String::new();
    };
    let seq: u64 = log
        .candidates
        .iter()
        .zip(&log.scans_on)
        .filter(|(n, _)| n.as_str() == "seq")
        .map(|(_, &k)| k)
        .sum();
    if seq == 0 && log.switches.is_empty() {
        return String::new();
    }
    format!(
        "; {seq} of them on the sequential walk, {}",
        count(log.switches.len() as u64, "switch", "switches")
    )
}

/// Which program instances of the configuration each scan ran, and how to run another alone.
fn instances_text(r: &RunReport) -> Option<String> {
    let names: Vec<String> = r
        .instances
        .iter()
        .map(|i| run_label(&run_entry(i)))
        .collect();
    let names = names.join(", ");
    match (r.instances.len(), r.configured_instances) {
        (0, 0) => None,
        (0, all) => Some(format!(
            "ran program {} alone: none of the configuration's {} runs it",
            r.program,
            count(all as u64, "program instance", "program instances")
        )),
        (1, 1) => Some(format!("ran program instance {names}")),
        (n, all) if n == all => Some(format!(
            "ran all {n} program instances each scan, one after another in task order: {names} (--pou NAME runs one program alone)"
        )),
        (n, all) => Some(format!(
            "ran {} of {all}, selected by --pou: {names}",
            count(n as u64, "program instance", "program instances")
        )),
    }
}

/// The text report.
pub fn render_text(r: &RunReport) -> String {
    let mut s = String::new();
    let _ = writeln!(
        s,
        "program {}: {}, cycle {} ms, {}{}",
        r.program,
        count(r.scans, "scan", "scans"),
        r.cycle_ms,
        count(r.threads as u64, "thread", "threads"),
        if r.workers != r.threads {
            format!(
                " (planned for {})",
                count(r.workers as u64, "worker", "workers")
            )
        } else {
            String::new()
        }
    );
    if let Some(line) = instances_text(r) {
        let _ = writeln!(s, "{line}");
    }
    if !r.skipped.is_empty() {
        let names: Vec<String> = r.skipped.iter().map(|p| p.text()).collect();
        let _ = writeln!(
            s,
            "not executed (--allow-skipped; stand-in rungs keep every value): {}",
            names.join(", ")
        );
    }
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
    write_faults(&mut s, r);
    let _ = writeln!(s, "speed:");
    let seq_total = r.modes.iter().find(|m| m.0 == "seq").map(|m| m.1);
    let spreads: Vec<Option<(f64, f64)>> = (0..r.modes.len())
        .map(|k| spread(r.windows.get(k).map_or(&[][..], Vec::as_slice)))
        .collect();
    for (k, &(name, total)) in r.modes.iter().enumerate() {
        let ns = total.as_nanos() as f64 / r.scans as f64;
        let per_s = if ns > 0.0 { 1e9 / ns } else { 0.0 };
        let _ = write!(
            s,
            "  {name}  {:>12.0} scans/s  {:>10}/scan  {:>8.1} M rungs/s",
            per_s,
            time_text(ns),
            per_s * r.rungs as f64 / 1e6
        );
        // A figure whose windows spread by more than a tenth of it is shown with its spread.
        let wide = |(lo, hi): (f64, f64)| hi - lo > 0.1 * ns;
        if let Some((lo, hi)) = spreads[k].filter(|&sp| wide(sp)) {
            let _ = write!(s, "  (windows {}–{}/scan)", time_text(lo), time_text(hi));
        }
        if let (Some(st), "par") = (seq_total, name) {
            match &r.sequential_fallback {
                Some(why) => {
                    let _ = write!(
                        s,
                        "  the same sequential walk as seq, so no ratio: sequential fallback ({why})"
                    );
                }
                None if !total.is_zero() => {
                    // Overlapping windows: the two figures are not told apart by this run.
                    let overlap = match (spreads.first().copied().flatten(), spreads[k]) {
                        (Some((slo, shi)), Some((plo, phi))) => slo <= phi && plo <= shi,
                        _ => false,
                    };
                    let _ = write!(
                        s,
                        "  ({:.2}x seq over {}{}{}){}",
                        st.as_secs_f64() / total.as_secs_f64(),
                        count(r.scans, "scan", "scans"),
                        mix_text(r),
                        turns_text(r),
                        if overlap {
                            ", within the windows' spread"
                        } else {
                            ""
                        }
                    );
                }
                None => {}
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

/// The figures the HTML page shows of a run (measured times as they are, not zeroed), with the
/// warnings it gave.
pub fn run_figures(r: &RunReport, warnings: &[RunWarning]) -> RunFigures {
    RunFigures {
        scans: r.scans,
        cycle_ms: r.cycle_ms,
        threads: r.threads,
        workers: r.workers,
        rungs: r.rungs,
        modes: r
            .modes
            .iter()
            .map(|&(name, total)| ModeFigures {
                name,
                ns_per_scan: total.as_nanos() as f64 / r.scans.max(1) as f64,
            })
            .collect(),
        plan: r.plan_run.as_ref().map(|log| PlanFigures {
            kind: r.plan_kind.name(),
            scans_on: log
                .candidates
                .iter()
                .cloned()
                .zip(log.scans_on.iter().copied())
                .collect(),
            last: log.candidates.get(log.last).cloned().unwrap_or_default(),
            switches: log.switches.len(),
            fallback: r.sequential_fallback.clone(),
        }),
        block_scans: r.block_scans,
        identical: r.identical,
        first_difference: r.first_difference.as_ref().map(|d| d.to_string()),
        outputs: r
            .outputs
            .iter()
            .map(|(n, v)| (n.clone(), value_text(*v)))
            .collect(),
        fault_count: r.fault_count,
        faults: r
            .fault_summary
            .iter()
            .map(|f| FaultRow {
                rung: f.rung.clone(),
                kind: f.kind.name(),
                count: f.count,
                first_scan: f.first_scan,
                last_scan: f.last_scan,
            })
            .collect(),
        explain: r.explain.as_ref().map(|(text, _)| text.clone()),
        warnings: warnings.iter().map(|w| (w.code(), w.to_string())).collect(),
    }
}

/// Writes the HTML page of a run of `p` (analysed as `a`, FBD bodies `fbd`) that gave
/// `warnings`: the report page of the program with the run's section (docs/html.md).
pub fn write_html(
    p: &Program,
    a: &Analysis,
    fbd: &Fbd,
    r: &RunReport,
    warnings: &[RunWarning],
    out: &mut dyn std::io::Write,
) -> std::io::Result<()> {
    let parts = fbd_parts(p, fbd);
    let doc = document_with(p, a, parts.as_ref());
    let mut out = std::io::BufWriter::with_capacity(1 << 16, out);
    render_run_html(
        &HtmlInput {
            doc: &doc,
            program: p,
            analysis: a,
            fbd: Some(fbd),
        },
        &run_figures(r, warnings),
        &mut out,
    )?;
    std::io::Write::flush(&mut out)
}

/// The smallest and largest of a pass's window times (ns per scan), when it has at least three.
fn spread(windows: &[f64]) -> Option<(f64, f64)> {
    (windows.len() >= 3).then(|| {
        windows
            .iter()
            .fold((f64::INFINITY, 0.0_f64), |(lo, hi), &w| {
                (lo.min(w), hi.max(w))
            })
    })
}
