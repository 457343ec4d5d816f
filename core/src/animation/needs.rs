//! What an animation takes, counted from the scene's text and the image's
//! size ([`AnimationNeeds`]), the names of those capacities, and the error
//! when a room lacks one.
//!
//! Invariant: what a scene needs grows with its `MOVE`s and their keys,
//! never with its frames.

use super::coherence::Coherence;
use super::TILE;
use crate::motion::{Key, MotionNeeds, Track};
use crate::parse::Pos;
use core::fmt;
use embedded_graphics_core::geometry::Size;

/// What an animation of a scene takes on an image of a given size: a byte
/// a tile of the image, a track a `MOVE` and its keys. A build script
/// counts a board's ([`AnimationNeeds::of`], feature-free) and writes the
/// counts as a constant, which sizes the board's one
/// [`AnimationRoom`](super::AnimationRoom).
///
/// ```
/// use embedded_graphics::prelude::Size;
/// use octrace_core::animation::AnimationNeeds;
///
/// let text = "FRAMES 1000000\nSURFACE 1 .1 .1 .1 .7 .2 .2 0 0 0 1 0 0\nLIGHT 10 5 5 5\n\
///             SPHERE 1 1 0 0 0 MOVE 0 -2 0 0  400000 2 0 0  999999 0 1 0\n";
/// // A million frames: three keys, not a table of frames.
/// let needs = AnimationNeeds::of(text, Size::new(240, 240));
/// assert_eq!(needs, AnimationNeeds { tiles: 3600, tracks: 1, keys: 3 });
/// assert!(needs.moves());
/// ```
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct AnimationNeeds {
    /// A byte for each tile of the image ([`TILE`] pixels a side).
    pub tiles: usize,
    /// One for each `MOVE`.
    pub tracks: usize,
    /// The keys of all the `MOVE`s.
    pub keys: usize,
}

impl AnimationNeeds {
    /// What `text`'s animation takes on an image of `size` (a scene with
    /// errors: what its valid `MOVE`s take).
    pub fn of(text: &str, size: Size) -> AnimationNeeds {
        let motion = MotionNeeds::of(text);
        AnimationNeeds { tiles: Self::tiles_for(size), tracks: motion.tracks, keys: motion.keys }
    }

    /// Whether anything moves (the scene has a `MOVE`): what decides a
    /// profile's [`SceneCapacities::MOTION`](crate::scene::SceneCapacities::MOTION).
    pub const fn moves(&self) -> bool {
        self.tracks > 0
    }

    /// The tiles of an image of `size`: [`Coherence::tiles_for`] in tiles
    /// of [`TILE`], a `const fn` (3,600 for a 240×240 panel).
    pub const fn tiles_for(size: Size) -> usize {
        Coherence::tiles_for(size.width, size.height, TILE)
    }

    /// About how many bytes of RAM they take.
    pub const fn bytes(&self) -> usize {
        self.tiles + self.tracks * size_of::<Track>() + self.keys * size_of::<Key>()
    }

    /// Each capacity of `room` that these needs exceed: what it holds and
    /// what they need.
    pub fn beyond(&self, room: &AnimationNeeds) -> [Option<NoRoom>; 3] {
        let short = |what, needed: usize, holds: usize| (needed > holds).then_some(NoRoom { what, needed, holds });
        [
            short(AnimationCapacity::Tiles, self.tiles, room.tiles),
            short(AnimationCapacity::Tracks, self.tracks, room.tracks),
            short(AnimationCapacity::Keys, self.keys, room.keys),
        ]
    }
}

/// What an [`AnimationRoom`](super::AnimationRoom) holds: the vocabulary of its capacities.
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum AnimationCapacity {
    /// A byte a tile of the image.
    Tiles,
    /// A track a `MOVE`.
    Tracks,
    /// The `MOVE`s' keys.
    Keys,
}

impl AnimationCapacity {
    /// Its name, as [`AnimationNeeds`]'s field: `tiles`, `tracks`, `keys`.
    pub const fn name(self) -> &'static str {
        match self {
            AnimationCapacity::Tiles => "tiles",
            AnimationCapacity::Tracks => "tracks",
            AnimationCapacity::Keys => "keys",
        }
    }

    /// What a scene has of it, in the format's words, for messages.
    pub const fn what(self) -> &'static str {
        match self {
            AnimationCapacity::Tiles => "tiles of the image (a byte each)",
            AnimationCapacity::Tracks => "moving statements (one a MOVE)",
            AnimationCapacity::Keys => "MOVE keys",
        }
    }
}

/// A capacity of an animation's room that a scene needs more of.
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct NoRoom {
    /// What runs out.
    pub what: AnimationCapacity,
    /// How many the scene needs.
    pub needed: usize,
    /// How many the room holds.
    pub holds: usize,
}

impl NoRoom {
    /// Where in `text` the scene first needs more than the room holds, for
    /// the error's line and column: the `MOVE` whose track or keys go past
    /// it; for the tiles (the image's, which the scene needs as an
    /// animation), its `FRAMES`. `None` when `text` does not go past it.
    ///
    /// ```
    /// use octrace_core::animation::{AnimationCapacity, NoRoom};
    /// use octrace_core::parse::Pos;
    ///
    /// let text = "FRAMES 4\nSPHERE 1 1 0 0 0 MOVE 0 0 0 0  2 1 0 0\nSPHERE 1 1 3 0 0 MOVE 0 0 0 0  2 0 1 0\n";
    /// let short = NoRoom { what: AnimationCapacity::Tracks, needed: 2, holds: 1 };
    /// assert_eq!(short.position_in(text), Some(Pos { line: 3, column: 18 }));
    /// let short = NoRoom { what: AnimationCapacity::Tiles, needed: 3600, holds: 0 };
    /// assert_eq!(short.position_in(text), Some(Pos { line: 1, column: 1 }));
    /// ```
    pub fn position_in(&self, text: &str) -> Option<Pos> {
        let (mut tracks, mut keys, mut past) = (0, 0, None);
        let frames = crate::parse::for_each_move(text, |pos, moved| {
            tracks += 1;
            keys += moved.iter().count();
            let count = match self.what {
                AnimationCapacity::Tiles => return,
                AnimationCapacity::Tracks => tracks,
                AnimationCapacity::Keys => keys,
            };
            if count > self.holds {
                past.get_or_insert(pos);
            }
        });
        match self.what {
            AnimationCapacity::Tiles => frames.map(|(pos, _)| pos),
            _ => past,
        }
    }
}

impl fmt::Display for NoRoom {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let NoRoom { what, needed, holds } = self;
        write!(
            f,
            "too many {} to play this animation: this build's room for it ({}) holds {holds} and the scene needs \
             {needed}",
            what.what(),
            what.name()
        )
    }
}

impl core::error::Error for NoRoom {}

#[cfg(test)]
mod tests {
    use super::*;

    /// The sizes the docs give a board's integrator (docs/animation.md and
    /// the module's doc): a change to a track or a key updates them.
    #[test]
    fn a_track_and_a_key_take_the_documented_bytes() {
        assert_eq!((size_of::<Track>(), size_of::<Key>()), (88, 76));
    }
}
