//! A real Pico beside the emulated one, in one command: builds the Pico
//! template's embedded-scene firmware (`examples/pico-st7789`) for each
//! scene, runs it on the emulated Pico and asks it what it measured, then
//! flashes it to the Pico on the USB port (picotool, the Pico held in
//! BOOTSEL for each scene), asks the board the same, and prints both
//! side by side: the load and the render by each one's TIMER, and the
//! accesses to the striped SRAM banks that waited for the other core
//! (BUSCTRL's counters). The emulator's cycle count of the same run is
//! printed too, for the emulator's own check.
//!
//!     cargo run --release -p octrace-tests --bin pico-compare -- [--port /dev/ttyACM0 [--no-flash]] [scene...]
//!
//! Without `--port`, only the emulated Pico's column. With `--no-flash`,
//! the Pico on the port already runs this build (one scene). The table is
//! Markdown: paste it into an issue of the repository (the template's
//! README says how).

use octrace_tests::pico::{self, Build, Report, Template};
use std::path::{Path, PathBuf};
use std::process::Command;
use std::time::{Duration, Instant};

const USAGE: &str = "usage: pico-compare [--port PORT [--no-flash]] [scene...]";

/// How long a Pico has to come back as a serial port after picotool, and to draw its picture.
const BOARD_TIMEOUT: Duration = Duration::from_secs(60);
/// How long to wait for the Pico to be put in BOOTSEL mode.
const BOOTSEL_TIMEOUT: Duration = Duration::from_secs(120);

/// One scene's comparison: the firmware's report on the emulated Pico, the
/// emulator's own count of that run, and the report of the Pico at the port.
struct Row {
    scene: String,
    emulated: Report,
    cycles: pico::Cycles,
    board: Option<Report>,
}

struct Options {
    port: Option<PathBuf>,
    flash: bool,
    scenes: Vec<String>,
}

fn main() {
    let options = options().unwrap_or_else(|e| usage(&e));
    let dir = tempfile::tempdir().expect("a temporary directory");
    let mut rows = Vec::new();
    for scene in &options.scenes {
        match compare(scene, &options, dir.path()) {
            Ok(row) => rows.push(row),
            Err(e) => {
                eprintln!("pico-compare: {scene}: {e}");
                std::process::exit(1);
            }
        }
    }
    println!("| scene | | load | render | scene to picture | contested SRAM0-3 accesses (load + render) |");
    println!("| --- | --- | ---: | ---: | ---: | ---: |");
    for Row { scene, emulated, cycles, board } in &rows {
        let line = |who: &str, r: &Report| {
            let contested: u64 = r.load_contested.iter().chain(&r.render_contested).sum();
            println!(
                "| {scene} | {who} | {:.4} s | {:.4} s | **{:.4} s** | {contested} |",
                r.load_us as f64 / 1e6,
                r.render_us as f64 / 1e6,
                r.to_picture_seconds()
            );
        };
        line("emulated Pico", emulated);
        println!(
            "| {scene} | (the emulator's count) | | | {:.4} s | {} |",
            cycles.to_picture_seconds(),
            cycles.striped_contested
        );
        if let Some(board) = board {
            line("this Pico", board);
            println!(
                "| {scene} | this Pico against the emulated | | | {:+.2} % | {:+.1} % |",
                100.0 * (board.to_picture_seconds() / emulated.to_picture_seconds() - 1.0),
                100.0 * (contested(board) as f64 / contested(emulated).max(1) as f64 - 1.0)
            );
        }
    }
    println!();
    let clocks: Vec<String> = rows.iter().map(|row| format!("{:.0} MHz", row.cycles.clock_hz / 1e6)).collect();
    println!(
        "Both at the clock the firmware sets ({}); the emulator is `emulator/` of this repository at its commit.",
        clocks.first().map_or("none run", String::as_str)
    );
}

fn contested(report: &Report) -> u64 {
    report.load_contested.iter().chain(&report.render_contested).sum()
}

/// One scene: the emulated Pico's report and count, and the board's report.
fn compare(scene: &str, options: &Options, dir: &Path) -> Result<Row, String> {
    let elf = pico::build(&Build::of(Template::St7789, scene))?;
    eprintln!("pico-compare: {scene}: on the emulated Pico (a minute or so)");
    let (cycles, emulated) = pico::run_reporting(&elf, &dir.join(format!("{scene}.png")))?;
    let board = match &options.port {
        None => None,
        Some(port) => {
            if options.flash {
                flash(&elf, scene)?;
            }
            eprintln!("pico-compare: {scene}: asking the Pico at {}", port.display());
            Some(pico::ask_report(port, BOARD_TIMEOUT)?)
        }
    };
    if let Some(board) = &board {
        if board.scene != scene {
            return Err(format!("the Pico at the port drew {}, not {scene}", board.scene));
        }
    }
    Ok(Row { scene: scene.to_owned(), emulated, cycles, board })
}

/// Loads `elf` into the Pico with picotool, waiting for the Pico to be in
/// BOOTSEL mode (held while plugged in) for at most BOOTSEL_TIMEOUT.
fn flash(elf: &Path, scene: &str) -> Result<(), String> {
    eprintln!("pico-compare: {scene}: hold BOOTSEL and plug the Pico in (picotool loads it and starts it)");
    let started = Instant::now();
    loop {
        let out =
            Command::new("picotool").args(["load", "-u", "-v", "-x", "-t", "elf"]).arg(elf).output().map_err(|e| {
                format!("cannot run picotool (install it from your distribution or raspberrypi/picotool): {e}")
            })?;
        if out.status.success() {
            return Ok(());
        }
        if started.elapsed() > BOOTSEL_TIMEOUT {
            return Err(format!("picotool did not load the Pico: {}", String::from_utf8_lossy(&out.stderr).trim()));
        }
        std::thread::sleep(Duration::from_secs(1));
    }
}

fn options() -> Result<Options, String> {
    let mut options = Options { port: None, flash: true, scenes: Vec::new() };
    let mut args = std::env::args().skip(1);
    while let Some(arg) = args.next() {
        match arg.as_str() {
            "--port" => options.port = Some(args.next().ok_or("--port names the Pico's serial port")?.into()),
            "--no-flash" => options.flash = false,
            flag if flag.starts_with('-') => return Err(format!("unknown option {flag}")),
            _ => options.scenes.push(arg),
        }
    }
    if options.scenes.is_empty() {
        options.scenes = ["fig5_1", "fig5_3", "fig5_5"].map(String::from).to_vec();
    }
    if !options.flash && (options.port.is_none() || options.scenes.len() != 1) {
        return Err("--no-flash compares the one scene the Pico at --port already runs".to_owned());
    }
    Ok(options)
}

fn usage(message: &str) -> ! {
    eprintln!("pico-compare: {message}\n{USAGE}");
    std::process::exit(2);
}
