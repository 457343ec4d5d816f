//! octrace's independent double-precision (f64) reference ray tracer.
//!
//! It is written from the scene-format contract (`docs/scene-format.md`) alone and
//! shares no code with `octrace-core`: the accuracy test renders every scene
//! with both tracers and compares the images. The code aims to be obviously
//! correct rather than fast (O(objects) per ray, no acceleration structure).
//!
//! Rendering model, in short:
//! - camera rays from VIEWPOINT through the VIEWPORT (centred on ORIGIN);
//! - nearest hit with t > 0, ties go to the object earlier in the file;
//! - local colour = ambient + Σ lights B/(d + d0)·(diffuse·N·L + specular·(R·V)^k),
//!   with hard shadows cast by every object (transparent ones too);
//! - C = (1 − t)·C_local + t·C_behind + r·C_reflected, recursion while
//!   depth < RDEPTH; the transmitted ray continues unbent;
//! - each sample is clamped to [0, 1], samples are averaged, then gamma
//!   corrected and rounded (half up) to 0…255.
//!
//! - `BSPLINE` patches are evaluated here independently (Cox–de Boor in f64)
//!   into triangles carrying the surface normals at their corners; a hit on
//!   one is shaded with the barycentric blend of those normals, and its
//!   shadow rays leave from the hit point lifted onto the corners' tangent
//!   planes (when that lifts it towards the viewer's side), as the core does
//!   against shadow-terminator speckles.
//!
//! A crate of its own, depending on nothing but `std`, so that it cannot share
//! code with `octrace-core` by accident.
//!
//! ```
//! let scene = octrace_reference::parse(
//!     "VIEWPOINT 0 0 5\nRASTER 4 4\nLIGHT 1 3 3 3\nBACKGROUND 0 0 1\n\
//!      SPHERE 1 1 0 0 0\nSURFACE 1 0.1 0.1 0.1 0.8 0.2 0.2 0.5 0.5 0.5 20 0 0\n",
//! )?;
//! let pixels = scene.render(4, 4);
//! assert_eq!(pixels[0], [0, 0, 255], "a corner shows the background");
//! assert_ne!(pixels[5], pixels[0], "the middle shows the sphere");
//! # Ok::<(), String>(())
//! ```

mod bspline;
mod intersect;
mod parse;
mod render;
mod vector;

pub use bspline::Patch;
pub use parse::parse;
use vector::Rgb;
pub use vector::V3;

/// A material (`SURFACE` statement).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Surface {
    pub ambient: Rgb,
    pub diffuse: Rgb,
    pub specular: Rgb,
    /// Specular exponent k (k = 0: the specular factor is 1).
    pub exponent: f64,
    pub reflectivity: f64,
    pub transparency: f64,
}

/// A white point light.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Light {
    pub brightness: f64,
    pub position: V3,
}

/// The geometry of one object.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Shape {
    Sphere {
        centre: V3,
        radius: f64,
    },
    /// Axis-aligned box; `half` holds the half-sizes.
    Box {
        centre: V3,
        half: V3,
    },
    /// Σ |(x_i − c_i)/s_i|^power = 1.
    Superquadric {
        power: f64,
        centre: V3,
        half: V3,
    },
    /// Corners p1, p2, p3; `normal` = normalise((p2 − p1) × (p3 − p1)).
    Triangle {
        p: [V3; 3],
        normal: V3,
    },
    /// Planar convex quad, corners counter-clockwise seen from the front.
    Rectangle {
        p: [V3; 4],
        normal: V3,
    },
    /// A triangle of a B-spline patch, with the surface normals at its
    /// corners (turned to the front `normal`'s side).
    SmoothTriangle {
        p: [V3; 3],
        normal: V3,
        normals: [V3; 3],
    },
}

impl Shape {
    fn is_flat(&self) -> bool {
        matches!(self, Shape::Triangle { .. } | Shape::Rectangle { .. } | Shape::SmoothTriangle { .. })
    }
}

/// One object: a shape and the index of its surface in [`RefScene::surfaces`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Object {
    pub shape: Shape,
    pub surface: usize,
}

/// A parsed scene in world units (f64).
#[derive(Clone, Debug, PartialEq)]
pub struct RefScene {
    pub viewpoint: V3,
    pub origin: V3,
    pub upvector: V3,
    pub raster: (u32, u32),
    /// Explicit VIEWPORT (width, height), or `None` for the default.
    pub viewport: Option<(f64, f64)>,
    pub rdepth: u32,
    pub imagefile: Option<String>,
    pub lights: Vec<Light>,
    pub background: Rgb,
    pub gamma: f64,
    pub attenuation: f64,
    pub samples: u32,
    /// Objects in file order (the order matters for ties).
    pub objects: Vec<Object>,
    /// Surfaces, indexed by `Object::surface`.
    pub surfaces: Vec<Surface>,
}

#[cfg(test)]
mod tests {
    use super::*;

    fn centre_pixel(scene: &RefScene, w: u32, h: u32) -> [u8; 3] {
        scene.render(w, h)[(h / 2 * w + w / 2) as usize]
    }

    fn close(a: [f64; 3], b: [f64; 3]) -> bool {
        (0..3).all(|i| (a[i] - b[i]).abs() < 1e-9)
    }

    #[test]
    fn single_sphere_centre_pixel() {
        // Camera (0,0,10) looking at a unit sphere at the origin; a 3×3
        // raster puts the centre pixel's ray exactly on the axis, hitting
        // P = (0,0,1) with N = (0,0,1). Light at (0,0,10): d = 9, N·L = 1,
        // R·V = 1, so C = a + 1/(9+1)·(diffuse + specular).
        let scene = parse(
            "RASTER 3 3 GAMMA 1 LIGHT 1 0 0 10
             SPHERE 1 1 0 0 0
             SURFACE 1 0.1 0.2 0.0  0.5 0.3 0.8  0.2 0.1 0.0  10 0 0",
        )
        .unwrap();
        let c = scene.sample(3, 3, 1, 1, 0, 0);
        assert!(close(c, [0.17, 0.24, 0.08]), "{c:?}");
        // 255·0.17 = 43.35, 255·0.24 = 61.2, 255·0.08 = 20.4
        assert_eq!(centre_pixel(&scene, 3, 3), [43, 61, 20]);
        // The same with the default gamma 2.2.
        let g = parse(
            "RASTER 3 3 LIGHT 1 0 0 10 SPHERE 1 1 0 0 0
             SURFACE 1 0.1 0.2 0.0  0.5 0.3 0.8  0.2 0.1 0.0  10 0 0",
        )
        .unwrap();
        let expect = [0.17f64, 0.24, 0.08].map(|v| (255.0 * v.powf(1.0 / 2.2) + 0.5).floor() as u8);
        assert_eq!(centre_pixel(&g, 3, 3), expect);
        assert_eq!(expect, [114, 133, 81]);
        // A corner pixel misses the sphere.
        assert_eq!(scene.render(3, 3)[0], [0, 0, 0]);
    }

    #[test]
    fn background_only() {
        let scene = parse("BACKGROUND 0.5 0.25 1 GAMMA 1").unwrap();
        assert_eq!(scene.raster(), (320, 240));
        let image = scene.render(8, 6);
        assert_eq!(image.len(), 48);
        // 127.5 and 63.75 round half up.
        assert!(image.iter().all(|&p| p == [128, 64, 255]));
        // An empty file renders black.
        assert!(parse("").unwrap().render(4, 4).iter().all(|&p| p == [0, 0, 0]));
    }

    #[test]
    fn tie_goes_to_earlier_object() {
        let tri = |s: u32| format!("TRIANGLE {s} -5 -5 0  5 -5 0  0 5 0\n");
        let surfaces = "SURFACE 1 1 0 0  0 0 0  0 0 0  0 0 0
                        SURFACE 2 0 1 0  0 0 0  0 0 0  0 0 0
                        GAMMA 1 RASTER 3 3";
        let a = parse(&format!("{}{}{surfaces}", tri(1), tri(2))).unwrap();
        let b = parse(&format!("{}{}{surfaces}", tri(2), tri(1))).unwrap();
        assert_eq!(centre_pixel(&a, 3, 3), [255, 0, 0]);
        assert_eq!(centre_pixel(&b, 3, 3), [0, 255, 0]);
        // Two identical spheres.
        let c = parse(&format!("SPHERE 2 1 0 0 0 SPHERE 1 1 0 0 0 {surfaces}")).unwrap();
        assert_eq!(centre_pixel(&c, 3, 3), [0, 255, 0]);
    }

    #[test]
    fn superquadric_p2_matches_sphere() {
        let rest = "VIEWPOINT 1 2 9 LIGHT 1 -4 5 6 LIGHT 0.5 5 1 3 BACKGROUND 0.1 0.1 0.2
                    SURFACE 1 0.05 0.05 0.05  0.7 0.4 0.2  0.5 0.5 0.5  20 0.2 0
                    TRIANGLE 1 -9 -1.5 9  9 -1.5 9  0 -1.5 -9";
        let sphere = parse(&format!("SPHERE 1 1.5 0.2 0.1 0 {rest}")).unwrap();
        let sq = parse(&format!("SUPERQUADRIC 1 2 0.2 0.1 0  1.5 1.5 1.5 {rest}")).unwrap();
        let (a, b) = (sphere.render(64, 48), sq.render(64, 48));
        let mut lit = 0;
        for (pa, pb) in a.iter().zip(&b) {
            for c in 0..3 {
                assert!(pa[c].abs_diff(pb[c]) <= 1, "{pa:?} vs {pb:?}");
            }
            lit += usize::from(pa[0] > 60);
        }
        assert!(lit > 100, "the sphere should cover part of the image");
    }

    #[test]
    fn superquadric_large_power_hits_face_centre() {
        // Head-on, the centre ray of a p = 64 superquadric meets it where it
        // touches its bounding box: same colour as a box there.
        let rest = "RASTER 3 3 GAMMA 1 LIGHT 1 0 0 10
                    SURFACE 1 0.1 0.1 0.1  0.5 0.5 0.5  0 0 0  0 0 0";
        let sq = parse(&format!("SUPERQUADRIC 1 64 0 0 0 1 1 1 {rest}")).unwrap();
        let bx = parse(&format!("BOX 1 0 0 0 1 1 1 {rest}")).unwrap();
        let (a, b) = (sq.sample(3, 3, 1, 1, 0, 0), bx.sample(3, 3, 1, 1, 0, 0));
        assert!(close(a, b), "{a:?} vs {b:?}");
        assert!(close(a, [0.15; 3]), "{a:?}");
        // A non-integer power renders something too.
        let nf = parse(&format!("SUPERQUADRIC 1 3.7 0 0 0 1 1 1 {rest}")).unwrap();
        assert!(close(nf.sample(3, 3, 1, 1, 0, 0), [0.15; 3]));
    }

    #[test]
    fn shadow_occlusion() {
        // Ground z = 0 facing the camera; light at (5,0,5); a small sphere
        // at (2.5,0,2.5) sits on the segment from (0,0,0) to the light but
        // off the camera's centre ray.
        let base = "RASTER 3 3 GAMMA 1 LIGHT 1 5 0 5
                    RECTANGLE 1 -9 -9 0  9 -9 0  9 9 0  -9 9 0
                    SURFACE 1 0.1 0.1 0.1  0.5 0.5 0.5  0 0 0  0 0 0";
        let shadowed = |t: &str| {
            let s = parse(&format!("{base} SPHERE 2 0.5 2.5 0 2.5 SURFACE 2 1 1 1 1 1 1 0 0 0 0 0 {t}")).unwrap();
            s.sample(3, 3, 1, 1, 0, 0)
        };
        assert!(close(shadowed("0"), [0.1; 3]));
        // Transparent objects cast shadows too.
        assert!(close(shadowed("1"), [0.1; 3]));
        // Without the sphere the point is lit: d = √50, N·L = 1/√2.
        let lit = parse(base).unwrap().sample(3, 3, 1, 1, 0, 0);
        let d = 50f64.sqrt();
        let expect = 0.1 + 1.0 / (d + 1.0) * 0.5 / 2f64.sqrt();
        assert!(close(lit, [expect; 3]), "{lit:?}");
    }

    #[test]
    fn transparent_sphere_and_depth() {
        // A fully transparent sphere: the ray enters, reaches the far side
        // (not the near root again) and leaves into the background.
        let scene = |depth: u32| {
            parse(&format!(
                "RASTER 3 3 GAMMA 1 RDEPTH {depth} BACKGROUND 0.2 0.4 0.6
                 SPHERE 1 1 0 0 0 SURFACE 1 0.5 0.5 0.5 0 0 0 0 0 0 0 0 1"
            ))
            .unwrap()
            .sample(3, 3, 1, 1, 0, 0)
        };
        assert!(close(scene(2), [0.2, 0.4, 0.6]));
        assert!(close(scene(3), [0.2, 0.4, 0.6]));
        // Depth 1: the transmitted ray reaches the back face, which may not
        // recurse further; its local colour is weighted by 1 − t = 0.
        assert!(close(scene(1), [0.0; 3]));
        assert!(close(scene(0), [0.0; 3]));
    }

    #[test]
    fn mirror_reflects_background() {
        // A mirror triangle facing the camera reflects the ray straight back:
        // nothing is behind the camera, so it sees the background.
        let s = parse(
            "RASTER 3 3 GAMMA 1 BACKGROUND 0.3 0.3 0.3
             TRIANGLE 1 -5 -5 0 5 -5 0 0 5 0
             SURFACE 1 0.1 0.1 0.1 0 0 0 0 0 0 0 0.5 0",
        )
        .unwrap();
        assert!(close(s.sample(3, 3, 1, 1, 0, 0), [0.25; 3]));
    }

    #[test]
    fn parsing_rules() {
        let s = parse(
            "/* comment
                over lines */ viewpoint 1 +2.5E2 .25 // rest of line
             Raster 4 2 samples 2 imagefile \"my file.png\" Light 1e-3 0 0 0
             surface 3 0 0 0 0 0 0 0 0 0 0 0 0 sphere 3 1 0 0 -5",
        )
        .unwrap();
        assert_eq!(s.viewpoint, V3::new(1.0, 250.0, 0.25));
        assert_eq!(s.raster(), (4, 2));
        assert_eq!(s.samples, 2);
        assert_eq!(s.imagefile.as_deref(), Some("my file.png"));
        assert_eq!(s.lights[0].brightness, 1e-3);
        assert_eq!(s.render(4, 2).len(), 8);

        let err = |text: &str| parse(text).unwrap_err();
        assert!(err("SPHERE 1 1 0 0 0\n  FOO").starts_with("2:3:"), "{}", err("\n  FOO"));
        assert!(err("RASTER 3 nan").starts_with("1:10:"));
        assert!(err("GAMMA 0x10").starts_with("1:7:"));
        assert!(err("RASTER 3.5 2").starts_with("1:8:"));
        assert!(err("\n/* open").starts_with("2:1:"));
        assert!(err("SPHERE 1 1 0 0 0").contains("surface 1"));
        assert!(err("GAMMA 1\nGAMMA 2").contains("lines 1 and 2"));
        assert!(err("SPHERE 1 1 0 0").contains("end of file"));
        assert!(err("BSPLINE 1 2").contains("BSPLINE"));
        assert!(err("BSPLINE 1 3 2 3 4 4").contains("BSPLINE"));
    }

    #[test]
    fn default_viewport_follows_render_aspect() {
        // A pixel's horizontal extent must not depend on the render height.
        let s = parse("").unwrap();
        let d1 = s.primary_direction(320, 240, 0, 120, 0, 0);
        let d2 = s.primary_direction(320, 100, 0, 50, 0, 0);
        assert!((d1.x - d2.x).abs() < 1e-12);
        // The left edge of the viewport is at −d·tan30° = −10·tan30°.
        let left = s.primary_direction(1_000_000, 1, 0, 0, 0, 0);
        assert!((left.x / left.z - 30f64.to_radians().tan()).abs() < 1e-5);
    }
}
