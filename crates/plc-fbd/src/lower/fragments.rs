//! One network → rungs: blocks in execution order, each conditional fragment an `if` block
//! (guard rung, landing rung), compound fragments tested through their run flags.

use super::{condition, contact, end_with_jump, Cx, ForwardJump, Net, Result};
use crate::model::*;
use crate::types::TypedNetwork;
use plc_diag::LoadError;
use plc_model::*;
use std::collections::HashMap;

impl Cx<'_> {
    /// Lowers one network; returns the rung of each block and the network's typed form. A
    /// guard rung gets its jump when its landing rung is made; a JMP block's jump goes to
    /// `jumps`, as the labelled network may come later.
    pub(super) fn network(
        &mut self,
        net: &Network,
        plan: &Plan,
        labels: &HashMap<&str, usize>,
        jumps: &mut Vec<ForwardJump>,
    ) -> Result<(Vec<u32>, TypedNetwork<VarRef>)> {
        let n = net.blocks.len();
        let mut used: Vec<Vec<bool>> = net
            .blocks
            .iter()
            .map(|b| vec![false; b.outputs.len()])
            .collect();
        // Per block, the first block (in block order) whose result has the type of what its
        // first output feeds into it (`Net::type_heir`).
        let mut type_heir: Vec<Option<BlockId>> = vec![None; n];
        for (c, b) in net.blocks.iter().enumerate() {
            for (k, p) in b.inputs.iter().enumerate() {
                if let Some(Input::Arc { from, pin: 0 }) = p.input {
                    let passes = match b.op {
                        Op::Arith(_) | Op::Move | Op::Max | Op::Min | Op::Limit => true,
                        Op::Sel => k > 0,
                        _ => false,
                    };
                    if passes && type_heir[from.index()].is_none() {
                        type_heir[from.index()] = Some(net.blocks.id(c));
                    }
                }
            }
        }
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
        let mut nx = Net {
            net,
            type_heir,
            used,
            values,
            constants: HashMap::new(),
        };
        let rp = self.names.rung_prefix.clone();
        let e_net = |k| LoadError::fbd(&net.id, None, &net.path, k);
        // Run flags of compound fragments: reset first, set inside each source fragment.
        let mut flags: HashMap<FragmentId, VarId> = HashMap::new();
        let mut sets: HashMap<FragmentId, Vec<VarId>> = HashMap::new();
        let mut pending: Vec<Element> = Vec::new();
        for (f, frag) in plan.fragments.iter_enumerated() {
            if let FragmentKind::Compound(mc) = &frag.kind {
                let name = format!("{}_run_{}_{}", self.names.var_prefix, net.id, frag.name);
                let flag = self.env.hidden(name, Type::Bool).map_err(e_net)?;
                flags.insert(f, flag);
                pending.push(Element::Reset(flag));
                for m in mc {
                    sets.entry(*m).or_default().push(flag);
                }
            }
        }
        let first = self.rungs.len();
        let mut block_rung: Vec<Option<u32>> = vec![None; n];
        // The guard rungs entered and not yet left, with their landings' labels.
        let mut guards: Vec<(usize, String)> = Vec::new();
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
                    series.splice(0..0, pending.drain(..));
                    let comment = Some(format!("if {}", frag.condition));
                    let g = self.push(
                        format!("{rp}{}.{}", net.id, frag.name),
                        None,
                        comment,
                        series,
                        (&net.path, net.origin),
                    );
                    guards.push((g, landing));
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
                    // EN (IEC 61131-3 2.5.1.2): an `if` around this block alone.
                    let gate = match (&blk.cond, blk.en) {
                        (Some(c), true) => self.en_guard(&mut nx, b, c)?,
                        _ => None,
                    };
                    let landing = format!("{rp}{}.{}.en.end", net.id, blk.id);
                    let gated = gate.is_some();
                    if let Some(mut guard) = gate {
                        guard.splice(0..0, pending.drain(..));
                        let g = self.push(
                            format!("{rp}{}.{}.en", net.id, blk.id),
                            None,
                            Some(format!("if EN of {}", blk.id)),
                            guard,
                            (&blk.path, blk.origin),
                        );
                        guards.push((g, landing.clone()));
                    }
                    series.splice(0..0, pending.drain(..));
                    let r = self.push(
                        format!("{rp}{}.{}", net.id, blk.id),
                        None,
                        blk.comment.clone(),
                        series,
                        (&blk.path, blk.origin),
                    );
                    if let Op::Jmp { label } = &blk.op {
                        // Checked by the block's lowering: the label is defined.
                        if let Some(&network) = labels.get(label.as_str()) {
                            jumps.push(ForwardJump {
                                rung: r,
                                label: label.clone(),
                                network,
                            });
                        }
                    }
                    block_rung[b.index()] = Some(r as u32);
                    if gated {
                        let end = self.push(
                            landing.clone(),
                            Some(landing),
                            None,
                            Vec::new(),
                            (&blk.path, blk.origin),
                        );
                        let (g, label) = guards.pop().expect("pushed above");
                        end_with_jump(&mut self.rungs[g], label, RungId::relative(end as u32));
                    }
                }
                Step::Leave(f) => {
                    let frag = &plan.fragments[f.index()];
                    let landing = format!("{rp}{}.{}.end", net.id, frag.name);
                    let r = self.push(
                        landing.clone(),
                        Some(landing),
                        None,
                        std::mem::take(&mut pending),
                        (&net.path, net.origin),
                    );
                    let (g, label) = guards.pop().expect("entered");
                    end_with_jump(&mut self.rungs[g], label, RungId::relative(r as u32));
                }
            }
        }
        debug_assert!(pending.is_empty());
        let first_rung = &mut self.rungs[first];
        first_rung.label = net.label.clone();
        if first_rung.comment.is_none() {
            first_rung.comment = net.comment.clone();
        }
        let block_rung = block_rung
            .into_iter()
            .map(|r| r.expect("a plan's steps hold every block of its network once"))
            .collect();
        Ok((block_rung, self.typed_network(&nx)))
    }

    /// The guard of block `b` whose EN is `en`: the series that is powered when EN is FALSE
    /// (the caller adds the jump over the block). A disabled function's outputs that arcs read
    /// take their type's initial value there, as matiec's `TEST_EN` returns `__INIT_<type>`
    /// (lib/C/iec_std_functions.h) into the temporary Beremiz assigns; a function block keeps
    /// its outputs (its body returns at once). `None` when EN is the constant TRUE.
    fn en_guard(&mut self, nx: &mut Net, b: BlockId, en: &Input) -> Result<Option<Series>> {
        let blk = nx.net.block(b);
        let path = format!("{}.en", blk.path);
        let o = self.bool_input(nx, Some(blk.id), en, &path, "EN")?;
        if o == Operand::Const(Value::Bool(true)) {
            return Ok(None);
        }
        let mut guard = condition(o, true);
        let function = !matches!(
            blk.op,
            Op::Timer { .. }
                | Op::Ctu { .. }
                | Op::Ctd { .. }
                | Op::Ctud { .. }
                | Op::Bistable { .. }
                | Op::Trigger { .. }
                | Op::Call { .. }
                | Op::Jmp { .. }
                | Op::Ret
                | Op::TStart
                | Op::TStop
        );
        if function {
            for (pin, v) in nx.values[b.index()].iter().enumerate() {
                if let (true, Some((Operand::Var(r), ty))) = (nx.used[b.index()][pin], v) {
                    if r.field.is_none() {
                        guard.push(match ty {
                            Type::Bool => Element::Reset(r.var),
                            _ => Element::Move {
                                from: Operand::Const(ty.zero()),
                                to: r.var,
                            },
                        });
                    }
                }
            }
        }
        Ok(Some(guard))
    }
}
