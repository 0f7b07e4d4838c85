//! The standard function blocks the interpreter runs besides timers and counters: the
//! bistables SR and RS, the edge detectors R_TRIG and F_TRIG, and the up-down counter CTUD, each
//! exactly as IEC 61131-3 (2nd ed., 2.5.2.3.1–2.5.2.3.3) defines its body, on the instance bytes
//! that `layout` places (Q1; Q and M; QU, the previous CU/CD, CV, PV and QD).
//!
//! Invariants: every function reads and writes only its instance's bytes, and returns the box's
//! power output (Q1, Q, QU). F_TRIG keeps the standard's body literally: its M starts FALSE, so
//! the first evaluation with CLK FALSE gives Q TRUE (docs/scan.md says so). CTUD counts on INT
//! with the standard's PVmax/PVmin (32767, −32768): at a limit it stops, it does not wrap.
//!
//! Not here: the timers and CTU/CTD (`run`), and what powers a box (`run`, `lower`).

use super::layout::{CV, MEM, PREV, PV, Q, QD};
use super::store::Addr;
use super::Store;
use plc_model::{index_type, BistableKind, TriggerKind};

index_type!(
    /// A CTUD box's operands: index into the machine's `ctuds`.
    CtudId
);

/// The operands of one CTUD box besides CU (the power): too many for one instruction.
#[derive(Copy, Clone, Debug)]
pub(crate) struct CtudPins {
    pub cd: Addr,
    pub reset: Addr,
    pub load: Addr,
    pub pv: Addr,
}

/// SR (`Q1 := S1 OR (NOT R AND Q1)`) or RS (`Q1 := NOT R1 AND (S OR Q1)`) on the instance at
/// `i`; returns Q1.
#[inline]
pub(crate) fn bistable<S: Store + ?Sized>(
    st: &mut S,
    kind: BistableKind,
    i: Addr,
    set: bool,
    reset: bool,
) -> bool {
    let q1 = st.load::<u8>(i.offset(Q)) != 0;
    let q1 = match kind {
        BistableKind::SetDominant => set || (!reset && q1),
        BistableKind::ResetDominant => !reset && (set || q1),
    };
    st.store(i.offset(Q), q1 as u8);
    q1
}

/// R_TRIG (`Q := CLK AND NOT M; M := CLK`) or F_TRIG (`Q := NOT CLK AND NOT M; M := NOT CLK`)
/// on the instance at `i`; returns Q.
#[inline]
pub(crate) fn trigger<S: Store + ?Sized>(
    st: &mut S,
    kind: TriggerKind,
    i: Addr,
    clk: bool,
) -> bool {
    let m = st.load::<u8>(i.offset(MEM)) != 0;
    let x = match kind {
        TriggerKind::Rising => clk,
        TriggerKind::Falling => !clk,
    };
    let q = x && !m;
    st.store(i.offset(Q), q as u8);
    st.store(i.offset(MEM), x as u8);
    q
}

/// CTUD on the instance at `i` (CU is `cu`, the rest from `pins`); returns QU.
///
/// The standard's body: both edges are detected on every evaluation (its R_TRIG instances
/// `CU_T`, `CD_T` run first); then R gives CV := 0, else LD gives CV := PV, else a CU edge
/// without a CD edge counts up below PVmax and a CD edge without a CU edge down above PVmin;
/// QU := CV >= PV, QD := CV <= 0.
#[inline]
///
/// `stop_at_preset`: count up only while `CV < PV` and down only while `CV > 0` (matiec's and
/// CODESYS's CTUD, [`plc_model::Dialect::counters_stop_at_preset`]); else to the INT limits.
pub(crate) fn ctud<S: Store + ?Sized>(
    st: &mut S,
    i: Addr,
    pins: CtudPins,
    cu: bool,
    stop_at_preset: bool,
) -> bool {
    let pv = st.load::<i16>(pins.pv);
    let cd = st.load::<u8>(pins.cd) != 0;
    let reset = st.load::<u8>(pins.reset) != 0;
    let load = st.load::<u8>(pins.load) != 0;
    let prev = st.load::<u8>(i.offset(PREV));
    let up = cu && prev & 1 == 0;
    let down = cd && prev & 2 == 0;
    st.store(i.offset(PREV), cu as u8 | (cd as u8) << 1);
    let mut cv = st.load::<i16>(i.offset(CV));
    if reset {
        cv = 0;
    } else if load {
        cv = pv;
    } else if !(up && down) {
        let (top, bottom) = if stop_at_preset {
            (pv, 0)
        } else {
            (i16::MAX, i16::MIN)
        };
        if up && cv < top {
            cv += 1;
        } else if down && cv > bottom {
            cv -= 1;
        }
    }
    st.store(i.offset(CV), cv);
    st.store(i.offset(PV), pv);
    let qu = cv >= pv;
    st.store(i.offset(Q), qu as u8);
    st.store(i.offset(QD), (cv <= 0) as u8);
    qu
}
