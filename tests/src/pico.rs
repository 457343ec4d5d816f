//! Building the Raspberry Pi Pico template (`examples/pico-st7789`) for a
//! scene, as its user does (`OCTRACE_SCENE` at build time), and running its
//! ELF on the emulated Pico (`examples/pico-st7789/emulator`), for the
//! bit-exactness test and the Pico benchmark.
//!
//! The builds share one target directory (`target/pico-st7789/`, apart from
//! a developer's own): build one scene at a time; each ELF is copied out
//! under the scene's name, so runs may overlap.

use crate::repo;
use std::path::{Path, PathBuf};
use std::process::Command;

/// The emulated Pico's clock.
pub const CLOCK_HZ: f64 = 125e6;

fn template() -> PathBuf {
    repo().join("examples/pico-st7789")
}

fn target_dir() -> PathBuf {
    repo().join("target/pico-st7789")
}

/// The scene the template embeds when `OCTRACE_SCENE` is not set.
const DEFAULT_SCENE: &str = "fig5_1";

/// Builds the template (release) with `scenes/SCENE.txt` and returns its ELF.
/// The default scene is built as a user builds the template, without
/// `OCTRACE_SCENE` (and so as `scripts/test-all` built it already).
pub fn build(scene: &str) -> Result<PathBuf, String> {
    let dir = target_dir();
    let mut cargo = Command::new(std::env::var_os("CARGO").unwrap_or_else(|| "cargo".into()));
    // The template's .cargo/config.toml (target, linker script) is found
    // from the working directory.
    cargo.current_dir(template());
    cargo.args(["build", "--release", "--quiet"]).arg("--target-dir").arg(&dir);
    for var in ["CARGO_TARGET_DIR", "RUSTFLAGS", "CARGO_ENCODED_RUSTFLAGS", "CARGO_BUILD_TARGET", "OCTRACE_SCENE"] {
        cargo.env_remove(var);
    }
    if scene != DEFAULT_SCENE {
        cargo.env("OCTRACE_SCENE", repo().join("scenes").join(format!("{scene}.txt")));
    }
    let out = cargo.output().map_err(|e| format!("cannot run cargo: {e}"))?;
    if !out.status.success() {
        return Err(format!("the Pico template with {scene} did not build:\n{}", String::from_utf8_lossy(&out.stderr)));
    }
    let elf = dir.join(format!("{scene}.elf"));
    std::fs::copy(dir.join("thumbv6m-none-eabi/release/octrace-pico-st7789"), &elf)
        .map_err(|e| format!("cannot copy the ELF to {}: {e}", elf.display()))?;
    Ok(elf)
}

/// What one run on the emulated Pico took, in its cycles (125 MHz).
#[derive(Clone, Copy, Debug)]
pub struct Cycles {
    /// Clocks, the panel's set-up and clear, up to the backlight.
    pub start_up: u64,
    /// Parsing and indexing the scene, up to the picture's first row.
    pub parse_and_index: u64,
    /// Tracing the picture into the panel.
    pub render: u64,
    /// The whole run, until the core sleeps.
    pub total: u64,
}

impl Cycles {
    /// From the scene text to the last pixel, in seconds at 125 MHz.
    pub fn to_picture_seconds(&self) -> f64 {
        (self.parse_and_index + self.render) as f64 / CLOCK_HZ
    }
}

/// Runs `elf` on the emulated Pico; the panel's picture goes to `png`.
pub fn run(elf: &Path, png: &Path) -> Result<Cycles, String> {
    let emulator = template().join("emulator");
    if !emulator.join("node_modules/rp2040js").is_dir() {
        return Err(format!("the emulator is not installed: run `npm ci` in {}", emulator.display()));
    }
    let out = Command::new("node")
        .arg(emulator.join("run.mjs"))
        .arg(elf)
        .arg("--out")
        .arg(png)
        .arg("--json")
        .output()
        .map_err(|e| format!("cannot run node: {e}"))?;
    if !out.status.success() {
        return Err(format!(
            "the emulated Pico ran {} with exit code {:?}:\n{}",
            elf.display(),
            out.status.code(),
            String::from_utf8_lossy(&out.stderr)
        ));
    }
    let report: serde_json::Value =
        serde_json::from_slice(&out.stdout).map_err(|e| format!("the emulator's report is not JSON: {e}"))?;
    let cycles =
        |key: &str| report["cycles"][key].as_u64().ok_or_else(|| format!("the run has no {key} phase: {report}"));
    Ok(Cycles {
        start_up: cycles("startUp")?,
        parse_and_index: cycles("parseAndIndex")?,
        render: cycles("render")?,
        total: cycles("total")?,
    })
}
