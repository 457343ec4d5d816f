//! Panels of few levels on whole scenes: issue 42's measure reproduces the
//! issue's own figures, and the default dithering meets its quality target
//! (one bit ≥ 28 dB, four grays ≥ 37 dB on fig5_1, fig5_3 and fig5_5 at
//! 128×64). The full table of every method on every scene is
//! `octrace-bench panels` (BENCHMARKS.md).

use host_sim::{load_file, new_scene, render, RenderOptions};
use octrace_core::panel::{Dithering, Panel};
use octrace_images::{panel, RgbImage};
use octrace_tests::scene_path;

/// The three scenes of the issue's table at 128×64.
fn renders() -> Vec<(&'static str, RgbImage)> {
    ["fig5_1", "fig5_3", "fig5_5"]
        .into_iter()
        .map(|name| {
            let mut scene = new_scene();
            load_file(&scene_path(name), &mut scene).unwrap();
            let options = RenderOptions { size: Some((128, 64)), ..Default::default() };
            (name, render(&mut scene, &options).unwrap().image)
        })
        .collect()
}

fn score(render: &RgbImage, panel: Panel, dithering: Dithering) -> f64 {
    panel::seen_psnr(render, &panel::dithered(render, panel, dithering).to_rgb(), panel)
}

#[test]
fn the_measure_gives_the_issues_figures() {
    // The issue's rows for a cut at mid-gray and for 4×4 Bayer, to their
    // 0.1 dB: both depend on each pixel alone, so they pin the measure down.
    let issue = [(Dithering::Nearest, [11.4, 15.9, 11.1]), (Dithering::Bayer, [25.7, 23.6, 25.9])];
    for (i, (name, render)) in renders().iter().enumerate() {
        for (dithering, figures) in issue {
            let measured = score(render, Panel::Mono, dithering);
            assert!((measured - figures[i]).abs() < 0.06, "{name} by {dithering}: {measured:.2} dB");
        }
    }
}

#[test]
fn the_default_meets_the_quality_target() {
    for (name, render) in renders() {
        let one_bit = score(&render, Panel::Mono, Dithering::default());
        let four_grays = score(&render, Panel::Gray2, Dithering::default());
        println!("{name}: one bit {one_bit:.2} dB, four grays {four_grays:.2} dB");
        assert!(one_bit >= 28.0, "{name}: one bit {one_bit:.2} dB, below 28");
        assert!(four_grays >= 37.0, "{name}: four grays {four_grays:.2} dB, below 37");
        // And it beats the classic methods it is chosen over.
        for other in [Dithering::FloydSteinberg, Dithering::Bayer, Dithering::Nearest] {
            assert!(one_bit > score(&render, Panel::Mono, other), "{name}: {other} beats fs-pe");
        }
    }
}
