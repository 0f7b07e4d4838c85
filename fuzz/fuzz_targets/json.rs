//! cargo-fuzz target: the json reader and the pipeline after it (`plc_deps_fuzz::program`).
#![no_main]

libfuzzer_sys::fuzz_target!(|data: &[u8]| {
    if let Ok(text) = std::str::from_utf8(data) {
        plc_deps_fuzz::program(plc_deps_fuzz::Format::Json, text);
    }
});
