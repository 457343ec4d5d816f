//! What every draw of a [`TracedImage`] runs, whichever picture it asks
//! for: a renderer from the draw's source (the loading core's room, or
//! another core's), then an area of a still, the progressive order, or a
//! frame's bands of tiles, into the target converted or dithered. Which
//! pixels a draw traces, and in what order, is decided here (a pixel's
//! tracing itself is the renderer's).
//!
//! Invariants: one renderer a draw, its counters added to the loaded
//! scene's; a draw asked to stop ends within a ray, having drawn only
//! pixels that are the picture's (a frame's tiles not drawn keep their
//! mark to be traced); a draw that asks nothing runs the tracer without
//! any of the asking.

use super::picture::{sealed::Kind, Picture as Drawn};
use super::{DrawError, RendererRoom, ScreenLists};
use crate::accel::{Linked, SceneAccelerator};
use crate::animation::Playing;
use crate::motion::Lookout;
use crate::panel::{Dithered, Dithering, TracedColor, IMAGE_ERROR_WORDS};
use crate::profile::Profile;
use crate::render::{clipped, Halt, Progressive, Renderer};
use crate::scene::{CameraError, SceneView, MAX_SIDE};
use crate::shade::{Poll, Stats};
use core::cell::{Cell, RefCell};
use embedded_graphics_core::draw_target::DrawTarget;
use embedded_graphics_core::geometry::{Dimensions, Point, Size};
use embedded_graphics_core::primitives::Rectangle;
use embedded_graphics_core::Pixel;

/// Where a draw's renderer comes from: a scene's view and accelerator,
/// and the room its renderer traces in.
pub(super) struct Source<'s, 'r, P: Profile> {
    pub view: &'s SceneView<'r>,
    pub accelerator: &'s SceneAccelerator<'r, P>,
    pub first_hits: bool,
    pub room: &'s RendererRoom<P>,
    /// The loaded scene's counters, which each draw adds to.
    pub stats: Option<&'s Cell<Stats>>,
}

impl<P: Profile> Clone for Source<'_, '_, P> {
    fn clone(&self) -> Self {
        *self
    }
}

impl<P: Profile> Copy for Source<'_, '_, P> {}

impl<'r, P: Profile> Source<'_, 'r, P> {
    /// Runs `f` with a renderer of an image of `size` in the source's room
    /// (none of it if a draw holds it already: only a display that draws
    /// from inside a draw; the render goes without, the same image),
    /// watching the motion to come with `lookout` if given.
    pub(super) fn with_renderer<R>(
        &self,
        size: Size,
        lookout: Option<Lookout<'_>>,
        f: impl FnOnce(&mut Renderer<'_, P>) -> R,
    ) -> Result<R, CameraError> {
        let mut room = self.room.room.try_borrow_mut();
        let (mailbox, lists) = match room.as_deref_mut() {
            Ok(room) => {
                let (mailbox, lists) = room.prepare(self.view.object_count(), self.first_hits);
                (Some(mailbox), lists)
            }
            Err(_) => (None, None),
        };
        let mut renderer = renderer_in(*self.view, self.accelerator, size, mailbox, lists)?;
        renderer.set_lookout(lookout);
        let result = f(&mut renderer);
        if let Some(stats) = self.stats {
            let mut total = stats.get();
            total.add(&renderer.stats());
            stats.set(total);
        }
        Ok(result)
    }
}

/// A renderer over `view` for an image of `size`, with a mailbox and screen
/// lists where given. Inlined: a board's renderer is made in place.
#[inline(always)]
pub(super) fn renderer_in<'a, L: Linked>(
    view: SceneView<'a>,
    accel: &'a SceneAccelerator<'a, L>,
    size: Size,
    mailbox: Option<&'a mut [u32]>,
    lists: Option<ScreenLists<'a>>,
) -> Result<Renderer<'a, L>, CameraError> {
    let mut renderer = Renderer::with_size(view, accel, size.width, size.height)?;
    if let Some(words) = mailbox {
        renderer.set_mailbox(words);
    }
    if let Some((lists, mirror)) = lists {
        renderer.set_first_hits(lists, mirror);
    }
    Ok(renderer)
}

/// What a [`TracedImage`](super::TracedImage) asks to be drawn: its
/// source, its size, its options.
pub(super) struct Request<'s, 'r, P: Profile> {
    pub source: Source<'s, 'r, P>,
    pub size: Size,
    pub dithering: Dithering,
    pub picture: Picture<'s>,
    /// Error diffusion's rows, if the caller gives them.
    pub rows: Option<&'s RefCell<[i16]>>,
}

impl<P: Profile> Clone for Request<'_, '_, P> {
    fn clone(&self) -> Self {
        *self
    }
}

impl<P: Profile> Copy for Request<'_, '_, P> {}

/// What an image draws.
#[derive(Clone, Copy)]
pub(super) enum Picture<'s> {
    /// A still's pixels in this rectangle (of the image), with its top-left
    /// pixel at the target's origin.
    Area(Rectangle),
    /// A still whole, in the progressive order.
    Progressive(&'s Progressive),
    /// A still's areas, the next `next` gives until it gives none, each at
    /// its place in the image.
    Areas(&'s dyn Fn() -> Option<Rectangle>),
    /// A frame's planned tiles: every band, or the next band `next` gives
    /// until it gives none.
    Bands(Playing<'s>, Option<&'s dyn Fn() -> Option<u32>>),
}

impl<'s> Picture<'s> {
    /// What an image of `size` draws at first: a frame's planned tiles
    /// (`playing`), or the whole still.
    pub(super) fn whole(size: Size, playing: Option<Playing<'s>>) -> Self {
        match playing {
            Some(playing) => Picture::Bands(playing, None),
            None => Picture::Area(Rectangle::new(Point::zero(), size)),
        }
    }
}

/// Draws what `image` asks into `target`, `poll` asked before every ray:
/// the picture `K`, whose code alone a draw of it links.
pub(super) fn draw<P, C, K, D, Q>(
    image: &Request<'_, '_, P>,
    target: &mut D,
    poll: &mut Q,
) -> Result<Stats, DrawError<D::Error>>
where
    P: Profile,
    C: TracedColor,
    K: Drawn,
    D: DrawTarget<Color = C>,
    Q: Poll,
{
    let (width, height) = (image.size.width, image.size.height);
    if width > MAX_SIDE || height > MAX_SIDE {
        // The camera would trace a picture of at most that, clipped.
        return Err(DrawError::TooLarge { width, height });
    }
    // Matched on `K`'s constant first: the other pictures' arms are dead
    // code in this instance.
    match (K::KIND, image.picture) {
        (Kind::Bands, Picture::Bands(playing, next)) => match C::PANEL {
            // Ordered dithering, which needs no order: a changed tile
            // draws the same whatever was drawn around it.
            Some(_) => bands(image, &playing, next, &mut Dithered::ordered(target), poll),
            None => bands(image, &playing, next, target, poll),
        },
        (Kind::InOrder, Picture::Progressive(order)) => {
            drawn(image.source.with_renderer(order.size(), None, |renderer| match C::PANEL {
                // Bayer too: the one method a block order keeps.
                Some(_) => order.render_polled(renderer, &mut Dithered::ordered(target), poll),
                None => order.render_polled(renderer, target, poll),
            }))
        }
        (Kind::Areas, Picture::Areas(next)) => {
            let mut shifted = Shifted { target, offset: Point::zero() };
            match C::PANEL {
                // Ordered, as a frame's tiles: no order between areas.
                Some(_) => still(image, &mut || next(), &mut Dithered::ordered(&mut shifted), poll),
                None => still(image, &mut || next(), &mut shifted, poll),
            }
        }
        (Kind::Still, Picture::Area(area)) => {
            let mut shifted = Shifted { target, offset: Point::zero() - area.top_left };
            // The pixels there are: the rows a ditherer is set up for.
            let area = clipped(&area, image.size);
            match (C::PANEL, image.rows) {
                (None, _) => {
                    let mut one = Some(area);
                    still(image, &mut || one.take(), &mut shifted, poll)
                }
                (Some(_), Some(given)) => match given.try_borrow_mut() {
                    Ok(mut given) => dithered(image, &area, &mut shifted, &mut given, poll),
                    Err(_) => dithered_on_stack::<IMAGE_ERROR_WORDS, _, _, _, _>(image, &area, &mut shifted, poll),
                },
                // A small panel's row in a small frame.
                (Some(panel), None) if panel.error_words(area.size.width) <= SMALL_ERROR_WORDS => {
                    dithered_on_stack::<SMALL_ERROR_WORDS, _, _, _, _>(image, &area, &mut shifted, poll)
                }
                (Some(_), None) => dithered_on_stack::<IMAGE_ERROR_WORDS, _, _, _, _>(image, &area, &mut shifted, poll),
            }
        }
        // Never: an image's type and its picture are set together.
        _ => Ok(Stats::default()),
    }
}

/// A still's areas, the next `next` gives until it gives none (each
/// clipped to the image), into `target`, through one renderer: the one
/// loop of a still in areas, so that a board links it once whether it
/// draws one area or many.
fn still<P, D, Q>(
    image: &Request<'_, '_, P>,
    next: &mut dyn FnMut() -> Option<Rectangle>,
    target: &mut D,
    poll: &mut Q,
) -> Result<Stats, DrawError<D::Error>>
where
    P: Profile,
    D: DrawTarget,
    D::Color: TracedColor,
    Q: Poll,
{
    drawn(image.source.with_renderer(image.size, None, |renderer| {
        let mut stats = Stats::default();
        while let Some(area) = next() {
            stats.add(&rows(renderer, &clipped(&area, image.size), target, poll)?);
        }
        Ok(stats)
    }))
}

/// What a renderer's draw ended with, as a draw's result.
fn drawn<E, S>(drawn: Result<Result<Stats, Halt<E, S>>, CameraError>) -> Result<Stats, DrawError<E>> {
    match drawn {
        Ok(Ok(stats)) => Ok(stats),
        Ok(Err(Halt::Sink(e))) => Err(DrawError::Target(e)),
        Ok(Err(Halt::Stopped(_))) => Err(DrawError::Stopped),
        Err(e) => Err(DrawError::Camera(e)),
    }
}

/// The error row of a panel image up to 256 `i16`s wide (a one-bit 128×64
/// OLED needs 128) takes only this much of the draw's stack (512 bytes).
const SMALL_ERROR_WORDS: usize = 256;

/// A frame's bands (every one, or those `next` gives) into `target`:
/// each planned run of tiles row by row, in one `fill_contiguous` a row.
fn bands<P, D, Q>(
    image: &Request<'_, '_, P>,
    playing: &Playing<'_>,
    next: Option<&dyn Fn() -> Option<u32>>,
    target: &mut D,
    poll: &mut Q,
) -> Result<Stats, DrawError<D::Error>>
where
    P: Profile,
    D: DrawTarget,
    D::Color: TracedColor,
    Q: Poll,
{
    let coherence = playing.coherence;
    let mut all = 0..coherence.bands();
    let mut taken = || match next {
        Some(next) => next(),
        None => all.next(),
    };
    drawn(image.source.with_renderer(coherence.size(), playing.lookout(), |renderer| {
        let mut stats = Stats::default();
        while let Some(band) = taken() {
            stats.add(&coherence.trace_band(renderer, band, poll, &mut |line, pixels| {
                target.fill_contiguous(line, pixels.map(|p| D::Color::traced(p.color, p.object)))
            })?);
        }
        Ok(stats)
    }))
}

/// The rows of `area` (of the image) into `target`, each in one
/// `fill_contiguous`; a row stopped inside is handed over up to the
/// stopped pixel. Returns the counters of the rows.
fn rows<L, D, Q>(
    renderer: &mut Renderer<'_, L>,
    area: &Rectangle,
    target: &mut D,
    poll: &mut Q,
) -> Result<Stats, Halt<D::Error, Q::Stopped>>
where
    L: crate::accel::Linked,
    D: DrawTarget,
    D::Color: TracedColor,
    Q: Poll,
{
    if !Q::ASKS {
        // Nothing asked: the renderer's own loop, as fast as a still's.
        return renderer.render_rect(area, target).map_err(Halt::Sink);
    }
    let before = renderer.stats();
    let x0 = area.top_left.x as u32;
    for y in area.rows() {
        let line = Rectangle::new(Point::new(x0 as i32, y), Size::new(area.size.width, 1));
        let mut halted = None;
        let pixels = (x0..x0 + area.size.width).map_while(|x| match renderer.pixel_polled(x, y as u32, poll) {
            Ok(p) => Some(D::Color::traced(p.color, p.object)),
            Err(stopped) => {
                halted = Some(stopped);
                None
            }
        });
        target.fill_contiguous(&line, pixels).map_err(Halt::Sink)?;
        if let Some(stopped) = halted {
            return Err(Halt::Stopped(stopped));
        }
    }
    Ok(renderer.stats().since(&before))
}

/// A still's `area` dithered, its error row of `WORDS` on this frame. Not
/// inlined: a truecolour draw never holds the row.
#[inline(never)]
fn dithered_on_stack<const WORDS: usize, P, C, D, Q>(
    image: &Request<'_, '_, P>,
    area: &Rectangle,
    target: &mut D,
    poll: &mut Q,
) -> Result<Stats, DrawError<D::Error>>
where
    P: Profile,
    C: TracedColor,
    D: DrawTarget<Color = C>,
    Q: Poll,
{
    dithered(image, area, target, &mut [0; WORDS], poll)
}

/// A still's `area` dithered across its width, error diffusion's rows in
/// `rows`. Not inlined: one copy of the render loop whatever frame the
/// row is in.
#[inline(never)]
fn dithered<P, C, D, Q>(
    image: &Request<'_, '_, P>,
    area: &Rectangle,
    target: &mut D,
    rows: &mut [i16],
    poll: &mut Q,
) -> Result<Stats, DrawError<D::Error>>
where
    P: Profile,
    C: TracedColor,
    D: DrawTarget<Color = C>,
    Q: Poll,
{
    let (left, width) = (area.top_left.x, area.size.width);
    let mut dithered = Dithered::across(target, image.dithering, left, width, rows).map_err(DrawError::ErrorRow)?;
    drawn(image.source.with_renderer(image.size, None, |renderer| self::rows(renderer, area, &mut dithered, poll)))
}

/// A target seen shifted by `offset`: a sub-image's pixels land at the
/// target's origin.
struct Shifted<'t, D> {
    target: &'t mut D,
    offset: Point,
}

impl<D: DrawTarget> Dimensions for Shifted<'_, D> {
    fn bounding_box(&self) -> Rectangle {
        let b = self.target.bounding_box();
        Rectangle::new(b.top_left - self.offset, b.size)
    }
}

impl<D: DrawTarget> DrawTarget for Shifted<'_, D> {
    type Color = D::Color;
    type Error = D::Error;

    fn draw_iter<I: IntoIterator<Item = Pixel<D::Color>>>(&mut self, pixels: I) -> Result<(), D::Error> {
        let offset = self.offset;
        self.target.draw_iter(pixels.into_iter().map(|Pixel(p, c)| Pixel(p + offset, c)))
    }

    fn fill_contiguous<I: IntoIterator<Item = D::Color>>(
        &mut self,
        area: &Rectangle,
        colors: I,
    ) -> Result<(), D::Error> {
        self.target.fill_contiguous(&Rectangle::new(area.top_left + self.offset, area.size), colors)
    }
}
