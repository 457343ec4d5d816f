//! Chooses the board, scene, size, mode and pixel format from the
//! environment, at build time:
//!
//! | variable | values | default |
//! | --- | --- | --- |
//! | `OCTRACE_BOARD` | `microbit` (thumbv6m), `mps2-an385` or `lm3s6965evb` (thumbv7m) | from the target: thumbv6m `microbit`, thumbv7m `mps2-an385` |
//! | `OCTRACE_SCENE` | a scene in `scenes/` (name without `.txt`) | `fig5_1` |
//! | `OCTRACE_SIZE` | `WxH` (at most the panel's 128x64 on `lm3s6965evb`) | `160x128`; `128x64` on `lm3s6965evb` |
//! | `OCTRACE_ACCEL` | `auto`, `naive`, `octree`, `dda` | `auto` |
//! | `OCTRACE_COLOR` | `rgb888`, `rgb565`, `dither` (1-byte indices into the 6×6×6 cube), `gray4` (1 byte a pixel, the level 0 to 15); only `gray4` on `lm3s6965evb` | `rgb888`; `gray4` on `lm3s6965evb` |
//! | `OCTRACE_OUT` | host file the pixels are written to; on `lm3s6965evb` the PNG of the panel's screen that the runner grabs | `octrace-out.raw`; `screen.png` on `lm3s6965evb` |
//!
//! | board | qemu `-machine` | core | flash | RAM | display |
//! | --- | --- | --- | --- | --- | --- |
//! | `microbit` | `microbit` | Cortex-M0 | 256 KiB | 16 KiB | semihosting file |
//! | `mps2-an385` | `mps2-an385` | Cortex-M3 | 4 MiB | 4 MiB | semihosting file |
//! | `lm3s6965evb` | `lm3s6965evb` | Cortex-M3 | 256 KiB | 64 KiB | 128×64 16-gray OLED (SSD0323 on SSI0) |
//!
//! The runner (`run.sh`) learns the machine and the output from the ELF
//! itself: this script puts them in the non-loaded section `.octrace_run`
//! (see `memory-*.x`), so an ELF always runs on the board it was built for.

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
    let default_board = match target.as_str() {
        "thumbv6m-none-eabi" => "microbit",
        "thumbv7m-none-eabi" => "mps2-an385",
        other => fail(format!("no board for target {other}: use thumbv6m-none-eabi or thumbv7m-none-eabi")),
    };
    let board = var("OCTRACE_BOARD", default_board);
    let board = match (board.as_str(), target.as_str()) {
        ("microbit", "thumbv6m-none-eabi") => "microbit",
        ("mps2-an385", "thumbv7m-none-eabi") => "mps2-an385",
        ("lm3s6965evb", "thumbv7m-none-eabi") => "lm3s6965evb",
        ("microbit", _) => fail(format!("OCTRACE_BOARD=microbit needs --target thumbv6m-none-eabi, not {target}")),
        ("mps2-an385" | "lm3s6965evb", _) => {
            fail(format!("OCTRACE_BOARD={board} needs --target thumbv7m-none-eabi, not {target}"))
        }
        (other, _) => fail(format!("OCTRACE_BOARD={other}: expected microbit, mps2-an385 or lm3s6965evb")),
    };
    let oled = board == "lm3s6965evb";
    let memory = manifest.join(format!("memory-{board}.x"));
    std::fs::copy(&memory, out.join("memory.x")).expect("copy memory.x");
    println!("cargo:rustc-link-search={}", out.display());
    println!("cargo:rerun-if-changed={}", memory.display());
    println!("cargo:rustc-check-cfg=cfg(board, values(\"microbit\", \"mps2-an385\", \"lm3s6965evb\"))");
    println!("cargo:rustc-cfg=board=\"{board}\"");

    let scene = var("OCTRACE_SCENE", "fig5_1");
    let scene_path = manifest.join("../scenes").join(format!("{scene}.txt"));
    if !scene_path.is_file() {
        fail(format!("OCTRACE_SCENE={scene}: no file {}", scene_path.display()));
    }
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
    let accel = match var("OCTRACE_ACCEL", "auto").as_str() {
        "auto" => "Auto",
        "naive" => "Naive",
        "octree" => "Octree",
        "dda" => "Dda",
        other => fail(format!("OCTRACE_ACCEL={other}: expected auto, naive, octree or dda")),
    };
    let wire = match var("OCTRACE_COLOR", if oled { "gray4" } else { "rgb888" }).as_str() {
        "gray4" => "Gray4",
        other if oled => fail(format!("OCTRACE_COLOR={other}: the lm3s6965evb's OLED shows 16 grays: use gray4")),
        "rgb888" => "Rgb888",
        "rgb565" => "Rgb565",
        "dither" => "Dither",
        other => fail(format!("OCTRACE_COLOR={other}: expected rgb888, rgb565, dither or gray4")),
    };
    let output = var("OCTRACE_OUT", if oled { "screen.png" } else { "octrace-out.raw" });
    if output.contains(['\0', '\n']) {
        fail("OCTRACE_OUT: a path without NUL or newline".to_owned());
    }

    let mut config = String::new();
    writeln!(config, "pub const BOARD: &str = {board:?};").unwrap();
    writeln!(config, "pub const SCENE_NAME: &str = {scene:?};").unwrap();
    writeln!(config, "pub const SCENE: &str = include_str!({:?});", scene_path.display().to_string()).unwrap();
    writeln!(config, "pub const WIDTH: u32 = {w};").unwrap();
    writeln!(config, "pub const HEIGHT: u32 = {h};").unwrap();
    writeln!(config, "pub const ACCEL: crate::Accel = crate::Accel::{accel};").unwrap();
    writeln!(config, "pub const WIRE: crate::Wire = crate::Wire::{wire};").unwrap();
    if !oled {
        // The guest writes this file; on the OLED board the runner does.
        writeln!(config, "pub const OUTPUT: &str = {:?};", format!("{output}\0")).unwrap();
    }
    // What the runner reads from the ELF: `key=value` lines.
    let run = format!("machine={board}\noutput={output}\n");
    writeln!(config, "#[used]").unwrap();
    writeln!(config, "#[link_section = \".octrace_run\"]").unwrap();
    writeln!(config, "static RUN: [u8; {}] = {:?};", run.len(), run.as_bytes()).unwrap();
    std::fs::write(out.join("config.rs"), config).expect("write config.rs");
}
