//! cargo-fuzz target: the `run --inputs` JSON reader (`plc_deps_fuzz::inputs`); the first byte
//! picks the program the inputs are for.
#![no_main]

libfuzzer_sys::fuzz_target!(|data: &[u8]| {
    if let Some((&pick, rest)) = data.split_first() {
        if let Ok(text) = std::str::from_utf8(rest) {
            plc_deps_fuzz::inputs(plc_deps_fuzz::Inputs::Json, pick, text);
        }
    }
});
