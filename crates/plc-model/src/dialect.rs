//! The dialect a program is run in: where IEC 61131-3 leaves a result to the implementation, or
//! where the toolchain a file was written for differs from the standard's text, which rule the
//! executor and the generated C follow.
//!
//! Each dialect is the reference toolchain of a family of files: [`Dialect::Matiec`] for
//! Beremiz and OpenPLC Editor projects (Beremiz's generator and matiec, whose standard library
//! is `lib/counter.txt`, `lib/timer.txt` and `lib/C/iec_std_lib.h`), [`Dialect::Codesys`] for
//! CODESYS and TwinCAT exports (their Standard / Tc2_Standard library manuals), [`Dialect::Iec`]
//! for the JSON program format and S7-200 STL (IEC 61131-3's text, milliseconds for TIME). The
//! differences, each with its source, are the table of docs/dialects.md; this module is that
//! table as data, and the executor and the C generator ask it, never the dialect itself.
//!
//! Deliberately not here: anything that does not change a value (analysis, order), and the
//! S7-200's own instructions (their semantics are the STL reader's).

use std::fmt;

/// Which toolchain's rules a run follows where they differ (docs/dialects.md).
#[derive(Copy, Clone, Debug, Default, PartialEq, Eq, Hash)]
pub enum Dialect {
    /// IEC 61131-3's text; TIME conversions in milliseconds. The JSON format's and STL's.
    #[default]
    Iec,
    /// Beremiz's generator and matiec: Beremiz and OpenPLC Editor projects.
    Matiec,
    /// CODESYS and TwinCAT (its Tc2_Standard library).
    Codesys,
}

impl Dialect {
    /// Every dialect, in the order the documentation lists them.
    pub const ALL: [Dialect; 3] = [Dialect::Iec, Dialect::Matiec, Dialect::Codesys];

    /// The name the command line and the documentation use.
    pub fn name(self) -> &'static str {
        match self {
            Dialect::Iec => "iec",
            Dialect::Matiec => "matiec",
            Dialect::Codesys => "codesys",
        }
    }

    /// The dialect of a name ([`Dialect::name`]), in any case.
    pub fn from_name(name: &str) -> Option<Dialect> {
        Dialect::ALL
            .into_iter()
            .find(|d| d.name().eq_ignore_ascii_case(name))
    }

    /// The dialect of a PLCopen file by the editor its `fileHeader` names (`productName`):
    /// CODESYS, TwinCAT and e!COCKPIT (a CODESYS) are [`Dialect::Codesys`]; any other editor
    /// (Beremiz, OpenPLC Editor, which write the same header) is [`Dialect::Matiec`].
    pub fn of_editor(product_name: &str) -> Dialect {
        let p = product_name.to_ascii_lowercase();
        if ["codesys", "twincat", "e!cockpit"]
            .iter()
            .any(|n| p.contains(n))
        {
            Dialect::Codesys
        } else {
            Dialect::Matiec
        }
    }

    /// CTU counts only while `CV < PV`, CTD only while `CV > 0`, CTUD both (matiec's
    /// `lib/counter.txt`; Beckhoff's Tc2_Standard and CODESYS's Standard: "as long as CV is less
    /// than PV"), rather than up to the type's limits as IEC 61131-3's text says.
    pub fn counters_stop_at_preset(self) -> bool {
        matches!(self, Dialect::Matiec | Dialect::Codesys)
    }

    /// Milliseconds per unit of an integer or real converted from or to TIME: matiec converts
    /// whole seconds (`__time_to_int` returns `tv_sec`, `__int_to_time(n)` is n s,
    /// `__time_to_real` seconds), CODESYS and the JSON format milliseconds.
    pub fn time_unit_ms(self) -> i64 {
        match self {
            Dialect::Matiec => 1000,
            Dialect::Iec | Dialect::Codesys => 1,
        }
    }

    /// A timer's Q changes only in a call after the one that sees its edge (matiec's
    /// `lib/timer.txt`: the rising-edge call of TON sets `Q := FALSE` and starts the time; the
    /// elapsed time is compared from the next call, so with `PT = T#0s` Q rises one call after
    /// IN; likewise TOF's falling edge and TP's end); and an elapsed TON keeps Q and ET until IN
    /// falls, even if a later call gives a longer PT (its STATE 2). The others compare in the
    /// edge's call.
    pub fn timer_compares_after_edge(self) -> bool {
        self == Dialect::Matiec
    }

    /// ST arithmetic of types narrower than DINT (SINT, INT, USINT, UINT) is computed in DINT
    /// and cut to its type only where it is stored or passed: matiec writes `a * b` as C's
    /// `a * b`, which C computes in `int` (C11 6.3.1.1), so `w <= i * 258` compares the whole
    /// product. IEC 61131-3 types `i * 258` INT; CODESYS's rule is not documented, so it keeps
    /// IEC's. Fixed when an ST body is read, by the file's editor (`--dialect` does not change it).
    pub fn int_arithmetic_in_dint(self) -> bool {
        self == Dialect::Matiec
    }
}

impl fmt::Display for Dialect {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn editors_choose_their_toolchains_dialect() {
        assert_eq!(Dialect::of_editor("CODESYS"), Dialect::Codesys);
        assert_eq!(Dialect::of_editor("TwinCAT PLC Control"), Dialect::Codesys);
        assert_eq!(Dialect::of_editor("e!COCKPIT"), Dialect::Codesys);
        assert_eq!(Dialect::of_editor("Beremiz"), Dialect::Matiec);
        assert_eq!(Dialect::of_editor("Unnamed"), Dialect::Matiec);
        assert_eq!(Dialect::from_name("MATIEC"), Some(Dialect::Matiec));
        assert_eq!(Dialect::from_name("s7"), None);
    }
}
