//! The render check: parse, and if the scene parsed, render it at 8×8 with the naive
//! accelerator and with the octree (both walks: the thesis's named-box walk
//! and the 3DDDA). The modes are documented to give the same bits, so the
//! images (and the object seen through every pixel, and the ray counts) must
//! be identical.
//!
//! Work is bounded so that an input cannot legitimately take seconds: RDEPTH
//! is capped at 3 and SAMPLES is lowered for large scenes (the core itself
//! bounds the rays per sample). A timeout here is therefore a finding.

use crate::{parse_checked, Sink};
use octrace_core::accel::{Accelerator, Mailbox, Naive, Octree, OctreeConfig, Traversal};
use octrace_core::profile::Board64K;
use octrace_core::render::{PixelSample, Renderer};
use octrace_core::scene::{ObjectId, Scene, SceneView};
use octrace_core::shade::Stats;
use std::cell::RefCell;

const SIDE: u32 = 8;
/// RDEPTH at most this (≤ 15 rays per sample).
const MAX_RDEPTH: u32 = 3;
/// Budget of ray-object tests per render, roughly.
const BUDGET: u64 = 4_000_000;

struct State {
    scene: Box<Scene<Board64K>>,
    octree: Box<Octree<Board64K>>,
}

thread_local! {
    static STATE: RefCell<State> =
        RefCell::new(State { scene: Box::new(Scene::new()), octree: Box::new(Octree::new()) });
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

fn render<A: Accelerator>(view: SceneView<'_>, accel: &A) -> Option<Image> {
    // Mailbox as host-sim sets it up: one bit per object.
    let mut words = vec![0u32; Mailbox::words_for(view.object_count())];
    // A camera error on a parsed scene is not a panic; host-sim reports it.
    let renderer = Renderer::with_size(view, accel, SIDE, SIDE).ok()?;
    let mut renderer = renderer.with_mailbox(&mut words);
    assert_eq!((renderer.size().width, renderer.size().height), (SIDE, SIDE));
    let mut sink = Sink::new(SIDE, SIDE);
    let Ok(stats): Result<Stats, _> = renderer.render(&mut sink);
    assert_eq!(sink.outside, 0, "pixels drawn outside the image");
    // The objects seen, through the per-pixel API (same pixels again).
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
    assert_eq!(&sink.pixels[..(SIDE * SIDE) as usize], &again[..], "render() and row() differ");
    Some(Image { colors, objects, rays: stats.rays, shadow_rays: stats.shadow_rays, truncated: stats.truncated })
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
        let settings = &mut state.scene.settings;
        settings.rdepth = settings.rdepth.min(MAX_RDEPTH);
        let view = state.scene.view();
        let per_sample = ((1u64 << (view.settings.rdepth + 1)) - 1)
            * (1 + view.lights.len() as u64)
            * (1 + view.object_count() as u64)
            * u64::from(SIDE * SIDE);
        let mut samples = view.settings.samples;
        while samples > 1 && u64::from(samples * samples) * per_sample > BUDGET {
            samples -= 1;
        }
        state.scene.settings.samples = samples;
        let view = state.scene.view();

        let Some(naive) = render(view, &Naive) else { return };

        // Every subdivision criterion from 1 (split as deep as allowed) to
        // the default 4 (small scenes get a subdivided tree too). The input
        // does not choose it, so `cargo fuzz tmin` keeps the failing tree.
        let octree = &mut *state.octree;
        for max_objects in 1..=4 {
            let config = OctreeConfig { max_objects, ..OctreeConfig::default() };
            for traversal in [Traversal::Named, Traversal::Dda] {
                if traversal == Traversal::Named {
                    octree.build(&view, &OctreeConfig { traversal, ..config });
                } else {
                    octree.set_traversal(traversal);
                }
                let image = render(view, &*octree).expect("the naive render set up but the octree's did not");
                if image != naive {
                    panic!(
                        "{traversal:?} octree (max_objects {max_objects}) differs from naive: {} (report {:?})",
                        first_diff(&naive, &image),
                        octree.report()
                    );
                }
            }
        }
    });
}
