//! The render check: parse, and if the scene parsed, load it into a
//! `Raytracer` and render it at 8×8 with the naive accelerator and with the
//! octree (both walks: the thesis's named-box walk and the 3DDDA). The
//! modes are documented to give the same bits, so the images (and the
//! object seen through every pixel, and the ray counts) must be identical.
//!
//! Work is bounded so that an input cannot legitimately take seconds: a
//! scene with RDEPTH over 3, or with more SAMPLES than the budget allows
//! its size, is not rendered (the core itself bounds the rays per sample).
//! A timeout here is therefore a finding.

use crate::{parse_checked, Sink};
use embedded_graphics_core::geometry::Size;
use octrace_core::accel::{AccelMode, Indexing, OctreeConfig, Traversal};
use octrace_core::profile::Board64K;
use octrace_core::render::PixelSample;
use octrace_core::scene::{ObjectId, Scene};
use octrace_core::{DrawError, LoadedScene, Raytracer};
use std::cell::RefCell;

const SIDE: u32 = 8;
/// RDEPTH at most this (≤ 15 rays per sample).
const MAX_RDEPTH: u32 = 3;
/// Budget of ray-object tests per render, roughly.
const BUDGET: u64 = 4_000_000;

struct State {
    scene: Box<Scene<Board64K>>,
    raytracer: Box<Raytracer<Board64K>>,
}

thread_local! {
    static STATE: RefCell<State> =
        RefCell::new(State { scene: Box::new(Scene::new()), raytracer: Box::new(Raytracer::new()) });
}

/// The image, the object of each pixel and the counters of one render.
#[derive(PartialEq, Eq, Debug)]
struct Image {
    colors: Vec<[u8; 3]>,
    objects: Vec<Option<ObjectId>>,
    rays: u64,
    shadow_rays: u64,
    truncated: u64,
}

fn render(scene: &LoadedScene<'_, Board64K>) -> Option<Image> {
    // A camera error on a parsed scene is not a panic; host-sim reports it.
    let mut sink = Sink::new(SIDE, SIDE);
    let stats = match scene.image_for(&sink).try_draw(&mut sink) {
        Ok(stats) => stats,
        Err(DrawError::Camera(_)) => return None,
        Err(e) => panic!("an 8x8 image into an 8x8 sink: {e}"),
    };
    assert_eq!(sink.outside, 0, "pixels drawn outside the image");
    // The objects seen, through the per-pixel API (same pixels again).
    scene
        .with_renderer(Size::new(SIDE, SIDE), |renderer| {
            assert_eq!((renderer.size().width, renderer.size().height), (SIDE, SIDE));
            let mut objects = Vec::with_capacity((SIDE * SIDE) as usize);
            let mut again = Vec::with_capacity((SIDE * SIDE) as usize);
            for y in 0..SIDE {
                for p in renderer.row(y, 0..SIDE) {
                    let p: PixelSample = p;
                    objects.push(p.object);
                    again.push(p.color);
                }
            }
            let colors: Vec<[u8; 3]> = sink.pixels[..(SIDE * SIDE) as usize]
                .iter()
                .map(|c| {
                    use embedded_graphics_core::pixelcolor::RgbColor;
                    [c.r(), c.g(), c.b()]
                })
                .collect();
            assert_eq!(&sink.pixels[..(SIDE * SIDE) as usize], &again[..], "the image and row() differ");
            Image { colors, objects, rays: stats.rays, shadow_rays: stats.shadow_rays, truncated: stats.truncated }
        })
        .ok()
}

fn first_diff(a: &Image, b: &Image) -> String {
    for i in 0..a.colors.len() {
        if a.colors[i] != b.colors[i] || a.objects[i] != b.objects[i] {
            return format!(
                "pixel ({}, {}): {:?}/{:?} vs {:?}/{:?}",
                i as u32 % SIDE,
                i as u32 / SIDE,
                a.colors[i],
                a.objects[i],
                b.colors[i],
                b.objects[i]
            );
        }
    }
    format!(
        "counters: rays {} vs {}, shadow {} vs {}, truncated {} vs {}",
        a.rays, b.rays, a.shadow_rays, b.shadow_rays, a.truncated, b.truncated
    )
}

/// Parses `data` and, if it is a scene, renders it in every mode; panics if
/// the images (or objects seen, or ray counts) differ or a contract breaks.
pub fn check_render(data: &[u8]) {
    STATE.with(|state| {
        let state = &mut *state.borrow_mut();
        if !parse_checked(data, &mut state.scene) {
            return;
        }
        // Bound the work (see the module comment).
        let view = state.scene.view();
        let per_sample = ((1u64 << (view.settings.rdepth.min(MAX_RDEPTH) + 1)) - 1)
            * (1 + view.lights.len() as u64)
            * (1 + view.object_count() as u64)
            * u64::from(SIDE * SIDE);
        let samples = u64::from(view.settings.samples);
        if view.settings.rdepth > MAX_RDEPTH || samples * samples * per_sample > BUDGET {
            return;
        }
        let raytracer = &mut *state.raytracer;
        let Ok(scene) = raytracer.load_with(data, AccelMode::Naive, &mut |_| {}) else {
            panic!("the parser took the scene but the raytracer did not");
        };
        let Some(naive) = render(&scene) else { return };

        // Every subdivision criterion from 1 (split as deep as allowed) to
        // the default 4 (small scenes get a subdivided tree too). The input
        // does not choose it, so `cargo fuzz tmin` keeps the failing tree.
        for max_objects in 1..=4 {
            for (mode, traversal) in [(AccelMode::Octree, Traversal::Named), (AccelMode::Dda, Traversal::Dda)] {
                let octree = Some(OctreeConfig { max_objects, traversal, ..OctreeConfig::default() });
                let scene = raytracer.load_with(data, Indexing { mode, octree }, &mut |_| {}).expect("loaded before");
                let image = render(&scene).expect("the naive render set up but the octree's did not");
                if image != naive {
                    panic!(
                        "{traversal:?} octree (max_objects {max_objects}) differs from naive: {} (report {:?})",
                        first_diff(&naive, &image),
                        scene.octree_report()
                    );
                }
            }
        }
    });
}
