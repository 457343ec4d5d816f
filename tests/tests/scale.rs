//! The same scene written at 1e-3, 1 and 1e5 scale renders (nearly) the same
//! image: the loader normalises every scene into the fixed-point range.
//!
//! Scaling a scene by s scales every length, the VIEWPORT and ATTENUATION d0;
//! the light brightness scales too, so that B/(d + d0) is unchanged.

use host_sim::{load_bytes, new_scene, render, RenderOptions, RgbImage};

/// A scene with every primitive, two lights and reflections, at scale `s`.
fn scene(s: f64) -> String {
    let l = |v: f64| format!("{:e}", v * s);
    let p = |x: f64, y: f64, z: f64| format!("{} {} {}", l(x), l(y), l(z));
    format!(
        "RASTER 96 72 RDEPTH 2 BACKGROUND 0.1 0.1 0.2\n\
         VIEWPOINT {eye} ORIGIN {origin} ATTENUATION {d0}\n\
         LIGHT {b1} {l1}\nLIGHT {b2} {l2}\n\
         SPHERE 1 {r} {c1}\n\
         BOX 2 {c2} {h2}\n\
         SUPERQUADRIC 3 5.5 {c3} {h3}\n\
         TRIANGLE 4 {t1} {t2} {t3}\n\
         RECTANGLE 5 {q1} {q2} {q3} {q4}\n\
         SURFACE 1 0.1 0 0  0.8 0.2 0.2  0.8 0.8 0.8  40 0.3 0\n\
         SURFACE 2 0 0.1 0  0.2 0.7 0.3  0.5 0.5 0.5  20 0 0\n\
         SURFACE 3 0 0 0.1  0.2 0.3 0.9  0.9 0.9 0.9  60 0.2 0\n\
         SURFACE 4 0.1 0.1 0  0.8 0.8 0.2  0 0 0  0 0 0.5\n\
         SURFACE 5 0.05 0.05 0.05  0.6 0.6 0.6  0.2 0.2 0.2  10 0.4 0\n",
        eye = p(1.0, 3.0, 9.0),
        origin = p(0.0, 0.5, 0.0),
        d0 = l(1.0),
        b1 = l(8.0),
        l1 = p(-4.0, 7.0, 5.0),
        b2 = l(3.0),
        l2 = p(5.0, 4.0, 2.0),
        r = l(1.1),
        c1 = p(-1.6, 1.1, 0.0),
        c2 = p(1.5, 0.6, -0.5),
        h2 = p(0.6, 0.6, 0.6),
        c3 = p(0.2, 0.7, 1.8),
        h3 = p(0.7, 0.7, 0.5),
        t1 = p(-3.0, 0.0, -3.0),
        t2 = p(3.0, 0.0, -3.0),
        t3 = p(0.0, 3.5, -3.5),
        q1 = p(-5.0, 0.0, 5.0),
        q2 = p(5.0, 0.0, 5.0),
        q3 = p(5.0, 0.0, -5.0),
        q4 = p(-5.0, 0.0, -5.0),
    )
}

fn image(s: f64) -> RgbImage {
    let mut sc = new_scene();
    load_bytes("scale", scene(s).as_bytes(), &mut sc).unwrap_or_else(|e| panic!("scale {s}: {e}"));
    render(&mut sc, &RenderOptions::default()).unwrap().image
}

#[test]
fn tiny_and_huge_scenes_render_like_unit_scale() {
    let unit = image(1.0);
    for s in [1e-3, 1e5] {
        let other = image(s);
        let pixels = unit.data.len() / 3;
        let mut off = 0;
        let mut worst = 0;
        for (a, b) in unit.data.chunks(3).zip(other.data.chunks(3)) {
            let d = a.iter().zip(b).map(|(x, y)| x.abs_diff(*y)).max().unwrap_or(0);
            worst = worst.max(d);
            if d > 2 {
                off += 1;
            }
        }
        println!("scale {s:e}: {off} of {pixels} pixels differ by more than 2 levels, worst {worst}");
        assert!(off * 200 <= pixels, "scale {s:e}: {off} pixels of {pixels} differ by more than 2 levels");
    }
}
