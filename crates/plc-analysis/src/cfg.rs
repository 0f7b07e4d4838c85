//! The control-flow graph of a program (Zhao & Yan, 2012, §2 "control dependence": CFG ⟨V, E, T/F,
//! START, STOP⟩).
//!
//! One node per rung (node `i` is `RungId(i)`) plus START (`rung count`) and STOP (`+ 1`).
//! A rung's out-edges follow its control elements in evaluation order:
//! - `jmp` → the labelled rung (T), `ret` → the POU's return (STOP in the main program, back to
//!   every caller in a subroutine), `end` → STOP; a transfer whose power is constantly TRUE (no
//!   condition before it) is unconditional: nothing after it in the rung runs and the rung has no
//!   fall-through;
//! - `call` → the subroutine's first rung (T, or unlabelled if unconditional); the subroutine's
//!   exits (its last rung's fall-through and its `ret`s) return to the calling rung, which then
//!   continues (this is the paper's shape: ipdom of a subroutine rung is its caller);
//! - a FOR head → the first body rung (T, loop enter) and the rung after its NEXT (F, loop exit);
//!   a NEXT rung → its FOR head (loop back: the head tests the index again);
//! - otherwise the fall-through to the next rung of the POU (F when the rung also has conditional
//!   transfers), or the POU's exit after its last rung.
//!
//! A subroutine that nothing calls returns to STOP. The graph deliberately keeps call and return
//! edges context-insensitive (the paper's view); the combined schedule drops them and runs calls
//! inside the calling rung instead (see `schedule`).

use plc_graph::Csr;
use plc_model::*;

/// Which branch of a rung an edge is.
#[derive(Copy, Clone, Debug, PartialEq, Eq, Hash)]
pub enum Branch {
    /// The transfer is taken (jump taken, loop entered, call made, RET/END taken).
    T,
    /// The transfer is not taken (fall-through, loop exit).
    F,
}

/// What an edge does.
#[derive(Copy, Clone, Debug, PartialEq, Eq, Hash)]
pub enum EdgeKind {
    /// START to the first rung of the main program.
    Entry,
    /// To the next rung, or to the POU's exit.
    Fallthrough,
    Jump,
    Ret,
    End,
    Call,
    /// From a subroutine's exit back to a calling rung.
    Return,
    LoopEnter,
    LoopExit,
    LoopBack,
    /// From a rung whose loop-back is an unconditional backward jump, on past it: the way the
    /// scan goes when the iteration cap refuses the jump (it then acts as a jump without power).
    Refused,
}

impl EdgeKind {
    pub fn name(self) -> &'static str {
        match self {
            EdgeKind::Entry => "entry",
            EdgeKind::Fallthrough => "fallthrough",
            EdgeKind::Jump => "jump",
            EdgeKind::Ret => "ret",
            EdgeKind::End => "end",
            EdgeKind::Call => "call",
            EdgeKind::Return => "return",
            EdgeKind::LoopEnter => "loop-enter",
            EdgeKind::LoopExit => "loop-exit",
            EdgeKind::LoopBack => "loop-back",
            EdgeKind::Refused => "refused",
        }
    }
}

plc_model::index_type!(
    /// A CFG node: rung `i` of [`Program::rungs`] is node `i`; START and STOP follow
    /// ([`Cfg::start`], [`Cfg::stop`]).
    CfgNode
);

impl From<RungId> for CfgNode {
    fn from(r: RungId) -> CfgNode {
        CfgNode(r.raw())
    }
}

plc_model::index_type!(
    /// A CFG edge: index into [`Cfg::edges`].
    CfgEdgeId
);

/// One CFG edge.
#[derive(Copy, Clone, Debug, PartialEq, Eq, Hash)]
pub struct CfgEdge {
    pub from: CfgNode,
    pub to: CfgNode,
    pub label: Option<Branch>,
    pub kind: EdgeKind,
}

/// The control-flow graph.
#[derive(Clone, Debug)]
pub struct Cfg {
    /// Number of rungs; START and STOP follow.
    pub rungs: u32,
    /// Edges, grouped by source node in node order, in evaluation order within a rung.
    pub edges: Vec<CfgEdge>,
    /// Subroutines that nothing calls (their exits go to STOP).
    pub uncalled: Vec<PouId>,
}

impl Cfg {
    pub fn start(&self) -> CfgNode {
        CfgNode(self.rungs)
    }
    pub fn stop(&self) -> CfgNode {
        CfgNode(self.rungs + 1)
    }
    pub fn node_count(&self) -> usize {
        self.rungs as usize + 2
    }
    /// The rung a node stands for; `None` for START and STOP.
    pub fn rung(&self, p: &Program, n: CfgNode) -> Option<RungId> {
        p.rungs().get_id(n.index())
    }
    /// The edge with index `e`.
    pub fn edge(&self, e: CfgEdgeId) -> &CfgEdge {
        &self.edges[e.index()]
    }
    /// Successor adjacency of the whole graph (nodes as [`CfgNode`] numbers).
    pub fn graph(&self) -> Csr {
        let pairs: Vec<(u32, u32)> = self.edges.iter().map(|e| (e.from.0, e.to.0)).collect();
        Csr::from_edges(self.node_count(), &pairs)
    }
    /// Nodes reachable from START.
    pub fn reachable(&self) -> Vec<bool> {
        plc_graph::reachable(&self.graph(), self.start().0)
    }
    /// The indices in [`Cfg::edges`] of the edges of the paper's CFG: every edge but the
    /// iteration cap's [`EdgeKind::Refused`] ones (the paper's programs have no iteration cap).
    pub fn paper_edges(&self) -> Vec<CfgEdgeId> {
        (0..self.edges.len() as u32)
            .map(CfgEdgeId)
            .filter(|&e| self.edge(e).kind != EdgeKind::Refused)
            .collect()
    }
}

/// A control transfer found in a rung, in evaluation order.
#[derive(Copy, Clone, Debug)]
pub enum Transfer {
    Jump(RungId),
    Ret,
    End,
    Call(PouId),
}

/// The control transfers of a series, each with "power is constantly TRUE here"; stops after
/// the first unconditional jump, ret or end. Returns whether such a terminator was found.
pub fn transfers(series: &[Element], out: &mut Vec<(Transfer, bool)>) -> bool {
    transfers_refusing(series, None, out)
}

/// Whether transfers found by [`transfers`] (`terminated`: its result) end the rung of `r` in
/// an unconditional jump back to `r` itself or an earlier rung: a loop-back the iteration cap
/// may refuse, after which the rest of the rung runs ([`transfers_refusing`]).
pub fn ends_in_loop_back(found: &[(Transfer, bool)], terminated: bool, r: RungId) -> bool {
    terminated && matches!(found.last(), Some(&(Transfer::Jump(t), true)) if t.raw() <= r.raw())
}

/// [`transfers`] of rung `refused`'s series when the iteration cap refuses its backward jumps
/// (those to `refused` itself or an earlier rung): each is listed, as it may be taken before
/// the cap is reached, and then acts as a jump without power, so the walk goes on past it with
/// power no longer constantly TRUE. Returns whether the rung still ends in an unconditional
/// transfer (a later jump, RET or END); if not, control goes on to the next rung.
pub fn transfers_refusing(
    series: &[Element],
    refused: Option<RungId>,
    out: &mut Vec<(Transfer, bool)>,
) -> bool {
    walk_series(series, true, refused, out).1
}

/// One series of [`transfers_refusing`] entered with power `always` (constantly TRUE or not):
/// returns the power after it and whether it ended in an unconditional transfer.
fn walk_series(
    series: &[Element],
    mut always: bool,
    refused: Option<RungId>,
    out: &mut Vec<(Transfer, bool)>,
) -> (bool, bool) {
    let walk = |series: &[Element], always: bool, out: &mut Vec<(Transfer, bool)>| {
        walk_series(series, always, refused, out)
    };
    let back = |target: RungId| refused.is_some_and(|r| target.raw() <= r.raw());
    for e in series {
        match e {
            Element::Contact { .. }
            | Element::Compare { .. }
            | Element::Timer { .. }
            | Element::Ctu { .. }
            | Element::Ctd { .. }
            | Element::Bistable { .. }
            | Element::Trigger { .. }
            | Element::Ctud { .. } => always = false,
            Element::Or(bs) => {
                let mut any = false;
                for b in bs {
                    let (a, _) = walk_conditions(b, always);
                    any |= a;
                }
                always = any;
            }
            Element::Branch(bs) => {
                for b in bs {
                    let (_, stopped) = walk(b, always, out);
                    if stopped {
                        return (always, true);
                    }
                }
            }
            Element::Jmp { target, .. } if back(*target) => {
                out.push((Transfer::Jump(*target), always));
                always = false;
            }
            Element::Jmp { target, .. } => {
                out.push((Transfer::Jump(*target), always));
                if always {
                    return (always, true);
                }
            }
            Element::Ret => {
                out.push((Transfer::Ret, always));
                if always {
                    return (always, true);
                }
            }
            Element::End => {
                out.push((Transfer::End, always));
                if always {
                    return (always, true);
                }
            }
            Element::Call { pou } => out.push((Transfer::Call(*pou), always)),
            Element::Coil { .. }
            | Element::Set(_)
            | Element::Reset(_)
            | Element::Move { .. }
            | Element::Arith { .. }
            | Element::Function { .. }
            | Element::For { .. }
            | Element::Next { .. }
            | Element::RangeFault => {}
        }
    }
    (always, false)
}

fn walk_conditions(series: &[Element], mut always: bool) -> (bool, ()) {
    for e in series {
        match e {
            Element::Or(bs) => always = always && bs.iter().any(|b| walk_conditions(b, true).0),
            _ => always = false,
        }
    }
    (always, ())
}

/// Builds the CFG of a program.
pub fn control_flow_graph(p: &Program) -> Cfg {
    let n = p.rungs().len() as u32;
    let (start, stop) = (n, n + 1);
    // Callers of each POU.
    let mut callers: Vec<Vec<u32>> = vec![Vec::new(); p.pous().len()];
    let mut found = Vec::new();
    for r in p.rung_ids() {
        found.clear();
        transfers(&p.rung(r).series, &mut found);
        for (t, _) in &found {
            if let Transfer::Call(c) = t {
                if callers[c.index()].last() != Some(&r.raw()) {
                    callers[c.index()].push(r.raw());
                }
            }
        }
    }
    let uncalled: Vec<PouId> = (1..p.pous().len())
        .filter(|&i| callers[i].is_empty())
        .map(|i| p.pous().id(i))
        .collect();
    let mut edges = vec![CfgEdge {
        from: CfgNode(start),
        to: CfgNode(0),
        label: None,
        kind: EdgeKind::Entry,
    }];
    // Edges from `from` to the exit of `pou`.
    let exit = |edges: &mut Vec<CfgEdge>, from: u32, pou: PouId, label, kind| {
        if pou.index() == 0 || callers[pou.index()].is_empty() {
            edges.push(CfgEdge {
                from: CfgNode(from),
                to: CfgNode(stop),
                label,
                kind,
            });
        } else {
            for &c in &callers[pou.index()] {
                edges.push(CfgEdge {
                    from: CfgNode(from),
                    to: CfgNode(c),
                    label,
                    kind: if kind == EdgeKind::Fallthrough {
                        EdgeKind::Return
                    } else {
                        kind
                    },
                });
            }
        }
    };
    for r in p.rung_ids() {
        let rung = p.rung(r);
        let pou = p.pou(rung.pou);
        let next = if r.raw() + 1 < pou.rungs.end {
            Some(r.raw() + 1)
        } else {
            None
        };
        match rung.series.last() {
            Some(Element::For { next: nx, .. }) => {
                edges.push(CfgEdge {
                    from: CfgNode(r.raw()),
                    to: CfgNode(r.raw() + 1),
                    label: Some(Branch::T),
                    kind: EdgeKind::LoopEnter,
                });
                if nx.raw() + 1 < pou.rungs.end {
                    edges.push(CfgEdge {
                        from: CfgNode(r.raw()),
                        to: CfgNode(nx.raw() + 1),
                        label: Some(Branch::F),
                        kind: EdgeKind::LoopExit,
                    });
                } else {
                    exit(
                        &mut edges,
                        r.raw(),
                        rung.pou,
                        Some(Branch::F),
                        EdgeKind::LoopExit,
                    );
                }
                continue;
            }
            Some(Element::Next { head }) => {
                edges.push(CfgEdge {
                    from: CfgNode(r.raw()),
                    to: CfgNode(head.raw()),
                    label: None,
                    kind: EdgeKind::LoopBack,
                });
                continue;
            }
            _ => {}
        }
        found.clear();
        let mut terminated = transfers(&rung.series, &mut found);
        // An unconditional backward jump ends the rung only until the iteration cap refuses it:
        // then the rest of the rung runs, and control may go on past it.
        let capped = ends_in_loop_back(&found, terminated, r);
        if capped {
            found.clear();
            terminated = transfers_refusing(&rung.series, Some(r), &mut found);
        }
        let conditional =
            capped || found.iter().any(|(_, always)| !always) || terminated && found.len() > 1;
        let label = |always: bool| {
            if always && !conditional {
                None
            } else {
                Some(Branch::T)
            }
        };
        for &(t, always) in &found {
            match t {
                Transfer::Jump(target) => edges.push(CfgEdge {
                    from: CfgNode(r.raw()),
                    to: CfgNode(target.raw()),
                    label: label(always),
                    kind: EdgeKind::Jump,
                }),
                Transfer::End => edges.push(CfgEdge {
                    from: CfgNode(r.raw()),
                    to: CfgNode(stop),
                    label: label(always),
                    kind: EdgeKind::End,
                }),
                Transfer::Ret => exit(&mut edges, r.raw(), rung.pou, label(always), EdgeKind::Ret),
                Transfer::Call(c) => {
                    let callee = p.pou(c);
                    if !callee.rungs.is_empty() {
                        edges.push(CfgEdge {
                            from: CfgNode(r.raw()),
                            to: CfgNode(callee.rungs.start),
                            label: label(always),
                            kind: EdgeKind::Call,
                        });
                    }
                }
            }
        }
        if !terminated {
            let fl = if conditional { Some(Branch::F) } else { None };
            let kind = if capped {
                EdgeKind::Refused
            } else {
                EdgeKind::Fallthrough
            };
            match next {
                Some(nx) => edges.push(CfgEdge {
                    from: CfgNode(r.raw()),
                    to: CfgNode(nx),
                    label: fl,
                    kind,
                }),
                None => exit(&mut edges, r.raw(), rung.pou, fl, kind),
            }
        }
    }
    Cfg {
        rungs: n,
        edges,
        uncalled,
    }
}
