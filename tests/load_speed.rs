//! Load speed and memory of the reader and resolver alone, on a file:
//! `PLC_LOAD_FILE=/tmp/g1m.json cargo test --release --test load_speed -- --ignored --nocapture`
//! (run the test binary under `/usr/bin/time -v` for the peak memory). Ignored by default: it
//! needs a generated file (`plc-deps gen --rungs 1000000 --width 5000 -o /tmp/g1m.json`).

// The command line's allocator, so that the figures are the command line's.
#[global_allocator]
static GLOBAL: mimalloc::MiMalloc = mimalloc::MiMalloc;

use std::time::Instant;

#[test]
#[ignore]
fn load_file() {
    let Ok(path) = std::env::var("PLC_LOAD_FILE") else {
        eprintln!("set PLC_LOAD_FILE");
        return;
    };
    let text = std::fs::read_to_string(&path).expect("read the file");
    let runs: usize = std::env::var("PLC_LOAD_RUNS")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(1);
    for _ in 0..runs {
        let t = Instant::now();
        let syntax = plc_deps::read::json::parse(&text).expect("parses");
        let parsed = t.elapsed();
        let (p, _) = plc_deps::resolve::resolve(&text, &syntax).expect("resolves");
        let total = t.elapsed();
        drop(syntax);
        let mb = text.len() as f64 / 1e6;
        eprintln!(
            "{} rungs, {mb:.1} MB: parse {parsed:.2?}, parse+resolve {total:.2?} = {:.0} MB/s",
            p.rungs.len(),
            mb / total.as_secs_f64()
        );
        drop(p);
    }
}
