//! Building and running the board firmware (`firmware/`) in qemu, for the
//! bit-exactness test and the firmware benchmark.
//!
//! Each build is configured by environment variables (see
//! `firmware/build.rs`) and goes to one target directory for every board,
//! `target/firmware/boards/`, apart from a developer's own builds: the
//! build script's host crates (the scene's parser among them) are built
//! once, not once a board. A build replaces the previous ELF of its
//! target: build one configuration at a time (each ELF is then kept under
//! its configuration's name, and runs while the next builds).

use crate::{board_cargo, repo, scene_path};
use octrace_core::panel::Dithering;
use octrace_core::render::PanelColor;
use octrace_images::formats::Image;
use octrace_images::palette::{self, PaletteMode};
use octrace_images::panel;
use std::path::{Path, PathBuf};
use std::process::Command;

/// An emulated board.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Board {
    /// BBC micro:bit: Cortex-M0, 16 KiB RAM, no FPU.
    Microbit,
    /// ARM MPS2-AN385: Cortex-M3.
    Mps2An385,
    /// ARM MPS2-AN505: Cortex-M33 (Armv8-M Mainline), in its Secure state.
    Mps2An505,
    /// ARM MPS2-AN521: two Cortex-M33s, both rendering.
    Mps2An521,
    /// qemu's RISC-V `virt` machine with one RV32IMC hart.
    Virt,
}

impl Board {
    /// Every board the firmware streams pixels from, in the benchmark's order.
    pub const ALL: [Board; 5] = [Board::Microbit, Board::Mps2An385, Board::Mps2An505, Board::Mps2An521, Board::Virt];

    /// qemu's `-machine`, the Rust target and the core.
    fn facts(self) -> (&'static str, &'static str, &'static str) {
        match self {
            Board::Microbit => ("microbit", "thumbv6m-none-eabi", "Cortex-M0"),
            Board::Mps2An385 => ("mps2-an385", "thumbv7m-none-eabi", "Cortex-M3"),
            Board::Mps2An505 => ("mps2-an505", "thumbv8m.main-none-eabihf", "Cortex-M33"),
            Board::Mps2An521 => ("mps2-an521", "thumbv8m.main-none-eabihf", "2 × Cortex-M33"),
            Board::Virt => ("virt", "riscv32imc-unknown-none-elf", "RV32IMC"),
        }
    }

    pub fn machine(self) -> &'static str {
        self.facts().0
    }

    pub fn target(self) -> &'static str {
        self.facts().1
    }

    pub fn core(self) -> &'static str {
        self.facts().2
    }
}

/// One firmware configuration.
#[derive(Clone, Debug)]
pub struct Firmware {
    pub board: Board,
    /// A scene in `scenes/`, without `.txt`.
    pub scene: String,
    pub width: u32,
    pub height: u32,
    pub wire: PanelColor,
    /// How a panel of few levels is dithered (`OCTRACE_DITHER`).
    pub dithering: Dithering,
}

/// What a run printed and wrote.
#[derive(Debug)]
pub struct Run {
    /// The guest's exit status.
    pub status: i32,
    /// Everything the guest printed.
    pub output: String,
    /// The pixels it sent to the display, as they arrived.
    pub pixels: Vec<u8>,
}

impl Run {
    /// The peak stack the firmware reports.
    pub fn peak_stack(&self) -> Option<u64> {
        peak_stack(&self.output)
    }
}

/// The peak stack a firmware's output reports (`peak stack: N bytes`).
fn peak_stack(output: &str) -> Option<u64> {
    output.lines().find_map(|l| l.strip_prefix("peak stack: ")?.strip_suffix(" bytes")?.parse().ok())
}

/// Where every firmware build of the tests goes.
fn boards_target_dir() -> PathBuf {
    repo().join("target/firmware/boards")
}

impl Firmware {
    pub fn new(board: Board, scene: &str, width: u32, height: u32, wire: PanelColor) -> Firmware {
        Firmware { board, scene: scene.to_owned(), width, height, wire, dithering: Dithering::default() }
    }

    /// The same, a panel of few levels dithered by `dithering`.
    pub fn dithered(self, dithering: Dithering) -> Firmware {
        Firmware { dithering, ..self }
    }

    /// What the build is named by: board, scene, size, colours (and the
    /// dithering of a panel of few levels).
    pub fn slug(&self) -> String {
        let (board, scene, wire) = (self.board.machine(), &self.scene, self.wire.name());
        match self.wire.panel() {
            Some(_) => format!("{board}-{scene}-{}x{}-{wire}-{}", self.width, self.height, self.dithering.name()),
            None => format!("{board}-{scene}-{}x{}-{wire}", self.width, self.height),
        }
    }

    /// Where the guest writes its pixels.
    fn output_file(&self) -> PathBuf {
        boards_target_dir().join(format!("{}.raw", self.slug()))
    }

    /// Builds the firmware (release) and returns the ELF, kept under the
    /// build's name: the next build (which may write the same file) can
    /// then go on while qemu runs this one.
    pub fn build(&self) -> Result<PathBuf, String> {
        let dir = boards_target_dir();
        let mut cargo = board_cargo(&repo().join("firmware"), self.board.target())?;
        cargo.args(["build", "--release", "--quiet", "--target", self.board.target()]);
        cargo.arg("--target-dir").arg(&dir);
        cargo.env("OCTRACE_BOARD", self.board.machine());
        cargo.env("OCTRACE_SCENE", &self.scene);
        cargo.env("OCTRACE_SIZE", format!("{}x{}", self.width, self.height));
        cargo.env("OCTRACE_COLOR", self.wire.name());
        cargo.env("OCTRACE_DITHER", self.dithering.name());
        cargo.env("OCTRACE_OUT", self.output_file());
        let out = cargo.output().map_err(|e| format!("cannot run cargo: {e}"))?;
        if !out.status.success() {
            return Err(format!("firmware build {} failed:\n{}", self.slug(), String::from_utf8_lossy(&out.stderr)));
        }
        let built = dir.join(self.board.target()).join("release/octrace-firmware");
        let kept = dir.join(format!("{}.elf", self.slug()));
        std::fs::copy(&built, &kept).map_err(|e| format!("{} -> {}: {e}", built.display(), kept.display()))?;
        Ok(kept)
    }

    /// Runs the ELF in qemu (through the firmware's runner script, which
    /// has the timeout) and collects what the display received.
    pub fn run(&self, elf: &Path) -> Result<Run, String> {
        let file = self.output_file();
        let _ = std::fs::remove_file(&file);
        let out = Command::new("bash")
            .arg(repo().join("firmware/run.sh"))
            .arg(elf)
            .output()
            .map_err(|e| format!("cannot run qemu: {e}"))?;
        let output = String::from_utf8_lossy(&out.stdout).into_owned() + &String::from_utf8_lossy(&out.stderr);
        let pixels = std::fs::read(&file).unwrap_or_default();
        Ok(Run { status: out.status.code().unwrap_or(-1), output, pixels })
    }

    /// What host-sim renders for the same scene and size, in the wire
    /// format.
    pub fn expected_pixels(&self) -> Result<Vec<u8>, String> {
        let mut scene = host_sim::new_scene();
        let path = scene_path(&self.scene);
        host_sim::load_file(&path, &mut scene).map_err(|e| e.to_string())?;
        let options = host_sim::RenderOptions { size: Some((self.width, self.height)), ..Default::default() };
        let rendered = host_sim::render(&mut scene, &options).map_err(|e| format!("{e:?}"))?;
        let image = rendered.image;
        Ok(match (self.wire, self.wire.panel()) {
            // host-sim's panel previews and dither: their indices are the wire's.
            (_, Some(shown)) => indices(panel::dithered(&image, shown, self.dithering))?,
            (PanelColor::Rgb565, None) => {
                image.data.chunks(3).flat_map(|p| rgb565(p[0], p[1], p[2]).to_be_bytes()).collect()
            }
            (PanelColor::Dither, None) => indices(palette::apply(&image, &rendered.objects, PaletteMode::Dither))?,
            _ => image.data,
        })
    }
}

/// The colour-table indices of an indexed image.
fn indices(image: Image) -> Result<Vec<u8>, String> {
    match image {
        Image::Indexed { indices, .. } => Ok(indices),
        Image::Rgb(_) => Err("a truecolour image where colour-table indices were expected".into()),
    }
}

/// RGB565 as embedded-graphics converts Rgb888 to it (each channel
/// rounded to its width), written out here so that the test does not share
/// the firmware's conversion code.
fn rgb565(r: u8, g: u8, b: u8) -> u16 {
    let scale = |v: u8, max: u32| ((v as u32 * max + 127) / 255) as u16;
    (scale(r, 31) << 11) | (scale(g, 63) << 5) | scale(b, 31)
}

/// The OLED board's user-facing command, run as a user runs it:
///
/// ```text
/// cd firmware && OCTRACE_BOARD=lm3s6965evb OCTRACE_SCENE=SCENE \
///   OCTRACE_COLOR=gray4 OCTRACE_OUT=OUT cargo run --release --target thumbv7m-none-eabi
/// ```
///
/// in the target directory the other boards' builds share (their
/// dependencies are built once): the caller runs it when no other build
/// is under way there. Returns what the run printed; the
/// panel's screen is in `out`.
pub fn run_oled_command(scene: &str, out: &Path) -> Result<Run, String> {
    let target = "thumbv7m-none-eabi";
    let mut cargo = board_cargo(&repo().join("firmware"), target)?;
    cargo.args(["run", "--release", "--quiet", "--target", target]);
    cargo.arg("--target-dir").arg(boards_target_dir());
    for var in ["OCTRACE_SIZE", "OCTRACE_DITHER"] {
        cargo.env_remove(var);
    }
    cargo.env("OCTRACE_BOARD", "lm3s6965evb");
    cargo.env("OCTRACE_SCENE", scene);
    cargo.env("OCTRACE_COLOR", "gray4");
    cargo.env("OCTRACE_OUT", out);
    let run = cargo.output().map_err(|e| format!("cannot run cargo: {e}"))?;
    let output = String::from_utf8_lossy(&run.stdout).into_owned() + &String::from_utf8_lossy(&run.stderr);
    Ok(Run { status: run.status.code().unwrap_or(-1), output, pixels: Vec::new() })
}

/// What the benchmark measures of one configuration.
#[derive(Debug)]
pub struct Measurement {
    pub status: i32,
    pub output: String,
    /// Instructions executed from reset to exit.
    pub total: u64,
    /// Instructions of the render alone (between the firmware's markers).
    pub render: Option<u64>,
    /// Flash: text + data.
    pub flash: u64,
    /// Static RAM: data + bss.
    pub static_ram: u64,
}

impl Measurement {
    /// The peak stack the firmware reports.
    pub fn peak_stack(&self) -> Option<u64> {
        peak_stack(&self.output)
    }
}

/// The instruction counter: `$OCTRACE_QEMU_COUNT` if set (a program taking
/// the same arguments and printing the same lines), else the repository's
/// `firmware/tools/qemu-count` (which builds its qemu plugin with gcc).
pub fn qemu_count() -> PathBuf {
    std::env::var_os("OCTRACE_QEMU_COUNT")
        .map(PathBuf::from)
        .unwrap_or_else(|| repo().join("firmware/tools/qemu-count"))
}

impl Firmware {
    /// Whether its instructions are exact run to run: every board but the
    /// dual-core one, whose cores' waiting for each other depends on how
    /// qemu takes turns between them.
    pub fn counts_exactly(&self) -> bool {
        self.board != Board::Mps2An521
    }

    /// Runs the ELF once under `qemu-count` ([`Firmware::measure`]) and
    /// collects what the display received too: the run the bit-exactness
    /// test makes, with the instructions counted.
    pub fn run_measured(&self, elf: &Path, qemu_count: &Path) -> Result<(Run, Measurement), String> {
        let file = self.output_file();
        let _ = std::fs::remove_file(&file);
        let measured = self.measure(elf, qemu_count)?;
        let pixels = std::fs::read(&file).unwrap_or_default();
        Ok((Run { status: measured.status, output: measured.output.clone(), pixels }, measured))
    }

    /// Runs the ELF under `qemu-count` (`qemu-count MACHINE ELF`: the guest's
    /// output, then `insns_total=` and `insns_between_markers=` lines) and
    /// reads its sizes with `arm-none-eabi-size`.
    pub fn measure(&self, elf: &Path, qemu_count: &Path) -> Result<Measurement, String> {
        let out = Command::new(qemu_count)
            .arg(self.board.machine())
            .arg(elf)
            .output()
            .map_err(|e| format!("cannot run {}: {e}", qemu_count.display()))?;
        let text = String::from_utf8_lossy(&out.stdout).into_owned() + &String::from_utf8_lossy(&out.stderr);
        let value = |key: &str| text.lines().find_map(|l| l.strip_prefix(key)?.trim().parse::<u64>().ok());
        let total = value("insns_total=").ok_or_else(|| format!("no instruction count from qemu-count:\n{text}"))?;
        let sizes = Sizes::of(elf)?;
        Ok(Measurement {
            status: out.status.code().unwrap_or(-1),
            render: value("insns_between_markers="),
            total,
            flash: sizes.text + sizes.data,
            static_ram: sizes.data + sizes.bss,
            output: text,
        })
    }
}

impl Firmware {
    /// Each core's instructions between the markers and, of those, the
    /// ones spent waiting for the other core (`firmware/tools/cores.sh`):
    /// for the dual-core board.
    pub fn cores(&self, elf: &Path) -> Result<Vec<(u64, u64)>, String> {
        let out = Command::new("bash")
            .arg(repo().join("firmware/tools/cores.sh"))
            .arg(elf)
            .output()
            .map_err(|e| format!("cannot run cores.sh: {e}"))?;
        let text = String::from_utf8_lossy(&out.stdout).into_owned();
        let cores: Vec<(u64, u64)> = text
            .lines()
            .filter_map(|l| match l.split_whitespace().collect::<Vec<_>>()[..] {
                ["core", _, "insns", total, "wait", wait] => Some((total.parse().ok()?, wait.parse().ok()?)),
                _ => None,
            })
            .collect();
        if cores.is_empty() {
            return Err(format!("no core counts from cores.sh:\n{text}{}", String::from_utf8_lossy(&out.stderr)));
        }
        Ok(cores)
    }
}

/// An ELF's sections as `arm-none-eabi-size -B` counts them.
#[derive(Clone, Copy, Debug)]
pub struct Sizes {
    /// Code and constants (flash).
    pub text: u64,
    /// Initialised statics: flash for their initial values, and RAM.
    pub data: u64,
    /// Zeroed statics (RAM only).
    pub bss: u64,
}

impl Sizes {
    /// Reads `elf`'s sizes. riscv-rt reserves the stack as a section of
    /// its own, which `size` counts with `.bss`: it is left out, as the
    /// Cortex-M boards' stack is.
    pub fn of(elf: &Path) -> Result<Sizes, String> {
        let size = |format: &str| {
            let out = Command::new("arm-none-eabi-size")
                .arg(format)
                .arg(elf)
                .output()
                .map_err(|e| format!("cannot run arm-none-eabi-size: {e}"))?;
            Ok::<_, String>(String::from_utf8_lossy(&out.stdout).into_owned())
        };
        let (totals, sections) = (size("-B")?, size("-A")?);
        let numbers: Vec<u64> =
            totals.lines().nth(1).unwrap_or("").split_whitespace().take(3).filter_map(|n| n.parse().ok()).collect();
        let [text, data, bss] = numbers[..] else {
            return Err(format!("unexpected arm-none-eabi-size output:\n{totals}"));
        };
        let stack = sections
            .lines()
            .find_map(|l| l.strip_prefix(".stack ")?.split_whitespace().next()?.parse::<u64>().ok())
            .unwrap_or(0);
        Ok(Sizes { text, data, bss: bss - stack.min(bss) })
    }
}

/// Whether qemu for Arm is installed.
pub fn qemu_available() -> bool {
    Command::new("qemu-system-arm").arg("--version").output().is_ok_and(|o| o.status.success())
}
