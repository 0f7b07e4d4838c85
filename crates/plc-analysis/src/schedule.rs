//! The combined schedule: data and control dependences together, loops kept whole — the
//! levelling that a parallel scan can actually run (the correction to Zhao & Yan's two views).
//!
//! Units are *tasks* of the main program: a rung, or a loop — a strongly connected part of the
//! main program's CFG (FOR/NEXT, backward jumps) — run sequentially as one task. Calls are not
//! separate units: a CALL runs its subroutine inside the calling rung's task, so the call and
//! return edges are dropped here and the calling rung's IN/OUT (which include the callee's) stand
//! for it. Main-program rungs that START cannot reach never run and are left out.
//!
//! Contract (what the executor relies on): run the levels in order; inside a level, run every
//! task whose guard holds, in any order or at once; the result equals the sequential scan's.
//! It holds because
//! - tasks are ordered by a topological order of the condensed CFG that keeps program order
//!   wherever the CFG allows; any two tasks that run in the same scan run in this order
//!   sequentially, so data dependences are computed over it;
//! - a task whose execution depends on a decision (a jump, RET/END, a loop's exit) has a *guard*:
//!   the FOW control dependences of the condensed CFG, each "task A ran and left towards
//!   successor B"; it runs iff one of them holds (no guard: it always runs), and it is placed at
//!   a later level than every task that guards it;
//! - a loop task entered at more than one rung also comes after all its possible predecessors,
//!   so that the executor can tell where it was entered.
//!
//! Cost: O(rungs + CFG edges + accesses + control dependences).

use super::accesses::Accesses;
use super::cfg::{Cfg, EdgeKind};
use super::control::{control_dependences, post_dominators, PostDominators};
use super::dependences::Leveller;
use plc_graph::{strongly_connected_components, Csr};
use plc_model::*;
use std::cmp::Reverse;
use std::collections::BinaryHeap;

plc_model::index_type!(
    /// A task of the combined schedule: index into [`Schedule::tasks`].
    TaskId
);

/// Where control goes after a task: another task or the end of the scan.
#[derive(Copy, Clone, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum Successor {
    Task(TaskId),
    Stop,
}

/// One disjunct of a guard: task `controller` ran and left towards `successor`.
#[derive(Copy, Clone, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct Guard {
    pub controller: TaskId,
    pub successor: Successor,
}

/// A unit of the combined schedule.
#[derive(Clone, Debug)]
pub struct Task {
    /// Its rungs, ascending (one for a plain rung).
    pub rungs: Vec<RungId>,
    /// True if the task is a loop (the rungs form a cycle of the CFG).
    pub is_loop: bool,
    /// Rungs where control can enter the task.
    pub entries: Vec<RungId>,
    /// Runs iff any of these holds; empty means always.
    pub guard: Vec<Guard>,
    /// Level, 0-based.
    pub level: u32,
}

/// The combined schedule of a program.
#[derive(Clone, Debug)]
pub struct Schedule {
    /// Tasks in sequential order.
    pub tasks: Vec<Task>,
    /// Task of each rung (main-program rungs that run; `None` otherwise).
    pub task_of: Vec<Option<TaskId>>,
    /// Task indices per level, in sequential order.
    pub levels: Vec<Vec<TaskId>>,
    /// Main-program rungs that can never run.
    pub unreachable: Vec<RungId>,
    /// For each task, the earlier tasks it must wait for (data and control), deduplicated.
    pub preds: Vec<Vec<TaskId>>,
    /// Regions of the main program that can never reach the end of the scan.
    pub endless: Vec<Vec<RungId>>,
}

impl Schedule {
    /// Task `t`.
    pub fn task(&self, t: TaskId) -> &Task {
        &self.tasks[t.index()]
    }
    /// The first rung of task `t` (its name in reports).
    pub fn head(&self, t: TaskId) -> RungId {
        self.task(t).rungs[0]
    }
}

/// Builds the combined schedule from the program, its CFG and its accesses: the live main
/// program's CFG, its strongly connected parts as tasks in a topological order, the condensed
/// CFG's control dependences as guards, then the levels.
pub fn combined_schedule(p: &Program, cfg: &Cfg, acc: &Accesses) -> Schedule {
    let main = p.main().rungs.clone();
    let n = cfg.node_count();
    let (start, stop) = (cfg.start().raw(), cfg.stop().raw());
    let live = live_main_cfg(cfg, main.clone());
    let unreachable: Vec<RungId> = main
        .clone()
        .filter(|&r| !live.reach[r as usize])
        .map(|r| p.rungs().id(r as usize))
        .collect();
    let g = Csr::from_edges(n, &live.edges);
    let sccs = strongly_connected_components(&g);
    let comps = task_components(&sccs, &live, main.clone());
    let mut tasks: Vec<Task> = comps
        .iter()
        .map(|&c| Task {
            rungs: sccs
                .members(c)
                .iter()
                .map(|&m| p.rungs().id(m as usize))
                .collect(),
            is_loop: sccs.is_cyclic(c, &g),
            entries: Vec::new(),
            guard: Vec::new(),
            level: 0,
        })
        .collect();
    let mut task_of_comp: Vec<Option<TaskId>> = vec![None; sccs.len()];
    for (i, &c) in comps.iter().enumerate() {
        task_of_comp[c as usize] = Some(TaskId(i as u32));
    }
    let mut task_of: Vec<Option<TaskId>> = vec![None; p.rungs().len()];
    for r in main.filter(|&r| live.reach[r as usize]) {
        task_of[r as usize] = task_of_comp[sccs.component_of(r) as usize];
    }
    // Condensed CFG over tasks: nodes 0..t, START = t, STOP = t + 1.
    let t = tasks.len() as u32;
    let node = |v: u32| -> u32 {
        if v == start {
            t
        } else if v == stop {
            t + 1
        } else {
            task_of[v as usize].expect("live rung").0
        }
    };
    let condensed = condense(p, &live.edges, node, &mut tasks);
    let endless = guard_tasks(&condensed.edges, &mut tasks);
    let preds = level_tasks(&mut tasks, &condensed.entry_preds, acc, p.vars().len());
    let mut levels: Vec<Vec<TaskId>> = Vec::new();
    for (i, task) in tasks.iter().enumerate() {
        let l = task.level as usize;
        if levels.len() <= l {
            levels.resize(l + 1, Vec::new());
        }
        levels[l].push(TaskId(i as u32));
    }
    for task in &mut tasks {
        task.entries.sort_unstable();
        task.guard.sort_unstable();
    }
    Schedule {
        tasks,
        task_of,
        levels,
        unreachable,
        preds,
        endless,
    }
}

/// The main program's own CFG (no call or return edges) cut down to what START reaches.
struct LiveCfg {
    /// Per CFG node: whether START reaches it.
    reach: Vec<bool>,
    /// The edges leaving reached nodes.
    edges: Vec<(u32, u32)>,
}

/// The live part of the main program's CFG: its edges without calls and returns, from the
/// nodes START reaches. O(nodes + edges).
fn live_main_cfg(cfg: &Cfg, main: std::ops::Range<u32>) -> LiveCfg {
    let n = cfg.node_count();
    let (start, stop) = (cfg.start().raw(), cfg.stop().raw());
    let in_main = |v: u32| main.contains(&v) || v == start || v == stop;
    let edges: Vec<(u32, u32)> = cfg
        .edges
        .iter()
        .filter(|e| {
            !matches!(e.kind, EdgeKind::Call | EdgeKind::Return)
                && in_main(e.from.raw())
                && in_main(e.to.raw())
        })
        .map(|e| (e.from.raw(), e.to.raw()))
        .collect();
    let reach = plc_graph::reachable(&Csr::from_edges(n, &edges), start);
    let edges = edges
        .into_iter()
        .filter(|&(a, _)| reach[a as usize])
        .collect();
    LiveCfg { reach, edges }
}

/// The components of live main rungs (the tasks-to-be), in a topological order of the
/// condensed CFG that keeps program order: by first rung when every condensed edge goes forward
/// in program order (the usual case, O(V)), otherwise Kahn's algorithm preferring the earliest
/// first rung (O(V log V)).
fn task_components(sccs: &plc_graph::Sccs, live: &LiveCfg, main: std::ops::Range<u32>) -> Vec<u32> {
    let comp_count = sccs.len();
    let mut comp_is_task = vec![false; comp_count];
    for r in main.clone().filter(|&r| live.reach[r as usize]) {
        comp_is_task[sccs.component_of(r) as usize] = true;
    }
    let mut indeg = vec![0u32; comp_count];
    // At most one per live edge (sized once: see `direct_dependences`).
    let mut comp_edges: Vec<(u32, u32)> = Vec::with_capacity(live.edges.len());
    for &(a, b) in &live.edges {
        let (ca, cb) = (sccs.component_of(a), sccs.component_of(b));
        if ca != cb && comp_is_task[ca as usize] && comp_is_task[cb as usize] {
            comp_edges.push((ca, cb));
            indeg[cb as usize] += 1;
        }
    }
    let first = |c: u32| sccs.members(c)[0];
    if comp_edges.iter().all(|&(a, b)| first(a) < first(b)) {
        return main
            .filter(|&r| live.reach[r as usize] && first(sccs.component_of(r)) == r)
            .map(|r| sccs.component_of(r))
            .collect();
    }
    let comp_graph = Csr::from_edges(comp_count, &comp_edges);
    let mut heap: BinaryHeap<Reverse<(u32, u32)>> = (0..comp_count as u32)
        .filter(|&c| comp_is_task[c as usize] && indeg[c as usize] == 0)
        .map(|c| Reverse((first(c), c)))
        .collect();
    let mut order = Vec::new();
    while let Some(Reverse((_, c))) = heap.pop() {
        order.push(c);
        for &d in comp_graph.successors(c) {
            indeg[d as usize] -= 1;
            if indeg[d as usize] == 0 {
                heap.push(Reverse((first(d), d)));
            }
        }
    }
    order
}

/// The CFG condensed over tasks.
struct Condensed {
    /// Its edges, sorted, without duplicates or self-loops.
    edges: Vec<(u32, u32)>,
    /// Per task, the tasks with an edge into one of its entries.
    entry_preds: Vec<Vec<u32>>,
}

/// Condenses the live edges over tasks (`node` maps a CFG node to its task, START to `t` and
/// STOP to `t + 1` for `t` tasks) and records each task's entries.
fn condense(
    p: &Program,
    live_edges: &[(u32, u32)],
    node: impl Fn(u32) -> u32,
    tasks: &mut [Task],
) -> Condensed {
    let t = tasks.len() as u32;
    let mut edges: Vec<(u32, u32)> = Vec::with_capacity(live_edges.len());
    let mut entry_preds: Vec<Vec<u32>> = vec![Vec::new(); t as usize];
    for &(a, b) in live_edges {
        let (ca, cb) = (node(a), node(b));
        if ca == cb {
            continue;
        }
        edges.push((ca, cb));
        if cb < t {
            let task = &mut tasks[cb as usize];
            let entry = p.rungs().id(b as usize);
            if !task.entries.contains(&entry) {
                task.entries.push(entry);
            }
            if ca < t {
                entry_preds[cb as usize].push(ca);
            }
        }
    }
    edges.sort_unstable();
    edges.dedup();
    Condensed { edges, entry_preds }
}

/// Gives each task its guard: the control dependences (Ferrante, Ottenstein & Warren, 1987)
/// of the condensed CFG `cedges` (START = `t`, STOP = `t + 1` for `t` tasks), each "task A ran
/// and left towards successor B". Returns the regions that can never reach STOP, as rungs.
fn guard_tasks(cedges: &[(u32, u32)], tasks: &mut [Task]) -> Vec<Vec<RungId>> {
    let t = tasks.len() as u32;
    let (cstart, cstop) = (t, t + 1);
    let pdom: PostDominators = post_dominators(t as usize + 2, cedges, cstop);
    let endless: Vec<Vec<RungId>> = pdom
        .endless
        .iter()
        .map(|region| {
            region
                .iter()
                .filter(|&&c| c < t)
                .flat_map(|&c| tasks[c as usize].rungs.iter().copied())
                .collect()
        })
        .filter(|r: &Vec<RungId>| !r.is_empty())
        .collect();
    for d in control_dependences(cedges, &pdom, |_| true) {
        let (a, b) = cedges[d.edge as usize];
        if a == cstart || d.dependent >= t || d.dependent == a {
            continue;
        }
        let successor = if b == cstop {
            Successor::Stop
        } else {
            Successor::Task(TaskId(b))
        };
        let guard = Guard {
            controller: TaskId(a),
            successor,
        };
        let task = &mut tasks[d.dependent as usize];
        if !task.guard.contains(&guard) {
            task.guard.push(guard);
        }
    }
    endless
}

/// Levels the tasks in task order: each at the lowest level that its data dependences (over
/// the tasks' accesses) and its control floor (after every guarding task and, for a loop
/// entered at several rungs, every task that may enter it) allow. Returns each task's earlier
/// tasks it must wait for. O(accesses + dependences).
fn level_tasks(
    tasks: &mut [Task],
    entry_preds: &[Vec<u32>],
    acc: &Accesses,
    var_count: usize,
) -> Vec<Vec<TaskId>> {
    let t = tasks.len();
    let mut leveller = Leveller::new(var_count);
    let mut preds: Vec<Vec<TaskId>> = vec![Vec::new(); t];
    let mut last_writer: Vec<Option<u32>> = vec![None; var_count];
    // Readers of each variable since its last write, as linked lists in one flat array:
    // `first_reader[x]` → (task, next) in `reader_nodes`.
    let mut first_reader: Vec<Option<u32>> = vec![None; var_count];
    // At most one node per read of a live rung: sized once, so that growing it never holds
    // two copies (at a million rungs it is tens of MB).
    let read_count: usize = tasks
        .iter()
        .flat_map(|t| t.rungs.iter())
        .map(|&r| acc.ins(r).len())
        .sum();
    let mut reader_nodes: Vec<(u32, Option<u32>)> = Vec::with_capacity(read_count);
    let mut reads = Vec::new();
    let mut writes = Vec::new();
    for i in 0..t {
        reads.clear();
        writes.clear();
        for &r in &tasks[i].rungs {
            reads.extend_from_slice(acc.ins(r));
            writes.extend_from_slice(acc.outs(r));
        }
        if tasks[i].rungs.len() > 1 {
            reads.sort_unstable();
            reads.dedup();
            writes.sort_unstable();
            writes.dedup();
        }
        let mut ps: Vec<u32> = tasks[i].guard.iter().map(|g| g.controller.0).collect();
        if tasks[i].entries.len() > 1 {
            ps.extend_from_slice(&entry_preds[i]);
        }
        for &x in &reads {
            ps.extend(last_writer[x.index()]);
        }
        for &x in &writes {
            ps.extend(last_writer[x.index()]);
            let mut node = first_reader[x.index()];
            while let Some(at) = node {
                let (r, next) = reader_nodes[at as usize];
                if r as usize != i {
                    ps.push(r);
                }
                node = next;
            }
        }
        ps.sort_unstable();
        ps.dedup();
        let floor = ps
            .iter()
            .filter(|&&q| (q as usize) < i)
            .map(|&q| tasks[q as usize].level + 1)
            .max()
            .unwrap_or(0);
        tasks[i].level = leveller.place(&reads, &writes, floor);
        for &x in &reads {
            reader_nodes.push((i as u32, first_reader[x.index()]));
            first_reader[x.index()] = Some(reader_nodes.len() as u32 - 1);
        }
        for &x in &writes {
            last_writer[x.index()] = Some(i as u32);
            first_reader[x.index()] = None;
        }
        preds[i] = ps
            .into_iter()
            .filter(|&q| (q as usize) < i)
            .map(TaskId)
            .collect();
    }
    preds
}
