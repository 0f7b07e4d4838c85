//! FBD bodies as written ([`plc_syntax::fbd`]) → [`FbdPou`] (structure only).
//!
//! Checks what needs more than one node: block ids (unique in the POU), ops (built-in or a user
//! function block type), pins against the op, arcs (`{"from": ID}` names a block of the same
//! network and one of its outputs), control arcs, labels (valid names, unique, defined), and
//! reports what the reader found malformed at the point where these rules reach it; then plans
//! every network ([`plc_fbd::plan`]: order, cycles, fragments). Operands stay names and
//! constants as written: they are resolved and typed by the lowering, once per POU (per instance
//! for a function block type). docs/fbd.md is the format.
//!
//! One error per body, the first in this order: the body, then each network in file order —
//! its id, fields and blocks' ids and ops (file order), then every block's pins and fields (in
//! block id order) — then labels, then plans. Errors carry the network id, the block id, the
//! JSON path and the origin of the innermost network or block; the JSON reader then moves it to
//! the field or pin the path names (`read::json::path_offset`).

mod block;
mod input;
mod util;

use plc_diag::{Invalid, LoadError};
use plc_fbd::model::*;
use plc_model::Numbering;
use plc_syntax::fbd as syn;
use plc_syntax::Problem;
use std::collections::HashMap;

use block::Net;
pub(crate) use util::valid_name;

pub(super) type Result<T> = std::result::Result<T, LoadError>;

/// The pins of a user function block type (declared `inputs` and `outputs`, in order).
#[derive(Clone, Debug, Default)]
pub(crate) struct FbSig {
    pub inputs: Vec<String>,
    pub outputs: Vec<String>,
}

/// What every network of a body is read against.
pub(crate) struct Context<'c> {
    /// The pins of a user function block type by name.
    pub sig: &'c dyn Fn(&str) -> Option<FbSig>,
}

/// A problem the reader recorded, as an error at `path` (the path of the node that holds it).
pub(super) fn reported(
    p: &Problem,
    path: &str,
    place: impl FnOnce(&str, Invalid) -> LoadError,
) -> LoadError {
    place(&format!("{path}{}", p.at), p.kind.clone())
}

/// Reads the FBD body `body` at `path` of POU `name` and plans its networks.
pub(crate) fn read_body(
    body: &syn::FbdBody,
    path: &str,
    name: &str,
    kind: FbdPouKind,
    cx: &Context,
) -> Result<FbdPou> {
    let plain = |p: &str, k| LoadError::invalid(None, p, k);
    if let Some(p) = &body.problem {
        return Err(reported(p, path, plain));
    }
    let np = format!("{path}.networks");
    if body.networks.is_empty() && kind == FbdPouKind::Main {
        return Err(plain(
            &np,
            Invalid::Shape {
                expected: "at least one network",
                found: "an empty array".into(),
            },
        ));
    }
    let mut networks = Vec::with_capacity(body.networks.len());
    let mut ids: HashMap<String, String> = HashMap::new();
    let mut labels: HashMap<String, String> = HashMap::new();
    let mut block_ids: HashMap<u32, String> = HashMap::new();
    for (i, n) in body.networks.iter().enumerate() {
        let p = format!("{np}[{i}]");
        let net = network(n, &p, cx, &mut block_ids).map_err(|e| e.at(n.origin))?;
        let e = |q: String, k| LoadError::fbd(&net.id, None, &q, k).at(n.origin);
        if let Some(first) = ids.insert(net.id.clone(), p.clone()) {
            let id = net.id.clone();
            return Err(e(
                format!("{p}.id"),
                Invalid::DuplicateNetwork { id, first },
            ));
        }
        if let Some(l) = &net.label {
            if let Some(first) = labels.insert(l.clone(), net.id.clone()) {
                let (label, pou) = (l.clone(), name.to_owned());
                let kind = Invalid::DuplicateNetworkLabel { label, pou, first };
                return Err(e(format!("{p}.label"), kind));
            }
        }
        networks.push(net);
    }
    // Jump targets resolve within the POU.
    for net in &networks {
        for b in &net.blocks {
            if let Op::Jmp { label } = &b.op {
                if !labels.contains_key(label) {
                    return Err(LoadError::fbd(
                        &net.id,
                        Some(b.id),
                        &format!("{}.label", b.path),
                        Invalid::UndefinedLabel {
                            label: label.clone(),
                            pou: name.to_owned(),
                        },
                    ));
                }
            }
        }
    }
    let plans = networks
        .iter()
        .map(plc_fbd::plan)
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

/// A block as first read: its id and the kind of its op, before its pins and arcs are resolved.
pub(super) struct Draft<'s, 'a> {
    pub(super) id: u32,
    pub(super) kind: OpKind,
    /// The op's name: a built-in op's, or the user function block type's.
    pub(super) op: &'s str,
    pub(super) syn: &'s syn::Block<'a>,
    pub(super) path: String,
}

fn network(
    n: &syn::Network,
    path: &str,
    cx: &Context,
    block_ids: &mut HashMap<u32, String>,
) -> Result<Network> {
    let id = match &n.id {
        Ok(id) => id.to_string(),
        Err(p) => return Err(reported(p, path, |q, k| LoadError::invalid(None, q, k))),
    };
    if let Some(kind) = Invalid::control_char("network id", &id) {
        return Err(LoadError::invalid(None, &format!("{path}.id"), kind).at(n.origin));
    }
    let e = |q: &str, k| LoadError::fbd(&id, None, q, k);
    if let Some(p) = &n.problem {
        return Err(reported(p, path, e));
    }
    let label = match &n.label {
        None => None,
        Some(Err(p)) => return Err(reported(p, path, e)),
        Some(Ok(l)) if !valid_name(l) => {
            let kind = Invalid::BadName {
                name: l.to_string(),
            };
            return Err(e(&format!("{path}.label"), kind));
        }
        Some(Ok(l)) => Some(l.to_string()),
    };
    let comment = match &n.comment {
        None => None,
        Some(Err(p)) => return Err(reported(p, path, e)),
        Some(Ok(c)) => Some(c.to_string()),
    };
    let items = n.blocks.as_ref().map_err(|p| reported(p, path, e))?;
    // Pass 1: ids and ops.
    let mut drafts = Vec::with_capacity(items.len());
    for (i, b) in items.iter().enumerate() {
        let p = format!("{path}.blocks[{i}]");
        let d = draft(b, p, &id, cx, block_ids).map_err(|e| e.at(b.origin))?;
        drafts.push(d);
    }
    drafts.sort_by_key(|d| d.id);
    // The blocks are numbered in block id order; `blocks` below is built in the same order.
    let mut numbering: Numbering<BlockId> = Numbering::new();
    let block_ids: Vec<BlockId> = drafts.iter().map(|_| numbering.next_id()).collect();
    let index: HashMap<u32, BlockId> = drafts
        .iter()
        .zip(&block_ids)
        .map(|(d, &b)| (d.id, b))
        .collect();
    let out_pins: Vec<Vec<String>> = drafts
        .iter()
        .map(|d| match d.kind {
            OpKind::Call => (cx.sig)(d.op).map(|s| s.outputs).unwrap_or_default(),
            k => k.output_pins().iter().map(|s| s.to_string()).collect(),
        })
        .collect();
    // Pass 2: pins, arcs, the rest (in block id order).
    let net = Net {
        id: &id,
        index: &index,
        drafts: &drafts,
        out_pins: &out_pins,
        sig: cx.sig,
    };
    let blocks = drafts
        .iter()
        .zip(&block_ids)
        .map(|(d, &b)| net.block(b, d).map_err(|e| e.at(d.syn.origin)))
        .collect::<Result<Vec<_>>>()?;
    let mut roots = Vec::new();
    if let Some(order) = &n.order {
        let ids = order.as_ref().map_err(|p| reported(p, path, e))?;
        for (k, r) in ids.iter().enumerate() {
            let q = format!("{path}.order[{k}]");
            let id = *r.as_ref().map_err(|p| reported(p, &q, e))?;
            let b = index.get(&id).copied().ok_or_else(|| {
                e(
                    &q,
                    Invalid::Misplaced {
                        what: "a block id in `order`",
                        place: "that no block of the network has",
                    },
                )
            })?;
            if !roots.contains(&b) {
                roots.push(b);
            }
        }
    }
    Ok(Network {
        id,
        label,
        comment,
        path: path.to_owned(),
        origin: n.origin,
        blocks: blocks.into(),
        roots,
    })
}

/// Pass 1 of one block: its id (unique in the POU) and its op.
fn draft<'s, 'a>(
    b: &'s syn::Block<'a>,
    path: String,
    network: &str,
    cx: &Context,
    block_ids: &mut HashMap<u32, String>,
) -> Result<Draft<'s, 'a>> {
    let id = match &b.id {
        Ok(id) => *id,
        Err(p) => {
            return Err(reported(p, &path, |q, k| {
                LoadError::fbd(network, None, q, k)
            }))
        }
    };
    let be = |q: &str, k| LoadError::fbd(network, Some(id), q, k);
    if let Some(first) = block_ids.insert(id, path.clone()) {
        return Err(be(
            &format!("{path}.id"),
            Invalid::DuplicateBlock { id, first },
        ));
    }
    if let Some(p) = &b.problem {
        return Err(reported(p, &path, be));
    }
    let op: &str = b.op.as_ref().map_err(|p| reported(p, &path, be))?;
    let kind = match OpKind::parse(op) {
        Some(k) => k,
        None if (cx.sig)(op).is_some() => OpKind::Call,
        None => {
            let kind = Invalid::UnknownOp { op: op.to_owned() };
            return Err(be(&format!("{path}.op"), kind));
        }
    };
    Ok(Draft {
        id,
        kind,
        op,
        syn: b,
        path,
    })
}
