//! The report document: everything `plc-deps report` says about a program, built once from the
//! model and its [`Analysis`], rendered by every output format.
//!
//! The structs here are the JSON report: their `#[derive(Serialize)]` field names are its keys,
//! which are normative (docs/report.md, docs/report.schema.json; add fields, never rename or drop
//! one). `super::json` serialises the [`Report`] and nothing else: a field added here is in the
//! JSON, and must be added to the schema (tests/it/report_schema.rs checks). Sections whose
//! size grows with the program (rungs, dependences, CFG edges, post-dominators, tasks,
//! differences) are [`Lazy`] lists: each entry is made when a renderer asks for it, so a
//! million-rung report costs no second copy of the analysis, and a renderer that shows only the
//! first rows (the text report) only makes those. Everything small is built eagerly.
//!
//! Fields marked `#[serde(skip)]` are for the human renderers (text, DOT) and are not part of
//! the JSON contract. Nothing here writes output: renderers do (`text`, `json`, `dot`).

pub use super::explain::DifferenceEntry;
use super::explain::Explainer;
use super::{FbdParts, RungPart};
use plc_analysis::{Analysis, Branch, CfgEdgeId, ControlCause, Listed, Successor};
use plc_model::*;
use serde::ser::{Serialize, SerializeMap, Serializer};

/// A list whose entries are made on demand from the analysis, serialised as a JSON array.
pub struct Lazy<'a, T> {
    len: usize,
    make: Box<dyn Fn() -> Box<dyn Iterator<Item = T> + 'a> + 'a>,
}

impl<'a, T: 'a> Lazy<'a, T> {
    fn new<I: Iterator<Item = T> + 'a>(len: usize, make: impl Fn() -> I + 'a) -> Self {
        Lazy {
            len,
            make: Box::new(move || Box::new(make())),
        }
    }
    /// Number of entries.
    pub fn len(&self) -> usize {
        self.len
    }
    /// True if there are no entries.
    pub fn is_empty(&self) -> bool {
        self.len == 0
    }
    /// The entries, in order.
    pub fn iter(&self) -> Box<dyn Iterator<Item = T> + 'a> {
        (self.make)()
    }
}

impl<'a, T: Serialize + 'a> Serialize for Lazy<'a, T> {
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        s.collect_seq(self.iter())
    }
}

/// The whole report.
#[derive(serde::Serialize)]
pub struct Report<'a> {
    pub program: &'a str,
    pub rungs: Lazy<'a, RungEntry<'a>>,
    /// Data dependences (every pair, or the direct ones: see `dependences_listed`), then the
    /// paper's control dependences, one per (from, to) pair.
    pub dependences: Lazy<'a, DependenceEntry<'a>>,
    /// `"all"` or `"direct"`: which data pairs `dependences` lists.
    pub dependences_listed: &'static str,
    /// Pair counts of the every-pair definition, whichever pairs are listed.
    pub dependence_counts: DependenceCounts<'a>,
    pub self_control: Vec<&'a str>,
    pub cfg: CfgSection<'a>,
    pub ipdom: Ipdom<'a>,
    pub levels: Levels<'a>,
    pub cycles: Cycles,
    pub cost: Cost,
    pub schedule: ScheduleSection<'a>,
    /// The loops of the combined schedule, each named once by its first rung.
    pub loops: Vec<LoopEntry<'a>>,
    pub differences: Lazy<'a, DifferenceEntry>,
    pub warnings: Vec<String>,
    /// The code of each warning, in the same order (docs/diagnostics.md).
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub warning_codes: Vec<&'static str>,
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub networks: Vec<NetworkEntry<'a>>,
    /// For programs with interrupt routines: what each shares with the main program.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub interrupts: Vec<InterruptEntry<'a>>,
    /// For PLCopen projects with a configuration: its resources, their tasks and the program
    /// instances each runs.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub configuration: Option<super::configuration::ConfigurationEntry<'a>>,
    /// For PLCopen projects with a configuration: the program instances analysed, in run order.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub programs: Vec<super::configuration::ProgramRunEntry<'a>>,
    /// For PLCopen projects with a configuration: the globals that programs of different tasks
    /// share, where one writes.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub task_sharing: Option<Vec<super::configuration::TaskSharedEntry<'a>>>,
    /// For programs with FBD bodies: the program as written, in blocks and networks.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub fbd: Option<FbdSection<'a>>,
    /// The POUs whose bodies were not read as logic (PLCopen ST, IL, SFC): the analyses see
    /// their stand-in rungs, and no command executes them ([`Pou::skipped`]).
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub skipped_pous: Vec<SkippedPouEntry<'a>>,
    /// The levels without the lowering's empty landing rungs (what the text report shows).
    #[serde(skip)]
    pub shown_levels: Option<Levels<'a>>,
    /// For the human renderers.
    #[serde(skip)]
    pub summary: Summary,
    #[serde(skip)]
    pub post_dominator_tree: Lazy<'a, TreeNode<'a>>,
    #[serde(skip)]
    pub control_count: usize,
    /// The tasks level by level (sequential order inside a level), as the text report lists
    /// them.
    #[serde(skip)]
    pub tasks_by_level: Lazy<'a, TaskEntry<'a>>,
}

/// An FBD program as written: its blocks and networks, and the rungs its lowering added.
#[derive(serde::Serialize)]
pub struct FbdSection<'a> {
    pub blocks: usize,
    pub networks: usize,
    /// Rungs that test a conditional fragment's condition.
    pub fragment_guards: Vec<&'a str>,
    /// The empty rungs a fragment's guard jumps to.
    pub fragment_ends: Vec<&'a str>,
}

/// Sizes the text report's headline needs.
pub struct Summary {
    /// All rungs (main program and subroutines).
    pub rungs: usize,
    /// Rungs of the main program.
    pub main_rungs: usize,
}

#[derive(serde::Serialize)]
pub struct RungEntry<'a> {
    pub id: &'a str,
    pub pou: &'a str,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub label: Option<&'a str>,
    #[serde(rename = "in")]
    pub ins: Vec<&'a str>,
    pub out: Vec<&'a str>,
    pub cost: u64,
}

/// A dependence: a data pair with its variable, or a control pair with its cause.
#[derive(serde::Serialize)]
#[serde(untagged)]
pub enum DependenceEntry<'a> {
    Data {
        kind: &'static str,
        from: &'a str,
        to: &'a str,
        var: &'a str,
    },
    Control {
        kind: &'static str,
        from: &'a str,
        to: &'a str,
        cause: &'static str,
        #[serde(skip_serializing_if = "Option::is_none")]
        edge: Option<EdgeRef<'a>>,
        #[serde(skip_serializing_if = "Option::is_none")]
        var: Option<&'a str>,
    },
}

/// A CFG edge named by its end points (in a control dependence: the edge that causes it).
#[derive(serde::Serialize)]
pub struct EdgeRef<'a> {
    pub from: &'a str,
    pub to: &'a str,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub label: Option<&'static str>,
    #[serde(skip)]
    pub kind: &'static str,
}

#[derive(serde::Serialize)]
pub struct DependenceCounts<'a> {
    pub flow: u64,
    pub anti: u64,
    pub output: u64,
    pub control: u64,
    /// Per variable with at least one data pair.
    pub by_var: Lazy<'a, VarCount<'a>>,
}

#[derive(serde::Serialize)]
pub struct VarCount<'a> {
    pub var: &'a str,
    pub flow: u64,
    pub anti: u64,
    pub output: u64,
}

#[derive(serde::Serialize)]
pub struct CfgSection<'a> {
    pub edges: Lazy<'a, CfgEdgeEntry<'a>>,
}

#[derive(serde::Serialize)]
pub struct CfgEdgeEntry<'a> {
    pub from: &'a str,
    pub to: &'a str,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub label: Option<&'static str>,
    pub kind: &'static str,
}

/// Immediate post-dominator of START and of every rung that has one, as a JSON object.
pub struct Ipdom<'a>(Lazy<'a, (&'a str, &'a str)>);

impl Serialize for Ipdom<'_> {
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        let mut m = s.serialize_map(None)?;
        for (k, v) in self.0.iter() {
            m.serialize_entry(k, v)?;
        }
        m.end()
    }
}

/// A node of the post-dominator tree with its children (text report only).
pub struct TreeNode<'a> {
    pub node: &'a str,
    pub ipdom: Option<&'a str>,
    pub children: Vec<&'a str>,
}

#[derive(serde::Serialize)]
pub struct Levels<'a> {
    pub data: Vec<Vec<&'a str>>,
    pub control: Vec<Vec<&'a str>>,
    pub combined: Vec<Vec<TaskName<'a>>>,
}

/// A task in a level: one rung, or the rungs of one loop task.
#[derive(Clone, serde::Serialize)]
#[serde(untagged)]
pub enum TaskName<'a> {
    Rung(&'a str),
    Loop(Vec<&'a str>),
}

#[derive(serde::Serialize)]
pub struct Cycles {
    pub before: usize,
    pub data: usize,
    pub control: usize,
    pub combined: usize,
}

#[derive(serde::Serialize)]
pub struct Cost {
    pub work: u64,
    pub span: u64,
    pub ideal_speedup: f64,
    pub makespan: PerCores,
    pub level_makespan: PerCores,
}

/// Makespan per number of cores, as a JSON object keyed by the core count.
pub struct PerCores(pub Vec<(u32, u64)>);

impl Serialize for PerCores {
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        let mut m = s.serialize_map(Some(self.0.len()))?;
        for (p, v) in &self.0 {
            m.serialize_entry(&p.to_string(), v)?;
        }
        m.end()
    }
}

#[derive(serde::Serialize)]
pub struct ScheduleSection<'a> {
    pub tasks: Lazy<'a, TaskEntry<'a>>,
    pub unreachable: Vec<&'a str>,
}

#[derive(serde::Serialize)]
pub struct TaskEntry<'a> {
    pub rungs: Vec<&'a str>,
    #[serde(rename = "loop")]
    pub is_loop: bool,
    pub level: u32,
    pub entries: Vec<&'a str>,
    pub guard: Vec<GuardEntry<'a>>,
}

#[derive(serde::Serialize)]
pub struct GuardEntry<'a> {
    pub controller: &'a str,
    pub successor: &'a str,
}

/// A POU whose body is a stand-in (see [`Report::skipped_pous`]).
#[derive(serde::Serialize)]
pub struct SkippedPouEntry<'a> {
    pub pou: &'a str,
    /// `ST`, `IL`, `SFC`.
    pub language: &'a str,
    /// Where the body is in the program file (1-based), when known.
    pub line: Option<u32>,
    pub column: Option<u32>,
}

impl SkippedPouEntry<'_> {
    /// `CounterST (ST body at 483:11)`.
    pub fn text(&self) -> String {
        match (self.line, self.column) {
            (Some(l), Some(c)) => format!("{} ({} body at {l}:{c})", self.pou, self.language),
            _ => format!("{} ({} body)", self.pou, self.language),
        }
    }
}

/// What the dependences of a stand-in body are, as the reports say it.
pub const SKIPPED_MEANING: &str = "analysed through stand-in rungs that read and write whole variables (ST: one per top-level statement; IL, SFC: one for the body, through its interface): its dependences are over-approximated at the grain of whole variables, except the writes of function block instances that warning W0501 names, which are not seen; `run` and `c` do not execute it (they refuse it without --allow-skipped)";

fn skipped_of(p: &Program) -> Vec<SkippedPouEntry<'_>> {
    p.pous()
        .iter()
        .filter_map(|pou| {
            let s = pou.skipped.as_deref()?;
            Some(SkippedPouEntry {
                pou: &pou.name,
                language: &s.language,
                line: s.position.map(|p| p.0),
                column: s.position.map(|p| p.1),
            })
        })
        .collect()
}

#[derive(serde::Serialize)]
pub struct LoopEntry<'a> {
    /// The loop's name: its first rung.
    pub head: &'a str,
    pub rungs: Vec<&'a str>,
}

#[derive(serde::Serialize)]
pub struct NetworkEntry<'a> {
    pub pou: &'a str,
    pub id: &'a str,
    pub rungs: Vec<&'a str>,
    #[serde(rename = "in")]
    pub ins: Vec<&'a str>,
    pub out: Vec<&'a str>,
}

/// An interrupt routine and the variables it shares with the main program.
#[derive(serde::Serialize)]
pub struct InterruptEntry<'a> {
    pub pou: &'a str,
    pub shared: Vec<SharedVarEntry<'a>>,
}

/// A variable an interrupt routine and the main program share, and who reads and writes it.
#[derive(serde::Serialize)]
pub struct SharedVarEntry<'a> {
    pub var: &'a str,
    pub interrupt_reads: bool,
    pub interrupt_writes: bool,
    pub main_readers: Vec<&'a str>,
    pub main_writers: Vec<&'a str>,
}

fn label_name(b: Option<Branch>) -> Option<&'static str> {
    b.map(|b| match b {
        Branch::T => "T",
        Branch::F => "F",
    })
}

fn round3(x: f64) -> f64 {
    (x * 1000.0).round() / 1000.0
}

/// Builds the report document of `p` from its analysis `a`.
pub fn document<'a>(p: &'a Program, a: &'a Analysis) -> Report<'a> {
    document_with(p, a, None)
}

/// Builds the report document; `fbd` says which rungs the FBD lowering made.
pub fn document_with<'a>(p: &'a Program, a: &'a Analysis, fbd: Option<&'a FbdParts>) -> Report<'a> {
    let id = move |r: RungId| rung_id(p, r);
    let rungs = Lazy::new(p.rungs().len(), move || {
        p.rung_ids().map(move |r| {
            let rung = p.rung(r);
            RungEntry {
                id: id(r),
                pou: p.pou(rung.pou).name.as_str(),
                label: rung.label.as_deref(),
                ins: var_names(p, a.accesses.ins(r)),
                out: var_names(p, a.accesses.outs(r)),
                cost: a.rung_costs[r.index()],
            }
        })
    });
    let (dependences, control_count) = dependences_of(p, a);
    let edges = Lazy::new(a.cfg.edges.len(), move || {
        a.cfg.edges.iter().map(move |e| cfg_edge(p, e))
    });
    let levels = levels_of(p, a);
    let count = |levels: &[u32]| levels.iter().map(|&l| l as usize + 1).max().unwrap_or(0);
    let cycles = Cycles {
        before: p.rungs().len(),
        data: count(&a.data_levels),
        control: count(&a.control_levels),
        combined: a.schedule.levels.len(),
    };
    let (fbd_section, shown_levels) = fbd_of(p, fbd, &levels);
    Report {
        program: p.name(),
        rungs,
        dependences,
        dependences_listed: match a.listed {
            Listed::All => "all",
            Listed::Direct => "direct",
        },
        dependence_counts: dependence_counts_of(p, a, control_count),
        self_control: super::self_controlled(a).into_iter().map(id).collect(),
        cfg: CfgSection { edges },
        ipdom: ipdom_of(p, a),
        levels,
        cycles,
        cost: cost_of(a),
        schedule: ScheduleSection {
            tasks: Lazy::new(a.schedule.tasks.len(), move || {
                a.schedule.tasks.iter().map(move |t| task_entry(p, a, t))
            }),
            unreachable: a.schedule.unreachable.iter().map(|&r| id(r)).collect(),
        },
        loops: loops_of(p, a),
        differences: differences_of(p, a),
        warnings: a
            .warnings
            .iter()
            .map(|w| super::warning_text(p, w))
            .collect(),
        warning_codes: a.warnings.iter().map(super::warning_code).collect(),
        networks: networks_of(p, a),
        interrupts: interrupts_of(p, a),
        configuration: p
            .configuration()
            .map(super::configuration::configuration_entry),
        programs: a
            .task_sharing
            .runs
            .iter()
            .map(super::configuration::run_entry)
            .collect(),
        task_sharing: super::configuration::task_shared_entries(p, a),
        fbd: fbd_section,
        skipped_pous: skipped_of(p),
        shown_levels,
        summary: Summary {
            rungs: p.rungs().len(),
            main_rungs: p.main().rungs.len(),
        },
        post_dominator_tree: post_dominator_tree_of(p, a),
        control_count,
        tasks_by_level: tasks_by_level_of(p, a),
    }
}

/// Rung `r`'s id.
fn rung_id(p: &Program, r: RungId) -> &str {
    p.rung(r).id.as_str()
}

/// The names of variables `vs`.
fn var_names<'a>(p: &'a Program, vs: &[VarId]) -> Vec<&'a str> {
    vs.iter().map(|&v| p.var(v).name.as_str()).collect()
}

/// CFG edge `e` by its ends' names.
fn cfg_edge<'a>(p: &'a Program, e: &plc_analysis::CfgEdge) -> CfgEdgeEntry<'a> {
    CfgEdgeEntry {
        from: super::node_name(p, e.from.raw()),
        to: super::node_name(p, e.to.raw()),
        label: label_name(e.label),
        kind: e.kind.name(),
    }
}

/// The dependences (data, then the paper's control pairs) and the number of control pairs.
fn dependences_of<'a>(p: &'a Program, a: &'a Analysis) -> (Lazy<'a, DependenceEntry<'a>>, usize) {
    let id = move |r: RungId| rung_id(p, r);
    // A dependence names its rungs by position (dense CSR numbering).
    let at = move |i: u32| p.rungs()[i as usize].id.as_str();
    let var = move |v: VarId| p.var(v).name.as_str();
    let pairs = std::rc::Rc::new(super::paper_control_pairs(a));
    let control_count = pairs.len();
    let dependences = Lazy::new(a.data.len() + control_count, move || {
        let data = a.data.iter().map(move |d| DependenceEntry::Data {
            kind: d.kind.name(),
            from: at(d.from),
            to: at(d.to),
            var: var(d.var),
        });
        let pairs = pairs.clone();
        let control = (0..pairs.len()).map(move |i| {
            let (from, to, cause) = pairs[i];
            let (cause, edge, v) = match cause {
                ControlCause::Branch { edge } => ("branch", Some(edge_ref(p, a, edge)), None),
                ControlCause::Instance { var: v } => ("instance", None, Some(var(v))),
            };
            DependenceEntry::Control {
                kind: "control",
                from: id(from),
                to: id(to),
                cause,
                edge,
                var: v,
            }
        });
        data.chain(control)
    });
    (dependences, control_count)
}

/// CFG edge `i` as a control dependence's cause.
fn edge_ref<'a>(p: &'a Program, a: &'a Analysis, i: CfgEdgeId) -> EdgeRef<'a> {
    let e = cfg_edge(p, a.cfg.edge(i));
    EdgeRef {
        from: e.from,
        to: e.to,
        label: e.label,
        kind: e.kind,
    }
}

/// The pair counts of the every-pair definition, per kind and per variable.
fn dependence_counts_of<'a>(
    p: &'a Program,
    a: &'a Analysis,
    control_count: usize,
) -> DependenceCounts<'a> {
    let counts = &a.counts;
    DependenceCounts {
        flow: counts.flow,
        anti: counts.anti,
        output: counts.output,
        control: control_count as u64,
        by_var: Lazy::new(counts.by_var.len(), move || {
            counts
                .by_var
                .iter()
                .map(move |&(v, flow, anti, output)| VarCount {
                    var: p.var(v).name.as_str(),
                    flow,
                    anti,
                    output,
                })
        }),
    }
}

/// START and the rungs of `p`: the CFG nodes whose post-dominators are listed.
fn listed_nodes(p: &Program, a: &Analysis) -> impl Iterator<Item = u32> {
    std::iter::once(a.cfg.start().raw()).chain(0..p.rungs().len() as u32)
}

/// Each listed node's immediate post-dominator, by name.
fn ipdom_of<'a>(p: &'a Program, a: &'a Analysis) -> Ipdom<'a> {
    let node = move |n: u32| super::node_name(p, n);
    let with_ipdom = move || {
        listed_nodes(p, a)
            .filter_map(move |n| a.post_dominators.immediate(n).map(|d| (node(n), node(d))))
    };
    Ipdom(Lazy::new(with_ipdom().count(), with_ipdom))
}

/// The post-dominator tree, node by node (START, the rungs, STOP).
fn post_dominator_tree_of<'a>(p: &'a Program, a: &'a Analysis) -> Lazy<'a, TreeNode<'a>> {
    let node = move |n: u32| super::node_name(p, n);
    Lazy::new(p.rungs().len() + 2, move || {
        listed_nodes(p, a)
            .chain(std::iter::once(a.cfg.stop().raw()))
            .map(move |n| TreeNode {
                node: node(n),
                ipdom: a.post_dominators.immediate(n).map(node),
                children: a
                    .post_dominators
                    .children(n)
                    .iter()
                    .map(|&k| node(k))
                    .collect(),
            })
    })
}

/// Task `t` of the combined schedule, by its rungs' ids.
fn task_entry<'a>(p: &'a Program, a: &'a Analysis, t: &'a plc_analysis::Task) -> TaskEntry<'a> {
    let s = &a.schedule;
    let id = move |r: RungId| rung_id(p, r);
    TaskEntry {
        rungs: t.rungs.iter().map(|&r| id(r)).collect(),
        is_loop: t.is_loop,
        level: t.level + 1,
        entries: t.entries.iter().map(|&r| id(r)).collect(),
        guard: t
            .guard
            .iter()
            .map(|g| GuardEntry {
                controller: id(s.head(g.controller)),
                successor: match g.successor {
                    Successor::Task(x) => id(s.head(x)),
                    Successor::Stop => "STOP",
                },
            })
            .collect(),
    }
}

/// The tasks level by level, in sequential order inside a level.
fn tasks_by_level_of<'a>(p: &'a Program, a: &'a Analysis) -> Lazy<'a, TaskEntry<'a>> {
    let s = &a.schedule;
    let order = std::rc::Rc::new(s.levels.concat());
    Lazy::new(s.tasks.len(), move || {
        let order = order.clone();
        (0..order.len()).map(move |i| task_entry(p, a, s.task(order[i])))
    })
}

/// The loops of the combined schedule, each named by its first rung.
fn loops_of<'a>(p: &'a Program, a: &'a Analysis) -> Vec<LoopEntry<'a>> {
    a.schedule
        .tasks
        .iter()
        .filter(|t| t.is_loop)
        .map(|t| LoopEntry {
            head: rung_id(p, t.rungs[0]),
            rungs: t.rungs.iter().map(|&r| rung_id(p, r)).collect(),
        })
        .collect()
}

/// Why each rung whose combined level differs from a paper view's does.
fn differences_of<'a>(p: &'a Program, a: &'a Analysis) -> Lazy<'a, DifferenceEntry> {
    let explainer = std::rc::Rc::new(Explainer::new(p, a));
    let differing = std::rc::Rc::new(explainer.differing());
    Lazy::new(differing.len(), move || {
        let explainer = explainer.clone();
        let differing = differing.clone();
        (0..differing.len()).map(move |i| explainer.difference(differing[i]))
    })
}

/// The networks of the program (ladder networks, FBD networks) with their IN/OUT.
fn networks_of<'a>(p: &'a Program, a: &'a Analysis) -> Vec<NetworkEntry<'a>> {
    super::networks(p, a)
        .into_iter()
        .map(|n| NetworkEntry {
            pou: p.pou(n.pou).name.as_str(),
            id: p.rung(n.rungs[0]).network().unwrap_or_default(),
            rungs: n.rungs.iter().map(|&r| rung_id(p, r)).collect(),
            ins: var_names(p, &n.ins),
            out: var_names(p, &n.outs),
        })
        .collect()
}

/// What each interrupt routine shares with the main program.
fn interrupts_of<'a>(p: &'a Program, a: &'a Analysis) -> Vec<InterruptEntry<'a>> {
    let ids = |rs: &[RungId]| rs.iter().map(|&r| rung_id(p, r)).collect();
    a.interrupts
        .iter()
        .map(|i| InterruptEntry {
            pou: &p.pou(i.pou).name,
            shared: i
                .shared
                .iter()
                .map(|s| SharedVarEntry {
                    var: &p.var(s.var).name,
                    interrupt_reads: s.interrupt_reads,
                    interrupt_writes: s.interrupt_writes,
                    main_readers: ids(&s.main_readers),
                    main_writers: ids(&s.main_writers),
                })
                .collect(),
        })
        .collect()
}

/// The ids of the lowering's landing rungs.
fn landing_names<'a>(p: &'a Program, f: &FbdParts) -> std::collections::HashSet<&'a str> {
    p.rung_ids()
        .filter(|r| f.parts[r.index()] == RungPart::FragmentEnd)
        .map(|r| p.rung(r).id.as_str())
        .collect()
}

/// The three levellings, rung ids per level (a loop task of the combined schedule as one list).
fn levels_of<'a>(p: &'a Program, a: &'a Analysis) -> Levels<'a> {
    let id = move |r: RungId| p.rung(r).id.as_str();
    let groups = |levels: &[u32]| -> Vec<Vec<&'a str>> {
        super::rung_groups(p, levels)
            .into_iter()
            .map(|g| g.into_iter().map(id).collect())
            .collect()
    };
    let combined = super::combined_groups(a)
        .into_iter()
        .map(|level| {
            level
                .into_iter()
                .map(|task| {
                    if task.len() == 1 {
                        TaskName::Rung(id(task[0]))
                    } else {
                        TaskName::Loop(task.into_iter().map(id).collect())
                    }
                })
                .collect()
        })
        .collect();
    Levels {
        data: groups(&a.data_levels),
        control: groups(&a.control_levels),
        combined,
    }
}

/// The cost model's figures of the combined schedule.
fn cost_of(a: &Analysis) -> Cost {
    let c = &a.cost;
    Cost {
        work: c.work,
        span: c.span,
        ideal_speedup: if c.span == 0 {
            0.0
        } else {
            round3(c.work as f64 / c.span as f64)
        },
        makespan: PerCores(c.makespan.clone()),
        level_makespan: PerCores(c.level_makespan.clone()),
    }
}

/// The FBD section and the levels without the lowering's landing rungs (`None` without FBD).
fn fbd_of<'a>(
    p: &'a Program,
    fbd: Option<&'a FbdParts>,
    levels: &Levels<'a>,
) -> (Option<FbdSection<'a>>, Option<Levels<'a>>) {
    let id = move |r: RungId| p.rung(r).id.as_str();
    let of_part = |part: RungPart| -> Vec<&'a str> {
        fbd.map(|f| {
            p.rung_ids()
                .filter(|r| f.parts[r.index()] == part)
                .map(id)
                .collect()
        })
        .unwrap_or_default()
    };
    let fbd_section = fbd.map(|f| FbdSection {
        blocks: f.blocks,
        networks: f.networks,
        fragment_guards: of_part(RungPart::FragmentGuard),
        fragment_ends: of_part(RungPart::FragmentEnd),
    });
    let shown_levels = fbd.map(|f| {
        let landings = landing_names(p, f);
        let shown = |r: &&'a str| !landings.contains(r);
        let keep = |g: &Vec<Vec<&'a str>>| -> Vec<Vec<&'a str>> {
            g.iter()
                .map(|l| l.iter().copied().filter(shown).collect())
                .collect()
        };
        Levels {
            data: keep(&levels.data),
            control: keep(&levels.control),
            combined: levels
                .combined
                .iter()
                .map(|l| {
                    l.iter()
                        .filter(|t| !matches!(t, TaskName::Rung(x) if !shown(x)))
                        .cloned()
                        .collect()
                })
                .collect(),
        }
    });
    (fbd_section, shown_levels)
}
