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
use crate::shapes::{Aabb, Leaving, Ray, ShapeKinds};

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

/// A face's cells of one object (or the union of a light's objects): the
/// first and last along each of the face's two other axes, at the finest
/// level built, and its depth.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
struct Rect {
    low: [u8; 2],
    high: [u8; 2],
    depth: u32,
}

impl Rect {
    /// The rectangle `shift` levels coarser.
    fn coarser(self, shift: u32) -> Rect {
        Rect { low: self.low.map(|c| c >> shift), high: self.high.map(|c| c >> shift), ..self }
    }

    fn cells(self) -> usize {
        (self.high[0] - self.low[0] + 1) as usize * (self.high[1] - self.low[1] + 1) as usize
    }

    fn union(self, o: Rect) -> Rect {
        Rect {
            low: [0, 1].map(|k| self.low[k].min(o.low[k])),
            high: [0, 1].map(|k| self.high[k].max(o.high[k])),
            depth: 0,
        }
    }
}

/// Where an object is seen from a light: around it (its widened bounds hold
/// the light), or on each face a rectangle of cells, if any.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Footprint {
    Around,
    Faces([Option<Rect>; 6]),
}

/// The two axes of a face of axis `a`, in the order its cells are indexed.
const fn other_axes(a: usize) -> [usize; 2] {
    [(a + 1) % 3, (a + 2) % 3]
}

/// The cell `⌊2^level·(y + x) / 2x⌋` (clamped to `0..2^level`) of the
/// ratio `y / x`, `x > 0`, `|x|, |y| < 2^61`: exact, and monotone in the
/// ratio like the ray's. By long division, a bit a step: a 64-bit division
/// is long code on a 32-bit core, and a build makes up to 24 an object and
/// light (fig5_3's cost a Pico 3 M cycles).
fn cell_of_ratio(y: i64, x: i64, level: u32) -> u8 {
    let (rest, divisor) = (y + x, 2 * x);
    if rest <= 0 {
        return 0;
    }
    if rest >= divisor {
        return ((1 << level) - 1) as u8;
    }
    quotient_bits(rest, divisor, level) as u8
}

/// The first `steps` bits after the point of `rest / divisor` (`0 ≤ rest ≤
/// divisor`, all ones when equal; `2·divisor` fits `T`) by long division, a
/// bit a step: no divider, and on a 32-bit core no 64-bit division either.
#[inline(always)]
fn quotient_bits<T>(mut rest: T, divisor: T, steps: u32) -> u32
where
    T: Copy + Ord + core::ops::Shl<u32, Output = T> + core::ops::SubAssign,
{
    let mut quotient = 0;
    for _ in 0..steps {
        rest = rest << 1;
        quotient <<= 1;
        if rest >= divisor {
            rest -= divisor;
            quotient += 1;
        }
    }
    quotient
}

/// Where the box `[min, max]` widened by `margin` is seen from `light`, with
/// `2^level` cells a face side.
fn footprint(bounds: Aabb, light: [i64; 3], margin: i64, level: u32) -> Footprint {
    let (min, max) = (bounds.min.wide(), bounds.max.wide());
    let low = [0, 1, 2].map(|a| min[a] - margin - light[a]);
    let high = [0, 1, 2].map(|a| max[a] + margin - light[a]);
    if (0..3).all(|a| low[a] <= 0 && 0 <= high[a]) {
        return Footprint::Around;
    }
    let mut faces = [None; 6];
    for (face, slot) in faces.iter_mut().enumerate() {
        let a = face / 2;
        // Along the face's axis, pointing out of the face: [x0, x1].
        let (x0, x1) = if face % 2 == 0 { (low[a], high[a]) } else { (-high[a], -low[a]) };
        if x1 <= 0 {
            continue;
        }
        let mut rect = Rect { low: [0; 2], high: [0; 2], depth: 0 };
        let mut seen = true;
        for (k, b) in other_axes(a).into_iter().enumerate() {
            let (y0, y1) = (low[b], high[b]);
            // The face holds ratios in [−1, 1]; the box's lie in
            // [y0 / x1 or y0 / x0, y1 / x0 or y1 / x1] (over x in (0, x1]).
            if y0 > x1 || y1 < -x1 {
                seen = false;
                break;
            }
            rect.low[k] = match (y0 >= 0, x0 > 0) {
                (true, _) => cell_of_ratio(y0, x1, level),
                (false, true) => cell_of_ratio(y0, x0, level),
                (false, false) => 0,
            };
            rect.high[k] = match (y1 <= 0, x0 > 0) {
                (true, _) => cell_of_ratio(y1, x1, level),
                (false, true) => cell_of_ratio(y1, x0, level),
                (false, false) => ((1 << level) - 1) as u8,
            };
        }
        if seen {
            rect.depth = if x0 > 0 { ((x0 >> DEPTH_SHIFT) as u64).min(DEPTH_MAX as u64) as u32 } else { 0 };
            *slot = Some(rect);
        }
    }
    Footprint::Faces(faces)
}

/// What one light's cube needs at each level up to `finest`: cells (its
/// own list's slot included) and entries.
#[derive(Clone, Copy, Debug, Default)]
struct Needs {
    cells: [usize; MAX_LEVEL as usize + 1],
    entries: [usize; MAX_LEVEL as usize + 1],
}

/// Light `light`'s needs at each level up to `finest`, and the union of its
/// objects' rectangles on each face at `finest`.
fn needs(scene: &SceneView<'_>, light: usize, finest: u32, margin: i64) -> (Needs, [Option<Rect>; 6]) {
    let position = scene.lights[light].position.wide();
    let mut needs = Needs::default();
    let mut faces: [Option<Rect>; 6] = [None; 6];
    let mut around = 0;
    for id in scene.object_ids() {
        match footprint(scene.shape(id).bounds(), position, margin, finest) {
            Footprint::Around => around += 1,
            Footprint::Faces(rects) => {
                for (face, rect) in rects.iter().enumerate() {
                    let Some(rect) = *rect else { continue };
                    faces[face] = Some(faces[face].map_or(rect, |f| f.union(rect)));
                    for level in 0..=finest {
                        needs.entries[level as usize] += rect.coarser(finest - level).cells();
                    }
                }
            }
        }
    }
    for level in 0..=finest {
        let shift = finest - level;
        let cells: usize = faces.iter().flatten().map(|f| f.coarser(shift).cells()).sum();
        needs.cells[level as usize] = 1 + cells;
        needs.entries[level as usize] += around;
    }
    (needs, faces)
}

/// A light's cube as the build and the check read it from the words.
#[derive(Clone, Copy, Debug)]
struct Cube {
    light: [i64; 3],
    /// The cell of the light's own list.
    own: usize,
    /// Per face: its first cell and its rectangle's word.
    faces: [(usize, u32); 6],
}

impl Cube {
    fn read(words: &[u32]) -> Cube {
        Cube {
            light: [0, 1, 2].map(|a| words[a] as i32 as i64),
            own: words[3] as usize,
            faces: core::array::from_fn(|f| (words[4 + 2 * f] as usize, words[5 + 2 * f])),
        }
    }

    /// The cell of cell `(i, j)` of face `face`, if its rectangle holds it.
    fn cell(&self, face: usize, i: u32, j: u32) -> Option<usize> {
        let (first, rect) = self.faces[face];
        cell_in(first, rect, i, j)
    }
}

/// A face's rectangle of cells as a word: its first cells and its sides
/// along the face's two axes (sides 0: no cell).
const fn rect_word(low: [u8; 2], size: [u8; 2]) -> u32 {
    low[0] as u32 | (low[1] as u32) << 8 | (size[0] as u32) << 16 | (size[1] as u32) << 24
}

/// The cell of cell `(i, j)` in the rectangle `rect` whose first cell is
/// `first`, if the rectangle holds it (rows along the first axis).
#[inline(always)]
fn cell_in(first: usize, rect: u32, i: u32, j: u32) -> Option<usize> {
    let (i, j) = (i.wrapping_sub(rect & 0xFF), j.wrapping_sub(rect >> 8 & 0xFF));
    let (rows, columns) = (rect >> 16 & 0xFF, rect >> 24);
    (i < rows && j < columns).then(|| first + (i * columns + j) as usize)
}

/// Calls `each(cell, entry)` for every entry of the lists `cube`'s light
/// needs at `level` (`finest` or coarser).
fn for_each_entry(
    scene: &SceneView<'_>,
    cube: &Cube,
    level: u32,
    finest: u32,
    margin: i64,
    mut each: impl FnMut(usize, u32),
) {
    for id in scene.object_ids() {
        match footprint(scene.shape(id).bounds(), cube.light, margin, finest) {
            Footprint::Around => each(cube.own, id.0),
            Footprint::Faces(rects) => {
                for (face, rect) in rects.iter().enumerate() {
                    let Some(rect) = rect.map(|r| r.coarser(finest - level)) else { continue };
                    let entry = rect.depth << OBJECT_BITS | id.0;
                    for i in rect.low[0]..=rect.high[0] {
                        for j in rect.low[1]..=rect.high[1] {
                            if let Some(cell) = cube.cell(face, i as u32, j as u32) {
                                each(cell, entry);
                            }
                        }
                    }
                }
            }
        }
    }
}

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
}

impl core::fmt::Debug for LightBuffer<'_> {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        f.debug_struct("LightBuffer").field("report", &self.report()).finish_non_exhaustive()
    }
}

impl<'a> LightBuffer<'a> {
    /// No light buffered: every shadow ray takes the accelerator.
    pub const NONE: LightBuffer<'static> = LightBuffer { words: &[], lights: 0, level: 0, cells: 0, entries: 0 };

    /// Builds the buffer over `scene`'s lights and objects in `words` with
    /// at most `cells_a_side` cells a face side (rounded down to a power of
    /// two, at most [`MAX_CELLS_A_SIDE`]): the finest cube whose lists fit
    /// the arena, or, when even one cell a face does not fit, the first
    /// lights that do.
    ///
    /// ```
    /// use octrace_core::accel::{LightBuffer, LightBuffered, Naive};
    /// use octrace_core::parse::parse;
    /// use octrace_core::profile::Board64K;
    /// use octrace_core::render::Renderer;
    /// use octrace_core::scene::Scene;
    /// use embedded_graphics::{mock_display::MockDisplay, pixelcolor::Rgb888};
    ///
    /// let mut scene = Scene::<Board64K>::new();
    /// parse("RASTER 8 8\nVIEWPOINT 0 0 5\nLIGHT 10 5 5 5\nSPHERE 1 1 0 0 0\nSPHERE 1 0.5 1 1 1\nSPHERE 1 0.3 2 2 2\nSURFACE 1 .1 .1 .1 .8 .2 .2 0 0 0 1 0 0\n", &mut scene, &mut |e| panic!("{e}")).unwrap();
    /// let mut words = heapless::Vec::<u32, 400>::new();
    /// let buffer = LightBuffer::build(&scene.view(), &mut words, 8);
    /// assert_eq!((buffer.report().lights, buffer.report().cells_a_side), (1, 8));
    ///
    /// let mut lit = MockDisplay::<Rgb888>::new();
    /// Renderer::new(scene.view(), &LightBuffered::new(&Naive, buffer))?.render(&mut lit)?;
    /// let mut plain = MockDisplay::<Rgb888>::new();
    /// Renderer::new(scene.view(), &Naive)?.render(&mut plain)?;
    /// assert_eq!(lit, plain);
    /// # Ok::<(), Box<dyn core::error::Error>>(())
    /// ```
    pub fn build<W: Arena<u32>>(scene: &SceneView<'_>, words: &'a mut W, cells_a_side: u32) -> LightBuffer<'a> {
        Self::build_with_margin(scene, words, cells_a_side, usize::MAX, MARGIN)
    }

    /// [`LightBuffer::build`] for at most the first `lights` lights, with
    /// objects widened by `margin` (tests make it too small).
    pub(crate) fn build_with_margin<W: Arena<u32>>(
        scene: &SceneView<'_>,
        words: &'a mut W,
        cells_a_side: u32,
        lights: usize,
        margin: i64,
    ) -> LightBuffer<'a> {
        words.clear();
        let finest = (31 - cells_a_side.max(1).leading_zeros()).min(MAX_LEVEL);
        let capacity = W::CAPACITY;
        let objects = scene.object_count();
        if scene.lights.is_empty() || objects > OBJECT_MASK as usize + 1 {
            return Self::parse(words.as_slice()).unwrap_or(LightBuffer::NONE);
        }
        // The lights' needs at every level: the finest where all fit, else
        // one cell a face for as many lights as fit.
        let lights = scene.lights.len().min(lights);
        let mut total = Needs::default();
        for light in 0..lights {
            let (needs, _) = needs(scene, light, finest, margin);
            for level in 0..=finest as usize {
                total.cells[level] += needs.cells[level];
                total.entries[level] += needs.entries[level];
            }
        }
        // The cells end with one more: the last list's end.
        let fits = |lights: usize, cells: usize, entries: usize| Words::of(lights, cells + 1, entries) <= capacity;
        let chosen = (0..=finest).rev().find(|&l| fits(lights, total.cells[l as usize], total.entries[l as usize]));
        let (level, lights) = match chosen {
            Some(level) => (level, lights),
            None => {
                let (mut cells, mut entries, mut fitting) = (0, 0, 0);
                for light in 0..lights {
                    let (needs, _) = needs(scene, light, 0, margin);
                    if !fits(fitting + 1, cells + needs.cells[0], entries + needs.entries[0]) {
                        break;
                    }
                    (cells, entries, fitting) = (cells + needs.cells[0], entries + needs.entries[0], fitting + 1);
                }
                (0, fitting)
            }
        };
        if lights == 0 {
            return LightBuffer::NONE;
        }
        // The header and the cubes, then the cells (each a count first)
        // and the entries.
        for word in [Words::MAGIC, lights as u32, level, 0, objects as u32] {
            let _ = words.push(word);
        }
        let mut cell = 0usize;
        for light in 0..lights {
            let (_, faces) = needs(scene, light, finest, margin);
            for c in scene.lights[light].position.bits() {
                let _ = words.push(c as u32);
            }
            let _ = words.push(cell as u32);
            cell += 1;
            for rect in faces {
                let (low, size) = match rect.map(|r| r.coarser(finest - level)) {
                    Some(r) => (r.low, [0, 1].map(|k| r.high[k] - r.low[k] + 1)),
                    None => ([0; 2], [0; 2]),
                };
                let _ = words.push(cell as u32);
                let _ = words.push(rect_word(low, size));
                cell += size[0] as usize * size[1] as usize;
            }
        }
        let cells = cell + 1;
        words.as_mut_slice()[3] = cells as u32;
        for _ in 0..cells {
            let _ = words.push(0);
        }
        let (head, counts) = words.as_mut_slice().split_at_mut(Words::of(lights, 0, 0));
        let cubes = || head[Words::HEADER..].chunks_exact(Words::CUBE).map(Cube::read);
        for cube in cubes() {
            for_each_entry(scene, &cube, level, finest, margin, |cell, _| counts[cell] += 1);
        }
        let mut end = 0;
        for count in counts.iter_mut() {
            end += *count;
            *count = end;
        }
        for _ in 0..end {
            let _ = words.push(0);
        }
        let (head, rest) = words.as_mut_slice().split_at_mut(Words::of(lights, 0, 0));
        let (starts, entries) = rest.split_at_mut(cells);
        let cubes = || head[Words::HEADER..].chunks_exact(Words::CUBE).map(Cube::read);
        for cube in cubes() {
            for_each_entry(scene, &cube, level, finest, margin, |cell, entry| {
                starts[cell] -= 1;
                entries[starts[cell] as usize] = entry;
            });
        }
        for cell in 0..cells - 1 {
            crate::sort::sort_by_key(&mut entries[starts[cell] as usize..starts[cell + 1] as usize], |&e| e);
        }
        Self::parse(words.as_slice()).unwrap_or(LightBuffer::NONE)
    }

    /// The buffer in `words` if its header and sizes are sound.
    fn parse(words: &'a [u32]) -> Option<LightBuffer<'a>> {
        let &[magic, lights, level, cells, _] = words.get(..Words::HEADER)? else { return None };
        let (lights, cells) = (lights as usize, cells as usize);
        let entries = words.len().checked_sub(Words::of(lights, cells, 0))?;
        (magic == Words::MAGIC
            && level <= MAX_LEVEL
            && cells > 0
            && words[Words::of(lights, cells, 0) - 1] as usize == entries)
            .then_some(LightBuffer {
                words,
                lights,
                level: level as u8,
                cells: Words::of(lights, 0, 0),
                entries: Words::of(lights, cells, 0),
            })
    }

    /// A buffer built beforehand for a scene, after checking that it holds
    /// everything a buffer built for `scene` would: its lights and object
    /// count, and every object in every cell it can be seen in, at a depth
    /// no greater than where it begins. A build script can so keep a
    /// scene's buffer in flash ([`LightBuffer::words`] of one built on the
    /// host) and a board spend no RAM on it.
    ///
    /// ```
    /// use octrace_core::accel::{LightBuffer, LightBufferError};
    /// use octrace_core::parse::parse;
    /// use octrace_core::profile::Board64K;
    /// use octrace_core::scene::Scene;
    ///
    /// let text = "VIEWPOINT -9 -9 -9\nLIGHT 10 9 9 9\nSPHERE 1 1 0 0 0\nSPHERE 1 0.5 2 2 2\nSURFACE 1 .1 .1 .1 .8 .2 .2 0 0 0 1 0 0\n";
    /// let mut scene = Scene::<Board64K>::new();
    /// parse(text, &mut scene, &mut |e| panic!("{e}")).unwrap();
    /// let mut words = heapless::Vec::<u32, 400>::new();
    /// let built = LightBuffer::build(&scene.view(), &mut words, 8).words().to_vec();
    /// assert!(LightBuffer::verified(&scene.view(), &built).is_ok());
    ///
    /// // The same lights, but the second sphere moved: refused.
    /// let mut other = Scene::<Board64K>::new();
    /// parse(&text.replace("0.5 2 2 2", "0.5 2 -2 2"), &mut other, &mut |e| panic!("{e}")).unwrap();
    /// assert!(matches!(LightBuffer::verified(&other.view(), &built), Err(LightBufferError::Incomplete { .. })));
    /// ```
    pub fn verified(scene: &SceneView<'_>, words: &'a [u32]) -> Result<LightBuffer<'a>, LightBufferError> {
        use LightBufferError::{Incomplete, Malformed, OtherScene};
        let buffer = Self::parse(words).ok_or(Malformed)?;
        let (starts, entries) = words[buffer.cells..].split_at(buffer.entries - buffer.cells);
        if buffer.lights > scene.lights.len() || words[4] as usize != scene.object_count() {
            return Err(OtherScene);
        }
        // Every list within the entries and sorted, every object one of the
        // scene's.
        let list = |cell: usize| Some(&entries[*starts.get(cell)? as usize..*starts.get(cell + 1)? as usize]);
        for pair in starts.windows(2) {
            let list = entries.get(pair[0] as usize..pair[1] as usize).ok_or(Malformed)?;
            let sorted = list.windows(2).all(|e| e[0] >> OBJECT_BITS <= e[1] >> OBJECT_BITS);
            if !sorted || list.iter().any(|&e| (e & OBJECT_MASK) as usize >= scene.object_count()) {
                return Err(Malformed);
            }
        }
        let n = 1u32 << buffer.level;
        for (light, cube) in words[Words::HEADER..buffer.cells].chunks_exact(Words::CUBE).map(Cube::read).enumerate() {
            if cube.light != scene.lights[light].position.wide() {
                return Err(OtherScene);
            }
            let rects_fit = cube.faces.iter().all(|&(first, rect)| {
                let [low, size] = [rect, rect >> 16].map(|w| [w & 0xFF, w >> 8 & 0xFF]);
                (0..2).all(|k| low[k] + size[k] <= n) && first + ((size[0] * size[1]) as usize) < starts.len()
            });
            if !rects_fit || cube.own >= starts.len() - 1 {
                return Err(Malformed);
            }
            for id in scene.object_ids() {
                let listed = |cell: Option<usize>, depth: u32| {
                    cell.and_then(list)
                        .is_some_and(|l| l.iter().any(|&e| e & OBJECT_MASK == id.0 && e >> OBJECT_BITS <= depth))
                };
                let seen = match footprint(scene.shape(id).bounds(), cube.light, MARGIN, buffer.level as u32) {
                    Footprint::Around => listed(Some(cube.own), 0),
                    Footprint::Faces(rects) => rects.iter().enumerate().all(|(face, rect)| {
                        rect.is_none_or(|r| {
                            (r.low[0]..=r.high[0]).all(|i| {
                                (r.low[1]..=r.high[1]).all(|j| listed(cube.cell(face, i as u32, j as u32), r.depth))
                            })
                        })
                    }),
                };
                if !seen {
                    return Err(Incomplete { light, object: id });
                }
            }
        }
        Ok(buffer)
    }

    /// The words: what a build script writes out to keep the buffer in
    /// flash (see [`LightBuffer::verified`]).
    pub fn words(&self) -> &'a [u32] {
        self.words
    }

    /// Its size and fineness.
    pub fn report(&self) -> LightBufferReport {
        let cells = self.entries - self.cells;
        LightBufferReport {
            cells_a_side: if self.lights > 0 { 1 << self.level } else { 0 },
            lights: self.lights,
            cells,
            entries: self.words.len() - self.entries,
            words: self.words.len(),
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
        self.build_for(scene, cells_a_side, usize::MAX)
    }

    /// [`LightBufferStore::build`] for at most the first `lights` lights.
    pub(crate) fn build_for(&mut self, scene: &SceneView<'_>, cells_a_side: u32, lights: usize) -> LightBuffer<'_> {
        LightBuffer::build_with_margin(scene, &mut self.words, cells_a_side, lights, MARGIN)
    }

    /// The buffer last built (none before the first build).
    pub fn buffer(&self) -> LightBuffer<'_> {
        LightBuffer::parse(self.words.as_slice()).unwrap_or(LightBuffer::NONE)
    }
}

impl LightBuffer<'_> {
    /// Whether anything blocks `ray`, a shadow ray from its origin towards
    /// the scene's light `light` as the tracer aims it (see [`RAY_SLACK`]),
    /// before `t_max`; the blocker is left in the mailbox. `None` when the
    /// light is not buffered: the caller asks its accelerator.
    #[inline]
    #[allow(clippy::too_many_arguments)]
    pub(crate) fn occluded(
        &self,
        scene: &SceneView<'_>,
        kinds: ShapeKinds,
        ray: &Ray,
        t_max: Scalar,
        light: usize,
        start: Option<RayStart>,
        mailbox: &mut Mailbox<'_>,
    ) -> Option<bool> {
        let ([own, cell], depth) = self.lists(ray.origin.bits(), light)?;
        let shadow = Shadow { scene, kinds, ray, t_max, start, depth };
        // The light's own list is mostly empty.
        Some((!own.is_empty() && shadow.blocked_by(own, mailbox)) || shadow.blocked_by(cell, mailbox))
    }

    /// The lists a shadow ray from `origin` to light `light` tests (the
    /// light's own and its cell's) and the ray's depth; `None` when the
    /// light is not buffered.
    #[inline(never)]
    fn lists(&self, origin: [i32; 3], light: usize) -> Option<([&[u32]; 2], u32)> {
        if light >= self.lights {
            return None;
        }
        let cube = self.words.get(Words::HEADER + Words::CUBE * light..)?.get(..Words::CUBE)?;
        let v = [0, 1, 2].map(|a| origin[a].checked_sub(cube[a] as i32));
        let (face, m, [i, j]) = direction([v[0]?, v[1]?, v[2]?], self.level)?;
        let own = self.list(cube[3] as usize)?;
        let cell = match cell_in(cube[4 + 2 * face] as usize, cube[5 + 2 * face], i, j) {
            Some(cell) => self.list(cell)?,
            None => &[],
        };
        Some(([own, cell], m >> DEPTH_SHIFT))
    }

    /// The list of cell `cell`, if there is one.
    #[inline(always)]
    fn list(&self, cell: usize) -> Option<&[u32]> {
        let starts = self.words.get(self.cells + cell..self.cells + cell + 2)?;
        self.words.get(self.entries + starts[0] as usize..self.entries + starts[1] as usize)
    }
}

/// Where the direction `v` (from a light) is in a cube of `2^level` cells a
/// side: its face (its largest component's axis, `x` before `y` before `z`,
/// then that component's sign), that component's magnitude `m`, and its
/// cell along the face's two other axes. `None` for the zero vector and
/// for components of 2^30 or more (none in the scene's range).
#[inline(always)]
fn direction([x, y, z]: [i32; 3], level: u8) -> Option<(usize, u32, [u32; 2])> {
    let (ax, ay, az) = (x.unsigned_abs(), y.unsigned_abs(), z.unsigned_abs());
    let (face, m, vb, vc) = if ax >= ay && ax >= az {
        ((x < 0) as usize, ax, y, z)
    } else if ay >= az {
        (2 + (y < 0) as usize, ay, z, x)
    } else {
        (4 + (z < 0) as usize, az, x, y)
    };
    if m == 0 || m >= MAX_COMPONENT {
        return None;
    }
    Some((face, m, [cell_along(vb, m, level), cell_along(vc, m, level)]))
}

/// The cell `⌊2^level·(v + m) / 2m⌋` of `v` along a face whose axis's
/// component is `m` (`2^level − 1` when `v = m`): the finest cube's cell,
/// a bit a step in 32 bits (`m < 2^30` and `|v| ≤ m`, so nothing reaches
/// 2^32), then its coarser one (a quotient rounded down, halved and
/// rounded down, is the quotient of the half rounded down). A fixed count
/// of steps, which the compiler writes out without a loop.
#[inline(never)]
fn cell_along(v: i32, m: u32, level: u8) -> u32 {
    quotient_bits((v as u32).wrapping_add(m), m << 1, MAX_LEVEL) >> (MAX_LEVEL - level as u32)
}

/// A shadow ray testing lists.
struct Shadow<'s, 'r> {
    scene: &'s SceneView<'s>,
    kinds: ShapeKinds,
    ray: &'r Ray,
    t_max: Scalar,
    start: Option<RayStart>,
    /// The ray's depth: objects beyond it cannot block.
    depth: u32,
}

impl Shadow<'_, '_> {
    /// Whether an object of `list` up to the ray's depth blocks it (the
    /// blocker left in the mailbox).
    #[inline(never)]
    fn blocked_by(&self, list: &[u32], mailbox: &mut Mailbox<'_>) -> bool {
        for &entry in list {
            if entry >> OBJECT_BITS > self.depth {
                break;
            }
            let object = entry & OBJECT_MASK;
            let leaving = RayStart::leaving(self.start, ObjectId(object));
            // A ray leaving an object outward never meets it again (every
            // shape's test says so first).
            if leaving == Leaving::Outward {
                continue;
            }
            let Some(&handle) = self.scene.objects.get(object as usize) else { continue };
            if self.scene.intersect_handle(self.kinds, handle, self.ray, self.t_max, leaving).is_some() {
                mailbox.blocker = object;
                return true;
            }
        }
        false
    }
}

/// An accelerator with a light buffer in front of its shadow rays: every
/// query is the accelerator's but [`Accelerator::occluded_toward`] for a
/// buffered light, which tests only the objects its cell lists (the same
/// answer). See [`LightBuffer::build`].
#[derive(Clone, Copy, Debug)]
pub struct LightBuffered<'a, A> {
    accel: &'a A,
    buffer: LightBuffer<'a>,
}

impl<'a, A> LightBuffered<'a, A> {
    /// `accel` with `buffer` (built over the same scene) in front of its
    /// shadow rays.
    pub fn new(accel: &'a A, buffer: LightBuffer<'a>) -> Self {
        LightBuffered { accel, buffer }
    }
}

impl<A: Accelerator> Accelerator for LightBuffered<'_, A> {
    const KINDS: ShapeKinds = A::KINDS;
    const USES_MAILBOX: bool = A::USES_MAILBOX;

    fn first_hits_by_screen(&self) -> bool {
        self.accel.first_hits_by_screen()
    }

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
        match self.buffer.occluded(scene, A::KINDS, ray, t_max, light, start, mailbox) {
            Some(blocked) => blocked,
            None => self.accel.occluded_toward(scene, ray, t_max, light, start, mailbox),
        }
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
    use std::{boxed::Box, format, string::String, vec::Vec};

    type Arena = heapless::Vec<u32, 60_000>;

    /// The cell of the point `p` seen from `light`, as a shadow ray from `p`
    /// finds it, and whether the footprint lists it there at no greater
    /// depth.
    fn listed(footprint: &Footprint, light: [i64; 3], p: [i64; 3], level: u32) -> bool {
        let v = [0, 1, 2].map(|a| (p[a] - light[a]) as i32);
        match (direction(v, level as u8), footprint) {
            (_, Footprint::Around) => true,
            (None, Footprint::Faces(_)) => false,
            (Some((face, m, [i, j])), Footprint::Faces(rects)) => rects[face].is_some_and(|r| {
                (r.low[0] as u32..=r.high[0] as u32).contains(&i)
                    && (r.low[1] as u32..=r.high[1] as u32).contains(&j)
                    && r.depth <= m >> DEPTH_SHIFT
            }),
        }
    }

    /// The long division gives the quotient, clamped, for every size of
    /// ratio: both sides of the face, its edges, and each cell's edges.
    #[test]
    fn cells_of_ratios_are_the_clamped_quotients() {
        let mut next = crate::test_rng::seeded(0x7a71_0c31_1d1e);
        for _ in 0..200_000 {
            let level = (next() % (MAX_LEVEL as u64 + 1)) as u32;
            let x = (next() % (1 << (1 + next() % 42))) as i64 + 1;
            let y = match next() % 4 {
                // On a cell's edge, or a unit either side of it.
                0 => {
                    let k = (next() % ((1 << level) + 1)) as i64;
                    (2 * k - (1 << level)) * x / (1 << level) + (next() % 3) as i64 - 1
                }
                _ => (next() % (6 * x as u64)) as i64 - 3 * x,
            };
            let n = 1i64 << level;
            let quotient = (n * (y + x)).div_euclid(2 * x).clamp(0, n - 1) as u8;
            assert_eq!(cell_of_ratio(y, x, level), quotient, "y {y} x {x} level {level}");
        }
    }

    /// Every point of an object's bounds widened by the margin, corners and
    /// faces included, is in a cell its footprint lists, at a depth no
    /// greater than its own: the light's own list when the bounds hold the
    /// light. Boxes of every size, near the light and far, at every level.
    #[test]
    fn every_point_of_the_widened_bounds_is_in_a_listed_cell() {
        let mut next = crate::test_rng::seeded(0x1_1647_b0ff);
        let mut coordinate = move |bits: u32| (next() % (2 << bits)) as i64 - (1 << bits);
        let (mut around, mut points) = (0, 0);
        for _ in 0..20_000 {
            let level = (coordinate(3).unsigned_abs() as u32) % (MAX_LEVEL + 1);
            let light = [0; 3].map(|_| coordinate(27));
            let near = coordinate(1) > 0;
            let lo = [0, 1, 2].map(|a| if near { light[a] + coordinate(12) } else { coordinate(27) });
            let size = 1 + (coordinate(4).unsigned_abs() as u32 * 2).min(27);
            let hi = [0, 1, 2].map(|a| lo[a] + coordinate(size).abs());
            let bounds =
                Aabb { min: Vec3::from_bits(lo.map(|c| c as i32)), max: Vec3::from_bits(hi.map(|c| c as i32)) };
            let footprint = footprint(bounds, light, MARGIN, level);
            around += (footprint == Footprint::Around) as usize;
            let (wlo, whi) = (lo.map(|c| c - MARGIN), hi.map(|c| c + MARGIN));
            for k in 0..16 {
                let p = [0, 1, 2].map(|a| match k {
                    0..8 => {
                        if k >> a & 1 == 1 {
                            whi[a]
                        } else {
                            wlo[a]
                        }
                    }
                    _ => wlo[a] + coordinate(28).abs() % (whi[a] - wlo[a] + 1),
                });
                points += 1;
                assert!(listed(&footprint, light, p, level), "{p:?} from {light:?}: {footprint:?}, level {level}");
            }
        }
        assert!(around > 100 && points > 300_000, "{around} around the light");
    }

    /// `lo` and `hi` as bounds.
    fn aabb(lo: [i64; 3], hi: [i64; 3]) -> Aabb {
        Aabb { min: Vec3::from_bits(lo.map(|c| c as i32)), max: Vec3::from_bits(hi.map(|c| c as i32)) }
    }

    /// A box whose face lies a unit or two past a cell's edge from the light,
    /// and a point inside it two units from that face, seen in the cell
    /// beyond the edge (a direction `(m, v)` with `v / m` just below
    /// `2k / N − 1`): `(light, box, point)` on a random face of the cube.
    fn across_a_cell_edge(next: &mut impl FnMut() -> u64, level: u32) -> ([i64; 3], [[i64; 3]; 2], [i64; 3]) {
        let n = 1i64 << level;
        let light = [0; 3].map(|_| (next() % (1 << 24)) as i64 - (1 << 23));
        let (face, m) = ((next() % 6) as usize, (1 << 22) + (next() % (1 << 23)) as i64);
        let (a, sign) = (face / 2, if face % 2 == 0 { 1 } else { -1 });
        let [b, c] = other_axes(a);
        // An edge at a ratio in [0, 1): the smallest v beyond it is below.
        let k = n / 2 + (next() % (n as u64 / 2).max(1)) as i64;
        let v = ((2 * k - n) * m).div_euclid(n) - ((2 * k - n) * m % n == 0) as i64;
        let mut point = light;
        point[a] += sign * m;
        point[b] += v;
        point[c] += (next() % 1000) as i64 - 500;
        let mut lo = point;
        let mut hi = point;
        // Two units inside along the face's axis and above the low side.
        lo[a] = point[a] - if sign > 0 { 1 << 20 } else { 2 };
        hi[a] = point[a] + if sign > 0 { 2 } else { 1 << 20 };
        (lo[b], hi[b]) = (point[b] - 2, point[b] + (1 << 20));
        (lo[c], hi[c]) = (point[c] - 1000, point[c] + 1000);
        (light, [lo, hi], point)
    }

    /// The test above is sharp: bounds cut by a few units lose points near a
    /// cell's edge, so a margin smaller than the straying it covers fails.
    #[test]
    fn bounds_cut_by_a_few_units_lose_cells() {
        let mut next = crate::test_rng::seeded(0xc07_ed9e);
        let mut lost = 0;
        for case in 0..2000 {
            let level = 1 + (next() % MAX_LEVEL as u64) as u32;
            let (light, [lo, hi], point) = across_a_cell_edge(&mut next, level);
            let exact = footprint(aabb(lo, hi), light, 0, level);
            assert!(listed(&exact, light, point, level), "case {case}: the exact bounds list the point");
            lost += !listed(&footprint(aabb(lo, hi), light, -4, level), light, point, level) as usize;
        }
        assert!(lost > 1500, "only {lost} of 2000 points lost by bounds cut by 4 units");
    }

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
            let buffer = LightBuffer::build(&view, &mut words, MAX_CELLS_A_SIDE);
            assert_eq!(buffer.report().cells_a_side, MAX_CELLS_A_SIDE);
            let lit = LightBuffered::new(&Naive, buffer);
            let answer = lit.occluded_toward(&view, &ray, t_max, 1, None, &mut Mailbox::none());
            assert_eq!(answer, naive, "case {case}: {ray:?} to {t_max:?}\n{text}");
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
    /// way: the light buffer (at every fineness, and squeezed into arenas
    /// too small for every light) gives the naive mode's answer.
    #[test]
    fn shadow_rays_get_the_naive_answer() {
        let mut next = crate::test_rng::seeded(0x5_4ad0_b0ff);
        let (mut rays, mut blocked, mut buffered) = (0u64, 0u64, 0u64);
        for _ in 0..150 {
            let scene = random_scene(&mut next);
            let view = scene.view();
            if view.object_count() == 0 {
                continue;
            }
            let cells = 1 << (next() % (MAX_LEVEL as u64 + 1));
            let mut words = Arena::new();
            let mut small = heapless::Vec::<u32, 160>::new();
            let buffers = [LightBuffer::build(&view, &mut words, cells), LightBuffer::build(&view, &mut small, 64)];
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
            rays > 20_000 && blocked > rays / 10 && buffered > 150,
            "{rays} rays, {blocked} blocked, {buffered} buffered"
        );
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
        let words: Vec<u32> = LightBuffer::build(&view, &mut arena, 16).words().to_vec();
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
