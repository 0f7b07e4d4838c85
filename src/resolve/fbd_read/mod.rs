//! The FBD parts of the JSON program format → [`FbdPou`] (structure only).
//!
//! Checks every field, the op and its pins, block ids (unique in the POU), arcs (`{"from": ID}`
//! names a block of the same network and one of its outputs), control arcs and labels, then
//! plans every network ([`crate::fbd::plan`]: order, cycles, fragments). Operands stay JSON: they are
//! resolved and typed by the lowering, once per POU (per instance for a function block type).
//! Errors carry the network id, the block id and the JSON path.

mod block;
mod input;
mod util;

use crate::diag::{Invalid, LoadError};
use crate::fbd::model::*;
use serde_json::{Map, Value as Json};
use std::collections::HashMap;

use block::Net;
pub(crate) use util::kind_of;
#[allow(unused_imports)] // reachable at its old path, though only the reader uses it
pub(crate) use util::valid_name;
use util::{check_keys, name, string};

pub(super) type Result<T> = std::result::Result<T, LoadError>;

/// The pins of a user function block type (declared `inputs` and `outputs`, in order).
#[derive(Clone, Debug, Default)]
pub(crate) struct FbSig {
    pub inputs: Vec<String>,
    pub outputs: Vec<String>,
}

const NETWORK_KEYS: &[&str] = &["id", "label", "comment", "blocks"];
const BLOCK_KEYS: &[&str] = &[
    "id", "op", "in", "out", "instance", "cond", "after", "label", "comment",
];

/// Reads an `fbd` object (`{"networks": [...]}`) at `path` and plans its networks.
/// `sig` gives the pins of a user function block type by name.
pub(crate) fn read_body(
    v: &Json,
    path: &str,
    name: &str,
    kind: FbdPouKind,
    sig: &dyn Fn(&str) -> Option<FbSig>,
) -> Result<FbdPou> {
    let top = v.as_object().ok_or_else(|| {
        LoadError::invalid(
            None,
            path,
            Invalid::Shape {
                expected: "an object (an FBD body: {\"networks\": [...]})",
                found: kind_of(v),
            },
        )
    })?;
    if let Some(k) = top
        .keys()
        .find(|k| !["networks", "comment"].contains(&k.as_str()))
    {
        return Err(LoadError::invalid(
            None,
            &format!("{path}.{k}"),
            Invalid::UnknownField {
                field: k.clone(),
                what: "an FBD body",
                allowed: "networks, comment".into(),
            },
        ));
    }
    let np = format!("{path}.networks");
    let nets = top.get("networks").ok_or_else(|| {
        LoadError::invalid(
            None,
            path,
            Invalid::MissingField {
                field: "networks",
                what: "an FBD body",
            },
        )
    })?;
    let nets = nets.as_array().ok_or_else(|| {
        LoadError::invalid(
            None,
            &np,
            Invalid::Shape {
                expected: "an array",
                found: kind_of(nets),
            },
        )
    })?;
    if nets.is_empty() && kind == FbdPouKind::Main {
        return Err(LoadError::invalid(
            None,
            &np,
            Invalid::Shape {
                expected: "at least one network",
                found: "an empty array".into(),
            },
        ));
    }
    let mut networks = Vec::with_capacity(nets.len());
    let mut ids: HashMap<String, String> = HashMap::new();
    let mut labels: HashMap<String, String> = HashMap::new();
    let mut block_ids: HashMap<u32, String> = HashMap::new();
    for (i, n) in nets.iter().enumerate() {
        let p = format!("{np}[{i}]");
        let net = network(n, &p, sig, &mut block_ids)?;
        if let Some(first) = ids.insert(net.id.clone(), p.clone()) {
            return Err(LoadError::fbd(
                &net.id,
                None,
                &format!("{p}.id"),
                Invalid::DuplicateNetwork {
                    id: net.id.clone(),
                    first,
                },
            ));
        }
        if let Some(l) = &net.label {
            if let Some(first) = labels.insert(l.clone(), net.id.clone()) {
                return Err(LoadError::fbd(
                    &net.id,
                    None,
                    &format!("{p}.label"),
                    Invalid::DuplicateNetworkLabel {
                        label: l.clone(),
                        pou: name.to_owned(),
                        first,
                    },
                ));
            }
        }
        networks.push(net);
    }
    // Jump targets resolve within the POU.
    for net in &networks {
        for b in &net.blocks {
            if let Some(l) = &b.label {
                if !labels.contains_key(l) {
                    return Err(LoadError::fbd(
                        &net.id,
                        Some(b.id),
                        &format!("{}.label", b.path),
                        Invalid::UndefinedLabel {
                            label: l.clone(),
                            pou: name.to_owned(),
                        },
                    ));
                }
            }
        }
    }
    let plans = networks
        .iter()
        .map(crate::fbd::plan)
        .collect::<Result<Vec<_>>>()?;
    Ok(FbdPou {
        name: name.to_owned(),
        kind,
        path: path.to_owned(),
        networks,
        plans,
        copies: Vec::new(),
    })
}

/// A block as first read: its JSON and its op, before arcs are resolved.
pub(super) struct Draft<'v> {
    pub(super) id: u32,
    pub(super) op: Op,
    pub(super) o: &'v Map<String, Json>,
    pub(super) path: String,
}

fn network(
    v: &Json,
    path: &str,
    sig: &dyn Fn(&str) -> Option<FbSig>,
    block_ids: &mut HashMap<u32, String>,
) -> Result<Network> {
    let o = v.as_object().ok_or_else(|| {
        LoadError::invalid(
            None,
            path,
            Invalid::Shape {
                expected: "an object (a network)",
                found: kind_of(v),
            },
        )
    })?;
    let id = match o.get("id") {
        None => {
            return Err(LoadError::invalid(
                None,
                path,
                Invalid::MissingField {
                    field: "id",
                    what: "a network",
                },
            ))
        }
        Some(Json::String(s))
            if !s.is_empty() && !s.chars().any(|c| c.is_whitespace() || c == '"') =>
        {
            s.clone()
        }
        Some(Json::String(s)) => {
            return Err(LoadError::invalid(
                None,
                &format!("{path}.id"),
                Invalid::Shape {
                    expected: "a network id without spaces or quotes",
                    found: format!("\"{s}\""),
                },
            ))
        }
        Some(other) => {
            return Err(LoadError::invalid(
                None,
                &format!("{path}.id"),
                Invalid::Shape {
                    expected: "a string",
                    found: kind_of(other),
                },
            ))
        }
    };
    let e = |p: String, k: Invalid| LoadError::fbd(&id, None, &p, k);
    check_keys(o, NETWORK_KEYS, "a network", path).map_err(|(p, k)| e(p, k))?;
    let label = match o.get("label") {
        None => None,
        Some(l) => Some(
            name(l)
                .map_err(|k| e(format!("{path}.label"), k))?
                .to_owned(),
        ),
    };
    let comment = match o.get("comment") {
        None => None,
        Some(c) => Some(
            string(c)
                .map_err(|k| e(format!("{path}.comment"), k))?
                .to_owned(),
        ),
    };
    let bp = format!("{path}.blocks");
    let items = o.get("blocks").ok_or_else(|| {
        e(
            path.to_owned(),
            Invalid::MissingField {
                field: "blocks",
                what: "a network",
            },
        )
    })?;
    let items = items.as_array().ok_or_else(|| {
        e(
            bp.clone(),
            Invalid::Shape {
                expected: "an array",
                found: kind_of(items),
            },
        )
    })?;
    if items.is_empty() {
        return Err(e(
            bp,
            Invalid::Shape {
                expected: "at least one block",
                found: "an empty array".into(),
            },
        ));
    }
    // Pass 1: ids and ops.
    let mut drafts = Vec::with_capacity(items.len());
    for (i, item) in items.iter().enumerate() {
        let p = format!("{bp}[{i}]");
        let o = item.as_object().ok_or_else(|| {
            e(
                p.clone(),
                Invalid::Shape {
                    expected: "an object (a block)",
                    found: kind_of(item),
                },
            )
        })?;
        let bid = match o.get("id") {
            None => {
                return Err(e(
                    p,
                    Invalid::MissingField {
                        field: "id",
                        what: "a block",
                    },
                ))
            }
            Some(j) => j
                .as_u64()
                .filter(|&n| n <= u32::MAX as u64)
                .ok_or_else(|| {
                    e(
                        format!("{p}.id"),
                        Invalid::Shape {
                            expected: "a block id (a whole number, 0 or more)",
                            found: kind_of(j),
                        },
                    )
                })? as u32,
        };
        let be = |q: String, k: Invalid| LoadError::fbd(&id, Some(bid), &q, k);
        if let Some(first) = block_ids.insert(bid, p.clone()) {
            return Err(be(
                format!("{p}.id"),
                Invalid::DuplicateBlock { id: bid, first },
            ));
        }
        check_keys(o, BLOCK_KEYS, "a block", &p).map_err(|(q, k)| be(q, k))?;
        let opj = o.get("op").ok_or_else(|| {
            be(
                p.clone(),
                Invalid::MissingField {
                    field: "op",
                    what: "a block",
                },
            )
        })?;
        let opname = string(opj).map_err(|k| be(format!("{p}.op"), k))?;
        let op = match Op::parse(opname) {
            Some(op) => op,
            None if sig(opname).is_some() => Op::Call(opname.to_owned()),
            None => {
                return Err(be(
                    format!("{p}.op"),
                    Invalid::UnknownOp {
                        op: opname.to_owned(),
                    },
                ))
            }
        };
        drafts.push(Draft {
            id: bid,
            op,
            o,
            path: p,
        });
    }
    drafts.sort_by_key(|d| d.id);
    let index: HashMap<u32, BlockId> = drafts
        .iter()
        .enumerate()
        .map(|(i, d)| (d.id, BlockId(i as u32)))
        .collect();
    let outputs_of = |d: &Draft| -> Vec<String> {
        match &d.op {
            Op::Call(fb) => sig(fb).map(|s| s.outputs).unwrap_or_default(),
            op => op.output_pins().iter().map(|s| s.to_string()).collect(),
        }
    };
    let out_pins: Vec<Vec<String>> = drafts.iter().map(outputs_of).collect();
    // Pass 2: pins, arcs, the rest.
    let net = Net {
        id: &id,
        index: &index,
        drafts: &drafts,
        out_pins: &out_pins,
        sig,
    };
    let blocks = drafts
        .iter()
        .map(|d| net.block(d))
        .collect::<Result<Vec<_>>>()?;
    Ok(Network {
        id,
        label,
        comment,
        path: path.to_owned(),
        blocks,
    })
}
