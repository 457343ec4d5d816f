//! Animations: every frame traced with frame-to-frame coherence is the
//! frame traced whole from scratch (`--frame K`), bit for bit, on scenes
//! built so that each kind of dependence matters: an object seen only in a
//! mirror, one seen only by its shadow, one passing through another's
//! shadow, a moving light, a moving viewpoint, a moving B-spline patch, an
//! object seen only through glass, and anim_fig5_1. Each check also runs
//! with the tracking of the dependence its scene needs dropped
//! (`Coherence::ignoring`), and must then fail: the tests see a broken
//! tracker.

use embedded_graphics_core::draw_target::DrawTarget;
use embedded_graphics_core::geometry::{OriginDimensions, Size};
use embedded_graphics_core::pixelcolor::Rgb888;
use embedded_graphics_core::primitives::Rectangle;
use embedded_graphics_core::Pixel;
use octrace_core::animation::{Coherence, Dependence, Key, Motion, Track};
use octrace_core::profile::Host;
use octrace_core::Raytracer;
use octrace_tests::repo;
use std::sync::atomic::AtomicU8;

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

    fn fill_contiguous<I: IntoIterator<Item = Rgb888>>(&mut self, area: &Rectangle, colors: I) -> Result<(), Self::Error> {
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
    let counts: Vec<AtomicU8> = (0..Coherence::tiles_for(SIZE.width, SIZE.height, side)).map(|_| AtomicU8::new(0)).collect();
    let mut coherence = Coherence::new(&counts, SIZE, side).unwrap();
    if let Some(dependence) = ignored {
        coherence = coherence.ignoring(dependence);
    }
    let mut raytracer = Box::new(Raytracer::<Host>::new());
    let first = raytracer.load_frame(text, 0).unwrap();
    let frames = first.frames().expect("an animation");
    let needs = Motion::needs(text);
    let (mut tracks, mut keys, mut table) =
        (vec![Track::EMPTY; needs.tracks], vec![Key::default(); needs.keys], vec![[0; 3]; needs.displacements]);
    let motion = Motion::read(text, frames, &first.view(), 0, &mut tracks, &mut keys, &mut table).unwrap();
    let wholes: Vec<Panel> = frames.all().map(|k| whole(text, k)).collect();
    let mut panel = Panel::new(SIZE);
    let (mut traced, mut pixels) = (0, 0);
    for (step, frame) in frames.all().chain(frames.all()).enumerate() {
        let scene = raytracer.load_frame(text, frame).unwrap();
        coherence.plan();
        if step > 0 {
            traced += coherence.traced_pixels();
            pixels += u64::from(SIZE.width * SIZE.height);
        }
        scene.draw_changes(&motion, frame, &coherence, &mut panel).unwrap();
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
    let text = scene(
        8,
        &format!("{CAMERA}LIGHT 12 0 14 2\n{FLOOR}SPHERE 2 0.6  -3 6 0  MOVE 0 0 0 0  7 6 0 -1\n"),
    );
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
    let text = scene(
        6,
        &format!("{CAMERA}LIGHT 12 3 6 8\n{FLOOR}BSPLINE 2 3 3 3 6 6 {grid}  MOVE 0 -2 0 0  5 2 0.5 -1\n"),
    );
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
    let text = std::fs::read_to_string(repo().join("scenes/anim_fig5_1.txt")).unwrap();
    let share = exact_and_needs("anim_fig5_1", &text, Some(Dependence::Primary));
    assert!(share < 0.5, "{share}");
}
