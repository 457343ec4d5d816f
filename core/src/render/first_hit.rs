//! Camera rays without a walk: each object's bounds seen from the eye, as a
//! window of the image and the nearest its hit can be (the first-hit idea of
//! Weghorst, Hooper and Greenberg 1984, kept exact).
//!
//! Once per renderer, every object's bounds, widened by the filing margin,
//! are projected into the camera's offsets ([`Projection::window`]), and the
//! objects are sorted by a lower bound of the parameter of any hit on them
//! (the distance from the eye to the widened box). For a band of rows the
//! objects whose window meets the band are kept, still in that order. A
//! camera ray then tests the kept objects whose window holds its offsets,
//! in order, until the next one's bound is beyond the nearest hit so far.
//!
//! Exactness: a hit point strays from its object by less than the filing
//! margin (the octree relies on the same bound), and a camera ray from its
//! ideal direction by a few units, so every object a ray can hit has the
//! ray's offsets in its window and its bound at most the hit's parameter.
//! The earlier-object rule for equal parameters is kept by testing every
//! object whose bound is not beyond the nearest hit.

use crate::accel::{Hit, FILING_MARGIN};
use crate::math::{isqrt_u128, Scalar};
use crate::scene::{ObjectId, Projection, SceneView};
use crate::shapes::{Leaving, Ray, ShapeKinds};

/// Rows of a band: its objects are chosen once for them all.
const BAND_ROWS: u32 = 8;

/// What a camera ray needs to know of one object: where in the image its
/// bounds are seen and how near its hit can be. Storage for
/// [`Renderer::with_first_hits`](super::Renderer::with_first_hits): two per
/// object.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct ScreenBound {
    /// No camera ray hits the object at a smaller parameter (Q16.16 bits).
    near: i32,
    object: u32,
    /// The camera offsets (half sub-cells from the image centre) of the
    /// rays that can meet the object: `kx` in `x[0]..=x[1]`, `ky` in
    /// `y[0]..=y[1]`.
    x: [i32; 2],
    y: [i32; 2],
}

impl ScreenBound {
    /// A placeholder to fill storage with.
    pub const EMPTY: ScreenBound = ScreenBound { near: 0, object: 0, x: [0; 2], y: [0; 2] };

    fn of(scene: &SceneView<'_>, projection: &Projection, id: ObjectId) -> ScreenBound {
        let bounds = scene.shape(id).bounds();
        let lo = bounds.min.wide().map(|v| v - FILING_MARGIN);
        let hi = bounds.max.wide().map(|v| v + FILING_MARGIN);
        let eye = projection.eye();
        let gap2: u128 = (0..3)
            .map(|a| {
                let gap = (lo[a] - eye[a]).max(eye[a] - hi[a]).max(0) as u128;
                gap * gap
            })
            .sum();
        // A hit's parameter times |dir| (1 + 2^-29 at most) is the hit
        // point's distance from the eye, at least the box's, up to the
        // rounding of the point: a few units below the distance.
        let distance = isqrt_u128(gap2) as i64;
        let near = (distance - (distance >> 28) - 8).clamp(0, i32::MAX as i64) as i32;
        let [x, y] = projection.window(lo, hi).unwrap_or([[i32::MIN, i32::MAX]; 2]);
        ScreenBound { near, object: id.0, x, y }
    }
}

/// The sorted bounds of every object and the chosen ones of the current
/// band, in caller-owned storage.
pub(crate) struct FirstHits<'a> {
    /// Every object's bound, nearest first, then the band's.
    storage: &'a mut [ScreenBound],
    objects: usize,
    band: usize,
    /// The band's first row, `u32::MAX` before the first.
    band_start: u32,
}

impl<'a> FirstHits<'a> {
    /// The bounds of `scene`'s objects seen by `projection`, or `None`
    /// when `storage` holds fewer than two per object.
    pub fn new(scene: &SceneView<'_>, projection: &Projection, storage: &'a mut [ScreenBound]) -> Option<Self> {
        let objects = scene.object_count();
        let all = storage.get_mut(..objects.checked_mul(2)?)?;
        for (slot, id) in all.iter_mut().zip(scene.object_ids()) {
            *slot = ScreenBound::of(scene, projection, id);
        }
        all[..objects].sort_unstable_by_key(|b| (b.near, b.object));
        Some(FirstHits { storage, objects, band: 0, band_start: u32::MAX })
    }

    /// The objects that camera rays of row `y` may hit, nearest bound first;
    /// `ky_of_row(y)` gives the offsets `[min, max]` of a row's rays.
    #[inline]
    pub fn for_row(&mut self, y: u32, ky_of_row: impl Fn(u32) -> [i32; 2]) -> &[ScreenBound] {
        let start = y - y % BAND_ROWS;
        if start != self.band_start {
            self.band_start = start;
            let [low, _] = ky_of_row(start.saturating_add(BAND_ROWS - 1));
            let [_, high] = ky_of_row(start);
            let (all, band) = self.storage.split_at_mut(self.objects);
            let mut kept = 0;
            for bound in all.iter().filter(|b| b.y[0] <= high && b.y[1] >= low) {
                band[kept] = *bound;
                kept += 1;
            }
            self.band = kept;
        }
        &self.storage[self.objects..self.objects + self.band]
    }
}

/// The nearest hit of the camera ray with offsets `(kx, ky)` among `band`'s
/// objects: the hit every accelerator's `nearest` returns.
#[inline]
pub(crate) fn nearest(
    scene: &SceneView<'_>,
    kinds: ShapeKinds,
    band: &[ScreenBound],
    ray: &Ray,
    (kx, ky): (i32, i32),
) -> Option<Hit> {
    const NONE: ObjectId = ObjectId(u32::MAX);
    let mut best = Hit { t: Scalar::MAX, object: NONE };
    for bound in band {
        if bound.near > best.t.to_bits() {
            break;
        }
        if kx < bound.x[0] || kx > bound.x[1] || ky < bound.y[0] || ky > bound.y[1] {
            continue;
        }
        let object = ObjectId(bound.object);
        if let Some(t) = scene.intersect_handle(kinds, scene.objects[bound.object as usize], ray, best.t, Leaving::No) {
            if t < best.t || (t == best.t && object < best.object) {
                best = Hit { t, object };
            }
        }
    }
    (best.object != NONE).then_some(best)
}
