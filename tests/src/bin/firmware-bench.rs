//! The firmware benchmark: builds each scene for each emulated board, runs
//! it under the instruction-counting plugin and prints a Markdown table of
//! instructions per pixel, pixels per million instructions, flash, static
//! RAM and peak stack (the table in BENCHMARKS.md).
//!
//!     cargo run --release -p octrace-tests --bin firmware-bench [WxH] [scene...]
//!     cargo run --release -p octrace-tests --bin firmware-bench panels [WxH] [scene...]
//!
//! `panels`: the micro:bit drawing into a panel of few levels (`mono`,
//! `gray2`, `gray4`, `bwr`) by every dithering, at 128×64 (fig5_1 unless
//! named): instructions a pixel, and what each method costs over the
//! nearest level (the same render and the same byte a pixel to the display,
//! so the difference is the method's).
//!
//! The counter is `firmware/tools/qemu-count` (or the program
//! `$OCTRACE_QEMU_COUNT` names). Counts are instructions, exact and
//! repeatable, not cycles of a real chip.

use octrace_core::panel::Dithering;
use octrace_core::render::PanelColor;
use octrace_tests::firmware::{qemu_count, Board, Firmware};

fn main() {
    let mut args: Vec<String> = std::env::args().skip(1).collect();
    let panels = args.first().is_some_and(|a| a == "panels");
    if panels {
        args.remove(0);
    }
    let default_size = if panels { (128, 64) } else { (160, 128) };
    let (width, height) = match args.first().and_then(|a| a.split_once('x')) {
        Some((w, h)) => {
            let size = (w.parse().unwrap_or(default_size.0), h.parse().unwrap_or(default_size.1));
            args.remove(0);
            size
        }
        None => default_size,
    };
    let default_scenes: &[&str] = if panels { &["fig5_1"] } else { &["fig5_1", "fig5_3"] };
    let scenes = if args.is_empty() { default_scenes.iter().map(|s| s.to_string()).collect() } else { args };
    let qemu_count = qemu_count();
    if panels {
        return panels_table(&scenes, (width, height), &qemu_count);
    }

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
                    let stack = m.peak_stack().map_or("?".to_owned(), |b| b.to_string());
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

/// The micro:bit drawing each scene into every panel of few levels by every
/// dithering.
fn panels_table(scenes: &[String], (width, height): (u32, u32), qemu_count: &std::path::Path) {
    println!("| scene | panel | dithering | instructions / pixel | over nearest | flash | static RAM | peak stack |");
    println!("| --- | --- | --- | ---: | ---: | ---: | ---: | ---: |");
    let mut failures = 0;
    for scene in scenes {
        for color in PanelColor::ALL.into_iter().filter(|c| c.panel().is_some()) {
            // Nearest last in ALL: measured first here, as the baseline.
            let mut nearest = None;
            for dithering in Dithering::ALL.into_iter().rev() {
                let firmware = Firmware::new(Board::Microbit, scene, width, height, color).dithered(dithering);
                let label = format!("{scene} {width}×{height} | {color} | {dithering}");
                let measured = firmware.build().and_then(|elf| firmware.measure(&elf, qemu_count));
                match measured {
                    Ok(m) if m.status == 0 => {
                        let per_pixel = m.render.unwrap_or(m.total) as f64 / (width * height) as f64;
                        let over = match nearest {
                            None => {
                                nearest = Some(per_pixel);
                                "—".to_owned()
                            }
                            Some(base) => format!("{:+.1}", per_pixel - base),
                        };
                        let stack = m.peak_stack().map_or("?".to_owned(), |b| b.to_string());
                        println!(
                            "| {label} | {per_pixel:.1} | {over} | {:.1} KiB | {:.1} KiB | {stack} B |",
                            m.flash as f64 / 1024.0,
                            m.static_ram as f64 / 1024.0,
                        );
                    }
                    Ok(m) => {
                        println!("| {label} | does not run (exit {}) | | | | |", m.status);
                        failures += 1;
                    }
                    Err(e) => {
                        println!("| {label} | failed: {} | | | | |", e.lines().next().unwrap_or(""));
                        failures += 1;
                    }
                }
            }
        }
    }
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
