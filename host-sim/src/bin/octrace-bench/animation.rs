//! The `animation` table: frame-to-frame coherence on anim_fig5_1 at
//! 640×480 on one thread (full frames against incremental ones, the share
//! of pixels re-traced, what the tracking costs, what any exact method must
//! re-trace at least), a viewpoint that moves, and the memory coherence
//! takes for a 240×240 panel.

use crate::measure::{ms, BenchError};
use embedded_graphics_core::draw_target::DrawTarget;
use embedded_graphics_core::geometry::{OriginDimensions, Size};
use embedded_graphics_core::pixelcolor::Rgb888;
use embedded_graphics_core::Pixel;
use host_sim::animation::{render_frames, AnimationOptions, AnimationReport, FrameImage, COHERENCE_TILE};
use host_sim::RenderOptions;
use octrace_core::animation::{AnimationNeeds, Coherence, HostAnimationRoom};
use octrace_core::profile::Host;
use octrace_core::scene::Frames;
use octrace_core::{AccelMode, Raytracer};
use std::path::Path;
use std::time::{Duration, Instant};

/// Every frame of `bytes` at `size` on one thread: the report and the
/// frames.
fn play(bytes: &[u8], frames: Frames, size: (u32, u32), coherence: bool) -> (AnimationReport, Vec<FrameImage>) {
    let options = AnimationOptions {
        render: RenderOptions { size: Some(size), threads: 1, ..RenderOptions::default() },
        coherence,
    };
    let mut images = Vec::new();
    let report = render_frames(bytes, frames.all(), &options, &|_| {}, &mut |_, frame| {
        images.push(frame.clone());
        Ok(())
    });
    (report.unwrap_or_else(|e| panic!("the animation renders: {e:?}")), images)
}

fn frames_of(path: &Path) -> Result<(Vec<u8>, Frames), BenchError> {
    let bytes = std::fs::read(path)
        .map_err(|e| BenchError::Scene { path: path.to_owned(), error: host_sim::LoadError::Io(e) })?;
    let mut scene = host_sim::new_scene();
    let loaded = host_sim::load_bytes(&path.display().to_string(), &bytes, &mut scene)
        .map_err(|error| BenchError::Scene { path: path.to_owned(), error })?;
    Ok((bytes, loaded.frames.expect("an animation")))
}

/// Per frame after the first.
fn per_frame(report: &AnimationReport) -> Duration {
    (report.tracing - report.first_tracing) / (report.frames - 1).max(1)
}

/// The pixels whose colour changes from each frame to the next (the loop
/// closed), and the time to trace only those against all, with one
/// renderer over the naive mode (a ratio: any exact method traces at
/// least these).
fn changed(bytes: &[u8], images: &[FrameImage], size: (u32, u32)) -> (f64, f64) {
    let (w, h) = size;
    let (mut changed, mut only, mut all) = (0u64, Duration::ZERO, Duration::ZERO);
    for k in 0..images.len() {
        let before = &images[(k + images.len() - 1) % images.len()];
        let now = &images[k];
        let mask: Vec<bool> = before.image.data.chunks(3).zip(now.image.data.chunks(3)).map(|(a, b)| a != b).collect();
        changed += mask.iter().filter(|&&m| m).count() as u64;
        let mut raytracer = Box::new(Raytracer::<Host>::new());
        let scene = raytracer.load_frame_with(bytes, k as u32, AccelMode::Naive, &mut |_| {}).expect("loads");
        let traced = scene.with_renderer(Size::new(w, h), |renderer| {
            let mut trace = |masked: bool| {
                let started = Instant::now();
                for y in 0..h {
                    for x in 0..w {
                        if !masked || mask[(y * w + x) as usize] {
                            std::hint::black_box(renderer.pixel(x, y));
                        }
                    }
                }
                started.elapsed()
            };
            (trace(true), trace(false))
        });
        let (masked, whole) = traced.expect("a camera");
        only += masked;
        all += whole;
    }
    let pixels = (images.len() as u64 * u64::from(w) * u64::from(h)) as f64;
    (changed as f64 / pixels, only.as_secs_f64() / all.as_secs_f64())
}

/// The coherence's share at `size` with tiles of `side`, through the core's
/// board API (one core, the naive mode), after the first frame.
fn share_at(text: &str, size: (u32, u32), side: u32) -> f64 {
    let image = Size::new(size.0, size.1);
    let tiles = Coherence::tiles_for(size.0, size.1, side);
    let mut room = HostAnimationRoom::new(AnimationNeeds { tiles, ..AnimationNeeds::of(text, image) });
    let mut animation = room.animation_in_tiles(image, side).expect("room").indexed(AccelMode::Naive);
    let mut raytracer = Box::new(Raytracer::<Host>::new());
    let frames = raytracer.load(text).expect("loads").frames().expect("an animation");
    let (mut traced, mut pixels) = (0u64, 0u64);
    for frame in frames.all() {
        let loaded = animation.load(&mut raytracer, text, frame).expect("loads");
        if frame > 0 {
            traced += loaded.tiles().traced_pixels();
            pixels += u64::from(size.0) * u64::from(size.1);
        }
        loaded.image().try_draw(&mut Nowhere(image)).expect("draws");
    }
    traced as f64 / pixels as f64
}

/// A panel that shows nothing.
struct Nowhere(Size);

impl OriginDimensions for Nowhere {
    fn size(&self) -> Size {
        self.0
    }
}

impl DrawTarget for Nowhere {
    type Color = Rgb888;
    type Error = std::convert::Infallible;

    fn draw_iter<I: IntoIterator<Item = Pixel<Rgb888>>>(&mut self, pixels: I) -> Result<(), Self::Error> {
        pixels.into_iter().for_each(drop);
        Ok(())
    }
}

pub(crate) fn table(dir: &Path) -> Result<(), BenchError> {
    let path = dir.join("anim_fig5_1.txt");
    let (bytes, frames) = frames_of(&path)?;
    let size = (640, 480);
    println!("### Animation: anim_fig5_1 at 640×480, one thread ({} frames)\n", frames.count);
    // Alternating runs, the best of three of each: a busy spell of a
    // shared machine weighs on both.
    let best = |coherence: bool, runs: &mut Vec<(AnimationReport, Vec<FrameImage>)>| {
        let run = play(&bytes, frames, size, coherence);
        runs.push(run);
    };
    let (mut wholes, mut coherents) = (Vec::new(), Vec::new());
    for _ in 0..3 {
        best(false, &mut wholes);
        best(true, &mut coherents);
    }
    let fastest = |runs: Vec<(AnimationReport, Vec<FrameImage>)>| {
        runs.into_iter().min_by_key(|(report, _)| report.tracing).expect("three runs")
    };
    let (whole, images) = fastest(wholes);
    let (coherent, _) = fastest(coherents);
    let full = whole.tracing / whole.frames;
    let incremental = per_frame(&coherent);
    let traced =
        (coherent.traced - u64::from(size.0 * size.1)) as f64 / (coherent.pixels - u64::from(size.0 * size.1)) as f64;
    let (changed_share, changed_time) = changed(&bytes, &images, size);
    let loading = coherent.loading / coherent.frames;
    println!("| measure | value |");
    println!("| --- | ---: |");
    println!("| full frame (every pixel, `--no-coherence`), mean | {} |", ms(full));
    println!("| incremental frame (after the first), mean | {} |", ms(incremental));
    println!("| incremental / full | {:.1} % |", 100.0 * incremental.as_secs_f64() / full.as_secs_f64());
    println!("| pixels re-traced per frame (tiles of {COHERENCE_TILE}×{COHERENCE_TILE}) | {:.1} % |", 100.0 * traced);
    println!(
        "| first frame with the lookout / without | {:.2}× |",
        coherent.first_tracing.as_secs_f64() / whole.tracing.as_secs_f64() * whole.frames as f64
    );
    println!(
        "| pixels whose colour changes per frame (any exact method re-traces them) | {:.1} % |",
        100.0 * changed_share
    );
    println!("| tracing only those / a full frame | {:.1} % |", 100.0 * changed_time);
    println!(
        "| loading a frame (parse, index, light buffer) / full frame | {:.1} % |",
        100.0 * loading.as_secs_f64() / full.as_secs_f64()
    );
    println!();

    // A viewpoint that moves: everything is re-traced, and must cost no
    // more than frames traced whole.
    let text = String::from_utf8_lossy(&bytes)
        .replace("VIEWPOINT 0 3.2 11", "VIEWPOINT 0 3.2 11 MOVE 0 0 0 0  24 6 0 -3  47 0.25 0 -0.125");
    let (mut whole, mut coherent) = (Duration::MAX, Duration::MAX);
    for _ in 0..3 {
        whole = whole.min(play(text.as_bytes(), frames, size, false).0.tracing);
        coherent = coherent.min(play(text.as_bytes(), frames, size, true).0.tracing);
    }
    println!("### A moving viewpoint (anim_fig5_1 with its VIEWPOINT moving too), 640×480, one thread\n");
    println!("| frames traced whole | with coherence (everything re-traced) | ratio |");
    println!("| ---: | ---: | ---: |");
    let (a, b) = (whole / frames.count, coherent / frames.count);
    println!("| {} | {} | {:.2} |\n", ms(a), ms(b), b.as_secs_f64() / a.as_secs_f64());

    // A 240×240 panel: the share, and the memory.
    let text = String::from_utf8_lossy(&bytes).into_owned();
    println!("### anim_fig5_1 on a 240×240 panel: pixels re-traced per frame after the first, by tile side\n");
    println!("| tiles | counts (bytes) | pixels re-traced |");
    println!("| --- | ---: | ---: |");
    for side in [1, 2, 4, 8] {
        let share = share_at(&text, (240, 240), side);
        println!("| {side}×{side} | {} | {:.1} % |", Coherence::tiles_for(240, 240, side), 100.0 * share);
    }
    let needs = AnimationNeeds { tiles: 0, ..AnimationNeeds::of(&text, Size::new(240, 240)) };
    let track = AnimationNeeds { tiles: 0, tracks: 1, keys: 0 }.bytes();
    let key = AnimationNeeds { tiles: 0, tracks: 0, keys: 1 }.bytes();
    println!(
        "\nMotion (one track, {} keys, {} frames): {} bytes ({track} a track, {key} a key, whatever the frames).\n",
        needs.keys,
        frames.count,
        needs.bytes()
    );
    Ok(())
}
