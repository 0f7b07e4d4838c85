//! Lowering: an FBD body → ladder [`Rung`]s of the program model, so that the analyses, the
//! report, the interpreter and the parallel executor run FBD unchanged.
//!
//! One rung per block, id `<network>.<block>` (`N1.8`; `G1:N1.8` in the POU of instance `G1`),
//! in the network's execution order; the network's label goes on its first rung. Every output
//! that feeds an arc gets a hidden temp variable `_<block>_<pin>` (`_8_OUT`; prefixed `SBR:` in a
//! subroutine, `G1.` in an instance), written once per run of the block, so arcs are ordinary
//! flow dependences. Timers and counters are read through their instance (`T1.Q`, `T1.ET`).
//!
//! A conditional fragment becomes an `if` block as the FBD text-generation paper generates it: a guard rung
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
//!
//! Invariants: a jump is made only once its target rung is known (a guard's when its landing
//! rung is pushed, a JMP block's when every network's first rung is: [`ForwardJump`]), so no
//! rung ever holds a placeholder target; targets are POU-relative ([`Lowered`]).
//!
//! Not here: names, declarations and scopes (the resolver's, through [`Env`]; it also places
//! the rungs in the program and makes their jump targets absolute); the surface syntax.

mod blocks;
mod fragments;
mod functions;
mod instances;
mod pins;
mod standard;
mod time;
mod typed;

use crate::model::*;
use crate::types::TypedBody;
use plc_diag::{Invalid, LoadError, Origin};
use plc_model::untyped::Untyped;
use plc_model::*;
use std::collections::HashMap;
use std::ops::Range;

type Result<T> = std::result::Result<T, LoadError>;

use crate::ACCUMULATE_PT_MS;

/// What the lowering needs from the reader: names resolved in the POU's scope, new hidden
/// variables.
pub trait Env {
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
pub enum InstanceRef {
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
pub struct Names {
    /// The POU's name, for messages (`undefined label … in P`).
    pub pou: String,
    /// Prepended to rung ids (`G1:` in an instance's POU).
    pub rung_prefix: String,
    /// Prepended to hidden temp names (`SBR:` in a subroutine, `G1.` in an instance).
    pub var_prefix: String,
}

/// A lowered body: rungs with POU-relative jump targets (`RungId(i)` = the POU's `i`-th rung).
pub struct Lowered {
    pub rungs: Vec<Rung>,
    /// Per network: its rungs (POU-relative).
    pub networks: Vec<Range<u32>>,
    /// Per network, per block: its rung (POU-relative).
    pub blocks: Vec<Vec<u32>>,
    /// The body with typed pins, variables as this POU's scope resolves them.
    pub typed: TypedBody<VarRef>,
}

/// Lowers `fbd` in the scope `env` gives.
pub fn lower(fbd: &FbdPou, env: &mut dyn Env, names: &Names, pou: PouId) -> Result<Lowered> {
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
    let mut jumps: Vec<ForwardJump> = Vec::new();
    let mut networks = Vec::with_capacity(fbd.networks.len());
    let mut blocks = Vec::with_capacity(fbd.networks.len());
    let mut typed = Vec::with_capacity(fbd.networks.len());
    for (net, plan) in fbd.networks.iter().zip(&fbd.plans) {
        let start = cx.rungs.len() as u32;
        let (block_rungs, typed_net) = cx.network(net, plan, &labels, &mut jumps)?;
        typed.push(typed_net);
        for rung in &mut cx.rungs[start as usize..] {
            if let Some(from) = &mut rung.lowered {
                from.network = Some(net.id.clone());
            }
        }
        networks.push(start..cx.rungs.len() as u32);
        blocks.push(block_rungs);
    }
    for j in jumps {
        let target = RungId::relative(networks[j.network].start);
        end_with_jump(&mut cx.rungs[j.rung], j.label, target);
    }
    Ok(Lowered {
        rungs: cx.rungs,
        networks,
        blocks,
        typed: TypedBody { networks: typed },
    })
}

/// A JMP block's jump, not yet on its rung: the labelled network may come later, so the jump
/// is made (and its rung ends with it) once every network's first rung is known.
struct ForwardJump {
    /// The JMP block's rung (POU-relative).
    rung: usize,
    label: String,
    /// The network that carries the label.
    network: usize,
}

/// Ends `rung` with a jump to `label`, the rung `target`: a jump is made only once its target
/// is known.
fn end_with_jump(rung: &mut Rung, label: String, target: RungId) {
    rung.series.push(Element::Jmp { label, target });
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

/// A value connected to an input: typed (variable or arc), or a constant waiting for its type
/// (with the input pin it is connected to, whose typed value the lowering records).
#[derive(Clone)]
enum Val {
    Typed(Operand, Type, String),
    Const(Untyped, String, Option<PinSlot>),
}

/// Input pin `.1` of block `.0`.
#[derive(Copy, Clone, Debug, PartialEq, Eq, Hash)]
struct PinSlot(BlockId, usize);

impl Val {
    fn ty(&self) -> Option<Type> {
        match self {
            Val::Typed(_, t, _) => Some(*t),
            Val::Const(u, ..) => u.ty(),
        }
    }
    fn text(&self) -> &str {
        match self {
            Val::Typed(_, _, s) | Val::Const(_, s, _) => s,
        }
    }
}

/// The network being lowered: values of arcs so far.
struct Net<'n> {
    net: &'n Network,
    /// Per block, the block whose result type its first output takes when it writes no
    /// variable: the first block that reads it on an input of the result's type (ADD … MOD,
    /// MOVE, SEL's IN0/IN1, MAX, MIN, LIMIT).
    type_heir: Vec<Option<BlockId>>,
    /// Per block, per output pin: does an arc read it?
    used: Vec<Vec<bool>>,
    /// Per block, per output pin: the operand an arc reads.
    values: Vec<Vec<Option<(Operand, Type)>>>,
    /// The constants connected to input pins, as typed by their blocks.
    constants: HashMap<PinSlot, Value>,
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
        (path, origin): (&str, Origin),
    ) -> usize {
        self.rungs.push(Rung {
            id,
            label,
            comment,
            pou: self.pou,
            series,
            origin,
            lowered: Some(Box::new(LoweredFrom {
                block_path: path.to_owned(),
                network: None,
            })),
        });
        self.rungs.len() - 1
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A scope of BOOL variables `A`, `C`, `E`, `Y` and the hidden ones the lowering adds.
    struct Scope(Arena<VarId, Var>);

    impl Scope {
        fn find(&self, text: &str) -> std::result::Result<VarId, Invalid> {
            match self.0.iter().position(|v| v.name == text) {
                Some(i) => Ok(self.0.id(i)),
                None => Err(Invalid::UndefinedVar {
                    name: text.to_owned(),
                }),
            }
        }
    }

    impl Env for Scope {
        fn lookup(&self, text: &str) -> std::result::Result<(VarRef, Type), Invalid> {
            let var = self.find(text)?;
            Ok((VarRef { var, field: None }, self.0[var.index()].ty))
        }
        fn writable(&self, text: &str, _: &'static str) -> std::result::Result<VarId, Invalid> {
            self.find(text)
        }
        fn instance(&self, text: &str) -> std::result::Result<InstanceRef, Invalid> {
            Err(Invalid::UndefinedVar {
                name: text.to_owned(),
            })
        }
        fn var(&self, v: VarId) -> &Var {
            &self.0[v.index()]
        }
        fn hidden(&mut self, name: String, ty: Type) -> std::result::Result<VarId, Invalid> {
            Ok(self.0.push(Var {
                name,
                ty,
                class: VarClass::Memory,
                init: ty.zero(),
                scope: None,
                hidden: true,
            }))
        }
        fn claim_accumulator(&mut self, _: VarId) -> std::result::Result<(), Invalid> {
            Ok(())
        }
    }

    fn block(id: u32, op: Op, input: Option<&str>, out: Option<&str>, cond: Option<&str>) -> Block {
        Block {
            id,
            op,
            path: String::new(),
            origin: Origin::NONE,
            inputs: input
                .map(|i| InputPin {
                    name: "IN".into(),
                    input: Some(Input::Variable(i.into())),
                    path: String::new(),
                })
                .into_iter()
                .collect(),
            outputs: out
                .map(|o| OutputPin {
                    name: "OUT".into(),
                    vars: vec![(o.into(), String::new())],
                })
                .into_iter()
                .collect(),
            cond: cond.map(|c| Input::Variable(c.into())),
            en: cond.is_some() && out.is_some(),
            after: Vec::new(),
            comment: None,
        }
    }

    fn network(id: &str, label: Option<&str>, blocks: Vec<Block>) -> Network {
        Network {
            id: id.into(),
            label: label.map(str::to_owned),
            comment: None,
            path: String::new(),
            origin: Origin::NONE,
            blocks: blocks.into(),
            roots: Vec::new(),
        }
    }

    fn jump_of(r: &Rung) -> Option<(&str, RungId)> {
        match r.series.last() {
            Some(Element::Jmp { label, target }) => Some((label, *target)),
            _ => None,
        }
    }

    #[test]
    fn jumps_forward_and_over_a_disabled_block_land_on_their_rungs() {
        let jmp = Op::Jmp { label: "L2".into() };
        let networks = vec![
            network(
                "N1",
                None,
                vec![
                    block(1, Op::Move, Some("A"), Some("Y"), Some("E")),
                    block(2, jmp, None, None, Some("C")),
                ],
            ),
            network(
                "N2",
                Some("L2"),
                vec![block(3, Op::Move, Some("A"), Some("Y"), None)],
            ),
        ];
        let plans = networks
            .iter()
            .map(|n| crate::plan(n).expect("a plan"))
            .collect();
        let fbd = FbdPou {
            name: "P".into(),
            kind: FbdPouKind::Main,
            path: String::new(),
            networks,
            plans,
            copies: Vec::new(),
        };
        let bool_var = |name: &str| Var {
            name: name.into(),
            ty: Type::Bool,
            class: VarClass::Memory,
            init: Value::Bool(false),
            scope: None,
            hidden: false,
        };
        let mut scope = Scope(["A", "C", "E", "Y"].map(bool_var).to_vec().into());
        let names = Names {
            pou: "P".into(),
            rung_prefix: String::new(),
            var_prefix: String::new(),
        };
        let lowered = lower(&fbd, &mut scope, &names, PouId::from_raw(0)).expect("lowered");
        let rung = |id: &str| {
            let i = lowered.rungs.iter().position(|r| r.id == id);
            i.unwrap_or_else(|| panic!("no rung {id}"))
        };
        // The JMP block's rung jumps to the first rung of the labelled, later network.
        let jmp = &lowered.rungs[lowered.blocks[0][1] as usize];
        let second = RungId::relative(lowered.networks[1].start);
        assert_eq!(jump_of(jmp), Some(("L2", second)));
        // The EN guard of block 1 jumps to its landing rung, right after the block's rung.
        let guard = &lowered.rungs[rung("N1.1.en")];
        let landing = RungId::relative(rung("N1.1.en.end") as u32);
        assert_eq!(jump_of(guard), Some(("N1.1.en.end", landing)));
        assert_eq!(landing.index(), lowered.blocks[0][0] as usize + 1);
        // Those are the only jumps.
        let jumps = lowered.rungs.iter().filter_map(jump_of).count();
        assert_eq!(jumps, 2);
    }
}
