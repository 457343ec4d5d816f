//! The Pico proof: each board template a user copies, built for a scene as
//! its user builds it and run unmodified on an emulated Raspberry Pi Pico,
//! both cores tracing, shows exactly host-sim's preview of its panel:
//! `examples/pico-st7789` on its ST7789, host-sim's `--size 240x240 --color
//! rgb565` (and so does its progressive order, `OCTRACE_ORDER=progressive`,
//! whose first coarse panel comes within 0.1 s of the picture's start);
//! `examples/pico-ssd1306` on its SSD1306 over I2C, `--size 128x64 --color
//! mono`, its picture sent in at least the bus's time at 400 kHz. The
//! ST7789's fig5_1 firmware is then asked on its USB serial port what it
//! measured (what a user with a real Pico reads, `pico-compare`): its
//! TIMER's time from scene to picture is the emulator's count within the
//! timer's and the phases' edges, and its bus counters count the
//! contention the emulator counted. The
//! ST7789 template built for an animation (anim_fig5_1) plays it: each of
//! its first frames on the panel is host-sim's `--frame K` picture. The
//! same runs' cycles (each still from scene to picture, each frame), with
//! each firmware's flash and static RAM, are held to their budgets
//! (`budgets.toml`, section `pico`).
//!
//! Needs Node and the emulator's packages (`npm ci` in
//! `emulator/`; the test command does it); set
//! `OCTRACE_SKIP_FIRMWARE=1` to skip where they cannot be installed.

use octrace_tests::budgets::Budgets;
use octrace_tests::firmware::Sizes;
use octrace_tests::pico::{self, Build, Report, Template, DEFAULT_CODE_IN};
use octrace_tests::{host_sim_frame_preview, host_sim_preview};
use std::path::Path;

/// For each template, the thesis's first figure (naive, no octree), 200
/// spheres in an octree, and the chessboard of 64 rectangles, as a user
/// builds them; and the ST7789's first in the progressive order.
const BUILDS: [Build<'static>; 7] = [
    Build::of(Template::St7789, "fig5_1"),
    Build::of(Template::St7789, "fig5_3"),
    Build::of(Template::St7789, "fig5_5"),
    Build { template: Template::St7789, scene: "fig5_1", code_in: DEFAULT_CODE_IN, order: "progressive" },
    Build::of(Template::Ssd1306, "fig5_1"),
    Build::of(Template::Ssd1306, "fig5_3"),
    Build::of(Template::Ssd1306, "fig5_5"),
];

/// The least an SSD1306's 128×64 picture takes over I2C at 400 kHz, in
/// seconds: its 1,024 bytes at 9 clocks each (address and control bytes,
/// START and STOP come on top).
const OLED_PICTURE_SECONDS: f64 = 1024.0 * 9.0 / 400e3;

/// An animation, and how many of its frames are checked: the first (traced
/// whole) and two that re-trace only what moved, the second after a frame
/// that did so (enough to see tiles skipped that changed, or counts carried
/// wrongly from a frame to the next; `tests/tests/animation.rs` plays whole
/// loops on the host).
const ANIMATIONS: [Build<'static>; 2] =
    [Build::of(Template::St7789, "anim_fig5_1"), Build::of(Template::Ssd1306, "anim_fig5_1")];
const FRAMES_CHECKED: u32 = 3;

/// The first coarse panel of a progressive order, from the picture's start:
/// at most 0.1 s.
const FIRST_PANEL_SECONDS: f64 = 0.1;

/// An 8-bit RGB or gray PNG (host-sim writes a one-bit panel's preview in
/// gray) as RGB pixels.
fn read_png_as_rgb(path: &Path) -> (u32, u32, Vec<u8>) {
    let file = std::fs::File::open(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    let mut reader = png::Decoder::new(std::io::BufReader::new(file)).read_info().expect("a PNG");
    let mut pixels = vec![0; reader.output_buffer_size().expect("a small image")];
    let frame = reader.next_frame(&mut pixels).expect("PNG pixels");
    pixels.truncate(frame.buffer_size());
    let rgb = match (frame.color_type, frame.bit_depth) {
        (png::ColorType::Rgb, png::BitDepth::Eight) => pixels,
        (png::ColorType::Grayscale, png::BitDepth::Eight) => pixels.iter().flat_map(|&v| [v, v, v]).collect(),
        other => panic!("{}: a {other:?} PNG", path.display()),
    };
    (frame.width, frame.height, rgb)
}

/// The firmware's own measure of its scene against the emulator's count:
/// its TIMER ticks each microsecond (200 cycles at the template's clock,
/// which the emulator reads from the clock registers) and it reads it just after
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
fn each_pico_template_shows_host_sims_picture() {
    if std::env::var_os("OCTRACE_SKIP_FIRMWARE").is_some_and(|v| v != "0") {
        println!("skipped: OCTRACE_SKIP_FIRMWARE is set");
        return;
    }
    let dir = tempfile::tempdir().expect("a temporary directory");
    // One build at a time (they share a target directory), each run started
    // as soon as its firmware is built, beside the next build: the
    // animations first, the longest runs.
    let (animations, played, elves, runs) = std::thread::scope(|s| {
        let mut animations = Vec::new();
        let mut played = Vec::new();
        for build in &ANIMATIONS {
            let elf = pico::build(build).unwrap_or_else(|e| panic!("{e}"));
            let pattern = dir.path().join(format!("{}-{}-%d.png", build.template.name(), build.name()));
            let run = elf.clone();
            played.push(s.spawn(move || pico::run_frames(&run, &pattern, FRAMES_CHECKED)));
            animations.push(elf);
        }
        let mut elves = Vec::new();
        let mut runs = Vec::new();
        for (i, build) in BUILDS.iter().enumerate() {
            let elf = pico::build(build).unwrap_or_else(|e| panic!("{e}"));
            let panel = dir.path().join(format!("{}-{}-panel.png", build.template.name(), build.name()));
            let run = elf.clone();
            // The first build (fig5_1, as a user builds it) serves its USB
            // port too.
            runs.push(s.spawn(move || {
                let cycles = match i {
                    0 => pico::run_reporting(&run, &panel).map(|(cycles, report)| (cycles, Some(report))),
                    _ => pico::run(&run, &panel).map(|cycles| (cycles, None)),
                };
                (cycles, panel)
            }));
            elves.push(elf);
        }
        let runs: Vec<_> = runs.into_iter().map(|h| h.join().expect("the run's thread")).collect();
        let played: Vec<_> = played.into_iter().map(|h| h.join().expect("the animation's thread")).collect();
        (animations, played, elves, runs)
    });

    let mut budgets = Budgets::load("pico").unwrap_or_else(|e| panic!("{e}"));
    let subject = |build: &Build<'_>| format!("{} {}", build.template.name(), build.name());
    let subjects: Vec<String> = BUILDS.iter().chain(&ANIMATIONS).map(subject).collect();
    for (build, elf) in BUILDS.iter().chain(&ANIMATIONS).zip(elves.iter().chain(&animations)) {
        let sizes = Sizes::of(elf).unwrap_or_else(|e| panic!("{}: {e}", subject(build)));
        budgets.check(&subject(build), "flash", sizes.text + sizes.data);
        budgets.check(&subject(build), "static_ram", sizes.data + sizes.bss);
    }

    for (build, (run, panel)) in BUILDS.iter().zip(runs) {
        let name = subject(build);
        let (cycles, report) = run.unwrap_or_else(|e| panic!("{name}: {e}"));
        budgets.check(&name, "to_picture_cycles", cycles.to_picture_cycles());
        if let Some(report) = report {
            reported_as_the_emulator_counted(&name, &report, &cycles);
        }
        let preview = dir.path().join(format!("{}-{}-host-sim.png", build.template.name(), build.name()));
        let (size, color) = build.template.panel();
        host_sim_preview(build.scene, &preview, size, color).unwrap_or_else(|e| panic!("{e}"));

        assert_same_picture(&name, &panel, &preview, size);
        assert_eq!(cycles.cores, 2, "{name}: both cores trace");
        if build.order == "progressive" {
            assert!(
                cycles.seconds(cycles.first_full_panel) <= FIRST_PANEL_SECONDS,
                "{name}: the whole panel coarse after {} cycles, more than 0.1 s",
                cycles.first_full_panel
            );
        }
        if build.template == Template::Ssd1306 {
            let transfer =
                cycles.transfer.unwrap_or_else(|| panic!("{name}: no transfer of the picture after the LED"));
            assert!(
                cycles.seconds(transfer) >= OLED_PICTURE_SECONDS,
                "{name}: the picture went over I2C in {transfer} cycles, faster than 400 kHz carries it"
            );
        }
        println!(
            "{name}: {size} pixels identical; parse and index {} cycles, render {} cycles, transfer {:?} cycles: \
             {:.3} s at {:.0} MHz; whole panel after {} cycles; core 0 busy {}, core 1 busy {} cycles",
            cycles.parse_and_index,
            cycles.render,
            cycles.transfer,
            cycles.to_picture_seconds(),
            cycles.clock_hz / 1e6,
            cycles.first_full_panel,
            cycles.busy[0],
            cycles.busy[1]
        );
    }

    for (build, frames) in ANIMATIONS.iter().zip(played) {
        let name = subject(build);
        let frames = frames.unwrap_or_else(|e| panic!("{name}: {e}"));
        assert_eq!(frames.len(), FRAMES_CHECKED as usize, "{name}: the frames drawn");
        for (k, frame) in frames.iter().enumerate() {
            budgets.check(&name, &format!("frame_{k}_cycles"), frame.cycles);
        }
        let (size, color) = build.template.panel();
        for (k, frame) in (0..).zip(&frames) {
            let preview = dir.path().join(format!("{}-{}-host-sim-{k}.png", build.template.name(), build.name()));
            host_sim_frame_preview(build.scene, k, &preview, size, color).unwrap_or_else(|e| panic!("{e}"));
            assert_same_picture(&format!("{name}, frame {k}"), &frame.picture, &preview, size);
            println!(
                "{name}, frame {k}: {size} pixels identical; {} cycles ({:.3} s), core 0 busy {}, core 1 busy {}",
                frame.cycles, frame.seconds, frame.busy[0], frame.busy[1]
            );
        }
        // The frames after the first re-trace only what moved.
        assert!(frames[1..].iter().all(|f| f.cycles < frames[0].cycles / 2), "{name}: {frames:?}");
    }
    budgets.assert_within(&subjects);
}

/// Asserts the panel's picture `panel` is host-sim's `preview`, pixel for
/// pixel, at the panel's `size` (`WxH`).
fn assert_same_picture(name: &str, panel: &Path, preview: &Path, size: &str) {
    let (width, height, shown) = read_png_as_rgb(panel);
    let expected = read_png_as_rgb(preview);
    assert_eq!(format!("{width}x{height}"), size, "{name}: the panel's own size");
    let differing = shown.chunks(3).zip(expected.2.chunks(3)).filter(|(a, b)| a != b).count();
    assert_eq!(differing, 0, "{name}: {differing} of {} pixels differ from host-sim's preview", width * height);
}
