//! Boolean FBD networks → S7-200 STL through N-ary trees (Zhou & Zhang 2015, "Conversion of
//! PLC function block diagrams to instruction list based on N-ary trees").
//!
//! Each network becomes an N-ary tree held as first child / next sibling links. Leaves are
//! variable reads (negated when a NOT block reads a variable); inner nodes are AND, OR and NOT.
//! A block whose output has one consumer, a block, is part of that block's tree; a node of the
//! same type as its parent is removed and its children lifted (AND under AND), as the paper
//! simplifies. A block whose output feeds several consumers, or writes variables, is a *fork*:
//! the tree is split under a virtual root whose first child computes the fork's value and whose
//! next siblings are its consumers, in order: the variables it writes (`=`, which keeps the top
//! of the stack), then each consumer block with its other inputs and its own consumers, between
//! LPS, LRD … and LPP. A post-order walk emits the instructions: a first leaf loads (LD/LDN), a
//! later leaf ANDs or ORs (A/AN/O/ON), a later inner child is loaded and joined (ALD/OLD).
//!
//! Invariants: every block is emitted exactly once; the order in which the network reads and
//! writes each variable is the FBD execution order's (checked; a network where it would differ
//! is an error). Not here: ops other than AND, OR, NOT, constants, conditional or control arcs,
//! a block fed by two forks (that needs a scratch bit), blocks chained more than [`MAX_DEPTH`]
//! deep (the tree is built and walked by recursion): each an error naming the network and block.

use super::{check, IlError, Names, Net};
use plc_fbd::{BlockId, FbdPou, Input, Network, Op};
use plc_model::{PouId, Program};
use std::collections::HashMap;

/// The longest chain of blocks (each feeding the next) a network may have: the tree's builders
/// and walks recurse along such chains, and the S7-200's own logic stack is 9 bits deep.
const MAX_DEPTH: u32 = 256;

/// A node of the N-ary tree: its kind, first child and next sibling.
#[derive(Clone, Debug)]
struct Node {
    kind: Kind,
    first: Option<usize>,
    next: Option<usize>,
}

#[derive(Clone, Debug, PartialEq)]
enum Kind {
    /// A variable read (negated: through a NOT), with the block that reads it.
    Leaf {
        name: String,
        negated: bool,
        block: BlockId,
    },
    And,
    Or,
    Not,
    /// A virtual root: first child the value, next siblings its consumers.
    Root,
    /// A consumer block of a fork: its op (And, Or, Not), children: its other inputs, then
    /// one `Then` holding its own consumers.
    Apply(Box<Kind>),
    /// The consumers of an `Apply`'s result.
    Then,
    /// `= var`, written by block `block`.
    Out {
        name: String,
        block: BlockId,
    },
}

/// A read (false) or write (true) of a variable by a block, at an instruction index.
type Event = (String, BlockId, bool, usize);

struct Tree<'a> {
    nodes: Vec<Node>,
    net: &'a Network,
    names: &'a Names<'a>,
    pou: PouId,
    /// Per block: the blocks its output feeds (one entry per arc).
    users: Vec<Vec<BlockId>>,
    place: String,
}

/// The networks of an FBD POU: one STL network per FBD network, titled with its id.
pub(super) fn pou(
    p: &Program,
    names: &Names,
    id: PouId,
    f: &FbdPou,
) -> Result<Vec<(String, Net)>, IlError> {
    let _ = p;
    let mut out = Vec::new();
    for (net, plan) in f.networks.iter().zip(&f.plans) {
        let mut t = Tree {
            nodes: Vec::new(),
            net,
            names,
            pou: id,
            users: vec![Vec::new(); net.blocks.len()],
            place: format!("network {}", net.id),
        };
        t.check_blocks()?;
        let mut code = Net::default();
        if let Some(l) = &net.label {
            code.emit("LBL", &[l], 0);
        }
        let mut events = Vec::new();
        for root in t.roots()? {
            let r = t.fork(root)?;
            t.emit(r, &mut code, &mut events);
        }
        check(&t.place, &code)?;
        let order: HashMap<BlockId, usize> = plan
            .order
            .iter()
            .enumerate()
            .map(|(i, b)| (*b, i))
            .collect();
        t.check_order(&events, &order)?;
        out.push((net.id.clone(), code));
    }
    Ok(out)
}

/// The op as the program format names it.
fn op_name(op: &Op) -> String {
    match op {
        Op::Compare(c) => c.name().into(),
        Op::Function(f) => f.name(),
        Op::Arith(a) => a.name().into(),
        Op::And => "AND".into(),
        Op::Or => "OR".into(),
        Op::Xor => "XOR".into(),
        Op::Not => "NOT".into(),
        Op::Move => "MOVE".into(),
        Op::Sel => "SEL".into(),
        Op::Max => "MAX".into(),
        Op::Min => "MIN".into(),
        Op::Limit => "LIMIT".into(),
        Op::Timer { kind, .. } => kind.name().to_uppercase(),
        Op::Ctu { .. } => "CTU".into(),
        Op::Ctd { .. } => "CTD".into(),
        Op::Bistable { kind, .. } => match kind {
            plc_model::BistableKind::SetDominant => "SR".into(),
            plc_model::BistableKind::ResetDominant => "RS".into(),
        },
        Op::Trigger { kind, .. } => match kind {
            plc_model::TriggerKind::Rising => "R_TRIG".into(),
            plc_model::TriggerKind::Falling => "F_TRIG".into(),
        },
        Op::Ctud { .. } => "CTUD".into(),
        Op::Jmp { .. } => "JMP".into(),
        Op::Ret => "RET".into(),
        Op::TStart => "TSTART".into(),
        Op::TStop => "TSTOP".into(),
        Op::Call { fb, .. } => fb.clone(),
    }
}

impl Tree<'_> {
    fn fail<T>(&self, block: Option<BlockId>, message: String) -> Result<T, IlError> {
        let place = match block {
            Some(b) => format!("{} block {}", self.place, self.net.block(b).id),
            None => self.place.clone(),
        };
        Err(IlError { place, message })
    }

    /// Only AND, OR, NOT on variables and arcs, without conditional or control arcs.
    fn check_blocks(&mut self) -> Result<(), IlError> {
        for (b, blk) in self.net.blocks.iter_enumerated() {
            if !matches!(blk.op, Op::And | Op::Or | Op::Not) {
                return self.fail(Some(b), format!("{} is not a boolean logic block: `plc-deps il` translates FBD networks of AND, OR and NOT (not yet: other blocks)", op_name(&blk.op)));
            }
            if blk.cond.is_some() || !blk.after.is_empty() {
                return self.fail(
                    Some(b),
                    "a conditional or control arc has no S7-200 form in one network (not yet)"
                        .into(),
                );
            }
            let word = blk.inputs.iter().find_map(|pin| match &pin.input {
                Some(Input::Variable(v)) if !self.names.may_be_bool(v, self.pou) => Some(v),
                _ => None,
            });
            let word = word.or_else(|| {
                self.writes(b)
                    .iter()
                    .map(|(v, _)| v)
                    .find(|v| !self.names.may_be_bool(v, self.pou))
            });
            if let Some(v) = word {
                return self.fail(
                    Some(b),
                    format!("`{v}` is not a BOOL: `plc-deps il` translates FBD networks of boolean AND, OR and NOT (not yet: the bitwise ANDW, ORW, XORW, INVW of a network; a ladder rung's AND box of INTs is translated)"),
                );
            }
            for pin in &blk.inputs {
                match &pin.input {
                    Some(Input::Arc { from, .. }) => self.users[from.index()].push(b),
                    Some(Input::Variable(_)) => {}
                    _ => return self.fail(
                        Some(b),
                        "a constant input has no S7-200 form (not yet: use SM0.0 or a variable)"
                            .into(),
                    ),
                }
            }
        }
        self.check_depth()
    }

    /// No chain of blocks longer than [`MAX_DEPTH`]: each block's depth (1 + its deepest arc
    /// input's) found by an explicit stack, not by recursion (arcs form no cycle: the resolver
    /// refuses one).
    fn check_depth(&self) -> Result<(), IlError> {
        let n = self.net.blocks.len();
        let mut depth: Vec<Option<u32>> = vec![None; n];
        let arcs = |b: BlockId| {
            self.net
                .block(b)
                .inputs
                .iter()
                .filter_map(|pin| match &pin.input {
                    Some(Input::Arc { from, .. }) => Some(*from),
                    _ => None,
                })
        };
        for i in self.net.blocks.ids() {
            let mut stack = vec![(i, false)];
            while let Some((b, inputs_done)) = stack.pop() {
                if depth[b.index()].is_some() {
                    continue;
                }
                if inputs_done {
                    let d = 1 + arcs(b).filter_map(|f| depth[f.index()]).max().unwrap_or(0);
                    if d > MAX_DEPTH {
                        return self.fail(Some(b), format!("its inputs come through a chain of more than {MAX_DEPTH} blocks: `plc-deps il` translates networks whose blocks chain at most {MAX_DEPTH} deep (not yet: longer ones)"));
                    }
                    depth[b.index()] = Some(d);
                } else {
                    stack.push((b, true));
                    stack.extend(
                        arcs(b)
                            .filter(|f| depth[f.index()].is_none())
                            .map(|f| (f, false)),
                    );
                }
            }
        }
        Ok(())
    }

    fn writes(&self, b: BlockId) -> &[(String, String)] {
        self.net
            .block(b)
            .outputs
            .first()
            .map_or(&[][..], |o| &o.vars[..])
    }

    /// A fork: more than one consumer, or a variable written, or nothing at all.
    fn is_fork(&self, b: BlockId) -> bool {
        self.users[b.index()].len() != 1 || !self.writes(b).is_empty()
    }

    /// The inputs of `b` whose trees hold a fork (at most one is allowed).
    fn fork_input(&self, b: BlockId) -> Result<Option<usize>, IlError> {
        let mut found = None;
        for (k, pin) in self.net.block(b).inputs.iter().enumerate() {
            if let Some(Input::Arc { from, .. }) = &pin.input {
                if self.is_fork(*from) || self.fork_input(*from)?.is_some() {
                    if found.is_some() {
                        return self.fail(Some(b), "two inputs come from blocks whose results are used more than once: one S7-200 network cannot hold both (not yet)".into());
                    }
                    found = Some(k);
                }
            }
        }
        Ok(found)
    }

    /// The forks that no other fork feeds: each is one virtual root of the network.
    fn roots(&self) -> Result<Vec<BlockId>, IlError> {
        let mut roots = Vec::new();
        for b in self.net.blocks.ids() {
            if self.is_fork(b) && self.fork_input(b)?.is_none() {
                roots.push(b);
            }
        }
        Ok(roots)
    }

    fn add(&mut self, kind: Kind, children: Vec<usize>) -> usize {
        for w in children.windows(2) {
            self.nodes[w[0]].next = Some(w[1]);
        }
        self.nodes.push(Node {
            kind,
            first: children.first().copied(),
            next: None,
        });
        self.nodes.len() - 1
    }

    fn children(&self, n: usize) -> Vec<usize> {
        let mut out = Vec::new();
        let mut c = self.nodes[n].first;
        while let Some(i) = c {
            out.push(i);
            c = self.nodes[i].next;
        }
        out
    }

    fn op_kind(&self, b: BlockId) -> Kind {
        match self.net.block(b).op {
            Op::And => Kind::And,
            Op::Or => Kind::Or,
            _ => Kind::Not,
        }
    }

    /// The tree of one input of `b` (a variable or a block that is not a fork).
    fn input(&mut self, b: BlockId, k: usize, negated: bool) -> usize {
        match self.net.block(b).inputs[k].input.clone() {
            Some(Input::Variable(v)) => {
                let name = self.names.named(&v, self.pou);
                self.add(
                    Kind::Leaf {
                        name,
                        negated,
                        block: b,
                    },
                    vec![],
                )
            }
            Some(Input::Arc { from, .. }) => {
                let e = self.expr(from);
                if negated {
                    self.add(Kind::Not, vec![e])
                } else {
                    e
                }
            }
            _ => unreachable!("checked by check_blocks"),
        }
    }

    /// The expression tree of block `b`: NOT of a variable is a negated leaf, a child of the
    /// same type is lifted into its parent.
    fn expr(&mut self, b: BlockId) -> usize {
        let kind = self.op_kind(b);
        let n = self.net.block(b).inputs.len();
        if kind == Kind::Not {
            return self.input(b, 0, true);
        }
        let mut children = Vec::new();
        for k in 0..n {
            let c = self.input(b, k, false);
            if self.nodes[c].kind == kind {
                children.extend(self.children(c));
            } else {
                children.push(c);
            }
        }
        self.add(kind, children)
    }

    /// The virtual root of fork `b`: its value, then its consumers.
    fn fork(&mut self, b: BlockId) -> Result<usize, IlError> {
        let value = self.expr(b);
        let mut children = vec![value];
        children.extend(self.consumers(b)?);
        Ok(self.add(Kind::Root, children))
    }

    /// The consumers of `b`'s result: the variables it writes, then each consumer block.
    fn consumers(&mut self, b: BlockId) -> Result<Vec<usize>, IlError> {
        let mut out = Vec::new();
        for (v, _) in self.writes(b).to_vec() {
            let name = self.names.named(&v, self.pou);
            out.push(self.add(Kind::Out { name, block: b }, vec![]));
        }
        for c in self.users[b.index()].clone() {
            let k = self
                .fork_input(c)?
                .expect("a consumer of a fork has it as fork input");
            let kind = self.op_kind(c);
            let mut children = Vec::new();
            if kind == Kind::Not {
                // nothing else: NOT of the value on top
            } else {
                for j in 0..self.net.block(c).inputs.len() {
                    if j != k {
                        children.push(self.input(c, j, false));
                    }
                }
            }
            let then = self.consumers(c)?;
            children.push(self.add(Kind::Then, then));
            out.push(self.add(Kind::Apply(Box::new(kind)), children));
        }
        Ok(out)
    }

    /// Post-order emission of node `n` (a value is loaded; consumers act on the top).
    fn emit(&self, n: usize, code: &mut Net, ev: &mut Vec<Event>) {
        match &self.nodes[n].kind {
            Kind::Leaf {
                name,
                negated,
                block,
            } => {
                ev.push((name.clone(), *block, false, code.code.len()));
                code.emit(if *negated { "LDN" } else { "LD" }, &[name], 1);
            }
            Kind::And | Kind::Or => {
                let cs = self.children(n);
                self.emit(cs[0], code, ev);
                let is_and = self.nodes[n].kind == Kind::And;
                for &c in &cs[1..] {
                    self.combine(c, is_and, code, ev);
                }
            }
            Kind::Not => {
                let cs = self.children(n);
                self.emit(cs[0], code, ev);
                code.emit("NOT", &[], 0);
            }
            Kind::Root => {
                let cs = self.children(n);
                self.emit(cs[0], code, ev);
                self.emit_consumers(&cs[1..], code, ev);
            }
            Kind::Then => self.emit_consumers(&self.children(n), code, ev),
            Kind::Apply(kind) => {
                let cs = self.children(n);
                let (then, operands) = cs.split_last().expect("an Apply ends with Then");
                match **kind {
                    Kind::Not => code.emit("NOT", &[], 0),
                    ref k => {
                        for &c in operands {
                            self.combine(c, *k == Kind::And, code, ev);
                        }
                    }
                }
                self.emit(*then, code, ev);
            }
            Kind::Out { name, block } => {
                ev.push((name.clone(), *block, true, code.code.len()));
                code.emit("=", &[name], 0);
            }
        }
    }

    /// ANDs or ORs child `c` into the top: a leaf directly, an inner node loaded and joined.
    fn combine(&self, c: usize, and: bool, code: &mut Net, ev: &mut Vec<Event>) {
        if let Kind::Leaf {
            name,
            negated,
            block,
        } = &self.nodes[c].kind
        {
            ev.push((name.clone(), *block, false, code.code.len()));
            let op = match (and, negated) {
                (true, false) => "A",
                (true, true) => "AN",
                (false, false) => "O",
                (false, true) => "ON",
            };
            code.emit(op, &[name], 0);
            return;
        }
        self.emit(c, code, ev);
        code.emit(if and { "ALD" } else { "OLD" }, &[], -1);
    }

    /// The consumers of the value on top: outputs first (they keep it), then the blocks, each
    /// under LPS/LRD/LPP when there are several.
    fn emit_consumers(&self, cs: &[usize], code: &mut Net, ev: &mut Vec<Event>) {
        let (outs, blocks): (Vec<usize>, Vec<usize>) = cs
            .iter()
            .partition(|&&c| matches!(self.nodes[c].kind, Kind::Out { .. }));
        for o in outs {
            self.emit(o, code, ev);
        }
        let k = blocks.len();
        for (i, &b) in blocks.iter().enumerate() {
            if k > 1 {
                match i {
                    0 => code.lps(),
                    _ if i + 1 == k => code.lpp(),
                    _ => code.lrd(),
                }
            }
            self.emit(b, code, ev);
        }
    }

    /// The STL reads and writes each variable in the order the FBD execution order does.
    fn check_order(&self, ev: &[Event], order: &HashMap<BlockId, usize>) -> Result<(), IlError> {
        for (i, a) in ev.iter().enumerate() {
            for b in &ev[i + 1..] {
                if a.0 != b.0 || !(a.2 || b.2) {
                    continue;
                }
                // In FBD a block reads its inputs before it writes its outputs.
                let fa = (order[&a.1], a.2);
                let fb = (order[&b.1], b.2);
                if (fa < fb) != (a.3 < b.3) {
                    return self.fail(None, format!("reads and writes `{}` in an order the S7-200's single pass cannot keep (not yet: split the network)", a.0));
                }
            }
        }
        Ok(())
    }
}
