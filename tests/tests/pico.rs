//! The Pico proof: the board template a user copies (`examples/pico-st7789`),
//! built for a scene as its user builds it and run unmodified on an emulated
//! Raspberry Pi Pico with its ST7789 panel, both cores tracing, shows
//! exactly host-sim's `--size 240x240 --color rgb565` picture; and so does
//! its progressive order (`OCTRACE_ORDER=progressive`), whose first coarse
//! panel comes within 0.1 s of the picture's start. fig5_1's firmware is
//! then asked on its USB serial port what it measured (what a user with a
//! real Pico reads, `pico-compare`): its TIMER's time from scene to picture
//! is the emulator's count within the timer's and the phases' edges, and
//! its bus counters count the contention the emulator counted.
//!
//! Needs Node and the emulator's packages (`npm ci` in
//! `emulator/`; the test command does it); set
//! `OCTRACE_SKIP_FIRMWARE=1` to skip where they cannot be installed.

use octrace_tests::host_sim_preview;
use octrace_tests::pico::{self, Build, Report, DEFAULT_CODE_IN};
use std::path::Path;

/// The thesis's first figure (naive, no octree), 200 spheres in an
/// octree, and the chessboard of 64 rectangles, as a user builds them; and
/// the first in the progressive order.
const BUILDS: [Build<'static>; 4] = [
    Build { scene: "fig5_1", code_in: DEFAULT_CODE_IN, order: "rows" },
    Build { scene: "fig5_3", code_in: DEFAULT_CODE_IN, order: "rows" },
    Build { scene: "fig5_5", code_in: DEFAULT_CODE_IN, order: "rows" },
    Build { scene: "fig5_1", code_in: DEFAULT_CODE_IN, order: "progressive" },
];

/// The first coarse panel of a progressive order, from the picture's start:
/// at most 0.1 s at 125 MHz.
const FIRST_PANEL_CYCLES: u64 = 12_500_000;

fn read_rgb_png(path: &Path) -> (u32, u32, Vec<u8>) {
    let file = std::fs::File::open(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    let mut reader = png::Decoder::new(std::io::BufReader::new(file)).read_info().expect("a PNG");
    let mut pixels = vec![0; reader.output_buffer_size().expect("a small image")];
    let frame = reader.next_frame(&mut pixels).expect("PNG pixels");
    assert_eq!((frame.color_type, frame.bit_depth), (png::ColorType::Rgb, png::BitDepth::Eight), "{}", path.display());
    pixels.truncate(frame.buffer_size());
    (frame.width, frame.height, pixels)
}

/// The firmware's own measure of its scene against the emulator's count:
/// its TIMER ticks each microsecond (125 cycles) and it reads it just after
/// the panel's set-up and just after its last row, where the emulator's
/// phases start at the backlight and end at the last pixel's byte, so the
/// two agree within a few hundred microseconds; its bus counters cover the
/// load and the render, the emulator's the whole run (start-up too, where
/// the cores barely meet).
fn reported_as_the_emulator_counted(name: &str, report: &Report, cycles: &pico::Cycles) {
    assert_eq!(report.scene, "fig5_1", "{name}: {report:?}");
    assert!(report.firmware.starts_with("octrace-pico-st7789 "), "{name}: {report:?}");
    let (board, emulator) = (report.to_picture_seconds(), cycles.to_picture_seconds());
    assert!(
        (board - emulator).abs() < 300e-6,
        "{name}: the firmware measured {board} s, the emulator counted {emulator} s"
    );
    let counted: u64 = report.load_contested.iter().chain(&report.render_contested).sum();
    assert!(
        counted <= cycles.striped_contested && counted * 100 >= cycles.striped_contested * 99,
        "{name}: the firmware counted {counted} contested accesses, the emulator {}",
        cycles.striped_contested
    );
    println!("{name}: reported {board:.6} s and {counted} contested accesses; the emulator counted {emulator:.6} s");
}

#[test]
fn the_pico_template_shows_host_sims_picture() {
    if std::env::var_os("OCTRACE_SKIP_FIRMWARE").is_some_and(|v| v != "0") {
        println!("skipped: OCTRACE_SKIP_FIRMWARE is set");
        return;
    }
    let dir = tempfile::tempdir().expect("a temporary directory");
    // One build at a time (they share a target directory), then the runs
    // side by side.
    let elves: Vec<_> = BUILDS.iter().map(|build| pico::build(build).unwrap_or_else(|e| panic!("{e}"))).collect();
    // The first build (fig5_1, as a user builds it) serves its USB port too.
    let runs: Vec<_> = std::thread::scope(|s| {
        let handles: Vec<_> = BUILDS
            .iter()
            .zip(&elves)
            .enumerate()
            .map(|(i, (build, elf))| {
                let panel = dir.path().join(format!("{}-panel.png", build.name()));
                s.spawn(move || {
                    let run = match i {
                        0 => pico::run_reporting(elf, &panel).map(|(cycles, report)| (cycles, Some(report))),
                        _ => pico::run(elf, &panel).map(|cycles| (cycles, None)),
                    };
                    (run, panel)
                })
            })
            .collect();
        handles.into_iter().map(|h| h.join().expect("the run's thread")).collect()
    });

    for (build, (run, panel)) in BUILDS.iter().zip(runs) {
        let name = build.name();
        let (cycles, report) = run.unwrap_or_else(|e| panic!("{name}: {e}"));
        if let Some(report) = report {
            reported_as_the_emulator_counted(&name, &report, &cycles);
        }
        let preview = dir.path().join(format!("{name}-host-sim.png"));
        host_sim_preview(build.scene, &preview, "240x240", "rgb565").unwrap_or_else(|e| panic!("{e}"));

        let (width, height, shown) = read_rgb_png(&panel);
        let expected = read_rgb_png(&preview);
        assert_eq!((width, height), (240, 240), "{name}: the panel's own size");
        let differing = shown.chunks(3).zip(expected.2.chunks(3)).filter(|(a, b)| a != b).count();
        assert_eq!(differing, 0, "{name}: {differing} of {} pixels differ from host-sim's preview", width * height);
        assert_eq!(cycles.cores, 2, "{name}: both cores trace");
        if build.order == "progressive" {
            assert!(
                cycles.first_full_panel <= FIRST_PANEL_CYCLES,
                "{name}: the whole panel coarse after {} cycles, more than 0.1 s",
                cycles.first_full_panel
            );
        }
        println!(
            "{name}: 240x240 pixels identical; parse and index {} cycles, render {} cycles: {:.2} s at 125 MHz; \
             whole panel after {} cycles; core 0 busy {}, core 1 busy {} cycles",
            cycles.parse_and_index,
            cycles.render,
            cycles.to_picture_seconds(),
            cycles.first_full_panel,
            cycles.busy[0],
            cycles.busy[1]
        );
    }
}
