//! Camera rays without a walk: each object's bounds seen from the eye, as a
//! window of the image and the nearest its hit can be (the first-hit idea of
//! Weghorst, Hooper and Greenberg 1984, kept exact).
//!
//! Once per renderer (at its first pixel, where a caller's stop is asked
//! before each object, as before each ray), every object's bounds, widened
//! by the filing margin, are projected into the camera's offsets
//! ([`Projection::window`]), and the
//! objects are sorted by a lower bound of the parameter of any hit on them
//! (the distance from the eye to the widened box). For a band of rows the
//! objects whose window meets the band are kept, still in that order, and
//! of those, for each tile of the band, the ones whose window meets the
//! tile (both lists as 16-bit positions in the sorted bounds: 2 bytes an
//! entry, not a bound's 16, which is what lets a 16 KiB board keep them). A camera ray then tests its tile's objects whose window holds its
//! offsets, in order, until the next one's bound is beyond the nearest hit
//! so far.
//!
//! The same lists serve the reflections of camera rays off one mirror
//! along an axis (a floor's, a chessboard's), made from the eye's mirror
//! image (see `scene/mirror.rs`): each bound widened by the most such a ray
//! strays from that camera's ray, its window taken at the camera ray's
//! offsets, its nearest parameter less the camera ray's.
//!
//! Exactness: a hit point strays from its object by less than the filing
//! margin (the octree relies on the same bound), and a camera ray from its
//! ideal direction by a few units, so every object a ray can hit has the
//! ray's offsets in its window and its bound at most the hit's parameter.
//! The earlier-object rule for equal parameters is kept by testing every
//! object whose bound is not beyond the nearest hit.

use crate::accel::{Hit, RayStart, FILING_MARGIN};
use crate::math::{isqrt, mul_i64_wide, Scalar};
use crate::scene::{Camera, CameraRay, MirrorPlane, ObjectId, Projection, SceneView};
use crate::shade::Poll;
use crate::shapes::{Leaving, Ray, ShapeKind, ShapeKinds};

/// Rows of a band: its objects are chosen once for them all.
const BAND_ROWS: u32 = 8;
/// Columns of a tile of a band: the band's objects are chosen again for
/// each, so that a ray passing wide of them all reads a short list.
const TILE_COLUMNS: u32 = 16;
/// The lists pay for their set-up (a projection and a sort per object)
/// when there are at least this many camera rays per object; a scene of
/// more objects than that is left to the walk.
const MIN_RAYS_PER_OBJECT: u64 = 16;
/// A band seen through more objects than this, or a tile through more
/// than the second, leaves its camera rays to the accelerator: a tile's
/// choice reads the band's list, and a ray that hits nothing the tile's,
/// which would then cost more than the walk.
const MAX_BAND_OBJECTS: usize = 512;
const MAX_TILE_OBJECTS: usize = 128;
/// The lists hold 16-bit positions: a scene of more objects leaves its
/// camera rays to the accelerator.
const MAX_OBJECTS: usize = 1 << 16;

/// What a camera ray needs to know of one object: where in the image its
/// bounds are seen and how near its hit can be. Storage in a
/// [`RendererRoom`](crate::RendererRoom) of a profile with `first_hits`:
/// one for each of the scene's objects, beside
/// [`ScreenBound::positions_for`] them.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct ScreenBound {
    /// No camera ray hits the object at a smaller parameter (Q16.16 bits).
    near: i32,
    /// The camera offsets (half sub-cells from the image centre) of the
    /// rays that can meet the object, as [`narrow`] gives them: `narrow(kx)`
    /// in `x[0]..=x[1]`, `narrow(ky)` in `y[0]..=y[1]`. 16 bytes a bound,
    /// not 24, are what let a 16 KiB board keep the lists.
    x: [u16; 2],
    y: [u16; 2],
    /// The object's index (below [`MAX_OBJECTS`]).
    object: u16,
}

impl ScreenBound {
    /// A placeholder to fill storage with.
    pub const EMPTY: ScreenBound = ScreenBound { near: 0, object: 0, x: [0; 2], y: [0; 2] };

    /// How many positions (`u16`s) a renderer needs beside the bounds of
    /// `objects` objects: a band's and a tile's worth.
    pub const fn positions_for(objects: usize) -> usize {
        let band = if objects < MAX_BAND_OBJECTS { objects } else { MAX_BAND_OBJECTS };
        let tile = if objects < MAX_TILE_OBJECTS { objects } else { MAX_TILE_OBJECTS };
        band + tile
    }

    /// How many lists a renderer keeps: the camera's, and with `mirror`
    /// a mirror's too (see [`Linked::MIRROR_HITS`](crate::profile::Linked::MIRROR_HITS)).
    pub const fn lists(mirror: bool) -> usize {
        if mirror {
            2
        } else {
            1
        }
    }

    /// `count` when `wanted`, else 0: a profile's room for the bounds or
    /// the positions.
    pub const fn if_wanted(wanted: bool, count: usize) -> usize {
        if wanted {
            count
        } else {
            0
        }
    }

    /// A window that no offsets are in: an object no listed ray can hit.
    const UNSEEN: ScreenBound = ScreenBound { near: i32::MAX, object: 0, x: [u16::MAX, 0], y: [u16::MAX, 0] };

    /// `MIRROR`: whether `mirror` may be given (a build without mirror
    /// lists links only the camera's form).
    #[inline(never)]
    fn of<const MIRROR: bool>(
        scene: &SceneView<'_>,
        projection: &Projection,
        shift: u32,
        id: ObjectId,
        mirror: Option<MirrorPlane>,
    ) -> ScreenBound {
        let mirror = mirror.filter(|_| MIRROR);
        let bounds = scene.shape(id).bounds();
        let margin = FILING_MARGIN + mirror.map_or(0, |_| MirrorPlane::OFFSET);
        let lo = bounds.min.wide().map(|v| v - margin);
        let hi = bounds.max.wide().map(|v| v + margin);
        let eye = projection.eye();
        // Reflections leave the mirror away from its image of the eye, and
        // from no further than NEAR behind it: a bound wholly beyond that,
        // on the image's side, is met by none of them.
        if let Some(plane) = mirror {
            let (a, c) = (plane.axis, plane.coordinate as i64);
            let reach = MirrorPlane::NEAR as i64;
            if (eye[a] < c && hi[a] < c - reach) || (eye[a] > c && lo[a] > c + reach) {
                return ScreenBound { object: id.0 as u16, ..ScreenBound::UNSEEN };
            }
        }
        let gap2: u128 = (0..3)
            .map(|a| {
                let gap = (lo[a] - eye[a]).max(eye[a] - hi[a]).max(0);
                mul_i64_wide(gap, gap) as u128
            })
            .sum();
        // Within the normalised range the squares fit a u64; beyond it the
        // largest gap is a lower bound of the distance too.
        let distance = match u64::try_from(gap2) {
            Ok(gap2) => isqrt(gap2) as i64,
            Err(_) => (0..3).map(|a| (lo[a] - eye[a]).max(eye[a] - hi[a])).max().unwrap_or(0),
        };
        // A hit's parameter times |dir| (1 + 2^-29 at most) is the hit
        // point's distance from the eye, at least the box's, up to the
        // rounding of the point: a few units below the distance.
        let near = (distance - (distance >> 28) - 8).clamp(0, i32::MAX as i64) as i32;
        let [x, y] = projection.window(lo, hi).unwrap_or([[i32::MIN, i32::MAX]; 2]);
        let narrow = |[low, high]: [i32; 2]| [low, high].map(|k| narrow(k, shift));
        // Below MAX_OBJECTS: the cast is exact.
        ScreenBound { near, object: id.0 as u16, x: narrow(x), y: narrow(y) }
    }
}

// What a board's RAM pays an object for the lists.
const _: () = assert!(core::mem::size_of::<ScreenBound>() == 16);

/// A camera offset in 16 bits: shifted right by the lists' [`window_shift`]
/// (so exactly itself below 2^15 half sub-cells: an image up to 16,383
/// samples wide), biased by 2^15 and clamped. The floor and the clamp are
/// monotonic, so a window narrowed so holds every ray offset it held, and
/// one that met a band or a tile still meets it; unsigned, a board reads
/// it with one instruction.
#[inline(always)]
fn narrow(k: i32, shift: u32) -> u16 {
    (k >> shift).saturating_add(0x8000).clamp(0, 0xffff) as u16
}

/// The shift that brings every offset of `camera`'s rays (below `2 · n ·
/// side` half sub-cells in magnitude, `n` samples a side) within 16 bits:
/// 0 for any image up to 16,383 samples a side.
fn window_shift(camera: &Camera) -> u32 {
    let n = camera.samples();
    let reach = 2 * n * camera.width().max(camera.height());
    let mut shift = 0;
    while reach >> shift >= 0x8000 {
        shift += 1;
    }
    shift
}

/// Keeps the positions of `from` whose bounds in `all` `keep` admits, in
/// order, in `to`; `None` when more than `to` holds.
fn filter(
    all: &[ScreenBound],
    from: impl Iterator<Item = u16>,
    to: &mut [u16],
    keep: impl Fn(&ScreenBound) -> bool,
) -> Option<usize> {
    let mut kept = 0;
    for position in from.filter(|&p| all.get(p as usize).is_some_and(&keep)) {
        *to.get_mut(kept)? = position;
        kept += 1;
    }
    Some(kept)
}

/// The sorted bounds of every object, the chosen ones of the current band
/// and those of its current tile, in caller-owned storage.
pub(crate) struct FirstHits<'a> {
    /// Every object's bound, nearest first.
    all: &'a [ScreenBound],
    /// Room for the positions in `all` of a band's objects, then a tile's.
    positions: &'a mut [u16],
    /// The band's first row (`u32::MAX` before the first) and how many
    /// objects it kept (`None`: too many).
    band_start: u32,
    band: Option<usize>,
    /// The tile's first column (`u32::MAX`: none yet in this band) and
    /// its objects (`None`: too many).
    tile_start: u32,
    tile: Option<usize>,
    /// The bounds' windows are the camera's offsets shifted right by this
    /// ([`window_shift`]).
    shift: u32,
}

impl<'a> FirstHits<'a> {
    /// Whether lists of `scene`'s objects seen by `camera` fit `bounds`
    /// and `positions` (one bound an object, [`ScreenBound::positions_for`]
    /// positions) and pay: the objects are not too many for the image's
    /// rays (or for 16-bit positions).
    pub fn fit(scene: &SceneView<'_>, camera: &Camera, bounds: &[ScreenBound], positions: &[u16]) -> bool {
        let objects = scene.object_count();
        let n = camera.samples() as u64;
        objects <= MAX_OBJECTS
            && objects as u64 * MIN_RAYS_PER_OBJECT <= camera.width() as u64 * camera.height() as u64 * n * n
            && bounds.len() >= objects
            && positions.len() >= ScreenBound::positions_for(objects)
    }

    /// Projects every object of `scene` seen by `camera` into `bounds`,
    /// asking `poll` before each (an object's projection costs about what
    /// a ray does); false if it said stop.
    /// With `mirror` (only when `MIRROR`), `camera` is the eye's mirror
    /// image in it, and the bounds are for the reflections of the real
    /// camera's rays.
    pub fn project<Q: Poll, const MIRROR: bool>(
        scene: &SceneView<'_>,
        camera: &Camera,
        bounds: &mut [ScreenBound],
        poll: &mut Q,
        mirror: Option<MirrorPlane>,
    ) -> bool {
        let projection = Projection::new(camera);
        let shift = window_shift(camera);
        for (slot, id) in bounds.iter_mut().zip(scene.object_ids()) {
            if !poll.go_on() {
                return false;
            }
            *slot = ScreenBound::of::<MIRROR>(scene, &projection, shift, id, mirror);
        }
        true
    }

    /// The lists over the first `objects` of `bounds`, as
    /// [`FirstHits::project`] left them for `camera`, sorted here; `None`
    /// where they do not [fit](FirstHits::fit).
    pub fn new(
        objects: usize,
        camera: &Camera,
        bounds: &'a mut [ScreenBound],
        positions: &'a mut [u16],
    ) -> Option<Self> {
        let all = bounds.get_mut(..objects)?;
        let positions = positions.get_mut(..ScreenBound::positions_for(objects))?;
        crate::sort::sort_by_key(all, |b| (b.near, b.object));
        Some(FirstHits {
            all,
            positions,
            band_start: u32::MAX,
            band: None,
            tile_start: u32::MAX,
            tile: None,
            shift: window_shift(camera),
        })
    }

    /// The nearest hit of `camera`'s ray `ray` through a sub-cell of pixel
    /// (`x`, `y`) (the ray knows its offsets): the hit every accelerator's
    /// `nearest` returns for it; `None` where the lists are too long to pay.
    #[inline]
    pub fn nearest(
        &mut self,
        scene: &SceneView<'_>,
        kinds: ShapeKinds,
        camera: &Camera,
        ray: &mut CameraRay,
        [x, y]: [u32; 2],
    ) -> Option<Option<Hit>> {
        let offsets = ray.offsets;
        self.nearest_of(scene, kinds, camera, offsets, [x, y], &mut Seen { camera, ray })
    }

    /// The nearest hit of `ray`, the reflection off the lists' mirror of
    /// the camera ray with `offsets` through pixel (`x`, `y`), which hit the
    /// mirror at `primary_t`; `camera` is that ray's (its tiles are the
    /// mirrored camera's the lists were made for). The hit the
    /// accelerator's `nearest` returns for it.
    #[allow(clippy::too_many_arguments)]
    #[inline]
    pub fn nearest_reflected(
        &mut self,
        scene: &SceneView<'_>,
        kinds: ShapeKinds,
        camera: &Camera,
        offsets: (i32, i32),
        pixel: [u32; 2],
        ray: &Ray,
        start: Option<RayStart>,
        primary_t: Scalar,
    ) -> Option<Option<Hit>> {
        self.nearest_of(scene, kinds, camera, offsets, pixel, &mut Reflected { ray, start, primary_t })
    }

    #[inline]
    fn nearest_of<R: Listed>(
        &mut self,
        scene: &SceneView<'_>,
        kinds: ShapeKinds,
        camera: &Camera,
        (kx, ky): (i32, i32),
        [x, y]: [u32; 2],
        ray: &mut R,
    ) -> Option<Option<Hit>> {
        let all = self.all;
        let shift = self.shift;
        let tile = self.tile(camera, x, y)?;
        // A ray's offsets need no clamp ([`window_shift`]): `narrow`'s value.
        let ray_offset = |k: i32| ((k >> shift) + 0x8000) as u16;
        Some(nearest(scene, kinds, all, tile, ray, (ray_offset(kx), ray_offset(ky))))
    }

    /// The positions in the bounds of the objects that camera rays of
    /// pixel (`x`, `y`)'s tile may hit, nearest bound first, or `None` when
    /// they are too many.
    #[inline(always)]
    fn tile(&mut self, camera: &Camera, x: u32, y: u32) -> Option<&[u16]> {
        let (band_start, tile_start) = (y - y % BAND_ROWS, x - x % TILE_COLUMNS);
        if band_start != self.band_start || tile_start != self.tile_start {
            self.choose(camera, band_start, tile_start);
        }
        let band_room = self.all.len().min(MAX_BAND_OBJECTS);
        self.positions.get(band_room..)?.get(..self.tile?)
    }

    /// Chooses the objects of the band starting at row `band_start` (if it
    /// is not the current one) and of its tile starting at column
    /// `tile_start`. Out of line: once per tile of a band, where the
    /// look-up is once per ray.
    #[inline(never)]
    fn choose(&mut self, camera: &Camera, band_start: u32, tile_start: u32) {
        let last = camera.samples() - 1;
        let all = self.all;
        let (band, tile) = self.positions.split_at_mut(all.len().min(MAX_BAND_OBJECTS));
        if band_start != self.band_start {
            self.band_start = band_start;
            // The band's offsets: from its last row's last sub-cells up to
            // its first row's first (shifted as the windows are: a window
            // that meets the band still does).
            let low = narrow(camera.offsets(0, band_start.saturating_add(BAND_ROWS - 1), 0, last).1, self.shift);
            let high = narrow(camera.offsets(0, band_start, 0, 0).1, self.shift);
            // Positions below MAX_OBJECTS: the casts are exact.
            self.band = filter(all, (0..all.len()).map(|p| p as u16), band, |b| b.y[0] <= high && b.y[1] >= low);
        }
        self.tile_start = tile_start;
        // A band of too many objects has no tiles (its rays walk).
        self.tile = self.band.and_then(|band_len| {
            // The tile's offsets: from its first column's first sub-cells
            // to its last column's last.
            let low = narrow(camera.offsets(tile_start, 0, 0, 0).0, self.shift);
            let high = narrow(camera.offsets(tile_start.saturating_add(TILE_COLUMNS - 1), 0, last, 0).0, self.shift);
            filter(all, band[..band_len].iter().copied(), tile, |b| b.x[0] <= high && b.x[1] >= low)
        });
    }
}

/// A ray the lists find the hit of.
trait Listed {
    /// The ray (a camera ray's unit vector is made only when asked for).
    fn ray(&mut self) -> &Ray;
    /// How it leaves `object`.
    fn leaving(&self, object: ObjectId) -> Leaving;
    /// Whether a bound's `near` (from the lists' eye) is beyond every hit
    /// of parameter `t` on this ray.
    fn beyond(&self, near: i32, t: Scalar) -> bool;
}

/// A camera ray, from the lists' own camera.
struct Seen<'c, 'r> {
    camera: &'c Camera,
    ray: &'r mut CameraRay,
}

impl Listed for Seen<'_, '_> {
    #[inline(always)]
    fn ray(&mut self) -> &Ray {
        self.ray.get(self.camera)
    }

    #[inline(always)]
    fn leaving(&self, _: ObjectId) -> Leaving {
        Leaving::No
    }

    #[inline(always)]
    fn beyond(&self, near: i32, t: Scalar) -> bool {
        near > t.to_bits()
    }
}

/// A camera ray's reflection off the lists' mirror.
struct Reflected<'r> {
    ray: &'r Ray,
    start: Option<RayStart>,
    primary_t: Scalar,
}

impl Listed for Reflected<'_> {
    #[inline(always)]
    fn ray(&mut self) -> &Ray {
        self.ray
    }

    #[inline(always)]
    fn leaving(&self, object: ObjectId) -> Leaving {
        RayStart::leaving(self.start, object)
    }

    /// A hit `t` along the reflection is at most `t + primary_t` from the
    /// mirrored eye, each times `1 + 2^-29` (below 8 units for both, as
    /// each is below 2^31), plus how far the reflection strays from the
    /// mirrored camera's ray (below [`MirrorPlane::OFFSET`]).
    #[inline(always)]
    fn beyond(&self, near: i32, t: Scalar) -> bool {
        near as i64 > t.to_bits() as i64 + self.primary_t.to_bits() as i64 + 8 + MirrorPlane::OFFSET
    }
}

/// The nearest hit of `ray` with offsets `(kx, ky)` ([`narrow`]ed as the
/// windows are) among the objects at `tile`'s positions in `all`. A camera
/// ray is made only when a window holds the offsets.
///
/// The tile's first box whose window holds the ray is tested after the
/// others, and only if its bound is not beyond their nearest hit. A box is
/// its own bound, so a large one (fig5_5's base under its board, a floor,
/// a wall) comes first by its bound's distance while what stands on it is
/// hit nearer: tested first, it was a whole slab test and a division for a
/// hit that lost. Tested last, its hit is bounded, and the box's own test
/// turns most such rays away at their first slab. Exact: without the box's
/// hit the loop's nearest is no nearer, so it stops no earlier and tests
/// every object it tested before; the box is then tested within the
/// nearest of those, unless its bound (so any hit on it) is beyond it; and
/// the hit kept is the least by parameter, then object, in any order.
#[inline]
fn nearest<R: Listed>(
    scene: &SceneView<'_>,
    kinds: ShapeKinds,
    all: &[ScreenBound],
    tile: &[u16],
    ray: &mut R,
    (kx, ky): (u16, u16),
) -> Option<Hit> {
    let mut best = Hit::NONE;
    let mut deferred = None;
    for bound in tile.iter().filter_map(|&p| all.get(p as usize)) {
        if ray.beyond(bound.near, best.t) {
            break;
        }
        if kx < bound.x[0] || kx > bound.x[1] || ky < bound.y[0] || ky > bound.y[1] {
            continue;
        }
        // The first box is tested last (see the function's doc).
        if kinds.contains(ShapeKind::Box)
            && deferred.is_none()
            && scene.objects[bound.object as usize].kind() == ShapeKind::Box
        {
            deferred = Some(bound);
            continue;
        }
        test(scene, kinds, bound, ray, &mut best);
    }
    if let Some(bound) = deferred.filter(|bound| !ray.beyond(bound.near, best.t)) {
        test(scene, kinds, bound, ray, &mut best);
    }
    best.found()
}

/// Tests the object of `bound` against `ray` within `best`, and keeps its
/// hit if it wins.
#[inline(always)]
fn test<R: Listed>(scene: &SceneView<'_>, kinds: ShapeKinds, bound: &ScreenBound, ray: &mut R, best: &mut Hit) {
    let object = ObjectId(bound.object as u32);
    let leaving = ray.leaving(object);
    if let Some(t) = scene.intersect_handle(kinds, scene.objects[bound.object as usize], ray.ray(), best.t, leaving) {
        let hit = Hit { t, object };
        if hit.beats(best) {
            *best = hit;
        }
    }
}

// f64 appears only here: to write scene text and as the window test's own
// reference. The lists themselves are integers only.
#[cfg(test)]
mod tests {
    extern crate std;
    use super::*;
    use crate::accel::{Accelerator, Mailbox, Naive};
    use crate::parse::parse;
    use crate::profile::Board64K;
    use crate::scene::{RayCursor, Scene};
    use std::{boxed::Box, format, string::String, vec};

    /// A random scene of spheres, boxes, rectangles and triangles around
    /// the origin, seen from anywhere near or among them (eye inside some
    /// objects' bounds, objects behind it and beside it), wide or narrow,
    /// with one to three samples a side.
    fn random_scene(next: &mut impl FnMut() -> u64) -> Box<Scene<Board64K>> {
        fn coordinate(next: &mut impl FnMut() -> u64, range: u64) -> f64 {
            (next() % (2 * range * 100 + 1)) as f64 / 100.0 - range as f64
        }
        // Reflective: flat objects along an axis may be the scene's mirror.
        let mut text = String::from("SURFACE 1 0.1 0.1 0.1 0.5 0.5 0.5 0 0 0 0 0.5 0\n");
        let eye = [0; 3].map(|_| coordinate(next, 9));
        text += &format!("VIEWPOINT {} {} {}\n", eye[0], eye[1], eye[2]);
        text += &format!("ORIGIN {} {} {}\n", coordinate(next, 2), coordinate(next, 2), coordinate(next, 2));
        text += &format!("RASTER {} {}\n", 4 + next() % 29, 4 + next() % 23);
        text += &format!("SAMPLES {}\n", 1 + next() % 3);
        if next() % 3 == 0 {
            text +=
                &format!("VIEWPORT {} {}\n", 0.5 + (next() % 300) as f64 / 10.0, 0.5 + (next() % 300) as f64 / 10.0);
        }
        // Sometimes a board: tiles on a box's top face, sharing edges and
        // the face's plane (equal parameters: the earlier object wins).
        if next() % 2 == 0 {
            let board = "BOX 1 0 -1 0 3 1 3\n";
            let before = next() % 2 == 0;
            if before {
                text += board;
            }
            for (i, j) in (0..9).map(|k| (k % 3 * 2 - 3, k / 3 * 2 - 3)) {
                text += &format!("RECTANGLE 1 {i} 0 {} {} 0 {} {} 0 {j} {i} 0 {j}\n", j + 2, i + 2, j + 2, i + 2);
            }
            if !before {
                text += board;
            }
        }
        for _ in 0..1 + next() % 30 {
            let c = [0; 3].map(|_| coordinate(next, 6));
            let size = |next: &mut dyn FnMut() -> u64| 0.05 + (next() % 300) as f64 / 100.0;
            text += &match next() % 4 {
                0 => format!("SPHERE 1 {} {} {} {}\n", size(next), c[0], c[1], c[2]),
                1 => format!("BOX 1 {} {} {} {} {} {}\n", c[0], c[1], c[2], size(next), size(next), size(next)),
                2 => {
                    let (w, h) = (size(next), size(next));
                    let [x, y, z] = c;
                    format!("RECTANGLE 1 {x} {y} {z} {} {y} {z} {} {y} {} {x} {y} {}\n", x + w, x + w, z - h, z - h)
                }
                _ => {
                    let p = [0; 6].map(|_| size(next) - 1.5);
                    let [x, y, z] = c;
                    format!(
                        "TRIANGLE 1 {x} {y} {z} {} {} {} {} {} {}\n",
                        x + p[0],
                        y + p[1],
                        z,
                        x + p[2],
                        y + p[3],
                        z + p[4] + p[5]
                    )
                }
            };
        }
        let mut scene: Box<Scene<Board64K>> = Box::default();
        // Degenerate views or shapes are errors: those scenes are skipped.
        if parse(&text, &mut scene, &mut |_| {}).is_err() {
            scene.clear();
        }
        scene
    }

    /// The camera of `view` at its raster and samples, with the raster's
    /// width and height; `None` for an empty raster (a scene that did not
    /// parse).
    fn raster_camera(view: &SceneView<'_>) -> Option<(Camera, u32, u32)> {
        let [w, h] = view.settings.raster;
        let camera =
            (w > 0).then(|| Camera::new(&view.settings.view, &view.normalization, w, h, view.settings.samples));
        Some((camera?.unwrap(), w, h))
    }

    /// Room for one set of lists over `view`'s objects.
    fn room(view: &SceneView<'_>) -> (std::vec::Vec<ScreenBound>, std::vec::Vec<u16>) {
        (vec![ScreenBound::EMPTY; view.object_count()], vec![0; ScreenBound::positions_for(view.object_count())])
    }

    /// Every camera ray of random scenes gets the naive mode's hit (the
    /// same parameter and object), while most of the objects' tests are
    /// skipped.
    #[test]
    fn camera_rays_find_the_naive_hit() {
        let mut next = crate::test_rng::seeded(0xf1a5_7417);
        let (mut rays, mut skipped, mut naive_tests) = (0u64, 0u64, 0u64);
        for _ in 0..300 {
            let scene = random_scene(&mut next);
            let view = scene.view();
            let Some((camera, w, h)) = raster_camera(&view).filter(|_| view.object_count() > 0) else { continue };
            let (mut bounds, mut positions) = room(&view);
            if !FirstHits::fit(&view, &camera, &bounds, &positions) {
                continue;
            }
            assert!(FirstHits::project::<_, false>(&view, &camera, &mut bounds, &mut crate::shade::Unpolled, None));
            let Some(mut hits) = FirstHits::new(view.object_count(), &camera, &mut bounds, &mut positions) else {
                continue;
            };
            let n = camera.samples();
            for y in 0..h {
                for x in 0..w {
                    let tested = hits.tile(&camera, x, y).map_or(view.object_count(), <[_]>::len) as u64;
                    for (sx, sy) in (0..n * n).map(|s| (s % n, s / n)) {
                        let ray = camera.ray(x, y, sx, sy);
                        let mut lazy = camera.next_ray(&mut RayCursor::default(), x, y, sx, sy);
                        let listed = hits.nearest(&view, ShapeKinds::ALL, &camera, &mut lazy, [x, y]);
                        let naive = Naive.nearest(&view, &ray, None, &mut Mailbox::none());
                        assert_eq!(listed.unwrap_or(naive), naive, "pixel {x} {y}, sample {sx} {sy}");
                        rays += 1;
                        skipped += view.object_count() as u64 - tested;
                        naive_tests += view.object_count() as u64;
                    }
                }
            }
        }
        std::println!("{rays} rays; tiles left out {skipped} of {naive_tests} objects");
        assert!(rays > 100_000 && skipped * 3 > naive_tests, "the lists must leave objects out");
    }

    /// Every reflection of a camera ray off the mirror of random scenes
    /// gets the naive mode's hit from the mirror's lists, while most of
    /// the objects' tests are skipped.
    #[test]
    fn reflections_off_the_mirror_find_the_naive_hit() {
        let mut next = crate::test_rng::seeded(0x0d1a_7e55);
        let (mut rays, mut skipped, mut naive_tests, mut mirrors) = (0u64, 0u64, 0u64, 0);
        for _ in 0..1000 {
            let scene = random_scene(&mut next);
            let view = scene.view();
            let Some((camera, w, h)) = raster_camera(&view).filter(|_| view.object_count() > 0) else { continue };
            let Some(plane) = view.mirror() else { continue };
            let Some(image) = camera.mirrored(plane.axis, plane.coordinate) else { continue };
            let (mut bounds, mut positions) = room(&view);
            if !FirstHits::fit(&view, &camera, &bounds, &positions) {
                continue;
            }
            assert!(FirstHits::project::<_, true>(
                &view,
                &image,
                &mut bounds,
                &mut crate::shade::Unpolled,
                Some(plane)
            ));
            let Some(mut hits) = FirstHits::new(view.object_count(), &image, &mut bounds, &mut positions) else {
                continue;
            };
            mirrors += 1;
            let n = camera.samples();
            for (x, y) in (0..w * h).map(|p| (p % w, p / w)) {
                for (sx, sy) in (0..n * n).map(|s| (s % n, s / n)) {
                    let primary = camera.ray(x, y, sx, sy);
                    let Some(hit) = Naive.nearest(&view, &primary, None, &mut Mailbox::none()) else { continue };
                    let point = primary.at(hit.t);
                    let geometric = view.shape(hit.object).normal_at(point);
                    let facing = if geometric.dot_is_positive(primary.dir) { -geometric } else { geometric };
                    let dir = (-primary.dir).reflect_about(facing);
                    let reflected = Ray { origin: point, dir };
                    if !plane.mirrors(&primary, &reflected) {
                        continue;
                    }
                    let leaving = if geometric.dot_is_negative(dir) { Leaving::Inward } else { Leaving::Outward };
                    let start = Some(RayStart { object: hit.object, leaving });
                    let offsets = camera.offsets(x, y, sx, sy);
                    let listed = hits.nearest_reflected(
                        &view,
                        ShapeKinds::ALL,
                        &camera,
                        offsets,
                        [x, y],
                        &reflected,
                        start,
                        hit.t,
                    );
                    let naive = Naive.nearest(&view, &reflected, start, &mut Mailbox::none());
                    assert_eq!(listed.unwrap_or(naive), naive, "pixel {x} {y}, sample {sx} {sy}");
                    let tested = hits.tile(&camera, x, y).map_or(view.object_count(), <[_]>::len) as u64;
                    rays += 1;
                    skipped += view.object_count() as u64 - tested;
                    naive_tests += view.object_count() as u64;
                }
            }
        }
        std::println!("{mirrors} mirrors, {rays} reflections; tiles left out {skipped} of {naive_tests} objects");
        assert!(mirrors > 50 && rays > 20_000 && skipped * 3 > naive_tests, "the lists must leave objects out");
    }

    /// A band seen through too many objects has no tiles: its rays walk,
    /// every one of them (none reads the tile list the band before left).
    #[test]
    fn a_band_of_too_many_objects_leaves_every_ray_to_the_walk() {
        crate::profile! { struct Crowd { spheres: 700, surfaces: 1, lights: 1 } }
        // One sphere seen in the top band's last tile, 600 in a row across
        // the next band (a pixel is about 0.23 units there).
        let mut text = String::from("VIEWPOINT 0 0 40\nRASTER 200 64\nSURFACE 1 .1 .1 .1 .5 .5 .5 0 0 0 0 0 0\n");
        text += "SPHERE 1 0.5 22 6.6 0\n";
        for i in 0..600 {
            text += &format!("SPHERE 1 0.2 {} 4.6 0\n", -20.0 + i as f64 / 15.0);
        }
        let mut scene: Box<Scene<Crowd>> = Box::default();
        parse(&text, &mut scene, &mut |e| panic!("{e}")).unwrap();
        let view = scene.view();
        let camera = Camera::new(&view.settings.view, &view.normalization, 200, 64, 1).unwrap();
        let (mut bounds, mut positions) = room(&view);
        assert!(FirstHits::fit(&view, &camera, &bounds, &positions));
        assert!(FirstHits::project::<_, false>(&view, &camera, &mut bounds, &mut crate::shade::Unpolled, None));
        let mut hits = FirstHits::new(view.object_count(), &camera, &mut bounds, &mut positions).unwrap();
        let (mut crowded, mut listed) = (0, 0);
        for (x, y) in (0..64 * 200).map(|p| (p % 200, p / 200)) {
            let ray = camera.ray(x, y, 0, 0);
            let mut lazy = camera.next_ray(&mut RayCursor::default(), x, y, 0, 0);
            let naive = Naive.nearest(&view, &ray, None, &mut Mailbox::none());
            match hits.nearest(&view, ShapeKinds::ALL, &camera, &mut lazy, [x, y]) {
                Some(hit) => {
                    assert_eq!(hit, naive, "pixel {x} {y}");
                    listed += 1;
                }
                None => crowded += 1,
            }
        }
        assert!(crowded >= 200 && listed >= 200, "{crowded} rays walked, {listed} listed");
    }

    /// Every camera offset fits 16 bits once shifted, and a window narrowed
    /// to 16 bits still holds every offset the full one held, for images
    /// of every size up to the largest.
    #[test]
    fn narrowed_windows_keep_every_ray_they_held() {
        let mut next = crate::test_rng::seeded(0x16_b175);
        // A window no projection bounds (any ray may meet the box) holds
        // every offset at every shift.
        for shift in 0..6 {
            assert_eq!([i32::MIN, i32::MAX].map(|k| narrow(k, shift)), [0, 0xffff]);
        }
        for _ in 0..2_000 {
            let side = |r: u64| ((1 + (r % crate::scene::MAX_SIDE as u64) as u32) >> (r >> 60)).max(1);
            let (w, h, n) = (side(next()), side(next()), 1 + (next() % 16) as u32);
            let view = crate::scene::View::default();
            let camera = Camera::new(&view, &crate::scene::Normalization::IDENTITY, w, h, n).unwrap();
            let shift = window_shift(&camera);
            let corners = [(0, 0, 0, 0), (w - 1, h - 1, n - 1, n - 1), (w - 1, 0, n - 1, 0), (0, h - 1, 0, n - 1)];
            for (x, y, sx, sy) in corners {
                let (kx, ky) = camera.offsets(x, y, sx, sy);
                for k in [kx, ky] {
                    assert!((k >> shift).unsigned_abs() < 0x8000, "{w}x{h}x{n}: {k} >> {shift}");
                    assert_eq!(narrow(k, shift) as i32 - 0x8000, k >> shift);
                }
            }
            for _ in 0..20 {
                let a = (next() as i32) >> (next() % 32);
                let b = a.saturating_add((next() as i32 >> (next() % 32)).unsigned_abs() as i32);
                let narrowed = [a, b].map(|k| narrow(k, shift));
                let (kx, _) = camera.offsets((next() % w as u64) as u32, 0, (next() % n as u64) as u32, 0);
                if (a..=b).contains(&kx) {
                    assert!((narrowed[0]..=narrowed[1]).contains(&narrow(kx, shift)), "[{a}, {b}] {kx} {shift}");
                }
            }
        }
    }

    /// Windows hold the offsets of every point of their box ahead of the
    /// eye (exact f64 solutions of `v = αF + βX + γY`), and are not much
    /// wider than the corners' own offsets.
    #[test]
    fn windows_hold_every_point_of_the_box_and_little_more() {
        let mut next = crate::test_rng::seeded(0x3d_b0c5);
        let mut bounded = 0;
        for _ in 0..300 {
            let scene = random_scene(&mut next);
            let view = scene.view();
            let Some((camera, _, _)) = raster_camera(&view) else { continue };
            let projection = Projection::new(&camera);
            let f64s = |v: [i64; 3]| v.map(|c| c as f64);
            let (f, x, y) = (f64s(camera.forward), f64s(camera.step_x), f64s(camera.step_y));
            let det = |a: [f64; 3], b: [f64; 3], c: [f64; 3]| {
                a[0] * (b[1] * c[2] - b[2] * c[1]) - a[1] * (b[0] * c[2] - b[2] * c[0])
                    + a[2] * (b[0] * c[1] - b[1] * c[0])
            };
            let offsets = |v: [f64; 3]| {
                let alpha = det(v, x, y) / det(f, x, y);
                (alpha, det(f, v, y) / det(v, x, y), det(f, x, v) / det(v, x, y))
            };
            let eye = projection.eye();
            for _ in 0..20 {
                let lo = [0; 3].map(|_| (next() % (1 << 24)) as i64 - (1 << 23));
                let hi = [0, 1, 2].map(|a| lo[a] + (next() % (1 << (next() % 24))) as i64);
                let corners = (0..8).map(|c| [0, 1, 2].map(|a| if c >> a & 1 == 1 { hi[a] } else { lo[a] } - eye[a]));
                let Some([wx, wy]) = projection.window(lo, hi) else {
                    continue;
                };
                bounded += 1;
                let (mut min, mut max) = ([f64::MAX; 2], [f64::MIN; 2]);
                for v in corners {
                    let (alpha, kx, ky) = offsets(f64s(v));
                    assert!(alpha > 0.0, "a window for a box not ahead of the eye");
                    min = [min[0].min(kx), min[1].min(ky)];
                    max = [max[0].max(kx), max[1].max(ky)];
                }
                for (axis, window) in [wx, wy].into_iter().enumerate() {
                    assert!(
                        window[0] as f64 <= min[axis] && max[axis] <= window[1] as f64,
                        "{window:?} {min:?} {max:?}"
                    );
                    let fits = |k: f64| k.abs() < (1u64 << 30) as f64;
                    if fits(min[axis]) && fits(max[axis]) {
                        assert!(min[axis] - window[0] as f64 <= 8.0 && window[1] as f64 - max[axis] <= 8.0, "loose");
                    }
                }
                // Points inside the box lie between the corners' offsets
                // (a convex box projects onto its corners' hull).
                for _ in 0..4 {
                    let p = [0, 1, 2].map(|a| lo[a] + (next() % (hi[a] - lo[a] + 1) as u64) as i64 - eye[a]);
                    let (_, kx, ky) = offsets(f64s(p));
                    assert!(wx[0] as f64 <= kx && kx <= wx[1] as f64 && wy[0] as f64 <= ky && ky <= wy[1] as f64);
                }
            }
        }
        assert!(bounded > 1000, "{bounded} boxes had windows");
    }
}
