//! Directions to cells: the face and cell a direction from a light falls in,
//! and the cells an object's widened bounds are seen in (its footprint).

use super::{DEPTH_MAX, DEPTH_SHIFT, MAX_COMPONENT, MAX_LEVEL};
use crate::scene::SceneView;
use crate::shapes::Aabb;

/// A face's cells of one object (or the union of a light's objects): the
/// first and last along each of the face's two other axes, at the finest
/// level built, and its depth.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) struct Rect {
    pub(super) low: [u8; 2],
    pub(super) high: [u8; 2],
    pub(super) depth: u32,
}

impl Rect {
    /// The rectangle `shift` levels coarser.
    pub(super) fn coarser(self, shift: u32) -> Rect {
        Rect { low: self.low.map(|c| c >> shift), high: self.high.map(|c| c >> shift), ..self }
    }

    pub(super) fn cells(self) -> usize {
        (self.high[0] - self.low[0] + 1) as usize * (self.high[1] - self.low[1] + 1) as usize
    }

    pub(super) fn union(self, o: Rect) -> Rect {
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
pub(super) enum Footprint {
    Around,
    Faces([Option<Rect>; 6]),
}

/// The two axes of a face of axis `a`, in the order its cells are indexed.
pub(super) const fn other_axes(a: usize) -> [usize; 2] {
    [(a + 1) % 3, (a + 2) % 3]
}

/// The cell `⌊2^level·(y + x) / 2x⌋` (clamped to `0..2^level`) of the
/// ratio `y / x`, `x > 0`, `|x|, |y| < 2^61`: exact, and monotone in the
/// ratio like the ray's. By long division, a bit a step: a 64-bit division
/// is long code on a 32-bit core, and a build makes up to 24 an object and
/// light (fig5_3's cost a Pico 3 M cycles).
pub(super) fn cell_of_ratio(y: i64, x: i64, level: u32) -> u8 {
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
pub(super) fn quotient_bits<T>(mut rest: T, divisor: T, steps: u32) -> u32
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
pub(super) fn footprint(bounds: Aabb, light: [i64; 3], margin: i64, level: u32) -> Footprint {
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
pub(super) struct Needs {
    pub(super) cells: [usize; MAX_LEVEL as usize + 1],
    pub(super) entries: [usize; MAX_LEVEL as usize + 1],
}

/// Light `light`'s needs at each level up to `finest`, and the union of its
/// objects' rectangles on each face at `finest`.
pub(super) fn needs(scene: &SceneView<'_>, light: usize, finest: u32, margin: i64) -> (Needs, [Option<Rect>; 6]) {
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

/// Where the direction `v` (from a light) is in a cube of `2^level` cells a
/// side: its face (its largest component's axis, `x` before `y` before `z`,
/// then that component's sign), that component's magnitude `m`, and its
/// cell along the face's two other axes. `None` for the zero vector and
/// for components of 2^30 or more (none in the scene's range).
#[inline(always)]
pub(super) fn direction([x, y, z]: [i32; 3], level: u8) -> Option<(usize, u32, [u32; 2])> {
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
pub(super) fn cell_along(v: i32, m: u32, level: u8) -> u32 {
    quotient_bits((v as u32).wrapping_add(m), m << 1, MAX_LEVEL) >> (MAX_LEVEL - level as u32)
}

#[cfg(test)]
pub(super) mod tests {
    use super::*;
    use crate::accel::light_buffer::MARGIN;
    use crate::math::Vec3;

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
    pub(in crate::accel::light_buffer) fn across_a_cell_edge(
        next: &mut impl FnMut() -> u64,
        level: u32,
    ) -> ([i64; 3], [[i64; 3]; 2], [i64; 3]) {
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
}
