//! Times the two steps of loading: `cargo run --release --example time_load FILE`.

// mimalloc: the analyses allocate many small vectors right after the loader frees a large JSON
// tree; glibc's malloc spends seconds consolidating that heap at 1M rungs, mimalloc does not.
#[global_allocator]
static GLOBAL: mimalloc::MiMalloc = mimalloc::MiMalloc;
use std::time::Instant;
fn main() {
    let path = std::env::args().nth(1).expect("usage: time_load FILE");
    let text = std::fs::read_to_string(&path).expect("read");
    let t = Instant::now();
    let v: serde_json::Value = serde_json::from_str(&text).expect("json");
    eprintln!("parse: {:?}", t.elapsed());
    let t = Instant::now();
    let p = plc_deps::load::program_from_value(&v).expect("load");
    eprintln!("resolve: {:?} ({} rungs)", t.elapsed(), p.rungs().len());
    let t = Instant::now();
    drop(v);
    eprintln!("drop: {:?}", t.elapsed());
}
