//! Synthetic ladder programs of any size, for benchmarks and tests (`plc-deps gen`).
//!
//! [`write_program`] streams the program JSON (the crate's normative input format) straight to a
//! [`std::io::Write`], one rung per line, in time linear in `rungs` and memory `O(width)`; no JSON
//! tree is built. The same [`GenConfig`] always gives byte-identical output (a private splitmix64
//! generator seeded from [`GenConfig::seed`]; no global or OS randomness).
//!
//! # Shape (the contract of `plc-deps gen`)
//!
//! Let `n = rungs` and `W = clamp(width, 1, max(n, 1))` (the effective number of lanes).
//!
//! * **Stages and lanes.** The main program has exactly `n` rungs, ids `R1..Rn`. Main rung `r`
//!   (0-based) is lane `j = r % W` of stage `s = r / W`; there are `S = ceil(n / W)` stages.
//!   Lane 0 of every stage carries `"comment": "stage s"`.
//! * **Variables (all declared up front; a few may end up unused).** Globals, in this order:
//!   `I0..I{ni-1}` BOOL inputs with `ni = max(8, W/8)`; `Q0..Q{nq-1}` BOOL outputs with
//!   `nq = ceil(W/16)`; `M{j}_{p}` BOOL memory and `N{j}_{p}` INT memory for every lane `j < W`
//!   and phase `p ≤ max phase(s) for s < S` (a few carry a non-zero `init`); with `timers`, `T{j}_{p}` timer
//!   instances (TON mostly, TOF or TP for some `(j, p)`, fixed by `(5j + 3p) % 8`: 0 → TOF,
//!   1 → TP, else TON) and `C{j}_{p}` counter instances (CTU if `j + p` is even, else CTD); with
//!   `loops`, INT FOR indices `i0..i{W-1}` (one per lane); with `calls`, `SR{k}` BOOL results of the subroutines;
//!   with `hot_fraction`, the BOOL `FAULT`.
//! * **Normal rung** (stage `s`, lane `j`, phase `p = phase(s) = (s / 8) * 4 + s % 4`): a series
//!   of conditions, optional boxes, then one output writing the lane's own `M{j}_{p}` (memory is
//!   recycled every 4 stages within each section of 8 stages, so each variable has at most two
//!   writers, anti and output dependences occur, the number of dependence pairs stays linear in
//!   the program size, and the data-flow depth stays ≈ `S = n / W`).
//!   - Stage 0 reads inputs only: 4–6 distinct `I..` contacts (1 in 6 negated, 1 in 25 with a
//!     rising/falling edge).
//!   - Stage `s ≥ 1` reads 3–5 of the variables `M{l}_{phase(s-1)}` written by stage `s-1` in the
//!     nearby lanes `l ∈ j-2..=j+2` (mod W, distinct; 1 in 4 negated) — with
//!     `reads = Random` (`--reads random`) instead 3–6 distinct lanes `l` drawn uniformly from
//!     `0..W` (all of them if `W < 6`; the timer, counter and compare reads below come from these
//!     lanes, a `move`'s source stays a nearby `N`; header, jump and call rungs read 2–3 of
//!     them the same way) —, one input contact half
//!     of the time (or as many as needed to reach 4 conditions), and now and then: the `.Q` of a
//!     nearby timer of stage `s-1` (`timers`), the `.Q` or `.CV ≥ 3` of a nearby counter of
//!     stage `s-1` (`timers`), an INT `compare` of `N{l}_{phase(s-1)}` with a constant (1 in 30;
//!     lanes whose `N` was written in stage `s-1` preferred), a subroutine result `SR{k}`
//!     (`calls`, 1 in 100). 1 in 8 rungs wraps their first 2 or 3 conditions into an
//!     `{"or": [[a], [b]]}` or `{"or": [[a, b], [c]]}`.
//!   - Boxes before the output: with `timers`, 1 in 20 rungs has a timer box
//!     `{"ton"|"tof"|"tp": "T{j}_{p}", "pt": "T#100ms"|"T#250ms"|"T#1s"}` and about 1 in 60
//!     others a counter box on `C{j}_{p}` (`ctu` with `pv` 5 and `reset` an input, or `ctd` with
//!     `load` an input); 1 in 30 rungs has a `move` (constant or a nearby `N` of stage `s-1`) or
//!     an `op` (ADD/SUB/MUL/DIV/MOD with a small non-zero constant) writing `N{j}_{p}`, half of
//!     the time as a box in the series, half as an extra path of a `branch` output.
//!   - The output is a `coil` (most), `set` (1 in 10), `reset` (1 in 10) or negated coil (1 in
//!     40) of `M{j}_{p}`. The last rung of each lane `j ≡ 0 (mod 16)` (its rung in the last
//!     stage, or the stage before when that one is cut short) is the writer of `Q{j/16}`: its
//!     output is `{"branch": [[{"coil": "M{j}_{p}"}], [{"coil": "Q{j/16}"}]]}`.
//! * **`loops`**: 1 in 200 rungs (outside any other structure) starts a FOR block: a header
//!   rung with 2–3 conditions then `{"for": {"var": "i{k}", "from": 1, "to": 3}}` (`k` = the
//!   header's lane), 2–4 body rungs (normal rungs that also accumulate
//!   `{"op": "ADD", "in": ["N{j}_{p}", "i{k}"], "out": "N{j}_{p}"}` before their output) and a
//!   `[{"next": true}]` rung. Blocks are not nested. Header, body and NEXT rungs all count in
//!   `n` and occupy their stage/lane slots (header and NEXT write no `M`).
//!   With `for_body = N` (`--for-body N`, which needs `--loops`; `N ≥ 1`) every block has
//!   exactly `N` body rungs, and the first block starts at the first rung where it fits
//!   (header not a `Q` writer, NEXT before the end rung and not a `Q` writer), so a program
//!   with room for one block has one (e.g. `--rungs 10000 --loops --for-body 4000`: rung 0 heads a
//!   4,000-rung body closed by the NEXT rung 4001); further blocks start as above. A block that does not fit
//!   is not made.
//! * **`jumps`**: 1 in 100 rungs (outside FOR bodies, at most one jump pending at a time, no
//!   FOR block starting while one is) is a jump rung: 2–3 conditions then `{"jmp": "L{m}"}`,
//!   skipping the next 1–5 rungs; the target rung carries `"label": "L{m}"` (labels numbered
//!   program-wide, hence unique per POU). A jump that would run past the end is not made.
//!   Jumps never enter or leave a FOR body and never go backwards, so every scan terminates.
//!   The last main rung is `[{"end": true}]` when `n ≥ 3` and it is not a `Q` writer.
//! * **`calls`**: 2–4 subroutines `SBR_0..` of 3–10 rungs (the first has at least 4), whose
//!   rungs are numbered after the main ones. 1 in 500 main rungs (outside FOR bodies) is a call
//!   rung: 2–3 conditions then `{"call": "SBR_k"}`. Subroutine `k` declares its own BOOL
//!   `S{k}_B0..` (one per rung) and INT `S{k}_N`; its rung `i` reads `S{k}_B{i-1}`,
//!   `S{k}_B{i-2}`, a global input and a global `M..._0`, and writes `S{k}_B{i}`; one rung
//!   accumulates `S{k}_N` with an `op`, the last compares it and also writes the global
//!   `SR{k}` through a `branch`. Some subroutines call `SBR_{k+1}` (so calls form an acyclic
//!   chain), have a conditional `{"ret": true}` rung (SBR_0 always does), and, with `jumps`,
//!   a forward jump from their first rung.
//! * **`hot_fraction = F`** (`--hot-fraction F`, `0 < F ≤ 1`): a hot variable, the global BOOL
//!   `FAULT` (declared last), set by `k_w = clamp(round(F n), 1, n)` main rungs and read by
//!   `k_r = max(1, k_w / 10)`. Slot `i` of `k` is rung `(i n + off) / k` (evenly spread; the
//!   offset `off < k` comes from the seed through its own generator stream, so every rung that
//!   has no slot is byte-identical to the program without `hot_fraction`). A writer's output gets
//!   an extra path `[{"set": "FAULT"}]` (the output becomes a `branch` if it is not one); a reader
//!   gets `{"contact": "FAULT", "negated": true}` after its other conditions. Only normal and FOR
//!   body rungs carry slots; a slot on a header, NEXT, jump, call or end rung is owed to the next
//!   normal rung that has none of its own, so the counts are exact unless slots are still owed
//!   after the last normal rung. `--rungs 100000 --hot-fraction 0.05` gives 5,000 writers of
//!   `FAULT` 20 rungs apart and 500 readers: about 12.5 million output pairs (and 2.5 million
//!   flow and anti pairs) under the every-pair definition of the dependences, against a few per
//!   rung for the rest of the program.
//!
//! With every knob on and a few thousand rungs, every element kind of the format appears.
//! INT arithmetic is not bounded: over many scans accumulators may wrap (16-bit INT), so an
//! interpreter should use wrapping arithmetic.
//!
//! `rungs = 0` is refused (a program has at least one rung), as are `rungs` or `for_body` above
//! [`MAX_RUNGS`] (a program the readers could not read back), `for_body = 0` and a
//! `hot_fraction` outside `(0, 1]`: `GenConfig::validate` says why, `write_program` returns an
//! `InvalidInput` error without writing anything, and `plc-deps gen --rungs 0` exits with status 2
//! and `error: --rungs must be at least 1 (a program has at least one rung)`. The CLI also refuses
//! `--width 0` (the library clamps `width` to at least 1).
#![forbid(unsafe_code)]

mod emit;
mod hot;
mod program;
mod rung;
mod subs;

use emit::*;
use hot::{HotDuty, HotPlan};
use std::io::{self, Write};
use subs::SubPlan;

/// The most main rungs [`write_program`] writes: the largest such program (every knob on,
/// one stage as wide as the program, random reads) is about 500 bytes a rung, under the 2 GiB
/// the program readers read (`plc-deps` refuses a larger file), so whatever `gen` writes loads
/// back. Measured: 4,000,000 rungs of that shape (`--width 4000000`) are 1,958,606,542 bytes.
pub const MAX_RUNGS: usize = 4_000_000;

/// Shape knobs for [`write_program`]; see the module documentation for the exact shape.
#[derive(Debug, Clone, PartialEq)]
pub struct GenConfig {
    /// Number of rungs of the main program (subroutine rungs come on top, with `calls`).
    pub rungs: usize,
    /// Rungs per stage (lanes); the data-flow depth is about `rungs / width`. Clamped to
    /// `1..=max(rungs, 1)`.
    pub width: usize,
    /// Seed of the generator: same config (seed included) ⇒ byte-identical output.
    pub seed: u64,
    /// Timer (TON/TOF/TP) and counter (CTU/CTD) boxes, and contacts reading their outputs.
    pub timers: bool,
    /// FOR/NEXT blocks (about 1 in 200 rungs starts one).
    pub loops: bool,
    /// Conditional forward jumps (about 1 in 100 rungs) and a final `end` rung.
    pub jumps: bool,
    /// 2–4 subroutines, called from about 1 in 500 rungs.
    pub calls: bool,
    /// With `loops`: every FOR block has exactly this many body rungs (at least 1), and the
    /// first block starts at the first rung where it fits. `None`: 2–4 body rungs at random.
    pub for_body: Option<usize>,
    /// `Some(F)` with `0 < F ≤ 1`: about `F * rungs` main rungs also set the global BOOL `FAULT`
    /// and about a tenth as many read it (spread evenly; see the module documentation).
    pub hot_fraction: Option<f64>,
    /// Where a rung's conditions come from in the previous stage (see [`Reads`]).
    pub reads: Reads,
}

/// Which lanes of the previous stage a rung reads (`gen --reads`: the variants are the command
/// line's values, their doc comments not its help).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
#[cfg_attr(feature = "clap", derive(clap::ValueEnum))]
pub enum Reads {
    /// 3–5 of the nearby lanes `j-2..=j+2` (the default: producers and consumers stay close,
    /// as in real programs laid out by function).
    #[default]
    #[cfg_attr(feature = "clap", value(help = None::<&str>))]
    Local,
    /// 3–6 distinct lanes drawn uniformly from all `W` lanes (fewer when `W` is smaller): the
    /// values a level reads are spread over the whole level before it.
    #[cfg_attr(feature = "clap", value(help = None::<&str>))]
    Random,
}

impl Default for GenConfig {
    /// 1000 rungs, 32 lanes, seed 0, all knobs off.
    fn default() -> Self {
        GenConfig {
            rungs: 1000,
            width: 32,
            seed: 0,
            timers: false,
            loops: false,
            jumps: false,
            calls: false,
            for_body: None,
            hot_fraction: None,
            reads: Reads::Local,
        }
    }
}

impl GenConfig {
    /// The same shape with every knob (timers, loops, jumps, calls) on.
    pub fn all_features(rungs: usize, width: usize, seed: u64) -> Self {
        GenConfig {
            rungs,
            width,
            seed,
            timers: true,
            loops: true,
            jumps: true,
            calls: true,
            for_body: None,
            hot_fraction: None,
            reads: Reads::Local,
        }
    }

    /// Checks what [`write_program`] needs: `1 ≤ rungs ≤` [`MAX_RUNGS`] (a program has at least
    /// one rung, and one the readers can read back), `1 ≤ for_body ≤` [`MAX_RUNGS`] (a longer
    /// body fits no program, and rung numbers plus a body length cannot overflow), and
    /// `0 < hot_fraction ≤ 1`. `width` is clamped, never refused.
    pub fn validate(&self) -> Result<(), ConfigError> {
        if self.rungs == 0 {
            return Err(ConfigError::NoRungs);
        }
        if self.rungs > MAX_RUNGS {
            return Err(ConfigError::TooManyRungs(self.rungs));
        }
        match self.for_body {
            Some(0) => return Err(ConfigError::EmptyForBody),
            Some(b) if b > MAX_RUNGS => return Err(ConfigError::ForBodyTooLong(b)),
            _ => {}
        }
        match self.hot_fraction {
            Some(f) if !(f > 0.0 && f <= 1.0) => Err(ConfigError::HotFraction(f)),
            _ => Ok(()),
        }
    }
}

/// Why [`GenConfig::validate`] refuses a config.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum ConfigError {
    /// `rungs = 0`.
    #[error("rungs must be at least 1 (a program has at least one rung)")]
    NoRungs,
    /// `for_body = Some(0)`.
    #[error("for_body must be at least 1")]
    EmptyForBody,
    /// `rungs > MAX_RUNGS`.
    #[error("rungs must be at most {MAX_RUNGS}, not {0}")]
    TooManyRungs(usize),
    /// `for_body > MAX_RUNGS`.
    #[error("for_body must be at most {MAX_RUNGS}, not {0}")]
    ForBodyTooLong(usize),
    /// `hot_fraction` outside `(0, 1]` (or NaN).
    #[error("hot_fraction must be in (0, 1], not {0}")]
    HotFraction(f64),
}

/// Writes the program JSON for `config` to `out` (buffered internally; flushed at the end).
/// An invalid config ([`GenConfig::validate`]) is an [`io::ErrorKind::InvalidInput`] error and
/// writes nothing.
pub fn write_program<W: Write>(config: &GenConfig, out: W) -> io::Result<()> {
    config
        .validate()
        .map_err(|e| io::Error::new(io::ErrorKind::InvalidInput, e))?;
    let mut w = io::BufWriter::with_capacity(1 << 16, out);
    Generator::new(config).write(&mut w)?;
    w.flush()
}

/// [`write_program`] into a `String`. Panics on an invalid config ([`GenConfig::validate`]).
pub fn generate_string(config: &GenConfig) -> String {
    let mut buf = Vec::new();
    if let Err(e) = write_program(config, &mut buf) {
        panic!("{config:?}: {e}");
    }
    String::from_utf8(buf).expect("the generator writes ASCII only")
}

/// The variable phase of stage `s`: memory is recycled every 4 stages within sections of 8
/// stages (`(s / 8) * 4 + s % 4`), so each lane variable has at most two writers, the way real
/// programs keep variables local to a section; the number of dependence pairs stays linear.
pub fn phase(s: usize) -> usize {
    (s / 8) * 4 + s % 4
}

/// The generator's state while it writes one program (see [`program`] for the frame, [`rung`]
/// for the contents of main rungs, [`subs`] for the subroutines).
struct Generator {
    cfg: GenConfig,
    n: usize,
    lanes: usize,
    phases: usize,
    inputs: usize,
    outputs: usize,
    has_end: bool,
    subs: Vec<SubPlan>,
    sub_rng: Rng,
    rng: Rng,
    prev: Vec<u8>,
    cur: Vec<u8>,
    labels: usize,
    conds: Vec<Elem>,
    tail: Vec<Elem>,
    /// The hot variable's slots (`hot_fraction`).
    hot: Option<HotPlan>,
    /// What the rung being built does with the hot variable.
    duty: HotDuty,
}
