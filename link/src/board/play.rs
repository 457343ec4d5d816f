//! What a board needs to play an animation: the storage a firmware owns
//! for it ([`AnimationRoom`]: the tiles' counts and the motion), the check
//! that a scene fits it (each capacity that runs out named, as the
//! parser's are), and a frame's part of a [`Drawing`](super::Drawing)
//! ([`Playing`]).
//!
//! Invariants: a scene whose animation does not fit the room is rejected
//! with one `scene-error` for each capacity that runs out, before any
//! `drawing`; a room's storage is the caller's, never allocated.

use crate::message::{CapacityNeed, Panel};
use core::fmt;
use core::sync::atomic::AtomicU8;
use octrace_core::animation::{Coherence, Key, Motion, Track};
use octrace_core::profile::Profile;
use octrace_core::scene::Frames;
use octrace_core::LoadedScene;

/// The side of the square tiles a board's animation is traced in, in
/// pixels: 3,600 tiles (bytes) for a 240×240 panel,
/// `Coherence::tiles_for(240, 240, TILE)`.
pub const TILE: u32 = 4;

/// A firmware's storage for playing animations: a byte a tile of the
/// panel (`Coherence::tiles_for(width, height, TILE)`) and room for the
/// motion of the animations it takes ([`Motion::needs`] says a scene's).
/// [`AnimationRoom::none`]: the board plays no animation (an animated
/// scene is rejected, naming what it lacks).
///
/// ```
/// use core::sync::atomic::AtomicU8;
/// use octrace_core::animation::{Coherence, Key, Track};
/// use octrace_link::board::{AnimationRoom, TILE};
///
/// const TILES: usize = Coherence::tiles_for(240, 240, TILE);
/// static COUNTS: [AtomicU8; TILES] = [const { AtomicU8::new(0) }; TILES];
/// let (mut tracks, mut keys, mut displacements) = ([Track::EMPTY; 16], [Key::default(); 64], [[0; 3]; 256]);
/// let room = AnimationRoom { tiles: &COUNTS, tracks: &mut tracks, keys: &mut keys, displacements: &mut displacements };
/// assert_eq!(TILES, 3600);
/// # let _ = room;
/// ```
#[derive(Debug)]
pub struct AnimationRoom<'s> {
    /// A byte for each tile of the panel.
    pub tiles: &'s [AtomicU8],
    /// One for each `MOVE` of a scene.
    pub tracks: &'s mut [Track],
    /// The keys of all its `MOVE`s.
    pub keys: &'s mut [Key],
    /// Its frames once for each moving object statement.
    pub displacements: &'s mut [[i32; 3]],
}

impl AnimationRoom<'_> {
    /// No room: the board plays no animation.
    pub fn none() -> AnimationRoom<'static> {
        AnimationRoom { tiles: &[], tracks: &mut [], keys: &mut [], displacements: &mut [] }
    }

    pub(crate) fn sizes(&self) -> RoomSizes {
        RoomSizes {
            tiles: self.tiles.len(),
            tracks: self.tracks.len(),
            keys: self.keys.len(),
            displacements: self.displacements.len(),
        }
    }
}

/// What an [`AnimationRoom`] holds.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub(crate) struct RoomSizes {
    tiles: usize,
    tracks: usize,
    keys: usize,
    displacements: usize,
}

impl RoomSizes {
    /// Each capacity of the room that `text`'s animation, played on
    /// `panel`, needs more of.
    pub(crate) fn short_of(&self, text: &[u8], panel: Panel) -> [Option<CapacityNeed<'static>>; 4] {
        // The scene loaded: its text is UTF-8.
        let needs = core::str::from_utf8(text).map(Motion::needs).unwrap_or_default();
        let tiles = Coherence::tiles_for(panel.width.into(), panel.height.into(), TILE);
        let need = |name, needed: usize, holds: usize| {
            (needed > holds).then(|| CapacityNeed { name, needed: Some(saturate(needed)), holds: saturate(holds) })
        };
        [
            need("tiles", tiles, self.tiles),
            need("tracks", needs.tracks, self.tracks),
            need("keys", needs.keys, self.keys),
            need("displacements", needs.displacements, self.displacements),
        ]
    }
}

/// The frames of `scene`, if it is an animation to play (more than one
/// frame).
pub(crate) fn animated<P: Profile>(scene: &LoadedScene<'_, P>) -> Option<Frames> {
    scene.frames().filter(|frames| frames.count > 1)
}

pub(crate) fn saturate(n: usize) -> u32 {
    u32::try_from(n).unwrap_or(u32::MAX)
}

/// The message of a capacity of the [`AnimationRoom`] a scene needs more of.
pub(crate) struct NoRoom(pub(crate) CapacityNeed<'static>);

impl fmt::Display for NoRoom {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let NoRoom(need) = self;
        write!(f, "too many {} to play this animation: the board holds {}", need.name, need.holds)?;
        match need.needed {
            Some(needed) => write!(f, " and the scene needs {needed}"),
            None => Ok(()),
        }
    }
}

/// A frame of an animation being drawn: which, the loop's motion, and the
/// tiles its [`Coherence`] planned to trace (`Coherence::trace_band` or
/// `trace_band_until`, band by band, on one core or several).
#[derive(Clone, Copy, Debug)]
pub struct Playing<'r> {
    /// The frame, from 0.
    pub frame: u32,
    /// What moves over the loop.
    pub motion: &'r Motion<'r>,
    /// The tiles, planned for this frame.
    pub coherence: &'r Coherence<'r>,
}
