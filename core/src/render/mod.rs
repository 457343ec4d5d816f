//! Pixels out: a whole image, a band of rows or a rectangle, streamed into any
//! embedded-graphics [`DrawTarget`] one scanline per `fill_contiguous`.
//!
//! There is no framebuffer: each pixel is traced as the target pulls it from
//! the row iterator, so the memory cost is the same for 8×8 and 16384×16384.
//! Every pixel depends only on its coordinates, so any split of the image
//! into rows, tiles or threads gives the same bits, and so does any order
//! ([`Progressive`]: the whole picture in coarse blocks first).
//!
//! Given room (a profile with `first_hits`, see [`RendererRoom`](crate::RendererRoom)), camera rays find their hits
//! among the objects seen around their pixel, nearest first, instead of
//! walking the accelerator (`first_hit.rs`): the same hits.
//!
//! A render can be stopped inside a pixel ([`Renderer::pixel_until`] and a
//! [`Stop`], asked before every ray): a pixel stopped gives nothing, one
//! that completes gives the same bits as [`Renderer::pixel`].
//!
//! A pixel with SAMPLES n is the mean of its n² sample colours, each clamped
//! to [0, 1] first (an over-bright highlight does not bleed into its
//! neighbours), then gamma-corrected and rounded. Its object is the one hit
//! by sample (n/2, n/2), the centre sample for odd n.

mod first_hit;
mod gamma;
mod handoff;
mod panel;
mod progressive;
mod split;
mod stop;

use first_hit::FirstHits;
pub use first_hit::ScreenBound;
pub(crate) use gamma::GammaTable;
pub use handoff::{Handoff, SlotBusy, Taken};
pub use panel::PanelColor;
pub use progressive::{Progressive, ProgressiveError, TracedUnit, Unit};
pub use split::{interleaved_rows, Tiles};
pub(crate) use stop::{Halt, Polling};
pub use stop::{Stop, Stopped};

use crate::accel::{Hit, Linked, Mailbox, SceneAccelerator};
use crate::motion::{Lookout, RayKind};
use crate::panel::TracedColor;
use crate::scene::{
    Camera, CameraError, CameraRay, Color, MirrorPlane, ObjectId, RayCursor, SceneView, Stride, MAX_SIDE,
};
use crate::shade::{Mirror, Poll, Scratch, Stats, Tracer, Unpolled};
use crate::shapes::Ray;
use core::ops::Range;
use embedded_graphics_core::draw_target::DrawTarget;
use embedded_graphics_core::geometry::{Point, Size};
use embedded_graphics_core::pixelcolor::Rgb888;
use embedded_graphics_core::primitives::Rectangle;

/// Where a walk over pixels in any order ([`Renderer::pixel_on`]) was,
/// and its last jump along a row.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Walk {
    last: [u32; 2],
    jump: Option<(u32, Stride)>,
}

impl Walk {
    /// A walk that has not started.
    pub(crate) const NEW: Walk = Walk { last: [u32::MAX; 2], jump: None };
}

/// A finished pixel: its display colour and the object seen through it.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct PixelSample {
    /// The colour the display shows, gamma applied.
    pub color: Rgb888,
    /// The object the pixel's (centre) primary ray hits, as the scene file
    /// wrote it (see [`SceneView::written_object`]); `None` for background.
    pub object: Option<ObjectId>,
}

/// A sample as a colour: a target of `PixelSample`s takes each pixel's
/// colour and the object it sees (a desktop's image keeps both).
impl embedded_graphics_core::pixelcolor::PixelColor for PixelSample {
    type Raw = ();
}

/// A colour alone: a sample that sees no object.
impl From<Rgb888> for PixelSample {
    fn from(color: Rgb888) -> Self {
        PixelSample { color, object: None }
    }
}

impl TracedColor for PixelSample {
    fn traced(color: Rgb888, object: Option<ObjectId>) -> Self {
        PixelSample { color, object }
    }
}

/// Renders one scene through its accelerator, as build `L` links the
/// tracer (its [`Profile`](crate::profile::Profile)). A renderer holds the
/// mutable state of one core or thread (counters, mailbox, screen lists);
/// to render on several, give each its own over the same scene
/// ([`LoadedScene::with_renderer`](crate::LoadedScene::with_renderer) on
/// the loading core, [`SharedScene::renderer`](crate::SharedScene::renderer)
/// on the others). Most draws need none: a scene's
/// [`TracedImage`](crate::TracedImage) makes its own.
///
/// ```
/// use embedded_graphics::pixelcolor::{Rgb888, RgbColor};
/// use octrace_core::{profile::Board16K, Raytracer};
///
/// let mut raytracer = Raytracer::<Board16K>::new();
/// let scene = raytracer.load("RASTER 8 8\nVIEWPOINT 0 0 5\nORIGIN 0 0 0\nUPVECTOR 0 1 0\nBACKGROUND 0 0 1\nLIGHT 10 5 5 5\nSPHERE 1 1.5 0 0 0\nSURFACE 1 .1 .1 .1 .8 .2 .2 0 0 0 1 0 0\n")?;
/// scene.with_renderer(scene.raster(), |renderer| {
/// // A corner sees the background; the centre, the sphere.
/// assert_eq!(renderer.pixel(0, 0).color, Rgb888::BLUE);
/// assert!(renderer.pixel(0, 0).object.is_none());
/// assert!(renderer.pixel(4, 4).object.is_some());
/// let row: Vec<_> = renderer.row(4, 0..8).collect();
/// assert_eq!(row[4], renderer.pixel(4, 4));
/// assert_eq!(renderer.stats().rays, 12, "a ray a pixel asked: nothing reflects");
/// })?;
/// # Ok::<(), Box<dyn core::error::Error>>(())
/// ```
pub struct Renderer<'a, L: Linked> {
    tracer: Tracer<'a, L>,
    camera: Camera,
    /// The last primary ray's direction: the next one along a row is a sum.
    cursor: RayCursor,
    gamma: GammaTable,
    /// The last pixel's display values, where the next one's search starts.
    last_encoded: [u8; 3],
    scratch: Scratch<'a>,
    /// Camera rays' objects by where they are seen, when given storage.
    first_hits: ScreenLists<'a>,
    /// The same for their reflections off `mirror` (seen from the eye's
    /// image in it), when given storage and the scene has a mirror.
    mirror_hits: ScreenLists<'a>,
    mirror: Option<MirrorPlane>,
}

/// Room for screen lists: a bound for each object, and their positions.
pub(crate) type ScreenRoom<'a> = (&'a mut [ScreenBound], &'a mut [u16]);

/// Fills `lists`' room, if that is what it holds, for `camera` (the eye's
/// image in `mirror`, if given: only when `MIRROR`), `poll` asked before
/// each object: false if it said stop (the room stays, for the next ray to
/// fill).
#[cold]
#[inline(never)]
fn fill<'a, Q: Poll, const MIRROR: bool>(
    lists: &mut ScreenLists<'a>,
    scene: &SceneView<'_>,
    camera: &Camera,
    mirror: Option<MirrorPlane>,
    poll: &mut Q,
) -> bool {
    let ScreenLists::Room(bounds, _) = lists else { return true };
    if !FirstHits::project::<Q, MIRROR>(scene, camera, bounds, poll, mirror) {
        return false;
    }
    if let ScreenLists::Room(bounds, positions) = core::mem::replace(lists, ScreenLists::None) {
        *lists = FirstHits::new(scene.object_count(), camera, bounds, positions)
            .map_or(ScreenLists::None, ScreenLists::Lists);
    }
    true
}

/// The mirror's lists (or their room, until the first reflection off the
/// mirror fills it: a frame's run that has none never does), for one
/// camera ray's reflection; none without a mirror.
struct ListedMirror<'l, 'a, L> {
    lists: &'l mut ScreenLists<'a>,
    linked: core::marker::PhantomData<L>,
    plane: Option<MirrorPlane>,
    /// The renderer's camera: its tiles are the mirrored camera's.
    camera: &'l Camera,
    offsets: (i32, i32),
    pixel: [u32; 2],
}

impl<L: Linked> Mirror for ListedMirror<'_, '_, L> {
    // A build without the lists links none of the tracer's checks.
    const LISTS: bool = L::MIRROR_HITS;

    #[inline(always)]
    fn plane(&self) -> Option<MirrorPlane> {
        self.plane
    }

    // Out of line: inlined, the lists' walk would crowd the tracer's loop
    // (its registers) for every ray, where it serves one reflection.
    #[inline(never)]
    fn nearest<Q: Poll>(
        &mut self,
        scene: &SceneView<'_>,
        ray: &Ray,
        start: Option<crate::accel::RayStart>,
        primary_t: crate::math::Scalar,
        poll: &mut Q,
    ) -> Option<Option<Hit>> {
        if let ScreenLists::Room(..) = self.lists {
            let plane = self.plane?;
            let image = self.camera.mirrored(plane.axis, plane.coordinate)?;
            // Stopped: the sample is given up at its next ray.
            if !fill::<Q, true>(self.lists, scene, &image, Some(plane), poll) {
                return None;
            }
        }
        let ScreenLists::Lists(lists) = self.lists else { return None };
        lists.nearest_reflected(scene, L::KINDS, self.camera, self.offsets, self.pixel, ray, start, primary_t)
    }
}

/// A renderer's screen lists: none, their room until the first camera ray
/// fills it (asking the pixel's stop before each object, as before each
/// ray: the lists of hundreds of objects take a board a few hundred
/// milliseconds), or the lists.
enum ScreenLists<'a> {
    None,
    Room(&'a mut [ScreenBound], &'a mut [u16]),
    Lists(FirstHits<'a>),
}

impl<L: Linked> core::fmt::Debug for Renderer<'_, L> {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        f.debug_struct("Renderer").field("camera", &self.camera).finish_non_exhaustive()
    }
}

impl<'a, L: Linked> Renderer<'a, L> {
    /// A renderer at the scene's RASTER size.
    pub fn new(scene: SceneView<'a>, accel: &'a SceneAccelerator<'a, L>) -> Result<Self, CameraError> {
        let [w, h] = scene.settings.raster;
        Self::with_size(scene, accel, w, h)
    }

    /// A renderer at another size (the default VIEWPORT follows its aspect).
    // Not inlined: the set-up's temporaries then live in its own frame, gone
    // before the first pixel, instead of in the caller's for the whole render.
    #[inline(never)]
    pub fn with_size(
        scene: SceneView<'a>,
        accel: &'a SceneAccelerator<'a, L>,
        width: u32,
        height: u32,
    ) -> Result<Self, CameraError> {
        let s = scene.settings;
        let camera = Camera::new(&s.view, &scene.normalization, width, height, s.samples)?;
        // The table is filled in place: moving a 510-byte table around costs
        // a board stack space it does not have.
        let mut renderer = Renderer {
            tracer: Tracer::new(scene, accel),
            camera,
            cursor: RayCursor::default(),
            gamma: GammaTable { thresholds: [0; 255] },
            last_encoded: [0; 3],
            scratch: Scratch::new(Mailbox::none()),
            first_hits: ScreenLists::None,
            mirror_hits: ScreenLists::None,
            mirror: None,
        };
        renderer.gamma.fill(s.gamma);
        Ok(renderer)
    }

    /// Gives the renderer a mailbox of `words` (one bit per object,
    /// [`Mailbox::words_for`]), so that accelerators filing an object in
    /// several cells test it once per ray; in place (no move of the
    /// renderer, which matters on a board with a few KiB of stack).
    pub(crate) fn set_mailbox(&mut self, words: &'a mut [u32]) {
        self.scratch.mailbox = Mailbox::new(words);
    }

    /// Gives the renderer room for a [`ScreenBound`] for each of the
    /// scene's objects and [`ScreenBound::positions_for`] them, so that
    /// camera rays find their hits among the objects seen around their
    /// pixel instead of walking the accelerator, when it allows (the build
    /// links them, and the scene's octree, if any, is walked by 3DDDA).
    /// The same image, faster; too little room leaves the walk. A
    /// [`RendererRoom`](crate::RendererRoom) holds it.
    ///
    /// Room for as many again (`mirror`) lists the hits of the reflections
    /// of camera rays off the scene's mirror, if it has one
    /// ([`SceneView::has_mirror`]).
    pub(crate) fn set_first_hits(&mut self, lists: ScreenRoom<'a>, mirror: Option<ScreenRoom<'a>>) {
        let (scene, camera) = (self.tracer.scene(), &self.camera);
        let fits = |(bounds, positions): &ScreenRoom<'a>| FirstHits::fit(scene, camera, bounds, positions);
        if !self.tracer.accel().first_hits_by_screen() || !fits(&lists) {
            return;
        }
        self.first_hits = ScreenLists::Room(lists.0, lists.1);
        // Asked first: a build without the lists links none of the rest.
        if !self.tracer.accel().mirror_hits_by_screen() {
            return;
        }
        let Some(room) = mirror.filter(fits) else { return };
        let Some(plane) = scene.mirror() else { return };
        if camera.mirrored(plane.axis, plane.coordinate).is_some() {
            self.mirror_hits = ScreenLists::Room(room.0, room.1);
            self.mirror = Some(plane);
        }
    }

    /// Fills the screen lists' room, `poll` asked before each object: false
    /// if it said stop (the next camera ray fills it again).
    #[cold]
    #[inline(never)]
    fn fill_first_hits<Q: Poll>(&mut self, poll: &mut Q) -> bool {
        fill::<Q, false>(&mut self.first_hits, self.tracer.scene(), &self.camera, None, poll)
    }

    /// The camera ray's hit from the screen lists, if the renderer has them
    /// (filled by the first ray, `poll` asked before each object).
    #[inline]
    fn first_hit<Q: Poll>(&mut self, ray: &mut CameraRay, [x, y]: [u32; 2], poll: &mut Q) -> Option<Option<Hit>> {
        // Asked first: for an accelerator that never allows the lists (the
        // naive modes) the whole path folds away, a board's cycles too.
        if !self.tracer.accel().first_hits_by_screen() {
            return None;
        }
        if let ScreenLists::Room(..) = self.first_hits {
            // Stopped: the caller's next ask says so too.
            if !self.fill_first_hits(poll) {
                return None;
            }
        }
        let ScreenLists::Lists(hits) = &mut self.first_hits else { return None };
        hits.nearest(self.tracer.scene(), L::KINDS, &self.camera, ray, [x, y])
    }

    /// Counters since the renderer was made.
    pub fn stats(&self) -> Stats {
        self.scratch.stats
    }

    /// The image size the renderer traces for.
    pub fn size(&self) -> Size {
        Size::new(self.camera.width(), self.camera.height())
    }

    /// The pixel at (`x`, `y`), `x` to the right and `y` down.
    // Not inlined into the row loop: keeps the caller's frame (a display
    // driver's) small on a board.
    #[inline(never)]
    pub fn pixel(&mut self, x: u32, y: u32) -> PixelSample {
        match self.pixel_polled(x, y, &mut Unpolled) {
            Ok(pixel) => pixel,
            Err(never) => match never {},
        }
    }

    /// [`Renderer::pixel`], asking `stop` before every ray (and, at the
    /// renderer's first pixel, before each object of its screen lists)
    /// whether to go on: [`Stopped`] as soon as it says so, even inside the
    /// pixel's ray tree, or the very pixel [`Renderer::pixel`] gives. A
    /// stopped pixel may be asked for again; it is traced from its start.
    ///
    /// ```
    /// use octrace_core::render::{Renderer, Stopped};
    /// use octrace_core::{profile::Board16K, Raytracer};
    ///
    /// // Two facing mirrors with the eye between them: each of the pixel's
    /// // samples bounces thousands of times, its light asked at each.
    /// let mut raytracer = Raytracer::<Board16K>::new();
    /// let scene = raytracer.load(
    ///     "VIEWPOINT 0 0 0 ORIGIN 0 0 -1 RDEPTH 1000000 SAMPLES 4 LIGHT 1 0 1 0\n\
    ///      RECTANGLE 1 -5 -5 -3 5 -5 -3 5 5 -3 -5 5 -3\n\
    ///      RECTANGLE 1 -5 -5 3 -5 5 3 5 5 3 5 -5 3\n\
    ///      SURFACE 1 0.01 0.01 0.01 0 0 0 0 0 0 0 1 0\n",
    /// )?;
    /// let accelerator = scene.accelerator();
    /// let mut renderer = Renderer::with_size(scene.view(), &accelerator, 4, 4)?;
    ///
    /// // A board's stop: a flag its serial line's interrupt sets, say.
    /// let stop_now = core::sync::atomic::AtomicBool::new(false);
    /// let mut asked = 0;
    /// let mut stop = || {
    ///     asked += 1;
    ///     if asked == 10 {
    ///         stop_now.store(true, core::sync::atomic::Ordering::Relaxed);
    ///     }
    ///     stop_now.load(core::sync::atomic::Ordering::Relaxed)
    /// };
    /// assert_eq!(renderer.pixel_until(2, 2, &mut stop), Err(Stopped));
    /// // Stopped at its tenth ask: nine rays into the pixel's first sample.
    /// assert_eq!(renderer.stats().rays + renderer.stats().shadow_rays, 9);
    ///
    /// // Never stopped: the pixel's bits, as if nothing were asked.
    /// let pixel = renderer.pixel_until(2, 2, &mut || false)?;
    /// assert_eq!(pixel, renderer.pixel(2, 2));
    /// # Ok::<(), Box<dyn core::error::Error>>(())
    /// ```
    #[inline(never)]
    pub fn pixel_until<S: Stop>(&mut self, x: u32, y: u32, stop: &mut S) -> Result<PixelSample, Stopped> {
        self.pixel_polled(x, y, &mut stop::Polling { stop, stopped: false })
    }

    /// The pixel at (`x`, `y`), `poll` asked before each of its rays.
    #[inline(always)]
    pub(crate) fn pixel_polled<Q: Poll>(&mut self, x: u32, y: u32, poll: &mut Q) -> Result<PixelSample, Q::Stopped> {
        let n = self.camera.samples();
        let (mean, object) = if n == 1 {
            // One sample (the common case on a board): no loops, no sums.
            let (c, object) = self.sample(x, y, 0, 0, poll)?;
            (Color::from_bits(c.bits().map(|v| v.clamp(0, 1 << 16))), object)
        } else {
            self.mean_of_samples(n, x, y, poll)?
        };
        // Neighbouring pixels mostly differ by a level or none: the search
        // starts at the last pixel's (the same bits from any start).
        let [r, g, b] = self.last_encoded;
        let encoded =
            [self.gamma.encode_near(mean.r, r), self.gamma.encode_near(mean.g, g), self.gamma.encode_near(mean.b, b)];
        self.last_encoded = encoded;
        Ok(PixelSample { color: Rgb888::new(encoded[0], encoded[1], encoded[2]), object })
    }

    /// Watches the frames to come while tracing (an animation traced with
    /// coherence), or stops (`None`).
    pub(crate) fn set_lookout(&mut self, lookout: Option<Lookout<'a>>) {
        self.scratch.lookout = lookout;
    }

    /// Whether it watches the frames to come.
    pub(crate) fn is_watching(&self) -> bool {
        self.scratch.lookout.is_some()
    }

    /// The pixel at (`x`, `y`) and its clean count under the lookout, if
    /// below `bound` (else `bound`).
    /// `poll` asked before each of its rays.
    #[inline(always)]
    pub(crate) fn watched_pixel<Q: Poll>(
        &mut self,
        x: u32,
        y: u32,
        bound: u32,
        poll: &mut Q,
    ) -> Result<(PixelSample, u32), Q::Stopped> {
        if !L::COHERENCE {
            // Nothing watched the rays: the pixel is traced again next frame.
            return self.pixel_polled(x, y, poll).map(|pixel| (pixel, 0));
        }
        if let Some(lookout) = &mut self.scratch.lookout {
            lookout.start(bound);
        }
        let pixel = self.pixel_polled(x, y, poll)?;
        Ok((pixel, self.scratch.lookout.map_or(bound, |l| l.clean)))
    }

    /// The colour and object of sample (`sx`, `sy`) of pixel (`x`, `y`).
    #[inline]
    fn sample<Q: Poll>(
        &mut self,
        x: u32,
        y: u32,
        sx: u32,
        sy: u32,
        poll: &mut Q,
    ) -> Result<(Color, Option<ObjectId>), Q::Stopped> {
        let mut ray = self.camera.next_ray(&mut self.cursor, x, y, sx, sy);
        let seen = match self.first_hit(&mut ray, [x, y], poll) {
            // Shown by the lists to miss: the ray itself is made only for
            // the lookout.
            Some(None) if poll.go_on() => {
                if let Some(lookout) = self.scratch.lookout.as_mut().filter(|_| L::COHERENCE) {
                    lookout.ray(ray.get(&self.camera), None, RayKind::Primary);
                }
                self.tracer.missed(&mut self.scratch)
            }
            Some(None) => (Color::BLACK, None),
            first => {
                // One tracer for scenes with a mirror and without (a second
                // would take the shading out of line, for every hit).
                let mut mirror = ListedMirror::<L> {
                    lists: &mut self.mirror_hits,
                    linked: core::marker::PhantomData,
                    plane: self.mirror,
                    camera: &self.camera,
                    offsets: ray.offsets,
                    pixel: [x, y],
                };
                self.tracer.trace(*ray.get(&self.camera), first, &mut self.scratch, poll, &mut mirror)
            }
        };
        // A stopped sample's colour is partial: never used.
        poll.stopped()?;
        Ok(seen)
    }

    /// The mean of the `n`² samples of pixel (`x`, `y`) (channels clamped to
    /// 0..1 first, rounded to nearest) and the object hit by the middle one.
    fn mean_of_samples<Q: Poll>(
        &mut self,
        n: u32,
        x: u32,
        y: u32,
        poll: &mut Q,
    ) -> Result<(Color, Option<ObjectId>), Q::Stopped> {
        let mut object = None;
        // At most 16² samples of at most 2^16 each: the sums fit a u32.
        let mut sum = [0u32; 3];
        for sy in 0..n {
            for sx in 0..n {
                let (c, o) = self.sample(x, y, sx, sy, poll)?;
                if sx == n / 2 && sy == n / 2 {
                    object = o;
                }
                for (s, v) in sum.iter_mut().zip(c.bits()) {
                    *s += v.clamp(0, 1 << 16) as u32;
                }
            }
        }
        let count = n * n;
        Ok((Color::from_bits(sum.map(|s| ((s + count / 2) / count) as i32)), object))
    }

    /// The pixels of row `y` for the columns `xs`, traced lazily.
    pub fn row(&mut self, y: u32, xs: Range<u32>) -> impl Iterator<Item = PixelSample> + use<'_, 'a, L> {
        xs.map(move |x| self.pixel(x, y))
    }

    /// The pixel at (`x`, `y`) on `walk`, a walk over pixels in any order:
    /// along a row, after a jump as long as the walk's last, the camera
    /// ray is a sum, as after a step (the jump's change of direction is
    /// kept by the walk, not the renderer), so a row walked every b-th
    /// pixel costs what a row does.
    pub(crate) fn pixel_on<Q: Poll>(
        &mut self,
        walk: &mut Walk,
        x: u32,
        y: u32,
        poll: &mut Q,
    ) -> Result<PixelSample, Q::Stopped> {
        let along = x.wrapping_sub(walk.last[0]);
        if y == walk.last[1] && along > 1 && along <= MAX_SIDE {
            let stride = match walk.jump {
                Some((pixels, stride)) if pixels == along => stride,
                _ => self.camera.stride(along),
            };
            walk.jump = Some((along, stride));
            self.cursor.skip(&stride);
        }
        walk.last = [x, y];
        match Q::ASKS {
            true => self.pixel_polled(x, y, poll),
            false => Ok(self.pixel(x, y)),
        }
    }

    /// Renders the whole image.
    #[cfg(test)]
    pub(crate) fn render<D>(&mut self, target: &mut D) -> Result<Stats, D::Error>
    where
        D: DrawTarget,
        D::Color: TracedColor,
    {
        self.render_rect(&Rectangle::new(Point::zero(), self.size()), target)
    }

    /// Renders the pixels of `rect` (clipped to the image), one
    /// `fill_contiguous` per row. Returns the counters of this call.
    pub(crate) fn render_rect<D>(&mut self, rect: &Rectangle, target: &mut D) -> Result<Stats, D::Error>
    where
        D: DrawTarget,
        D::Color: TracedColor,
    {
        let r = clipped(rect, self.size());
        let before = self.scratch.stats;
        let x0 = r.top_left.x as u32;
        for y in r.top_left.y as u32..r.top_left.y as u32 + r.size.height {
            let line = Rectangle::new(Point::new(x0 as i32, y as i32), Size::new(r.size.width, 1));
            let pixels = self.row(y, x0..x0 + r.size.width);
            target.fill_contiguous(&line, pixels.map(|p| D::Color::traced(p.color, p.object)))?;
        }
        Ok(self.scratch.stats.since(&before))
    }
}

/// The part of `area` inside an image of `size`: what
/// `Rectangle::intersection` gives for an area that overlaps it (one
/// that does not gives an empty area), in a tenth of its code, which
/// every board's draw links.
pub(crate) fn clipped(area: &Rectangle, size: Size) -> Rectangle {
    let clip = |start: i32, length: u32, side: u32| {
        let side = side.min(i32::MAX as u32) as i32;
        let end = start.saturating_add(length.min(i32::MAX as u32) as i32).clamp(0, side);
        let start = start.clamp(0, end);
        (start, (end - start) as u32)
    };
    let (x, width) = clip(area.top_left.x, area.size.width, size.width);
    let (y, height) = clip(area.top_left.y, area.size.height, size.height);
    Rectangle::new(Point::new(x, y), Size::new(width, height))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn clipped_is_the_intersection_with_the_image() {
        let size = Size::new(12, 8);
        let image = Rectangle::new(Point::zero(), size);
        let (starts, lengths) = ([-20, -3, 0, 5, 11, 12, 40], [0, 1, 4, 12, 30]);
        for x in starts {
            for y in starts {
                for w in lengths {
                    for h in lengths {
                        let area = Rectangle::new(Point::new(x, y), Size::new(w, h));
                        let (clip, expected) = (clipped(&area, size), area.intersection(&image));
                        match expected.is_zero_sized() {
                            true => assert!(clip.is_zero_sized(), "{area:?}: {clip:?}"),
                            false => assert_eq!(clip, expected, "{area:?}"),
                        }
                    }
                }
            }
        }
        // Where embedded-graphics' own would overflow: inside, or empty.
        for (x, w) in [(i32::MIN, u32::MAX), (i32::MAX, u32::MAX), (-1, u32::MAX), (i32::MIN, 5)] {
            let clip = clipped(&Rectangle::new(Point::new(x, x), Size::new(w, w)), size);
            assert!(clip.is_zero_sized() || image.contains(clip.bottom_right().unwrap()), "{clip:?}");
        }
    }
}
