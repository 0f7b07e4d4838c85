//! The HTML report's size at scale: at 500 rungs every rung has its card; at 100,000 rungs
//! (`plc-deps gen --rungs 100000 --width 5000`) the page collapses the levels to summaries, says
//! so, and stays under a few megabytes; so does the page of `plc-deps run` at 100,000 rungs.

use crate::common;

use common::cli::{run, tmp};

/// A program of `gen --rungs R --width W`, written once per test process.
fn generated(rungs: usize, width: usize) -> String {
    let file = tmp(&format!("html-size-{rungs}.json"));
    let path = file.to_str().unwrap().to_owned();
    static LOCK: std::sync::Mutex<()> = std::sync::Mutex::new(());
    let _once = LOCK.lock().unwrap();
    if !file.exists() {
        let (r, w) = (rungs.to_string(), width.to_string());
        let out = run(&["gen", "--rungs", &r, "--width", &w, "-o", &path]);
        assert!(
            out.status.success(),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
    }
    path
}

fn html_of(rungs: usize, width: usize) -> String {
    let path = generated(rungs, width);
    let out = run(&["report", &path, "--format", "html"]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    String::from_utf8(out.stdout).unwrap()
}

#[test]
fn five_hundred_rungs_are_all_drawn() {
    let html = html_of(500, 100);
    assert_eq!(html.matches("<g class=\"card\"").count(), 500);
    for i in [1, 250, 500] {
        assert!(html.contains(&format!("id=\"rung-R{i}\"")), "R{i}");
    }
    assert!(!html.contains("this page draws as cards"));
    assert!(html.contains("<div id=\"info\">Hover or click a rung"));
    assert!(html.len() < 4_000_000, "{} bytes", html.len());
}

#[test]
fn a_hundred_thousand_rungs_collapse_to_level_summaries_under_a_few_megabytes() {
    let html = html_of(100_000, 5000);
    assert!(html.len() < 3_000_000, "{} bytes", html.len());
    assert_eq!(html.matches("<g class=\"card\"").count(), 0);
    assert!(html.contains("100,000 rungs: more than the 2,000 this page draws as cards"));
    assert!(html.contains("The CFG and the post-dominator tree have 100,002 nodes"));
    assert!(html.contains("each core's consecutive tasks drawn as one busy bar"));
    // One summary row per level.
    assert_eq!(html.matches("<tr data-level=").count(), 20);
    // No rung is drawn, so nothing invites the reader to hover one.
    assert!(!html.contains("Hover or click a rung"));
}

#[test]
fn the_run_page_of_a_hundred_thousand_rungs_stays_under_a_few_megabytes() {
    let path = generated(100_000, 5000);
    let out = run(&["run", &path, "--scans", "3", "--format", "html"]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let html = String::from_utf8(out.stdout).unwrap();
    assert!(html.len() < 3_000_000, "{} bytes", html.len());
    assert!(html.contains("<section id=\"run\">"));
    assert!(html.contains("<tr class=\"mode-seq\">") && html.contains("<tr class=\"mode-par\">"));
    assert!(html.contains("100,000 rungs: more than the 2,000 this page draws as cards"));
    // Every output variable of the program has its row (fewer than the 500 the page lists).
    let program: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&path).unwrap()).unwrap();
    let outputs = program["vars"]
        .as_array()
        .unwrap()
        .iter()
        .filter(|v| v["class"] == "output")
        .count();
    assert!(outputs > 100 && outputs < 500, "{outputs}");
    let rows = html
        .split("<table class=\"outputs\">")
        .nth(1)
        .unwrap()
        .split("</table>")
        .next()
        .unwrap()
        .matches("<tr><td>")
        .count();
    assert_eq!(rows, outputs);
}
