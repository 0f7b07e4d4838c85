//! Typed indices and values of the parallel plan: tasks, decision slots, the successor a task
//! leads to, and a task's decision (where control left it, or that it did not run).
//!
//! Invariants: a [`TaskId`] indexes `analysis::schedule::Schedule::tasks` (the combined schedule
//! of Zhao & Yan's levelling, control and data dependences together); a [`DecisionSlot`]
//! indexes the run's decision array. The only place a decision is packed into a machine word is
//! [`Decision::pack`]/[`Decision::unpack`], for the lock-free decision cells of a run; nothing
//! else sees the packing. This module deliberately holds no planning logic.

use plc_model::RungId;

/// A task of the combined schedule (the analysis's index).
pub use plc_analysis::schedule::TaskId;

/// A slot of the decision array: where one task records where control left it.
#[derive(Copy, Clone, Debug, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub struct DecisionSlot(pub u32);

impl DecisionSlot {
    /// As a `Vec` index.
    #[inline]
    pub fn index(self) -> usize {
        self.0 as usize
    }
}

/// Where control goes after a task: another task, or the end of the scan.
#[derive(Copy, Clone, Debug, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub enum Next {
    /// The task holding the rung control goes to.
    Task(TaskId),
    /// The end of the scan.
    Stop,
}

/// What a task did in the current scan.
#[derive(Copy, Clone, Debug, PartialEq, Eq, Hash)]
pub enum Decision {
    /// It did not run.
    NotRun,
    /// Control left to the end of the scan.
    Stop,
    /// Control left to the start of this rung.
    Rung(RungId),
    /// Control left to the FOR test of this head rung (never for tasks of the combined
    /// schedule, whose FOR heads share a task with their NEXT; encoded exactly anyway).
    ForTest(RungId),
}

const NOT_RUN: u32 = u32::MAX;
const STOP: u32 = u32::MAX - 1;
const FOR_TEST: u32 = 1 << 31;

impl Decision {
    /// The decision as one word (rung indices are below 2^31 − 2: the program loader and
    /// `Machine::new` refuse larger programs).
    #[inline]
    pub(super) fn pack(self) -> u32 {
        match self {
            Decision::NotRun => NOT_RUN,
            Decision::Stop => STOP,
            Decision::Rung(r) => r.raw(),
            Decision::ForTest(r) => r.raw() | FOR_TEST,
        }
    }

    /// The inverse of [`pack`](Self::pack).
    #[inline]
    pub(super) fn unpack(w: u32) -> Decision {
        match w {
            NOT_RUN => Decision::NotRun,
            STOP => Decision::Stop,
            w if w & FOR_TEST != 0 => Decision::ForTest(RungId::from_raw(w & !FOR_TEST)),
            w => Decision::Rung(RungId::from_raw(w)),
        }
    }

    /// The rung (or FOR test) control left to, if the task ran and control stayed in the scan.
    #[inline]
    pub fn rung(self) -> Option<RungId> {
        match self {
            Decision::Rung(r) | Decision::ForTest(r) => Some(r),
            Decision::NotRun | Decision::Stop => None,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    #[test]
    fn decisions_pack_and_unpack_exactly() {
        for d in [
            Decision::NotRun,
            Decision::Stop,
            Decision::Rung(RungId::from_raw(0)),
            Decision::Rung(RungId::from_raw(12345)),
            Decision::ForTest(RungId::from_raw(0)),
            Decision::ForTest(RungId::from_raw(77)),
        ] {
            assert_eq!(Decision::unpack(d.pack()), d);
        }
        assert_ne!(
            Decision::Rung(RungId::from_raw(3)).pack(),
            Decision::ForTest(RungId::from_raw(3)).pack()
        );
    }
}
