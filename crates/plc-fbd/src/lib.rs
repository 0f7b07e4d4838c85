//! Function block diagrams (FBD): a first-class input, read into their own model, ordered and
//! split into conditional fragments (the FBD text-generation paper), then lowered into the ladder model so that the
//! analyses, `plc-deps report`, the interpreter and the parallel executor work on them unchanged.
//!
//! - [`model`]: networks, blocks (dense [`BlockId`] indices, sorted by the user's id), arcs, and
//!   the [`Plan`] of a network (execution order, fragment tree);
//! - [`order`]: depth-first topological sort, O(V + E), ties by block id, cycles reported;
//! - [`fragments`]: the conditional fragment tree, the rule of conditional fragments, the
//!   regrouped order;
//! - [`types`]: user function block types with their interface and typed bodies;
//! - [`lower`]: an FBD body → ladder rungs of the program model, in the scope an [`lower::Env`]
//!   gives (the resolver's).
//!
//! Reading FBD bodies (names, declarations, arcs) is the resolver's (`plc_resolve`), which calls
//! [`plan`] and [`lower::lower`]; this crate knows neither the surface syntax nor the resolver.
//! `plc-deps order` renders the plans (`plc_report::order`). The format and every lowering rule
//! are in docs/fbd.md.
#![forbid(unsafe_code)]

pub mod fragments;
mod ids;
pub mod lower;
pub mod model;
pub mod order;
pub mod types;

/// The longest time an accumulation (TSTART/TSTOP) can run (the TIME range): the PT of its
/// hidden TON.
pub const ACCUMULATE_PT_MS: i32 = i32::MAX;
pub use model::*;
pub use types::*;

use plc_diag::{Invalid, LoadError};

/// Orders `net` and builds its fragment tree: a cycle of arcs or a block that depends on a
/// fragment that is neither its own nor an ancestor is an error naming the blocks (a cycle is
/// placed at its first block).
pub fn plan(net: &Network) -> Result<Plan, LoadError> {
    let topological = order::topological_order(net).map_err(|cycle| {
        let mut names: Vec<String> = cycle.iter().map(|b| net.block(*b).id.to_string()).collect();
        names.push(names[0].clone());
        // Placed at the cycle's first block, so that the error points at a block of it.
        let first = net.block(cycle[0]);
        LoadError::fbd(
            &net.id,
            Some(first.id),
            &first.path,
            Invalid::Cycle {
                blocks: names.join(" → "),
            },
        )
        .with_hint(&format!(
            "the blocks of the cycle: {}",
            cycle
                .iter()
                .map(|b| format!("{} at {}", net.block(*b).id, net.block(*b).path))
                .collect::<Vec<_>>()
                .join(", ")
        ))
    })?;
    fragments::fragments(net, topological)
}
