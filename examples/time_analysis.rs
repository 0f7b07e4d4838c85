//! Times loading and each analysis step: `cargo run --release --example time_analysis FILE`.

// mimalloc: the analyses allocate many small vectors right after the loader frees a large JSON
// tree; glibc's malloc spends seconds consolidating that heap at 1M rungs, mimalloc does not.
#[global_allocator]
static GLOBAL: mimalloc::MiMalloc = mimalloc::MiMalloc;
use plc_deps::analysis::*;
use std::time::Instant;
fn main() {
    let path = std::env::args().nth(1).expect("usage: time_analysis FILE");
    let text = std::fs::read_to_string(&path).expect("read");
    let t = Instant::now();
    let p = plc_deps::load::program_from_json(&text).expect("load");
    eprintln!("load: {:?} ({} rungs)", t.elapsed(), p.rungs().len());
    let all = Instant::now();
    let t = Instant::now();
    let acc = accesses(&p);
    eprintln!("accesses: {:?}", t.elapsed());
    let t = Instant::now();
    let d = data_dependences(&acc.reads, &acc.writes);
    eprintln!("data dependences: {:?} ({})", t.elapsed(), d.len());
    let t = Instant::now();
    let _ = data_levels(&acc.reads, &acc.writes);
    eprintln!("data levels: {:?}", t.elapsed());
    let t = Instant::now();
    let cfg = control_flow_graph(&p);
    eprintln!("cfg: {:?}", t.elapsed());
    let t = Instant::now();
    let pairs: Vec<(u32, u32)> = cfg
        .edges
        .iter()
        .map(|e| (e.from.raw(), e.to.raw()))
        .collect();
    let pd = post_dominators(cfg.node_count(), &pairs, cfg.stop().raw());
    eprintln!("post-dominators: {:?}", t.elapsed());
    let t = Instant::now();
    let cd = control_dependences(&pairs, &pd, |_| true);
    eprintln!("control dependences: {:?} ({})", t.elapsed(), cd.len());
    let t = Instant::now();
    let s = combined_schedule(&p, &cfg, &acc);
    eprintln!(
        "combined schedule: {:?} ({} levels)",
        t.elapsed(),
        s.levels.len()
    );
    eprintln!("steps total: {:?}", all.elapsed());
    let t = Instant::now();
    let a = analyse(&p);
    eprintln!(
        "analyse: {:?} ({} data deps, {} levels combined)",
        t.elapsed(),
        a.data.len(),
        a.schedule.levels.len()
    );
}
