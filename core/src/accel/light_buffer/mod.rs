//! The light buffer (Haines and Greenberg 1986): for each light, a cube of
//! directions around it whose cells list the objects that can lie between
//! the light and a point seen in that cell. A shadow ray tests only its
//! cell's list, nearest the light first, and stops at the first object
//! farther from the light than its own point.
//!
//! *Cells.* A direction `v` from the light (the shadow ray's origin less the
//! light, exact integers) belongs to the face of its largest component
//! (`x` before `y` before `z` on ties) and that component's sign; on the
//! face, with `m` that component's magnitude, to the cell
//! `⌊N·(v_b + m) / 2m⌋` along each other axis `b` (`N − 1` when `v_b = m`).
//! `N`, the cells a face side, is a power of two: the quotient's bits come
//! from steps of compare and subtract in 32 bits, exact. Only the
//! rectangle of a face's cells that list something is stored.
//!
//! *Lists.* An object is listed in every cell whose pyramid (the closed cone
//! of its directions, apex at the light) meets its bounds widened by
//! [`MARGIN`]: the cells between those of the widened box's extreme ratios
//! `v_b / m`, each an exact quotient rounded down, as the ray's cell is,
//! and monotone in the ratio. An object whose widened bounds hold the light
//! is on the light's own list, which every ray to it tests. Each entry
//! keeps its object's depth: how far from the light along the face's axis
//! its widened bounds begin, in units of 2^[`DEPTH_SHIFT`], rounded down; a
//! list is sorted by it.
//!
//! *Exactness.* Say an object blocks a shadow ray from `O` to the light `L`
//! at `H`. `H` lies within the filing margin of the object's bounds (the
//! octree's bound on a hit point's rounding) and within [`RAY_SLACK`] of a
//! point `S` of the segment `[L, O]` (the ray is the tracer's estimate of
//! the direction and length), so `S` is in the widened bounds. `S − L =
//! σ(O − L)` for a `σ` in `[0, 1]`: `S` is the light itself (the object is
//! on the light's own list) or has the ray's direction, so its cell; and
//! its component along the face's axis is `σm ≤ m`, so the object's depth
//! is at most the ray's. Testing a cell's list up to the ray's depth thus
//! gives exactly the answer of testing every object; the first object
//! found may differ, which only the tracer's remembered blocker sees.
//!
//! *Storage.* One array of 32-bit words (a layout of its own, `Words`): in
//! an arena a profile sizes (`light_buffer_words`), built when a scene
//! loads, or prebuilt for a scene by a build script and kept in flash,
//! checked against the scene before use ([`LightBuffer::verified`]: every
//! object listed wherever it can be seen, at no greater depth). The build
//! takes the finest cube, up to the side asked for, that fits the arena;
//! if even one cell a face does not fit, the first lights that do are
//! buffered and the others' shadow rays take the accelerator: slower,
//! never wrong. [`LightBufferReport`] says which.
//!
//! Invariants: the lists never change a shadow ray's answer, only its cost;
//! an entry holds an object below 2^[`OBJECT_BITS`] and a depth below
//! 2^(32 − [`OBJECT_BITS`]); each list is sorted by depth; a cell holds the
//! start of its list in the entries, the next cell its end.

use super::{Accelerator, Hit, Mailbox, RayStart, FILING_MARGIN};
use crate::capacity::{Arena, Counts};
use crate::math::Scalar;
use crate::scene::{ObjectId, SceneView};
use crate::shapes::{Ray, ShapeKinds};

mod build;
mod cells;
mod cones;
mod query;

pub(crate) use query::ShadowQuery;

/// How far a shadow ray strays from the segment between its origin and its
/// light, in Q16.16 raw units, at most. The tracer aims it with
/// [`Vec3::direction_and_length_estimate`](crate::math::Vec3::direction_and_length_estimate):
/// each component within 5.5 units of 2^-30 of the exact unit vector, so
/// within 11 units sideways over a length below 2^31 (the scene spans
/// ±2^29); and it ends at that estimate's length less one, within 2^-27 of
/// the exact length plus a unit: at most 17 units past the light. 64
/// covers both with room.
pub(crate) const RAY_SLACK: i64 = 64;

/// How far beyond its bounds an object counts as seen in a cell: a hit
/// point's rounding (the octree's filing margin) and a shadow ray's
/// straying.
pub(crate) const MARGIN: i64 = FILING_MARGIN + RAY_SLACK;

/// What a build links of the shadow rays' tests, as constants, so that its
/// code holds its own shapes' tests only: a profile's
/// ([`Linked`](crate::profile::Linked)), or
/// every kind's ([`EveryKind`]).
pub(crate) trait ShadowLinks {
    /// The shape kinds its objects can be.
    const KINDS: ShapeKinds;
    /// Whether it links a cube's look-up and build, and the cones' (a
    /// buffer of a form it does not link is not read: its lights' rays are
    /// left to the accelerator). At least one of them.
    const CUBES: bool;
    /// See [`ShadowLinks::CUBES`].
    const CONES: bool;
}

/// Every kind and both forms: a [`LightBuffered`](super::LightBuffered)
/// over any accelerator.
pub(crate) struct EveryKind;

impl ShadowLinks for EveryKind {
    const KINDS: ShapeKinds = ShapeKinds::ALL;
    const CUBES: bool = true;
    const CONES: bool = true;
}

/// The most cells a face side has: 2^`MAX_LEVEL`.
pub const MAX_CELLS_A_SIDE: u32 = 1 << MAX_LEVEL;
const MAX_LEVEL: u32 = 6;

/// An entry's low bits: the object. Scenes of more objects are not buffered.
const OBJECT_BITS: u32 = 20;
const OBJECT_MASK: u32 = (1 << OBJECT_BITS) - 1;
/// An entry's high bits: the depth in units of 2^`DEPTH_SHIFT`, rounded
/// down (a lower bound), at most `DEPTH_MAX`.
const DEPTH_SHIFT: u32 = 18;
const DEPTH_MAX: u32 = (1 << (32 - OBJECT_BITS)) - 1;
/// Rays whose direction has a component this large or more are left to the
/// accelerator (none in the scene's range): their cells' steps would leave
/// 32 bits.
const MAX_COMPONENT: u32 = 1 << 30;

/// The layout of a light buffer's words: a header, a cube for each
/// buffered light, the cells (list starts), the entries.
///
/// - header: `MAGIC`, the lights buffered (the scene's first), the level
///   (log2 of the cells a face side), the cells (list starts, the last
///   one the end of the last list) and the scene's objects;
/// - a cube: the light's position (three Q16.16 words), the cell of its own
///   list, and per face the cell of its first cell and its rectangle of
///   cells (`low_b | low_c << 8 | size_b << 16 | size_c << 24`, the sides
///   0 for a face that lists nothing), rows along `b`;
/// - an entry: `depth << OBJECT_BITS | object`.
struct Words;

impl Words {
    /// "LBF" and the layout's version.
    const MAGIC: u32 = 0x4C42_4601;
    const HEADER: usize = 5;
    const CUBE: usize = 4 + 2 * 6;

    /// Words of a buffer of `lights` cubes, `cells` cells and `entries`
    /// entries.
    const fn of(lights: usize, cells: usize, entries: usize) -> usize {
        Words::HEADER + Words::CUBE * lights + cells + entries
    }
}

/// What a light buffer's build produced.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct LightBufferReport {
    /// Cells a face side of every buffered light's cube (0: none).
    pub cells_a_side: u32,
    /// The lights buffered: the first ones (the others' shadow rays take
    /// the accelerator because the lists did not fit).
    pub lights: usize,
    /// Cells (list starts, the end of the last list included).
    pub cells: usize,
    /// Entries: objects listed in cells (an object once per cell).
    pub entries: usize,
    /// Words in all (4 bytes each).
    pub words: usize,
    /// Whether it holds cones rather than a cube (few objects, see
    /// [`LightBuffer::build`]): then `cells_a_side` and `cells` are 0 and
    /// there is an entry for each object a light.
    pub cones: bool,
}

impl LightBufferReport {
    /// The counts of a profile that builds this very buffer.
    pub fn counts(&self) -> Counts {
        Counts { light_buffer_lights: self.lights, light_buffer_words: self.words, ..Counts::ZERO }
    }
}

/// Why a prebuilt light buffer was refused ([`LightBuffer::verified`],
/// [`LoadedScene::use_light_buffer`](crate::LoadedScene::use_light_buffer)).
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum LightBufferError {
    /// The capacity profile serves no lights with a light buffer
    /// (`light_buffer_lights: 0`), so it links none of its code.
    NoRoom,
    /// The words are not a light buffer of this version.
    Malformed,
    /// It was built for other lights or another number of objects.
    OtherScene,
    /// An object is missing from a cell it can be seen in (or listed
    /// deeper than it begins): it was built for other objects.
    Incomplete {
        /// The light.
        light: usize,
        /// The object.
        object: ObjectId,
    },
}

impl core::fmt::Display for LightBufferError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        match self {
            LightBufferError::NoRoom => {
                f.write_str("the capacity profile has no light buffer; give it one with octrace_core::profile! (light_buffer_lights: …)")
            }
            LightBufferError::Malformed => f.write_str("not a light buffer of this version"),
            LightBufferError::OtherScene => f.write_str("a light buffer built for other lights or objects"),
            LightBufferError::Incomplete { light, object } => write!(
                f,
                "a light buffer that misses object {} where light {light} sees it: built for other objects",
                object.0
            ),
        }
    }
}

impl core::error::Error for LightBufferError {}

/// The light buffer over one scene: its words, in an arena it was built in
/// ([`LightBuffer::build`]) or prebuilt and checked
/// ([`LightBuffer::verified`]). Read by every shadow ray;
/// [`LightBuffered`] puts it in front of any accelerator.
#[derive(Clone, Copy)]
pub struct LightBuffer<'a> {
    words: &'a [u32],
    /// The lights buffered, log2 of the cells a face side, and where the
    /// cells and the entries start in the words.
    lights: usize,
    level: u8,
    cells: usize,
    entries: usize,
    /// Whether the words are cones (`cones.rs`) rather than a cube.
    cones: bool,
}

impl core::fmt::Debug for LightBuffer<'_> {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        f.debug_struct("LightBuffer").field("report", &self.report()).finish_non_exhaustive()
    }
}

impl<'a> LightBuffer<'a> {
    /// No light buffered: every shadow ray takes the accelerator.
    pub const NONE: LightBuffer<'static> =
        LightBuffer { words: &[], lights: 0, level: 0, cells: 0, entries: 0, cones: false };

    /// Builds the buffer over `scene`'s lights and objects in `words` with
    /// at most `cells_a_side` cells a face side (rounded down to a power of
    /// two, at most [`MAX_CELLS_A_SIDE`]): the finest cube whose lists fit
    /// the arena, or, when even one cell a face does not fit, the first
    /// lights that do. A scene of
    /// [`AccelMode::AUTO_NAIVE_UP_TO`](crate::AccelMode::AUTO_NAIVE_UP_TO)
    /// objects or fewer gets no cube but a cone around each object as each
    /// light sees it (two words an object a light, for the first lights
    /// that fit): its shadow rays test only the objects whose cone holds
    /// their direction, for less than a cell's look-up would cost.
    ///
    /// ```
    /// use octrace_core::accel::LightBuffer;
    /// use octrace_core::parse::parse;
    /// use octrace_core::profile::Board64K;
    /// use octrace_core::scene::Scene;
    ///
    /// let spheres: String = (0..20).map(|k| format!("SPHERE 1 0.2 {} 0 0\n", k)).collect();
    /// let text = format!("RASTER 8 8\nVIEWPOINT 0 0 9\nLIGHT 10 5 5 5\n{spheres}SURFACE 1 .1 .1 .1 .8 .2 .2 0 0 0 1 0 0\n");
    /// let mut scene = Scene::<Board64K>::new();
    /// parse(&text, &mut scene, &mut |e| panic!("{e}")).unwrap();
    /// let mut words = heapless::Vec::<u32, 2000>::new();
    /// let buffer = LightBuffer::build(&scene.view(), &mut words, 8);
    /// assert_eq!((buffer.report().lights, buffer.report().cells_a_side), (1, 8));
    ///
    /// // Three spheres: a cone each.
    /// let mut few = Scene::<Board64K>::new();
    /// parse("LIGHT 10 5 5 5\nSPHERE 1 1 0 0 0\nSPHERE 1 0.5 1 1 1\nSPHERE 1 0.3 2 2 2\nSURFACE 1 .1 .1 .1 .8 .2 .2 0 0 0 1 0 0\n", &mut few, &mut |e| panic!("{e}")).unwrap();
    /// let report = LightBuffer::build(&few.view(), &mut words, 8).report();
    /// assert!(report.cones);
    /// assert_eq!((report.lights, report.entries, report.words), (1, 3, 3 + 2 * 3));
    /// ```
    pub fn build<W: Arena<u32>>(scene: &SceneView<'_>, words: &'a mut W, cells_a_side: u32) -> LightBuffer<'a> {
        Self::build_for::<EveryKind, W>(scene, words, cells_a_side, usize::MAX)
    }

    /// [`LightBuffer::build`] for at most the first `lights` lights, in
    /// the form build `S` links (both: the one that suits the scene), over
    /// its shapes.
    fn build_for<S: ShadowLinks, W: Arena<u32>>(
        scene: &SceneView<'_>,
        words: &'a mut W,
        cells_a_side: u32,
        lights: usize,
    ) -> LightBuffer<'a> {
        if S::CONES && (!S::CUBES || scene.object_count() <= crate::AccelMode::AUTO_NAIVE_UP_TO) {
            words.clear();
            return Self::build_cones(scene, words, lights);
        }
        Self::build_with_margin(scene, words, cells_a_side, lights, MARGIN)
    }

    /// The words: what a build script writes out to keep the buffer in
    /// flash (see [`LightBuffer::verified`]).
    pub fn words(&self) -> &'a [u32] {
        self.words
    }

    /// Its size and fineness.
    pub fn report(&self) -> LightBufferReport {
        if self.cones {
            return self.cones_report();
        }
        let cells = self.entries - self.cells;
        LightBufferReport {
            cells_a_side: if self.lights > 0 { 1 << self.level } else { 0 },
            lights: self.lights,
            cells,
            entries: self.words.len() - self.entries,
            words: self.words.len(),
            cones: false,
        }
    }
}

/// A light buffer's words in an arena of their own, for whoever keeps the
/// buffer beside its scene (a [`Raytracer`](crate::Raytracer), the
/// studio): built in place ([`LightBufferStore::build`]), read through
/// [`LightBufferStore::buffer`].
///
/// ```
/// use octrace_core::accel::{LightBufferStore, MAX_CELLS_A_SIDE};
/// use octrace_core::parse::parse;
/// use octrace_core::profile::Board64K;
/// use octrace_core::scene::Scene;
///
/// let mut scene = Scene::<Board64K>::new();
/// parse("LIGHT 10 5 5 5\nSPHERE 1 1 0 0 0\nSURFACE 1 .1 .1 .1 .8 .2 .2 0 0 0 1 0 0\n", &mut scene, &mut |e| panic!("{e}")).unwrap();
/// let mut store = LightBufferStore::<heapless::Vec<u32, 200>>::new();
/// assert_eq!(store.buffer().report().lights, 0);
/// store.build(&scene.view(), MAX_CELLS_A_SIDE);
/// assert_eq!(store.buffer().report().lights, 1);
/// ```
#[derive(Debug)]
pub struct LightBufferStore<W> {
    words: W,
}

impl<W: Arena<u32>> Default for LightBufferStore<W> {
    fn default() -> Self {
        Self::new()
    }
}

impl<W: Arena<u32>> LightBufferStore<W> {
    /// An empty store (a constant: zero bits for a board's arena).
    pub const fn new() -> Self {
        LightBufferStore { words: W::EMPTY }
    }

    /// Builds `scene`'s buffer in the store (see [`LightBuffer::build`]).
    pub fn build(&mut self, scene: &SceneView<'_>, cells_a_side: u32) -> LightBuffer<'_> {
        self.build_for::<EveryKind>(scene, cells_a_side, usize::MAX)
    }

    /// [`LightBufferStore::build`] for at most the first `lights` lights,
    /// over what build `S` links (see [`LightBuffer::build`]).
    pub(crate) fn build_for<S: ShadowLinks>(
        &mut self,
        scene: &SceneView<'_>,
        cells_a_side: u32,
        lights: usize,
    ) -> LightBuffer<'_> {
        LightBuffer::build_for::<S, W>(scene, &mut self.words, cells_a_side, lights)
    }

    /// The buffer last built (none before the first build).
    pub fn buffer(&self) -> LightBuffer<'_> {
        self.buffer_for::<EveryKind>()
    }

    /// The buffer last built by [`LightBufferStore::build_for`] for `S`.
    pub(crate) fn buffer_for<S: ShadowLinks>(&self) -> LightBuffer<'_> {
        let words = self.words.as_slice();
        match (S::CUBES, S::CONES) {
            (true, true) => LightBuffer::parse(words),
            (true, false) => LightBuffer::parse(words).filter(|buffer| !buffer.cones),
            (false, _) => LightBuffer::parse_cones(words),
        }
        .unwrap_or(LightBuffer::NONE)
    }
}

/// An accelerator with a light buffer in front of its shadow rays: every
/// query is the accelerator's but [`Accelerator::occluded_toward`] for a
/// buffered light, which tests only the objects its cell lists (the same
/// answer). See [`LightBuffer::build`].
#[derive(Clone, Copy, Debug)]
pub struct LightBuffered<'a, A> {
    accel: A,
    buffer: LightBuffer<'a>,
}

impl<'a, A> LightBuffered<'a, A> {
    /// `accel` (an accelerator, or a reference to one) with `buffer`
    /// (built over the same scene) in front of its shadow rays.
    pub fn new(accel: A, buffer: LightBuffer<'a>) -> Self {
        LightBuffered { accel, buffer }
    }

    /// The accelerator behind the buffer.
    pub fn accel(&self) -> &A {
        &self.accel
    }

    /// The buffer.
    pub fn buffer(&self) -> LightBuffer<'a> {
        self.buffer
    }
}

impl<A: Accelerator> LightBuffered<'_, A> {
    /// [`Accelerator::occluded_toward`] of the shadow ray `query` asks of,
    /// the buffer's objects tested over its kinds only (a build's, which
    /// links no other kind's code).
    #[inline]
    pub(crate) fn occluded_toward_among<S: ShadowLinks>(
        &self,
        query: &ShadowQuery<'_, '_>,
        mailbox: &mut Mailbox<'_>,
    ) -> bool {
        match self.buffer.occluded::<S>(query, mailbox) {
            Some(blocked) => blocked,
            None => {
                let ShadowQuery { scene, ray, t_max, light, start } = *query;
                self.accel.occluded_toward(scene, ray, t_max, light, start, mailbox)
            }
        }
    }
}

impl<A: Accelerator> Accelerator for LightBuffered<'_, A> {
    #[inline]
    fn nearest(
        &self,
        scene: &SceneView<'_>,
        ray: &Ray,
        start: Option<RayStart>,
        mailbox: &mut Mailbox<'_>,
    ) -> Option<Hit> {
        self.accel.nearest(scene, ray, start, mailbox)
    }

    #[inline]
    fn occluded(
        &self,
        scene: &SceneView<'_>,
        ray: &Ray,
        t_max: Scalar,
        start: Option<RayStart>,
        mailbox: &mut Mailbox<'_>,
    ) -> bool {
        self.accel.occluded(scene, ray, t_max, start, mailbox)
    }

    #[inline]
    fn occluded_toward(
        &self,
        scene: &SceneView<'_>,
        ray: &Ray,
        t_max: Scalar,
        light: usize,
        start: Option<RayStart>,
        mailbox: &mut Mailbox<'_>,
    ) -> bool {
        let query = ShadowQuery { scene, ray, t_max, light, start };
        self.occluded_toward_among::<EveryKind>(&query, mailbox)
    }
}

#[cfg(test)]
mod tests {
    extern crate std;
    use super::*;
    use crate::accel::Naive;
    use crate::accel::{Accelerator, RayStart};
    use crate::math::{Dir, Vec3};
    use crate::parse::parse;
    use crate::profile::Board64K;
    use crate::scene::ObjectId;
    use crate::scene::Scene;
    use crate::shapes::Leaving;
    use build::Cube;
    use cells::tests::across_a_cell_edge;
    use std::{boxed::Box, format, string::String, vec::Vec};

    type Arena = heapless::Vec<u32, 60_000>;

    /// A Q32.32 world value as exact decimal text.
    fn decimal(q: i64) -> String {
        let (int, frac) = (q.unsigned_abs() >> 32, q.unsigned_abs() & 0xFFFF_FFFF);
        let digits = frac as u128 * 5u128.pow(32);
        format!("{}{int}.{digits:032}", if q < 0 { "-" } else { "" })
    }

    /// The scene's text with a light at the normalised point `light` and
    /// boxes given by normalised corners (even spans, so that their centres
    /// and half-sizes are exact): the eye and a second light at ±8 fix the
    /// normalisation (centre 0, a world unit 2^26 raw units).
    fn exact_scene(light: [i64; 3], boxes: &[[[i64; 3]; 2]]) -> String {
        let world = |raw: i64| decimal(raw * 64);
        let mut text = String::from("VIEWPOINT -8 -8 -8\nLIGHT 10 8 8 8\nSURFACE 1 .1 .1 .1 .5 .5 .5 0 0 0 0 0 0\n");
        text += &format!("LIGHT 10 {} {} {}\n", world(light[0]), world(light[1]), world(light[2]));
        for [lo, hi] in boxes {
            let c = [0, 1, 2].map(|a| world((lo[a] + hi[a]) / 2));
            let h = [0, 1, 2].map(|a| world((hi[a] - lo[a]) / 2));
            text += &format!("BOX 1 {} {} {} {} {} {}\n", c[0], c[1], c[2], h[0], h[1], h[2]);
        }
        text
    }

    /// Shadow rays aimed through points just past a cell's edge inside a box
    /// (the box listed in that cell only thanks to rounding outward): the
    /// light buffer gives the naive mode's answer, and bounds cut by a few
    /// units would not.
    #[test]
    fn grazing_shadow_rays_get_the_naive_answer() {
        let mut next = crate::test_rng::seeded(0x6a2e_5ad0);
        let (mut blocked, mut wrong_if_cut) = (0, 0);
        for case in 0..300 {
            let (light, corners, point) = across_a_cell_edge(&mut next, MAX_LEVEL);
            let [lo, hi] = corners.map(|c| c.map(|v| v & !1));
            let text = exact_scene(light, &[[lo, [0, 1, 2].map(|a| hi[a].max(lo[a] + 2))]]);
            let mut scene: Box<Scene<Board64K>> = Box::default();
            parse(&text, &mut scene, &mut |e| panic!("case {case}: {e}\n{text}")).unwrap();
            let view = scene.view();
            assert_eq!(view.lights[1].position.wide(), light, "case {case}: the normalisation moved");
            let origin = Vec3::from_bits([0, 1, 2].map(|a| (light[a] + 3 * (point[a] - light[a])) as i32));
            let (dir, distance) = (view.lights[1].position - origin).direction_and_length_estimate().unwrap();
            let ray = Ray { origin, dir };
            let t_max = Scalar::from_bits(distance.to_bits() - 1);
            let naive = Naive.occluded(&view, &ray, t_max, None, &mut Mailbox::none());
            blocked += naive as usize;
            let mut words = Arena::new();
            let buffer = LightBuffer::build_with_margin(&view, &mut words, MAX_CELLS_A_SIDE, usize::MAX, MARGIN);
            assert_eq!(buffer.report().cells_a_side, MAX_CELLS_A_SIDE);
            let lit = LightBuffered::new(&Naive, buffer);
            let answer = lit.occluded_toward(&view, &ray, t_max, 1, None, &mut Mailbox::none());
            assert_eq!(answer, naive, "case {case}: {ray:?} to {t_max:?}\n{text}");
            let mut cone_words = Arena::new();
            let cones = LightBuffer::build(&view, &mut cone_words, MAX_CELLS_A_SIDE);
            assert!(cones.report().cones, "case {case}: one box gets cones");
            let answer =
                LightBuffered::new(&Naive, cones).occluded_toward(&view, &ray, t_max, 1, None, &mut Mailbox::none());
            assert_eq!(answer, naive, "case {case}, cones: {ray:?} to {t_max:?}\n{text}");
            let cut = LightBuffer::build_with_margin(&view, &mut words, MAX_CELLS_A_SIDE, usize::MAX, -4);
            let answer =
                LightBuffered::new(&Naive, cut).occluded_toward(&view, &ray, t_max, 1, None, &mut Mailbox::none());
            wrong_if_cut += (answer != naive) as usize;
        }
        assert!(blocked > 250 && wrong_if_cut > 200, "{blocked} blocked, {wrong_if_cut} wrong with bounds cut by 4");
    }

    /// A random scene of spheres, boxes, rectangles and triangles near the
    /// origin, with one to three lights, some inside objects' bounds.
    fn random_scene(next: &mut impl FnMut() -> u64) -> Box<Scene<Board64K>> {
        let mut c = |range: u64| (next() % (2 * range * 100 + 1)) as f64 / 100.0 - range as f64;
        let mut text = String::from("VIEWPOINT 0 2 14\nSURFACE 1 0.1 0.1 0.1 0.5 0.5 0.5 0 0 0 0 0 0\n");
        let objects = 1 + c(15).abs() as usize;
        for _ in 0..objects {
            let (x, y, z, size) = (c(6), c(6), c(6), 0.05 + c(2).abs());
            text += &match c(2).abs() as u32 {
                0 => format!("SPHERE 1 {size} {x} {y} {z}\n"),
                1 => format!("BOX 1 {x} {y} {z} {size} {} {}\n", 0.1 + c(1).abs(), 0.1 + c(1).abs()),
                _ if c(1) > 0.0 => format!(
                    "RECTANGLE 1 {x} {y} {z} {} {y} {z} {} {y} {} {x} {y} {}\n",
                    x + size,
                    x + size,
                    z + size,
                    z + size
                ),
                _ => format!("TRIANGLE 1 {x} {y} {z} {} {} {z} {x} {} {}\n", x + size, y + c(1), y + size, z + c(1)),
            };
        }
        for _ in 0..1 + c(1).abs() as usize * 2 {
            text += &format!("LIGHT 10 {} {} {}\n", c(7), c(7), c(7));
        }
        let mut scene: Box<Scene<Board64K>> = Box::default();
        if parse(&text, &mut scene, &mut |_| {}).is_err() {
            scene.clear();
        }
        scene
    }

    /// Shadow rays from the hits of random rays on random scenes to every
    /// light, aimed as the tracer aims them, leaving their object either
    /// way: the light buffer (cubes at every fineness, cones, each squeezed
    /// into arenas too small for every light) gives the naive mode's
    /// answer, and the cones pass a minority of the objects.
    #[test]
    fn shadow_rays_get_the_naive_answer() {
        let mut next = crate::test_rng::seeded(0x5_4ad0_b0ff);
        let (mut rays, mut blocked, mut buffered) = (0u64, 0u64, 0u64);
        let (mut coned, mut passed) = (0u64, 0u64);
        for _ in 0..150 {
            let scene = random_scene(&mut next);
            let view = scene.view();
            if view.object_count() == 0 {
                continue;
            }
            let cells = 1 << (next() % (MAX_LEVEL as u64 + 1));
            let mut words = Arena::new();
            let mut small = heapless::Vec::<u32, 160>::new();
            let (mut cone_words, mut few_cones) = (Arena::new(), heapless::Vec::<u32, 40>::new());
            let buffers = [
                LightBuffer::build_with_margin(&view, &mut words, cells, usize::MAX, MARGIN),
                LightBuffer::build_with_margin(&view, &mut small, 64, usize::MAX, MARGIN),
                LightBuffer::build(&view, &mut cone_words, cells),
                LightBuffer::build(&view, &mut few_cones, cells),
            ];
            assert!(buffers[2].report().cones && buffers[2].report().lights == view.lights.len());
            buffered += buffers.iter().map(|b| b.report().lights as u64).sum::<u64>();
            for _ in 0..300 {
                // From anywhere near the objects towards a point of one's
                // bounds.
                let origin = Vec3::from_bits([0; 3].map(|_| ((next() % (1 << 30)) as i64 - (1 << 29)) as i32));
                let bounds = view.shape(ObjectId((next() % view.object_count() as u64) as u32)).bounds();
                let (lo, hi) = (bounds.min.wide(), bounds.max.wide());
                let target = [0, 1, 2].map(|a| lo[a] + (next() % (hi[a] - lo[a] + 1) as u64) as i64);
                let Some(dir) = Dir::normalize([0, 1, 2].map(|a| target[a] - origin.wide()[a])) else { continue };
                let ray = Ray { origin, dir };
                let Some(hit) = Naive.nearest(&view, &ray, None, &mut Mailbox::none()) else { continue };
                let point = ray.at(hit.t);
                for (light, l) in view.lights.iter().enumerate() {
                    let Some((dir, distance)) = (l.position - point).direction_and_length_estimate() else { continue };
                    let shadow = Ray { origin: point, dir };
                    let t_max = Scalar::from_bits((distance.to_bits() - 1).max(0));
                    let leaving = if next() % 2 == 0 { Leaving::Inward } else { Leaving::Outward };
                    let start = Some(RayStart { object: hit.object, leaving });
                    let naive = Naive.occluded(&view, &shadow, t_max, start, &mut Mailbox::none());
                    rays += 1;
                    blocked += naive as u64;
                    if let Some(cones) = buffers[2].light_cones(light) {
                        let toward = shadow.dir.bits().map(|c| -(c >> 16));
                        coned += view.object_count() as u64;
                        passed += cones.chunks_exact(cones::CONE).filter(|&c| cones::passes(c, toward)).count() as u64;
                    }
                    for buffer in buffers {
                        let answer = LightBuffered::new(&Naive, buffer).occluded_toward(
                            &view,
                            &shadow,
                            t_max,
                            light,
                            start,
                            &mut Mailbox::none(),
                        );
                        assert_eq!(answer, naive, "{shadow:?} to light {light} ({:?})", buffer.report());
                    }
                }
            }
        }
        assert!(
            rays > 20_000 && blocked > rays / 10 && buffered > 300,
            "{rays} rays, {blocked} blocked, {buffered} buffered"
        );
        assert!(passed * 3 < coned, "the cones passed {passed} of {coned} objects");
    }

    /// A buffer built for one scene is refused for another, and one with an
    /// entry missing, deeper than its object, out of order or cut short.
    #[test]
    fn a_buffer_that_misses_anything_is_refused() {
        let text = "VIEWPOINT -9 -9 -9\nLIGHT 10 9 9 9\nLIGHT 5 -2 9 1\nSURFACE 1 .1 .1 .1 .8 .2 .2 0 0 0 1 0 0\n\
                    SPHERE 1 1 0 0 0\nSPHERE 1 0.5 2 2 2\nBOX 1 -3 -3 -3 1 1 1\nBOX 1 0 9 0 20 0.1 20\n";
        let mut scene: Box<Scene<Board64K>> = Box::default();
        parse(text, &mut scene, &mut |e| panic!("{e}")).unwrap();
        let view = scene.view();
        let mut arena = Arena::new();
        let words: Vec<u32> =
            LightBuffer::build_with_margin(&view, &mut arena, 16, usize::MAX, MARGIN).words().to_vec();
        let buffer = LightBuffer::verified(&view, &words).unwrap();
        assert_eq!(buffer.report().lights, 2);
        let entries = buffer.entries;
        // The second light is inside the big flat box's widened bounds: on
        // its own list.
        let own = Cube::read(&words[Words::HEADER + Words::CUBE..]).own;
        assert!(buffer.list(own).is_some_and(|l| l.iter().any(|&e| e & OBJECT_MASK == 3)), "around the light");
        let changed = |change: &dyn Fn(&mut Vec<u32>)| {
            let mut words = words.clone();
            change(&mut words);
            LightBuffer::verified(&view, &words).map(|_| ())
        };
        assert_eq!(changed(&|w| w.truncate(w.len() - 1)), Err(LightBufferError::Malformed));
        assert_eq!(changed(&|w| w[0] ^= 1), Err(LightBufferError::Malformed));
        assert_eq!(changed(&|w| w[4] += 1), Err(LightBufferError::OtherScene));
        assert_eq!(changed(&|w| w[Words::HEADER] += 1), Err(LightBufferError::OtherScene));
        // Every entry in turn made another object, or deeper: each is
        // needed somewhere (unless its object is listed there twice).
        let (mut missed, mut deeper) = (0, 0);
        for e in entries..words.len() {
            let other = |w: &mut Vec<u32>| w[e] = w[e] & !OBJECT_MASK | (((w[e] & OBJECT_MASK) + 1) % 4);
            missed += matches!(changed(&other), Err(LightBufferError::Incomplete { .. } | LightBufferError::Malformed))
                as usize;
            let deepen = |w: &mut Vec<u32>| w[e] += 1 << OBJECT_BITS;
            deeper += changed(&deepen).is_err() as usize;
        }
        assert_eq!(missed, words.len() - entries);
        assert!(deeper > (words.len() - entries) / 2, "{deeper} of {} deepened entries refused", words.len() - entries);
        // The same lights and objects but one moved.
        let mut moved: Box<Scene<Board64K>> = Box::default();
        parse(&text.replace("0.5 2 2 2", "0.5 2 -2 2"), &mut moved, &mut |e| panic!("{e}")).unwrap();
        let refused = LightBuffer::verified(&moved.view(), &words);
        assert!(matches!(refused, Err(LightBufferError::Incomplete { object: ObjectId(1), .. })), "{refused:?}");
    }
}
