//! Load speed and memory of the reader and resolver alone, on a file:
//! `cargo run --release --example load_speed -- /tmp/g1m.json 3`, after
//! `plc-deps gen --rungs 1000000 --width 5000 -o /tmp/g1m.json`. On Linux it also prints the
//! peak resident memory (VmHWM) after the text is read, after the first
//! load (as the command line loads: the main rungs resolved as they are read), and after
//! parsing into the whole syntax tree, so that what the model costs beyond the text can be read
//! off.

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
    let text_size = text.len();
    let runs: usize = args.next().and_then(|s| s.parse().ok()).unwrap_or(1);
    let mut peaks = vec![("text", peak_mb())];
    for run in 0..runs {
        // As the command line loads a program: the main rungs resolved as they are read.
        let t = Instant::now();
        let (p, _) = plc_deps::load::program_and_fbd_from_json(&text).expect("loads");
        let total = t.elapsed();
        if run == 0 {
            peaks.push(("loaded", peak_mb()));
            // What stays resident with the model alive is the text and the model: the rest of
            // the peak is what loading needed beyond the model (the text included).
            if let (Some(text), Some(resident), Some(peak)) = (peaks[0].1, resident_mb(), peak_mb())
            {
                let model = resident - text;
                eprintln!(
                    "model {model:.0} MB; loading needed {:.0} MB beyond the model = {:.2}x the file",
                    peak - model,
                    (peak - model) / (text_size as f64 / 1e6)
                );
            }
        }
        let mb = text.len() as f64 / 1e6;
        eprintln!(
            "{} rungs, {mb:.1} MB: loaded in {total:.2?} = {:.0} MB/s",
            p.rungs().len(),
            mb / total.as_secs_f64()
        );
        drop(p);
    }
    // The reader alone, into the whole syntax tree (what the resolver reads when the rungs
    // are not streamed), after the loads so that their peak is theirs.
    let t = Instant::now();
    let syntax = plc_deps::read::json::parse(&text).expect("parses");
    eprintln!("parse into the whole tree: {:.2?}", t.elapsed());
    drop(syntax);
    peaks.push(("parsed whole tree", peak_mb()));
    let peaks: Vec<String> = peaks
        .iter()
        .filter_map(|(at, mb)| Some(format!("{at} {:.0} MB", (*mb)?)))
        .collect();
    if !peaks.is_empty() {
        eprintln!("peak resident memory: {}", peaks.join(", "));
    }
}

/// The peak resident memory so far (Linux: VmHWM of /proc/self/status), in MB.
fn peak_mb() -> Option<f64> {
    status_mb("VmHWM:")
}

/// The resident memory now (VmRSS), in MB.
fn resident_mb() -> Option<f64> {
    status_mb("VmRSS:")
}

fn status_mb(key: &str) -> Option<f64> {
    let status = std::fs::read_to_string("/proc/self/status").ok()?;
    let line = status.lines().find(|l| l.starts_with(key))?;
    let kb: f64 = line.split_whitespace().nth(1)?.parse().ok()?;
    Some(kb / 1000.0)
}
