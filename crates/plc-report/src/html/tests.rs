//! Structural tests of the HTML report: the page parses as XML, every rung has its card, every
//! dependence its edge, nothing points outside the file, and the Gantt chart's makespans are the
//! cost model's; the run page shows the run's figures beside the model's. (The browser test is
//! tests/it/html_browser.rs; the run page from the command line is tested in tests/it/html_run.rs.)

use super::*;
use crate::document_with;
use crate::fbd_parts;
use plc_analysis::{analyse, cost};
use std::collections::BTreeSet;

fn page(example: &str) -> (String, Program, Analysis) {
    page_with(example, None)
}

/// The page of an example: the report page, or with `run` the run page.
fn page_with(example: &str, run: Option<&RunFigures>) -> (String, Program, Analysis) {
    let path = format!(
        "{}/../../analyses/{example}/program.json",
        env!("CARGO_MANIFEST_DIR")
    );
    let text = std::fs::read_to_string(path).expect("example");
    let (p, fbd) = plc_load::program_and_fbd_from_json(&text).expect("loads");
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
    match run {
        Some(run) => render_run_html(&input, run, &mut out),
        None => render_html(&input, &mut out),
    }
    .expect("in memory");
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
    let all: BTreeSet<String> = p.rungs().iter().map(|r| format!("rung-{}", r.id)).collect();
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
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../analyses");
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
        assert_eq!(cards(&html).len(), p.rungs().len(), "{name}");
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

/// A run of Example A on 2 workers: seq 50 ns a scan, par 25 ns.
fn example_a_run() -> RunFigures {
    RunFigures {
        scans: 1000,
        cycle_ms: 10,
        threads: 2,
        workers: 2,
        rungs: 5,
        modes: vec![
            ModeFigures {
                name: "seq",
                ns_per_scan: 50.0,
            },
            ModeFigures {
                name: "par",
                ns_per_scan: 25.0,
            },
        ],
        plan: Some(PlanFigures {
            kind: "auto",
            scans_on: vec![("seq".into(), 40), ("par-lpt".into(), 960)],
            last: "par-lpt".into(),
            switches: 1,
            fallback: None,
        }),
        block_scans: Some(1000),
        identical: Some(true),
        first_difference: None,
        outputs: vec![("Q1".into(), "TRUE".into()), ("Y".into(), "FALSE".into())],
        fault_count: 3,
        faults: vec![FaultRow {
            rung: "R4".into(),
            kind: "div-by-zero",
            count: 3,
            first_scan: 2,
            last_scan: 9,
        }],
        explain: None,
        warnings: Vec::new(),
    }
}

/// The text of every row of the table with class `class`, cells joined by `|`.
fn rows(html: &str, class: &str) -> Vec<String> {
    let doc = parse(html);
    let table = doc
        .descendants()
        .find(|n| n.has_tag_name("table") && has_class(n, class))
        .unwrap_or_else(|| panic!("a table {class}"));
    table
        .children()
        .filter(|n| n.has_tag_name("tr"))
        .skip(1)
        .map(|tr| {
            tr.children()
                .filter(|n| n.is_element())
                .map(|td| {
                    td.descendants()
                        .filter(|n| n.is_text())
                        .map(|n| n.text().unwrap())
                        .collect::<String>()
                })
                .collect::<Vec<_>>()
                .join("|")
        })
        .collect()
}

#[test]
fn a_run_page_is_the_report_page_with_the_run_beside_the_model() {
    let run = example_a_run();
    let (html, _, _) = page_with("example-a", Some(&run));
    let (report, _, _) = page("example-a");
    assert_eq!(cards(&html), cards(&report), "the same rung cards");
    assert_eq!(edges(&html), edges(&report), "the same edges");
    // The run section sits between the summary and the levels.
    let at = |id: &str| html.find(&format!("<section id=\"{id}\">")).unwrap();
    assert!(at("summary") < at("run") && at("run") < at("levels"));
    assert!(!report.contains("<section id=\"run\">"));
    assert!(html.contains("<title>example_a — plc-deps run</title>"));
    assert_eq!(
        rows(&html, "rates"),
        [
            "seq|0.050|20,000,000|100.0|",
            "par|0.025|40,000,000|200.0|×2.00 over 1,000 scans"
        ]
    );
    assert!(html.contains("plan chosen (<code>--plan auto</code>): <b>par-lpt</b>; ran <code>seq</code> 40 scans, <code>par-lpt</code> 960 scans, 1 switch."));
    // Modes that took turns say how.
    let mut turns = example_a_run();
    turns.block_scans = Some(250);
    let mut buf = Vec::new();
    run::write_rates(&mut buf, &turns).unwrap();
    let section = String::from_utf8(buf).unwrap();
    assert!(
        section.contains("×2.00</b> over 1,000 scans, seq and par alternating every 250 scans<"),
        "{section}"
    );
    // Example A: W = 10, S = 6; makespans 10, 6, 6, 6 and level by level 10, 8, 6, 6.
    assert_eq!(
        rows(&html, "ideal"),
        [
            "1|10|×1.00|10|×1.00",
            "2 (this run)|6|×1.67|8|×1.25",
            "4|6|×1.67|6|×1.67",
            "8|6|×1.67|6|×1.67"
        ]
    );
    assert!(html.contains("<title>measured: ×2.00</title>"));
    assert!(html.contains("<title>model, P = 2: ×1.67</title>"));
    assert!(html.contains("<title>levels, P = 2: ×1.25</title>"));
    assert!(html.contains("<title>W/S: ×1.67</title>"));
    assert!(html.contains("identical: yes"));
    assert_eq!(rows(&html, "outputs"), ["Q1|TRUE", "Y|FALSE"]);
    assert_eq!(rows(&html, "faults"), ["R4|div-by-zero|3|2|9"]);
    assert!(html.contains(r#"<span class="chip" data-rung="R4">R4</span>"#));
    assert!(html.contains("3 faults (1 distinct)"));
}

#[test]
fn a_run_page_says_when_the_parallel_pass_fell_back_and_what_differed() {
    let mut run = example_a_run();
    run.plan = Some(PlanFigures {
        kind: "auto",
        scans_on: vec![("seq".into(), 1000)],
        last: "seq".into(),
        switches: 0,
        fallback: Some("no level saves more than the barriers it needs".into()),
    });
    run.identical = Some(false);
    run.first_difference = Some(r#"{"scan":3,"variable":"X"}"#.into());
    run.workers = 3;
    run.warnings = vec![(
        "W0101",
        "--threads 3 is more than the 2 cores <of this machine>".into(),
    )];
    run.fault_count = 0;
    run.faults.clear();
    run.explain = Some("level 1: R1 R2 <R5>".into());
    let (html, _, _) = page_with("example-a", Some(&run));
    assert!(html.contains("<details><summary>The parallel plan (--explain)</summary><pre>level 1: R1 R2 &lt;R5&gt;</pre></details>"));
    assert_eq!(
        rows(&html, "rates")[1],
        "par|0.025|40,000,000|200.0|sequential fallback (no level saves more than the barriers it needs)"
    );
    assert!(html.contains("<title>measured (fallback): ×2.00</title>"));
    assert!(html.contains(
        "identical: NO, first difference: {&quot;scan&quot;:3,&quot;variable&quot;:&quot;X&quot;}"
    ));
    // Three workers: the model has no row for them, and says so.
    assert!(!html.contains("(this run)") && html.contains("this run had 3 workers"));
    assert!(!html.contains("model, P ="));
    assert!(html.contains("<li class=\"note\">warning[W0101]: --threads 3 is more than the 2 cores &lt;of this machine&gt;</li>"));
    assert!(html.contains("<p class=\"faults\">none</p>"));
}

#[test]
fn a_run_pages_lists_are_bounded() {
    let mut run = example_a_run();
    run.outputs = (0..OUTPUT_ROWS_SHOWN + 7)
        .map(|i| (format!("Q{i}"), "TRUE".into()))
        .collect();
    run.faults = (0..FAULT_ROWS_SHOWN + 3)
        .map(|i| FaultRow {
            rung: format!("R{i}"),
            kind: "loop-cap",
            count: 1,
            first_scan: 0,
            last_scan: 0,
        })
        .collect();
    run.modes.truncate(1);
    run.plan = None;
    run.identical = None;
    let (html, _, _) = page_with("example-a", Some(&run));
    assert_eq!(rows(&html, "outputs").len(), OUTPUT_ROWS_SHOWN);
    assert!(html.contains("… and 7 more outputs"));
    assert_eq!(rows(&html, "faults").len(), FAULT_ROWS_SHOWN);
    assert!(html.contains("… and 3 more distinct faults"));
    // Sequential only: one row, no plan, no comparison, no measured bar.
    assert_eq!(rows(&html, "rates").len(), 1);
    assert!(!html.contains("plan chosen") && !html.contains("identical:"));
    assert!(!html.contains("<title>measured"));
}

/// A program with two tasks and an instance of the resource's own, as the JSON format writes it
/// (the configuration of a PLCopen project after `plc-deps convert`).
const TWO_TASKS: &str = r#"{"program": "cell",
 "vars": [{"name": "G1", "type": "BOOL"}, {"name": "G2", "type": "BOOL"}, {"name": "G3", "type": "BOOL"}, {"name": "G4", "type": "BOOL"}],
 "rungs": [{"id": "Fast.A", "ld": [{"call": "A"}]}, {"id": "Slow.B", "ld": [{"call": "B"}]},
           {"id": "Slow.C", "ld": [{"call": "C"}]}, {"id": "resource.D", "ld": [{"call": "D"}]}],
 "subroutines": {
   "A": {"rungs": [{"id": "a1", "ld": [{"contact": "G3"}, {"coil": "G1"}]}]},
   "B": {"rungs": [{"id": "b1", "ld": [{"contact": "G1"}, {"coil": "G2"}]}]},
   "C": {"rungs": [{"id": "c1", "ld": [{"contact": "G2"}, {"coil": "G4"}]}]},
   "D": {"rungs": [{"id": "d1", "ld": [{"contact": "G1"}, {"coil": "G4"}]}]}},
 "configuration": {"name": "Cell", "resources": [{"name": "Cpu",
   "tasks": [{"name": "Slow", "priority": 2, "interval": "T#100ms", "instances": [{"name": "b", "program": "B"}, {"name": "c", "program": "C"}]},
             {"name": "Fast", "priority": 0, "single": "G3", "instances": [{"name": "a", "program": "A"}]}],
   "instances": [{"name": "d", "program": "D"}]}]}}"#;

/// The page of a program given as JSON text.
fn page_of_text(text: &str) -> String {
    let (p, fbd) = plc_load::program_and_fbd_from_json(text).expect("loads");
    let a = analyse(&p);
    let doc = document_with(&p, &a, None);
    let mut out = Vec::new();
    let input = HtmlInput {
        doc: &doc,
        program: &p,
        analysis: &a,
        fbd: Some(&fbd),
    };
    render_html(&input, &mut out).expect("in memory");
    String::from_utf8(out).expect("UTF-8")
}

#[test]
fn the_tasks_section_lists_the_tasks_their_instances_and_the_globals_they_share() {
    let html = page_of_text(TWO_TASKS);
    let at = |id: &str| html.find(&format!("<section id=\"{id}\">")).unwrap();
    assert!(at("summary") < at("tasks") && at("tasks") < at("levels"));
    assert!(html.contains("<h2>Tasks of configuration Cell</h2>\n<h3>Resource Cpu</h3>"));
    // In run order: priority 0 first; the resource's own instance last.
    assert_eq!(
        rows(&html, "tasks"),
        [
            "Fast|0|-|G3|a (A)",
            "Slow|2|T#100ms|-|b (B), c (C)",
            "(no task)|-|-|-|d (D)"
        ]
    );
    assert!(html.contains("<p class=\"analysed\">Analysed: all 4 program instances, in task order: Fast.a (A), Slow.b (B), Slow.c (C), d (D).</p>"));
    // G1: Fast's A writes it, Slow's B and the resource's D read it. G4: Slow's C and D write
    // it. G2 stays inside Slow, G3 is only read.
    assert_eq!(
        rows(&html, "shared"),
        ["G1|Slow.b (B)d (D)|Fast.a (A)", "G4|-|Slow.c (C)d (D)"]
    );
    assert!(html.contains("2 globals are shared."));
    // Without a configuration, no section.
    let plain = page_of_text(
        r#"{"program": "p", "vars": [{"name": "x", "type": "BOOL"}], "rungs": [{"id": "R1", "ld": [{"coil": "x"}]}]}"#,
    );
    assert!(!plain.contains("<section id=\"tasks\">"));
    // With one task, nothing is shared between tasks.
    let fast = ",\n             {\"name\": \"Fast\", \"priority\": 0, \"single\": \"G3\", \"instances\": [{\"name\": \"a\", \"program\": \"A\"}]}";
    assert!(TWO_TASKS.contains(fast));
    let one = TWO_TASKS.replace(fast, "").replace(
        "\"instances\": [{\"name\": \"d\", \"program\": \"D\"}]",
        "\"instances\": []",
    );
    let html = page_of_text(&one);
    assert_eq!(rows(&html, "tasks"), ["Slow|2|T#100ms|-|b (B), c (C)"]);
    assert!(html.contains("Analysed: all 2 program instances, in task order: Slow.b (B), Slow.c (C).</p>\n<p>One task: nothing is shared between tasks.</p>"));
    assert!(!html.contains("<table class=\"shared\">"));
}

/// One of a thing is singular everywhere on the page (`1 rung`, `level 1 · 1 task`), and the
/// saving is rounded as the text report rounds it: a chain of 3 rungs saves nothing; rungs
/// that all run at once save 2 of 3 cycles, 67 %.
#[test]
fn counts_of_one_are_singular_and_savings_round_as_in_the_text_report() {
    let one = r#"{"program": "one", "vars": [{"name": "a", "type": "BOOL", "class": "input"},
        {"name": "y", "type": "BOOL", "class": "output"}],
        "rungs": [{"id": "R1", "ld": [{"contact": "a"}, {"coil": "y"}]}]}"#;
    let html = page_of_text(one);
    assert!(
        html.contains("<p>1 rung (1 in the main program, 0 in subroutines).</p>"),
        "{html}"
    );
    assert!(html.contains("level 1 · 1 task<"), "{html}");
    assert!(
        !html.contains(" 1 tasks") && !html.contains(" 1 rungs"),
        "{html}"
    );
    let three = r#"{"program": "three", "vars": [{"name": "a", "type": "BOOL", "class": "input"},
        {"name": "x", "type": "BOOL"}, {"name": "y", "type": "BOOL"}, {"name": "z", "type": "BOOL"}],
        "rungs": [{"id": "R1", "ld": [{"contact": "a"}, {"coil": "x"}]},
                  {"id": "R2", "ld": [{"contact": "a"}, {"coil": "y"}]},
                  {"id": "R3", "ld": [{"contact": "a"}, {"coil": "z"}]}]}"#;
    let html = page_of_text(three);
    assert!(html.contains("<td>67 %</td>"), "{html}");
    assert!(html.contains("level 1 · 3 tasks<"), "{html}");
}

/// A landing rung (a jump's label) in a subroutine with a long name: the card's meta line
/// ("label … · POU · cost N") is cut with "…" where it would run into the title, and keeps the
/// whole line in its tooltip.
#[test]
fn a_cards_meta_line_never_runs_into_its_title() {
    let html = page_of_text(
        r#"{"program": "P", "vars": [{"name": "a", "type": "BOOL", "class": "input"},
            {"name": "q", "type": "BOOL", "class": "output"}],
          "rungs": [{"id": "R1", "ld": [{"call": "A_SUBROUTINE_WITH_A_VERY_LONG_NAME"}]}],
          "subroutines": {"A_SUBROUTINE_WITH_A_VERY_LONG_NAME": {"rungs": [
            {"id": "SUB_R1", "ld": [{"contact": "a"}, {"jmp": "THE_LANDING_LABEL"}]},
            {"id": "SUB_R2", "label": "THE_LANDING_LABEL", "ld": [{"contact": "a"}, {"coil": "q"}]}]}}}"#,
    );
    let doc = parse(&html);
    let card = doc
        .descendants()
        .find(|n| has_class(n, "card") && n.attribute("id") == Some("rung-SUB_R2"))
        .expect("the landing rung's card");
    let meta = card
        .descendants()
        .find(|n| has_class(n, "meta"))
        .expect("its meta line");
    let full = meta
        .children()
        .find(|n| n.has_tag_name("title"))
        .and_then(|t| t.text())
        .expect("the whole line as a tooltip");
    assert_eq!(
        full,
        "label THE_LANDING_LABEL · A_SUBROUTINE_WITH_A_VERY_LONG_NAME · cost 2"
    );
    let shown: String = meta
        .children()
        .filter(|n| n.is_text())
        .filter_map(|n| n.text())
        .collect();
    assert!(shown.ends_with('…'), "{shown}");
    assert!(full.starts_with(shown.trim_end_matches('…')), "{shown}");
    // Title (11 px bold) from x = 6, meta right-aligned at the card's width less 6: they must
    // not meet.
    use super::ladder::CHAR;
    use super::levels::CARD_W;
    let title_end = 6.0 + "SUB_R2".chars().count() as f64 * 6.7;
    let meta_start = CARD_W - 6.0 - shown.chars().count() as f64 * CHAR;
    assert!(title_end + 4.0 <= meta_start, "{title_end} {meta_start}");
}

/// A long rung widens its column (up to twice a card's width) instead of shrinking its text
/// below 0.8 of its size; a short rung's column keeps the card's width.
#[test]
fn a_long_rung_widens_its_column_rather_than_shrink_unreadably() {
    let contacts = |n: usize| {
        (0..n)
            .map(|k| format!(r#"{{"contact": "input_number_{k}"}}"#))
            .collect::<Vec<_>>()
            .join(", ")
    };
    let vars = (0..30)
        .map(|k| format!(r#"{{"name": "input_number_{k}", "type": "BOOL", "class": "input"}}"#))
        .collect::<Vec<_>>()
        .join(", ");
    let html = page_of_text(&format!(
        r#"{{"program": "P", "vars": [{vars}, {{"name": "q", "type": "BOOL", "class": "output"}},
            {{"name": "r", "type": "BOOL", "class": "output"}}, {{"name": "s", "type": "BOOL", "class": "output"}}],
          "rungs": [{{"id": "SHORT", "ld": [{{"contact": "input_number_0"}}, {{"coil": "q"}}]}},
                    {{"id": "LONG", "ld": [{}, {{"coil": "r"}}]}},
                    {{"id": "HUGE", "ld": [{}, {{"coil": "s"}}]}}]}}"#,
        contacts(3),
        contacts(30)
    ));
    let doc = parse(&html);
    let card = |id: &str| {
        let card = doc
            .descendants()
            .find(|n| has_class(n, "card") && n.attribute("id") == Some(&format!("rung-{id}")))
            .unwrap_or_else(|| panic!("card {id}"));
        let w: f64 = card
            .descendants()
            .find(|n| has_class(n, "frame"))
            .and_then(|f| f.attribute("width"))
            .and_then(|w| w.parse().ok())
            .expect("a frame width");
        let scale: f64 = card
            .descendants()
            .filter_map(|n| n.attribute("transform"))
            .find_map(|t| t.split("scale(").nth(1))
            .and_then(|s| s.trim_end_matches(')').parse().ok())
            .expect("a scale");
        (w, scale)
    };
    // All three rungs are independent: one level, one column, as wide as the longest needs.
    let (w_short, s_short) = card("SHORT");
    let (w_long, s_long) = card("LONG");
    let (w_huge, s_huge) = card("HUGE");
    assert_eq!(w_short, w_long);
    assert_eq!(w_long, w_huge);
    assert_eq!(
        w_huge,
        2.0 * super::levels::CARD_W,
        "capped at twice a card"
    );
    assert_eq!(s_short, 1.0);
    assert!(s_long >= 0.8, "{s_long}");
    assert!(s_huge < 0.8, "past the cap the drawing shrinks: {s_huge}");
}

/// Six flow edges between the same two rungs (one per variable) used to stack their labels
/// 5 px apart, unreadable: no two shown labels overlap now, and one without a free spot is
/// shown only while its edge is highlighted.
#[test]
fn edge_labels_do_not_pile_up() {
    let names = ["alpha", "bravo", "charlie", "delta", "echo", "foxtrot"];
    let vars: Vec<String> = names
        .iter()
        .map(|n| format!(r#"{{"name": "{n}", "type": "BOOL"}}"#))
        .collect();
    let coils: Vec<String> = names
        .iter()
        .map(|n| format!(r#"[{{"coil": "{n}"}}]"#))
        .collect();
    let contacts: Vec<String> = names
        .iter()
        .map(|n| format!(r#"{{"contact": "{n}"}}"#))
        .collect();
    let html = page_of_text(&format!(
        r#"{{"program": "P", "vars": [{{"name": "a", "type": "BOOL", "class": "input"}},
            {{"name": "q", "type": "BOOL", "class": "output"}}, {}],
          "rungs": [{{"id": "W", "ld": [{{"contact": "a"}}, {{"branch": [{}]}}]}},
                    {{"id": "R", "ld": [{}, {{"coil": "q"}}]}}]}}"#,
        vars.join(", "),
        coils.join(", "),
        contacts.join(", ")
    ));
    let doc = parse(&html);
    let shown: Vec<(f64, f64, f64)> = doc
        .descendants()
        .filter(|n| has_class(n, "elabel") && !has_class(n, "crowded"))
        .map(|n| {
            let x: f64 = n.attribute("x").unwrap().parse().unwrap();
            let y: f64 = n.attribute("y").unwrap().parse().unwrap();
            let half = n.text().unwrap_or("").chars().count() as f64 * 5.5 / 2.0;
            (x - half, x + half, y)
        })
        .collect();
    let all = doc.descendants().filter(|n| has_class(n, "elabel")).count();
    assert_eq!(all, 6, "one label per flow edge W -> R");
    assert!(shown.len() >= 2, "{shown:?}");
    for (i, a) in shown.iter().enumerate() {
        for b in &shown[i + 1..] {
            let apart = a.1 <= b.0 || b.1 <= a.0 || (a.2 - b.2).abs() >= 9.9;
            assert!(apart, "labels overlap: {a:?} {b:?}");
        }
    }
}
