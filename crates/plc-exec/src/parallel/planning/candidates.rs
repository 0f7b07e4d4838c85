//! The candidate plans of a run: one plan for every kind but auto (the levelled plan of the
//! cost model, or the dependence-driven plan of `--plan deps`), and for auto the levelled plans
//! under each slicing and the dependence-driven plan, those the cost model says may gain.
//! Above both planners; it builds plans and keeps or drops them, nothing else.

use super::deps_plan;
use super::plan::Plan;
use crate::parallel::config::{PlanConfig, PlanKind, Slicing};
use plc_analysis::Analysis;
use plc_model::Program;

/// The plans of `config.kind`: the model's plan (model, seq, par), the dependence-driven plan
/// (deps), or — auto, when slicing is left to the planner — the levelled plans of the model's
/// phases under contiguous, LPT and locality slicing, and the dependence-driven plan. LPT is
/// kept when its phases differ from contiguous ones; locality when its phases differ from both
/// and the model sees any gain over the contiguous plan (in data movement, what it is for); the
/// dependence-driven plan when its modelled scan beats the sequential one: the measurement then
/// decides.
pub(in crate::parallel) fn candidate_plans(
    p: &Program,
    a: &Analysis,
    config: &PlanConfig,
) -> Vec<Plan> {
    if config.kind == PlanKind::Deps {
        return vec![deps_plan::build(p, a, config)];
    }
    if config.kind != PlanKind::Auto || config.slicing != Slicing::Auto {
        return vec![Plan::build(p, a, config)];
    }
    let with = |slicing: Slicing| Plan::build(p, a, &PlanConfig { slicing, ..*config });
    let (contiguous, lpt, local) = (
        with(Slicing::Contiguous),
        with(Slicing::Lpt),
        with(Slicing::Locality),
    );
    let keep_lpt = lpt.sequential.is_none() && lpt.phases != contiguous.phases;
    let gains = contiguous.sequential.is_some() || local.est_plan < contiguous.est_plan;
    let keep_local = local.sequential.is_none()
        && gains
        && local.phases != contiguous.phases
        && (!keep_lpt || local.phases != lpt.phases);
    let keep_contiguous = contiguous.sequential.is_none() || !(keep_lpt || keep_local);
    let deps = deps_plan::build(p, a, config);
    let keep_deps = deps.sequential.is_none();
    [
        (keep_contiguous, contiguous),
        (keep_lpt, lpt),
        (keep_local, local),
        (keep_deps, deps),
    ]
    .into_iter()
    .filter_map(|(keep, plan)| keep.then_some(plan))
    .collect()
}
