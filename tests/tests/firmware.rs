//! The board proof: firmware built for emulated boards renders scenes on
//! the board (parsed there, from the scene text in flash) and the pixels its
//! display driver receives are bit-identical to host-sim's image. The same
//! runs count the instructions (qemu-count), which with each firmware's
//! flash, static RAM and peak stack are held to their budgets
//! (`budgets.toml`, section `firmware`).
//!
//! Needs `qemu-system-arm`, `qemu-system-riscv32` and gcc, which builds
//! qemu-count's plugin (`firmware/tools/qemu-count`; the test command
//! installs all three); set `OCTRACE_SKIP_FIRMWARE=1` to skip where they
//! cannot be installed.

use octrace_core::panel::Dithering;
use octrace_core::render::PanelColor;
use octrace_tests::budgets::Budgets;
use octrace_tests::firmware::{qemu_available, qemu_count, run_oled_command, Board, Firmware, Sizes};
use octrace_tests::host_sim_preview;

/// False (the test is skipped) when `OCTRACE_SKIP_FIRMWARE` is set; fails
/// when qemu is missing.
fn firmware_tests_run() -> bool {
    if std::env::var_os("OCTRACE_SKIP_FIRMWARE").is_some_and(|v| v != "0") {
        println!("skipped: OCTRACE_SKIP_FIRMWARE is set");
        return false;
    }
    assert!(qemu_available(), "qemu-system-arm is not installed (apt-get install qemu-system-arm)");
    true
}

#[test]
fn boards_render_the_same_bits_as_host_sim() {
    if !firmware_tests_run() {
        return;
    }
    let cases = [
        // The 16 KiB Cortex-M0 with the thesis's first figure...
        Firmware::new(Board::Microbit, "fig5_1", 160, 128, PanelColor::Rgb888),
        // ...and with 200 spheres and its octree, into an RGB565 display.
        Firmware::new(Board::Microbit, "fig5_3", 160, 128, PanelColor::Rgb565),
        // Arenas sized from each scene at build time: the chessboard's 64
        // rectangles, boxes and superquadrics, mirrors, and glass (2×2
        // samples) all fit the 16 KiB board; the first two into panels of
        // few levels, dithered on the Cortex-M0 as on the host (one bit by
        // FS-PE, four grays by Floyd–Steinberg).
        Firmware::new(Board::Microbit, "fig5_5", 64, 48, PanelColor::Mono),
        Firmware::new(Board::Microbit, "fig5_7", 64, 48, PanelColor::Gray2).dithered(Dithering::FloydSteinberg),
        Firmware::new(Board::Microbit, "fig5_8", 64, 48, PanelColor::Rgb888),
        Firmware::new(Board::Microbit, "glass", 48, 36, PanelColor::Rgb888),
        Firmware::new(Board::Mps2An385, "fig5_3", 160, 128, PanelColor::Rgb888),
        // A 256-colour display: indices of the dithered colour cube.
        Firmware::new(Board::Mps2An385, "fig5_1", 160, 128, PanelColor::Dither),
        // A 16-gray panel, as the OLED's: one level a byte, dithered.
        Firmware::new(Board::Mps2An385, "fig5_4", 64, 48, PanelColor::Gray4),
        // Armv8-M Mainline (Cortex-M33, the Pico 2's and nRF5340's core),
        // with the octree and both techniques.
        Firmware::new(Board::Mps2An505, "fig5_5", 160, 128, PanelColor::Rgb565),
        // Both Cortex-M33s of the AN521, rows dealt out in turn; into
        // black/white/red e-paper, the two cores' rows dithered as one
        // picture.
        Firmware::new(Board::Mps2An521, "fig5_3", 160, 128, PanelColor::Rgb565),
        Firmware::new(Board::Mps2An521, "fig5_1", 64, 48, PanelColor::Bwr),
        // RISC-V (RV32IMC, as the ESP32-C3), with the octree.
        Firmware::new(Board::Virt, "fig5_3", 160, 128, PanelColor::Rgb888),
        Firmware::new(Board::Virt, "fig5_1", 160, 128, PanelColor::Rgb565),
    ];
    let mut budgets = Budgets::load("firmware").unwrap_or_else(|e| panic!("{e}"));
    let qemu_count = qemu_count();
    let subjects: Vec<String> = cases.iter().map(Firmware::slug).collect();
    // Builds one after another (they share a target directory); each run,
    // and host-sim's picture for it, on a thread of its own as soon as its
    // ELF is built, so qemu and the next build share the cores. Every
    // figure is checked here, once all have run.
    std::thread::scope(|scope| {
        let mut runs = Vec::new();
        for firmware in &cases {
            let name = format!("{} on {}", firmware.scene, firmware.board.machine());
            let elf = firmware.build().unwrap_or_else(|e| panic!("{e}"));
            let sizes = Sizes::of(&elf).unwrap_or_else(|e| panic!("{name}: {e}"));
            let qemu_count = &qemu_count;
            let run = scope.spawn(move || {
                let run = if firmware.counts_exactly() {
                    firmware.run_measured(&elf, qemu_count).map(|(run, measured)| (run, Some(measured)))
                } else {
                    firmware.run(&elf).map(|run| (run, None))
                };
                (run, firmware.expected_pixels())
            });
            runs.push((firmware, name, sizes, run));
        }
        // The OLED board's `cargo run` builds in the same target directory
        // (its dependencies are theirs), so it comes after the builds above,
        // beside their runs: run beside them, it could replace a Cortex-M3
        // ELF between its build and its copy.
        oled_screen_is_host_sims_gray4_preview();
        for (firmware, name, sizes, run) in runs {
            if firmware.board == Board::Microbit {
                // Empty arenas are zero bits: no flash spent on an empty scene.
                assert!(sizes.data < 1024, "{name}: .data is {} bytes", sizes.data);
            }
            let subject = firmware.slug();
            budgets.check(&subject, "flash", sizes.text + sizes.data);
            budgets.check(&subject, "static_ram", sizes.data + sizes.bss);
            let (run, expected) = run.join().unwrap_or_else(|_| panic!("{name}: its run panicked"));
            let (run, measured) = run.unwrap_or_else(|e| panic!("{name}: {e}"));
            // A board that failed says so before any figure is missed.
            assert_eq!(run.status, 0, "{name}: the board exited with {}:\n{}", run.status, run.output);
            if let Some(measured) = measured {
                let render = measured.render.unwrap_or_else(|| panic!("{name}: no instructions between the markers"));
                budgets.check(&subject, "instructions", render);
                // Exact too where the instructions are (one core: the same
                // pixels take the same path), and what a micro:bit's stack,
                // sized by measurement, must keep room for.
                let stack = run.peak_stack().unwrap_or_else(|| panic!("{name}: no peak stack in\n{}", run.output));
                budgets.check(&subject, "peak_stack", stack);
            }
            let expected = expected.unwrap_or_else(|e| panic!("{name}: {e}"));
            assert_eq!(run.pixels.len(), expected.len(), "{name}: byte count\n{}", run.output);
            let differing = run.pixels.iter().zip(&expected).filter(|(a, b)| a != b).count();
            assert_eq!(differing, 0, "{name}: {differing} bytes differ from host-sim's");
            println!("{name} ({:?}): {} bytes identical; {}", firmware.wire, expected.len(), run.output.trim());
        }
    });
    budgets.assert_within(&subjects);
}

/// An 8-bit gray PNG's size and pixels.
fn read_gray_png(path: &std::path::Path) -> (u32, u32, Vec<u8>) {
    let file = std::fs::File::open(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    let mut reader = png::Decoder::new(std::io::BufReader::new(file)).read_info().expect("a PNG");
    let mut pixels = vec![0; reader.output_buffer_size().expect("a small image")];
    let frame = reader.next_frame(&mut pixels).expect("PNG pixels");
    assert_eq!(
        (frame.color_type, frame.bit_depth),
        (png::ColorType::Grayscale, png::BitDepth::Eight),
        "{}",
        path.display()
    );
    pixels.truncate(frame.buffer_size());
    (frame.width, frame.height, pixels)
}

/// The LM3S6965EVB renders fig5_1 onto its emulated 128×64 OLED; the screen
/// qemu shows, grabbed by the runner, is host-sim's `--color gray4` preview
/// bit for bit.
fn oled_screen_is_host_sims_gray4_preview() {
    let dir = tempfile::tempdir().expect("a temporary directory");
    let screen = dir.path().join("screen.png");
    let run = run_oled_command("fig5_1", &screen).unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(run.status, 0, "the OLED board exited with {}:\n{}", run.status, run.output);

    let preview = dir.path().join("preview.png");
    host_sim_preview("fig5_1", &preview, "128x64", "gray4").unwrap_or_else(|e| panic!("{e}"));

    let (width, height, shown) = read_gray_png(&screen);
    let expected = read_gray_png(&preview);
    assert_eq!((width, height), (128, 64), "the panel's own pixels");
    assert_eq!((width, height), (expected.0, expected.1));
    let differing = shown.iter().zip(&expected.2).filter(|(a, b)| a != b).count();
    assert_eq!(differing, 0, "{differing} of {} pixels differ from host-sim's preview\n{}", shown.len(), run.output);
    let levels: std::collections::BTreeSet<u8> = shown.iter().copied().collect();
    assert!(levels.len() > 8, "a picture, not a blank screen: levels {levels:?}");
    println!("lm3s6965evb OLED: {} pixels identical, {} gray levels; {}", shown.len(), levels.len(), run.output.trim());
}
