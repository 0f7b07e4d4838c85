//! The sequential interpreter's CPU time per rung on a program file: thread CPU time
//! (`CLOCK_THREAD_CPUTIME_ID`) of the scans alone, so time the thread spends descheduled on a
//! loaded machine does not count (caches shared with other processes still do). Inputs: every
//! BOOL input a fresh xorshift 0/1 per scan (64 rows, cycled); as many scans as `c_speed`
//! (about 20 M rung evaluations, 200 to 20,000 scans); `reps` repetitions, each from the
//! initial state. Prints the minimum and the median in ns per rung per scan.
//!
//! ```text
//! cargo run --release --example interp_cpu -- FILE.json [reps]
//! ```
//!
//! Linux (or any libc with `clock_gettime` and clock id 3) only.

use plc_deps::exec::{ExecConfig, Layout, Machine};
use plc_deps::model::{Type, Value, VarClass, VarId};

#[repr(C)]
struct Timespec {
    sec: i64,
    nsec: i64,
}

extern "C" {
    fn clock_gettime(clock: i32, t: *mut Timespec) -> i32;
}

/// `CLOCK_THREAD_CPUTIME_ID` on Linux.
const THREAD_CPU: i32 = 3;

/// This thread's CPU time, ns.
fn cpu_ns() -> i64 {
    let mut t = Timespec { sec: 0, nsec: 0 };
    // SAFETY: `t` is a valid, writable `struct timespec` (two 64-bit fields on 64-bit Linux).
    let rc = unsafe { clock_gettime(THREAD_CPU, &mut t) };
    assert_eq!(rc, 0, "clock_gettime");
    t.sec * 1_000_000_000 + t.nsec
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let Some(file) = args.get(1) else {
        eprintln!("usage: interp_cpu FILE.json [reps]");
        std::process::exit(2);
    };
    let reps: usize = args
        .get(2)
        .map_or(5, |a| a.parse().expect("reps: a number"));
    let text = std::fs::read_to_string(file).expect("the program file");
    let p = plc_deps::load::program_from_json(&text).expect("a program");
    let m = Machine::new(&p, Layout::dense(&p), &ExecConfig::default()).expect("lowers");
    let rungs = p.main().rungs.len();
    let scans = (20_000_000 / rungs).clamp(200, 20_000);
    let inputs: Vec<VarId> = (0..p.vars().len() as u32)
        .map(VarId::from_raw)
        .filter(|&v| p.var(v).class == VarClass::Input && p.var(v).ty == Type::Bool)
        .collect();
    let mut x = 0x9E37_79B9_7F4A_7C15u64;
    let rows: Vec<Vec<(VarId, Value)>> = (0..64)
        .map(|_| {
            inputs
                .iter()
                .map(|&v| {
                    x ^= x << 13;
                    x ^= x >> 7;
                    x ^= x << 17;
                    (v, Value::Bool(x >> 63 == 1))
                })
                .collect()
        })
        .collect();
    let mut per_rung = Vec::with_capacity(reps);
    for _ in 0..reps {
        let mut state = m.initial_state();
        let mut faults = Vec::new();
        let mut ns = 0i64;
        for k in 0..scans {
            m.set_inputs(&mut state, &rows[k % rows.len()]);
            let t0 = cpu_ns();
            m.run_scan(&mut state, k as u64, &mut faults);
            ns += cpu_ns() - t0;
        }
        per_rung.push(ns as f64 / scans as f64 / rungs as f64);
    }
    per_rung.sort_by(f64::total_cmp);
    println!(
        "{file}: {rungs} rungs, {} instructions, ns/rung (CPU) min {:.2} median {:.2}",
        m.instruction_count(),
        per_rung[0],
        per_rung[per_rung.len() / 2]
    );
}
