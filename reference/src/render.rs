//! Camera rays, shading, shadows, reflection and transparency, and gamma, as the format documents them.

use crate::bspline::barycentric;
use crate::intersect::Roots;
use crate::vector::{rgb_add, rgb_scale, Rgb, V3};
use crate::{Object, RefScene, Shape};

/// Where a secondary ray starts: on object `object`, whose geometric normal
/// there is `normal`.
#[derive(Clone, Copy)]
struct Start {
    object: usize,
    normal: V3,
}

impl RefScene {
    /// The RASTER size (width, height).
    pub fn raster(&self) -> (u32, u32) {
        self.raster
    }

    /// The viewport (width, height) for an image of the given size.
    fn viewport_for(&self, width: u32, height: u32) -> (f64, f64) {
        self.viewport.unwrap_or_else(|| {
            let d = (self.origin - self.viewpoint).length();
            let vw = 2.0 * d * 30f64.to_radians().tan();
            (vw, vw * f64::from(height) / f64::from(width))
        })
    }

    /// The primary ray direction (unit) for a sample.
    pub(crate) fn primary_direction(&self, width: u32, height: u32, x: u32, y: u32, sx: u32, sy: u32) -> V3 {
        let n = f64::from(self.samples);
        let (vw, vh) = self.viewport_for(width, height);
        let f = (self.origin - self.viewpoint).normalised();
        let r = f.cross(self.upvector).normalised();
        let u = r.cross(f);
        let a = (f64::from(x) + (f64::from(sx) + 0.5) / n) / f64::from(width) - 0.5;
        let b = 0.5 - (f64::from(y) + (f64::from(sy) + 0.5) / n) / f64::from(height);
        let target = self.origin + r * (a * vw) + u * (b * vh);
        (target - self.viewpoint).normalised()
    }

    /// Unclamped linear colour of one primary ray sample for pixel (x,y),
    /// sub-cell (sx,sy) (for debugging).
    pub fn sample(&self, width: u32, height: u32, x: u32, y: u32, sx: u32, sy: u32) -> [f64; 3] {
        let d = self.primary_direction(width, height, x, y, sx, sy);
        self.trace(self.viewpoint, d, 0, None)
    }

    /// Render at width×height (the RASTER may be overridden; a default
    /// VIEWPORT then follows the new aspect ratio). Row-major, top row first.
    pub fn render(&self, width: u32, height: u32) -> Vec<[u8; 3]> {
        let n = self.samples;
        let mut image = Vec::with_capacity(width as usize * height as usize);
        for y in 0..height {
            for x in 0..width {
                let mut sum = [0.0; 3];
                for sy in 0..n {
                    for sx in 0..n {
                        let c = self.sample(width, height, x, y, sx, sy);
                        sum = rgb_add(sum, c.map(|v| v.clamp(0.0, 1.0)));
                    }
                }
                let mean = rgb_scale(sum, 1.0 / f64::from(n * n));
                image.push(mean.map(|v| to_byte(v, self.gamma)));
            }
        }
        image
    }

    /// The nearest hit (t, object index) along the ray, ignoring what the
    /// start rule excludes; ties go to the earlier object.
    fn nearest(&self, o: V3, d: V3, start: Option<Start>) -> Option<(f64, usize)> {
        let mut best: Option<(f64, usize)> = None;
        for (i, object) in self.objects.iter().enumerate() {
            let Some(roots) = roots_for(object, i, d, start) else {
                continue;
            };
            if let Some(t) = object.hit(o, d, roots) {
                if best.is_none_or(|(bt, _)| t < bt) {
                    best = Some((t, i));
                }
            }
        }
        best
    }

    /// True if any object is hit with 0 < t < max_t.
    fn blocked(&self, o: V3, d: V3, max_t: f64, start: Start) -> bool {
        self.objects.iter().enumerate().any(|(i, object)| {
            roots_for(object, i, d, Some(start)).and_then(|roots| object.hit(o, d, roots)).is_some_and(|t| t < max_t)
        })
    }

    /// The colour seen along the ray o + t·d (d unit length).
    fn trace(&self, o: V3, d: V3, depth: u32, start: Option<Start>) -> Rgb {
        let Some((t, index)) = self.nearest(o, d, start) else {
            return self.background;
        };
        let object = &self.objects[index];
        let surface = &self.surfaces[object.surface];
        let p = o + d * t;
        let ng = object.normal(p);
        let facing = if ng.dot(d) < 0.0 { ng } else { -ng };
        // A B-spline's triangle shades with its blended corner normals and
        // sends shadow rays from the point lifted onto the smooth surface.
        let (n, shadow_from) = match object.shape {
            Shape::SmoothTriangle { p: corners, normals, .. } => {
                let w = barycentric(&corners, p);
                let blend = (0..3).fold(V3::new(0.0, 0.0, 0.0), |acc, i| acc + normals[i] * w[i]);
                let blend = if blend.length() > 0.0 { blend.normalised() } else { ng };
                let n = if facing.dot(ng) < 0.0 { -blend } else { blend };
                let lifted = (0..3).fold(V3::new(0.0, 0.0, 0.0), |acc, i| {
                    acc + (p - normals[i] * (p - corners[i]).dot(normals[i])) * w[i]
                });
                (n, if (lifted - p).dot(facing) > 0.0 { lifted } else { p })
            }
            _ => (facing, p),
        };
        let v = -d;
        let here = Start { object: index, normal: ng };

        let mut local = surface.ambient;
        for light in &self.lights {
            let to_light = light.position - shadow_from;
            let dist = to_light.length();
            if dist == 0.0 {
                continue;
            }
            let lv = to_light * (1.0 / dist);
            let ndl = n.dot(lv);
            if ndl <= 0.0 || self.blocked(shadow_from, lv, dist, here) {
                continue;
            }
            let r = n * (2.0 * ndl) - lv;
            let rv = r.dot(v).max(0.0);
            let spec = if surface.exponent == 0.0 { 1.0 } else { rv.powf(surface.exponent) };
            let scale = light.brightness / (dist + self.attenuation);
            for (c, channel) in local.iter_mut().enumerate() {
                *channel += scale * (surface.diffuse[c] * ndl + surface.specular[c] * spec);
            }
        }

        let mut colour = rgb_scale(local, 1.0 - surface.transparency);
        if depth < self.rdepth {
            if surface.transparency != 0.0 {
                let behind = self.trace(p, d, depth + 1, Some(here));
                colour = rgb_add(colour, rgb_scale(behind, surface.transparency));
            }
            if surface.reflectivity != 0.0 {
                let rd = (n * (2.0 * n.dot(v)) - v).normalised();
                let reflected = self.trace(p, rd, depth + 1, Some(here));
                colour = rgb_add(colour, rgb_scale(reflected, surface.reflectivity));
            }
        }
        colour
    }
}

/// How object `i` may be hit by a ray with direction `d` that leaves `start`:
/// `None` if it cannot be hit at all (flat shape it starts on, or a closed
/// shape it leaves outward), `FarOnly` for a closed shape it enters.
fn roots_for(object: &Object, i: usize, d: V3, start: Option<Start>) -> Option<Roots> {
    match start {
        Some(s) if s.object == i => {
            if object.shape.is_flat() || d.dot(s.normal) >= 0.0 {
                None
            } else {
                Some(Roots::FarOnly)
            }
        }
        _ => Some(Roots::Nearest),
    }
}

/// Gamma-correct a mean (already clamped) channel value and round half up.
fn to_byte(v: f64, gamma: f64) -> u8 {
    let g = v.clamp(0.0, 1.0).powf(1.0 / gamma);
    (255.0 * g + 0.5).floor().clamp(0.0, 255.0) as u8
}
