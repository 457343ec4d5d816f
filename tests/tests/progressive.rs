//! The progressive order on every scene: the whole picture coarse first,
//! and at the end host-sim's picture bit for bit, drawn by one core or by
//! two sharing the units (one of them drawing), every pixel traced once.

use embedded_graphics_core::geometry::Size;
use embedded_graphics_core::pixelcolor::Rgb888;
use host_sim::{load_file, new_scene, render, AccelMode, RenderOptions, RgbImage};
use octrace_core::profile::Host;
use octrace_core::render::Progressive;
use octrace_core::{Raytracer, RendererRoom};
use octrace_tests::scenes;
use std::sync::mpsc;

/// An odd size, so that blocks are clipped at both edges.
const SIZE: (u32, u32) = (37, 23);

/// Orders to try: the default mosaic, a fine one, and one whose first
/// blocks are taller than the image, finished from blocks of 8.
const ORDERS: [(u32, u32); 3] = [(16, 1), (4, 1), (32, 8)];

/// Slots of colours core 1 may fill ahead of core 0 (a board's ring).
const SLOTS: usize = 4;

#[test]
fn every_scene_ends_as_the_direct_picture_on_one_core_and_on_two() {
    let (w, h) = SIZE;
    for (name, path) in scenes() {
        let mut scene = new_scene();
        load_file(&path, &mut scene).unwrap_or_else(|e| panic!("{name}: {e}"));
        let expected = render(&mut scene, &RenderOptions { size: Some(SIZE), ..Default::default() }).unwrap();
        let text = std::fs::read(&path).unwrap();
        let mut raytracer = Box::new(Raytracer::<Host>::new());
        let loaded = raytracer.load_with(&text, AccelMode::Dda, &mut |e| panic!("{name}: {e}")).unwrap();
        // Each core its own room (mailbox and screen lists), as on a board.
        let shared = loaded.share();
        for (coarsest, finest) in ORDERS {
            let order = Progressive::new(Size::new(w, h), coarsest).with_finest(finest);
            let label = format!("{name}, coarsest {coarsest}, finest {finest}");

            let room = RendererRoom::<Host>::new();
            let mut one = RgbImage::new(w, h);
            let stats = shared.image(&room, Size::new(w, h)).progressive(&order).try_draw(&mut one).unwrap();
            assert!(one == expected.image, "{label}: one core's picture differs");
            assert_eq!(
                (stats.rays, stats.shadow_rays),
                (expected.stats.rays, expected.stats.shadow_rays),
                "{label}: one core traces each pixel once"
            );

            // Core 1 traces every other unit and hands its colours over
            // through a few slots; core 0 traces the rest and draws all.
            let mut two = RgbImage::new(w, h);
            let (to_core0, from_core1) = mpsc::sync_channel::<(usize, Vec<Rgb888>)>(SLOTS);
            let core1_rays = std::thread::scope(|s| {
                let core1 = s.spawn(|| {
                    let mut room = RendererRoom::<Host>::new();
                    let mut renderer = shared.renderer(&mut room, Size::new(w, h)).unwrap();
                    for (index, unit) in order.units().enumerate().skip(1).step_by(2) {
                        let mut slot = vec![Rgb888::new(0, 0, 0); order.max_unit_pixels()];
                        unit.trace(&mut renderer, &mut slot).unwrap();
                        to_core0.send((index, slot)).unwrap();
                    }
                    renderer.stats().rays
                });
                let mut room = RendererRoom::<Host>::new();
                let mut renderer = shared.renderer(&mut room, Size::new(w, h)).unwrap();
                let mut mine = vec![Rgb888::new(0, 0, 0); order.max_unit_pixels()];
                for (index, unit) in order.units().enumerate() {
                    if index % 2 == 0 {
                        unit.trace(&mut renderer, &mut mine).unwrap().draw(&mut two).unwrap();
                    } else {
                        let (handed, colors) = from_core1.recv().unwrap();
                        assert_eq!(handed, index, "{label}: units arrive in order");
                        unit.with_colors(&colors).unwrap().draw(&mut two).unwrap();
                    }
                }
                renderer.stats().rays + core1.join().unwrap()
            });
            assert!(two == expected.image, "{label}: two cores' picture differs");
            assert_eq!(core1_rays, expected.stats.rays, "{label}: two cores trace each pixel once");
        }
    }
}
