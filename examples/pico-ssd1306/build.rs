//! Embeds the scene `OCTRACE_SCENE` names (a path from this folder; default
//! the thesis's figure 5.1 of the octrace checkout the dependencies come
//! from), checked with the parser the board runs and with
//! a capacity profile sized for it, and puts the RP2040's memory map where
//! the linker finds it with the firmware's code placement
//! (`OCTRACE_CODE_IN`): all `octrace-pico-build`'s, which every Pico
//! template shares.

use octrace_pico_build::{embed_scene, link, BuildError, CodePlacement};

fn main() {
    println!("cargo:rerun-if-changed=build.rs");
    let placement = CodePlacement::from_env().unwrap_or_else(|e| fail(e));
    let scene = embed_scene().unwrap_or_else(|e| fail(e));
    link(&[("octrace-pico-ssd1306", placement, scene)]).unwrap_or_else(|e| fail(e));
}

fn fail(error: BuildError) -> ! {
    eprintln!("octrace-pico-ssd1306: {error}");
    std::process::exit(1);
}
