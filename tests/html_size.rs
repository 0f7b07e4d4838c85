//! The HTML report's size at scale: at 500 rungs every rung has its card; at 100,000 rungs
//! (`plc-deps gen --rungs 100000 --width 5000`) the page collapses the levels to summaries, says
//! so, and stays under a few megabytes.

mod common;

use common::cli::{run, tmp};

fn html_of(rungs: usize, width: usize) -> String {
    let file = tmp(&format!("html-size-{rungs}.json"));
    let path = file.to_str().unwrap().to_owned();
    let (r, w) = (rungs.to_string(), width.to_string());
    let out = run(&["gen", "--rungs", &r, "--width", &w, "-o", &path]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
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
}
