//! libFuzzer target: the scene parser on arbitrary bytes (see
//! `octrace_fuzz::check_parse`).
#![no_main]

libfuzzer_sys::fuzz_target!(|data: &[u8]| octrace_fuzz::check_parse(data));
