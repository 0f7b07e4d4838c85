//! The candidate plans of a run: one plan for every kind but auto (the levelled plan of the
//! cost model, or the dependence-driven plan of `--plan deps`), and for auto the levelled plan
//! under contiguous slicing and the dependence-driven plan, those the cost model says may gain.
//! Above both planners; it builds plans and keeps or drops them, nothing else.
//!
//! Auto once also timed the levelled plans under LPT and locality slicing (`par-lpt`,
//! `par-locality`) when their phases differed from the contiguous ones; measured on every
//! `plc-deps gen` shape at 2k and 20k rungs and every worked example (7 December 2026), LPT was
//! never a candidate and locality (one shape) never kept, so they are no longer candidates; the
//! model's own slicing (`Slicing::Auto`: contiguous, LPT or locality) is unchanged.

use super::deps_plan;
use super::plan::Plan;
use crate::parallel::config::{PlanConfig, PlanKind, Slicing, Strategy};
use plc_analysis::Analysis;
use plc_model::Program;

/// The plans of `config.kind`: the model's plan (model, seq), the levelled plan forced on every
/// level that can run in parallel (par, exchange: the planner's strategy becomes
/// [`Strategy::AllParallel`] unless the caller chose one), the dependence-driven plan
/// (deps), or — auto, when slicing is left to the planner — the levelled plan of the model's
/// phases under contiguous slicing (first, whether it runs in parallel or not), and the dependence-driven plan
/// when its modelled scan beats the sequential one: the measurement then decides.
pub(in crate::parallel) fn candidate_plans(
    p: &Program,
    a: &Analysis,
    config: &PlanConfig,
) -> Vec<Plan> {
    if config.kind == PlanKind::Deps {
        return vec![deps_plan::build(p, a, config)];
    }
    if matches!(config.kind, PlanKind::Par | PlanKind::Exchange)
        && config.strategy == Strategy::Auto
        && config.threads > 1
    {
        // Forced: every level that can run in parallel does, whatever the cost model says
        // (one worker still runs the sequential walk).
        let forced = PlanConfig {
            strategy: Strategy::AllParallel,
            ..*config
        };
        return vec![Plan::build(p, a, &forced)];
    }
    if config.kind != PlanKind::Auto || config.slicing != Slicing::Auto {
        return vec![Plan::build(p, a, config)];
    }
    let contiguous = Plan::build(
        p,
        a,
        &PlanConfig {
            slicing: Slicing::Contiguous,
            ..*config
        },
    );
    let deps = deps_plan::build(p, a, config);
    // The contiguous plan stays first even when sequential: it is the primary plan that
    // `--explain` describes.
    match deps.sequential {
        None => vec![contiguous, deps],
        Some(_) => vec![contiguous],
    }
}
