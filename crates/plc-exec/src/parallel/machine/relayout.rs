//! The state of one program in two layouts: the candidates' common layout, which the caller's
//! state and every plan on the shared state use, and the layout of the levelled plan that
//! `par-exchange` runs on private states, padded for that plan's writers alone. The common
//! layout is padded for every candidate's writers: on gen 20k the dependence-driven plan's
//! other cut of each level adds a few lines to every level, 45 KB of state instead of 41 KB
//! (this machine's L1d holds 48 KB), and `par-exchange`, whose workers each touch the whole of
//! their private state, ran 4–5 % slower on it than on its own layout.
//!
//! A [`Relayout`] moves a state between the two as runs of bytes: every value of
//! `Machine::canonical_values` (each variable's parts in declaration order, then the loop
//! counters), consecutive values that are consecutive in both layouts merged into one run; and
//! the inputs alone, which the caller writes into the common layout before each scan.
//! Constants and padding are not moved (each layout's machine puts its own constants into its
//! initial state; padding is never read). An [`OwnLayout`] is such a layout with its machine:
//! the plan's writer groups alone, lowered once more, the plan checked on it. It does not run
//! anything.

use crate::parallel::planning::{bools_first, check_plan, layout_groups, Plan};
use crate::{Addr, ExecConfig, Layout, Machine, LINE_BYTES};
use plc_model::Program;

/// Runs of bytes between two layouts of one program's state.
#[derive(Clone, Debug)]
pub(in crate::parallel) struct Relayout {
    /// (common address, own address, bytes), every stored value.
    values: Vec<(u32, u32, u32)>,
    /// The same for the inputs only.
    inputs: Vec<(u32, u32, u32)>,
}

/// Runs of `pairs` ((common, own, width), in order), merged where both sides continue.
fn runs(pairs: impl IntoIterator<Item = ((Addr, u32), (Addr, u32))>) -> Vec<(u32, u32, u32)> {
    let mut out: Vec<(u32, u32, u32)> = Vec::new();
    for ((a, wa), (b, wb)) in pairs {
        assert_eq!(
            wa, wb,
            "two layouts of one program store a value in as many bytes"
        );
        match out.last_mut() {
            Some((c, o, n)) if *c + *n == a.0 && *o + *n == b.0 => *n += wa,
            _ => out.push((a.0, b.0, wa)),
        }
    }
    out
}

impl Relayout {
    /// The runs between `common`'s layout and `own`'s (two machines of one program).
    pub(in crate::parallel) fn new(common: &Machine, own: &Machine) -> Relayout {
        let (a, b) = (common.canonical_values(), own.canonical_values());
        assert_eq!(a.len(), b.len(), "two machines of one program");
        let (ia, ib) = (common.input_spans(), own.input_spans());
        Relayout {
            values: runs(a.into_iter().zip(b)),
            inputs: runs(ia.into_iter().zip(ib)),
        }
    }

    /// Copies every value of `common` (a state in the common layout) into `own`.
    pub(in crate::parallel) fn to_own(&self, common: &[u8], own: &mut [u8]) {
        copy(&self.values, common, own, false);
    }

    /// Copies every value of `own` into `common`.
    pub(in crate::parallel) fn to_common(&self, own: &[u8], common: &mut [u8]) {
        copy(&self.values, own, common, true);
    }

    /// Copies the inputs of `common` into `own`.
    pub(in crate::parallel) fn inputs_to_own(&self, common: &[u8], own: &mut [u8]) {
        copy(&self.inputs, common, own, false);
    }

    /// Runs of the values (for `--explain` and tests).
    pub(in crate::parallel) fn runs(&self) -> usize {
        self.values.len()
    }
}

/// Copies each run from `src` to `dst`; `back`: from the own side to the common one.
fn copy(runs: &[(u32, u32, u32)], src: &[u8], dst: &mut [u8], back: bool) {
    for &(c, o, n) in runs {
        let (from, to) = if back { (o, c) } else { (c, o) };
        let (from, to, n) = (from as usize, to as usize, n as usize);
        dst[to..to + n].copy_from_slice(&src[from..from + n]);
    }
}

/// A `par-exchange` plan's own layout: the plan's writer groups alone, its machine, and the
/// moves between it and the common layout.
#[derive(Debug)]
pub(in crate::parallel) struct OwnLayout {
    pub(in crate::parallel) machine: Machine,
    pub(in crate::parallel) relayout: Relayout,
    /// Padding groups of the layout (for `--explain`).
    pub(in crate::parallel) groups: usize,
}

impl OwnLayout {
    /// The layout of `plan`'s writers alone; `None` if it cannot be built or the plan fails its
    /// check on it (the plan then runs on the common layout).
    pub(super) fn new(
        program: &Program,
        exec: &ExecConfig,
        common: &Machine,
        plan: &Plan,
    ) -> Option<OwnLayout> {
        let groups = bools_first(program, layout_groups(&[plan], program.vars()));
        let layout = Layout::from_groups(program, &groups, LINE_BYTES).ok()?;
        let machine = Machine::new(program, layout, exec).ok()?;
        check_plan(&machine, plan).ok()?;
        Some(OwnLayout {
            relayout: Relayout::new(common, &machine),
            machine,
            groups: groups.len(),
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use plc_model::VarId;

    /// A state moved to a padded layout and back is the state it was, value for value, and the
    /// inputs move alone.
    #[test]
    fn a_state_moves_between_layouts_value_for_value() {
        let p = plc_load::program_from_json(
            r#"{"program": "p", "vars": [
                {"name": "a", "type": "BOOL", "class": "input"},
                {"name": "n", "type": "INT", "class": "input"},
                {"name": "x", "type": "BOOL", "class": "output"},
                {"name": "t", "type": "TON"},
                {"name": "y", "type": "INT", "class": "output"}],
              "rungs": [{"id": "R1", "ld": [{"contact": "a"}, {"coil": "x"}]},
                        {"id": "R2", "ld": [{"contact": "x"}, {"move": 7, "to": "y"}]}]}"#,
        )
        .unwrap();
        let dense = Machine::new(&p, Layout::dense(&p), &ExecConfig::default()).unwrap();
        let groups: Vec<Vec<VarId>> = (0..5).rev().map(|v| vec![VarId::from_raw(v)]).collect();
        let padded = Layout::from_groups(&p, &groups, LINE_BYTES).unwrap();
        let padded = Machine::new(&p, padded, &ExecConfig::default()).unwrap();
        let r = Relayout::new(&dense, &padded);
        let mut a = dense.initial_state();
        for (i, b) in a.bytes_mut().iter_mut().enumerate() {
            *b = (i * 37 + 11) as u8;
        }
        let mut own = padded.initial_state();
        r.to_own(a.bytes(), own.bytes_mut());
        let values = |m: &Machine, s: &[u8]| -> Vec<Vec<u8>> {
            (m.canonical_values().iter())
                .map(|&(at, w)| s[at.index()..at.index() + w as usize].to_vec())
                .collect()
        };
        assert_eq!(values(&dense, a.bytes()), values(&padded, own.bytes()));
        let mut back = dense.initial_state();
        r.to_common(own.bytes(), back.bytes_mut());
        assert_eq!(values(&dense, a.bytes()), values(&dense, back.bytes()));
        // The inputs alone: a and n, nothing else.
        let mut fresh = padded.initial_state();
        r.inputs_to_own(a.bytes(), fresh.bytes_mut());
        let init = padded.initial_state();
        for (at, w) in padded.canonical_values() {
            let span = at.index()..at.index() + w as usize;
            let input = padded.input_spans().iter().any(|&(i, _)| i == at);
            let moved = fresh.bytes()[span.clone()] != init.bytes()[span];
            assert!(!moved || input, "only inputs move");
        }
        assert_eq!(
            values(&padded, fresh.bytes())[..2],
            values(&dense, a.bytes())[..2]
        );
    }
}
