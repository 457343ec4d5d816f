//! `BOX s xc yc zc xs ys zs`: an axis-aligned box given by its centre and
//! half-sizes.
//!
//! The slab test orders the crossings as exact ratios (cross multiplication)
//! and divides once, for the crossing it returns: a ray parallel to a face, or
//! nearly so, needs no special case and cannot overflow.

use super::{less_when_sure, Aabb, Leaving, Ratio, Ray, Shape};
use crate::math::{div_saturating, mul_u32_wide, mul_wide, part_wise_or, Dir, Scalar, Vec3};

/// A BOX: its corners in normalised space.
// Public only for `profile!` (arenas of it) and the firmware's RAM
// estimate; its geometry is the core's own business.
#[doc(hidden)]
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct AxisAlignedBox {
    pub min: Vec3,
    pub max: Vec3,
    pub surface: u16,
}

/// The parameter interval in which a ray is inside an axis-aligned box, as
/// exact ratios; `None` bounds are unbounded.
#[derive(Clone, Copy, Debug)]
pub(crate) struct SlabSpan {
    pub enter: Option<Ratio>,
    pub exit: Option<Ratio>,
}

/// Clips `ray` against the box `[min, max]`; `None` when the ray's line misses
/// it. The span may lie partly or wholly behind the origin.
pub(crate) fn slab_span(ray: &Ray, min: Vec3, max: Vec3) -> Option<SlabSpan> {
    let (o, d, lo, hi) = (ray.origin.bits(), ray.dir.bits(), min.bits(), max.bits());
    match slab_span_narrow(o, d, lo, hi) {
        Ok(span) => span,
        Err(NeedsWide) => slab_span_wide(ray.origin.wide(), ray.dir.wide(), min.wide(), max.wide()),
    }
}

/// A box's face further from a ray's origin than an `i32` holds, or a
/// direction's component past a unit's rounding: the slab test takes
/// 64-bit crossings.
struct NeedsWide;

/// The largest direction component a [`Crossing`] takes: a unit and the
/// rounding of an estimated unit vector, with room to spare (`den >> 15`
/// at most 2^15, as [`coarse_crossing_lt`] needs).
const MAX_CROSSING_DEN: u32 = (1 << 30) + (1 << 15) - 1;

/// [`slab_span_wide`] in 32-bit crossings, for a box whose faces lie within
/// an `i32` of the origin on every axis (every box of a normalised scene,
/// whose points are within ±2^29) and a direction within
/// [`MAX_CROSSING_DEN`]: the same span, compared as
/// [`Crossing`]s, where the wide one's `i64` ratios were 64-bit
/// bookkeeping on a 32-bit core (the emulated Pico's fig5_5 spent 16.5 M
/// cycles in the wide span, 8.3 M in this one).
#[inline]
fn slab_span_narrow(o: [i32; 3], d: [i32; 3], lo: [i32; 3], hi: [i32; 3]) -> Result<Option<SlabSpan>, NeedsWide> {
    let mut span = NarrowSpan { enter: None, exit: None };
    // Axis by axis in straight code: a loop kept its index and the arrays
    // on the stack.
    for axis in [0, 1, 2] {
        if !span.clip(o[axis], d[axis], lo[axis], hi[axis])? {
            return Ok(None);
        }
    }
    if let (Some(e), Some(x)) = (span.enter, span.exit) {
        if x.lt(e) {
            return Ok(None);
        }
    }
    Ok(Some(SlabSpan { enter: span.enter.map(Crossing::ratio), exit: span.exit.map(Crossing::ratio) }))
}

/// The crossings of [`slab_span_narrow`] so far: the latest entry, the
/// earliest exit.
struct NarrowSpan {
    enter: Option<Crossing>,
    exit: Option<Crossing>,
}

impl NarrowSpan {
    /// Clips the span by one axis's slab `[lo, hi]` (the origin's `o`, the
    /// direction's `d`); `false` when the ray's line misses the slab.
    #[inline(always)]
    fn clip(&mut self, o: i32, d: i32, lo: i32, hi: i32) -> Result<bool, NeedsWide> {
        let gap = |face: i32, from: i32| face.checked_sub(from).ok_or(NeedsWide);
        let (near, far) = match d {
            0 => return Ok(lo <= o && o <= hi),
            d if d > 0 => (gap(lo, o)?, gap(hi, o)?),
            _ => (gap(o, hi)?, gap(o, lo)?),
        };
        let den = d.unsigned_abs();
        if den > MAX_CROSSING_DEN {
            return Err(NeedsWide);
        }
        let den = den as i32;
        let (near, far) = (Crossing { num: near, den }, Crossing { num: far, den });
        if self.enter.is_none_or(|e| e.lt(near)) {
            self.enter = Some(near);
        }
        if self.exit.is_none_or(|x| far.lt(x)) {
            self.exit = Some(far);
        }
        Ok(true)
    }
}

/// A ray's parameter at a slab's face, `num / den`: a Q16.16 gap over a
/// direction's magnitude in Q2.30 (`0 < den ≤ MAX_CROSSING_DEN`), both in
/// 32 bits.
#[derive(Clone, Copy, Debug)]
struct Crossing {
    num: i32,
    den: i32,
}

impl Crossing {
    /// `self < o`, exactly; on ARMv6-M from 32-bit products of the top
    /// bits when they decide ([`coarse_crossing_lt`]).
    #[inline(always)]
    fn lt(self, o: Crossing) -> bool {
        part_wise_or(|| coarse_crossing_lt(self, o), || mul_wide(self.num, o.den) < mul_wide(o.num, self.den))
    }

    fn ratio(self) -> Ratio {
        Ratio { num: self.num as i64, den: self.den as i64 }
    }
}

/// Whether `x < y` (`x.num·y.den < y.num·x.den`) when the products of
/// their top bits decide it, else `None`.
///
/// Why: with `num = h·2^16 + l` (`|h| ≤ 2^15`, `0 ≤ l < 2^16`) and `den =
/// k·2^15 + m` (`0 ≤ k ≤ 2^15`, `0 ≤ m < 2^15`), `num·den − h·k·2^31 =
/// h·m·2^16 + l·k·2^15 + l·m` lies in `(−2^46, 2^47 + 2^31)`, so the two
/// products' difference is within `3·2^46 + 2^31` of `H·2^31`, `H` the
/// short products' difference (`|H| < 2^31`): `H ≤ −(3·2^15 + 2)` makes
/// it negative, `H ≥ 3·2^15 + 2` positive.
#[inline(always)]
fn coarse_crossing_lt(x: Crossing, y: Crossing) -> Option<bool> {
    const SURE: i32 = (3 << 15) + 2;
    let short = |num: i32, den: i32| (num >> 16) * (den >> 15);
    less_when_sure(short(x.num, y.den) - short(y.num, x.den), SURE)
}

/// [`slab_span`] for a ray and a box given as raw integers (origin and box in
/// Q16.16, direction in Q2.30; coordinates within ±2^31).
pub(crate) fn slab_span_wide(o: [i64; 3], d: [i64; 3], lo: [i64; 3], hi: [i64; 3]) -> Option<SlabSpan> {
    let mut enter: Option<Ratio> = None;
    let mut exit: Option<Ratio> = None;
    for axis in 0..3 {
        let (near, far) = match d[axis] {
            0 => {
                if o[axis] < lo[axis] || o[axis] > hi[axis] {
                    return None;
                }
                continue;
            }
            dv if dv > 0 => (lo[axis] - o[axis], hi[axis] - o[axis]),
            _ => (o[axis] - hi[axis], o[axis] - lo[axis]),
        };
        let den = d[axis].abs();
        let near = Ratio { num: near, den };
        let far = Ratio { num: far, den };
        if enter.is_none_or(|e| e.lt(near)) {
            enter = Some(near);
        }
        if exit.is_none_or(|x| far.lt(x)) {
            exit = Some(far);
        }
    }
    if let (Some(e), Some(x)) = (enter, exit) {
        if x.lt(e) {
            return None;
        }
    }
    Some(SlabSpan { enter, exit })
}

/// Whether a ray (origin `o`, direction `d`) not leaving the box `[lo, hi]`
/// (raw bits) enters one of its slabs at a positive parameter whose
/// rounding is beyond `t_max`. Its entry into the box is then that far at
/// least (the slabs' latest entry, rounded down alike), so the span's hit,
/// that entry or none, is not within `t_max`.
#[inline(always)]
fn enters_beyond([o, d, lo, hi]: [[i32; 3]; 4], t_max: Scalar) -> bool {
    (0..3).any(|a| {
        let near = match d[a] {
            0 => return false,
            dv if dv > 0 => lo[a] as i64 - o[a] as i64,
            _ => o[a] as i64 - hi[a] as i64,
        };
        near > 0 && !Ratio { num: near, den: d[a].unsigned_abs() as i64 }.le_scalar(t_max)
    })
}

impl AxisAlignedBox {
    pub fn new(center: Vec3, half: Vec3, surface: u16) -> AxisAlignedBox {
        AxisAlignedBox { min: center - half, max: center + half, surface }
    }

    /// The hit from the ray's span in the box, for a ray not leaving it
    /// outward.
    #[inline]
    fn intersect_span(&self, ray: &Ray, t_max: Scalar, leaving: Leaving) -> Option<Scalar> {
        let span = slab_span(ray, self.min, self.max)?;
        let positive = |r: Ratio| r.num > 0;
        let chosen = match (leaving, span.enter) {
            (Leaving::No, Some(e)) if positive(e) => e,
            _ => span.exit?,
        };
        if !positive(chosen) || !chosen.le_scalar(t_max) {
            return None;
        }
        // Below t_max + 1, so the quotient of these positive numbers fits.
        let t = div_saturating((chosen.num << 30) as u64, chosen.den as u32) as i32;
        (t > 0).then_some(Scalar::from_bits(t))
    }
}

impl Shape for AxisAlignedBox {
    const FLAT: bool = false;

    #[inline]
    fn intersect(&self, ray: &Ray, t_max: Scalar, leaving: Leaving) -> Option<Scalar> {
        if leaving == Leaving::Outward {
            return None;
        }
        // A ray outside a slab and not moving towards it leaves the box
        // behind: its span would end at a parameter ≤ 0.
        let (o, d, lo, hi) = (ray.origin.bits(), ray.dir.bits(), self.min.bits(), self.max.bits());
        if (0..3).any(|a| (o[a] > hi[a] && d[a] >= 0) || (o[a] < lo[a] && d[a] <= 0)) {
            return None;
        }
        // A ray whose hit is bounded (a box tested after what the ray hits
        // first, see render/first_hit.rs) is often turned away at its
        // first slab, before the others' ratios and the division.
        if leaving == Leaving::No && t_max != Scalar::MAX && enters_beyond([o, d, lo, hi], t_max) {
            return None;
        }
        self.intersect_span(ray, t_max, leaving)
    }

    /// Outward normal of the face nearest to `p` (relative to each half-size);
    /// on an edge or corner the lowest axis wins.
    fn normal_at(&self, p: Vec3) -> Dir {
        let c = [0, 1, 2].map(|a| (self.min.axis(a).to_bits() as i64 + self.max.axis(a).to_bits() as i64) / 2);
        let h = [0, 1, 2].map(|a| (self.max.axis(a).to_bits() as i64 - self.min.axis(a).to_bits() as i64).max(1));
        let off = [0, 1, 2].map(|a| p.axis(a).to_bits() as i64 - c[a]);
        // Largest |off_a| / h_a by cross multiplication: of i32 points'
        // differences, below 2^32 each, so 32×32→64 products (the i64 ones
        // were library calls on a Cortex-M0).
        let (off_magnitude, h) = (off.map(|o| o.unsigned_abs() as u32), h.map(|h| h as u32));
        let mut best = 0;
        for a in 1..3 {
            if mul_u32_wide(off_magnitude[a], h[best]) > mul_u32_wide(off_magnitude[best], h[a]) {
                best = a;
            }
        }
        Dir::axis_unit(best, off[best] < 0)
    }

    fn bounds(&self) -> Aabb {
        Aabb { min: self.min, max: self.max }
    }

    fn surface(&self) -> u16 {
        self.surface
    }
}

#[cfg(test)]
mod tests {
    use super::super::test_util::*;
    use super::*;

    fn cube() -> AxisAlignedBox {
        AxisAlignedBox::new(p(0, 0, -10), p(1, 2, 3), 0)
    }

    #[test]
    fn hits_the_near_face_then_the_far_one() {
        let r = ray(p(0, 0, 0), [0, 0, -1]);
        assert_eq!(cube().intersect(&r, far(), Leaving::No), Some(s(7)));
        assert_eq!(cube().intersect(&r, far(), Leaving::Inward), Some(s(13)));
        assert_eq!(cube().intersect(&r, far(), Leaving::Outward), None);
        assert_eq!(cube().normal_at(r.at(s(7))), Dir::Z);
        assert_eq!(cube().normal_at(r.at(s(13))), -Dir::Z);
    }

    #[test]
    fn misses_and_parallel_rays() {
        assert_eq!(cube().intersect(&ray(p(2, 0, 0), [0, 0, -1]), far(), Leaving::No), None);
        // Parallel to the x faces, inside the x slab: hits.
        assert_eq!(cube().intersect(&ray(p(1, 0, 0), [0, 0, -1]), far(), Leaving::No), Some(s(7)));
        // Pointing away.
        assert_eq!(cube().intersect(&ray(p(0, 0, 0), [0, 0, 1]), far(), Leaving::No), None);
    }

    #[test]
    fn oblique_hit_and_side_normal() {
        let r = ray(p(-5, 0, -10), [1, 0, 0]);
        assert_eq!(cube().intersect(&r, far(), Leaving::No), Some(s(4)));
        assert_eq!(cube().normal_at(r.at(s(4))), -Dir::X);
        let r = ray(p(0, 10, -10), [0, -1, 0]);
        assert_eq!(cube().normal_at(r.at(cube().intersect(&r, far(), Leaving::No).unwrap())), Dir::Y);
    }

    #[test]
    fn from_inside_exits() {
        let r = ray(p(0, 0, -10), [1, 0, 0]);
        assert_eq!(cube().intersect(&r, far(), Leaving::No), Some(s(1)));
    }

    #[test]
    fn nearly_parallel_ray_has_no_overflow() {
        let r = Ray { origin: p(0, 0, 0), dir: Dir::from_bits([1, 0, -(1 << 30)]) };
        assert_eq!(cube().intersect(&r, far(), Leaving::No), Some(s(7)));
        let r = Ray { origin: p(5, 0, -10), dir: Dir::from_bits([-1, 0, 1 << 30]) };
        assert_eq!(cube().intersect(&r, far(), Leaving::No), None);
    }

    /// The 32-bit span is the wide one, and refuses what it cannot hold:
    /// random boxes and rays at every scale, faces and directions at their
    /// extremes.
    #[test]
    fn the_narrow_span_is_the_wide_one() {
        let mut next = crate::test_rng::seeded(0x51ab_5a11);
        let span_bits = |span: Option<SlabSpan>| span.map(|s| [s.enter, s.exit].map(|r| r.map(|r| (r.num, r.den))));
        let extremes = [i32::MIN, i32::MIN + 1, -(1 << 30), -1, 0, 1, 1 << 30, i32::MAX - 1, i32::MAX];
        let (mut narrow, mut wide) = (0, 0);
        for _ in 0..200_000 {
            let mut coordinate = || {
                let v = next();
                match v % 8 {
                    0 => extremes[(v >> 3) as usize % extremes.len()],
                    k => ((v >> 8) as i32) >> (4 * k),
                }
            };
            let (o, a, b) = ([0; 3].map(|_| coordinate()), [0; 3].map(|_| coordinate()), [0; 3].map(|_| coordinate()));
            let (lo, hi) = ([0, 1, 2].map(|k| a[k].min(b[k])), [0, 1, 2].map(|k| a[k].max(b[k])));
            let d = [0; 3].map(|_| match next() % 6 {
                0 => 0,
                1 => [1 << 30, -(1 << 30), MAX_CROSSING_DEN as i32, -(MAX_CROSSING_DEN as i32), i32::MIN]
                    [next() as usize % 5],
                _ => (next() as i32) >> 1,
            });
            let expected = slab_span_wide(o.map(i64::from), d.map(i64::from), lo.map(i64::from), hi.map(i64::from));
            match slab_span_narrow(o, d, lo, hi) {
                Ok(span) => {
                    narrow += 1;
                    assert_eq!(span_bits(span), span_bits(expected), "{o:?} {d:?} {lo:?} {hi:?}");
                }
                Err(NeedsWide) => {
                    wide += 1;
                    let reach = |x: i32, y: i32| x.checked_sub(y).is_none();
                    assert!(
                        (0..3).any(|k| reach(lo[k], o[k])
                            || reach(hi[k], o[k])
                            || reach(o[k], lo[k])
                            || reach(o[k], hi[k]))
                            || d.iter().any(|&c| c.unsigned_abs() > MAX_CROSSING_DEN),
                        "{o:?} {d:?} {lo:?} {hi:?}"
                    );
                }
            }
        }
        assert!(narrow > 100_000 && wide > 10_000, "{narrow} narrow, {wide} wide");
    }

    /// The coarse comparison, where it answers, is the exact one: random
    /// crossings, many at the extremes of their ranges and nearly equal.
    #[test]
    fn coarse_crossings_compare_exactly() {
        let mut next = crate::test_rng::seeded(0xc0a5_e5e5);
        let mut decided = 0;
        for _ in 0..500_000 {
            let mut num = || match next() % 4 {
                0 => [i32::MIN, i32::MAX, 0, 1, -1][next() as usize % 5],
                k => (next() as i32) >> (8 * (k - 1)),
            };
            let (xn, yn) = (num(), num());
            let mut den = || match next() % 4 {
                0 => [1, MAX_CROSSING_DEN, 1 << 30, 1 << 15][next() as usize % 4] as i32,
                k => 1 + ((next() as u32 % MAX_CROSSING_DEN) >> (8 * (k - 1))) as i32,
            };
            let (x, y) = (Crossing { num: xn, den: den() }, Crossing { num: yn, den: den() });
            let exact = (x.num as i64) * (y.den as i64) < (y.num as i64) * (x.den as i64);
            if let Some(answer) = coarse_crossing_lt(x, y) {
                decided += 1;
                assert_eq!(answer, exact, "{x:?} {y:?}");
            }
            assert_eq!(x.lt(y), exact, "{x:?} {y:?}");
        }
        assert!(decided > 250_000, "{decided} decided");
    }

    /// Rays from outside a slab moving away from it, and rays entering a
    /// slab beyond their bound, are rejected before the span, with the
    /// span's answer: random boxes and rays, many along the axes, from
    /// outside, inside and on the faces.
    #[test]
    fn rays_leaving_a_slab_behind_miss_as_the_span_says() {
        let mut next = crate::test_rng::seeded(0xb0c5_1ab5);
        let mut coordinate = move |range: u64| (next() % (2 * range + 1)) as i32 - range as i32;
        let (mut early, mut beyond) = (0, 0);
        for _ in 0..100_000 {
            let c = Vec3::from_bits([0; 3].map(|_| coordinate(1 << 20)));
            let h = Vec3::from_bits([0; 3].map(|_| 1 + coordinate(1 << 18).abs()));
            let b = AxisAlignedBox::new(c, h, 0);
            let (lo, hi) = (b.min.bits(), b.max.bits());
            let o = Vec3::from_bits([0, 1, 2].map(|a| match coordinate(2) {
                -2 => lo[a],
                2 => hi[a],
                _ => lo[a] + coordinate(1 << 21),
            }));
            let d = [0; 3].map(|_| if coordinate(2) == 0 { 0 } else { coordinate(1 << 20) as i64 });
            let Some(dir) = Dir::normalize(d) else { continue };
            let r = Ray { origin: o, dir };
            let t_max = Scalar::from_bits(coordinate(1 << 24).abs());
            for leaving in [Leaving::No, Leaving::Inward] {
                let hit = b.intersect(&r, t_max, leaving);
                assert_eq!(hit, b.intersect_span(&r, t_max, leaving), "{r:?} {b:?}");
                // The parameter is the span's crossing divided exactly.
                if let (Some(t), Some(span)) = (hit, slab_span(&r, b.min, b.max)) {
                    let crossings = [span.enter, span.exit].into_iter().flatten();
                    assert!(crossings.map(|c| (c.num << 30) / c.den).any(|q| q == t.to_bits() as i64), "{r:?} {b:?}");
                }
            }
            // A bound at the hit's own parameter, and one short of it.
            if let Some(t) = b.intersect_span(&r, Scalar::MAX, Leaving::No) {
                for bound in [t, Scalar::from_bits(t.to_bits() - 1)] {
                    assert_eq!(
                        b.intersect(&r, bound, Leaving::No),
                        b.intersect_span(&r, bound, Leaving::No),
                        "{r:?} {b:?}"
                    );
                }
            }
            let (ob, db) = (o.bits(), dir.bits());
            early += (0..3).any(|a| (ob[a] > hi[a] && db[a] >= 0) || (ob[a] < lo[a] && db[a] <= 0)) as u32;
            beyond += enters_beyond([ob, db, lo, hi], t_max) as u32;
        }
        assert!(early > 30_000 && beyond > 10_000, "{early} rejected early, {beyond} entering beyond");
    }
}
