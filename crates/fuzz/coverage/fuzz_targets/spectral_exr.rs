//! libFuzzer target: `fuzz::run_one("spectral-exr", data)` — a panic is a crash; an `Err` is a refused input.
#![no_main]
libfuzzer_sys::fuzz_target!(|data: &[u8]| fuzz::run_one("spectral-exr", data));
