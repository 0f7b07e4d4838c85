//! Subroutines (`calls`): their layout, planned from the subroutine generator `sub_rng` before
//! anything is written, and their rungs, numbered after the main ones. Subroutines only read
//! globals written by the main program's first phase and write their own locals and `SR{k}`.

use super::emit::*;
use super::Generator;
use std::io::{self, Write};

/// Layout of one subroutine, fixed before anything is written.
pub(super) struct SubPlan {
    rungs: usize,
    ret_at: Option<usize>,
    call_next: bool,
    /// Jump from rung 0 to this rung.
    jump_to: Option<usize>,
    input: usize,
    global_lane: Option<usize>,
}

impl Generator {
    pub(super) fn plan_subs(&mut self) {
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

    pub(super) fn write_subs<W: Write>(&mut self, w: &mut W) -> io::Result<()> {
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
