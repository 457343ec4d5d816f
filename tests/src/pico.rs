//! Building the Raspberry Pi Pico template (`examples/pico-st7789`) for a
//! scene, as its user does (`OCTRACE_SCENE`, and `OCTRACE_CODE_IN` and
//! `OCTRACE_ORDER` to measure the other ways, at build time), and running
//! its ELF on the emulated Pico (`emulator/`), for the
//! bit-exactness tests and the Pico benchmark.
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

/// Where the template's code runs when `OCTRACE_CODE_IN` is not set.
pub const DEFAULT_CODE_IN: &str = "parse-and-render";

/// How the embedded-scene firmware is built: its scene, where its code runs
/// (`OCTRACE_CODE_IN`) and its pixel order (`OCTRACE_ORDER`). The default is
/// the template as a user builds it.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Build<'a> {
    pub scene: &'a str,
    /// `parse-and-render` (the default), `render`, `sram` or `flash`.
    pub code_in: &'a str,
    /// `rows` (the default) or `progressive`.
    pub order: &'a str,
}

impl<'a> Build<'a> {
    /// The template as a user builds it, with `scenes/SCENE.txt`.
    pub fn of(scene: &'a str) -> Build<'a> {
        Build { scene, code_in: DEFAULT_CODE_IN, order: "rows" }
    }

    /// What the build is named by: the scene, and what differs from the
    /// default.
    pub fn name(&self) -> String {
        let mut name = self.scene.to_owned();
        for (value, default) in [(self.code_in, DEFAULT_CODE_IN), (self.order, "rows")] {
            if value != default {
                name = format!("{name}-{value}");
            }
        }
        name
    }
}

/// Builds the template (release) as `build` says and returns its
/// embedded-scene ELF. The default build is made as a user makes it,
/// without any variable (and so as `scripts/test-all` built it already).
pub fn build(build: &Build<'_>) -> Result<PathBuf, String> {
    let dir = target_dir();
    let mut cargo = Command::new(std::env::var_os("CARGO").unwrap_or_else(|| "cargo".into()));
    // The template's .cargo/config.toml (target, linker script) is found
    // from the working directory.
    cargo.current_dir(template());
    cargo.args(["build", "--release", "--quiet"]).arg("--target-dir").arg(&dir);
    for var in [
        "CARGO_TARGET_DIR",
        "RUSTFLAGS",
        "CARGO_ENCODED_RUSTFLAGS",
        "CARGO_BUILD_TARGET",
        "OCTRACE_SCENE",
        "OCTRACE_CODE_IN",
        "OCTRACE_ORDER",
    ] {
        cargo.env_remove(var);
    }
    if build.scene != DEFAULT_SCENE {
        cargo.env("OCTRACE_SCENE", repo().join("scenes").join(format!("{}.txt", build.scene)));
    }
    if build.code_in != DEFAULT_CODE_IN {
        cargo.env("OCTRACE_CODE_IN", build.code_in);
    }
    if build.order != "rows" {
        cargo.env("OCTRACE_ORDER", build.order);
    }
    let out = cargo.output().map_err(|e| format!("cannot run cargo: {e}"))?;
    if !out.status.success() {
        return Err(format!(
            "the Pico template ({}) did not build:\n{}",
            build.name(),
            String::from_utf8_lossy(&out.stderr)
        ));
    }
    let elf = dir.join(format!("{}.elf", build.name()));
    std::fs::copy(dir.join("thumbv6m-none-eabi/release/octrace-pico-st7789"), &elf)
        .map_err(|e| format!("cannot copy the ELF to {}: {e}", elf.display()))?;
    Ok(elf)
}

/// The bytes of code `elf` copies into SRAM at boot (its `.sram_code`
/// section; 0 when its code runs from flash).
pub fn sram_code_bytes(elf: &Path) -> Result<u64, String> {
    let out = Command::new("arm-none-eabi-size")
        .arg("-A")
        .arg(elf)
        .output()
        .map_err(|e| format!("cannot run arm-none-eabi-size: {e}"))?;
    let sections = String::from_utf8_lossy(&out.stdout);
    Ok(sections
        .lines()
        .find_map(|l| l.strip_prefix(".sram_code ")?.split_whitespace().next()?.parse().ok())
        .unwrap_or(0))
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
    /// From the picture's first command until every pixel of the panel has
    /// been written once: the whole panel coarse, in a progressive order.
    pub first_full_panel: u64,
    /// The whole run, until both cores sleep.
    pub total: u64,
    /// How many cores ran the firmware.
    pub cores: u64,
    /// Each core's cycles: busy (of them stalled on a flash cache miss, and
    /// on the other core at the bus fabric) and waiting (asleep).
    pub busy: [u64; 2],
    pub stalled: [u64; 2],
    pub bus_stalled: [u64; 2],
    pub waiting: [u64; 2],
    /// Accesses to the striped SRAM banks (SRAM0 to SRAM3) that waited for
    /// the other core (BUSCTRL's contested events, summed).
    pub striped_contested: u64,
    /// The XIP cache: flash reads, misses.
    pub flash_reads: u64,
    pub cache_misses: u64,
}

impl Cycles {
    /// From the scene text to the last pixel, in seconds at 125 MHz.
    pub fn to_picture_seconds(&self) -> f64 {
        (self.parse_and_index + self.render) as f64 / CLOCK_HZ
    }
}

/// Whether the emulated Pico's two cores wait for each other on the bus
/// fabric (as on the chip), or each goes at full speed (what the contention
/// costs).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Contention {
    On,
    Off,
}

/// Runs `elf` on the emulated Pico, its cores contending for the bus as on
/// the chip; the panel's picture goes to `png`.
pub fn run(elf: &Path, png: &Path) -> Result<Cycles, String> {
    run_with(elf, png, Contention::On)
}

/// Runs `elf` on the emulated Pico with or without the bus's contention.
pub fn run_with(elf: &Path, png: &Path, contention: Contention) -> Result<Cycles, String> {
    let emulator = repo().join("emulator");
    if !emulator.join("node_modules/rp2040js").is_dir() {
        return Err(format!("the emulator is not installed: run `npm ci` in {}", emulator.display()));
    }
    let out = Command::new("node")
        .arg(emulator.join("run.mjs"))
        .arg(elf)
        .arg("--out")
        .arg(png)
        .arg("--json")
        .arg("--contention")
        .arg(if contention == Contention::On { "on" } else { "off" })
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
    let number = |value: &serde_json::Value, what: &str| {
        value.as_u64().ok_or_else(|| format!("the emulator's report has no {what}: {report}"))
    };
    let phase = |key: &str| number(&report["cycles"][key], key);
    let core = |k: usize, key: &str| number(&report["coreCycles"][k][key], key);
    let ports = &report["busFabric"]["ports"];
    let striped_contested =
        ["sram0", "sram1", "sram2", "sram3"].iter().map(|bank| ports[bank]["contested"].as_u64().unwrap_or(0)).sum();
    Ok(Cycles {
        start_up: phase("startUp")?,
        parse_and_index: phase("parseAndIndex")?,
        render: phase("render")?,
        first_full_panel: phase("firstFullPanel")?,
        total: phase("total")?,
        cores: number(&report["cores"], "cores")?,
        busy: [core(0, "busy")?, core(1, "busy")?],
        stalled: [core(0, "flashStall")?, core(1, "flashStall")?],
        bus_stalled: [core(0, "busStall")?, core(1, "busStall")?],
        waiting: [core(0, "waiting")?, core(1, "waiting")?],
        striped_contested,
        flash_reads: number(&report["xipCache"]["accesses"], "accesses")?,
        cache_misses: number(&report["xipCache"]["misses"], "misses")?,
    })
}
