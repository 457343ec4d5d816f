//! libFuzzer target: parse, then render in every mode (see
//! `octrace_fuzz::check_render`).
#![no_main]

libfuzzer_sys::fuzz_target!(|data: &[u8]| octrace_fuzz::check_render(data));
