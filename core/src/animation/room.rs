//! The storage an animation's needs are held in: [`AnimationRoom`] in a
//! `static` on a board, [`HostAnimationRoom`] on the heap.
//!
//! Invariants: a room holds exactly the counts it is declared with, all
//! zero bits (a board's `static` lands in `.bss`).

#[cfg(feature = "alloc")]
use super::needs::AnimationNeeds;
use super::needs::NoRoom;
use super::player::{Animation, State};
use super::TILE;
use crate::motion::{Key, Track};
use core::fmt;
use core::sync::atomic::AtomicU8;
use embedded_graphics_core::geometry::Size;

/// Room for one animation on a board: `TILES` bytes of tiles, `TRACKS`
/// tracks and `KEYS` keys, all zero bits (a `static` of it costs no
/// flash). Size it with the [`AnimationNeeds`](super::AnimationNeeds) of the scenes it plays,
/// keep it in a `static`, and take it once:
///
/// ```
/// use embedded_graphics::prelude::Size;
/// use octrace_core::animation::{AnimationNeeds, AnimationRoom};
/// use octrace_core::ConstStaticCell;
///
/// // What a build script writes for the board's scene.
/// const NEEDS: AnimationNeeds = AnimationNeeds { tiles: AnimationNeeds::tiles_for(Size::new(240, 240)), tracks: 1, keys: 6 };
/// static ANIMATION: ConstStaticCell<AnimationRoom<{ NEEDS.tiles }, { NEEDS.tracks }, { NEEDS.keys }>> =
///     ConstStaticCell::new(AnimationRoom::new());
/// let animation = ANIMATION.take().animation(Size::new(240, 240))?;
/// assert_eq!(animation.room(), NEEDS);
/// # Ok::<(), octrace_core::animation::NoRoom>(())
/// ```
pub struct AnimationRoom<const TILES: usize, const TRACKS: usize, const KEYS: usize> {
    tiles: [AtomicU8; TILES],
    tracks: [Track; TRACKS],
    keys: [Key; KEYS],
    state: State,
}

impl<const TILES: usize, const TRACKS: usize, const KEYS: usize> AnimationRoom<TILES, TRACKS, KEYS> {
    /// Empty room: a constant of all-zero bits.
    pub const fn new() -> Self {
        AnimationRoom {
            tiles: [const { AtomicU8::new(0) }; TILES],
            tracks: [Track::EMPTY; TRACKS],
            keys: [Key::EMPTY; KEYS],
            state: State::EMPTY,
        }
    }

    /// An animation in this room on an image of `size` (where the last one
    /// made in it left off, at the same size), or what its tiles lack.
    pub fn animation(&mut self, size: Size) -> Result<Animation<'_>, NoRoom> {
        Animation::new((&self.tiles, &mut self.tracks, &mut self.keys, &mut self.state), size, TILE)
    }
}

impl<const TILES: usize, const TRACKS: usize, const KEYS: usize> Default for AnimationRoom<TILES, TRACKS, KEYS> {
    fn default() -> Self {
        Self::new()
    }
}

impl<const TILES: usize, const TRACKS: usize, const KEYS: usize> fmt::Debug for AnimationRoom<TILES, TRACKS, KEYS> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_struct("AnimationRoom").field("tiles", &TILES).field("tracks", &TRACKS).field("keys", &KEYS).finish()
    }
}

/// Room for one animation on the heap, as large as a scene needs (feature
/// `alloc`): a desktop's.
///
/// ```
/// use embedded_graphics::prelude::Size;
/// use octrace_core::animation::{AnimationNeeds, HostAnimationRoom};
///
/// let text = "FRAMES 1000000\nSURFACE 1 .1 .1 .1 .7 .2 .2 0 0 0 1 0 0\nLIGHT 10 5 5 5\n".to_owned()
///     + &(0..200).map(|i| format!("SPHERE 1 0.1 {i} 0 0 MOVE 0 0 0 0  999999 0 5 0\n")).collect::<String>();
/// let size = Size::new(640, 480);
/// let needs = AnimationNeeds::of(&text, size);
/// // 200 moving spheres over a million frames: 66 KiB (19 of them the
/// // tiles), nothing a frame.
/// assert!(needs.bytes() < 70 * 1024, "{needs:?}");
/// let mut room = HostAnimationRoom::new(needs);
/// let animation = room.animation(size)?;
/// # let _ = animation;
/// # Ok::<(), octrace_core::animation::NoRoom>(())
/// ```
#[cfg(feature = "alloc")]
#[derive(Debug)]
pub struct HostAnimationRoom {
    tiles: alloc::vec::Vec<AtomicU8>,
    tracks: alloc::vec::Vec<Track>,
    keys: alloc::vec::Vec<Key>,
    state: State,
}

#[cfg(feature = "alloc")]
impl HostAnimationRoom {
    /// Room for `needs`.
    pub fn new(needs: AnimationNeeds) -> HostAnimationRoom {
        HostAnimationRoom {
            tiles: (0..needs.tiles).map(|_| AtomicU8::new(0)).collect(),
            tracks: alloc::vec![Track::EMPTY; needs.tracks],
            keys: alloc::vec![Key::EMPTY; needs.keys],
            state: State::EMPTY,
        }
    }

    /// What it holds.
    pub fn room(&self) -> AnimationNeeds {
        AnimationNeeds { tiles: self.tiles.len(), tracks: self.tracks.len(), keys: self.keys.len() }
    }

    /// An animation in this room on an image of `size` (where the last one
    /// made in it left off, at the same size), or what its tiles lack.
    pub fn animation(&mut self, size: Size) -> Result<Animation<'_>, NoRoom> {
        self.animation_in_tiles(size, TILE)
    }

    /// [`HostAnimationRoom::animation`] in tiles of `side` pixels a side
    /// (the room holding as many): for a benchmark that weighs the sides.
    #[doc(hidden)]
    pub fn animation_in_tiles(&mut self, size: Size, side: u32) -> Result<Animation<'_>, NoRoom> {
        Animation::new((&self.tiles, &mut self.tracks, &mut self.keys, &mut self.state), size, side)
    }
}
