//! Puts `memory.x` where the linker finds it, and embeds the scene: the file
//! `OCTRACE_SCENE` names (a path from this folder; default the thesis's
//! figure 5.1, `../../scenes/fig5_1.txt`). The scene is checked here, on the
//! host, with the parser the board runs: its errors fail the build with their
//! line and column. `SceneProfile` holds exactly what it needs, its octree
//! included, so the Pico's RAM holds just this scene (the linker says so if
//! it does not fit). It also holds the screen lists of first hits, which
//! render the same picture faster for RAM the Pico has to spare (at most
//! 28 bytes an object), and for a scene walked in an octree a light buffer
//! (its shadow rays test only the objects their direction's cell lists),
//! built in RAM when the scene loads. The octree's shadow shafts are left
//! out: on the thesis's scenes they take longer to build than they save in
//! one picture (BENCHMARKS.md).

use octrace_core::accel::OctreeConfig;
use octrace_core::accel::MAX_CELLS_A_SIDE;
use octrace_core::profile::{needed_by, needed_with_light_buffer, ProfileText};
use octrace_core::AccelMode;
use std::env;
use std::path::PathBuf;

const DEFAULT_SCENE: &str = "../../scenes/fig5_1.txt";

fn main() {
    let out = PathBuf::from(env::var("OUT_DIR").expect("cargo sets OUT_DIR"));
    let manifest = PathBuf::from(env::var("CARGO_MANIFEST_DIR").expect("cargo sets CARGO_MANIFEST_DIR"));
    // Where each firmware's code runs: memory.x includes
    // `code-placement.x`, found in a folder of its own for each binary.
    println!("cargo:rerun-if-env-changed=OCTRACE_CODE_IN");
    let scene_firmware = match env::var("OCTRACE_CODE_IN").as_deref() {
        Ok("parse-and-render") | Err(_) => Placement::LoadAndRenderInSram,
        Ok("render") => Placement::RenderInSram,
        Ok("sram") => Placement::AllInSram,
        Ok("flash") => Placement::Flash,
        Ok(other) => fail(&format!(
            "OCTRACE_CODE_IN={other}: expected `parse-and-render` (the default), `render`, `sram` or `flash`"
        )),
    };
    let read = |script: &str| {
        println!("cargo:rerun-if-changed={script}");
        std::fs::read_to_string(script).unwrap_or_else(|e| fail(&format!("read {script}: {e}")))
    };
    let sram_code = read("sram-code.x");
    // The live firmware's arenas fill the RAM: only its render path fits.
    for (binary, placement) in [("octrace-pico-st7789", scene_firmware), ("octrace-pico-live", Placement::RenderInSram)]
    {
        let dir = out.join(binary);
        let script = match placement.copied() {
            Some(copied) => sram_code.replace("COPIED", &copied),
            None => "/* The code runs in place from flash, through the XIP cache. */\n".to_owned(),
        };
        std::fs::create_dir_all(&dir)
            .and_then(|()| std::fs::write(dir.join("code-placement.x"), script))
            .unwrap_or_else(|e| fail(&format!("write {binary}/code-placement.x: {e}")));
        println!("cargo:rustc-link-arg-bin={binary}=-L{}", dir.display());
    }
    let in_sram = scene_firmware != Placement::Flash;
    if in_sram {
        println!("cargo:rustc-cfg=code_in_sram");
    }
    println!("cargo::rustc-check-cfg=cfg(code_in_sram)");

    // The embedded-scene firmware's pixel order: row by row (the default,
    // the faster), or progressive (the whole panel in coarse blocks at
    // once, then finer).
    println!("cargo:rerun-if-env-changed=OCTRACE_ORDER");
    match env::var("OCTRACE_ORDER").as_deref() {
        Ok("rows") | Err(_) => {}
        Ok("progressive") => println!("cargo:rustc-cfg=progressive_order"),
        Ok(other) => fail(&format!("OCTRACE_ORDER={other}: expected `rows` (the default) or `progressive`")),
    }
    println!("cargo::rustc-check-cfg=cfg(progressive_order)");
    // Where the linker finds memory.x when it runs elsewhere than here.
    std::fs::write(out.join("memory.x"), read("memory.x")).unwrap_or_else(|e| fail(&format!("write memory.x: {e}")));
    println!("cargo:rustc-link-search={}", out.display());
    println!("cargo:rerun-if-changed=build.rs");

    println!("cargo:rerun-if-env-changed=OCTRACE_SCENE");
    let scene = env::var("OCTRACE_SCENE").unwrap_or_else(|_| DEFAULT_SCENE.to_owned());
    let path = manifest.join(&scene);
    println!("cargo:rerun-if-changed={}", path.display());
    let text = std::fs::read_to_string(&path).unwrap_or_else(|e| fail(&format!("OCTRACE_SCENE={scene}: {e}")));
    // `Raytracer::load` picks the accelerator as `Auto` does, with the
    // octree `profile!` builds by default.
    let mut report = |error| eprintln!("{scene}:{error}");
    let needs = needed_by(&text, AccelMode::Auto, &OctreeConfig::DEFAULT, &mut report).unwrap_or_else(|errors| {
        fail(&format!("{scene}: {errors} error(s); nothing is built from a scene with errors"))
    });
    // A scene walked in an octree gets a light buffer for its shadow rays,
    // built in RAM when the scene loads (the code runs from SRAM, the RAM is
    // there; in flash its reads would miss the XIP cache). A scene of a few
    // objects tests them all: the buffer does not pay there.
    let needs = if needs.octree_boxes > 0 {
        needed_with_light_buffer(&text, AccelMode::Auto, &OctreeConfig::DEFAULT, MAX_CELLS_A_SIDE, &mut report)
            .unwrap_or_else(|errors| fail(&format!("{scene}: {errors} error(s)")))
    } else {
        needs
    };

    // `load` walks the octree by 3DDDA: no room for the thesis's hash table.
    let doc = format!("Exactly what `{scene}` needs, its octree included.");
    let profile = ProfileText {
        name: "SceneProfile",
        doc: &doc,
        counts: &needs,
        octree: None,
        named_walk: false,
        first_hits: true,
    };
    let name = path.file_stem().map_or_else(|| scene.clone(), |stem| stem.to_string_lossy().into_owned());
    let source = format!(
        "/// The scene, from `{scene}`.\npub const SCENE_TEXT: &str = include_str!({path:?});\n\
         /// Its file's name, without the extension.\npub const SCENE_NAME: &str = {name:?};\n{profile}"
    );
    std::fs::write(out.join("scene.rs"), source).expect("write scene.rs into OUT_DIR");
}

fn fail(message: &str) -> ! {
    eprintln!("octrace-pico-st7789: {message}");
    std::process::exit(1);
}

/// The render path's input sections: octrace-core's tracing and
/// indexing, the two cores' loop, the compiler's 64-bit helpers.
const RENDER_PATH: &str = concat!(
    ".text.*octrace_core*accel* .text.*octrace_core*shapes* .text.*octrace_core*shade* ",
    ".text.*octrace_core*render* .text.*octrace_core*math* .text.*both_cores* ",
    ".text.__aeabi_* .text.__*di3 .text.__*di4"
);

/// The loader's: the parser and the scene's set-up.
const LOADER: &str = ".text.*octrace_core*parse* .text.*octrace_core*scene*";

/// Where a firmware's code runs.
#[derive(Clone, Copy, PartialEq, Eq)]
enum Placement {
    /// All of it (and its constants) copied into SRAM at boot: a little
    /// faster than `RenderInSram` for a small scene, too large beside a
    /// large one.
    AllInSram,
    /// `RenderInSram` and the loader (the parser, the scene's set-up):
    /// what runs once the board is up, fig5_3's parse and index 1.3 M
    /// cycles faster, for 34 KiB more of SRAM than `RenderInSram`.
    LoadAndRenderInSram,
    /// The render path copied into SRAM at boot (octrace-core's tracing
    /// and indexing, the two cores' loop, the compiler's 64-bit helpers);
    /// the rest (the parser, USB, the panel's set-up) runs from flash, so
    /// that SRAM is left to the scene.
    RenderInSram,
    /// All of it in place in flash, through the XIP cache.
    Flash,
}

impl Placement {
    /// The input sections `sram-code.x` copies, or none.
    fn copied(self) -> Option<String> {
        match self {
            Placement::AllInSram => Some("*(.text .text.*); *(.rodata .rodata.*);".to_owned()),
            Placement::LoadAndRenderInSram => Some(format!("*({RENDER_PATH} {LOADER});")),
            Placement::RenderInSram => Some(format!("*({RENDER_PATH});")),
            Placement::Flash => None,
        }
    }
}
