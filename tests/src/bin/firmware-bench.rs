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
    let mut dual_rows = Vec::new();
    let mut failures = 0;
    for board in Board::ALL {
        for scene in &scenes {
            let firmware = Firmware::new(board, scene, width, height, PanelColor::Rgb888);
            let label = format!("{} ({}) | {scene} | {width}×{height}", board.machine(), board.core());
            let result = firmware.build().and_then(|elf| {
                let measured = firmware.measure(&elf, &qemu_count)?;
                // Two cores: the busier core's work (what is not waiting).
                let cores = if board == Board::Mps2An521 { Some(firmware.cores(&elf)?) } else { None };
                Ok((measured, cores))
            });
            match result {
                Ok((m, cores)) if m.status == 0 => {
                    let pixels = (width * height) as f64;
                    let mut render = m.render.unwrap_or(m.total) as f64;
                    if let Some(cores) = cores {
                        render = cores.iter().map(|&(total, wait)| total - wait).max().unwrap_or(0) as f64;
                        dual_rows.push(dual_row(scene, &cores));
                    }
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
                Ok((m, _)) => {
                    // The first error, without its file position and advice.
                    let reason = m.output.lines().find(|l| l.contains(".txt:")).unwrap_or("");
                    let reason = reason.splitn(4, ':').nth(3).unwrap_or(reason).split(';').next().unwrap_or("").trim();
                    println!("| {label} | does not run (exit {}): {reason} | | | | |", m.status);
                }
                Err(e) => {
                    println!("| {label} | failed: {} | | | | |", e.lines().next().unwrap_or(""));
                    failures += 1;
                }
            }
        }
    }
    if !dual_rows.is_empty() {
        println!();
        println!(
            "Both cores of the MPS2-AN521: each core's work between the markers (exact), and its waiting for \
             the other (which depends on how qemu takes turns between the cores, so it varies run to run):"
        );
        println!();
        println!(
            "| scene | core 0 work | core 1 work | core 0 waiting | core 1 waiting | core 0's share of the work |"
        );
        println!("| --- | ---: | ---: | ---: | ---: | ---: |");
        for row in dual_rows {
            println!("{row}");
        }
    }
    // A row the harness could not measure is not a figure: the run fails.
    if failures > 0 {
        eprintln!("firmware-bench: {failures} measurement(s) failed");
        std::process::exit(1);
    }
}

/// A row of the dual-core table: each core's instructions, its waiting,
/// and core 0's share of the two cores' work (what is not waiting).
fn dual_row(scene: &str, cores: &[(u64, u64)]) -> String {
    let [(total0, wait0), (total1, wait1), ..] = cores[..] else {
        return format!("| {scene} | one core counted | | | | |");
    };
    let (work0, work1) = (total0 - wait0, total1 - wait1);
    let share = 100.0 * work0 as f64 / (work0 + work1).max(1) as f64;
    let m = |v: u64| format!("{:.1} M", v as f64 / 1e6);
    format!("| {scene} | {} | {} | {} | {} | {share:.2} % |", m(work0), m(work1), m(wait0), m(wait1))
}
