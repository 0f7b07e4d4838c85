//! Loops of arcs between the blocks of one FBD network (a block's output wired, through other
//! blocks, back into its own input), closed as Beremiz closes them: its generator marks a block
//! computed *before* computing its inputs (`PLCGenerator.GenerateBlock`), so the walk that comes
//! back around to a block in progress reads that block's output variable as it is — the value
//! of the previous scan (docs/design/plcopen-semantics.md §2.1).
//!
//! Here: a depth-first walk over the arcs (consumer to producer), from the blocks in file order;
//! each arc that reaches a block still in progress (a back edge) is cut: the producer's output
//! pin also writes a variable `<producer id>__<pin>` (added to the POU, typed like the pin), and
//! the consumer reads that variable instead. A note names every cut arc.
//!
//! Deliberately not here: loops through variables (not arcs; nothing to cut), and Beremiz's
//! exact start order (its walk starts from the out variables in file order; this one from the
//! blocks in file order, so in a loop with several entries the cut may fall elsewhere).

use super::pins::{add_target, Added};
use super::xml::Note;
use plc_diag::Origin;
use plc_syntax::fbd::{Block, Connection, Input, Inputs, OutVar};
use std::borrow::Cow;
use std::collections::HashMap;

/// The arcs of block `b`: (input index, or `None` for its condition; producer id; pin).
fn arcs(b: &Block) -> Vec<(Option<usize>, u32, Option<String>)> {
    let mut out = Vec::new();
    let pin = |p: &Option<plc_syntax::fbd::Read<plc_syntax::Text>>| {
        p.as_ref()
            .and_then(|r| r.as_ref().ok())
            .map(|s| s.to_string())
    };
    if let Some(Ok(Inputs::Named(ins))) = &b.inputs {
        for (k, (_, i)) in ins.iter().enumerate() {
            if let Connection::Arc { block, pin: p } = &i.from {
                out.push((Some(k), *block, pin(p)));
            }
        }
    }
    if let Some(Input {
        from: Connection::Arc { block, pin: p },
        ..
    }) = &b.cond
    {
        out.push((None, *block, pin(p)));
    }
    out
}

/// Cuts the back edges of `blocks` (see the module doc); `ty` gives the type of a producer's
/// output pin (`None`: its first output). Returns a note per cut.
pub(super) fn cut(
    blocks: &mut [Block<'static>],
    added: &mut Added,
    ty: &dyn Fn(u32, Option<&str>) -> Option<String>,
    place: &str,
) -> Vec<Note> {
    let index: HashMap<u32, usize> = blocks
        .iter()
        .enumerate()
        .filter_map(|(i, b)| b.id.as_ref().ok().map(|id| (*id, i)))
        .collect();
    // 0: not seen, 1: in progress, 2: done.
    let mut state = vec![0u8; blocks.len()];
    let mut backs: Vec<(usize, Option<usize>, u32, Option<String>)> = Vec::new();
    for start in 0..blocks.len() {
        if state[start] != 0 {
            continue;
        }
        let mut stack: Vec<(usize, usize)> = vec![(start, 0)];
        state[start] = 1;
        while let Some(&mut (b, ref mut next)) = stack.last_mut() {
            let a = arcs(&blocks[b]);
            if *next >= a.len() {
                state[b] = 2;
                stack.pop();
                continue;
            }
            let (k, producer, pin) = a[*next].clone();
            *next += 1;
            let Some(&p) = index.get(&producer) else {
                continue;
            };
            match state[p] {
                0 => {
                    state[p] = 1;
                    stack.push((p, 0));
                }
                1 => backs.push((b, k, producer, pin)),
                _ => {}
            }
        }
    }
    let mut notes = Vec::new();
    for (b, k, producer, pin) in backs {
        let p = index[&producer];
        let pin_name = pin.clone().unwrap_or_else(|| "OUT".to_owned());
        let v = format!("{}__{producer}_{pin_name}", op_name(&blocks[p]));
        let at = blocks[b].origin;
        if !added.vars.iter().any(|x| x.name.value == v) {
            let t = ty(producer, pin.as_deref()).unwrap_or_else(|| "BOOL".to_owned());
            added.declare(&v, &t, at);
            let target = OutVar {
                origin: at,
                name: Cow::Owned(v.clone()),
            };
            add_target(&mut blocks[p], pin_name.clone(), target);
        }
        let read = Connection::Variable(Cow::Owned(v.clone()));
        match k {
            Some(k) => {
                if let Some(Ok(Inputs::Named(ins))) = &mut blocks[b].inputs {
                    ins[k].1.from = read;
                }
            }
            None => {
                if let Some(c) = &mut blocks[b].cond {
                    c.from = read;
                }
            }
        }
        let consumer = blocks[b].id.as_ref().map_or(0, |i| *i);
        notes.push(Note {
            origin: if at == Origin::NONE { blocks[p].origin } else { at },
            message: format!("{place}: blocks {consumer} and {producer} are in a loop of arcs; as Beremiz closes it, block {consumer} reads output {pin_name} of block {producer} as the variable `{v}` (its value from the previous scan when {consumer} runs first)"),
        });
    }
    notes
}

fn op_name(b: &Block) -> String {
    b.op.as_ref()
        .map_or_else(|_| "block".to_owned(), |o| o.to_string())
}
