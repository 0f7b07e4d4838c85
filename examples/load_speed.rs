//! Load speed and memory of the reader and resolver alone, on a file:
//! `cargo run --release --example load_speed -- /tmp/g1m.json 3` (run the built example under
//! `/usr/bin/time -v` for the peak memory), after
//! `plc-deps gen --rungs 1000000 --width 5000 -o /tmp/g1m.json`.

// The command line's allocator, so that the figures are the command line's.
#[global_allocator]
static GLOBAL: mimalloc::MiMalloc = mimalloc::MiMalloc;

use std::time::Instant;

fn main() {
    let mut args = std::env::args().skip(1);
    let Some(path) = args.next() else {
        eprintln!("usage: load_speed FILE [RUNS]");
        std::process::exit(2);
    };
    let text = std::fs::read_to_string(&path).expect("read the file");
    let runs: usize = args.next().and_then(|s| s.parse().ok()).unwrap_or(1);
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
