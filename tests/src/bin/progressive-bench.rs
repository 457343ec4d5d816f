//! What the progressive order costs a panel's bus: for each order, the
//! rectangles (a window command each) and pixels its first pass and all its
//! passes send, and their time on an SPI bus, against the direct order's
//! row by row (the table in BENCHMARKS.md, "A picture at once").
//!
//!     cargo run --release -p octrace-tests --bin progressive-bench [WxH] [scene]
//!
//! Drawn as two cores draw it (each unit from colours handed over) and as
//! one core does (`Progressive::render`, tracing the scene, fig5_1 unless
//! named: it cuts runs of many blocks to its stack buffer). The bus: 16-bit
//! pixels and 11 bytes a window (an ST7789's column address, row address
//! and memory write commands) at 31.25 MHz, as the Pico template drives it.
//! Tracing is the same in every order: each pixel once.

use embedded_graphics_core::draw_target::DrawTarget;
use embedded_graphics_core::geometry::{OriginDimensions, Size};
use embedded_graphics_core::pixelcolor::Rgb888;
use embedded_graphics_core::primitives::Rectangle;
use embedded_graphics_core::Pixel;
use octrace_core::profile::Host;
use octrace_core::render::Progressive;
use octrace_core::{AccelMode, Raytracer};
use octrace_tests::repo;

/// The bus: bits a second, bytes a window command, bytes a pixel.
const BUS_HZ: f64 = 31.25e6;
const WINDOW_BYTES: u64 = 11;
const PIXEL_BYTES: u64 = 2;

/// Orders measured: (coarsest, finest); (1, 1) is the direct order.
const ORDERS: [(u32, u32); 6] = [(1, 1), (16, 1), (8, 1), (16, 4), (8, 4), (16, 8)];

/// Counts what a panel is sent: rectangles and their pixels.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
struct Sent {
    rectangles: u64,
    pixels: u64,
}

impl Sent {
    fn bus_ms(&self) -> f64 {
        (self.rectangles * WINDOW_BYTES + self.pixels * PIXEL_BYTES) as f64 * 8.0 / BUS_HZ * 1e3
    }
}

/// A panel that only counts (and takes every colour, so that a streamed
/// row is traced).
struct Bus {
    size: Size,
    sent: Sent,
}

impl OriginDimensions for Bus {
    fn size(&self) -> Size {
        self.size
    }
}

impl DrawTarget for Bus {
    type Color = Rgb888;
    type Error = core::convert::Infallible;

    fn draw_iter<I: IntoIterator<Item = Pixel<Rgb888>>>(&mut self, pixels: I) -> Result<(), Self::Error> {
        // A pixel drawn alone is a window of its own.
        let count = pixels.into_iter().count() as u64;
        self.sent.rectangles += count;
        self.sent.pixels += count;
        Ok(())
    }

    fn fill_contiguous<I: IntoIterator<Item = Rgb888>>(
        &mut self,
        area: &Rectangle,
        colors: I,
    ) -> Result<(), Self::Error> {
        let pixels = area.size.width as u64 * area.size.height as u64;
        let taken = colors.into_iter().take(pixels as usize).count() as u64;
        assert_eq!(taken, pixels, "{area:?} filled");
        self.sent.rectangles += 1;
        self.sent.pixels += pixels;
        Ok(())
    }

    fn fill_solid(&mut self, area: &Rectangle, _: Rgb888) -> Result<(), Self::Error> {
        self.sent.rectangles += 1;
        self.sent.pixels += area.size.width as u64 * area.size.height as u64;
        Ok(())
    }
}

fn main() {
    let mut args: Vec<String> = std::env::args().skip(1).collect();
    let size = match args.first().and_then(|a| a.split_once('x')) {
        Some((w, h)) => {
            let size = Size::new(w.parse().unwrap_or(240), h.parse().unwrap_or(240));
            args.remove(0);
            size
        }
        None => Size::new(240, 240),
    };
    let scene_name = args.first().cloned().unwrap_or_else(|| "fig5_1".to_owned());
    let text = std::fs::read(repo().join("scenes").join(format!("{scene_name}.txt"))).unwrap_or_else(|e| {
        eprintln!("progressive-bench: {scene_name}: {e}");
        std::process::exit(1);
    });
    let mut raytracer = Box::new(Raytracer::<Host>::new());
    let scene = raytracer.load_with(&text, AccelMode::Dda, &mut |_| {}).unwrap_or_else(|e| {
        eprintln!("progressive-bench: {scene_name}: {e}");
        std::process::exit(1);
    });

    println!(
        "| {}×{} order | first pass: traces | rectangles | pixels | bus | all: rectangles (two cores / one) | pixels | bus | more than direct |",
        size.width, size.height
    );
    println!("| --- | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: |");
    let mut direct_ms = None;
    for (coarsest, finest) in ORDERS {
        let order = Progressive::new(size, coarsest).with_finest(finest);
        // Two cores: every unit drawn from its colours.
        let mut bus = Bus { size, sent: Sent::default() };
        let colors = vec![Rgb888::new(0, 0, 0); order.max_unit_pixels()];
        let (mut first, mut traces) = (Sent::default(), 0);
        for unit in order.units() {
            unit.with_colors(&colors).unwrap_or_else(|e| panic!("{e}")).draw(&mut bus).unwrap_or_else(|e| match e {});
            if unit.pass() == 0 {
                first = bus.sent;
                traces += unit.pixel_count();
            }
        }
        let all = bus.sent;
        // One core, tracing.
        let mut bus = Bus { size, sent: Sent::default() };
        let stats = scene.image_for(&bus).progressive(&order).try_draw(&mut bus).unwrap_or_else(|e| panic!("{e}"));
        assert_eq!(bus.sent.pixels, all.pixels, "one core sends the same pixels");
        assert!(stats.rays >= size.width as u64 * size.height as u64, "every pixel traced");
        let direct = *direct_ms.get_or_insert(all.bus_ms());
        let name = match (coarsest, finest) {
            (1, _) => "direct (rows)".to_owned(),
            (c, 1) => format!("mosaic {c} → 1"),
            (c, f) => format!("mosaic {c} → {f}, then rows"),
        };
        println!(
            "| {name} | {traces} | {} | {} | {:.1} ms | {} / {} | {} | {:.1} ms | {:+.1} ms |",
            first.rectangles,
            first.pixels,
            first.bus_ms(),
            all.rectangles,
            bus.sent.rectangles,
            all.pixels,
            all.bus_ms(),
            all.bus_ms() - direct,
        );
    }
}
