//! libFuzzer target: arbitrary bytes from a serial line into the board
//! protocol's decoder and the board's answers (see
//! `octrace_fuzz::check_link`).
#![no_main]

libfuzzer_sys::fuzz_target!(|data: &[u8]| octrace_fuzz::check_link(data));
