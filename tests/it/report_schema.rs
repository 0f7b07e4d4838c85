//! The JSON report and its documented schema (docs/report.schema.json) agree: the report of every
//! program under analyses/ (JSON programs and PLCopen projects), of generated programs with every
//! option and of a two-task PLCopen project validates, and the keys those reports emit are
//! exactly the keys the schema names, object by object (the schema's objects are closed, so a
//! key added to the report's structs fails here until the schema has it, and a key the schema
//! names that no report emits is stale).

use crate::common;
use crate::plcopen_common as px;

use serde_json::Value;
use std::collections::BTreeSet;
use std::path::{Path, PathBuf};

fn schema() -> Value {
    let path = common::cli::root().join("docs/report.schema.json");
    serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap()
}

fn validator(schema: &Value) -> jsonschema::Validator {
    jsonschema::draft202012::new(schema).expect("the schema is valid Draft 2020-12")
}

/// `plc-deps report FILE --format json`, parsed.
fn report_of(file: &Path) -> Value {
    let out = common::cli::run(&["report", file.to_str().unwrap(), "--format", "json"]);
    assert_eq!(
        out.status.code(),
        Some(0),
        "{}: {}",
        file.display(),
        String::from_utf8_lossy(&out.stderr)
    );
    serde_json::from_slice(&out.stdout).unwrap()
}

/// The program files under analyses/: each folder's program.json, or its program.xml (the
/// PLCopen projects under analyses/plcopen/).
fn analysed_programs() -> Vec<PathBuf> {
    let mut files = Vec::new();
    let root = common::cli::root().join("analyses");
    for dir in [root.clone(), root.join("plcopen")] {
        for entry in std::fs::read_dir(dir).unwrap() {
            let dir = entry.unwrap().path();
            for name in ["program.json", "program.xml"] {
                if dir.join(name).is_file() {
                    files.push(dir.join(name));
                    break;
                }
            }
        }
    }
    files.sort();
    files
}

/// Reports of every kind of program: analyses/, generated programs with every option, and a
/// PLCopen project whose tasks share globals.
fn reports() -> Vec<(String, Value)> {
    let mut out: Vec<(String, Value)> = analysed_programs()
        .iter()
        .map(|f| (f.display().to_string(), report_of(f)))
        .collect();
    assert!(out.len() >= 25, "{} programs under analyses/", out.len());
    for (name, args) in [
        (
            "report_schema_all.json",
            &[
                "--rungs",
                "600",
                "--width",
                "20",
                "--timers",
                "--loops",
                "--jumps",
                "--calls",
                "--hot-fraction",
                "0.05",
            ][..],
        ),
        (
            "report_schema_random.json",
            &["--rungs", "300", "--reads", "random", "--seed", "7"][..],
        ),
    ] {
        let file = common::cli::generated(name, args);
        out.push((name.to_owned(), report_of(&file)));
    }
    let (r, _) = px::json_output(
        &["report", "-", "--format", "json"],
        &crate::plcopen_project::two_task_project(),
    );
    out.push(("two-task project".to_owned(), r));
    out
}

/// The object keys a schema names, as paths (`.rungs[].id`; a map's keys as `*`: `.ipdom.*`),
/// following `$ref`, `items`, `oneOf` and `anyOf`.
fn schema_keys(root: &Value, node: &Value, path: &str, out: &mut BTreeSet<String>) {
    if let Some(r) = node.get("$ref").and_then(Value::as_str) {
        let name = r.strip_prefix("#/$defs/").expect("a local $ref");
        schema_keys(root, &root["$defs"][name], path, out);
    }
    if let Some(props) = node.get("properties").and_then(Value::as_object) {
        for (k, v) in props {
            let p = format!("{path}.{k}");
            out.insert(p.clone());
            schema_keys(root, v, &p, out);
        }
    }
    if let Some(extra) = node.get("additionalProperties").filter(|v| v.is_object()) {
        let p = format!("{path}.*");
        out.insert(p.clone());
        schema_keys(root, extra, &p, out);
    }
    if let Some(items) = node.get("items") {
        schema_keys(root, items, &format!("{path}[]"), out);
    }
    for alt in ["oneOf", "anyOf"] {
        for v in node
            .get(alt)
            .and_then(Value::as_array)
            .into_iter()
            .flatten()
        {
            schema_keys(root, v, path, out);
        }
    }
}

/// The object keys `v` has, as paths; the keys of the objects at `maps` (paths ending in `.*`)
/// as `*`.
fn report_keys(v: &Value, path: &str, maps: &BTreeSet<String>, out: &mut BTreeSet<String>) {
    match v {
        Value::Object(m) => {
            let is_map = maps.contains(&format!("{path}.*"));
            for (k, x) in m {
                let p = if is_map {
                    format!("{path}.*")
                } else {
                    format!("{path}.{k}")
                };
                out.insert(p.clone());
                report_keys(x, &p, maps, out);
            }
        }
        Value::Array(items) => {
            for x in items {
                report_keys(x, &format!("{path}[]"), maps, out);
            }
        }
        _ => {}
    }
}

#[test]
fn every_report_validates_and_emits_exactly_the_schemas_keys() {
    let schema = schema();
    let v = validator(&schema);
    let mut declared = BTreeSet::new();
    schema_keys(&schema, &schema, "", &mut declared);
    let maps: BTreeSet<String> = declared
        .iter()
        .filter(|k| k.ends_with(".*"))
        .cloned()
        .collect();
    assert_eq!(
        maps.iter().map(String::as_str).collect::<Vec<_>>(),
        [".cost.level_makespan.*", ".cost.makespan.*", ".ipdom.*"]
    );
    let mut emitted = BTreeSet::new();
    for (name, report) in reports() {
        let errors: Vec<String> = v
            .iter_errors(&report)
            .take(5)
            .map(|e| format!("{e} at {}", e.instance_path()))
            .collect();
        assert!(errors.is_empty(), "{name}: {errors:#?}");
        report_keys(&report, "", &maps, &mut emitted);
    }
    let missing: Vec<&String> = emitted.difference(&declared).collect();
    assert!(
        missing.is_empty(),
        "keys the reports emit that the schema lacks: {missing:?}"
    );
    let stale: Vec<&String> = declared.difference(&emitted).collect();
    assert!(
        stale.is_empty(),
        "keys of the schema no report emits: {stale:?}"
    );
}

/// The schema is not a rubber stamp: a report with a key it does not know, without a required
/// key, or with a value of the wrong kind is refused.
#[test]
fn the_schema_refuses_reports_that_break_the_contract() {
    let schema = schema();
    let v = validator(&schema);
    let file = common::cli::root().join("analyses/example-a/program.json");
    let good = report_of(&file);
    assert!(v.is_valid(&good));
    let mut extra = good.clone();
    extra["rungs"][0]["colour"] = "red".into();
    assert!(!v.is_valid(&extra));
    let mut dropped = good.clone();
    dropped.as_object_mut().unwrap().remove("levels");
    assert!(!v.is_valid(&dropped));
    let mut renamed = good.clone();
    let deps = renamed["dependences"].as_array_mut().unwrap();
    let first = deps[0].as_object_mut().unwrap();
    let var = first.remove("var").unwrap();
    first.insert("variable".into(), var);
    assert!(!v.is_valid(&renamed));
    let mut wrong = good;
    wrong["cfg"]["edges"][0]["kind"] = "teleport".into();
    assert!(!v.is_valid(&wrong));
}
