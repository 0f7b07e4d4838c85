//! The analysis' graphs as [`petgraph`] graphs, for library users who want to run their own
//! algorithms on them (paths, cycles, orders, dominators, DOT): the data dependences, the
//! control-flow graph, the post-dominator tree, the control dependences (FOW, and the paper's
//! control view) and the combined schedule.
//!
//! Each function copies one result of an [`Analysis`] into a fresh [`DiGraph`]; nothing is
//! computed again, so a view holds exactly what the analysis holds (`plc-deps report` shows the
//! same). Node indices are the library's dense ids: node `i` of the rung graphs is the rung `p.rungs().id(i)`,
//! of the CFG graphs `CfgNode(i)` (START and STOP last, see [`Cfg`](super::Cfg)), of the
//! schedule `TaskId(i)`; [`rung_node`], [`cfg_node`] and [`task_node`] convert, and every node
//! weight is its id too. Edges are added in the analysis' order, so in [`cfg_graph`] edge
//! index `i` is [`CfgEdgeId`]`(i)`.
//!
//! Not here: the analyses themselves (they run on the crate's own compact graphs,
//! [`plc_graph`], which are faster at a million rungs), and any cost of building a view
//! when it is not asked for: [`super::analyse`] builds none.
//!
//! # Example
//!
//! ```
//! # // A user reaches the layers through the facade crate `plc_deps`; here, below it, the
//! # // same paths are made from the layers themselves.
//! # mod plc_deps {
//! #     pub(crate) use ::plc_analysis as analysis;
//! #     pub(crate) use ::plc_load as load;
//! #     pub(crate) use ::plc_model as model;
//! # }
//! use petgraph::algo::{has_path_connecting, toposort};
//! use plc_deps::analysis::{analyse, graphs, DepKind};
//!
//! // R2 and R3 both write X (output), R4 reads it (flow); R1 jumps over R2 when A is on.
//! let program = r#"{
//!   "program": "demo",
//!   "vars": [
//!     {"name": "A", "type": "BOOL", "class": "input"},
//!     {"name": "B", "type": "BOOL", "class": "input"},
//!     {"name": "X", "type": "BOOL"},
//!     {"name": "Y", "type": "BOOL", "class": "output"}
//!   ],
//!   "rungs": [
//!     {"id": "R1", "ld": [{"contact": "A"}, {"jmp": "L1"}]},
//!     {"id": "R2", "ld": [{"contact": "B"}, {"coil": "X"}]},
//!     {"id": "R3", "label": "L1", "ld": [{"contact": "A"}, {"coil": "X"}]},
//!     {"id": "R4", "ld": [{"contact": "X"}, {"coil": "Y"}]}
//!   ]
//! }"#;
//! let p = plc_deps::load::program_from_json(program).expect("a valid program");
//! let a = analyse(&p);
//!
//! // Data dependences: node i is rung i, each edge says its kind and variable.
//! let deps = graphs::dependence_graph(&p, &a);
//! let (r2, r4) = (graphs::rung_node(p.rungs().id(1)), graphs::rung_node(p.rungs().id(3)));
//! assert!(has_path_connecting(&deps, r2, r4, None));
//! let flows = deps.edge_weights().filter(|e| e.kind == DepKind::Flow).count();
//! assert_eq!(flows, 2); // R2 → R4 and R3 → R4, both through X
//! let order = toposort(&deps, None).expect("data dependences go forward");
//! let names: Vec<&str> = order.iter().map(|&n| p.rung(deps[n]).id.as_str()).collect();
//! let at = |name| names.iter().position(|&r| r == name).unwrap();
//! assert!(at("R2") < at("R3") && at("R3") < at("R4"));
//!
//! // The control dependences: R2 runs only if R1 does not jump.
//! let cdg = graphs::control_dependence_graph(&a);
//! let r1 = graphs::cfg_node(p.rungs().id(0).into());
//! let r2 = graphs::cfg_node(p.rungs().id(1).into());
//! assert!(cdg.contains_edge(r1, r2));
//!
//! // The post-dominator tree: R3 is where both ways from R1 meet again.
//! let pdom = graphs::post_dominator_tree(&a);
//! let r3 = graphs::cfg_node(p.rungs().id(2).into());
//! assert!(pdom.contains_edge(r3, r1));
//!
//! // The combined schedule: tasks with their levels, edges to the tasks that must wait.
//! let schedule = graphs::schedule_graph(&a);
//! let last = schedule.node_weights().map(|t| t.level).max();
//! assert_eq!(last, Some(3)); // R1; R2 (guarded by R1); R3 (writes X after R2); R4
//! ```

use super::schedule::TaskId;
use super::{Analysis, CfgEdge, CfgEdgeId, CfgNode, ControlCause, DepKind};
use petgraph::graph::{DiGraph, NodeIndex};
use plc_model::{Program, RungId, VarId};

/// What a data dependence edge says: its kind (flow, anti or output) and the variable.
#[derive(Copy, Clone, Debug, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub struct DataEdge {
    pub kind: DepKind,
    pub var: VarId,
}

/// A node of [`schedule_graph`]: a task of the combined schedule, its first rung (its name in
/// reports) and its level (0-based; tasks of one level may run at the same time).
#[derive(Copy, Clone, Debug, PartialEq, Eq, Hash)]
pub struct ScheduledTask {
    pub task: TaskId,
    pub head: RungId,
    pub level: u32,
}

/// The node of rung `r` in the rung graphs ([`dependence_graph`], [`paper_control_graph`]).
pub fn rung_node(r: RungId) -> NodeIndex {
    NodeIndex::new(r.index())
}

/// The node of CFG node `n` in the CFG graphs ([`cfg_graph`], [`post_dominator_tree`],
/// [`control_dependence_graph`]); a rung converts with `RungId::into`.
pub fn cfg_node(n: CfgNode) -> NodeIndex {
    NodeIndex::new(n.index())
}

/// The node of task `t` in [`schedule_graph`].
pub fn task_node(t: TaskId) -> NodeIndex {
    NodeIndex::new(t.index())
}

/// A graph with one node per rung, weighted by its id.
fn rung_graph<E>(p: &Program, edges: usize) -> DiGraph<RungId, E> {
    let mut g = DiGraph::with_capacity(p.rungs().len(), edges);
    for r in p.rung_ids() {
        g.add_node(r);
    }
    g
}

/// A graph with one node per CFG node (rungs, START, STOP), weighted by its id.
fn cfg_nodes<E>(a: &Analysis, edges: usize) -> DiGraph<CfgNode, E> {
    let n = a.cfg.node_count();
    let mut g = DiGraph::with_capacity(n, edges);
    for v in 0..n as u32 {
        g.add_node(CfgNode::new(v));
    }
    g
}

/// The data dependences between rungs: an edge `from → to` per flow, anti and output pair of
/// [`Analysis::data`], in its order (every pair of the paper's definition, or only the direct
/// ones when there were too many to list: see [`Analysis::listed`]; either way their ASAP
/// levels are [`Analysis::data_levels`]). Every edge goes forward in program order, so the
/// graph is acyclic.
pub fn dependence_graph(p: &Program, a: &Analysis) -> DiGraph<RungId, DataEdge> {
    let mut g = rung_graph(p, a.data.len());
    for d in &a.data {
        g.add_edge(
            NodeIndex::new(d.from as usize),
            NodeIndex::new(d.to as usize),
            DataEdge {
                kind: d.kind,
                var: d.var,
            },
        );
    }
    g
}

/// The control-flow graph: a node per rung, then START and STOP; edge `i` is
/// [`Analysis::cfg`]'s edge [`CfgEdgeId`]`(i)` (with its branch label and kind), the iteration
/// cap's `refused` edges included (the paper's CFG is without them:
/// [`Cfg::paper_edges`](super::Cfg::paper_edges)).
pub fn cfg_graph(a: &Analysis) -> DiGraph<CfgNode, CfgEdge> {
    let mut g = cfg_nodes(a, a.cfg.edges.len());
    for e in &a.cfg.edges {
        g.add_edge(cfg_node(e.from), cfg_node(e.to), *e);
    }
    g
}

/// The post-dominator tree of the paper's CFG: an edge `ipdom(n) → n` for every CFG node but
/// STOP, the root (so a node's one parent is its immediate post-dominator,
/// [`PostDominators::immediate`](super::PostDominators::immediate)).
pub fn post_dominator_tree(a: &Analysis) -> DiGraph<CfgNode, ()> {
    let n = a.cfg.node_count();
    let mut g = cfg_nodes(a, n.saturating_sub(1));
    for v in 0..n as u32 {
        if let Some(parent) = a.post_dominators.immediate(v) {
            g.add_edge(
                cfg_node(CfgNode::new(parent)),
                cfg_node(CfgNode::new(v)),
                (),
            );
        }
    }
    g
}

/// The control dependence graph (Ferrante, Ottenstein & Warren) over the whole CFG: an edge
/// `controller → dependent` per [`Analysis::control`] entry, weighted by the CFG edge that
/// causes it; a loop's rung may depend on itself (a self edge).
pub fn control_dependence_graph(a: &Analysis) -> DiGraph<CfgNode, CfgEdgeId> {
    let mut g = cfg_nodes(a, a.control.len());
    for d in &a.control {
        g.add_edge(
            cfg_node(CfgNode::new(d.controller)),
            cfg_node(CfgNode::new(d.dependent)),
            CfgEdgeId::new(d.edge),
        );
    }
    g
}

/// The paper's control view between rungs ([`Analysis::paper_control`]): the control
/// dependences between rungs and the reads of a timer's or counter's fields after its box, each
/// edge weighted by its cause. Its ASAP levels, with a strongly connected part on one level and
/// self edges ignored, are [`Analysis::control_levels`].
pub fn paper_control_graph(p: &Program, a: &Analysis) -> DiGraph<RungId, ControlCause> {
    let mut g = rung_graph(p, a.paper_control.len());
    for d in &a.paper_control {
        g.add_edge(rung_node(d.from), rung_node(d.to), d.cause);
    }
    g
}

/// The combined schedule: a node per task (in [`Schedule::tasks`](super::Schedule::tasks)
/// order, with its level) and an edge `earlier → task` for each task it must wait for
/// ([`Schedule::preds`](super::Schedule::preds): data and control together, so edges carry no
/// kind). Acyclic; each task's level is one more than its predecessors' highest (0 without
/// any), and [`Schedule::levels`](super::Schedule::levels) groups the nodes by it.
pub fn schedule_graph(a: &Analysis) -> DiGraph<ScheduledTask, ()> {
    let s = &a.schedule;
    let edges = s.preds.iter().map(Vec::len).sum();
    let mut g = DiGraph::with_capacity(s.tasks.len(), edges);
    for (i, t) in s.tasks.iter().enumerate() {
        g.add_node(ScheduledTask {
            task: TaskId::new(i as u32),
            head: t.rungs[0],
            level: t.level,
        });
    }
    for (i, preds) in s.preds.iter().enumerate() {
        for &q in preds {
            g.add_edge(task_node(q), task_node(TaskId::new(i as u32)), ());
        }
    }
    g
}
