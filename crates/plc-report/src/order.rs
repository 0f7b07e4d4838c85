//! `plc-deps order`: each FBD network's execution order and fragment tree, as text (aligned
//! tables), JSON (normative keys, docs/fbd.md) and DOT (networks and fragments as clusters).
//!
//! IN/OUT of blocks and networks come from `analysis::accesses` on the lowered program: the
//! rung a block became (per instance, for a function block type).

use plc_analysis::{accesses, Accesses};
use plc_fbd::*;
use plc_model::{Program, VarId};
use serde_json::{json, Value as Json};
use std::fmt::Write;

/// Text: per network, the orders, the fragment tree and the blocks with their IN/OUT.
pub fn render_order_text(p: &Program, fbd: &Fbd) -> String {
    let acc = accesses(p);
    let mut o = String::new();
    let _ = writeln!(o, "{}: FBD execution order (depth-first topological sort, ties by block id; conditional fragments as in the FBD text-generation paper)", p.name());
    if fbd.pous.is_empty() {
        let _ = writeln!(o, "\nno FBD bodies (the program is ladder only)");
        return o;
    }
    for pou in &fbd.pous {
        for (ni, (net, plan)) in pou.networks.iter().zip(&pou.plans).enumerate() {
            let _ = writeln!(o);
            let label = net
                .label
                .as_ref()
                .map(|l| format!(" (label {l})"))
                .unwrap_or_default();
            let (nb, nf) = (net.blocks.len(), plan.fragments.len());
            let _ = writeln!(
                o,
                "{} {}, network {}{label}: {nb} block{}, {nf} fragment{}",
                pou.kind.name(),
                pou.name,
                net.id,
                plural(nb),
                plural(nf)
            );
            let ids = |bs: &[BlockId]| {
                bs.iter()
                    .map(|b| net.block(*b).id.to_string())
                    .collect::<Vec<_>>()
                    .join(" ")
            };
            table(
                &mut o,
                &[],
                &[
                    vec!["topological order".into(), ids(&plan.topological)],
                    vec!["execution order".into(), ids(&plan.order)],
                ],
            );
            let _ = writeln!(o);
            let rows: Vec<Vec<String>> = plan
                .fragment_order()
                .into_iter()
                .map(|f| &plan.fragments[f.index()])
                .map(|f| {
                    let parent = f
                        .parent
                        .map_or("-".to_string(), |q| plan.fragments[q.index()].name.clone());
                    vec![
                        format!("{}{}", "  ".repeat(f.depth as usize), f.name),
                        parent,
                        f.condition.clone(),
                        ids(&f.blocks),
                    ]
                })
                .collect();
            table(
                &mut o,
                &["fragment", "parent", "condition", "blocks"],
                &rows,
            );
            if pou.copies.is_empty() {
                let _ = writeln!(
                    o,
                    "\n  (no instance: the function block is not part of the lowered program)"
                );
            }
            for copy in &pou.copies {
                let _ = writeln!(o);
                if pou.kind == FbdPouKind::FunctionBlock {
                    let _ = writeln!(o, "  instance {}", p.pou(copy.pou).name);
                }
                let rows: Vec<Vec<String>> = plan
                    .order
                    .iter()
                    .map(|&b| {
                        let blk = net.block(b);
                        let r = copy.blocks[ni][b.index()];
                        vec![
                            blk.id.to_string(),
                            op_text(blk),
                            plan.fragments[plan.fragment_of[b.index()].index()]
                                .name
                                .clone(),
                            p.rung(r).id.clone(),
                            names(p, acc.reads.list(r.index())),
                            names(p, acc.writes.list(r.index())),
                        ]
                    })
                    .collect();
                table(
                    &mut o,
                    &["block", "op", "fragment", "rung", "IN", "OUT"],
                    &rows,
                );
                let (ins, outs) = network_sets(&acc, copy.networks[ni].clone());
                let _ = writeln!(o, "  network IN: {}", names(p, &ins));
                let _ = writeln!(o, "  network OUT: {}", names(p, &outs));
            }
        }
    }
    o
}

/// JSON: `{"pous": [{"name", "kind", "networks": [{"id", "order", "topological", "fragments":
/// [{"id", "parent", "condition", "blocks"}], "in", "out"}]}]}`.
pub fn render_order_json(p: &Program, fbd: &Fbd) -> String {
    let acc = accesses(p);
    let pous: Vec<Json> = fbd
        .pous
        .iter()
        .map(|pou| {
            let networks: Vec<Json> = pou
                .networks
                .iter()
                .zip(&pou.plans)
                .enumerate()
                .map(|(ni, (net, plan))| {
                    let ids = |bs: &[BlockId]| {
                        bs.iter()
                            .map(|b| json!(net.block(*b).id))
                            .collect::<Vec<_>>()
                    };
                    let fragments: Vec<Json> = plan
                        .fragment_order()
                        .into_iter()
                        .map(|f| &plan.fragments[f.index()])
                        .map(|f| {
                            json!({
                                "id": f.name,
                                "parent": f.parent.map(|q| plan.fragments[q.index()].name.clone()),
                                "condition": f.condition,
                                "blocks": ids(&f.blocks),
                            })
                        })
                        .collect();
                    let (mut ins, mut outs) = (Vec::new(), Vec::new());
                    for copy in &pou.copies {
                        let (i, o) = network_sets(&acc, copy.networks[ni].clone());
                        ins.extend(i);
                        outs.extend(o);
                    }
                    ins.sort_unstable();
                    ins.dedup();
                    outs.sort_unstable();
                    outs.dedup();
                    json!({
                        "id": net.id,
                        "order": ids(&plan.order),
                        "topological": ids(&plan.topological),
                        "fragments": fragments,
                        "in": ins.iter().map(|v| p.var(*v).name.clone()).collect::<Vec<_>>(),
                        "out": outs.iter().map(|v| p.var(*v).name.clone()).collect::<Vec<_>>(),
                    })
                })
                .collect();
            json!({"name": pou.name, "kind": kind_key(pou.kind), "networks": networks})
        })
        .collect();
    let mut s =
        serde_json::to_string_pretty(&json!({ "pous": pous })).expect("JSON values serialise");
    s.push('\n');
    s
}

/// DOT: one cluster per network, nested clusters per fragment; data arcs solid (labelled with
/// their pins), conditional arcs dashed, control arcs dotted; each block shows its execution
/// position.
pub fn render_order_dot(p: &Program, fbd: &Fbd) -> String {
    let mut o = String::new();
    let _ = writeln!(
        o,
        "digraph {} {{",
        quote(&format!("{} FBD order", p.name()))
    );
    let _ = writeln!(o, "  rankdir=LR;");
    let _ = writeln!(o, "  node [shape=box, fontname=\"Helvetica\"];");
    let _ = writeln!(o, "  edge [fontname=\"Helvetica\", fontsize=10];");
    for (pi, pou) in fbd.pous.iter().enumerate() {
        for (ni, (net, plan)) in pou.networks.iter().zip(&pou.plans).enumerate() {
            let node = |b: BlockId| quote(&format!("p{pi}n{ni}b{}", net.block(b).id));
            let mut position = vec![0usize; net.blocks.len()];
            for (i, b) in plan.order.iter().enumerate() {
                position[b.index()] = i + 1;
            }
            let _ = writeln!(o, "  subgraph {} {{", quote(&format!("cluster_p{pi}n{ni}")));
            let _ = writeln!(
                o,
                "    label={};",
                quote(&format!(
                    "{} {}, network {}",
                    pou.kind.name(),
                    pou.name,
                    net.id
                ))
            );
            // Fragments as nested clusters, in tree order (children after their parent).
            let mut children: Vec<Vec<usize>> = vec![Vec::new(); plan.fragments.len()];
            for (f, frag) in plan.fragments.iter().enumerate().skip(1) {
                children[frag.parent.expect("non-root").index()].push(f);
            }
            let mut stack: Vec<(usize, usize)> = vec![(0, 0)];
            for &b in &plan.fragments[0].blocks {
                let _ = writeln!(
                    o,
                    "    {} [label={}];",
                    node(b),
                    quote(&block_label(net.block(b), position[b.index()]))
                );
            }
            while let Some(top) = stack.last_mut() {
                let (f, i) = *top;
                if let Some(&c) = children[f].get(i) {
                    top.1 += 1;
                    let frag = &plan.fragments[c];
                    let indent = "  ".repeat(stack.len() + 1);
                    let _ = writeln!(
                        o,
                        "{indent}subgraph {} {{",
                        quote(&format!("cluster_p{pi}n{ni}f{c}"))
                    );
                    let _ = writeln!(
                        o,
                        "{indent}  label={}; style=rounded;",
                        quote(&format!("{}: if {}", frag.name, frag.condition))
                    );
                    for &b in &frag.blocks {
                        let _ = writeln!(
                            o,
                            "{indent}  {} [label={}];",
                            node(b),
                            quote(&block_label(net.block(b), position[b.index()]))
                        );
                    }
                    stack.push((c, 0));
                } else {
                    stack.pop();
                    if f != 0 {
                        let _ = writeln!(o, "{}}}", "  ".repeat(stack.len() + 1));
                    }
                }
            }
            let _ = writeln!(o, "  }}");
            for (bi, blk) in net.blocks.iter_enumerated() {
                let to = node(bi);
                for pin in &blk.inputs {
                    if let Some(Input::Arc { from, pin: out }) = &pin.input {
                        let label = format!(
                            "{}→{}",
                            net.block(*from).outputs[*out as usize].name,
                            pin.name
                        );
                        let _ =
                            writeln!(o, "  {} -> {} [label={}];", node(*from), to, quote(&label));
                    }
                }
                if let Some(Input::Arc { from, .. }) = &blk.cond {
                    let _ = writeln!(
                        o,
                        "  {} -> {} [label=\"cond\", style=dashed];",
                        node(*from),
                        to
                    );
                }
                for a in &blk.after {
                    let _ = writeln!(
                        o,
                        "  {} -> {} [style=dotted, arrowhead=empty];",
                        node(*a),
                        to
                    );
                }
            }
        }
    }
    let _ = writeln!(o, "}}");
    o
}

fn plural(n: usize) -> &'static str {
    if n == 1 {
        ""
    } else {
        "s"
    }
}

fn kind_key(k: FbdPouKind) -> &'static str {
    match k {
        FbdPouKind::Main => "program",
        FbdPouKind::Subroutine => "subroutine",
        FbdPouKind::FunctionBlock => "function_block",
    }
}

fn block_label(b: &Block, position: usize) -> String {
    format!("{}  {}\n#{position}", b.id, op_text(b))
}

/// `ADD`, `TON T1`, `JMP L2`, `WriteValue WV1`, `TSTART TimeVar`.
fn op_text(b: &Block) -> String {
    let mut s = b.op.name().to_owned();
    if let Some(i) = b.op.instance() {
        let _ = write!(s, " {i}");
    }
    if let Op::Jmp { label } = &b.op {
        let _ = write!(s, " {label}");
    }
    if matches!(b.op, Op::TStart | Op::TStop) {
        if let Some(Input::Variable(v)) = b.inputs.first().and_then(|p| p.input.as_ref()) {
            let _ = write!(s, " {v}");
        }
    }
    s
}

/// IN and OUT of a network: the union over its rungs.
fn network_sets(acc: &Accesses, rungs: std::ops::Range<u32>) -> (Vec<VarId>, Vec<VarId>) {
    let (mut ins, mut outs) = (Vec::new(), Vec::new());
    for r in rungs {
        ins.extend_from_slice(acc.reads.list(r as usize));
        outs.extend_from_slice(acc.writes.list(r as usize));
    }
    ins.sort_unstable();
    ins.dedup();
    outs.sort_unstable();
    outs.dedup();
    (ins, outs)
}

fn names(p: &Program, vars: &[VarId]) -> String {
    if vars.is_empty() {
        "-".into()
    } else {
        vars.iter()
            .map(|v| p.var(*v).name.as_str())
            .collect::<Vec<_>>()
            .join(" ")
    }
}

/// An aligned table, indented by two spaces; no header row when `header` is empty.
fn table(o: &mut String, header: &[&str], rows: &[Vec<String>]) {
    let cols = rows
        .iter()
        .map(Vec::len)
        .chain(std::iter::once(header.len()))
        .max()
        .unwrap_or(0);
    let mut width = vec![0usize; cols];
    for (i, h) in header.iter().enumerate() {
        width[i] = width[i].max(h.chars().count());
    }
    for r in rows {
        for (i, c) in r.iter().enumerate() {
            width[i] = width[i].max(c.chars().count());
        }
    }
    let mut line = |cells: Vec<&str>| {
        let mut l = String::from(" ");
        for (i, c) in cells.iter().enumerate() {
            l.push(' ');
            l.push_str(c);
            if i + 1 < cells.len() {
                l.push_str(&" ".repeat(width[i] - c.chars().count() + 1));
            }
        }
        let _ = writeln!(o, "{}", l.trim_end());
    };
    if !header.is_empty() {
        line(header.to_vec());
    }
    for r in rows {
        line(r.iter().map(String::as_str).collect());
    }
}

fn quote(s: &str) -> String {
    format!(
        "\"{}\"",
        s.replace('\\', "\\\\")
            .replace('"', "\\\"")
            .replace('\n', "\\n")
    )
}
