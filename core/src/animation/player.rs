//! An animation being played: its motion and its tiles' coherence in one
//! place, over storage the caller owns ([`AnimationRoom`](super::AnimationRoom)).
//! The loader records the motion into it as it places a new scene
//! (`Animation::load`, in `raytracer/`), and steps its tiles from the
//! frame shown to the one loaded.
//!
//! Invariants: while `state.loaded`, the tracks and keys hold the motion
//! of the text `state.fingerprint` names, recorded when it was first loaded
//! (and every frame's camera checked then), and the tiles' counts are
//! those of an image of `state.size` after frame `state.frame`, whatever
//! order frames are asked in (a jump of s frames is s steps of the loop,
//! capped where every count has run out); each object track keeps its
//! displacement at that frame. The state lives in the room, so that an
//! animation made again from it goes on where the last left off.

use super::coherence::Coherence;
use super::needs::{AnimationCapacity, AnimationNeeds, NoRoom};
use crate::accel::Indexing;
use crate::motion::{Dependence, Key, Lookout, Motion, MotionNeeds, Recorder, Track};
use crate::scene::Frames;
use core::sync::atomic::AtomicU8;
use embedded_graphics_core::geometry::Size;

/// After this many steps every count has run out (the longest kept is 253)
/// but a tile's that nothing can change: stepping further changes nothing.
const LONGEST_STEP: u32 = 255;

/// An animation: what moves over its loop and what each tile of the image
/// still shows, in the caller's storage ([`AnimationRoom`](super::AnimationRoom) on a board,
/// `HostAnimationRoom` on a desktop, feature `alloc`). Load
/// each frame with [`Animation::load`] (it records the motion of a scene it
/// has not seen, checking the camera of every frame, and otherwise steps
/// its tiles on), then draw the [`Frame`](crate::Frame) as a still is
/// drawn: only its tiles the motion can have changed are traced.
///
/// ```
/// use embedded_graphics::{image::Image, mock_display::MockDisplay, pixelcolor::Rgb888, prelude::*};
/// use octrace_core::animation::{AnimationNeeds, AnimationRoom};
/// use octrace_core::Raytracer;
///
/// octrace_core::profile! {
///     /// Two spheres, one moving; frames re-trace only what changes.
///     struct Moving { spheres: 2, surfaces: 1, lights: 1 }
///     coherence: true
/// }
/// let text = "FRAMES 4\nRASTER 16 16\nBACKGROUND 0 0 1\nSURFACE 1 .1 .1 .1 .7 .2 .2 0 0 0 1 0 0\n\
///             LIGHT 10 5 5 5\nSPHERE 1 2 0 0 -4\nSPHERE 1 0.5 -3 2 0 MOVE 0 0 0 0  3 1.5 0 0\n";
/// const NEEDS: AnimationNeeds = AnimationNeeds { tiles: AnimationNeeds::tiles_for(Size::new(16, 16)), tracks: 1, keys: 2 };
/// let mut room = AnimationRoom::<{ NEEDS.tiles }, { NEEDS.tracks }, { NEEDS.keys }>::new();
/// let mut animation = room.animation(Size::new(16, 16))?;
/// let mut raytracer = Raytracer::<Moving>::new();
/// let mut panel = MockDisplay::<Rgb888>::new();
/// panel.set_allow_overdraw(true);
/// for frame in 0..4 {
///     let loaded = animation.load(&mut raytracer, text, frame)?;
///     let traced = loaded.tiles().traced_pixels();
///     loaded.image_for(&panel).try_draw(&mut panel)?;
///     // The panel shows frame `frame`, as if drawn whole.
///     let mut whole = MockDisplay::<Rgb888>::new();
///     Image::new(&loaded.scene().image(Size::new(16, 16)), Point::zero()).draw(&mut whole)?;
///     assert_eq!(panel, whole);
///     assert!(frame == 0 && traced == 256 || frame > 0 && traced < 256, "frame {frame}: {traced} pixels");
/// }
/// # Ok::<(), Box<dyn core::error::Error>>(())
/// ```
#[derive(Debug)]
pub struct Animation<'s> {
    tracks: &'s mut [Track],
    keys: &'s mut [Key],
    coherence: Coherence<'s>,
    /// What its storage holds.
    room: AnimationNeeds,
    state: &'s mut State,
    /// How its frames' scenes are indexed.
    indexing: Indexing,
    /// Dependences the tracker drops, by a test only.
    ignored: u8,
}

/// What an animation's room holds of it besides its storage: the scene it
/// holds the motion of, and the frame its tiles are at. All zero bits when
/// nothing is loaded.
#[derive(Clone, Copy, Debug, Default)]
pub(crate) struct State {
    loaded: bool,
    fingerprint: u64,
    /// The image's size the tiles are of.
    size: [u32; 2],
    /// FRAMES: count and rate.
    frames: [u32; 2],
    tracks: u32,
    keys: u32,
    frame: u32,
}

impl State {
    /// Nothing loaded: a constant of all-zero bits.
    pub(crate) const EMPTY: State =
        State { loaded: false, fingerprint: 0, size: [0; 2], frames: [0; 2], tracks: 0, keys: 0, frame: 0 };

    fn frames(&self) -> Frames {
        let [count, rate] = self.frames;
        Frames { count, rate }
    }
}

/// What a frame's draw needs of its animation: the motion, the tiles
/// planned, the frame; read-only, shared by the cores that draw it.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Playing<'a> {
    pub motion: Motion<'a>,
    pub coherence: Coherence<'a>,
    pub frame: u32,
    pub ignored: u8,
}

impl<'s> Animation<'s> {
    /// An animation over `tiles`, `tracks`, `keys` and `state` on an
    /// image of `size` in tiles of `side`: where the last one made over
    /// them left off, at the same size; else with nothing loaded.
    pub(crate) fn new(
        (tiles, tracks, keys, state): (&'s [AtomicU8], &'s mut [Track], &'s mut [Key], &'s mut State),
        size: Size,
        side: u32,
    ) -> Result<Animation<'s>, NoRoom> {
        let room = AnimationNeeds { tiles: tiles.len(), tracks: tracks.len(), keys: keys.len() };
        let went_on = state.loaded && state.size == [size.width, size.height];
        let coherence = Coherence::new(tiles, size, side, !went_on).map_err(|needed| NoRoom {
            what: AnimationCapacity::Tiles,
            needed,
            holds: tiles.len(),
        })?;
        if !went_on {
            *state = State::EMPTY;
        }
        Ok(Animation { tracks, keys, coherence, room, state, indexing: Indexing::default(), ignored: 0 })
    }

    /// The animation, its frames' scenes indexed as `indexing` says (an
    /// [`AccelMode`](crate::AccelMode), or with an octree criterion of its
    /// own), not as [`Indexing::default`]: the same pictures.
    pub fn indexed(self, indexing: impl Into<Indexing>) -> Self {
        Animation { indexing: indexing.into(), ..self }
    }

    /// How its frames' scenes are indexed.
    pub(crate) fn indexing(&self) -> Indexing {
        self.indexing
    }

    /// What its storage holds.
    pub fn room(&self) -> AnimationNeeds {
        self.room
    }

    /// The tiles of the image and what the frame loaded last traces of
    /// them (every tile, at the first).
    pub fn tiles(&self) -> &Coherence<'s> {
        &self.coherence
    }

    /// The loaded scene's frames (a still scene is one frame), and the
    /// frame loaded last.
    pub fn frames(&self) -> Option<(Frames, u32)> {
        self.state.loaded.then(|| (self.state.frames(), self.state.frame))
    }

    /// Forgets what the image shows: the next frame loaded traces every
    /// tile (for a display something else drew over).
    pub fn restart(&mut self) {
        self.coherence.restart();
    }

    /// Drops the dependence `dependence` from the tracking: for a test
    /// that checks its check of exactness fails without it.
    #[doc(hidden)]
    pub fn ignoring(mut self, dependence: Dependence) -> Self {
        self.ignored |= 1 << dependence as u8;
        self
    }

    /// Whether `text` is the scene whose motion it holds.
    pub(crate) fn holds(&self, text: &[u8]) -> bool {
        self.state.loaded && self.state.fingerprint == fingerprint(text)
    }

    /// A recorder of `text`'s motion into the storage, and the length of
    /// its loop (1 for a still); or what the storage lacks.
    pub(crate) fn recorder(&mut self, text: &[u8]) -> Result<(Recorder<'_>, u32), NoRoom> {
        let motion = core::str::from_utf8(text).map(MotionNeeds::of).unwrap_or_default();
        let needs = AnimationNeeds { tiles: 0, tracks: motion.tracks, keys: motion.keys };
        if let Some(short) = needs.beyond(&self.room).into_iter().flatten().next() {
            return Err(short);
        }
        self.state.loaded = false;
        Ok((Recorder::new(self.tracks, self.keys), motion.frames.max(1)))
    }

    /// The length of the loop of the scene it holds.
    pub(crate) fn loop_length(&self) -> u32 {
        self.state.frames[0].max(1)
    }

    /// `text`'s motion recorded (`tracks` tracks, `keys` keys) from frame
    /// `frame` of its `frames`: every tile is traced next.
    pub(crate) fn recorded(&mut self, text: &[u8], frames: Frames, (tracks, keys): (usize, usize), frame: u32) {
        let size = self.coherence.size();
        *self.state = State {
            loaded: true,
            fingerprint: fingerprint(text),
            size: [size.width, size.height],
            frames: [frames.count, frames.rate],
            tracks: tracks as u32,
            keys: keys as u32,
            frame,
        };
        self.coherence.restart();
        self.keep(frame);
    }

    /// Steps the tiles from the frame loaded last to `frame`, forward round
    /// the loop.
    pub(crate) fn step_to(&mut self, frame: u32) {
        if !self.state.loaded {
            return;
        }
        let count = self.state.frames[0].max(1);
        let steps = (frame % count + count - self.state.frame % count) % count;
        self.state.frame = frame;
        for _ in 0..steps.min(LONGEST_STEP) {
            self.coherence.plan();
        }
        self.keep(frame);
    }

    /// The object tracks keep their displacements at `frame`.
    fn keep(&mut self, frame: u32) {
        let s = *self.state;
        if s.loaded {
            Motion::at_frame(&mut self.tracks[..s.tracks as usize], &self.keys[..s.keys as usize], s.frames(), frame);
        }
    }

    /// What a draw of the frame loaded needs.
    pub(crate) fn playing(&self) -> Playing<'_> {
        let s = *self.state;
        let (frames, tracks, keys, frame) = match s.loaded {
            true => (s.frames(), s.tracks as usize, s.keys as usize, s.frame),
            false => (Frames { count: 1, rate: Frames::DEFAULT_RATE }, 0, 0, 0),
        };
        let motion = Motion::new(frames, &self.tracks[..tracks], &self.keys[..keys], frame);
        Playing { motion, coherence: self.coherence, frame, ignored: self.ignored }
    }
}

impl<'a> Playing<'a> {
    /// The lookout a renderer of the frame watches the motion to come
    /// with; none when the camera moves before the next frame (every count
    /// is then 0: the pixels are traced as a still's, at a still's cost).
    pub(crate) fn lookout(&self) -> Option<Lookout<'a>> {
        let lookout = Lookout::new(self.motion, self.frame, self.ignored);
        (!lookout.is_idle()).then_some(lookout)
    }
}

/// A fingerprint of a scene's text: a text edited between two frames is
/// another animation. Two 32-bit multiplicative hashes of its 4-byte words
/// with its length: a board hashes its text every frame, and a 32-bit
/// product is one instruction on a Cortex-M0+ where a 64-bit one (as in
/// 64-bit FNV) is a library call a byte.
fn fingerprint(text: &[u8]) -> u64 {
    const PRIMES: [u32; 2] = [0x0100_0193, 0x9e37_79b1];
    let mut lanes = [0x811c_9dc5u32, 0x2f73_2b1d];
    let words = text.chunks_exact(4);
    let mut last = [0; 4];
    last[..words.remainder().len()].copy_from_slice(words.remainder());
    for word in words.map(|w| [w[0], w[1], w[2], w[3]]).chain([last]) {
        let word = u32::from_le_bytes(word);
        for (lane, prime) in lanes.iter_mut().zip(PRIMES) {
            // The rotation brings the product's high bits, which every
            // bit of the word reaches, down to where the next word lands.
            *lane = (*lane ^ word).wrapping_mul(prime).rotate_left(15);
        }
    }
    let length = text.len() as u32;
    (u64::from(lanes[0] ^ length) << 32) | u64::from(lanes[1].wrapping_add(length))
}

#[cfg(test)]
mod tests {
    use super::fingerprint;

    #[test]
    fn any_one_byte_edit_or_a_byte_more_changes_the_fingerprint() {
        let text = b"FRAMES 48 12\nSPHERE 1 0.5 0 0 0\nMOVE 0 0 0 0\n  47 1 0 0\n";
        let original = fingerprint(text);
        for at in 0..text.len() {
            for bit in 0..8 {
                let mut edited = *text;
                edited[at] ^= 1 << bit;
                assert_ne!(fingerprint(&edited), original, "byte {at}, bit {bit}");
            }
        }
        for more in 1..8 {
            let longer: heapless::Vec<u8, 80> = text.iter().copied().chain(core::iter::repeat_n(0, more)).collect();
            assert_ne!(fingerprint(&longer), original, "{more} zero bytes more");
        }
        assert_eq!(fingerprint(text), original);
    }
}
