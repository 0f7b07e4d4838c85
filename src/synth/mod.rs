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
//!   `loops`, INT FOR indices `i0..i{W-1}` (one per lane); with `calls`, `SR{k}` BOOL results of the subroutines.
//! * **Normal rung** (stage `s`, lane `j`, phase `p = phase(s) = (s / 8) * 4 + s % 4`): a series
//!   of conditions, optional boxes, then one output writing the lane's own `M{j}_{p}` (memory is
//!   recycled every 4 stages within each section of 8 stages, so each variable has at most two
//!   writers, anti and output dependences occur, the number of dependence pairs stays linear in
//!   the program size, and the data-flow depth stays ≈ `S = n / W`).
//!   - Stage 0 reads inputs only: 4–6 distinct `I..` contacts (1 in 6 negated, 1 in 25 with a
//!     rising/falling edge).
//!   - Stage `s ≥ 1` reads 3–5 of the variables `M{l}_{phase(s-1)}` written by stage `s-1` in the
//!     nearby lanes `l ∈ j-2..=j+2` (mod W, distinct; 1 in 4 negated), one input contact half
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
//!
//! With every knob on and a few thousand rungs, every element kind of the format appears.
//! INT arithmetic is not bounded: over many scans accumulators may wrap (16-bit INT), so an
//! interpreter should use wrapping arithmetic. `rungs = 0` gives an empty (invalid) program.

mod emit;

use emit::*;
use std::io::{self, Write};

/// Shape knobs for [`write_program`]; see the module documentation for the exact shape.
#[derive(Debug, Clone, PartialEq, Eq)]
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
        }
    }
}

/// Writes the program JSON for `config` to `out` (buffered internally; flushed at the end).
pub fn write_program<W: Write>(config: &GenConfig, out: W) -> io::Result<()> {
    let mut w = io::BufWriter::with_capacity(1 << 16, out);
    Generator::new(config).write(&mut w)?;
    w.flush()
}

/// [`write_program`] into a `String`.
pub fn generate_string(config: &GenConfig) -> String {
    let mut buf = Vec::new();
    write_program(config, &mut buf).expect("writing to a Vec cannot fail");
    String::from_utf8(buf).expect("the generator writes ASCII only")
}

// ---------------------------------------------------------------------------------------------
// Generator

/// Per-lane facts about the previous / current stage.
const F_TIMER: u8 = 1;
const F_COUNTER: u8 = 2;
const F_INT: u8 = 4;

const CMP_OPS: [&str; 6] = ["EQ", "NE", "LT", "LE", "GT", "GE"];

/// Layout of one subroutine, fixed before anything is written.
struct SubPlan {
    rungs: usize,
    ret_at: Option<usize>,
    call_next: bool,
    /// Jump from rung 0 to this rung.
    jump_to: Option<usize>,
    input: usize,
    global_lane: Option<usize>,
}

/// The variable phase of stage `s`: memory is recycled every 4 stages within sections of 8
/// stages (`(s / 8) * 4 + s % 4`), so each lane variable has at most two writers, the way real
/// programs keep variables local to a section; the number of dependence pairs stays linear.
pub fn phase(s: usize) -> usize {
    (s / 8) * 4 + s % 4
}

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
}

/// What a main rung slot is.
enum Kind {
    Normal,
    Body(usize),
    ForHead(usize),
    Next,
    Jump(usize),
    Call(usize),
    End,
}

impl Generator {
    fn new(cfg: &GenConfig) -> Self {
        let n = cfg.rungs;
        let lanes = cfg.width.clamp(1, n.max(1));
        let stages = n.div_ceil(lanes);
        let phases = (stages.saturating_sub(8)..stages)
            .map(|s| phase(s) + 1)
            .max()
            .unwrap_or(0);
        let inputs = (lanes / 8).max(8);
        let outputs = lanes.div_ceil(16);
        let mut g = Generator {
            cfg: cfg.clone(),
            n,
            lanes,
            phases,
            inputs,
            outputs,
            has_end: false,
            subs: Vec::new(),
            sub_rng: Rng::new(cfg.seed ^ 0x5EED_5AB0_0000_0001),
            rng: Rng::new(cfg.seed),
            prev: vec![0; lanes],
            cur: vec![0; lanes],
            labels: 0,
            conds: Vec::with_capacity(8),
            tail: Vec::with_capacity(4),
        };
        g.has_end = cfg.jumps && n >= 3 && g.q_of(n - 1).is_none();
        if cfg.calls {
            g.plan_subs();
        }
        g
    }

    fn plan_subs(&mut self) {
        let r = &mut self.sub_rng;
        let count = r.range(2, 4);
        for k in 0..count {
            let rungs = if k == 0 {
                r.range(4, 10)
            } else {
                r.range(3, 10)
            };
            let ret_at = (rungs >= 4 && (k == 0 || r.one_in(2))).then_some(rungs - 2);
            let call_next = k + 1 < count && r.one_in(2);
            let jump_to = (self.cfg.jumps && rungs >= 5 && r.one_in(2)).then(|| r.range(2, 3));
            let input = r.below(self.inputs);
            let global_lane = (self.phases > 0).then(|| r.below(self.lanes));
            self.subs.push(SubPlan {
                rungs,
                ret_at,
                call_next,
                jump_to,
                input,
                global_lane,
            });
        }
    }

    /// `Some(q)` when main rung `r` is the writer of output `Q{q}`.
    fn q_of(&self, r: usize) -> Option<usize> {
        let j = r % self.lanes;
        // The last rung of the lane; the end rung (if any) hands the job to the one before.
        let limit = if self.has_end { self.n - 1 } else { self.n };
        (j.is_multiple_of(16) && r < limit && r + self.lanes >= limit).then_some(j / 16)
    }

    fn write<W: Write>(&mut self, w: &mut W) -> io::Result<()> {
        w.write_all(b"{\"program\":\"GEN\",\"vars\":[")?;
        self.write_globals(w)?;
        w.write_all(b"\n],\"rungs\":[")?;
        self.write_main(w)?;
        w.write_all(b"\n],\"subroutines\":{")?;
        self.write_subs(w)?;
        w.write_all(b"}}\n")
    }

    fn write_globals<W: Write>(&self, w: &mut W) -> io::Result<()> {
        let mut first = true;
        let mut var =
            |w: &mut W, name: Name, ty: &str, class: &str, init: Option<&str>| -> io::Result<()> {
                w.write_all(if first { b"\n" } else { b",\n" })?;
                first = false;
                write!(
                    w,
                    "{{\"name\":\"{name}\",\"type\":\"{ty}\",\"class\":\"{class}\""
                )?;
                if let Some(init) = init {
                    write!(w, ",\"init\":{init}")?;
                }
                w.write_all(b"}")
            };
        for i in 0..self.inputs {
            var(w, Name::I(i), "BOOL", "input", None)?;
        }
        for q in 0..self.outputs {
            var(w, Name::Q(q), "BOOL", "output", None)?;
        }
        for p in 0..self.phases {
            for j in 0..self.lanes {
                var(
                    w,
                    Name::M(j, p),
                    "BOOL",
                    "memory",
                    ((j + p) % 7 == 3).then_some("true"),
                )?;
            }
        }
        let inits = ["1", "2", "5", "10", "100"];
        for p in 0..self.phases {
            for j in 0..self.lanes {
                let init = ((j + 2 * p) % 5 == 1).then(|| inits[(j / 5) % inits.len()]);
                var(w, Name::N(j, p), "INT", "memory", init)?;
            }
        }
        if self.cfg.timers {
            for p in 0..self.phases {
                for j in 0..self.lanes {
                    var(
                        w,
                        Name::T(j, p),
                        Timer::of(j, p).type_name(),
                        "memory",
                        None,
                    )?;
                }
            }
            for p in 0..self.phases {
                for j in 0..self.lanes {
                    let ty = if counter_is_ctu(j, p) { "CTU" } else { "CTD" };
                    var(w, Name::C(j, p), ty, "memory", None)?;
                }
            }
        }
        if self.cfg.loops {
            for k in 0..self.lanes {
                var(w, Name::Idx(k), "INT", "memory", None)?;
            }
        }
        for k in 0..self.subs.len() {
            var(w, Name::Sr(k), "BOOL", "memory", None)?;
        }
        Ok(())
    }

    /// Rung `{"id": ..., "label"?, "comment"?, "ld": [conds..., tail...]}` on its own line.
    fn write_rung<W: Write>(
        &self,
        w: &mut W,
        first: bool,
        id: usize,
        label: Option<usize>,
        comment: Option<usize>,
    ) -> io::Result<()> {
        w.write_all(if first { b"\n" } else { b",\n" })?;
        write!(w, "{{\"id\":\"R{id}\"")?;
        if let Some(l) = label {
            write!(w, ",\"label\":\"L{l}\"")?;
        }
        if let Some(s) = comment {
            write!(w, ",\"comment\":\"stage {s}\"")?;
        }
        w.write_all(b",\"ld\":[")?;
        for (i, e) in self.conds.iter().chain(self.tail.iter()).enumerate() {
            if i > 0 {
                w.write_all(b",")?;
            }
            write_elem(w, e)?;
        }
        w.write_all(b"]}")
    }

    fn write_main<W: Write>(&mut self, w: &mut W) -> io::Result<()> {
        let n = self.n;
        let usable = if self.has_end { n - 1 } else { n };
        let mut pending: Option<(usize, usize)> = None; // (target rung, label)
        let mut in_for: Option<(usize, usize)> = None; // (next rung, k)
        for r in 0..n {
            let (s, j) = (r / self.lanes, r % self.lanes);
            if j == 0 && s > 0 {
                std::mem::swap(&mut self.prev, &mut self.cur);
                self.cur.iter_mut().for_each(|f| *f = 0);
            }
            let label = match pending {
                Some((t, l)) if t == r => {
                    pending = None;
                    Some(l)
                }
                _ => None,
            };
            let is_q = self.q_of(r).is_some();
            let kind = if let Some((next, k)) = in_for {
                if r == next {
                    in_for = None;
                    Kind::Next
                } else {
                    Kind::Body(k)
                }
            } else if self.has_end && r == n - 1 {
                Kind::End
            } else if self.cfg.loops && self.rng.one_in(200) {
                let body = self.rng.range(2, 4);
                let next = r + body + 1;
                if pending.is_none() && !is_q && next < usable && self.q_of(next).is_none() {
                    // One index per lane: a block's index is local to it, as in real programs.
                    let k = r % self.lanes;
                    in_for = Some((next, k));
                    Kind::ForHead(k)
                } else {
                    Kind::Normal
                }
            } else if self.cfg.jumps && self.rng.one_in(100) {
                let skip = self.rng.range(1, 5);
                let target = r + 1 + skip;
                if pending.is_none() && !is_q && target < n {
                    let l = self.labels;
                    self.labels += 1;
                    pending = Some((target, l));
                    Kind::Jump(l)
                } else {
                    Kind::Normal
                }
            } else if self.cfg.calls && self.rng.one_in(500) && !is_q {
                Kind::Call(self.rng.below(self.subs.len()))
            } else {
                Kind::Normal
            };
            self.conds.clear();
            self.tail.clear();
            match kind {
                Kind::Normal => self.normal_rung(r, None),
                Kind::Body(k) => self.normal_rung(r, Some(k)),
                Kind::ForHead(k) => {
                    self.short_conds(s, j);
                    self.tail.push(Elem::For { k });
                }
                Kind::Next => self.tail.push(Elem::Next),
                Kind::Jump(l) => {
                    self.short_conds(s, j);
                    self.tail.push(Elem::Jmp(l));
                }
                Kind::Call(k) => {
                    self.short_conds(s, j);
                    self.tail.push(Elem::Call(k));
                }
                Kind::End => self.tail.push(Elem::End),
            }
            self.write_rung(w, r == 0, r + 1, label, (j == 0).then_some(s))?;
        }
        Ok(())
    }

    /// Distinct lanes among `j-2..=j+2` (mod W), in a random order.
    fn nearby(&mut self, j: usize) -> ([usize; 5], usize) {
        let w = self.lanes;
        let mut out = [0usize; 5];
        let mut len = 0;
        for d in 0..5 {
            let l = (j + w * 2 + d - 2) % w;
            if !out[..len].contains(&l) {
                out[len] = l;
                len += 1;
            }
        }
        for i in (1..len).rev() {
            let k = self.rng.below(i + 1);
            out.swap(i, k);
        }
        (out, len)
    }

    fn input_contact(&mut self, exclude: &[usize]) -> (usize, Elem) {
        let mut i = self.rng.below(self.inputs);
        while exclude.contains(&i) {
            i = (i + 1) % self.inputs;
        }
        let e = if self.rng.one_in(25) {
            let edge = if self.rng.one_in(2) {
                "rising"
            } else {
                "falling"
            };
            Elem::Contact {
                var: Opnd::Var(Name::I(i)),
                negated: false,
                edge: Some(edge),
            }
        } else {
            contact(Name::I(i), self.rng.one_in(6))
        };
        (i, e)
    }

    /// 2–3 conditions for a header / jump / call rung.
    fn short_conds(&mut self, s: usize, j: usize) {
        let count = self.rng.range(2, 3);
        if s == 0 {
            let mut used = [usize::MAX; 3];
            for k in 0..count {
                let (i, e) = self.input_contact(&used[..k]);
                used[k] = i;
                self.conds.push(e);
            }
        } else {
            let pp = phase(s - 1);
            let (lanes, len) = self.nearby(j);
            for &l in lanes.iter().take(count.min(len)) {
                let neg = self.rng.one_in(4);
                self.conds.push(contact(Name::M(l, pp), neg));
            }
            if len < count {
                let (_, e) = self.input_contact(&[]);
                self.conds.push(e);
            }
        }
    }

    fn normal_rung(&mut self, r: usize, body: Option<usize>) {
        let (s, j) = (r / self.lanes, r % self.lanes);
        let p = phase(s);
        // Conditions.
        if s == 0 {
            let count = self.rng.range(4, 6);
            let mut used = [usize::MAX; 6];
            for k in 0..count {
                let (i, e) = self.input_contact(&used[..k]);
                used[k] = i;
                self.conds.push(e);
            }
        } else {
            let pp = phase(s - 1);
            let (lanes, len) = self.nearby(j);
            let take = self.rng.range(3, 5).min(len);
            for &l in &lanes[..take] {
                let neg = self.rng.one_in(4);
                self.conds.push(contact(Name::M(l, pp), neg));
            }
            let mut used = [usize::MAX; 4];
            let mut nin = 0;
            if self.rng.one_in(2) {
                let (i, e) = self.input_contact(&[]);
                used[0] = i;
                nin = 1;
                self.conds.push(e);
            }
            while self.conds.len() < 4 {
                let (i, e) = self.input_contact(&used[..nin]);
                used[nin] = i;
                nin += 1;
                self.conds.push(e);
            }
            if self.cfg.timers {
                if let Some(l) = self.flagged(&lanes[..len], F_TIMER) {
                    if self.rng.one_in(2) {
                        let neg = self.rng.one_in(4);
                        self.conds.push(Elem::Contact {
                            var: Opnd::Field(Name::T(l, pp), "Q"),
                            negated: neg,
                            edge: None,
                        });
                    }
                }
                if let Some(l) = self.flagged(&lanes[..len], F_COUNTER) {
                    if self.rng.one_in(2) {
                        self.conds.push(if self.rng.one_in(2) {
                            Elem::Contact {
                                var: Opnd::Field(Name::C(l, pp), "Q"),
                                negated: false,
                                edge: None,
                            }
                        } else {
                            Elem::Compare {
                                op: "GE",
                                a: Opnd::Field(Name::C(l, pp), "CV"),
                                b: Opnd::Int(3),
                            }
                        });
                    }
                }
            }
            if self.rng.one_in(30) {
                let l = self.flagged(&lanes[..len], F_INT).unwrap_or(j);
                let op = CMP_OPS[self.rng.below(6)];
                let b = self.rng.range(0, 20) as i64 - 5;
                self.conds.push(Elem::Compare {
                    op,
                    a: Opnd::Var(Name::N(l, pp)),
                    b: Opnd::Int(b),
                });
            }
            if self.cfg.calls && self.rng.one_in(100) {
                let k = self.rng.below(self.subs.len());
                self.conds.push(contact(Name::Sr(k), false));
            }
        }
        if self.rng.one_in(8) {
            let b = if self.rng.one_in(3) {
                let (a, b, c) = (
                    self.conds.remove(0),
                    self.conds.remove(0),
                    self.conds.remove(0),
                );
                vec![vec![a, b], vec![c]]
            } else {
                let (a, b) = (self.conds.remove(0), self.conds.remove(0));
                vec![vec![a], vec![b]]
            };
            self.conds.insert(0, Elem::Or(b));
        }
        // Boxes.
        if let Some(k) = body {
            self.tail.push(Elem::Op {
                op: "ADD",
                a: Opnd::Var(Name::N(j, p)),
                b: Opnd::Var(Name::Idx(k)),
                out: Name::N(j, p),
            });
            self.cur[j] |= F_INT;
        }
        if self.cfg.timers {
            if self.rng.one_in(20) {
                self.tail.push(Elem::Timer {
                    kind: Timer::of(j, p),
                    var: Name::T(j, p),
                });
                self.cur[j] |= F_TIMER;
            } else if self.rng.one_in(57) {
                let c = Name::C(j, p);
                let ctl = Opnd::Var(Name::I(self.rng.below(self.inputs)));
                self.tail.push(if counter_is_ctu(j, p) {
                    Elem::Ctu {
                        var: c,
                        pv: Opnd::Int(5),
                        reset: ctl,
                    }
                } else {
                    Elem::Ctd {
                        var: c,
                        pv: Opnd::Int(5),
                        load: ctl,
                    }
                });
                self.cur[j] |= F_COUNTER;
            }
        }
        let mut extra_path = None;
        if body.is_none() && self.rng.one_in(30) {
            let to = Name::N(j, p);
            let src = if s > 0 {
                let l = (j + self.lanes * 2 + self.rng.below(5) - 2) % self.lanes;
                Opnd::Var(Name::N(l, phase(s - 1)))
            } else {
                Opnd::Var(to)
            };
            let e = if self.rng.one_in(2) {
                let from = if self.rng.one_in(2) {
                    Opnd::Int(self.rng.range(0, 100) as i64)
                } else {
                    src
                };
                Elem::Move { from, to }
            } else {
                let (op, c) = match self.rng.below(5) {
                    0 => ("ADD", self.rng.range(1, 10)),
                    1 => ("SUB", self.rng.range(1, 10)),
                    2 => ("MUL", self.rng.range(1, 3)),
                    3 => ("DIV", self.rng.range(1, 9)),
                    _ => ("MOD", self.rng.range(2, 9)),
                };
                Elem::Op {
                    op,
                    a: src,
                    b: Opnd::Int(c as i64),
                    out: to,
                }
            };
            self.cur[j] |= F_INT;
            if self.rng.one_in(2) {
                self.tail.push(e);
            } else {
                extra_path = Some(e);
            }
        }
        // Output.
        let m = Name::M(j, p);
        let q = self.q_of(r);
        if q.is_some() || extra_path.is_some() {
            let mut paths = vec![vec![Elem::Coil {
                var: m,
                negated: false,
            }]];
            if let Some(q) = q {
                paths.push(vec![Elem::Coil {
                    var: Name::Q(q),
                    negated: false,
                }]);
            }
            if let Some(e) = extra_path {
                paths.push(vec![e]);
            }
            self.tail.push(Elem::Branch(paths));
        } else {
            self.tail.push(match self.rng.below(40) {
                0..=3 => Elem::Set(m),
                4..=7 => Elem::Reset(m),
                8 => Elem::Coil {
                    var: m,
                    negated: true,
                },
                _ => Elem::Coil {
                    var: m,
                    negated: false,
                },
            });
        }
    }

    /// A lane among `lanes` whose previous-stage rung has `flag` (first in their random order).
    fn flagged(&self, lanes: &[usize], flag: u8) -> Option<usize> {
        lanes.iter().copied().find(|&l| self.prev[l] & flag != 0)
    }

    fn write_subs<W: Write>(&mut self, w: &mut W) -> io::Result<()> {
        let mut id = self.n + 1;
        for k in 0..self.subs.len() {
            if k > 0 {
                w.write_all(b",")?;
            }
            write!(w, "\n\"SBR_{k}\":{{\"vars\":[")?;
            let sp = &self.subs[k];
            for i in 0..sp.rungs {
                let sep = if i == 0 { "" } else { "," };
                write!(
                    w,
                    "{sep}\n{{\"name\":\"{}\",\"type\":\"BOOL\",\"class\":\"memory\"}}",
                    Name::Sb(k, i)
                )?;
            }
            write!(w, ",\n{{\"name\":\"{}\",\"type\":\"INT\",\"class\":\"memory\",\"init\":0}}\n],\"rungs\":[", Name::Sn(k))?;
            let jump_label = sp.jump_to.map(|_| {
                self.labels += 1;
                self.labels - 1
            });
            let sp = &self.subs[k];
            let (rungs, ret_at, call_next, jump_to, input, global) = (
                sp.rungs,
                sp.ret_at,
                sp.call_next,
                sp.jump_to,
                sp.input,
                sp.global_lane,
            );
            // The op goes on the first plain rung after rung 0.
            let plain = |i: usize| i != 0 && Some(i) != ret_at && !(call_next && i == 1);
            let op_at = (1..rungs).find(|&i| plain(i)).unwrap_or(rungs - 1);
            for i in 0..rungs {
                self.conds.clear();
                self.tail.clear();
                let r = &mut self.sub_rng;
                let label = (jump_to == Some(i)).then_some(jump_label).flatten();
                if i == 0 && jump_to.is_some() {
                    self.conds.push(contact(Name::I(input), r.one_in(2)));
                    self.tail.push(Elem::Jmp(jump_label.unwrap_or(0)));
                } else if Some(i) == ret_at {
                    self.conds.push(contact(Name::I(input), true));
                    self.tail.push(Elem::Ret);
                } else if call_next && i == 1 {
                    self.conds.push(contact(Name::Sb(k, 0), false));
                    self.tail.push(Elem::Call(k + 1));
                } else {
                    if i >= 1 {
                        self.conds.push(contact(Name::Sb(k, i - 1), r.one_in(4)));
                    }
                    if i >= 2 && r.one_in(2) {
                        self.conds.push(contact(Name::Sb(k, i - 2), r.one_in(4)));
                    }
                    if self.conds.is_empty() || r.one_in(2) {
                        self.conds.push(contact(Name::I(input), r.one_in(4)));
                    }
                    if let Some(l) = global {
                        if i == 0 || r.one_in(3) {
                            self.conds.push(contact(Name::M(l, 0), false));
                        }
                    }
                    if i == op_at {
                        self.tail.push(Elem::Op {
                            op: "ADD",
                            a: Opnd::Var(Name::Sn(k)),
                            b: Opnd::Int(1),
                            out: Name::Sn(k),
                        });
                    }
                    let b = Name::Sb(k, i);
                    if i + 1 == rungs {
                        self.conds.push(Elem::Compare {
                            op: "GT",
                            a: Opnd::Var(Name::Sn(k)),
                            b: Opnd::Int(10),
                        });
                        self.tail.push(Elem::Branch(vec![
                            vec![Elem::Coil {
                                var: b,
                                negated: false,
                            }],
                            vec![Elem::Coil {
                                var: Name::Sr(k),
                                negated: false,
                            }],
                        ]));
                    } else {
                        self.tail.push(match r.below(12) {
                            0 => Elem::Set(b),
                            1 => Elem::Reset(b),
                            _ => Elem::Coil {
                                var: b,
                                negated: false,
                            },
                        });
                    }
                }
                self.write_rung(w, i == 0, id, label, None)?;
                id += 1;
            }
            w.write_all(b"\n]}")?;
        }
        if !self.subs.is_empty() {
            w.write_all(b"\n")?;
        }
        Ok(())
    }
}
