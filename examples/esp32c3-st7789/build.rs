//! Embeds the scene: the file
//! `OCTRACE_SCENE` names (a path from this folder; default the thesis's
//! figure 5.1, `../../scenes/fig5_1.txt`). The scene is checked here, on the
//! host, with the parser the board runs: its errors fail the build with their
//! line and column. `SceneProfile` holds exactly what it needs, its octree
//! included, so the ESP32-C3's RAM holds just this scene (the linker says so if
//! it does not fit). It also holds the screen lists of first hits, which
//! render the same picture faster for RAM the ESP32-C3 has to spare (at most
//! 28 bytes an object). The octree's shadow shafts are left
//! out: on the thesis's scenes they take longer to build than they save in
//! one picture (BENCHMARKS.md).

use octrace_core::accel::OctreeConfig;
use octrace_core::profile::{needed_by, ProfileText};
use octrace_core::AccelMode;
use std::env;
use std::path::PathBuf;

const DEFAULT_SCENE: &str = "../../scenes/fig5_1.txt";

fn main() {
    let out = PathBuf::from(env::var("OUT_DIR").expect("cargo sets OUT_DIR"));
    let manifest = PathBuf::from(env::var("CARGO_MANIFEST_DIR").expect("cargo sets CARGO_MANIFEST_DIR"));
    // The memory map and linker scripts come from esp-hal (linkall.x).
    println!("cargo:rerun-if-changed=build.rs");

    println!("cargo:rerun-if-env-changed=OCTRACE_SCENE");
    let scene = env::var("OCTRACE_SCENE").unwrap_or_else(|_| DEFAULT_SCENE.to_owned());
    let path = manifest.join(&scene);
    println!("cargo:rerun-if-changed={}", path.display());
    let text = std::fs::read_to_string(&path).unwrap_or_else(|e| fail(&format!("OCTRACE_SCENE={scene}: {e}")));
    // `Raytracer::load` picks the accelerator as `Auto` does, with the
    // octree `profile!` builds by default.
    let needs = needed_by(&text, AccelMode::Auto, &OctreeConfig::DEFAULT, &mut |error| {
        eprintln!("{scene}:{error}");
    })
    .unwrap_or_else(|errors| fail(&format!("{scene}: {errors} error(s); nothing is built from a scene with errors")));

    // `load` walks the octree by 3DDDA: no room for the thesis's hash table.
    let doc = format!("Exactly what `{scene}` needs, its octree included.");
    let profile = ProfileText {
        name: "SceneProfile",
        doc: &doc,
        counts: &needs,
        octree: None,
        named_walk: false,
        first_hits: true,
        coherence: false,
    };
    let source =
        format!("/// The scene, from `{scene}`.\npub const SCENE_TEXT: &str = include_str!({path:?});\n{profile}");
    std::fs::write(out.join("scene.rs"), source).expect("write scene.rs into OUT_DIR");
}

fn fail(message: &str) -> ! {
    eprintln!("octrace-esp32c3-st7789: {message}");
    std::process::exit(1);
}
