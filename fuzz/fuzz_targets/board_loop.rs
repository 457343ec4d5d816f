//! libFuzzer target: arbitrary byte streams, in pieces at arbitrary times,
//! into the board's whole loop (octrace-link's `board::Link`, as the live
//! firmware runs it); every frame answered (see
//! `octrace_fuzz::check_board_loop`).
#![no_main]

libfuzzer_sys::fuzz_target!(|data: &[u8]| octrace_fuzz::check_board_loop(data));
