//! The firmware benchmark: builds each scene for each emulated board, runs
//! it under the instruction-counting plugin and prints a Markdown table of
//! instructions per pixel, pixels per million instructions, flash, static
//! RAM and peak stack (the table in BENCHMARKS.md).
//!
//!     cargo run --release -p octrace-tests --bin firmware-bench [WxH] [scene...]
//!
//! `qemu-count` is `$OCTRACE_QEMU_COUNT`, else `../shared/tools/qemu-count`
//! beside the repository. Counts are instructions, exact and repeatable, not
//! cycles of a real chip.

use octrace_core::render::PanelColor;
use octrace_tests::firmware::{Board, Firmware};
use octrace_tests::repo;
use std::path::PathBuf;

fn main() {
    let mut args: Vec<String> = std::env::args().skip(1).collect();
    let (width, height) = match args.first().and_then(|a| a.split_once('x')) {
        Some((w, h)) => {
            let size = (w.parse().unwrap_or(160), h.parse().unwrap_or(128));
            args.remove(0);
            size
        }
        None => (160, 128),
    };
    let scenes = if args.is_empty() { vec!["fig5_1".to_owned(), "fig5_3".to_owned()] } else { args };
    let qemu_count = std::env::var_os("OCTRACE_QEMU_COUNT")
        .map(PathBuf::from)
        .unwrap_or_else(|| repo().join("../shared/tools/qemu-count"));

    println!(
        "| board | scene | size | instructions / pixel | pixels / M instructions | flash | static RAM | peak stack |"
    );
    println!("| --- | --- | --- | ---: | ---: | ---: | ---: | ---: |");
    for board in Board::ALL {
        for scene in &scenes {
            let firmware = Firmware::new(board, scene, width, height, PanelColor::Rgb888);
            let label = format!("{} ({}) | {scene} | {width}×{height}", board.machine(), board.core());
            let result = firmware.build().and_then(|elf| firmware.measure(&elf, &qemu_count));
            match result {
                Ok(m) if m.status == 0 => {
                    let pixels = (width * height) as f64;
                    let render = m.render.unwrap_or(m.total) as f64;
                    let stack = m
                        .output
                        .lines()
                        .find_map(|l| l.strip_prefix("peak stack: ")?.strip_suffix(" bytes"))
                        .unwrap_or("?");
                    println!(
                        "| {label} | {:.0} | {:.1} | {:.1} KiB | {:.1} KiB | {stack} B |",
                        render / pixels,
                        pixels / render * 1e6,
                        m.flash as f64 / 1024.0,
                        m.static_ram as f64 / 1024.0,
                    );
                }
                Ok(m) => {
                    // The first error, without its file position and advice.
                    let reason = m.output.lines().find(|l| l.contains(".txt:")).unwrap_or("");
                    let reason = reason.splitn(4, ':').nth(3).unwrap_or(reason).split(';').next().unwrap_or("").trim();
                    println!("| {label} | does not run (exit {}): {reason} | | | | |", m.status);
                }
                Err(e) => println!("| {label} | failed: {} | | | | |", e.lines().next().unwrap_or("")),
            }
        }
    }
}
