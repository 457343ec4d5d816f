//! The board proof: firmware built for emulated boards renders scenes on
//! the board (parsed there, from the scene text in flash) and the pixels its
//! display driver receives are bit-identical to host-sim's image.
//!
//! Needs `qemu-system-arm` (the test command installs it); set
//! `OCTRACE_SKIP_FIRMWARE=1` to skip where it cannot be installed.

use octrace_tests::firmware::{qemu_available, Board, Firmware, Sizes, Wire};

#[test]
fn boards_render_the_same_bits_as_host_sim() {
    if std::env::var_os("OCTRACE_SKIP_FIRMWARE").is_some_and(|v| v != "0") {
        println!("skipped: OCTRACE_SKIP_FIRMWARE is set");
        return;
    }
    assert!(qemu_available(), "qemu-system-arm is not installed (apt-get install qemu-system-arm)");
    let cases = [
        // The 16 KiB Cortex-M0 with the thesis's first figure...
        Firmware::new(Board::Microbit, "fig5_1", 160, 128, Wire::Rgb888),
        // ...and with 200 spheres and its octree, into an RGB565 display.
        Firmware::new(Board::Microbit, "fig5_3", 160, 128, Wire::Rgb565),
        // Arenas sized from each scene at build time: the chessboard's 64
        // rectangles, boxes and superquadrics, mirrors, and glass (2×2
        // samples) all fit the 16 KiB board.
        Firmware::new(Board::Microbit, "fig5_5", 64, 48, Wire::Rgb565),
        Firmware::new(Board::Microbit, "fig5_7", 64, 48, Wire::Rgb888),
        Firmware::new(Board::Microbit, "fig5_8", 64, 48, Wire::Rgb888),
        Firmware::new(Board::Microbit, "glass", 48, 36, Wire::Rgb888),
        Firmware::new(Board::Mps2An385, "fig5_3", 160, 128, Wire::Rgb888),
        // A 256-colour display: indices of the dithered colour cube.
        Firmware::new(Board::Mps2An385, "fig5_1", 160, 128, Wire::Dither),
    ];
    for firmware in cases {
        let name = format!("{} on {}", firmware.scene, firmware.board.machine());
        let elf = firmware.build().unwrap_or_else(|e| panic!("{e}"));
        if firmware.board == Board::Microbit {
            // Empty arenas are zero bits: no flash spent on an empty scene.
            let sizes = Sizes::of(&elf).unwrap_or_else(|e| panic!("{name}: {e}"));
            assert!(sizes.data < 1024, "{name}: .data is {} bytes", sizes.data);
        }
        let run = firmware.run(&elf).unwrap_or_else(|e| panic!("{name}: {e}"));
        assert_eq!(run.status, 0, "{name}: the board exited with {}:\n{}", run.status, run.output);
        let expected = firmware.expected_pixels().unwrap_or_else(|e| panic!("{name}: {e}"));
        assert_eq!(run.pixels.len(), expected.len(), "{name}: byte count\n{}", run.output);
        let differing = run.pixels.iter().zip(&expected).filter(|(a, b)| a != b).count();
        assert_eq!(differing, 0, "{name}: {differing} bytes differ from host-sim's");
        println!("{name} ({:?}): {} bytes identical; {}", firmware.wire, expected.len(), run.output.trim());
    }
}
