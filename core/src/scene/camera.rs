//! Primary rays, exactly as the format specifies: the ray from VIEWPOINT
//! through `ORIGIN + ((i + ½)/W − ½)·vw·r + (½ − (j + ½)/H)·vh·u`, with the
//! ½ offsets replaced by the centres of the n×n sub-cells for SAMPLES n.
//!
//! The set-up works in world units with wide integers once per image; each ray
//! then costs two integer multiply-adds per axis and one normalisation. A ray
//! depends only on its pixel and sub-cell (no accumulated state), so any tile
//! or row order gives the same bits.

use super::normalize::{Normalization, WorldPoint, WorldValue};
use crate::math::{isqrt_u128, mul_i64_i32, mul_i64_wide, Dir, Vec3};
use crate::shapes::Ray;

/// The most samples per pixel side (SAMPLES 1 to 16): the renderer sums
/// 16² samples of at most 2^16 in a `u32`.
pub const MAX_SAMPLES: u32 = 16;
/// The widest and tallest image (RASTER 1 to 16384): the camera's pixel
/// offsets then fit an i32.
pub const MAX_SIDE: u32 = 16384;

/// Why a camera cannot be built.
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum CameraError {
    /// VIEWPOINT equals ORIGIN: there is no view direction.
    EyeAtOrigin,
    /// UPVECTOR is zero or parallel to the view direction.
    UpParallel,
}

impl core::fmt::Display for CameraError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        f.write_str(match self {
            CameraError::EyeAtOrigin => "VIEWPOINT equals ORIGIN: there is no view direction",
            CameraError::UpParallel => "UPVECTOR is zero or parallel to the view direction (ORIGIN − VIEWPOINT)",
        })
    }
}

impl core::error::Error for CameraError {}

/// Everything the camera needs from the scene, in world units (Q32.32).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct View {
    /// VIEWPOINT: where the eye is.
    pub eye: WorldPoint,
    /// ORIGIN: the point the eye looks at.
    pub look_at: WorldPoint,
    /// UPVECTOR: which way is up in the image.
    pub up: WorldPoint,
    /// VIEWPORT width and height; `None` for the default (60° wide).
    pub viewport: Option<[WorldValue; 2]>,
}

impl Default for View {
    fn default() -> View {
        View { eye: [0, 0, 10 << 32], look_at: [0; 3], up: [0, 1 << 32, 0], viewport: None }
    }
}

/// The primary-ray generator for one image size.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Camera {
    eye: Vec3,
    /// Forward, and the per-unit steps along r and u, in a common fixed-point
    /// scale chosen so that no pixel's direction overflows.
    pub(crate) forward: [i64; 3],
    pub(crate) step_x: [i64; 3],
    pub(crate) step_y: [i64; 3],
    width: u32,
    height: u32,
    samples: u32,
}

/// The last primary ray's sub-cell offsets and unnormalised direction, for
/// [`Camera::next_ray`]; empty at first.
#[derive(Clone, Copy, Debug, Default)]
pub(crate) struct RayCursor {
    last: Option<(i32, i32, [i64; 3])>,
}

impl RayCursor {
    /// Moves the remembered ray `stride` along its row, so that the pixel
    /// that far from the last one is the next sub-cell for
    /// [`Camera::next_ray`]: a sum, when a row is walked every b-th pixel
    /// (as a progressive order does). Exact: the cursor stays the ray of
    /// its offsets (a sum of exact steps), whatever it held.
    pub(crate) fn skip(&mut self, stride: &Stride) {
        if let Some((kx, _, d)) = &mut self.last {
            *kx = kx.wrapping_add(stride.offsets);
            *d = [0, 1, 2].map(|a| d[a].wrapping_add(stride.step[a]));
        }
    }
}

/// A jump of whole pixels along a row, less the one sub-cell that
/// [`Camera::next_ray`] steps itself: in offsets, and the change of
/// direction it makes. Made once for a walk ([`Camera::stride`]), kept by
/// the walk rather than in the cursor (a renderer's size is stack on a board).
#[derive(Clone, Copy, Debug)]
pub(crate) struct Stride {
    offsets: i32,
    step: [i64; 3],
}

/// A primary ray whose direction is known but not yet a unit vector: the
/// unit vector (a square root and three divisions, the dearest part of a
/// camera ray on a board) is made only when something asks for the ray, so
/// a ray the screen lists show to miss everything never pays for it.
#[derive(Clone, Copy, Debug)]
pub(crate) struct CameraRay {
    direction: [i64; 3],
    /// The sub-cell's offsets, as [`Camera::offsets`] gives them: the
    /// screen lists' window test reads them without making them again.
    pub(crate) offsets: (i32, i32),
    ray: Option<Ray>,
}

impl CameraRay {
    /// The ray, from `camera` (the one that made the direction).
    #[inline]
    pub(crate) fn get(&mut self, camera: &Camera) -> &Ray {
        self.ray.get_or_insert_with(|| camera.ray_through(self.direction))
    }
}

/// Rounded `a · b / c` in `i128`, `c > 0`. Not inlined: 128-bit division
/// is long code on a 32-bit core, and a camera's set-up uses it often.
#[inline(never)]
fn mul_div(a: i128, b: i128, c: i128) -> i128 {
    let p = a * b;
    if p >= 0 {
        (p + c / 2) / c
    } else {
        (p - c / 2) / c
    }
}

impl Camera {
    /// Checks the view (the parser reports these as scene errors).
    pub fn check(view: &View) -> Result<(), CameraError> {
        Self::basis(view).map(|_| ())
    }

    /// (forward, right, up) unit vectors and the eye-to-origin distance (Q32.32).
    fn basis(view: &View) -> Result<(Dir, Dir, Dir, u128), CameraError> {
        let f_vec = [0, 1, 2].map(|a| view.look_at[a] - view.eye[a]);
        let f = Dir::normalize(f_vec).ok_or(CameraError::EyeAtOrigin)?;
        let up = Dir::normalize(view.up).ok_or(CameraError::UpParallel)?;
        let a = f.wide();
        let b = up.wide();
        let cross = [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]];
        // Parallel: the sine of the angle is below 2^-20 (Q4.60 raw 2^40).
        if cross.iter().all(|c| c.unsigned_abs() < 1 << 40) {
            return Err(CameraError::UpParallel);
        }
        let r = Dir::normalize(cross).ok_or(CameraError::UpParallel)?;
        let u = r.cross(f).ok_or(CameraError::UpParallel)?;
        let d2: u128 = f_vec.iter().map(|&c| (c as i128 * c as i128) as u128).sum();
        Ok((f, r, u, isqrt_u128(d2)))
    }

    /// The camera for a `width × height` image with `samples`² rays per pixel
    /// (`samples` is clamped to 1 ..= [`MAX_SAMPLES`], the sides to
    /// 1 ..= [`MAX_SIDE`]).
    pub fn new(
        view: &View,
        norm: &Normalization,
        width: u32,
        height: u32,
        samples: u32,
    ) -> Result<Camera, CameraError> {
        let (f, r, u, dist) = Self::basis(view)?;
        let samples = samples.clamp(1, MAX_SAMPLES);
        let (width, height) = (width.clamp(1, MAX_SIDE), height.clamp(1, MAX_SIDE));
        let (w, h, n) = (width as i128, height as i128, samples as i128);
        let dist = dist.max(1) as i128;
        // Tangent-like ratios vw/d and vh/d in Q32.32.
        let (ax, ay) = match view.viewport {
            Some([vw, vh]) => (mul_div(vw as i128, 1 << 32, dist), mul_div(vh as i128, 1 << 32, dist)),
            None => {
                // 2·tan 30° = 2/√3 = sqrt(4/3).
                let ax = isqrt_u128((4u128 << 64) / 3) as i128;
                (ax, mul_div(ax, h, w))
            }
        };
        // Largest |direction| before normalisation is about 1 + ax/2 + ay/2:
        // pick the fraction bits so that it stays below 2^61.
        let reach = 1 + ((ax + ay) >> 32) as u128 + 1;
        let frac = (60 - (128 - reach.leading_zeros() as i32)).clamp(8, 44) as u32;
        let scale = |d: Dir, ratio: i128, div: i128| -> [i64; 3] {
            // ratio (Q32) · d (Q30) / div, to `frac` bits.
            d.wide().map(|c| mul_div(ratio * c as i128, 1 << frac, div << 62) as i64)
        };
        Ok(Camera {
            eye: norm.point(view.eye),
            forward: f.wide().map(|c| if frac >= 30 { c << (frac - 30) } else { c >> (30 - frac) }),
            step_x: scale(r, ax, 2 * n * w),
            step_y: scale(u, ay, 2 * n * h),
            width,
            height,
            samples,
        })
    }

    /// The camera's mirror image in the plane across `axis` at `coordinate`
    /// (Q16.16 bits; a `MirrorPlane`'s fields, taken apart so that this
    /// file does not import the scene's mirror, which imports the scene):
    /// each of its rays is this camera's ray of the same offsets, mirrored,
    /// to the bit (normalising a vector does not see its signs). `None` if
    /// the mirrored eye is out of normalised range.
    pub(crate) fn mirrored(&self, axis: usize, coordinate: i32) -> Option<Camera> {
        let mut eye = self.eye.bits();
        eye[axis] = i32::try_from(2 * coordinate as i64 - eye[axis] as i64).ok()?;
        let mirror = |mut v: [i64; 3]| {
            v[axis] = -v[axis];
            v
        };
        Some(Camera {
            eye: Vec3::from_bits(eye),
            forward: mirror(self.forward),
            step_x: mirror(self.step_x),
            step_y: mirror(self.step_y),
            ..*self
        })
    }

    /// Image width in pixels.
    pub fn width(&self) -> u32 {
        self.width
    }

    /// Image height in pixels.
    pub fn height(&self) -> u32 {
        self.height
    }

    /// Samples per pixel along each axis.
    pub fn samples(&self) -> u32 {
        self.samples
    }

    /// The eye in normalised space.
    pub fn eye(&self) -> Vec3 {
        self.eye
    }

    /// The ray through sub-cell (`sx`, `sy`) of pixel (`x`, `y`); `x` grows
    /// to the right and `y` downwards.
    pub fn ray(&self, x: u32, y: u32, sx: u32, sy: u32) -> Ray {
        let (kx, ky) = self.offsets(x, y, sx, sy);
        self.ray_through(self.direction(kx, ky))
    }

    /// [`Camera::ray`], taking the unnormalised direction from the previous
    /// ray's in `cursor` when this sub-cell is the next one along the row
    /// (the next pixel, or the next sample of one): an addition instead of
    /// six wide products. Exact: the sum of the steps is the product.
    pub(crate) fn next_ray(&self, cursor: &mut RayCursor, x: u32, y: u32, sx: u32, sy: u32) -> CameraRay {
        let (kx, ky) = self.offsets(x, y, sx, sy);
        let d = match cursor.last {
            Some((last_kx, last_ky, d)) if ky == last_ky && kx == last_kx.wrapping_add(2) => {
                // Two's complement: the wrapping sums equal the products'
                // exact sum, which fits (see `direction`).
                [0, 1, 2].map(|a| d[a].wrapping_add(self.step_x[a].wrapping_mul(2)))
            }
            _ => self.direction(kx, ky),
        };
        cursor.last = Some((kx, ky, d));
        CameraRay { direction: d, offsets: (kx, ky), ray: None }
    }

    /// The jump of `pixels` pixels along a row, for [`RayCursor::skip`].
    pub(crate) fn stride(&self, pixels: u32) -> Stride {
        // At most 2 · MAX_SAMPLES · MAX_SIDE: the offsets fit an i32, and
        // the wrapping products are the exact ones modulo 2^64 (which is
        // all that the sums need, see `next_ray`).
        let offsets = (2 * self.samples as i32).wrapping_mul(pixels.min(MAX_SIDE) as i32) - 2;
        Stride { offsets, step: self.step_x.map(|s| mul_i64_i32(s, offsets)) }
    }

    /// The sub-cell's offsets from the image centre in half sub-cells.
    #[inline]
    pub(crate) fn offsets(&self, x: u32, y: u32, sx: u32, sy: u32) -> (i32, i32) {
        // |k| ≤ 2 · MAX_SAMPLES · MAX_SIDE: the offsets fit an i32.
        let n = self.samples as i32;
        let kx = 2 * n * x as i32 + 2 * sx as i32 + 1 - n * self.width as i32;
        let ky = n * self.height as i32 - 2 * n * y as i32 - 2 * sy as i32 - 1;
        (kx, ky)
    }

    #[inline]
    fn direction(&self, kx: i32, ky: i32) -> [i64; 3] {
        [0, 1, 2].map(|a| self.forward[a] + mul_i64_i32(self.step_x[a], kx) + mul_i64_i32(self.step_y[a], ky))
    }

    #[inline]
    fn ray_through(&self, d: [i64; 3]) -> Ray {
        Ray {
            origin: self.eye,
            // Never zero: the forward part dominates any sideways offset's
            // perpendicular component.
            dir: Dir::normalize(d).unwrap_or(Dir::Z),
        }
    }
}

/// Where the camera sees points: the offsets (as [`Camera::offsets`]) of the
/// ray through a point in front of the eye. A direction is `F + kx·X + ky·Y`
/// (forward and the two steps), so a point `v` from the eye lies on the ray
/// of `kx = v·(Y×F) / v·(X×Y)` and `ky = v·(F×X) / v·(X×Y)` (Cramer's
/// rule, no assumption that the steps are orthogonal). The three normals
/// are kept in `i64`, all cut by the same shift so their ratios hold: the
/// cut moves a product with `v` by less than Σ|v_a| (in the cut scale).
#[derive(Clone, Copy, Debug)]
pub(crate) struct Projection {
    eye: [i64; 3],
    across: [i64; 3],
    down: [i64; 3],
    depth: [i64; 3],
}

/// Offsets are clamped to ±2^21 half sub-cells, past every pixel's
/// (2 · 16 · 16384 = 2^19 at most): a box seen further out than that is
/// seen no nearer to the image.
const OFFSET_LIMIT: i64 = 1 << 21;

impl Projection {
    #[inline(never)]
    pub(crate) fn new(camera: &Camera) -> Projection {
        let (f, x, y) = (camera.forward, camera.step_x, camera.step_y);
        let cross = |a: [i64; 3], b: [i64; 3]| {
            [0, 1, 2].map(|i| {
                let (j, k) = ((i + 1) % 3, (i + 2) % 3);
                mul_i64_wide(a[j], b[k]) - mul_i64_wide(a[k], b[j])
            })
        };
        let (across, down, depth) = (cross(y, f), cross(f, x), cross(x, y));
        let top = [across, down, depth].iter().flatten().map(|c| c.unsigned_abs()).max().unwrap_or(0);
        let cut = (128 - top.leading_zeros()).saturating_sub(62);
        let cut_down = |v: [i128; 3]| v.map(|c| (c >> cut) as i64);
        let (mut across, mut down, mut depth) = (cut_down(across), cut_down(down), cut_down(depth));
        // Oriented so that points ahead of the eye have a positive depth.
        let ahead = dot(&f, &depth);
        if ahead < 0 {
            for v in [&mut across, &mut down, &mut depth] {
                *v = v.map(|c| -c);
            }
        }
        let eye = camera.eye.bits().map(|c| c as i64);
        Projection { eye, across, down, depth }
    }

    /// The offsets `[kx_min, kx_max]` and `[ky_min, ky_max]` of every ray
    /// that can pass through the box `[lo, hi]` (normalised units), widened
    /// by the projection's rounding and two half sub-cells; `None` when the
    /// box is not wholly ahead of the eye (any ray may then meet it).
    ///
    /// A box projects onto the hull of its corners' offsets. Per corner `v`
    /// the products with the cut normals are exact in `i128`; each is within
    /// Σ|v_a| of the true one's (in the cut scale), and cutting both to about
    /// 41 bits adds less than one more. With `e` bounding both errors, the
    /// true offset is within `e·(1 + |k|) / (depth − e)` of the quotient `k`.
    // Not inlined, nor its products: once per object, and 128-bit code is
    // large on a 32-bit core (flash, not time, is what it costs a board).
    #[inline(never)]
    pub(crate) fn window(&self, lo: [i64; 3], hi: [i64; 3]) -> Option<[[i32; 2]; 2]> {
        // A corner's product with a normal is a sum of one product an axis,
        // with the box's low or high side: six products a normal, not 24
        // (a Pico spent 7 M cycles on fig5_3's 200 boxes). The same sums.
        let sides = [0, 1, 2].map(|a| [lo[a] - self.eye[a], hi[a] - self.eye[a]]);
        let products = |normal: &[i64; 3]| [0, 1, 2].map(|a| sides[a].map(|side| mul_i64_wide(normal[a], side)));
        let (depths, across, down) = (products(&self.depth), products(&self.across), products(&self.down));
        let at = |products: &[[i128; 2]; 3], corner: usize| (0..3).map(|a| products[a][corner >> a & 1]).sum::<i128>();
        let mut window = [[i64::MAX, i64::MIN]; 2];
        for corner in 0..8 {
            let v = [0, 1, 2].map(|a| sides[a][corner >> a & 1]);
            let depth = at(&depths, corner);
            if depth <= 0 {
                return None;
            }
            let shift = (128 - depth.leading_zeros()).saturating_sub(41);
            let slack = v.iter().map(|c| c.unsigned_abs()).sum::<u64>();
            let error = (slack >> shift) as i64 + 2;
            let depth = (depth >> shift) as i64;
            if depth <= 2 * error {
                return None;
            }
            for (axis, products) in [&across, &down].into_iter().enumerate() {
                let num = at(products, corner) >> shift;
                // |num| below 2^62 keeps the quotient in i64; beyond, the
                // offset is past the limit anyway (depth < 2^41).
                let k = if num.unsigned_abs() < 1 << 62 {
                    (num as i64).div_euclid(depth)
                } else {
                    num.signum() as i64 * OFFSET_LIMIT
                };
                let k = k.clamp(-OFFSET_LIMIT, OFFSET_LIMIT);
                // Mostly below one: then no 64-bit division (long on a
                // 32-bit core) is needed to know the quotient is 0.
                let (spread, room) = (error * (2 + k.abs()), depth - error);
                let error = if spread < room { 0 } else { spread / room } + 1;
                window[axis][0] = window[axis][0].min(k - error);
                window[axis][1] = window[axis][1].max(k + 1 + error);
            }
        }
        Some(window.map(|[a, b]| [(a - 2) as i32, (b + 2) as i32]))
    }

    /// The eye in normalised units.
    pub(crate) fn eye(&self) -> [i64; 3] {
        self.eye
    }
}

/// `n · v`, exactly.
#[inline(never)]
fn dot(n: &[i64; 3], v: &[i64; 3]) -> i128 {
    (0..3).map(|a| mul_i64_wide(n[a], v[a])).sum()
}

#[cfg(test)]
mod tests {
    use super::*;

    const ONE: i64 = 1 << 32;

    fn camera(view: &View, w: u32, h: u32, n: u32) -> Camera {
        let norm = Normalization::fit([-10 * ONE; 3], [10 * ONE; 3]);
        Camera::new(view, &norm, w, h, n).unwrap()
    }

    #[test]
    fn centre_pixel_looks_at_origin() {
        let c = camera(&View::default(), 3, 3, 1);
        assert_eq!(c.ray(1, 1, 0, 0).dir, -Dir::Z);
    }

    #[test]
    fn image_axes_follow_right_and_up() {
        let c = camera(&View::default(), 4, 2, 1);
        let left_top = c.ray(0, 0, 0, 0).dir.bits();
        let right_bottom = c.ray(3, 1, 0, 0).dir.bits();
        assert!(left_top[0] < 0 && left_top[1] > 0);
        assert!(right_bottom[0] > 0 && right_bottom[1] < 0);
        assert_eq!(left_top[0], -right_bottom[0]);
    }

    #[test]
    fn default_viewport_is_sixty_degrees_wide() {
        // The outer edge of the image (not a pixel centre) is at 30°: with
        // W = 1 and 1 sample, the pixel centre is the axis; use two pixels and
        // extrapolate: centre of pixel 0 is at x = −vw/4.
        let c = camera(&View::default(), 2, 2, 1);
        let d = c.ray(0, 0, 0, 0).dir.bits();
        // tan(angle) = (vw/4)/d = tan 30°/2 = 0.288675…
        let tan_millionths = d[0] as i64 * 1_000_000 / d[2] as i64;
        assert!((tan_millionths - 288_675).abs() <= 1, "{tan_millionths}");
    }

    #[test]
    fn explicit_viewport_and_non_perpendicular_up() {
        let view =
            View { eye: [0, 0, 4 * ONE], look_at: [0; 3], up: [0, ONE, ONE], viewport: Some([8 * ONE, 4 * ONE]) };
        let c = camera(&view, 2, 1, 1);
        // Pixel 1's centre is at x = +2 on the window, at distance 4.
        let d = c.ray(1, 0, 0, 0).dir.bits();
        assert!((2 * d[0] as i64 + d[2] as i64).abs() < 4, "{d:?}");
        assert_eq!(d[1], 0);
    }

    #[test]
    fn samples_are_sub_cell_centres() {
        let c1 = camera(&View::default(), 2, 2, 1);
        let c2 = camera(&View::default(), 1, 1, 2);
        // A 1×1 image with 2×2 samples has the same rays as a 2×2 image.
        assert_eq!(c1.ray(0, 0, 0, 0), c2.ray(0, 0, 0, 0));
        assert_eq!(c1.ray(1, 1, 0, 0), c2.ray(0, 0, 1, 1));
    }

    #[test]
    fn degenerate_views_are_errors() {
        let norm = Normalization::IDENTITY;
        let at_origin = View { eye: [0; 3], ..View::default() };
        assert_eq!(Camera::new(&at_origin, &norm, 4, 4, 1), Err(CameraError::EyeAtOrigin));
        let parallel = View { up: [0, 0, -3 * ONE], ..View::default() };
        assert_eq!(Camera::check(&parallel), Err(CameraError::UpParallel));
        let zero_up = View { up: [0; 3], ..View::default() };
        assert_eq!(Camera::check(&zero_up), Err(CameraError::UpParallel));
    }

    #[test]
    fn a_skipped_cursor_gives_the_ray() {
        // Every b-th pixel of a row (a sum after the first), after any
        // other ray, with one to three samples: the exact direction.
        for (w, h, n) in [(40, 5, 1), (33, 3, 3), (16384, 2, 1), (9, 9, 2)] {
            let view = View { eye: [3 * ONE, ONE / 3, 7 * ONE], viewport: None, ..View::default() };
            let c = camera(&view, w, h, n);
            let mut cursor = RayCursor::default();
            let mut sums = 0;
            for (y, b) in [(0, 1), (1, 2), (h - 1, 3), (1, 16), (2 % h, 5)] {
                let stride = c.stride(b);
                for x in (b / 2..w).step_by(b as usize) {
                    cursor.skip(&stride);
                    for sy in 0..n {
                        for sx in 0..n {
                            let before = cursor.last;
                            let mut ray = c.next_ray(&mut cursor, x, y, sx, sy);
                            let (kx, ky) = c.offsets(x, y, sx, sy);
                            sums +=
                                before.is_some_and(|(last_kx, last_ky, _)| (last_kx + 2, last_ky) == (kx, ky)) as u32;
                            assert_eq!(ray.direction, c.direction(kx, ky), "{w}x{h}/{n}: {x} {y} {sx} {sy}");
                            assert_eq!(*ray.get(&c), c.ray(x, y, sx, sy));
                        }
                    }
                }
            }
            assert!(sums > w, "{w}x{h}/{n}: the skips made sums ({sums})");
        }
    }

    #[test]
    fn the_next_ray_along_a_row_is_the_ray() {
        // Rows, samples, jumps back and a new row: every ray equals the one
        // computed from its pixel alone.
        for (w, h, n) in [(7, 5, 1), (4, 3, 3), (16384, 2, 1)] {
            let view = View { eye: [3 * ONE, ONE / 3, 7 * ONE], viewport: None, ..View::default() };
            let c = camera(&view, w, h, n);
            let mut cursor = RayCursor::default();
            let columns = [0, 1, 2, 3, 1, 2, w - 2, w - 1, 0];
            for y in [0, 1, h - 1, 1] {
                for &x in &columns {
                    for sy in 0..n {
                        for sx in 0..n {
                            assert_eq!(
                                *c.next_ray(&mut cursor, x, y, sx, sy).get(&c),
                                c.ray(x, y, sx, sy),
                                "{x} {y} {sx} {sy}"
                            );
                        }
                    }
                }
            }
        }
    }

    /// `Projection::window` as it was first written: each corner's
    /// products with the normals one by one, every error divided.
    fn window_corner_by_corner(p: &Projection, lo: [i64; 3], hi: [i64; 3]) -> Option<[[i32; 2]; 2]> {
        let mut window = [[i64::MAX, i64::MIN]; 2];
        for corner in 0..8 {
            let v = [0, 1, 2].map(|a| if corner >> a & 1 == 1 { hi[a] } else { lo[a] } - p.eye[a]);
            let depth = dot(&p.depth, &v);
            if depth <= 0 {
                return None;
            }
            let shift = (128 - depth.leading_zeros()).saturating_sub(41);
            let slack = v.iter().map(|c| c.unsigned_abs()).sum::<u64>();
            let error = (slack >> shift) as i64 + 2;
            let depth = (depth >> shift) as i64;
            if depth <= 2 * error {
                return None;
            }
            for (axis, normal) in [&p.across, &p.down].into_iter().enumerate() {
                let num = dot(normal, &v) >> shift;
                let k = if num.unsigned_abs() < 1 << 62 {
                    (num as i64).div_euclid(depth)
                } else {
                    num.signum() as i64 * OFFSET_LIMIT
                };
                let k = k.clamp(-OFFSET_LIMIT, OFFSET_LIMIT);
                let error = error * (2 + k.abs()) / (depth - error) + 1;
                window[axis][0] = window[axis][0].min(k - error);
                window[axis][1] = window[axis][1].max(k + 1 + error);
            }
        }
        Some(window.map(|[a, b]| [(a - 2) as i32, (b + 2) as i32]))
    }

    /// Boxes of every size, ahead of the eye, beside it, behind it and
    /// around it, seen by cameras looking every way: the window of six
    /// products a normal is the window of each corner's.
    #[test]
    fn a_window_from_the_sides_products_is_the_corners_window() {
        let mut next = crate::test_rng::seeded(0x3a1d_0f5e_77c2);
        let mut coordinate = |scale: u64| (next() % (2 * scale + 1)) as i64 - scale as i64;
        let mut ahead = 0;
        for _ in 0..300 {
            let point = |c: &mut dyn FnMut(u64) -> i64| [0; 3].map(|_| c(9) << 32 | (c(1 << 31) & 0xffff_ffff));
            let view = View { eye: point(&mut coordinate), look_at: point(&mut coordinate), ..View::default() };
            let Ok(camera) = Camera::new(&view, &Normalization::fit([-10 * ONE; 3], [10 * ONE; 3]), 320, 240, 2) else {
                continue;
            };
            let projection = Projection::new(&camera);
            for _ in 0..100 {
                let size = 1u64 << (coordinate(15).unsigned_abs() + 4);
                // Half of them near the eye, of any size, where the
                // rounding's error is large against the depth.
                let near = coordinate(1) == 0;
                let lo = [0, 1, 2].map(|a| match near {
                    true => {
                        let scale = 1 << coordinate(30).unsigned_abs();
                        projection.eye[a] + coordinate(scale)
                    }
                    false => coordinate(1 << 31),
                });
                let hi = [0, 1, 2].map(|a| lo[a] + (coordinate(size / 2) + size as i64 / 2));
                let window = projection.window(lo, hi);
                ahead += window.is_some() as u32;
                assert_eq!(window, window_corner_by_corner(&projection, lo, hi), "{view:?} {lo:?} {hi:?}");
            }
        }
        assert!(ahead > 1_000, "{ahead} boxes ahead of the eye");
    }
}
