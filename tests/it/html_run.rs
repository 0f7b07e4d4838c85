//! `plc-deps run --format html` from the command line: the page is the program's report page
//! (a card for every rung) with the run's section, whose outputs and faults are those of the
//! same run in the text and JSON reports, whose rates are the modes that ran, and which is
//! written whole or not at all (exit codes as for the other formats: 1 after a faulted run with
//! the page written, 2 with nothing written). The page in a real browser: tests/it/html_browser.rs.

use crate::common;

use common::cli::{root, run, temp_files_in, tmp};
use serde_json::Value;

const FAULTY: &str = r#"{"program": "faulty",
  "vars": [{"name": "d", "type": "INT", "class": "input"}, {"name": "x", "type": "INT", "class": "output"},
           {"name": "i", "type": "INT"}, {"name": "Q", "type": "BOOL", "class": "output"}],
  "rungs": [
    {"id": "DIV", "ld": [{"op": "DIV", "in": [10, "d"], "out": "x"}]},
    {"id": "L", "label": "back", "ld": [{"op": "ADD", "in": ["i", 1], "out": "i"}]},
    {"id": "J", "ld": [{"compare": "GT", "a": "i", "b": 0}, {"jmp": "back"}]},
    {"id": "S", "ld": [{"compare": "GT", "a": "x", "b": 1}, {"coil": "Q"}]}
  ]}"#;

fn write(name: &str, text: &str) -> String {
    let path = tmp(name);
    std::fs::write(&path, text).unwrap();
    path.to_str().unwrap().to_owned()
}

fn parse(html: &str) -> roxmltree::Document<'_> {
    let opt = roxmltree::ParsingOptions {
        allow_dtd: true,
        ..Default::default()
    };
    roxmltree::Document::parse_with_options(html, opt).expect("the page is well-formed XML")
}

fn has_class(n: &roxmltree::Node, c: &str) -> bool {
    n.attribute("class")
        .is_some_and(|v| v.split(' ').any(|x| x == c))
}

/// The cells of every row of the table with class `class` (none if there is no such table).
fn rows(doc: &roxmltree::Document, class: &str) -> Vec<Vec<String>> {
    let Some(table) = doc
        .descendants()
        .find(|n| n.has_tag_name("table") && has_class(n, class))
    else {
        return Vec::new();
    };
    table
        .children()
        .filter(|n| n.has_tag_name("tr"))
        .skip(1)
        .map(|tr| {
            tr.children()
                .filter(|n| n.is_element())
                .map(|td| {
                    td.descendants()
                        .filter_map(|n| n.text().filter(|_| n.is_text()))
                        .collect()
                })
                .collect()
        })
        .collect()
}

/// The ids of the rung cards, sorted.
fn cards(doc: &roxmltree::Document) -> Vec<String> {
    let mut ids: Vec<String> = doc
        .descendants()
        .filter(|n| has_class(n, "card"))
        .map(|n| n.attribute("id").unwrap().to_string())
        .collect();
    ids.sort();
    ids
}

/// (name, value) of the text report's "outputs after scan" lines.
fn text_outputs(text: &str) -> Vec<Vec<String>> {
    text.lines()
        .skip_while(|l| !l.starts_with("outputs after scan"))
        .skip(1)
        .take_while(|l| l.starts_with("  "))
        .map(|l| {
            let (n, v) = l.trim().split_once(' ').unwrap();
            vec![n.to_string(), v.trim().to_string()]
        })
        .collect()
}

#[test]
fn a_faulted_run_writes_its_page_with_the_faults_and_outputs_and_exits_1() {
    let program = write("faulty.json", FAULTY);
    let inputs = write("faulty.csv", "d\n0\n5\n0\n");
    let page = tmp("faulty.html");
    let args = ["run", &program, "--inputs", &inputs, "--loop-cap", "10"];
    let out = run(&[
        &args[..],
        &["--format", "html", "-o", page.to_str().unwrap()],
    ]
    .concat());
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{stderr}");
    assert!(
        stderr.starts_with("error: the run faulted: 5 faults"),
        "{stderr}"
    );
    assert!(out.stdout.is_empty());
    let html = std::fs::read_to_string(&page).expect("the page is written");
    let doc = parse(&html);
    assert_eq!(cards(&doc), ["rung-DIV", "rung-J", "rung-L", "rung-S"]);
    // The faults are the JSON report's fault summary of the same run, row for row.
    let json = run(&[&args[..], &["--format", "json"]].concat());
    assert_eq!(json.status.code(), Some(1));
    let j: Value = serde_json::from_slice(&json.stdout).unwrap();
    let want: Vec<Vec<String>> = j["fault_summary"]
        .as_array()
        .unwrap()
        .iter()
        .map(|f| {
            ["rung", "kind", "count", "first_scan", "last_scan"]
                .iter()
                .map(|k| match &f[*k] {
                    Value::String(s) => s.clone(),
                    v => v.to_string(),
                })
                .collect()
        })
        .collect();
    assert_eq!(
        want,
        [
            ["DIV", "div-by-zero", "2", "0", "2"],
            ["J", "loop-cap", "3", "0", "2"]
        ]
    );
    assert_eq!(rows(&doc, "faults"), want);
    assert!(html.contains("5 faults (2 distinct)"));
    // Each fault's rung is a chip that highlights the rung's card.
    assert!(html.contains(r#"<span class="chip" data-rung="DIV">DIV</span>"#));
    // The outputs are the text report's.
    let text = run(&args);
    let want = text_outputs(&String::from_utf8_lossy(&text.stdout));
    assert_eq!(
        want,
        [
            vec!["x".to_string(), "0".into()],
            vec!["Q".into(), "FALSE".into()]
        ]
    );
    assert_eq!(rows(&doc, "outputs"), want);
    assert!(html.contains("<h3>Outputs after scan 2</h3>"));
}

#[test]
fn the_rates_are_the_modes_that_ran_beside_the_models_makespans() {
    let page = tmp("example-a-run.html");
    let out = run(&[
        "run",
        "analyses/example-a/program.json",
        "--inputs",
        "analyses/example-a/inputs.csv",
        "--threads",
        "2",
        "--format",
        "html",
        "-o",
        page.to_str().unwrap(),
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let html = std::fs::read_to_string(&page).unwrap();
    let doc = parse(&html);
    let rates = rows(&doc, "rates");
    assert_eq!(rates.len(), 2);
    assert_eq!((rates[0][0].as_str(), rates[1][0].as_str()), ("seq", "par"));
    for r in &rates {
        let us: f64 = r[1].parse().unwrap();
        let per_s: f64 = r[2].replace(',', "").parse().unwrap();
        assert!(us > 0.0, "{r:?}");
        // µs/scan and scans/s are one figure two ways (both rounded).
        assert!((us * per_s / 1e6 - 1.0).abs() < 0.05, "{r:?}");
    }
    let inputs = std::fs::read_to_string(root().join("analyses/example-a/inputs.csv")).unwrap();
    let scans = inputs.lines().count() - 1;
    assert!(
        rates[1][4].starts_with("sequential fallback (")
            || rates[1][4].ends_with(&format!(" over {scans} scans")),
        "{:?}",
        rates[1]
    );
    assert!(html.contains("plan chosen (<code>--plan auto</code>): <b>"));
    // The model's figures for Example A (W = 10), the row of the 2 workers marked.
    assert_eq!(
        rows(&doc, "ideal")[1],
        ["2 (this run)", "6", "×1.67", "8", "×1.25"]
    );
    assert!(html.contains("identical: yes, seq == par after every scan"));
    // The same report page: every rung of Example A has its card.
    assert_eq!(
        cards(&doc),
        ["rung-R1", "rung-R2", "rung-R3", "rung-R4", "rung-R5"]
    );
}

#[test]
fn a_sequential_run_has_one_rate_and_no_plan() {
    let page = tmp("seq.html");
    let out = run(&[
        "run",
        "analyses/example-b/program.json",
        "--mode",
        "seq",
        "--scans",
        "20",
        "--format",
        "html",
        "-o",
        page.to_str().unwrap(),
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let html = std::fs::read_to_string(&page).unwrap();
    let doc = parse(&html);
    let rates = rows(&doc, "rates");
    assert_eq!(rates.len(), 1);
    assert_eq!(rates[0][0], "seq");
    assert!(!html.contains("plan chosen") && !html.contains("identical:"));
    assert!(html.contains("<h3>Outputs after scan 19</h3>"));
}

#[test]
fn a_page_is_written_whole_or_not_at_all() {
    // A program that does not load: exit 2, no page, no temporary file.
    let bad = write(
        "bad.json",
        r#"{"program": "p", "rungs": [{"id": "R1", "ld": [{"contact": "nope"}]}]}"#,
    );
    // In a folder of its own: other tests write pages beside theirs at the same time.
    let dir = tmp("whole-or-nothing");
    std::fs::create_dir_all(&dir).unwrap();
    let page = dir.join("never.html");
    let out = run(&[
        "run",
        &bad,
        "--format",
        "html",
        "-o",
        page.to_str().unwrap(),
    ]);
    assert_eq!(out.status.code(), Some(2));
    assert!(
        String::from_utf8_lossy(&out.stderr).starts_with("error[E0204]: undefined variable `nope`")
    );
    assert!(!page.exists());
    assert!(temp_files_in(&dir).is_empty());
    // An -o in a folder that does not exist: refused before the run.
    let nowhere = tmp("no-such-folder").join("p.html");
    let out = run(&[
        "run",
        "analyses/example-a/program.json",
        "--format",
        "html",
        "-o",
        nowhere.to_str().unwrap(),
    ]);
    assert_eq!(out.status.code(), Some(2));
    assert!(!nowhere.exists());
}

#[test]
fn the_runs_warnings_are_on_its_page_as_on_standard_error() {
    let page = tmp("interrupt.html");
    let out = run(&[
        "run",
        "analyses/encoder-interrupt/program.json",
        "--scans",
        "3",
        "--mode",
        "seq",
        "--format",
        "html",
        "-o",
        page.to_str().unwrap(),
    ]);
    assert!(out.status.success());
    let stderr = String::from_utf8_lossy(&out.stderr);
    let want = "warning[W0104]: interrupt routine ENCODER never runs here";
    assert!(stderr.starts_with(want), "{stderr}");
    let html = std::fs::read_to_string(&page).unwrap();
    let run_section = html.split("<section id=\"run\">").nth(1).unwrap();
    assert!(run_section.contains(&format!("<li class=\"note\">{want}")));
    // The analysis's warning stays in the summary, with its code.
    let summary = html.split("<section id=\"run\">").next().unwrap();
    assert!(
        summary.contains("<li class=\"note\">warning[W0204]: interrupt routine ENCODER may run")
    );
}
