//! `plc-deps order` as a user meets it: the normative JSON keys, the text, DOT that Graphviz
//! renders cleanly (also the report's DOT of FBD programs), and cycles and fragment-rule
//! violations as one located error with exit code 2 and no output file.

use crate::common;

use common::cli::*;

use serde_json::Value;

const FBD_EXAMPLES: &[&str] = &[
    "example-c",
    "kaskad-1",
    "kaskad-2",
    "kaskad-3",
    "kaskad-4",
    "kaskad-5",
];

fn keys(v: &Value) -> Vec<&str> {
    let mut k: Vec<&str> = v
        .as_object()
        .expect("an object")
        .keys()
        .map(String::as_str)
        .collect();
    k.sort_unstable();
    k
}

#[test]
fn order_json_has_the_normative_keys() {
    let out = run(&[
        "order",
        "analyses/example-c/program.json",
        "--format",
        "json",
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let doc: Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(keys(&doc), vec!["pous"]);
    let pous = doc["pous"].as_array().unwrap();
    assert_eq!(
        pous.iter()
            .map(|p| p["name"].as_str().unwrap())
            .collect::<Vec<_>>(),
        vec!["block1", "WriteValue"]
    );
    for pou in pous {
        assert!(keys(pou).contains(&"name") && keys(pou).contains(&"networks"));
        for net in pou["networks"].as_array().unwrap() {
            for k in ["id", "order", "fragments"] {
                assert!(keys(net).contains(&k), "network lacks {k}");
            }
            for f in net["fragments"].as_array().unwrap() {
                assert_eq!(keys(f), vec!["blocks", "condition", "id", "parent"]);
            }
        }
    }
    let n1 = &pous[0]["networks"][0];
    assert_eq!(n1["id"], "N1");
    assert_eq!(
        n1["order"],
        serde_json::json!([3, 4, 8, 10, 27, 24, 15, 17])
    );
    let frags: Vec<(String, Value, String, Value)> = n1["fragments"]
        .as_array()
        .unwrap()
        .iter()
        .map(|f| {
            (
                f["id"].as_str().unwrap().to_owned(),
                f["parent"].clone(),
                f["condition"].as_str().unwrap().to_owned(),
                f["blocks"].clone(),
            )
        })
        .collect();
    use serde_json::json;
    assert_eq!(
        frags,
        vec![
            ("root".into(), Value::Null, "always".into(), json!([3, 4])),
            ("F(3)".into(), json!("root"), "3.OUT".into(), json!([8])),
            (
                "F(4)".into(),
                json!("root"),
                "4.OUT".into(),
                json!([10, 27])
            ),
            ("F(27)".into(), json!("F(4)"), "27.OUT".into(), json!([24])),
            (
                "FC".into(),
                json!("root"),
                "F(3) OR F(4)".into(),
                json!([15, 17])
            ),
        ]
    );
}

#[test]
fn order_text_shows_orders_fragments_and_block_accesses() {
    let out = run(&["order", "analyses/example-c/program.json"]);
    assert!(out.status.success());
    let text = String::from_utf8(out.stdout).unwrap();
    assert!(
        text.contains("execution order    3 4 8 10 27 24 15 17"),
        "{text}"
    );
    assert!(
        text.contains("topological order  3 4 8 10 15 17 27 24"),
        "{text}"
    );
    assert!(
        text.contains("FC       root    F(3) OR F(4)  15 17"),
        "{text}"
    );
    assert!(text.contains("instance WriteValue_17"), "{text}");
    assert!(text.contains("network IN:"), "{text}");
}

#[test]
fn order_of_a_ladder_program_has_no_networks() {
    let out = run(&[
        "order",
        "analyses/example-a/program.json",
        "--format",
        "json",
    ]);
    assert!(out.status.success());
    let doc: Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(doc, serde_json::json!({"pous": []}));
    let out = run(&["order", "analyses/example-a/program.json"]);
    assert!(String::from_utf8(out.stdout)
        .unwrap()
        .contains("no FBD bodies"));
}

#[test]
fn order_writes_the_output_file_whole() {
    let file = tmp("order.json");
    let out = run(&[
        "order",
        "analyses/kaskad-5/program.json",
        "--format",
        "json",
        "-o",
        file.to_str().unwrap(),
    ]);
    assert!(out.status.success() && out.stdout.is_empty());
    assert_eq!(
        std::fs::read_to_string(&file).unwrap(),
        std::fs::read_to_string(root().join("analyses/kaskad-5/order.json")).unwrap()
    );
}

/// A failing `order`: exit code 2, one line on stderr, nothing on stdout, no output file.
fn refused(program: &str) -> String {
    let file = tmp(&format!("{}.txt", program.replace('/', "_")));
    let out = run(&["order", program, "-o", file.to_str().unwrap()]);
    let stderr = String::from_utf8(out.stderr).unwrap();
    assert_eq!(out.status.code(), Some(2), "{stderr}");
    assert!(out.stdout.is_empty());
    assert!(!file.exists());
    assert_eq!(one_line(&stderr).lines().count(), 1, "{stderr}");
    stderr
}

#[test]
fn a_cycle_of_arcs_is_exit_code_2_naming_the_blocks() {
    let e = refused("tests/errors/fbd-cycle.json");
    assert_eq!(
        e,
        std::fs::read_to_string(root().join("tests/errors/fbd-cycle.err")).unwrap()
    );
    assert!(
        e.contains("blocks 5 → 6 → 7 → 5 form a cycle") && e.contains("variable"),
        "{e}"
    );
}

#[test]
fn a_fragment_rule_violation_is_exit_code_2_naming_blocks_and_fragments() {
    let e = refused("tests/errors/fbd-fragment-rule.json");
    assert_eq!(
        e,
        std::fs::read_to_string(root().join("tests/errors/fbd-fragment-rule.err")).unwrap()
    );
    assert!(
        e.contains("block 12 (fragment F(3)) reads an output of block 9 (fragment F(4))"),
        "{e}"
    );
}

#[test]
fn order_and_report_dot_render_with_graphviz_without_warnings() {
    for example in FBD_EXAMPLES {
        let program = format!("analyses/{example}/program.json");
        let out = run(&["order", &program, "--format", "dot"]);
        assert!(out.status.success());
        let dot = String::from_utf8(out.stdout.clone()).unwrap();
        assert!(
            dot.contains("subgraph \"cluster_p0n0\""),
            "{example}: {dot}"
        );
        graphviz(&out.stdout, &format!("order {example}"));
        let out = run(&["report", &program, "--format", "dot"]);
        assert!(out.status.success());
        graphviz(&out.stdout, &format!("report {example}"));
    }
    let dot = String::from_utf8(
        run(&[
            "order",
            "analyses/example-c/program.json",
            "--format",
            "dot",
        ])
        .stdout,
    )
    .unwrap();
    assert!(dot.contains("label=\"F(27): if 27.OUT\""), "{dot}");
}
