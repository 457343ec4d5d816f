//! The studio's state and operations, in safe Rust, independent of how the
//! page calls them (tests call them directly).
//!
//! Invariants: the raytracer holds frame `frame` of `text` once `loaded`,
//! indexed as the last `prepare` said (the player's frames are loaded
//! into it too, indexed the same); an animation's every frame was checked
//! when its text was loaded.

use crate::error::StudioError;
use crate::player::{Player, Refused};
use embedded_graphics_core::geometry::{Point, Size};
use embedded_graphics_core::primitives::Rectangle;
use octrace_core::panel::{Dithering, Panel};
use octrace_core::parse::ParseError;
use octrace_core::profile::Host;
use octrace_core::render::PixelSample;
use octrace_core::scene::Frames;
use octrace_core::{AccelMode, Raytracer};
use octrace_images::formats::{self, Format, Image};
use octrace_images::palette::{self, PaletteMode};
use octrace_images::{panel, RgbImage, SampleImage, NO_OBJECT};

/// The intersection mode the page numbers `code`: 0 auto, 1 naive,
/// 2 octree, 3 dda (the core's order).
pub fn accel_from_code(code: u32) -> Option<AccelMode> {
    AccelMode::ALL.get(code as usize).copied()
}

/// The page's code for `mode`, which [`accel_from_code`] reads back.
pub fn accel_code(mode: AccelMode) -> u32 {
    AccelMode::ALL.iter().position(|&m| m == mode).unwrap_or_default() as u32
}

/// How a finished image is shown: truecolour, one of the four 256-colour
/// modes, a panel's colour depth, or a panel of few levels, dithered.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Display {
    Palette(PaletteMode),
    Rgb565,
    Panel(Panel, Dithering),
}

/// The panels of few levels in the page's order, from code 6.
const PANELS: [Panel; 4] = [Panel::Gray4, Panel::Mono, Panel::Gray2, Panel::BlackWhiteRed];

impl Display {
    /// The display numbered `code` by the page: 0 truecolour, 1 scan,
    /// 2 dither, 3 coarse, 4 gray, 5 rgb565, 6 gray4, 7 mono, 8 gray2,
    /// 9 bwr; a panel of few levels dithered by `dithering`, the code of
    /// its method ([`Dithering::ALL`]'s order: 0 fs-pe, 1 fs, 2 bayer,
    /// 3 nearest).
    pub fn from_codes(code: u32, dithering: u32) -> Option<Display> {
        match code {
            0..=4 => Some(Display::Palette(PaletteMode::ALL[code as usize])),
            5 => Some(Display::Rgb565),
            _ => {
                let panel = PANELS.get(code as usize - 6)?;
                Some(Display::Panel(*panel, *Dithering::ALL.get(dithering as usize)?))
            }
        }
    }
}

/// What [`Studio::load`] found: the scene's RASTER, its objects and, for
/// an animation, its frames.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Loaded {
    pub raster: (u32, u32),
    pub objects: usize,
    pub frames: Option<Frames>,
}

/// One scene (a frame of it, for an animation) in the core's raytracer, as
/// a board holds it, indexed as the page asked, at the render size; and
/// the player that traces an animation's frames one after the other.
pub struct Studio {
    raytracer: Box<Raytracer<Host>>,
    loaded: bool,
    /// The text the scene was parsed from, and its frame.
    text: Vec<u8>,
    frame: u32,
    frames: Option<Frames>,
    /// The mode asked for last.
    accel: AccelMode,
    size: (u32, u32),
    player: Player,
}

impl Default for Studio {
    fn default() -> Self {
        Studio {
            raytracer: Box::new(Raytracer::new()),
            loaded: false,
            text: Vec::new(),
            frame: 0,
            frames: None,
            accel: AccelMode::default(),
            size: (1, 1),
            player: Player::default(),
        }
    }
}

impl Studio {
    /// Parses frame `frame` of `text` (for a scene without FRAMES, the
    /// scene: every frame is the same). An animation's every frame is
    /// checked the first time its text is loaded: a camera that cannot be
    /// set up at any frame is an error at its line and column.
    pub fn load(&mut self, text: &[u8], frame: u32) -> Result<Loaded, StudioError> {
        self.loaded = false;
        self.text.clear();
        self.text.extend_from_slice(text);
        self.frame = frame;
        let frames = self.parse(text, frame)?;
        if frames.is_some_and(|f| f.count > 1) {
            self.player.check(&mut self.raytracer, text).map_err(StudioError::Scene)?;
            // The check loaded frame 0.
            self.parse(text, frame)?;
        }
        self.loaded = true;
        self.frames = frames;
        let view = self.raytracer.view();
        let raster = (view.settings.raster[0], view.settings.raster[1]);
        self.size = raster;
        Ok(Loaded { raster, objects: view.object_count(), frames })
    }

    /// Parses frame `frame` of `text` into the raytracer, indexing nothing
    /// yet: its FRAMES, or its errors.
    fn parse(&mut self, text: &[u8], frame: u32) -> Result<Option<Frames>, StudioError> {
        let mut errors = Vec::new();
        let mut on_error = |e: ParseError<'_>| errors.push(e.to_string());
        match self.raytracer.load_frame_with(text, frame, AccelMode::Naive, &mut on_error) {
            Ok(scene) => Ok(scene.frames()),
            Err(_) => Err(StudioError::Scene(errors)),
        }
    }

    /// Sets the image size and indexes the scene as `accel` says; returns
    /// the mode used (never `Auto`).
    pub fn prepare(&mut self, accel: AccelMode, width: u32, height: u32) -> Result<AccelMode, StudioError> {
        if !self.loaded {
            return Err(StudioError::NoScene);
        }
        self.raytracer.view().check_camera(width, height).map_err(|e| StudioError::Camera(format!("{e:?}")))?;
        self.size = (width, height);
        self.accel = accel;
        let scene = self.raytracer.reindex(accel, |beside, here| {
            here();
            beside();
        });
        Ok(scene.mode())
    }

    /// Renders the rectangle at (`x`, `y`) of `width`×`height` pixels into
    /// `out`: its colours (RGB, row-major), then the object under each pixel
    /// (little-endian `u32`, [`NO_OBJECT`] for the background).
    pub fn render_rect(&self, x: u32, y: u32, width: u32, height: u32, out: &mut Vec<u8>) -> Result<(), StudioError> {
        let Some(scene) = self.raytracer.indexed().filter(|_| self.loaded) else { return Err(StudioError::NoScene) };
        let (w, h) = self.size;
        if x.checked_add(width).is_none_or(|r| r > w) || y.checked_add(height).is_none_or(|b| b > h) {
            return Err(StudioError::BadInput("the rectangle is outside the image"));
        }
        let count = width as usize * height as usize;
        let (mut colours, mut objects) = (vec![0; 3 * count], vec![NO_OBJECT; count]);
        let mut pixels = SampleImage { colours: &mut colours, objects: &mut objects, size: Size::new(width, height) };
        let area = Rectangle::new(Point::new(x as i32, y as i32), Size::new(width, height));
        let image = scene.image::<PixelSample>(Size::new(w, h)).area(area);
        image.try_draw(&mut pixels).map_err(|e| StudioError::Camera(format!("{e:?}")))?;
        out.clear();
        out.reserve(7 * count);
        out.extend_from_slice(&colours);
        out.extend(objects.iter().flat_map(|o| o.to_le_bytes()));
        Ok(())
    }

    /// Traces the loaded frame whole, at the prepared size, into `out` as
    /// [`Studio::render_rect`] writes it; for an animation, re-tracing only
    /// what can have changed since the frame the player traced last when
    /// that was a frame of the same text at the same size (the core's
    /// coherence: the same bits as a frame traced whole). Returns how many
    /// pixels it traced.
    pub fn trace_frame(&mut self, out: &mut Vec<u8>) -> Result<u64, StudioError> {
        if !self.loaded {
            return Err(StudioError::NoScene);
        }
        let text = std::str::from_utf8(&self.text).map_err(|_| StudioError::BadInput("the scene is not UTF-8"))?;
        let traced =
            self.player.trace(&mut self.raytracer, (text, self.frame), self.accel, self.size).map_err(|e| match e {
                Refused::Scene(errors) => StudioError::Scene(errors),
                Refused::Setup(why) => StudioError::Motion(why),
            })?;
        self.player.write(out);
        Ok(traced)
    }
}

/// Splits `input` (colours then objects, as [`Studio::render_rect`] writes
/// them) into an image and its objects.
pub fn split_render(width: u32, height: u32, input: &[u8]) -> Result<(RgbImage, Vec<u32>), StudioError> {
    let count = width as usize * height as usize;
    if input.len() != 7 * count || count == 0 {
        return Err(StudioError::BadInput("the image buffer does not match its size"));
    }
    let (colours, objects) = input.split_at(3 * count);
    let objects = objects.chunks_exact(4).map(|b| u32::from_le_bytes([b[0], b[1], b[2], b[3]])).collect();
    Ok((RgbImage { width, height, data: colours.to_vec() }, objects))
}

/// The image as `display` shows it: indexed for the 256-colour modes,
/// truecolour otherwise.
pub fn display(image: &RgbImage, objects: &[u32], display: Display) -> Image {
    match display {
        Display::Palette(mode) => palette::apply(image, objects, mode),
        Display::Rgb565 => Image::Rgb(panel::rgb565(image)),
        // As RGB, so that a saved file is the picture shown whatever the format.
        Display::Panel(shown, dithering) => Image::Rgb(panel::dithered(image, shown, dithering).to_rgb()),
    }
}

/// `image` as a file of `format`.
pub fn encode(image: &Image, format: Format) -> Result<Vec<u8>, StudioError> {
    let mut bytes = Vec::new();
    formats::write(image, format, &mut bytes).map_err(StudioError::Image)?;
    Ok(bytes)
}

/// An image file's pixels.
pub fn decode(bytes: &[u8]) -> Result<RgbImage, StudioError> {
    formats::read(bytes).map(|image| image.to_rgb()).map_err(StudioError::Image)
}

#[cfg(test)]
mod tests {
    use super::*;

    const SCENE: &[u8] = b"VIEWPOINT 0 0 5\nRASTER 8 6\nLIGHT 5 3 3 3\nSPHERE 1 1 0 0 0\nSURFACE 1 0.1 0.1 0.1 0.8 0.2 0.2 0.5 0.5 0.5 20 0 0\n";

    #[test]
    fn every_mode_renders_the_same_bits_in_any_pieces() {
        let mut studio = Studio::default();
        assert_eq!(studio.load(SCENE, 0).unwrap(), Loaded { raster: (8, 6), objects: 1, frames: None });
        studio.prepare(AccelMode::Naive, 8, 6).unwrap();
        let mut whole = Vec::new();
        studio.render_rect(0, 0, 8, 6, &mut whole).unwrap();
        let (image, objects) = split_render(8, 6, &whole).unwrap();
        assert!(objects.contains(&0) && objects.contains(&NO_OBJECT));
        for accel in [AccelMode::Octree, AccelMode::Dda, AccelMode::Auto] {
            studio.prepare(accel, 8, 6).unwrap();
            let mut piece = Vec::new();
            studio.render_rect(3, 2, 4, 3, &mut piece).unwrap();
            for (i, p) in piece[..36].chunks(3).enumerate() {
                let (x, y) = (3 + i as u32 % 4, 2 + i as u32 / 4);
                assert_eq!(p, image.pixel(x, y), "{accel:?} at {x},{y}");
            }
        }
    }

    #[test]
    fn every_mode_has_the_code_the_page_reads_back() {
        for mode in AccelMode::ALL {
            assert_eq!(accel_from_code(accel_code(mode)), Some(mode), "{mode}");
        }
    }

    #[test]
    fn errors_come_with_line_and_column() {
        let mut studio = Studio::default();
        let Err(StudioError::Scene(errors)) = studio.load(b"VIEWPOINT 0 0 5\nSPHERE 1 x 0 0 0\n", 0) else {
            panic!("the scene has an error")
        };
        assert!(errors[0].starts_with("2:10:"), "{errors:?}");
        assert!(matches!(studio.prepare(AccelMode::Naive, 4, 4), Err(StudioError::NoScene)));
    }

    #[test]
    fn rectangles_outside_the_image_are_refused() {
        let mut studio = Studio::default();
        studio.load(SCENE, 0).unwrap();
        studio.prepare(AccelMode::Naive, 8, 6).unwrap();
        let mut out = Vec::new();
        assert!(studio.render_rect(5, 0, 4, 1, &mut out).is_err());
        assert!(studio.render_rect(u32::MAX, 0, 2, 1, &mut out).is_err());
    }

    /// `text`'s frame `frame` at `size`, traced whole with `accel`.
    fn frame_traced_whole(text: &[u8], frame: u32, accel: AccelMode, (w, h): (u32, u32)) -> Vec<u8> {
        let mut studio = Studio::default();
        studio.load(text, frame).unwrap();
        studio.prepare(accel, w, h).unwrap();
        let mut out = Vec::new();
        studio.render_rect(0, 0, w, h, &mut out).unwrap();
        out
    }

    #[test]
    fn frames_played_in_turn_are_the_frames_traced_whole_and_retrace_less() {
        let text = include_bytes!("../../scenes/anim_fig5_1.txt");
        let (w, h) = (48, 36);
        let pixels = u64::from(w * h);
        let mut studio = Studio::default();
        let mut play = |frame: u32, accel: AccelMode| {
            let loaded = studio.load(text, frame).unwrap();
            assert_eq!(loaded.frames.map(|f| (f.count, f.rate)), Some((48, 24)));
            studio.prepare(accel, w, h).unwrap();
            let mut out = Vec::new();
            let traced = studio.trace_frame(&mut out).unwrap();
            assert_eq!(out, frame_traced_whole(text, frame, AccelMode::Naive, (w, h)), "frame {frame}");
            traced
        };
        assert_eq!(play(0, AccelMode::Dda), pixels, "the first frame is traced whole");
        // One step, several at once, round the loop past the last frame:
        // fewer pixels, the same bits, in any mode.
        let mut retraced = 0;
        for (frame, accel) in [(1, AccelMode::Dda), (2, AccelMode::Naive), (5, AccelMode::Octree), (47, AccelMode::Dda)]
        {
            retraced += play(frame, accel);
        }
        for frame in [0, 1] {
            retraced += play(frame, AccelMode::Auto);
        }
        assert!(retraced < 6 * pixels / 2, "{retraced} pixels re-traced in 6 frames of {pixels}");
        assert_eq!(play(1, AccelMode::Dda), 0, "the frame shown again traces nothing");
        // Backwards is round the loop: the same bits.
        play(0, AccelMode::Dda);
        // Another text starts again from every tile.
        let other = [&text[..], b"\n/* edited */\n"].concat();
        studio.load(&other, 1).unwrap();
        studio.prepare(AccelMode::Dda, w, h).unwrap();
        assert_eq!(studio.trace_frame(&mut Vec::new()).unwrap(), pixels);
    }

    #[test]
    fn an_animation_whose_camera_breaks_at_a_later_frame_does_not_load_at_any_frame() {
        // The eye moves onto the point looked at at frame 2.
        let text = b"FRAMES 3\nVIEWPOINT 0 0 5 MOVE 0 0 0 0  2 0 0 -5\nORIGIN 0 0 0\n\
            SURFACE 1 .1 .1 .1 .7 .2 .2 0 0 0 1 0 0\nLIGHT 10 5 5 5\nSPHERE 1 1 0 0 3\n";
        let mut studio = Studio::default();
        for frame in [0, 1] {
            let Err(StudioError::Scene(errors)) = studio.load(text, frame) else { panic!("frame {frame} loads") };
            assert_eq!(errors, ["2:17: at frame 2, VIEWPOINT equals ORIGIN: there is no view direction"]);
        }
        assert!(matches!(studio.prepare(AccelMode::Naive, 4, 4), Err(StudioError::NoScene)));
    }

    #[test]
    fn files_round_trip_and_panels_reduce_colour() {
        let image = RgbImage { width: 2, height: 1, data: vec![255, 128, 7, 0, 0, 0] };
        for format in [Format::Png, Format::Tga, Format::Ras] {
            let bytes = encode(&Image::Rgb(image.clone()), format).unwrap();
            assert_eq!(decode(&bytes).unwrap(), image);
        }
        let panel = display(&image, &[NO_OBJECT; 2], Display::Rgb565).to_rgb();
        assert_eq!(panel.pixel(0, 0), [255, 130, 8]);
        let gray = display(&image, &[NO_OBJECT; 2], Display::from_codes(6, 0).unwrap()).to_rgb();
        assert!(gray.data.chunks(3).all(|p| p[0] == p[1] && p[1] == p[2]));
        let mono = display(&image, &[NO_OBJECT; 2], Display::from_codes(7, 2).unwrap()).to_rgb();
        assert!(mono.data.iter().all(|&v| v == 0 || v == 255));
        assert_eq!(Display::from_codes(9, 3), Some(Display::Panel(Panel::BlackWhiteRed, Dithering::Nearest)));
        assert_eq!(Display::from_codes(10, 0), None);
        assert_eq!(Display::from_codes(7, 4), None);
        assert!(decode(b"not an image").is_err());
    }
}
