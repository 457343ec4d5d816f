//! Accuracy: every scene rendered by the fixed-point core is compared with
//! the independent f64 reference tracer (`octrace-reference`), which
//! evaluates the same model from the contract alone. At least 99% of the
//! pixels must be within ±4 levels in every channel; the figures are printed
//! for each scene (`cargo test -p octrace-tests --test accuracy -- --nocapture`).

use host_sim::{load_file, new_scene, render, RenderOptions};
use octrace_reference as reference;
use octrace_tests::scenes;

/// The largest per-channel difference that counts as "close".
const TOLERANCE: u8 = 4;
/// The share of pixels that must be close.
const REQUIRED: f64 = 0.99;

#[test]
fn every_scene_is_within_four_levels_of_the_f64_reference() {
    let mut failures = Vec::new();
    println!("{:<10} {:>8} {:>9} {:>9} {:>9}", "scene", "pixels", "exact", "within 4", "max diff");
    for (name, path) in scenes() {
        let text = std::fs::read_to_string(&path).unwrap();
        let expected = reference::parse(&text).unwrap_or_else(|e| panic!("{name}: reference parser: {e}"));
        let mut scene = new_scene();
        load_file(&path, &mut scene).unwrap_or_else(|e| panic!("{name}: {e}"));
        let image = render(&mut scene, &RenderOptions::default()).unwrap_or_else(|e| panic!("{name}: {e:?}")).image;
        let (width, height) = expected.raster();
        assert_eq!((image.width, image.height), (width, height), "{name}: size");
        let want = expected.render(width, height);

        let mut exact = 0usize;
        let mut close = 0usize;
        let mut worst = 0u8;
        for (got, want) in image.data.chunks(3).zip(&want) {
            let diff = got.iter().zip(want).map(|(a, b)| a.abs_diff(*b)).max().unwrap_or(0);
            worst = worst.max(diff);
            exact += usize::from(diff == 0);
            close += usize::from(diff <= TOLERANCE);
        }
        let total = want.len();
        let share = close as f64 / total as f64;
        println!(
            "{name:<10} {total:>8} {:>8.2}% {:>8.2}% {worst:>9}",
            100.0 * exact as f64 / total as f64,
            100.0 * share
        );
        if share < REQUIRED {
            failures.push(format!("{name}: only {:.2}% of pixels within ±{TOLERANCE}", 100.0 * share));
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}
