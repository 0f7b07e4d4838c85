//! The shipped JSON Schema (`plc-deps schema`) agrees with the reader: every program the project
//! ships or generates validates, and every malformed shape the reader rejects, the schema
//! rejects too.

use crate::common;

use std::path::PathBuf;

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

fn validator() -> jsonschema::Validator {
    let schema: serde_json::Value =
        serde_json::from_str(plc_deps::cmd::schema::PROGRAM_SCHEMA).unwrap();
    jsonschema::draft202012::new(&schema).expect("the schema is valid Draft 2020-12")
}

fn json(path: &std::path::Path) -> serde_json::Value {
    serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap()
}

#[test]
fn shipped_and_generated_programs_validate() {
    let v = validator();
    let mut checked = 0;
    for entry in std::fs::read_dir(root().join("analyses")).unwrap() {
        let path = entry.unwrap().path().join("program.json");
        if path.is_file() {
            let doc = json(&path);
            let errors: Vec<String> = v
                .iter_errors(&doc)
                .map(|e| format!("{} at {}", e, e.instance_path()))
                .collect();
            assert!(errors.is_empty(), "{}: {errors:?}", path.display());
            checked += 1;
        }
    }
    assert!(checked >= 5);
    let config = plc_deps::synth::GenConfig {
        rungs: 2000,
        width: 50,
        seed: 3,
        timers: true,
        loops: true,
        jumps: true,
        calls: true,
        ..Default::default()
    };
    let doc: serde_json::Value =
        serde_json::from_str(&plc_deps::synth::generate_string(&config)).unwrap();
    assert!(v.is_valid(&doc));
}

/// The random programs of the differential tests (every element kind, every elementary type,
/// every standard function and conversion) load, so they must validate too.
#[test]
fn random_programs_with_every_function_validate() {
    let v = validator();
    let mut checked = 0;
    for seed in 0..300 {
        let text = common::random_program(seed, 40);
        // Some are rejected by the loader (a jump into a FOR body): skipped, as elsewhere.
        if plc_deps::load::program_from_json(&text).is_err() {
            continue;
        }
        checked += 1;
        let doc: serde_json::Value = serde_json::from_str(&text).unwrap();
        let errors: Vec<String> = v
            .iter_errors(&doc)
            .map(|e| format!("{} at {}", e, e.instance_path()))
            .take(3)
            .collect();
        assert!(errors.is_empty(), "seed {seed}: {errors:?}");
    }
    assert!(checked >= 100, "{checked}");
}

#[test]
fn malformed_shapes_are_rejected_by_the_schema_too() {
    let v = validator();
    for name in [
        "unknown-field",
        "unknown-element",
        "unknown-type",
        "not-an-object",
        "time-needs-literal",
    ] {
        let doc = json(&root().join(format!("tests/errors/{name}.json")));
        assert!(!v.is_valid(&doc), "{name} should not validate");
    }
}

/// Every PLCopen fixture that loads, written as the JSON program format (what `convert` writes),
/// validates, with its configuration; and a configuration with a field the reader refuses does
/// not.
#[test]
fn converted_plcopen_projects_validate_with_their_configuration() {
    let v = validator();
    let mut with_configuration = 0;
    let dirs = ["tests/plcopen", "tests/plcopen_structs"];
    for entry in dirs
        .iter()
        .flat_map(|d| std::fs::read_dir(root().join(d)).unwrap())
    {
        let path = entry.unwrap().path();
        if path.extension().is_none_or(|e| e != "xml") {
            continue;
        }
        let text = std::fs::read_to_string(&path).unwrap();
        if plc_deps::load::plcopen(&text).is_err() {
            continue;
        }
        let (syntax, _) = plc_deps::read::plcopen::parse(&text).unwrap();
        let mut out = Vec::new();
        plc_deps::write::json::program(&syntax, &mut out).unwrap();
        let doc: serde_json::Value = serde_json::from_slice(&out).unwrap();
        let errors: Vec<String> = v
            .iter_errors(&doc)
            .map(|e| format!("{} at {}", e, e.instance_path()))
            .collect();
        assert!(errors.is_empty(), "{}: {errors:?}", path.display());
        if doc.get("configuration").is_some() {
            with_configuration += 1;
        }
        let mut bad = doc.clone();
        if let Some(c) = bad.get_mut("configuration") {
            c["resources"][0]["tasks"][0]["cycle"] = serde_json::json!("T#1s");
            let refused = v
                .iter_errors(&bad)
                .any(|e| e.instance_path().to_string() == "/configuration/resources/0/tasks/0");
            assert!(refused, "{}", path.display());
        }
    }
    assert!(with_configuration >= 10, "{with_configuration}");
}
