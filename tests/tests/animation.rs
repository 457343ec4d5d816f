//! Animations: every frame traced with frame-to-frame coherence is the
//! frame traced whole from scratch (`--frame K`), bit for bit, on scenes
//! built so that each kind of dependence matters: an object seen only in a
//! mirror, one seen only by its shadow, one passing through another's
//! shadow, a moving light, a moving viewpoint, a moving B-spline patch, an
//! object seen only through glass, and anim_fig5_1. Each check also runs
//! with the tracking of the dependence its scene needs dropped
//! (`Animation::ignoring`), and must then fail: the tests see a broken
//! tracker.

use embedded_graphics_core::draw_target::DrawTarget;
use embedded_graphics_core::geometry::{OriginDimensions, Size};
use embedded_graphics_core::pixelcolor::Rgb888;
use embedded_graphics_core::primitives::Rectangle;
use embedded_graphics_core::Pixel;
use octrace_core::animation::{AnimationNeeds, Coherence, Dependence, HostAnimationRoom};
use octrace_core::profile::Host;
use octrace_core::Raytracer;
use octrace_tests::scene_path;

/// A framebuffer: what a panel shows.
#[derive(Clone, PartialEq, Eq)]
struct Panel {
    size: Size,
    pixels: Vec<Rgb888>,
}

impl Panel {
    fn new(size: Size) -> Panel {
        Panel { size, pixels: vec![Rgb888::new(1, 2, 3); (size.width * size.height) as usize] }
    }
}

impl OriginDimensions for Panel {
    fn size(&self) -> Size {
        self.size
    }
}

impl DrawTarget for Panel {
    type Color = Rgb888;
    type Error = core::convert::Infallible;

    fn draw_iter<I: IntoIterator<Item = Pixel<Rgb888>>>(&mut self, pixels: I) -> Result<(), Self::Error> {
        for Pixel(p, c) in pixels {
            self.pixels[(p.y as u32 * self.size.width + p.x as u32) as usize] = c;
        }
        Ok(())
    }

    fn fill_contiguous<I: IntoIterator<Item = Rgb888>>(
        &mut self,
        area: &Rectangle,
        colors: I,
    ) -> Result<(), Self::Error> {
        let mut colors = colors.into_iter();
        for y in area.rows() {
            for x in area.columns() {
                if let Some(c) = colors.next() {
                    self.pixels[(y as u32 * self.size.width + x as u32) as usize] = c;
                }
            }
        }
        Ok(())
    }
}

const SIZE: Size = Size::new(48, 36);

/// Frame `frame` of `text` traced whole, from scratch.
fn whole(text: &str, frame: u32) -> Panel {
    let mut raytracer = Box::new(Raytracer::<Host>::new());
    let scene = raytracer.load_frame(text, frame).unwrap_or_else(|e| panic!("frame {frame}: {e}"));
    let mut panel = Panel::new(SIZE);
    let image = scene.image::<Rgb888>(SIZE);
    embedded_graphics_core::Drawable::draw(
        &embedded_graphics::image::Image::new(&image, embedded_graphics_core::geometry::Point::zero()),
        &mut panel,
    )
    .unwrap();
    panel
}

/// The loop played twice with coherence (tiles of `side`, `ignored`
/// dropped): the first frame whose panel is not the frame traced whole,
/// and the share of pixels re-traced after the first frame.
fn play(text: &str, side: u32, ignored: Option<Dependence>) -> (Option<u32>, f64) {
    let tiles = Coherence::tiles_for(SIZE.width, SIZE.height, side);
    let mut room = HostAnimationRoom::new(AnimationNeeds { tiles, ..AnimationNeeds::of(text, SIZE) });
    let mut animation = room.animation_in_tiles(SIZE, side).unwrap();
    if let Some(dependence) = ignored {
        animation = animation.ignoring(dependence);
    }
    let mut raytracer = Box::new(Raytracer::<Host>::new());
    let frames = raytracer.load(text).unwrap().frames().expect("an animation");
    let wholes: Vec<Panel> = frames.all().map(|k| whole(text, k)).collect();
    let mut panel = Panel::new(SIZE);
    let (mut traced, mut pixels) = (0, 0);
    for (step, frame) in frames.all().chain(frames.all()).enumerate() {
        let loaded = animation.load(&mut raytracer, text, frame).unwrap();
        if step > 0 {
            traced += loaded.tiles().traced_pixels();
            pixels += u64::from(SIZE.width * SIZE.height);
        }
        loaded.image_for(&panel).try_draw(&mut panel).unwrap();
        if panel != wholes[frame as usize] {
            return (Some(frame), 0.0);
        }
    }
    (None, traced as f64 / pixels.max(1) as f64)
}

const SURFACES: &str = "SURFACE 1 .1 .1 .1 .6 .6 .5 .3 .3 .3 10 0 0\n\
                        SURFACE 2 .1 0 0 .8 .1 .1 .5 .5 .5 40 0 0\n\
                        SURFACE 3 0 0 0 .05 .05 .05 1 1 1 100 .9 0\n\
                        SURFACE 4 0 0 0 .05 .05 .05 .9 .9 .9 100 .05 .85\n";
const FLOOR: &str = "RECTANGLE 1  -8 -1 6  8 -1 6  8 -1 -10  -8 -1 -10\n";
const CAMERA: &str = "VIEWPOINT 0 2 9\nORIGIN 0 0 0\nBACKGROUND .1 .15 .2\n";

/// An animation of `frames` frames: `body` after the surfaces.
fn scene(frames: u32, body: &str) -> String {
    format!("FRAMES {frames}\n{SURFACES}{body}")
}

/// Checks `text` is exact with every dependence tracked, and that it is not
/// with `needed` dropped; returns the share re-traced.
fn exact_and_needs(name: &str, text: &str, needed: Option<Dependence>) -> f64 {
    let (wrong, share) = play(text, 4, None);
    assert_eq!(wrong, None, "{name}: a frame differs from the frame traced whole");
    if let Some(dependence) = needed {
        let (broken, _) = play(text, 4, Some(dependence));
        assert!(broken.is_some(), "{name}: still exact without tracking {dependence:?}: the test cannot see it");
    }
    println!("{name}: exact, {:.1} % of the pixels re-traced after the first frame", 100.0 * share);
    share
}

#[test]
fn an_object_seen_only_in_a_mirror() {
    // The ball moves behind the camera: the mirror shows it.
    let text = scene(
        8,
        &format!(
            "{CAMERA}LIGHT 10 3 6 8\n{FLOOR}RECTANGLE 3 -4 -1 -3  4 -1 -3  4 4 -3  -4 4 -3\n\
             SPHERE 2 0.8  -3 0.5 12  MOVE 0 0 0 0  7 6 0 0\n"
        ),
    );
    let share = exact_and_needs("mirror", &text, Some(Dependence::Reflected));
    assert!(share < 0.9, "the ball only moves in the mirror: {share}");
}

#[test]
fn an_object_seen_only_by_its_shadow() {
    // The ball moves above the picture; its shadow crosses the floor.
    let text = scene(8, &format!("{CAMERA}LIGHT 12 0 14 2\n{FLOOR}SPHERE 2 0.6  -3 6 0  MOVE 0 0 0 0  7 6 0 -1\n"));
    exact_and_needs("shadow", &text, Some(Dependence::Shadows));
}

#[test]
fn an_object_passing_through_anothers_shadow() {
    let text = scene(
        8,
        &format!(
            "{CAMERA}LIGHT 12 -2 8 4\n{FLOOR}BOX 1 0 1.5 0  0.6 0.6 0.6\n\
             SPHERE 2 0.5  -3 -0.5 -1.5  MOVE 0 0 0 0  7 6 0 0\n"
        ),
    );
    exact_and_needs("through a shadow", &text, Some(Dependence::Primary));
}

#[test]
fn a_moving_light() {
    let text = scene(
        6,
        &format!("{CAMERA}LIGHT 12 -5 6 4 MOVE 0 0 0 0  5 10 0 -4\n{FLOOR}SPHERE 2 1 0 0 0\nBOX 1 2.5 0 -1 .5 1 .5\n"),
    );
    exact_and_needs("light", &text, Some(Dependence::Lights));
}

#[test]
fn a_moving_viewpoint() {
    let text = scene(
        6,
        "VIEWPOINT 0 2 9 MOVE 0 0 0 0  5 6 1 -3\nORIGIN 0 0 0\nLIGHT 12 3 6 8\nRECTANGLE 1 -8 -1 6 8 -1 6 8 -1 -10 -8 -1 -10\n\
         SPHERE 2 1 0 0 0\n",
    );
    let share = exact_and_needs("viewpoint", &text, Some(Dependence::Camera));
    assert!(share > 0.99, "everything, when the viewpoint moves: {share}");
}

#[test]
fn a_moving_bspline_patch() {
    let grid = "-2 0 -2  0 1 -2  2 0 -2   -2 1 0  0 2.5 0  2 1 0   -2 0 2  0 1 2  2 0 2";
    let text =
        scene(6, &format!("{CAMERA}LIGHT 12 3 6 8\n{FLOOR}BSPLINE 2 3 3 3 6 6 {grid}  MOVE 0 -2 0 0  5 2 0.5 -1\n"));
    exact_and_needs("B-spline", &text, Some(Dependence::Primary));
}

#[test]
fn an_object_seen_only_through_glass() {
    // A pane of glass fills the view; the ball moves behind it.
    let text = scene(
        6,
        &format!(
            "{CAMERA}LIGHT 12 3 6 8\n{FLOOR}BOX 4 0 1 4  9 6 0.2\n\
             SPHERE 2 0.8  -2 0 -2  MOVE 0 0 0 0  5 4 0 0\n"
        ),
    );
    exact_and_needs("glass", &text, Some(Dependence::Transmitted));
}

#[test]
fn anim_fig5_1_is_exact_and_saves_most_of_the_tracing() {
    let text = std::fs::read_to_string(scene_path("anim_fig5_1")).unwrap();
    let share = exact_and_needs("anim_fig5_1", &text, Some(Dependence::Primary));
    assert!(share < 0.5, "{share}");
}

/// host-sim's command line as a program (`tests/src/bin/host-sim-cli.rs`).
const HOST_SIM: &str = env!("CARGO_BIN_EXE_host-sim-cli");

/// Runs host-sim with `args` in `dir`: exit code and standard error.
fn host_sim(dir: &std::path::Path, args: &[&str]) -> (i32, String) {
    let output = std::process::Command::new(HOST_SIM)
        .args(args)
        .current_dir(dir)
        .env_remove("SLURM_ARRAY_TASK_ID")
        .env_remove("JOB_COMPLETION_INDEX")
        .output()
        .expect("host-sim-cli runs");
    (output.status.code().unwrap_or(-1), String::from_utf8_lossy(&output.stderr).into_owned())
}

fn files(dir: &std::path::Path) -> Vec<String> {
    let mut names: Vec<String> =
        std::fs::read_dir(dir).unwrap().map(|e| e.unwrap().file_name().to_string_lossy().into_owned()).collect();
    names.sort();
    names
}

/// A small animation of fig5_1 in `dir` (40×30, the first 8 frames' motion
/// in 8 frames).
fn small_animation(dir: &std::path::Path) -> std::path::PathBuf {
    let text = std::fs::read_to_string(scene_path("anim_fig5_1")).unwrap();
    let text = text.replace("FRAMES 48 24", "FRAMES 8 12").replace("RASTER    240 180", "RASTER 40 30");
    let text = text
        .replace("MOVE   0    0     0  0", "MOVE   0    0     0  0  7 -3 0 -3 MOVE")
        .replace("MOVE\n      10", "/* cut */ FRAMES 1 /*");
    // The scene keeps its first key and gains one at frame 7; the rest of
    // the path is cut out.
    let start = text.find("/* cut */").unwrap();
    let end = text.find("SPHERE 3").unwrap();
    let text = format!("{}\n{}", &text[..start], &text[end..]);
    let path = dir.join("anim.txt");
    std::fs::write(&path, text).unwrap();
    path
}

#[test]
fn a_gif_that_cannot_keep_the_rate_says_so_even_when_quiet() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let text = std::fs::read_to_string(small_animation(d)).unwrap();
    std::fs::write(d.join("fast.txt"), text.replace("FRAMES 8 12", "FRAMES 8 100")).unwrap();
    let note = "fast.gif at 100 frames a second plays its loop in 0.16 s, not 0.08 s";
    let (code, err) = host_sim(d, &["fast.txt", "fast.gif", "-q"]);
    assert!(code == 0 && err.contains(note), "{err}");
    // Frames merged into one: the same; at a rate a GIF keeps, nothing.
    assert_eq!(host_sim(d, &["fast.txt", "f%d.png", "-q"]).0, 0);
    let frames: Vec<String> = (0..8).map(|k| format!("f{k}.png")).collect();
    let args: Vec<&str> = ["merge", "fast.gif"].into_iter().chain(frames.iter().map(String::as_str)).collect();
    let (code, err) = host_sim(d, &args);
    assert!(code == 0 && err.contains(note), "{err}");
    let (code, err) = host_sim(d, &["anim.txt", "a.gif", "-q"]);
    assert!(code == 0 && err.is_empty(), "{err}");
}

#[test]
fn host_sim_writes_gif_apng_and_frame_files_identical_to_single_frames() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    small_animation(d);
    for (out, extra) in [("a.gif", &[][..]), ("b.gif", &["--no-coherence"][..]), ("c.gif", &["--threads", "3"][..])] {
        let args: Vec<&str> = ["anim.txt", out, "-q"].iter().copied().chain(extra.iter().copied()).collect();
        let (code, err) = host_sim(d, &args);
        assert_eq!(code, 0, "{err}");
    }
    let gif = std::fs::read(d.join("a.gif")).unwrap();
    assert_eq!(gif, std::fs::read(d.join("b.gif")).unwrap(), "coherence against every frame whole");
    assert_eq!(gif, std::fs::read(d.join("c.gif")).unwrap(), "one thread against three");
    // Frame files, truecolour: each the still `--frame K` writes.
    assert_eq!(host_sim(d, &["anim.txt", "f%02d.png", "-q"]).0, 0);
    for k in 0..8 {
        let still = format!("still{k}.png");
        assert_eq!(host_sim(d, &["anim.txt", &still, "--frame", &k.to_string(), "-q"]).0, 0);
        let frame = octrace_images::formats::read(&std::fs::read(d.join(format!("f{k:02}.png"))).unwrap()).unwrap();
        let still = octrace_images::formats::read(&std::fs::read(d.join(still)).unwrap()).unwrap();
        assert_eq!(frame.to_rgb(), still.to_rgb(), "frame {k}");
    }
    // The APNG's frames are the frame files' pixels; after the first, each
    // stores only the rectangle that changed.
    assert_eq!(host_sim(d, &["anim.txt", "a.png", "-q"]).0, 0);
    let (frames, areas) = apng_frames(&std::fs::read(d.join("a.png")).unwrap());
    assert_eq!(frames.len(), 8);
    for (k, frame) in frames.iter().enumerate() {
        let file = octrace_images::formats::read(&std::fs::read(d.join(format!("f{k:02}.png"))).unwrap()).unwrap();
        assert_eq!(frame, &file.to_rgb().data, "APNG frame {k}");
    }
    assert_eq!(areas[0], 40 * 30);
    assert!(areas[1..].iter().all(|&a| a < 40 * 30 / 2), "{areas:?}");
}

/// An APNG's frames as shown (each region blended over the frame
/// before, its pixels of the `tRNS` colour transparent), RGB, with each
/// stored region's pixels; it loops forever.
fn apng_frames(bytes: &[u8]) -> (Vec<Vec<u8>>, Vec<u32>) {
    let mut decoder = png::Decoder::new(std::io::Cursor::new(bytes));
    decoder.set_transformations(png::Transformations::IDENTITY);
    let mut reader = decoder.read_info().unwrap();
    let info = reader.info();
    let (w, count) = (info.width as usize, info.animation_control().map(|a| (a.num_frames, a.num_plays)));
    assert_eq!(info.color_type, png::ColorType::Rgb);
    // The tRNS colour, as 16-bit samples or already cut to 8 bits.
    let key: Option<Vec<u8>> = info.trns.as_ref().map(|t| match t.len() {
        6 => t.chunks(2).map(|v| v[1]).collect(),
        _ => t.to_vec(),
    });
    let (count, plays) = count.expect("an APNG");
    assert_eq!(plays, 0, "loops forever");
    let mut canvas = vec![0u8; 3 * w * info.height as usize];
    let mut buffer = vec![0; reader.output_buffer_size().unwrap()];
    let (mut frames, mut areas) = (Vec::new(), Vec::new());
    for _ in 0..count {
        let out = reader.next_frame(&mut buffer).unwrap();
        let control = *reader.info().frame_control().expect("fcTL");
        let (x0, y0) = (control.x_offset as usize, control.y_offset as usize);
        for y in 0..out.height as usize {
            for x in 0..out.width as usize {
                let p = &buffer[3 * (y * out.width as usize + x)..][..3];
                let transparent = key.as_deref() == Some(p);
                assert!(!transparent || control.blend_op == png::BlendOp::Over, "a transparent pixel is blended");
                if !transparent {
                    let at = 3 * ((y0 + y) * w + x0 + x);
                    canvas[at..at + 3].copy_from_slice(p);
                }
            }
        }
        frames.push(canvas.clone());
        areas.push(out.width * out.height);
    }
    (frames, areas)
}

#[test]
fn frames_rendered_apart_merge_into_the_same_gif() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    small_animation(d);
    assert_eq!(host_sim(d, &["anim.txt", "whole.gif", "--palette", "dither", "-q"]).0, 0);
    for part in ["1/3", "2/3", "3/3"] {
        let (code, err) = host_sim(d, &["anim.txt", "p%d.png", "--part", part, "--palette", "dither", "-q"]);
        assert_eq!(code, 0, "{err}");
    }
    let frames: Vec<String> = (0..8).map(|k| format!("p{k}.png")).collect();
    let mut args = vec!["merge", "merged.gif"];
    args.extend(frames.iter().rev().map(String::as_str));
    let (code, err) = host_sim(d, &args);
    assert_eq!(code, 0, "{err}");
    assert_eq!(std::fs::read(d.join("merged.gif")).unwrap(), std::fs::read(d.join("whole.gif")).unwrap());
    // `--color dither` is `--palette dither`, for a loop as for a still.
    assert_eq!(host_sim(d, &["anim.txt", "color.gif", "--color", "dither", "-q"]).0, 0);
    assert_eq!(std::fs::read(d.join("color.gif")).unwrap(), std::fs::read(d.join("whole.gif")).unwrap());
    // Truecolour frames, merged into a GIF whose colours are chosen for
    // the whole loop: the direct render's file (which knew the tiles each
    // frame re-traced; merge compares the frames).
    assert_eq!(host_sim(d, &["anim.txt", "loop.gif", "-q"]).0, 0);
    for part in ["1/2", "2/2"] {
        assert_eq!(host_sim(d, &["anim.txt", "t%d.png", "--part", part, "-q"]).0, 0);
    }
    let mut args = vec!["merge", "merged-loop.gif"];
    let frames: Vec<String> = (0..8).map(|k| format!("t{k}.png")).collect();
    args.extend(frames.iter().map(String::as_str));
    let (code, err) = host_sim(d, &args);
    assert_eq!(code, 0, "{err}");
    assert_eq!(std::fs::read(d.join("merged-loop.gif")).unwrap(), std::fs::read(d.join("loop.gif")).unwrap());
    // A frame missing, or twice: refused, nothing written.
    let (code, err) = host_sim(d, &["merge", "bad.gif", "p0.png", "p1.png", "p3.png"]);
    assert_eq!(code, 2, "{err}");
    assert!(err.contains("frames 2, 4 to 7 missing (the animation has 8 frames)"), "{err}");
    let (code, err) = host_sim(d, &["merge", "bad.gif", "p0.png", "p0.png", "p1.png"]);
    assert!(code == 2 && err.contains("frame 0 is given twice: p0.png and p0.png"), "{err}");
    assert!(!d.join("bad.gif").exists());
    // Frames into a still's format, or with a still's band part.
    let (code, err) = host_sim(d, &["merge", "bad.tga", "p0.png", "p1.png"]);
    assert!(code == 2 && err.contains("frames merge into an animated GIF (.gif) or an APNG (.png)"), "{err}");
    // An animation's name with a --format that contradicts it: the --format is named.
    let (code, err) = host_sim(d, &["merge", "bad.gif", "p0.png", "p1.png", "--format", "tga"]);
    let want = "--format tga: bad.gif is written as an animated GIF; --format chooses the format of frame files";
    assert!(code == 2 && err.contains(want), "{err}");
    assert_eq!(host_sim(d, &["anim.txt", "band.png", "--frame", "0", "--part", "1/2", "-q"]).0, 0);
    let (code, err) = host_sim(d, &["merge", "bad.png", "p0.png", "band.png"]);
    assert!(code == 2 && err.contains("p0.png is an animation's frame file and band.png not a frame file"), "{err}");
    // A file that is not there is said so (exit 1), not taken for a kind of
    // file; a still's band parts are not a GIF's.
    let (code, err) = host_sim(d, &["merge", "bad.gif", "p0.png", "p1.pgn"]);
    assert!(code == 1 && err.contains("cannot read p1.pgn: No such file"), "{err}");
    let (code, err) = host_sim(d, &["merge", "bad.gif", "band.png"]);
    assert!(code == 2 && err.contains("a still's band parts merge into a PNG, Targa or Sun raster image"), "{err}");
    // A frame of another render says how it differs.
    assert_eq!(host_sim(d, &["anim.txt", "small%d.png", "--size", "4x3", "-q"]).0, 0);
    let (code, err) = host_sim(d, &["merge", "bad.gif", "p0.png", "small1.png"]);
    assert!(code == 2 && err.contains("small1.png is not a frame of the animation of p0.png: another size"), "{err}");
    assert!(!d.join("bad.tga").exists() && !d.join("bad.png").exists() && !d.join("bad.gif").exists());
}

#[test]
fn animation_errors_name_the_place_and_leave_no_file() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    small_animation(d);
    let before = files(d);
    // A GIF without a colour table, a still format, --frame out of range.
    for (args, message) in [
        (&["anim.txt", "x.gif", "--palette", "none"][..], "a GIF holds 256 colours"),
        (&["anim.txt", "x.tga"][..], "--frame K renders one frame"),
        (&["anim.txt", "x.png", "--frame", "8"][..], "has 8 frames, 0 to 7"),
        (&["anim.txt", "x.gif", "--part", "1/2"][..], "--part splits an animation's frames"),
        (&["anim.txt", "x.gif", "--format", "tga"][..], "is written as an animated GIF"),
        (&["anim.txt", "x.png", "--format", "ras"][..], "is written as an APNG"),
        (&["anim.txt", "f%d.png", "--format", "tga"][..], "--format tga: f0.png names a PNG file"),
        (&["anim.txt", "x.png", "--frame", "1", "--no-coherence"][..], "--frame 1 traces that frame alone, whole"),
        (&["anim.txt", "x.gif", "--accel", "naive", "--max-depth", "3"][..], "--max-depth shapes the octree"),
    ] {
        let (code, err) = host_sim(d, args);
        assert_eq!(code, 2, "{args:?}: {err}");
        assert!(err.contains(message), "{args:?}: {err}");
    }
    // A camera lost at frame 6 only: every file of the run goes. A frame
    // asked for alone, or a band of one, is refused alike: the scene is
    // valid or not whichever frame is drawn.
    let text = std::fs::read_to_string(d.join("anim.txt")).unwrap();
    let lost = text.replace("ORIGIN    0 0.6 0", "ORIGIN    0 0.6 0 MOVE 0 0 0 0  6 0 2.6 11");
    std::fs::write(d.join("lost.txt"), lost).unwrap();
    for args in [
        &["lost.txt", "y.gif"][..],
        &["lost.txt", "y%d.png"],
        &["lost.txt", "y.png", "--frame", "0"],
        &["lost.txt", "y.png", "--frame", "0", "--part", "1/2"],
    ] {
        let (code, err) = host_sim(d, args);
        assert_eq!(code, 2, "{args:?}: {err}");
        // ORIGIN reaches VIEWPOINT within a unit of rounding: no view, or
        // one along UPVECTOR. Found as frame 0 loads, which checks every
        // frame's camera before any is drawn (the message names the frame,
        // the summary no other).
        let found = err.contains("lost.txt:9:19: at frame 6, ") && err.contains("in lost.txt; nothing rendered");
        assert!(found, "{args:?}: {err}");
    }
    let mut after = files(d);
    after.retain(|f| f != "lost.txt");
    assert_eq!(after, before, "no file left behind");
}

#[test]
fn the_gnu_parallel_frames_recipe_gives_the_single_render() {
    let found = std::process::Command::new("parallel").arg("--version").output().is_ok_and(|o| o.status.success());
    if !found {
        assert!(std::env::var("CI").as_deref() != Ok("true"), "GNU parallel is missing (apt-get install parallel)");
        println!("SKIPPED: GNU parallel is not installed (apt-get install parallel): the recipe was not run");
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    std::fs::create_dir_all(dir.path().join("scenes")).unwrap();
    // The recipe's scene, small: quick in CI.
    let small = small_animation(dir.path());
    std::fs::rename(&small, dir.path().join("scenes/anim_fig5_1.txt")).unwrap();
    octrace_tests::run_recipe(&octrace_tests::recipe("parallel-frames"), dir.path(), HOST_SIM);
    let (code, err) = host_sim(dir.path(), &["scenes/anim_fig5_1.txt", "single.gif", "-q"]);
    assert_eq!(code, 0, "{err}");
    let merged = std::fs::read(dir.path().join("anim_fig5_1.gif")).unwrap();
    assert_eq!(merged, std::fs::read(dir.path().join("single.gif")).unwrap());
    assert_eq!(files(dir.path()), ["anim_fig5_1.gif", "bin", "scenes", "single.gif"]);
}
