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

use crate::accel::{Accelerator, Hit, RayStart};
use crate::math::{pow_unit, Dir, Scalar, Unit};
use crate::scene::{Color, ObjectId, SceneView};
use crate::shapes::{Leaving, Ray};

/// Rays traced (not counting shadow rays) for one primary sample at most.
pub const MAX_RAYS_PER_SAMPLE: u32 = 4096;
/// Secondary rays waiting to be traced, at most.
pub const PENDING_RAYS: usize = 24;

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
}

impl Stats {
    pub fn add(&mut self, o: &Stats) {
        self.rays += o.rays;
        self.shadow_rays += o.shadow_rays;
        self.truncated += o.truncated;
    }
}

/// A ray waiting in the tree, with the weight its colour counts with.
#[derive(Clone, Copy)]
struct Pending {
    ray: Ray,
    start: Option<RayStart>,
    depth: u32,
    weight: Scalar,
}

/// Traces rays through a scene with a given accelerator.
#[derive(Clone, Copy)]
pub struct Tracer<'a, A> {
    scene: SceneView<'a>,
    accel: &'a A,
}

/// `num / den` in Q16.16, both Q32.32, saturating.
fn ratio_q16(num: u64, den: u64) -> i32 {
    if den == 0 {
        return i32::MAX;
    }
    let lz = num.leading_zeros();
    let q = if lz >= 16 {
        (num << 16) / den
    } else {
        let d = den >> (16 - lz);
        if d == 0 {
            return i32::MAX;
        }
        (num << lz) / d
    };
    q.min(i32::MAX as u64) as i32
}

/// How a ray leaving a surface along `dir` relates to the shape it leaves:
/// closed shapes are entered when `dir` points against the outward normal.
#[inline]
fn leaving_along(geometric_normal: Dir, dir: Dir) -> Leaving {
    if geometric_normal.dot_q60(dir) < 0 {
        Leaving::Inward
    } else {
        Leaving::Outward
    }
}

impl<'a, A: Accelerator> Tracer<'a, A> {
    pub fn new(scene: SceneView<'a>, accel: &'a A) -> Self {
        Tracer { scene, accel }
    }

    pub fn scene(&self) -> &SceneView<'a> {
        &self.scene
    }

    /// The linear colour seen along a primary ray, and the object it hits.
    pub fn trace(&self, ray: Ray, stats: &mut Stats) -> (Color, Option<ObjectId>) {
        let mut stack: heapless::Vec<Pending, PENDING_RAYS> = heapless::Vec::new();
        let mut color = Color::BLACK;
        let mut first_object = None;
        let mut traced = 0;
        let mut next = Some(Pending {
            ray,
            start: None,
            depth: 0,
            weight: Scalar::ONE,
        });
        while let Some(p) = next.take().or_else(|| stack.pop()) {
            if traced == MAX_RAYS_PER_SAMPLE {
                stats.truncated += 1 + stack.len() as u64;
                break;
            }
            traced += 1;
            stats.rays += 1;
            let hit = self.accel.nearest(&self.scene, &p.ray, p.start);
            if p.depth == 0 {
                first_object = hit.map(|h| h.object);
            }
            let Some(hit) = hit else {
                color = color.saturating_add(self.scene.settings.background.scale(p.weight));
                continue;
            };
            let children = self.shade(&p, hit, &mut color, stats);
            for child in children.into_iter().flatten() {
                if child.weight.to_bits() <= 0 {
                    continue;
                }
                if next.is_none() {
                    next = Some(child);
                } else if stack.push(child).is_err() {
                    stats.truncated += 1;
                }
            }
        }
        (color, first_object)
    }

    /// Adds the weighted local colour at `hit` to `color` and returns the
    /// transmitted and reflected rays to trace.
    fn shade(&self, p: &Pending, hit: Hit, color: &mut Color, stats: &mut Stats) -> [Option<Pending>; 2] {
        let shape = self.scene.shape(hit.object);
        let point = p.ray.at(hit.t);
        let geometric = shape.normal_at(point);
        // Two-sided: shade with the normal facing the incoming ray.
        let normal = if geometric.dot_q60(p.ray.dir) > 0 { -geometric } else { geometric };
        let to_eye = -p.ray.dir;
        let surface = self.scene.surface(shape.surface());
        let mut local = surface.ambient;
        for light in self.scene.lights {
            let to_light = light.position - point;
            let Some(light_dir) = to_light.direction() else { continue };
            let cos = normal.dot(light_dir);
            if cos.to_bits() <= 0 {
                continue;
            }
            let distance = to_light.length();
            stats.shadow_rays += 1;
            let shadow = Ray {
                origin: point,
                dir: light_dir,
            };
            let start = RayStart {
                object: hit.object,
                leaving: leaving_along(geometric, light_dir),
            };
            let t_max = Scalar::from_bits((distance.to_bits() - 1).max(0));
            if self.accel.occluded(&self.scene, &shadow, t_max, Some(start)) {
                continue;
            }
            let attenuation = self.attenuation(light.brightness.to_bits(), distance);
            let mirrored = light_dir.reflect_about(normal);
            let rv = mirrored.dot(to_eye).to_bits().max(0);
            let spec = pow_unit(rv, surface.exponent.to_bits() << 16);
            let term = surface
                .diffuse
                .scale_unit(cos)
                .saturating_add(surface.specular.scale_unit(Unit::from_bits(spec)));
            local = local.saturating_add(term.scale(attenuation));
        }
        let t = surface.transparency;
        let r = surface.reflectivity;
        *color = color.saturating_add(local.scale(mul(p.weight, Scalar::ONE - t)));
        if p.depth >= self.scene.settings.rdepth {
            return [None, None];
        }
        let child = |dir: Dir, k: Scalar| {
            (k.to_bits() > 0).then(|| Pending {
                ray: Ray { origin: point, dir },
                start: Some(RayStart {
                    object: hit.object,
                    leaving: leaving_along(geometric, dir),
                }),
                depth: p.depth + 1,
                weight: mul(p.weight, k),
            })
        };
        [child(p.ray.dir, t), child(to_eye.reflect_about(normal), r)]
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
    Scalar::from_bits(((a.to_bits() as i64 * b.to_bits() as i64) >> 16) as i32)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ratio_saturates_and_is_exact() {
        let one = 1u64 << 32;
        assert_eq!(ratio_q16(one, 2 * one), 1 << 15);
        assert_eq!(ratio_q16(1_000_000 * one, one / 1000), i32::MAX);
        assert_eq!(ratio_q16(one, 0), i32::MAX);
        assert_eq!(ratio_q16(3 * one, 4 * one), 3 << 14);
    }
}
