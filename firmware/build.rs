//! Chooses the board from the target and the scene, size, mode and pixel
//! format from the environment, at build time:
//!
//! | variable | values | default |
//! | --- | --- | --- |
//! | `OCTRACE_SCENE` | a scene in `scenes/` (name without `.txt`) | `fig5_1` |
//! | `OCTRACE_SIZE` | `WxH` | `160x128` |
//! | `OCTRACE_ACCEL` | `auto`, `naive`, `octree`, `dda` | `auto` |
//! | `OCTRACE_COLOR` | `rgb888`, `rgb565`, `dither` (1-byte indices into the 6×6×6 cube) | `rgb888` |
//! | `OCTRACE_OUT` | host file the pixels are written to | `octrace-out.raw` |

use std::env;
use std::fmt::Write as _;
use std::path::PathBuf;

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
    let board = match target.as_str() {
        "thumbv6m-none-eabi" => "microbit",
        "thumbv7m-none-eabi" => "mps2-an385",
        other => fail(format!("no board for target {other}: use thumbv6m-none-eabi or thumbv7m-none-eabi")),
    };
    let memory = manifest.join(format!("memory-{board}.x"));
    std::fs::copy(&memory, out.join("memory.x")).expect("copy memory.x");
    println!("cargo:rustc-link-search={}", out.display());
    println!("cargo:rerun-if-changed={}", memory.display());
    println!("cargo:rustc-check-cfg=cfg(board, values(\"microbit\", \"mps2-an385\"))");
    println!("cargo:rustc-cfg=board=\"{board}\"");

    let scene = var("OCTRACE_SCENE", "fig5_1");
    let scene_path = manifest.join("../scenes").join(format!("{scene}.txt"));
    if !scene_path.is_file() {
        fail(format!("OCTRACE_SCENE={scene}: no file {}", scene_path.display()));
    }
    println!("cargo:rerun-if-changed={}", scene_path.display());
    let size = var("OCTRACE_SIZE", "160x128");
    let (w, h) = size
        .split_once('x')
        .and_then(|(w, h)| Some((w.parse::<u32>().ok()?, h.parse::<u32>().ok()?)))
        .filter(|&(w, h)| (1..=16384).contains(&w) && (1..=16384).contains(&h))
        .unwrap_or_else(|| fail(format!("OCTRACE_SIZE={size}: expected WxH, 1 to 16384 each")));
    let accel = match var("OCTRACE_ACCEL", "auto").as_str() {
        "auto" => "Auto",
        "naive" => "Naive",
        "octree" => "Octree",
        "dda" => "Dda",
        other => fail(format!("OCTRACE_ACCEL={other}: expected auto, naive, octree or dda")),
    };
    let wire = match var("OCTRACE_COLOR", "rgb888").as_str() {
        "rgb888" => "Rgb888",
        "rgb565" => "Rgb565",
        "dither" => "Dither",
        other => fail(format!("OCTRACE_COLOR={other}: expected rgb888, rgb565 or dither")),
    };
    let output = var("OCTRACE_OUT", "octrace-out.raw");

    let mut config = String::new();
    writeln!(config, "pub const BOARD: &str = {board:?};").unwrap();
    writeln!(config, "pub const SCENE_NAME: &str = {scene:?};").unwrap();
    writeln!(config, "pub const SCENE: &str = include_str!({:?});", scene_path.display().to_string()).unwrap();
    writeln!(config, "pub const WIDTH: u32 = {w};").unwrap();
    writeln!(config, "pub const HEIGHT: u32 = {h};").unwrap();
    writeln!(config, "pub const ACCEL: crate::Accel = crate::Accel::{accel};").unwrap();
    writeln!(config, "pub const WIRE: crate::Wire = crate::Wire::{wire};").unwrap();
    writeln!(config, "pub const OUTPUT: &str = {:?};", format!("{output}\0")).unwrap();
    std::fs::write(out.join("config.rs"), config).expect("write config.rs");
}
