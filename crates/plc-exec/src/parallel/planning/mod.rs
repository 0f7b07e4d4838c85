//! Planning: what the parallel scan will run, decided before the first scan from the program,
//! its analysis and the cost model, and checked against the lowered code. The candidates
//! ([`candidate_plans`]: the sequential walk, the levelled plan under contiguous slicing, the
//! dependence-driven plan), the cost model (`rung_cost`, `movement`, the calibrated line cost
//! of `calibrate`), the partition of each level (`tasks`' contiguous and LPT cuts, `partition`'s
//! locality partition, `slicing`), the phases (`plan`, `deps_plan`) and the check of every plan
//! (`check`, `order_check`).
//!
//! Invariants: planning reads the program, the analysis and the lowered code, and writes
//! nothing a run reads but the plans; it never runs a scan (the measured choice and the running
//! machine are the layers above it, which it does not know).
//!
//! # Modules, bottom to top
//! Each uses only the ones before it (and the basics below planning: `ids`, `config`, `pad`):
//! `calibrate` (the per-line and hand-over costs measured), `rung_cost` (what a rung costs the
//! interpreter, fused or not), `calls` (call closures, loop-backs), `tasks` (task facts, items,
//! contiguous and LPT cuts), `partition` (the locality partition of one level), `movement`
//! (lines moved between workers), `slicing` (each level's slices and modelled makespan),
//! `ready` (the dependence-driven plan's waits), `one_way` (the chain partition of the
//! dependence-driven plan), `phase` (a phase's items), `plan` (phases on the cost model), `deps_plan`
//! (the dependence-driven plan), `candidates` (the plans a run chooses from), `order_check`
//! (the dependence-driven order against the lowered code), `check` (every plan against the
//! lowered code), `exchange` (what each worker of a levelled plan on private states hands the
//! others after each phase, from the lowered code's writes), `remote` (the lines each slice finds in another core's cache, to prefetch).

mod calibrate;
mod calls;
mod candidates;
mod check;
mod deps_plan;
mod early;
mod exchange;
mod movement;
mod one_way;
mod order_check;
mod partition;
mod phase;
mod plan;
mod ready;
mod remote;
mod rung_cost;
mod slicing;
mod tasks;

pub use calibrate::{measure_handover, measure_line_cost, LineTiming};
pub(super) use exchange::Exchange;
pub use plan::Plan;
pub use ready::Ready;
pub use slicing::LevelPlan;

pub(super) use candidates::candidate_plans;
pub(super) use check::check_plan;
#[cfg(test)]
pub(super) use exchange::Segment;
pub(super) use exchange::{exchange_plan, Key, LINE_WORDS};
pub(super) use phase::{Phase, RemoteLines};
pub(super) use plan::{bools_first, layout_groups};
pub(super) use remote::find_remote_lines;
pub(super) use tasks::{Item, Region};
