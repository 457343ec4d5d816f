//! Golden images: every scene in `scenes/`, rendered at its RASTER size, must
//! equal `docs/gallery/<scene>.png` bit for bit (the output is
//! deterministic). These are also the README's gallery, so the gallery is
//! always what the code produces.
//!
//! fig5_1 is also kept in each 256-colour mode (`fig5_1-scan.png`, …, indexed
//! PNGs), the README's palette gallery, and at 128×64 on each panel of few
//! levels and with each dithering (`fig5_1-mono.png`, `fig5_1-mono-bayer.png`,
//! …: host-sim's `--color` preview files, byte for byte), its panel gallery;
//! each animation (`scenes/anim_*.txt`) as the animated GIF `host-sim
//! scenes/anim_….txt OUT.gif` writes (`docs/gallery/anim_….gif`, byte for
//! byte).
//!
//! Re-bless after an intended change of the images:
//!
//!     OCTRACE_BLESS=1 cargo test -p octrace-tests --test golden

use host_sim::{load_file, new_scene, render, RenderOptions};
use octrace_core::panel::Dithering;
use octrace_core::render::PanelColor;
use octrace_images::formats::{self, Format, Image};
use octrace_images::palette::{self, PaletteMode};
use octrace_tests::{animations, blessing, repo, scene_path, scenes};

#[test]
fn every_scene_matches_its_golden_image() {
    let gallery = repo().join("docs/gallery");
    let mut failures = Vec::new();
    for (name, path) in scenes() {
        let mut scene = new_scene();
        load_file(&path, &mut scene).unwrap_or_else(|e| panic!("{name}: {e}"));
        let image = render(&mut scene, &RenderOptions::default()).unwrap_or_else(|e| panic!("{name}: {e:?}")).image;
        let golden = gallery.join(format!("{name}.png"));
        if blessing() {
            std::fs::create_dir_all(&gallery).unwrap();
            let mut file = std::fs::File::create(&golden).unwrap();
            formats::write(&Image::Rgb(image), Format::Png, &mut file).unwrap();
            println!("blessed {}", golden.display());
            continue;
        }
        let expected = std::fs::read(&golden)
            .map_err(|e| e.to_string())
            .and_then(|b| formats::read(&b).map(|i| i.to_rgb()).map_err(|e| e.to_string()));
        match expected {
            Err(e) => failures.push(format!("{name}: cannot read {}: {e}", golden.display())),
            Ok(expected) if expected != image => {
                let differing = expected.data.chunks(3).zip(image.data.chunks(3)).filter(|(a, b)| a != b).count();
                failures.push(format!("{name}: {differing} pixels differ from {}", golden.display()));
            }
            Ok(_) => println!("{name}: identical"),
        }
    }
    assert!(
        failures.is_empty(),
        "{}\n(re-bless with OCTRACE_BLESS=1 cargo test -p octrace-tests --test golden)",
        failures.join("\n")
    );
}

#[test]
fn fig5_1_in_every_palette_mode_matches_its_golden_image() {
    let gallery = repo().join("docs/gallery");
    let mut scene = new_scene();
    load_file(&scene_path("fig5_1"), &mut scene).unwrap();
    let rendered = render(&mut scene, &RenderOptions::default()).unwrap();
    let mut failures = Vec::new();
    for mode in [PaletteMode::Scan, PaletteMode::Dither, PaletteMode::Coarse, PaletteMode::Gray] {
        let image = palette::apply(&rendered.image, &rendered.objects, mode);
        let golden = gallery.join(format!("fig5_1-{}.png", mode.name()));
        if blessing() {
            formats::write(&image, Format::Png, &mut std::fs::File::create(&golden).unwrap()).unwrap();
            continue;
        }
        match std::fs::read(&golden)
            .map_err(|e| e.to_string())
            .and_then(|b| formats::read(&b).map_err(|e| e.to_string()))
        {
            Ok(expected) if expected == image => {}
            Ok(_) => failures.push(format!("{}: differs", golden.display())),
            Err(e) => failures.push(format!("{}: {e}", golden.display())),
        }
    }
    assert!(
        failures.is_empty(),
        "{}\n(re-bless with OCTRACE_BLESS=1 cargo test -p octrace-tests --test golden)",
        failures.join("\n")
    );
}

#[test]
fn fig5_1_on_every_panel_matches_its_golden_image() {
    let gallery = repo().join("docs/gallery");
    let dir = tempfile::tempdir().unwrap();
    let scene = scene_path("fig5_1");
    // Each panel by its default method; one bit by every method.
    let default = Dithering::default();
    let shown = PanelColor::ALL.into_iter().filter(|c| c.panel().is_some()).map(|c| (c, default));
    let one_bit = Dithering::ALL.into_iter().filter(|&d| d != default).map(|d| (PanelColor::Mono, d));
    let mut failures = Vec::new();
    for (color, dithering) in shown.chain(one_bit) {
        let name = match dithering == default {
            true => format!("fig5_1-{}.png", color.name()),
            false => format!("fig5_1-{}-{}.png", color.name(), dithering.name()),
        };
        let out = dir.path().join(&name);
        let args = [scene.to_str().unwrap(), out.to_str().unwrap(), "--size", "128x64", "--quiet"];
        let args = ["host-sim"].into_iter().chain(args).chain(["--color", color.name(), "--dither", dithering.name()]);
        let mut stderr = Vec::new();
        assert_eq!(host_sim::cli::run(args, &mut Vec::new(), &mut stderr), 0, "{}", String::from_utf8_lossy(&stderr));
        let written = std::fs::read(&out).unwrap();
        let golden = gallery.join(&name);
        if blessing() {
            std::fs::write(&golden, &written).unwrap();
            continue;
        }
        match std::fs::read(&golden) {
            Ok(expected) if expected == written => {}
            Ok(_) => failures.push(format!("{}: differs from host-sim's preview", golden.display())),
            Err(e) => failures.push(format!("{}: {e}", golden.display())),
        }
    }
    assert!(
        failures.is_empty(),
        "{}\n(re-bless with OCTRACE_BLESS=1 cargo test -p octrace-tests --test golden)",
        failures.join("\n")
    );
}

#[test]
fn every_animation_matches_its_golden_gif() {
    let gallery = repo().join("docs/gallery");
    let dir = std::env::temp_dir().join(format!("octrace-golden-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let mut failures = Vec::new();
    for (name, path) in animations() {
        let out = dir.join(format!("{name}.gif"));
        let mut stderr = Vec::new();
        let code = host_sim::cli::run(
            ["host-sim".as_ref(), path.as_os_str(), out.as_os_str(), "-q".as_ref()],
            &mut Vec::new(),
            &mut stderr,
        );
        assert_eq!(code, 0, "{name}: {}", String::from_utf8_lossy(&stderr));
        let made = std::fs::read(&out).unwrap();
        let golden = gallery.join(format!("{name}.gif"));
        if blessing() {
            std::fs::write(&golden, &made).unwrap();
            println!("blessed {}", golden.display());
            continue;
        }
        match std::fs::read(&golden) {
            Err(e) => failures.push(format!("{name}: cannot read {}: {e}", golden.display())),
            Ok(expected) if expected != made => failures.push(format!("{name}: differs from {}", golden.display())),
            Ok(_) => println!("{name}: identical"),
        }
    }
    let _ = std::fs::remove_dir_all(&dir);
    assert!(!animations().is_empty(), "scenes/ holds animations");
    assert!(
        failures.is_empty(),
        "{}\n(re-bless with OCTRACE_BLESS=1 cargo test -p octrace-tests --test golden)",
        failures.join("\n")
    );
}
