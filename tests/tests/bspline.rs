//! B-spline patches against an independent double-precision evaluation
//! (`octrace_reference::Patch`, Cox–de Boor in f64): the fixed-point
//! core must generate the same triangles, with the same corners and corner
//! normals, for random patches of every order (the seed is printed; set
//! `OCTRACE_SEED` to replay one).

use host_sim::{load_bytes, new_scene};
use octrace_core::math::Vec3;
use octrace_reference::{Patch, Shape, V3};
use octrace_tests::Rng;

/// World coordinates (f64) to the scene's normalised fixed point.
fn normalised(scene: &host_sim::HostScene, p: V3) -> Vec3 {
    let q32 = |v: f64| (v * 4_294_967_296.0).round() as i64;
    scene.view().normalization.point([q32(p.x), q32(p.y), q32(p.z)])
}

#[test]
fn random_patches_match_the_f64_evaluation() {
    let mut rng = Rng::from_env("random_patches_match_the_f64_evaluation");
    let mut worst_point = 0i64;
    let mut worst_normal = 0f64;
    for round in 0..40 {
        let order = 2 + rng.below(4) as usize;
        let rows = order + rng.below(4) as usize;
        let cols = order + rng.below(4) as usize;
        let (su, sv) = (2 + rng.below(9) as usize, 2 + rng.below(9) as usize);
        let points: Vec<V3> = (0..rows * cols)
            .map(|i| {
                let (r, c) = ((i / cols) as f64, (i % cols) as f64);
                V3::new(c * 2.0 + rng.range(-0.8, 0.8), rng.range(-3.0, 3.0), r * 2.0 + rng.range(-0.8, 0.8))
            })
            .collect();
        let mut text = format!("SURFACE 1 0 0 0 1 1 1 0 0 0 0 0 0\nBSPLINE 1 {order} {rows} {cols} {su} {sv}\n");
        for p in &points {
            text += &format!("{} {} {}\n", p.x, p.y, p.z);
        }
        let mut scene = new_scene();
        load_bytes("patch", text.as_bytes(), &mut scene).unwrap_or_else(|e| panic!("round {round}: {e}\n{text}"));
        // `{}` prints the shortest decimal that reads back as the same f64.
        let patch = Patch { order, rows, cols, points };
        let expected = patch.triangles(su, sv);
        let got = scene.view().bspline_triangles;
        assert_eq!(got.len(), expected.len(), "round {round}: triangle count");
        for (t, e) in got.iter().zip(&expected) {
            let Shape::SmoothTriangle { p, normals, .. } = e else { panic!("smooth triangles") };
            for i in 0..3 {
                let (want, have) = (normalised(&scene, p[i]).wide(), t.triangle.polygon.corners[i].wide());
                let off = (0..3).map(|a| (want[a] - have[a]).abs()).max().unwrap_or(0);
                worst_point = worst_point.max(off);
                assert!(off <= 8, "round {round}: corner {i} off by {off} units: {have:?} vs {want:?}");
                let n = t.normals[i].bits().map(|c| c as f64 / (1u64 << 30) as f64);
                let cos = n[0] * normals[i].x + n[1] * normals[i].y + n[2] * normals[i].z;
                worst_normal = worst_normal.max(1.0 - cos);
                assert!(cos > 1.0 - 1e-6, "round {round}: normal {i}: {n:?} vs {:?}", normals[i]);
            }
        }
    }
    println!("worst corner error {worst_point} units of 2^-16, worst normal 1 − cos = {worst_normal:.2e}");
}
