//! A 50 MB generated PLCopen LD file loads whole (every rung, each with its OR), and how long the
//! XML parse and the resolution take (printed; the figure to compare is in docs/plcopen.md).

use crate::plcopen_common as px;

use std::time::Instant;

#[test]
fn a_50_mb_ld_file_loads_whole() {
    let (xml, rungs) = px::generated_ld(50_000_000);
    assert!(xml.len() >= 50_000_000);
    let t = Instant::now();
    let (syntax, _) = plc_deps::read::plcopen::parse(&xml).unwrap();
    let parsed = t.elapsed();
    let (p, _, notes) = plc_deps::load::plcopen(&xml).unwrap();
    let loaded = t.elapsed() - parsed;
    drop(syntax);
    assert_eq!(p.rungs().len(), rungs);
    assert!(rungs > 30_000, "{rungs}");
    assert!(notes.is_empty());
    eprintln!(
        "{} bytes, {rungs} rungs: read into syntax {parsed:?}; read and resolved {loaded:?}",
        xml.len()
    );
}
