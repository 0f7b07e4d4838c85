//! The petgraph views of `plc_deps::analysis::graphs` hold exactly what the analysis holds, on
//! every worked example of `analyses/`: the same nodes, one edge per dependence (each one of the
//! analysis'), the post-dominator tree's parents are the analysis' ipdoms (and petgraph's own
//! dominator algorithm on the reversed CFG agrees), and ASAP levels computed with petgraph's
//! topological sort are the analysis' levels. Also: docs/library.md shows the module's
//! documentation test, line for line.

use petgraph::algo::{condensation, dominators, is_cyclic_directed, toposort};
use petgraph::graph::{DiGraph, NodeIndex};
use petgraph::visit::{EdgeRef, Reversed};
use petgraph::Direction;
use plc_deps::analysis::graphs::{self, DataEdge, ScheduledTask};
use plc_deps::analysis::schedule::TaskId;
use plc_deps::analysis::{
    analyse, Analysis, CfgEdgeId, CfgNode, DataDependence, DepKind, EdgeKind, Listed,
};
use plc_deps::model::{Program, RungId};
use std::collections::BTreeSet;
use std::path::{Path, PathBuf};

/// The repository root: the outermost folder with a `Cargo.toml` above this package, inside the
/// git checkout.
fn repo_root() -> PathBuf {
    let here = PathBuf::from(env!("CARGO_MANIFEST_DIR"));
    let mut root = here.clone();
    for dir in here.ancestors() {
        if dir.join("Cargo.toml").is_file() {
            root = dir.to_path_buf();
        }
        if dir.join(".git").exists() {
            break;
        }
    }
    root
}

/// A program whose jump back can never reach the end of the scan in the paper's CFG (only the
/// iteration cap lets the scan go on): the post-dominators get a virtual exit.
const ENDLESS: &str = r#"{
  "program": "endless",
  "vars": [
    {"name": "A", "type": "BOOL", "class": "input"},
    {"name": "X", "type": "BOOL"},
    {"name": "Y", "type": "BOOL", "class": "output"}
  ],
  "rungs": [
    {"id": "R1", "ld": [{"contact": "A"}, {"coil": "X"}]},
    {"id": "R2", "label": "L", "ld": [{"contact": "X"}, {"coil": "Y"}]},
    {"id": "R3", "ld": [{"jmp": "L"}]}
  ]
}"#;

/// Every worked example (its folder's name, the program and its analysis), and [`ENDLESS`].
fn examples() -> Vec<(String, Program, Analysis)> {
    let dir = repo_root().join("analyses");
    let mut dirs: Vec<PathBuf> = std::fs::read_dir(&dir)
        .expect("analyses/ exists")
        .map(|e| e.expect("readable entry").path())
        .filter(|p| p.join("program.json").is_file())
        .collect();
    dirs.sort();
    assert!(dirs.len() >= 5, "expected the worked examples in analyses/");
    dirs.iter()
        .map(|d| {
            let text = std::fs::read_to_string(d.join("program.json")).unwrap();
            let p = plc_deps::load::program_from_json(&text)
                .unwrap_or_else(|e| panic!("{}: {e}", d.display()));
            let a = analyse(&p);
            (d.file_name().unwrap().to_string_lossy().into_owned(), p, a)
        })
        .chain(std::iter::once_with(|| {
            let p = plc_deps::load::program_from_json(ENDLESS).unwrap();
            let a = analyse(&p);
            ("endless".to_string(), p, a)
        }))
        .collect()
}

/// ASAP levels of an acyclic graph by petgraph's topological sort: 0 without predecessors,
/// else one more than the highest predecessor.
fn asap<N, E>(g: &DiGraph<N, E>) -> Vec<u32> {
    let order = toposort(g, None).unwrap_or_else(|_| panic!("the graph is acyclic"));
    let mut level = vec![0u32; g.node_count()];
    for n in order {
        for m in g.neighbors_directed(n, Direction::Outgoing) {
            level[m.index()] = level[m.index()].max(level[n.index()] + 1);
        }
    }
    level
}

#[test]
fn dependence_graph_is_the_analysis_data_dependences() {
    for (name, p, a) in examples() {
        let g = graphs::dependence_graph(&p, &a);
        assert_eq!(g.node_count(), p.rungs().len(), "{name}");
        for r in 0..p.rungs().len() as u32 {
            assert_eq!(
                g[graphs::rung_node(RungId::from_raw(r))],
                RungId::from_raw(r),
                "{name}"
            );
        }
        assert_eq!(
            a.listed,
            Listed::All,
            "{name}: a worked example lists every pair"
        );
        assert_eq!(g.edge_count() as u64, a.counts.total(), "{name}");
        assert_eq!(g.edge_count(), a.data.len(), "{name}");
        let kind = |k| g.edge_weights().filter(|e| e.kind == k).count() as u64;
        assert_eq!(
            (
                kind(DepKind::Flow),
                kind(DepKind::Anti),
                kind(DepKind::Output)
            ),
            (a.counts.flow, a.counts.anti, a.counts.output),
            "{name}"
        );
        let listed: BTreeSet<DataDependence> = a.data.iter().copied().collect();
        let edges: BTreeSet<DataDependence> = g
            .edge_references()
            .map(|e| {
                let DataEdge { kind, var } = *e.weight();
                DataDependence {
                    from: e.source().index() as u32,
                    to: e.target().index() as u32,
                    kind,
                    var,
                }
            })
            .collect();
        assert_eq!(edges, listed, "{name}");
        assert_eq!(asap(&g), a.data_levels, "{name}: data levels");
    }
}

#[test]
fn cfg_graph_is_the_analysis_cfg_edge_for_edge() {
    for (name, _, a) in examples() {
        let g = graphs::cfg_graph(&a);
        assert_eq!(g.node_count(), a.cfg.node_count(), "{name}");
        assert_eq!(g[graphs::cfg_node(a.cfg.stop())], a.cfg.stop(), "{name}");
        assert_eq!(g.edge_count(), a.cfg.edges.len(), "{name}");
        for e in g.edge_references() {
            let cfg_edge = a.cfg.edge(CfgEdgeId::from_raw(e.id().index() as u32));
            assert_eq!(e.weight(), cfg_edge, "{name}");
            assert_eq!(
                (e.source(), e.target()),
                (
                    graphs::cfg_node(cfg_edge.from),
                    graphs::cfg_node(cfg_edge.to)
                ),
                "{name}"
            );
        }
    }
}

#[test]
fn post_dominator_tree_parents_are_the_ipdoms_and_petgraph_agrees() {
    let mut virtual_edges = 0;
    for (name, _, a) in examples() {
        let tree = graphs::post_dominator_tree(&a);
        let n = a.cfg.node_count();
        let stop = a.cfg.stop();
        assert_eq!(tree.node_count(), n, "{name}");
        assert_eq!(
            tree.edge_count(),
            n - 1,
            "{name}: a tree over every CFG node"
        );
        assert!(!is_cyclic_directed(&tree), "{name}");
        // petgraph's dominators of the reversed paper CFG (with the analysis' virtual exits
        // from endless loops), rooted at STOP.
        let mut paper = graphs::cfg_graph(&a).filter_map(
            |_, &v| Some(v),
            |_, e| (e.kind != EdgeKind::Refused).then_some(()),
        );
        for &(from, to) in &a.post_dominators.virtual_edges {
            paper.add_edge(
                NodeIndex::new(from as usize),
                NodeIndex::new(to as usize),
                (),
            );
            virtual_edges += 1;
        }
        let theirs = dominators::simple_fast(Reversed(&paper), graphs::cfg_node(stop));
        for v in 0..n as u32 {
            let node = graphs::cfg_node(CfgNode::from_raw(v));
            let parents: Vec<u32> = tree
                .neighbors_directed(node, Direction::Incoming)
                .map(|p| tree[p].raw())
                .collect();
            let ipdom = a.post_dominators.immediate(v);
            assert_eq!(
                parents,
                ipdom.into_iter().collect::<Vec<_>>(),
                "{name}: {v}"
            );
            assert_eq!(
                theirs.immediate_dominator(node).map(|d| d.index() as u32),
                ipdom,
                "{name}: node {v}"
            );
        }
        assert_eq!(a.post_dominators.immediate(stop.raw()), None, "{name}");
    }
    // With the endless loop, the virtual exits were checked too.
    assert_eq!(virtual_edges, 1);
}

#[test]
fn control_dependence_graphs_are_the_analysis_control_dependences() {
    let mut instance_reads = 0;
    for (name, p, a) in examples() {
        let cdg = graphs::control_dependence_graph(&a);
        assert_eq!(cdg.node_count(), a.cfg.node_count(), "{name}");
        assert_eq!(cdg.edge_count(), a.control.len(), "{name}");
        let mut listed: Vec<(u32, u32, u32)> = a
            .control
            .iter()
            .map(|d| (d.controller, d.dependent, d.edge))
            .collect();
        let mut edges: Vec<(u32, u32, u32)> = cdg
            .edge_references()
            .map(|e| {
                (
                    cdg[e.source()].raw(),
                    cdg[e.target()].raw(),
                    e.weight().raw(),
                )
            })
            .collect();
        listed.sort_unstable();
        edges.sort_unstable();
        assert_eq!(edges, listed, "{name}");

        let view = graphs::paper_control_graph(&p, &a);
        assert_eq!(view.node_count(), p.rungs().len(), "{name}");
        assert_eq!(view.edge_count(), a.paper_control.len(), "{name}");
        for (e, d) in view.edge_references().zip(&a.paper_control) {
            assert_eq!(
                (view[e.source()], view[e.target()], *e.weight()),
                (d.from, d.to, d.cause),
                "{name}"
            );
            instance_reads += usize::from(matches!(
                d.cause,
                plc_deps::analysis::ControlCause::Instance { .. }
            ));
        }
        // Levels: each strongly connected part on one level, self edges ignored.
        let no_self = view.filter_map(
            |_, &r| Some(r),
            |i, &c| {
                let (s, t) = view.edge_endpoints(i).unwrap();
                (s != t).then_some(c)
            },
        );
        let parts = condensation(no_self, true);
        let part_levels = asap(&parts);
        let mut levels = vec![0u32; p.rungs().len()];
        for part in parts.node_indices() {
            for r in &parts[part] {
                levels[r.index()] = part_levels[part.index()];
            }
        }
        assert_eq!(levels, a.control_levels, "{name}: control levels");
    }
    assert!(instance_reads > 0, "an example reads a timer's fields");
}

#[test]
fn schedule_graph_is_the_combined_schedule_with_its_levels() {
    for (name, _, a) in examples() {
        let s = &a.schedule;
        let g = graphs::schedule_graph(&a);
        assert_eq!(g.node_count(), s.tasks.len(), "{name}");
        for (i, t) in s.tasks.iter().enumerate() {
            let id = TaskId::from_raw(i as u32);
            assert_eq!(
                g[graphs::task_node(id)],
                ScheduledTask {
                    task: id,
                    head: s.head(id),
                    level: t.level
                },
                "{name}"
            );
        }
        let preds: usize = s.preds.iter().map(Vec::len).sum();
        assert_eq!(g.edge_count(), preds, "{name}");
        for e in g.edge_references() {
            let (from, to) = (g[e.source()].task, g[e.target()].task);
            assert!(
                s.preds[to.index()].contains(&from),
                "{name}: {from:?} → {to:?}"
            );
        }
        let levels: Vec<u32> = g.node_weights().map(|t| t.level).collect();
        assert_eq!(asap(&g), levels, "{name}: ASAP levels are the schedule's");
        let mut by_level: Vec<Vec<TaskId>> = Vec::new();
        for t in g.node_weights() {
            if by_level.len() <= t.level as usize {
                by_level.resize(t.level as usize + 1, Vec::new());
            }
            by_level[t.level as usize].push(t.task);
        }
        assert_eq!(by_level, s.levels, "{name}");
    }
}

/// The visible lines of the first documentation test of a Rust file's `//!` comment (hidden
/// `# ` lines left out).
fn doctest_lines(rust: &str) -> Vec<String> {
    let mut out = Vec::new();
    let mut inside = false;
    for line in rust.lines().filter_map(|l| l.strip_prefix("//!")) {
        let line = line.strip_prefix(' ').unwrap_or(line);
        if line.starts_with("```") {
            if inside {
                return out;
            }
            inside = true;
        } else if inside && !line.starts_with("# ") {
            out.push(line.to_string());
        }
    }
    panic!("no documentation test");
}

/// The lines of the first ```` ```rust ```` block of a Markdown text.
fn rust_block_lines(markdown: &str) -> Vec<String> {
    markdown
        .lines()
        .skip_while(|l| l.trim() != "```rust")
        .skip(1)
        .take_while(|l| l.trim() != "```")
        .map(String::from)
        .collect()
}

/// The source file of `plc_deps::analysis::graphs`, wherever the crate's sources live (`src/`,
/// or a crate of the workspace).
fn graphs_source(root: &Path) -> PathBuf {
    let mut todo = vec![root.to_path_buf()];
    while let Some(dir) = todo.pop() {
        for e in std::fs::read_dir(&dir).unwrap().flatten() {
            let path = e.path();
            let name = e.file_name().to_string_lossy().into_owned();
            if e.file_type().unwrap().is_dir() {
                if !name.starts_with('.') && name != "target" {
                    todo.push(path);
                }
            } else if name == "graphs.rs"
                && path
                    .parent()
                    .is_some_and(|d| d.ends_with("analysis") || d.ends_with("src"))
                && std::fs::read_to_string(&path)
                    .unwrap()
                    .contains("pub fn dependence_graph(")
            {
                return path;
            }
        }
    }
    panic!(
        "no graphs.rs with dependence_graph under {}",
        root.display()
    );
}

#[test]
fn library_doc_shows_the_documentation_test() {
    let root = repo_root();
    let source = std::fs::read_to_string(graphs_source(&root)).unwrap();
    let doc = std::fs::read_to_string(root.join("docs/library.md")).unwrap();
    let (tested, shown) = (doctest_lines(&source), rust_block_lines(&doc));
    assert!(tested.len() > 20);
    assert_eq!(
        shown, tested,
        "docs/library.md's example is the doctest of graphs.rs"
    );
}
