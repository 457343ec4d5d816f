//! The shading model of section 5: ambient, diffuse with B/(d + d0), Phong
//! specular, shadows by any object, and reflected and transmitted rays
//! weighted `C = (1 − t)·C_local + t·C_behind + r·C_reflected`.
//!
//! The ray tree is walked with an explicit, fixed-size stack instead of
//! recursion: `C` is linear in the child colours, so each ray simply adds
//! its weighted local colour to the sample and pushes its children with
//! their weights. Stack use is bounded whatever RDEPTH says (a 16 KiB board
//! cannot recurse a thousand levels).
//!
//! Bounds, per primary sample: at most [`MAX_RAYS_PER_SAMPLE`] rays are
//! traced and at most [`PENDING_RAYS`] wait; a branch whose weight rounds to
//! zero (below 2^-16, invisible) is not traced. Work cut by either limit is
//! counted in [`Stats::truncated`], never dropped silently. So the worst-case
//! time per pixel is `SAMPLES² · MAX_RAYS_PER_SAMPLE · (1 + lights)` ray
//! queries, each O(objects) in the naive mode.
//!
//! A sample can be stopped between any two of its rays, shadow rays
//! included (`Poll`, asked before each): the colour of a stopped sample
//! is partial, and `Poll::stopped` says so; one not stopped gives the
//! same bits whether it was asked or not.

mod mirror;

pub(crate) use mirror::Mirror;
#[cfg(test)]
pub(crate) use mirror::NoMirror;

use crate::accel::{uses_mailbox, Accelerator, Hit, Linked, Mailbox, RayStart, SceneAccelerator, ShadowLinks};
use crate::math::{
    leading_zeros, mul_u32_wide, mul_wide, pow_unit, reciprocal_start, shr_saturating_u32, shr_signed_to_u32, Dir,
    Scalar, Unit, Vec3, UNIT_ONE,
};
use crate::motion::{Lookout, RayKind};
use crate::scene::{Color, ObjectId, SceneView};
use crate::shapes::{Leaving, Ray};
use core::convert::Infallible;

/// Rays traced (not counting shadow rays) for one primary sample at most.
pub const MAX_RAYS_PER_SAMPLE: u32 = 4096;
/// Secondary rays waiting to be traced, at most.
pub const PENDING_RAYS: usize = 10;

/// Counters of one render call.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Stats {
    /// Primary, reflected and transmitted rays.
    pub rays: u64,
    /// Shadow rays.
    pub shadow_rays: u64,
    /// Branches of the ray tree not traced because a bound was reached
    /// (weights below 2^-16 are not counted: they are invisible).
    pub truncated: u64,
    /// Acceleration cells (octree leaves) visited by all queries.
    pub cells: u64,
}

impl Stats {
    /// What was counted after `earlier` (a copy of these counters).
    pub fn since(&self, earlier: &Stats) -> Stats {
        Stats {
            rays: self.rays - earlier.rays,
            shadow_rays: self.shadow_rays - earlier.shadow_rays,
            truncated: self.truncated - earlier.truncated,
            cells: self.cells - earlier.cells,
        }
    }

    /// Adds another render's counters, to total several threads or draws.
    pub fn add(&mut self, o: &Stats) {
        self.rays += o.rays;
        self.shadow_rays += o.shadow_rays;
        self.truncated += o.truncated;
        self.cells += o.cells;
    }
}

/// Asked before each ray of a sample (primary, reflected, transmitted or
/// shadow) whether to go on; the render module's `Stop` is behind it.
pub(crate) trait Poll {
    /// Why a sample stopped ([`Infallible`] for [`Unpolled`]).
    type Stopped;

    /// Whether it asks anything: false, a caller's loop may run the
    /// unpolled path itself.
    const ASKS: bool = true;

    /// Whether the sample traces its next ray: once false, false until the
    /// sample is given up.
    fn go_on(&mut self) -> bool;

    /// `Err` if a [`Poll::go_on`] said no: the sample's colour is partial.
    fn stopped(&self) -> Result<(), Self::Stopped>;
}

/// Never stops: the render path of a caller that does not ask, its checks
/// compiled away (the tracer's code is the same as without them).
pub(crate) struct Unpolled;

impl Poll for Unpolled {
    type Stopped = Infallible;

    const ASKS: bool = false;

    #[inline(always)]
    fn go_on(&mut self) -> bool {
        true
    }

    #[inline(always)]
    fn stopped(&self) -> Result<(), Infallible> {
        Ok(())
    }
}

/// Lights whose last blocker is remembered (light index modulo this).
const BLOCKER_SLOTS: usize = 8;

/// The mutable state of one thread of rendering: counters, the mailbox, and
/// per light the object that last blocked a shadow ray towards it.
pub(crate) struct Scratch<'m> {
    pub stats: Stats,
    pub mailbox: Mailbox<'m>,
    /// Neighbouring shadow rays are usually blocked by the same object, so
    /// it is tried before any walk (`u32::MAX`: none). Any blocker gives the
    /// same answer, so this cannot change an image.
    blockers: [u32; BLOCKER_SLOTS],
    /// In an animation traced with coherence, what sees every segment of
    /// the ray tree (`None`: a still picture, or a frame traced whole).
    pub lookout: Option<Lookout<'m>>,
}

impl<'m> Scratch<'m> {
    pub fn new(mailbox: Mailbox<'m>) -> Scratch<'m> {
        Scratch { stats: Stats::default(), mailbox, blockers: [u32::MAX; BLOCKER_SLOTS], lookout: None }
    }
}

/// A ray waiting in the tree, with the weight its colour counts with.
#[derive(Clone, Copy)]
struct Pending {
    ray: Ray,
    start: Option<RayStart>,
    depth: u32,
    weight: Scalar,
    kind: RayKind,
}

/// Traces rays through a scene with its accelerator, as build `L` links
/// it.
pub(crate) struct Tracer<'a, L: Linked> {
    scene: SceneView<'a>,
    accel: &'a SceneAccelerator<'a, L>,
}

impl<L: Linked> Clone for Tracer<'_, L> {
    fn clone(&self) -> Self {
        *self
    }
}

impl<L: Linked> Copy for Tracer<'_, L> {}

/// `num / den` in Q16.16, both Q32.32, rounded to nearest within 2^-17 of
/// the quotient (relative), saturating (and `i32::MAX` for a zero `den`):
/// the light's fall-off, where an exact quotient would cost three times as
/// much on a Cortex-M0 for nothing a 24-bit pixel can show. The top 32 bits
/// of each operand, and the divisor's reciprocal from the table
/// ([`reciprocal_start`]): one product.
fn ratio_q16(num: u64, den: u64) -> i32 {
    if den == 0 {
        return i32::MAX;
    }
    if num == 0 {
        return 0;
    }
    let (zn, zd) = (leading_zeros(num), leading_zeros(den));
    // Each operand's top 32 bits, in [2^31, 2^32): x = top · 2^(32 − z).
    let top = |x: u64, z: u32| shr_signed_to_u32(x, 32 - z as i32);
    // q ≈ (num_top / den_top) · 2^63, and the quotient num·2^16/den is
    // q · 2^(16 + zd − zn − 63), rounded on its last bit.
    let q = mul_u32_wide(top(num, zn), reciprocal_start(top(den, zd)));
    let shift = 46 + zn as i32 - zd as i32;
    let twice = match shift {
        ..1 => return i32::MAX,
        64.. => return 0,
        _ => shr_saturating_u32(q, shift as u32),
    };
    (twice / 2 + (twice & 1)).min(i32::MAX as u32) as i32
}

/// Whether the cosine between `normal` and the direction of `v` (as
/// [`Vec3::direction_and_length_estimate`] makes it, or exactly rounded)
/// surely has a Q2.30 floor ≤ 0, from the exact `n · v` (Q18.46).
///
/// Why `n · v ≤ −2^37` is enough: the direction's components are `v`'s
/// magnitudes cut by less than 2^shift ≤ 4 (moving `n · v` by less than
/// 4·√3·2^30 < 7·2^30), divided by a length below 2^31 after a scaling by
/// 2^-shift ≥ 1/4 (so the ideal Q4.60 cosine is at most (n·v + 7·2^30)/8),
/// then off by at most 8 units each (less than 14·2^30 in all): at most
/// (−128 + 7)/8·2^30 + 14·2^30 < 2^30 in Q4.60.
#[inline]
fn surely_behind(v: Vec3, normal: Dir) -> bool {
    v.dot_dir_q46_at_most(normal, -(1 << 37))
}

/// How a ray leaving a surface along `dir` relates to the shape it leaves:
/// closed shapes are entered when `dir` points against the outward normal.
#[inline]
fn leaving_along(geometric_normal: Dir, dir: Dir) -> Leaving {
    if geometric_normal.dot_is_negative(dir) {
        Leaving::Inward
    } else {
        Leaving::Outward
    }
}

impl<'a, L: Linked> Tracer<'a, L> {
    pub fn new(scene: SceneView<'a>, accel: &'a SceneAccelerator<'a, L>) -> Self {
        Tracer { scene, accel }
    }

    pub fn scene(&self) -> &SceneView<'a> {
        &self.scene
    }

    pub fn accel(&self) -> &'a SceneAccelerator<'a, L> {
        self.accel
    }

    /// What [`Tracer::trace`] gives for a primary ray known to hit nothing
    /// (the same colour and counts), without the ray.
    pub fn missed(&self, scratch: &mut Scratch<'_>) -> (Color, Option<ObjectId>) {
        scratch.stats.rays += 1;
        (Color::BLACK.saturating_add(self.background(Scalar::ONE)), None)
    }

    /// The background's share in a ray of `weight` that hits nothing.
    #[inline]
    fn background(&self, weight: Scalar) -> Color {
        self.scene.settings.background.scale(weight)
    }

    /// The linear colour seen along a primary ray, and the object it hits (as
    /// written: [`SceneView::written_object`]); `first_hit` is the ray's hit
    /// when the caller knows it, `mirror` where its reflection's may be
    /// found.
    // Not inlined: a frame of its own keeps the stack of a small board bounded
    // (inlined into the row loop, its locals and the pending rays multiply).
    #[inline(never)]
    pub fn trace<Q: Poll, M: Mirror>(
        &self,
        ray: Ray,
        mut first_hit: Option<Option<Hit>>,
        scratch: &mut Scratch<'_>,
        poll: &mut Q,
        mirror: &mut M,
    ) -> (Color, Option<ObjectId>) {
        let mut stack: heapless::Vec<Pending, PENDING_RAYS> = heapless::Vec::new();
        let mut color = Color::BLACK;
        let mut first_object = None;
        let mut traced = 0;
        // Where the camera ray hit, and whether its reflection is the
        // mirror's (the one reflected ray of depth 1), for the mirror's lists.
        let mut primary_t = Scalar::ZERO;
        let mut mirrored = false;
        // The ray being traced; its first child follows it directly, the
        // other waits on the stack (depth first, as a recursion would go).
        let mut p = Pending { ray, start: None, depth: 0, weight: Scalar::ONE, kind: RayKind::Primary };
        loop {
            if traced == MAX_RAYS_PER_SAMPLE {
                scratch.stats.truncated += 1 + stack.len() as u64;
                break;
            }
            if !poll.go_on() {
                break;
            }
            traced += 1;
            scratch.stats.rays += 1;
            let hit = match first_hit.take() {
                Some(hit) => hit,
                None => {
                    let listed = match M::LISTS && mirrored && p.depth == 1 && p.kind == RayKind::Reflected {
                        true => mirror.nearest(&self.scene, &p.ray, p.start, primary_t, poll),
                        false => None,
                    };
                    match listed {
                        Some(hit) => hit,
                        None => {
                            if uses_mailbox::<L>() {
                                scratch.mailbox.clear();
                            }
                            self.accel.nearest(&self.scene, &p.ray, p.start, &mut scratch.mailbox)
                        }
                    }
                }
            };
            if p.depth == 0 {
                first_object = hit.map(|h| self.scene.written_object(h.object));
            }
            if let Some(lookout) = scratch.lookout.as_mut().filter(|_| L::COHERENCE) {
                lookout.ray(&p.ray, hit.map(|h| h.t), p.kind);
            }
            let mut next = None;
            match hit {
                None => color = color.saturating_add(self.background(p.weight)),
                Some(hit) => {
                    let children = self.shade(&p, hit, &mut color, scratch, poll);
                    if M::LISTS && p.depth == 0 {
                        primary_t = hit.t;
                        mirrored =
                            mirror.plane().zip(children[1]).is_some_and(|(plane, r)| plane.mirrors(&p.ray, &r.ray));
                    }
                    for &child in children.iter().flatten() {
                        if child.weight.to_bits() <= 0 {
                            continue;
                        }
                        if next.is_none() {
                            next = Some(child);
                        } else if stack.push(child).is_err() {
                            scratch.stats.truncated += 1;
                        }
                    }
                }
            }
            match next.or_else(|| stack.pop()) {
                Some(child) => p = child,
                None => break,
            }
        }
        scratch.stats.cells = scratch.mailbox.cells;
        (color, first_object)
    }

    /// Adds the weighted local colour at `hit` to `color` and returns the
    /// transmitted and reflected rays to trace.
    fn shade<Q: Poll>(
        &self,
        p: &Pending,
        hit: Hit,
        color: &mut Color,
        scratch: &mut Scratch<'_>,
        poll: &mut Q,
    ) -> [Option<Pending>; 2] {
        let shape = self.scene.shape(hit.object);
        let point = p.ray.at(hit.t);
        let geometric = shape.normal_at_among(L::KINDS, point);
        // Two-sided: shade with the normal facing the incoming ray (for a
        // B-spline's triangle, its interpolated normal; shadow rays then
        // leave from the smooth surface, see shapes::SmoothTriangle).
        let flipped = geometric.dot_is_positive(p.ray.dir);
        let facing = if flipped { -geometric } else { geometric };
        let (normal, shadow_from) = shape.shading_among(L::KINDS, point, facing);
        let to_eye = -p.ray.dir;
        let surface = self.scene.surface(shape.surface());
        let mut local = surface.ambient;
        // N·V, made once the first light is found to reach the point.
        let mut normal_to_eye = None;
        for (index, light) in self.scene.lights.iter().enumerate() {
            let to_light = light.position - shadow_from;
            // A light surely behind the surface is skipped before the unit
            // vector is made: its cosine would round to ≤ 0 (see
            // `surely_behind`), so the image cannot change.
            if surely_behind(to_light, normal) {
                continue;
            }
            let Some((light_dir, distance)) = to_light.direction_and_length_estimate() else {
                continue;
            };
            let cos = normal.dot(light_dir);
            if cos.to_bits() <= 0 {
                continue;
            }
            if !poll.go_on() {
                // Nothing more of this sample is traced (see `trace`).
                return [None, None];
            }
            scratch.stats.shadow_rays += 1;
            let shadow = Ray { origin: shadow_from, dir: light_dir };
            // Shading with the facing normal itself (every shape but a
            // B-spline's triangles), the positive cosine already says which
            // side of the geometric normal the light is on: its sign flips
            // with the normal's, exactly.
            let leaving = match (normal == facing, flipped) {
                (true, false) => Leaving::Outward,
                (true, true) => Leaving::Inward,
                (false, _) => leaving_along(geometric, light_dir),
            };
            let start = RayStart { object: hit.object, leaving };
            let t_max = Scalar::from_bits((distance.to_bits() - 1).max(0));
            if let Some(lookout) = scratch.lookout.as_mut().filter(|_| L::COHERENCE) {
                lookout.shadow(shadow_from, light.position);
            }
            if self.occluded(
                &shadow,
                t_max,
                index,
                start,
                &mut scratch.blockers[index % BLOCKER_SLOTS],
                &mut scratch.mailbox,
            ) {
                continue;
            }
            let attenuation = self.attenuation(light.brightness.to_bits(), distance);
            // R·V with R = 2(N·L)N − L the mirror image of L: 2(N·L)(N·V) −
            // L·V, without making R (Q4.60 until the one rounding).
            let nv = *normal_to_eye.get_or_insert_with(|| normal.dot(to_eye).to_bits());
            let rv = ((mul_wide(cos.to_bits(), nv) << 1) - light_dir.dot_q60(to_eye)) >> 30;
            let spec = pow_unit(rv.clamp(0, UNIT_ONE) as i32, surface.exponent.to_bits() << 16);
            let term =
                surface.diffuse.scale_unit(cos).saturating_add(surface.specular.scale_unit(Unit::from_bits(spec)));
            local = local.saturating_add(term.scale(attenuation));
        }
        let t = surface.transparency;
        let r = surface.reflectivity;
        *color = color.saturating_add(local.scale(mul(p.weight, Scalar::ONE - t)));
        if p.depth >= self.scene.settings.rdepth {
            return [None, None];
        }
        // The direction is made only for a ray that will be traced.
        let child = |dir: &dyn Fn() -> Dir, k: Scalar, kind: RayKind| {
            (k.to_bits() > 0).then(|| {
                let dir = dir();
                Pending {
                    ray: Ray { origin: point, dir },
                    start: Some(RayStart { object: hit.object, leaving: leaving_along(geometric, dir) }),
                    depth: p.depth + 1,
                    weight: mul(p.weight, k),
                    kind,
                }
            })
        };
        [child(&|| p.ray.dir, t, RayKind::Transmitted), child(&|| to_eye.reflect_about(normal), r, RayKind::Reflected)]
    }

    /// Whether anything blocks `shadow` to light `light` before `t_max`,
    /// trying `blocker` (the object that blocked the last shadow ray to this
    /// light, if it was blocked) first, and remembering the next.
    #[inline]
    fn occluded(
        &self,
        shadow: &Ray,
        t_max: Scalar,
        light: usize,
        start: RayStart,
        blocker: &mut u32,
        mailbox: &mut Mailbox<'_>,
    ) -> bool {
        if uses_mailbox::<L>() {
            mailbox.clear();
        }
        // A build of cones alone (few objects, see `Linked::LIGHT_CUBES`)
        // finds the blocker behind a few cheap rejections: no remembered
        // one is tried first.
        if <L as ShadowLinks>::CUBES && (*blocker as usize) < self.scene.object_count() {
            let object = ObjectId(*blocker);
            let leaving = RayStart::leaving(Some(start), object);
            if self.scene.shape(object).intersect_among(L::KINDS, shadow, t_max, leaving).is_some() {
                return true;
            }
            // Missed: the walk need not test it again.
            if uses_mailbox::<L>() {
                mailbox.first_visit(*blocker);
            }
        }
        mailbox.blocker = u32::MAX;
        let blocked = self.accel.occluded_toward(&self.scene, shadow, t_max, light, Some(start), mailbox);
        // Forget a blocker that missed once the light is seen: in the open
        // it would cost every shadow ray an extra test.
        *blocker = mailbox.blocker;
        blocked
    }

    /// B / (d + d0) with d in world units, Q16.16, saturating.
    fn attenuation(&self, brightness_q32: i64, distance: Scalar) -> Scalar {
        let norm = &self.scene.normalization;
        let d = norm.world_distance_q32(distance.to_bits() as i64) as u64;
        let d0 = self.scene.settings.attenuation.to_bits() as u64;
        Scalar::from_bits(ratio_q16(brightness_q32 as u64, d.saturating_add(d0)))
    }
}

/// Product of two Q16.16 weights in [0, 1].
#[inline]
fn mul(a: Scalar, b: Scalar) -> Scalar {
    Scalar::from_bits((mul_wide(a.to_bits(), b.to_bits()) >> 16) as i32)
}

#[cfg(test)]
mod tests {
    extern crate std;
    use super::*;

    #[test]
    fn a_light_surely_behind_has_a_cosine_of_at_most_zero() {
        // Vectors of every scale nearly in the plane of random normals: when
        // the pre-test says "behind", the rounded cosine is ≤ 0.
        let mut next = crate::test_rng::seeded(0x0c05_1e55_u64);
        let (mut behind, mut near) = (0, 0);
        for i in 0..300_000 {
            let Some(normal) = Dir::normalize([0; 3].map(|_| next() as i32 as i64)) else { continue };
            let scale = 2 + next() % 29;
            let v = Vec3::from_bits([0; 3].map(|_| (next() as i32) >> scale));
            // Push v towards the plane: subtract most of its normal part.
            let along = v.dot_dir(normal).to_bits();
            let keep = (next() % 3) as i32;
            let v = v - normal.scale(Scalar::from_bits(along - (along >> 8) * keep));
            if surely_behind(v, normal) {
                behind += 1;
                near += (v.dot_dir_q46(normal) > -(1 << 40)) as u32;
                for d in [v.direction(), v.direction_and_length_estimate().map(|(d, _)| d)].into_iter().flatten() {
                    assert!(normal.dot(d).to_bits() <= 0, "case {i}: {v:?} {normal:?}");
                }
            }
        }
        assert!(behind > 40_000 && near > 1_000, "{behind} behind, {near} near the plane");
    }

    #[test]
    fn ratio_is_within_its_bound_and_saturates() {
        let one = 1u64 << 32;
        assert_eq!(ratio_q16(one, 2 * one), 1 << 15);
        assert_eq!(ratio_q16(3 * one, 4 * one), 3 << 14);
        assert_eq!(ratio_q16(1_000_000 * one, one / 1000), i32::MAX);
        assert_eq!(ratio_q16(one, 0), i32::MAX);
        assert_eq!(ratio_q16(0, one), 0);
        assert_eq!(ratio_q16(1, u64::MAX), 0);
        let mut next = crate::test_rng::seeded(0xa77e_0a7e_u64);
        for _ in 0..200_000 {
            let (num, den) = (next() >> (next() % 64), (next() >> (next() % 64)).max(1));
            let exact = ((num as u128) << 16) / den as u128;
            let got = ratio_q16(num, den) as u128;
            if exact >= i32::MAX as u128 {
                assert!(got + 1 >= exact.min(i32::MAX as u128), "{num} / {den}: {got}, not saturated");
            } else {
                assert!(got.abs_diff(exact) <= 1 + (exact >> 17), "{num} / {den}: {got} for {exact}");
            }
        }
    }
}

#[cfg(test)]
mod shading_tests {
    extern crate std;
    use super::*;
    use crate::accel::LightBuffer;
    use crate::parse::parse;
    use crate::profile::Board64K;
    use crate::scene::Scene;
    use std::boxed::Box;
    use std::format;

    /// The colour seen from the eye (0, 0, 10) straight down −z.
    fn look(text: &str) -> (Color, Option<ObjectId>, Stats) {
        let mut scene: Box<Scene<Board64K>> = Box::default();
        parse(text, &mut scene, &mut |e| panic!("{e}")).unwrap();
        let view = scene.view();
        let eye = view.normalization.point(view.settings.view.eye);
        let accel = SceneAccelerator::<Board64K>::new(None, LightBuffer::NONE);
        let tracer = Tracer::new(view, &accel);
        let mut scratch = Scratch::new(Mailbox::none());
        let (c, o) = traced(&tracer, Ray { origin: eye, dir: -Dir::Z }, &mut scratch);
        (c, o, scratch.stats)
    }

    /// What `tracer` sees along `ray`.
    fn traced(tracer: &Tracer<'_, Board64K>, ray: Ray, scratch: &mut Scratch<'_>) -> (Color, Option<ObjectId>) {
        tracer.trace(ray, None, scratch, &mut Unpolled, &mut NoMirror)
    }

    fn approx(c: Color, rgb: [i32; 3]) {
        for (got, w) in c.bits().iter().zip(rgb) {
            assert!((got - w).abs() <= 24, "{:?} vs {rgb:?}", c.bits());
        }
    }

    /// Q16.16 of a decimal given in thousandths.
    fn m(thousandths: i64) -> i32 {
        ((thousandths << 16) / 1000) as i32
    }

    const SPHERE: &str = "SPHERE 1 1 0 0 0\n";

    fn surface(amb: &str, dif: &str, spec: &str, k: &str, r: &str, t: &str) -> std::string::String {
        format!("SURFACE 1 {amb} {amb} {amb} {dif} {dif} {dif} {spec} {spec} {spec} {k} {r} {t}\n")
    }

    #[test]
    fn ambient_diffuse_and_specular_add_up() {
        // Light at the eye, 9 units from the hit point: B/(d + d0) = 10/10.
        let text = format!("{SPHERE}LIGHT 10 0 0 10\n{}", surface("0.1", "0.5", "0.25", "10", "0", "0"));
        let (c, o, stats) = look(&text);
        approx(c, [m(850); 3]);
        assert_eq!(o, Some(ObjectId(0)));
        assert_eq!((stats.rays, stats.shadow_rays), (1, 1));
    }

    #[test]
    fn attenuation_uses_world_distance_and_d0() {
        // d = 9, d0 = 3: factor 10 / 12; diffuse only.
        let text = format!("{SPHERE}ATTENUATION 3 LIGHT 10 0 0 10\n{}", surface("0", "0.6", "0", "0", "0", "0"));
        approx(look(&text).0, [m(500); 3]);
        // The same scene 1000 times larger, with d0 scaled too: same colour.
        let big = format!(
            "VIEWPOINT 0 0 10000 SPHERE 1 1000 0 0 0 ATTENUATION 3000 LIGHT 10000 0 0 10000\n{}",
            surface("0", "0.6", "0", "0", "0", "0")
        );
        approx(look(&big).0, [m(500); 3]);
    }

    #[test]
    fn specular_exponent_zero_is_constant() {
        // Light off to the side: R·V < 1, but k = 0 makes the term constant.
        let text = format!("{SPHERE}LIGHT 9 7 0 8\n{}", surface("0", "0", "0.5", "0", "0", "0"));
        let (c, _, _) = look(&text);
        // d = |(7, 0, 7)| = 9.8995 from P = (0, 0, 1): 9 / 10.8995 · 0.5.
        approx(c, [m(413); 3]);
    }

    #[test]
    fn a_remembered_blocker_never_shadows_a_lit_point() {
        // A blocker between the light and the pole of the sphere: the ray to
        // the pole is in shadow, the ray beside it is lit. Tracing the lit
        // ray after the shadowed one (the blocker remembered) must give the
        // same colour as tracing it alone.
        let text = format!(
            "{SPHERE}SPHERE 2 0.2 0 0 5\nLIGHT 10 0 0 10\n{}SURFACE 2 0 0 0 0 0 0 0 0 0 0 0 0\n",
            surface("0.1", "0.5", "0", "0", "0", "0")
        );
        let mut scene: Box<Scene<Board64K>> = Box::default();
        parse(&text, &mut scene, &mut |e| panic!("{e}")).unwrap();
        let view = scene.view();
        let ray = |x: i64| Ray { origin: view.normalization.point([x, 0, 3 << 32]), dir: -Dir::Z };
        let accel = SceneAccelerator::<Board64K>::new(None, LightBuffer::NONE);
        let tracer = Tracer::new(view, &accel);
        let mut alone = Scratch::new(Mailbox::none());
        let lit = traced(&tracer, ray(1 << 31), &mut alone).0;
        let mut shared = Scratch::new(Mailbox::none());
        let shadowed = traced(&tracer, ray(0), &mut shared).0;
        approx(shadowed, [m(100); 3]); // the pole is in shadow: ambient only
        assert_eq!(traced(&tracer, ray(1 << 31), &mut shared).0, lit);
        assert_ne!(lit, shadowed);
    }

    #[test]
    fn light_behind_the_surface_gives_ambient_only() {
        let text = format!("{SPHERE}LIGHT 10 0 0 -10\n{}", surface("0.2", "0.5", "0.5", "10", "0", "0"));
        let (c, _, stats) = look(&text);
        assert_eq!(c.bits(), [m(200); 3]);
        assert_eq!(stats.shadow_rays, 0);
    }

    #[test]
    fn any_object_casts_a_shadow_even_a_transparent_one() {
        let text = format!(
            "{SPHERE}SPHERE 2 0.5 0 0 5\nLIGHT 10 0 0 10\n{}SURFACE 2 0 0 0 0 0 0 0 0 0 0 0 1",
            surface("0.2", "0.5", "0", "0", "0", "0")
        );
        // The small sphere is between the eye and the big one, so look past
        // it: a ray from the side, hitting the big sphere at (1, 0, 0)… use
        // the eye ray but with the small sphere fully transparent.
        let (c, o, _) = look(&text);
        assert_eq!(o, Some(ObjectId(1)));
        // Seen through the transparent sphere: the big sphere in its shadow.
        approx(c, [m(200); 3]);
    }

    #[test]
    fn reflection_adds_r_times_what_the_mirror_sees() {
        let text = format!("{SPHERE}BACKGROUND 0.5 0.5 0.5\n{}", surface("0.1", "0", "0", "0", "0.4", "0"));
        // The mirror direction at the pole is straight back to the eye:
        // background. C = 0.1 + 0.4 · 0.5.
        let (c, _, stats) = look(&text);
        approx(c, [m(300); 3]);
        assert_eq!(stats.rays, 2);
    }

    #[test]
    fn transparency_mixes_local_and_behind() {
        // t = 0.5: C = 0.5 · 0.2 + 0.5 · background (the ray passes the
        // sphere: its far side, then nothing). The far side's own colour
        // counts too (it is the same transparent surface).
        let text = format!("{SPHERE}BACKGROUND 1 1 1 RDEPTH 1\n{}", surface("0.2", "0", "0", "0", "0", "0.5"));
        // Depth 1: the far side is reached but not passed: 0.5·0.2 + 0.5·(0.5·0.2).
        approx(look(&text).0, [m(150); 3]);
        let text = format!("{SPHERE}BACKGROUND 1 1 1 RDEPTH 2\n{}", surface("0.2", "0", "0", "0", "0", "0.5"));
        // Depth 2: … + 0.25 · background.
        approx(look(&text).0, [m(400); 3]);
    }

    #[test]
    fn rdepth_zero_traces_primary_rays_only() {
        let text = format!("{SPHERE}BACKGROUND 1 1 1 RDEPTH 0\n{}", surface("0.2", "0", "0", "0", "1", "1"));
        let (c, _, stats) = look(&text);
        assert_eq!(c.bits(), [0; 3]); // (1 − t) · local = 0
        assert_eq!(stats.rays, 1);
    }

    #[test]
    fn two_facing_mirrors_are_bounded() {
        // Perfect mirrors facing each other with the eye between them: the
        // ray bounces RDEPTH times at most, then the per-sample limit.
        let text = "VIEWPOINT 0 0 0 ORIGIN 0 0 -1 RDEPTH 100000 \
                    RECTANGLE 1 -5 -5 -3  5 -5 -3  5 5 -3  -5 5 -3 \
                    RECTANGLE 1 -5 -5 3  -5 5 3  5 5 3  5 -5 3 \
                    SURFACE 1 0.01 0.01 0.01 0 0 0 0 0 0 0 1 0";
        let (c, _, stats) = look(text);
        assert_eq!(stats.rays, MAX_RAYS_PER_SAMPLE as u64);
        assert_eq!(stats.truncated, 1);
        // Each ray traced adds the ambient 0.01 (655 in Q16.16) at full
        // weight: a perfect mirror passes all of its weight on.
        assert_eq!(c.bits(), [655 * MAX_RAYS_PER_SAMPLE as i32; 3]);
    }

    #[test]
    fn the_back_of_a_triangle_is_lit_from_behind() {
        // Clockwise seen from the eye: its front faces −z, the eye sees its
        // back, lit from the eye's side at d = 10: 10/11 · 0.5.
        let text =
            format!("TRIANGLE 1 -2 -2 0  0 2 0  2 -2 0\nLIGHT 10 0 0 10\n{}", surface("0", "0.5", "0", "0", "0", "0"));
        approx(look(&text).0, [(5 << 16) / 11; 3]);
    }
}
