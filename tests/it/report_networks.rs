//! FBD programs get per-network IN/OUT in the report: the union over the network's block rungs.

use crate::common;

use serde_json::Value;
use std::collections::BTreeSet;

fn report(name: &str) -> Value {
    common::example_report(name)
}

fn names(v: &Value) -> BTreeSet<String> {
    v.as_array()
        .unwrap()
        .iter()
        .map(|x| x.as_str().unwrap().to_owned())
        .collect()
}

#[test]
fn network_in_out_is_the_union_of_its_blocks() {
    let r = report("example-c");
    let nets = r["networks"]
        .as_array()
        .expect("FBD programs have networks");
    let n1 = nets.iter().find(|n| n["id"] == "N1").unwrap();
    let rungs = names(&n1["rungs"]);
    // The network's rungs are its eight blocks plus the fragment guards and landing rungs.
    for b in [
        "N1.3", "N1.4", "N1.8", "N1.10", "N1.27", "N1.24", "N1.15", "N1.17",
    ] {
        assert!(rungs.contains(b), "{b} missing from {rungs:?}");
    }
    let (mut ins, mut outs) = (BTreeSet::new(), BTreeSet::new());
    for rung in r["rungs"].as_array().unwrap() {
        if rungs.contains(rung["id"].as_str().unwrap()) {
            ins.extend(names(&rung["in"]));
            outs.extend(names(&rung["out"]));
        }
    }
    assert_eq!(names(&n1["in"]), ins);
    assert_eq!(names(&n1["out"]), outs);
    assert!(ins.contains("Var1") && outs.contains("Var3"));
}

#[test]
fn ladder_programs_have_no_networks_key() {
    assert!(report("example-b").get("networks").is_none());
}
