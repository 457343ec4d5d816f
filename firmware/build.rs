//! Chooses the board, scene, size, mode and pixel format from the
//! environment, at build time, and sizes the board's arenas
//! for exactly that scene: it parses the scene and builds its octree here,
//! on the host, with the core the board runs, and writes a
//! `octrace_core::profile!` holding what they needed.
//!
//! | variable | values | default |
//! | --- | --- | --- |
//! | `OCTRACE_BOARD` | `microbit` (thumbv6m), `mps2-an385` or `lm3s6965evb` (thumbv7m), `mps2-an505` or `mps2-an521` (thumbv8m.main), `virt` (riscv32imc) | from the target: thumbv6m `microbit`, thumbv7m `mps2-an385`, thumbv8m.main `mps2-an505`, riscv32imc `virt` |
//! | `OCTRACE_SCENE` | a scene in `scenes/` by name (without `.txt`), or a scene file's path | `fig5_1` |
//! | `OCTRACE_SIZE` | `WxH` (on `lm3s6965evb` at most the panel's 128x64, an even width) | `160x128`; `128x64` on `lm3s6965evb` |
//! | `OCTRACE_ACCEL` | `auto`, `naive`, `octree`, `dda` | `auto` |
//! | `OCTRACE_COLOR` | `rgb888`, `rgb565`, `dither` (1-byte indices into the 6×6×6 cube), and the panels of few levels, 1 byte a pixel holding the level: `mono` (0, 1), `gray2` (0 to 3), `gray4` (0 to 15), `bwr` (0 black, 1 white, 2 red); only `gray4` on `lm3s6965evb` | `rgb888`; `gray4` on `lm3s6965evb` |
//! | `OCTRACE_DITHER` | how `mono`, `gray2`, `gray4` and `bwr` are dithered: `fs-pe`, `fs`, `bayer`, `nearest` | `fs-pe` |
//! | `OCTRACE_TECHNIQUES` | `auto` (every technique whose RAM fits beside the deepest octree that fits, and for a scene walked in an octree the light buffer in flash instead of the shadow shafts, for a few objects their cones in RAM), `none`, or a comma list of `first-hits`, `shadow-shafts`, `light-buffer` (built here, kept in flash), `light-buffer-ram` (built by the board, in RAM; each still only where it fits) | `auto` |
//! | `OCTRACE_OUT` | host file the pixels are written to; on `lm3s6965evb` the PNG of the panel's screen that the runner grabs | `octrace-out.raw`; `screen.png` on `lm3s6965evb` |
//!
//! | board | qemu `-machine` | core | flash | RAM | display |
//! | --- | --- | --- | --- | --- | --- |
//! | `microbit` | `microbit` | Cortex-M0 | 256 KiB | 16 KiB | semihosting file |
//! | `mps2-an385` | `mps2-an385` | Cortex-M3 | 4 MiB | 4 MiB | semihosting file |
//! | `mps2-an505` | `mps2-an505` | Cortex-M33 (Secure state) | 4 MiB | 4 MiB | semihosting file |
//! | `mps2-an521` | `mps2-an521` | two Cortex-M33s, both rendering (`src/both_cores.rs`) | 4 MiB | 4 MiB | semihosting file |
//! | `virt` | `virt` (`qemu-system-riscv32`) | RV32IMC hart | none (code in RAM) | 8 MiB | semihosting file |
//! | `lm3s6965evb` | `lm3s6965evb` | Cortex-M3 | 256 KiB | 64 KiB | 128×64 16-gray OLED (SSD0323 on SSI0) |
//!
//! The runner (`run.sh`) learns the machine and the output from the ELF
//! itself: this script puts them in the non-loaded section `.octrace_run`
//! (see `memory-*.x`), so an ELF always runs on the board it was built for.

use octrace_core::accel::OctreeConfig;
use octrace_core::animation::AnimationNeeds;
use octrace_core::capacity::Counts;
use octrace_core::panel::Dithering;
use octrace_core::parse::{count, parse};
use octrace_core::profile::Host;
use octrace_core::profile::{light_buffer_words, needed_with_light_buffer, ProfileText};
use octrace_core::render::PanelColor;
use octrace_core::scene::Scene;
use octrace_core::AccelMode;
use std::env;
use std::fmt::Write as _;
use std::path::PathBuf;

/// What each board's RAM holds besides the stack, and how its octree is
/// built: on the micro:bit at most 4 levels of 8 objects a leaf (fewer
/// levels when the scene's arenas would not fit its RAM otherwise).
struct Board {
    name: &'static str,
    /// Bytes for the statics: the arenas and `OTHER_STATICS`.
    static_ram: usize,
    config: OctreeConfig,
}

/// What the firmware's statics take besides the arenas (the tracer's
/// settings and camera, the mailbox's bookkeeping, the display's and
/// semihosting's buffers): 382 to 394 bytes on every board and scene
/// measured (`.data` + `.bss` less the arenas' estimate), with room to spare.
/// Without it a scene could pass here and then overflow RAM at link time.
const OTHER_STATICS: usize = 512;

fn var(name: &str, default: &str) -> String {
    println!("cargo:rerun-if-env-changed={name}");
    env::var(name).unwrap_or_else(|_| default.to_owned())
}

fn fail(message: String) -> ! {
    eprintln!("octrace-firmware: {message}");
    std::process::exit(1);
}

fn main() {
    let out = PathBuf::from(env::var("OUT_DIR").expect("cargo sets OUT_DIR"));
    let manifest = PathBuf::from(env::var("CARGO_MANIFEST_DIR").expect("cargo sets CARGO_MANIFEST_DIR"));
    let target = env::var("TARGET").unwrap_or_default();
    let default_board = match target.as_str() {
        "thumbv6m-none-eabi" => "microbit",
        "thumbv7m-none-eabi" => "mps2-an385",
        "thumbv8m.main-none-eabihf" => "mps2-an505",
        "riscv32imc-unknown-none-elf" => "virt",
        other => fail(format!(
            "no board for target {other}: use thumbv6m-none-eabi, thumbv7m-none-eabi, thumbv8m.main-none-eabihf \
             or riscv32imc-unknown-none-elf"
        )),
    };
    let board = var("OCTRACE_BOARD", default_board);
    let mut board = match (board.as_str(), target.as_str()) {
        ("microbit", "thumbv6m-none-eabi") => Board {
            name: "microbit",
            // Set with the stack, once the colours are known.
            static_ram: 0,
            config: OctreeConfig { max_objects: 8, max_depth: 4, ..OctreeConfig::DEFAULT },
        },
        ("mps2-an385", "thumbv7m-none-eabi") => {
            Board { name: "mps2-an385", static_ram: 3 * 1024 * 1024, config: OctreeConfig::DEFAULT }
        }
        ("mps2-an505", "thumbv8m.main-none-eabihf") => {
            Board { name: "mps2-an505", static_ram: 3 * 1024 * 1024, config: OctreeConfig::DEFAULT }
        }
        ("mps2-an521", "thumbv8m.main-none-eabihf") => {
            Board { name: "mps2-an521", static_ram: 3 * 1024 * 1024, config: OctreeConfig::DEFAULT }
        }
        ("virt", "riscv32imc-unknown-none-elf") => {
            Board { name: "virt", static_ram: 3 * 1024 * 1024, config: OctreeConfig::DEFAULT }
        }
        ("lm3s6965evb", "thumbv7m-none-eabi") => {
            Board { name: "lm3s6965evb", static_ram: 56 * 1024, config: OctreeConfig::DEFAULT }
        }
        ("microbit", _) => fail(format!("OCTRACE_BOARD=microbit needs --target thumbv6m-none-eabi, not {target}")),
        ("mps2-an385" | "lm3s6965evb", _) => {
            fail(format!("OCTRACE_BOARD={board} needs --target thumbv7m-none-eabi, not {target}"))
        }
        ("virt", _) => fail(format!("OCTRACE_BOARD=virt needs --target riscv32imc-unknown-none-elf, not {target}")),
        ("mps2-an505" | "mps2-an521", _) => {
            fail(format!("OCTRACE_BOARD={board} needs --target thumbv8m.main-none-eabihf, not {target}"))
        }
        (other, _) => fail(format!(
            "OCTRACE_BOARD={other}: expected microbit, mps2-an385, mps2-an505, mps2-an521, lm3s6965evb or virt"
        )),
    };
    let oled = board.name == "lm3s6965evb";
    let memory = manifest.join(format!("memory-{}.x", board.name));
    println!("cargo:rustc-link-search={}", out.display());
    println!("cargo:rerun-if-changed={}", memory.display());
    println!("cargo:rustc-check-cfg=cfg(board, values(\"microbit\", \"mps2-an385\", \"mps2-an505\", \"mps2-an521\", \"lm3s6965evb\", \"virt\"))");
    println!("cargo:rustc-cfg=board=\"{}\"", board.name);

    let given = var("OCTRACE_SCENE", "fig5_1");
    // A scene of `scenes/` by its name, or any scene file by its path
    // (relative to `firmware/`, where cargo runs this), named by its stem.
    let (scene, scene_path) = if given.ends_with(".txt") || given.contains(['/', '\\']) {
        let path = manifest.join(&given);
        (path.file_stem().map_or_else(String::new, |s| s.to_string_lossy().into_owned()), path)
    } else {
        (given.clone(), manifest.join("../scenes").join(format!("{given}.txt")))
    };
    let bytes = std::fs::read(&scene_path)
        .unwrap_or_else(|e| fail(format!("OCTRACE_SCENE={given}: {}: {e}", scene_path.display())));
    // A scene's other errors the board reports; this one, include_str!
    // could not embed.
    let text = octrace_core::parse::scene_text(&bytes)
        .map(str::to_owned)
        .unwrap_or_else(|e| fail(format!("{}:{e}", scene_path.display())));
    println!("cargo:rerun-if-changed={}", scene_path.display());
    let size = var("OCTRACE_SIZE", if oled { "128x64" } else { "160x128" });
    let (w, h) = size
        .split_once('x')
        .and_then(|(w, h)| Some((w.parse::<u32>().ok()?, h.parse::<u32>().ok()?)))
        .filter(|&(w, h)| (1..=16384).contains(&w) && (1..=16384).contains(&h))
        .unwrap_or_else(|| fail(format!("OCTRACE_SIZE={size}: expected WxH, 1 to 16384 each")));
    if oled && (w > 128 || h > 64) {
        fail(format!("OCTRACE_SIZE={size}: the lm3s6965evb's panel is 128x64"));
    }
    if oled && !w.is_multiple_of(2) {
        fail(format!("OCTRACE_SIZE={size}: the lm3s6965evb's panel takes pixels in pairs: an even width"));
    }
    let accel = var("OCTRACE_ACCEL", "auto");
    let Some(accel) = AccelMode::from_name(&accel) else {
        let names: Vec<&str> = AccelMode::ALL.iter().map(|m| m.name()).collect();
        fail(format!("OCTRACE_ACCEL={accel}: expected {}", names.join(", ")))
    };
    let color = var("OCTRACE_COLOR", if oled { "gray4" } else { "rgb888" });
    let wire = match PanelColor::from_name(&color) {
        Some(PanelColor::Gray4) => PanelColor::Gray4,
        _ if oled => fail(format!("OCTRACE_COLOR={color}: the lm3s6965evb's OLED shows 16 grays: use gray4")),
        Some(wire) => wire,
        None => {
            let names: Vec<&str> = PanelColor::ALL.iter().map(|c| c.name()).collect();
            fail(format!("OCTRACE_COLOR={color}: expected {}", names.join(", ")))
        }
    };
    let dithering = var("OCTRACE_DITHER", Dithering::default().name());
    let Some(dithering) = Dithering::from_name(&dithering) else {
        let names: Vec<&str> = Dithering::ALL.iter().map(|d| d.name()).collect();
        fail(format!("OCTRACE_DITHER={dithering}: expected {}", names.join(", ")))
    };
    // The linker script: the micro:bit's splits its RAM between the stack
    // this build needs and the statics.
    let mut linker_script =
        std::fs::read_to_string(&memory).unwrap_or_else(|e| fail(format!("{}: {e}", memory.display())));
    // Parsed once: the stack the micro:bit needs, and the mirror's lists.
    let (rdepth, has_mirror) = surveyed(&text);
    if board.name == "microbit" {
        let stack = microbit_stack(wire, rdepth);
        board.static_ram = MICROBIT_RAM - stack;
        linker_script = linker_script.replace("STACK_BYTES", &stack.to_string());
    }
    std::fs::write(out.join("memory.x"), linker_script).expect("write memory.x");
    // Error diffusion's row for the panel's width, on the draw's stack.
    let error_words = match wire.panel() {
        Some(panel) if dithering.diffuses() => panel.error_words(w),
        _ => 0,
    };
    let output = var("OCTRACE_OUT", if oled { "screen.png" } else { "octrace-out.raw" });
    if output.contains(['\0', '\n']) {
        fail("OCTRACE_OUT: a path without NUL or newline".to_owned());
    }
    // Only the thesis's walk reads the octree's hash table.
    let named_walk = accel == AccelMode::Octree;
    let techniques = var("OCTRACE_TECHNIQUES", "auto");
    let Some(mut wanted) = Techniques::from_names(&techniques) else {
        fail(format!(
            "OCTRACE_TECHNIQUES={techniques}: expected auto, none, or a comma list of {}",
            Techniques::NAMES.join(", ")
        ))
    };
    // The mirror's lists serve a scene with a mirror walked in an octree
    // (a few objects, traced naively, cost a reflection what they would);
    // not on the micro:bit, whose stack is sized for the builds measured
    // without them (making them from inside a ray's trace overflowed it).
    let indexed = accel.resolve(count(&text).objects).traversal().is_some();
    wanted.mirror_hits &= wanted.first_hits && indexed && board.name != "microbit" && has_mirror;
    // The naive mode asked for by name stays the thesis's test of every
    // object: the board API gives it no light buffer of its own.
    if accel == AccelMode::Naive {
        (wanted.light_buffer, wanted.light_buffer_in_flash) = (0, false);
    }
    // A handful of objects, tested in the naive mode, get cones for a light
    // buffer (a cube's look-up would cost what testing them all does):
    // a few words, built by the board in RAM, where checking a copy in
    // flash would take longer than building it.
    let wanted_light_buffer = wanted.light_buffer > 0 || wanted.light_buffer_in_flash;
    if !indexed {
        wanted.light_buffer = if wanted_light_buffer { Techniques::LIGHT_CELLS[0] } else { 0 };
        wanted.light_buffer_in_flash = false;
    }
    // With every light buffered, nothing would read the shafts.
    if wanted.light_buffer_in_flash {
        wanted.shadow_shafts = false;
    }
    // The board's octree, or a shallower one if the scene's arenas would
    // not fit its RAM otherwise, with every technique that fits beside it
    // (a level less costs more than either technique gains).
    let budget = board.static_ram - OTHER_STATICS;
    // A scene without a MOVE links none of the interpolation of keys.
    let motion = AnimationNeeds::of(&text, Default::default()).moves();
    let plan = |accel: AccelMode, techniques: Techniques, max_depth: u32| {
        let config = OctreeConfig { max_depth, shadow_shafts: techniques.shadow_shafts, ..board.config };
        let counts = needs(&text, accel, &config, techniques.light_buffer);
        let profile = ProfileText {
            name: "",
            doc: "",
            counts: &counts,
            octree: Some(&config),
            named_walk,
            first_hits: techniques.first_hits,
            mirror_hits: techniques.mirror_hits,
            coherence: false,
            motion,
        };
        let bytes = profile.arena_bytes();
        (config, techniques, counts, bytes)
    };
    let (octree, techniques, counts, bytes) = (1..=board.config.max_depth)
        .rev()
        .flat_map(|depth| wanted.subsets().map(move |techniques| (techniques, depth)))
        .map(|(techniques, depth)| plan(accel, techniques, depth))
        .find(|&(.., bytes)| bytes <= budget)
        .unwrap_or_else(|| plan(accel, Techniques::NONE, board.config.max_depth));
    if let Err(e) = counts.check_octree_index() {
        fail(format!("{scene} is too large for any board: {e}"));
    }
    if bytes > budget {
        // Without an octree the objects alone may fit: said, not chosen
        // (the naive walk is slower by as much as the octree gains).
        let (.., naive_bytes) = plan(AccelMode::Naive, Techniques::NONE, board.config.max_depth);
        let hint = match accel != AccelMode::Naive && naive_bytes <= budget {
            true => format!("; without its octree it needs about {naive_bytes}: build it with OCTRACE_ACCEL=naive"),
            false => String::new(),
        };
        fail(format!(
            "{scene} needs about {bytes} bytes of arenas ({}), more than the {} bytes the {} has for them \
             beside its stack and other statics{hint}",
            counts.described(),
            budget,
            board.name
        ));
    }

    let mut config = String::new();
    writeln!(config, "pub const BOARD: &str = {:?};", board.name).unwrap();
    writeln!(config, "pub const SCENE_NAME: &str = {scene:?};").unwrap();
    writeln!(config, "pub const SCENE: &str = include_str!({:?});", scene_path.display().to_string()).unwrap();
    writeln!(config, "pub const WIDTH: u32 = {w};").unwrap();
    writeln!(config, "pub const HEIGHT: u32 = {h};").unwrap();
    writeln!(config, "pub const ACCEL: octrace_core::AccelMode = octrace_core::AccelMode::{accel:?};").unwrap();
    writeln!(config, "pub const WIRE: crate::PanelColor = crate::PanelColor::{wire:?};").unwrap();
    writeln!(
        config,
        "pub const DITHERING: octrace_core::panel::Dithering = octrace_core::panel::Dithering::{dithering:?};"
    )
    .unwrap();
    writeln!(config, "pub const ERROR_WORDS: usize = {error_words};").unwrap();
    if !oled {
        // The guest writes this file; on the OLED board the runner does.
        writeln!(config, "pub const OUTPUT: &str = {:?};", format!("{output}\0")).unwrap();
        writeln!(config, "pub const OUTPUT_NAME: &str = {output:?};").unwrap();
    }
    // A light buffer in flash serves every light (and takes no RAM).
    let light_buffer = if techniques.light_buffer_in_flash { light_buffer_in_flash(&text) } else { Vec::new() };
    let mut counts = counts;
    if !light_buffer.is_empty() {
        counts.light_buffer_lights = counts.lights;
    }
    let doc = format!("Exactly what {scene} needs (about {bytes} bytes).");
    let profile = ProfileText {
        name: "Profile",
        doc: &doc,
        counts: &counts,
        octree: Some(&octree),
        named_walk,
        first_hits: techniques.first_hits,
        mirror_hits: techniques.mirror_hits,
        coherence: false,
        motion,
    };
    write!(config, "{profile}").unwrap();
    writeln!(config, "/// The scene's light buffer, built on the host (empty: none in flash).").unwrap();
    writeln!(config, "pub static LIGHT_BUFFER: [u32; {}] = {light_buffer:?};", light_buffer.len()).unwrap();
    // What the runner reads from the ELF: `key=value` lines.
    let run = format!("machine={}\noutput={output}\n", board.name);
    writeln!(config, "#[used]").unwrap();
    writeln!(config, "#[link_section = \".octrace_run\"]").unwrap();
    writeln!(config, "static RUN: [u8; {}] = {:?};", run.len(), run.as_bytes()).unwrap();
    std::fs::write(out.join("config.rs"), config).expect("write config.rs");
}

/// The words of the scene's light buffer for flash: the finest cube up to
/// 64 cells a face side that takes at most `LIGHT_BUFFER_FLASH` bytes.
fn light_buffer_in_flash(text: &str) -> Vec<u32> {
    const LIGHT_BUFFER_FLASH: usize = 48 * 1024;
    let mut cells = 64;
    loop {
        let words = light_buffer_words(text, cells, &mut |_| {}).unwrap_or_default();
        if words.len() * 4 <= LIGHT_BUFFER_FLASH || cells == 1 {
            return words;
        }
        cells /= 2;
    }
}

/// What the scene needs of each capacity with the board's octree; a scene
/// with errors needs what it counts, and the board then reports its errors.
fn needs(text: &str, accel: AccelMode, config: &OctreeConfig, light_cells: u32) -> Counts {
    needed_with_light_buffer(text, accel, config, light_cells, &mut |_| {}).unwrap_or_else(|_| count(text))
}

/// The micro:bit's RAM, which its stack and its statics share.
const MICROBIT_RAM: usize = 16 * 1024;

/// The micro:bit's stack for a build drawing in `wire` a scene whose rays
/// go `rdepth` reflections and refractions deep: what the deepest scene
/// the tests draw of its kind needs, painted and measured (`peak stack`).
/// RGB with RDEPTH 4 at most: 7 KiB (fig5_5 at 160×128, RDEPTH 4 with
/// first hits: 7,080 bytes, 2026-12-03). Deeper rays (glass, RDEPTH 5:
/// 7,280 bytes), a panel of few levels or the 256-colour palette (their
/// dithering's frames and error row; fig5_5 in one bit at 64×48: 7,536
/// bytes): 7.5 KiB. The statics have the rest (fig5_3's 200 spheres leave
/// no room to raise either). The margins are thin, so the firmware test
/// holds each case's peak stack to a budget (`budgets.toml`); an overflow
/// runs off the start of RAM and faults (`memory-microbit.x`).
fn microbit_stack(wire: PanelColor, rdepth: u32) -> usize {
    match wire {
        PanelColor::Rgb888 | PanelColor::Rgb565 if rdepth <= 4 => 7 * 1024,
        _ => 7 * 1024 + 512,
    }
}

/// The scene's RDEPTH (the deepest its stack goes; a scene with errors
/// the deepest there is, and the board then reports its errors) and
/// whether it has a mirror (`SceneView::has_mirror`).
fn surveyed(text: &str) -> (u32, bool) {
    let mut scene = Box::new(Scene::<Host>::new());
    match parse(text, &mut scene, &mut |_| {}) {
        Ok(_) => (scene.view().settings.rdepth, scene.view().has_mirror()),
        Err(_) => (u32::MAX, false),
    }
}

/// What a board may spend memory on beyond the scene to render faster
/// (the same image): the camera rays' screen lists (and the mirror's), the
/// octree's shadow shafts and the shadow rays' light buffer, in RAM or
/// (built here) in flash.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
struct Techniques {
    first_hits: bool,
    mirror_hits: bool,
    shadow_shafts: bool,
    /// Cells a face side of the light buffer's cubes in RAM (0: none there).
    light_buffer: u32,
    /// Whether the light buffer is built here and kept in flash.
    light_buffer_in_flash: bool,
}

impl Techniques {
    const NONE: Techniques = Techniques {
        first_hits: false,
        mirror_hits: false,
        shadow_shafts: false,
        light_buffer: 0,
        light_buffer_in_flash: false,
    };
    const NAMES: [&str; 5] = ["first-hits", "shadow-shafts", "light-buffer", "light-buffer-ram", "mirror-hits"];
    /// The light buffer's cubes tried in RAM, finest first.
    const LIGHT_CELLS: [u32; 6] = [32, 16, 8, 4, 2, 1];

    /// `auto` (the screen lists, the mirror's and the shafts where they
    /// fit, the light buffer in flash), `none`, or a comma list of names.
    fn from_names(names: &str) -> Option<Techniques> {
        match names {
            "auto" => {
                return Some(Techniques {
                    first_hits: true,
                    mirror_hits: true,
                    shadow_shafts: true,
                    light_buffer_in_flash: true,
                    ..Techniques::NONE
                })
            }
            "none" => return Some(Techniques::NONE),
            _ => {}
        }
        let mut wanted = Techniques::NONE;
        for name in names.split(',') {
            match Techniques::NAMES.iter().position(|n| *n == name.trim())? {
                0 => wanted.first_hits = true,
                1 => wanted.shadow_shafts = true,
                2 => wanted.light_buffer_in_flash = true,
                3 => wanted.light_buffer = Techniques::LIGHT_CELLS[0],
                _ => wanted.mirror_hits = true,
            }
        }
        Some(wanted)
    }

    /// The techniques in RAM among these, and their subsets, the most
    /// helpful first: the screen lists spare every camera ray its walk, a
    /// light buffer most shadow rays most of their tests (the finer its
    /// cubes the more), the shafts only the shadow rays that see their
    /// light.
    fn subsets(self) -> impl Iterator<Item = Techniques> {
        let light_cells = Techniques::LIGHT_CELLS.into_iter().chain([0]);
        // The mirror's lists only beside the camera's.
        let lists = [(true, true), (true, false), (false, false)];
        lists
            .into_iter()
            .flat_map(|lists| [true, false].map(move |shafts| (lists, shafts)))
            .flat_map(move |both| light_cells.clone().map(move |cells| (both, cells)))
            .map(move |(((first_hits, mirror_hits), shadow_shafts), light_buffer)| Techniques {
                first_hits,
                mirror_hits,
                shadow_shafts,
                light_buffer,
                light_buffer_in_flash: self.light_buffer_in_flash,
            })
            .filter(move |t| {
                (self.first_hits || !t.first_hits)
                    && (self.mirror_hits || !t.mirror_hits)
                    && (self.shadow_shafts || !t.shadow_shafts)
                    && t.light_buffer <= self.light_buffer
            })
    }
}
