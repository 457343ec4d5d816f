//! The board's display: an embedded-graphics `DrawTarget` that streams each
//! scanline to a host file over semihosting, as an SPI display driver
//! streams it to the panel. It holds one small chunk of bytes, never a
//! framebuffer.
//!
//! Pixel formats: `Rgb888` (3 bytes a pixel), `Rgb565` (2 bytes, big
//! endian, as common SPI displays take it), `PaletteIndex` (1 byte, an
//! entry of the display's 256-colour table), and a byte a pixel holding
//! the level of a panel of few levels: `BinaryColor` (0 or 1), `Gray2`
//! (0 to 3), `Gray4` (0 to 15), `BlackWhiteRed` (0 black, 1 white, 2 red).

use crate::semihosting::HostFile;
use embedded_graphics_core::draw_target::DrawTarget;
use embedded_graphics_core::geometry::{OriginDimensions, Size};
use embedded_graphics_core::pixelcolor::{
    BinaryColor, Gray2, Gray4, GrayColor, IntoStorage, PixelColor, Rgb565, Rgb888, RgbColor,
};
use embedded_graphics_core::primitives::Rectangle;
use embedded_graphics_core::Pixel;
use octrace_core::palette::PaletteIndex;
use octrace_core::panel::BlackWhiteRed;

/// How a colour goes on the wire.
pub trait WireColor: PixelColor {
    const BYTES: usize;
    fn encode(self, out: &mut [u8]);
}

impl WireColor for Rgb888 {
    const BYTES: usize = 3;
    fn encode(self, out: &mut [u8]) {
        out.copy_from_slice(&[self.r(), self.g(), self.b()]);
    }
}

impl WireColor for PaletteIndex {
    const BYTES: usize = 1;
    fn encode(self, out: &mut [u8]) {
        out[0] = self.0;
    }
}

impl WireColor for BinaryColor {
    const BYTES: usize = 1;
    fn encode(self, out: &mut [u8]) {
        out[0] = self.is_on() as u8;
    }
}

impl WireColor for Gray2 {
    const BYTES: usize = 1;
    fn encode(self, out: &mut [u8]) {
        out[0] = self.luma();
    }
}

impl WireColor for Gray4 {
    const BYTES: usize = 1;
    fn encode(self, out: &mut [u8]) {
        out[0] = self.luma();
    }
}

impl WireColor for BlackWhiteRed {
    const BYTES: usize = 1;
    fn encode(self, out: &mut [u8]) {
        out[0] = self as u8;
    }
}

impl WireColor for Rgb565 {
    const BYTES: usize = 2;
    fn encode(self, out: &mut [u8]) {
        out.copy_from_slice(&self.into_storage().to_be_bytes());
    }
}

/// Pixels written since the last error, in raster order.
pub struct StreamDisplay<C> {
    file: HostFile,
    size: Size,
    chunk: [u8; 96],
    used: usize,
    _color: core::marker::PhantomData<C>,
}

/// Why a write failed.
#[derive(Debug)]
pub enum WriteError {
    /// The host refused the bytes.
    Host,
    /// Single pixels: a stream only takes whole rows, in raster order.
    Unsupported,
}

impl<C: WireColor> StreamDisplay<C> {
    pub fn new(file: HostFile, size: Size) -> Self {
        StreamDisplay { file, size, chunk: [0; 96], used: 0, _color: core::marker::PhantomData }
    }

    fn push(&mut self, c: C) -> Result<(), WriteError> {
        if self.used + C::BYTES > self.chunk.len() {
            self.flush()?;
        }
        c.encode(&mut self.chunk[self.used..self.used + C::BYTES]);
        self.used += C::BYTES;
        Ok(())
    }

    pub fn flush(&mut self) -> Result<(), WriteError> {
        let ok = self.file.write(&self.chunk[..self.used]);
        self.used = 0;
        ok.then_some(()).ok_or(WriteError::Host)
    }
}

impl<C> OriginDimensions for StreamDisplay<C> {
    fn size(&self) -> Size {
        self.size
    }
}

impl<C: WireColor> DrawTarget for StreamDisplay<C> {
    type Color = C;
    type Error = WriteError;

    /// A stream cannot go back: only whole rows, in raster order, through
    /// `fill_contiguous` (which is how octrace's renderer draws).
    fn draw_iter<I>(&mut self, pixels: I) -> Result<(), WriteError>
    where
        I: IntoIterator<Item = Pixel<C>>,
    {
        match pixels.into_iter().next() {
            None => Ok(()),
            Some(_) => Err(WriteError::Unsupported),
        }
    }

    fn fill_contiguous<I>(&mut self, area: &Rectangle, colors: I) -> Result<(), WriteError>
    where
        I: IntoIterator<Item = C>,
    {
        let count = area.size.width as usize * area.size.height as usize;
        for c in colors.into_iter().take(count) {
            self.push(c)?;
        }
        self.flush()
    }
}
