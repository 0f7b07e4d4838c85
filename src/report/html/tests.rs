//! Structural tests of the HTML report: the page parses as XML, every rung has its card, every
//! dependence its edge, nothing points outside the file, and the Gantt chart's makespans are the
//! cost model's. (The browser test is tests/html_browser.rs.)

use super::*;
use crate::analysis::{analyse, cost};
use crate::report::document_with;
use crate::report::fbd_parts;
use std::collections::BTreeSet;

fn page(example: &str) -> (String, Program, Analysis) {
    let path = format!(
        "{}/analyses/{example}/program.json",
        env!("CARGO_MANIFEST_DIR")
    );
    let text = std::fs::read_to_string(path).expect("example");
    let (p, fbd) = crate::load::program_and_fbd_from_json(&text).expect("loads");
    let a = analyse(&p);
    let parts = fbd_parts(&p, &fbd);
    let doc = document_with(&p, &a, parts.as_ref());
    let mut out = Vec::new();
    let input = HtmlInput {
        doc: &doc,
        program: &p,
        analysis: &a,
        fbd: Some(&fbd),
    };
    render_html(&input, &mut out).expect("in memory");
    drop(doc);
    (String::from_utf8(out).expect("UTF-8"), p, a)
}

fn has_class(n: &roxmltree::Node, c: &str) -> bool {
    n.attribute("class")
        .is_some_and(|v| v.split(' ').any(|x| x == c))
}

/// (id, data-level) of every card, in document order.
fn parse(html: &str) -> roxmltree::Document<'_> {
    let opt = roxmltree::ParsingOptions {
        allow_dtd: true,
        ..Default::default()
    };
    roxmltree::Document::parse_with_options(html, opt).expect("the page is well-formed XML")
}

fn cards(html: &str) -> Vec<(String, Option<String>)> {
    let doc = parse(html);
    doc.descendants()
        .filter(|n| has_class(n, "card"))
        .map(|n| {
            (
                n.attribute("id").unwrap_or_default().to_string(),
                n.attribute("data-level").map(str::to_string),
            )
        })
        .collect()
}

/// (from, to, kind, var) of every drawn edge.
fn edges(html: &str) -> BTreeSet<(String, String, String, String)> {
    let doc = parse(html);
    doc.descendants()
        .filter(|n| has_class(n, "e"))
        .map(|n| {
            let kind = n.attribute("class").unwrap().split(' ').nth(1).unwrap();
            let a = |k| n.attribute(k).unwrap_or_default().to_string();
            (
                a("data-from"),
                a("data-to"),
                kind.to_string(),
                a("data-var"),
            )
        })
        .collect()
}

#[test]
fn example_a_has_a_card_per_rung_at_its_level_and_an_edge_per_dependence() {
    let (html, _, _) = page("example-a");
    let c = cards(&html);
    // Cards in program order, each with its combined level.
    let want = [
        ("R1", "1"),
        ("R2", "1"),
        ("R3", "2"),
        ("R4", "3"),
        ("R5", "1"),
    ];
    let got: Vec<(&str, &str)> = c
        .iter()
        .map(|(id, l)| (id.trim_start_matches("rung-"), l.as_deref().unwrap()))
        .collect();
    assert_eq!(got, want);
    let s = |a: &str| a.to_string();
    let want: BTreeSet<_> = [
        (s("R2"), s("R3"), s("output"), s("X")),
        (s("R2"), s("R4"), s("flow"), s("X")),
        (s("R3"), s("R4"), s("flow"), s("X")),
    ]
    .into_iter()
    .collect();
    assert_eq!(edges(&html), want);
}

#[test]
fn example_b_draws_subroutines_loops_and_control_edges() {
    let (html, p, _) = page("example-b");
    let c = cards(&html);
    let ids: BTreeSet<String> = c.iter().map(|(id, _)| id.clone()).collect();
    let all: BTreeSet<String> = p.rungs.iter().map(|r| format!("rung-{}", r.id)).collect();
    assert_eq!(ids, all, "one card per rung, subroutine rungs included");
    // Subroutine rungs run inside R10's task: no level of their own.
    let level = |id: &str| c.iter().find(|(x, _)| x == id).unwrap().1.clone();
    assert_eq!(level("rung-R11"), None);
    assert_eq!(level("rung-R3").as_deref(), Some("3"));
    assert_eq!(
        html.matches("<rect class=\"loop\"").count(),
        1,
        "one loop task"
    );
    let e = edges(&html);
    // 7 data pairs and 10 control pairs (the text report's counts).
    assert_eq!(e.iter().filter(|x| x.2 != "control").count(), 7);
    assert_eq!(e.iter().filter(|x| x.2 == "control").count(), 10);
    assert!(e.contains(&("R6".into(), "R7".into(), "control".into(), "T1".into())));
    assert!(e.contains(&("R3".into(), "R5".into(), "control".into(), "if T".into())));
    // The ladder drawing has R1's jump and R6's timer box.
    assert!(html.contains(">TON T1</text>") && html.contains(">PT T#500ms</text>"));
}

#[test]
fn every_example_page_is_well_formed_and_self_contained() {
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("analyses");
    let mut n = 0;
    for dir in std::fs::read_dir(root).unwrap() {
        let dir = dir.unwrap().path();
        if !dir.join("program.json").is_file() {
            continue;
        }
        let name = dir.file_name().unwrap().to_string_lossy().into_owned();
        let (html, p, _) = page(&name);
        assert!(
            !html.to_lowercase().contains("http"),
            "{name}: a URL in the page"
        );
        assert!(!html.contains(" src="), "{name}: a loaded resource");
        assert_eq!(cards(&html).len(), p.rungs.len(), "{name}");
        n += 1;
    }
    assert!(n >= 11, "{n} examples");
}

#[test]
fn fbd_blocks_are_drawn_as_blocks_with_their_arcs() {
    let (html, _, _) = page("kaskad-1");
    // Block 2 (ADD) reads block 1's OUT through an arc and writes nothing itself.
    assert!(html.contains(">#2 ADD</text>"), "the block's title");
    assert!(
        html.contains(">#1.OUT</text>"),
        "the arc into it, named by block and pin"
    );
}

#[test]
fn the_gantt_makespans_are_the_cost_models() {
    for example in ["example-b", "packaging-line", "mixing-station"] {
        let (html, _, a) = page(example);
        let costs = cost::task_costs(&a.schedule, &a.rung_costs);
        for &(p, m) in &a.cost.makespan {
            let slots = cost::list_schedule(&costs, &a.schedule.preds, p as usize);
            assert_eq!(slots.len(), a.schedule.tasks.len());
            let got = slots.iter().map(|s| s.finish).max().unwrap_or(0);
            assert_eq!(got, m, "{example}, P = {p}");
            // No core runs two tasks at once.
            for s in &slots {
                assert!(!slots.iter().any(|t| t.core == s.core
                    && t.task != s.task
                    && t.start < s.finish
                    && s.start < t.finish));
            }
        }
        for p in [2, 4] {
            let m = a.cost.makespan.iter().find(|x| x.0 == p).unwrap().1;
            assert!(
                html.contains(&format!("<h3>P = {p}: makespan {m}</h3>")),
                "{example}"
            );
        }
    }
}

#[test]
fn escaping_covers_markup_and_quotes() {
    assert_eq!(esc("a<b>&\"c'"), "a&lt;b&gt;&amp;&quot;c&#39;");
    assert!(matches!(esc("plain"), Cow::Borrowed("plain")));
}
