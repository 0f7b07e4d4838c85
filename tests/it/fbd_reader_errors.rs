//! What the FBD reader refuses, and the exact message for each: every malformed part of a
//! body, a network, a block, an input, an output, and the order in which two problems of one
//! body are reported (the first in the order docs/fbd.md's error rules walk a body). The texts
//! are those of the reader that walked JSON values before the FBD syntax existed.

use serde_json::{json, Value as Json};

/// `(fbd, other top-level keys, message)`: the program is `{"program": "p", "vars": VARS,
/// "fbd": fbd, …}` (the other keys may replace `vars`).
const CASES: &[(&str, &str, &str)] = &[
    (
        r###"5"###,
        r###"{}"###,
        r###"at fbd: expected an object (an FBD body: {"networks": [...]}), found number 5"###,
    ),
    (
        r###"{"networks": [], "x": 1}"###,
        r###"{}"###,
        r###"at fbd.x: unknown field `x` in an FBD body (allowed: networks, comment)"###,
    ),
    (
        r###"{}"###,
        r###"{}"###,
        r###"at fbd: missing field `networks` in an FBD body"###,
    ),
    (
        r###"{"networks": 5}"###,
        r###"{}"###,
        r###"at fbd.networks: expected an array, found number 5"###,
    ),
    (
        r###"{"networks": []}"###,
        r###"{}"###,
        r###"at fbd.networks: expected at least one network, found an empty array"###,
    ),
    (
        r###"{"networks": [5]}"###,
        r###"{}"###,
        r###"at fbd.networks[0]: expected an object (a network), found number 5"###,
    ),
    (
        r###"{"networks": [{}]}"###,
        r###"{}"###,
        r###"at fbd.networks[0]: missing field `id` in a network"###,
    ),
    (
        r###"{"networks": [{"id": "a b", "blocks": [{"id": 1, "op": "ADD", "in": ["A", 1], "out": "B"}]}]}"###,
        r###"{}"###,
        r###"at fbd.networks[0].id: expected a network id without spaces or quotes, found "a b""###,
    ),
    (
        r###"{"networks": [{"id": 5}]}"###,
        r###"{}"###,
        r###"at fbd.networks[0].id: expected a string, found number 5"###,
    ),
    (
        r###"{"networks": [{"id": "N1", "blocks": [{"id": 1, "op": "ADD", "in": ["A", 1], "out": "B"}], "x": 1}]}"###,
        r###"{}"###,
        r###"network N1 at fbd.networks[0].x: unknown field `x` in a network (allowed: id, label, comment, blocks, order)"###,
    ),
    (
        r###"{"networks": [{"id": "N1", "blocks": [{"id": 1, "op": "ADD", "in": ["A", 1], "out": "B"}], "label": 5}]}"###,
        r###"{}"###,
        r###"network N1 at fbd.networks[0].label: expected a string, found number 5"###,
    ),
    (
        r###"{"networks": [{"id": "N1", "blocks": [{"id": 1, "op": "ADD", "in": ["A", 1], "out": "B"}], "label": "1a"}]}"###,
        r###"{}"###,
        r###"network N1 at fbd.networks[0].label: `1a` is not a valid name (letters, digits and _, not starting with a digit)"###,
    ),
    (
        r###"{"networks": [{"id": "N1", "blocks": [{"id": 1, "op": "ADD", "in": ["A", 1], "out": "B"}], "comment": 5}]}"###,
        r###"{}"###,
        r###"network N1 at fbd.networks[0].comment: expected a string, found number 5"###,
    ),
    (
        r###"{"networks": [{"id": "N1"}]}"###,
        r###"{}"###,
        r###"network N1 at fbd.networks[0]: missing field `blocks` in a network"###,
    ),
    (
        r###"{"networks": [{"id": "N1", "blocks": 5}]}"###,
        r###"{}"###,
        r###"network N1 at fbd.networks[0].blocks: expected an array, found number 5"###,
    ),
    (
        r###"{"networks": [{"id": "N1", "blocks": []}]}"###,
        r###"{}"###,
        r###"network N1 at fbd.networks[0].blocks: expected at least one block, found an empty array"###,
    ),
    (
        r###"{"networks": [{"id": "N1", "blocks": [{"id": 1, "op": "ADD", "in": ["A", 1], "out": "B"}]}, {"id": "N1", "blocks": [{"id": 2, "op": "ADD", "in": ["A", 1], "out": "B"}]}]}"###,
        r###"{}"###,
        r###"network N1 at fbd.networks[1].id: network id `N1` is used twice (first at fbd.networks[0])"###,
    ),
    (
        r###"{"networks": [{"id": "N1", "blocks": [{"id": 1, "op": "ADD", "in": ["A", 1], "out": "B"}], "label": "L"}, {"id": "N2", "label": "L", "blocks": [{"id": 2, "op": "ADD", "in": ["A", 1], "out": "B"}]}]}"###,
        r###"{}"###,
        r###"network N2 at fbd.networks[1].label: label `L` is used twice in p (first on network N1)"###,
    ),
    (
        r###"{"networks": [{"id": "N1", "blocks": [5]}]}"###,
        r###"{}"###,
        r###"network N1 at fbd.networks[0].blocks[0]: expected an object (a block), found number 5"###,
    ),
    (
        r###"{"networks": [{"id": "N1", "blocks": [{}]}]}"###,
        r###"{}"###,
        r###"network N1 at fbd.networks[0].blocks[0]: missing field `id` in a block"###,
    ),
    (
        r###"{"networks": [{"id": "N1", "blocks": [{"id": -1}]}]}"###,
        r###"{}"###,
        r###"network N1 at fbd.networks[0].blocks[0].id: expected a block id (a whole number, 0 or more), found number -1"###,
    ),
    (
        r###"{"networks": [{"id": "N1", "blocks": [{"id": 1.5}]}]}"###,
        r###"{}"###,
        r###"network N1 at fbd.networks[0].blocks[0].id: expected a block id (a whole number, 0 or more), found number 1.5"###,
    ),
    (
        r###"{"networks": [{"id": "N1", "blocks": [{"id": 1, "op": "ADD", "in": ["A", 1], "out": "B", "x": 1}]}]}"###,
        r###"{}"###,
        r###"network N1 block 1 at fbd.networks[0].blocks[0].x: unknown field `x` in a block (allowed: id, op, in, out, instance, cond, en, after, label, comment)"###,
    ),
    (
        r###"{"networks": [{"id": "N1", "blocks": [{"id": 1}]}]}"###,
        r###"{}"###,
        r###"network N1 block 1 at fbd.networks[0].blocks[0]: missing field `op` in a block"###,
    ),
    (
        r###"{"networks": [{"id": "N1", "blocks": [{"id": 1, "op": 5}]}]}"###,
        r###"{}"###,
        r###"network N1 block 1 at fbd.networks[0].blocks[0].op: expected a string, found number 5"###,
    ),
    (
        r###"{"networks": [{"id": "N1", "blocks": [{"id": 1, "op": "JMP", "in": 5, "label": "L"}]}]}"###,
        r###"{}"###,
        r###"network N1 block 1 at fbd.networks[0].blocks[0].in: `in` is not allowed on a JMP or RET (its condition is `cond`)"###,
    ),
    (
        r###"{"networks": [{"id": "N1", "blocks": [{"id": 1, "op": "ADD"}]}]}"###,
        r###"{}"###,
        r###"network N1 block 1 at fbd.networks[0].blocks[0]: missing field `in` in a block with inputs"###,
    ),
    (
        r###"{"networks": [{"id": "N1", "blocks": [{"id": 1, "op": "SUB", "in": ["A"]}]}]}"###,
        r###"{}"###,
        r###"network N1 block 1 at fbd.networks[0].blocks[0].in: SUB takes 2 inputs (IN1, IN2), found 1"###,
    ),
    (
        r###"{"networks": [{"id": "N1", "blocks": [{"id": 1, "op": "ADD", "in": 5}]}]}"###,
        r###"{}"###,
        r###"network N1 block 1 at fbd.networks[0].blocks[0].in: expected an array of inputs or an object {PIN: input}, found number 5"###,
    ),
    (
        r###"{"networks": [{"id": "N1", "blocks": [{"id": 1, "op": "SUB", "in": {"IN1": "A", "Q": "B"}}]}]}"###,
        r###"{}"###,
        r###"network N1 block 1 at fbd.networks[0].blocks[0].in.Q: SUB has no input `Q` (inputs: IN1, IN2)"###,
    ),
    (
        r###"{"networks": [{"id": "N1", "blocks": [{"id": 1, "op": "ADD", "in": {"IN0": "A"}}]}]}"###,
        r###"{}"###,
        r###"network N1 block 1 at fbd.networks[0].blocks[0].in.IN0: ADD has no input `IN0` (inputs: IN1, IN2, …)"###,
    ),
    (
        r###"{"networks": [{"id": "N1", "blocks": [{"id": 1, "op": "ADD", "in": [null, 1], "out": "B"}]}]}"###,
        r###"{}"###,
        r###"network N1 block 1 at fbd.networks[0].blocks[0].in[0]: expected an operand or an arc {"from": BLOCK}, found null"###,
    ),
    (
        r###"{"networks": [{"id": "N1", "blocks": [{"id": 1, "op": "JMP", "label": "L", "out": "A"}]}]}"###,
        r###"{}"###,
        r###"network N1 block 1 at fbd.networks[0].blocks[0].out: `out` is not allowed on a block without outputs"###,
    ),
    (
        r###"{"networks": [{"id": "N1", "blocks": [{"id": 1, "op": "ADD", "in": ["A", 1], "out": 5}]}]}"###,
        r###"{}"###,
        r###"network N1 block 1 at fbd.networks[0].blocks[0].out: expected a variable name, an array or an object {PIN: variable}, found number 5"###,
    ),
    (
        r###"{"networks": [{"id": "N1", "blocks": [{"id": 1, "op": "ADD", "in": ["A", 1], "out": [5]}]}]}"###,
        r###"{}"###,
        r###"network N1 block 1 at fbd.networks[0].blocks[0].out[0]: expected a variable name or null, found number 5"###,
    ),
    (
        r###"{"networks": [{"id": "N1", "blocks": [{"id": 1, "op": "ADD", "in": ["A", 1], "out": ["A", "B"]}]}]}"###,
        r###"{}"###,
        r###"network N1 block 1 at fbd.networks[0].blocks[0].out: ADD takes at most 1 output (OUT), found 2"###,
    ),
    (
        r###"{"networks": [{"id": "N1", "blocks": [{"id": 1, "op": "ADD", "in": ["A", 1], "out": {"X": "A"}}]}]}"###,
        r###"{}"###,
        r###"network N1 block 1 at fbd.networks[0].blocks[0].out.X: ADD has no output `X` (outputs: OUT)"###,
    ),
    (
        r###"{"networks": [{"id": "N1", "blocks": [{"id": 1, "op": "ADD", "in": ["A", 1], "out": {"OUT": 5}}]}]}"###,
        r###"{}"###,
        r###"network N1 block 1 at fbd.networks[0].blocks[0].out.OUT: expected a variable name or an array of them, found number 5"###,
    ),
    (
        r###"{"networks": [{"id": "N1", "blocks": [{"id": 1, "op": "ADD", "in": ["A", 1], "out": {"OUT": ["B", 5]}}]}]}"###,
        r###"{}"###,
        r###"network N1 block 1 at fbd.networks[0].blocks[0].out.OUT[1]: expected a variable name, found number 5"###,
    ),
    (
        r###"{"networks": [{"id": "N1", "blocks": [{"id": 1, "op": "TON", "in": ["X", "T#1s"]}]}]}"###,
        r###"{}"###,
        r###"network N1 block 1 at fbd.networks[0].blocks[0]: missing field `instance` in a timer, counter or function block"###,
    ),
    (
        r###"{"networks": [{"id": "N1", "blocks": [{"id": 1, "op": "ADD", "in": ["A", 1], "out": "B", "instance": "T1"}]}]}"###,
        r###"{}"###,
        r###"network N1 block 1 at fbd.networks[0].blocks[0].instance: `instance` is not allowed on this block (only timers, counters and function blocks have one)"###,
    ),
    (
        r###"{"networks": [{"id": "N1", "blocks": [{"id": 1, "op": "TON", "in": ["X", "T#1s"], "instance": 5}]}]}"###,
        r###"{}"###,
        r###"network N1 block 1 at fbd.networks[0].blocks[0].instance: expected a string, found number 5"###,
    ),
    (
        r###"{"networks": [{"id": "N1", "blocks": [{"id": 1, "op": "TON", "in": ["X", "T#1s"], "instance": "T1", "label": "L"}]}]}"###,
        r###"{}"###,
        r###"network N1 block 1 at fbd.networks[0].blocks[0].label: `label` is not allowed on a block other than JMP (label the network)"###,
    ),
    (
        r###"{"networks": [{"id": "N1", "blocks": [{"id": 1, "op": "JMP"}]}]}"###,
        r###"{}"###,
        r###"network N1 block 1 at fbd.networks[0].blocks[0]: missing field `label` in a JMP"###,
    ),
    (
        r###"{"networks": [{"id": "N1", "blocks": [{"id": 1, "op": "ADD", "in": ["A", 1], "out": "B", "label": "L"}]}]}"###,
        r###"{}"###,
        r###"network N1 block 1 at fbd.networks[0].blocks[0].label: `label` is not allowed on a block other than JMP (label the network)"###,
    ),
    (
        r###"{"networks": [{"id": "N1", "blocks": [{"id": 1, "op": "JMP", "label": 5}]}]}"###,
        r###"{}"###,
        r###"network N1 block 1 at fbd.networks[0].blocks[0].label: expected a string, found number 5"###,
    ),
    (
        r###"{"networks": [{"id": "N1", "blocks": [{"id": 1, "op": "JMP", "label": "1x"}]}]}"###,
        r###"{}"###,
        r###"network N1 block 1 at fbd.networks[0].blocks[0].label: `1x` is not a valid name (letters, digits and _, not starting with a digit)"###,
    ),
    (
        r###"{"networks": [{"id": "N1", "blocks": [{"id": 1, "op": "JMP", "label": "L", "instance": "T1"}]}]}"###,
        r###"{}"###,
        r###"network N1 block 1 at fbd.networks[0].blocks[0].instance: `instance` is not allowed on this block (only timers, counters and function blocks have one)"###,
    ),
    (
        r###"{"networks": [{"id": "N1", "blocks": [{"id": 1, "op": "ADD", "in": ["A", 1], "out": "B", "cond": null}]}]}"###,
        r###"{}"###,
        r###"network N1 block 1 at fbd.networks[0].blocks[0].cond: expected an operand or an arc {"from": BLOCK}, found null"###,
    ),
    (
        r###"{"networks": [{"id": "N1", "blocks": [{"id": 1, "op": "ADD", "in": ["A", 1], "out": "B", "after": 5}]}]}"###,
        r###"{}"###,
        r###"network N1 block 1 at fbd.networks[0].blocks[0].after: expected an array of block ids, found number 5"###,
    ),
    (
        r###"{"networks": [{"id": "N1", "blocks": [{"id": 1, "op": "ADD", "in": ["A", 1], "out": "B", "after": ["x"]}]}]}"###,
        r###"{}"###,
        r###"network N1 block 1 at fbd.networks[0].blocks[0].after[0]: expected a block id, found string "x""###,
    ),
    (
        r###"{"networks": [{"id": "N1", "blocks": [{"id": 1, "op": "ADD", "in": ["A", 1], "out": "B", "after": [9]}]}]}"###,
        r###"{}"###,
        r###"network N1 block 1 at fbd.networks[0].blocks[0].after[0]: no block 9 in network N1"###,
    ),
    (
        r###"{"networks": [{"id": "N1", "blocks": [{"id": 1, "op": "ADD", "in": ["A", 1], "out": "B", "comment": 5}]}]}"###,
        r###"{}"###,
        r###"network N1 block 1 at fbd.networks[0].blocks[0].comment: expected a string, found number 5"###,
    ),
    (
        r###"{"networks": [{"id": "N1", "blocks": [{"id": 1, "op": "ADD", "in": [{"from": "x"}, 1], "out": "B"}]}]}"###,
        r###"{}"###,
        r###"network N1 block 1 at fbd.networks[0].blocks[0].in[0].from: expected a block id, found string "x""###,
    ),
    (
        r###"{"networks": [{"id": "N1", "blocks": [{"id": 1, "op": "ADD", "in": [{"x": 1}, 1], "out": "B"}]}]}"###,
        r###"{}"###,
        r###"network N1 block 1 at fbd.networks[0].blocks[0].in[0].x: unknown field `x` in an arc (allowed: from, pin)"###,
    ),
    (
        r###"{"networks": [{"id": "N1", "blocks": [{"id": 1, "op": "ADD", "in": [{}, 1], "out": "B"}]}]}"###,
        r###"{}"###,
        r###"network N1 block 1 at fbd.networks[0].blocks[0].in[0]: missing field `from` in an arc"###,
    ),
    (
        r###"{"networks": [{"id": "N1", "blocks": [{"id": 1, "op": "ADD", "in": ["A", 1], "out": "B"}, {"id": 2, "op": "ADD", "in": [{"from": 1, "pin": 5}, 1], "out": "A"}]}]}"###,
        r###"{}"###,
        r###"network N1 block 2 at fbd.networks[0].blocks[1].in[0].pin: expected a string, found number 5"###,
    ),
    (
        r###"{"networks": [{"id": "N1", "blocks": [{"id": 1, "op": "ADD", "in": ["A", 1], "out": "B"}, {"id": 2, "op": "ADD", "in": [{"from": 1, "pin": "Q"}, 1], "out": "A"}]}]}"###,
        r###"{}"###,
        r###"network N1 block 2 at fbd.networks[0].blocks[1].in[0].pin: block 1 (ADD) has no output `Q` (outputs: OUT)"###,
    ),
    (
        r###"{"networks": [{"id": "N1", "blocks": [{"id": 1, "op": "RET"}, {"id": 2, "op": "ADD", "in": [{"from": 1}, 1], "out": "A"}]}]}"###,
        r###"{}"###,
        r###"network N1 block 2 at fbd.networks[0].blocks[1].in[0].from: block 1 (RET) has no output `(any)` (outputs: none)"###,
    ),
    (
        r###"{"networks": [{"id": "N1", "blocks": [{"id": 1, "op": "TSTART", "in": [5]}]}]}"###,
        r###"{}"###,
        r###"network N1 block 1 at fbd.networks[0].blocks[0].in[0]: expected a TIME variable, found number 5"###,
    ),
    (
        r###"{"networks": [{"id": "N1", "blocks": [{"id": 1, "op": "TSTART", "in": [true]}]}]}"###,
        r###"{}"###,
        r###"network N1 block 1 at fbd.networks[0].blocks[0].in[0]: expected a TIME variable, found boolean true"###,
    ),
    (
        r###"{"networks": [{"id": "N1", "blocks": [{"id": 1, "op": "MOVE", "in": ["T#1s"]}, {"id": 2, "op": "TSTART", "in": [{"from": 1}]}]}]}"###,
        r###"{}"###,
        r###"network N1 block 2 at fbd.networks[0].blocks[1].in[0]: expected a TIME variable, found an arc"###,
    ),
    (
        r###"{"networks": [{"id": "N1", "blocks": [{"id": 2, "op": "ADD", "in": ["A", 1], "out": "B", "comment": 5}, {"id": 1, "op": "ADD", "in": [{"from": 9}, 1], "out": "B"}]}]}"###,
        r###"{}"###,
        r###"network N1 block 1 at fbd.networks[0].blocks[1].in[0].from: no block 9 in network N1"###,
    ),
    (
        r###"{"networks": [{"id": "N1", "blocks": [{"id": 1, "op": "ADD", "in": 5, "x": 1}]}]}"###,
        r###"{}"###,
        r###"network N1 block 1 at fbd.networks[0].blocks[0].x: unknown field `x` in a block (allowed: id, op, in, out, instance, cond, en, after, label, comment)"###,
    ),
    (
        r###"{"networks": [{"id": "N1", "blocks": [{"id": 1, "op": "ADD", "in": ["A", 1], "out": "B"}], "label": "1a", "comment": 5}]}"###,
        r###"{}"###,
        r###"network N1 at fbd.networks[0].label: `1a` is not a valid name (letters, digits and _, not starting with a digit)"###,
    ),
    (
        r###"{"networks": [{"id": "N1", "blocks": [{"id": 1, "op": "ADD", "in": [{"from": 9, "pin": 5}, 1], "out": "B"}]}]}"###,
        r###"{}"###,
        r###"network N1 block 1 at fbd.networks[0].blocks[0].in[0].from: no block 9 in network N1"###,
    ),
    (
        r###"{"networks": [{"id": "N1", "blocks": [{"id": 1, "op": "MOVE", "in": ["T#xx"], "out": "TV"}]}]}"###,
        r###"{}"###,
        r###"network N1 block 1 at fbd.networks[0].blocks[0].in[0]: `T#xx` is not a valid TIME literal (write e.g. "T#1s", "T#250ms")"###,
    ),
    (
        r###"{"networks": [{"id": "N1", "blocks": [{"id": 1, "op": "G", "instance": "g", "in": [1, 2]}]}]}"###,
        r###"{"vars": [{"name": "A", "type": "INT"}, {"name": "B", "type": "INT"}, {"name": "X", "type": "BOOL"}, {"name": "T1", "type": "TON"}, {"name": "TV", "type": "TIME"}, {"name": "C1", "type": "CTU"}, {"name": "g", "type": "G"}], "function_blocks": {"G": {"inputs": [{"name": "I", "type": "INT"}], "outputs": [{"name": "O", "type": "INT"}], "fbd": {"networks": [{"id": "N1", "blocks": [{"id": 1, "op": "MOVE", "in": ["I"], "out": "O"}]}]}}}}"###,
        r###"network N1 block 1 at fbd.networks[0].blocks[0].in: G takes at most 1 inputs (I), found 2"###,
    ),
    // A pin number far beyond the inputs given is a gap, found before any pin is made (it
    // once asked for a trillion-byte allocation).
    (
        r###"{"networks": [{"id": "N1", "blocks": [{"id": 1, "op": "ADD", "in": {"IN1": "A", "IN42949672961": 1}, "out": "B"}]}]}"###,
        r###"{}"###,
        r###"network N1 block 1 at fbd.networks[0].blocks[0].in: ADD needs its input `IN2` connected"###,
    ),
    (
        r###"{"networks": [{"id": "N1", "blocks": [{"id": 1, "op": "MUX", "in": {"K": "A", "IN0": 1, "IN99999999999": 2}, "out": "B"}]}]}"###,
        r###"{}"###,
        r###"network N1 block 1 at fbd.networks[0].blocks[0].in: MUX needs its input `IN1` connected"###,
    ),
    (
        r###"{"networks": [{"id": "N1", "blocks": [{"id": 1, "op": "ADD", "in": ["A", 1], "out": "B"}]}]}"###,
        r###"{"function_blocks": {"G": {"fbd": {"networks": 5}}}}"###,
        r###"at function_blocks.G.fbd.networks: expected an array, found number 5"###,
    ),
];

fn vars() -> Json {
    json!([{"name": "A", "type": "INT"}, {"name": "B", "type": "INT"}, {"name": "X", "type": "BOOL"},
           {"name": "T1", "type": "TON"}, {"name": "TV", "type": "TIME"}, {"name": "C1", "type": "CTU"}])
}

#[test]
fn every_malformed_part_is_one_located_error_with_its_exact_text() {
    let mut failures = Vec::new();
    for (fbd, extra, expected) in CASES {
        let mut doc = json!({"program": "p", "vars": vars()});
        doc["fbd"] = serde_json::from_str(fbd).expect("case JSON");
        let extra: Json = serde_json::from_str(extra).expect("case JSON");
        for (k, v) in extra.as_object().expect("an object") {
            doc[k] = v.clone();
        }
        match plc_deps::load::program_and_fbd_from_json(&doc.to_string()) {
            Ok(_) => failures.push(format!("{fbd}: loaded, expected `{expected}`")),
            Err(e) => {
                let got = e.to_string();
                if got != *expected {
                    failures.push(format!("{fbd}:\n  expected {expected}\n  got      {got}"));
                }
            }
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

#[test]
fn an_fbd_error_carries_the_line_and_column_of_the_field_it_names() {
    let text = "{\"program\": \"p\", \"vars\": [{\"name\": \"A\", \"type\": \"INT\"}],\n\"fbd\": {\"networks\": [{\"id\": \"N1\", \"blocks\": [\n  {\"id\": 1, \"op\": \"MOVE\", \"in\": [\"A\"], \"out\": \"A\"},\n  {\"id\": 2, \"op\": \"CONCATX\"}]}]}}";
    let e = plc_deps::load::program_from_json(text).expect_err("CONCATX is no op");
    let d = &e.diagnostics()[0];
    assert_eq!(d.location.position, Some((4, 13)));
    let text = text.replace("\"CONCATX\"", "\"MOVE\", \"in\": [{\"from\": 7}]");
    let e = plc_deps::load::program_from_json(&text).expect_err("no block 7");
    assert_eq!(e.diagnostics()[0].location.position, Some((4, 35)));
}

#[test]
fn a_repeated_key_keeps_its_last_value() {
    let text = r#"{"program": "p", "vars": [{"name": "A", "type": "INT"}, {"name": "B", "type": "INT"}],
        "fbd": {"networks": [{"id": "N1", "blocks": 5, "blocks": [
            {"id": 1, "op": "SUB", "in": {"IN2": "A", "IN1": "B", "IN2": 5}, "out": "B"}]}]}}"#;
    let (_, fbd) = plc_deps::load::program_and_fbd_from_json(text).expect("loads");
    let b = &fbd.pous[0].networks[0].blocks[0];
    let pins: Vec<(&str, Option<&plc_deps::fbd::Input>)> = b
        .inputs
        .iter()
        .map(|p| (p.name.as_str(), p.input.as_ref()))
        .collect();
    assert_eq!(
        pins,
        vec![
            ("IN1", Some(&plc_deps::fbd::Input::Variable("B".into()))),
            (
                "IN2",
                Some(&plc_deps::fbd::Input::Constant(
                    plc_deps::fbd::Constant::Number(5.into())
                ))
            )
        ]
    );
}
