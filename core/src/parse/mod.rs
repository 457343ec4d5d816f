//! The scene-format parser: text in, a normalised [`Scene`] out, or every
//! error with its line and column.
//!
//! It reads the text twice, allocating nothing (the text may live in flash):
//! 1. the *survey* gathers the surfaces and the world-space extent of objects,
//!    eye and lights, which fixes the [`Normalization`](crate::scene::Normalization)
//!    (see `survey.rs`);
//! 2. the *build* reads every statement again, reports every error, and
//!    stores the objects in normalised space.
//!
//! After an error the parser skips to where the next statement begins (a
//! keyword, or a word opening a line) and goes on, so one run reports every
//! line's error. A scene with errors is cleared: nothing can be rendered
//! from it.
//!
//! No-panic contract: for any input text, [`parse`] returns (it neither
//! panics nor loops), in time linear in the text's length plus
//! O(objects · log surfaces), and for a moving camera (checked at every
//! frame) O(frames).

mod error;
mod keyword;
mod lexer;
mod motion;
mod number;
mod statement;
mod statements;
mod survey;

pub use error::{escaped_in_messages, ErrorKind, Field, Found, ParseError, Pos, Rule};
pub(crate) use motion::{for_each_move, MotionSink, Moved, Mover};

pub(crate) use statement::{Keys, Statement};

use crate::capacity::{CapacityError, CapacityKind, Counts};
use crate::scene::motion::KeyWalk;
use crate::scene::{displacement_at, Camera, CameraError, Frames, Light, Scene, SceneCapacities, WorldPoint};
use crate::shapes::{AxisAlignedBox, Rectangle, ShapeKind, Sphere, Superquadric, Triangle};

use keyword::{Keyword, KeywordSet};
use motion::{for_each_paired, MovedObjects, Paired};
use statement::{AnyRoom, Patch, RoomOf};
use statements::for_each_statement;
use survey::{survey, Survey};

/// What the parse found besides the scene.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Parsed<'a> {
    /// The IMAGEFILE name, if given.
    pub imagefile: Option<&'a str>,
    /// FRAMES, if given: the scene is an animation.
    pub frames: Option<Frames>,
}

/// Every statement keyword of the format, in the format's order, with how
/// many arguments follow it (for `BSPLINE`, those before its 3 × rows ×
/// cols control point coordinates). For editors that find statements in
/// scene text without parsing it, such as the studio's page.
///
/// ```
/// use octrace_core::parse::statement_arities;
///
/// let sphere = statement_arities().find(|&(keyword, _)| keyword == "SPHERE");
/// assert_eq!(sphere, Some(("SPHERE", 5)));
/// ```
pub fn statement_arities() -> impl Iterator<Item = (&'static str, usize)> {
    Keyword::ALL.into_iter().map(|keyword| (keyword.name(), keyword.arity()))
}

/// Parses `bytes`, reporting invalid UTF-8 as an error at the first bad byte.
// Not inlined: a board may run the loader's indexing from RAM, and the
// parser (long, run once a scene) stays where the linker puts its module.
#[inline(never)]
pub fn parse_bytes<'a, C: SceneCapacities>(
    bytes: &'a [u8],
    scene: &mut Scene<C>,
    on_error: &mut dyn FnMut(ParseError<'a>),
) -> Result<Parsed<'a>, usize> {
    parse_frame_bytes(bytes, scene, 0, on_error)
}

/// [`parse_frame`] from bytes, as [`parse_bytes`] reads them.
#[inline(never)]
pub fn parse_frame_bytes<'a, C: SceneCapacities>(
    bytes: &'a [u8],
    scene: &mut Scene<C>,
    frame: u32,
    on_error: &mut dyn FnMut(ParseError<'a>),
) -> Result<Parsed<'a>, usize> {
    parse_recording(bytes, scene, frame, on_error, None)
}

/// [`parse_frame_bytes`], handing each moving statement to `motion` once
/// placed, if given; then the camera of every frame is checked, not only
/// this one's (an animation is refused whole, before any frame plays).
#[inline(never)]
pub(crate) fn parse_recording<'a, C: SceneCapacities>(
    bytes: &'a [u8],
    scene: &mut Scene<C>,
    frame: u32,
    on_error: &mut dyn FnMut(ParseError<'a>),
    motion: Option<&mut dyn MotionSink>,
) -> Result<Parsed<'a>, usize> {
    match scene_text(bytes) {
        Ok(text) => parse_in(text, scene, frame, on_error, motion),
        Err(e) => {
            scene.clear();
            on_error(e);
            Err(1)
        }
    }
}

/// `bytes` as a scene's text, or the error at its first byte that is not
/// UTF-8 (the format is UTF-8 throughout, comments too): what a build
/// script that embeds a scene file reports.
///
/// ```
/// use octrace_core::parse::scene_text;
///
/// assert_eq!(scene_text(b"RDEPTH 2\n"), Ok("RDEPTH 2\n"));
/// let error = scene_text(b"RDEPTH 2\n// caf\xe9\n").unwrap_err();
/// assert_eq!(error.to_string(), "2:7: the file is not valid UTF-8 (invalid byte here)");
/// ```
pub fn scene_text(bytes: &[u8]) -> Result<&str, ParseError<'static>> {
    core::str::from_utf8(bytes).map_err(|e| {
        // The valid prefix is UTF-8; its lines end as the lexer's do.
        let good = core::str::from_utf8(&bytes[..e.valid_up_to()]).unwrap_or_default();
        ParseError::new(lexer::Lexer::end_of(good), ErrorKind::InvalidUtf8)
    })
}

/// Parses `text` into `scene` (cleared first). Every error goes to
/// `on_error`; the result is the number of errors if there were any.
///
/// ```
/// use octrace_core::{parse::parse, profile::Board16K, scene::Scene};
///
/// let mut scene = Scene::<Board16K>::new();
/// let good = "SURFACE 1 .1 .1 .1 .7 .2 .2 0 0 0 1 0 0\nSPHERE 1 1 0 0 0\nIMAGEFILE ball.png\n";
/// let parsed = parse(good, &mut scene, &mut |e| panic!("{e}")).unwrap();
/// assert_eq!(parsed.imagefile, Some("ball.png"));
/// assert_eq!(scene.view().object_count(), 1);
///
/// // Every error is reported with its line and column; the scene is left empty.
/// let mut messages = Vec::new();
/// let bad = "SURFACE 1 .1 .1 .1 .7 .2 .2 0 0 0 1 0 0\nSPHERE 1 -1 0 0 0\nCONE 1\n";
/// let errors = parse(bad, &mut scene, &mut |e| messages.push(e.to_string())).unwrap_err();
/// assert_eq!(errors, 2);
/// assert!(messages[0].starts_with("2:10: SPHERE radius must be > 0"), "{messages:?}");
/// assert!(messages[1].starts_with("3:1: unknown keyword `CONE`"), "{messages:?}");
/// assert_eq!(scene.view().object_count(), 0);
/// ```
pub fn parse<'a, C: SceneCapacities>(
    text: &'a str,
    scene: &mut Scene<C>,
    on_error: &mut dyn FnMut(ParseError<'a>),
) -> Result<Parsed<'a>, usize> {
    parse_frame(text, scene, 0, on_error)
}

/// Parses frame `frame` of an animation (a scene with `FRAMES`): each
/// statement that a `MOVE` follows stands displaced as its keys say at that
/// frame. A scene without `FRAMES` is the same at every frame, as
/// [`parse`] reads it; a frame beyond the last has the last frame's
/// displacements. Every frame of a scene is normalised alike (from the
/// extent over all its frames), so frames share their bits.
///
/// ```
/// use octrace_core::{parse::parse_frame, profile::Board16K, scene::Scene};
///
/// let text = "FRAMES 5\nSURFACE 1 .1 .1 .1 .7 .2 .2 0 0 0 1 0 0\n\
///             SPHERE 1 1  0 0 0  MOVE 0 0 0 0  4 8 0 0\nSPHERE 1 1  0 3 0\n";
/// let mut scene = Scene::<Board16K>::new();
/// let mut x = |frame| {
///     let parsed = parse_frame(text, &mut scene, frame, &mut |e| panic!("{e}")).unwrap();
///     assert_eq!(parsed.frames.map(|f| (f.count, f.rate)), Some((5, 24)));
///     let [moving, still] = [0, 1].map(|i| scene.view().spheres[i].center);
///     (moving.x - still.x).to_bits()
/// };
/// // 2 units a frame, in the scene's normalised units.
/// let step = x(1) - x(0);
/// assert_eq!([x(0), x(2), x(4)], [0, 2 * step, 4 * step]);
/// ```
pub fn parse_frame<'a, C: SceneCapacities>(
    text: &'a str,
    scene: &mut Scene<C>,
    frame: u32,
    on_error: &mut dyn FnMut(ParseError<'a>),
) -> Result<Parsed<'a>, usize> {
    parse_in(text, scene, frame, on_error, None)
}

/// [`parse_frame`], and with `motion`, [`parse_recording`]'s.
fn parse_in<'a, C: SceneCapacities>(
    text: &'a str,
    scene: &mut Scene<C>,
    frame: u32,
    on_error: &mut dyn FnMut(ParseError<'a>),
    motion: Option<&mut dyn MotionSink>,
) -> Result<Parsed<'a>, usize> {
    scene.clear();
    let Survey { needed, frames, failed } = survey(text, scene);
    let mut build = Build {
        scene,
        needed,
        failed,
        parsed: Parsed { imagefile: None, frames },
        frame,
        first: [None; Keyword::COUNT],
        camera_move: None,
        camera_keys: [None; 2],
        errors: 0,
        reported_capacity: 0,
        on_error,
        motion,
    };
    for_each_paired::<RoomOf<C>>(text, |paired| match paired {
        Paired::Statement { pos, statement, moved } => build.apply(pos, statement, moved),
        Paired::Error(e, _) => build.report(e),
        Paired::Stray { pos, after } => match build.parsed.frames {
            None => build.move_without_frames(pos),
            Some(_) => build.report(ParseError::new(pos, ErrorKind::NothingToMove { after })),
        },
    });
    build.check_camera();
    let (errors, parsed) = (build.errors, build.parsed);
    if errors > 0 {
        scene.clear();
        return Err(errors);
    }
    Ok(parsed)
}

/// The IMAGEFILE of `text`, if it names one (its first, as the parser
/// reads it; a scene with errors may name one too), and where the name is
/// written, for a program's errors about the file it names.
///
/// ```
/// use octrace_core::parse::{imagefile, Pos};
///
/// let text = "RASTER 8 8\nIMAGEFILE ball.png SPHERE 1 1 0 0 0";
/// assert_eq!(imagefile(text), Some(("ball.png", Pos { line: 2, column: 11 })));
/// assert_eq!(imagefile("RASTER 8 8"), None);
/// ```
pub fn imagefile(text: &str) -> Option<(&str, Pos)> {
    let mut found = None;
    for_each_statement::<AnyRoom>(text, |_, _, result| {
        if let Ok(Statement::Imagefile(name)) = result {
            found.get_or_insert(name);
        }
    });
    // The name is a slice of the text: its token is the one that starts
    // where it does (found here, on the host's path alone, rather than
    // carried in every board's statements).
    let name = found?;
    let mut lexer = lexer::Lexer::new(text);
    while let Ok(Some(token)) = lexer.next_token() {
        if core::ptr::eq(token.text, name) {
            return Some((name, token.pos));
        }
    }
    None
}

/// What `text` needs of each capacity, counting its valid statements (a
/// B-spline patch at its full grid of triangles): the counts a profile for
/// this scene holds, but for the octree's, which depend on the build (see
/// [`crate::accel::BuildReport::counts`]). Like [`parse`], it never panics.
///
/// ```
/// use octrace_core::{capacity::CapacityKind, parse::count};
///
/// let needed = count("SPHERE 1 1 0 0 0\nSPHERE 1 1 3 0 0\nLIGHT 10 5 5 5\nSURFACE 1 .1 .1 .1 .7 .2 .2 0 0 0 1 0 0\n");
/// assert_eq!((needed.spheres, needed.objects, needed.surfaces), (2, 2, 1));
/// assert_eq!(needed.get(CapacityKind::Lights), 1);
/// ```
pub fn count(text: &str) -> Counts {
    let mut counts = Counts::ZERO;
    for_each_statement::<AnyRoom>(text, |_, _, result| {
        if let Ok(s) = result {
            s.count(&mut counts);
        }
    });
    counts.with_objects()
}

/// A statement's displacement at the frame being built.
#[derive(Clone, Copy)]
struct Offset {
    /// In world units (Q32.32): the camera's.
    world: WorldPoint,
    /// In normalised units (Q16.16, wide): every other statement's.
    normalised: [i64; 3],
    /// The normalised displacement at frame 0, where a B-spline patch is
    /// evaluated.
    first: [i64; 3],
}

impl Offset {
    const NONE: Offset = Offset { world: [0; 3], normalised: [0; 3], first: [0; 3] };

    /// World point `p` displaced.
    fn world_moved(&self, p: WorldPoint) -> WorldPoint {
        [0, 1, 2].map(|a| p[a] + self.world[a])
    }
}

/// Pass 2 state.
struct Build<'s, 'a, 'e, 'm, C: SceneCapacities> {
    scene: &'s mut Scene<C>,
    /// What the whole scene needs, for capacity errors.
    needed: Counts,
    /// Keywords with a statement in error (see [`Survey::failed`]).
    failed: KeywordSet,
    parsed: Parsed<'a>,
    /// The frame being built.
    frame: u32,
    /// Where each once-only parameter was first given, by keyword.
    first: [Option<Pos>; Keyword::COUNT],
    /// Where the MOVE of VIEWPOINT or ORIGIN is, if the camera moves.
    camera_move: Option<Pos>,
    /// The eye's and the point looked at's written places and keys, if
    /// they move (for the check of every frame's camera).
    camera_keys: [Option<(WorldPoint, Keys<'a>)>; 2],
    errors: usize,
    /// Bit set of capacities already reported (one error each is enough),
    /// bit `kind as u8`.
    reported_capacity: u32,
    on_error: &'e mut dyn FnMut(ParseError<'a>),
    /// What records the motion, when an animation is loaded.
    motion: Option<&'m mut dyn MotionSink>,
}

impl<'a, C: SceneCapacities> Build<'_, 'a, '_, '_, C> {
    fn report(&mut self, e: ParseError<'a>) {
        self.errors += 1;
        (self.on_error)(e);
    }

    fn capacity(&mut self, pos: Pos, e: CapacityError) {
        let bit = 1 << e.kind as u8;
        if self.reported_capacity & bit == 0 {
            self.reported_capacity |= bit;
            let needed = Some(self.needed.get(e.kind));
            self.report(ParseError::new(pos, ErrorKind::Capacity(CapacityError { needed, ..e })));
        }
    }

    /// Records a once-only parameter; false (with an error) if it was
    /// given before.
    fn once(&mut self, keyword: Keyword, pos: Pos) -> bool {
        let first = &mut self.first[keyword as usize];
        if let Some(first) = *first {
            let keyword = keyword.name();
            self.report(ParseError::new(pos, ErrorKind::Repeated { keyword, first_line: first.line }));
            return false;
        }
        *first = Some(pos);
        true
    }

    /// A MOVE at `pos` in a scene without FRAMES: an error, unless a FRAMES
    /// with errors of its own is there.
    fn move_without_frames(&mut self, pos: Pos) {
        if !self.failed.contains(Keyword::Frames) {
            self.report(ParseError::new(pos, ErrorKind::MoveWithoutFrames));
        }
    }

    /// The surface index for an object, or an error. Not inlined: one copy
    /// for every kind of object that `place` makes.
    #[inline(never)]
    fn surface(&mut self, keyword: Keyword, number: u32, pos: Pos) -> Option<u16> {
        let found = self.scene.view().surface_index(number);
        // The survey stored every SURFACE, wherever it stands, until the
        // arena was full: with one left out (its capacity error is at the
        // first SURFACE that did not fit, maybe further down than this
        // object), a surface not found is likely that, not an error here.
        // Likewise a SURFACE with errors may be the one meant.
        let overflowed = self.needed.get(CapacityKind::Surfaces) > Scene::<C>::surfaces_full().capacity;
        if found.is_none() && !overflowed && !self.failed.contains(Keyword::Surface) {
            let keyword = keyword.name();
            self.report(ParseError::new(pos, ErrorKind::UndefinedSurface { keyword, number }));
        }
        found
    }

    /// The displacement of `s` at the frame being built, from the MOVE
    /// that follows it once its keys are checked against FRAMES and the
    /// format's range (errors reported; none without a MOVE).
    fn offset(&mut self, s: &Statement<'a>, moved: Option<(Pos, Keys<'a>)>) -> Offset {
        let Some((at, keys)) = moved else { return Offset::NONE };
        if !C::MOTION {
            // Nothing below is linked into a build for a still.
            self.report(ParseError::new(at, ErrorKind::NoMotion { profile: C::NAME }));
            return Offset::NONE;
        }
        let Some(frames) = self.parsed.frames else {
            self.move_without_frames(at);
            return Offset::NONE;
        };
        let limit = (number::LIMIT as i64) << 32;
        let written = s.written_box();
        for key in keys.iter() {
            let kind = if key.frame >= frames.count {
                ErrorKind::FrameBeyond { frame: key.frame, count: frames.count }
            } else if written
                .is_some_and(|(lo, hi)| (0..3).any(|a| lo[a] + key.offset[a] < -limit || hi[a] + key.offset[a] > limit))
            {
                ErrorKind::MovedOutOfRange { keyword: s.keyword().name(), frame: key.frame }
            } else {
                continue;
            };
            self.report(ParseError::new(key.pos, kind));
            return Offset::NONE;
        }
        if let Statement::Viewpoint(p) | Statement::Origin(p) = s {
            self.camera_move.get_or_insert(at);
            self.camera_keys[usize::from(matches!(s, Statement::Origin(_)))] = Some((*p, keys));
        }
        let norm = self.scene.normalization;
        let normalised = || keys.offsets().map(move |(f, d)| (f, d.map(|v| norm.length_wide(v))));
        Offset {
            world: displacement_at(keys.offsets(), self.frame),
            normalised: displacement_at(normalised(), self.frame),
            first: displacement_at(normalised(), 0),
        }
    }

    fn apply(&mut self, pos: Pos, s: Statement<'a>, moved: Option<(Pos, Keys<'a>)>) {
        let keyword = s.keyword();
        if keyword.once_only() && !self.once(keyword, pos) {
            return;
        }
        // One call of `place` whether or not the motion is recorded: it is
        // the parser's largest function, and a board links it once.
        let recorded = moved.filter(|_| self.motion.is_some()).map(|(_, keys)| keys);
        let (errors, objects) = (self.errors, self.scene.view().object_count() as u32);
        let mover = recorded.and(s.mover());
        self.place(pos, s, moved);
        // A statement in error (and with it the scene) is not recorded.
        let (Some(keys), Some(mover), Some(frames), true) =
            (recorded, mover, self.parsed.frames, self.errors == errors)
        else {
            return;
        };
        let view = self.scene.view();
        let placed = objects..view.object_count() as u32;
        let objects = (mover == Mover::Object).then(|| {
            let [mut lo, mut hi] = [[i32::MAX; 3], [i32::MIN; 3]];
            for id in placed.clone() {
                let bounds = view.shape(crate::scene::ObjectId(id)).bounds();
                let (min, max) = (bounds.min.bits(), bounds.max.bits());
                (lo, hi) = ([0, 1, 2].map(|a| lo[a].min(min[a])), [0, 1, 2].map(|a| hi[a].max(max[a])));
            }
            let sphere =
                placed.len() == 1 && view.shape(crate::scene::ObjectId(placed.start)).kind() == ShapeKind::Sphere;
            MovedObjects { bounds: [lo, hi], sphere }
        });
        let moved = Moved { mover, keys, norm: self.scene.normalization, frames, frame: self.frame, objects };
        if let Some(motion) = self.motion.as_mut() {
            motion.moved(&moved);
        }
    }

    /// Places statement `s` (at `pos`, moved by `moved`) in the scene.
    fn place(&mut self, pos: Pos, s: Statement<'a>, moved: Option<(Pos, Keys<'a>)>) {
        let keyword = s.keyword();
        let offset = self.offset(&s, moved);
        let norm = self.scene.normalization;
        let place = |w: WorldPoint| norm.moved(w, offset.normalised);
        let too_small = || ParseError::new(pos, ErrorKind::TooSmall { keyword: keyword.name() });
        let settings = &mut self.scene.settings;
        match s {
            Statement::Viewpoint(p) => settings.view.eye = offset.world_moved(p),
            Statement::Origin(p) => settings.view.look_at = offset.world_moved(p),
            // Read by the survey; a MOVE comes paired with its statement.
            Statement::Frames(_) | Statement::Move(_) => {}
            Statement::Upvector(p) => settings.view.up = p,
            Statement::Raster(r) => settings.raster = r,
            Statement::Viewport(v) => settings.view.viewport = Some(v),
            Statement::Rdepth(d) => settings.rdepth = d,
            Statement::Imagefile(name) => self.parsed.imagefile = Some(name),
            Statement::Background(c) => settings.background = c,
            Statement::Gamma(g) => settings.gamma = g,
            Statement::Attenuation(d) => settings.attenuation = d,
            Statement::Samples(n) => settings.samples = n,
            Statement::Light { brightness, position } => {
                let light = Light { position: place(position), brightness };
                if let Err(e) = self.scene.push_light(light) {
                    self.capacity(pos, e);
                }
            }
            Statement::Surface { number, .. } => {
                let view = self.scene.view();
                match view.surface_index(number).map(|i| view.surfaces[i as usize]) {
                    Some(first) if (first.line, first.column) != (pos.line, pos.column) => {
                        self.report(ParseError::new(pos, ErrorKind::SurfaceRepeated { number, first_line: first.line }))
                    }
                    Some(_) => {}
                    None => self.capacity(pos, Scene::<C>::surfaces_full()),
                }
            }
            Statement::Sphere { surface, radius, center } => {
                let Some(surface) = self.surface(keyword, surface, pos) else {
                    return;
                };
                let radius = norm.length(radius);
                if radius.to_bits() <= 0 {
                    return self.report(too_small());
                }
                let r = self.scene.push_shape(Sphere::new(place(center), radius, surface));
                if let Err(e) = r {
                    self.capacity(pos, e);
                }
            }
            Statement::Box { surface, center, half } => {
                let Some(surface) = self.surface(keyword, surface, pos) else {
                    return;
                };
                let min = place([0, 1, 2].map(|a| center[a] - half[a]));
                let max = place([0, 1, 2].map(|a| center[a] + half[a]));
                if (0..3).any(|a| min.axis(a) >= max.axis(a)) {
                    return self.report(too_small());
                }
                let b = AxisAlignedBox { min, max, surface };
                if let Err(e) = self.scene.push_shape(b) {
                    self.capacity(pos, e);
                }
            }
            Statement::Superquadric { surface, power, center, half } => {
                let Some(surface) = self.surface(keyword, surface, pos) else {
                    return;
                };
                let half =
                    crate::math::Vec3 { x: norm.length(half[0]), y: norm.length(half[1]), z: norm.length(half[2]) };
                if half.bits().iter().any(|&h| h <= 0) {
                    return self.report(too_small());
                }
                let power = crate::math::Scalar::from_bits(statement::q32_to_q16(power.to_bits()) as i32);
                let q = Superquadric::new(place(center), half, power, surface);
                if let Err(e) = self.scene.push_shape(q) {
                    self.capacity(pos, e);
                }
            }
            Statement::Triangle { surface, corners } => {
                let Some(surface) = self.surface(keyword, surface, pos) else {
                    return;
                };
                if Scene::<C>::capacity_of(ShapeKind::Triangle) == 0 {
                    return self.capacity(pos, Scene::<C>::full(CapacityKind::Triangles, 0));
                }
                let Some(t) = Triangle::new(corners.map(place), surface) else {
                    return self.report(too_small());
                };
                if let Err(e) = self.scene.push_shape(t) {
                    self.capacity(pos, e);
                }
            }
            Statement::Bspline(patch) => self.bspline(pos, patch, offset),
            Statement::Rectangle { surface, corners } => {
                let Some(surface) = self.surface(keyword, surface, pos) else {
                    return;
                };
                // Checked on the constant before the shape is made (like
                // B-spline patches): a profile without room for rectangles
                // links none of their set-up (see `Room`).
                if Scene::<C>::capacity_of(ShapeKind::Rectangle) == 0 {
                    return self.capacity(pos, Scene::<C>::full(CapacityKind::Rectangles, 0));
                }
                let Some(r) = Rectangle::new(corners.map(place), surface) else {
                    return self.report(too_small());
                };
                if let Err(e) = self.scene.push_shape(r) {
                    self.capacity(pos, e);
                }
            }
        }
    }

    /// A B-spline patch: its triangles' room is checked as a whole before
    /// any is made. A moving patch is evaluated where it stands at frame 0
    /// and its triangles moved from there, whole: it moves rigidly, to the
    /// bit.
    fn bspline(&mut self, pos: Pos, patch: Patch<'a>, offset: Offset) {
        let Patch { surface, order, rows, cols, samples, points } = patch;
        let Some(surface) = self.surface(Keyword::Bspline, surface, pos) else {
            return;
        };
        let triangles = 2 * (samples[0] as usize - 1) * (samples[1] as usize - 1);
        // Checked on the constant first, so that a profile without room for
        // patches (a small board's) compiles no evaluation code at all.
        if Scene::<C>::capacity_of(ShapeKind::SmoothTriangle) == 0 {
            return self.capacity(pos, Scene::<C>::full(CapacityKind::BsplineTriangles, 0));
        }
        if let Err(e) = self.scene.check_room(ShapeKind::SmoothTriangle, triangles) {
            return self.capacity(pos, e);
        }
        let norm = self.scene.normalization;
        if let Err(e) = self.scene.set_control_points(points.iter().map(|p| norm.moved(p, offset.first))) {
            return self.capacity(pos, e);
        }
        // Both places are within the scene's range: so is their difference.
        let shift = crate::math::Vec3::from_bits([0, 1, 2].map(|a| (offset.normalised[a] - offset.first[a]) as i32));
        match self.scene.push_bspline(order, rows, cols, samples, surface, shift) {
            // No triangle: a patch whose control points span a plane in the
            // file, but no longer once placed in the scene's units, is too
            // small for them, as an object of one is.
            Ok(0)
                if !statement::collinear(points.iter())
                    && statement::collinear(points.iter().map(|p| norm.moved(p, offset.first).wide())) =>
            {
                self.report(ParseError::new(pos, ErrorKind::TooSmall { keyword: Keyword::Bspline.name() }))
            }
            Ok(0) => self.report(ParseError::new(
                pos,
                ErrorKind::Degenerate {
                    keyword: Keyword::Bspline.name(),
                    why: "its control points do not span a surface",
                },
            )),
            Ok(_) => {}
            Err(e) => self.capacity(pos, e),
        }
    }

    /// The camera of every frame of an animation that is loaded to play:
    /// the first frame whose camera cannot be set up is an error at the
    /// camera's MOVE, naming the frame, so that nothing of it plays.
    fn check_every_frame(&mut self) {
        let (Some(frames), Some(pos), true) = (self.parsed.frames, self.camera_move, C::MOTION) else { return };
        let mut view = self.scene.settings.view;
        let mut last = None;
        // Each camera key read once over the loop, not once a frame.
        let mut walks =
            self.camera_keys.each_ref().map(|moved| moved.as_ref().map(|(w, k)| (*w, KeyWalk::new(k.offsets()))));
        for frame in 0..frames.count {
            for (i, moved) in walks.iter_mut().enumerate() {
                let Some((written, walk)) = moved else { continue };
                let d = walk.at(frame);
                let point = [0, 1, 2].map(|a| written[a] + d[a]);
                match i {
                    0 => view.eye = point,
                    _ => view.look_at = point,
                }
            }
            // A camera that stands still is checked once.
            if last.replace((view.eye, view.look_at)) == Some((view.eye, view.look_at)) {
                continue;
            }
            if let Err(error) = Camera::check(&view) {
                return self.report(ParseError::new(pos, ErrorKind::MovedCamera { error, frame }));
            }
        }
    }

    /// The camera needs VIEWPOINT ≠ ORIGIN and an UPVECTOR off the view line.
    fn check_camera(&mut self) {
        let at = |keyword: Keyword| self.first[keyword as usize];
        let start = Pos { line: 1, column: 1 };
        let view_pos = at(Keyword::Viewpoint).max(at(Keyword::Origin)).unwrap_or(start);
        match Camera::check(&self.scene.settings.view) {
            Ok(()) if self.motion.is_some() => self.check_every_frame(),
            Ok(()) => {}
            Err(error) if self.camera_move.is_some() => {
                let (pos, frame) = (self.camera_move.unwrap_or(view_pos), self.frame);
                self.report(ParseError::new(pos, ErrorKind::MovedCamera { error, frame }))
            }
            Err(CameraError::EyeAtOrigin) => self.report(ParseError::new(view_pos, ErrorKind::EyeAtOrigin)),
            Err(CameraError::UpParallel) => {
                let pos = at(Keyword::Upvector).unwrap_or(view_pos);
                self.report(ParseError::new(pos, ErrorKind::UpParallel))
            }
        }
    }
}

#[cfg(test)]
mod tests {
    extern crate std;
    use super::*;
    use crate::math::Scalar;
    use crate::profile::Board64K;
    use crate::scene::ObjectId;
    use crate::shapes::ShapeKind;
    use std::format;
    use std::string::{String, ToString};
    use std::vec::Vec;

    type TestScene = Scene<Board64K>;

    crate::profile! {
        /// A board's profile for a still: no motion.
        struct Still { spheres: 1, surfaces: 1, lights: 1 }
        motion: false
    }

    fn load(text: &str) -> (std::boxed::Box<TestScene>, Result<Parsed<'_>, usize>, Vec<String>) {
        let mut scene = std::boxed::Box::new(TestScene::new());
        let mut errors = Vec::new();
        let r = parse(text, &mut scene, &mut |e| errors.push(e.to_string()));
        (scene, r, errors)
    }

    fn ok(text: &str) -> std::boxed::Box<TestScene> {
        let (scene, r, errors) = load(text);
        assert!(r.is_ok(), "{errors:?}");
        scene
    }

    fn errs(text: &str) -> Vec<String> {
        let (scene, r, errors) = load(text);
        assert_eq!(r, Err(errors.len()), "{errors:?}");
        assert_eq!(scene.view().object_count(), 0, "a failed scene is cleared");
        errors
    }

    fn one_err(text: &str) -> String {
        let e = errs(text);
        assert_eq!(e.len(), 1, "{e:?}");
        e.into_iter().next().unwrap_or_default()
    }

    const SURF: &str = "SURFACE 1 0.1 0.1 0.1 0.5 0.5 0.5 1 1 1 10 0.2 0.3\n";

    #[test]
    fn empty_and_comment_only_files_are_valid() {
        for text in ["", "   \n\t", "/* nothing */ // at all\n"] {
            let s = ok(text);
            assert_eq!(s.view().object_count(), 0);
            assert_eq!(s.settings, crate::scene::Settings::default());
        }
    }

    #[test]
    fn every_scene_parameter() {
        let s = ok("VIEWPOINT 1 2 3 ORIGIN 4 5 6 UPVECTOR 0 0 1 RASTER 64 48 VIEWPORT 3 2 RDEPTH 7 \
                    IMAGEFILE out.png LIGHT 0.5 1 1 1 LIGHT 2 -1 -1 -1 BACKGROUND 0.5 0 1 GAMMA 1.8 \
                    ATTENUATION 2.5 SAMPLES 3");
        let st = &s.settings;
        let one = 1i64 << 32;
        assert_eq!(st.view.eye, [one, 2 * one, 3 * one]);
        assert_eq!(st.view.look_at, [4 * one, 5 * one, 6 * one]);
        assert_eq!(st.view.up, [0, 0, one]);
        assert_eq!(st.raster, [64, 48]);
        assert_eq!(st.view.viewport, Some([3 * one, 2 * one]));
        assert_eq!(st.rdepth, 7);
        assert_eq!(st.background.bits(), [1 << 15, 0, 1 << 16]);
        assert_eq!(st.gamma.to_bits(), (18 * one + 5) / 10);
        assert_eq!(st.attenuation.to_bits(), 5 * one / 2);
        assert_eq!(st.samples, 3);
        assert_eq!(s.view().lights.len(), 2);
        assert_eq!(s.view().lights[1].brightness.to_bits(), 2 * one);
        let (_, r, _) = load("IMAGEFILE \"a b.png\"");
        assert_eq!(r.unwrap().imagefile, Some("a b.png"));
    }

    #[test]
    fn keywords_ignore_case_and_line_breaks_do_not_matter() {
        let a = ok("sphere 1 2 0 0 0 Surface 1 0 0 0 1 1 1 0 0 0 0 0 0");
        let b = ok("SPHERE\n1\n2\n0 0\n0\nSURFACE 1\n0 0 0\n1 1 1\n0 0 0\n0\n0\n0");
        assert_eq!(a.view().spheres, b.view().spheres);
        assert_eq!(a.view().object_count(), 1);
    }

    #[test]
    fn every_object_kind_with_a_surface_defined_later() {
        let text = format!(
            "SPHERE 1 1 0 0 0 BOX 1 0 0 0 1 2 3 SUPERQUADRIC 1 4.5 0 0 0 1 1 1 \
             TRIANGLE 1 0 0 0 1 0 0 0 1 0 RECTANGLE 1 0 0 0 1 0 0 1 1 0 0 1 0 {SURF}"
        );
        let s = ok(&text);
        let v = s.view();
        let kinds: Vec<ShapeKind> = v.objects.iter().map(|h| h.kind()).collect();
        assert_eq!(
            kinds,
            [ShapeKind::Sphere, ShapeKind::Box, ShapeKind::Superquadric, ShapeKind::Triangle, ShapeKind::Rectangle]
        );
        let surf = v.surface(v.spheres[0].surface);
        assert_eq!(surf.transparency, Scalar::from_num(0.3));
        assert_eq!(surf.exponent.to_num::<i32>(), 10);
        assert_eq!(v.superquadrics[0].power, Scalar::from_num(4.5));
    }

    #[test]
    fn the_scene_is_normalised_into_range_at_any_scale() {
        for (scale, ten) in [("0.001", "0.01"), ("1", "10"), ("1000", "10000"), ("100000", "1000000")] {
            let text = format!("VIEWPOINT 0 0 {ten} SPHERE 1 {scale} 0 0 0 LIGHT 1 {ten} {ten} 0 {SURF}");
            let s = ok(&text);
            let v = s.view();
            assert!(crate::scene::Normalization::in_range(v.spheres[0].center));
            assert!(crate::scene::Normalization::in_range(v.lights[0].position));
            // The same proportions whatever the scale, to 10^-6 (decimal
            // fractions such as 0.001 round in Q32.32 when read).
            let r = v.spheres[0].radius.to_bits() as i64;
            let lx = (v.lights[0].position - v.spheres[0].center).x.to_bits() as i64;
            assert!((lx - 10 * r).abs() * 1_000_000 <= lx, "{scale}: {lx} vs {r}");
            assert!(r > 1 << 24, "{scale}: radius keeps precision ({r})");
        }
    }

    fn check(text: &str, want: &str) {
        let e = one_err(text);
        assert!(e.contains(want), "{text:?}: got {e:?}, want {want:?}");
    }

    #[test]
    fn lexical_and_number_errors() {
        check("SPHERE 1 nan 0 0 0", "1:10: expected a number for SPHERE radius, found `nan`");
        check("SPHERE 1 1 inf 0 0", "expected a number for SPHERE x, found `inf`");
        check("SPHERE 1 1 0x10 0 0", "found `0x10`");
        check("SPHERE 1 1 0 0", "1:15: expected a number for SPHERE z, found the end of the file");
        check("RASTER 3.5 2", "expected an integer for RASTER width, found `3.5`");
        // A quoted number is text: the message shows the quotes and says so.
        let quoted = "expected an integer for RASTER width, found `\"4\"` (a quoted name, not a number)";
        check("RASTER \"4\" 4", quoted);
        check("LIGHT 1 \"2\" 0 0", "expected a number for LIGHT x, found `\"2\"` (a quoted name");
        check("SPHERE 1.5 1 0 0 0", "expected an integer for SPHERE surface number");
        check("\n\n  /* open", "3:3: unterminated comment");
        check("IMAGEFILE \"abc", "unterminated string");
        check("SPHERE 1 1e400 0 0 0", "SPHERE radius must be at most 1e6 in magnitude, found 1e400");
        check("VIEWPOINT 1000000.5 0 0", "VIEWPOINT x must be at most 1e6 in magnitude");
        check("SPHER 1 1 0 0 0", "unknown keyword `SPHER`");
        check(
            &format!("{SURF}SPHERE 1 1 0 0 0 -0.5"),
            "2:18: expected a statement's keyword, found the number `-0.5`, one too many for the statement before it",
        );
    }

    #[test]
    fn range_errors() {
        check("SPHERE 1 -1 0 0 0", "SPHERE radius must be > 0, found -1");
        check("SPHERE 1 0 0 0 0", "SPHERE radius must be > 0, found 0");
        check("BOX 1 0 0 0 1 0 1", "BOX ys must be > 0, found 0");
        check("SUPERQUADRIC 1 1.5 0 0 0 1 1 1", "SUPERQUADRIC power must be between 2 and 64, found 1.5");
        check("SUPERQUADRIC 1 65 0 0 0 1 1 1", "between 2 and 64");
        check("RASTER 0 10", "RASTER width must be an integer from 1 to 16384, found 0");
        check("RASTER 10 16385", "RASTER height must be an integer from 1 to 16384");
        check("SAMPLES 17", "SAMPLES count must be an integer from 1 to 16");
        check("RDEPTH -1", "RDEPTH depth must be an integer from 0 to 1000000");
        check("GAMMA 0", "GAMMA value must be > 0");
        check("ATTENUATION -2", "ATTENUATION d0 must be > 0");
        check("LIGHT -0.5 0 0 0", "LIGHT brightness must be >= 0");
        check("BACKGROUND 0 1.5 0", "BACKGROUND green must be between 0 and 1, found 1.5");
        check("VIEWPORT 0 1", "VIEWPORT width must be > 0");
        check("SURFACE -1 0 0 0 0 0 0 0 0 0 0 0 0", "SURFACE surface number must be an integer from 0 to 1000000");
        check("SURFACE 1 0 0 0 0 0 0 0 0 0 -1 0 0", "SURFACE specular exponent must be >= 0");
        check("SURFACE 1 0 0 0 0 0 0 0 0 0 0 2 0", "SURFACE reflectivity must be between 0 and 1");
    }

    #[test]
    fn context_errors() {
        check("RDEPTH 2\nRDEPTH 3", "2:1: RDEPTH is given twice (first on line 1)");
        check(&format!("{SURF}{SURF}"), "2:1: SURFACE 1 is defined twice (first on line 1)");
        check(
            "SURFACE 1 0 0 0 0 0 0 0 0 0 0 0 0 SURFACE 1 0 0 0 0 0 0 0 0 0 0 0 0",
            "1:35: SURFACE 1 is defined twice",
        );
        check("\nSPHERE 7 1 0 0 0", "2:1: SPHERE uses surface 7, which is never defined");
        check(
            &format!("TRIANGLE 1 0 0 0 1 1 1 2 2 2 {SURF}"),
            "1:1: TRIANGLE is degenerate: its corners are collinear",
        );
        check(&format!("RECTANGLE 1 0 0 0 1 0 0 1 1 0.5 0 1 0 {SURF}"), "RECTANGLE is not planar");
        check(&format!("RECTANGLE 1 0 0 0 1 1 0 1 0 0 0 1 0 {SURF}"), "RECTANGLE is not convex");
        check(&format!("RECTANGLE 1 0 0 0 0 0 0 0 0 0 0 0 0 {SURF}"), "RECTANGLE is degenerate");
        check("VIEWPOINT 1 2 3 ORIGIN 1 2 3", "1:17: VIEWPOINT equals ORIGIN");
        check("UPVECTOR 0 0 5", "1:1: UPVECTOR is zero or parallel to the view direction");
        check("UPVECTOR 0 0 0", "UPVECTOR is zero or parallel");
    }

    /// A valid statement for each keyword.
    fn example(keyword: Keyword) -> &'static str {
        match keyword {
            Keyword::Viewpoint => "VIEWPOINT 0 0 10",
            Keyword::Origin => "ORIGIN 0 0 1",
            Keyword::Upvector => "UPVECTOR 0 1 0",
            Keyword::Raster => "RASTER 8 8",
            Keyword::Viewport => "VIEWPORT 1 1",
            Keyword::Rdepth => "RDEPTH 2",
            Keyword::Imagefile => "IMAGEFILE a.png",
            Keyword::Light => "LIGHT 1 5 5 5",
            Keyword::Background => "BACKGROUND 0 0 0.5",
            Keyword::Gamma => "GAMMA 2.2",
            Keyword::Attenuation => "ATTENUATION 1",
            Keyword::Samples => "SAMPLES 2",
            Keyword::Sphere => "SPHERE 1 1 0 0 0",
            Keyword::Box => "BOX 1 0 0 0 1 1 1",
            Keyword::Superquadric => "SUPERQUADRIC 1 4 0 0 0 1 1 1",
            Keyword::Triangle => "TRIANGLE 1 0 0 0 1 0 0 0 1 0",
            Keyword::Rectangle => "RECTANGLE 1 0 0 0 1 0 0 1 1 0 0 1 0",
            Keyword::Bspline => "BSPLINE 1 2 2 2 2 2 0 0 0 1 0 0 0 1 0 1 1 0",
            Keyword::Surface => "SURFACE 2 0 0 0 0 0 0 0 0 0 0 0 0",
            Keyword::Frames => "FRAMES 4 12",
            Keyword::Move => "LIGHT 1 5 5 5 MOVE 0 1 0 0  3 0 1 0",
        }
    }

    #[test]
    fn parameters_may_be_given_once_and_the_rest_repeat() {
        for keyword in Keyword::ALL {
            let statement = example(keyword);
            // A MOVE needs FRAMES (on the line of the surface).
            let frames = if keyword == Keyword::Move { "FRAMES 4 " } else { "" };
            ok(&format!("{SURF}{frames}{statement}"));
            let twice = format!("{SURF}{frames}{statement}\n{statement}");
            if keyword.once_only() {
                let name = keyword.name();
                assert_eq!(one_err(&twice), format!("3:1: {name} is given twice (first on line 2)"));
            } else if keyword == Keyword::Surface {
                assert_eq!(one_err(&twice), "3:1: SURFACE 2 is defined twice (first on line 2)");
            } else {
                ok(&twice);
            }
        }
    }

    #[test]
    fn clockwise_rectangles_are_convex_too() {
        ok(&format!("RECTANGLE 1 0 0 0 0 1 0 1 1 0 1 0 0 {SURF}"));
    }

    #[test]
    fn all_errors_are_reported_in_order() {
        let e = errs("SPHERE 1 -1 0 0 0\nFOO 1 2 3\nRASTER 1 1\nRASTER 2 2 BOX 1 0 0 0 0 1 1\n/* open");
        assert_eq!(e.len(), 5, "{e:?}");
        assert!(e[0].starts_with("1:10:") && e[1].starts_with("2:1:") && e[2].starts_with("4:1:"));
        assert!(e[3].starts_with("4:24:") && e[4].starts_with("5:1:"), "{e:?}");
    }

    #[test]
    fn recovery_resumes_at_the_next_keyword() {
        // The missing z is reported at the keyword that follows, which is
        // then read normally, even on the same line.
        let e = errs(&format!("SPHERE 1 1 0 0\n{SURF}RDEPTH 2 RDEPTH 3"));
        assert_eq!(e.len(), 2, "{e:?}");
        assert!(e[0].contains("2:1: expected a number for SPHERE z, found `SURFACE`"), "{e:?}");
        assert!(e[1].contains("RDEPTH is given twice"), "{e:?}");
    }

    /// Where each error of `text` is, as `line:column`.
    fn error_positions(text: &str) -> Vec<String> {
        errs(text).iter().map(|e| e.split(": ").next().unwrap_or_default().to_string()).collect()
    }

    #[test]
    fn recovery_reports_every_lines_error() {
        // An unknown word is its own offending token: the next line's word
        // is read again as a statement.
        assert_eq!(error_positions("x\nx\nx\nx\nx\n"), ["1:1", "2:1", "3:1", "4:1", "5:1"]);
        // A statement cut short by a keyword on the next line: that
        // statement is read, its own error reported, and the line after.
        let e = errs("SPHERE 1 1 0 0\nSPHERE 1 -1 0 0 0\nx\n");
        assert_eq!(e.len(), 3, "{e:?}");
        assert!(e[0].starts_with("2:1: expected a number for SPHERE z, found `SPHERE`"), "{e:?}");
        assert!(e[1].starts_with("2:10: SPHERE radius must be > 0"), "{e:?}");
        assert!(e[2].starts_with("3:1: unknown keyword `x`"), "{e:?}");
        // A bad number: the rest of its statement is dropped, not the next
        // line; numbers on the lines after an unknown word are its own.
        assert_eq!(
            error_positions("SPHERE 1 y 0 0 0\nx\nLIGHT 1 0 5 q\nx 1 2\n 3 4\nx\n"),
            ["1:10", "2:1", "3:13", "4:1", "6:1"]
        );
        // The offending word opening a line is reported once, as what the
        // statement did not expect.
        let e = errs("SPHERE 1 1\nfoo 0 0\nx\n");
        assert_eq!(e.len(), 2, "{e:?}");
        assert!(e[0].starts_with("2:1: expected a number for SPHERE x, found `foo`"), "{e:?}");
        assert!(e[1].starts_with("3:1: unknown keyword `x`"), "{e:?}");
        // A statement wrong as a whole (reported at its keyword): the next
        // line's word is still read.
        assert_eq!(error_positions(&format!("{SURF}TRIANGLE 1 0 0 0 1 1 1 2 2 2\nx\n")), ["2:1", "3:1"]);
        // A bad control point: the patch's other points, on the lines
        // after it, are skipped as its own.
        let patch = "BSPLINE 1 2 3 3 2 2\n0 0 0 1 0 0 2 0 0\n0 1 0 q 1 0 2 1 0\n0 2 0 1 2 0 2 2 0\nx\n";
        assert_eq!(error_positions(&format!("{SURF}{patch}")), ["4:7", "6:1"]);
        // An unterminated comment takes the rest of the text: what is in
        // it is not read, what came before is all reported.
        assert_eq!(error_positions("x\nSPHERE 1 1 0 /* open\nx\n"), ["1:1", "2:14"]);
        assert_eq!(error_positions("x\nRDEPTH 2 x\n/* open\nx\n"), ["1:1", "2:10", "3:1"]);
        // A quoted keyword begins no statement.
        assert_eq!(error_positions("x \"RDEPTH\" 2\nRDEPTH 2\n"), ["1:1"]);
    }

    #[test]
    fn capacity_errors_name_the_limit_once() {
        let mut text = String::from(SURF);
        for _ in 0..40 {
            text.push_str("BOX 1 0 0 0 1 1 1\n");
        }
        let e = errs(&text);
        assert_eq!(e.len(), 1, "{e:?}");
        assert_eq!(
            e.iter()
                .filter(|m| m.contains("too many boxes: the capacity profile Board64K holds 32 and the scene needs 40;"))
                .count(),
            1,
            "{e:?}"
        );
    }

    #[test]
    fn a_surface_in_error_is_not_also_never_defined() {
        // Its objects, before it and after, name it: its error alone.
        let transparent = SURF.replacen("0.2 0.3", "0.2 1.5", 1);
        for text in [
            std::format!("SPHERE 1 1 0 0 0\n{transparent}SPHERE 1 1 3 0 0\n"),
            "SPHERE 1 1 0 0 0\nSURFACE 1 0 0 0\n".into(),
        ] {
            let e = errs(&text);
            assert_eq!(e.len(), 1, "{e:?}");
            assert!(e[0].starts_with("2:"), "{e:?}");
        }
    }

    /// The errors of `text`, which has some, loaded with profile `C`.
    fn errors_in<C: SceneCapacities>(text: &str) -> Vec<String> {
        let mut scene = std::boxed::Box::new(Scene::<C>::new());
        let mut errors = Vec::new();
        let r = parse(text, &mut scene, &mut |e| errors.push(e.to_string()));
        assert_eq!(r, Err(errors.len()), "{errors:?}");
        errors
    }

    #[test]
    fn surfaces_beyond_the_capacity_leave_the_objects_before_them_unblamed() {
        crate::profile! {
            struct OneSurface { spheres: 4, surfaces: 1, lights: 1 }
        }
        let load = errors_in::<OneSurface>;
        // Objects may name a surface defined further down: the one that
        // did not fit is the error, not the spheres that name it.
        let surface = |n: u32| SURF.replacen("SURFACE 1", &std::format!("SURFACE {n}"), 1);
        let e = load(&std::format!("SPHERE 2 1 0 0 0\nSPHERE 1 1 3 0 0\n{}{}", surface(1), surface(2)));
        assert_eq!(e.len(), 1, "{e:?}");
        assert!(e[0].starts_with("4:1: too many surfaces: the capacity profile OneSurface holds 1"), "{e:?}");
        // Within the capacity, a surface no SURFACE defines is one still.
        let e = load(&std::format!("SPHERE 2 1 0 0 0\n{}", surface(1)));
        assert_eq!(e, ["1:1: SPHERE uses surface 2, which is never defined"]);
    }

    #[test]
    fn a_profile_without_room_for_a_flat_kind_names_its_first_statement() {
        crate::profile! {
            struct SpheresOnly { spheres: 2, surfaces: 1, lights: 1 }
        }
        let load = errors_in::<SpheresOnly>;
        // A valid rectangle, then one that is not convex: the board skips
        // their checks, and the first one is the capacity error.
        let rectangles = format!(
            "{SURF}SPHERE 1 1 0 0 0\nRECTANGLE 1 0 0 0 1 0 0 1 1 0 0 1 0\nRECTANGLE 1 0 0 0 1 1 0 1 0 0 0 1 0\n"
        );
        let e = load(&rectangles);
        assert_eq!(e.len(), 1, "{e:?}");
        assert!(e[0].starts_with("3:1: too many rectangles: the capacity profile SpheresOnly holds 0"), "{e:?}");
        let e = load(&format!("{SURF}TRIANGLE 1 0 0 0 1 0 0 2 0 0\nTRIANGLE 1 0 0 0 1 0 0 0 1 0\n"));
        assert_eq!(e.len(), 1, "{e:?}");
        assert!(e[0].starts_with("2:1: too many triangles: the capacity profile SpheresOnly holds 0"), "{e:?}");
        // With room, the same rectangles are checked as before.
        let e = errs(&rectangles);
        assert_eq!(e.len(), 1, "{e:?}");
        assert!(e[0].starts_with("4:1:") && e[0].contains("convex"), "{e:?}");
    }

    #[test]
    fn invalid_utf8_is_located() {
        let mut scene = std::boxed::Box::new(TestScene::new());
        let mut errors = Vec::new();
        let bytes = b"RDEPTH 2\nLIGHT 1 \xff 0 0";
        let r = parse_bytes(bytes, &mut scene, &mut |e| errors.push(e.to_string()));
        assert_eq!(r, Err(1));
        assert_eq!(errors, ["2:9: the file is not valid UTF-8 (invalid byte here)"]);
        // Lines end at CRLF and at a lone CR too, as everywhere else.
        for bytes in [&b"RDEPTH 2\r\nLIGHT 1 \xff 0 0"[..], b"RDEPTH 2\rLIGHT 1 \xff 0 0", b"RDEPTH 2\r\xff"] {
            errors.clear();
            let r = parse_bytes(bytes, &mut scene, &mut |e| errors.push(e.to_string()));
            assert_eq!(r, Err(1));
            let at = if bytes.ends_with(b"\xff") { "2:1" } else { "2:9" };
            assert_eq!(errors, [format!("{at}: the file is not valid UTF-8 (invalid byte here)")], "{bytes:?}");
        }
    }

    #[test]
    fn objects_keep_file_order_and_positions() {
        let s = ok(&format!("SPHERE 1 1 0 0 0 SPHERE 1 2 5 0 0 {SURF} LIGHT 1 -5 0 0"));
        let v = s.view();
        let a = v.spheres[0];
        let b = v.spheres[1];
        assert_eq!(b.radius.to_bits(), 2 * a.radius.to_bits());
        assert_eq!((b.center - a.center).x.to_bits(), 5 * a.radius.to_bits());
        assert_eq!(v.lights[0].position.y, a.center.y);
        assert_eq!([b.center.y, b.center.z], [a.center.y, a.center.z]);
    }

    /// The single error `text` gives, as a value.
    fn the_error(text: &[u8]) -> ParseError<'_> {
        let mut scene = std::boxed::Box::new(TestScene::new());
        let mut errors = Vec::new();
        let r = parse_bytes(text, &mut scene, &mut |e| errors.push(e));
        assert_eq!(r, Err(1), "{:?}: {errors:?}", std::string::String::from_utf8_lossy(text));
        errors[0]
    }

    fn at(line: u32, column: u32) -> Pos {
        Pos { line, column }
    }

    #[test]
    fn an_unfinished_statement_is_reported_right_after_its_last_token() {
        let field = |statement, name| Field { statement, name };
        let cases: [(&str, Pos, ErrorKind<'_>); 7] = [
            (
                "RDEPTH 1\nSPHERE 1 1 0 0",
                at(2, 15),
                ErrorKind::ExpectedNumber { field: field("SPHERE", "z"), found: Found::EndOfFile },
            ),
            // Not past the end, where blank lines and comments lead.
            (
                "RDEPTH 1\nSPHERE 1 1 0 0 // z?\n\n  /* */\n",
                at(2, 15),
                ErrorKind::ExpectedNumber { field: field("SPHERE", "z"), found: Found::EndOfFile },
            ),
            (
                "\nSPHERE\n",
                at(2, 7),
                ErrorKind::ExpectedInteger { field: field("SPHERE", "surface number"), found: Found::EndOfFile },
            ),
            (
                "RASTER 8\r\n",
                at(1, 9),
                ErrorKind::ExpectedInteger { field: field("RASTER", "height"), found: Found::EndOfFile },
            ),
            ("RDEPTH 1 IMAGEFILE\n", at(1, 19), ErrorKind::ExpectedName { field: field("IMAGEFILE", "file name") }),
            (
                "BSPLINE 1 2 2 2 2 2  0 0 0  1 0 0\n  0 1\n",
                at(2, 6),
                ErrorKind::ExpectedNumber { field: field("BSPLINE", "control point z"), found: Found::EndOfFile },
            ),
            // Columns count characters: é is one.
            (
                "LIGHT 1 1 é",
                at(1, 11),
                ErrorKind::ExpectedNumber { field: field("LIGHT", "y"), found: Found::Token("é") },
            ),
        ];
        for (text, pos, kind) in cases {
            assert_eq!(the_error(text.as_bytes()), ParseError::new(pos, kind), "{text:?}");
        }
    }

    /// A number for each error kind; exhaustive, so a new kind does not
    /// compile until it gets a case in the test below.
    fn kind_number(kind: &ErrorKind<'_>) -> usize {
        match kind {
            ErrorKind::InvalidUtf8 => 0,
            ErrorKind::UnterminatedComment => 1,
            ErrorKind::UnterminatedString => 2,
            ErrorKind::UnknownKeyword(_) => 3,
            ErrorKind::ExpectedNumber { .. } => 4,
            ErrorKind::ExpectedInteger { .. } => 5,
            ErrorKind::ExpectedName { .. } => 6,
            ErrorKind::OutOfRange { .. } => 7,
            ErrorKind::Repeated { .. } => 8,
            ErrorKind::SurfaceRepeated { .. } => 9,
            ErrorKind::UndefinedSurface { .. } => 10,
            ErrorKind::Degenerate { .. } => 11,
            ErrorKind::NotPlanar => 12,
            ErrorKind::NotConvex => 13,
            ErrorKind::TooFewControlPoints { .. } => 14,
            ErrorKind::TooSmall { .. } => 15,
            ErrorKind::EyeAtOrigin => 16,
            ErrorKind::UpParallel => 17,
            ErrorKind::Capacity(_) => 18,
            ErrorKind::MoveWithoutFrames => 19,
            ErrorKind::NothingToMove { .. } => 20,
            ErrorKind::FramesOutOfOrder { .. } => 21,
            ErrorKind::FrameBeyond { .. } => 22,
            ErrorKind::MovedOutOfRange { .. } => 23,
            ErrorKind::MovedCamera { .. } => 24,
            ErrorKind::NoMotion { .. } => 25,
        }
    }
    const ERROR_KINDS: usize = 26;

    #[test]
    fn every_error_kind_reports_its_line_and_column() {
        let boxes: String = (0..33).map(|_| "BOX 1 0 0 0 1 1 1\n").collect();
        // Lights 10^6 apart: one fixed-point step is about 2^-29 of that,
        // 0.002; a radius of 0.0001 rounds to nothing, 0.002 does not.
        let wide = "LIGHT 1 -500000 0 0 LIGHT 1 500000 0 0\n";
        assert!(ok(&format!("{wide}{SURF} SPHERE 1 0.002 0 0 0")).view().spheres[0].radius.to_bits() > 0);
        let cases: [(String, Pos, usize); 25] = [
            ("RDEPTH 1\n  /* open\n".into(), at(2, 3), 1),
            ("RDEPTH 1\nIMAGEFILE \"abc\n".into(), at(2, 11), 2),
            ("RDEPTH 1\n  FOO 1".into(), at(2, 3), 3),
            ("LIGHT 1 0\n x".into(), at(2, 2), 4),
            ("RASTER 8\n4.5".into(), at(2, 1), 5),
            ("RDEPTH 1 IMAGEFILE\n".into(), at(1, 19), 6),
            ("SAMPLES 0".into(), at(1, 9), 7),
            ("GAMMA 2\n GAMMA 2".into(), at(2, 2), 8),
            (format!("{SURF}  {SURF}"), at(2, 3), 9),
            ("\n SPHERE 7 1 0 0 0".into(), at(2, 2), 10),
            (format!("{SURF} TRIANGLE 1 0 0 0 1 1 1 2 2 2"), at(2, 2), 11),
            (format!("{SURF} BSPLINE 1 2 2 2 2 2 1 1 1 1 1 1 1 1 1 1 1 1"), at(2, 2), 11),
            (format!("{SURF} RECTANGLE 1 0 0 0 1 0 0 1 1 1 0 1 0"), at(2, 2), 12),
            (format!("{SURF} RECTANGLE 1 0 0 0 1 1 0 1 0 0 0 1 0"), at(2, 2), 13),
            (format!("{SURF} BSPLINE 1 4 3 3 4 4 {GRID}"), at(2, 2), 14),
            (format!("{wide}{SURF} SPHERE 1 0.0001 0 0 0"), at(3, 2), 15),
            ("VIEWPOINT 0 0 1\n ORIGIN 0 0 1".into(), at(2, 2), 16),
            ("\n  UPVECTOR 0 0 -3".into(), at(2, 3), 17),
            (format!("{SURF}{boxes}"), at(34, 1), 18),
            ("LIGHT 1 0 0 0\n MOVE 0 1 1 1".into(), at(2, 2), 19),
            ("FRAMES 2\n MOVE 0 1 1 1".into(), at(2, 2), 20),
            ("FRAMES 9 LIGHT 1 0 0 0\nMOVE 3 0 0 0  3 1 1 1".into(), at(2, 15), 21),
            ("FRAMES 3 LIGHT 1 0 0 0\nMOVE 0 0 0 0  3 1 1 1".into(), at(2, 15), 22),
            ("FRAMES 3 LIGHT 1 999999 0 0\nMOVE 0 0 0 0  2 2 0 0".into(), at(2, 15), 23),
            ("FRAMES 3 VIEWPOINT 0 0 5\n MOVE 0 0 0 -5".into(), at(2, 2), 24),
        ];
        let mut covered = [false; ERROR_KINDS];
        let bad_byte = (b"RDEPTH 2\n\xc3\xa9 \xff".to_vec(), at(2, 3), 0);
        for (bytes, pos, kind) in
            cases.map(|(text, pos, kind)| (text.into_bytes(), pos, kind)).into_iter().chain([bad_byte])
        {
            let e = the_error(&bytes);
            assert_eq!((e.pos, kind_number(&e.kind)), (pos, kind), "{e}");
            covered[kind] = true;
        }
        // In a build for a still.
        let mut still = std::boxed::Box::new(Scene::<Still>::new());
        let mut errors = Vec::new();
        let moved = "FRAMES 3 LIGHT 1 0 0 0\n MOVE 0 0 0 0  2 1 0 0";
        assert_eq!(parse(moved, &mut still, &mut |e| errors.push(e)), Err(1), "{errors:?}");
        assert_eq!((errors[0].pos, kind_number(&errors[0].kind)), (at(2, 2), 25), "{}", errors[0]);
        assert_eq!(
            errors[0].to_string(),
            "2:2: MOVE, but this build's profile Still holds no motion (built for a still: `motion: false`)"
        );
        covered[25] = true;
        assert_eq!(covered, [true; ERROR_KINDS], "an error kind has no case");
    }

    /// A 3 × 3 grid of control points in the plane z = 0, row by row.
    const GRID: &str = "0 0 0  1 0 0  2 0 0   0 1 0  1 1 0  2 1 0   0 2 0  1 2 0  2 2 0";

    #[test]
    fn bspline_patches_become_smooth_triangles() {
        let s = ok(&format!("BSPLINE 1 3 3 3 4 3 {GRID} SPHERE 1 1 5 5 5 {SURF}"));
        let v = s.view();
        // 2 · (4 − 1) · (3 − 1) triangles, in file order before the sphere.
        assert_eq!(v.bspline_triangles.len(), 12);
        assert_eq!(v.object_count(), 13);
        assert_eq!(v.objects[12].kind(), ShapeKind::Sphere);
        assert!(v.objects[..12].iter().all(|h| h.kind() == ShapeKind::SmoothTriangle));
        // Each patch is one object as written: its first triangle.
        let two = ok(&format!("SPHERE 1 1 5 5 5 BSPLINE 1 3 3 3 3 3 {GRID} BSPLINE 1 3 3 3 3 3 {GRID} {SURF}"));
        let v = two.view();
        let written: Vec<u32> = (0..v.object_count() as u32).map(|i| v.written_object(ObjectId(i)).0).collect();
        assert_eq!(written, [[0].as_slice(), &[1; 8], &[9; 8]].concat());
        // Keywords are case-insensitive and the points may span lines.
        let t = ok(&format!("bspline 1 2 3 3 2 2\n{}\n{SURF}", GRID.replace("   ", "\n")));
        assert_eq!(t.view().bspline_triangles.len(), 2);
    }

    #[test]
    fn bspline_errors() {
        let check = |text: &str, want: &str| {
            let e = one_err(&format!("{text} {SURF}"));
            assert!(e.contains(want), "{text}: {e}");
        };
        check(&format!("BSPLINE 1 1 3 3 4 4 {GRID}"), "1:11: BSPLINE order must be an integer from 2 to 8, found 1");
        check(&format!("BSPLINE 1 9 3 3 4 4 {GRID}"), "BSPLINE order must be an integer from 2 to 8, found 9");
        check(
            &format!("BSPLINE 1 4 3 3 4 4 {GRID}"),
            "1:1: BSPLINE of order 4 needs at least 4 control points along each side, found 3 × 3",
        );
        check(&format!("BSPLINE 1 3 3 3 1 4 {GRID}"), "BSPLINE su must be an integer from 2 to 1024, found 1");
        check(&format!("BSPLINE 1 3 3 3 4 1 {GRID}"), "BSPLINE sv must be an integer from 2 to 1024, found 1");
        check(
            "BSPLINE 1 3 3 3 4 4 0 0 0 1 0 0",
            "1:33: expected a number for BSPLINE control point x, found `SURFACE`",
        );
        check(&format!("BSPLINE 1 2 3 3 4 4 {} 1e7", &GRID[..GRID.len() - 2]), "control point z must be at most 1e6");
        check(&format!("BSPLINE 7 3 3 3 4 4 {GRID}"), "BSPLINE uses surface 7, which is never defined");
        check("BSPLINE 1 2 2 2 3 3 1 1 1 1 1 1 1 1 1 1 1 1", "BSPLINE is degenerate");
        // A patch of 1e-9 beside a light 1e6 away: a square in the file, a
        // point in the scene's units, as a triangle that small is.
        let tiny = "0 0 0 1e-9 0 0 0 1e-9 0 1e-9 1e-9 0";
        check(&format!("LIGHT 1 1e6 0 0 BSPLINE 1 2 2 2 2 2 {tiny}"), "1:17: BSPLINE is too small");
        check("LIGHT 1 1e6 0 0 TRIANGLE 1 0 0 0 1e-9 0 0 0 1e-9 0", "1:17: TRIANGLE is too small");
        // 2 · 5 · 5 = 50 triangles: more than Board64K's 32, said once, up front.
        let e = errs(&format!("BSPLINE 1 3 3 3 6 6 {GRID} BSPLINE 1 3 3 3 6 6 {GRID} {SURF}"));
        assert_eq!(e.len(), 1, "{e:?}");
        assert!(
            e[0].contains(
                "too many B-spline triangles: the capacity profile Board64K holds 32 and the scene needs 100; \
                 define a profile that holds them with octrace_core::profile! (bspline_triangles: 100, …)"
            ),
            "{e:?}"
        );
    }

    #[test]
    fn a_patch_at_exactly_its_capacity_loads_and_one_triangle_over_is_named() {
        crate::profile! {
            struct Exactly32 { bspline_triangles: 32, control_points: 9, surfaces: 1 }
        }
        crate::profile! {
            struct Only31 { bspline_triangles: 31, control_points: 9, surfaces: 1 }
        }
        // 2 · 4 · 4 = 32 triangles.
        let text = format!("{SURF}BSPLINE 1 3 3 3 5 5 {GRID}\n");
        let mut scene = std::boxed::Box::new(Scene::<Exactly32>::new());
        let mut errors = Vec::new();
        let r = parse(&text, &mut scene, &mut |e| errors.push(e.to_string()));
        assert_eq!((r, errors.len()), (Ok(Parsed::default()), 0), "{errors:?}");
        assert_eq!(scene.view().bspline_triangles.len(), 32);
        let mut scene = std::boxed::Box::new(Scene::<Only31>::new());
        let r = parse(&text, &mut scene, &mut |e| errors.push(e.to_string()));
        assert_eq!(r, Err(1), "{errors:?}");
        assert!(
            errors[0].starts_with(
                "2:1: too many B-spline triangles: the capacity profile Only31 holds 31 and the scene needs 32"
            ),
            "{errors:?}"
        );
    }

    #[test]
    fn hostile_text_in_messages_is_cut_and_escaped() {
        let long = "X".repeat(5000);
        let e = one_err(&long);
        assert!(e.contains(&format!("`{}… (5000 characters)`", "X".repeat(40))), "{e}");
        assert!(e.len() < 400, "{} bytes", e.len());
        let e = one_err("SPHERE 1 \u{1b}[31mred 0 0 0");
        assert!(e.contains("`\\u{1b}[31mred`"), "{e}");
        assert!(!e.contains('\u{1b}'));
    }

    #[test]
    fn byte_order_marks_and_old_mac_line_ends() {
        let s = ok(&format!("\u{feff}SPHERE 1 1 0 0 0 {SURF}"));
        assert_eq!(s.view().object_count(), 1);
        // A mark anywhere else is not whitespace, and is shown escaped.
        assert!(one_err("SPHERE 1 1 0 0 0\u{feff}").contains("\\u{feff}"));
        // Lone CRs end lines (and // comments) like LF and CRLF do.
        for nl in ["\n", "\r\n", "\r"] {
            let e = one_err(&format!("// comment{nl}RASTER 8 8{nl}{nl}  FOO{nl}"));
            assert!(e.starts_with("4:3: unknown keyword `FOO`"), "{nl:?}: {e}");
        }
    }

    #[test]
    fn positive_values_that_read_as_zero_say_so() {
        let e = one_err(&format!("SPHERE 1 1e-400 0 0 0 {SURF}"));
        assert!(
            e.contains("SPHERE radius must be at least 2^-32 (smaller positive values read as 0), found 1e-400"),
            "{e}"
        );
        let e = one_err(&format!("SPHERE 1 -1 0 0 0 {SURF}"));
        assert!(e.contains("SPHERE radius must be > 0, found -1"), "{e}");
    }

    #[test]
    fn an_unclosed_comment_or_string_after_a_statement_of_varying_length_is_its_error() {
        // FRAMES and MOVE look past their last number for another: the
        // lexer's error there must not end the text without a word.
        for (text, at) in [
            ("FRAMES 2 /* open\nSPHERE 1 1 0 0 0\n", "2:10"),
            ("FRAMES 2 \"open\nSPHERE 1 1 0 0 0\n", "2:10"),
            ("FRAMES 2 LIGHT 1 1 1 1 MOVE 0 1 1 1 /* open\nSPHERE 1 1 0 0 0\n", "2:37"),
        ] {
            // The SURFACE before them is line 1.
            let e = one_err(&format!("{SURF}{text}"));
            assert!(e.starts_with(at), "{text}: {e}");
            assert!(e.contains("never closed"), "{text}: {e}");
        }
    }

    #[test]
    fn range_checks_apply_to_the_value_as_read() {
        // Negative decimals that read as 0 are 0, as `-0` is; one below the
        // resolution's half reads as −2^-32 and is refused.
        let s = ok(&format!(
            "SURFACE 2 -1e-20 -0 0 0 0 0 0 0 0 -1e-400 1.0000000001 0\nLIGHT -1e-400 1 1 1\nSPHERE 2 1 0 0 0\n{SURF}"
        ));
        assert_eq!(s.view().object_count(), 1);
        let e = one_err(&format!("{SURF}SURFACE 2 -3e-10 0 0 0 0 0 0 0 0 0 0 0\n"));
        assert!(e.contains("must be between 0 and 1"), "{e}");
    }

    #[test]
    fn a_long_thin_rectangle_is_convex() {
        // Its short sides, cut to nothing at its long sides' scale, still
        // turn the way they do; as two triangles the same area loads.
        for corners in [
            "0 0 0  100 0 0  100 0.000001 0  0 0.000001 0",
            "0 0 0  0 0.000001 0  100 0.000001 0  100 0 0",
            "0 0 0  1000000 0 0  1000000 0.01 0  0 0.01 0",
        ] {
            let s = ok(&format!("VIEWPOINT 50 0 10 ORIGIN 50 0 0 RECTANGLE 1 {corners}\n{SURF}"));
            assert_eq!(s.view().object_count(), 1, "{corners}");
        }
    }
}
