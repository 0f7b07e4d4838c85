//! Profiling aid: loads once, then runs `analyse` N times (`... FILE N`).

#[global_allocator]
static GLOBAL: mimalloc::MiMalloc = mimalloc::MiMalloc;

fn main() {
    let mut args = std::env::args().skip(1);
    let path = args.next().expect("usage: time_analyse_only FILE [N]");
    let n: usize = args.next().map(|s| s.parse().unwrap()).unwrap_or(5);
    let p = plc_deps::load::program_from_json(&std::fs::read_to_string(path).unwrap()).unwrap();
    for _ in 0..n {
        let t = std::time::Instant::now();
        let a = plc_deps::analysis::analyse(&p);
        eprintln!(
            "analyse: {:?} ({} levels)",
            t.elapsed(),
            a.schedule.levels.len()
        );
    }
}
