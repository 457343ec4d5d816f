//! The light buffer of a scene of few objects: for each light, a cone
//! around each object as the light sees it, which a shadow ray's direction
//! is tested against in three 16-bit products before the object's own test.
//!
//! A build whose profile holds [`AccelMode::AUTO_NAIVE_UP_TO`] objects or
//! fewer (scenes the `Auto` mode tests one by one) links this form alone
//! ([`Linked::LIGHT_CONES`](crate::profile::Linked::LIGHT_CONES)), and
//! [`LightBuffer::build`] gives it to such a scene: on a Cortex-M0 a cube's
//! look-up (the face, the cell, the list) costs what testing every object
//! does, where a cone's test costs a quarter of a sphere's quickest
//! rejection. Such a build tests every shadow ray in the cone loop, every
//! object for a light without cones.
//!
//! *Cones.* For light `L` and object `k`: the ball of centre `C` and radius
//! `R` (rounded up) that holds the object widened by [`MARGIN`] (a
//! sphere's own, else its bounds': their centre rounded down), at
//! `D = |C − L|` from the light. Every direction from `L` to a point of
//! the ball makes with `C − L` an angle whose cosine is at least
//! `√(1 − x)` for any `x ≥ (R/D)²`, and so at least `1 − x/2 − x²/2`.
//! Stored: the axis `(C − L)/D` (as the tracer normalises it) in Q2.14,
//! each component rounded to nearest, and the threshold, that lower bound
//! (from `R` rounded up, `D` down, every term against it) less [`SLACK`],
//! in Q2.14 rounded down (compared in Q4.28); a light in the ball or within
//! [`NEAR`] of it gets [`ALWAYS`], which every ray passes. Made in 32-bit
//! steps, the unit vector and the length by the tracer's own
//! normalisation.
//!
//! *Exactness.* An object that blocks a shadow ray from `O` has a point `S`
//! of the segment `[L, O]` within [`MARGIN`] of it (the cube's argument, in
//! the module above: its hit point strays from it by less than the filing
//! margin), so in the ball, and `S ≠ L` (the light is outside the
//! ball): `(O − L)/|O − L|` points from the light into the ball. The ray's
//! direction `d` (from `O` to the light, as the tracer aims it) is the
//! opposite within 6 units of 2^-30 a component, and `−d`'s components
//! shifted down to Q2.14 are within 1.001 units of 2^-14 of their ideal
//! values; the axis's, within 0.51 (a unit vector's components are within
//! 3 units of 2^-30 of the exact ones). The product of the two is then
//! within `2^14·√3·(0.51 + 1.001) + 3·0.51·1.001 < 2^16` units of 2^-28
//! of the cosine of the ray's angle with the axis, and [`SLACK`] is twice
//! that: a ray that can meet the object passes its test.
//!
//! Invariants: a cone is two words of `i16`s (`x | y << 16` of the axis,
//! `z | threshold << 16`): two a cone, so that the tracer finds a light's
//! cones by a shift; the cones of a light are its objects', in order, and
//! the lights' follow each other.

use super::query::ShadowQuery;
use super::{LightBuffer, LightBufferError, LightBufferReport, ShadowLinks, Words, MARGIN};
use crate::accel::{naive, Mailbox, RayStart};
use crate::capacity::Arena;
use crate::math::{leading_zeros_u32, Dir};
use crate::scene::{ObjectId, SceneView};
use crate::shapes::{Aabb, Leaving, ShapeHandle, ShapeRef};
use crate::AccelMode;

/// Twice what the 16-bit products may lose, in units of 2^-28 (see the
/// module's exactness).
const SLACK: i64 = 1 << 17;
/// A ball nearer the light than this (Q16.16 raw units, 1/8192 of the
/// scene's span) is always tested: the axis's rounding bound needs `D` of
/// at least 2^16.
const NEAR: i64 = 1 << 16;
/// Every ray passes a cone with this threshold: −2 in Q4.28, below any
/// product of two near-unit vectors.
const ALWAYS: i16 = i16::MIN;

/// The words of a cone: `[x | y << 16, z | threshold << 16]`.
pub(super) const CONE: usize = 2;

impl Words {
    /// "LBC" and the layout's version: a light buffer of cones.
    pub(super) const CONES_MAGIC: u32 = 0x4C42_4301;
    /// The magic, the lights, the objects.
    pub(super) const CONES_HEADER: usize = 3;

    /// Words of the cones of `lights` lights over `objects` objects.
    pub(super) const fn of_cones(lights: usize, objects: usize) -> usize {
        Words::CONES_HEADER + CONE * lights * objects
    }
}

/// The ball (centre and radius, Q16.16 bits) that holds `shape` widened by
/// [`MARGIN`]: a sphere's own, else its bounds'. In 32 bits: the scene
/// spans ±2^29 raw units.
#[inline(never)]
fn ball(shape: ShapeRef<'_>) -> Option<([i32; 3], u32)> {
    const WIDENED: i32 = MARGIN as i32 + 1;
    if let ShapeRef::Sphere(sphere) = shape {
        return Some((sphere.center.bits(), sphere.radius.to_bits().unsigned_abs().saturating_add(WIDENED as u32)));
    }
    let Aabb { min, max } = shape.bounds();
    let (min, max) = (min.bits(), max.bits());
    // Half the side, rounded up, widened, and a unit more for the centre's
    // rounding down: every point of the widened box is within this of the
    // centre on each axis.
    let side = [0, 1, 2].map(|a| max[a] - min[a]);
    let center = [0, 1, 2].map(|a| min[a] + side[a] / 2);
    let (_, _, above) = direction_and_length(side.map(|s| s / 2 + 1 + WIDENED))?;
    Some((center, above))
}

/// The unit vector along `v` (Q16.16 bits, components below 2^30 in
/// magnitude: differences of the scene's points) and its length's bounds
/// `[below, above]`, from the tracer's normalisation (the floor of the
/// length scaled up by 2^-shift; `None` beyond that range).
fn direction_and_length(v: [i32; 3]) -> Option<(Dir, u32, u32)> {
    let (unit, length, shift) = Dir::normalize_with_length(v.map(i64::from))?;
    // Scaled up by at most 2^29 (a component of 1), down by none: exact.
    let down = u32::try_from(-shift).ok()?;
    let length = length as u32;
    Some((unit, length >> down, ((length + 1) >> down) + 1))
}

/// The cone of the object behind `handle` seen from the light at `light`
/// (Q16.16 bits).
#[inline(never)]
fn cone(scene: &SceneView<'_>, handle: ShapeHandle, light: [i32; 3]) -> [u32; CONE] {
    const ALWAYS_TESTED: [u32; CONE] = [0, (ALWAYS as u16 as u32) << 16];
    // The shape from its handle here, not in the caller's loop: a board's
    // load then calls the scene's one copy of that dispatch.
    let Some((center, radius)) = ball(scene.shape_of(handle)) else { return ALWAYS_TESTED };
    let axis = [0, 1, 2].map(|a| center[a] - light[a]);
    let Some((unit, distance, _)) = direction_and_length(axis) else { return ALWAYS_TESTED };
    if distance <= radius.saturating_add(NEAR as u32) {
        return ALWAYS_TESTED;
    }
    // R/D from above in Q14, both scaled down to D below 2^17 (R rounded
    // up, D down; R < D − 2^16, so their ratio stays below one); then
    // x ≥ (R/D)² in Q28, and √(1 − x) ≥ 1 − x/2 − x²/2 on [0, 1], each
    // term rounded against it: below the cosine, in 32-bit steps.
    let k = 15u32.saturating_sub(leading_zeros_u32(distance));
    let (r, d) = (((radius - 1) >> k) + 1, distance >> k);
    let ratio = (r << 14).div_ceil(d);
    let x = ratio * ratio;
    let high = (x >> 14) + 1;
    let cosine = (1 << 28) - x.div_ceil(2) as i32 - (high * high).div_ceil(2) as i32;
    // In units of 2^-14, rounded down: within [−16, 2^14].
    let threshold = ((cosine - SLACK as i32) >> 14) as i16;
    // The axis's components rounded to nearest: within [−2^14, 2^14].
    let [x, y, z] = unit.bits().map(|c| ((c as i64 + (1 << 15)) >> 16) as i16);
    [x as u16 as u32 | (y as u16 as u32) << 16, z as u16 as u32 | (threshold as u16 as u32) << 16]
}

impl<'a> LightBuffer<'a> {
    /// The cones of the first `lights` of `scene`'s lights that fit
    /// `words` (none if not even one light's do).
    pub(super) fn build_cones<W: Arena<u32>>(
        scene: &SceneView<'_>,
        words: &'a mut W,
        lights: usize,
    ) -> LightBuffer<'a> {
        let objects = scene.object_count();
        let room = W::CAPACITY.saturating_sub(Words::CONES_HEADER) / (CONE * objects).max(1);
        let lights = scene.lights.len().min(lights).min(room);
        if lights == 0 {
            return LightBuffer::NONE;
        }
        for word in [Words::CONES_MAGIC, lights as u32, objects as u32] {
            let _ = words.push(word);
        }
        for light in scene.lights.iter().take(lights) {
            for &handle in scene.objects {
                for word in cone(scene, handle, light.position.bits()) {
                    let _ = words.push(word);
                }
            }
        }
        Self::parse_cones(words.as_slice()).unwrap_or(LightBuffer::NONE)
    }

    /// The cones in `words` if their header and size are sound.
    pub(super) fn parse_cones(words: &'a [u32]) -> Option<LightBuffer<'a>> {
        let &[magic, lights, objects] = words.get(..Words::CONES_HEADER)? else { return None };
        let (lights, objects) = (lights as usize, objects as usize);
        // Cones serve at most `AUTO_NAIVE_UP_TO` objects: the size fits.
        let sound =
            magic == Words::CONES_MAGIC && lights <= u16::MAX as usize && objects <= AccelMode::AUTO_NAIVE_UP_TO;
        let header = Words::CONES_HEADER;
        (sound && words.len() == Words::of_cones(lights, objects)).then_some(LightBuffer {
            words,
            lights,
            level: 0,
            cells: header,
            entries: header,
            cones: true,
        })
    }

    /// Prebuilt cones, if they are `scene`'s: every cone the one a build
    /// for it makes.
    pub(super) fn verified_cones(&self, scene: &SceneView<'_>) -> Result<(), LightBufferError> {
        if self.lights > scene.lights.len() || self.words[2] as usize != scene.object_count() {
            return Err(LightBufferError::OtherScene);
        }
        for (light, l) in scene.lights[..self.lights].iter().enumerate() {
            for id in scene.object_ids() {
                if self.cone_of(light, id) != Some(&cone(scene, scene.objects[id.0 as usize], l.position.bits())[..]) {
                    return Err(LightBufferError::Incomplete { light, object: id });
                }
            }
        }
        Ok(())
    }

    /// [`LightBuffer::report`] of cones.
    pub(super) fn cones_report(&self) -> LightBufferReport {
        let entries = (self.words.len() - Words::CONES_HEADER) / CONE;
        LightBufferReport { lights: self.lights, entries, words: self.words.len(), cones: true, ..Default::default() }
    }

    /// The words of light `light`'s cone around object `id`.
    fn cone_of(&self, light: usize, id: ObjectId) -> Option<&'a [u32]> {
        let cones = self.light_cones(light)?;
        cones.get(CONE * id.0 as usize..CONE * (id.0 as usize + 1))
    }

    /// The cones of light `light`, if it has them.
    pub(super) fn light_cones(&self, light: usize) -> Option<&'a [u32]> {
        if !self.cones || light >= self.lights {
            return None;
        }
        let objects = self.words[2] as usize;
        let first = Words::CONES_HEADER + CONE * light * objects;
        self.words.get(first..first + CONE * objects)
    }

    /// Whether anything blocks the shadow ray `query` asks of, testing only
    /// the objects whose cone its direction is in (every object when its
    /// light has no cones); the blocker is left in the mailbox.
    #[inline(never)]
    pub(super) fn occluded_in_cones<S: ShadowLinks>(
        &self,
        query: &ShadowQuery<'_, '_>,
        mailbox: &mut Mailbox<'_>,
    ) -> bool {
        let ShadowQuery { scene, ray, t_max, light, start } = *query;
        let Some(cones) = self.light_cones(light).filter(|cones| cones.len() == CONE * scene.object_count()) else {
            return naive::occluded(S::KINDS, scene, ray, t_max, start, mailbox);
        };
        // From the light towards the ray's origin, in Q2.14: within
        // [−2^14, 2^14 + 1].
        let toward = ray.dir.bits().map(|c| -(c >> 16));
        // The cones alone in the loop: an object is looked up only once its
        // cone holds the ray. The first blocker in file order, as the naive
        // walk finds it (an object outside its cone blocks nothing).
        let in_cone = cones.chunks_exact(CONE).enumerate().filter(|(_, cone)| passes(cone, toward));
        let blocker = in_cone.map(|(object, _)| object).find(|&object| {
            let leaving = RayStart::leaving(start, ObjectId(object as u32));
            // A ray leaving an object outward never meets it again.
            leaving != Leaving::Outward
                && scene
                    .objects
                    .get(object)
                    .is_some_and(|&handle| scene.intersect_handle(S::KINDS, handle, ray, t_max, leaving).is_some())
        });
        blocker.inspect(|&object| mailbox.blocker = object as u32).is_some()
    }
}

/// Whether the direction `toward` (from the light, Q2.14, each component
/// within [−2^14, 2^14 + 1]) is in the cone `cone`.
#[inline(always)]
pub(super) fn passes(cone: &[u32], toward: [i32; 3]) -> bool {
    let axis = [cone[0] as i16, (cone[0] >> 16) as i16, cone[1] as i16].map(i32::from);
    let threshold = ((cone[1] >> 16) as i16 as i32) << 14;
    // Each product within ±(2^28 + 2^14): their sum fits.
    toward[0] * axis[0] + toward[1] * axis[1] + toward[2] * axis[2] >= threshold
}

#[cfg(test)]
mod tests {
    extern crate std;
    use super::*;
    use crate::parse::parse;
    use crate::profile::Board64K;
    use crate::scene::Scene;
    use std::{boxed::Box, format, string::String, vec::Vec};

    fn scene(text: &str) -> Box<Scene<Board64K>> {
        let mut scene: Box<Scene<Board64K>> = Box::default();
        parse(text, &mut scene, &mut |e| panic!("{e}\n{text}")).unwrap();
        scene
    }

    fn spheres(count: usize) -> String {
        let spheres: String = (0..count).map(|k| format!("SPHERE 1 0.3 {} 0 0\n", k)).collect();
        format!("VIEWPOINT 0 5 20\nLIGHT 10 0 9 0\nLIGHT 5 -9 9 3\nSURFACE 1 .1 .1 .1 .8 .2 .2 0 0 0 1 0 0\n{spheres}")
    }

    /// As many objects as the `Auto` mode tests one by one get cones; one
    /// more, a cube.
    #[test]
    fn few_objects_get_cones_and_more_a_cube() {
        let mut words = heapless::Vec::<u32, 4000>::new();
        let few = scene(&spheres(crate::AccelMode::AUTO_NAIVE_UP_TO));
        let report = LightBuffer::build(&few.view(), &mut words, 16).report();
        assert!(report.cones && report.cells_a_side == 0 && report.lights == 2, "{report:?}");
        assert_eq!(report.words, Words::of_cones(2, crate::AccelMode::AUTO_NAIVE_UP_TO));
        let more = scene(&spheres(crate::AccelMode::AUTO_NAIVE_UP_TO + 1));
        let report = LightBuffer::build(&more.view(), &mut words, 16).report();
        assert!(!report.cones && report.cells_a_side == 16, "{report:?}");
        // Room for one light's cones: the first light's.
        let mut one = heapless::Vec::<u32, { Words::of_cones(1, 16) }>::new();
        assert_eq!(LightBuffer::build(&few.view(), &mut one, 16).report().lights, 1);
    }

    /// A light within an object's widened bounds tests it whatever the
    /// direction; one far from a small sphere passes only the directions
    /// near it.
    #[test]
    fn a_cone_holds_its_object_and_little_else() {
        let view = scene("LIGHT 10 0 0 0\nSURFACE 1 .1 .1 .1 .8 .2 .2 0 0 0 1 0 0\nBOX 1 0 0 0 1 1 1\nSPHERE 1 0.5 10 0 0\nVIEWPOINT 0 0 30\n");
        let view = view.view();
        let mut words = heapless::Vec::<u32, 64>::new();
        let buffer = LightBuffer::build(&view, &mut words, 1);
        let cones = buffer.light_cones(0).unwrap();
        assert_eq!(cones[1] >> 16, ALWAYS as u16 as u32, "the light in the box");
        let sphere = &cones[CONE..];
        let toward = |x: f64, y: f64| {
            let length = (x * x + y * y).sqrt();
            [(x / length * 16384.0) as i32, (y / length * 16384.0) as i32, 0]
        };
        // The sphere spans asin(0.5 / 10), 2.9 degrees, from the light;
        // the slack takes the cone to 3.4.
        for (x, y, inside) in [
            (1.0, 0.0, true),
            (10.0, 0.49, true),
            (10.0, -0.49, true),
            (10.0, 0.65, false),
            (0.0, 1.0, false),
            (-1.0, 0.0, false),
        ] {
            assert_eq!(passes(sphere, toward(x, y)), inside, "towards ({x}, {y})");
        }
    }

    /// Cones kept elsewhere are taken only for their scene: any word
    /// changed, the size or another scene is refused.
    #[test]
    fn prebuilt_cones_are_checked() {
        let text = spheres(4);
        let view = scene(&text);
        let view = view.view();
        let mut arena = heapless::Vec::<u32, 100>::new();
        let words: Vec<u32> = LightBuffer::build(&view, &mut arena, 16).words().to_vec();
        assert!(LightBuffer::verified(&view, &words).is_ok_and(|b| b.report().cones));
        for k in 1..words.len() {
            let mut changed = words.clone();
            changed[k] ^= 1 << 3;
            assert!(LightBuffer::verified(&view, &changed).is_err(), "word {k} changed");
        }
        let mut short = words.clone();
        short.pop();
        assert_eq!(LightBuffer::verified(&view, &short).map(|_| ()), Err(LightBufferError::Malformed));
        let moved = scene(&text.replace("SPHERE 1 0.3 2 0 0", "SPHERE 1 0.3 2 1 0"));
        let refused = LightBuffer::verified(&moved.view(), &words).map(|_| ());
        assert!(matches!(refused, Err(LightBufferError::Incomplete { object: ObjectId(2), .. })), "{refused:?}");
    }
}
