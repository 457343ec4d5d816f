//! The software board: the board's loop of octrace-link
//! (`octrace_link::board::Link`, the one the live firmware runs on a Pico)
//! on this machine, behind a pseudo-terminal: frames in byte by byte, each
//! answered, a scene's rows rendered one after the other and sent as they
//! are drawn, a frame from the host stopping a drawing between two rays.
//! The tests of `host-sim board` (tests/tests/board.rs) talk to it as they
//! will to the emulated Pico.
//!
//!     software-board [--profile board16k|board64k|host] [--panel WxH] [--max-scene BYTES]
//!
//! It prints `serial: PATH`, the device a host opens, then serves until its
//! standard input closes; its lines are the tests' commands, answered on
//! standard output as the emulated Pico answers them (`hold`, `release`,
//! `times`, `panel PATH`: see `octrace_tests::board`), the times by this
//! process's clock, and no watchdog. Defaults: Board64K, the Pico template's 240×240
//! RGB565 panel, scenes of up to 16,384 bytes.

use embedded_graphics_core::pixelcolor::Rgb565;
use octrace_core::accel::Mailbox;
use octrace_core::profile::{Board16K, Board64K, Host, Profile};
use octrace_core::render::Renderer;
use octrace_core::Raytracer;
use octrace_link::board::{Line, Link};
use octrace_link::{Panel, PixelFormat, OVERHEAD};
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
}

fn options() -> Result<Options, String> {
    let mut options = Options {
        profile: "board64k".into(),
        panel: Panel { width: 240, height: 240, format: PixelFormat::Rgb565 },
        max_scene: 16 * 1024,
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
            _ => return Err(format!("unknown argument {arg} (--profile, --panel, --max-scene)")),
        }
    }
    Ok(options)
}

/// What the tests' commands see and set, shared with the board's loop.
struct Controls {
    started: Instant,
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
    fn now_us(&self) -> u64 {
        self.started.elapsed().as_micros() as u64
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
            std::thread::sleep(Duration::from_millis(1));
            return 0;
        }
        // Non-blocking: a full terminal takes nothing.
        match self.out.write(bytes) {
            Ok(n) => {
                self.controls.last_out.store(self.controls.now_us(), Ordering::Relaxed);
                n
            }
            Err(e) if e.kind() == ErrorKind::WouldBlock => {
                std::thread::sleep(Duration::from_millis(1));
                0
            }
            // No host has the terminal open: what it would get is lost.
            Err(_) => bytes.len(),
        }
    }

    fn discard(&mut self) {
        // What the terminal holds already is the host's.
    }

    fn now_us(&mut self) -> u64 {
        self.controls.now_us()
    }

    fn sleep(&mut self) -> bool {
        self.controls.sleeping.store(true, Ordering::SeqCst);
        let chunk = self.chunks.recv();
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
/// does (on one core).
fn serve<P: Profile>(options: &Options, line: &mut Pty, controls: &Controls) {
    let mut link = Link::new(options.panel, FIRMWARE, vec![0u8; options.max_scene + OVERHEAD + 1]);
    let mut raytracer = Box::new(Raytracer::<P>::new());
    let (width, height) = (u32::from(options.panel.width), u32::from(options.panel.height));
    let mut row = vec![Rgb565::default(); width as usize];
    while link
        .serve(line, &mut raytracer, |drawing, rows| {
            let scene = drawing.scene();
            let accelerator = scene.accelerator();
            let Ok(renderer) = Renderer::with_size(scene.view(), &accelerator, width, height) else { return 0 };
            let mut mailbox = vec![0u32; Mailbox::words_for(scene.view().object_count())];
            let mut renderer = renderer.with_mailbox(&mut mailbox);
            rows.draw_on_one_core(drawing, &mut renderer, &mut row, |y, pixels| {
                let mut panel = controls.panel.lock().unwrap_or_else(|e| e.into_inner());
                let at = usize::from(y) * pixels.len();
                panel[at..at + pixels.len()].copy_from_slice(pixels);
            })
        })
        .is_some()
    {}
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
        hold: AtomicBool::new(false),
        last_in: AtomicU64::new(u64::MAX),
        last_out: AtomicU64::new(u64::MAX),
        panel: Mutex::new(vec![Rgb565::default(); usize::from(panel.width) * usize::from(panel.height)]),
        sleeping: AtomicBool::new(false),
        unread_chunks: AtomicU64::new(0),
    });
    let mut reader = controller.try_clone().expect("a second handle on the pseudo-terminal");
    let (chunks, received) = mpsc::channel();
    let reading = Arc::clone(&controls);
    std::thread::spawn(move || {
        let mut chunk = [0u8; 4096];
        loop {
            match reader.read(&mut chunk) {
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
    match options.profile.as_str() {
        "board16k" => serve::<Board16K>(&options, &mut line, &controls),
        "board64k" => serve::<Board64K>(&options, &mut line, &controls),
        "host" => serve::<Host>(&options, &mut line, &controls),
        other => {
            eprintln!("software-board: unknown profile {other} (board16k, board64k, host)");
            std::process::exit(2);
        }
    }
}
