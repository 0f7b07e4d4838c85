//! Zhao & Yan's worked examples (Example A and B), number by number.

use crate::common;

use serde_json::{json, Value};

fn report(name: &str) -> Value {
    common::example_report(name)
}

fn deps(r: &Value, kind: &str) -> Vec<(String, String)> {
    r["dependences"]
        .as_array()
        .unwrap()
        .iter()
        .filter(|d| d["kind"] == kind)
        .map(|d| {
            (
                d["from"].as_str().unwrap().to_owned(),
                d["to"].as_str().unwrap().to_owned(),
            )
        })
        .collect()
}

fn pairs(v: &[(&str, &str)]) -> Vec<(String, String)> {
    v.iter()
        .map(|(a, b)| (a.to_string(), b.to_string()))
        .collect()
}

#[test]
fn example_a_dependences_levels_and_cycles() {
    let r = report("example-a");
    assert_eq!(deps(&r, "output"), pairs(&[("R2", "R3")]));
    assert_eq!(deps(&r, "flow"), pairs(&[("R2", "R4"), ("R3", "R4")]));
    assert_eq!(deps(&r, "anti"), pairs(&[]));
    assert_eq!(deps(&r, "control"), pairs(&[]));
    assert_eq!(
        r["levels"]["data"],
        json!([["R1", "R2", "R5"], ["R3"], ["R4"]])
    );
    assert_eq!(r["cycles"]["before"], 5);
    assert_eq!(r["cycles"]["data"], 3);
    // No control flow to respect: the combined schedule is the data view.
    assert_eq!(
        r["levels"]["combined"],
        json!([["R1", "R2", "R5"], ["R3"], ["R4"]])
    );
}

#[test]
fn example_b_ipdoms_control_dependences_levels_and_cycles() {
    let r = report("example-b");
    let expected_ipdom = json!({
        "START": "R1", "R1": "R9", "R2": "R3", "R3": "R4", "R4": "R9", "R5": "R6", "R6": "R7",
        "R7": "R8", "R8": "R3", "R9": "R10", "R10": "STOP", "R11": "R10", "R12": "R10"
    });
    assert_eq!(r["ipdom"], expected_ipdom);
    assert_eq!(
        deps(&r, "control"),
        pairs(&[
            ("R1", "R2"),
            ("R1", "R3"),
            ("R1", "R4"),
            ("R3", "R5"),
            ("R3", "R6"),
            ("R3", "R7"),
            ("R3", "R8"),
            ("R6", "R7"),
            ("R10", "R11"),
            ("R10", "R12"),
        ])
    );
    assert_eq!(
        r["levels"]["control"],
        json!([
            ["R1", "R9", "R10"],
            ["R2", "R3", "R4", "R11", "R12"],
            ["R5", "R6", "R8"],
            ["R7"]
        ])
    );
    assert_eq!(r["cycles"]["before"], 12);
    assert_eq!(r["cycles"]["control"], 4);
    // The correct schedule keeps the loop R3..R8 whole and waits for R1's jump decision. R4
    // runs only if the loop is left through R3: when the iteration cap refuses R8's jump,
    // control goes on to R9 and R4 is skipped, so R4 waits for the loop task.
    assert_eq!(
        r["levels"]["combined"],
        json!([
            ["R1", "R9", "R10"],
            ["R2"],
            [["R3", "R5", "R6", "R7", "R8"]],
            ["R4"]
        ])
    );
    assert_eq!(r["cycles"]["combined"], 4);
    // CFG edge labels where rungs branch.
    let edges = r["cfg"]["edges"].as_array().unwrap();
    let labelled = |from: &str, to: &str| {
        edges
            .iter()
            .find(|e| e["from"] == from && e["to"] == to)
            .map(|e| e["label"].clone())
    };
    assert_eq!(labelled("R1", "R9"), Some(json!("T")));
    assert_eq!(labelled("R1", "R2"), Some(json!("F")));
    assert_eq!(labelled("R3", "R5"), Some(json!("T")));
    assert_eq!(labelled("R3", "R4"), Some(json!("F")));
    // R8's unconditional backward jump, and where a refusal by the iteration cap goes; the
    // paper's post-dominators and control dependences (above) do not see that edge.
    assert_eq!(labelled("R8", "R3"), Some(json!("T")));
    assert_eq!(labelled("R8", "R9"), Some(json!("F")));
    let refused: Vec<_> = edges.iter().filter(|e| e["kind"] == "refused").collect();
    assert_eq!(
        refused,
        [&json!({"from": "R8", "to": "R9", "label": "F", "kind": "refused"})]
    );
}
