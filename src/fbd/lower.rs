//! Lowering: an FBD body → ladder [`Rung`]s of the program model, so that the analyses, the
//! report, the interpreter and the parallel executor run FBD unchanged.
//!
//! One rung per block, id `<network>.<block>` (`N1.8`; `G1:N1.8` in the POU of instance `G1`),
//! in the network's execution order; the network's label goes on its first rung. Every output
//! that feeds an arc gets a hidden temp variable `_<block>_<pin>` (`_8_OUT`; prefixed `SBR:` in a
//! subroutine, `G1.` in an instance), written once per run of the block, so arcs are ordinary
//! flow dependences. Timers and counters are read through their instance (`T1.Q`, `T1.ET`).
//!
//! A conditional fragment becomes an `if` block as seed 000 generates it: a guard rung
//! `<network>.<fragment>` = `[contact cond negated, jmp <landing>]` before its body and an empty
//! landing rung `<network>.<fragment>.end` after it, so the CFG's control dependences inside a
//! network are exactly the fragment tree. A compound fragment tests a hidden run flag
//! `_run_<network>_<fragment>` that the network's first rung resets and the first rung inside each
//! of its source fragments sets. docs/fbd.md gives every block's rung.
//!
//! TSTART/TSTOP (KASKAD's TIME accumulation) use three hidden variables per accumulated TIME
//! variable `V` — `V:acc` (BOOL, accumulating), `V:timer` (TON), `V:last` (TIME, the timer's
//! elapsed time when `V` was last brought up to date) — and one extra rung `acc:V` at the start of
//! the POU: `[contact V:acc, branch [[ton V:timer PT], [V := V − V:last], [V := V + V:timer.ET],
//! [V:last := V:timer.ET]]]`.

use super::model::*;
use crate::model::*;
use crate::read::operand::{self, Untyped};
use crate::read::{Invalid, LoadError};
use std::collections::HashMap;
use std::ops::Range;

type Result<T> = std::result::Result<T, LoadError>;

/// The longest time an accumulation can run (the TIME range): the PT of its hidden TON.
pub const ACCUMULATE_PT_MS: i32 = i32::MAX;

/// What the lowering needs from the reader: names resolved in the POU's scope, new hidden
/// variables.
pub(crate) trait Env {
    /// A name read by a block: variable, instance field (`T1.Q`) or user instance member (`G1.OUT`).
    fn lookup(&self, text: &str) -> std::result::Result<(VarRef, Type), Invalid>;
    /// A variable a block writes.
    fn writable(&self, text: &str, what: &'static str) -> std::result::Result<VarId, Invalid>;
    /// What a block's `instance` names.
    fn instance(&self, text: &str) -> std::result::Result<InstanceRef, Invalid>;
    fn var(&self, v: VarId) -> &Var;
    /// Adds a hidden variable named `name` (refused if the name is taken).
    fn hidden(&mut self, name: String, ty: Type) -> std::result::Result<VarId, Invalid>;
    /// Records that this POU accumulates TIME variable `v` (refused if another POU does).
    fn claim_accumulator(&mut self, v: VarId) -> std::result::Result<(), Invalid>;
}

/// What an `instance` names.
pub(crate) enum InstanceRef {
    /// A TON/TOF/TP/CTU/CTD instance.
    Builtin(VarId, FbKind),
    /// An instance of a user function block type, with its POU and its input and output variables.
    User {
        pou: PouId,
        fb: String,
        inputs: Vec<(String, VarId)>,
        outputs: Vec<(String, VarId)>,
    },
    /// A variable that is no instance (its type, for the message).
    Other(Type),
}

/// Names of the POU being lowered.
pub(crate) struct Names {
    /// The POU's name, for messages (`undefined label … in P`).
    pub pou: String,
    /// Prepended to rung ids (`G1:` in an instance's POU).
    pub rung_prefix: String,
    /// Prepended to hidden temp names (`SBR:` in a subroutine, `G1.` in an instance).
    pub var_prefix: String,
}

/// A lowered body: rungs with POU-relative jump targets (`RungId(i)` = the POU's `i`-th rung).
pub(crate) struct Lowered {
    pub rungs: Vec<Rung>,
    /// Per network: its rungs (POU-relative).
    pub networks: Vec<Range<u32>>,
    /// Per network, per block: its rung (POU-relative).
    pub blocks: Vec<Vec<u32>>,
}

/// Lowers `fbd` in the scope `env` gives.
pub(crate) fn lower(fbd: &FbdPou, env: &mut dyn Env, names: &Names, pou: PouId) -> Result<Lowered> {
    let mut cx = Cx {
        env,
        names,
        pou,
        rungs: Vec::new(),
        accumulators: HashMap::new(),
    };
    let labels: HashMap<&str, usize> = fbd
        .networks
        .iter()
        .enumerate()
        .filter_map(|(i, n)| n.label.as_deref().map(|l| (l, i)))
        .collect();
    cx.accumulator_rungs(fbd)?;
    let mut jumps: Vec<(usize, usize)> = Vec::new();
    let mut networks = Vec::with_capacity(fbd.networks.len());
    let mut blocks = Vec::with_capacity(fbd.networks.len());
    for (net, plan) in fbd.networks.iter().zip(&fbd.plans) {
        let start = cx.rungs.len() as u32;
        let block_rungs = cx.network(net, plan, &labels, &mut jumps)?;
        for rung in &mut cx.rungs[start as usize..] {
            rung.network = Some(net.id.clone());
        }
        networks.push(start..cx.rungs.len() as u32);
        blocks.push(block_rungs);
    }
    for (rung, target) in jumps {
        let t = RungId(networks[target].start);
        set_jump_target(&mut cx.rungs[rung], t);
    }
    Ok(Lowered {
        rungs: cx.rungs,
        networks,
        blocks,
    })
}

fn set_jump_target(rung: &mut Rung, t: RungId) {
    match rung.series.last_mut() {
        Some(Element::Jmp { target, .. }) => *target = t,
        _ => unreachable!("jump rungs end with their jump"),
    }
}

struct Acc {
    acc: VarId,
    timer: VarId,
    last: VarId,
}

struct Cx<'e> {
    env: &'e mut dyn Env,
    names: &'e Names,
    pou: PouId,
    rungs: Vec<Rung>,
    accumulators: HashMap<VarId, Acc>,
}

/// A value connected to an input: typed (variable or arc), or a constant waiting for its type.
#[derive(Clone)]
enum Val {
    Typed(Operand, Type, String),
    Const(Untyped, String),
}

impl Val {
    fn ty(&self) -> Option<Type> {
        match self {
            Val::Typed(_, t, _) => Some(*t),
            Val::Const(u, _) => u.ty(),
        }
    }
    fn text(&self) -> &str {
        match self {
            Val::Typed(_, _, s) | Val::Const(_, s) => s,
        }
    }
}

/// The network being lowered: values of arcs so far.
struct Net<'n> {
    net: &'n Network,
    /// Per block, per output pin: does an arc read it?
    used: Vec<Vec<bool>>,
    /// Per block, per output pin: the operand an arc reads.
    values: Vec<Vec<Option<(Operand, Type)>>>,
}

fn never() -> Element {
    Element::Compare {
        op: CmpOp::Ne,
        a: Operand::Const(Value::Int(0)),
        b: Operand::Const(Value::Int(0)),
    }
}

fn contact(r: VarRef, negated: bool) -> Element {
    Element::Contact {
        var: r,
        kind: if negated {
            ContactKind::Negated
        } else {
            ContactKind::Normal
        },
    }
}

/// Conditions that pass power when the BOOL `o` is TRUE (FALSE when `negated`).
fn condition(o: Operand, negated: bool) -> Vec<Element> {
    match o {
        Operand::Var(r) => vec![contact(r, negated)],
        Operand::Const(Value::Bool(b)) if b != negated => Vec::new(),
        Operand::Const(_) => vec![never()],
    }
}

fn var_op(v: VarId) -> Operand {
    Operand::Var(VarRef {
        var: v,
        field: None,
    })
}

fn field_op(v: VarId, f: Field) -> Operand {
    Operand::Var(VarRef {
        var: v,
        field: Some(f),
    })
}

/// One series, or several run one after another from the same power (a `branch`).
fn steps(mut s: Vec<Series>) -> Series {
    if s.len() == 1 {
        s.pop().expect("one")
    } else {
        vec![Element::Branch(s)]
    }
}

impl Cx<'_> {
    fn push(
        &mut self,
        id: String,
        label: Option<String>,
        comment: Option<String>,
        series: Series,
        path: &str,
    ) -> usize {
        self.rungs.push(Rung {
            id,
            label,
            comment,
            pou: self.pou,
            series,
            path: path.to_owned(),
            network: None,
        });
        self.rungs.len() - 1
    }

    /// The update rungs of every TIME variable this body accumulates, first use first.
    fn accumulator_rungs(&mut self, fbd: &FbdPou) -> Result<()> {
        for (net, plan) in fbd.networks.iter().zip(&fbd.plans) {
            for &b in &plan.order {
                let blk = net.block(b);
                if !matches!(blk.op, Op::TStart | Op::TStop) {
                    continue;
                }
                let v = self.accumulated_var(net, blk)?;
                if self.accumulators.contains_key(&v) {
                    continue;
                }
                let e = |k| LoadError::fbd(&net.id, Some(blk.id), &blk.inputs[0].path, k);
                self.env.claim_accumulator(v).map_err(e)?;
                let name = self.env.var(v).name.clone();
                let acc = self
                    .env
                    .hidden(format!("{name}:acc"), Type::Bool)
                    .map_err(e)?;
                let timer = self
                    .env
                    .hidden(format!("{name}:timer"), Type::Fb(FbKind::Ton))
                    .map_err(e)?;
                let last = self
                    .env
                    .hidden(format!("{name}:last"), Type::Time)
                    .map_err(e)?;
                let pt = Operand::Const(Value::Time(ACCUMULATE_PT_MS));
                let series = vec![
                    contact(
                        VarRef {
                            var: acc,
                            field: None,
                        },
                        false,
                    ),
                    Element::Branch(vec![
                        vec![Element::Timer {
                            kind: TimerKind::Ton,
                            instance: timer,
                            pt,
                        }],
                        vec![Element::Arith {
                            op: ArithOp::Sub,
                            a: var_op(v),
                            b: var_op(last),
                            out: v,
                        }],
                        vec![Element::Arith {
                            op: ArithOp::Add,
                            a: var_op(v),
                            b: field_op(timer, Field::Et),
                            out: v,
                        }],
                        vec![Element::Move {
                            from: field_op(timer, Field::Et),
                            to: last,
                        }],
                    ]),
                ];
                let local = name
                    .strip_prefix(self.names.var_prefix.as_str())
                    .unwrap_or(&name);
                let id = format!("{}acc:{local}", self.names.rung_prefix);
                self.push(
                    id,
                    None,
                    Some(format!(
                        "brings {name} up to date while it accumulates (TSTART/TSTOP)"
                    )),
                    series,
                    &blk.path,
                );
                self.accumulators.insert(v, Acc { acc, timer, last });
            }
        }
        Ok(())
    }

    fn accumulated_var(&self, net: &Network, blk: &Block) -> Result<VarId> {
        let pin = &blk.inputs[0];
        let e = |k| LoadError::fbd(&net.id, Some(blk.id), &pin.path, k);
        let text = match &pin.input {
            Some(Input::Operand(serde_json::Value::String(s))) => s.as_str(),
            Some(Input::Operand(j)) => {
                return Err(e(Invalid::Shape {
                    expected: "a TIME variable",
                    found: super::read::kind_of(j),
                }))
            }
            _ => {
                return Err(e(Invalid::Shape {
                    expected: "a TIME variable",
                    found: "an arc".into(),
                }))
            }
        };
        let v = self.env.writable(text, "TSTART/TSTOP").map_err(e)?;
        let ty = self.env.var(v).ty;
        if ty != Type::Time {
            return Err(e(Invalid::Type {
                what: "TSTART/TSTOP",
                expected: "TIME".into(),
                operand: text.to_owned(),
                found: ty.to_string(),
            }));
        }
        Ok(v)
    }

    /// Lowers one network; returns the rung of each block.
    fn network(
        &mut self,
        net: &Network,
        plan: &Plan,
        labels: &HashMap<&str, usize>,
        jumps: &mut Vec<(usize, usize)>,
    ) -> Result<Vec<u32>> {
        let n = net.blocks.len();
        let mut used: Vec<Vec<bool>> = net
            .blocks
            .iter()
            .map(|b| vec![false; b.outputs.len()])
            .collect();
        for b in &net.blocks {
            for i in b
                .inputs
                .iter()
                .filter_map(|p| p.input.as_ref())
                .chain(b.cond.as_ref())
            {
                if let Input::Arc { from, pin } = i {
                    used[from.index()][*pin as usize] = true;
                }
            }
        }
        let values = net
            .blocks
            .iter()
            .map(|b| vec![None; b.outputs.len()])
            .collect();
        let mut nx = Net { net, used, values };
        let rp = self.names.rung_prefix.clone();
        let e_net = |k| LoadError::fbd(&net.id, None, &net.path, k);
        // Run flags of compound fragments: reset first, set inside each source fragment.
        let mut flags: HashMap<FragmentId, VarId> = HashMap::new();
        let mut sets: HashMap<FragmentId, Vec<VarId>> = HashMap::new();
        let mut pending: Vec<Element> = Vec::new();
        for (f, frag) in plan.fragments.iter().enumerate() {
            if let FragmentKind::Compound(mc) = &frag.kind {
                let name = format!("{}_run_{}_{}", self.names.var_prefix, net.id, frag.name);
                let flag = self.env.hidden(name, Type::Bool).map_err(e_net)?;
                flags.insert(FragmentId(f as u32), flag);
                pending.push(Element::Reset(flag));
                for m in mc {
                    sets.entry(*m).or_default().push(flag);
                }
            }
        }
        let first = self.rungs.len();
        let mut block_rung = vec![u32::MAX; n];
        let mut guards: Vec<usize> = Vec::new();
        for step in &plan.steps {
            match *step {
                Step::Enter(f) => {
                    let frag = &plan.fragments[f.index()];
                    let mut series = match &frag.kind {
                        FragmentKind::Conditional(input) => {
                            let what = "a condition";
                            let o = self.bool_input(&mut nx, None, input, &net.path, what)?;
                            condition(o, true)
                        }
                        FragmentKind::Compound(_) => vec![contact(
                            VarRef {
                                var: flags[&f],
                                field: None,
                            },
                            true,
                        )],
                        FragmentKind::Root => unreachable!("the root is never entered"),
                    };
                    let landing = format!("{rp}{}.{}.end", net.id, frag.name);
                    series.push(Element::Jmp {
                        label: landing,
                        target: RungId(u32::MAX),
                    });
                    series.splice(0..0, pending.drain(..));
                    let comment = Some(format!("if {}", frag.condition));
                    guards.push(self.push(
                        format!("{rp}{}.{}", net.id, frag.name),
                        None,
                        comment,
                        series,
                        &net.path,
                    ));
                    pending.extend(
                        sets.get(&f)
                            .into_iter()
                            .flatten()
                            .map(|&flag| Element::Set(flag)),
                    );
                }
                Step::Block(b) => {
                    let blk = net.block(b);
                    let mut series = self.block(&mut nx, b, labels)?;
                    series.splice(0..0, pending.drain(..));
                    let r = self.push(
                        format!("{rp}{}.{}", net.id, blk.id),
                        None,
                        blk.comment.clone(),
                        series,
                        &blk.path,
                    );
                    if blk.op == Op::Jmp {
                        let target = labels[blk.label.as_deref().expect("a JMP has a label")];
                        jumps.push((r, target));
                    }
                    block_rung[b.index()] = r as u32;
                }
                Step::Leave(f) => {
                    let frag = &plan.fragments[f.index()];
                    let landing = format!("{rp}{}.{}.end", net.id, frag.name);
                    let r = self.push(
                        landing.clone(),
                        Some(landing),
                        None,
                        std::mem::take(&mut pending),
                        &net.path,
                    );
                    let g = guards.pop().expect("entered");
                    set_jump_target(&mut self.rungs[g], RungId(r as u32));
                }
            }
        }
        debug_assert!(pending.is_empty());
        let first_rung = &mut self.rungs[first];
        first_rung.label = net.label.clone();
        if first_rung.comment.is_none() {
            first_rung.comment = net.comment.clone();
        }
        Ok(block_rung)
    }

    // ------------------------------------------------------------------ inputs and outputs

    fn val(&self, nx: &Net, input: &Input, path: &str, block: Option<u32>) -> Result<Val> {
        match input {
            Input::Arc { from, pin } => {
                let src = nx.net.block(*from);
                let (o, t) = nx.values[from.index()][*pin as usize]
                    .expect("arcs come from blocks lowered earlier");
                Ok(Val::Typed(
                    o,
                    t,
                    format!("{}.{}", src.id, src.outputs[*pin as usize].name),
                ))
            }
            Input::Operand(j) => {
                let env = &*self.env;
                let u = operand::parse(j, &|n| env.lookup(n))
                    .map_err(|k| LoadError::fbd(&nx.net.id, block, path, k))?;
                let text = match j {
                    serde_json::Value::String(s) => s.clone(),
                    other => other.to_string(),
                };
                Ok(match u {
                    Untyped::Var(r, t) => Val::Typed(Operand::Var(r), t, text),
                    other => Val::Const(other, text),
                })
            }
        }
    }

    fn coerce(
        &self,
        nx: &Net,
        v: &Val,
        ty: Type,
        what: &'static str,
        path: &str,
        block: Option<u32>,
    ) -> Result<Operand> {
        let e = |k| LoadError::fbd(&nx.net.id, block, path, k);
        match v {
            Val::Typed(o, t, text) if *t != ty => {
                let _ = o;
                Err(e(Invalid::Type {
                    what,
                    expected: ty.to_string(),
                    operand: text.clone(),
                    found: t.to_string(),
                }))
            }
            Val::Typed(o, _, _) => Ok(*o),
            Val::Const(u, text) => operand::typed(u, ty, what, text).map_err(e),
        }
    }

    fn bool_input(
        &self,
        nx: &mut Net,
        block: Option<u32>,
        input: &Input,
        path: &str,
        what: &'static str,
    ) -> Result<Operand> {
        let v = self.val(nx, input, path, block)?;
        self.coerce(nx, &v, Type::Bool, what, path, block)
    }

    /// The variables output pin `pin` of `b` is written to, type-checked against `ty`.
    fn out_vars(&self, nx: &Net, b: BlockId, pin: usize, ty: Option<Type>) -> Result<Vec<VarId>> {
        let blk = nx.net.block(b);
        let mut out = Vec::new();
        for (name, path) in &blk.outputs[pin].vars {
            let e = |k| LoadError::fbd(&nx.net.id, Some(blk.id), path, k);
            let v = self.env.writable(name, "a block output").map_err(e)?;
            let vt = self.env.var(v).ty;
            if let Some(ty) = ty {
                if vt != ty {
                    return Err(e(Invalid::Type {
                        what: "a block output",
                        expected: ty.to_string(),
                        operand: name.clone(),
                        found: vt.to_string(),
                    }));
                }
            }
            out.push(v);
        }
        Ok(out)
    }

    /// A hidden temp `_<block>_<pin>` for output `pin` of `b`, which arcs read from now on.
    fn temp(&mut self, nx: &mut Net, b: BlockId, pin: usize, ty: Type) -> Result<VarId> {
        let blk = nx.net.block(b);
        let name = format!(
            "{}_{}_{}",
            self.names.var_prefix, blk.id, blk.outputs[pin].name
        );
        let t = self
            .env
            .hidden(name, ty)
            .map_err(|k| LoadError::fbd(&nx.net.id, Some(blk.id), &blk.path, k))?;
        nx.values[b.index()][pin] = Some((var_op(t), ty));
        Ok(t)
    }

    /// Where a function-like block computes output `pin`: a temp when an arc reads it, when no
    /// variable takes it, or when the first variable is also an input of a block computed in
    /// several steps (`avoid`); otherwise the first variable. Returns it and the other variables.
    fn dest(
        &mut self,
        nx: &mut Net,
        b: BlockId,
        pin: usize,
        ty: Type,
        avoid: &[Operand],
    ) -> Result<(VarId, Vec<VarId>)> {
        let vars = self.out_vars(nx, b, pin, Some(ty))?;
        let aliased = |v: VarId| avoid.iter().any(|o| o.var() == Some(v));
        if nx.used[b.index()][pin] || vars.is_empty() || aliased(vars[0]) {
            let t = self.temp(nx, b, pin, ty)?;
            Ok((t, vars))
        } else {
            Ok((vars[0], vars[1..].to_vec()))
        }
    }

    // ------------------------------------------------------------------ blocks

    /// The rung series of block `b`.
    fn block(&mut self, nx: &mut Net, b: BlockId, labels: &HashMap<&str, usize>) -> Result<Series> {
        let net = nx.net;
        let blk = net.block(b);
        let id = Some(blk.id);
        let e = |path: &str, k| LoadError::fbd(&net.id, id, path, k);
        // The connected inputs, in pin order.
        let mut vals: Vec<(Val, &str)> = Vec::with_capacity(blk.inputs.len());
        if !matches!(blk.op, Op::TStart | Op::TStop | Op::Call(_)) {
            for pin in &blk.inputs {
                let input = pin
                    .input
                    .as_ref()
                    .expect("built-in ops have every input connected");
                vals.push((self.val(nx, input, &pin.path, id)?, pin.path.as_str()));
            }
        }
        let series = match &blk.op {
            Op::Compare(c) => {
                let ty = numeric_type(&vals, None);
                if !ty.is_numeric() {
                    let (v, p) = vals
                        .iter()
                        .find(|(v, _)| v.ty().is_some())
                        .unwrap_or(&vals[0]);
                    return Err(e(
                        p,
                        Invalid::Type {
                            what: "a comparison",
                            expected: "INT, DINT, REAL or TIME".into(),
                            operand: v.text().to_owned(),
                            found: ty.to_string(),
                        },
                    ));
                }
                let a = self.coerce(nx, &vals[0].0, ty, "a comparison", vals[0].1, id)?;
                let bb = self.coerce(nx, &vals[1].0, ty, "a comparison", vals[1].1, id)?;
                let (d, rest) = self.dest(nx, b, 0, Type::Bool, &[])?;
                let mut s = vec![
                    Element::Compare { op: *c, a, b: bb },
                    Element::Coil {
                        var: d,
                        negated: false,
                    },
                ];
                s.extend(rest.into_iter().map(|v| Element::Coil {
                    var: v,
                    negated: false,
                }));
                s
            }
            Op::Arith(op) => {
                let out_ty = self
                    .out_vars(nx, b, 0, None)?
                    .first()
                    .map(|&v| self.env.var(v).ty);
                let ty = numeric_type(&vals, out_ty);
                let ok = match op {
                    ArithOp::Add | ArithOp::Sub => ty.is_numeric(),
                    ArithOp::Mul | ArithOp::Div => {
                        matches!(ty, Type::Int | Type::Dint | Type::Real)
                    }
                    ArithOp::Mod => matches!(ty, Type::Int | Type::Dint),
                };
                if !ok {
                    let (v, p) = vals
                        .iter()
                        .find(|(v, _)| v.ty().is_some())
                        .unwrap_or(&vals[0]);
                    return Err(e(
                        p,
                        Invalid::Type {
                            what: "this arithmetic block",
                            expected: if *op == ArithOp::Mod {
                                "INT or DINT".into()
                            } else {
                                "a numeric type".into()
                            },
                            operand: v.text().to_owned(),
                            found: ty.to_string(),
                        },
                    ));
                }
                let ops = self.typed_all(nx, &vals, ty, "an arithmetic block", id)?;
                let avoid: &[Operand] = if ops.len() > 2 { &ops[2..] } else { &[] };
                let (d, rest) = self.dest(nx, b, 0, ty, avoid)?;
                let mut s = vec![Element::Arith {
                    op: *op,
                    a: ops[0],
                    b: ops[1],
                    out: d,
                }];
                for o in &ops[2..] {
                    s.push(Element::Arith {
                        op: *op,
                        a: var_op(d),
                        b: *o,
                        out: d,
                    });
                }
                s.extend(moves(d, &rest));
                s
            }
            Op::And | Op::Or | Op::Not => {
                let ops = self.typed_all(nx, &vals, Type::Bool, "a logic block", id)?;
                let (d, rest) = self.dest(nx, b, 0, Type::Bool, &[])?;
                let mut s: Series = match blk.op {
                    Op::And => ops.iter().flat_map(|o| condition(*o, false)).collect(),
                    Op::Or => vec![Element::Or(
                        ops.iter().map(|o| condition(*o, false)).collect(),
                    )],
                    _ => condition(ops[0], true),
                };
                s.push(Element::Coil {
                    var: d,
                    negated: false,
                });
                s.extend(rest.into_iter().map(|v| Element::Coil {
                    var: v,
                    negated: false,
                }));
                s
            }
            Op::Xor => {
                let ops = self.typed_all(nx, &vals, Type::Bool, "a logic block", id)?;
                let (d, rest) = self.dest(
                    nx,
                    b,
                    0,
                    Type::Bool,
                    if ops.len() > 2 { &ops[2..] } else { &[] },
                )?;
                let xor = |a: Operand, bb: Operand| -> Series {
                    let mut l = condition(a, false);
                    l.extend(condition(bb, true));
                    let mut r = condition(a, true);
                    r.extend(condition(bb, false));
                    vec![
                        Element::Or(vec![l, r]),
                        Element::Coil {
                            var: d,
                            negated: false,
                        },
                    ]
                };
                let mut parts = vec![xor(ops[0], ops[1])];
                for o in &ops[2..] {
                    parts.push(xor(var_op(d), *o));
                }
                let mut s = steps(parts);
                s.extend(rest.into_iter().map(|v| Element::Coil {
                    var: v,
                    negated: false,
                }));
                s
            }
            Op::Move => {
                let out_ty = self
                    .out_vars(nx, b, 0, None)?
                    .first()
                    .map(|&v| self.env.var(v).ty);
                let ty = vals[0]
                    .0
                    .ty()
                    .or(out_ty)
                    .unwrap_or_else(|| match &vals[0].0 {
                        Val::Const(u, _) => operand::default_type(u),
                        Val::Typed(_, t, _) => *t,
                    });
                if matches!(ty, Type::Fb(_)) {
                    return Err(e(
                        vals[0].1,
                        Invalid::Type {
                            what: "MOVE",
                            expected: "a value (BOOL, INT, DINT, REAL or TIME)".into(),
                            operand: vals[0].0.text().to_owned(),
                            found: ty.to_string(),
                        },
                    ));
                }
                let a = self.coerce(nx, &vals[0].0, ty, "MOVE", vals[0].1, id)?;
                let (d, rest) = self.dest(nx, b, 0, ty, &[])?;
                let mut s = vec![Element::Move { from: a, to: d }];
                s.extend(moves(d, &rest));
                s
            }
            Op::Sel => {
                let g = self.coerce(nx, &vals[0].0, Type::Bool, "SEL's G", vals[0].1, id)?;
                let out_ty = self
                    .out_vars(nx, b, 0, None)?
                    .first()
                    .map(|&v| self.env.var(v).ty);
                let ty = numeric_type(&vals[1..], out_ty);
                if matches!(ty, Type::Fb(_)) {
                    return Err(e(
                        vals[1].1,
                        Invalid::Type {
                            what: "SEL",
                            expected: "a value (BOOL, INT, DINT, REAL or TIME)".into(),
                            operand: vals[1].0.text().to_owned(),
                            found: ty.to_string(),
                        },
                    ));
                }
                let in0 = self.coerce(nx, &vals[1].0, ty, "SEL", vals[1].1, id)?;
                let in1 = self.coerce(nx, &vals[2].0, ty, "SEL", vals[2].1, id)?;
                let (d, rest) = self.dest(nx, b, 0, ty, &[g, in1])?;
                let mut parts = vec![vec![Element::Move { from: in0, to: d }]];
                let mut second = condition(g, false);
                second.push(Element::Move { from: in1, to: d });
                parts.push(second);
                let mut s = steps(parts);
                s.extend(moves(d, &rest));
                s
            }
            Op::Max | Op::Min | Op::Limit => {
                let out_ty = self
                    .out_vars(nx, b, 0, None)?
                    .first()
                    .map(|&v| self.env.var(v).ty);
                let ty = numeric_type(&vals, out_ty);
                if !ty.is_numeric() {
                    let (v, p) = vals
                        .iter()
                        .find(|(v, _)| v.ty().is_some())
                        .unwrap_or(&vals[0]);
                    return Err(e(
                        p,
                        Invalid::Type {
                            what: "this block",
                            expected: "INT, DINT, REAL or TIME".into(),
                            operand: v.text().to_owned(),
                            found: ty.to_string(),
                        },
                    ));
                }
                let ops = self.typed_all(nx, &vals, ty, blk.op.name_static(), id)?;
                let (d, rest) = self.dest(nx, b, 0, ty, &ops)?;
                let dv = var_op(d);
                let cmp_move = |op: CmpOp, x: Operand| {
                    vec![
                        Element::Compare { op, a: x, b: dv },
                        Element::Move { from: x, to: d },
                    ]
                };
                let parts: Vec<Series> = match blk.op {
                    Op::Limit => vec![
                        vec![Element::Move {
                            from: ops[1],
                            to: d,
                        }],
                        vec![
                            Element::Compare {
                                op: CmpOp::Lt,
                                a: dv,
                                b: ops[0],
                            },
                            Element::Move {
                                from: ops[0],
                                to: d,
                            },
                        ],
                        vec![
                            Element::Compare {
                                op: CmpOp::Gt,
                                a: dv,
                                b: ops[2],
                            },
                            Element::Move {
                                from: ops[2],
                                to: d,
                            },
                        ],
                    ],
                    _ => {
                        let c = if blk.op == Op::Max {
                            CmpOp::Gt
                        } else {
                            CmpOp::Lt
                        };
                        std::iter::once(vec![Element::Move {
                            from: ops[0],
                            to: d,
                        }])
                        .chain(ops[1..].iter().map(|&x| cmp_move(c, x)))
                        .collect()
                    }
                };
                let mut s = steps(parts);
                s.extend(moves(d, &rest));
                s
            }
            Op::Timer(kind) => {
                let inst = self.builtin_instance(nx, b, kind.fb())?;
                let inp = self.coerce(nx, &vals[0].0, Type::Bool, "a timer's IN", vals[0].1, id)?;
                let pt = self.coerce(nx, &vals[1].0, Type::Time, "a timer's PT", vals[1].1, id)?;
                let mut first = condition(inp, false);
                first.push(Element::Timer {
                    kind: *kind,
                    instance: inst,
                    pt,
                });
                self.instance_outputs(
                    nx,
                    b,
                    inst,
                    [(Field::Q, Type::Bool), (Field::Et, Type::Time)],
                    first,
                )?
            }
            Op::Ctu | Op::Ctd => {
                let fb = if blk.op == Op::Ctu {
                    FbKind::Ctu
                } else {
                    FbKind::Ctd
                };
                let inst = self.builtin_instance(nx, b, fb)?;
                let c = self.coerce(
                    nx,
                    &vals[0].0,
                    Type::Bool,
                    "a counter's input",
                    vals[0].1,
                    id,
                )?;
                let r = self.coerce(
                    nx,
                    &vals[1].0,
                    Type::Bool,
                    if fb == FbKind::Ctu {
                        "a counter's reset"
                    } else {
                        "a counter's load"
                    },
                    vals[1].1,
                    id,
                )?;
                let pv = self.coerce(nx, &vals[2].0, Type::Int, "a counter's PV", vals[2].1, id)?;
                let mut first = condition(c, false);
                first.push(if fb == FbKind::Ctu {
                    Element::Ctu {
                        instance: inst,
                        pv,
                        reset: r,
                    }
                } else {
                    Element::Ctd {
                        instance: inst,
                        pv,
                        load: r,
                    }
                });
                self.instance_outputs(
                    nx,
                    b,
                    inst,
                    [(Field::Q, Type::Bool), (Field::Cv, Type::Int)],
                    first,
                )?
            }
            Op::Jmp | Op::Ret => {
                let mut s = match &blk.cond {
                    Some(c) => {
                        let o = self.bool_input(
                            nx,
                            id,
                            c,
                            &format!("{}.cond", blk.path),
                            "a condition",
                        )?;
                        condition(o, false)
                    }
                    None => Vec::new(),
                };
                if blk.op == Op::Jmp {
                    let label = blk.label.clone().expect("a JMP has a label");
                    if !labels.contains_key(label.as_str()) {
                        return Err(e(
                            &format!("{}.label", blk.path),
                            Invalid::UndefinedLabel {
                                label,
                                pou: self.names.pou.clone(),
                            },
                        ));
                    }
                    s.push(Element::Jmp {
                        label,
                        target: RungId(u32::MAX),
                    });
                } else {
                    s.push(Element::Ret);
                }
                s
            }
            Op::TStart | Op::TStop => {
                let v = self.accumulated_var(net, blk)?;
                let a = &self.accumulators[&v];
                let acc = VarRef {
                    var: a.acc,
                    field: None,
                };
                let pt = Operand::Const(Value::Time(ACCUMULATE_PT_MS));
                let timer = Element::Timer {
                    kind: TimerKind::Ton,
                    instance: a.timer,
                    pt,
                };
                if blk.op == Op::TStart {
                    vec![Element::Branch(vec![
                        vec![
                            contact(acc, true),
                            Element::Set(a.acc),
                            Element::Move {
                                from: Operand::Const(Value::Time(0)),
                                to: a.last,
                            },
                        ],
                        vec![contact(acc, false), timer],
                    ])]
                } else {
                    vec![Element::Reset(a.acc), contact(acc, false), timer]
                }
            }
            Op::Call(fb) => self.call(nx, b, fb)?,
        };
        Ok(series)
    }

    fn typed_all(
        &self,
        nx: &Net,
        vals: &[(Val, &str)],
        ty: Type,
        what: &'static str,
        id: Option<u32>,
    ) -> Result<Vec<Operand>> {
        vals.iter()
            .map(|(v, p)| self.coerce(nx, v, ty, what, p, id))
            .collect()
    }

    fn builtin_instance(&self, nx: &Net, b: BlockId, fb: FbKind) -> Result<VarId> {
        let blk = nx.net.block(b);
        let path = format!("{}.instance", blk.path);
        let name = blk.instance.as_deref().expect("checked by the reader");
        let e = |k| LoadError::fbd(&nx.net.id, Some(blk.id), &path, k);
        match self.env.instance(name).map_err(e)? {
            InstanceRef::Builtin(v, k) if k == fb => Ok(v),
            other => Err(e(Invalid::Type {
                what: "this block",
                expected: format!("a {} instance", Type::Fb(fb)),
                operand: name.to_owned(),
                found: instance_type(&other),
            })),
        }
    }

    /// A timer or counter rung: `first` (its condition and box), then its outputs: arcs read the
    /// instance's fields; variables get moves.
    fn instance_outputs(
        &mut self,
        nx: &mut Net,
        b: BlockId,
        inst: VarId,
        fields: [(Field, Type); 2],
        first: Series,
    ) -> Result<Series> {
        let mut parts = vec![first];
        for (pin, (f, ty)) in fields.into_iter().enumerate() {
            nx.values[b.index()][pin] = Some((field_op(inst, f), ty));
            for v in self.out_vars(nx, b, pin, Some(ty))? {
                parts.push(vec![Element::Move {
                    from: field_op(inst, f),
                    to: v,
                }]);
            }
        }
        Ok(steps(parts))
    }

    /// A user function block call: inputs moved into the instance, `call`, outputs moved out.
    fn call(&mut self, nx: &mut Net, b: BlockId, fb: &str) -> Result<Series> {
        let net = nx.net;
        let blk = net.block(b);
        let id = Some(blk.id);
        let path = format!("{}.instance", blk.path);
        let name = blk.instance.as_deref().expect("checked by the reader");
        let e = |k| LoadError::fbd(&net.id, id, &path, k);
        let (pou, inputs, outputs) = match self.env.instance(name).map_err(e)? {
            InstanceRef::User {
                pou,
                fb: t,
                inputs,
                outputs,
            } if t == fb => (pou, inputs, outputs),
            other => {
                return Err(e(Invalid::Type {
                    what: "this block",
                    expected: format!("a {fb} instance"),
                    operand: name.to_owned(),
                    found: instance_type(&other),
                }))
            }
        };
        let mut s = Vec::new();
        for (pin, (_, var)) in blk.inputs.iter().zip(&inputs) {
            if let Some(input) = &pin.input {
                let ty = self.env.var(*var).ty;
                let v = self.val(nx, input, &pin.path, id)?;
                let from = self.coerce(nx, &v, ty, "a function block input", &pin.path, id)?;
                s.push(Element::Move { from, to: *var });
            }
        }
        s.push(Element::Call { pou });
        for (pin, (_, var)) in outputs.iter().enumerate() {
            let ty = self.env.var(*var).ty;
            let vars = self.out_vars(nx, b, pin, Some(ty))?;
            if nx.used[b.index()][pin] {
                let t = self.temp(nx, b, pin, ty)?;
                s.push(Element::Move {
                    from: var_op(*var),
                    to: t,
                });
            }
            s.extend(vars.into_iter().map(|v| Element::Move {
                from: var_op(*var),
                to: v,
            }));
        }
        Ok(s)
    }
}

fn instance_type(i: &InstanceRef) -> String {
    match i {
        InstanceRef::Builtin(_, k) => Type::Fb(*k).to_string(),
        InstanceRef::User { fb, .. } => fb.clone(),
        InstanceRef::Other(t) => t.to_string(),
    }
}

fn moves(from: VarId, to: &[VarId]) -> impl Iterator<Item = Element> + '_ {
    to.iter().map(move |&v| Element::Move {
        from: var_op(from),
        to: v,
    })
}

/// The type of a numeric operation: the first input that has one, else `fallback` (the output
/// variable's), else REAL if a constant is REAL, else DINT (as ladder compares do).
fn numeric_type(vals: &[(Val, &str)], fallback: Option<Type>) -> Type {
    if let Some(t) = vals.iter().find_map(|(v, _)| v.ty()) {
        return t;
    }
    if let Some(t) = fallback {
        return t;
    }
    let real = vals
        .iter()
        .any(|(v, _)| matches!(v, Val::Const(u, _) if operand::default_type(u) == Type::Real));
    if real {
        Type::Real
    } else {
        Type::Dint
    }
}

impl Op {
    /// The op name for messages that need a `&'static str`.
    fn name_static(&self) -> &'static str {
        match self {
            Op::Max => "MAX",
            Op::Min => "MIN",
            Op::Limit => "LIMIT",
            _ => "this block",
        }
    }
}
