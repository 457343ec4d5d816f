//! The software board: the board's side of octrace-link
//! (`octrace_link::board`) on this machine, behind a pseudo-terminal, run as
//! the live firmware runs it on a Pico: frames in byte by byte, each
//! answered, a scene's rows rendered one after the other and sent as they
//! are drawn, a frame from the host stopping a drawing between rows. The
//! tests of `host-sim board` (tests/tests/board.rs) talk to it as they will
//! to the emulated Pico.
//!
//!     software-board [--profile board16k|board64k|host] [--panel WxH] [--max-scene BYTES]
//!
//! It prints `serial: PATH`, the device a host opens, then serves until its
//! standard input closes. Defaults: Board64K, the Pico template's 240×240
//! RGB565 panel, scenes of up to 16,384 bytes.

use embedded_graphics_core::pixelcolor::Rgb565;
use octrace_core::accel::Mailbox;
use octrace_core::profile::{Board16K, Board64K, Host, Profile};
use octrace_core::render::Renderer;
use octrace_core::Raytracer;
use octrace_link::board::Board;
use octrace_link::{Counters, Decoder, Panel, PixelFormat, Timing, OVERHEAD};
use std::collections::VecDeque;
use std::fs::File;
use std::io::{Read, Write};
use std::sync::mpsc::{self, Receiver, TryRecvError};
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

/// The bytes a host sends, from a thread reading the pseudo-terminal.
struct Line {
    chunks: Receiver<Vec<u8>>,
    bytes: VecDeque<u8>,
}

impl Line {
    /// The next byte, waiting for it.
    fn wait(&mut self) -> Option<u8> {
        while self.bytes.is_empty() {
            self.bytes.extend(self.chunks.recv().ok()?);
        }
        self.bytes.pop_front()
    }

    /// The next byte if one has come.
    fn poll(&mut self) -> Option<u8> {
        while self.bytes.is_empty() {
            match self.chunks.try_recv() {
                Ok(chunk) => self.bytes.extend(chunk),
                Err(TryRecvError::Empty | TryRecvError::Disconnected) => return None,
            }
        }
        self.bytes.pop_front()
    }
}

/// Answers frames until the line ends, as a firmware's main loop does.
fn serve<P: Profile>(options: &Options, line: &mut Line, out: &mut File) {
    let mut decoder = Decoder::new(vec![0u8; options.max_scene + OVERHEAD + 1]);
    let board = Board::new(options.panel, FIRMWARE, &decoder);
    let mut raytracer = Box::new(Raytracer::<P>::new());
    let (width, height) = (u32::from(options.panel.width), u32::from(options.panel.height));
    let mut row = vec![Rgb565::default(); width as usize];
    // A frame came while drawing: answered next.
    let mut pending = false;
    loop {
        if !pending {
            let Some(byte) = line.wait() else { return };
            if decoder.push(byte).is_none() {
                continue;
            }
        }
        pending = false;
        let Some(received) = decoder.received() else { continue };
        let started = Instant::now();
        // A host that went away while the board wrote is not waited for.
        let Ok(Some(drawing)) = board.answer(received, &mut *raytracer, out) else { continue };
        let loaded = Instant::now();
        let scene = drawing.scene();
        let accelerator = scene.accelerator();
        let Ok(renderer) = Renderer::with_size(scene.view(), &accelerator, width, height) else {
            let _ = drawing.cancel(0, out);
            continue;
        };
        let mut mailbox = vec![0u32; Mailbox::words_for(scene.view().object_count())];
        let mut renderer = renderer.with_mailbox(&mut mailbox);
        let mut drawn = 0;
        let mut sent = true;
        while drawn < height && sent && !pending {
            for (pixel, sample) in row.iter_mut().zip(renderer.row(drawn, 0..width)) {
                *pixel = sample.color.into();
            }
            sent = drawing.send_row(drawn as u16, &row, out).is_ok();
            drawn += 1;
            while let (false, Some(byte)) = (pending, line.poll()) {
                pending = decoder.push(byte).is_some();
            }
        }
        let _ = match pending {
            true => drawing.cancel(drawn as u16, out),
            false => {
                // By the host's clock; it has no counters.
                let (elapsed, render) = (started.elapsed(), loaded.elapsed());
                let load = Some(elapsed - render);
                let timing =
                    Timing { elapsed: Some(elapsed), load, render: Some(render), counters: Counters::new(&[]) };
                drawing.finish(&timing, out)
            }
        };
    }
}

fn main() {
    let options = options().unwrap_or_else(|e| {
        eprintln!("software-board: {e}");
        std::process::exit(2);
    });
    let (mut controller, path) = octrace_tests::board::open_pty().unwrap_or_else(|e| {
        eprintln!("software-board: cannot open a pseudo-terminal: {e}");
        std::process::exit(1);
    });
    let mut reader = controller.try_clone().expect("a second handle on the pseudo-terminal");
    let (chunks, received) = mpsc::channel();
    std::thread::spawn(move || {
        let mut chunk = [0u8; 4096];
        loop {
            match reader.read(&mut chunk) {
                Ok(n) if n > 0 => {
                    if chunks.send(chunk[..n].to_vec()).is_err() {
                        return;
                    }
                }
                // No host has the device open (EIO once one closed it): wait for the next.
                _ => std::thread::sleep(Duration::from_millis(10)),
            }
        }
    });
    // The process ends with its standard input, so that it never outlives
    // the test that started it.
    std::thread::spawn(|| {
        let _ = std::io::copy(&mut std::io::stdin(), &mut std::io::sink());
        std::process::exit(0);
    });
    println!("serial: {}", path.display());
    let _ = std::io::stdout().flush();
    let mut line = Line { chunks: received, bytes: VecDeque::new() };
    match options.profile.as_str() {
        "board16k" => serve::<Board16K>(&options, &mut line, &mut controller),
        "board64k" => serve::<Board64K>(&options, &mut line, &mut controller),
        "host" => serve::<Host>(&options, &mut line, &mut controller),
        other => {
            eprintln!("software-board: unknown profile {other} (board16k, board64k, host)");
            std::process::exit(2);
        }
    }
}
