//! Parallel rendering gives the same bits: any number of threads, either
//! partition, and the interleaved-row split a dual-core board would use.

use embedded_graphics_core::geometry::Size;
use embedded_graphics_core::pixelcolor::RgbColor;
use host_sim::{load_file, new_scene, render, AccelMode, Partition, RenderOptions};
use octrace_core::profile::Host;
use octrace_core::render::interleaved_rows;
use octrace_core::{Raytracer, RendererRoom};
use octrace_tests::{scene_path, scenes};
use std::sync::Mutex;

#[test]
fn every_thread_count_and_partition_gives_the_same_image() {
    for (name, path) in scenes() {
        let mut scene = new_scene();
        load_file(&path, &mut scene).unwrap_or_else(|e| panic!("{name}: {e}"));
        // An odd size, so that tiles and quarters are uneven.
        let base = RenderOptions { size: Some((101, 67)), ..Default::default() };
        let one = render(&mut scene, &base).unwrap().image;
        for partition in [Partition::Tiles, Partition::Equal4] {
            for threads in [1, 2, 3, 7] {
                let options = RenderOptions { threads, partition, ..base };
                let rendered = render(&mut scene, &options).unwrap();
                assert!(rendered.image == one, "{name}: {threads} threads, {partition:?} differ");
                assert_eq!(rendered.busy.len(), threads);
            }
        }
    }
}

#[test]
fn stats_do_not_depend_on_the_thread_count() {
    let path = scene_path("fig5_3");
    let mut scene = new_scene();
    load_file(&path, &mut scene).unwrap();
    let options =
        |threads| RenderOptions { size: Some((96, 64)), accel: AccelMode::Dda, threads, ..Default::default() };
    let one = render(&mut scene, &options(1)).unwrap().stats;
    let four = render(&mut scene, &options(4)).unwrap().stats;
    assert_eq!(one, four);
}

/// The split a dual-core board uses (README, "octrace on your board"):
/// each core its own renderer over the shared scene and octree, rows dealt
/// out in turn, each row sent to the display where it belongs.
#[test]
fn two_cores_with_interleaved_rows_give_the_same_image() {
    let path = scene_path("fig5_3");
    let mut scene = new_scene();
    load_file(&path, &mut scene).unwrap();
    let (w, h) = (120, 90);
    let expected = render(&mut scene, &RenderOptions { size: Some((w, h)), ..Default::default() }).unwrap().image;
    let text = std::fs::read(&path).unwrap();
    let mut raytracer = Box::new(Raytracer::<Host>::new());
    let loaded = raytracer.load_with(&text, AccelMode::Dda, &mut |e| panic!("{e}")).unwrap();
    let shared = loaded.share();
    let display = Mutex::new(host_sim::RgbImage::new(w, h));
    std::thread::scope(|s| {
        for core in 0..2 {
            let display = &display;
            s.spawn(move || {
                let mut room = RendererRoom::<Host>::new();
                let mut renderer = shared.renderer(&mut room, Size::new(w, h)).unwrap();
                for y in interleaved_rows(h, core, 2) {
                    let row: Vec<_> = renderer.row(y, 0..w).map(|p| p.color).collect();
                    let mut image = display.lock().unwrap();
                    for (x, c) in row.into_iter().enumerate() {
                        let i = (y as usize * w as usize + x) * 3;
                        image.data[i..i + 3].copy_from_slice(&[c.r(), c.g(), c.b()]);
                    }
                }
            });
        }
    });
    assert!(display.into_inner().unwrap() == expected);
}
