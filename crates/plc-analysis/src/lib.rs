//! The analyses of Zhao & Yan (2012), each a plain function from the model (or an earlier result) to a
//! result value, and [`analyse`], which runs them all in order.
//!
//! - [`accesses`]: IN/OUT per rung;
//! - [`dependences`]: flow/anti/output pairs and the paper's data levels;
//! - [`cfg`]: the control-flow graph;
//! - [`control`]: post-dominators and control dependences (FOW);
//! - [`levels`]: ASAP levelling of any dependence graph (the paper's control view);
//! - [`schedule`]: the correct combined schedule (data + control, loops whole);
//! - [`cost`]: the cost model, work, span and makespans;
//! - [`graphs`]: these results as `petgraph` graphs, for library users' own algorithms.
//!
//! Nothing here prints or allocates per-rung strings; reports render these values.
#![forbid(unsafe_code)]

pub mod accesses;
pub mod cfg;
pub mod control;
pub mod cost;
pub mod dependences;
pub mod graphs;
pub mod interrupts;
pub mod levels;
pub mod schedule;
pub mod task_sharing;

pub use accesses::{accesses, Accesses, VarSets};
pub use cfg::{control_flow_graph, Branch, Cfg, CfgEdge, CfgEdgeId, CfgNode, EdgeKind};
pub use control::{control_dependences, post_dominators, ControlDependence, PostDominators};
pub use cost::CostSummary;
pub use dependences::{
    data_dependences, data_levels, dependence_counts, direct_dependences, DataDependence, DepKind,
    DependenceCounts,
};
use plc_model::*;
pub use schedule::{combined_schedule, Guard, Schedule, Successor, Task};

/// A control dependence of the paper's control view.
#[derive(Copy, Clone, Debug, PartialEq, Eq, PartialOrd, Ord)]
pub struct PaperControl {
    pub from: RungId,
    pub to: RungId,
    pub cause: ControlCause,
}

/// Why a rung is control dependent on another in the paper's view.
#[derive(Copy, Clone, Debug, PartialEq, Eq, PartialOrd, Ord)]
pub enum ControlCause {
    /// FOW control dependence through CFG edge `edge` (an index into `Cfg::edges`).
    Branch { edge: CfgEdgeId },
    /// The rung reads a field of a timer or counter instance whose box is on `from` (the paper
    /// counts these as control dependences).
    Instance { var: VarId },
}

/// Something the user should know that is not an error.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum Warning {
    /// Main-program rungs that can never run.
    Unreachable(Vec<RungId>),
    /// Rungs that can never reach the end of the scan (an endless loop).
    Endless(Vec<RungId>),
    /// A subroutine nothing calls.
    Uncalled(PouId),
    /// An interrupt routine: it may run between any two rungs, and the scan raises no events.
    Interrupt(PouId),
    /// Rungs with no elements at all (written by the user, not FBD lowering).
    Empty(Vec<RungId>),
    /// Rungs that write nothing and transfer no control: they have no effect on the scan.
    NoEffect(Vec<RungId>),
    /// Rungs that write an input variable (matiec accepts a coil on `%IX0.0`): the value lasts
    /// until the next scan copies the input image in ([`Program::written_inputs`]).
    WritesInput(VarId, Vec<RungId>),
}

/// Per input variable the program writes ([`Program::written_inputs`]), the rungs that write
/// it (listing order).
fn input_writes(p: &Program, acc: &Accesses) -> Vec<(VarId, Vec<RungId>)> {
    let written = &p.written_inputs();
    let mut by: Vec<(VarId, Vec<RungId>)> = written.iter().map(|&v| (v, Vec::new())).collect();
    if by.is_empty() {
        return by;
    }
    for r in p.rung_ids() {
        for v in acc.outs(r) {
            if let Ok(k) = written.binary_search(v) {
                if by[k].1.last() != Some(&r) {
                    by[k].1.push(r);
                }
            }
        }
    }
    by
}

/// Rungs of the user's ladder program that are empty or have no effect. Rungs lowered from FBD
/// are left out: their empty landing rungs belong to the lowering.
fn idle_rungs(p: &Program, acc: &Accesses) -> (Vec<RungId>, Vec<RungId>) {
    let (mut empty, mut no_effect) = (Vec::new(), Vec::new());
    for r in p.rung_ids() {
        let rung = p.rung(r);
        if rung.network().is_some() {
            continue;
        }
        if rung.series.is_empty() {
            empty.push(r);
            continue;
        }
        let mut transfers = false;
        walk_elements(&rung.series, &mut |e| transfers |= e.transfers_control());
        if !transfers && acc.outs(r).is_empty() {
            no_effect.push(r);
        }
    }
    (empty, no_effect)
}

/// Which data dependences an [`Analysis`] lists (levels and schedule never depend on it;
/// `report --dependences`: `All` and `Direct` are the command line's values, their doc comments
/// not its help).
#[derive(Copy, Clone, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "clap", derive(clap::ValueEnum))]
pub enum DependenceListing {
    /// Every pair of the paper's definition.
    #[cfg_attr(feature = "clap", value(help = None::<&str>))]
    All,
    /// Only the direct pairs ([`direct_dependences`]), linear in the accesses.
    #[cfg_attr(feature = "clap", value(help = None::<&str>))]
    Direct,
    /// Every pair while there are at most this many, the direct ones beyond.
    #[cfg_attr(feature = "clap", value(skip))]
    UpTo(u64),
}

/// What [`analyse_with`] computes.
#[derive(Copy, Clone, Debug, PartialEq, Eq)]
pub struct AnalysisConfig {
    pub dependences: DependenceListing,
}

/// The default limit of listed pairs: beyond it the report lists the direct ones.
pub const DEFAULT_MAX_PAIRS: u64 = 2_000_000;

impl Default for AnalysisConfig {
    fn default() -> Self {
        AnalysisConfig {
            dependences: DependenceListing::UpTo(DEFAULT_MAX_PAIRS),
        }
    }
}

/// Which data dependences [`Analysis::data`] holds.
#[derive(Copy, Clone, Debug, PartialEq, Eq)]
pub enum Listed {
    All,
    Direct,
}

/// Everything `plc-deps report` shows.
#[derive(Clone, Debug)]
pub struct Analysis {
    pub accesses: Accesses,
    /// Data dependences between rungs in listing order (unit index = `RungId`): every pair, or
    /// the direct ones (see `listed`).
    pub data: Vec<DataDependence>,
    /// Which pairs `data` holds.
    pub listed: Listed,
    /// How many pairs of each kind the every-pair definition gives.
    pub counts: DependenceCounts,
    /// Paper data view: level per rung (0-based).
    pub data_levels: Vec<u32>,
    pub cfg: Cfg,
    pub post_dominators: PostDominators,
    /// FOW control dependences over the whole CFG (controller/dependent are CFG nodes).
    pub control: Vec<ControlDependence>,
    /// The paper's control view: CDG without self edges, plus instance reads.
    pub paper_control: Vec<PaperControl>,
    /// Paper control view: level per rung (0-based).
    pub control_levels: Vec<u32>,
    pub schedule: Schedule,
    pub cost: CostSummary,
    /// Cost of each rung (calls included, loop multipliers applied).
    pub rung_costs: Vec<u64>,
    pub warnings: Vec<Warning>,
    /// What each interrupt routine shares with the main program.
    pub interrupts: Vec<interrupts::InterruptSharing>,
    /// The program instances of the PLCopen configuration, in run order, and the globals that
    /// programs of different tasks share.
    pub task_sharing: task_sharing::TaskSharing,
}

/// Runs every analysis on `p` with the default [`AnalysisConfig`].
pub fn analyse(p: &Program) -> Analysis {
    analyse_with(p, &AnalysisConfig::default())
}

/// The data dependences to list, and which kind of list that is.
fn listed_dependences(
    acc: &Accesses,
    counts: &DependenceCounts,
    listing: DependenceListing,
) -> (Vec<DataDependence>, Listed) {
    let all = match listing {
        DependenceListing::All => true,
        DependenceListing::Direct => false,
        DependenceListing::UpTo(max) => counts.total() <= max,
    };
    if all {
        (data_dependences(&acc.reads, &acc.writes), Listed::All)
    } else {
        (direct_dependences(&acc.reads, &acc.writes), Listed::Direct)
    }
}

/// Runs every analysis on `p`. The paper's views and the combined schedule are independent once
/// the accesses and the CFG are known, so they are computed on two threads (rayon).
pub fn analyse_with(p: &Program, config: &AnalysisConfig) -> Analysis {
    let (acc, cfg) = rayon::join(|| accesses(p), || control_flow_graph(p));
    let n = p.rungs().len();
    let paper = || {
        let ((counts, (data, listed)), data_lv) = rayon::join(
            || {
                let counts = dependence_counts(&acc.reads, &acc.writes);
                let data = listed_dependences(&acc, &counts, config.dependences);
                (counts, data)
            },
            || data_levels(&acc.reads, &acc.writes),
        );
        // The paper's views are computed on the paper's CFG; the combined schedule (below)
        // also knows where the iteration cap can send control.
        let paper_edges = cfg.paper_edges();
        let pairs: Vec<(u32, u32)> = paper_edges
            .iter()
            .map(|&e| (cfg.edge(e).from.raw(), cfg.edge(e).to.raw()))
            .collect();
        let pdom = post_dominators(cfg.node_count(), &pairs, cfg.stop().raw());
        let reachable = plc_graph::reachable(
            &plc_graph::Csr::from_edges(cfg.node_count(), &pairs),
            cfg.start().raw(),
        );
        let mut control = control_dependences(&pairs, &pdom, |a| reachable[a as usize]);
        for d in &mut control {
            d.edge = paper_edges[d.edge as usize].raw(); // an index into `cfg.edges`
        }
        let paper_control = paper_control_view(p, &control);
        let cv_edges: Vec<(u32, u32)> = paper_control
            .iter()
            .map(|d| (d.from.raw(), d.to.raw()))
            .filter(|(a, b)| a != b)
            .collect();
        let control_lv = levels::asap_levels(n, &cv_edges);
        (
            data,
            listed,
            counts,
            data_lv,
            pdom,
            control,
            paper_control,
            control_lv,
        )
    };
    let combined = || {
        let schedule = combined_schedule(p, &cfg, &acc);
        let base = cost::rung_costs(p);
        let mut rung_costs = base.clone();
        for pou in p.pous().ids() {
            for (r, m) in p.pou_rungs(pou).zip(cost::multipliers(p, pou)) {
                rung_costs[r.index()] = base[r.index()].saturating_mul(m).min(cost::COST_MAX);
            }
        }
        let task_costs = cost::task_costs(&schedule, &rung_costs);
        let task_levels: Vec<u32> = schedule.tasks.iter().map(|t| t.level).collect();
        let cost = cost::summarise(&task_costs, &schedule.preds, &task_levels);
        (schedule, rung_costs, cost)
    };
    let (
        (data, listed, counts, data_lv, pdom, control, paper_control, control_lv),
        (schedule, rung_costs, cost),
    ) = rayon::join(paper, combined);
    let mut warnings = Vec::new();
    if !schedule.unreachable.is_empty() {
        warnings.push(Warning::Unreachable(schedule.unreachable.clone()));
    }
    for region in &pdom.endless {
        let rungs: Vec<RungId> = region
            .iter()
            .filter(|&&v| (v as usize) < n)
            .map(|&v| p.rungs().id(v as usize))
            .collect();
        if !rungs.is_empty() {
            warnings.push(Warning::Endless(rungs));
        }
    }
    for &pou in &cfg.uncalled {
        warnings.push(match p.pou(pou).kind {
            PouKind::Interrupt => Warning::Interrupt(pou),
            _ => Warning::Uncalled(pou),
        });
    }
    let (empty, no_effect) = idle_rungs(p, &acc);
    if !empty.is_empty() {
        warnings.push(Warning::Empty(empty));
    }
    if !no_effect.is_empty() {
        warnings.push(Warning::NoEffect(no_effect));
    }
    for (v, rungs) in input_writes(p, &acc) {
        warnings.push(Warning::WritesInput(v, rungs));
    }
    let interrupts = interrupts::interrupt_sharing(p, &acc);
    let task_sharing = task_sharing::task_sharing(p, &acc);
    Analysis {
        interrupts,
        task_sharing,
        accesses: acc,
        data,
        listed,
        counts,
        data_levels: data_lv,
        cfg,
        post_dominators: pdom,
        control,
        paper_control,
        control_levels: control_lv,
        schedule,
        cost,
        rung_costs,
        warnings,
    }
}

/// The paper's control view: FOW dependences between rungs, and reads of a timer or counter
/// instance's fields after the rung holding its box.
fn paper_control_view(p: &Program, control: &[ControlDependence]) -> Vec<PaperControl> {
    let n = p.rungs().len() as u32;
    let mut out: Vec<PaperControl> = control
        .iter()
        .filter(|d| d.controller < n && d.dependent < n)
        .map(|d| PaperControl {
            from: p.rungs().id(d.controller as usize),
            to: p.rungs().id(d.dependent as usize),
            cause: ControlCause::Branch {
                edge: CfgEdgeId::new(d.edge),
            },
        })
        .collect();
    // Box rungs per instance (a linked list, newest first, in one flat array: most variables are
    // not instances); then each field read pairs with the earlier box rungs.
    let mut last_box: Vec<Option<u32>> = vec![None; p.vars().len()];
    let mut box_nodes: Vec<(RungId, Option<u32>)> = Vec::new();
    let mut field_reads: Vec<VarId> = Vec::new();
    let mut own_boxes: Vec<VarId> = Vec::new();
    for r in p.rung_ids() {
        field_reads.clear();
        own_boxes.clear();
        walk_elements(&p.rung(r).series, &mut |e| match e {
            Element::Timer { instance, .. }
            | Element::Ctu { instance, .. }
            | Element::Ctd { instance, .. }
            | Element::Trigger { instance, .. } => own_boxes.push(*instance),
            Element::Bistable {
                instance, reset, ..
            } => {
                own_boxes.push(*instance);
                if let Operand::Var(v) = reset {
                    if v.field.is_some() {
                        field_reads.push(v.var);
                    }
                }
            }
            Element::Ctud { instance, inputs } => {
                own_boxes.push(*instance);
                for o in inputs.operands() {
                    if let Operand::Var(v) = o {
                        if v.field.is_some() {
                            field_reads.push(v.var);
                        }
                    }
                }
            }
            Element::Contact { var, .. } if var.field.is_some() => field_reads.push(var.var),
            Element::Compare { a, b, .. } | Element::Arith { a, b, .. } => {
                for o in [a, b] {
                    if let Operand::Var(v) = o {
                        if v.field.is_some() {
                            field_reads.push(v.var);
                        }
                    }
                }
            }
            Element::Function { args, .. } => {
                for o in args.iter() {
                    if let Operand::Var(v) = o {
                        if v.field.is_some() {
                            field_reads.push(v.var);
                        }
                    }
                }
            }
            Element::Move {
                from: Operand::Var(v),
                ..
            } if v.field.is_some() => field_reads.push(v.var),
            _ => {}
        });
        field_reads.sort_unstable();
        field_reads.dedup();
        for &v in &field_reads {
            let mut node = last_box[v.index()];
            while let Some(at) = node {
                let (s, next) = box_nodes[at as usize];
                out.push(PaperControl {
                    from: s,
                    to: r,
                    cause: ControlCause::Instance { var: v },
                });
                node = next;
            }
        }
        for &v in &own_boxes {
            let head = last_box[v.index()];
            if head.is_none_or(|h| box_nodes[h as usize].0 != r) {
                box_nodes.push((r, head));
                last_box[v.index()] = Some(box_nodes.len() as u32 - 1);
            }
        }
    }
    out.sort_unstable();
    out
}
