//! What each main-program rung costs the interpreter, in the cost model's steps (1 step ≈ 1 ns
//! on the machine the defaults were measured on: `config`), as the planner weighs tasks.
//!
//! The analysis' cost model (`analysis::cost`, element steps: a contact 1, a coil 1, …) counts
//! what a rung *says*; the interpreter runs a rung of at most eight plain contacts and one output
//! as one table lookup (`exec::fuse`), whatever its contacts, and a rung that starts with such
//! contacts as one lookup for them and then its other elements one by one. So a rung fused whole
//! costs [`PlanConfig::fused_rung_cost`]; a rung with a fused head costs that plus the element
//! steps of what follows the head (scaled by `step_tenths`); any other rung its element steps
//! (scaled). The fusion decision is the interpreter's own (`fuse::start`, asked with dummy
//! addresses), so the two cannot disagree on a rung's shape.
//!
//! It does not measure anything (the constants are `config`'s) and does not know the layout:
//! where a rung's bytes are (cache lines moved between workers) is `movement`'s business.

use crate::fuse::{self, Tables};
use crate::parallel::config::PlanConfig;
use crate::Addr;
use plc_analysis::Analysis;
use plc_model::{Element, Program};

/// The interpreter's cost of every rung, in steps, at least 1.
pub(in crate::parallel) fn interpreter_costs(
    p: &Program,
    a: &Analysis,
    config: &PlanConfig,
) -> Vec<u64> {
    let mut tables = Tables::default();
    let scaled = |steps: u64| (steps * config.step_tenths).div_ceil(10);
    (p.rung_ids())
        .map(|rid| {
            let series = &p.rung(rid).series;
            let whole = a.rung_costs[rid.index()];
            let c = match fuse::start(series, &mut tables, |_| Addr(0), |_| Addr(0)) {
                Some(s) if s.whole => config.fused_rung_cost,
                Some(s) => {
                    let head = head_steps(&series[..s.taken]);
                    config.fused_rung_cost + scaled(whole.saturating_sub(head))
                }
                None => scaled(whole),
            };
            c.max(1)
        })
        .collect()
}

/// The element steps of a fused head (plain contacts and `or`s of them), as `analysis::cost`
/// counts them: a contact 1, an `or` 1 plus its branches.
fn head_steps(series: &[Element]) -> u64 {
    series
        .iter()
        .map(|e| match e {
            Element::Or(bs) => 1 + bs.iter().map(|b| head_steps(b)).sum::<u64>(),
            _ => 1,
        })
        .sum()
}
