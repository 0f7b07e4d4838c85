//! `plc-deps convert`: a program written as the JSON program format reads back to the same
//! model — every committed PLCopen file that loads, the hand-written PLCopen cases, and every
//! worked example of `analyses/` (JSON to JSON) — and a file that does not load is refused with
//! exit 2 and no output.

use crate::common;

use crate::plcopen_common as px;

use common::cli::{error_line, run, tmp};
use std::path::{Path, PathBuf};

/// The model and FBD bodies of a program text, as `Debug` text.
fn model_of(text: &str) -> Option<String> {
    // `convert` writes an ST body that lowers to rungs as those rungs (what `run` executes).
    let loaded = if plc_deps::read::plcopen::looks_like_xml(text) {
        plc_deps::load::plcopen_lowered_selected(text, plc_deps::load::Pick::default())
            .map(|r| (r.program, r.fbd))
    } else {
        plc_deps::load::program_and_fbd_from_json(text)
    };
    // Where a rung or block stands in its file is not part of what the two texts mean.
    loaded.ok().map(|(p, mut f)| {
        let mut parts = p.into_parts();
        for r in parts.rungs.iter_mut() {
            r.origin = plc_deps::diag::Origin::NONE;
        }
        // Which bodies the XML reader read only as stand-in rungs (ST, IL, SFC) is its own
        // knowledge: the JSON has the stand-in rungs, not the language they stand for.
        for pou in parts.pous.iter_mut() {
            pou.skipped = None;
        }
        let p = plc_deps::model::Program::new(parts).expect("a loaded program's parts");
        for n in f.pous.iter_mut().flat_map(|pou| &mut pou.networks) {
            n.origin = plc_deps::diag::Origin::NONE;
            for b in n.blocks.iter_mut() {
                b.origin = plc_deps::diag::Origin::NONE;
            }
        }
        format!("{p:#?}\n{f:#?}")
    })
}

/// The text converted by the command line.
fn converted(path: &Path) -> String {
    let out = tmp(&format!(
        "{}.json",
        path.file_name().unwrap().to_string_lossy()
    ));
    // Projects with ST, IL or SFC bodies convert with their stand-in rungs.
    let r = run(&[
        "convert",
        path.to_str().unwrap(),
        "--allow-skipped",
        "-o",
        out.to_str().unwrap(),
    ]);
    assert_eq!(
        r.status.code(),
        Some(0),
        "{}: {}",
        path.display(),
        String::from_utf8_lossy(&r.stderr)
    );
    std::fs::read_to_string(out).unwrap()
}

fn files(dir: &str, ext: &str) -> Vec<PathBuf> {
    let mut v: Vec<PathBuf> = walk(&common::cli::root().join(dir))
        .into_iter()
        .filter(|p| p.extension().is_some_and(|e| e == ext))
        .collect();
    v.sort();
    v
}

fn walk(dir: &Path) -> Vec<PathBuf> {
    let mut out = Vec::new();
    for e in std::fs::read_dir(dir).unwrap().flatten() {
        let p = e.path();
        if p.is_dir() {
            out.extend(walk(&p));
        } else {
            out.push(p);
        }
    }
    out
}

#[test]
fn every_plcopen_file_that_loads_converts_to_json_with_the_same_model() {
    let mut checked = 0;
    for path in files("tests/plcopen", "xml")
        .into_iter()
        .chain(files("tests/plcopen_structs", "xml"))
    {
        let text = std::fs::read_to_string(&path).unwrap();
        let Some(model) = model_of(&text) else {
            continue;
        };
        let json = converted(&path);
        assert!(!plc_deps::read::plcopen::looks_like_xml(&json));
        let back = model_of(&json).unwrap_or_else(|| panic!("{}: {json}", path.display()));
        assert_eq!(back, model, "{}", path.display());
        checked += 1;
    }
    // All twelve real exports, the hand-written comment_fbd.xml and the structures that load
    // (all but the unknown field).
    assert!(checked >= 19, "{checked} files checked");
}

#[test]
fn a_generated_plcopen_ld_file_converts_with_the_same_model() {
    let (xml, rungs) = px::generated_ld(400_000);
    let path = tmp("generated-ld.xml");
    std::fs::write(&path, &xml).unwrap();
    let model = model_of(&xml).expect("the generated file loads");
    let json = converted(&path);
    assert_eq!(json.matches("\"id\":").count(), rungs);
    assert_eq!(model_of(&json).as_deref(), Some(&*model));
}

#[test]
fn every_worked_example_converts_to_itself() {
    let mut checked = 0;
    for path in files("analyses", "json")
        .into_iter()
        .filter(|p| p.file_name().is_some_and(|n| n == "program.json"))
    {
        let text = std::fs::read_to_string(&path).unwrap();
        let model = model_of(&text).unwrap_or_else(|| panic!("{} loads", path.display()));
        let json = converted(&path);
        assert_eq!(
            model_of(&json).as_deref(),
            Some(&*model),
            "{}",
            path.display()
        );
        // Converting the converted file changes nothing more.
        let again = tmp("again.json");
        std::fs::write(&again, &json).unwrap();
        assert_eq!(converted(&again), json, "{}", path.display());
        checked += 1;
    }
    assert!(checked >= 10, "{checked} examples checked");
}

#[test]
fn a_file_that_does_not_load_is_refused_and_nothing_is_written() {
    let bad = tmp("bad-convert.json");
    std::fs::write(
        &bad,
        r#"{"program": "P", "vars": [], "rungs": [{"id": "R1", "ld": [{"coil": "Z"}]}]}"#,
    )
    .unwrap();
    let out = tmp("bad-convert.out.json");
    let _ = std::fs::remove_file(&out);
    let r = run(&[
        "convert",
        bad.to_str().unwrap(),
        "-o",
        out.to_str().unwrap(),
    ]);
    let line = error_line(&r, "an undefined variable");
    assert!(line.contains("bad-convert.json:1:"), "{line}");
    assert!(line.contains("Z"), "{line}");
    assert!(!out.exists());
}
