//! Puts `memory.x` where the linker finds it, and embeds the scene: the file
//! `OCTRACE_SCENE` names (a path from this folder; default the thesis's
//! figure 5.1, `scenes/fig5_1.txt` of the octrace checkout the dependencies
//! come from, `octrace_pico_build::DEFAULT_SCENE`). The scene is checked here, on the
//! host, with the parser the board runs: its errors fail the build with their
//! line and column. `SceneProfile` holds exactly what it needs, its octree
//! included, so the Pico's RAM holds just this scene (the linker says so if
//! it does not fit). It also holds the screen lists of first hits, which
//! render the same picture faster for RAM the Pico has to spare (at most
//! 28 bytes an object). The octree's shadow shafts are left
//! out: on the thesis's scenes they take longer to build than they save in
//! one picture (BENCHMARKS.md).
//!
//! The scene's reading, checking and profile are `octrace-pico-build`'s
//! `embed_still_scene`, which every board template's build script shares.

use octrace_pico_build::{embed_still_scene, BuildError};
use std::env;
use std::path::PathBuf;

fn main() {
    let out = PathBuf::from(env::var("OUT_DIR").expect("cargo sets OUT_DIR"));
    std::fs::copy("memory.x", out.join("memory.x")).expect("copy memory.x into OUT_DIR");
    println!("cargo:rustc-link-search={}", out.display());
    println!("cargo:rerun-if-changed=memory.x");
    println!("cargo:rerun-if-changed=build.rs");
    embed_still_scene().unwrap_or_else(|e| fail(e));
}

fn fail(error: BuildError) -> ! {
    eprintln!("octrace-pico2-st7789: {error}");
    std::process::exit(1);
}
