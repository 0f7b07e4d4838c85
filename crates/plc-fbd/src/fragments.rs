//! Conditional fragments of a network (the FBD text-generation paper) and the regrouped execution order.
//!
//! Blocks are taken in topological order. A block's *data fragment* FD is the deepest fragment
//! among those of the blocks it depends on: its data arcs, its conditional arc and a control arc
//! with one source (which only orders). Then:
//! - a block with a conditional arc (`cond`, except on JMP and RET, whose `cond` is their own
//!   condition) goes to the fragment conditional on that arc under FD: the first such block creates
//!   it (`F(3)`: conditional on block 3's output), later ones with the same arc and FD join it;
//! - a block with a compound control arc (`after` with several sources) goes to the fragment FC
//!   that runs when at least one of the sources' fragments MC ran, a child of their deepest common
//!   ancestor FP; blocks with the same MC share it (fragments of MC inside another one of MC
//!   are dropped first: when the inner one ran, so did the outer; if one fragment is left, the
//!   arc only orders);
//! - any other block joins FD.
//!
//! Then the rule: a block may depend (data arc, conditional arc, one-source control arc) only on
//! blocks of its own fragment or of its ancestors; otherwise the paper's generator refuses the
//! network, naming both blocks and fragments.
//!
//! Regrouping: inside each fragment, its own blocks and its child fragments (each as one item)
//! are put in a topological order of the arcs between them, ties broken by the topological
//! position of the item's first block. So every fragment is contiguous, a child fragment comes
//! after every block it depends on — a compound fragment after all of MC — and otherwise keeps
//! the place of its first block (the seed's generator writes nested fragments at the end of their
//! parent; placing them as early as their arcs allow keeps them before a later RET or JMP of the
//! parent, which the seed's dialect does not have). If the items of a fragment form a cycle — a
//! compound control arc reduced to an outer fragment orders a block after a nested fragment that
//! depends on it — the nested fragment cannot stay contiguous: an error names the arcs.
//! Cost: O((V + E) log V + E·depth).

use super::model::*;
use plc_diag::{Invalid, LoadError};
use std::cmp::Reverse;
use std::collections::{BinaryHeap, HashMap};

/// Builds the fragment tree of `net` from its topological order and regroups the order.
pub fn fragments(net: &Network, topological: Vec<BlockId>) -> Result<Plan, LoadError> {
    let n = net.blocks.len();
    let mut t = Tree {
        frags: vec![Fragment {
            name: "root".into(),
            parent: None,
            depth: 0,
            kind: FragmentKind::Root,
            condition: "always".into(),
            blocks: Vec::new(),
        }],
    };
    let mut of: Vec<FragmentId> = vec![FragmentId::new(0); n];
    let mut conditional: HashMap<(FragmentId, String), FragmentId> = HashMap::new();
    let mut compound: HashMap<Vec<FragmentId>, FragmentId> = HashMap::new();
    let mut names: HashMap<String, u32> = HashMap::new();
    names.insert("root".into(), 1);
    let mut compounds = 0u32;

    for &v in &topological {
        let b = net.block(v);
        let mut deps: Vec<(BlockId, &'static str)> = Vec::new();
        for pin in &b.inputs {
            if let Some(Input::Arc { from, .. }) = &pin.input {
                deps.push((*from, "reads an output of"));
            }
        }
        if let Some(Input::Arc { from, .. }) = &b.cond {
            deps.push((*from, "takes its condition from"));
        }
        let mut mc: Vec<FragmentId> = Vec::new();
        if b.after.len() == 1 {
            deps.push((b.after[0], "runs after"));
        } else {
            mc = b.after.iter().map(|a| of[a.index()]).collect();
            mc.sort_unstable();
            mc.dedup();
            let all = mc.clone();
            mc.retain(|&f| !all.iter().any(|&g| g != f && t.is_ancestor(g, f)));
        }
        // The data fragment: the deepest among the dependences (first one on ties).
        let mut fd = FragmentId::new(0);
        let candidates = deps
            .iter()
            .map(|(d, _)| of[d.index()])
            .chain(if mc.len() == 1 { Some(mc[0]) } else { None });
        for f in candidates {
            if t.depth(f) > t.depth(fd) {
                fd = f;
            }
        }
        let own_cond = b.cond.as_ref().filter(|_| b.cond_opens_fragment());
        let frag = if let Some(cond) = own_cond {
            if mc.len() >= 2 {
                return Err(LoadError::fbd(
                    &net.id,
                    Some(b.id),
                    &format!("{}.cond", b.path),
                    Invalid::Misplaced {
                        what: "`cond`",
                        place: "together with a compound `after` (one control input per block)",
                    },
                ));
            }
            let key = (fd, cond_key(cond));
            match conditional.get(&key) {
                Some(&f) => f,
                None => {
                    let (base, condition) = conditional_name(net, cond);
                    let f = t.add(
                        unique(&mut names, base),
                        fd,
                        FragmentKind::Conditional(cond.clone()),
                        condition,
                    );
                    conditional.insert(key, f);
                    f
                }
            }
        } else if mc.len() >= 2 {
            match compound.get(&mc) {
                Some(&f) => f,
                None => {
                    let fp = mc.iter().skip(1).fold(mc[0], |a, &f| t.lca(a, f));
                    compounds += 1;
                    let base = if compounds == 1 {
                        "FC".to_string()
                    } else {
                        format!("FC{compounds}")
                    };
                    let condition = mc
                        .iter()
                        .map(|f| t.frags[f.index()].name.clone())
                        .collect::<Vec<_>>()
                        .join(" OR ");
                    let f = t.add(
                        unique(&mut names, base),
                        fp,
                        FragmentKind::Compound(mc.clone()),
                        condition,
                    );
                    compound.insert(mc, f);
                    f
                }
            }
        } else {
            fd
        };
        of[v.index()] = frag;
        for &(d, how) in &deps {
            let fdep = of[d.index()];
            if !t.is_ancestor(fdep, frag) {
                return Err(LoadError::fbd(
                    &net.id,
                    Some(b.id),
                    &b.path,
                    Invalid::FragmentRule {
                        block: b.id,
                        fragment: t.frags[frag.index()].name.clone(),
                        how,
                        dep: net.block(d).id,
                        dep_fragment: t.frags[fdep.index()].name.clone(),
                    },
                )
                .with_hint(&fragment_rule_fix(how, b.id, net.block(d).id)));
            }
        }
    }

    let steps = regroup(net, &topological, &of, &t)?;
    let order: Vec<BlockId> = steps
        .iter()
        .filter_map(|s| {
            if let Step::Block(b) = s {
                Some(*b)
            } else {
                None
            }
        })
        .collect();
    let mut frags = t.frags;
    for &b in &order {
        frags[of[b.index()].index()].blocks.push(b);
    }
    Ok(Plan {
        topological,
        order,
        fragments: plc_model::Arena::from(frags),
        fragment_of: of,
        steps,
    })
}

/// The shortest fix of a fragment-rule violation (block `block` depends, `how`, on block `dep` of
/// a fragment that may not have run): a value or condition goes through a variable, which keeps
/// its last value in the scans where `dep` does not run; a one-source control arc, which only
/// orders, is dropped.
fn fragment_rule_fix(how: &str, block: u32, dep: u32) -> String {
    if how == "runs after" {
        format!("remove the control arc from block {dep} to block {block}: block {dep} does not run in every scan that runs block {block}, so it cannot order it")
    } else {
        format!("write that output of block {dep} to a variable and use the variable in block {block} instead of the arc: it keeps its last value in the scans where block {dep} does not run")
    }
}

struct Tree {
    frags: Vec<Fragment>,
}

impl Tree {
    fn depth(&self, f: FragmentId) -> u32 {
        self.frags[f.index()].depth
    }
    fn parent(&self, f: FragmentId) -> Option<FragmentId> {
        self.frags[f.index()].parent
    }
    fn add(
        &mut self,
        name: String,
        parent: FragmentId,
        kind: FragmentKind,
        condition: String,
    ) -> FragmentId {
        let id = FragmentId::new(self.frags.len() as u32);
        let depth = self.depth(parent) + 1;
        self.frags.push(Fragment {
            name,
            parent: Some(parent),
            depth,
            kind,
            condition,
            blocks: Vec::new(),
        });
        id
    }
    /// `a` is `b` or an ancestor of `b`.
    fn is_ancestor(&self, a: FragmentId, mut b: FragmentId) -> bool {
        while self.depth(b) > self.depth(a) {
            b = self.parent(b).expect("non-root has a parent");
        }
        a == b
    }
    fn lca(&self, mut a: FragmentId, mut b: FragmentId) -> FragmentId {
        while self.depth(a) > self.depth(b) {
            a = self.parent(a).expect("non-root");
        }
        while self.depth(b) > self.depth(a) {
            b = self.parent(b).expect("non-root");
        }
        while a != b {
            a = self.parent(a).expect("non-root");
            b = self.parent(b).expect("non-root");
        }
        a
    }
    /// The child of `l` on the way down to its descendant `f` (`f != l`).
    fn child_toward(&self, l: FragmentId, mut f: FragmentId) -> FragmentId {
        while self.parent(f) != Some(l) {
            f = self.parent(f).expect("f is below l");
        }
        f
    }
}

/// The error when the items of a fragment form a cycle (every unsorted item has a predecessor
/// among the unsorted ones): walk predecessors until one repeats, and name that cycle's arcs.
/// This happens when a compound control arc, reduced to an outer fragment, orders a block after
/// a nested fragment some of whose blocks depend on that block: the nested fragment would have to
/// be split.
fn split_error(
    net: &Network,
    t: &Tree,
    edges: &[(usize, usize, BlockId, BlockId)],
    indeg: &[u32],
    n: usize,
) -> LoadError {
    let pending = |i: usize| indeg[i] > 0;
    let start = edges
        .iter()
        .find(|e| pending(e.1))
        .map(|e| e.1)
        .expect("an unsorted item");
    let mut path: Vec<usize> = Vec::new(); // indices into `edges`, walking backwards
    let mut seen: HashMap<usize, usize> = HashMap::new();
    let mut at = start;
    let cycle = loop {
        if let Some(&k) = seen.get(&at) {
            break path[k..].to_vec();
        }
        seen.insert(at, path.len());
        let e = edges
            .iter()
            .position(|e| e.1 == at && pending(e.0))
            .expect("a pending item has a pending predecessor");
        path.push(e);
        at = edges[e].0;
    };
    let id = |b: BlockId| net.block(b).id;
    let arcs: Vec<String> = cycle
        .iter()
        .rev()
        .map(|&e| format!("{} → {}", id(edges[e].2), id(edges[e].3)))
        .collect();
    let fragment = cycle
        .iter()
        .flat_map(|&e| [edges[e].0, edges[e].1])
        .find(|&i| i >= n)
        .map_or_else(|| "?".to_string(), |i| t.frags[i - n].name.clone());
    let block = id(edges[cycle[0]].3);
    LoadError::fbd(
        &net.id,
        Some(block),
        &net.block(edges[cycle[0]].3).path,
        Invalid::FragmentSplit {
            fragment,
            arcs: arcs.join(", "),
        },
    )
}

/// The name (`F(3)`, `F(5.ET)`, `F(Var)`) and the condition text of the fragment conditional
/// on `cond`.
fn conditional_name(net: &Network, cond: &Input) -> (String, String) {
    match cond {
        Input::Arc { from, pin } => {
            let src = net.block(*from);
            let pin_name = &src.outputs[*pin as usize].name;
            let base = if *pin == 0 {
                format!("F({})", src.id)
            } else {
                format!("F({}.{pin_name})", src.id)
            };
            (base, format!("{}.{pin_name}", src.id))
        }
        Input::Variable(v) => (format!("F({v})"), v.clone()),
        Input::Constant(c) => {
            let text = c.text();
            (format!("F({text})"), text)
        }
    }
}

fn cond_key(i: &Input) -> String {
    match i {
        Input::Arc { from, pin } => format!("#{}:{pin}", from.raw()),
        Input::Variable(v) => format!("v:{v}"),
        Input::Constant(c) => format!("c:{}", c.text()),
    }
}

fn unique(names: &mut HashMap<String, u32>, base: String) -> String {
    let count = names.entry(base.clone()).or_insert(0);
    *count += 1;
    if *count == 1 {
        base
    } else {
        format!("{base}#{count}")
    }
}

/// The regrouped order as nested steps (see the module documentation).
fn regroup(
    net: &Network,
    topological: &[BlockId],
    of: &[FragmentId],
    t: &Tree,
) -> Result<Vec<Step>, LoadError> {
    let n = net.blocks.len();
    let nf = t.frags.len();
    let mut pos = vec![0usize; n];
    for (i, b) in topological.iter().enumerate() {
        pos[b.index()] = i;
    }
    // Items: blocks 0..n, fragments n..n+nf. Priority: topological position of the first block.
    let mut first = vec![usize::MAX; nf];
    for b in 0..n {
        let f = of[b].index();
        first[f] = first[f].min(pos[b]);
    }
    for f in (1..nf).rev() {
        let p = t.frags[f].parent.expect("non-root").index();
        first[p] = first[p].min(first[f]);
    }
    let prio = |item: usize| if item < n { pos[item] } else { first[item - n] };
    let mut members: Vec<Vec<usize>> = vec![Vec::new(); nf];
    for b in 0..n {
        members[of[b].index()].push(b);
    }
    for f in 1..nf {
        members[t.frags[f].parent.expect("non-root").index()].push(n + f);
    }
    // Per fragment: (item, item, block arc it comes from).
    let mut edges: Vec<Vec<(usize, usize, BlockId, BlockId)>> = vec![Vec::new(); nf];
    for v in 0..n {
        for u in net.predecessors(BlockId::new(v as u32)) {
            let (a, b) = (of[u.index()], of[v]);
            let l = t.lca(a, b);
            let iu = if a == l {
                u.index()
            } else {
                n + t.child_toward(l, a).index()
            };
            let iv = if b == l {
                v
            } else {
                n + t.child_toward(l, b).index()
            };
            if iu != iv {
                edges[l.index()].push((iu, iv, u, BlockId::new(v as u32)));
            }
        }
    }
    // Kahn per fragment, smallest priority first.
    let mut indeg = vec![0u32; n + nf];
    let mut succ: HashMap<usize, Vec<usize>> = HashMap::new();
    let mut sorted: Vec<Vec<usize>> = vec![Vec::new(); nf];
    for f in 0..nf {
        succ.clear();
        for &(a, b, _, _) in &edges[f] {
            indeg[b] += 1;
            succ.entry(a).or_default().push(b);
        }
        let mut heap: BinaryHeap<Reverse<(usize, usize)>> = members[f]
            .iter()
            .filter(|&&i| indeg[i] == 0)
            .map(|&i| Reverse((prio(i), i)))
            .collect();
        while let Some(Reverse((_, i))) = heap.pop() {
            sorted[f].push(i);
            if let Some(next) = succ.get(&i) {
                for &j in next {
                    indeg[j] -= 1;
                    if indeg[j] == 0 {
                        heap.push(Reverse((prio(j), j)));
                    }
                }
            }
        }
        if sorted[f].len() < members[f].len() {
            return Err(split_error(net, t, &edges[f], &indeg, n));
        }
        for &i in &members[f] {
            indeg[i] = 0;
        }
    }
    // Emit depth first.
    let mut steps = Vec::with_capacity(n + 2 * nf);
    let mut stack: Vec<(usize, usize)> = vec![(0, 0)];
    while let Some(top) = stack.last_mut() {
        let (f, i) = *top;
        if let Some(&item) = sorted[f].get(i) {
            top.1 += 1;
            if item < n {
                steps.push(Step::Block(BlockId::new(item as u32)));
            } else {
                steps.push(Step::Enter(FragmentId::new((item - n) as u32)));
                stack.push((item - n, 0));
            }
        } else {
            if f != 0 {
                steps.push(Step::Leave(FragmentId::new(f as u32)));
            }
            stack.pop();
        }
    }
    Ok(steps)
}
