//! Checking seq == par: every scan's full state in a layout-independent order of its stored
//! values condensed into a 128-bit digest, and the exact lockstep replay that names the first
//! difference.

use super::inputs::InputTable;
use plc_exec::parallel::{ParallelMachine, RunLog};
use plc_exec::{load_bits, parts, Addr, Fault, FaultKind, Machine};
use plc_model::Program;
use serde_json::{json, Value as Json};

/// Stored values in an order independent of the layout (`Machine::canonical_values`): every
/// variable's values in declaration order, then the loop counters in rung order.
pub(super) fn canonical_slots(m: &Machine) -> Vec<(Addr, u32)> {
    m.canonical_values()
}

/// 128-bit digest of a scan's state (its values in canonical order) and faults.
///
/// The values are packed, in canonical order, into 64-bit words (eight BOOLs to a word); each
/// (position, word) pair is hashed on its own (splitmix64's finaliser) and the hashes are
/// summed, in one lane as they are and in another rotated by the position, so that no word
/// waits for the one before it. (Hashing every value into a chain took about 2 ns a value: as
/// long as a scan of `gen --rungs 20000` itself.) Not a cryptographic hash: it tells apart
/// states that differ by chance, not by design.
pub(super) fn digest(mem: &[u8], canon: &[(Addr, u32)], faults: &[Fault]) -> u128 {
    #[inline(always)]
    fn mix(mut z: u64) -> u64 {
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }
    let (mut a, mut b) = (0x243F_6A88_85A3_08D3u64, 0x1319_8A2E_0370_7344u64);
    let mut feed = |i: u64, v: u64| {
        let h = mix(v ^ i.wrapping_mul(0x9E37_79B9_7F4A_7C15));
        a = a.wrapping_add(h);
        b ^= h.rotate_left((i % 63) as u32 + 1);
    };
    // The values packed into 64-bit words in canonical order (most are one-byte BOOLs), one
    // hash per word.
    let (mut word, mut filled, mut k) = (0u64, 0u32, 0u64);
    for &(at, w) in canon {
        let bits = w * 8;
        if filled + bits > 64 {
            feed(k, word);
            (word, filled, k) = (0, 0, k + 1);
        }
        word |= load_bits(mem, at, w) << filled;
        filled += bits;
    }
    if filled > 0 {
        feed(k, word);
    }
    for (i, f) in faults.iter().enumerate() {
        let kind = match f.kind {
            FaultKind::DivByZero => 1,
            FaultKind::LoopCap => 2,
            FaultKind::ScanBudget => 3,
            FaultKind::IndexRange => 4,
        };
        feed(u64::MAX - i as u64, (f.rung.raw() as u64) << 8 | kind);
    }
    ((mix(a ^ mix(b)) as u128) << 64) | mix(b.wrapping_add(mix(a))) as u128
}

/// Names the first difference between the two runs by replaying both exactly up to `scan`.
#[allow(clippy::too_many_arguments)]
pub(super) fn first_difference(
    p: &Program,
    seq: &Machine,
    par: &ParallelMachine,
    pool: Option<&rayon::ThreadPool>,
    log: &RunLog,
    inputs: &InputTable,
    until: u64,
) -> Json {
    let (cs, cp) = (canonical_slots(seq), canonical_slots(par.machine()));
    let (mut a, mut b) = (seq.initial_state(), par.initial_state());
    let n_var_slots: usize = p.vars().iter().map(|v| parts(v.ty).len()).sum();
    let value = |mem: &[u8], (at, w): (Addr, u32)| load_bits(mem, at, w);
    for scan in 0..=until {
        let (mut fa, mut fb) = (Vec::new(), Vec::new());
        seq.scan(&mut a, scan, inputs.at(scan), &mut fa);
        // The candidate the run used for this scan: the replay repeats the run exactly.
        par.scan_on(
            log.candidate_at(scan),
            pool,
            &mut b,
            scan,
            inputs.at(scan),
            &mut fb,
        );
        if let Some(i) = cs
            .iter()
            .zip(&cp)
            .position(|(&x, &y)| value(a.bytes(), x) != value(b.bytes(), y))
        {
            if i < n_var_slots {
                // Which variable holds canonical value i.
                let mut k = 0;
                for v in p.vars().ids() {
                    let w = parts(p.var(v).ty).len();
                    if i < k + w {
                        let (va, vb) = (seq.value(&a, v), par.machine().value(&b, v));
                        let mut d = json!({"scan": scan, "variable": p.var(v).name, "seq": va.to_json(), "par": vb.to_json()});
                        if va == vb {
                            d["detail"] =
                                json!(format!("internal value {} of the instance", i - k));
                        }
                        return d;
                    }
                    k += w;
                }
            }
            let (rung, _) = seq
                .loop_counters()
                .nth(i - n_var_slots)
                .expect("a loop counter");
            return json!({"scan": scan, "variable": format!("loop counter of rung {}", p.rung(rung).id),
                "seq": value(a.bytes(), cs[i]), "par": value(b.bytes(), cp[i])});
        }
        if fa != fb {
            let list = |fs: &[Fault]| {
                fs.iter().map(|f| json!({"scan": f.scan, "rung": p.rung(f.rung).id, "kind": f.kind.name()})).collect::<Vec<_>>()
            };
            return json!({"scan": scan, "variable": null, "faults": {"seq": list(&fa), "par": list(&fb)}});
        }
    }
    json!({"scan": until, "variable": null, "detail": "the digests differed but an exact replay found no difference"})
}

#[cfg(test)]
mod tests {
    use super::*;
    use plc_analysis::analyse;
    use plc_exec::parallel::PlanConfig;
    use plc_exec::{ExecConfig, Layout};
    #[test]
    fn first_difference_names_the_variable_and_both_values() {
        // The same program on two clocks: the timer's ET differs from scan 1 on.
        let p = plc_load::program_from_json(
            r#"{"program": "t", "vars": [{"name": "go", "type": "BOOL", "class": "input", "init": true},
                {"name": "T1", "type": "TON"}], "rungs": [{"id": "R1", "ld": [{"contact": "go"}, {"ton": "T1", "pt": "T#1s"}]}]}"#,
        )
        .unwrap();
        let a = analyse(&p);
        let seq = Machine::new(
            &p,
            Layout::dense(&p),
            &ExecConfig {
                cycle_ms: 10,
                loop_cap: 10,
                scan_budget: plc_exec::DEFAULT_SCAN_BUDGET,
            },
        )
        .unwrap();
        let par = ParallelMachine::new(
            &p,
            &a,
            &ExecConfig {
                cycle_ms: 20,
                loop_cap: 10,
                scan_budget: plc_exec::DEFAULT_SCAN_BUDGET,
            },
            &PlanConfig::new(1),
        )
        .unwrap();
        let log = RunLog::default();
        let d = first_difference(&p, &seq, &par, None, &log, &InputTable::default(), 5);
        assert_eq!(
            d,
            json!({"scan": 1, "variable": "T1", "seq": {"Q": false, "ET": 10, "PT": 1000}, "par": {"Q": false, "ET": 20, "PT": 1000}})
        );
        let d = first_difference(&p, &seq, &par, None, &log, &InputTable::default(), 0);
        assert_eq!(d["variable"], Json::Null, "no difference in scan 0: {d}");
    }

    #[test]
    fn digests_see_every_value_and_the_faults() {
        let canon = [(Addr(0), 1), (Addr(2), 2), (Addr(4), 4)];
        let state = |a: u8, b: i16, c: i32| {
            let mut m = vec![0u8; 8];
            m[0] = a;
            m[2..4].copy_from_slice(&b.to_ne_bytes());
            m[4..8].copy_from_slice(&c.to_ne_bytes());
            m
        };
        let base = digest(&state(1, 2, 3), &canon, &[]);
        assert_ne!(base, digest(&state(1, 2, 4), &canon, &[]));
        assert_ne!(base, digest(&state(2, 1, 3), &canon, &[]));
        assert_ne!(base, digest(&state(1, 2, 3 << 16), &canon, &[]));
        let f = Fault {
            scan: 0,
            rung: plc_model::RungId::from_raw(0),
            kind: FaultKind::DivByZero,
        };
        assert_ne!(base, digest(&state(1, 2, 3), &canon, &[f]));
        // The same values at other addresses.
        let mut moved = vec![9u8; 16];
        moved[8..16].copy_from_slice(&state(1, 2, 3));
        let canon_moved = canon.map(|(at, w)| (at.offset(8), w));
        assert_eq!(
            base,
            digest(&moved, &canon_moved, &[]),
            "the layout does not matter"
        );
    }
}
