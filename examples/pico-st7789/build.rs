//! Embeds the scene `OCTRACE_SCENE` names (a path from this folder; default
//! the thesis's figure 5.1 of the octrace checkout the dependencies come
//! from), checked with the parser the board runs and with
//! a capacity profile sized for it; puts the RP2040's memory map where the
//! linker finds it, with each firmware's code placement (`OCTRACE_CODE_IN`
//! for the embedded-scene firmware; the live one's arenas fill the RAM, so
//! only its render path is copied into SRAM; an animation's tracking goes
//! with the embedded-scene firmware's); and reads the embedded-scene
//! firmware's pixel order (`OCTRACE_ORDER`). All but the order is
//! `octrace-pico-build`'s, which every Pico template shares.

use octrace_pico_build::{embed_scene, link, BuildError, CodePlacement, SceneKind};

fn main() {
    println!("cargo:rerun-if-changed=build.rs");
    let placement = CodePlacement::from_env().unwrap_or_else(|e| fail(e));
    let scene = embed_scene().unwrap_or_else(|e| fail(e));
    link(&[
        ("octrace-pico-st7789", placement, scene),
        ("octrace-pico-live", CodePlacement::RenderInSram, SceneKind::Still),
    ])
    .unwrap_or_else(|e| fail(e));

    // The embedded-scene firmware's pixel order: row by row (the default,
    // the faster), or progressive (the whole panel in coarse blocks at
    // once, then finer).
    println!("cargo:rerun-if-env-changed=OCTRACE_ORDER");
    println!("cargo::rustc-check-cfg=cfg(progressive_order)");
    match std::env::var("OCTRACE_ORDER").as_deref() {
        Ok("rows") | Err(_) => {}
        Ok("progressive") => println!("cargo:rustc-cfg=progressive_order"),
        Ok(other) => fail(BuildError::Variable {
            name: "OCTRACE_ORDER",
            value: other.to_owned(),
            expected: "`rows` (the default) or `progressive`",
        }),
    }
}

fn fail(error: BuildError) -> ! {
    eprintln!("octrace-pico-st7789: {error}");
    std::process::exit(1);
}
