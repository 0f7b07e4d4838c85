//! The frame of a generated program: the generator's set-up, the global declarations, which
//! main rung slot is which kind (normal, FOR header/body/NEXT, jump, call, end) and the JSON of
//! one rung. It does not choose what a normal rung contains (that is `super::rung`) nor write
//! subroutines (`super::subs`).

use super::emit::*;
use super::{phase, GenConfig, Generator, HotDuty, HotPlan};
use std::io::{self, Write};

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
    pub(super) fn new(cfg: &GenConfig) -> Self {
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
            hot: cfg.hot_fraction.map(|f| HotPlan::new(n, f, cfg.seed)),
            duty: HotDuty::default(),
        };
        g.has_end = cfg.jumps && n >= 3 && g.q_of(n - 1).is_none();
        if cfg.calls {
            g.plan_subs();
        }
        g
    }
}

impl Generator {
    /// `Some(q)` when main rung `r` is the writer of output `Q{q}`.
    pub(super) fn q_of(&self, r: usize) -> Option<usize> {
        let j = r % self.lanes;
        // The last rung of the lane; the end rung (if any) hands the job to the one before.
        let limit = if self.has_end { self.n - 1 } else { self.n };
        (j.is_multiple_of(16) && r < limit && r + self.lanes >= limit).then_some(j / 16)
    }

    pub(super) fn write<W: Write>(&mut self, w: &mut W) -> io::Result<()> {
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
        if self.hot.is_some() {
            var(w, Name::Hot, "BOOL", "memory", None)?;
        }
        Ok(())
    }

    /// Rung `{"id": ..., "label"?, "comment"?, "ld": [conds..., tail...]}` on its own line.
    pub(super) fn write_rung<W: Write>(
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

    /// With a fixed FOR body length, the first block starts at the first rung (not a `Q` writer)
    /// where it fits, so that a program of `n ≥ for_body + 2` rungs (`+ 1` with an end rung)
    /// always has one.
    fn eager_for(&self, r: usize, blocks: usize, usable: usize) -> bool {
        match self.cfg.for_body {
            Some(b) if blocks == 0 => {
                self.q_of(r).is_none() && self.next_fits(r + b.max(1) + 1, usable)
            }
            _ => false,
        }
    }

    /// A FOR block's NEXT rung can go at `next`: before the end rung (if any), not a `Q` writer.
    fn next_fits(&self, next: usize, usable: usize) -> bool {
        next < usable && self.q_of(next).is_none()
    }

    fn write_main<W: Write>(&mut self, w: &mut W) -> io::Result<()> {
        let n = self.n;
        let usable = if self.has_end { n - 1 } else { n };
        let mut pending: Option<(usize, usize)> = None; // (target rung, label)
        let mut in_for: Option<(usize, usize)> = None; // (next rung, k)
        let mut blocks = 0usize; // FOR blocks started
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
            } else if self.cfg.loops
                && ((pending.is_none() && self.eager_for(r, blocks, usable))
                    || self.rng.one_in(200))
            {
                let body = match self.cfg.for_body {
                    Some(b) => b.max(1),
                    None => self.rng.range(2, 4),
                };
                let next = r + body + 1;
                if pending.is_none() && !is_q && self.next_fits(next, usable) {
                    // One index per lane: a block's index is local to it, as in real programs.
                    let k = r % self.lanes;
                    in_for = Some((next, k));
                    blocks += 1;
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
            let can_carry = matches!(kind, Kind::Normal | Kind::Body(_));
            if let Some(hot) = &mut self.hot {
                self.duty = hot.duty(r, can_carry);
            }
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
}
