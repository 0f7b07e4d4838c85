//! The contents of main rungs: the conditions read from the previous stage, the optional boxes
//! and the output of a normal rung, and the short conditions of header, jump and call rungs.
//! Every choice draws from the main generator `rng`, in a fixed order (the output is
//! byte-identical for a given config). It does not decide where rungs go (`super::program`).

use super::emit::*;
use super::{phase, Generator, Reads};

/// Per-lane facts about the previous / current stage.
const F_TIMER: u8 = 1;
const F_COUNTER: u8 = 2;
const F_INT: u8 = 4;

const CMP_OPS: [&str; 6] = ["EQ", "NE", "LT", "LE", "GT", "GE"];

impl Generator {
    /// The lanes of the previous stage a rung of lane `j` may read, in a random order, and how
    /// many it reads at most: nearby lanes (at most 5), or random ones (at most 6).
    fn sources(&mut self, j: usize) -> ([usize; 6], usize, usize) {
        match self.cfg.reads {
            Reads::Local => {
                let (lanes, len) = self.nearby(j);
                let mut out = [0usize; 6];
                out[..5].copy_from_slice(&lanes);
                (out, len, 5)
            }
            Reads::Random => {
                let w = self.lanes;
                let mut out = [0usize; 6];
                let len = w.min(6);
                if w <= 6 {
                    for (k, o) in out.iter_mut().enumerate().take(len) {
                        *o = k;
                    }
                    for i in (1..len).rev() {
                        let k = self.rng.below(i + 1);
                        out.swap(i, k);
                    }
                } else {
                    let mut n = 0;
                    while n < len {
                        let l = self.rng.below(w);
                        if !out[..n].contains(&l) {
                            out[n] = l;
                            n += 1;
                        }
                    }
                }
                (out, len, 6)
            }
        }
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
    pub(super) fn short_conds(&mut self, s: usize, j: usize) {
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
            let (lanes, len, _) = self.sources(j);
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

    /// A normal rung (stage `s = r / W`, lane `j = r % W`), or a FOR body rung (`body` = the
    /// block's index lane): conditions, boxes, then the output writing `M{j}_{phase(s)}`.
    pub(super) fn normal_rung(&mut self, r: usize, body: Option<usize>) {
        let (s, j) = (r / self.lanes, r % self.lanes);
        let p = phase(s);
        self.conditions(s, j);
        if self.duty.read {
            self.conds.push(contact(Name::Hot, true));
        }
        let extra_path = self.boxes(s, j, body);
        self.output(r, j, p, extra_path);
    }

    /// The conditions of a normal rung into `self.conds`: inputs at stage 0, nearby variables
    /// of stage `s - 1` afterwards, and now and then an `or` around the first two or three.
    fn conditions(&mut self, s: usize, j: usize) {
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
            let (lanes, len, most) = self.sources(j);
            let take = self.rng.range(3, most).min(len);
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
    }

    /// The boxes of a normal rung into `self.tail`; returns the `move`/`op` that goes on an extra
    /// path of the output branch instead, if any.
    fn boxes(&mut self, s: usize, j: usize, body: Option<usize>) -> Option<Elem> {
        let p = phase(s);
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
        extra_path
    }

    /// The output of a normal rung into `self.tail`: `M{j}_{p}`, with the `Q` write of the
    /// lane's last rung and the extra `move`/`op` path in a `branch`.
    fn output(&mut self, r: usize, j: usize, p: usize, extra_path: Option<Elem>) {
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
        if self.duty.write {
            self.set_hot();
        }
    }

    /// Adds `{"set": "FAULT"}` as an extra path of the output (made a `branch` if it is not one).
    fn set_hot(&mut self) {
        let set = vec![Elem::Set(Name::Hot)];
        match self.tail.pop() {
            Some(Elem::Branch(mut paths)) => {
                paths.push(set);
                self.tail.push(Elem::Branch(paths));
            }
            Some(out) => self.tail.push(Elem::Branch(vec![vec![out], set])),
            None => self.tail.push(Elem::Set(Name::Hot)),
        }
    }

    /// A lane among `lanes` whose previous-stage rung has `flag` (first in their random order).
    fn flagged(&self, lanes: &[usize], flag: u8) -> Option<usize> {
        lanes.iter().copied().find(|&l| self.prev[l] & flag != 0)
    }
}
