//! The exchange of a levelled plan run on private states (`par-exchange`): what each worker
//! hands the others after each phase, found from the *lowered instructions'* actual byte writes
//! (`Machine::rung_accesses`), as segments of the state packed into 64-bit words: a run of BOOL
//! bytes as bits (64 BOOLs a word: a level's 500 BOOLs cross the cores as one line instead of
//! eight), anything else byte for byte.
//!
//! The idea is distributed memory's: in a levelled plan every byte is written by at most one
//! worker per phase and no worker reads in a phase what another writes in it (the plan check),
//! so a worker that runs its slices on a private copy of the state, and before each phase copies
//! in what the others wrote in the phase before, reads exactly the values the sequential walk
//! reads. Only the exchanged words cross between the cores; no line of the state is shared.
//!
//! Invariants: a key (one per (phase, worker), and one for the driver's inputs) lists exactly
//! the bytes it covers (never a padding byte or another key's byte by rounding: a partial word
//! copies only its bytes); every key has at least one line, so waiting for every other worker's
//! key of a phase is a barrier even for a worker that writes nothing. It does not run anything
//! (the running side's `exchange` does). A sequential phase of the plan is worker 0's alone:
//! the other workers' keys of it are empty.

use super::early::{Split, Splitter};
use super::plan::Plan;
use crate::{Layout, Machine};
use plc_model::{Program, Type};

/// Data words per exchange line; the eighth word of a line is its sequence number.
pub(in crate::parallel) const LINE_WORDS: usize = 7;

/// A run of state bytes one key hands over.
#[derive(Copy, Clone, Debug, PartialEq, Eq)]
pub(in crate::parallel) struct Segment {
    /// First byte in the state.
    pub at: u32,
    /// Bytes.
    pub len: u32,
    /// BOOL bytes (each 0 or 1), packed 64 to a word; otherwise 8 bytes a word.
    pub bools: bool,
    /// First data word, counted from the key's first.
    pub word: u32,
}

impl Segment {
    /// Data words the segment takes.
    pub(crate) fn words(&self) -> u32 {
        if self.bools {
            self.len.div_ceil(64)
        } else {
            self.len.div_ceil(8)
        }
    }
}

/// What one worker hands over after one phase (or worker 0 before a scan): its segments and
/// its lines in the exchange buffer.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub(in crate::parallel) struct Key {
    pub segments: Vec<Segment>,
    /// First line, counted from the buffer's first.
    pub first_line: u32,
    /// Lines (at least one).
    pub lines: u32,
}

/// The exchange of one plan: a key per (phase, worker), in that order, and the key of the
/// program's inputs, which worker 0 hands over after the driver wrote them, before each scan.
#[derive(Clone, Debug)]
pub(crate) struct Exchange {
    pub(in crate::parallel) threads: usize,
    pub(in crate::parallel) keys: Vec<Key>,
    /// Per (phase, worker), as `keys`: its work in the order it runs it (`early`).
    pub(in crate::parallel) splits: Vec<Split>,
    pub(in crate::parallel) inputs: Key,
    /// Lines of all keys (one set of buffers).
    pub(in crate::parallel) lines: u32,
}

impl Exchange {
    /// The key of worker `w` after phase `phase`.
    pub(in crate::parallel) fn key(&self, phase: usize, w: usize) -> &Key {
        &self.keys[phase * self.threads + w]
    }

    /// Worker `w`'s work of phase `phase`, in the order it runs it.
    pub(in crate::parallel) fn split(&self, phase: usize, w: usize) -> &Split {
        &self.splits[phase * self.threads + w]
    }

    /// Items run before their phase's hand-over, and items in all, once the plan's items are
    /// cut into pieces (for `--explain`).
    pub(crate) fn early_items(&self) -> (u64, u64) {
        let early = self.splits.iter().map(|s| s.early as u64).sum();
        let all = self.splits.iter().map(|s| s.items.len() as u64).sum();
        (early, all)
    }

    /// Data words a scan hands over, over all keys (for `--explain`).
    pub(crate) fn words(&self) -> u64 {
        let segs = self
            .keys
            .iter()
            .chain([&self.inputs])
            .flat_map(|k| &k.segments);
        segs.map(|s| s.words() as u64).sum()
    }

    /// Lines of all keys, one set of buffers (a run keeps two: consecutive scans use
    /// different ones).
    pub(crate) fn lines(&self) -> u32 {
        self.lines
    }
}

/// Which bytes of a state of `size` bytes hold a BOOL variable.
fn bool_bytes(p: &Program, layout: &Layout, size: usize) -> Vec<bool> {
    let mut is_bool = vec![false; size];
    for (v, var) in p.vars().iter_enumerated() {
        if var.ty == Type::Bool {
            is_bool[layout.start(v).index()] = true;
        }
    }
    is_bool
}

/// The key of ascending, distinct `bytes`, its lines from `first_line`: runs of consecutive
/// bytes of one class.
fn key_of(bytes: &[u32], is_bool: &[bool], first_line: u32) -> Key {
    let mut segments: Vec<Segment> = Vec::new();
    let mut word = 0;
    for &b in bytes {
        let bools = is_bool[b as usize];
        match segments.last_mut() {
            Some(s) if s.at + s.len == b && s.bools == bools => s.len += 1,
            _ => {
                if let Some(s) = segments.last() {
                    word += s.words();
                }
                segments.push(Segment {
                    at: b,
                    len: 1,
                    bools,
                    word,
                });
            }
        }
    }
    let words = segments.last().map_or(0, |s| s.word + s.words());
    Key {
        segments,
        first_line,
        lines: (words as usize).div_ceil(LINE_WORDS).max(1) as u32,
    }
}

/// The exchange of `plan` (checked, levelled) on `machine`; `Err(why)` if the plan cannot run
/// that way (a dependence-driven plan, the sequential walk, or a program that writes an
/// input). A sequential phase is worker 0's: the others' keys of it are empty.
pub(in crate::parallel) fn exchange_plan(
    p: &Program,
    machine: &Machine,
    plan: &Plan,
) -> Result<Exchange, String> {
    if plan.ready.is_some() {
        return Err("a dependence-driven plan orders its items by ready flags".into());
    }
    if plan.sequential.is_some() || plan.phases.is_empty() {
        return Err("the plan is the sequential walk".into());
    }
    let size = machine.state_size() as usize;
    let is_bool = bool_bytes(p, machine.layout(), size);
    let mut written = vec![false; size];
    let mut mine = vec![false; size];
    let mut sp = Splitter::new(size);
    let mut before: Vec<Vec<u32>> = vec![Vec::new(); plan.threads];
    let mut keys = Vec::with_capacity(plan.phases.len() * plan.threads);
    let mut splits = Vec::with_capacity(keys.capacity());
    let mut line = 0;
    for (pi, ph) in plan.phases.iter().enumerate() {
        let mut now: Vec<Vec<u32>> = Vec::with_capacity(plan.threads);
        for w in 0..plan.threads {
            let mut bytes: Vec<u32> = Vec::new();
            let split = sp.split(machine, plan, (w, ph.items_of(w)), pi == 0, |writes| {
                for &(at, n) in writes {
                    for b in at.0..at.0 + n {
                        if !std::mem::replace(&mut mine[b as usize], true) {
                            bytes.push(b);
                        }
                        written[b as usize] = true;
                    }
                }
            });
            splits.push(split);
            bytes.sort_unstable();
            for &b in &bytes {
                mine[b as usize] = false;
            }
            let key = key_of(&bytes, &is_bool, line);
            line += key.lines;
            keys.push(key);
            now.push(bytes);
        }
        sp.next_phase(&before, &now);
        before = now;
    }
    let mut inputs: Vec<u32> = Vec::new();
    for (at, n) in machine.input_spans() {
        for b in at.0..at.0 + n {
            if written[b as usize] {
                return Err(format!("byte {b} of an input is written by the program"));
            }
            inputs.push(b);
        }
    }
    inputs.sort_unstable();
    inputs.dedup();
    let inputs = key_of(&inputs, &is_bool, line);
    line += inputs.lines;
    Ok(Exchange {
        threads: plan.threads,
        keys,
        splits,
        inputs,
        lines: line,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::parallel::config::{PlanConfig, Strategy};
    use crate::{ExecConfig, LINE_BYTES};

    /// Each worker's key after the one phase holds exactly the bytes its rung writes (a BOOL
    /// coil, and an INT through MOVE), and the inputs' key the inputs' bytes.
    #[test]
    fn keys_hold_exactly_what_each_worker_writes() {
        let p = plc_load::program_from_json(
            r#"{"program": "p", "vars": [
                {"name": "a", "type": "BOOL", "class": "input"},
                {"name": "b", "type": "BOOL", "class": "input"},
                {"name": "x", "type": "BOOL", "class": "output"},
                {"name": "y", "type": "BOOL", "class": "output"},
                {"name": "n", "type": "INT", "class": "output"}],
              "rungs": [{"id": "R1", "ld": [{"contact": "a"}, {"coil": "x"}]},
                        {"id": "R2", "ld": [{"contact": "b"}, {"coil": "y"},
                                            {"move": 7, "to": "n"}]}]}"#,
        )
        .unwrap();
        let a = plc_analysis::analyse(&p);
        let config = PlanConfig {
            strategy: Strategy::AllParallel,
            ..PlanConfig::new(2)
        };
        let plan = Plan::build(&p, &a, &config);
        assert_eq!(plan.phases.len(), 1);
        let groups = super::super::plan::bools_first(
            &p,
            super::super::plan::layout_groups(&[&plan], p.vars()),
        );
        let layout = Layout::from_groups(&p, &groups, LINE_BYTES).unwrap();
        let m = Machine::new(&p, layout.clone(), &ExecConfig::default()).unwrap();
        let x = exchange_plan(&p, &m, &plan).unwrap();
        let at = |v: u32| layout.start(plc_model::VarId::from_raw(v)).0;
        let seg = |at, len, bools, word| Segment {
            at,
            len,
            bools,
            word,
        };
        let (w0, w1) = (&x.key(0, 0).segments, &x.key(0, 1).segments);
        let r1 = vec![seg(at(2), 1, true, 0)];
        let r2 = vec![seg(at(3), 1, true, 0), seg(at(4), 2, false, 1)];
        // One worker runs R1, the other R2 (which one is the slicing's business).
        assert!(
            (*w0 == r1 && *w1 == r2) || (*w0 == r2 && *w1 == r1),
            "{w0:?} {w1:?}"
        );
        // Inputs a and b are packed next to each other.
        assert_eq!(at(1), at(0) + 1);
        assert_eq!(x.inputs.segments, vec![seg(at(0), 2, true, 0)]);
        assert_eq!((x.words(), x.lines()), (4, 3));
    }

    #[test]
    fn runs_split_by_class_and_gap_and_count_their_words() {
        // Bytes 0..70 BOOL, 70..72 not, 80 BOOL: three segments (a gap before 80).
        let mut is_bool = vec![false; 128];
        is_bool[..70].fill(true);
        is_bool[80] = true;
        let bytes: Vec<u32> = (0..72).chain([80]).collect();
        let k = key_of(&bytes, &is_bool, 5);
        let seg = |at, len, bools, word| Segment {
            at,
            len,
            bools,
            word,
        };
        assert_eq!(
            k.segments,
            vec![
                seg(0, 70, true, 0),
                seg(70, 2, false, 2),
                seg(80, 1, true, 3)
            ]
        );
        assert_eq!((k.first_line, k.lines), (5, 1));
        // Nothing to hand over still takes a line (its sequence number is the barrier).
        assert_eq!(key_of(&[], &is_bool, 0).lines, 1);
        // 8 words: two lines.
        let many: Vec<u32> = (0..64).collect();
        assert_eq!(key_of(&many, &[false; 64], 0).lines, 2);
    }
}
