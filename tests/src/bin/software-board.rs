//! The software board: the board's loop of octrace-link
//! (`octrace_link::board::Link`, the one the live firmware runs on a Pico)
//! on this machine, behind a pseudo-terminal: frames in byte by byte, each
//! answered, a scene's rows rendered one after the other and sent as they
//! are drawn, a frame from the host stopping a drawing between two rays.
//! The tests of `host-sim board` (tests/tests/board/) talk to it as they
//! will to the emulated Pico.
//!
//!     software-board [--profile board16k|board64k|host] [--panel WxH] [--max-scene BYTES]
//!                    [--misbehave HOW]
//!
//! It prints `serial: PATH`, the device a host opens, then serves until its
//! standard input closes; its lines are the tests' commands, answered on
//! standard output as the emulated Pico answers them (`hold`, `release`,
//! `times`, `panel PATH`: see `octrace_tests::board`), the times by the
//! board's own clock, and no watchdog. Its clock counts the time it works
//! (its process's CPU time) and the time it waits on purpose (for the
//! host's bytes, for room to send), not the time this machine gives other
//! programs: as an emulated board's clock counts its cycles, so that what
//! a test measures by it does not depend on how busy the machine is. Defaults: Board64K, the Pico template's 240×240
//! RGB565 panel, scenes of up to 16,384 bytes.
//!
//! `--misbehave` makes it a hostile board, for the tests of what a host
//! does with one ([`Misbehaviour`]): `draws-at:WxH`, `wrong-pixel` (or
//! `wrong-pixel:red`, `:green`, `:blue`), `errors-every:MS`,
//! `reads-slowly`, `escapes`.

use embedded_graphics_core::geometry::Size;
use embedded_graphics_core::pixelcolor::raw::RawU16;
use embedded_graphics_core::pixelcolor::{IntoStorage, Rgb565, RgbColor};
use octrace_core::animation::{AnimationNeeds, HostAnimationRoom};
use octrace_core::profile::{Board16K, Board64K, Host, Profile};
use octrace_core::Raytracer;
use octrace_link::board::{Board, Line, Link};
use octrace_link::{Counters, Decoder, Message, Panel, PixelFormat, SceneError, Timing, OVERHEAD};
use std::collections::VecDeque;
use std::fs::File;
use std::io::{ErrorKind, Read, Write};
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::sync::mpsc::{self, Receiver, TryRecvError};
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};

const FIRMWARE: &str = concat!("octrace software board ", env!("CARGO_PKG_VERSION"));

/// What the command line asks for.
struct Options {
    profile: String,
    panel: Panel,
    max_scene: usize,
    misbehave: Option<Misbehaviour>,
}

/// How a hostile board departs from the protocol or from octrace's board.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Misbehaviour {
    /// Answers every scene with `drawing` at this panel (not the one its
    /// hello describes), then `done`, without a row.
    DrawsAt { width: u16, height: u16 },
    /// Draws every scene with its first pixel of another colour: in every
    /// channel (None), or in one alone (its lowest bit).
    WrongPixel(Option<Channel>),
    /// Answers every scene with scene errors, one every this many
    /// milliseconds, never closed by `rejected`.
    ErrorsEvery(u64),
    /// Reads its port slowly: 1 KiB every 100 ms (10 KiB/s), so that a
    /// host's write waits longer than a serial port's own timeout.
    ReadsSlowly,
    /// Its firmware's name and its answer to every scene (one error) carry
    /// terminal escapes.
    Escapes,
}

/// A channel of an RGB565 pixel.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Channel {
    Red,
    Green,
    Blue,
}

impl Channel {
    /// `pixel` with this channel's lowest bit flipped.
    fn flip(self, pixel: Rgb565) -> Rgb565 {
        let bit = match self {
            Channel::Red => 1 << 11,
            Channel::Green => 1 << 5,
            Channel::Blue => 1,
        };
        Rgb565::from(RawU16::new(pixel.into_storage() ^ bit))
    }
}

impl Misbehaviour {
    fn parse(text: &str) -> Result<Misbehaviour, String> {
        let size = |size: &str| -> Option<(u16, u16)> {
            let (w, h) = size.split_once('x')?;
            Some((w.parse().ok()?, h.parse().ok()?))
        };
        Ok(match text.split_once(':') {
            Some(("draws-at", wxh)) => {
                let (width, height) = size(wxh).ok_or(format!("--misbehave {text}: expected draws-at:WxH"))?;
                Misbehaviour::DrawsAt { width, height }
            }
            Some(("errors-every", ms)) => {
                Misbehaviour::ErrorsEvery(ms.parse().map_err(|e| format!("--misbehave {text}: {e}"))?)
            }
            Some(("wrong-pixel", channel)) => Misbehaviour::WrongPixel(Some(match channel {
                "red" => Channel::Red,
                "green" => Channel::Green,
                "blue" => Channel::Blue,
                _ => return Err(format!("--misbehave {text}: wrong-pixel:red, :green or :blue")),
            })),
            _ => match text {
                "wrong-pixel" => Misbehaviour::WrongPixel(None),
                "reads-slowly" => Misbehaviour::ReadsSlowly,
                "escapes" => Misbehaviour::Escapes,
                _ => {
                    return Err(format!(
                    "--misbehave {text}: draws-at:WxH, wrong-pixel[:CHANNEL], errors-every:MS, reads-slowly or escapes"
                ))
                }
            },
        })
    }

    /// Answers the scene request `tag` as this misbehaviour does, if it
    /// answers scenes its own way.
    fn answer_scene(self, tag: u16, pixels: bool, line: &mut Pty) -> bool {
        let send = |message: Message<'_>, line: &mut Pty| line.send(tag, message);
        match self {
            Misbehaviour::DrawsAt { width, height } => {
                let panel = Panel { width, height, format: PixelFormat::Rgb565 };
                let _ = send(Message::Drawing { panel, pixels, frames: 0 }, line)
                    && send(Message::Done(Timing::NONE), line);
            }
            Misbehaviour::ErrorsEvery(ms) => {
                let error = SceneError { line: 1, column: 1, capacity: None, message: "one more error" };
                // Until the host says something else (the byte that says so
                // is dropped: a frame's opening delimiter, which a decoder
                // that ended its last frame does without), or goes.
                while line.read().is_none() && send(Message::SceneError(error), line) {
                    line.controls.clone().waiting(|| std::thread::sleep(Duration::from_millis(ms)));
                }
            }
            Misbehaviour::Escapes => {
                let message = "\u{1b}[2J\u{1b}[31mred\u{1b}[0m\nhost-sim: 0 error(s)";
                let error = SceneError { line: 1, column: 1, capacity: None, message };
                let _ = send(Message::SceneError(error), line) && send(Message::Rejected { errors: 1 }, line);
            }
            Misbehaviour::WrongPixel(_) | Misbehaviour::ReadsSlowly => return false,
        }
        true
    }
}

fn options() -> Result<Options, String> {
    let mut options = Options {
        profile: "board64k".into(),
        panel: Panel { width: 240, height: 240, format: PixelFormat::Rgb565 },
        max_scene: 16 * 1024,
        misbehave: None,
    };
    let mut args = std::env::args().skip(1);
    while let Some(arg) = args.next() {
        let mut value = || args.next().ok_or(format!("{arg} needs a value"));
        match arg.as_str() {
            "--profile" => options.profile = value()?.to_ascii_lowercase(),
            "--panel" => {
                let size = value()?;
                let (w, h) = size.split_once('x').ok_or(format!("--panel {size}: expected WxH"))?;
                let side = |s: &str| s.parse::<u16>().ok().filter(|&n| n > 0).ok_or(format!("--panel {size}"));
                options.panel.width = side(w)?;
                options.panel.height = side(h)?;
            }
            "--max-scene" => options.max_scene = value()?.parse().map_err(|e| format!("--max-scene: {e}"))?,
            "--misbehave" => options.misbehave = Some(Misbehaviour::parse(&value()?)?),
            _ => return Err(format!("unknown argument {arg} (--profile, --panel, --max-scene, --misbehave)")),
        }
    }
    Ok(options)
}

/// What the tests' commands see and set, shared with the board's loop.
struct Controls {
    started: Instant,
    /// The board's waits on purpose: their total in µs, and when the one
    /// under way began (µs since `started`).
    waits: Mutex<(u64, Option<u64>)>,
    /// The host takes nothing the board sends.
    hold: AtomicBool,
    /// When the host last handed the board bytes, and when the board last
    /// sent some (µs since `started`; u64::MAX: never).
    last_in: AtomicU64,
    last_out: AtomicU64,
    /// The panel: what the board drew, row-major.
    panel: Mutex<Vec<Rgb565>>,
    /// The board waits for the host, in `Line::sleep`.
    sleeping: AtomicBool,
    /// Chunks read from the terminal that the board has not taken yet.
    unread_chunks: AtomicU64,
}

impl Controls {
    /// The board's clock, in µs: the process's CPU time and the board's
    /// waits on purpose.
    fn now_us(&self) -> u64 {
        let cpu = rustix::time::clock_gettime(rustix::time::ClockId::ProcessCPUTime);
        let cpu_us = cpu.tv_sec as u64 * 1_000_000 + cpu.tv_nsec as u64 / 1_000;
        let (waited, since) = *self.waits.lock().unwrap_or_else(|e| e.into_inner());
        cpu_us + waited + since.map_or(0, |since| self.wall_us().saturating_sub(since))
    }

    /// µs since the board started, by this machine's clock.
    fn wall_us(&self) -> u64 {
        self.started.elapsed().as_micros() as u64
    }

    /// Runs `wait`, a wait of the board's on purpose, its time counted on
    /// the board's clock.
    fn waiting<T>(&self, wait: impl FnOnce() -> T) -> T {
        let began = self.wall_us();
        self.waits.lock().unwrap_or_else(|e| e.into_inner()).1 = Some(began);
        let result = wait();
        let mut waits = self.waits.lock().unwrap_or_else(|e| e.into_inner());
        *waits = (waits.0 + self.wall_us().saturating_sub(began), None);
        result
    }

    /// The answer to one command line.
    fn answer(&self, command: &str, panel: Panel) -> String {
        let time = |t: &AtomicU64| match t.load(Ordering::Relaxed) {
            u64::MAX => "-".to_string(),
            t => t.to_string(),
        };
        match command.split_once(' ').unwrap_or((command, "")) {
            ("hold", _) => {
                self.hold.store(true, Ordering::Relaxed);
                "ok".into()
            }
            ("release", _) => {
                self.hold.store(false, Ordering::Relaxed);
                "ok".into()
            }
            ("times", _) => {
                // Asleep with nothing on its way: the board sets `sleeping`
                // false before it counts a chunk taken.
                let idle = self.sleeping.load(Ordering::SeqCst) && self.unread_chunks.load(Ordering::SeqCst) == 0;
                let idle = u8::from(idle);
                format!("times {} {} {} - {idle}", time(&self.last_in), time(&self.last_out), self.now_us())
            }
            ("panel", path) if !path.is_empty() => {
                let mut image = octrace_images::RgbImage::new(panel.width.into(), panel.height.into());
                let pixels = self.panel.lock().unwrap_or_else(|e| e.into_inner());
                let colors = pixels.iter().flat_map(|&c| {
                    let c = embedded_graphics_core::pixelcolor::Rgb888::from(c);
                    use embedded_graphics_core::pixelcolor::RgbColor;
                    [c.r(), c.g(), c.b()]
                });
                image.data.iter_mut().zip(colors).for_each(|(byte, c)| *byte = c);
                let written = File::create(path).map_err(|e| e.to_string()).and_then(|mut file| {
                    let image = octrace_images::formats::Image::Rgb(image);
                    octrace_images::formats::write(&image, octrace_images::formats::Format::Png, &mut file)
                        .map_err(|e| e.to_string())
                });
                written.map_or_else(|e| format!("panel {path}: {e}"), |()| "ok".into())
            }
            _ => format!("unknown command '{command}' (hold, release, times, panel PATH)"),
        }
    }
}

/// The pseudo-terminal as the board's line: the bytes a host sends, from
/// a thread reading it; what the board sends, written without waiting.
struct Pty {
    chunks: Receiver<Vec<u8>>,
    bytes: VecDeque<u8>,
    out: File,
    controls: Arc<Controls>,
}

impl Pty {
    /// Sends `message` with `tag` whole (waiting while the host holds);
    /// false if it cannot be encoded.
    fn send(&mut self, tag: u16, message: Message<'_>) -> bool {
        let mut frame = Vec::new();
        if message.encode(tag, &mut frame).is_err() {
            return false;
        }
        self.send_bytes(&frame);
        true
    }

    fn send_bytes(&mut self, mut bytes: &[u8]) {
        while !bytes.is_empty() {
            let taken = self.write(bytes);
            bytes = &bytes[taken..];
        }
    }

    /// The next byte from the host, waiting for it; None once the line ends.
    fn wait(&mut self) -> Option<u8> {
        loop {
            if let Some(byte) = self.read() {
                return Some(byte);
            }
            if !self.sleep() {
                return None;
            }
        }
    }
}

impl Line for Pty {
    fn read(&mut self) -> Option<u8> {
        while self.bytes.is_empty() {
            match self.chunks.try_recv() {
                Ok(chunk) => {
                    self.controls.unread_chunks.fetch_sub(1, Ordering::SeqCst);
                    self.bytes.extend(chunk);
                }
                Err(TryRecvError::Empty | TryRecvError::Disconnected) => return None,
            }
        }
        self.bytes.pop_front()
    }

    fn write(&mut self, bytes: &[u8]) -> usize {
        if self.controls.hold.load(Ordering::Relaxed) {
            return 0;
        }
        // Non-blocking: a full terminal takes nothing.
        match self.out.write(bytes) {
            Ok(n) => {
                self.controls.last_out.store(self.controls.now_us(), Ordering::Relaxed);
                n
            }
            Err(e) if e.kind() == ErrorKind::WouldBlock => 0,
            // No host has the terminal open: what it would get is lost.
            Err(_) => bytes.len(),
        }
    }

    fn wait_for_room(&mut self, at_most_us: u64) {
        // The terminal says nothing when it has room again: all the wait
        // the loop allows (a millisecond at most), then a look.
        self.controls.waiting(|| std::thread::sleep(Duration::from_micros(at_most_us)));
    }

    fn discard(&mut self) {
        // What the terminal holds already is the host's.
    }

    fn now_us(&mut self) -> u64 {
        self.controls.now_us()
    }

    fn sleep(&mut self) -> bool {
        self.controls.sleeping.store(true, Ordering::SeqCst);
        let chunk = self.controls.waiting(|| self.chunks.recv());
        self.controls.sleeping.store(false, Ordering::SeqCst);
        match chunk {
            Ok(chunk) => {
                self.controls.unread_chunks.fetch_sub(1, Ordering::SeqCst);
                self.bytes.extend(chunk);
                true
            }
            Err(_) => false,
        }
    }

    fn alive(&mut self) {}
}

/// Answers frames until the line ends, as the live firmware's main loop
/// does (on one core), an animation's frames re-tracing only what moved
/// under a profile with coherence (`--profile host`; the boards' presets
/// trace every tile of every frame, the same pictures).
fn serve<P: Profile>(options: &Options, line: &mut Pty, controls: &Controls) {
    let (width, height) = (u32::from(options.panel.width), u32::from(options.panel.height));
    // As much motion as the live firmware holds, and more.
    let size = Size::new(width, height);
    let mut room =
        HostAnimationRoom::new(AnimationNeeds { tiles: AnimationNeeds::tiles_for(size), tracks: 256, keys: 4096 });
    let Ok(animation) = room.animation(size) else { return };
    let mut link =
        Link::new(options.panel, FIRMWARE, vec![0u8; options.max_scene + OVERHEAD + 1]).with_animations(animation);
    let mut raytracer = Box::new(Raytracer::<P>::new());
    let mut row = vec![Rgb565::default(); width as usize];
    while link
        .serve(line, &mut raytracer, |drawing, rows| {
            rows.draw_on_one_core(drawing, &mut row, |area, pixels| {
                let mut panel = controls.panel.lock().unwrap_or_else(|e| e.into_inner());
                let at = area.top_left.y as usize * width as usize + area.top_left.x as usize;
                panel[at..at + pixels.len()].copy_from_slice(pixels);
            })
        })
        .is_some()
    {}
}

/// Answers frames as a hostile board does (`--misbehave`): octrace's
/// board's answers, but with `misbehave`'s departures, one frame at a time
/// (a frame that comes while it draws waits for the drawing's end), each
/// row sent as it is drawn.
fn serve_hostile<P: Profile>(options: &Options, misbehave: Misbehaviour, line: &mut Pty) {
    let mut decoder = Decoder::new(vec![0u8; options.max_scene + OVERHEAD + 1]);
    let firmware = match misbehave {
        Misbehaviour::Escapes => "\u{1b}]0;pwned\u{7}\u{1b}[2Joctrace software board",
        _ => FIRMWARE,
    };
    let board = Board::new(options.panel, firmware, &decoder);
    let mut raytracer = Box::new(Raytracer::<P>::new());
    let (width, height) = (u32::from(options.panel.width), u32::from(options.panel.height));
    let mut row = vec![Rgb565::default(); width as usize];
    let mut out = Vec::new();
    while let Some(byte) = line.wait() {
        if decoder.push(byte).is_none() {
            continue;
        }
        let Some(received) = decoder.received() else { continue };
        if let Ok(frame) = &received {
            if let Message::Scene { pixels, .. } = frame.message {
                if misbehave.answer_scene(frame.tag, pixels, line) {
                    continue;
                }
            }
        }
        let started = Instant::now();
        out.clear();
        let answered = board.answer(received, &mut *raytracer, None, &mut out);
        let loaded = Instant::now();
        line.send_bytes(&out);
        let Ok(Some(drawing)) = answered else { continue };
        out.clear();
        let drawn = drawing.scene().with_renderer(Size::new(width, height), |renderer| {
            for y in 0..height {
                for (pixel, sample) in row.iter_mut().zip(renderer.row(y, 0..width)) {
                    *pixel = sample.color.into();
                }
                if let (0, Misbehaviour::WrongPixel(channel)) = (y, misbehave) {
                    row[0] = match channel {
                        None if row[0] == Rgb565::WHITE => Rgb565::BLACK,
                        None => Rgb565::WHITE,
                        Some(channel) => channel.flip(row[0]),
                    };
                }
                out.clear();
                let _ = drawing.send_row(y as u16, &row, &mut out);
                line.send_bytes(&out);
            }
        });
        match drawn {
            Ok(()) => {
                out.clear();
                // By the host's clock; it has no counters.
                let (elapsed, render) = (started.elapsed(), loaded.elapsed());
                let timing = Timing {
                    elapsed: Some(elapsed),
                    load: Some(elapsed - render),
                    render: Some(render),
                    counters: Counters::new(&[]),
                };
                let _ = drawing.finish(&timing, &mut out);
            }
            Err(_) => _ = drawing.cancel(0, &mut out),
        }
        line.send_bytes(&out);
    }
}

fn main() {
    let options = options().unwrap_or_else(|e| {
        eprintln!("software-board: {e}");
        std::process::exit(2);
    });
    let (controller, path) = octrace_tests::board::open_pty().unwrap_or_else(|e| {
        eprintln!("software-board: cannot open a pseudo-terminal: {e}");
        std::process::exit(1);
    });
    let panel = options.panel;
    let controls = Arc::new(Controls {
        started: Instant::now(),
        waits: Mutex::new((0, None)),
        hold: AtomicBool::new(false),
        last_in: AtomicU64::new(u64::MAX),
        last_out: AtomicU64::new(u64::MAX),
        panel: Mutex::new(vec![Rgb565::default(); usize::from(panel.width) * usize::from(panel.height)]),
        sleeping: AtomicBool::new(false),
        unread_chunks: AtomicU64::new(0),
    });
    let mut reader = controller.try_clone().expect("a second handle on the pseudo-terminal");
    let (chunks, received) = mpsc::channel();
    let slowly = options.misbehave == Some(Misbehaviour::ReadsSlowly);
    let reading = Arc::clone(&controls);
    std::thread::spawn(move || {
        let mut chunk = [0u8; 4096];
        loop {
            if slowly {
                std::thread::sleep(Duration::from_millis(100));
            }
            let chunk = if slowly { &mut chunk[..1024] } else { &mut chunk[..] };
            match reader.read(chunk) {
                Ok(n) if n > 0 => {
                    reading.last_in.store(reading.now_us(), Ordering::Relaxed);
                    reading.unread_chunks.fetch_add(1, Ordering::SeqCst);
                    if chunks.send(chunk[..n].to_vec()).is_err() {
                        return;
                    }
                }
                // No host has the device open (EIO once one closed it): wait for the next.
                _ => std::thread::sleep(Duration::from_millis(1)),
            }
        }
    });
    // Commands, a line each; the process ends with its standard input, so
    // that it never outlives the test that started it.
    let commanded = Arc::clone(&controls);
    std::thread::spawn(move || {
        for command in std::io::stdin().lines().map_while(Result::ok) {
            println!("{}", commanded.answer(command.trim(), panel));
        }
        std::process::exit(0);
    });
    println!("serial: {}", path.display());
    let _ = std::io::stdout().flush();
    let out = controller.try_clone().expect("a third handle on the pseudo-terminal");
    rustix::fs::fcntl_setfl(&out, rustix::fs::OFlags::NONBLOCK | rustix::fs::OFlags::RDWR)
        .expect("the pseudo-terminal takes O_NONBLOCK");
    let mut line = Pty { chunks: received, bytes: VecDeque::new(), out, controls: Arc::clone(&controls) };
    let hostile = options.misbehave.filter(|&how| how != Misbehaviour::ReadsSlowly);
    match (options.profile.as_str(), hostile) {
        ("board16k", Some(how)) => serve_hostile::<Board16K>(&options, how, &mut line),
        ("board64k", Some(how)) => serve_hostile::<Board64K>(&options, how, &mut line),
        ("host", Some(how)) => serve_hostile::<Host>(&options, how, &mut line),
        ("board16k", None) => serve::<Board16K>(&options, &mut line, &controls),
        ("board64k", None) => serve::<Board64K>(&options, &mut line, &controls),
        ("host", None) => serve::<Host>(&options, &mut line, &controls),
        (other, _) => {
            eprintln!("software-board: unknown profile {other} (board16k, board64k, host)");
            std::process::exit(2);
        }
    }
}
