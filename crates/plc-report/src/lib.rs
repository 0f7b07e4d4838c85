//! `plc-deps report`: the analysis as one [`Report`] document ([`document`]), rendered as text
//! (for people, bounded at any program size), JSON (for tools; the document's serde keys are the
//! normative keys of docs/report.md), DOT (for Graphviz) and HTML (one self-contained page,
//! docs/html.md).
//!
//! The document is built once from the model and its [`Analysis`]; renderers write it to an
//! `impl Write` and never print, so the caller decides where output goes and writes an output
//! file whole or not at all. Adding a renderer touches no other renderer. The naming shared by
//! every format and the explanation of where the combined schedule differs from the paper's
//! views (Zhao & Yan, 2012) live here and in `explain`.
#![forbid(unsafe_code)]

pub mod configuration;
pub mod document;
mod dot;
mod explain;
pub mod html;
mod json;
pub mod order;
pub mod text;
mod words;

pub use document::{document, document_with, Report};
pub use dot::{render_dot, select_rungs, Selection, MAX_RUNGS as DOT_MAX_RUNGS};
pub use html::{
    render_html, render_run_html, FaultRow, HtmlInput, ModeFigures, PlanFigures, RunFigures,
};
pub use json::render_json;
pub use text::{render_text, Rows, TextOptions};

use plc_analysis::{Analysis, ControlCause, Warning};
use plc_model::*;

/// Which levellings a text or DOT report shows (JSON always carries all of them; `--view`: the
/// variants are the command line's values, their doc comments not its help).
#[derive(Copy, Clone, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "clap", derive(clap::ValueEnum))]
pub enum View {
    /// The paper's data and control views.
    #[cfg_attr(feature = "clap", value(help = None::<&str>))]
    Paper,
    /// The correct combined schedule.
    #[cfg_attr(feature = "clap", value(help = None::<&str>))]
    Combined,
    /// Both.
    #[cfg_attr(feature = "clap", value(help = None::<&str>))]
    All,
}

/// Name of a CFG node: a rung id, `START` or `STOP`.
pub(crate) fn node_name(p: &Program, n: u32) -> &str {
    let rungs = p.rungs().len() as u32;
    if n < rungs {
        &p.rungs()[n as usize].id
    } else if n == rungs {
        "START"
    } else {
        "STOP"
    }
}

/// The paper's control view as unique (from, to) pairs without self pairs, with one cause each.
pub(crate) fn paper_control_pairs(a: &Analysis) -> Vec<(RungId, RungId, ControlCause)> {
    let mut out: Vec<(RungId, RungId, ControlCause)> = Vec::new();
    for d in &a.paper_control {
        if d.from == d.to {
            continue;
        }
        if out
            .last()
            .is_some_and(|&(f, t, _)| f == d.from && t == d.to)
        {
            continue;
        }
        out.push((d.from, d.to, d.cause));
    }
    out
}

/// Rungs the paper's control view finds control dependent on themselves (loop heads, calls).
pub(crate) fn self_controlled(a: &Analysis) -> Vec<RungId> {
    let mut v: Vec<RungId> = a
        .paper_control
        .iter()
        .filter(|d| d.from == d.to)
        .map(|d| d.from)
        .collect();
    v.dedup();
    v
}

/// Level groups (0-based level → rung ids in program order) from per-rung levels.
pub(crate) fn rung_groups(p: &Program, levels: &[u32]) -> Vec<Vec<RungId>> {
    plc_analysis::levels::group_by_level(levels)
        .into_iter()
        .map(|g| g.into_iter().map(|r| p.rungs().id(r as usize)).collect())
        .collect()
}

/// Level groups of the combined schedule: each task's rungs, tasks ordered by first rung.
pub(crate) fn combined_groups(a: &Analysis) -> Vec<Vec<Vec<RungId>>> {
    a.schedule
        .levels
        .iter()
        .map(|level| {
            let mut tasks: Vec<Vec<RungId>> = level
                .iter()
                .map(|&t| a.schedule.task(t).rungs.clone())
                .collect();
            tasks.sort_unstable_by_key(|t| t[0]);
            tasks
        })
        .collect()
}

/// An FBD network of the program: its (contiguous) rungs and the union of their IN and OUT.
pub(crate) struct Network {
    pub pou: PouId,
    pub id: String,
    pub rungs: Vec<RungId>,
    pub ins: Vec<VarId>,
    pub outs: Vec<VarId>,
}

/// The FBD networks, in program order (empty for a pure ladder program).
pub(crate) fn networks(p: &Program, a: &Analysis) -> Vec<Network> {
    let mut out: Vec<Network> = Vec::new();
    for r in p.rung_ids() {
        let rung = p.rung(r);
        let Some(net) = rung.network() else { continue };
        let same = out.last().is_some_and(|n| {
            n.pou == rung.pou
                && n.id == net
                && n.rungs.last().is_some_and(|l| l.raw() + 1 == r.raw())
        });
        if !same {
            out.push(Network {
                pou: rung.pou,
                id: net.to_owned(),
                rungs: Vec::new(),
                ins: Vec::new(),
                outs: Vec::new(),
            });
        }
        let n = out.last_mut().expect("pushed above");
        n.rungs.push(r);
        n.ins.extend_from_slice(a.accesses.ins(r));
        n.outs.extend_from_slice(a.accesses.outs(r));
    }
    for n in &mut out {
        for l in [&mut n.ins, &mut n.outs] {
            l.sort_unstable();
            l.dedup();
        }
    }
    out
}

/// Human text of a warning.
pub fn warning_text(p: &Program, w: &Warning) -> String {
    // At most ten ids: a warning is one line even about a million rungs.
    let ids = |rs: &[RungId]| {
        let mut list = rs
            .iter()
            .take(10)
            .map(|r| p.rung(*r).id.as_str())
            .collect::<Vec<_>>()
            .join(", ");
        if rs.len() > 10 {
            list.push_str(&format!(" … (+{} more)", text::thousands(rs.len() - 10)));
        }
        if rs.len() == 1 {
            format!("rung {list}")
        } else {
            format!("rungs {list}")
        }
    };
    match w {
        Warning::Unreachable(rs) => format!("{} can never run (no path from the start of the scan reaches it)", ids(rs)),
        Warning::Endless(rs) => format!(
            "{} can never reach the end of the scan (an endless loop): the post-dominator tree treats the last of them as an exit, and `plc-deps run` leaves the loop after --loop-cap loop-backs of each loop-back rung per scan (default 100,000) with a loop-cap fault in every scan",
            ids(rs)
        ),
        Warning::Uncalled(pou) => format!("subroutine {} is never called", p.pou(*pou).name),
        Warning::Interrupt(pou) => format!(
            "interrupt routine {} may run between any two rungs of the scan: it is analysed on its own (the report's interrupts section lists what it shares with the main program), and `plc-deps run` raises no interrupt events, so it never runs there",
            p.pou(*pou).name
        ),
        Warning::Empty(rs) => format!("{} {} empty (no elements)", ids(rs), if rs.len() == 1 { "is" } else { "are" }),
        Warning::NoEffect(rs) => format!(
            "{} {} no effect: nothing is written and control is not transferred",
            ids(rs),
            if rs.len() == 1 { "has" } else { "have" }
        ),
        Warning::WritesInput(v, rs) => format!(
            "{} {} the input `{}`: the value lasts until the next scan copies the input image into it (as the Beremiz/OpenPLC runtime does with located %I variables)",
            ids(rs),
            if rs.len() == 1 { "writes" } else { "write" },
            p.var(*v).name
        ),
    }
}

/// The stable code of an analysis warning (`W02xx`, each documented with an example in
/// docs/diagnostics.md); [`warning_text`] is its message.
/// Where a warning points in the program's text: its first rung (for a routine, the routine's
/// first rung), none when that rung has no origin.
pub fn warning_origin(p: &Program, w: &Warning) -> plc_diag::Origin {
    let first = match w {
        Warning::Unreachable(rs)
        | Warning::Endless(rs)
        | Warning::Empty(rs)
        | Warning::NoEffect(rs)
        | Warning::WritesInput(_, rs) => rs.first().copied(),
        Warning::Uncalled(pou) | Warning::Interrupt(pou) => p.pou_rungs(*pou).next(),
    };
    first.map_or(plc_diag::Origin::NONE, |r| p.rung(r).origin)
}

pub fn warning_code(w: &Warning) -> &'static str {
    match w {
        Warning::Unreachable(_) => "W0201",
        Warning::Endless(_) => "W0202",
        Warning::Uncalled(_) => "W0203",
        Warning::Interrupt(_) => "W0204",
        Warning::Empty(_) => "W0205",
        Warning::NoEffect(_) => "W0206",
        Warning::WritesInput(..) => "W0208",
    }
}

/// The code of the report's warning that only the direct data dependences are listed
/// (`--max-pairs`).
pub const DIRECT_PAIRS_ONLY: &str = "W0207";

/// What a rung of the lowered program is to the user who wrote the program.
#[derive(Copy, Clone, Debug, PartialEq, Eq)]
pub enum RungPart {
    /// A ladder rung as written.
    Ladder,
    /// An FBD block (one rung per block).
    Block,
    /// The test of a conditional fragment, made by the lowering (`N1.F(3)`).
    FragmentGuard,
    /// The empty rung a fragment's guard jumps to, made by the lowering (`N1.F(3).end`).
    FragmentEnd,
}

/// The FBD bodies of a program as the user wrote them: how many blocks and networks, and what
/// each rung of the lowered program is.
#[derive(Clone, Debug)]
pub struct FbdParts {
    /// Blocks as written (a function block type's body counted once).
    pub blocks: usize,
    /// Networks as written.
    pub networks: usize,
    /// Per rung of the lowered program.
    pub parts: Vec<RungPart>,
}

/// The blocks, networks and rung parts of `p`'s FBD bodies `fbd` (`None` for a ladder program).
pub fn fbd_parts(p: &Program, fbd: &plc_fbd::Fbd) -> Option<FbdParts> {
    if fbd.pous.is_empty() {
        return None;
    }
    let mut parts = vec![RungPart::Ladder; p.rungs().len()];
    for pou in &fbd.pous {
        for copy in &pou.copies {
            for (range, blocks) in copy.networks.iter().zip(&copy.blocks) {
                for r in range.clone() {
                    parts[r as usize] = if p.rungs()[r as usize].series.is_empty() {
                        RungPart::FragmentEnd
                    } else {
                        RungPart::FragmentGuard
                    };
                }
                for r in blocks {
                    parts[r.index()] = RungPart::Block;
                }
            }
        }
    }
    Some(FbdParts {
        blocks: fbd
            .pous
            .iter()
            .flat_map(|u| &u.networks)
            .map(|n| n.blocks.len())
            .sum(),
        networks: fbd.pous.iter().map(|u| u.networks.len()).sum(),
        parts,
    })
}
