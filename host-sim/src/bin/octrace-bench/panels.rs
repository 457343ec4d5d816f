//! The `panels` table: every scene at 128×64 on every panel of few levels
//! by every dithering, under issue 42's measure (what the eye sees of the
//! picture through a blur of one pixel), and each method's cost per pixel
//! here.

use crate::measure::{best_of, load, scene_files, BenchError};
use host_sim::{all_cores, render, RenderOptions};
use octrace_core::panel::{Dithering, Panel};
use octrace_core::render::PanelColor;
use octrace_images::panel;
use std::path::Path;
use std::time::Duration;

/// Every scene at 128×64 on every panel of few levels by every dithering:
/// issue 42's measure (what the eye sees of the picture through a blur of
/// one pixel, [`octrace_images::panel::seen_psnr`]), and each method's cost
/// per pixel on this machine.
pub(crate) fn table(dir: &Path) -> Result<(), BenchError> {
    let mut renders = Vec::new();
    for path in scene_files(dir) {
        let name = path.file_stem().unwrap_or_default().to_string_lossy().into_owned();
        let scene = load(&path)?;
        let options = RenderOptions { size: Some((128, 64)), threads: all_cores(), ..Default::default() };
        if let Ok(rendered) = render(&scene, &options) {
            renders.push((name, rendered.image));
        }
    }
    for shown in Panel::ALL {
        let against = match shown {
            Panel::BlackWhiteRed => "the render's RGB (capped by the colours three inks cannot mix)",
            _ => "the render's gray",
        };
        println!(
            "### `--color {}` at 128×64: dB against {against}, blurred by σ = 1 pixel
",
            PanelColor::from(shown)
        );
        let methods =
            Dithering::ALL.map(|d| format!("{d}{}", if d == Dithering::default() { " (default)" } else { "" }));
        println!("| scene | {} |", methods.join(" | "));
        println!("| --- |{}", " ---: |".repeat(methods.len()));
        let mut cost = [Duration::ZERO; Dithering::ALL.len()];
        for (name, image) in &renders {
            print!("| {name} |");
            for (i, dithering) in Dithering::ALL.into_iter().enumerate() {
                let (time, preview) = best_of(5, || panel::dithered(image, shown, dithering));
                cost[i] += time;
                print!(" {:.2} |", panel::seen_psnr(image, &preview.to_rgb(), shown));
            }
            println!();
        }
        let pixels = (renders.len() * 128 * 64) as f64;
        let cost: Vec<String> = cost.iter().map(|c| format!("{:.1} ns", c.as_nanos() as f64 / pixels)).collect();
        println!("| cost per pixel | {} |\n", cost.join(" | "));
    }
    Ok(())
}
