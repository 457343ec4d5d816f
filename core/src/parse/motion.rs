//! `MOVE` and the statement it moves: every pass over the text pairs them
//! the same way ([`for_each_paired`]), so the survey's extent, the build's
//! placing (which hands each moving statement, once placed, to the
//! animation's [`MotionSink`]) and the room counted for the motion agree.
//!
//! Invariants: each statement is handed over once, in file order, with the
//! keys of the MOVE right after it if there is one; a MOVE after a
//! statement that failed to parse is dropped (its statement's error is
//! reported); any other MOVE that follows nothing movable is handed over as
//! a stray, at its position.

use super::error::{ParseError, Pos};
use super::keyword::Keyword;
use super::statement::{AnyRoom, Room};
use super::statement::{Keys, Statement};
use super::statements::for_each_statement;
use crate::scene::{Frames, Normalization, WorldPoint};

/// What a MOVE can move: a statement with a place.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Mover {
    /// An object statement (a B-spline patch moves whole).
    Object,
    /// A LIGHT.
    Light,
    /// VIEWPOINT.
    Eye,
    /// ORIGIN.
    LookAt,
}

impl Statement<'_> {
    /// What a MOVE after this statement moves, if it can follow it.
    pub(crate) fn mover(&self) -> Option<Mover> {
        match self {
            Statement::Viewpoint(_) => Some(Mover::Eye),
            Statement::Origin(_) => Some(Mover::LookAt),
            Statement::Light { .. } => Some(Mover::Light),
            s if s.object_bounds().is_some() => Some(Mover::Object),
            _ => None,
        }
    }

    /// The box of the points the statement writes (a centre, corners,
    /// control points, a light's or the camera's point): what a MOVE must
    /// keep within the format's range.
    pub(crate) fn written_box(&self) -> Option<(WorldPoint, WorldPoint)> {
        let point = |p: &WorldPoint| Some((*p, *p));
        match self {
            Statement::Viewpoint(p) | Statement::Origin(p) => point(p),
            Statement::Light { position, .. } => point(position),
            Statement::Sphere { center, .. }
            | Statement::Box { center, .. }
            | Statement::Superquadric { center, .. } => point(center),
            // Corners and control points: their box is the object's.
            s => s.object_bounds(),
        }
    }
}

/// A statement as a pass receives it.
pub(crate) enum Paired<'a> {
    /// A statement that parsed, at `pos`, with the MOVE that follows it
    /// (its position and keys), if any.
    Statement { pos: Pos, statement: Statement<'a>, moved: Option<(Pos, Keys<'a>)> },
    /// A statement that did not parse, and its keyword if it has one.
    Error(ParseError<'a>, Option<Keyword>),
    /// A MOVE at `pos` that follows nothing it can move: the keyword of
    /// the statement before it, if any.
    Stray { pos: Pos, after: Option<&'static str> },
}

/// The statement before the one being read, as far as a MOVE cares.
enum Before<'a> {
    Nothing,
    /// Movable, held until the next statement says whether it is a MOVE.
    Movable(Pos, Statement<'a>),
    Failed,
    Unmovable(&'static str),
}

/// Reads every statement of `text` as [`for_each_statement`] does, pairing
/// each movable statement with the MOVE that follows it.
pub(crate) fn for_each_paired<'a, R: Room>(text: &'a str, mut each: impl FnMut(Paired<'a>)) {
    let mut before = Before::Nothing;
    for_each_statement::<R>(text, |pos, keyword, result| {
        if let Ok(Statement::Move(keys)) = result {
            match core::mem::replace(&mut before, Before::Unmovable("MOVE")) {
                Before::Movable(at, statement) => {
                    each(Paired::Statement { pos: at, statement, moved: Some((pos, keys)) })
                }
                Before::Failed => {}
                Before::Nothing => each(Paired::Stray { pos, after: None }),
                Before::Unmovable(keyword) => each(Paired::Stray { pos, after: Some(keyword) }),
            }
            return;
        }
        if let Before::Movable(at, statement) = core::mem::replace(&mut before, Before::Nothing) {
            each(Paired::Statement { pos: at, statement, moved: None });
        }
        before = match result {
            Ok(statement) if statement.mover().is_some() => Before::Movable(pos, statement),
            Ok(statement) => {
                let keyword = statement.keyword().name();
                each(Paired::Statement { pos, statement, moved: None });
                Before::Unmovable(keyword)
            }
            Err(e) => {
                each(Paired::Error(e, keyword));
                Before::Failed
            }
        };
    });
    if let Before::Movable(pos, statement) = before {
        each(Paired::Statement { pos, statement, moved: None });
    }
}

/// A moving statement as the build placed it, for a [`MotionSink`]: what
/// it moves, its keys, and for objects where they stand.
pub(crate) struct Moved<'a> {
    pub mover: Mover,
    pub keys: Keys<'a>,
    /// The scene's normalisation: the keys of objects and lights in
    /// normalised units, as the build places them (the camera's stay in
    /// world units).
    pub norm: Normalization,
    pub frames: Frames,
    /// The frame the build placed the statement at.
    pub frame: u32,
    /// Objects: their box there, and whether they are one sphere.
    pub objects: Option<MovedObjects>,
}

/// The objects of a moving statement where the build placed them.
#[derive(Clone, Copy, Debug)]
pub(crate) struct MovedObjects {
    /// Their bounds together, in normalised raw units.
    pub bounds: [[i32; 3]; 2],
    pub sphere: bool,
}

impl Moved<'_> {
    /// The keys as `(frame, displacement)` in the units the statement is
    /// placed in.
    pub(crate) fn values(&self) -> impl Iterator<Item = (u32, [i64; 3])> + '_ {
        let normalised = self.mover != Mover::Eye && self.mover != Mover::LookAt;
        let norm = self.norm;
        self.keys.offsets().map(move |(f, d)| (f, if normalised { d.map(|v| norm.length_wide(v)) } else { d }))
    }
}

/// What a parse that records an animation's motion hands each moving
/// statement to, once placed (the motion module's recorder): so the motion
/// is the loaded scene's, read in the same pass.
pub(crate) trait MotionSink {
    fn moved(&mut self, moved: &Moved<'_>);
}

/// The position and keys of every MOVE of `text` that follows what it can
/// move, in file order: what an animation's motion takes room for. Returns
/// the scene's FRAMES and where it stands, if it says (its first, as the
/// parser reads it).
pub(crate) fn for_each_move<'a>(text: &'a str, mut each: impl FnMut(Pos, Keys<'a>)) -> Option<(Pos, Frames)> {
    let mut frames = None;
    for_each_paired::<AnyRoom>(text, |paired| match paired {
        Paired::Statement { moved: Some((pos, keys)), .. } => each(pos, keys),
        Paired::Statement { pos, statement: Statement::Frames(f), .. } => {
            frames.get_or_insert((pos, f));
        }
        _ => {}
    });
    frames
}

#[cfg(test)]
mod tests {
    extern crate std;
    use crate::parse::{parse_frame, ParseError};
    use crate::profile::Board64K;
    use crate::scene::Scene;
    use std::boxed::Box;
    use std::format;
    use std::string::{String, ToString};
    use std::vec::Vec;

    const SURF: &str = "SURFACE 1 0.1 0.1 0.1 0.5 0.5 0.5 1 1 1 10 0.2 0.3\n";

    fn frame(text: &str, k: u32) -> Result<Box<Scene<Board64K>>, Vec<String>> {
        let mut scene = Box::new(Scene::<Board64K>::new());
        let mut errors = Vec::new();
        match parse_frame(text, &mut scene, k, &mut |e: ParseError<'_>| errors.push(e.to_string())) {
            Ok(_) => Ok(scene),
            Err(_) => Err(errors),
        }
    }

    #[test]
    fn a_move_follows_what_has_a_place_and_only_that() {
        let e = frame(&format!("FRAMES 3 {SURF}MOVE 0 1 1 1"), 0).unwrap_err();
        assert_eq!(e, ["2:1: MOVE must follow an object, LIGHT, VIEWPOINT or ORIGIN statement, not SURFACE"]);
        let e = frame("FRAMES 3 RASTER 4 4 MOVE 0 1 1 1", 0).unwrap_err();
        assert!(e[0].starts_with("1:21:") && e[0].ends_with("not RASTER"), "{e:?}");
        let e = frame("MOVE 0 1 1 1 FRAMES 3", 0).unwrap_err();
        assert!(e[0].starts_with("1:1:") && e[0].ends_with("and nothing comes before it"), "{e:?}");
        let e = frame("FRAMES 3 LIGHT 1 0 0 0 MOVE 0 1 1 1 MOVE 1 2 2 2", 0).unwrap_err();
        assert!(e[0].starts_with("1:37:") && e[0].contains("follows another"), "{e:?}");
        // FRAMES may come after the MOVE; without it each MOVE is an error.
        assert!(frame("LIGHT 1 0 0 0 MOVE 0 1 1 1 FRAMES 2", 0).is_ok());
        let e = frame("LIGHT 1 0 0 0 MOVE 0 1 1 1 LIGHT 1 0 0 0 MOVE 0 1 1 1", 0).unwrap_err();
        assert_eq!(e.len(), 2, "{e:?}");
        assert!(e[0].starts_with("1:15: MOVE in a scene without FRAMES"), "{e:?}");
        // A FRAMES in error is there all the same: its error alone.
        for frames in ["FRAMES 4 0", "FRAMES 0", "FRAMES x"] {
            let e = frame(&format!("{frames}\nLIGHT 1 0 0 0 MOVE 0 1 1 1\nMOVE 1 1 1 1"), 0).unwrap_err();
            assert_eq!(e.len(), 1, "{frames}: {e:?}");
            assert!(e[0].starts_with("1:"), "{frames}: {e:?}");
        }
        // A MOVE after a statement in error adds no error of its own.
        let e = frame("FRAMES 3 LIGHT -1 0 0 0 MOVE 0 1 1 1", 0).unwrap_err();
        assert_eq!(e.len(), 1, "{e:?}");
        assert!(e[0].starts_with("1:16: LIGHT brightness"), "{e:?}");
        // Its own syntax still counts.
        let e = frame("FRAMES 3 LIGHT 1 0 0 0 MOVE 0 1 1", 0).unwrap_err();
        assert!(e[0].contains("expected a number for MOVE dz, found the end of the file"), "{e:?}");
        let e = frame("FRAMES 3 LIGHT 1 0 0 0 MOVE 0.5 1 1 1", 0).unwrap_err();
        assert!(e[0].contains("expected an integer for MOVE frame, found `0.5`"), "{e:?}");
    }

    #[test]
    fn frames_and_their_rate() {
        let parsed = |text: &str| {
            let mut scene = Box::new(Scene::<Board64K>::new());
            parse_frame(text, &mut scene, 0, &mut |e| panic!("{e}")).unwrap().frames.map(|f| (f.count, f.rate))
        };
        assert_eq!(parsed("FRAMES 48"), Some((48, 24)));
        assert_eq!(parsed("frames 10 30 RDEPTH 2"), Some((10, 30)));
        assert_eq!(parsed("RDEPTH 2"), None);
        let e = frame("FRAMES 0", 0).unwrap_err();
        assert!(e[0].contains("FRAMES count must be an integer from 1 to 1000000, found 0"), "{e:?}");
        let e = frame("FRAMES 4 29.97", 0).unwrap_err();
        assert!(e[0].contains("expected an integer for FRAMES rate, found `29.97`"), "{e:?}");
    }

    #[test]
    fn every_frame_is_normalised_alike_and_moves_by_whole_bits() {
        let text = format!(
            "FRAMES 9 {SURF}SPHERE 1 1  0 0 0  MOVE 2 -3 0 0  6 40 2 0\n\
             SPHERE 1 1  0 5 0\nLIGHT 1 0 9 0 MOVE 8 0 -4 0\n"
        );
        let scenes: Vec<_> = (0..9).map(|k| frame(&text, k).unwrap()).collect();
        let norm = scenes[0].normalization;
        assert!(scenes.iter().all(|s| s.normalization == norm));
        // The extent is every frame's: x from -3 - 1 to 40 + 1.
        assert_eq!(norm.center[0], 37 << 31);
        let still = scenes[0].view().spheres[1].center;
        let x = |k: usize| (scenes[k].view().spheres[0].center - still).x.to_bits() as i64;
        let unit = norm.length_wide(1 << 32);
        assert_eq!([0, 2, 4, 6, 8].map(x), [-6, -6, 37, 80, 80].map(|v| v * unit / 2));
        // One key: the light stands 4 down (at the still sphere's height)
        // in every frame.
        let light = |k: usize| scenes[k].view().lights[0].position.y;
        assert!((0..9).all(|k| light(k) == still.y));
    }

    #[test]
    fn a_patch_moves_rigidly_and_a_motion_stays_in_range() {
        let grid = "0 0 0  1 0 0  2 0 0   0 1 0  1 1.3 0  2 1 0   0 2 0  1 2 0.7  2 2 0";
        let text = format!("FRAMES 5 {SURF}BSPLINE 1 3 3 3 5 5 {grid} MOVE 0 0 0 0  4 3.3 -1.1 0.7\n");
        let at = |k| frame(&text, k).unwrap();
        let (first, last) = (at(0), at(4));
        let shift = last.view().bspline_triangles[0].triangle.polygon.corners[0]
            - first.view().bspline_triangles[0].triangle.polygon.corners[0];
        for (a, b) in first.view().bspline_triangles.iter().zip(last.view().bspline_triangles) {
            assert_eq!(a.triangle.polygon.corners.map(|c| c + shift), b.triangle.polygon.corners);
            assert_eq!((a.normals, a.triangle.polygon.normal), (b.normals, b.triangle.polygon.normal));
        }
        let e = frame("FRAMES 5 LIGHT 1 999999 0 0 MOVE 0 0 0 0  4 2 0 0", 0).unwrap_err();
        assert!(e[0].starts_with("1:43: MOVE takes LIGHT beyond 1e6 at frame 4"), "{e:?}");
        assert!(frame("FRAMES 5 LIGHT 1 999999 0 0 MOVE 0 0 0 0  4 -1e6 0 0", 3).is_ok());
    }
}
