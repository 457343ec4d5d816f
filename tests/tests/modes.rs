//! The three intersection modes (naive, the thesis's octree walk, 3DDDA)
//! give bit-identical images, with or without the shadow rays' light
//! buffer: on every scene in `scenes/`, and on random scenes and rays (the
//! seed is printed; set `OCTRACE_SEED` to replay one).

use host_sim::{load_bytes, load_file, new_scene, render, AccelMode, HostScene, RenderOptions};
use octrace_core::accel::{
    prepare, Accelerator, Indexing, LightBuffer, LightBuffered, Mailbox, Naive, Octree, OctreeConfig, RayStart,
    Traversal, MAX_CELLS_A_SIDE,
};
use octrace_core::capacity::Arena;
use octrace_core::math::{Dir, Scalar, Vec3};
use octrace_core::profile::{Host, Profile};
use octrace_core::scene::ObjectId;
use octrace_core::shapes::{Leaving, Ray};
use octrace_tests::{scene_path, scenes, Rng};

fn image(
    scene: &mut HostScene,
    accel: AccelMode,
    octree: OctreeConfig,
    size: Option<(u32, u32)>,
) -> host_sim::RgbImage {
    // On every core: the suite's last minutes run few tests beside this one.
    let threads = std::thread::available_parallelism().map_or(1, usize::from);
    render(scene, &RenderOptions { size, accel, octree, threads, ..Default::default() }).expect("renders").image
}

#[test]
fn every_scene_is_identical_in_every_mode() {
    for (name, path) in scenes() {
        let mut scene = new_scene();
        load_file(&path, &mut scene).unwrap();
        let config = host_sim::OCTREE;
        // Half size keeps the naive mode quick on the large free-form scene
        // (the golden test renders every scene at full size).
        let size = Some((160, 120));
        // The naive mode named has no light buffer; `auto` (naive for a
        // handful of objects) and the octree's walks have one.
        let naive = image(&mut scene, AccelMode::Naive, config, size);
        for mode in [AccelMode::Auto, AccelMode::Octree, AccelMode::Dda] {
            let other = image(&mut scene, mode, config, size);
            let differ = naive.data.chunks(3).zip(other.data.chunks(3)).filter(|(a, b)| a != b).count();
            assert_eq!(differ, 0, "{name}: {} differs from naive in {differ} pixels", mode.name());
        }
        println!("{name}: naive, and auto, octree and dda with a light buffer, identical");
    }
}

/// A random scene of every primitive, with reflective and transparent
/// surfaces, objects touching, overlapping and sharing faces.
fn random_scene(rng: &mut Rng) -> String {
    let mut s = String::new();
    let c = |rng: &mut Rng| rng.range(-4.0, 4.0);
    s += &format!(
        "RASTER 40 30 RDEPTH 3 VIEWPOINT {} {} {} ORIGIN 0 0 0 BACKGROUND 0.2 0.3 0.4\n",
        rng.range(-12.0, 12.0),
        rng.range(2.0, 12.0),
        rng.range(6.0, 14.0)
    );
    for _ in 0..1 + rng.below(3) {
        s += &format!("LIGHT {} {} {} {}\n", rng.range(3.0, 15.0), c(rng) * 3.0, rng.range(3.0, 12.0), c(rng) * 3.0);
    }
    for n in 1..=4 {
        s += &format!(
            "SURFACE {n} 0.1 0.1 0.1 {} {} {} 0.5 0.5 0.5 {} {} {}\n",
            rng.range(0.2, 1.0),
            rng.range(0.2, 1.0),
            rng.range(0.2, 1.0),
            rng.below(60),
            if rng.below(3) == 0 { 0.5 } else { 0.0 },
            if rng.below(4) == 0 { 0.6 } else { 0.0 },
        );
    }
    // A floor of tiles sharing edges.
    let tiles = rng.below(4) as i32;
    for i in -tiles..tiles {
        for j in -tiles..tiles {
            let (x0, z0, x1, z1) = (i * 2, j * 2, i * 2 + 2, j * 2 + 2);
            s += &format!(
                "RECTANGLE {} {x0} -2 {z1} {x1} -2 {z1} {x1} -2 {z0} {x0} -2 {z0}\n",
                1 + (i + j).rem_euclid(2)
            );
        }
    }
    // Sometimes a small B-spline patch, folded at random.
    if rng.below(3) == 0 {
        let (order, rows, cols) = (2 + rng.below(2), 3 + rng.below(2), 3 + rng.below(2));
        s += &format!("BSPLINE {} {order} {rows} {cols} {} {}\n", 1 + rng.below(4), 3 + rng.below(5), 3 + rng.below(5));
        for i in 0..rows {
            for j in 0..cols {
                s += &format!("{} {} {}  ", i as f64 * 1.5 - 2.0, rng.range(-1.5, 1.5), j as f64 * 1.5 - 2.0);
            }
            s += "\n";
        }
    }
    for _ in 0..rng.below(40) {
        let surf = 1 + rng.below(4);
        let (x, y, z) = (c(rng), c(rng), c(rng));
        match rng.below(5) {
            0 => s += &format!("SPHERE {surf} {} {x} {y} {z}\n", rng.range(0.1, 1.5)),
            1 => {
                s += &format!(
                    "BOX {surf} {x} {y} {z} {} {} {}\n",
                    rng.range(0.1, 1.0),
                    rng.range(0.1, 1.0),
                    rng.range(0.1, 1.0)
                )
            }
            2 => {
                s += &format!(
                    "SUPERQUADRIC {surf} {} {x} {y} {z} {} {} {}\n",
                    rng.range(2.0, 30.0),
                    rng.range(0.2, 1.0),
                    rng.range(0.2, 1.0),
                    rng.range(0.2, 1.0)
                )
            }
            3 => {
                s += &format!(
                    "TRIANGLE {surf} {x} {y} {z} {} {} {} {} {} {}\n",
                    x + rng.range(0.5, 2.0),
                    y + rng.range(-1.0, 1.0),
                    z,
                    x,
                    y + rng.range(0.5, 2.0),
                    z + rng.range(-1.0, 1.0)
                )
            }
            _ => {
                // Two spheres touching, or a sphere on a box: exact ties.
                s += &format!("SPHERE {surf} 0.5 {x} {y} {z}\nSPHERE {surf} 0.5 {} {y} {z}\n", x + 1.0);
                s += &format!("BOX {surf} {x} {} {z} 0.5 0.5 0.5\n", y - 1.0);
            }
        }
    }
    s
}

#[test]
fn random_scenes_are_identical_in_every_mode() {
    let mut rng = Rng::from_env("random_scenes_are_identical_in_every_mode");
    for round in 0..24 {
        let text = random_scene(&mut rng);
        let mut scene = new_scene();
        if let Err(e) = load_bytes("random", text.as_bytes(), &mut scene) {
            // Random corners can make a degenerate triangle: skip those.
            assert!(e.to_string().contains("degenerate"), "round {round}: {e}\n{text}");
            continue;
        }
        let config =
            OctreeConfig { max_objects: 1 + rng.below(6) as usize, max_depth: 1 + rng.below(10), ..host_sim::OCTREE };
        let naive = image(&mut scene, AccelMode::Naive, config, None);
        for mode in [AccelMode::Octree, AccelMode::Dda] {
            let other = image(&mut scene, mode, config, None);
            assert!(naive == other, "round {round}: {} differs from naive ({config:?})\n{text}", mode.name());
        }
    }
}

/// Query-level check: random rays from random points inside and outside the
/// scene, starting on objects or not, nearest and any-hit.
#[test]
fn random_queries_agree_with_the_naive_mode() {
    let mut rng = Rng::from_env("random_queries_agree_with_the_naive_mode");
    for round in 0..12 {
        let text = random_scene(&mut rng);
        let mut scene = new_scene();
        if load_bytes("random", text.as_bytes(), &mut scene).is_err() {
            continue;
        }
        let view = scene.view();
        let n = view.object_count() as u32;
        for traversal in [Traversal::Named, Traversal::Dda] {
            let config = OctreeConfig {
                max_objects: 1 + rng.below(4) as usize,
                max_depth: 2 + rng.below(9),
                traversal,
                ..host_sim::OCTREE
            };
            let mode = if traversal == Traversal::Dda { AccelMode::Dda } else { AccelMode::Octree };
            let mut tree: Box<Octree<Host>> = Box::default();
            if prepare(mode, &view, &mut *tree, &config).report.is_none() {
                continue;
            }
            let cells = 1 << rng.below(MAX_CELLS_A_SIDE.trailing_zeros() + 1);
            let mut arena = <Host as Profile>::LightBufferWords::EMPTY;
            let buffer = LightBuffer::build(&view, &mut arena, cells);
            let (lit, lit_tree) = (LightBuffered::new(&Naive, buffer), LightBuffered::new(&*tree, buffer));
            let mut words = vec![0u32; Mailbox::words_for(n as usize)];
            let mut mailbox = Mailbox::new(&mut words);
            for _ in 0..2000 {
                let scale = view.normalization.length(4 << 32).to_bits() as f64;
                let p = |rng: &mut Rng| Scalar::from_bits((rng.range(-1.6, 1.6) * scale) as i32);
                let origin = Vec3 { x: p(&mut rng), y: p(&mut rng), z: p(&mut rng) };
                let d = [0, 1, 2].map(|_| match rng.below(6) {
                    0 => 0,
                    _ => (rng.range(-1.0, 1.0) * (1u64 << 40) as f64) as i64,
                });
                let Some(dir) = Dir::normalize(d) else { continue };
                let ray = Ray { origin, dir };
                let start = (n > 0 && rng.below(3) == 0).then(|| RayStart {
                    object: ObjectId(rng.below(n)),
                    leaving: if rng.below(2) == 0 { Leaving::Inward } else { Leaving::Outward },
                });
                mailbox.clear();
                let nearest = Naive.nearest(&view, &ray, start, &mut mailbox);
                mailbox.clear();
                let b = tree.nearest(&view, &ray, start, &mut mailbox);
                assert_eq!(nearest, b, "round {round} {traversal:?} {config:?}: nearest along {ray:?}\n{text}");
                let t_max = Scalar::from_bits((rng.range(0.0, 2.0) * scale) as i32);
                mailbox.clear();
                let a = Naive.occluded(&view, &ray, t_max, start, &mut mailbox);
                mailbox.clear();
                let b = tree.occluded(&view, &ray, t_max, start, &mut mailbox);
                assert_eq!(a, b, "round {round} {traversal:?}: occluded along {ray:?} to {t_max}\n{text}");
                // Shadow rays from the hit to every light, as the tracer
                // makes them (and exactly aimed): the octree's shadow
                // shafts, and the light buffer in front of either mode,
                // answer as the walk.
                let Some(hit) = nearest else { continue };
                let point = ray.at(hit.t);
                for (light, l) in view.lights.iter().enumerate() {
                    let to_light = l.position - point;
                    for aimed in [to_light.direction_and_length_estimate(), to_light.direction_and_length()] {
                        let Some((dir, distance)) = aimed else { continue };
                        let shadow = Ray { origin: point, dir };
                        let t_max = Scalar::from_bits((distance.to_bits() - 1).max(0));
                        let leaving = if rng.below(2) == 0 { Leaving::Inward } else { Leaving::Outward };
                        let start = Some(RayStart { object: hit.object, leaving });
                        mailbox.clear();
                        let a = Naive.occluded(&view, &shadow, t_max, start, &mut mailbox);
                        let by = |accel: &dyn Fn(&mut Mailbox<'_>) -> bool, mailbox: &mut Mailbox<'_>| {
                            mailbox.clear();
                            accel(mailbox)
                        };
                        let answers = [
                            by(&|m| tree.occluded_toward(&view, &shadow, t_max, light, start, m), &mut mailbox),
                            by(&|m| lit.occluded_toward(&view, &shadow, t_max, light, start, m), &mut mailbox),
                            by(&|m| lit_tree.occluded_toward(&view, &shadow, t_max, light, start, m), &mut mailbox),
                        ];
                        assert_eq!(
                            answers, [a; 3],
                            "round {round} {traversal:?}: shadow ray {shadow:?} to light {light} (octree, light \
                             buffer of {cells} cells a side alone and with the octree)\n{text}"
                        );
                    }
                }
            }
        }
    }
}

#[test]
fn small_capacities_fall_back_without_changing_the_image() {
    use embedded_graphics_core::geometry::Size;
    use octrace_core::profile::Board16K;
    use octrace_core::Raytracer;
    // fig5_3's 200 spheres in the 16 KiB board profile: the octree's arenas
    // are small, so boxes stay unsplit; the image must not change.
    let text = std::fs::read(scene_path("fig5_3")).unwrap();
    let mut raytracer: Box<Raytracer<Board16K>> = Box::default();
    let mut draw = |indexing: Indexing| {
        let scene = raytracer.load_with(&text, indexing, &mut |e| panic!("{e}")).unwrap();
        let mut image = host_sim::RgbImage::new(64, 48);
        scene.image(Size::new(64, 48)).try_draw(&mut image).unwrap();
        (image, scene.octree_report().copied())
    };
    let (a, _) = draw(AccelMode::Naive.into());
    let config = OctreeConfig { max_objects: 1, max_depth: 12, traversal: Traversal::Dda, ..host_sim::OCTREE };
    let (b, report) = draw(Indexing { mode: AccelMode::Dda, octree: Some(config) });
    let report = report.expect("an octree");
    println!("{report:?}");
    assert!(report.unsplit > 0, "the small profile should run out: {report:?}");
    assert!(a == b);
}
