//! LD bodies (TC6 `LD`) → ladder rungs of the syntax: the wiring graph cut into rungs, each
//! rung's series/parallel element tree, rungs in the order the editor runs them.
//!
//! A **rung** is a connected component of the wiring between the rails (the rails themselves do
//! not connect: every rung of a diagram hangs on the same pair). Its **outputs** are the
//! elements whose power goes nowhere but the right rail: coils, out variables, jumps, returns,
//! blocks whose power output is not wired on, and contacts that end a wire. Each output's
//! series from the left rail is computed by [`super::ld_power`]; the series of a rung's outputs
//! are merged where they agree (a shared prefix is one series, where they part a `branch`), so a
//! rung is evaluated once from left to right as in IEC 61131-3 8.2.
//!
//! **Order** (docs/plcopen.md, from Beremiz's `PLCGenerator.ComputeProgram`, which OpenPLC
//! Editor shares): Beremiz emits one statement per coil and out variable in *file order* (since
//! its Python 3 port `SortInstances` no longer sorts), each block just before its first
//! consumer, blocks nothing consumes at the end; `executionOrderId` is not read for LD. So rungs
//! run in the order of their first coil, out variable, jump or return in the file (a rung of
//! blocks only: of its first block), and within a rung the output paths in the order of their
//! outputs — except that an output reading an output of a function block other than its power
//! output (`C1.QD`) goes after the output whose series holds the box, and the series that writes
//! the network feeding a box's data pin goes just before it; a rung whose merge cannot keep
//! those orders is an error. Where the outputs of two rungs interleave in the file, Beremiz's statement order
//! differs from running each rung whole: a note names the rungs. A `label` starts the first rung
//! whose first output follows it in the file.
//!
//! Differences from Beremiz, on purpose (documented): a contact shared by several outputs is read
//! once per rung evaluation, where Beremiz re-reads it for every coil; jumps, labels and returns
//! have their IEC meaning (Beremiz drops them).
//!
//! Deliberately not here: boxes (`super::ld_block`), the OR of parallel wires
//! (`super::ld_power`).

use super::ld_block;
use super::ld_power::{Item, Key, Path, Power};
use super::wiring::{graph, ElemId, Graph};
use super::xml::{attr, error, identifier, origin, Note, Notes, Tc6, R};
use plc_syntax::{Element, ElementKind, Located, Name, Rung, Series};
use roxmltree::Node;

/// Elements of an LD body that are read.
const LD_TAGS: &[&str] = &[
    "leftPowerRail",
    "rightPowerRail",
    "contact",
    "coil",
    "block",
    "inVariable",
    "outVariable",
    "connector",
    "continuation",
    "jump",
    "label",
    "return",
    "comment",
];

/// Reads LD body `node` of POU `pou` into rungs `<pou>.R1`, `<pou>.R2` … in execution order.
pub(super) fn rungs(
    tc6: Tc6,
    node: Node,
    pou: &str,
    inits: &super::block_types::Inits,
    notes: &mut Notes,
) -> R<Vec<Rung<'static>>> {
    let place = format!("pou {pou}, LD");
    let g = graph(tc6, node, &place, notes)?;
    g.only(LD_TAGS, "LD", &place)?;
    for el in &g.elems {
        if let Some(x) = el.node.attribute("executionOrderId") {
            if x.trim() != "0" && el.tag != "block" {
                notes.push(Note {
                    origin: origin(el.node),
                    message: format!("{place}: executionOrderId {x} of {} localId {} is ignored (Beremiz does not read it in LD)", el.tag, el.local_id),
                });
            }
        }
    }
    let mut power = Power::new(&g, place.clone(), ld_block::BLOCKS);
    power.inits = inits.clone();
    let outputs = outputs(&power)?;
    let component = components(&g);
    let groups = groups(&g, &outputs, &component, &place)?;
    let labels = labels(&g, &groups, &place)?;
    let mut out = Vec::with_capacity(groups.len());
    let mut placed = vec![false; g.elems.len()];
    for (r, group) in groups.iter().enumerate() {
        let mut paths = Vec::with_capacity(group.len());
        for &o in group {
            paths.push(output_path(&mut power, o)?);
        }
        let paths = after_their_boxes(&power, group, paths);
        let paths = with_feeds(&mut power, paths);
        check_order(&power, &paths)?;
        for item in paths.iter().flatten() {
            if let Key::Elem(e) = item.key {
                placed[e.0 as usize] = true;
            }
        }
        let refs: Vec<&[Item]> = paths.iter().map(|p| p.as_slice()).collect();
        let ld = merge(&refs);
        let first = origin(g.get(group[0]).node);
        out.push(Rung {
            origin: first,
            id: Located {
                value: format!("{pou}.R{}", r + 1).into(),
                origin: first,
            },
            label: labels[r].clone().map(Box::new),
            comment: None,
            ld,
            ld_origin: first,
            problem: None,
            problem_in_rung: false,
        });
    }
    unplaced(&power, &placed)?;
    notes
        .ld_vars
        .extend(power.vars.drain(..).map(|v| (pou.to_owned(), v)));
    Ok(out)
}

/// An error naming the first box or coil that no output's series holds: a loop of blocks that
/// feed each other with nothing after them (a TP and a TOF blinking each other, a counter
/// whose Q resets it) has no output, and a rung reader that stopped there would drop it.
fn unplaced(p: &Power, placed: &[bool]) -> R<()> {
    let g = p.g;
    for (i, el) in g.elems.iter().enumerate() {
        let boxed = el.tag == "block"
            && !el
                .node
                .attribute("typeName")
                .is_some_and(super::ld_logic::is_logic);
        if (boxed || el.tag == "coil") && !placed[i] {
            let what = el.node.attribute("typeName").unwrap_or(el.tag);
            return Err(error(
                origin(el.node),
                &p.at(ElemId(i as u32)),
                format!(
                    "{what} (localId {}) is on no rung: it feeds a loop of blocks that ends in no coil, out variable or unread block",
                    el.local_id
                ),
            ));
        }
    }
    Ok(())
}

/// The outputs of the body in statement order: coils, out variables, jumps, returns and ending
/// contacts in file order, then blocks whose power output goes nowhere.
fn outputs(p: &Power) -> R<Vec<ElemId>> {
    let g = p.g;
    let feeds_on = |e: usize| {
        g.consumers[e]
            .iter()
            .any(|(c, _, _)| g.get(*c).tag != "rightPowerRail")
    };
    let (mut first, mut last) = (Vec::new(), Vec::new());
    for (i, el) in g.elems.iter().enumerate() {
        let e = ElemId(i as u32);
        match el.tag {
            "jump" | "return" => first.push(e),
            "coil" | "contact" if !feeds_on(i) => first.push(e),
            "outVariable" if !ld_block::absorbed(p, e) => first.push(e),
            "block"
                if !g.consumers[i].iter().any(|(c, _, pin)| {
                    g.get(*c).tag != "rightPowerRail"
                        && !ld_block::absorbed(p, *c)
                        && !ld_block::reads_side(p, e, *pin)
                }) =>
            {
                last.push(e)
            }
            "inVariable" if !feeds_on(i) => {
                return Err(error(
                    origin(el.node),
                    &p.at(e),
                    format!(
                        "inVariable localId {} is not connected to anything",
                        el.local_id
                    ),
                ))
            }
            "inOutVariable" => {
                return Err(error(
                    origin(el.node),
                    &p.at(e),
                    "inOutVariable in an LD body is not supported yet",
                ))
            }
            _ => {}
        }
    }
    first.extend(last);
    Ok(first)
}

/// The outputs' paths reordered so that a path that reads an output of a function block other
/// than its power output (`C1.QD`) comes after the path that holds the block's box: the box is
/// called before its outputs are read, as in the diagram. Otherwise file order is kept; a
/// block whose output feeds back into itself is read before it (its previous value).
fn after_their_boxes(p: &Power, group: &[ElemId], paths: Vec<Path>) -> Vec<Path> {
    let reads: Vec<Vec<ElemId>> = group.iter().map(|&o| side_reads(p, o)).collect();
    if reads.iter().all(Vec::is_empty) {
        return paths;
    }
    let holds = |path: &Path, b: ElemId| path.iter().any(|x| x.key == Key::Elem(b));
    let mut placed: Vec<usize> = Vec::with_capacity(paths.len());
    while placed.len() < paths.len() {
        let ready = (0..paths.len()).find(|&i| {
            !placed.contains(&i)
                && reads[i].iter().all(|&b| {
                    placed.iter().any(|&j| holds(&paths[j], b))
                        || holds(&paths[i], b)
                        || !paths.iter().any(|q| holds(q, b))
                })
        });
        // A feedback loop: the rest in file order.
        let next =
            ready.unwrap_or_else(|| (0..paths.len()).find(|i| !placed.contains(i)).unwrap_or(0));
        placed.push(next);
    }
    let mut paths: Vec<Option<Path>> = paths.into_iter().map(Some).collect();
    placed.iter().filter_map(|&i| paths[i].take()).collect()
}

/// The paths with the series that feed data pins of their boxes ([`Power::feeds`]) put just
/// before the first path that holds the box.
fn with_feeds(p: &mut Power, paths: Vec<Path>) -> Vec<Path> {
    if p.feeds.is_empty() {
        return paths;
    }
    let mut out = Vec::with_capacity(paths.len() + p.feeds.len());
    for path in paths {
        let mut k = 0;
        while k < p.feeds.len() {
            let b = p.feeds[k].0;
            if path.iter().any(|x| x.key == Key::Elem(b)) {
                out.push(p.feeds.remove(k).1);
            } else {
                k += 1;
            }
        }
        out.push(path);
    }
    out
}

/// The order [`merge`] evaluates the paths in: those that end first, then each group of paths
/// with the same next key, groups in the order of their first path.
/// A loop over a stack of groups, not a call per key: a path of 20,000 elements is 20,000
/// steps, not 20,000 nested calls.
fn merged_order(paths: &[Path], idx: Vec<usize>, depth: usize, out: &mut Vec<usize>) {
    let mut work = vec![(idx, depth)];
    while let Some((idx, depth)) = work.pop() {
        let (ended, rest): (Vec<usize>, Vec<usize>) =
            idx.into_iter().partition(|&i| paths[i].len() <= depth);
        out.extend(ended);
        let mut groups: Vec<(&Key, Vec<usize>)> = Vec::new();
        for i in rest {
            let k = &paths[i][depth].key;
            match groups.iter_mut().find(|(g, _)| *g == k) {
                Some((_, g)) => g.push(i),
                None => groups.push((k, vec![i])),
            }
        }
        // The first group on top: groups are taken in order, each whole before the next.
        work.extend(groups.into_iter().rev().map(|(_, g)| (g, depth + 1)));
    }
}

/// An error when merging the paths into one series would evaluate a box before the series
/// that feeds its data pin, or a read of a box's output before the box: sharing a prefix with
/// an earlier output pulls the box ahead, and one left-to-right rung cannot express the order.
fn check_order(p: &Power, paths: &[Path]) -> R<()> {
    let mut order = Vec::with_capacity(paths.len());
    merged_order(paths, (0..paths.len()).collect(), 0, &mut order);
    let rank = |i: usize| order.iter().position(|&j| j == i).unwrap_or(0);
    let first = |pred: &dyn Fn(&Key) -> bool| {
        (0..paths.len())
            .filter(|&i| paths[i].iter().any(|x| pred(&x.key)))
            .min_by_key(|&i| rank(i))
    };
    for b in paths.iter().flatten().filter_map(|x| match x.key {
        Key::Elem(b) if p.g.get(b).tag == "block" => Some(b),
        _ => None,
    }) {
        let boxed = first(&|k| *k == Key::Elem(b));
        let fed = first(&|k| matches!(k, Key::Feed(f, _) if *f == b));
        let read = first(&|k| matches!(k, Key::Pin(f, _) if *f == b));
        let late_feed = matches!((fed, boxed), (Some(f), Some(x)) if rank(f) > rank(x));
        let early_read = matches!((read, boxed), (Some(r), Some(x)) if rank(r) < rank(x) && !paths[r].iter().any(|y| y.key == Key::Elem(b)));
        if late_feed || early_read {
            let el = p.g.get(b);
            return Err(error(
                origin(el.node),
                &p.at(b),
                format!("block localId {} cannot be placed in one left-to-right rung: {}; the rung shares its start with another output that would run it first", el.local_id, if late_feed { "the network feeding one of its data pins must run before it" } else { "an output of it is read by an output that would run before it" }),
            ));
        }
    }
    Ok(())
}

/// The function blocks whose outputs other than the power output feed `o`, through any wiring.
fn side_reads(p: &Power, o: ElemId) -> Vec<ElemId> {
    let mut seen = vec![false; p.g.elems.len()];
    let (mut stack, mut out) = (vec![o], Vec::new());
    while let Some(x) = stack.pop() {
        for s in p.g.get(x).inputs.iter().flat_map(|pin| &pin.sources) {
            if ld_block::reads_side(p, s.elem, s.pin) {
                out.push(s.elem);
            } else if !std::mem::replace(&mut seen[s.elem.0 as usize], true) {
                stack.push(s.elem);
            }
        }
    }
    out
}

/// The series of one output, ending with it.
fn output_path(p: &mut Power, o: ElemId) -> R<Path> {
    let el = p.g.get(o);
    let node = el.node;
    let kind = match el.tag {
        "jump" => {
            let raw = attr(node, "label", &p.at(o))?;
            ElementKind::Jmp(name(identifier(raw, "label", node, &p.at(o))?, node))
        }
        "return" => ElementKind::Ret,
        // An out variable fed by a function block's data output (a CTU's CV, a timer's ET) is
        // assigned that output after the box (as Beremiz generates it), not a coil powered
        // through a contact on it: the output is not BOOL.
        "outVariable" => match data_side_output(p, o)? {
            Some(from) => {
                let to = p.variable(o)?;
                return Ok(vec![Item {
                    key: Key::Elem(o),
                    element: Element {
                        origin: origin(node),
                        kind: ElementKind::Move(Box::new(plc_syntax::Move { from, to })),
                    },
                }]);
            }
            None => return p.out(o, None),
        },
        _ => return p.out(o, None),
    };
    let mut path = p.input(o, 0)?;
    path.push(Item {
        key: Key::Elem(o),
        element: Element {
            origin: origin(node),
            kind,
        },
    });
    Ok(path)
}

/// The field `instance.CV` / `instance.ET` when out variable `o` is fed by one alone: the data
/// outputs of the standard function blocks (IEC 61131-3 2.5.2.3), the others being BOOL.
fn data_side_output(p: &Power, o: ElemId) -> R<Option<plc_syntax::Operand<'static>>> {
    let el = p.g.get(o);
    let [pin] = el.inputs.as_slice() else {
        return Ok(None);
    };
    let [s] = pin.sources.as_slice() else {
        return Ok(None);
    };
    let Some(out) = s.pin.filter(|x| matches!(*x, "CV" | "ET")) else {
        return Ok(None);
    };
    if !ld_block::reads_side(p, s.elem, Some(out)) {
        return Ok(None);
    }
    let src = p.g.get(s.elem).node;
    let here = p.at(s.elem);
    let raw = attr(src, "instanceName", &here)?;
    let instance = identifier(raw, "instance", src, &here)?;
    Ok(Some(Located {
        value: plc_syntax::Scalar::Str(format!("{instance}.{out}").into()),
        origin: origin(el.node),
    }))
}

fn name(s: String, node: Node) -> Name<'static> {
    Located {
        value: s.into(),
        origin: origin(node),
    }
}

/// Merges the outputs' series where they agree: one series while they share their elements, a
/// `branch` where they part (branches in the order of their first output).
fn merge(paths: &[&[Item]]) -> Series<'static> {
    let mut out = Vec::new();
    let mut paths: Vec<&[Item]> = paths.iter().copied().filter(|p| !p.is_empty()).collect();
    loop {
        let mut groups: Vec<(&Key, Vec<&[Item]>)> = Vec::new();
        for p in &paths {
            match groups.iter_mut().find(|(k, _)| *k == &p[0].key) {
                Some((_, g)) => g.push(p),
                None => groups.push((&p[0].key, vec![p])),
            }
        }
        match groups.len() {
            0 => return out,
            1 => {
                out.push(paths[0][0].element.clone());
                paths = paths
                    .iter()
                    .map(|p| &p[1..])
                    .filter(|p| !p.is_empty())
                    .collect();
            }
            _ => {
                let branches = groups
                    .into_iter()
                    .map(|(_, g)| {
                        let mut s = vec![g[0][0].element.clone()];
                        let rests: Vec<&[Item]> = g.iter().map(|p| &p[1..]).collect();
                        s.extend(merge(&rests));
                        s
                    })
                    .collect();
                out.push(Element {
                    origin: paths[0][0].element.origin,
                    kind: ElementKind::Branch(branches),
                });
                return out;
            }
        }
    }
}

/// The connected component of every element (rails excluded: they join nothing).
pub(super) fn components(g: &Graph) -> Vec<usize> {
    let mut parent: Vec<usize> = (0..g.elems.len()).collect();
    fn find(parent: &mut [usize], mut x: usize) -> usize {
        while parent[x] != x {
            parent[x] = parent[parent[x]];
            x = parent[x];
        }
        x
    }
    let rail = |e: usize| matches!(g.elems[e].tag, "leftPowerRail" | "rightPowerRail");
    for (i, el) in g.elems.iter().enumerate() {
        for pin in &el.inputs {
            for s in &pin.sources {
                let j = s.elem.0 as usize;
                if !rail(i) && !rail(j) {
                    let (a, b) = (find(&mut parent, i), find(&mut parent, j));
                    parent[a.max(b)] = a.min(b);
                }
            }
        }
    }
    (0..g.elems.len()).map(|i| find(&mut parent, i)).collect()
}

/// Labels: each starts the first rung whose first output follows it in the file.
fn labels(g: &Graph, groups: &[Vec<ElemId>], place: &str) -> R<Vec<Option<Name<'static>>>> {
    let rungs = groups.len();
    let mut labels: Vec<Option<Name>> = vec![None; rungs];
    // The first output of each rung, by file position.
    let first_at: Vec<usize> = groups
        .iter()
        .map(|gr| gr.iter().map(|o| o.0 as usize).min().unwrap_or(usize::MAX))
        .collect();
    for (i, el) in g.elems.iter().enumerate() {
        if el.tag != "label" {
            continue;
        }
        let here = g.place(place, ElemId(i as u32));
        let raw = attr(el.node, "label", &here)?;
        let label = identifier(raw, "label", el.node, &here)?;
        let target = (0..rungs)
            .filter(|&r| first_at[r] > i)
            .min_by_key(|&r| first_at[r]);
        match target {
            Some(r) if labels[r].is_none() => labels[r] = Some(name(label, el.node)),
            Some(_) => {
                return Err(error(
                    origin(el.node),
                    &here,
                    format!("label `{label}` falls on a rung that already has a label"),
                ))
            }
            None => {
                return Err(error(
                    origin(el.node),
                    &here,
                    format!("label `{label}` has no rung after it in the file"),
                ))
            }
        }
    }
    Ok(labels)
}

/// The outputs grouped into rungs, in execution order. A rung is a component's outputs, in the
/// order of its first. Beremiz runs one statement per coil, out variable, jump and return in
/// file order (PLCGenerator.ComputeProgram), so where the outputs of components interleave in
/// the file, each run of consecutive outputs of one component is a rung of its own (its
/// contacts read again, as Beremiz reads them for each coil). Blocks whose power goes nowhere
/// join the last rung of their component (Beremiz computes them after every statement). A box
/// cannot run once per rung, so a component with a block whose outputs are split is an error,
/// after which the body is read as data flow ([`super::ld_flow`]), which keeps that order.
fn groups(g: &Graph, outputs: &[ElemId], component: &[usize], place: &str) -> R<Vec<Vec<ElemId>>> {
    let mut groups: Vec<Vec<ElemId>> = Vec::new();
    let mut of: Vec<usize> = Vec::new(); // the component of each group
    let mut last_group: std::collections::HashMap<usize, usize> = Default::default();
    let mut split: Option<(ElemId, usize)> = None;
    for &o in outputs.iter().filter(|o| g.get(**o).tag != "block") {
        let c = component[o.0 as usize];
        if of.last() == Some(&c) {
            groups.last_mut().expect("of and groups agree").push(o);
            continue;
        }
        if let Some(&prev) = last_group.get(&c) {
            split.get_or_insert((o, prev));
        }
        groups.push(vec![o]);
        of.push(c);
        last_group.insert(c, groups.len() - 1);
    }
    for &o in outputs.iter().filter(|o| g.get(**o).tag == "block") {
        let c = component[o.0 as usize];
        match last_group.get(&c) {
            Some(&k) => groups[k].push(o),
            None => {
                groups.push(vec![o]);
                of.push(c);
                last_group.insert(c, groups.len() - 1);
            }
        }
    }
    if let Some((o, prev)) = split {
        let c = component[o.0 as usize];
        if let Some(b) =
            (0..g.elems.len()).find(|&i| component[i] == c && g.elems[i].tag == "block")
        {
            let el = g.get(o);
            return Err(error(
                origin(el.node),
                &g.place(place, o),
                format!(
                    "{} localId {} comes in the file after outputs of another rung, and its rung (with rung {} before them) holds block localId {}: Beremiz runs the outputs in file order, which splits the rung, and a box cannot run once per part",
                    el.tag,
                    el.local_id,
                    prev + 1,
                    g.elems[b].local_id
                ),
            ));
        }
    }
    Ok(groups)
}
