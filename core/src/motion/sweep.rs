//! Where a ray segment meets a moving object: exact integer tests of a
//! segment against boxes and spheres on the tracker's grid
//! ([`super::grid`]), and the search for the first frame of the loop at
//! which a track's objects meet a segment.
//!
//! Conservative by construction, as the grid is: "no meeting" means no
//! ray along the segment can meet anything in the box. On the grid every
//! coordinate is below 2^14 in magnitude, so the slab test's products fit
//! an `i32`.

/// A sphere's search tests ranges of fewer frames than this frame by frame,
/// by the sphere's own test: below it a range's box, and then its halves',
/// cost more than the frames' own tests (measured on the Cortex-M0+, the
/// emulated Pico's anim_fig5_1: 3 against 2 or 6, −2 % a frame, −4 % the
/// first frame's search of the whole loop, against halving down to one).
const SCANNED_STEPS: u32 = 3;

use super::grid::{cell, cell_of_i32, GridBox, GRID_BITS, WIDENING};
use super::path::{Path, Stretch};
use crate::math::{mul_u32_wide, square_u32_wide};

/// A segment from `p` to `q` on the grid.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) struct Segment {
    p: [i32; 3],
    q: [i32; 3],
    /// The segment's own box on the grid, for a quick rejection.
    lo: [i32; 3],
    hi: [i32; 3],
}

/// `u · v` for grid differences (each below 2^15 in magnitude): every
/// product fits an `i32`, which a Cortex-M0 makes in one instruction
/// (an `i64` product is a library call there).
#[inline]
fn dot(u: [i32; 3], v: [i32; 3]) -> i64 {
    i64::from(u[0] * v[0]) + i64::from(u[1] * v[1]) + i64::from(u[2] * v[2])
}

/// `|u|²` for a difference of grid differences (each below 2^16 in
/// magnitude): every square fits a `u32`.
#[inline]
fn squared_length(u: [i32; 3]) -> i64 {
    u.iter().map(|&x| i64::from(x.unsigned_abs() * x.unsigned_abs())).sum()
}

/// Whether the point `w` from the segment's start is within `√k` of the
/// line along `d`: `|w|²·|d|² − (w·d)² ≤ k·|d|²`, given the dot products.
/// Those of grid differences, and `k` (a squared radius on the grid), are
/// below 2^32 in magnitude, so each product is a 32×32→64 one
/// (`mul_u32_wide`: four one-instruction multiplies on a Cortex-M0, where
/// an `i64` product is a library call); `|w|²·|d|² ≥ (w·d)²` (Cauchy and
/// Schwarz, exactly in integers), so the difference never wraps.
#[inline]
fn within_line(ww: i64, wd: i64, dd: i64, k: i64) -> bool {
    let (ww, wd, dd, k) = (ww as u32, wd.unsigned_abs() as u32, dd as u32, k as u32);
    mul_u32_wide(ww, dd) - square_u32_wide(wd) <= mul_u32_wide(k, dd)
}

impl Segment {
    /// The segment between raw points `p` and `q`.
    pub(crate) fn new(p: [i64; 3], q: [i64; 3]) -> Segment {
        let (p, q) = (p.map(cell), q.map(cell));
        let lo = [0, 1, 2].map(|a| p[a].min(q[a]));
        let hi = [0, 1, 2].map(|a| p[a].max(q[a]));
        Segment { p, q, lo, hi }
    }

    /// Whether the segment comes near the raw sphere of centre `center` and
    /// radius `radius`: on the grid, the radius widened and rounded up,
    /// then by two cells (more than the rounding of the centre and of the
    /// segment's ends moves them apart).
    pub(crate) fn near_sphere(&self, center: [i32; 3], radius: i32) -> bool {
        let c = center.map(cell_of_i32);
        // Below 2^14 (radii below 2^31), its square below 2^28: one
        // instruction, in an `i32`; so are the box's sides, `c ± r`
        // (within 2^15), and the comparisons.
        let r = (radius.saturating_add(WIDENING) >> GRID_BITS) + 3;
        let r2 = i64::from(r * r);
        if (0..3).any(|a| self.hi[a] < c[a] - r || self.lo[a] > c[a] + r) {
            return false;
        }
        // Cells are below 2^14: differences below 2^15, their squares and
        // their products' sums fit an i64.
        let d = [0, 1, 2].map(|a| self.q[a] - self.p[a]);
        let w = [0, 1, 2].map(|a| c[a] - self.p[a]);
        let (dd, wd, ww) = (dot(d, d), dot(w, d), dot(w, w));
        if wd <= 0 || dd == 0 {
            return ww <= r2;
        }
        if wd >= dd {
            return squared_length([0, 1, 2].map(|a| w[a] - d[a])) <= r2;
        }
        within_line(ww, wd, dd, r2)
    }

    /// Whether the segment surely passes through the raw sphere of centre
    /// `center` and radius `radius`, well inside it, with both its ends well
    /// outside: a shadow ray along it is surely blocked by the sphere. On
    /// the grid, the radius narrowed by four widenings and four cells for
    /// the line, and widened likewise for the ends: any ray the tracer
    /// sends along the segment meets the sphere between its ends.
    pub(crate) fn through_sphere(&self, center: [i32; 3], radius: i32) -> bool {
        let c = center.map(cell_of_i32);
        // Both below 2^14, their squares in an `i32`, as the box's sides.
        let inner = (radius.saturating_sub(4 * WIDENING) >> GRID_BITS) - 4;
        let outer = (radius.saturating_add(4 * WIDENING) >> GRID_BITS) + 5;
        let (inner2, outer2) = (i64::from(inner * inner), i64::from(outer * outer));
        // Passing within `inner` of the centre, the segment's box meets the
        // centre's box of that half-side.
        if inner <= 0 || (0..3).any(|a| self.hi[a] < c[a] - inner || self.lo[a] > c[a] + inner) {
            return false;
        }
        let d = [0, 1, 2].map(|a| self.q[a] - self.p[a]);
        let w = [0, 1, 2].map(|a| c[a] - self.p[a]);
        let e = squared_length([0, 1, 2].map(|a| w[a] - d[a]));
        let (dd, wd, ww) = (dot(d, d), dot(w, d), dot(w, w));
        ww > outer2 && e > outer2 && wd > 0 && wd < dd && within_line(ww, wd, dd, inner2)
    }

    /// Whether the segment comes near the raw box `[lo, hi]` (for the
    /// tests: the tracker's boxes are on the grid already).
    #[cfg(test)]
    fn meets(&self, lo: [i32; 3], hi: [i32; 3]) -> bool {
        self.meets_grid(&GridBox::around([lo, hi]))
    }

    /// Whether the segment comes near the box `grid`, a raw box on the grid
    /// (widened and rounded outward, then by a whole cell).
    pub(crate) fn meets_grid(&self, grid: &GridBox) -> bool {
        let [lo, hi] = grid.corners();
        if (0..3).any(|a| self.hi[a] < lo[a] || self.lo[a] > hi[a]) {
            return false;
        }
        // The parameters where the segment is within each slab, as
        // fractions num/den with den > 0: it enters at the largest start
        // and leaves at the smallest end.
        let (mut enter, mut enter_den, mut leave, mut leave_den) = (0i32, 1i32, 1i32, 1i32);
        for a in 0..3 {
            let d = self.q[a] - self.p[a];
            if d == 0 {
                // Within the slab on this axis (the box test above).
                continue;
            }
            let (from, to) = (lo[a] - self.p[a], hi[a] - self.p[a]);
            let (start, end, den) = if d > 0 { (from, to, d) } else { (-to, -from, -d) };
            if start * enter_den > enter * den {
                (enter, enter_den) = (start, den);
            }
            if end * leave_den < leave * den {
                (leave, leave_den) = (end, den);
            }
            if enter * leave_den > leave * enter_den {
                return false;
            }
        }
        true
    }
}

/// A track's objects through the loop: their box at frame 0, for a
/// sphere its centre and radius there (its own test is then used at each
/// frame), and their displacement at each frame (from frame 0), whose
/// keys cut the loop into monotone stretches.
pub(crate) struct Sweep<'m> {
    pub first: [[i32; 3]; 2],
    pub sphere: Option<([i32; 3], i32)>,
    pub path: Path<'m>,
}

/// The centre and (rounded up) radius of the sphere whose box is `[lo, hi]`:
/// the box is the centre ± the radius, exactly.
pub(crate) fn sphere_in([lo, hi]: [[i32; 3]; 2]) -> ([i32; 3], i32) {
    let center = [0, 1, 2].map(|a| lo[a] / 2 + hi[a] / 2 + (lo[a] % 2 + hi[a] % 2) / 2);
    (center, hi[0] / 2 - lo[0] / 2 + 1)
}

impl Sweep<'_> {
    /// A sphere's centre when displaced by `d` and its radius, if the
    /// track is one.
    fn sphere_at(&self, d: [i32; 3]) -> Option<([i32; 3], i32)> {
        let (center, radius) = self.sphere?;
        Some(([0, 1, 2].map(|a| center[a].saturating_add(d[a])), radius))
    }

    /// Whether `segment` comes near the objects at frame `frame`.
    pub(crate) fn meets_at(&self, segment: &Segment, frame: u32) -> bool {
        self.meets_displaced(segment, self.path.at(frame))
    }

    /// Whether `segment` comes near the objects displaced by `d`.
    fn meets_displaced(&self, segment: &Segment, d: [i32; 3]) -> bool {
        match self.sphere_at(d) {
            Some((center, radius)) => segment.near_sphere(center, radius),
            None => self.meets_between(segment, (d, d)),
        }
    }

    /// Whether the objects (a sphere) surely block a shadow ray along
    /// `segment` at frame `frame`.
    pub(crate) fn blocks_at(&self, segment: &Segment, frame: u32) -> bool {
        self.sphere_at(self.path.at(frame)).is_some_and(|(center, radius)| segment.through_sphere(center, radius))
    }

    /// The smallest `e` in `1..=limit` such that the objects do not surely
    /// block `segment` at frame `frame + e` of the loop, if any.
    pub(crate) fn first_unblocked(&self, segment: &Segment, frame: u32, limit: u32) -> Option<u32> {
        let n = self.path.frames;
        (1..=limit.min(n.saturating_sub(1))).find(|&e| !self.blocks_at(segment, (frame + e) % n))
    }

    /// Whether `segment` comes near the objects displaced by any amount
    /// within `lo..=hi` on each axis.
    fn meets_between(&self, segment: &Segment, displacements: ([i32; 3], [i32; 3])) -> bool {
        segment.meets_grid(&GridBox::displaced(self.first, displacements))
    }

    /// The smallest `e` in `1..=limit` such that `segment` comes near the
    /// objects at frame `frame + e` of the loop (after the last frame,
    /// frame 0 again), if any.
    pub(crate) fn first_meeting(&self, segment: &Segment, frame: u32, limit: u32) -> Option<u32> {
        let n = self.path.frames;
        let limit = limit.min(n.saturating_sub(1));
        if limit == 0 {
            return None;
        }
        // The frames after `frame` up to the last, then from frame 0.
        let end = frame.saturating_add(limit);
        if frame + 1 < n {
            if let Some(g) = self.first_within(segment, frame + 1, end.min(n - 1)) {
                return Some(g - frame);
            }
        }
        if end >= n {
            return self.first_within(segment, 0, end - n).map(|g| g + n - frame);
        }
        None
    }

    /// The first frame of `lo..=hi` at which `segment` comes near the
    /// objects.
    fn first_within(&self, segment: &Segment, lo: u32, hi: u32) -> Option<u32> {
        for stretch in self.path.stretches() {
            let (a, b) = (stretch.from.max(lo), stretch.to.min(hi));
            if a > b {
                continue;
            }
            if let Some(g) = self.bisect(segment, &stretch, a, b) {
                return Some(g);
            }
        }
        None
    }

    /// The first frame of `a..=b` (within `stretch`) at which `segment`
    /// comes near the objects: halves tested by the bounds of their
    /// displacements (a range none of whose frames the objects come near
    /// is left whole), left first, and single frames by the objects' own
    /// test (a sphere's ranges shorter than [`SCANNED_STEPS`] frame by
    /// frame). Counted in steps after the stretch's key, where a frame is
    /// its key's frame plus its step (or the stretch stands still).
    fn bisect(&self, segment: &Segment, stretch: &Stretch, a: u32, b: u32) -> Option<u32> {
        let key = self.path.key(stretch);
        let (ta, tb) = (key.steps_to(a), key.steps_to(b));
        if ta == tb {
            // Standing still over a..=b: near at every frame or at none.
            return self.meets_displaced(segment, key.after(ta)).then_some(a);
        }
        // Moving: a..=b are the key's steps ta..=tb, each a frame.
        let frame_of = |t: u32| a + (t - ta);
        // The whole stretch: its box on the grid, made once as the motion
        // was recorded, is the first range's.
        let mut known_to_meet = match key.reach_over(ta, tb) {
            Some(reach) if !segment.meets_grid(reach) => return None,
            Some(_) => true,
            None => false,
        };
        // Each step pops one range and pushes two, halving: 2 · 32 levels.
        let mut stack: heapless::Vec<(u32, u32), 64> = heapless::Vec::new();
        let _ = stack.push((ta, tb));
        while let Some((ta, tb)) = stack.pop() {
            let met = core::mem::take(&mut known_to_meet);
            if self.sphere.is_some() && tb - ta < SCANNED_STEPS {
                if let Some(t) = (ta..=tb).find(|&t| self.meets_displaced(segment, key.after(t))) {
                    return Some(frame_of(t));
                }
                continue;
            }
            if !met && !self.meets_between(segment, key.within(ta, tb)) {
                continue;
            }
            if ta == tb {
                if self.meets_displaced(segment, key.after(ta)) {
                    return Some(frame_of(ta));
                }
                continue;
            }
            let mid = ta + (tb - ta) / 2;
            // Room for both: the stack holds at most one range a level.
            let _ = stack.push((mid + 1, tb));
            let _ = stack.push((ta, mid));
        }
        None
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const CELL: i64 = 1 << GRID_BITS;

    fn box_at(c: [i64; 3], half: i64) -> ([i32; 3], [i32; 3]) {
        (c.map(|v| (v - half) as i32), c.map(|v| (v + half) as i32))
    }

    #[test]
    fn a_segment_meets_what_lies_on_it_and_misses_what_is_far() {
        let s = Segment::new([0, 0, 0], [100 * CELL, 0, 0]);
        let (lo, hi) = box_at([50 * CELL, 0, 0], CELL);
        assert!(s.meets(lo, hi));
        let (lo, hi) = box_at([50 * CELL, 20 * CELL, 0], CELL);
        assert!(!s.meets(lo, hi));
        // Beyond its end.
        let (lo, hi) = box_at([110 * CELL, 0, 0], CELL);
        assert!(!s.meets(lo, hi));
        // A diagonal passing a box's corner at a distance.
        let d = Segment::new([0, 0, 0], [100 * CELL, 100 * CELL, 0]);
        assert!(d.meets(box_at([50 * CELL, 50 * CELL, 0], CELL).0, box_at([50 * CELL, 50 * CELL, 0], CELL).1));
        assert!(!d.meets(box_at([50 * CELL, 60 * CELL, 0], CELL).0, box_at([50 * CELL, 60 * CELL, 0], CELL).1));
    }

    #[test]
    fn near_misses_within_the_widening_count_as_meetings() {
        // The box's edge WIDENING − 1 raw units from the segment, off the
        // grid: rounding must not lose it.
        let mut next = crate::test_rng::seeded(0x5e9_1e57);
        for _ in 0..20_000 {
            let mut r = || (next() as i64 >> 36) % (1 << 29);
            let p = [r(), r(), r()];
            let q = [r(), r(), r()];
            let t = (next() % 1024) as i64;
            let on = [0, 1, 2].map(|a| p[a] + (q[a] - p[a]) * t / 1024);
            let gap = WIDENING as i64 - 1;
            let lo = on.map(|v| (v + gap) as i32);
            let hi = on.map(|v| (v + gap + 5) as i32);
            assert!(Segment::new(p, q).meets(lo, hi), "{p:?} {q:?} {on:?}");
        }
    }

    /// The distance from raw point `c` to the raw segment `p`–`q`, and
    /// where along it the nearest point is (0 at `p`, 1 at `q`).
    fn distance_to_segment(p: [i64; 3], q: [i64; 3], c: [i64; 3]) -> (f64, f64) {
        let d = [0, 1, 2].map(|a| (q[a] - p[a]) as f64);
        let w = [0, 1, 2].map(|a| (c[a] - p[a]) as f64);
        let dd: f64 = d.iter().map(|x| x * x).sum();
        let t = if dd == 0.0 { 0.0 } else { (0..3).map(|a| w[a] * d[a]).sum::<f64>() / dd };
        let t = t.clamp(0.0, 1.0);
        let gap: f64 = (0..3).map(|a| (w[a] - t * d[a]).powi(2)).sum();
        (gap.sqrt(), t)
    }

    /// A random raw point of the scene's range (2^29 each way).
    fn point(next: &mut impl FnMut() -> u64) -> [i64; 3] {
        [0; 3].map(|_| (next() as i64 >> 34) % (1 << 29))
    }

    /// A random raw segment of the scene's range, and a point of it.
    fn segment_and_point(next: &mut impl FnMut() -> u64) -> ([i64; 3], [i64; 3], [i64; 3]) {
        let (p, q) = (point(next), point(next));
        let t = (next() % 1025) as i64;
        (p, q, [0, 1, 2].map(|a| p[a] + (q[a] - p[a]) * t / 1024))
    }

    /// A random unit vector.
    fn direction(next: &mut impl FnMut() -> u64) -> [f64; 3] {
        loop {
            let v = [0; 3].map(|_| (next() >> 11) as f64 / (1u64 << 53) as f64 * 2.0 - 1.0);
            let length = v.iter().map(|x| x * x).sum::<f64>().sqrt();
            if (0.1..=1.0).contains(&length) {
                return v.map(|x| x / length);
            }
        }
    }

    /// A random radius: from under a grid cell to a quarter of the range.
    fn radius(next: &mut impl FnMut() -> u64) -> i64 {
        let bits = 10 + next() % 18;
        (next() % (1 << bits)) as i64 + 1
    }

    #[test]
    fn a_sphere_just_within_the_widening_of_a_segment_is_near_it() {
        // The sphere's surface WIDENING less a few raw units from a point
        // of the segment (the few: that point's own rounding): at the edge
        // of the widening the nearness test promises, which its margin of
        // cells only just covers for every rounding of the grid.
        let mut next = crate::test_rng::seeded(0x5fe7_e0ed);
        for _ in 0..400_000 {
            let (p, q, on) = segment_and_point(&mut next);
            let r = radius(&mut next);
            let u = direction(&mut next);
            let reach = (r + i64::from(WIDENING) - 3) as f64;
            let c = [0, 1, 2].map(|a| on[a] + (u[a] * reach).round() as i64);
            let (gap, _) = distance_to_segment(p, q, c);
            assert!(gap <= (r + i64::from(WIDENING)) as f64, "{gap} {r}");
            let center = c.map(|v| v as i32);
            assert!(Segment::new(p, q).near_sphere(center, r as i32), "p {p:?} q {q:?} centre {c:?} radius {r}");
        }
    }

    #[test]
    fn a_box_just_within_the_widening_of_a_segment_on_either_side_is_met() {
        // Each axis's face of the box WIDENING − 1 raw units beyond a point
        // of the segment, on its low or its high side: rounding must lose
        // neither (the box's low end is rounded down and widened a cell,
        // its high end rounded down and widened two).
        let mut next = crate::test_rng::seeded(0x0b0c_5ede);
        for _ in 0..400_000 {
            let (p, q, on) = segment_and_point(&mut next);
            let gap = i64::from(WIDENING) - 1;
            let size = (next() % (1 << 20)) as i64;
            let above = [0; 3].map(|_| next() % 2 == 0);
            let lo = [0, 1, 2].map(|a| if above[a] { on[a] + gap } else { on[a] - gap - size } as i32);
            let hi = [0, 1, 2].map(|a| if above[a] { on[a] + gap + size } else { on[a] - gap } as i32);
            assert!(Segment::new(p, q).meets(lo, hi), "p {p:?} q {q:?} box {lo:?}..{hi:?}");
        }
    }

    #[test]
    fn a_segment_through_a_sphere_is_said_so_only_well_inside_it_with_its_ends_well_outside() {
        // Segments passing at any depth in the sphere up to just outside
        // four widenings within its surface, their ends from just inside
        // four widenings beyond it to a dozen cells further: where
        // `through_sphere` says "through", the raw segment passes within
        // four widenings of the surface, and its ends are at least that far
        // outside. (Its margins keep about two cells more than that
        // rounding needs, so a margin three cells narrower fails here, one
        // cell narrower does not.)
        let mut next = crate::test_rng::seeded(0x7b0_05ed);
        let (four, cell) = (4 * i64::from(WIDENING), 1i64 << GRID_BITS);
        let (mut through, mut cases) = (0, 0);
        for _ in 0..400_000 {
            let r = 16 * cell + (next() % (1 << 26)) as i64;
            let c = point(&mut next);
            // The line's direction, and the way from the centre to its nearest point.
            let (u, v) = (direction(&mut next), direction(&mut next));
            let dot: f64 = (0..3).map(|a| u[a] * v[a]).sum();
            let side = [0, 1, 2].map(|a| v[a] - dot * u[a]);
            let length = side.iter().map(|x| x * x).sum::<f64>().sqrt();
            if length < 0.1 {
                continue;
            }
            let side = side.map(|x| x / length);
            // At the line's edge (the ends far outside), or at an end's (the
            // line deep inside), within a few cells of it.
            let near = |next: &mut dyn FnMut() -> u64, below: i64, above: i64| {
                (next() % ((below + above) * cell) as u64) as i64 - below * cell
            };
            let along = |from_centre: i64, pass: f64| ((from_centre as f64).powi(2) - pass * pass).max(0.0).sqrt();
            let (pass, before, after) = match next() % 2 {
                0 => {
                    let pass = (r - four + near(&mut next, 4, 1)) as f64;
                    let far = r + four + 6 * cell;
                    (pass, along(far + near(&mut next, 0, 14), pass), along(far + near(&mut next, 0, 14), pass))
                }
                _ => {
                    let pass = (next() % (r as u64 / 2)) as f64;
                    let edge = r + four + near(&mut next, 1, 5);
                    (pass, along(edge, pass), along(r + four + 6 * cell + near(&mut next, 0, 14), pass))
                }
            };
            let (before, after) = if next() % 2 == 0 { (before, after) } else { (after, before) };
            let at = |along: f64| [0, 1, 2].map(|a| c[a] + (side[a] * pass + u[a] * along).round() as i64);
            let (p, q) = (at(-before), at(after));
            cases += 1;
            if !Segment::new(p, q).through_sphere(c.map(|v| v as i32), r as i32) {
                continue;
            }
            through += 1;
            let (gap, t) = distance_to_segment(p, q, c);
            let end = |e: [i64; 3]| distance_to_segment(e, e, c).0;
            assert!(gap <= (r - four) as f64 && t > 0.0 && t < 1.0, "line: p {p:?} q {q:?} c {c:?} r {r}: {gap}");
            assert!(end(p) >= (r + four) as f64 && end(q) >= (r + four) as f64, "ends: p {p:?} q {q:?} c {c:?} r {r}");
        }
        assert!(through > cases / 50, "{through} of {cases} said through: the cases reach its edges");
    }

    #[test]
    fn the_line_test_in_32_bit_products_is_the_wide_one() {
        // Grid differences up to the extremes (below 2^15), squared radii
        // up to 2^30, against the inequality in i128.
        let mut next = crate::test_rng::seeded(0x11e_7e57);
        let mut difference = || (next() % (1 << 16)) as i32 - (1 << 15) + 1;
        for case in 0..100_000 {
            let (w, d) = ([0; 3].map(|_| difference()), [0; 3].map(|_| difference()));
            let k = i64::from(difference().unsigned_abs()).pow(2) >> (case % 4);
            let (ww, wd, dd) = (dot(w, w), dot(w, d), dot(d, d));
            let wide = |x: i64| i128::from(x);
            let expected = wide(ww) * wide(dd) - wide(wd) * wide(wd) <= wide(k) * wide(dd);
            assert_eq!(within_line(ww, wd, dd, k), expected, "case {case}: w {w:?} d {d:?} k {k}");
            // On the line (w = d): within any k, 0 included.
            assert!(within_line(dd, dd, dd, 0), "case {case}: d {d:?}");
            // At the edge: the least k that holds, and the one below it.
            if dd > 0 {
                let least = (wide(ww) * wide(dd) - wide(wd) * wide(wd) + wide(dd) - 1) / wide(dd);
                let least = least as i64;
                assert!(within_line(ww, wd, dd, least), "case {case}: w {w:?} d {d:?} at {least}");
                assert!(
                    least == 0 || !within_line(ww, wd, dd, least - 1),
                    "case {case}: w {w:?} d {d:?} below {least}"
                );
            }
        }
    }

    #[test]
    fn the_extremes_fit_the_products() {
        // A miss's far end beyond the range and a box at the other side.
        let far = (1i64 << 29) + (1 << 31);
        let s = Segment::new([-(1 << 29); 3], [far, far, -far]);
        assert!(!s.meets([1 << 29; 3], [(1 << 29) + 5; 3]));
        let s = Segment::new([-(1 << 29); 3], [far; 3]);
        assert!(s.meets([1 << 28; 3], [(1 << 28) + 5; 3]));
        // The spheres' tests at the same extremes (a product past an
        // `i32` panics here, in a test build), a centre at either end.
        let s = Segment::new([-far; 3], [far, far, -far]);
        for center in [[i32::MIN; 3], [i32::MAX; 3], [i32::MAX, i32::MIN, i32::MAX]] {
            for radius in [1, 1 << 20, i32::MAX] {
                let _ = (s.near_sphere(center, radius), s.through_sphere(center, radius));
            }
        }
        let s = Segment::new([far; 3], [-far; 3]);
        assert!(s.near_sphere([0; 3], 1) && !s.near_sphere([i32::MAX, i32::MIN, 0], 1));
    }
}
