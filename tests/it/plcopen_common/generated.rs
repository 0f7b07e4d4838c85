//! A big generated PLCopen LD file, for the load-speed test and bench (which includes this file
//! alone: it needs nothing else of the test helpers).

/// The PLCopen TC6 2.01 namespace.
pub(crate) const NS: &str = "http://www.plcopen.org/xml/tc6_0201";

/// A generated LD program of about `bytes` bytes (as Beremiz writes positions and relPositions):
/// rungs `(a OR NOT b) AND c → coil d` over 2,000 BOOL variables, a splitmix sequence picking
/// them. Returns the text and its number of rungs.
pub(crate) fn generated_ld(bytes: usize) -> (String, usize) {
    let nv = 2000u64;
    let mut state = 1u64;
    let mut pick = || {
        state = state.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = state;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        (z ^ (z >> 31)) % nv
    };
    let mut s = String::with_capacity(bytes + 4096);
    s.push_str(&format!("<?xml version=\"1.0\" encoding=\"utf-8\"?>\n<project xmlns=\"{NS}\">\n<types><dataTypes/><pous><pou name=\"Big\" pouType=\"program\"><interface><localVars>\n"));
    for i in 0..nv {
        s.push_str(&format!(
            "<variable name=\"v{i}\"><type><BOOL/></type></variable>\n"
        ));
    }
    s.push_str("</localVars></interface><body><LD>\n<leftPowerRail localId=\"1\"><position x=\"0\" y=\"0\"/><connectionPointOut formalParameter=\"\"/></leftPowerRail>\n");
    let contact = |s: &mut String, id: u64, var: u64, refs: &[u64], neg: bool, y: u64| {
        let n = if neg { " negated=\"true\"" } else { "" };
        s.push_str(&format!("<contact localId=\"{id}\"{n}><position x=\"30\" y=\"{y}\"/><connectionPointIn><relPosition x=\"0\" y=\"15\"/>"));
        for r in refs {
            s.push_str(&format!("<connection refLocalId=\"{r}\"><position x=\"10\" y=\"{y}\"/><position x=\"20\" y=\"{y}\"/></connection>"));
        }
        s.push_str(&format!("</connectionPointIn><connectionPointOut><relPosition x=\"21\" y=\"15\"/></connectionPointOut><variable>v{var}</variable></contact>\n"));
    };
    let (mut id, mut rungs) = (2u64, 0usize);
    while s.len() < bytes {
        let y = rungs as u64 * 40;
        let (a, b, c, d) = (id, id + 1, id + 2, id + 3);
        id += 4;
        contact(&mut s, a, pick(), &[1], false, y);
        contact(&mut s, b, pick(), &[1], true, y);
        contact(&mut s, c, pick(), &[a, b], false, y);
        s.push_str(&format!("<coil localId=\"{d}\"><position x=\"90\" y=\"{y}\"/><connectionPointIn><relPosition x=\"0\" y=\"15\"/><connection refLocalId=\"{c}\"/></connectionPointIn><connectionPointOut/><variable>v{}</variable></coil>\n", pick()));
        rungs += 1;
    }
    s.push_str(
        "</LD></body></pou></pous></types><instances><configurations/></instances></project>\n",
    );
    (s, rungs)
}
