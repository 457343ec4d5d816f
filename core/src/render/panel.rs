//! The pixel formats of the displays octrace is shown on, named once for the
//! firmware's `OCTRACE_COLOR`, host-sim's `--color` previews and the tests.

/// How a display takes its pixels. Each is an embedded-graphics colour type
/// the renderer converts to, except `Dither`, which is
/// [`palette::Dither`](crate::palette::Dither)'s indices into the 6×6×6
/// colour cube.
///
/// ```
/// use octrace_core::render::PanelColor;
///
/// assert_eq!(PanelColor::from_name("RGB565"), Some(PanelColor::Rgb565));
/// assert_eq!(PanelColor::Gray4.name(), "gray4");
/// assert_eq!(PanelColor::from_name("cmyk"), None);
/// ```
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum PanelColor {
    /// 8 bits a channel (`Rgb888`).
    #[default]
    Rgb888,
    /// 5, 6 and 5 bits (`Rgb565`), as most SPI colour panels take them.
    Rgb565,
    /// 16 gray levels (`Gray4`), as small OLEDs such as the SSD0323 show.
    Gray4,
    /// One byte a pixel: an index into the ordered-dithered 6×6×6 cube.
    Dither,
}

impl PanelColor {
    /// Every format, in the order of their names in messages.
    pub const ALL: [PanelColor; 4] = [PanelColor::Rgb888, PanelColor::Rgb565, PanelColor::Gray4, PanelColor::Dither];

    /// The format's name: `rgb888`, `rgb565`, `gray4`, `dither`.
    pub const fn name(self) -> &'static str {
        match self {
            PanelColor::Rgb888 => "rgb888",
            PanelColor::Rgb565 => "rgb565",
            PanelColor::Gray4 => "gray4",
            PanelColor::Dither => "dither",
        }
    }

    /// The format its name stands for (case-insensitive).
    pub fn from_name(name: &str) -> Option<PanelColor> {
        PanelColor::ALL.into_iter().find(|c| c.name().eq_ignore_ascii_case(name))
    }
}

impl core::fmt::Display for PanelColor {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        f.write_str(self.name())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_name_reads_back() {
        for color in PanelColor::ALL {
            assert_eq!(PanelColor::from_name(color.name()), Some(color));
        }
    }
}
