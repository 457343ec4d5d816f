//! The pixel formats of the displays octrace is shown on, named once for the
//! firmware's `OCTRACE_COLOR`, host-sim's `--color` previews and the tests.

use crate::panel::Panel;

/// How a display takes its pixels. Each is an embedded-graphics colour type
/// the renderer converts to or dithers onto (a [`Panel`]), except
/// `Dither`, which is [`palette::Dither`](crate::palette::Dither)'s indices
/// into the 6×6×6 colour cube.
///
/// ```
/// use octrace_core::{panel::Panel, render::PanelColor};
///
/// assert_eq!(PanelColor::from_name("RGB565"), Some(PanelColor::Rgb565));
/// assert_eq!(PanelColor::Gray4.name(), "gray4");
/// assert_eq!(PanelColor::Mono.panel(), Some(Panel::Mono));
/// assert_eq!(PanelColor::from(Panel::BlackWhiteRed), PanelColor::Bwr);
/// assert_eq!(PanelColor::from_name("cmyk"), None);
/// ```
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum PanelColor {
    /// 8 bits a channel (`Rgb888`).
    #[default]
    Rgb888,
    /// 5, 6 and 5 bits (`Rgb565`), as most SPI colour panels take them.
    Rgb565,
    /// One bit (`BinaryColor`), dithered: an SSD1306 OLED, black-and-white
    /// e-paper.
    Mono,
    /// 4 gray levels (`Gray2`), dithered: 4-gray e-paper.
    Gray2,
    /// 16 gray levels (`Gray4`), dithered, as small OLEDs such as the SSD0323
    /// and SSD1327 show.
    Gray4,
    /// Black, white and red e-paper
    /// ([`BlackWhiteRed`](crate::panel::BlackWhiteRed)), dithered.
    Bwr,
    /// One byte a pixel: an index into the ordered-dithered 6×6×6 cube.
    Dither,
}

impl PanelColor {
    /// Every format, in the order of their names in messages.
    pub const ALL: [PanelColor; 7] = [
        PanelColor::Rgb888,
        PanelColor::Rgb565,
        PanelColor::Mono,
        PanelColor::Gray2,
        PanelColor::Gray4,
        PanelColor::Bwr,
        PanelColor::Dither,
    ];

    /// The format's name: `rgb888`, `rgb565`, `mono`, `gray2`, `gray4`,
    /// `bwr`, `dither`.
    pub const fn name(self) -> &'static str {
        match self {
            PanelColor::Rgb888 => "rgb888",
            PanelColor::Rgb565 => "rgb565",
            PanelColor::Mono => "mono",
            PanelColor::Gray2 => "gray2",
            PanelColor::Gray4 => "gray4",
            PanelColor::Bwr => "bwr",
            PanelColor::Dither => "dither",
        }
    }

    /// The format its name stands for (case-insensitive).
    pub fn from_name(name: &str) -> Option<PanelColor> {
        PanelColor::ALL.into_iter().find(|c| c.name().eq_ignore_ascii_case(name))
    }

    /// The panel of few levels it is, dithered; `None` for the others.
    pub const fn panel(self) -> Option<Panel> {
        match self {
            PanelColor::Mono => Some(Panel::Mono),
            PanelColor::Gray2 => Some(Panel::Gray2),
            PanelColor::Gray4 => Some(Panel::Gray4),
            PanelColor::Bwr => Some(Panel::BlackWhiteRed),
            PanelColor::Rgb888 | PanelColor::Rgb565 | PanelColor::Dither => None,
        }
    }
}

impl From<Panel> for PanelColor {
    fn from(panel: Panel) -> PanelColor {
        match panel {
            Panel::Mono => PanelColor::Mono,
            Panel::Gray2 => PanelColor::Gray2,
            Panel::Gray4 => PanelColor::Gray4,
            Panel::BlackWhiteRed => PanelColor::Bwr,
        }
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

    #[test]
    fn every_panel_has_its_format() {
        for panel in Panel::ALL {
            assert_eq!(PanelColor::from(panel).panel(), Some(panel));
        }
    }
}
