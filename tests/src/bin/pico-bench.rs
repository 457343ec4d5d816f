//! The Pico benchmark: builds the Pico template (`examples/pico-st7789`) for
//! each scene, runs it on the emulated Pico and prints a Markdown table of
//! the cycles it took to parse and index the scene and to render it into the
//! 240×240 panel, the seconds from scene text to picture at 125 MHz, and the
//! firmware's flash and static RAM (the table in BENCHMARKS.md).
//!
//!     cargo run --release -p octrace-tests --bin pico-bench [scene...]
//!
//! Cycles are the emulator's (rp2040js: Cortex-M0+ timings, no flash-cache
//! misses), so a real Pico takes somewhat longer.

use octrace_tests::firmware::Sizes;
use octrace_tests::pico::{self, CLOCK_HZ};

fn main() {
    let mut scenes: Vec<String> = std::env::args().skip(1).collect();
    if scenes.is_empty() {
        scenes = ["fig5_1", "fig5_3", "fig5_5"].map(String::from).to_vec();
    }
    let dir = tempfile::tempdir().expect("a temporary directory");
    println!("| scene | parse and index | render | scene to picture at 125 MHz | flash | static RAM |");
    println!("| --- | ---: | ---: | ---: | ---: | ---: |");
    let mut failures = 0;
    for scene in &scenes {
        let elf = match pico::build(scene) {
            Ok(elf) => elf,
            Err(e) => {
                println!("| {scene} | failed to build: {} | | | | |", e.lines().next().unwrap_or(""));
                failures += 1;
                continue;
            }
        };
        let result = pico::run(&elf, &dir.path().join("panel.png")).and_then(|c| Ok((c, Sizes::of(&elf)?)));
        match result {
            Ok((cycles, sizes)) => println!(
                "| {scene} | {:.1} M cycles ({:.3} s) | {:.1} M cycles ({:.2} s) | **{:.2} s** | {:.1} KiB | {:.1} KiB |",
                cycles.parse_and_index as f64 / 1e6,
                cycles.parse_and_index as f64 / CLOCK_HZ,
                cycles.render as f64 / 1e6,
                cycles.render as f64 / CLOCK_HZ,
                cycles.to_picture_seconds(),
                (sizes.text + sizes.data) as f64 / 1024.0,
                (sizes.data + sizes.bss) as f64 / 1024.0,
            ),
            Err(e) => {
                println!("| {scene} | failed: {} | | | | |", e.lines().next().unwrap_or(""));
                failures += 1;
            }
        }
    }
    // A row that could not be measured is not a figure: the run fails.
    if failures > 0 {
        eprintln!("pico-bench: {failures} scene(s) failed");
        std::process::exit(1);
    }
}
