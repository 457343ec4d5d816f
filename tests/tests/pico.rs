//! The Pico proof: the board template a user copies (`examples/pico-st7789`),
//! built for a scene as its user builds it and run unmodified on an emulated
//! Raspberry Pi Pico with its ST7789 panel, shows exactly host-sim's
//! `--size 240x240 --color rgb565` picture.
//!
//! Needs Node and the emulator's packages (`npm ci` in
//! `examples/pico-st7789/emulator`; the test command does it); set
//! `OCTRACE_SKIP_FIRMWARE=1` to skip where they cannot be installed.

use octrace_tests::{host_sim_preview, pico};
use std::path::Path;

/// The thesis's first figure (naive, no octree), 200 spheres in an
/// octree, and the chessboard of 64 rectangles.
const SCENES: [&str; 3] = ["fig5_1", "fig5_3", "fig5_5"];

fn read_rgb_png(path: &Path) -> (u32, u32, Vec<u8>) {
    let file = std::fs::File::open(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    let mut reader = png::Decoder::new(std::io::BufReader::new(file)).read_info().expect("a PNG");
    let mut pixels = vec![0; reader.output_buffer_size().expect("a small image")];
    let frame = reader.next_frame(&mut pixels).expect("PNG pixels");
    assert_eq!((frame.color_type, frame.bit_depth), (png::ColorType::Rgb, png::BitDepth::Eight), "{}", path.display());
    pixels.truncate(frame.buffer_size());
    (frame.width, frame.height, pixels)
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
    let elves: Vec<_> = SCENES.iter().map(|scene| pico::build(scene).unwrap_or_else(|e| panic!("{e}"))).collect();
    let runs: Vec<_> = std::thread::scope(|s| {
        let handles: Vec<_> = SCENES
            .iter()
            .zip(&elves)
            .map(|(scene, elf)| {
                let panel = dir.path().join(format!("{scene}-panel.png"));
                s.spawn(move || (pico::run(elf, &panel), panel))
            })
            .collect();
        handles.into_iter().map(|h| h.join().expect("the run's thread")).collect()
    });

    for (scene, (cycles, panel)) in SCENES.iter().zip(runs) {
        let cycles = cycles.unwrap_or_else(|e| panic!("{scene}: {e}"));
        let preview = dir.path().join(format!("{scene}-host-sim.png"));
        host_sim_preview(scene, &preview, "240x240", "rgb565").unwrap_or_else(|e| panic!("{e}"));

        let (width, height, shown) = read_rgb_png(&panel);
        let expected = read_rgb_png(&preview);
        assert_eq!((width, height), (240, 240), "{scene}: the panel's own size");
        let differing = shown.chunks(3).zip(expected.2.chunks(3)).filter(|(a, b)| a != b).count();
        assert_eq!(differing, 0, "{scene}: {differing} of {} pixels differ from host-sim's preview", width * height);
        println!(
            "{scene}: 240x240 pixels identical; parse and index {} cycles, render {} cycles: {:.2} s at 125 MHz",
            cycles.parse_and_index,
            cycles.render,
            cycles.to_picture_seconds()
        );
    }
}
