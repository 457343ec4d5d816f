//! Building a Raspberry Pi Pico template (`examples/pico-st7789`,
//! `examples/pico-ssd1306`) for a scene, as its user does (`OCTRACE_SCENE`,
//! and `OCTRACE_CODE_IN` and the ST7789's `OCTRACE_ORDER` to measure the
//! other ways, at build time), and running its ELF on the emulated Pico
//! (`emulator/`), for the bit-exactness tests and the Pico benchmark.
//!
//! The ST7789 template's embedded-scene firmware answers on its USB serial
//! port with what it measured of its scene by its own TIMER and bus
//! counters ([`Report`]): [`ask_report`] reads it from a board's port,
//! [`run_reporting`] from the emulated Pico's beside the emulator's own
//! count.
//!
//! The templates' builds share one target directory (`target/pico/`, apart
//! from a developer's own, so their dependencies are built once): build one
//! scene at a time; each ELF is copied out under the template's and the
//! build's name, so runs may overlap.

use crate::{board_cargo, repo, scene_path};
use std::io::{BufRead, BufReader, Read, Write};
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::str::FromStr;
use std::time::{Duration, Instant};

/// A Pico template of the repository, and the panel it drives.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Template {
    /// `examples/pico-st7789`: a 240×240 ST7789 on SPI, RGB565.
    St7789,
    /// `examples/pico-ssd1306`: a 128×64 SSD1306 on I2C, one bit.
    Ssd1306,
}

impl Template {
    /// Every template, the ST7789 first.
    pub const ALL: [Template; 2] = [Template::St7789, Template::Ssd1306];

    /// Its folder in `examples/`.
    pub fn name(self) -> &'static str {
        match self {
            Template::St7789 => "pico-st7789",
            Template::Ssd1306 => "pico-ssd1306",
        }
    }

    /// Its embedded-scene firmware.
    fn binary(self) -> &'static str {
        match self {
            Template::St7789 => "octrace-pico-st7789",
            Template::Ssd1306 => "octrace-pico-ssd1306",
        }
    }

    /// The panel's size and host-sim's preview of its colours
    /// (`--size`, `--color`).
    pub fn panel(self) -> (&'static str, &'static str) {
        match self {
            Template::St7789 => ("240x240", "rgb565"),
            Template::Ssd1306 => ("128x64", "mono"),
        }
    }

    fn dir(self) -> PathBuf {
        repo().join("examples").join(self.name())
    }
}

/// Where the templates are built.
fn target_dir() -> PathBuf {
    repo().join("target/pico")
}

/// The RP2040's Rust target, which the templates' .cargo/config.toml set.
const TARGET: &str = "thumbv6m-none-eabi";

/// The scene the template embeds when `OCTRACE_SCENE` is not set.
const DEFAULT_SCENE: &str = "fig5_1";

/// Where the template's code runs when `OCTRACE_CODE_IN` is not set.
pub const DEFAULT_CODE_IN: &str = "parse-and-render";

/// How a template's embedded-scene firmware is built: its scene, where its
/// code runs (`OCTRACE_CODE_IN`) and its pixel order (`OCTRACE_ORDER`, the
/// ST7789's). The default is the template as a user builds it.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Build<'a> {
    pub template: Template,
    pub scene: &'a str,
    /// `parse-and-render` (the default), `render`, `sram` or `flash`.
    pub code_in: &'a str,
    /// `rows` (the default) or `progressive`.
    pub order: &'a str,
}

impl<'a> Build<'a> {
    /// `template` as a user builds it, with `scenes/SCENE.txt`.
    pub const fn of(template: Template, scene: &'a str) -> Build<'a> {
        Build { template, scene, code_in: DEFAULT_CODE_IN, order: "rows" }
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
/// without any `OCTRACE_` variable, and with the checkout's path remapped
/// as all board builds ([`board_cargo`]): so `scripts/test-all` built it
/// already.
pub fn build(build: &Build<'_>) -> Result<PathBuf, String> {
    let template = build.template;
    if template == Template::Ssd1306 && build.order != "rows" {
        return Err(format!("{}: the SSD1306 template draws rows only, not {}", build.name(), build.order));
    }
    let dir = target_dir();
    let mut cargo = board_cargo(&template.dir(), TARGET)?;
    // Only the embedded-scene binary: the ST7789's live firmware embeds no
    // scene, and rebuilding it for each scene would cost a whole-program
    // build and replace the ELF the live board's cases may be starting.
    cargo.args(["build", "--release", "--quiet", "--bin", template.binary()]).arg("--target-dir").arg(&dir);
    for var in ["OCTRACE_SCENE", "OCTRACE_CODE_IN", "OCTRACE_ORDER"] {
        cargo.env_remove(var);
    }
    if build.scene != DEFAULT_SCENE {
        cargo.env("OCTRACE_SCENE", scene_path(build.scene));
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
            "the Pico template {} ({}) did not build:\n{}",
            template.name(),
            build.name(),
            String::from_utf8_lossy(&out.stderr)
        ));
    }
    let elf = dir.join(format!("{}-{}.elf", template.name(), build.name()));
    std::fs::copy(dir.join(TARGET).join("release").join(template.binary()), &elf)
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

/// What one run on the emulated Pico took, in its cycles of the system
/// clock the firmware set.
#[derive(Clone, Copy, Debug)]
pub struct Cycles {
    /// The system clock the firmware set (the emulator's `clockHz`), in Hz.
    pub clock_hz: f64,
    /// Clocks, the panel's set-up and clear: up to the ST7789's backlight,
    /// or the end of the SSD1306's clearing transfer.
    pub start_up: u64,
    /// The same in seconds: its first part (the boot ROM, boot2, the copy
    /// into SRAM, the clocks' set-up) runs before the firmware's clock.
    pub start_up_seconds: f64,
    /// Parsing and indexing the scene, up to the picture's first row (the
    /// ST7789) or the LED lit (the SSD1306).
    pub parse_and_index: u64,
    /// Tracing the picture into the panel (the SSD1306: into its buffer,
    /// while the LED is lit).
    pub render: u64,
    /// The SSD1306's picture sent over I2C, after the render (none for the
    /// ST7789, which takes its rows as they are traced).
    pub transfer: Option<u64>,
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
    /// From the scene text to the last pixel on the panel.
    pub fn to_picture_cycles(&self) -> u64 {
        self.parse_and_index + self.render + self.transfer.unwrap_or(0)
    }

    /// From the scene text to the last pixel on the panel, in seconds at
    /// the clock the firmware set.
    pub fn to_picture_seconds(&self) -> f64 {
        self.seconds(self.to_picture_cycles())
    }

    /// `cycles` in seconds at the clock the firmware set.
    pub fn seconds(&self, cycles: u64) -> f64 {
        cycles as f64 / self.clock_hz
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
    let on = if contention == Contention::On { "on" } else { "off" };
    cycles_of(&emulate(elf, png, &["--contention", on])?)
}

/// `node emulator/run.mjs ELF`, once the emulator is installed.
fn emulator(elf: &Path) -> Result<Command, String> {
    let emulator = repo().join("emulator");
    if !emulator.join("node_modules/rp2040js").is_dir() {
        return Err(format!("the emulator is not installed: run `npm ci` in {}", emulator.display()));
    }
    let mut command = Command::new("node");
    command.arg(emulator.join("run.mjs")).arg(elf);
    Ok(command)
}

/// The cycles in the emulator's JSON report.
fn cycles_of(report: &serde_json::Value) -> Result<Cycles, String> {
    let number = |value: &serde_json::Value, what: &str| {
        value.as_u64().ok_or_else(|| format!("the emulator's report has no {what}: {report}"))
    };
    let phase = |key: &str| number(&report["cycles"][key], key);
    let core = |k: usize, key: &str| number(&report["coreCycles"][k][key], key);
    let clock_hz = report["clockHz"]
        .as_f64()
        .filter(|hz| *hz > 0.0)
        .ok_or_else(|| format!("the emulator's report has no clockHz: {report}"))?;
    let ports = &report["busFabric"]["ports"];
    let striped_contested =
        ["sram0", "sram1", "sram2", "sram3"].iter().map(|bank| ports[bank]["contested"].as_u64().unwrap_or(0)).sum();
    Ok(Cycles {
        clock_hz,
        start_up: phase("startUp")?,
        start_up_seconds: report["seconds"]["startUp"]
            .as_f64()
            .ok_or_else(|| format!("the emulator's report has no startUp seconds: {report}"))?,
        parse_and_index: phase("parseAndIndex")?,
        render: phase("render")?,
        transfer: report["cycles"].get("transfer").map(|t| number(t, "transfer")).transpose()?,
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

/// One frame of an animation drawn on the emulated Pico (`run.mjs
/// --frames`), in its cycles.
#[derive(Clone, Debug)]
pub struct FrameCycles {
    /// From the end of the frame before (the first: from its start) to
    /// this one whole on the panel.
    pub cycles: u64,
    /// The same in seconds, at the clock the firmware set.
    pub seconds: f64,
    /// While the board's LED was lit: the frame's work, without waiting
    /// for its time.
    pub lit: u64,
    /// Each core's cycles not asleep in the frame.
    pub busy: [u64; 2],
    /// The panel's picture then.
    pub picture: PathBuf,
}

/// Runs `elf`, a firmware that plays an animation, on the emulated Pico
/// until it has drawn `count` frames, each written to `pattern` (one `%d`
/// or `%0Nd`) with its number in the order drawn.
pub fn run_frames(elf: &Path, pattern: &Path, count: u32) -> Result<Vec<FrameCycles>, String> {
    let report = emulate(elf, pattern, &["--frames", &count.to_string()])?;
    let frames = report["frames"].as_array().ok_or_else(|| format!("the emulator's report has no frames: {report}"))?;
    frames
        .iter()
        .map(|frame| {
            let number = |value: &serde_json::Value| {
                value.as_u64().ok_or_else(|| format!("the emulator's report has a frame without its cycles: {frame}"))
            };
            Ok(FrameCycles {
                cycles: number(&frame["cycles"])?,
                seconds: frame["seconds"]
                    .as_f64()
                    .ok_or_else(|| format!("the emulator's report has a frame without its seconds: {frame}"))?,
                lit: number(&frame["lit"])?,
                busy: [number(&frame["busy"][0])?, number(&frame["busy"][1])?],
                picture: frame["out"]
                    .as_str()
                    .map(PathBuf::from)
                    .ok_or_else(|| format!("a frame without its file: {frame}"))?,
            })
        })
        .collect()
}

/// Runs `elf` on the emulated Pico (`run.mjs ELF --out OUT --json` and
/// `more`) and returns its report.
fn emulate(elf: &Path, out: &Path, more: &[&str]) -> Result<serde_json::Value, String> {
    let output = emulator(elf)?
        .arg("--out")
        .arg(out)
        .arg("--json")
        .args(more)
        .output()
        .map_err(|e| format!("cannot run node: {e}"))?;
    if !output.status.success() {
        return Err(format!(
            "the emulated Pico ran {} with exit code {:?}:\n{}",
            elf.display(),
            output.status.code(),
            String::from_utf8_lossy(&output.stderr)
        ));
    }
    serde_json::from_slice(&output.stdout).map_err(|e| format!("the emulator's report is not JSON: {e}"))
}

/// What the embedded-scene firmware measured of its scene, as it answers on
/// its USB serial port (the template's `measure::Report`): the load (parse
/// and index) and the render (the renderers' set-up to the last row) in
/// microseconds by its TIMER, and each one's accesses to SRAM0 to SRAM3
/// that waited for the other core (BUSCTRL's counters).
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Report {
    /// The firmware's name and version.
    pub firmware: String,
    pub scene: String,
    pub load_us: u64,
    pub render_us: u64,
    pub load_contested: [u64; 4],
    pub render_contested: [u64; 4],
}

impl Report {
    /// From the scene text to the last pixel.
    pub fn to_picture_seconds(&self) -> f64 {
        (self.load_us + self.render_us) as f64 / 1e6
    }
}

impl FromStr for Report {
    type Err = String;

    /// `NAME VERSION scene=S load_us=N render_us=N load_contested=A,B,C,D render_contested=A,B,C,D`.
    fn from_str(line: &str) -> Result<Report, String> {
        let bad = || format!("not a report of the Pico template: {line:?}");
        let mut words = line.split_whitespace();
        let firmware = format!("{} {}", words.next().ok_or_else(bad)?, words.next().ok_or_else(bad)?);
        let fields: Vec<(&str, &str)> =
            words.map(|word| word.split_once('=').ok_or_else(bad)).collect::<Result<_, _>>()?;
        let field = |key: &str| fields.iter().find(|(k, _)| *k == key).map(|(_, v)| *v).ok_or_else(bad);
        let number = |key: &str| field(key)?.parse::<u64>().map_err(|_| bad());
        let banks = |key: &str| -> Result<[u64; 4], String> {
            let counts: Vec<u64> =
                field(key)?.split(',').map(|n| n.parse().map_err(|_| bad())).collect::<Result<_, _>>()?;
            counts.try_into().map_err(|_| bad())
        };
        Ok(Report {
            firmware,
            scene: field("scene")?.to_owned(),
            load_us: number("load_us")?,
            render_us: number("render_us")?,
            load_contested: banks("load_contested")?,
            render_contested: banks("render_contested")?,
        })
    }
}

/// Asks the board serving serial device `port` (a real Pico's USB port, or
/// the emulated Pico's pseudo-terminal) for its report: opens the port
/// once it exists, and sends a newline every second until the board
/// answers, then reads the whole line, for at most `timeout` (the board may
/// be drawing still).
pub fn ask_report(port: &Path, timeout: Duration) -> Result<Report, String> {
    let deadline = Instant::now() + timeout;
    let mut serial = loop {
        match serialport::new(port.to_string_lossy(), 115_200).timeout(Duration::from_millis(100)).open() {
            Ok(serial) => break serial,
            Err(_) if Instant::now() < deadline => std::thread::sleep(Duration::from_millis(200)),
            Err(e) => return Err(format!("cannot open {}: {e}", port.display())),
        }
    };
    let mut line = Vec::new();
    let mut asked = Instant::now() - Duration::from_secs(1);
    while Instant::now() < deadline {
        // Asked until it answers (the board may not have read the first ask).
        if line.is_empty() && asked.elapsed() >= Duration::from_secs(1) {
            serial.write_all(b"\n").map_err(|e| format!("writing to {}: {e}", port.display()))?;
            asked = Instant::now();
        }
        let mut chunk = [0u8; 256];
        match serial.read(&mut chunk) {
            Ok(n) => line.extend_from_slice(&chunk[..n]),
            Err(e) if e.kind() == std::io::ErrorKind::TimedOut => {}
            Err(e) => return Err(format!("reading {}: {e}", port.display())),
        }
        // A whole line, the last one the board sent (an answer may have been asked twice).
        if let Some(end) = line.iter().rposition(|&b| b == b'\n') {
            let text = String::from_utf8_lossy(&line[..end]);
            let last = text.lines().map(str::trim).rfind(|l| !l.is_empty()).unwrap_or("");
            return last.parse();
        }
    }
    Err(format!("{} sent no report within {} s", port.display(), timeout.as_secs()))
}

/// Runs `elf` (the embedded-scene firmware) on the emulated Pico serving
/// its USB port, asks the firmware for its report, and returns it with the
/// emulator's own count of the run; the panel's picture goes to `png`.
pub fn run_reporting(elf: &Path, png: &Path) -> Result<(Cycles, Report), String> {
    let mut child = emulator(elf)?
        .arg("--serial")
        .arg("--out")
        .arg(png)
        .arg("--json")
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .map_err(|e| format!("cannot run node: {e}"))?;
    let mut stdout = BufReader::new(child.stdout.take().ok_or("no standard output")?);
    let mut path = String::new();
    let asked = match stdout.read_line(&mut path) {
        Ok(n) if n > 0 => ask_report(Path::new(path.trim()), crate::HANG_GUARD),
        _ => Err("the emulated Pico named no serial device".to_owned()),
    };
    // Its standard input closed, the emulator ends and prints its own count.
    drop(child.stdin.take());
    let mut json = Vec::new();
    let read = stdout.read_to_end(&mut json);
    let out = child.wait_with_output().map_err(|e| format!("the emulator: {e}"))?;
    if !out.status.success() || read.is_err() {
        return Err(format!("the emulated Pico ran {}:\n{}", elf.display(), String::from_utf8_lossy(&out.stderr)));
    }
    let report = serde_json::from_slice(&json).map_err(|e| format!("the emulator's report is not JSON: {e}"))?;
    Ok((cycles_of(&report)?, asked?))
}
