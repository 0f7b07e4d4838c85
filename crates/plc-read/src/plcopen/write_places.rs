//! Where an out variable or a coil of a data-flow body (FBD, or LD read as data flow) is
//! written: at its own statement, as Beremiz's generator writes it.
//!
//! Beremiz (`PLCGenerator.ComputeProgram`) emits one statement `X := <expression>` per out
//! variable and coil, in its statement order, and computes a block the first time a statement
//! reads it: a function's result goes into a temporary (`_TMP_ADD5_OUT`), a function block's
//! output is read from the instance (`TON0.Q`) by the statement. So `X` changes at its statement,
//! not when the block that feeds it runs. The readers attach `X` to the output of the block that
//! feeds it (the block writes it when it runs), which is the same thing unless something that
//! runs between the block and `X`'s statement reads or writes `X`: then this pass moves the
//! write into a MOVE of the block's output placed at the statement (so `X` is read with last
//! scan's value until then, as matiec's C reads it).
//!
//! Input: the network's blocks and its statements in Beremiz's order (a block to run, or the
//! write of the target whose origin is the statement's element). Output: the network's roots
//! (docs/fbd.md `order`), the statements' blocks in order. The run order simulated here is the
//! one `plc_fbd::order` makes of the roots (depth-first, predecessors by increasing id), so the
//! decision holds for the order that runs.
//!
//! Conservative on purpose: a block between the two places that calls user code (a user
//! function, a function block that is not a standard one: it may read `X` as a global), or a
//! jump or return, counts as touching `X`. Not moved: a write held by a block with EN (Beremiz
//! writes it under `IF ENO`, which the EN block models already).

use super::block_types::Ctx;
use super::pins::Added;
use plc_diag::Origin;
use plc_syntax::fbd::{Block, Connection, Input, Inputs, OutVar, Outputs, Targets};
use std::borrow::Cow;
use std::collections::HashMap;

/// One statement of Beremiz's order.
#[derive(Copy, Clone, Debug, PartialEq, Eq, Hash)]
pub(super) enum Statement {
    /// Compute a block (a block nothing reads, a jump, a return).
    Run(u32),
    /// Write the out variable or coil whose element is at this origin, with its localId.
    Write { at: Origin, local_id: u32 },
}

/// The roots of the network of `blocks` whose statements are `statements`, after moving each
/// write that must happen at its statement to that place (new blocks and variables in `added`;
/// `ctx` gives the variables' types and tells the blocks that run user code).
pub(super) fn place_writes(
    blocks: &mut Vec<Block<'static>>,
    statements: &[Statement],
    added: &mut Added,
    ctx: &Ctx,
) -> Vec<u32> {
    let index: HashMap<u32, usize> = blocks
        .iter()
        .enumerate()
        .filter_map(|(i, b)| b.id.as_ref().ok().map(|&id| (id, i)))
        .collect();
    // Who holds each write: target origin → (block index, pin, variable).
    let mut holder: HashMap<Origin, (usize, Option<String>, String)> = HashMap::new();
    for (i, b) in blocks.iter().enumerate() {
        for (pin, t) in targets(b) {
            holder.insert(t.origin, (i, pin.map(str::to_owned), t.name.to_string()));
        }
    }
    // The run order of the statements, as plc_fbd::order makes it from these roots.
    let preds: Vec<Vec<usize>> = blocks
        .iter()
        .map(|b| {
            let mut p: Vec<usize> = inputs(b)
                .filter_map(|i| match &i.from {
                    Connection::Arc { block, .. } => index.get(block).copied(),
                    _ => None,
                })
                .chain(
                    b.after
                        .iter()
                        .flat_map(|a| a.iter().flatten())
                        .flat_map(|a| a.iter())
                        .filter_map(|id| index.get(id).copied()),
                )
                .collect();
            p.sort_unstable_by_key(|&j| blocks[j].id.as_ref().ok().copied());
            p.dedup();
            p
        })
        .collect();
    // Every run and every write statement gets the next tick of one clock.
    let mut ran_at: Vec<Option<usize>> = vec![None; blocks.len()];
    let mut runs: Vec<(usize, usize)> = Vec::new(); // (tick, block index)
    let mut clock = 0usize;
    let mut grey = vec![false; blocks.len()];
    let mut run = |root: usize, ran_at: &mut Vec<Option<usize>>, clock: &mut usize| {
        if ran_at[root].is_some() {
            return;
        }
        let mut stack = vec![(root, 0usize)];
        grey[root] = true;
        while let Some(top) = stack.last_mut() {
            let (v, k) = *top;
            if let Some(&p) = preds[v].get(k) {
                top.1 += 1;
                if ran_at[p].is_none() && !grey[p] {
                    grey[p] = true;
                    stack.push((p, 0));
                }
            } else {
                ran_at[v] = Some(*clock);
                runs.push((*clock, v));
                *clock += 1;
                stack.pop();
            }
        }
    };
    // Each write statement: (its origin and localId, holder index, the holder's tick, the
    // statement's tick).
    let mut writes: Vec<(Origin, u32, usize, usize, usize)> = Vec::new();
    for s in statements {
        match *s {
            Statement::Run(id) => {
                if let Some(&i) = index.get(&id) {
                    run(i, &mut ran_at, &mut clock);
                }
            }
            Statement::Write { at, local_id } => {
                if let Some((i, _, _)) = holder.get(&at) {
                    run(*i, &mut ran_at, &mut clock);
                    let r = ran_at[*i].expect("just ran");
                    writes.push((at, local_id, *i, r, clock));
                    clock += 1;
                }
            }
        }
    }
    // What each run touches: variables by lower-case base name, or everything; and the ticks
    // at which a statement's variable may be written (its holder's and its own).
    let mut touches: HashMap<String, Vec<usize>> = HashMap::new();
    let mut touch_all: Vec<usize> = Vec::new();
    for &(tick, i) in &runs {
        let b = &blocks[i];
        let op =
            b.op.as_ref()
                .map(|o| o.to_ascii_uppercase())
                .unwrap_or_default();
        if matches!(op.as_str(), "JMP" | "RET") || calls_user_code(ctx, b) {
            touch_all.push(tick);
        }
        for i in inputs(b) {
            if let Connection::Variable(v) = &i.from {
                touches.entry(base(v)).or_default().push(tick);
            }
        }
    }
    for &(at, _, _, r, w) in &writes {
        touches
            .entry(base(&holder[&at].2))
            .or_default()
            .extend([r, w]);
    }
    for v in touches.values_mut() {
        v.sort_unstable();
    }
    let between = |list: Option<&Vec<usize>>, lo: usize, hi: usize| {
        list.is_some_and(|l| {
            let k = l.partition_point(|&p| p <= lo);
            k < l.len() && l[k] < hi
        })
    };
    // A write to move: the holder writes a temporary of the variable's type instead (so the
    // block's generic typing is as before), and a MOVE at the statement copies it.
    let mut moved: HashMap<Origin, u32> = HashMap::new();
    for &(at, local_id, i, r, w) in &writes {
        let (_, _, var) = &holder[&at];
        let key = base(var);
        if blocks[i].en || !(between(touches.get(&key), r, w) || between(Some(&touch_all), r, w)) {
            continue;
        }
        let Some(ty) = ctx.vars.get(&var.to_ascii_lowercase()) else {
            continue;
        };
        let temp = format!(
            "{}__{local_id}",
            var.replace(|c: char| !c.is_ascii_alphanumeric(), "_")
        );
        let Some(target) = retarget(&mut blocks[i], at, &temp) else {
            continue;
        };
        added.declare(&temp, ty, target.origin);
        let id = added.next_id;
        added.next_id += 1;
        let from = Input {
            origin: target.origin,
            from: Connection::Variable(Cow::Owned(temp)),
        };
        let at_target = target.origin;
        blocks.push(super::pins::move_block(id, from, target, at_target));
        moved.insert(at, id);
    }
    statements
        .iter()
        .filter_map(|s| match *s {
            Statement::Run(id) => index.contains_key(&id).then_some(id),
            Statement::Write { at, .. } => moved.get(&at).copied().or_else(|| {
                let (i, ..) = holder.get(&at)?;
                blocks[*i].id.as_ref().ok().copied()
            }),
        })
        .collect()
}

/// True when `b` runs code of the project (a user function, an instance of a function block
/// that is not a standard one), which may read or write any variable it sees.
pub(super) fn calls_user_code(ctx: &Ctx, b: &Block) -> bool {
    let Ok(op) = &b.op else { return true };
    ctx.functions.contains_key(op.as_ref())
        || (b.instance.is_some() && !super::black_box::is_standard_fb(op))
}

/// The origins of the variables `b`'s outputs write (the statements that may be its).
pub(super) fn target_origins(b: &Block<'static>) -> Vec<Origin> {
    targets(b).into_iter().map(|(_, t)| t.origin).collect()
}

/// A variable's base name in lower case: `a` of `a.b`, `a[3]`, `A`.
fn base(v: &str) -> String {
    let end = v.find(['.', '[']).unwrap_or(v.len());
    v[..end].trim().to_ascii_lowercase()
}

/// The inputs of `b`, its condition included.
fn inputs<'b>(b: &'b Block<'static>) -> impl Iterator<Item = &'b Input<'static>> {
    let listed: Vec<&Input<'static>> = match &b.inputs {
        Some(Ok(Inputs::List(v))) => v.iter().collect(),
        Some(Ok(Inputs::Named(v))) => v.iter().map(|(_, i)| i).collect(),
        _ => Vec::new(),
    };
    listed.into_iter().chain(b.cond.iter())
}

/// The variables `b`'s outputs write, each with its pin's name (`None`: the first output).
fn targets<'b>(b: &'b Block<'static>) -> Vec<(Option<&'b str>, &'b OutVar<'static>)> {
    let mut out = Vec::new();
    match &b.outputs {
        Some(Ok(Outputs::First(t))) => out.push((None, t)),
        Some(Ok(Outputs::List(v))) => out.extend(v.iter().flatten().flatten().map(|t| (None, t))),
        Some(Ok(Outputs::Named(v))) => {
            for (pin, ts) in v {
                match ts {
                    Ok(Targets::One(t)) => out.push((Some(pin.as_ref()), t)),
                    Ok(Targets::Many(ts)) => {
                        out.extend(ts.iter().flatten().map(|t| (Some(pin.as_ref()), t)))
                    }
                    Err(_) => {}
                }
            }
        }
        _ => {}
    }
    out
}

/// Renames the target at `at` of `b`'s outputs to `temp`; the target as it was.
fn retarget(b: &mut Block<'static>, at: Origin, temp: &str) -> Option<OutVar<'static>> {
    let t: &mut OutVar<'static> = match &mut b.outputs {
        Some(Ok(Outputs::First(t))) if t.origin == at => t,
        Some(Ok(Outputs::List(v))) => v.iter_mut().flatten().flatten().find(|t| t.origin == at)?,
        Some(Ok(Outputs::Named(v))) => v.iter_mut().find_map(|(_, ts)| match ts {
            Ok(Targets::One(t)) if t.origin == at => Some(t),
            Ok(Targets::Many(list)) => list.iter_mut().flatten().find(|t| t.origin == at),
            _ => None,
        })?,
        _ => return None,
    };
    let was = t.clone();
    t.name = Cow::Owned(temp.to_owned());
    Some(was)
}

#[cfg(test)]
mod tests {
    use super::super::block_types::Sig;
    use super::*;

    fn at(k: usize) -> Origin {
        Origin::at(k)
    }

    fn var(name: &'static str) -> Input<'static> {
        Input {
            origin: Origin::NONE,
            from: Connection::Variable(Cow::Borrowed(name)),
        }
    }

    fn arc(block: u32) -> Input<'static> {
        Input {
            origin: Origin::NONE,
            from: Connection::Arc { block, pin: None },
        }
    }

    /// Block `id` running `op` on `inputs`, its output OUT writing `writes` (name, origin).
    fn block(
        id: u32,
        op: &'static str,
        inputs: Vec<Input<'static>>,
        writes: &[(&'static str, usize)],
    ) -> Block<'static> {
        let targets = writes
            .iter()
            .map(|&(n, k)| {
                Ok(OutVar {
                    origin: at(k),
                    name: Cow::Borrowed(n),
                })
            })
            .collect::<Vec<_>>();
        Block {
            origin: Origin::NONE,
            id: Ok(id),
            op: Ok(Cow::Borrowed(op)),
            inputs: Some(Ok(Inputs::List(inputs))),
            outputs: (!targets.is_empty()).then(|| {
                Ok(Outputs::Named(vec![(
                    Cow::Borrowed("OUT"),
                    Ok(Targets::Many(targets)),
                )]))
            }),
            instance: None,
            label: None,
            cond: None,
            en: false,
            after: None,
            comment: None,
            problem: None,
        }
    }

    fn ctx() -> Ctx {
        let mut c = Ctx::default();
        for v in ["x", "y", "z"] {
            c.vars.insert(v.to_owned(), "INT".to_owned());
        }
        c
    }

    fn write(k: usize) -> Statement {
        Statement::Write {
            at: at(k),
            local_id: k as u32,
        }
    }

    fn added() -> Added {
        Added {
            next_id: 100,
            blocks: Vec::new(),
            vars: Vec::new(),
            elements: Default::default(),
        }
    }

    #[test]
    fn a_write_read_between_its_block_and_its_statement_moves_to_the_statement() {
        // Y := GT(ADD(X, 1)) (statement 8) runs ADD 5; Z := X (statement 9, MOVE 7) reads X;
        // X := ADD's OUT (statement 10) must come after it.
        let mut blocks = vec![
            block(5, "ADD", vec![var("X")], &[("X", 10)]),
            block(6, "GT", vec![arc(5)], &[("Y", 8)]),
            block(7, "MOVE", vec![var("X")], &[("Z", 9)]),
        ];
        let mut a = added();
        let roots = place_writes(
            &mut blocks,
            &[write(8), write(9), write(10)],
            &mut a,
            &ctx(),
        );
        assert_eq!(roots, vec![6, 7, 100]);
        assert_eq!(blocks.len(), 4);
        assert_eq!(
            targets(&blocks[0])[0].1.name,
            "X__10",
            "ADD writes the temporary"
        );
        assert_eq!(targets(&blocks[3])[0].1.name, "X", "the MOVE writes X");
        assert_eq!(a.vars.len(), 1);
        assert_eq!(a.vars[0].ty.value, "INT");
    }

    #[test]
    fn a_write_nothing_reads_in_between_stays_on_its_block() {
        // The same without the reader of X in between: Z := Y instead.
        let mut blocks = vec![
            block(5, "ADD", vec![var("X")], &[("X", 10)]),
            block(6, "GT", vec![arc(5)], &[("Y", 8)]),
            block(7, "MOVE", vec![var("Y")], &[("Z", 9)]),
        ];
        let mut a = added();
        let roots = place_writes(
            &mut blocks,
            &[write(8), write(9), write(10)],
            &mut a,
            &ctx(),
        );
        assert_eq!(roots, vec![6, 7, 5]);
        assert_eq!(blocks.len(), 3);
        assert!(a.vars.is_empty());
    }

    #[test]
    fn user_code_or_a_jump_in_between_counts_as_a_read() {
        for (op, user) in [("MyFun", true), ("JMP", false)] {
            let mut c = ctx();
            if user {
                c.functions.insert(
                    op.to_owned(),
                    Sig {
                        inputs: vec![],
                        outputs: vec![],
                    },
                );
            }
            let mut blocks = vec![
                block(5, "ADD", vec![var("X")], &[("X", 10)]),
                block(6, "GT", vec![arc(5)], &[("Y", 8)]),
                block(7, op, vec![var("Y")], &[("Z", 9)]),
            ];
            let mut a = added();
            let roots = place_writes(&mut blocks, &[write(8), write(9), write(10)], &mut a, &c);
            assert_eq!(roots, vec![6, 7, 100], "{op}");
        }
    }

    #[test]
    fn a_write_of_a_variable_without_a_known_type_stays() {
        let mut blocks = vec![
            block(5, "ADD", vec![var("W")], &[("W", 10)]),
            block(6, "GT", vec![arc(5)], &[("Y", 8)]),
            block(7, "MOVE", vec![var("W")], &[("Z", 9)]),
        ];
        let roots = place_writes(
            &mut blocks,
            &[write(8), write(9), write(10)],
            &mut added(),
            &ctx(),
        );
        assert_eq!(roots, vec![6, 7, 5]);
    }
}
